//! F22 §4.4's directed energy deposition: grains flying into a laser pool.
//! F22 reports an order of events and one size; the check measures, at every
//! sample (diagnostics samples too: the events are microseconds apart):
//! - **Arrival** of each grain (the scene's rigid bodies, by index): the time
//!   the lowest of its initial particles (followed by id, molten or not: a
//!   grain that melts in flight is still the same material) first passes below
//!   the substrate's initial top (the highest non-body particle of a melting
//!   solid + ½Δx), linear between the two samples around it: the grain enters
//!   the pool. F22's first grain enters it "at about 6 µs"; its centre, 40 µm
//!   up the 45° line at 10 m/s, would reach the substrate's centre at
//!   40√2 µm / 10 m/s = 5.7 µs.
//! - **Pool diameter**: the mean of the pool's extents along x and y (the
//!   largest connected melt region, crate::pool; molten grains in it count) at
//!   the sample nearest `diameter_time`. F22: about 130 µm near 18 µs.
//! - **Molten state of each grain** at the end: the share of its initial
//!   particles seen molten (liquid fraction ≥ ½) at any sample. F22 with the
//!   laser off at 12 µs: grains that melt only partly stay as inclusions.
//!
//! The criteria are those the scene gives: `arrival` (the first grain's time
//! within 20%, fixed: F22 gives it only as "near" 5.7 µs), `diameter` (within
//! `diameter_tolerance`, default 10%), `unmolten = true` (at least one grain not
//! fully molten at the end). The verdict is the number missed.

use super::{Check, Series, Verdict};
use crate::model::{BodySource, Model};
use crate::scene::PhaseKind;
use crate::state::State;

/// F22 gives the arrival only as "near" 5.7 µs: held to ±20%.
const ARRIVAL_TOLERANCE: f64 = 0.2;

pub struct Deposition {
    arrival: Option<f64>,
    diameter: Option<(f64, f64, f64)>,
    unmolten: bool,
    /// The substrate's initial top and each grain's particle ids.
    layout: Option<(f64, Vec<Vec<u32>>)>,
    /// Per grain: arrival time, the last sample's (time, centre height).
    arrived: Vec<Option<f64>>,
    last_height: Vec<(f64, f64)>,
    /// Particle ids seen molten.
    molten: Vec<bool>,
    /// (time, pool diameter, grains arrived) per sample.
    series: Vec<[f64; 3]>,
}

impl Deposition {
    pub fn new(c: &crate::scene::DepositionCheck) -> Deposition {
        Deposition {
            arrival: c.arrival,
            diameter: c.diameter.map(|d| {
                (
                    d,
                    c.diameter_time.unwrap_or(f64::NAN),
                    c.diameter_tolerance.unwrap_or(0.1),
                )
            }),
            unmolten: c.unmolten.unwrap_or(false),
            layout: None,
            arrived: Vec::new(),
            last_height: Vec::new(),
            molten: Vec::new(),
            series: Vec::new(),
        }
    }

    fn layout(m: &Model, st: &State) -> (f64, Vec<Vec<u32>>) {
        let up = m.dim as usize - 1;
        let mut grains = vec![Vec::new(); m.bodies.len()];
        let mut top = f64::NEG_INFINITY;
        for i in 0..st.active() {
            let id = st.id[i];
            match st.body.get(id as usize) {
                Some(&b) if b != crate::state::NO_BODY => grains[b as usize].push(id),
                _ => {
                    let ph = &m.phases[st.phase[i] as usize];
                    if ph.kind == PhaseKind::Solid && ph.switch_to.is_some() {
                        top = top.max(m.to_world(st.pos[i])[up]);
                    }
                }
            }
        }
        (top + 0.5 * m.dx, grains)
    }

    /// Height of each grain's lowest initial particle still in the domain
    /// (NaN: none left).
    fn lowest(&self, m: &Model, st: &State) -> Vec<f64> {
        let up = m.dim as usize - 1;
        let Some((_, grains)) = self.layout.as_ref() else {
            return Vec::new();
        };
        let mut grain_of = vec![usize::MAX; st.len()];
        for (g, ids) in grains.iter().enumerate() {
            for &id in ids {
                grain_of[id as usize] = g;
            }
        }
        let mut low = vec![f64::NAN; grains.len()];
        for i in 0..st.active() {
            let g = grain_of[st.id[i] as usize];
            if g != usize::MAX {
                low[g] = low[g].min(m.to_world(st.pos[i])[up]);
            }
        }
        low
    }

    /// Share of each grain's initial particles seen molten.
    fn molten_shares(&self) -> Vec<f64> {
        let Some((_, grains)) = self.layout.as_ref() else {
            return Vec::new();
        };
        grains
            .iter()
            .map(|ids| {
                let seen = ids
                    .iter()
                    .filter(|&&id| self.molten.get(id as usize).copied().unwrap_or(false))
                    .count();
                seen as f64 / ids.len().max(1) as f64
            })
            .collect()
    }
}

impl Check for Deposition {
    fn every_sample(&self) -> bool {
        true
    }

    fn observe(&mut self, m: &Model, st: &State) {
        if self.layout.is_none() {
            self.layout = Some(Self::layout(m, st));
            self.arrived = vec![None; m.bodies.len()];
            self.last_height = vec![(f64::NAN, f64::NAN); m.bodies.len()];
            self.molten = vec![false; st.len()];
        }
        let time = st.sim.time as f64;
        let top = self.layout.as_ref().map_or(f64::NAN, |l| l.0);
        let lowest = self.lowest(m, st);
        for k in 0..m.bodies.len() {
            if !matches!(m.bodies[k].source, BodySource::Shape(_)) {
                continue;
            }
            let z = lowest[k];
            if !z.is_finite() {
                continue;
            }
            let (t0, z0) = self.last_height[k];
            if self.arrived[k].is_none() && z <= top {
                // Linear between the sample above and this one.
                let t = if z0.is_finite() && z0 > top {
                    t0 + (time - t0) * (z0 - top) / (z0 - z)
                } else {
                    time
                };
                self.arrived[k] = Some(t);
            }
            self.last_height[k] = (time, z);
        }
        for i in 0..st.active() {
            if crate::pool::is_melt(m, st, i) {
                if let Some(seen) = self.molten.get_mut(st.id[i] as usize) {
                    *seen = true;
                }
            }
        }
        let regions = crate::pool::melt_regions(m, st);
        let f = crate::pool::PoolFigures::of(m, st, &regions, None);
        let diameter = 0.5 * (f.length + f.width);
        let arrived = self.arrived.iter().filter(|a| a.is_some()).count();
        self.series.push([time, diameter, arrived as f64]);
    }

    fn series(&self) -> Option<Series> {
        Some(Series {
            columns: vec!["time", "pool_diameter", "grains_arrived"],
            rows: self.series.iter().map(|r| r.to_vec()).collect(),
        })
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let mut details = vec!["  t (s), pool diameter (m), grains arrived:".to_string()];
        for s in &self.series {
            details.push(format!("  {:.4e} {:.4e} {}", s[0], s[1], s[2]));
        }
        let shares = self.molten_shares();
        let mut figures = Vec::new();
        for (k, a) in self.arrived.iter().enumerate() {
            let share = shares.get(k).copied().unwrap_or(f64::NAN);
            details.push(format!(
                "  grain {}: {}, {:.0}% of it seen molten",
                k + 1,
                a.map_or(
                    "never reaches the substrate's top".to_string(),
                    |t| format!("reaches the substrate's top at {t:.4e} s")
                ),
                100.0 * share
            ));
            figures.push((format!("arrival_{}", k + 1), a.unwrap_or(f64::NAN)));
            figures.push((format!("molten_share_{}", k + 1), share));
        }
        let first = self
            .arrived
            .iter()
            .flatten()
            .copied()
            .fold(f64::NAN, f64::min);
        let mut missed = 0;
        let mark = |ok: bool| if ok { "yes" } else { "NO" };
        if let Some(reference) = self.arrival {
            let off = (first - reference).abs() / reference;
            let ok = off <= ARRIVAL_TOLERANCE;
            missed += usize::from(!ok);
            details.push(format!(
                "  first arrival {first:.4e} s against {reference:.4e} s: {:.1}% off (within {:.0}%): {}",
                100.0 * off,
                100.0 * ARRIVAL_TOLERANCE,
                mark(ok)
            ));
        }
        let at = |t_ref: f64| {
            self.series
                .iter()
                .min_by(|a, b| (a[0] - t_ref).abs().total_cmp(&(b[0] - t_ref).abs()))
                .copied()
        };
        if let Some((reference, t_ref, tolerance)) = self.diameter {
            let (t, d) = at(t_ref).map_or((f64::NAN, f64::NAN), |r| (r[0], r[1]));
            let off = (d - reference).abs() / reference;
            let ok = off <= tolerance;
            missed += usize::from(!ok);
            details.push(format!(
                "  pool diameter {d:.4e} m at t = {t:.4e} s against {reference:.4e} m: {:.1}% off \
                 (within {:.0}%): {}",
                100.0 * off,
                100.0 * tolerance,
                mark(ok)
            ));
            figures.push(("pool_diameter".into(), d));
        }
        let not_fully = shares.iter().filter(|&&s| s < 1.0).count();
        if self.unmolten {
            let ok = not_fully >= 1;
            missed += usize::from(!ok);
            details.push(format!(
                "  grains not fully molten at the end: {not_fully} of {}: {}",
                shares.len(),
                mark(ok)
            ));
        }
        figures.push(("first_arrival".into(), first));
        figures.push(("grains_not_fully_molten".into(), not_fully as f64));
        Verdict {
            metric: "criteria of F22 §4.4 missed".into(),
            value: missed as f64,
            details,
            figures,
        }
    }
}
