//! Scenario files: the TOML format (each section's types here, `[check]`'s in
//! check.rs), `--set` overrides (overrides.rs) and the parse.
//!
//! Parsing is strict: unknown keys are errors, every physical value is checked for
//! sign and range, and each message names the file and the dotted key.

use crate::error::InputError;
use serde::Deserialize;
use std::collections::BTreeMap;

mod check;
mod overrides;

pub use check::*;
use overrides::apply_override;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    Quintic,
    WendlandC2,
    Cubic,
}

impl KernelKind {
    /// Support radius in units of h.
    pub fn support_factor(self) -> f64 {
        match self {
            KernelKind::Quintic => 3.0,
            KernelKind::WendlandC2 | KernelKind::Cubic => 2.0,
        }
    }
    /// Default h/Δx: where each kernel converges on the flow checks (Poiseuille
    /// and Couette over Δx = L/15 … L/40, `bench accuracy`; docs/benchmarks.md
    /// has the sweep). The quintic at F22's h = Δx: order 2.08 / 2.04. The
    /// cubic at 1.5Δx (support 3Δx, the quintic's): 1.96 / 1.50, where h = Δx
    /// (SPlisHSPlasH's support 2Δx) gets worse with resolution (−0.66 / −0.14).
    /// Wendland C2 at 2Δx (support 4Δx): 1.58 / 0.73, where R18's 1.2Δx sits on
    /// an error floor (5.1e-2 / 1.8e-2 at every Δx, order 0.12 / 0.03). h/Δx =
    /// 1.8 is worse than 1.5 and 2.0 for both (a lattice resonance).
    pub fn default_h_over_dx(self) -> f64 {
        match self {
            KernelKind::Quintic => 1.0,
            KernelKind::WendlandC2 => 2.0,
            KernelKind::Cubic => 1.5,
        }
    }
    pub fn code(self) -> u32 {
        match self {
            KernelKind::Quintic => 0,
            KernelKind::WendlandC2 => 1,
            KernelKind::Cubic => 2,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            KernelKind::Quintic => "quintic",
            KernelKind::WendlandC2 => "wendland_c2",
            KernelKind::Cubic => "cubic",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    Wcsph,
    /// R18's δ-SPH: continuity density with density diffusion on ρ − ρ0.
    DeltaWcsph,
    /// Divergence-free SPH (Bender & Koschier; J22): implicit pressure.
    Dfsph,
}

impl Formulation {
    /// Its code in the parameter block (`solve.formulation`).
    pub fn code(self) -> u32 {
        match self {
            Formulation::Wcsph => 0,
            Formulation::DeltaWcsph => 1,
            Formulation::Dfsph => 2,
        }
    }
    pub fn from_code(code: u32) -> Formulation {
        match code {
            0 => Formulation::Wcsph,
            1 => Formulation::DeltaWcsph,
            2 => Formulation::Dfsph,
            c => panic!("no formulation with code {c}"),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Formulation::Wcsph => "wcsph",
            Formulation::DeltaWcsph => "delta_wcsph",
            Formulation::Dfsph => "dfsph",
        }
    }
}

/// `simulation.viscosity_form`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViscosityForm {
    /// Morris et al. 1997 (F22 (23)): Σ (V_i² + V_j²) η̃ u_ij (∂W/∂r)/r.
    #[default]
    Morris,
    /// Monaghan–Gingold in Marrone's multiphase form (R18 (3.18)).
    Marrone,
}

/// `simulation.density_diffusion` (δ-SPH): what the density diffusion smooths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DensityDiffusion {
    /// R18 (3.53): the excess ρ − ρ0(T), between particles of one phase (the
    /// compatible form).
    #[default]
    Excess,
    /// Antuono et al.'s term on the raw ρ between every pair of fluid
    /// particles: R18 Test 4's "incompatible" variant, which diffuses density
    /// across an interface of two ρ0 (kept for that comparison).
    Raw,
}

/// `[heat] integrator`: how the enthalpy advances over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeatIntegrator {
    /// h^{n+1} = h^n + Δt ḣ(T^n) (F22, J22).
    #[default]
    Euler,
    /// h^{n+1} = h^n + Δt/2 (ḣ(T^n) + ḣ(T^{n+1})) (Crank–Nicolson), by
    /// fixed-point iteration (R18 Algorithm 3.1).
    Trapezoidal,
}

/// `[heat]`: the time integration of the energy equation (heat scenes only).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeatDef {
    #[serde(default)]
    pub integrator: HeatIntegrator,
    /// Trapezoidal rule: iterate until max|h^{k+1} − h^k| / max|h^{k+1} − h^n|
    /// (the change of the iterate against the step's) is at most this (R18
    /// prints no value).
    #[serde(default = "default_heat_tolerance")]
    pub tolerance: f64,
    /// Trapezoidal rule: at most this many iterations per step (each is a
    /// conduction sweep; the GPU records them all).
    #[serde(default = "default_heat_iterations")]
    pub max_iterations: u32,
}

fn default_heat_tolerance() -> f64 {
    1e-4
}
fn default_heat_iterations() -> u32 {
    8
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PhaseKind {
    Liquid,
    Gas,
    Wall,
    /// Fixed substrate that conducts heat: a wall for the fluid, a thermal body
    /// for the heat passes (F22 §3.2: solid particles of a fixed substrate).
    Solid,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Slip {
    #[default]
    NoSlip,
    FreeSlip,
}

/// Pressure the fluid starts with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum InitialPressure {
    /// p = 0 everywhere: a column at rest first sinks and rings acoustically.
    #[default]
    Zero,
    /// The weight of the fluid above each particle (setup.rs `hydrostatic_start`).
    Hydrostatic,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub simulation: Simulation,
    pub domain: Domain,
    pub materials: BTreeMap<String, Material>,
    pub phases: BTreeMap<String, PhaseDef>,
    #[serde(default)]
    pub shapes: Vec<ShapeDef>,
    #[serde(default)]
    pub run: RunDef,
    pub check: Option<CheckDef>,
    #[serde(default)]
    pub watchdog: WatchdogDef,
    pub laser: Option<LaserDef>,
    /// The beam's path as tracks (instead of `laser.path`).
    pub scan: Option<ScanDef>,
    pub surface_tension: Option<SurfaceTensionDef>,
    pub powder: Option<PowderDef>,
    pub contact: Option<ContactDef>,
    pub heat: Option<HeatDef>,
}

/// `[contact]`: F22 (39)–(40), the repulsive spring–dashpot between particles of
/// different rigid bodies and between a body and the walls or substrate, acting
/// within one particle spacing. F22 has no friction, and neither has spatter.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactDef {
    /// k_c (kg/s²; F22: 1.0).
    pub stiffness: f64,
    /// d_c (kg/s; F22: 1e-4).
    pub damping: f64,
}

/// `[powder]`: a bed of grains poured into a box and levelled at its top
/// (src/powder.rs). The vertical is the last axis.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowderDef {
    /// The grains' phase: solid (conducts, may melt) or wall. Fixed in place
    /// until rigid bodies exist.
    pub phase: String,
    /// Grains rest on the box's bottom face, stay inside its sides and are
    /// levelled at its top face.
    #[serde(rename = "box")]
    pub box_: BoxDef,
    pub diameter: DiameterDef,
    /// Seed of the grain sizes and drop positions (same seed, same bed).
    #[serde(default)]
    pub seed: u64,
    /// Pour exactly this many grains and level nothing (the box's top is only
    /// where the pour starts; the bed keeps the drawn diameters). Default: pour
    /// until the box is full, levelled at its top.
    pub max_grains: Option<usize>,
    /// Each grain is a rigid body (F22 §2.2): it moves under gravity, contact
    /// ([contact] is required) and the fluid's forces. A grain phase that melts
    /// (`melts_into`) loses its molten members to the melt and bonds where its
    /// melt solidifies (F22 §3.2). Default: grains fixed in place.
    #[serde(default)]
    pub rigid: bool,
}

/// `powder.diameter`: ln d ~ N(ln median, log_sigma²), clipped to [min, max] (m).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiameterDef {
    pub median: f64,
    pub log_sigma: f64,
    pub min: f64,
    pub max: f64,
}

/// `simulation.solid_fluid_viscosity`: F22 (33)'s α_0^sf and ΔT_d.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolidFluidViscosityDef {
    /// α_0^sf (dimensionless, as α_0^lg).
    pub coefficient: f64,
    /// ΔT_d (K): full at the solidus, none at solidus + ΔT_d.
    pub width: f64,
}

/// `[surface_tension]`: CSF surface tension with Marangoni, F22 (24)–(26), (8),
/// between one liquid phase and one gas phase (F22's form, with gas particles),
/// or at the free surface of a liquid in a scene without gas particles (R18
/// §3.1.1–3.1.2: Shepard-corrected colour gradient, curvature capped at 1/support
/// and smoothed); `gas` chooses.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceTensionDef {
    /// The liquid phase.
    pub liquid: String,
    /// How the force is computed: `"csf"` (default; F22 (24)-(26) with gas, R18's
    /// free-surface CSF without) or `"muller"`, J22 (5)-(8) after Müller et al.
    /// 2003: a colour field's Laplacian along its gradient, free-surface form only,
    /// constant coefficient, no Marangoni stress.
    #[serde(default)]
    pub model: TensionModel,
    /// The gas phase around it (F22's form). Absent: the free-surface form, for
    /// scenes without gas particles.
    pub gas: Option<String>,
    /// α0 (N/m): the coefficient at `reference_temperature` (or everywhere when
    /// `temperature_coefficient` is 0).
    pub coefficient: f64,
    /// α0' (N/(m K)), F22 (8): α(T) = α0 + α0' (T − T_α0), ≤ 0. Default 0.
    #[serde(default)]
    pub temperature_coefficient: f64,
    /// T_α0 (K); needed with a temperature coefficient.
    pub reference_temperature: Option<f64>,
    /// α_min (N/m): α is clipped there, and α' is 0 where it is. Default 0.
    #[serde(default)]
    pub minimum: f64,
    /// R18 (4.2): Sahoo et al.'s sulphur term on top of the linear law, σ(T) =
    /// coefficient + temperature_coefficient (T − reference_temperature)
    /// − R T Γ_s ln(1 + k_l a_s e^{−ΔH0/(R T)}), with its analytic dσ/dT.
    pub sahoo: Option<SahooDef>,
    /// ΔT_s (K), F22 (21): in heat scenes whose liquid melts, the force and each
    /// curvature neighbour ramp from 0 at the solidus to 1 at solidus + ΔT_s.
    pub melting_width: Option<f64>,
    /// Static contact angle θ0 (degrees) of the liquid on the wall and solid
    /// phases: wetting by a prescribed normal, F22 (27)–(29) (F22 form only).
    /// One number for all of them, or a table naming every wall and solid phase
    /// (`{ substrate = 60.0, wall = 90.0 }`). Absent: no wetting model.
    pub contact_angle: Option<ContactAngleDef>,
    /// R18 §4.4's rule for thin films (free-surface form): no tension on a
    /// liquid surface particle whose liquid, along its normal, is at most this
    /// many particles thick (R18: 2): their normal and curvature come from a
    /// support that holds one or two rows. Absent or 0: tension everywhere.
    pub thin_layer_rows: Option<u32>,
}

/// `surface_tension.model`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TensionModel {
    /// Continuum surface force from the normals' divergence (F22, R18).
    #[default]
    Csf,
    /// J22 (5)-(8): f = −σ ∇²c n/|n| of the colour c = Σ V_j W_ij (Müller 2003).
    Muller,
}

/// `surface_tension.sahoo`: the surface-active solute's term of R18 (4.2)
/// (Sahoo, DebRoy & McNallan 1988). R18 prints Γ_s = 1.3e-8 without its unit:
/// Sahoo's is kmol/m², and only that reading makes dσ/dT change sign (near
/// 1713 K for 304 SS at a_s = 0.0022 wt%); read as mol/m² the term is 1e-4 N/m.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SahooDef {
    /// Γ_s, the surface excess at saturation, in kmol/m² (Sahoo's unit).
    pub surface_excess: f64,
    /// k_l, the entropy factor of segregation (R18: 0.0032).
    pub segregation_constant: f64,
    /// a_s, the solute's activity in wt% (R18: sulphur, 0.0022).
    pub activity: f64,
    /// ΔH0, the standard heat of adsorption in J/mol (R18: −1.66e5).
    pub adsorption_enthalpy: f64,
}

/// `surface_tension.contact_angle`: one angle, or one per wall and solid phase.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum ContactAngleDef {
    All(f64),
    PerPhase(std::collections::BTreeMap<String, f64>),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LaserModel {
    /// Volumetric Beer–Lambert absorption with column binning (R18 §3.2.2).
    BeerLambert,
    /// Gaussian flux through the surface F22 (17): ζ ⟨−n·e_l⟩ s_l(x) δ.
    GaussianSurface,
    /// The beam as a bundle of rays, each absorbed at the surface it meets by
    /// the Fresnel absorptivity of the material's optical constants at the angle
    /// of incidence, and reflected specularly on (docs/physics.md, "Ray-traced
    /// absorption").
    RayTraced,
}

/// `laser.profile`: the beam's irradiance across its radius (ray-traced model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BeamProfile {
    /// exp(−2 r²/r_w²), `radius` the 1/e² radius r_w (= D4σ / 2).
    #[default]
    Gaussian,
    /// Uniform out to `radius`, nothing beyond.
    TopHat,
}

/// `laser.power`: one number, or a [time, power] schedule.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum PowerDef {
    Constant(f64),
    Schedule(Vec<Vec<f64>>),
}

/// A laser heat source. The beam points down the last axis (−y in 2D, −z in 3D).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaserDef {
    pub model: LaserModel,
    /// Absorptivity ζ: the fraction of the beam power the material can take up
    /// (`beer_lambert`, `gaussian_surface`; the ray-traced model takes it from
    /// the materials' optical constants instead).
    pub absorptivity: Option<f64>,
    /// Beam radius r_w (m): irradiance ∝ exp(−2 r²/r_w²), d_w = 2 r_w (F22 (17));
    /// D4σ = 2 r_w. A top-hat beam's edge radius.
    pub radius: f64,
    /// Ray-traced model: `gaussian` (default) or `top_hat`.
    #[serde(default)]
    pub profile: BeamProfile,
    /// Ray-traced model: rays per Δx across the beam (default 2: a ray every
    /// Δx/2 laterally, out to 2 r_w).
    pub rays_per_dx: Option<u32>,
    /// Ray-traced model: surface hits a ray may make (default 8); the power a
    /// ray still carries after its last is absorbed there, and reported.
    pub max_bounces: Option<u32>,
    /// Laser wavelength (m): needed where a material gives its optics as an
    /// electrical resistivity (Hagen–Rubens).
    pub wavelength: Option<f64>,
    /// Beer–Lambert absorption coefficient (1/m).
    pub absorption_coefficient: Option<f64>,
    /// Beam power (W; W per metre of depth in 2D): one number, held from t = 0,
    /// or a schedule of [time, power] pairs, each power held from its time on
    /// (before the first time the beam is off). One number is what `spatter
    /// sweep --vary laser.power=...` varies.
    pub power: PowerDef,
    /// s: the beam goes off for good at this time, whatever `power` says (a
    /// line melt's end, kept apart from the power so a sweep can vary it).
    pub power_until: Option<f64>,
    /// Scan path: [time, x] (2D) or [time, x, y] (3D) beam centres, linear in
    /// between and held before the first and after the last. Absent where a
    /// `[scan]` gives the tracks.
    #[serde(default)]
    pub path: Vec<Vec<f64>>,
}

/// `[scan]`: the beam's path as a process engineer gives it, one track or a
/// hatch of parallel tracks, compiled to the laser's path and power tables
/// (the beam at `laser.power` on each track, off in the turns). The
/// alternative to `laser.path` and `laser.power_until`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanDef {
    /// Where the first track starts: [x] (2D) or [x, y] (3D), m.
    pub start: Vec<f64>,
    /// The first track's direction along the plate: [1] or [-1] (2D), a
    /// vector [dx, dy] in the plate's plane (3D; normalised). Default +x.
    pub direction: Option<Vec<f64>>,
    /// Scan speed (m/s).
    pub speed: f64,
    /// Each track's length (m).
    pub length: f64,
    /// When the first track starts (s; default 0).
    #[serde(default)]
    pub start_time: f64,
    /// The beam on and held still at each track's start before it moves (s;
    /// default 0).
    #[serde(default)]
    pub dwell: f64,
    /// Number of parallel tracks (default 1; 3D only above 1).
    #[serde(default = "one_track")]
    pub tracks: u32,
    /// Distance between neighbouring tracks' centre lines (m), to the left of
    /// the first track's direction (+y for a track along +x).
    pub hatch_spacing: Option<f64>,
    /// Every track the same way (`unidirectional`, default) or each the
    /// other way from the last (`alternating`, a serpentine).
    #[serde(default)]
    pub pattern: HatchPattern,
    /// Beam off between one track's end and the next one's start (s), while
    /// the beam moves over.
    pub turnaround: Option<f64>,
}

fn one_track() -> u32 {
    1
}

/// `scan.pattern`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HatchPattern {
    #[default]
    Unidirectional,
    Alternating,
}

/// `simulation.interface_viscosity`: α at this Δx, or α at a reference Δx.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum InterfaceViscosityDef {
    Alpha(f64),
    Scaled { alpha: f64, at_dx: f64 },
}

impl Default for InterfaceViscosityDef {
    fn default() -> Self {
        InterfaceViscosityDef::Alpha(0.0)
    }
}

impl InterfaceViscosityDef {
    /// α at resolution dx (NaN for a reference Δx that is not positive).
    pub fn alpha(&self, dx: f64) -> f64 {
        match *self {
            InterfaceViscosityDef::Alpha(a) => a,
            InterfaceViscosityDef::Scaled { alpha, at_dx } if at_dx > 0.0 => alpha * (at_dx / dx),
            InterfaceViscosityDef::Scaled { .. } => f64::NAN,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    pub dimension: u32,
    #[serde(default = "default_formulation")]
    pub formulation: Formulation,
    /// δ-SPH (formulation = "delta_wcsph"): the density diffusion coefficient δ
    /// of R18 (3.53) (R18 prints none; Antuono et al. 2012's 0.1 is the default).
    pub delta: Option<f64>,
    /// δ-SPH: the viscous term, F22 (23)'s (`morris`, default) or R18 (3.18)'s
    /// (`marrone`; 17% weak in shear at h = Δx with the quintic: docs/physics.md).
    #[serde(default)]
    pub viscosity_form: ViscosityForm,
    /// δ-SPH: diffuse the excess ρ − ρ0(T) (`excess`, default, R18 (3.53)) or
    /// the raw ρ across phases (`raw`, R18 Test 4's incompatible variant).
    #[serde(default)]
    pub density_diffusion: DensityDiffusion,
    #[serde(default = "default_kernel")]
    pub kernel: KernelKind,
    pub h_over_dx: Option<f64>,
    pub dx: f64,
    #[serde(default)]
    pub gravity: Vec<f64>,
    /// Transport-velocity background pressure p_b in Pa (F22 §4.1: 5 p0); 0 switches
    /// the transport-velocity correction off.
    #[serde(default)]
    pub background_pressure: f64,
    /// Clamp the equation of state at p >= 0. Needed for single-phase free surfaces,
    /// where summation density is deficient near the surface (docs/physics.md,
    /// formulation `wcsph`).
    #[serde(default)]
    pub pressure_floor: bool,
    /// `zero` (default) or `hydrostatic`: start each fluid particle at the pressure
    /// of the fluid above it, so a layer at rest starts in equilibrium.
    #[serde(default)]
    pub initial_pressure: InitialPressure,
    /// F22 (31)–(32) liquid–gas interface viscosity α_0^lg (0 = off; F22 Table 1,
    /// molten steel: 7.2; Table 4, liquid binder: 1.8), at a liquid's surface with
    /// gas or free. A number is α at this Δx; `{ alpha = 7.2, at_dx = 1.6667e-6 }`
    /// is α at a reference Δx (F22's), scaled as at_dx/Δx so that the damping
    /// viscosity α h c / (2(d + 2)) it adds stays the same when Δx changes.
    #[serde(default)]
    pub interface_viscosity: InterfaceViscosityDef,
    /// F22 (33) solid–fluid artificial viscosity: α_i^sf = coefficient ×
    /// f̄[T_i, T_s, T_s + width] on particles of melting liquids (T_s their
    /// solidus), in the form of F22 (31) (F22 Table 1: 1.0 and 300 K).
    pub solid_fluid_viscosity: Option<SolidFluidViscosityDef>,
    /// Seeded random displacement of fluid particles, as a fraction of Δx.
    #[serde(default)]
    pub jitter: f64,
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Viscous heating: the kinetic energy the viscous forces F22 (23) remove turns
    /// into enthalpy (heat scenes).
    #[serde(default)]
    pub viscous_heating: bool,
    /// Temperature of the surroundings for radiation loss (K).
    #[serde(default = "default_ambient")]
    pub ambient_temperature: f64,
    /// F22 (34) barrier force between fluid and wall particles closer than its
    /// radius: keeps splashes out of the walls. Absent: off.
    pub barrier: Option<BarrierDef>,
    /// `formulation = "dfsph"`: the pressure solves' tolerances and bound.
    pub dfsph: Option<DfsphDef>,
}

/// `simulation.dfsph`: when the two solves of divergence-free SPH stop.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DfsphDef {
    /// Mean density error (ρ* − ρ0)/ρ0 over the fluid at which the
    /// constant-density solve stops (default 1e-3: 0.1%).
    pub density_tolerance: f64,
    /// Mean divergence error Δt max(Dρ/Dt, 0)/ρ0 at which the divergence-free
    /// solve stops (default 1e-3).
    pub divergence_tolerance: f64,
    /// Iterations each solve may take per step (default 100, at most 200: the
    /// GPU records them all).
    pub max_iterations: u32,
    /// "implicit" (default): the viscosity (Weiler et al. 2018) and XSPH are
    /// one linear system solved by conjugate gradients after the explicit
    /// forces (J22 (17)), so no viscous time-step limit; "explicit": the
    /// forces pass's F22 (23) viscosity with its limit 0.125 h²/ν.
    pub viscosity: DfsphViscosity,
    /// The conjugate gradients stop at |r| ≤ this × |r0| (default 1e-3), r0
    /// the viscous and XSPH impulse at v*.
    pub viscosity_tolerance: f64,
    /// Their bound per step (default 100, at most 200).
    pub viscosity_max_iterations: u32,
    /// J22 (14)'s XSPH factor α (default 0: off; J22 uses 0.3), solved with
    /// the viscosity (needs `viscosity = "implicit"`).
    pub xsph: f64,
    /// J22 (15)'s cohesion γ^f and (16)'s adhesion γ^b, read per unit mass
    /// in 1/s² (J22 prints N/m and 200, which is nothing in SI units: see
    /// docs/physics.md); default 0, on the implicit solve's right side.
    pub cohesion: f64,
    pub adhesion: f64,
    /// "lattice" (default): the domain's walls are as many layers of the
    /// lattice as the kernel's support, each of volume m/ρ0; "akinci": one
    /// layer, every wall particle's volume V_b = 1/Σ_b' W_bb' over the wall
    /// particles (J22 (23)–(24), Akinci et al. 2012).
    pub boundary: DfsphBoundary,
}

/// `simulation.dfsph.boundary`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DfsphBoundary {
    #[default]
    Lattice,
    Akinci,
}

impl Default for DfsphDef {
    fn default() -> Self {
        DfsphDef {
            density_tolerance: 1.0e-3,
            divergence_tolerance: 1.0e-3,
            max_iterations: 100,
            viscosity: DfsphViscosity::Implicit,
            viscosity_tolerance: 1.0e-3,
            viscosity_max_iterations: 100,
            xsph: 0.0,
            cohesion: 0.0,
            adhesion: 0.0,
            boundary: DfsphBoundary::Lattice,
        }
    }
}

/// `simulation.dfsph.viscosity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DfsphViscosity {
    Implicit,
    Explicit,
}

/// `simulation.barrier`: F22 (34) F = Σ_j (k_b g + d_b g ġ) e_ij over wall
/// particles j with r_ij < r_b, g = r_b − r_ij, ġ = −e_ij·u_ij.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarrierDef {
    /// r_b (m), below h (F22: 0.83 µm ≈ Δx/2); or `radius_dx`, in Δx, which
    /// follows a `--set dx=…` refinement.
    pub radius: Option<f64>,
    pub radius_dx: Option<f64>,
    /// k_b (kg/s², N/m; F22: 1.0).
    pub stiffness: f64,
    /// d_b (kg/(m s); F22: 1.0).
    #[serde(default)]
    pub damping: f64,
}

fn default_ambient() -> f64 {
    300.0
}

fn default_formulation() -> Formulation {
    Formulation::Wcsph
}
fn default_kernel() -> KernelKind {
    KernelKind::Quintic
}
fn default_seed() -> u64 {
    1
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
    #[serde(default)]
    pub periodic: Vec<bool>,
    /// Phase of the wall layers put around every non-periodic side.
    pub wall_phase: Option<String>,
    /// Per-side override of the wall phase: keys x_min, x_max, y_min, y_max, z_min, z_max.
    #[serde(default)]
    pub wall_sides: BTreeMap<String, String>,
    /// Sides left open (no wall layers), e.g. ["z_max"] above a free surface.
    /// A particle that crosses one leaves the simulation (see `open_sides_policy`).
    #[serde(default)]
    pub open_sides: Vec<String>,
    /// What a particle crossing an open side does to the run.
    #[serde(default)]
    pub open_sides_policy: OpenSidesPolicy,
}

/// `domain.open_sides_policy`: what happens when a particle leaves through an
/// open side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OpenSidesPolicy {
    /// The particle is taken out of the simulation, counted with its mass, and
    /// the run goes on (what DualSPHysics calls excluded particles).
    #[default]
    Remove,
    /// The run stops (exit 3) at the first particle that leaves, naming it.
    Stop,
}

/// Names of the domain sides, by axis then (min, max).
pub const SIDE_NAMES: [[&str; 2]; 3] = [["x_min", "x_max"], ["y_min", "y_max"], ["z_min", "z_max"]];

/// Axis of a side name (`x_min` → 0), None if the name is not a side.
pub fn side_axis(name: &str) -> Option<usize> {
    SIDE_NAMES.iter().position(|pair| pair.contains(&name))
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Reference density ρ0 in kg/m³.
    pub density: f64,
    /// Dynamic viscosity η in Pa·s.
    pub viscosity: f64,
    /// Speed of sound c in m/s; give this or `reference_pressure`.
    pub sound_speed: Option<f64>,
    /// Reference pressure p0 = ρ0 c² in Pa (F22 §4.1 uses 1e7 Pa).
    pub reference_pressure: Option<f64>,
    /// Thermal conductivity k in W/(m K) (heat scenes).
    pub conductivity: Option<f64>,
    /// Specific heat capacity c_p in J/(kg K) (heat scenes).
    pub heat_capacity: Option<f64>,
    /// Melting band [solidus, liquidus] in K and latent heat of melting in J/kg
    /// (J22 (19): h(T) = c_p T + L f_l(T), f_l linear over the band).
    pub solidus: Option<f64>,
    pub liquidus: Option<f64>,
    pub latent_heat: Option<f64>,
    /// Liquid-state conductivity and heat capacity (default: the solid's); inside
    /// the melting band both vary linearly with the liquid fraction.
    pub liquid_conductivity: Option<f64>,
    pub liquid_heat_capacity: Option<f64>,
    /// Evaporation heat loss F22 (18) with the recoil-pressure law F22 (10), liquid
    /// phases at a free surface.
    pub evaporation: Option<EvaporationDef>,
    /// Radiation loss σ ε (T⁴ − T_ambient⁴) from free surfaces (R18 (3.39)).
    pub emissivity: Option<f64>,
    /// Mushy-zone momentum sink C (1/s), J22 (11)–(13): a liquid particle's velocity
    /// is divided by 1 + Δt C (1 − f_l) each step, so the melt stiffens as it
    /// solidifies.
    pub mushy_damping: Option<f64>,
    /// The reference density as a function of temperature, ρ0(T) (R18 (3.52),
    /// §4.4): points [T (K), ρ0 (kg/m³)] in rising temperature, linear between
    /// them and continued along the first and last segments beyond; a temperature
    /// given twice is a step (R18's 304 SS law jumps at the solidus). The EOS is
    /// p = c²(ρ − ρ0(T)) and the density diffusion acts on ρ − ρ0(T), so a heated
    /// particle expands with mass held exact. `formulation = "delta_wcsph"` only;
    /// `density` stays the nominal value (sound speed from `reference_pressure`,
    /// the surface terms' volumes m/ρ0).
    pub density_law: Option<Vec<Vec<f64>>>,
    /// Specific enthalpy h(T) = ∫_0^T c_p dT with the latent heat (J22 (19),
    /// §4.2): 2 to 8 points [T (K), h (J/kg)], both rising, linear between them
    /// and continued along the first and last segments. Replaces
    /// `heat_capacity`, `liquid_heat_capacity` and `latent_heat` (solidus and
    /// liquidus still give the liquid fraction).
    pub enthalpy_table: Option<Vec<Vec<f64>>>,
    /// Conductivity λ(T): 2 to 8 points [T (K), λ (W/(m K))] in rising
    /// temperature, linear between them and held at the end values beyond.
    /// Replaces `conductivity` and `liquid_conductivity`.
    pub conductivity_table: Option<Vec<Vec<f64>>>,
    /// Complex refractive index [n, k] at the laser's wavelength (ray-traced
    /// laser): the Fresnel absorptivity of a surface at any angle follows.
    pub refractive_index: Option<Vec<f64>>,
    /// DC electrical resistivity ρ_e (Ω m), the alternative to
    /// `refractive_index`: n = k = 1/√(2 ε0 ω ρ_e) (Hagen–Rubens, the Drude
    /// model's low-frequency limit; needs `laser.wavelength`).
    pub electrical_resistivity: Option<f64>,
}

/// F22 Table 1 names: p_v(T) = C_p exp[−C_T (1/T − 1/T_v)], ṁ = 0.82 c_s p_v √(C_M/T),
/// loss per area ṁ (h_v + c_p (T − T_h0)).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvaporationDef {
    /// C_p (Pa).
    pub pressure_constant: f64,
    /// C_T (K).
    pub temperature_constant: f64,
    /// T_v (K).
    pub boiling_temperature: f64,
    /// h_v (J/kg).
    pub latent_heat: f64,
    /// T_h0 (K), reference temperature of the vapour's specific enthalpy.
    pub enthalpy_reference: f64,
    /// C_M = M/(2πR) (K s²/m²).
    pub vapor_constant: f64,
    /// c_s, close to one for metals.
    #[serde(default = "one")]
    pub sticking: f64,
    /// F22 (30): the vapour's recoil pressure p_v(T) pushes the liquid's surface,
    /// −p_v δ n per unit volume (liquid phases). On unless set false.
    #[serde(default = "yes")]
    pub recoil: bool,
}

fn yes() -> bool {
    true
}

fn one() -> f64 {
    1.0
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseDef {
    pub kind: PhaseKind,
    pub material: String,
    #[serde(default)]
    pub slip: Slip,
    /// Prescribed velocity of a wall phase (m/s). It enters the no-slip condition;
    /// the wall's particles stay in place unless `moves` is set.
    pub velocity: Option<Vec<f64>>,
    /// Wall phases: the particles move with `velocity` from t = 0 (a gate lifted
    /// out of the tank, a sliding plate). Without it the wall stays in place and its
    /// velocity only enters the no-slip condition (a lid or a belt).
    #[serde(default)]
    pub moves: bool,
    /// Initial temperature in K. Giving it to any phase makes the scene a heat scene;
    /// on a wall phase it is a fixed (Dirichlet) temperature, and a wall phase
    /// without one is adiabatic.
    pub temperature: Option<f64>,
    /// A cosine added to `temperature` along one axis, T = temperature + amplitude
    /// cos(2π x_axis / wavelength): a wall heated periodically (the thermocapillary
    /// channel of Pendse & Esmaeeli 2010), or an initial temperature field.
    pub temperature_wave: Option<TemperatureWaveDef>,
    /// Solid phases: the liquid phase a particle becomes when it melts (liquid
    /// fraction ≥ ½); it turns back into this solid, frozen in place, when it
    /// solidifies (F22 §3.2 with a fixed substrate).
    pub melts_into: Option<String>,
    /// A temperature imposed on the phase's particles instead of the heat
    /// equation: T(t) = temperature + amplitude sin(2π t / period) + rate min(t,
    /// until) (R18 Test 1's thermal cycle, Test 3's heating ramp). Liquid, gas and
    /// solid phases without a melting band, explicit heat integration.
    pub temperature_program: Option<TemperatureProgramDef>,
    /// m/s: this phase's sound speed in place of its material's (R18 §4.4
    /// lowers it ×5 on melting, so that the melt's expansion does not blow
    /// particles off the solid: the liquid phase a solid melts into takes its
    /// own). Fluid phases only.
    pub sound_speed: Option<f64>,
}

/// `phases.<name>.temperature_program`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureProgramDef {
    /// K (default 0); needs `period`.
    #[serde(default)]
    pub amplitude: f64,
    /// K/s (default 0): the amplitude grows as A + Ȧ t (R18 Test 2, whose
    /// expansion coefficient rises linearly in time); needs `period`.
    #[serde(default)]
    pub amplitude_rate: f64,
    /// s.
    pub period: Option<f64>,
    /// K/s (default 0).
    #[serde(default)]
    pub rate: f64,
    /// s: the ramp holds its temperature after this time (default: never).
    pub until: Option<f64>,
}

/// `phases.<name>.temperature_wave`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureWaveDef {
    /// K; smaller than the phase's temperature (T stays positive).
    pub amplitude: f64,
    /// m.
    pub wavelength: f64,
    /// "x", "y" or "z".
    pub axis: String,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDef {
    pub phase: String,
    #[serde(rename = "box")]
    pub box_: Option<BoxDef>,
    pub sphere: Option<SphereDef>,
    pub cylinder: Option<CylinderDef>,
    /// Initial velocity of the shape's particles (m/s; liquid and gas phases,
    /// and rigid bodies): a jet, a droplet in flight. Absent: at rest.
    pub velocity: Option<Vec<f64>>,
    /// The shape's particles (of a wall or solid phase) form one rigid body
    /// (F22 §2.2): they keep their places in the body's frame and move with it.
    #[serde(default)]
    pub body: bool,
    /// A body's initial angular velocity (rad/s): 3 components in 3D, 1 (about z)
    /// in 2D.
    pub angular_velocity: Option<Vec<f64>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxDef {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereDef {
    pub center: Vec<f64>,
    pub radius: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderDef {
    /// Centre of one end face.
    pub base: Vec<f64>,
    /// Axis from the base face to the other face; its length is the cylinder's length.
    pub axis: Vec<f64>,
    pub radius: f64,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunDef {
    pub end_time: Option<f64>,
    pub steps: Option<u64>,
    /// Fixed time step; absent means adaptive from the F22 (42) limits.
    pub dt: Option<f64>,
    /// A cap on the adaptive time step (J22 Table 2a's "CFL max Δt"): DFSPH's
    /// flow CFL grows without bound in a fluid at rest.
    pub max_dt: Option<f64>,
    /// Simulated time between state samples (checks, output frames).
    pub output_interval: Option<f64>,
    /// Simulated time between `/diagnostics` messages and watchdog scans
    /// (default: the output interval).
    pub diagnostics_interval: Option<f64>,
    /// Refuse a fixed `dt` above the F22 (42) limits (default true). Switching it off
    /// is for deliberately unstable runs, such as testing the watchdog.
    pub dt_check: Option<bool>,
    /// "solidified": end a laser run at the first sample after the beam is off
    /// for good with no melt left (liquid fraction ≥ ½), or `stop_grace`
    /// seconds after the beam went off, whichever comes first.
    pub stop_when: Option<StopWhen>,
    /// s after the beam goes off (default: none, only the melt's end stops it).
    pub stop_grace: Option<f64>,
}

/// `run.stop_when`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopWhen {
    Solidified,
}

/// Instability watchdog thresholds. Densities are relative to each
/// phase's ρ0, the Δt floor to the initial F22 (42) limit.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WatchdogDef {
    pub enabled: bool,
    /// Lower density bound ρ/ρ0. A lone particle keeps only its own kernel
    /// contribution, m W(0) ≈ 0.1–0.3 ρ0 for the kernels here, so the bound sits below.
    pub min_density_ratio: f64,
    /// Upper density bound ρ/ρ0; weakly compressible flow stays within a few percent.
    pub max_density_ratio: f64,
    /// Δt below this fraction of the initial limit counts as a collapse.
    pub min_dt_ratio: f64,
    /// Stop when a fluid particle is more than this many Δx behind a wall face.
    /// Absent (the default): only when it has passed through all the wall layers
    /// (as many Δx as the layers); shallower leaks are measured and warned about.
    pub wall_penetration: Option<f64>,
    /// Scenes with a liquid and a gas: the share of liquid particles
    /// with no liquid, solid or wall particle within 1.5 Δx (alone in the gas)
    /// above which the liquid counts as dispersing into its gas (default 0.05;
    /// at least 10 such particles). A drop that holds together has none: a
    /// splash sheds droplets of several particles. Without gas, under the
    /// free-surface tension: the share in pieces too small to resolve
    /// (crate::watchdog::fragment_limit).
    pub liquid_dispersion: f64,
    /// What a dispersing liquid does to the run: "stop" (exit 3 with the
    /// diagnosis) or "warn" (a warning at the first sample past the bound, and
    /// again whenever the share has grown by half). Default: "stop", "warn"
    /// in scenes with a phase that melts, where a melt pool's single-particle
    /// spatter counts too (Model::dispersion_action).
    pub on_dispersion: Option<DispersionAction>,
}

/// `watchdog.on_dispersion`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DispersionAction {
    #[default]
    Stop,
    Warn,
}

impl Default for WatchdogDef {
    fn default() -> Self {
        WatchdogDef {
            enabled: true,
            min_density_ratio: 0.02,
            max_density_ratio: 3.0,
            min_dt_ratio: 1e-3,
            wall_penetration: None,
            liquid_dispersion: 0.05,
            on_dispersion: None,
        }
    }
}

/// Parse scenario text (named `file` in messages). Returns the scene and the resolved
/// TOML text after overrides, which is what a run records for reproduction.
pub fn parse_str(
    file: &str,
    text: &str,
    overrides: &[String],
) -> Result<(SceneFile, String), InputError> {
    let mut table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| InputError::new(file, "", describe(&e, text)))?;
    for ov in overrides {
        apply_override(file, &mut table, ov)?;
    }
    let resolved = toml::to_string(&table).unwrap_or_default();
    // Spans point into the user's own file when there are no overrides.
    let src = if overrides.is_empty() {
        text
    } else {
        resolved.as_str()
    };
    let scene: SceneFile = toml::from_str(src).map_err(|e| {
        let mut key = error_key_from_text(&e, src);
        let mut msg = describe(&e, src);
        // `[check]` is a tagged enum, read through serde's buffer: its errors
        // point at the section. Re-read it as its kind's own struct for the key.
        if key == "check" {
            if let Some((k, m)) = table.get("check").and_then(CheckDef::key_error) {
                key = format!("check.{k}");
                msg = match e.span() {
                    Some(s) => format!("{m} (line {})", line_of(src, s.start)),
                    None => m,
                };
            }
        }
        // the keys a scan's figures are looked for under, first
        if matches!(
            key.as_str(),
            "laser.speed" | "laser.length" | "laser.hatch_spacing" | "laser.tracks"
        ) {
            msg.push_str(&format!(
                "; a scan's figures are given in a [scan] section: `scan.{}` (docs/scenario-format.md, [scan])",
                &key["laser.".len()..]
            ));
        }
        InputError::new(file, &key, msg)
    })?;
    Ok((scene, resolved))
}

fn line_of(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].matches('\n').count() + 1
}

fn describe(e: &toml::de::Error, text: &str) -> String {
    let msg = e.message().trim().to_string();
    match e.span() {
        Some(span) => format!("{msg} (line {})", line_of(text, span.start)),
        None => msg,
    }
}

fn error_key_from_text(e: &toml::de::Error, text: &str) -> String {
    let Some(span) = e.span() else {
        return String::new();
    };
    let upto = &text[..span.start.min(text.len())];
    let rest = &text[span.start.min(text.len())..];
    if let Some(header) = rest
        .lines()
        .next()
        .map(str::trim)
        .filter(|l| l.starts_with('['))
    {
        return header
            .trim_matches(|c| c == '[' || c == ']')
            .trim()
            .to_string();
    }
    let mut section = String::new();
    for line in upto.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            section = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
        }
    }
    let line = upto.rsplit('\n').next().unwrap_or("");
    let full_line = format!("{line}{}", rest.lines().next().unwrap_or(""));
    let key = full_line
        .split('=')
        .next()
        .unwrap_or("")
        .trim()
        .trim_matches('"');
    let key_ok = !key.is_empty() && !key.starts_with('[') && !key.contains(' ');
    match (section.is_empty(), key_ok) {
        (true, true) => key.to_string(),
        (false, true) => format!("{section}.{key}"),
        (false, false) => section,
        (true, false) => String::new(),
    }
}
