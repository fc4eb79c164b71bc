//! Pressure noise (R18 Test 4, a heavy blob sinking in a lighter fluid): how far
//! each interior particle's pressure departs from the smooth field around it.
//! R18 shows it by pictures (WCSPH noisy, δ-SPH on ρ − ρ0 smooth, δ-SPH on raw
//! ρ failing); this puts a number on it:
//!
//!   δp_i = p_i − Σ_j w_ij p_j / Σ_j w_ij,  w_ij = (1 − r_ij²/r_c²)²,
//!
//! over the fluid neighbours j within the kernel's support r_c (i included), so
//! a linear field (hydrostatic) gives δp ≈ 0 and a checkerboard gives its full
//! amplitude. Only interior particles count: those whose fluid neighbour count
//! is at least 90% of the median (the free surface, the walls and the first rows
//! next to them truncate the sum). The figure is the RMS of δp over them,
//! divided by ρ_l g H (ρ_l the first liquid's ρ0, H the fluid's initial height),
//! averaged over the samples after `settle_time`; the largest sample is printed.

use super::{g_mag, liquid_rho0, Check, Verdict};
use crate::model::Model;
use std::collections::HashMap;

use crate::state::State;

/// RMS pressure noise per sample, relative to ρ_l g H.
pub struct PressureNoise {
    settle_time: f64,
    /// ρ_l g H, from the first sample.
    scale: Option<f64>,
    /// (t, RMS δp / scale, interior particles).
    samples: Vec<(f64, f64, usize)>,
}

impl PressureNoise {
    pub fn new(settle_time: Option<f64>) -> Self {
        PressureNoise {
            settle_time: settle_time.unwrap_or(0.0),
            scale: None,
            samples: Vec::new(),
        }
    }
}

/// The fluid particles' world positions and pressures.
fn fluid(m: &Model, st: &State) -> Vec<([f64; 3], f64)> {
    (0..st.active())
        .filter(|&i| m.phases[st.phase[i] as usize].is_fluid())
        .map(|i| (m.to_world(st.pos[i]), st.press[i] as f64))
        .collect()
}

/// Each point's neighbours within `rc` (itself included), by a hash of cells rc wide.
fn neighbours(pts: &[([f64; 3], f64)], rc: f64) -> Vec<Vec<(usize, f64)>> {
    let cell = |x: &[f64; 3]| {
        let c = |a: usize| (x[a] / rc).floor() as i64;
        (c(0), c(1), c(2))
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (k, (x, _)) in pts.iter().enumerate() {
        grid.entry(cell(x)).or_default().push(k);
    }
    pts.iter()
        .map(|(x, _)| {
            let (cx, cy, cz) = cell(x);
            let mut out = Vec::new();
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let Some(ks) = grid.get(&(cx + dx, cy + dy, cz + dz)) else {
                            continue;
                        };
                        for &k in ks {
                            let y = &pts[k].0;
                            let r2 = (0..3).map(|a| (x[a] - y[a]).powi(2)).sum::<f64>();
                            if r2 < rc * rc {
                                out.push((k, r2));
                            }
                        }
                    }
                }
            }
            out
        })
        .collect()
}

/// RMS of δp over the interior particles, and how many there are.
fn rms_noise(pts: &[([f64; 3], f64)], rc: f64) -> (f64, usize) {
    let near = neighbours(pts, rc);
    let mut counts: Vec<usize> = near.iter().map(Vec::len).collect();
    counts.sort_unstable();
    let Some(&median) = counts.get(counts.len() / 2) else {
        return (f64::NAN, 0);
    };
    let (mut sum2, mut n) = (0.0, 0usize);
    for (i, js) in near.iter().enumerate() {
        if (js.len() as f64) < 0.9 * median as f64 {
            continue;
        }
        let (mut wp, mut ws) = (0.0, 0.0);
        for &(j, r2) in js {
            let w = (1.0 - r2 / (rc * rc)).powi(2);
            wp += w * pts[j].1;
            ws += w;
        }
        let dp = pts[i].1 - wp / ws;
        sum2 += dp * dp;
        n += 1;
    }
    ((sum2 / n.max(1) as f64).sqrt(), n)
}

impl Check for PressureNoise {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        let pts = fluid(m, st);
        let up = m.dim as usize - 1;
        let scale = *self.scale.get_or_insert_with(|| {
            let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
                (a.0.min(p.0[up]), a.1.max(p.0[up]))
            });
            liquid_rho0(m) * g_mag(m) * (hi - lo + m.dx)
        });
        if t < self.settle_time || self.samples.last().is_some_and(|s| s.0 >= t) {
            return;
        }
        let rc = m.kernel.support_factor() * m.h;
        let (rms, n) = rms_noise(&pts, rc);
        self.samples.push((t, rms / scale, n));
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let metric = "RMS pressure noise / (rho_l g H), mean over samples".to_string();
        if self.samples.is_empty() {
            return (
                metric,
                f64::NAN,
                vec!["  no sample after settle_time".into()],
            )
                .into();
        }
        let mean = self.samples.iter().map(|s| s.1).sum::<f64>() / self.samples.len() as f64;
        let worst = self
            .samples
            .iter()
            .fold((0.0, 0.0), |a, s| if s.1 > a.1 { (s.0, s.1) } else { a });
        let last = self.samples[self.samples.len() - 1];
        let details = vec![format!(
            "  {} samples; largest {:.3e} at t = {:.4} s; last {:.3e} over {} interior particles",
            self.samples.len(),
            worst.1,
            worst.0,
            last.1,
            last.2
        )];
        Verdict {
            metric,
            value: mean,
            details,
            figures: vec![("largest".into(), worst.1), ("last".into(), last.1)],
        }
    }
}
