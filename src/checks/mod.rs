//! Validation checks against reference solutions (docs/validation.md). A scene's `[check]`
//! section picks one; the run feeds it state samples and prints its verdict.
//!
//! One file per kind, each a `Check`: flow.rs (hydrostatic pressure, Poiseuille
//! and Couette profiles), dam_break.rs (surge front against the experiments),
//! two_layer.rs (liquid under gas), compression.rs (liquid density), heat.rs
//! (conduction, two materials, adiabatic box, Stefan, Rosenthal, laser energy),
//! tension.rs (Laplace, recoil impulse, drop shape, contact angle),
//! thermocapillary.rs (Marangoni flow in a two-layer channel), bodies.rs (rigid
//! bodies: restitution, free rotation, flotation, a bed at rest, a melting grain),
//! expansion.rs (δ-SPH thermal expansion: R18 Tests 1, 2 and 3), noise.rs (pressure
//! noise: R18 Test 4), track.rs (R18 §5.1.1's 2D powder-bed track), splat.rs
//! (J22's droplet impact timings and splat size), remelt.rs (F22 §4.3: a
//! drop's remelt of its substrate), drops.rs (F22 §4.3: drops on drops),
//! point_melt.rs (F22 §4.5: PBF point melting's keyhole, ejections,
//! indentation), deposition.rs (F22 §4.4: grains flying into a laser pool),
//! binder.rs (F22 §4.2: a binder drop into a powder bed), measured_track.rs (a
//! laser track's melt pool against a measured one: NIST AM-Bench AMB2018-02).

mod binder;
mod bodies;
mod compression;
mod dam_break;
mod deposition;
mod drops;
mod expansion;
mod flow;
mod heat;
mod impact;
mod measured_track;
mod noise;
mod point_melt;
mod remelt;
mod solidification;
mod splat;
mod tension;
pub mod thermocapillary;
mod track;
mod two_layer;

pub use dam_break::{fit_release_delay, ReleaseDelayFit};

use crate::model::Model;
use crate::scene::{CheckDef, CheckKind, PhaseKind};
use crate::state::State;

pub struct CheckResult {
    pub name: String,
    pub metric: String,
    pub value: f64,
    pub tolerance: f64,
    pub pass: bool,
    /// Extra lines (e.g. sampled values) printed before the verdict.
    pub details: Vec<String>,
    /// Named secondary figures a check measures besides its verdict (e.g. the dam
    /// break's fitted release delay), for tests and scripts.
    pub figures: Vec<(String, f64)>,
    /// The observables the check followed over the samples, where it keeps them.
    pub series: Option<Series>,
}

/// A check's observables per sample: named columns, one row per sample (the
/// first column is the time, s).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Series {
    pub columns: Vec<&'static str>,
    pub rows: Vec<Vec<f64>>,
}

/// The `/check` message: the verdict, its figures and the series, written to
/// the MCAP stream at the end of a completed run.
#[derive(serde::Serialize)]
pub struct CheckMessage<'a> {
    pub kind: &'a str,
    pub metric: &'a str,
    pub value: f64,
    pub tolerance: f64,
    pub pass: bool,
    pub figures: std::collections::BTreeMap<&'a str, f64>,
    pub series: Option<&'a Series>,
}

impl CheckResult {
    pub fn message(&self) -> CheckMessage<'_> {
        CheckMessage {
            kind: &self.name,
            metric: &self.metric,
            value: self.value,
            tolerance: self.tolerance,
            pass: self.pass,
            figures: self.figures.iter().map(|(k, v)| (k.as_str(), *v)).collect(),
            series: self.series.as_ref(),
        }
    }

    pub fn line(&self) -> String {
        format!(
            "check {}: {} = {:.4e} (tolerance {:.4e}) {}",
            self.name,
            self.metric,
            self.value,
            self.tolerance,
            if self.pass { "PASS" } else { "FAIL" }
        )
    }
}

/// What a check concludes: its metric and value (held against the scene's
/// tolerance), lines printed before the verdict, and named secondary figures.
pub struct Verdict {
    pub metric: String,
    pub value: f64,
    pub details: Vec<String>,
    pub figures: Vec<(String, f64)>,
}

impl From<(String, f64, Vec<String>)> for Verdict {
    fn from((metric, value, details): (String, f64, Vec<String>)) -> Self {
        Verdict {
            metric,
            value,
            details,
            figures: Vec::new(),
        }
    }
}

/// One kind of validation check.
pub trait Check {
    /// A state sample during the run (every output frame, and the final state).
    fn observe(&mut self, _m: &Model, _st: &State) {}
    /// The verdict on the final state and the samples seen.
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict;
    /// The observables followed over the samples (for the `/check` message).
    fn series(&self) -> Option<Series> {
        None
    }
    /// Sample at every diagnostics record too, not only at frames (events
    /// closer together than the frames are).
    fn every_sample(&self) -> bool {
        false
    }
}

/// The scene's check, watching the run: `observe` at every sample, `finish` at the end.
pub struct Checker {
    kind: CheckKind,
    tolerance: f64,
    check: Box<dyn Check>,
}

impl Checker {
    pub fn new(m: &Model) -> Option<Checker> {
        m.check.as_ref().map(|c| Checker {
            kind: c.kind(),
            tolerance: c.tolerance(),
            check: make(m, c),
        })
    }

    pub fn observe(&mut self, m: &Model, st: &State) {
        self.check.observe(m, st);
    }

    /// Does the check sample every diagnostics record (not only frames)?
    pub fn every_sample(&self) -> bool {
        self.check.every_sample()
    }

    pub fn finish(&mut self, m: &Model, st: &State) -> CheckResult {
        self.check.observe(m, st);
        let v = self.check.verdict(m, st);
        CheckResult {
            name: self.kind.name().into(),
            metric: v.metric,
            value: v.value,
            tolerance: self.tolerance,
            pass: v.value.is_finite() && v.value <= self.tolerance,
            details: v.details,
            figures: v.figures,
            series: self.check.series(),
        }
    }
}

/// The check a `[check]` section asks for, built from its kind's keys.
fn make(m: &Model, c: &CheckDef) -> Box<dyn Check> {
    use CheckDef as D;
    match c {
        D::Hydrostatic(d) => Box::new(flow::Hydrostatic {
            surface: d.surface,
            exclude: d.exclude_depth.unwrap_or(3.0 * m.h),
        }),
        D::Poiseuille(_) => Box::new(flow::Profile::Poiseuille),
        D::Couette(_) => Box::new(flow::Profile::Couette),
        D::DamBreakFront(d) => Box::new(dam_break::DamBreak::new(d.column_width, d.experiment)),
        D::TwoLayer(_) => Box::new(two_layer::TwoLayer::default()),
        D::Compression(_) => Box::new(compression::Compression::default()),
        D::Laplace(d) => Box::new(tension::Laplace::new(m, d)),
        D::RecoilImpulse(d) => Box::new(tension::RecoilImpulse::new(d.area)),
        D::DropShape(_) => Box::new(tension::DropShape::default()),
        D::ContactAngle(_) => Box::new(tension::ContactAngle::default()),
        D::Thermocapillary(d) => Box::new(thermocapillary::Thermocapillary::new(d.surface)),
        D::Conduction1d(_) => Box::new(heat::Conduction1d),
        D::ConductionTwoMaterials(d) => Box::new(heat::TwoMaterials {
            interface: d.surface,
        }),
        D::Adiabatic(_) => Box::new(heat::Adiabatic::default()),
        D::Stefan1d(_) => Box::new(heat::Stefan::default()),
        D::SolidificationFront(_) => Box::new(solidification::Front),
        D::Rosenthal(_) => Box::new(heat::Rosenthal),
        D::LaserEnergy(_) => Box::new(heat::LaserEnergy::default()),
        D::Restitution(_) => Box::new(bodies::Restitution),
        D::Flotation(_) => Box::new(bodies::Flotation),
        D::BedAtRest(d) => Box::new(bodies::AtRest::new(d.settle_time)),
        D::MeltingGrain(_) => Box::new(bodies::MeltingGrain::default()),
        D::Settling(d) => Box::new(bodies::Settling::new(d.settle_time)),
        D::ThermalExpansion(d) => Box::new(expansion::ThermalExpansion::new(
            d.settle_time,
            d.band_tolerance,
            d.tolerance,
        )),
        D::RisingAmplitude(d) => Box::new(expansion::RisingAmplitude::new(
            d.settle_time,
            d.swing.unwrap_or(0.41),
        )),
        D::ColumnExpansion(d) => Box::new(expansion::ColumnExpansion::new(d.area)),
        D::PressureNoise(d) => Box::new(noise::PressureNoise::new(d.settle_time)),
        D::R18Track(d) => Box::new(track::R18Track::new(d.surface, d.r18_slice_depth)),
        D::Splat(d) => Box::new(splat::Splat::new(m, d.phase.as_deref(), d.spread_factor)),
        D::ImpactForce(d) => Box::new(impact::ImpactForce::new(m, d.phase.as_deref())),
        D::Remelt(d) => Box::new(remelt::Remelt::new(d.depth)),
        D::DropContact(d) => Box::new(drops::DropContact::new(d.fraction)),
        D::PointMelt(_) => Box::new(point_melt::PointMelt::new()),
        D::Deposition(d) => Box::new(deposition::Deposition::new(d)),
        D::Binder(d) => Box::new(binder::Binder::new(d)),
        D::MeasuredTrack(d) => Box::new(measured_track::MeasuredTrack::new(&d.measured)),
        D::FreeRotation(d) => Box::new(bodies::FreeRotation::new(d.energy_tolerance)),
    }
}

/// Particle in absolute coordinates with its phase kind.
pub(super) struct P {
    pub x: [f64; 3],
    pub v: [f64; 3],
    p: f64,
    kind: PhaseKind,
}

/// The particles still in the simulation (those that left are not sampled).
pub(super) fn particles<'a>(m: &'a Model, st: &'a State) -> impl Iterator<Item = P> + 'a {
    (0..st.active()).map(move |i| {
        let v = st.vel[i];
        P {
            x: m.to_world(st.pos[i]),
            v: [v[0] as f64, v[1] as f64, v[2] as f64],
            p: st.press[i] as f64,
            kind: m.phases[st.phase[i] as usize].kind,
        }
    })
}

pub(super) fn g_mag(m: &Model) -> f64 {
    m.gravity.iter().map(|g| g * g).sum::<f64>().sqrt()
}

pub(super) fn liquid_rho0(m: &Model) -> f64 {
    m.phases
        .iter()
        .find(|p| p.kind == PhaseKind::Liquid)
        .map(|p| p.rho0)
        .unwrap_or(1.0)
}

pub(super) fn linear_fit_at_zero(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    if n < 2.0 {
        return f64::NAN;
    }
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (sxx, sxy) = pts.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + (p.0 - mx) * (p.0 - mx), a.1 + (p.0 - mx) * (p.1 - my))
    });
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    my - slope * mx
}

/// Linear interpolation in a table sorted by x, held at the end values outside it.
/// Repeated x (a run's final state is observed twice) are skipped.
pub(super) fn interpolate(table: &[(f64, f64)], x: f64) -> f64 {
    if x <= table[0].0 {
        return table[0].1;
    }
    for w in table.windows(2) {
        if x <= w[1].0 && w[1].0 > w[0].0 {
            let f = (x - w[0].0) / (w[1].0 - w[0].0);
            return w[0].1 + f * (w[1].1 - w[0].1);
        }
    }
    table[table.len() - 1].1
}
