//! The f32 parameter block both backends read (DESIGN rule 6): computed once on the
//! host in f64 and rounded to f32, so the CPU twin and the WGSL pass see the same bits.
//!
//! Every member has a name, the same in Rust and in shaders/lib/params.wgsl;
//! tests/params_layout.rs holds the two layouts against each other through naga.
//! Booleans live as named bits in `sizes.flags` (scene-wide) and `Phase::flags`
//! (per phase); nothing is read by position.

use crate::gpu_layout::gpu_struct;
use crate::model::{Model, MAX_LASER_POINTS, MAX_PHASES};
use crate::scene::{KernelKind, PhaseKind, Slip};
use bytemuck::Zeroable;
use std::f64::consts::PI;

/// `sizes.flags`: axis a is periodic when bit a is set.
pub const FLAG_PERIODIC_X: u32 = 1;
pub const FLAG_PERIODIC_Y: u32 = 2;
pub const FLAG_PERIODIC_Z: u32 = 4;
/// The equation of state clamps negative pressure to 0.
pub const FLAG_PRESSURE_FLOOR: u32 = 8;
/// Forces pass writes the viscous dissipation (W/kg) into acc.w; heat adds it.
pub const FLAG_VISCOUS_HEATING: u32 = 16;
/// The scene carries temperature (heat passes run).
pub const FLAG_HEAT: u32 = 32;
/// The scene needs interface normals and surface deltas (interface pass).
pub const FLAG_INTERFACE: u32 = 64;
/// F22's gas-interface form (19)–(20): the scene has gas particles beside the
/// condensed phase, so no Shepard sums are needed.
pub const FLAG_GAS_INTERFACE: u32 = 128;
/// F22 (24)–(26) surface tension between `tension.liquid` and `tension.gas`.
pub const FLAG_SURFACE_TENSION: u32 = 256;
/// Some phase takes the F22 (30) recoil pressure (PHASE_RECOIL).
pub const FLAG_RECOIL: u32 = 512;
/// Surface tension in the free-surface form (R18 §3.1.1–3.1.2, no gas particles):
/// the curvature is capped and smoothed (`tension_smooth`); `tension.gas` is
/// `NO_PHASE`.
pub const FLAG_FREE_SURFACE_TENSION: u32 = 1024;
/// Wetting by a prescribed normal near walls and solids, F22 (27)–(29)
/// (`tension.cos_contact`, `tension.sin_contact`).
pub const FLAG_WETTING: u32 = 2048;
/// The scene has rigid bodies (`bodies`): the body passes run and the body
/// fields exist.
pub const FLAG_BODIES: u32 = 4096;
/// δ-SPH (R18): the density is continuity state (`continuity` pass, sorted).
pub const FLAG_CONTINUITY: u32 = 8192;
/// δ-SPH with R18 (3.18)'s viscous term (`simulation.viscosity_form = "marrone"`).
pub const FLAG_MARRONE_VISCOSITY: u32 = 16384;
/// δ-SPH with the density diffusion on the raw ρ across phases
/// (`simulation.density_diffusion = "raw"`, R18 Test 4's incompatible variant).
pub const FLAG_RAW_DENSITY_DIFFUSION: u32 = 32768;
/// A phase melts (and the scene has heat): the temperature pass records each
/// particle's liquidus crossing on cooling and the `solidification_gradient`
/// dispatch its |∇T| (`State::solidification`).
pub const FLAG_SOLIDIFICATION: u32 = 65536;
/// Divergence-free SPH: its warm-start store is sorted with the particles.
pub const FLAG_DFSPH: u32 = 131072;
/// Free-surface tension by J22 (5)-(8)'s colour Laplacian (`model = "muller"`):
/// the `tension_colour` and `tension_laplacian` dispatches replace R18's CSF pair.
pub const FLAG_COLOUR_TENSION: u32 = 262144;
/// Some phase has a `conductivity_table`: the conduction's per-pair λ looks it
/// up (a scene-wide flag, so that other scenes' pair loops skip the test).
pub const FLAG_CONDUCTIVITY_TABLE: u32 = 524288;
/// A phase index that names no phase (`tension.gas` of the free-surface form).
pub const NO_PHASE: u32 = u32::MAX;

/// `Phase::kind`.
pub const KIND_LIQUID: u32 = 0;
pub const KIND_GAS: u32 = 1;
pub const KIND_WALL: u32 = 2;
pub const KIND_SOLID: u32 = 3;

/// `Phase::flags` bits.
pub const HEAT_DIRICHLET: u32 = 1;
pub const HEAT_MELTS: u32 = 2;
pub const HEAT_LIQUID: u32 = 4;
/// Bits 8..11: 1 + the phase this one switches to on melting or solidifying (0: none).
pub const HEAT_SWITCH_SHIFT: u32 = 8;
/// A wall phase with free slip (no viscous term against it).
pub const PHASE_FREE_SLIP: u32 = 1 << 12;
/// A wall phase whose particles drift with its velocity.
pub const PHASE_MOVES: u32 = 1 << 13;
/// A liquid phase that takes the F22 (30) recoil pressure at its surface.
pub const PHASE_RECOIL: u32 = 1 << 14;
/// A fluid phase whose reference density follows the temperature (δ-SPH).
pub const PHASE_DENSITY_LAW: u32 = 1 << 15;
/// A phase whose temperature follows its program instead of the heat equation.
pub const PHASE_PROGRAM: u32 = 1 << 16;

/// `Laser::model` codes (0: no laser).
pub const LASER_BEER_LAMBERT: u32 = 1;
pub const LASER_SURFACE: u32 = 2;
pub const LASER_RAY_TRACED: u32 = 3;
/// `Laser::profile` codes (ray-traced model).
pub const PROFILE_GAUSSIAN: u32 = 0;
pub const PROFILE_TOP_HAT: u32 = 1;
/// Fixed-point units in the largest beam power of the schedule (2^31): ray
/// powers are u32 counts, so the absorbed power of a bin is an integer sum,
/// the same in any thread order, and every ray's split into absorbed and
/// leaving power is exact.
pub const RAY_UNITS_PER_PEAK: f64 = 2_147_483_648.0;

gpu_struct! {
    /// Counts and scene-wide flags.
    pub struct Sizes {
        pub n_particles: u32,
        pub n_cells: u32,
        pub dim: u32,
        /// FLAG_* bits.
        pub flags: u32,
    }
}

gpu_struct! {
    /// The cell grid (grid-relative coordinates: the domain's lower corner is 0).
    pub struct Grid {
        /// Cells along x, y, z (w unused).
        pub cells: glam::UVec4,
        /// 1 / cell size per axis.
        pub cell_inv: glam::Vec4,
        /// Period length per axis (0 where not periodic).
        pub period: glam::Vec4,
        /// Half the period per axis, for the minimum-image test.
        pub half_period: glam::Vec4,
        /// A particle below `keep_lo` or above `keep_hi` on an axis has left the
        /// simulation: at an open face, or (wall_layers + 1) Δx behind a
        /// walled one, the edge of the padded box; ±f32::MAX on periodic and
        /// absent axes.
        pub keep_lo: glam::Vec4,
        pub keep_hi: glam::Vec4,
    }
}

gpu_struct! {
    /// The smoothing kernel.
    pub struct Kernel {
        /// 0 quintic, 1 Wendland C2, 2 cubic spline (`KernelKind::code`).
        pub kind: u32,
        pub h: f32,
        pub inv_h: f32,
        /// Normalisation σ (∫W = 1).
        pub sigma: f32,
        /// Support radius squared.
        pub support2: f32,
        /// η² = 0.01 h², the Cleary–Monaghan regularisation of 1/r² terms.
        pub eta2: f32,
    }
}

gpu_struct! {
    /// The time-step limits F22 (42) (f32::MAX where a limit does not apply).
    pub struct TimeStep {
        /// Largest reference sound speed of the fluid phases.
        pub max_sound_speed: f32,
        /// 0.125 h²/ν.
        pub viscous_limit: f32,
        /// 0.1 ρ c_p h²/k.
        pub conduction_limit: f32,
        /// A fixed Δt (0: adaptive).
        pub fixed_dt: f32,
        /// 0.22 √(m/k_b), the barrier force's limit.
        pub barrier_limit: f32,
        /// 0.25 √(ρ h³/(2π α)), the capillary limit.
        pub capillary_limit: f32,
        /// 0.22 √(m/k_c), the body contact limit (F22 (42)).
        pub contact_limit: f32,
        /// `run.max_dt` (f32::MAX without it).
        pub maximum_limit: f32,
    }
}

gpu_struct! {
    /// Body force, transport velocity, interface viscosity and the wall pass.
    pub struct Flow {
        /// Gravity xyz (w unused).
        pub gravity: glam::Vec4,
        /// Transport-velocity background pressure p_b (Adami 2013).
        pub background_pressure: f32,
        /// F22 (32) interface viscosity α_0^lg (0 = off).
        pub interface_viscosity: f32,
        /// Wall pass: Shepard weight floor ε (`WALL_WEIGHT_FLOOR` × W(0)).
        pub wall_weight_floor: f32,
        /// F22 (34) barrier between fluid and walls: r_b (m; 0 = off), k_b, d_b.
        pub barrier_radius: f32,
        pub barrier_stiffness: f32,
        pub barrier_damping: f32,
        /// F22 (33) solid–fluid viscosity α_0^sf (0 = off) and 1/ΔT_d.
        pub solid_fluid_viscosity: f32,
        pub solid_fluid_inv_width: f32,
    }
}

gpu_struct! {
    /// Interface pass (normals and surface delta).
    pub struct Surfaces {
        /// 1/κ, the normalisation of the surface delta (κ = Σ δ V per unit area
        /// across a planar lattice surface, `surface_delta_integral` or
        /// `gas_delta_integral`).
        pub inv_kappa: f32,
        /// T_ambient⁴ for radiation.
        pub ambient_t4: f32,
        /// The free-surface CSF skips a particle with a full support whose δ is
        /// below this: `state::INTERIOR_GRADIENT` inv_kappa inv_h (|g| h <
        /// INTERIOR_GRADIENT) where `Model::csf_skips_interior`, 0 (skips none)
        /// elsewhere.
        pub interior_delta: f32,
    }
}

gpu_struct! {
    /// Surface tension F22 (24)–(26), (8), (21) between one liquid and one gas
    /// phase (FLAG_SURFACE_TENSION).
    pub struct Tension {
        /// α0, α0', T_α0, α_min of F22 (8).
        pub alpha0: f32,
        pub alpha_slope: f32,
        pub t_ref: f32,
        pub alpha_min: f32,
        /// F22 (21) ramp f[T, T_m, T_m + ΔT_s]: T_m and 1/ΔT_s (0: no ramp, f = 1).
        pub t_melt: f32,
        pub inv_ramp_width: f32,
        pub liquid: u32,
        /// NO_PHASE in the free-surface form.
        pub gas: u32,
        /// Free-surface form: |κ| ≤ 1/support (R18's cap 1/(2h) of Wendland); 0 otherwise.
        pub kappa_max: f32,
        /// R18 (4.2)'s solute term (model::tension::Sahoo; all 0 without it):
        /// RΓ, k_l a_s, −ΔH0/R, ΓΔH0.
        pub sahoo_r_gamma: f32,
        pub sahoo_k_a: f32,
        pub sahoo_q: f32,
        pub sahoo_gamma_h: f32,
        /// R18 §4.4: a free-surface particle with no liquid particle at least
        /// this deep along −n is on a thin layer and gets no tension
        /// ((rows − ½) Δx; 0: off).
        pub thin_layer_depth: f32,
    }
}

gpu_struct! {
    /// One point of the scan path.
    pub struct PathPoint {
        /// Aligned to 16, so the array's stride is the 16 bytes the uniform
        /// address space asks of an array.
        #[shader(align(16))]
        pub time: f32,
        /// Lateral beam centre, grid-relative (y is 0 in 2D).
        pub x: f32,
        pub y: f32,
    }
}

gpu_struct! {
    /// One step of the power schedule: `power` from `time` on.
    pub struct PowerStep {
        /// Aligned to 16: the uniform array stride, as in `PathPoint`.
        #[shader(align(16))]
        pub time: f32,
        pub power: f32,
    }
}

gpu_struct! {
    /// The laser: beam, absorption bins and schedule.
    pub struct Laser {
        /// Absorptivity ζ.
        pub absorptivity: f32,
        /// Beam radius r_w.
        pub radius: f32,
        /// Absorption coefficient a (Beer–Lambert).
        pub absorption: f32,
        /// 0 none, LASER_BEER_LAMBERT, LASER_SURFACE, LASER_RAY_TRACED.
        pub model: u32,
        /// Bin size (= Δx).
        pub bin_size: f32,
        /// Peak irradiance per watt: 2/(π r_w²) in 3D, √(2/π)/r_w in 2D.
        pub peak_per_watt: f32,
        /// Bin volume Δx^d.
        pub bin_volume: f32,
        /// Column cross-section Δx^(d−1).
        pub column_area: f32,
        /// Bins per axis (1 beyond the dimension; w unused).
        pub bins: glam::UVec4,
        /// Lower corner of the bin grid, grid-relative.
        pub lo: glam::Vec4,
        pub path_points: u32,
        pub power_steps: u32,
        /// Ray-traced model: rays per lateral axis (odd, centred on the beam).
        pub rays_per_side: u32,
        /// Lateral spacing of the rays (Δx / rays_per_dx).
        pub ray_spacing: f32,
        /// 1 / Σ g over the bundle (g: the profile at each ray), so the rays
        /// carry the whole beam power.
        pub ray_norm: f32,
        /// Surface hits a ray may make.
        pub max_bounces: u32,
        /// Watts per fixed-point unit (largest scheduled power / 2^31).
        pub power_unit: f32,
        /// PROFILE_GAUSSIAN, PROFILE_TOP_HAT.
        pub profile: u32,
        /// March step along a ray (Δx / 4).
        pub march_step: f32,
        /// Steps a ray may march between two hits (the bin box's diagonal over
        /// the step, and one).
        pub march_steps: u32,
        /// The arrays' own align(16) is what their 16-aligned elements imply by
        /// WGSL's rules (encase follows them); naga 30 takes a struct's alignment
        /// from its members' types and not their `@align`, so without it naga
        /// (and so the GPU) would start `path` at 72, encase at 80.
        #[shader(align(16))]
        pub path: [PathPoint; MAX_LASER_POINTS],
        #[shader(align(16))]
        pub power: [PowerStep; MAX_LASER_POINTS],
    }
}

gpu_struct! {
    /// One phase's material.
    pub struct Phase {
        /// Reference density ρ0.
        pub rho0: f32,
        /// Sound speed squared c².
        pub c2: f32,
        /// Dynamic viscosity η.
        pub eta: f32,
        /// KIND_LIQUID, KIND_GAS, KIND_WALL or KIND_SOLID.
        pub kind: u32,
        /// Wall velocity xyz (w unused).
        pub velocity: glam::Vec4,
        /// Solid conductivity k_s.
        pub conductivity: f32,
        /// Solid heat capacity c_s.
        pub heat_capacity: f32,
        /// T_ref: particles store h − h(T_ref) (`Thermal::reference_temperature`).
        pub reference_temperature: f32,
        /// Band enthalpy h(T_l) − h(T_s) of a melting material.
        pub band_enthalpy: f32,
        /// Solidus T_s.
        pub solidus: f32,
        /// Liquidus T_l.
        pub liquidus: f32,
        /// b = c_s + L/(T_l − T_s).
        pub band_capacity: f32,
        /// HEAT_*, PHASE_* bits.
        pub flags: u32,
        /// Mushy-zone sink C (1/s, liquids).
        pub mushy_damping: f32,
        /// Liquid conductivity k_l.
        pub liquid_conductivity: f32,
        /// Liquid heat capacity c_l.
        pub liquid_heat_capacity: f32,
        /// a = (c_l − c_s)/(2 (T_l − T_s)) (0 without melting).
        pub capacity_slope: f32,
        /// Evaporation (all 0 without it): C_p (Pa).
        pub evap_pressure: f32,
        /// C_T (K).
        pub evap_temperature: f32,
        /// 1/T_v (1/K).
        pub inv_boiling_temperature: f32,
        /// h_v (J/kg).
        pub evap_latent_heat: f32,
        /// T_h0 (K).
        pub evap_enthalpy_reference: f32,
        /// C_M.
        pub vapor_constant: f32,
        /// 0.82 c_s (recondensation).
        pub recondensation: f32,
        /// ε σ_B (radiation).
        pub emissivity_sb: f32,
        /// cos θ0, sin θ0 of the liquid's static contact angle on this wall or
        /// solid phase (FLAG_WETTING; F22 (27)). (A Dirichlet wall particle's
        /// fixed temperature is its own, in heat.x.)
        pub contact_cos: f32,
        pub contact_sin: f32,
        /// Thermal expansion (PHASE_DENSITY_LAW, δ-SPH): the density law's
        /// point count; point k is density[k / 4]'s component k % 4.
        pub density_points: u32,
        /// PHASE_PROGRAM: T(t) = reference + (A + Ȧ t) sin(2π f t) + Ṫ min(t,
        /// t_end), the reference being the phase's initial temperature.
        pub program_temperature: f32,
        pub program_amplitude: f32,
        pub program_amplitude_rate: f32,
        pub program_frequency: f32,
        pub program_rate: f32,
        pub program_until: f32,
        /// DFSPH's implicit viscosity (backend/cpu/dfsph_viscosity.rs): the
        /// dynamic viscosity μ it solves with; `eta` is then 0 (the forces
        /// pass has no explicit viscous term and the time step no viscous limit).
        pub implicit_eta: f32,
        /// `enthalpy_table` (0: none): point k is enthalpy[k / 4]'s component
        /// k % 4, its value h_k − h(T_ref) and the slope to the next point (the
        /// last: the last segment's, continued).
        pub enthalpy_points: u32,
        /// `conductivity_table` (0: none): λ_k and the slope to the next point
        /// (the last: 0, held).
        pub conductivity_points: u32,
        /// Ray-traced laser: the complex refractive index (n, k) of an
        /// absorbing phase at the laser's wavelength (0 elsewhere).
        pub optical_n: f32,
        pub optical_k: f32,
        pub density: [LawPoints; 2],
        pub enthalpy: [LawPoints; 2],
        pub conductivity_law: [LawPoints; 2],
    }
}

gpu_struct! {
    /// Four points of a phase's piecewise-linear law y(T): the density law ρ0(T)
    /// (model::expansion::DensityLaw), the enthalpy h(T), the conductivity λ(T):
    /// y = value[k] + slope[k] (T − temperature[k]) from point k to the next.
    pub struct LawPoints {
        pub temperature: glam::Vec4,
        pub value: glam::Vec4,
        pub slope: glam::Vec4,
    }
}

/// The segment of a piecewise-linear law (`n` points in two `LawPoints` rows)
/// that `x` lies on: the last point k ≥ 1 whose `key` (its temperatures, or
/// for the enthalpy's inverse its values) x reaches, else 0; as (row, component).
/// The WGSL twins write the same loop inline (uniform arrays are not passed).
#[inline(always)]
pub fn law_segment(
    law: &[LawPoints; 2],
    n: u32,
    x: f32,
    key: impl Fn(&LawPoints) -> glam::Vec4,
) -> (&LawPoints, usize) {
    let mut k = 0usize;
    for i in 1..n as usize {
        if x >= key(&law[i / 4])[i % 4] {
            k = i;
        }
    }
    (&law[k / 4], k % 4)
}

/// y(t) on a law by temperature: value + slope (t − T) on t's segment.
#[inline(always)]
pub fn law_at(law: &[LawPoints; 2], n: u32, t: f32) -> f32 {
    let (row, c) = law_segment(law, n, t, |r| r.temperature);
    row.value[c] + row.slope[c] * (t - row.temperature[c])
}

gpu_struct! {
    /// Rigid bodies and their contact F22 (39)–(40) (FLAG_BODIES).
    pub struct Bodies {
        pub n_bodies: u32,
        /// k_c.
        pub contact_stiffness: f32,
        /// d_c.
        pub contact_damping: f32,
        /// Contact acts below this distance: Δx (F22 (40)).
        pub contact_distance: f32,
    }
}

gpu_struct! {
    /// The formulation and its solvers (backend::schedule).
    pub struct Solve {
        /// `Formulation::code`.
        pub formulation: u32,
        /// HEAT_EULER or HEAT_TRAPEZOIDAL.
        pub heat_integrator: u32,
        /// Trapezoidal rule: converged when max|h^{k+1} − h^k| ≤ this × max|h^{k+1} − h^n|.
        pub heat_tolerance: f32,
        /// Trapezoidal rule: the repeat's bound.
        pub heat_max_iterations: u32,
        /// δ-SPH: δ h c0 of the density diffusion R18 (3.53) (c0 the largest
        /// sound speed).
        pub delta_hc: f32,
        /// δ-SPH: 2 (d + 2) of the Monaghan–Marrone viscosity R18 (3.18).
        pub viscosity_factor: f32,
        /// DFSPH: the density solve stops at this mean (ρ* − ρ0)/ρ0.
        pub dfsph_density_tolerance: f32,
        /// DFSPH: the divergence solve stops at this mean Δt Dρ/Dt / ρ0.
        pub dfsph_divergence_tolerance: f32,
        /// DFSPH: each solve's bound.
        pub dfsph_max_iterations: u32,
        /// DFSPH implicit viscosity: CG stops at |r| ≤ this × |r0|.
        pub dfsph_viscosity_tolerance: f32,
        /// DFSPH implicit viscosity: the CG repeat's bound.
        pub dfsph_viscosity_max_iterations: u32,
        /// DFSPH: J22 (14)'s XSPH factor α, solved with the viscosity.
        pub dfsph_xsph: f32,
        /// 0.01 h², Weiler et al. (2018)'s regularisation of 1/r².
        pub dfsph_viscosity_eps: f32,
        /// The implicit viscosity's form: 0 F22 (23) (Morris), 1 Weiler et
        /// al. (2018) / R18 (3.18) (`viscosity_form = "marrone"`).
        pub dfsph_viscosity_form: u32,
        /// J22 (15) γ^f and (16) γ^b (1/s², per unit mass), on the CG's
        /// right side; 0: off.
        pub dfsph_cohesion: f32,
        pub dfsph_adhesion: f32,
        /// DFSPH: a fluid particle with fewer neighbours than this (a quarter
        /// of the lattice's, `lattice_neighbours`) takes no part in the
        /// divergence solve: its error is 0 (spray; see shaders/dfsph.wgsl).
        pub dfsph_min_neighbours: u32,
    }
}

/// `solve.heat_integrator` codes.
pub const HEAT_EULER: u32 = 0;
pub const HEAT_TRAPEZOIDAL: u32 = 1;

gpu_struct! {
    /// Arithmetic literals for the shaders (`SHADER_CONSTS`). lavapipe's compiler
    /// reassociates a product with a literal constant (measured: `6.0 * (a * a)`
    /// differs from Rust in 10% of inputs, the same 6.0 from a buffer never), so
    /// shaders read every multiplying or adding literal from here.
    pub struct Consts {
        pub half: f32,
        pub quarter: f32,
        pub two: f32,
        pub one: f32,
        pub three: f32,
        pub six: f32,
        pub fifteen: f32,
        pub five: f32,
        pub thirty: f32,
        pub seventy_five: f32,
        pub one_and_half: f32,
        pub three_quarters: f32,
        pub nine_quarters: f32,
        pub log2e: f32,
        pub ln2_hi: f32,
        pub ln2_lo: f32,
        pub exp_c0: f32,
        pub exp_c1: f32,
        pub exp_c2: f32,
        pub exp_c3: f32,
        pub exp_c4: f32,
        pub exp_c5: f32,
        pub ln_c0: f32,
        pub ln_c1: f32,
        pub ln_c2: f32,
        pub ln_c3: f32,
        pub ln_c4: f32,
        pub four: f32,
        pub tenth: f32,
        /// The rigid bodies' Jacobi rotations leave an off-diagonal entry at or
        /// below this fraction of its diagonal pair (f32 rounding).
        pub jacobi_floor: f32,
        /// Portable sin (portable_math::sin_cycles): 2π and the odd Taylor
        /// coefficients −1/3!, 1/5!, …, −1/11!.
        pub two_pi: f32,
        pub sin_c0: f32,
        pub sin_c1: f32,
        pub sin_c2: f32,
        pub sin_c3: f32,
        pub sin_c4: f32,
        /// The timestep pass counts the end time as reached when less than this
        /// fraction of it remains (f32 time's rounding, a few ulps).
        pub end_slack: f32,
        /// model::limits::END_STEPS and END_STRETCH: the approach to the end.
        pub end_steps: f32,
        pub end_stretch: f32,
    }
}

gpu_struct! {
    /// The whole block, bound as `P` in every pass. encase places each member
    /// by WGSL's rules; the uniform address space also wants a struct member at
    /// a multiple of 16 and at least its predecessor's size rounded up to 16
    /// past it, which the members after the structs of only 4-byte members
    /// (`kernel`, `surfaces`) state as `align(16)`, as the WGSL does (encase
    /// checks it on every write). The others follow a struct with a vec4 (its
    /// alignment is 16) or one whose size is a multiple of 16 (`sizes`,
    /// `bodies`).
    pub struct Params {
        pub sizes: Sizes,
        pub grid: Grid,
        pub kernel: Kernel,
        #[shader(align(16))]
        pub time_step: TimeStep,
        pub flow: Flow,
        pub surfaces: Surfaces,
        #[shader(align(16))]
        pub tension: Tension,
        pub laser: Laser,
        pub bodies: Bodies,
        pub solve: Solve,
        pub phases: [Phase; MAX_PHASES],
        pub consts: Consts,
    }
}

/// The wall pass divides by Σ W + ε with ε this fraction of W(0) (src/backend/cpu/wall.rs).
pub const WALL_WEIGHT_FLOOR: f64 = 1e-9;

/// The values of `Consts`; src/portable_math.rs uses the same f32 values.
pub const SHADER_CONSTS: Consts = {
    use crate::portable_math as pm;
    Consts {
        half: 0.5,
        quarter: 0.25,
        two: 2.0,
        one: 1.0,
        three: 3.0,
        six: 6.0,
        fifteen: 15.0,
        five: 5.0,
        thirty: 30.0,
        seventy_five: 75.0,
        one_and_half: 1.5,
        three_quarters: 0.75,
        nine_quarters: 2.25,
        log2e: pm::LOG2E,
        ln2_hi: pm::LN2_HI,
        ln2_lo: pm::LN2_LO,
        exp_c0: pm::EXP_C[0],
        exp_c1: pm::EXP_C[1],
        exp_c2: pm::EXP_C[2],
        exp_c3: pm::EXP_C[3],
        exp_c4: pm::EXP_C[4],
        exp_c5: pm::EXP_C[5],
        ln_c0: pm::LN_C[0],
        ln_c1: pm::LN_C[1],
        ln_c2: pm::LN_C[2],
        ln_c3: pm::LN_C[3],
        ln_c4: pm::LN_C[4],
        four: 4.0,
        tenth: 0.1,
        jacobi_floor: 1e-7,
        two_pi: std::f32::consts::TAU,
        sin_c0: pm::SIN_C[0],
        sin_c1: pm::SIN_C[1],
        sin_c2: pm::SIN_C[2],
        sin_c3: pm::SIN_C[3],
        sin_c4: pm::SIN_C[4],
        end_slack: crate::model::limits::END_SLACK,
        end_steps: crate::model::limits::END_STEPS,
        end_stretch: crate::model::limits::END_STRETCH,
    }
};

/// Kernel normalisation σ so that ∫W = 1 (Morris 1997 quintic, Wendland C2, cubic spline).
pub fn kernel_sigma(kind: KernelKind, dim: u32, h: f64) -> f64 {
    let hd = h.powi(dim as i32);
    let s = match (kind, dim) {
        (KernelKind::Quintic, 2) => 7.0 / (478.0 * PI),
        // ∫(a−q)⁵q²dq = a⁸/168 ⇒ 4π/168·(3⁸ − 6·2⁸ + 15) = 120π.
        (KernelKind::Quintic, _) => 1.0 / (120.0 * PI),
        (KernelKind::WendlandC2, 2) => 7.0 / (4.0 * PI),
        (KernelKind::WendlandC2, _) => 21.0 / (16.0 * PI),
        (KernelKind::Cubic, 2) => 10.0 / (7.0 * PI),
        (KernelKind::Cubic, _) => 1.0 / PI,
    };
    s / hd
}

impl Params {
    /// The block's bytes in the uniform layout (encase: WGSL's offsets, zero
    /// padding between members), as the passes bind it.
    pub fn uniform_bytes(&self) -> Vec<u8> {
        let mut buf = encase::UniformBuffer::new(Vec::<u8>::new());
        buf.write(self)
            .expect("the parameter block fits a growable buffer");
        buf.into_inner()
    }
    pub fn new(m: &Model, n_particles: u32) -> Params {
        let mut p = Params::zeroed();
        p.sizes = Sizes {
            n_particles,
            n_cells: m.n_cells() as u32,
            dim: m.dim,
            flags: scene_flags(m),
        };
        p.grid = grid_block(m);
        p.kernel = Kernel {
            kind: m.kernel.code(),
            h: m.h as f32,
            inv_h: (1.0 / m.h) as f32,
            sigma: kernel_sigma(m.kernel, m.dim, m.h) as f32,
            support2: (m.support * m.support) as f32,
            eta2: (0.01 * m.h * m.h) as f32,
        };
        p.time_step = TimeStep {
            max_sound_speed: m.max_sound_speed() as f32,
            viscous_limit: finite_or_max(m.limits.viscous),
            conduction_limit: finite_or_max(m.limits.conduction),
            fixed_dt: m.fixed_dt.unwrap_or(0.0) as f32,
            barrier_limit: finite_or_max(m.limits.barrier),
            capillary_limit: finite_or_max(m.limits.capillary),
            contact_limit: finite_or_max(m.limits.contact),
            maximum_limit: finite_or_max(m.limits.maximum),
        };
        p.flow = Flow {
            gravity: glam::Vec4::new(
                m.gravity[0] as f32,
                m.gravity[1] as f32,
                m.gravity[2] as f32,
                0.0,
            ),
            background_pressure: m.background_pressure as f32,
            interface_viscosity: 0.0,
            wall_weight_floor: 0.0,
            barrier_radius: m.barrier.map_or(0.0, |b| b.radius as f32),
            barrier_stiffness: m.barrier.map_or(0.0, |b| b.stiffness as f32),
            barrier_damping: m.barrier.map_or(0.0, |b| b.damping as f32),
            solid_fluid_viscosity: m.solid_fluid_viscosity.map_or(0.0, |s| s.0 as f32),
            solid_fluid_inv_width: m.solid_fluid_viscosity.map_or(0.0, |s| (1.0 / s.1) as f32),
        };
        for (i, ph) in m.phases.iter().enumerate() {
            p.phases[i] = phase_block(ph);
            if p.phases[i].conductivity_points > 0 {
                p.sizes.flags |= FLAG_CONDUCTIVITY_TABLE;
            }
            if m.implicit_viscosity() {
                p.phases[i].implicit_eta = p.phases[i].eta;
                p.phases[i].eta = 0.0;
            }
        }
        p.laser = laser_block(m);
        if let Some(r) = m.laser.as_ref().and_then(|l| l.rays.as_ref()) {
            for (i, nk) in r.optics.iter().enumerate() {
                if let Some((n, k)) = nk {
                    p.phases[i].optical_n = *n as f32;
                    p.phases[i].optical_k = *k as f32;
                }
            }
        }
        if let Some(c) = m.contact.filter(|_| m.has_bodies()) {
            p.sizes.flags |= FLAG_BODIES;
            p.bodies = Bodies {
                n_bodies: m.bodies.len() as u32,
                contact_stiffness: c.stiffness as f32,
                contact_damping: c.damping as f32,
                contact_distance: m.dx as f32,
            };
        }
        p.solve = Solve {
            formulation: m.formulation.code(),
            heat_integrator: match m.heat.integrator {
                crate::scene::HeatIntegrator::Euler => HEAT_EULER,
                crate::scene::HeatIntegrator::Trapezoidal => HEAT_TRAPEZOIDAL,
            },
            heat_tolerance: m.heat.tolerance as f32,
            heat_max_iterations: m.heat.max_iterations,
            delta_hc: m
                .delta
                .map_or(0.0, |d| (d * m.h * m.max_sound_speed()) as f32),
            viscosity_factor: (2.0 * (m.dim as f64 + 2.0)) as f32,
            dfsph_density_tolerance: m.dfsph.density_tolerance as f32,
            dfsph_divergence_tolerance: m.dfsph.divergence_tolerance as f32,
            dfsph_max_iterations: m.dfsph.max_iterations,
            dfsph_viscosity_tolerance: m.dfsph.viscosity_tolerance as f32,
            // 0: no implicit solve (backend::passes::Features::dfsph_viscosity).
            dfsph_viscosity_max_iterations: if m.implicit_viscosity() {
                m.dfsph.viscosity_max_iterations
            } else {
                0
            },
            dfsph_xsph: m.dfsph.xsph as f32,
            dfsph_viscosity_eps: (0.01 * m.h * m.h) as f32,
            dfsph_viscosity_form: (m.viscosity_form == crate::scene::ViscosityForm::Marrone) as u32,
            dfsph_cohesion: m.dfsph.cohesion as f32,
            dfsph_adhesion: m.dfsph.adhesion as f32,
            dfsph_min_neighbours: lattice_neighbours(m.dim, m.dx, m.support) / 4,
        };
        if m.delta.is_some() {
            p.sizes.flags |= FLAG_CONTINUITY;
        }
        if m.formulation == crate::scene::Formulation::Dfsph {
            p.sizes.flags |= FLAG_DFSPH;
        }
        if m.viscosity_form == crate::scene::ViscosityForm::Marrone && m.delta.is_some() {
            p.sizes.flags |= FLAG_MARRONE_VISCOSITY;
        }
        if m.density_diffusion == crate::scene::DensityDiffusion::Raw {
            p.sizes.flags |= FLAG_RAW_DENSITY_DIFFUSION;
        }
        p.consts = SHADER_CONSTS;
        if m.needs_interface() {
            let gas = m.phases.iter().find(|ph| ph.kind == PhaseKind::Gas);
            // The condensed side of F22's interface: a conducting liquid or solid,
            // or (interface viscosity without heat) the liquid.
            let tension_liquid = m.surface_tension.as_ref().map(|s| s.liquid);
            let condensed = m.phases.iter().enumerate().find(|(i, ph)| {
                matches!(ph.kind, PhaseKind::Liquid | PhaseKind::Solid)
                    && (ph.conducts() || m.interface_viscosity > 0.0 || tension_liquid == Some(*i))
            });
            let kappa = match (gas, condensed) {
                (Some(g), Some((_, c))) => {
                    p.sizes.flags |= FLAG_GAS_INTERFACE;
                    gas_delta_integral(&p, m.dx, c.rho0, g.rho0)
                }
                _ => surface_delta_integral(&p, m.dx),
            };
            p.surfaces.inv_kappa = (1.0 / kappa) as f32;
            if m.csf_skips_interior() {
                p.surfaces.interior_delta =
                    crate::state::INTERIOR_GRADIENT * p.surfaces.inv_kappa * p.kernel.inv_h;
            }
            p.surfaces.ambient_t4 = m.ambient_temperature.powi(4) as f32;
            p.flow.interface_viscosity = m.interface_viscosity as f32;
        }
        let recoil = (0..m.phases.len()).any(|i| p.phases[i].flags & PHASE_RECOIL != 0);
        if recoil && m.needs_interface() {
            p.sizes.flags |= FLAG_RECOIL;
        }
        if let Some(s) = &m.surface_tension {
            p.sizes.flags |= FLAG_SURFACE_TENSION;
            let t = &mut p.tension;
            t.alpha0 = s.coefficient as f32;
            t.alpha_slope = s.slope as f32;
            t.t_ref = s.reference_temperature as f32;
            t.alpha_min = s.minimum as f32;
            if let Some(sh) = s.sahoo {
                t.sahoo_r_gamma = sh.r_gamma as f32;
                t.sahoo_k_a = sh.k_a as f32;
                t.sahoo_q = sh.q as f32;
                t.sahoo_gamma_h = sh.gamma_h as f32;
            }
            if let Some((t_m, width)) = s.ramp {
                t.t_melt = t_m as f32;
                t.inv_ramp_width = (1.0 / width) as f32;
            }
            t.liquid = s.liquid as u32;
            if let Some(angles) = &s.contact_angle {
                p.sizes.flags |= FLAG_WETTING;
                for (k, theta) in angles.iter().enumerate() {
                    if let Some(theta) = theta {
                        p.phases[k].contact_cos = theta.cos() as f32;
                        p.phases[k].contact_sin = theta.sin() as f32;
                    }
                }
            }
            match s.gas {
                Some(g) => t.gas = g as u32,
                None => {
                    p.sizes.flags |= FLAG_FREE_SURFACE_TENSION;
                    if s.colour_laplacian {
                        p.sizes.flags |= FLAG_COLOUR_TENSION;
                    }
                    t.gas = NO_PHASE;
                    t.kappa_max = (1.0 / m.support) as f32;
                    if s.thin_layer_rows > 0 {
                        t.thin_layer_depth = ((s.thin_layer_rows as f64 - 0.5) * m.dx) as f32;
                    }
                }
            }
        }
        p.flow.wall_weight_floor = (WALL_WEIGHT_FLOOR * crate::kernel::w(&p, 0.0) as f64) as f32;
        p
    }
    pub fn n(&self) -> usize {
        self.sizes.n_particles as usize
    }
    pub fn flag(&self, bit: u32) -> bool {
        self.sizes.flags & bit != 0
    }
    /// Outside the box a particle must stay in: it has left. Twin of
    /// `outside_keep_box` in shaders/lib/grid.wgsl.
    #[inline(always)]
    pub fn outside_keep_box(&self, p: &[f32; 4]) -> bool {
        let (lo, hi) = (&self.grid.keep_lo, &self.grid.keep_hi);
        p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2]
    }
    /// Axis a is periodic.
    pub fn periodic(&self, a: usize) -> bool {
        self.sizes.flags & (FLAG_PERIODIC_X << a) != 0
    }
    pub fn phase(&self, phase: u32) -> &Phase {
        &self.phases[phase as usize]
    }
    /// The reference density at temperature t: the density law's ρ0(T)
    /// (PHASE_DENSITY_LAW), else ρ0. Twin of reference_density in
    /// shaders/lib/phase.wgsl (same operations).
    #[inline(always)]
    pub fn reference_density(&self, phase: u32, t: f32) -> f32 {
        let p = self.phase(phase);
        if p.flags & PHASE_DENSITY_LAW == 0 {
            return p.rho0;
        }
        law_at(&p.density, p.density_points, t)
    }
    /// The phase's temperature follows its program, not the heat equation.
    pub fn programmed(&self, phase: u32) -> bool {
        self.phase(phase).flags & PHASE_PROGRAM != 0
    }
    /// A PHASE_PROGRAM phase's temperature at time t. Twin of
    /// programmed_temperature in shaders/heat.wgsl.
    pub fn programmed_temperature(&self, phase: u32, time: f32) -> f32 {
        let p = self.phase(phase);
        let cycle = crate::portable_math::sin_cycles(p.program_frequency * time);
        p.program_temperature
            + (p.program_amplitude + p.program_amplitude_rate * time) * cycle
            + p.program_rate * time.min(p.program_until)
    }
    /// (α, dα/dT) of the surface-tension law at T: F22 (8) plus R18 (4.2)'s
    /// solute term (when `sahoo_r_gamma` > 0), clipped at α_min. Twin of
    /// tension_law in shaders/surface_forces.wgsl (portable exp and ln).
    #[inline(always)]
    pub fn tension_law(&self, t_i: f32) -> (f32, f32) {
        use crate::portable_math as pm;
        let t = &self.tension;
        let mut alpha = t.alpha0 + t.alpha_slope * (t_i - t.t_ref);
        let mut slope = t.alpha_slope;
        if t.sahoo_r_gamma > 0.0 {
            let ka = t.sahoo_k_a * pm::exp(t.sahoo_q / t_i);
            let l = pm::ln(1.0 + ka);
            alpha -= t.sahoo_r_gamma * t_i * l;
            slope = slope - t.sahoo_r_gamma * l - t.sahoo_gamma_h * ka / (t_i * (1.0 + ka));
        }
        if alpha <= t.alpha_min {
            (t.alpha_min, 0.0)
        } else {
            (alpha, slope)
        }
    }
    /// A wall for the fluid passes: wall or solid particles (they do not move).
    pub fn is_wall(&self, phase: u32) -> bool {
        self.phases[phase as usize].kind >= KIND_WALL
    }
    /// A wall phase whose particles move with its velocity.
    pub fn wall_moves(&self, phase: u32) -> bool {
        self.phases[phase as usize].flags & PHASE_MOVES != 0
    }
    /// Carries an evolving temperature (liquid, gas or solid in a heat scene).
    pub fn conducts(&self, phase: u32) -> bool {
        self.flag(FLAG_HEAT) && self.phases[phase as usize].kind != KIND_WALL
    }
    /// Particles the interface pass gives a normal and δ, in either form (F22's
    /// gas interface, or the free surface for condensed ones): conducting ones (for
    /// the surface fluxes) and, with surface tension or the interface viscosity on,
    /// every fluid one.
    pub fn gets_interface(&self, phase: u32) -> bool {
        self.conducts(phase)
            || ((self.flow.interface_viscosity > 0.0 || self.flag(FLAG_SURFACE_TENSION))
                && !self.is_wall(phase))
    }
    pub fn heat_flags(&self, phase: u32) -> u32 {
        self.phases[phase as usize].flags
    }
    /// The phase a particle of `phase` switches to on melting/solidifying.
    pub fn switch_target(&self, phase: u32) -> Option<u32> {
        let t = (self.heat_flags(phase) >> HEAT_SWITCH_SHIFT) & 15;
        (t > 0).then(|| t - 1)
    }
}

fn scene_flags(m: &Model) -> u32 {
    let mut flags = 0;
    for a in 0..3 {
        if m.periodic[a] {
            flags |= FLAG_PERIODIC_X << a;
        }
    }
    if m.pressure_floor {
        flags |= FLAG_PRESSURE_FLOOR;
    }
    if m.viscous_heating && m.is_thermal() {
        flags |= FLAG_VISCOUS_HEATING;
    }
    if m.is_thermal() {
        flags |= FLAG_HEAT;
    }
    if m.needs_interface() {
        flags |= FLAG_INTERFACE;
    }
    if m.melts() {
        flags |= FLAG_SOLIDIFICATION;
    }
    flags
}

fn grid_block(m: &Model) -> Grid {
    let mut g = Grid::zeroed();
    for a in 0..3 {
        g.cells[a] = m.grid[a];
        g.cell_inv[a] = (1.0 / m.cell_size[a]) as f32;
        if m.periodic[a] {
            let len = m.domain_hi[a] - m.domain_lo[a];
            g.period[a] = len as f32;
            g.half_period[a] = (0.5 * len) as f32;
        }
        let (lo, hi) = m.keep_box(a);
        g.keep_lo[a] = lo as f32;
        g.keep_hi[a] = hi as f32;
    }
    g
}

/// κ = ∫δ dn of the interface pass's surface delta across a planar surface of the
/// particle lattice (spacing Δx, half-space below the surface), per unit area.
/// The Shepard-corrected colour gradient (R18 (3.25)) overshoots the unit jump of
/// the colour by a few percent (quintic h = Δx: 1.059, Wendland C2 1.2Δx: 1.028,
/// cubic: 1.108, measured as absorbed laser power on a flat plate); dividing δ by
/// κ makes a surface flux ∫ s δ dV deposit exactly s per unit area on a flat
/// surface (F22 (17)).
pub fn surface_delta_integral(p: &Params, dx: f64) -> f64 {
    let dim = p.sizes.dim as i64;
    let support = (p.kernel.support2 as f64).sqrt();
    let reach = (support / dx).ceil() as i64 + 1;
    let depth = 3 * reach;
    let vol = dx.powi(dim as i32);
    let lateral: Vec<[i64; 2]> = (-reach..=reach)
        .flat_map(|a| (-reach..=reach).map(move |b| [a, b]))
        .filter(|l| dim == 3 || l[1] == 0)
        .collect();
    // Offsets from a particle in layer k to every lattice site within the support.
    let sites = |k: i64| {
        let lat = &lateral;
        (0..depth + reach).flat_map(move |kj| {
            lat.iter().filter_map(move |l| {
                let dz = (kj - k) as f64 * dx;
                let r2 = (l[0] * l[0] + l[1] * l[1]) as f64 * dx * dx + dz * dz;
                (r2 < support * support).then_some((kj, dz, r2.sqrt()))
            })
        })
    };
    let gamma: Vec<f64> = (0..depth + reach)
        .map(|k| {
            sites(k)
                .map(|(_, _, r)| vol * crate::kernel::w(p, r as f32) as f64)
                .sum()
        })
        .collect();
    (0..depth)
        .map(|k| {
            let g: f64 = sites(k)
                .filter(|s| s.2 > 0.0)
                .map(|(kj, dz, r)| {
                    vol * (1.0 / gamma[k as usize] + 1.0 / gamma[kj as usize])
                        * crate::kernel::dw(p, r as f32) as f64
                        / r
                        * -dz
                })
                .sum();
            // Layers below the normal threshold get no normal and absorb nothing.
            if g.abs() > 0.1 * p.kernel.inv_h as f64 {
                g.abs() * dx
            } else {
                0.0
            }
        })
        .sum()
}

/// κ_F22: the condensed side's ∫δ dn for the F22 (19) colour gradient across a
/// planar lattice interface between condensed material (density ρ_c, below) and
/// gas (ρ_g, above). The density weight ρ_i/(ρ_i + ρ_j) gives the condensed side
/// nearly all of the jump (F22 Remark 3) when ρ_c ≫ ρ_g.
pub fn gas_delta_integral(p: &Params, dx: f64, rho_c: f64, rho_g: f64) -> f64 {
    let dim = p.sizes.dim as i64;
    let support = (p.kernel.support2 as f64).sqrt();
    let reach = (support / dx).ceil() as i64 + 1;
    let vol_c = dx.powi(dim as i32);
    // Every lattice site holds volume Δx^d whatever its phase (m = ρ0 Δx^d).
    let vol_g = vol_c;
    let weight = rho_c / (rho_c + rho_g);
    (0..2 * reach)
        .map(|k| {
            // Condensed particle at depth (k + ½)Δx; gas sites at heights (kg + ½)Δx.
            let mut g = 0.0;
            for kg in 0..reach {
                let dz = (k + kg + 1) as f64 * dx; // vertical distance (condensed below)
                for a in -reach..=reach {
                    for b in -reach..=reach {
                        if dim == 2 && b != 0 {
                            continue;
                        }
                        let r2 = (a * a + b * b) as f64 * dx * dx + dz * dz;
                        if r2 >= support * support {
                            continue;
                        }
                        let r = r2.sqrt();
                        let f = (vol_c * vol_c + vol_g * vol_g)
                            * weight
                            * crate::kernel::dw(p, r as f32) as f64
                            / r;
                        g += f * -dz;
                    }
                }
            }
            let g = g / vol_c;
            if g.abs() > 0.1 * p.kernel.inv_h as f64 {
                g.abs() * dx
            } else {
                0.0
            }
        })
        .sum()
}

/// The laser part of the block (all zero without a laser).
fn laser_block(m: &Model) -> Laser {
    let mut p = Laser::zeroed();
    let Some(l) = &m.laser else { return p };
    let d = m.dim as i32;
    let dx = m.dx;
    p.model = match l.model {
        crate::scene::LaserModel::BeerLambert => LASER_BEER_LAMBERT,
        crate::scene::LaserModel::GaussianSurface => LASER_SURFACE,
        crate::scene::LaserModel::RayTraced => LASER_RAY_TRACED,
    };
    p.absorptivity = l.absorptivity.unwrap_or(0.0) as f32;
    p.radius = l.radius as f32;
    p.absorption = l.absorption as f32;
    let peak = if m.dim == 3 {
        2.0 / (PI * l.radius * l.radius)
    } else {
        (2.0 / PI).sqrt() / l.radius
    };
    p.bin_size = dx as f32;
    p.peak_per_watt = peak as f32;
    p.bin_volume = dx.powi(d) as f32;
    p.column_area = dx.powi(d - 1) as f32;
    let mut bins = [1u32, 1, 1, 0];
    for a in 0..m.dim as usize {
        bins[a] = ((m.domain_hi[a] - m.domain_lo[a]) / dx - 1e-9)
            .ceil()
            .max(1.0) as u32;
    }
    p.bins = bins.into();
    p.path_points = l.path.len() as u32;
    p.power_steps = l.power.len() as u32;
    let lo = m.to_local(m.domain_lo);
    p.lo = glam::Vec4::new(lo[0] as f32, lo[1] as f32, lo[2] as f32, 0.0);
    for (k, (t, x)) in l.path.iter().enumerate() {
        let mut abs = m.domain_lo;
        abs[0] = x[0];
        if m.dim == 3 {
            abs[1] = x[1];
        }
        let loc = m.to_local(abs);
        p.path[k] = PathPoint {
            time: *t as f32,
            x: loc[0] as f32,
            y: if m.dim == 3 { loc[1] as f32 } else { 0.0 },
        };
    }
    for (k, (t, pw)) in l.power.iter().enumerate() {
        p.power[k] = PowerStep {
            time: *t as f32,
            power: *pw as f32,
        };
    }
    if let Some(r) = &l.rays {
        ray_block(&mut p, m, l, r);
    }
    p
}

/// Watts per fixed-point count of the ray-traced laser: the schedule's largest
/// power over 2^31 (RAY_UNITS_PER_PEAK), as the device holds it.
pub fn ray_power_unit(l: &crate::model::Laser) -> f32 {
    let peak = l.power.iter().map(|q| q.1).fold(0.0, f64::max);
    let peak = if peak > 0.0 { peak } else { 1.0 };
    (peak / RAY_UNITS_PER_PEAK) as f32
}

/// The ray-traced model's bundle: its count, spacing, the weights' normalisation
/// (Σ g over the same offsets the passes evaluate, in f64) and the march.
fn ray_block(p: &mut Laser, m: &Model, l: &crate::model::Laser, r: &crate::model::RayTracing) {
    let n = r.rays_per_side(m.dx, l.radius);
    let spacing = m.dx / r.rays_per_dx as f64;
    p.rays_per_side = n;
    p.ray_spacing = spacing as f32;
    p.max_bounces = r.max_bounces;
    p.profile = match r.profile {
        crate::scene::BeamProfile::Gaussian => PROFILE_GAUSSIAN,
        crate::scene::BeamProfile::TopHat => PROFILE_TOP_HAT,
    };
    let half = (n / 2) as i64;
    let rw = l.radius;
    let g = |o: f64| -> f64 {
        match r.profile {
            crate::scene::BeamProfile::Gaussian => (-2.0 * o / (rw * rw)).exp(),
            crate::scene::BeamProfile::TopHat => (o <= rw * rw) as u8 as f64,
        }
    };
    let offsets: Vec<f64> = (-half..=half).map(|k| k as f64 * spacing).collect();
    let mut sum = 0.0;
    for &a in &offsets {
        if m.dim == 3 {
            for &b in &offsets {
                sum += g(a * a + b * b);
            }
        } else {
            sum += g(a * a);
        }
    }
    p.ray_norm = (1.0 / sum) as f32;
    p.power_unit = ray_power_unit(l);
    p.march_step = (0.25 * m.dx) as f32;
    let diagonal: f64 = (0..m.dim as usize)
        .map(|a| (p.bins[a] as f64 * m.dx).powi(2))
        .sum::<f64>()
        .sqrt();
    p.march_steps = (diagonal / (0.25 * m.dx)).ceil() as u32 + 1;
}

fn finite_or_max(v: f64) -> f32 {
    if v.is_finite() {
        v as f32
    } else {
        f32::MAX
    }
}

use crate::model::STEFAN_BOLTZMANN;

/// One phase's row: flow material, wall motion, heat, melting and surface losses.
fn phase_block(ph: &crate::model::PhaseInfo) -> Phase {
    let mut b = Phase::zeroed();
    b.rho0 = ph.rho0 as f32;
    b.c2 = (ph.sound_speed * ph.sound_speed) as f32;
    b.eta = ph.viscosity as f32;
    b.kind = match ph.kind {
        PhaseKind::Liquid => KIND_LIQUID,
        PhaseKind::Gas => KIND_GAS,
        PhaseKind::Wall => KIND_WALL,
        PhaseKind::Solid => KIND_SOLID,
    };
    b.velocity = glam::Vec4::new(
        ph.velocity[0] as f32,
        ph.velocity[1] as f32,
        ph.velocity[2] as f32,
        0.0,
    );
    if ph.slip == Slip::FreeSlip {
        b.flags |= PHASE_FREE_SLIP;
    }
    if ph.moves {
        b.flags |= PHASE_MOVES;
    }
    let Some(t) = ph.thermal else { return b };
    if ph.kind == PhaseKind::Wall {
        b.flags |= HEAT_DIRICHLET;
    }
    if ph.is_fluid() {
        b.flags |= HEAT_LIQUID;
    }
    if t.melting.is_some() {
        b.flags |= HEAT_MELTS;
    }
    if let Some(target) = ph.switch_to {
        b.flags |= (target as u32 + 1) << HEAT_SWITCH_SHIFT;
    }
    let cp = t.heat_capacity;
    b.conductivity = t.conductivity as f32;
    b.heat_capacity = cp as f32;
    b.reference_temperature = t.reference_temperature() as f32;
    if let Some((ts, tl, l)) = t.melting {
        b.band_enthalpy = (t.enthalpy(tl) - t.enthalpy(ts)) as f32;
        b.solidus = ts as f32;
        b.liquidus = tl as f32;
        b.band_capacity = (cp + l / (tl - ts)) as f32;
    }
    if ph.kind == PhaseKind::Liquid {
        b.mushy_damping = t.mushy_damping as f32;
    }
    let (kl, cl) = t.liquid;
    b.liquid_conductivity = kl as f32;
    b.liquid_heat_capacity = cl as f32;
    b.capacity_slope = t.melting.map_or(0.0, |(ts, tl, _)| {
        (cl - t.heat_capacity) / (2.0 * (tl - ts))
    }) as f32;
    if let Some(v) = t.evaporation {
        b.evap_pressure = v.pressure_constant as f32;
        b.evap_temperature = v.temperature_constant as f32;
        b.inv_boiling_temperature = (1.0 / v.boiling_temperature) as f32;
        b.evap_latent_heat = v.latent_heat as f32;
        b.evap_enthalpy_reference = v.enthalpy_reference as f32;
        b.vapor_constant = v.vapor_constant as f32;
        b.recondensation = (0.82 * v.sticking) as f32;
        if ph.recoil().is_some() {
            b.flags |= PHASE_RECOIL;
        }
    }
    b.emissivity_sb = (t.emissivity * STEFAN_BOLTZMANN) as f32;
    if let Some(p) = t.program {
        b.flags |= PHASE_PROGRAM;
        b.program_temperature = t.temperature as f32;
        b.program_amplitude = p.amplitude as f32;
        b.program_amplitude_rate = p.amplitude_rate as f32;
        b.program_frequency = p.frequency as f32;
        b.program_rate = p.rate as f32;
        b.program_until = finite_or_max(p.until);
    }
    if let Some(law) = &ph.density_law {
        b.flags |= PHASE_DENSITY_LAW;
        b.density_points = law.points.len() as u32;
        for (k, (&(t, r), s)) in law.points.iter().zip(law.slopes()).enumerate() {
            let row = &mut b.density[k / 4];
            row.temperature[k % 4] = t as f32;
            row.value[k % 4] = r as f32;
            row.slope[k % 4] = s as f32;
        }
    }
    if let Some(table) = &t.enthalpy_table {
        b.enthalpy_points = table.n as u32;
        let h_ref = t.reference_enthalpy();
        for (k, &(tk, hk)) in table.points().iter().enumerate() {
            let row = &mut b.enthalpy[k / 4];
            row.temperature[k % 4] = tk as f32;
            row.value[k % 4] = (hk - h_ref) as f32;
            row.slope[k % 4] = table.slope(k) as f32;
        }
    }
    if let Some(table) = &t.conductivity_table {
        b.conductivity_points = table.n as u32;
        for (k, &(tk, lk)) in table.points().iter().enumerate() {
            let row = &mut b.conductivity_law[k / 4];
            row.temperature[k % 4] = tk as f32;
            row.value[k % 4] = lk as f32;
            row.slope[k % 4] = if k + 1 < table.n {
                table.slope(k) as f32
            } else {
                0.0
            };
        }
    }
    b
}

/// W(r) in f64 (host-side setup), the kernels of `kernel_sigma`.
pub fn kernel_w_f64(kind: KernelKind, dim: u32, h: f64, r: f64) -> f64 {
    let q = r / h;
    let sigma = kernel_sigma(kind, dim, h);
    match kind {
        KernelKind::Quintic => {
            let p = |a: f64| (a - q).max(0.0).powi(5);
            sigma * (p(3.0) - 6.0 * p(2.0) + 15.0 * p(1.0))
        }
        KernelKind::WendlandC2 => sigma * (1.0 - 0.5 * q).max(0.0).powi(4) * (2.0 * q + 1.0),
        KernelKind::Cubic => {
            if q < 1.0 {
                sigma * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
            } else if q < 2.0 {
                sigma * 0.25 * (2.0 - q).powi(3)
            } else {
                0.0
            }
        }
    }
}

/// Calls `f` with the distance |k| Δx of every site k of the square (cubic)
/// lattice within `support` of the origin, the origin included.
fn for_each_lattice_site(dim: u32, dx: f64, support: f64, mut f: impl FnMut(f64)) {
    let reach = (support / dx).ceil() as i64;
    let z = if dim == 3 { reach } else { 0 };
    for a in -reach..=reach {
        for b in -reach..=reach {
            for c in -z..=z {
                let r = dx * ((a * a + b * b + c * c) as f64).sqrt();
                if r < support {
                    f(r);
                }
            }
        }
    }
}

/// The neighbours of a particle inside the square (cubic) lattice: the sites
/// k ≠ 0 with |k| Δx < support (24 in 2D and 92 in 3D for the quintic's
/// 3 Δx).
pub fn lattice_neighbours(dim: u32, dx: f64, support: f64) -> u32 {
    let mut count = 0;
    // Sites on the support's edge (W = 0) are no neighbours.
    for_each_lattice_site(dim, dx, support * (1.0 - 1e-9), |r| {
        if r > 0.0 {
            count += 1;
        }
    });
    count
}

/// Σ_k W(|k| Δx) Δx^d over the square (cubic) lattice: the summation density
/// of a particle inside a lattice of mass ρ0 Δx^d, over ρ0 (1.0026 for the
/// quintic at h = Δx in 2D).
pub fn lattice_density_ratio(kind: KernelKind, dim: u32, h: f64, dx: f64, support: f64) -> f64 {
    let mut sum = 0.0;
    for_each_lattice_site(dim, dx, support, |r| sum += kernel_w_f64(kind, dim, h, r));
    sum * dx.powi(dim as i32)
}

#[cfg(test)]
mod tests {
    /// A lattice particle's neighbours inside the support, the sites on its
    /// edge excluded: the quintic's 3 Δx (24 in 2D: rings of 4, 4, 4, 8, 4;
    /// 92 in 3D) and a 2 Δx support (8 and 26: |k|² = 4 sits on the edge).
    #[test]
    fn lattice_neighbours_count_the_sites_inside_the_support() {
        assert_eq!(super::lattice_neighbours(2, 1.0e-3, 3.0e-3), 24);
        assert_eq!(super::lattice_neighbours(3, 1.0e-3, 3.0e-3), 92);
        assert_eq!(super::lattice_neighbours(2, 1.0e-3, 2.0e-3), 8);
        assert_eq!(super::lattice_neighbours(3, 1.0e-3, 2.0e-3), 26);
    }
}
