// The parameter block and the Sim block (twin of src/params.rs, src/state.rs).
// Bit-match rules (DESIGN.md): same operation order as the Rust twin, no fma, no
// built-in transcendentals, explicit x*x+y*y+z*z.

struct Params {
    counts: vec4<u32>,       // n, n_cells, dim, kernel
    grid: vec4<u32>,         // nx, ny, nz, flags
    cell_inv: vec4<f32>,
    period: vec4<f32>,
    half_period: vec4<f32>,
    kern: vec4<f32>,         // h, 1/h, sigma, support²
    gravity: vec4<f32>,      // g, background pressure
    dtp: vec4<f32>,          // h, c_max, viscous limit, fixed dt
    phase_a: array<vec4<f32>, 8>, // rho0, c², eta, kind
    phase_b: array<vec4<f32>, 8>, // wall velocity, slip
    phase_c: array<vec4<f32>, 8>, // heat: k, c_p, h_solidus, h_liquidus
    phase_d: array<vec4<f32>, 8>, // heat: T_solidus, T_liquidus, L, flags
    phase_e: array<vec4<f32>, 8>, // evaporation: C_p, C_T, 1/T_v, h_v
    phase_f: array<vec4<f32>, 8>, // T_h0, C_M, 0.82 c_s, emissivity * sigma_B
    phase_g: array<vec4<f32>, 8>, // mushy-zone sink C (1/s), unused
    heat: vec4<f32>,              // conduction dt limit, eta², heat scene (1/0), unused
    laser: vec4<f32>,             // absorptivity, beam radius, absorption coefficient, model
    iface: vec4<f32>,             // interface pass: 1/kappa, T_ambient^4, F22 gas mode (1/0), alpha_0^lg
    laser_grid: vec4<f32>,        // bin size, peak irradiance per watt, bin volume, column area
    laser_bins: vec4<u32>,        // bins per axis, path points + 256 * power steps
    laser_lo: vec4<f32>,          // bin grid lower corner (grid-relative)
    laser_path: array<vec4<f32>, 8>,  // time, lateral beam centre
    laser_power: array<vec4<f32>, 8>, // time, power from then on
    consts: array<vec4<f32>, 8>,  // arithmetic literals, see c_* below
    wall: vec4<f32>,              // wall pass: Shepard weight floor; moving wall phases (bit mask)
}

struct Sim {
    dt: f32,
    time: f32,
    step: u32,
    dt_limit: u32,
    umax2: f32,
    amax2: f32,
    pad0: u32,
    pad1: u32,
}

const FLAG_PRESSURE_FLOOR: u32 = 8u;
const FLAG_VISCOUS_HEATING: u32 = 16u;
const KIND_WALL: f32 = 2.0;
const KIND_SOLID: f32 = 3.0;
const HEAT_DIRICHLET: u32 = 1u;
const HEAT_MELTS: u32 = 2u;
const HEAT_LIQUID: u32 = 4u;
const WG: u32 = 64u;
