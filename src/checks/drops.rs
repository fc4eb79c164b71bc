//! Drops landing on drops (F22 §4.3, material jetting with two and three
//! drops): how much of the first drop is solid when the second first touches it.
//! - The drops are the connected sets (link 1.5 Δx) of the liquid phases'
//!   particles at the first sample, ordered by their lowest point: drop 1
//!   lands first, drop 2 next. They are followed by id (a drop that freezes may
//!   change phase).
//! - Touch: the first sample at which a particle of drop 2 lies within 1.5 Δx
//!   of one of drop 1 (so the sample interval bounds the time's error).
//! - Solid: liquid fraction below ½, whatever the particle's phase.
//!
//! The verdict is drop 1's solid (`fraction = "solid"`) or liquid share at the
//! touch against the tolerance, which bounds it from above; a run in which
//! drop 2 never touches scores infinity. F22: with three drops (the second
//! 80 µm above the first) less than half of the first is solid; with two (160
//! µm above) the first is almost completely solid.

use super::{Check, Series, Verdict};
use crate::model::Model;
use crate::scene::{DropFraction, PhaseKind};
use crate::state::{State, H_LIQUID};

/// Within this many Δx of each other, two particles touch (the drops' link).
const LINK: f64 = 1.5;

pub struct DropContact {
    fraction: DropFraction,
    /// Drop index per particle id (usize::MAX: none), and the drop count.
    drops: Option<(Vec<usize>, usize)>,
    /// (time, drop 1's solid share) per sample until the touch.
    history: Vec<(f64, f64)>,
    touch: Option<(f64, f64)>,
}

impl DropContact {
    pub fn new(fraction: DropFraction) -> DropContact {
        DropContact {
            fraction,
            drops: None,
            history: Vec::new(),
            touch: None,
        }
    }

    /// Label the liquid particles' connected sets by their lowest point.
    fn label(m: &Model, st: &State) -> (Vec<usize>, usize) {
        let axis = m.dim as usize - 1;
        let liquid: Vec<usize> = (0..st.active())
            .filter(|&i| m.phases[st.phase[i] as usize].kind == PhaseKind::Liquid)
            .collect();
        let xs: Vec<[f64; 3]> = liquid.iter().map(|&i| m.to_world(st.pos[i])).collect();
        let (label, n) = crate::pool::connected_regions(&xs, LINK * m.dx, m.dim);
        let mut lowest = vec![f64::INFINITY; n];
        for (k, &l) in label.iter().enumerate() {
            lowest[l] = lowest[l].min(xs[k][axis]);
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| lowest[a].total_cmp(&lowest[b]));
        let mut rank = vec![0; n];
        for (r, &l) in order.iter().enumerate() {
            rank[l] = r;
        }
        let mut drop_of = vec![usize::MAX; st.len()];
        for (k, &i) in liquid.iter().enumerate() {
            drop_of[st.id[i] as usize] = rank[label[k]];
        }
        (drop_of, n)
    }
}

impl Check for DropContact {
    fn observe(&mut self, m: &Model, st: &State) {
        if self.touch.is_some() {
            return;
        }
        let (drop_of, n) = self.drops.get_or_insert_with(|| Self::label(m, st));
        if *n < 2 || st.heat.is_empty() {
            return;
        }
        let of = |i: usize| {
            drop_of
                .get(st.id[i] as usize)
                .copied()
                .unwrap_or(usize::MAX)
        };
        let first: Vec<usize> = (0..st.active()).filter(|&i| of(i) == 0).collect();
        let second: Vec<[f64; 3]> = (0..st.active())
            .filter(|&i| of(i) == 1)
            .map(|i| m.to_world(st.pos[i]))
            .collect();
        let solid = first
            .iter()
            .filter(|&&i| st.heat[i][H_LIQUID] < 0.5)
            .count();
        let share = solid as f64 / first.len().max(1) as f64;
        let t = st.sim.time as f64;
        self.history.push((t, share));
        let reach2 = (LINK * m.dx).powi(2);
        let touches = first.iter().any(|&i| {
            let x = m.to_world(st.pos[i]);
            second
                .iter()
                .any(|y| (0..3).map(|a| (x[a] - y[a]).powi(2)).sum::<f64>() < reach2)
        });
        if touches {
            self.touch = Some((t, share));
        }
    }

    fn series(&self) -> Option<Series> {
        Some(Series {
            columns: vec!["time", "drop1_solid_share"],
            rows: self.history.iter().map(|&(t, s)| vec![t, s]).collect(),
        })
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let n = self.drops.as_ref().map_or(0, |d| d.1);
        let mut details = vec![format!(
            "  {n} drop(s) at the start; t (s), solid share of drop 1:"
        )];
        for (t, s) in &self.history {
            details.push(format!("  {t:.4e} {s:.4}"));
        }
        let what = match self.fraction {
            DropFraction::Solid => "solid",
            DropFraction::Liquid => "liquid",
        };
        let value = match (self.touch, self.fraction) {
            (None, _) => f64::INFINITY,
            (Some((_, s)), DropFraction::Solid) => s,
            (Some((_, s)), DropFraction::Liquid) => 1.0 - s,
        };
        details.push(match self.touch {
            Some((t, s)) => format!(
                "  drop 2 touches drop 1 at t = {t:.4e} s (first sample within {LINK} dx): drop 1 is {:.1}% solid",
                100.0 * s
            ),
            None => "  drop 2 never touches drop 1".to_string(),
        });
        Verdict {
            metric: format!("{what} share of drop 1 when drop 2 first touches it"),
            value,
            details,
            figures: vec![
                ("touch_time".into(), self.touch.map_or(f64::NAN, |t| t.0)),
                ("solid_share".into(), self.touch.map_or(f64::NAN, |t| t.1)),
            ],
        }
    }
}
