// The parameter block and the Sim block: twins of src/params.rs and src/state.rs,
// member for member (tests/params_layout.rs compares the two layouts through
// naga). Bit-match rules (docs/design.md): same operation order as the Rust twin, no
// fma, no built-in transcendentals, explicit x*x+y*y+z*z.

struct Sizes {
    n_particles: u32,
    n_cells: u32,
    dim: u32,
    flags: u32,              // FLAG_* bits
}

struct Grid {
    cells: vec4<u32>,        // cells along x, y, z
    cell_inv: vec4<f32>,     // 1 / cell size per axis
    period: vec4<f32>,       // period length per axis (0 where not periodic)
    half_period: vec4<f32>,
    keep_lo: vec4<f32>,      // below keep_lo or above keep_hi: left
    keep_hi: vec4<f32>,
}

struct Kernel {
    kind: u32,               // 0 quintic, 1 Wendland C2, 2 cubic spline
    h: f32,
    inv_h: f32,
    sigma: f32,              // normalisation
    support2: f32,           // support radius squared
    eta2: f32,               // 0.01 h², regularises 1/r² terms
}

struct TimeStep {
    max_sound_speed: f32,
    viscous_limit: f32,      // 0.125 h²/nu
    conduction_limit: f32,   // 0.1 rho c_p h²/k
    fixed_dt: f32,           // 0: adaptive
    barrier_limit: f32,      // 0.22 sqrt(m/k_b)
    capillary_limit: f32,    // 0.25 sqrt(rho h^3/(2 pi alpha))
    contact_limit: f32,      // 0.22 sqrt(m/k_c)
    maximum_limit: f32,      // run.max_dt
}

struct Flow {
    gravity: vec4<f32>,
    background_pressure: f32,
    interface_viscosity: f32, // F22 (32) alpha_0^lg (0 = off)
    wall_weight_floor: f32,   // wall pass: Shepard weight floor
    barrier_radius: f32,      // F22 (34) r_b (0 = off)
    barrier_stiffness: f32,   // k_b
    barrier_damping: f32,     // d_b
    solid_fluid_viscosity: f32,  // F22 (33) alpha_0^sf (0 = off)
    solid_fluid_inv_width: f32,  // 1 / dT_d
}

struct Tension {             // F22 (24)-(26), (8), (21)
    alpha0: f32,
    alpha_slope: f32,
    t_ref: f32,
    alpha_min: f32,
    t_melt: f32,             // ramp f[T, T_m, T_m + dT_s]
    inv_ramp_width: f32,     // 1/dT_s (0: no ramp)
    liquid: u32,
    gas: u32,                // NO_PHASE in the free-surface form
    kappa_max: f32,          // free-surface form: |kappa| <= 1/support
    sahoo_r_gamma: f32,      // R18 (4.2): R Gamma_s (0: no solute term)
    sahoo_k_a: f32,          // k_l a_s
    sahoo_q: f32,            // -dH0 / R
    sahoo_gamma_h: f32,      // Gamma_s dH0
    thin_layer_depth: f32,   // R18 4.4: no tension without liquid this deep along -n (0: off)
}

struct Surfaces {
    inv_kappa: f32,          // 1 / kappa, the surface delta's normalisation
    ambient_t4: f32,         // T_ambient^4 for radiation
    interior_delta: f32,     // the free-surface CSF skips full-support particles below this delta (0: none)
}

struct PathPoint {
    @align(16) time: f32,    // 16: the uniform array stride
    x: f32,                  // lateral beam centre (grid-relative)
    y: f32,
}

struct PowerStep {
    @align(16) time: f32,    // 16: the uniform array stride
    power: f32,              // from `time` on
}

struct Laser {
    absorptivity: f32,
    radius: f32,
    absorption: f32,         // Beer-Lambert absorption coefficient
    model: u32,              // 0 none, LASER_BEER_LAMBERT, LASER_SURFACE, LASER_RAY_TRACED
    bin_size: f32,
    peak_per_watt: f32,      // peak irradiance per watt
    bin_volume: f32,
    column_area: f32,
    bins: vec4<u32>,         // bins per axis
    lo: vec4<f32>,           // bin grid lower corner (grid-relative)
    path_points: u32,
    power_steps: u32,
    rays_per_side: u32,      // ray-traced: rays per lateral axis (odd)
    ray_spacing: f32,        // their lateral spacing
    ray_norm: f32,           // 1 / sum of the profile over the bundle
    max_bounces: u32,        // surface hits a ray may make
    power_unit: f32,         // W per fixed-point unit
    profile: u32,            // PROFILE_GAUSSIAN, PROFILE_TOP_HAT
    march_step: f32,         // step along a ray
    march_steps: u32,        // steps a ray may march between two hits
    // @align(16): naga takes a struct's alignment from its members' types, not
    // their @align, so PathPoint's own would not place the array (params.rs).
    @align(16) path: array<PathPoint, 32>,
    @align(16) power: array<PowerStep, 32>,
}

struct Bodies {              // rigid bodies, F22 (39)-(40) contact (FLAG_BODIES)
    n_bodies: u32,
    contact_stiffness: f32,  // k_c
    contact_damping: f32,    // d_c
    contact_distance: f32,   // dx
}

struct Solve {                // the formulation and its solvers (backend::schedule)
    formulation: u32,
    heat_integrator: u32,     // HEAT_EULER, HEAT_TRAPEZOIDAL
    heat_tolerance: f32,
    heat_max_iterations: u32,
    delta_hc: f32,            // delta h c0, R18 (3.53)
    viscosity_factor: f32,    // 2 (d + 2), R18 (3.18)
    dfsph_density_tolerance: f32,     // DFSPH: mean (rho* - rho0)/rho0
    dfsph_divergence_tolerance: f32,  // DFSPH: mean dt max(D rho/Dt, 0)/rho0
    dfsph_max_iterations: u32,
    dfsph_viscosity_tolerance: f32,   // DFSPH implicit viscosity: CG stops at |r| <= this |r0|
    dfsph_viscosity_max_iterations: u32,
    dfsph_xsph: f32,                  // J22 (14) alpha
    dfsph_viscosity_eps: f32,         // 0.01 h^2
    dfsph_viscosity_form: u32,        // 0 F22 (23) (Morris), 1 Weiler 2018 / R18 (3.18)
    dfsph_cohesion: f32,              // J22 (15) gamma_f, 1/s^2
    dfsph_adhesion: f32,              // J22 (16) gamma_b, 1/s^2
    dfsph_min_neighbours: u32,        // DFSPH: fewer: no divergence solve (spray)
}

struct Phase {
    rho0: f32,
    c2: f32,                 // sound speed squared
    eta: f32,                // dynamic viscosity
    kind: u32,               // KIND_*
    velocity: vec4<f32>,     // wall velocity
    conductivity: f32,       // solid k_s
    heat_capacity: f32,      // solid c_s
    reference_temperature: f32,
    band_enthalpy: f32,      // h(T_l) - h(T_s)
    solidus: f32,
    liquidus: f32,
    band_capacity: f32,      // b = c_s + L / (T_l - T_s)
    flags: u32,              // HEAT_*, PHASE_* bits
    mushy_damping: f32,      // C (1/s)
    liquid_conductivity: f32,
    liquid_heat_capacity: f32,
    capacity_slope: f32,     // a = (c_l - c_s) / (2 (T_l - T_s))
    evap_pressure: f32,      // C_p
    evap_temperature: f32,   // C_T
    inv_boiling_temperature: f32,
    evap_latent_heat: f32,   // h_v
    evap_enthalpy_reference: f32, // T_h0
    vapor_constant: f32,     // C_M
    recondensation: f32,     // 0.82 c_s
    emissivity_sb: f32,      // emissivity * sigma_B
    contact_cos: f32,        // F22 (27): cos, sin of the liquid's contact angle on
    contact_sin: f32,        // this wall/solid phase (FLAG_WETTING); a Dirichlet
                             // wall's temperature is per particle (heat.x)
    density_points: u32,     // PHASE_DENSITY_LAW: point k is density[k / 4][k % 4]
    program_temperature: f32, // PHASE_PROGRAM: T = this + (A + A' t) sin(2 pi f t) + rate min(t, until)
    program_amplitude: f32,
    program_amplitude_rate: f32,
    program_frequency: f32,
    program_rate: f32,
    program_until: f32,
    implicit_eta: f32,       // DFSPH implicit viscosity's mu (eta is then 0)
    enthalpy_points: u32,    // enthalpy_table (0: none): h - h(T_ref) at point k is enthalpy[k / 4].value[k % 4]
    conductivity_points: u32, // conductivity_table (0: none), in conductivity_law
    optical_n: f32,          // ray-traced laser: complex refractive index n + ik
    optical_k: f32,
    density: array<LawPoints, 2>,
    enthalpy: array<LawPoints, 2>,
    conductivity_law: array<LawPoints, 2>,
}

// Four points of a piecewise-linear law y(T): y = value + slope (T - temperature)
// from a point to the next (the density law rho0(T), the enthalpy h(T), the
// conductivity lambda(T)).
struct LawPoints {
    temperature: vec4<f32>,
    value: vec4<f32>,
    slope: vec4<f32>,
}

// Arithmetic literals (see consts.wgsl).
struct Consts {
    half: f32,
    quarter: f32,
    two: f32,
    one: f32,
    three: f32,
    six: f32,
    fifteen: f32,
    five: f32,
    thirty: f32,
    seventy_five: f32,
    one_and_half: f32,
    three_quarters: f32,
    nine_quarters: f32,
    log2e: f32,
    ln2_hi: f32,
    ln2_lo: f32,
    exp_c0: f32,
    exp_c1: f32,
    exp_c2: f32,
    exp_c3: f32,
    exp_c4: f32,
    exp_c5: f32,
    ln_c0: f32,
    ln_c1: f32,
    ln_c2: f32,
    ln_c3: f32,
    ln_c4: f32,
    four: f32,
    tenth: f32,
    jacobi_floor: f32,
    two_pi: f32,
    sin_c0: f32,
    sin_c1: f32,
    sin_c2: f32,
    sin_c3: f32,
    sin_c4: f32,
    end_slack: f32,          // the end time counts as reached within this fraction of it
    end_steps: f32,          // the approach to the end: equal steps within this many
    end_stretch: f32,        // and up to this factor over the limits
}

// Offsets, sizes and strides follow WGSL's layout rules (encase computes the same
// on the Rust side); @align(16) states the uniform address space's constraint on a
// member after a struct of 4-byte members (Kernel, Surfaces), as params.rs does.
struct Params {
    sizes: Sizes,
    grid: Grid,
    kernel: Kernel,
    @align(16) time_step: TimeStep,
    flow: Flow,
    surfaces: Surfaces,
    @align(16) tension: Tension,
    laser: Laser,
    bodies: Bodies,
    solve: Solve,
    phases: array<Phase, 8>,
    consts: Consts,
}

struct Sim {
    dt: f32,
    time: f32,
    step: u32,
    dt_limit: u32,
    umax2: f32,
    amax2: f32,
    removed: u32,            // particles taken out, sorted last
    end_time: f32,           // the run's end (0: none); the last steps land on it
}

// One solver's state in this step: twin of src/state.rs `Solver`, one per slot
// of backend::schedule::SOLVER_SLOTS (SOLVER_* below).
struct Solver {
    iterations: u32,         // iterations run since the repeat began
    converged: u32,          // 1: the residual fell to the tolerance; the loop's kernels return
    residual: f32,           // the last iteration's residual
    capped: u32,             // steps ended at the bound unconverged (kept by the reset)
    scalars: vec4<f32>,      // a solver's own scalars (conjugate gradients: r.z, r0.r0, alpha, beta)
}

// The begin stage's reset of a solver's slot (twin of Solver::reset).
fn solver_reset(s: Solver) -> Solver {
    return Solver(0u, 0u, 0.0, s.capped, vec4<f32>(0.0));
}

// One iteration's end (twin of Solver::finish): count, residual, converged
// flag; a step ended at the bound unconverged counts as capped.
fn solver_finish(s: Solver, residual: f32, converged: bool, max_iterations: u32) -> Solver {
    var t = s;
    t.iterations = t.iterations + 1u;
    t.residual = residual;
    t.converged = select(0u, 1u, converged);
    if (!converged && t.iterations >= max_iterations) {
        t.capped = t.capped + 1u;
    }
    return t;
}

// One rigid body: twin of src/state.rs `Body` (world frame, grid-relative).
struct Body {
    x: vec4<f32>,            // centre of mass, w: mass
    q: vec4<f32>,            // orientation quaternion (x, y, z, w), body -> world
    v: vec4<f32>,            // velocity of the centre of mass
    l: vec4<f32>,            // angular momentum about the centre of mass
    inertia: vec4<f32>,      // principal moments; w: one particle's own, per unit mass
    force: vec4<f32>,        // sum of member forces (contact, fluid)
    torque: vec4<f32>,       // sum of (x_r - x_k) x f_r
    first: u32,              // members[first .. first + count] (melted ones dropped)
    count: u32,
    bonded: u32,             // 0 free, BODY_BONDED, or BODY_LEFT (left the domain)
    initial_count: u32,      // members at the start
}

const FLAG_PRESSURE_FLOOR: u32 = 8u;
const FLAG_VISCOUS_HEATING: u32 = 16u;
const FLAG_HEAT: u32 = 32u;
const FLAG_INTERFACE: u32 = 64u;
const FLAG_GAS_INTERFACE: u32 = 128u;
const FLAG_SURFACE_TENSION: u32 = 256u;
const FLAG_RECOIL: u32 = 512u;
const FLAG_FREE_SURFACE_TENSION: u32 = 1024u;
const FLAG_WETTING: u32 = 2048u;
const FLAG_BODIES: u32 = 4096u;
const FLAG_CONTINUITY: u32 = 8192u;
const FLAG_MARRONE_VISCOSITY: u32 = 16384u;
const FLAG_RAW_DENSITY_DIFFUSION: u32 = 32768u;
const FLAG_SOLIDIFICATION: u32 = 65536u;
const FLAG_DFSPH: u32 = 131072u;
const FLAG_COLOUR_TENSION: u32 = 262144u;
const FLAG_CONDUCTIVITY_TABLE: u32 = 524288u;
const NO_BODY: u32 = 4294967295u;
// body[id] of a particle that solidified in this step, until body_bond.
const BODY_SOLIDIFIED: u32 = 4294967294u;
const NO_PHASE: u32 = 4294967295u;
const KIND_LIQUID: u32 = 0u;
const KIND_GAS: u32 = 1u;
const KIND_WALL: u32 = 2u;
const KIND_SOLID: u32 = 3u;
const HEAT_DIRICHLET: u32 = 1u;
const HEAT_MELTS: u32 = 2u;
const HEAT_LIQUID: u32 = 4u;
const HEAT_SWITCH_SHIFT: u32 = 8u;
const PHASE_FREE_SLIP: u32 = 4096u;
const PHASE_MOVES: u32 = 8192u;
const PHASE_RECOIL: u32 = 16384u;
const PHASE_DENSITY_LAW: u32 = 32768u;
const PHASE_PROGRAM: u32 = 65536u;
const LASER_BEER_LAMBERT: u32 = 1u;
const LASER_SURFACE: u32 = 2u;
const LASER_RAY_TRACED: u32 = 3u;
const PROFILE_GAUSSIAN: u32 = 0u;
const PROFILE_TOP_HAT: u32 = 1u;
const HEAT_EULER: u32 = 0u;
const HEAT_TRAPEZOIDAL: u32 = 1u;
const SOLVER_HEAT: u32 = 0u;
const SOLVER_DENSITY: u32 = 1u;
const SOLVER_DIVERGENCE: u32 = 2u;
const SOLVER_VISCOSITY: u32 = 3u;
// Slots of the packed per-particle vectors (src/state.rs, same names): heat[i]
// is (h, T, f_l, dh/dt); surface[i] is (normal xyz, delta) and surface[n + i]
// (Shepard sum, curvature, raw curvature, -).
const H_ENTHALPY: u32 = 0u;
const H_TEMPERATURE: u32 = 1u;
const H_LIQUID: u32 = 2u;
const H_RATE: u32 = 3u;
const S_DELTA: u32 = 3u;
const S_SHEPARD: u32 = 0u;
const S_CURVATURE: u32 = 1u;
const S_RAW_CURVATURE: u32 = 2u;
const S_THIN: u32 = 3u;
const S_COLOUR: u32 = 2u;
// The free-surface form's tension skips particles whose Shepard sum reads a full
// support and whose delta is below P.surfaces.interior_delta (src/state.rs).
const INTERIOR_SHEPARD: f32 = 0.95;
// Body.bonded: bonded into the substrate; the centre left through an open side.
const BODY_BONDED: u32 = 1u;
const BODY_LEFT: u32 = 2u;
// solidification[id] is (time, G, cooling rate, crossings), solidification[n + id]
// (position xyz, gradient pending): the last liquidus crossing on cooling.
const SOL_TIME: u32 = 0u;
const SOL_GRADIENT: u32 = 1u;
const SOL_COOLING: u32 = 2u;
const SOL_COUNT: u32 = 3u;
const SOL_PENDING: u32 = 3u;
// Time-step limit codes (sim.dt_limit; src/model/limits.rs).
const DT_ACOUSTIC: u32 = 0u;
const DT_VISCOUS: u32 = 1u;
const DT_FORCE: u32 = 2u;
const DT_FIXED: u32 = 3u;
const DT_CONDUCTION: u32 = 4u;
const DT_BARRIER: u32 = 5u;
const DT_CAPILLARY: u32 = 6u;
const DT_CONTACT: u32 = 7u;
const DT_MAXIMUM: u32 = 8u;
const DT_END: u32 = 9u;
const WG: u32 = 64u;
