//! Dam-break surge front against Koshizuka & Oka (1996) and Martin & Moyce (1952),
//! with the release delay that best aligns the run with each experiment.

use super::{g_mag, interpolate, particles, Check, Verdict};
use crate::model::Model;
use crate::scene::{DamBreakExperiment, PhaseKind};
use crate::state::State;

/// Front position (m) per sample time, for a column of width `width`.
pub struct DamBreak {
    width: f64,
    experiment: DamBreakExperiment,
    samples: Vec<(f64, f64)>,
}

impl DamBreak {
    pub fn new(width: f64, experiment: DamBreakExperiment) -> Self {
        DamBreak {
            width,
            experiment,
            samples: Vec::new(),
        }
    }
}

impl Check for DamBreak {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        let front = particles(m, st)
            .filter(|p| p.kind == PhaseKind::Liquid)
            .map(|p| p.x[0])
            .fold(f64::MIN, f64::max);
        self.samples.push((t, front + 0.5 * m.dx));
    }

    fn verdict(&mut self, m: &Model, _st: &State) -> Verdict {
        let (width, experiment) = (self.width, self.experiment);
        let mut figures = Vec::new();
        let Experiment { table, name, .. } = Experiment::of(experiment);
        let scale = (2.0 * g_mag(m) / width).sqrt();
        let mut worst: f64 = 0.0;
        let mut details = Vec::new();
        let mut used = 0;
        for &(t, front) in &self.samples {
            let tt = t * scale;
            // From the first data point of either experiment to T = 2.5.
            if !(table[1].0..=DAM_BREAK_T_MAX).contains(&tt) {
                continue;
            }
            let z = (front - m.domain_lo[0]) / width;
            let zr = interpolate(table, tt);
            let e = (z - zr).abs() / zr;
            worst = worst.max(e);
            used += 1;
            // Both experiments on every line, so the two can be compared.
            let (ko, mm) = (
                interpolate(&KOSHIZUKA_OKA, tt),
                interpolate(&MARTIN_MOYCE, tt),
            );
            details.push(format!(
                "  T = {tt:.3}: Z = {z:.3}, Koshizuka-Oka {ko:.3} ({:+.1}%), Martin-Moyce {mm:.3} ({:+.1}%)",
                100.0 * (z - ko) / ko,
                100.0 * (z - mm) / mm
            ));
        }
        if used == 0 {
            worst = f64::NAN;
            details.push(format!(
                "  no sample with {} <= T <= {DAM_BREAK_T_MAX}; run longer",
                table[1].0
            ));
        } else {
            let run: Vec<(f64, f64)> = self
                .samples
                .iter()
                .map(|&(t, front)| (t * scale, (front - m.domain_lo[0]) / width))
                .collect();
            for exp in [
                DamBreakExperiment::KoshizukaOka,
                DamBreakExperiment::MartinMoyce,
            ] {
                release_delay_line(&run, exp, &mut details, &mut figures);
            }
        }
        Verdict {
            metric: format!("max relative surge-front error vs {name}"),
            value: worst,
            details,
            figures,
        }
    }
}

/// Latest T of the experiments' points the dam-break check compares with.
const DAM_BREAK_T_MAX: f64 = 2.5;
/// Release delays tried by the fit, in units of T: 0 to 0.5 (0 to 43 ms in Koshizuka
/// & Oka's column, 0 to 27 ms in Martin & Moyce's) by 0.0025.
const DELAY_STEP: f64 = 0.0025;
const DELAY_STEPS: usize = 200;

/// The run against one experiment once the experiment's clock is allowed to start
/// early: Z_run(T − ΔT) against Z_data(T). In the experiments whatever held the
/// column had to be removed before it could fall, and the data carry no record of
/// how long that took, while the run releases the column at t = 0. A front that moves
/// as in the experiment but starts late is matched by one delay; a front that moves
/// at the wrong speed is not matched by any.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReleaseDelayFit {
    /// ΔT that gives the smallest worst relative error (the first such on the grid).
    pub delay: f64,
    /// Worst |Z_run(T − ΔT) − Z_data| / Z_data over the points, at that delay.
    pub error: f64,
    /// The same with ΔT = 0, at the data points themselves.
    pub unshifted: f64,
    /// Data points compared: those with 0 < T ≤ `t_max`.
    pub points: usize,
}

/// Fits the release delay of `run` (T, Z), sorted by T and starting at the release,
/// to the experiment's points `data` with 0 < T ≤ `t_max`. Before the run's first
/// sample the column is at rest (`interpolate` holds the first Z). None when no
/// point lies in range or the run ends before the last of them.
pub fn fit_release_delay(
    run: &[(f64, f64)],
    data: &[(f64, f64)],
    t_max: f64,
) -> Option<ReleaseDelayFit> {
    let points: Vec<(f64, f64)> = data
        .iter()
        .copied()
        .filter(|&(t, _)| t > 0.0 && t <= t_max)
        .collect();
    let last = points.last()?.0;
    if run.last()?.0 < last {
        return None;
    }
    let worst = |delay: f64| {
        points
            .iter()
            .map(|&(t, z)| (interpolate(run, t - delay) - z).abs() / z)
            .fold(0.0, f64::max)
    };
    let unshifted = worst(0.0);
    let (mut delay, mut error) = (0.0, unshifted);
    for k in 1..=DELAY_STEPS {
        let d = k as f64 * DELAY_STEP;
        let e = worst(d);
        if e < error {
            (delay, error) = (d, e);
        }
    }
    Some(ReleaseDelayFit {
        delay,
        error,
        unshifted,
        points: points.len(),
    })
}

/// One details line (and two figures) for the fitted release delay against `exp`.
fn release_delay_line(
    run: &[(f64, f64)],
    exp: DamBreakExperiment,
    details: &mut Vec<String>,
    figures: &mut Vec<(String, f64)>,
) {
    let Experiment {
        table,
        name,
        key,
        width,
    } = Experiment::of(exp);
    let Some(f) = fit_release_delay(run, table, DAM_BREAK_T_MAX) else {
        return;
    };
    // The delay in the experiment's own seconds: T = t sqrt(2g/a) with its a and
    // the laboratory's g.
    let ms = 1e3 * f.delay * (width / (2.0 * 9.81)).sqrt();
    details.push(format!(
        "  release delay fit vs {name} ({} points, T <= {DAM_BREAK_T_MAX}): best ΔT = {:.3} \
         ({ms:.0} ms in its {:.0} mm column), within {:.1}% (ΔT = 0: {:.1}%)",
        f.points,
        f.delay,
        1e3 * width,
        100.0 * f.error,
        100.0 * f.unshifted
    ));
    figures.push((format!("release_delay_{key}"), f.delay));
    figures.push((format!("release_delay_error_{key}"), f.error));
}

/// One dam-break experiment: its front data, names and column width.
struct Experiment {
    table: &'static [(f64, f64)],
    name: &'static str,
    /// Name in figure keys.
    key: &'static str,
    /// Column width a or L (m).
    width: f64,
}

impl Experiment {
    fn of(exp: DamBreakExperiment) -> Self {
        match exp {
            DamBreakExperiment::KoshizukaOka => Experiment {
                table: &KOSHIZUKA_OKA,
                name: "Koshizuka-Oka",
                key: "koshizuka_oka",
                width: 0.146,
            },
            DamBreakExperiment::MartinMoyce => Experiment {
                table: &MARTIN_MOYCE,
                name: "Martin-Moyce",
                key: "martin_moyce",
                width: 2.25 * 0.0254,
            },
        }
    }
}

/// Surge front Z = z/L against T = t sqrt(2g/L) for a column of width L and height 2L:
/// Koshizuka & Oka (1996), L = 0.146 m, as commonly digitised from their figure.
const KOSHIZUKA_OKA: [(f64, f64); 9] = [
    (0.0, 1.0),
    (0.381, 1.111),
    (0.769, 1.252),
    (1.153, 1.505),
    (1.537, 1.892),
    (1.935, 2.241),
    (2.323, 2.615),
    (2.719, 3.003),
    (3.096, 3.624),
];

/// The same for Martin & Moyce (1952), Fig. 3, n² = 2, a = 2.25 in (digitised points).
const MARTIN_MOYCE: [(f64, f64); 6] = [
    (0.0, 1.0),
    (0.832, 1.217),
    (1.219, 1.474),
    (1.997, 2.292),
    (2.547, 2.995),
    (3.345, 4.134),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// A front that starts at rest and runs at a constant speed after T = 1.
    fn front(t: f64) -> f64 {
        if t <= 0.0 {
            1.0
        } else if t < 1.0 {
            1.0 + 0.5 * t * t
        } else {
            1.5 + (t - 1.0)
        }
    }

    fn run_of(shift: f64) -> Vec<(f64, f64)> {
        (0..=260)
            .map(|k| {
                let t = 0.01 * k as f64;
                (t, front(t + shift))
            })
            .collect()
    }

    #[test]
    fn release_delay_recovers_a_late_start() {
        // The experiment's points lag the run by 0.2: the fit must find that delay
        // (a multiple of the grid step) and then match to interpolation error.
        let data: Vec<(f64, f64)> = KOSHIZUKA_OKA
            .iter()
            .map(|&(t, _)| (t, front(t - 0.2)))
            .collect();
        let f = fit_release_delay(&run_of(0.0), &data, DAM_BREAK_T_MAX).unwrap();
        assert!((f.delay - 0.2).abs() < 0.5 * DELAY_STEP, "{f:?}");
        assert!(f.error < 1e-3, "{f:?}");
        assert!(f.unshifted > 0.05, "{f:?}");
        // Every data point inside the window is compared, and only those.
        let inside = KOSHIZUKA_OKA
            .iter()
            .filter(|&&(t, _)| t > 0.0 && t <= DAM_BREAK_T_MAX)
            .count();
        assert!(inside > 0 && f.points == inside, "{f:?}");
    }

    #[test]
    fn release_delay_is_zero_for_a_matching_run_and_absent_for_a_short_one() {
        let data: Vec<(f64, f64)> = KOSHIZUKA_OKA.iter().map(|&(t, _)| (t, front(t))).collect();
        let f = fit_release_delay(&run_of(0.0), &data, DAM_BREAK_T_MAX).unwrap();
        assert_eq!(f.delay, 0.0);
        assert!(f.error < 1e-3 && f.unshifted == f.error, "{f:?}");
        assert!(fit_release_delay(&run_of(0.0)[..150], &data, DAM_BREAK_T_MAX).is_none());
    }

    #[test]
    fn no_delay_fits_a_front_at_the_wrong_speed() {
        // A front 20% faster after the start is not a late start: the best delay
        // still leaves a large error.
        let data: Vec<(f64, f64)> = KOSHIZUKA_OKA.iter().map(|&(t, _)| (t, front(t))).collect();
        let fast: Vec<(f64, f64)> = run_of(0.0)
            .into_iter()
            .map(|(t, z)| (t, 1.0 + 1.2 * (z - 1.0)))
            .collect();
        let f = fit_release_delay(&fast, &data, DAM_BREAK_T_MAX).unwrap();
        assert!(f.error > 0.03, "{f:?}");
    }
}
