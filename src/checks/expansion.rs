//! Thermal expansion on δ-SPH (R18 §4.3.1): does each particle take the volume
//! its temperature asks for? A particle's own volume is V = m/ρ (the continuity
//! density), the volume it should have V_true = m/ρ0(T) (the density law at its
//! temperature); R18 measures V by Voronoi cells, which a particle method
//! without a mesh does not have, so the geometric side here is the region a
//! fluid fills (its centroid height in the column).
//!
//! - `thermal_expansion` (R18 Test 1, a load-free drop heated as a cycle): the
//!   mean |V − V_true|/V_true over the interior (r < 0.5 R) and over the band
//!   0.8 R < r < 0.9 R, R the radius of the drop's true volume, at every sample
//!   after `settle_time`; R18: below 0.4% and 0.8%, not growing.
//! - `rising_amplitude` (R18 Test 2, Test 1 with a growing amplitude): the
//!   density increase reached before the drop splits, against R18's 140%.
//! - `column_expansion` (R18 Test 3, a lower fluid whose ρ0 falls under a
//!   fluid of constant ρ0 in an open tank): the lower fluid's height, from its
//!   centroid, against the height its true volume fills over the tank's
//!   width; R18: volume error below 1%.

use super::{Check, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::{State, H_TEMPERATURE};

/// A particle's true volume m/ρ0(T) (the phase's ρ0 without a density law).
fn true_volume(m: &Model, st: &State, i: usize) -> f64 {
    let ph = &m.phases[st.phase[i] as usize];
    let t = if st.heat.is_empty() {
        0.0
    } else {
        st.heat[i][H_TEMPERATURE] as f64
    };
    st.mass[i] as f64 / ph.rho0_at(t)
}

fn fluid(m: &Model, st: &State, i: usize) -> bool {
    m.phases[st.phase[i] as usize].is_fluid()
}

/// A drop's volume errors at one state: the mean |m/ρ − m/ρ0(T)| / (m/ρ0(T))
/// over the interior (r < 0.5 R) and over the band 0.8 R < r < 0.9 R, R the
/// radius of the drop's true volume about its centroid; and the drop's mean
/// true density Σm / Σ m/ρ0(T).
struct VolumeErrors {
    interior: f64,
    band: f64,
    true_density: f64,
}

fn volume_errors(m: &Model, st: &State) -> VolumeErrors {
    let d = m.dim as usize;
    let idx: Vec<usize> = (0..st.active()).filter(|&i| fluid(m, st, i)).collect();
    let (mut volume, mut mass, mut centre) = (0.0, 0.0, [0.0f64; 3]);
    for &i in &idx {
        let v = true_volume(m, st, i);
        let x = m.to_world(st.pos[i]);
        volume += v;
        mass += st.mass[i] as f64;
        for a in 0..d {
            centre[a] += v * x[a];
        }
    }
    centre.iter_mut().for_each(|c| *c /= volume);
    let radius = if d == 2 {
        (volume / std::f64::consts::PI).sqrt()
    } else {
        (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt()
    };
    let (mut inner, mut band) = ((0.0, 0usize), (0.0, 0usize));
    for &i in &idx {
        let x = m.to_world(st.pos[i]);
        let r = (0..d)
            .map(|a| (x[a] - centre[a]).powi(2))
            .sum::<f64>()
            .sqrt()
            / radius;
        let vt = true_volume(m, st, i);
        let e = (st.mass[i] as f64 / st.rho[i] as f64 - vt).abs() / vt;
        if r < 0.5 {
            inner = (inner.0 + e, inner.1 + 1);
        } else if r > 0.8 && r < 0.9 {
            band = (band.0 + e, band.1 + 1);
        }
    }
    let mean = |s: (f64, usize)| if s.1 > 0 { s.0 / s.1 as f64 } else { f64::NAN };
    VolumeErrors {
        interior: mean(inner),
        band: mean(band),
        true_density: mass / volume,
    }
}

/// R18 Test 1: the volume error of the drop's interior and of its outer band.
pub struct ThermalExpansion {
    settle_time: f64,
    /// The band's tolerance (default twice the interior's: R18's 0.8% / 0.4%).
    band_tolerance: f64,
    /// (t, interior error, band error) per sample after the settle time.
    samples: Vec<(f64, f64, f64)>,
}

impl ThermalExpansion {
    pub fn new(settle_time: Option<f64>, band_tolerance: Option<f64>, tolerance: f64) -> Self {
        ThermalExpansion {
            settle_time: settle_time.unwrap_or(0.0),
            band_tolerance: band_tolerance.unwrap_or(2.0 * tolerance),
            samples: Vec::new(),
        }
    }
}

impl Check for ThermalExpansion {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        if t < self.settle_time || self.samples.last().is_some_and(|s| s.0 >= t) {
            return;
        }
        let e = volume_errors(m, st);
        self.samples.push((t, e.interior, e.band));
    }

    /// The worst interior error; infinite (FAIL) when the band exceeds its
    /// tolerance or the error grows: the worst of the run's last fifth above
    /// twice the worst of its first fifth after the settle time.
    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let metric = "largest mean volume error |m/ρ − m/ρ0(T)| / (m/ρ0(T)), r < 0.5 R".to_string();
        if self.samples.len() < 5 {
            return (
                metric,
                f64::NAN,
                vec!["  fewer than 5 samples after settle_time".into()],
            )
                .into();
        }
        let worst = |s: &[(f64, f64, f64)], k: usize| {
            s.iter()
                .map(|x| if k == 1 { x.1 } else { x.2 })
                .fold(0.0, f64::max)
        };
        let n = self.samples.len();
        let fifth = (n / 5).max(1);
        let (inner, band) = (worst(&self.samples, 1), worst(&self.samples, 2));
        let (early, late) = (
            worst(&self.samples[..fifth], 1),
            worst(&self.samples[n - fifth..], 1),
        );
        let mut details = vec![format!(
            "  {n} samples from t = {:.3} s: interior worst {:.3e}, band 0.8-0.9 R worst {:.3e} (tolerance {:.1e}); interior worst of the first / last fifth {:.3e} / {:.3e}",
            self.samples[0].0,
            inner,
            band,
            self.band_tolerance,
            early,
            late
        )];
        let mut value = inner;
        if !(band <= self.band_tolerance) {
            details.push("  the band 0.8 R < r < 0.9 R exceeds its tolerance".into());
            value = f64::INFINITY;
        }
        if !(late <= 2.0 * early) {
            details.push("  the interior error grows: the last fifth's worst is above twice the first fifth's".into());
            value = f64::INFINITY;
        }
        Verdict {
            metric,
            value,
            details,
            figures: vec![
                ("interior_error".into(), inner),
                ("band_error".into(), band),
                ("early_error".into(), early),
                ("late_error".into(), late),
            ],
        }
    }
}

/// R18 Test 2: the drop of Test 1 under a cycle whose amplitude grows (R18
/// raised α_T as 10 t / T_tot; here the program's `amplitude_rate` raises the
/// temperature swing, the same ρ0(t) for a linear law). Per sample: the volume
/// errors of Test 1, the drop's true density against its initial one (the
/// swing s = |ρ̄0/ρ̄0(0) − 1|), and whether the drop is still one piece (one
/// connected region at the kernel's support, crate::pool: pieces farther apart
/// no longer interact). It fails where
/// neighbours split apart (R18's words): at the first sample with more than one
/// region. The verdict is the shortfall of the density increase reached before
/// it, ρ_max/ρ_min − 1 over the samples before the failure, against R18's
/// "about 140%" (`swing` 0.41: 1.41 / 0.59 = 2.4), relative; the volume errors
/// up to that swing are reported beside it.
pub struct RisingAmplitude {
    settle_time: f64,
    swing: f64,
    rho_initial: Option<f64>,
    /// (t, interior error, band error, true density / initial, regions).
    samples: Vec<CycleSample>,
}

impl RisingAmplitude {
    pub fn new(settle_time: Option<f64>, swing: f64) -> Self {
        RisingAmplitude {
            settle_time: settle_time.unwrap_or(0.0),
            swing,
            rho_initial: None,
            samples: Vec::new(),
        }
    }
}

/// ρ_max/ρ_min − 1 of a swing of +c and −e.
fn density_ratio_increase(compression: f64, expansion: f64) -> f64 {
    (1.0 + compression) / (1.0 - expansion).max(f64::MIN_POSITIVE) - 1.0
}

impl Check for RisingAmplitude {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        if self.samples.last().is_some_and(|s| s.0 >= t) {
            return;
        }
        let e = volume_errors(m, st);
        let rho0 = *self.rho_initial.get_or_insert(e.true_density);
        let ratio = e.true_density / rho0;
        let pos: Vec<[f64; 3]> = (0..st.active())
            .filter(|&i| fluid(m, st, i))
            .map(|i| m.to_world(st.pos[i]))
            .collect();
        // Pieces that no longer interact: no pair within the kernel's support.
        let (_, regions) = crate::pool::connected_regions(&pos, m.support, m.dim);
        self.samples.push((t, e.interior, e.band, ratio, regions));
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let target = density_ratio_increase(self.swing, self.swing);
        let metric = format!(
            "shortfall of the density increase rho_max / rho_min - 1 reached before the drop splits, against R18's {:.0}%",
            100.0 * target
        );
        let counted: Vec<_> = self
            .samples
            .iter()
            .filter(|s| s.0 >= self.settle_time)
            .collect();
        if counted.len() < 5 {
            return (
                metric,
                f64::NAN,
                vec!["  fewer than 5 samples after settle_time".into()],
            )
                .into();
        }
        let fail = counted.iter().position(|s| s.4 > 1);
        let before = &counted[..fail.unwrap_or(counted.len())];
        let compression = before.iter().map(|s| s.3 - 1.0).fold(0.0, f64::max);
        let expansion = before.iter().map(|s| 1.0 - s.3).fold(0.0, f64::max);
        let reached = density_ratio_increase(compression, expansion);
        // Volume errors while the swing has stayed within `swing`.
        let upto = counted
            .iter()
            .position(|s| (s.3 - 1.0).abs() > self.swing)
            .unwrap_or(counted.len());
        let within = &counted[..upto.min(fail.unwrap_or(counted.len()))];
        let worst = |k: usize| {
            within
                .iter()
                .map(|s| if k == 1 { s.1 } else { s.2 })
                .fold(0.0, f64::max)
        };
        let fail_time = fail.map_or(f64::NAN, |k| counted[k].0);
        let mut details = per_cycle(&self.samples);
        details.push(format!(
            "  before the swing passed {:.0}% and the drop split ({} samples): interior volume error worst {:.3e}, band {:.3e}",
            100.0 * self.swing,
            within.len(),
            worst(1),
            worst(2)
        ));
        details.push(match fail {
            Some(k) => format!(
                "  split at t = {fail_time:.3} s into {} pieces: largest compression +{:.1}%, expansion -{:.1}% before it, rho_max / rho_min - 1 = {:.0}% (R18: about {:.0}%)",
                counted[k].4,
                100.0 * compression,
                100.0 * expansion,
                100.0 * reached,
                100.0 * target
            ),
            None => format!(
                "  one piece to the end: compression +{:.1}%, expansion -{:.1}%, rho_max / rho_min - 1 = {:.0}% (R18 split at about {:.0}%)",
                100.0 * compression,
                100.0 * expansion,
                100.0 * reached,
                100.0 * target
            ),
        });
        Verdict {
            metric,
            value: (1.0 - reached / target).max(0.0),
            details,
            figures: vec![
                ("density_ratio_increase".into(), reached),
                ("split_time".into(), fail_time),
                ("compression".into(), compression),
                ("expansion".into(), expansion),
                ("interior_error".into(), worst(1)),
                ("band_error".into(), worst(2)),
            ],
        }
    }
}

/// A sample of the rising-amplitude drop: time, swing, interior error, band
/// error, pieces.
type CycleSample = (f64, f64, f64, f64, usize);

/// One line per second of samples (a cycle of R18's program): the largest
/// swing and the worst interior and band errors.
fn per_cycle(samples: &[CycleSample]) -> Vec<String> {
    let mut lines = Vec::new();
    let end = samples.last().map_or(0.0, |s| s.0);
    let mut t0 = 0.0;
    while t0 < end {
        let part: Vec<_> = samples
            .iter()
            .filter(|s| s.0 > t0 && s.0 <= t0 + 1.0)
            .collect();
        if !part.is_empty() {
            let worst =
                |f: &dyn Fn(&CycleSample) -> f64| part.iter().map(|s| f(s)).fold(0.0, f64::max);
            lines.push(format!(
                "  t in ({t0:.0}, {:.0}] s: swing {:.1}%, interior {:.2e}, band {:.2e}, pieces up to {}",
                t0 + 1.0,
                100.0 * worst(&|s| (s.3 - 1.0).abs()),
                worst(&|s| s.1),
                worst(&|s| s.2),
                part.iter().map(|s| s.4).max().unwrap_or(0)
            ));
        }
        t0 += 1.0;
    }
    lines
}

/// R18 Test 3: each fluid's height in an open tank against its true volume.
pub struct ColumnExpansion {
    /// Tank width (m; per metre of depth in 2D, the face area in 3D: `area`).
    area: f64,
    /// (t, the lower fluid's height error, the upper fluid's) per sample.
    samples: Vec<(f64, f64, f64)>,
    /// The lower fluid's volume change m/ρ0(T) over the run (relative).
    expansion: f64,
    v0: Option<f64>,
}

impl ColumnExpansion {
    pub fn new(area: f64) -> Self {
        ColumnExpansion {
            area,
            samples: Vec::new(),
            expansion: 0.0,
            v0: None,
        }
    }
}

impl Check for ColumnExpansion {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        if self.samples.last().is_some_and(|s| s.0 >= t) {
            return;
        }
        let up = (0..3)
            .max_by(|&a, &b| m.gravity[a].abs().total_cmp(&m.gravity[b].abs()))
            .unwrap_or(1);
        // Per liquid phase: (phase, true volume, Σ height, count); heights from
        // the floor, half a spacing below the lowest liquid particle.
        let liquid: Vec<usize> = (0..st.active())
            .filter(|&i| m.phases[st.phase[i] as usize].kind == PhaseKind::Liquid)
            .collect();
        let height = |i: usize| m.to_world(st.pos[i])[up];
        let floor = liquid
            .iter()
            .map(|&i| height(i))
            .fold(f64::INFINITY, f64::min)
            - 0.5 * m.dx;
        let mut per: Vec<(usize, f64, f64, usize)> = Vec::new();
        for &i in &liquid {
            let p = st.phase[i] as usize;
            let (v, y) = (true_volume(m, st, i), height(i) - floor);
            match per.iter_mut().find(|e| e.0 == p) {
                Some(e) => {
                    e.1 += v;
                    e.2 += y;
                    e.3 += 1;
                }
                None => per.push((p, v, y, 1)),
            }
        }
        // (true volume, centroid height), lowest fluid first.
        let mut rows: Vec<(f64, f64)> = per.iter().map(|e| (e.1, e.2 / e.3 as f64)).collect();
        rows.sort_by(|a, b| a.1.total_cmp(&b.1));
        if rows.len() < 2 {
            return;
        }
        // The lower fluid fills [0, H1]: centroid H1/2. The upper fills [H1, H1 + H2].
        let h1 = rows[0].0 / self.area;
        let h2 = rows[1].0 / self.area;
        let lower = (2.0 * rows[0].1 - h1).abs() / h1;
        let upper = (2.0 * (rows[1].1 - h1) - h2).abs() / h2;
        let v0 = *self.v0.get_or_insert(rows[0].0);
        self.expansion = self.expansion.max((rows[0].0 - v0).abs() / v0);
        self.samples.push((t, lower, upper));
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let metric =
            "largest height error of the two fluids against their true volumes / width".to_string();
        if self.samples.is_empty() {
            return (metric, f64::NAN, vec!["  needs two liquid phases".into()]).into();
        }
        let worst = |k: usize| {
            self.samples
                .iter()
                .map(|s| (if k == 1 { s.1 } else { s.2 }, s.0))
                .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
        };
        let ((lower, t_lower), (upper, t_upper)) = (worst(1), worst(2));
        let details = vec![format!(
            "  {} samples: lower fluid worst {:.3e} (t = {:.3} s), upper fluid worst {:.3e} (t = {:.3} s); the lower fluid's true volume changed by up to {:.2}%",
            self.samples.len(),
            lower,
            t_lower,
            upper,
            t_upper,
            100.0 * self.expansion
        )];
        Verdict {
            metric,
            value: lower.max(upper),
            details,
            figures: vec![
                ("lower_error".into(), lower),
                ("upper_error".into(), upper),
                ("expansion".into(), self.expansion),
            ],
        }
    }
}
