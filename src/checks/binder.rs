//! F22 §4.2's binder jetting: a binder drop into a powder bed. F22 prints no
//! number, only comparisons between drop speeds and what happens at 50 m/s;
//! the check measures, at every frame:
//! - **Penetration**: how far the lowest binder particle lies below the bed's
//!   top (the powder generator's levelled or poured height), 0 above it.
//! - **Spread width**: the lateral extent of the binder on or in the bed
//!   (below the bed's top plus one median grain diameter; a splash above it
//!   does not count), + Δx; in 3D the mean of the x and y extents.
//! - **Binder at the walls**: a binder particle within 1.5 Δx of a side face
//!   of the domain (F22 at 50 m/s: spatters adhere to the walls).
//! - **Ejected grains**: grains whose centre rose more than their diameter
//!   above the bed's top (crate::bodies' rule) at any frame.
//! - **Sinking**: the binder's mean vertical velocity (F22: at 1 and at
//!   10 m/s the binder still moves down at the end of the run).
//!
//! Penetration and spread are taken at the end (F22's figures are at the end
//! of each run). The criteria are those the scene gives: `penetration_below`
//! and `spread_above` (m: the figures of a slower drop's run, so that F22's
//! order — less penetration, wider spread at 10 than at 1 m/s — is one
//! scene's check), `reaches_walls = true`, `ejected` (at least that many
//! grains), `sinking = true` (the mean vertical velocity at the end is
//! downward). The verdict is the number missed.

use super::{Check, Series, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;

pub struct Binder {
    penetration_below: Option<f64>,
    spread_above: Option<f64>,
    reaches_walls: bool,
    ejected_at_least: Option<usize>,
    sinking: bool,
    /// (time, penetration, spread width, binder at a wall (0/1), grains
    /// ejected so far, mean vertical velocity) per frame.
    series: Vec<[f64; 6]>,
    at_walls: bool,
    ejected: Vec<bool>,
}

impl Binder {
    pub fn new(c: &crate::scene::BinderCheck) -> Binder {
        Binder {
            penetration_below: c.penetration_below,
            spread_above: c.spread_above,
            reaches_walls: c.reaches_walls.unwrap_or(false),
            ejected_at_least: c.ejected,
            sinking: c.sinking.unwrap_or(false),
            series: Vec::new(),
            at_walls: false,
            ejected: Vec::new(),
        }
    }
}

/// The bed's top and its median grain diameter.
fn bed(m: &Model) -> (f64, f64) {
    let up = m.dim as usize - 1;
    m.powder.as_ref().map_or((f64::NAN, 0.0), |b| {
        (b.spec.lo[up] + b.thickness, b.spec.diameters.median)
    })
}

impl Check for Binder {
    fn observe(&mut self, m: &Model, st: &State) {
        let up = m.dim as usize - 1;
        let (top, grain) = bed(m);
        let mut lowest = f64::INFINITY;
        let mut extent = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
        let mut at_wall = false;
        let (mut vertical, mut count) = (0.0, 0usize);
        let near = 1.5 * m.dx;
        for i in 0..st.active() {
            if m.phases[st.phase[i] as usize].kind != PhaseKind::Liquid {
                continue;
            }
            let x = m.to_world(st.pos[i]);
            lowest = lowest.min(x[up]);
            vertical += st.vel[i][up] as f64;
            count += 1;
            for a in 0..up {
                let face = x[a] - m.domain_lo[a] < near || m.domain_hi[a] - x[a] < near;
                at_wall |= face;
                if x[up] < top + grain {
                    extent[a] = [extent[a][0].min(x[a]), extent[a][1].max(x[a])];
                }
            }
        }
        let spans: Vec<f64> = extent[..up]
            .iter()
            .map(|e| {
                if e[1] >= e[0] {
                    e[1] - e[0] + m.dx
                } else {
                    0.0
                }
            })
            .collect();
        let spread = spans.iter().sum::<f64>() / spans.len() as f64;
        let penetration = (top - lowest).max(0.0);
        self.at_walls |= at_wall;
        if let Some(rise) = crate::bodies::grain_rise(m, st) {
            self.ejected.resize(rise.len(), false);
            for (seen, r) in self.ejected.iter_mut().zip(rise) {
                *seen |= r > 1.0;
            }
        }
        let ejected = self.ejected.iter().filter(|&&e| e).count();
        self.series.push([
            st.sim.time as f64,
            penetration,
            spread,
            f64::from(u8::from(at_wall)),
            ejected as f64,
            vertical / count.max(1) as f64,
        ]);
    }

    fn series(&self) -> Option<Series> {
        Some(Series {
            columns: vec![
                "time",
                "penetration",
                "spread_width",
                "binder_at_wall",
                "grains_ejected",
                "mean_vertical_velocity",
            ],
            rows: self.series.iter().map(|r| r.to_vec()).collect(),
        })
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let mut details = vec![
            "  t (s), penetration below the bed's top (m), spread width (m), binder at a side wall, grains ejected so far, binder's mean vertical velocity (m/s):"
                .to_string(),
        ];
        for s in &self.series {
            details.push(format!(
                "  {:.4e} {:.4e} {:.4e} {} {} {:.4e}",
                s[0], s[1], s[2], s[3], s[4], s[5]
            ));
        }
        let last = self.series.last().copied().unwrap_or([f64::NAN; 6]);
        let (penetration, spread) = (last[1], last[2]);
        let ejected = self.ejected.iter().filter(|&&e| e).count();
        details.push(format!(
            "  at the end: penetration {penetration:.4e} m, spread width {spread:.4e} m; binder \
             reached a side wall: {}; grains ejected: {ejected} of {}",
            if self.at_walls { "yes" } else { "no" },
            self.ejected.len()
        ));
        let mark = |ok: bool| if ok { "yes" } else { "NO" };
        let mut missed = 0;
        let mut judge = |ok: bool, what: String, details: &mut Vec<String>| {
            missed += usize::from(!ok);
            details.push(format!("  {what}: {}", mark(ok)));
        };
        if let Some(p) = self.penetration_below {
            judge(
                penetration < p,
                format!("penetration {penetration:.4e} m below {p:.4e} m"),
                &mut details,
            );
        }
        if let Some(w) = self.spread_above {
            judge(
                spread > w,
                format!("spread width {spread:.4e} m above {w:.4e} m"),
                &mut details,
            );
        }
        if self.reaches_walls {
            judge(
                self.at_walls,
                "binder reaches a side wall".into(),
                &mut details,
            );
        }
        if self.sinking {
            judge(
                last[5] < 0.0,
                format!("binder still moving down at the end ({:.4e} m/s)", last[5]),
                &mut details,
            );
        }
        if let Some(n) = self.ejected_at_least {
            judge(
                ejected >= n,
                format!("{ejected} grains ejected, at least {n}"),
                &mut details,
            );
        }
        Verdict {
            metric: "criteria of F22 §4.2 missed".into(),
            value: missed as f64,
            details,
            figures: vec![
                ("penetration".into(), penetration),
                ("spread_width".into(), spread),
                ("binder_at_wall".into(), f64::from(u8::from(self.at_walls))),
                ("ejected_grains".into(), ejected as f64),
                ("mean_vertical_velocity".into(), last[5]),
            ],
        }
    }
}
