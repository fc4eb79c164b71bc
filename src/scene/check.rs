//! `[check]`: a scene's reference solution or measurement. `kind` picks the
//! check and, with it, the struct its other keys deserialise into (a
//! serde-tagged enum: a key another kind reads is an unknown key here). What
//! each kind needs from the rest of the scene is model/check_inputs.rs; the
//! verdicts are crate::checks.

use serde::Deserialize;

/// The check kinds: for each, its variant, the struct of its keys and its name
/// in scenario files. Generates `CheckKind` (the bare kind, for outputs and
/// matching), `CheckDef` (the tagged enum a `[check]` deserialises into) and
/// their accessors.
macro_rules! check_kinds {
    ($( $(#[$doc:meta])* $variant:ident($def:ty) = $name:literal, )*) => {
        /// The kind of a scene's check (`check.kind`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum CheckKind { $( $(#[$doc])* $variant, )* }

        impl CheckKind {
            /// Every kind, in the order above.
            pub const ALL: &'static [CheckKind] = &[$(CheckKind::$variant,)*];
            /// The name as written in scenario files.
            pub fn name(self) -> &'static str {
                match self { $( CheckKind::$variant => $name, )* }
            }
        }

        /// A scene's `[check]`: `kind` and that kind's own keys.
        #[derive(Debug, Clone, Deserialize)]
        #[serde(tag = "kind")]
        pub enum CheckDef { $( #[serde(rename = $name)] $variant($def), )* }

        impl CheckDef {
            pub fn kind(&self) -> CheckKind {
                match self { $( CheckDef::$variant(_) => CheckKind::$variant, )* }
            }
            /// `check.tolerance`, which every kind takes.
            pub fn tolerance(&self) -> f64 {
                match self { $( CheckDef::$variant(d) => d.tolerance, )* }
            }
            /// A `[check]` table that did not deserialise, re-read as its
            /// kind's own struct (serde's tagged-enum buffer drops the
            /// spans): the key at fault and the message. None when the kind
            /// itself is unknown.
            pub(super) fn key_error(check: &toml::Value) -> Option<(String, String)> {
                let mut rest = check.as_table()?.clone();
                let kind = rest.remove("kind")?;
                let text = toml::to_string(&rest).ok()?;
                let e = match kind.as_str()? {
                    $( $name => toml::from_str::<$def>(&text).err(), )*
                    _ => None,
                }?;
                Some((field_of(&e, &text)?, e.message().trim().to_string()))
            }
        }
    };
}

/// The key an error of a lone check table is about: the line its span
/// starts on, else the field a serde message names in backquotes.
fn field_of(e: &toml::de::Error, text: &str) -> Option<String> {
    let named = e.message().split('`').nth(1).map(str::to_string);
    if e.message().starts_with("missing field") {
        return named;
    }
    let from_span = e.span().and_then(|s| {
        let upto = &text[..s.start.min(text.len())];
        let line = text[s.start.min(text.len())..].lines().next()?;
        let head = upto.rsplit('\n').next().unwrap_or("");
        let key = format!("{head}{line}");
        let key = key.split('=').next()?.trim().trim_matches('"').to_string();
        if key.is_empty() || key.contains([' ', '[']) {
            return None;
        }
        // inside a sub-table ([measured]): its name before the key
        let table = upto
            .lines()
            .map(str::trim)
            .rfind(|l| l.starts_with('['))
            .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
        Some(match table {
            Some(t) => format!("{t}.{key}"),
            None => key,
        })
    });
    from_span.or(named)
}

check_kinds! {
    /// Hydrostatic pressure below a free surface at `surface`.
    Hydrostatic(HydrostaticCheck) = "hydrostatic",
    /// Channel flow driven by a body force: the velocity profile.
    Poiseuille(Tolerance) = "poiseuille",
    /// Shear flow between a moving and a fixed wall: the velocity profile.
    Couette(Tolerance) = "couette",
    /// A column collapsing: its surge front against the experiment's.
    DamBreakFront(DamBreakCheck) = "dam_break_front",
    /// Two immiscible layers at rest keep their colours apart.
    TwoLayer(Tolerance) = "two_layer",
    /// Semi-infinite solid, surface held at a fixed temperature: erf solution.
    Conduction1d(Tolerance) = "conduction_1d",
    /// Steady conduction through two layers between two Dirichlet walls, the
    /// interface at `surface`.
    ConductionTwoMaterials(SurfaceCheck) = "conduction_two_materials",
    /// Closed adiabatic box: total enthalpy constant.
    Adiabatic(Tolerance) = "adiabatic",
    /// One-phase Stefan problem: melting front s(t) = 2λ√(α t).
    Stefan1d(Tolerance) = "stefan_1d",
    /// Two-phase Stefan (Neumann) solidification from a cold wall: the
    /// solidification record's G and R against the front's gradient and speed.
    SolidificationFront(Tolerance) = "solidification_front",
    /// Energy balance with a laser: enthalpy gained = ζ ∫P dt − energy lost
    /// through Dirichlet walls (none in an insulated scene).
    LaserEnergy(Tolerance) = "laser_energy",
    /// Quasi-steady temperature around a moving source on a plate (Rosenthal).
    Rosenthal(Tolerance) = "rosenthal",
    /// Weak compressibility: the largest (ρ − ρ0)/ρ0 of any liquid particle at
    /// any sample, the cost side of a WCSPH sound speed (c ≥ 10 u_max aims at
    /// about 1%).
    Compression(Tolerance) = "compression",
    /// Pressure jump across a drop's surface against Laplace's σ/R (2D), 2σ/R (3D).
    Laplace(LaplaceCheck) = "laplace",
    /// Momentum a free layer gains from the recoil pressure against −∫ p_v A dt.
    RecoilImpulse(AreaCheck) = "recoil_impulse",
    /// A 2D drop (a square at the start) relaxed to a disc: the spread of its
    /// outline's radius over 32 sectors, in Δx.
    DropShape(Tolerance) = "drop_shape",
    /// A 2D sessile drop on the y_min wall settles at its static contact angle.
    ContactAngle(Tolerance) = "contact_angle",
    /// Marangoni flow in a two-layer channel over a wall heated as a cosine
    /// (Pendse & Esmaeeli 2010): the interface velocity against the Stokes
    /// solution; the interface at `surface`.
    Thermocapillary(SurfaceCheck) = "thermocapillary",
    /// Two rigid bodies collide head-on: the coefficient of restitution against
    /// the spring–dashpot's analytic value.
    Restitution(Tolerance) = "restitution",
    /// A free rigid body: angular momentum and energy conserved, the
    /// intermediate-axis flip.
    FreeRotation(FreeRotationCheck) = "free_rotation",
    /// A body lighter than the liquid floats with the immersed depth Archimedes
    /// gives.
    Flotation(Tolerance) = "flotation",
    /// Bodies at rest (a poured bed under gravity) stay at rest.
    BedAtRest(SettleCheck) = "bed_at_rest",
    /// A grain dropped into a melt melts completely, conserving mass and momentum.
    MeltingGrain(Tolerance) = "melting_grain",
    /// A 2D disc settling midway between two walls reaches Faxén's terminal velocity.
    Settling(SettleCheck) = "settling",
    /// R18 Test 1: a load-free drop under a thermal cycle takes the volume its
    /// density law asks for (each particle's m/ρ against m/ρ0(T)).
    ThermalExpansion(ThermalExpansionCheck) = "thermal_expansion",
    /// R18 Test 2: Test 1 with an amplitude that grows; the density increase
    /// reached before the drop splits, against R18's.
    RisingAmplitude(RisingAmplitudeCheck) = "rising_amplitude",
    /// R18 Test 3: two fluids in an open tank, the lower one expanding: each
    /// fluid's height against its true volume over the tank's width (`area`).
    ColumnExpansion(AreaCheck) = "column_expansion",
    /// R18 Test 4: the RMS departure of interior pressures from their local
    /// smooth mean, relative to ρ_l g H (checks/noise.rs).
    PressureNoise(SettleCheck) = "pressure_noise",
    /// R18 §5.1.1: a 2D powder-bed track's substrate penetration, peak
    /// temperature and speed beside R18's Table 5.3 at the run's power.
    R18Track(R18TrackCheck) = "r18_track",
    /// J22 §4.1: a droplet's impact, mean vertical velocity through zero and
    /// stop against J22's Fluent comparison; splat diameter and height.
    Splat(SplatCheck) = "splat",
    /// A 3D droplet landing on a flat wall: the peak of the wall force (the
    /// droplet's rate of change of momentum) against 0.8 ρV²D² (inertial regime).
    ImpactForce(ImpactForceCheck) = "impact_force",
    /// F22 §4.3: the deepest substrate remelt under a molten drop against a
    /// reference depth (`depth`).
    Remelt(RemeltCheck) = "remelt",
    /// F22 §4.3, two and three drops: the share of the first drop that is
    /// solid (or liquid: `fraction`) when the second first touches it.
    DropContact(DropContactCheck) = "drop_contact",
    /// F22 §4.5, PBF point melting: peak temperature above T_v, a depression
    /// deeper than a quarter of its width while the beam is on, an ejected
    /// grain, an indentation below the plate's top after solidification.
    PointMelt(Tolerance) = "point_melt",
    /// F22 §4.4, directed energy deposition: the first grain's arrival, the
    /// pool's diameter at a time, grains left not fully molten.
    Deposition(DepositionCheck) = "deposition",
    /// F22 §4.2, binder jetting: the binder's penetration into the bed and
    /// its spread against a slower drop's, binder at the walls, ejected grains.
    Binder(BinderCheck) = "binder",
    /// A laser track's melt pool (width, depth, length) against a measured one
    /// (`[check.measured]`); counts the figures outside their tolerance.
    MeasuredTrack(MeasuredTrackCheck) = "measured_track",
}

/// A check whose only key is its tolerance.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tolerance {
    pub tolerance: f64,
}

/// `hydrostatic`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HydrostaticCheck {
    pub tolerance: f64,
    /// The initial free-surface height (m).
    pub surface: f64,
    /// Particles closer than this to the free surface are left out (m;
    /// default 3h).
    pub exclude_depth: Option<f64>,
}

/// `dam_break_front`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamBreakCheck {
    pub tolerance: f64,
    /// The initial column width L (m).
    pub column_width: f64,
    /// The experiment the metric compares with (default Koshizuka & Oka).
    #[serde(default)]
    pub experiment: DamBreakExperiment,
}

/// `conduction_two_materials`, `thermocapillary`: a height along y.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceCheck {
    pub tolerance: f64,
    /// The interface's height (m).
    pub surface: f64,
}

/// `laplace`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaplaceCheck {
    pub tolerance: f64,
    /// The drop's centre and radius (m).
    pub center: Vec<f64>,
    pub radius: f64,
}

/// `recoil_impulse`, `column_expansion`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaCheck {
    pub tolerance: f64,
    /// Recoil impulse: the hot surface's area (m², m per metre of depth in 2D).
    /// Column expansion: the tank's cross-section (its width in 2D).
    pub area: f64,
}

/// `free_rotation`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FreeRotationCheck {
    pub tolerance: f64,
    /// The largest relative change of the rotational energy.
    pub energy_tolerance: f64,
}

/// `bed_at_rest`, `settling`, `pressure_noise`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettleCheck {
    pub tolerance: f64,
    /// Bed at rest: the time (s) after which no body may move (default: half
    /// the run). Settling: the time after which the fall speed is averaged.
    /// Pressure noise: the time after which samples count.
    pub settle_time: Option<f64>,
}

/// `thermal_expansion`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThermalExpansionCheck {
    pub tolerance: f64,
    /// The time after which samples count (s).
    pub settle_time: Option<f64>,
    /// The mean volume error allowed in the band 0.8 R < r < 0.9 R (default
    /// twice `tolerance`, R18's 0.8% against 0.4%).
    pub band_tolerance: Option<f64>,
}

/// `rising_amplitude`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RisingAmplitudeCheck {
    pub tolerance: f64,
    /// The time after which samples count (s).
    pub settle_time: Option<f64>,
    /// R18's swing of the drop's true density |ρ̄0/ρ̄0(0) − 1| at failure
    /// (default 0.41: R18 Test 2 split at a 140% density increase, 1.41 / 0.59
    /// = 2.4).
    pub swing: Option<f64>,
}

/// `r18_track`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct R18TrackCheck {
    pub tolerance: f64,
    /// The plate's initial top (m).
    pub surface: f64,
    /// The depth (m) a 2D slice stands for, so that R18's watts are the power
    /// per metre times it.
    pub r18_slice_depth: f64,
}

/// `splat`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SplatCheck {
    pub tolerance: f64,
    /// The droplet's phase (default: every liquid phase), for scenes whose
    /// substrate is a liquid phase too (J22 §4.2).
    pub phase: Option<String>,
    /// A reference spread factor D/D0 of the splat at the run's end (J22 §4.2
    /// measured its splats after 2 µs). With it the verdict is the relative
    /// departure from it, not J22's Fluent-case timings.
    pub spread_factor: Option<f64>,
}

/// `impact_force`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactForceCheck {
    pub tolerance: f64,
    /// The droplet's phase (default: every liquid phase).
    pub phase: Option<String>,
}

/// `remelt`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RemeltCheck {
    pub tolerance: f64,
    /// The reference remelt depth (m; F22 §4.3).
    pub depth: f64,
}

/// `drop_contact`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DropContactCheck {
    pub tolerance: f64,
    /// The first drop's share measured when the second touches it, "solid"
    /// (default) or "liquid"; the tolerance bounds it from above.
    #[serde(default)]
    pub fraction: DropFraction,
}

/// `deposition`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepositionCheck {
    pub tolerance: f64,
    /// The first grain's reference arrival at the substrate (s).
    pub arrival: Option<f64>,
    /// The reference pool diameter (m) at `diameter_time` (s), within
    /// `diameter_tolerance` (relative, default 0.1).
    pub diameter: Option<f64>,
    pub diameter_time: Option<f64>,
    pub diameter_tolerance: Option<f64>,
    /// At least one grain must be left not fully molten.
    pub unmolten: Option<bool>,
}

/// `binder`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BinderCheck {
    pub tolerance: f64,
    /// The penetration (m) must end below this and the spread width above
    /// that (a slower drop's figures: F22's order).
    pub penetration_below: Option<f64>,
    pub spread_above: Option<f64>,
    /// The binder must reach a side wall.
    pub reaches_walls: Option<bool>,
    /// At least this many grains must be ejected.
    pub ejected: Option<usize>,
    /// The binder must still move down at the end.
    pub sinking: Option<bool>,
}

/// `measured_track`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredTrackCheck {
    pub tolerance: f64,
    /// The measured melt-pool figures and where the track is steady.
    pub measured: MeasuredTrackDef,
}

/// `[check.measured]` of `measured_track`: a laser track's melt pool as
/// measured (width and depth from cross-sections of the solidified track,
/// length from thermography of the moving pool), each with its tolerance.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredTrackDef {
    /// m.
    pub width: f64,
    pub depth: f64,
    pub length: f64,
    /// [x0, x1] (m): the track's steady part, where width and depth are
    /// averaged over the slices and the pool's length over the samples with the
    /// beam centre inside it.
    pub steady: Vec<f64>,
    /// Relative tolerance of width and depth (default 0.10).
    pub width_depth_tolerance: Option<f64>,
    /// Relative tolerance of the length (default 0.20: thermography's
    /// emissivity makes it the least certain).
    pub length_tolerance: Option<f64>,
}

impl MeasuredTrackDef {
    pub const WIDTH_DEPTH_TOLERANCE: f64 = 0.10;
    pub const LENGTH_TOLERANCE: f64 = 0.20;
    /// Its own keys' validation (exit 2 naming the key).
    pub fn validate(&self, file: &str, dim: u32) -> Result<(), crate::error::InputError> {
        let err = |k: &str, m: String| {
            crate::error::InputError::new(file, &format!("check.measured.{k}"), m)
        };
        for (k, v) in [
            ("width", self.width),
            ("depth", self.depth),
            ("length", self.length),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(err(k, format!("must be a positive length in m (got {v})")));
            }
        }
        if dim != 3 {
            return Err(err(
                "width",
                "a measured track's width needs a 3D scene".into(),
            ));
        }
        if self.steady.len() != 2 || !(self.steady[0] < self.steady[1]) {
            return Err(err("steady", "expected [x0, x1] with x0 < x1 (m)".into()));
        }
        for (k, v) in [
            ("width_depth_tolerance", self.width_depth_tolerance),
            ("length_tolerance", self.length_tolerance),
        ] {
            if let Some(t) = v {
                if !(t.is_finite() && t > 0.0 && t < 1.0) {
                    return Err(err(k, format!("a relative tolerance in (0, 1) (got {t})")));
                }
            }
        }
        Ok(())
    }
}

/// Surge-front data for a column of width L and height 2L (checks/dam_break.rs holds the tables).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DamBreakExperiment {
    /// Koshizuka & Oka (1996), L = 0.146 m.
    #[default]
    KoshizukaOka,
    /// Martin & Moyce (1952), n² = 2, a = 2.25 in.
    MartinMoyce,
}

/// `check.fraction` of `drop_contact`: which share of the first drop it measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DropFraction {
    #[default]
    Solid,
    Liquid,
}
