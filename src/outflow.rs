//! Particles that have left the simulation: how many, of which phase,
//! with how much mass, through which side and when; and the exact mass balance
//! initial = in the domain + removed.
//!
//! The step removes a particle that crosses an open side or leaves the padded box
//! (`Params::outside_keep_box`): the neighbour pass sorts it after every cell, so
//! the removed particles are the last `sim.removed` entries of the state, frozen
//! where they left, with the time they left in `pos[i][3]`.

use crate::model::Model;
use crate::scene::SIDE_NAMES;
use crate::state::{State, NO_BODY};
use serde::Serialize;
use std::collections::{BTreeMap, HashSet};

/// Exact sum of f32 values. Every f32 is an integer multiple of 2^-149; the sum
/// keeps one integer per binary exponent, so it depends neither on the order of
/// the terms nor on how they are grouped, and two sums compare exactly.
#[derive(Debug, Clone)]
pub struct ExactSum {
    /// buckets[e]: integer multiple of 2^(e − 150), e the biased exponent (≥ 1).
    buckets: Vec<i64>,
}

impl Default for ExactSum {
    fn default() -> Self {
        ExactSum {
            buckets: vec![0; 257],
        }
    }
}

impl ExactSum {
    /// Adds a finite value (a term of up to 2^24 per bucket: 2^39 terms fit).
    pub fn add(&mut self, x: f32) {
        let bits = x.to_bits();
        let exp = ((bits >> 23) & 0xff) as usize;
        let mut mantissa = (bits & 0x7f_ffff) as i64;
        if exp != 0 {
            mantissa |= 0x80_0000;
        }
        let sign = if bits >> 31 != 0 { -1 } else { 1 };
        self.buckets[exp.max(1)] += sign * mantissa;
    }
    pub fn sum(values: impl IntoIterator<Item = f32>) -> ExactSum {
        let mut s = ExactSum::default();
        values.into_iter().for_each(|x| s.add(x));
        s
    }
    pub fn plus(&self, other: &ExactSum) -> ExactSum {
        let buckets = self
            .buckets
            .iter()
            .zip(&other.buckets)
            .map(|(a, b)| a + b)
            .collect();
        ExactSum { buckets }
    }
    /// The same value with every bucket but the last in {0, 1} (carries moved up):
    /// one representation per value.
    fn canonical(&self) -> Vec<i64> {
        let mut b = self.buckets.clone();
        for e in 0..b.len() - 1 {
            let carry = b[e].div_euclid(2);
            b[e] -= 2 * carry;
            b[e + 1] += carry;
        }
        b
    }
    /// The value in f64 (rounded; for printing).
    pub fn value(&self) -> f64 {
        self.canonical()
            .iter()
            .enumerate()
            .map(|(e, &k)| k as f64 * 2f64.powi(e as i32 - 150))
            .sum()
    }
}

impl PartialEq for ExactSum {
    fn eq(&self, other: &Self) -> bool {
        self.canonical() == other.canonical()
    }
}

/// The removed particles of a state.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outflow {
    /// Per phase name: particles removed and their mass (kg; per metre in 2D).
    pub per_phase: BTreeMap<String, (u64, f64)>,
    /// Per side name: particles that left through it.
    pub per_side: BTreeMap<&'static str, u64>,
    /// When the first and the last of them left (s).
    pub first_time: Option<f64>,
    pub last_time: Option<f64>,
}

impl Outflow {
    pub fn of(m: &Model, st: &State) -> Outflow {
        let mut o = Outflow::default();
        for i in st.active()..st.len() {
            let phase = &m.phases[st.phase[i] as usize].name;
            let e = o.per_phase.entry(phase.clone()).or_default();
            e.0 += 1;
            e.1 += st.mass[i] as f64;
            *o.per_side.entry(side_name(m, st, i)).or_default() += 1;
            let t = st.pos[i][3] as f64;
            o.first_time = Some(o.first_time.map_or(t, |f| f.min(t)));
            o.last_time = Some(o.last_time.map_or(t, |l| l.max(t)));
        }
        o
    }

    pub fn count(&self) -> u64 {
        self.per_phase.values().map(|v| v.0).sum()
    }

    pub fn summary(&self) -> String {
        if self.count() == 0 {
            return "no particle left the domain".into();
        }
        let phases: Vec<String> = self
            .per_phase
            .iter()
            .map(|(p, (n, mass))| format!("{p} {n} ({mass:.4e} kg)"))
            .collect();
        let sides: Vec<String> = self
            .per_side
            .iter()
            .map(|(s, n)| format!("{n} through {s}"))
            .collect();
        format!(
            "{} particle(s) left the domain: {}; {}; between t = {:.4e} s and {:.4e} s",
            self.count(),
            phases.join(", "),
            sides.join(", "),
            self.first_time.unwrap_or(0.0),
            self.last_time.unwrap_or(0.0)
        )
    }
}

fn side_name(m: &Model, st: &State, i: usize) -> &'static str {
    let (a, side, _) = m.exit_face(exit_point(m, st, i));
    SIDE_NAMES[a][side]
}

/// Where removed particle i left, for naming its face (world coordinates): its
/// own position, or for a member of a rigid body that left, the body's centre,
/// which is past the face; the member itself may still stand inside the
/// domain, nearer a closed wall than the open face (bodies::place).
pub fn exit_point(m: &Model, st: &State, i: usize) -> [f64; 3] {
    let k = st.body.get(st.id[i] as usize).copied().unwrap_or(NO_BODY);
    match st.bodies.get(k as usize) {
        Some(b) if b.left() => m.to_world(b.x),
        _ => m.to_world(st.pos[i]),
    }
}

/// Initial mass against the mass still in the domain plus the mass removed, each
/// an exact sum of the particles' f32 masses.
#[derive(Debug, Clone)]
pub struct MassBalance {
    pub initial: ExactSum,
    pub domain: ExactSum,
    pub removed: ExactSum,
}

impl MassBalance {
    pub fn of(initial: &State, now: &State) -> MassBalance {
        let n = now.active();
        MassBalance {
            initial: ExactSum::sum(initial.mass.iter().copied()),
            domain: ExactSum::sum(now.mass[..n].iter().copied()),
            removed: ExactSum::sum(now.mass[n..].iter().copied()),
        }
    }
    pub fn exact(&self) -> bool {
        self.domain.plus(&self.removed) == self.initial
    }
    pub fn summary(&self) -> String {
        let (d, r, i) = (
            self.domain.value(),
            self.removed.value(),
            self.initial.value(),
        );
        let verdict = if self.exact() {
            "equal to the initial mass exactly".to_string()
        } else {
            format!(
                "NOT equal to the initial {i:.9e} kg (off by {:.3e} kg)",
                d + r - i
            )
        };
        format!("in the domain {d:.9e} kg + removed {r:.9e} kg: {verdict}")
    }
}

/// One particle leaving the domain, as the `/removed` MCAP channel records it.
#[derive(Debug, Clone, Serialize)]
pub struct RemovalEvent {
    pub id: u32,
    pub phase: String,
    /// When it left (s).
    pub time: f64,
    pub side: &'static str,
    /// Where it was at the end of the step it left in (m, world coordinates).
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub speed: f64,
    pub mass: f64,
}

/// The `/removed` events of a run not yet written (crate::diagnostics::REMOVED_TOPIC).
#[derive(Debug, Default)]
pub struct RemovalLog {
    /// Ids whose removal is written; None until the first state (a resumed run's
    /// earlier removals are in the earlier file).
    reported: Option<HashSet<u32>>,
}

impl RemovalLog {
    /// The particles that have left since the last state seen, by id; none at
    /// the first state, which only records who is out already.
    pub fn new_events(&mut self, m: &Model, st: &State) -> Vec<RemovalEvent> {
        match self.reported.as_mut() {
            Some(reported) => new_removals(m, st, reported),
            None => {
                self.reported = Some(removed_ids(st));
                Vec::new()
            }
        }
    }
}

/// The removals of `st` not yet in `reported` (which they are added to), by id.
fn new_removals(m: &Model, st: &State, reported: &mut HashSet<u32>) -> Vec<RemovalEvent> {
    let mut out: Vec<RemovalEvent> = (st.active()..st.len())
        .filter(|&i| reported.insert(st.id[i]))
        .map(|i| {
            let [x, y, z] = m.to_world(st.pos[i]);
            let v = st.vel[i];
            RemovalEvent {
                id: st.id[i],
                phase: m.phases[st.phase[i] as usize].name.clone(),
                time: st.pos[i][3] as f64,
                side: side_name(m, st, i),
                x,
                y,
                z,
                speed: ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) as f64).sqrt(),
                mass: st.mass[i] as f64,
            }
        })
        .collect();
    out.sort_by_key(|e| e.id);
    out
}

/// The ids already removed in `st` (a resumed run's earlier removals).
fn removed_ids(st: &State) -> HashSet<u32> {
    st.id[st.active()..].iter().copied().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact in any order and grouping, where an f64 sum is not; equal sums
    /// compare equal whatever their buckets.
    #[test]
    fn exact_sum_does_not_depend_on_order_or_grouping() {
        let xs: Vec<f32> = (0..10_000)
            .map(|k| {
                1.0e-3 * (1.0 + (k % 97) as f32 * 1.37e-3) * if k % 7 == 0 { 64.0 } else { 1.0 }
            })
            .collect();
        let forward = ExactSum::sum(xs.iter().copied());
        let backward = ExactSum::sum(xs.iter().rev().copied());
        let (a, b) = xs.split_at(3_333);
        let split = ExactSum::sum(a.iter().copied()).plus(&ExactSum::sum(b.iter().copied()));
        assert_eq!(forward, backward);
        assert_eq!(forward, split);
        let one_more = ExactSum::sum(xs.iter().copied().chain([f32::MIN_POSITIVE]));
        assert_ne!(forward, one_more);
        let f64_sum: f64 = xs.iter().map(|&x| x as f64).sum();
        assert!((forward.value() - f64_sum).abs() <= 1e-12 * f64_sum);
        // 1 + 2^-24 + 2^-24 is exactly 1 + 2^-23 (f32 sums would drop both halves).
        let s = ExactSum::sum([1.0, 2f32.powi(-24), 2f32.powi(-24)]);
        assert_eq!(s, ExactSum::sum([1.0, 2f32.powi(-23)]));
    }
}
