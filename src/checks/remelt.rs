//! A substrate's remelt under a molten drop (F22 §4.3, material jetting): the
//! deepest point below the substrate's initial top that substrate material
//! reaches molten (liquid fraction ≥ ½), over every sample.
//! - The substrate is the particles of the scene's melting solid phases at
//!   the first sample (by id: melted, they change phase); its top is their
//!   highest particle plus Δx/2.
//! - The depth at a sample is the top less the lowest molten substrate
//!   particle, less Δx/2 (that particle's own half cell); 0 when none is
//!   molten.
//!
//! The verdict is |max depth − reference| / Δx against the tolerance (in Δx):
//! F22 reports about 16 µm near 0.075 ms on a 1500 K substrate and no
//! noticeable melting on a 500 K one (reference 0).

use super::{Check, Series, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;

pub struct Remelt {
    reference: f64,
    /// Substrate particle ids (by id, a bitmap) and the initial top.
    substrate: Option<(Vec<bool>, f64)>,
    /// (time, depth) per sample.
    samples: Vec<(f64, f64)>,
}

impl Remelt {
    pub fn new(reference: f64) -> Remelt {
        Remelt {
            reference,
            substrate: None,
            samples: Vec::new(),
        }
    }
}

impl Check for Remelt {
    fn observe(&mut self, m: &Model, st: &State) {
        let axis = m.dim as usize - 1;
        if self.substrate.is_none() {
            let mut ids = vec![false; st.len()];
            let mut top = f64::NEG_INFINITY;
            for i in 0..st.active() {
                let ph = &m.phases[st.phase[i] as usize];
                if ph.kind == PhaseKind::Solid && ph.switch_to.is_some() {
                    ids[st.id[i] as usize] = true;
                    top = top.max(m.to_world(st.pos[i])[axis]);
                }
            }
            self.substrate = Some((ids, top + 0.5 * m.dx));
        }
        let Some((ids, top)) = self.substrate.as_ref() else {
            return;
        };
        let lowest = (0..st.active())
            .filter(|&i| ids.get(st.id[i] as usize).copied().unwrap_or(false))
            .filter(|&i| !st.heat.is_empty() && st.heat[i][2] >= 0.5)
            .map(|i| m.to_world(st.pos[i])[axis])
            .fold(f64::INFINITY, f64::min);
        let depth = if lowest.is_finite() {
            (top - lowest - 0.5 * m.dx).max(0.0)
        } else {
            0.0
        };
        self.samples.push((st.sim.time as f64, depth));
    }

    fn series(&self) -> Option<Series> {
        Some(Series {
            columns: vec!["time", "remelt_depth"],
            rows: self.samples.iter().map(|&(t, d)| vec![t, d]).collect(),
        })
    }

    fn verdict(&mut self, m: &Model, _st: &State) -> Verdict {
        let (t_max, d_max) =
            self.samples.iter().copied().fold(
                (f64::NAN, 0.0),
                |best, s| if s.1 > best.1 { s } else { best },
            );
        let mut details = vec!["  t (s), remelt depth (m):".to_string()];
        for (t, d) in &self.samples {
            details.push(format!("  {t:.4e} {d:.4e}"));
        }
        details.push(if d_max > 0.0 {
            format!(
                "  deepest remelt {d_max:.4e} m ({:.2} dx) at t = {t_max:.4e} s; reference {:.4e} m",
                d_max / m.dx,
                self.reference
            )
        } else {
            format!(
                "  no substrate particle molten at any sample; reference {:.4e} m",
                self.reference
            )
        });
        Verdict {
            metric: "|deepest substrate remelt - reference| / dx".into(),
            value: (d_max - self.reference).abs() / m.dx,
            details,
            figures: vec![
                ("remelt_depth".into(), d_max),
                ("remelt_time".into(), t_max),
            ],
        }
    }
}
