//! The solidification record: where, when and under what
//! thermal conditions the metal froze, the inputs of a columnar/equiaxed map
//! (Hunt 1984, Gäumann et al. 2001) and of grain-structure codes that take G and R
//! from a melt-pool simulation.
//!
//! The device keeps one record per particle (`State::solidification`, indexed by
//! id), written when a melting particle's temperature falls through the liquidus
//! (`heat.temperature`; the dendrite tips grow at the liquidus isotherm):
//! - time of the crossing, linear in T within the step;
//! - G = |∇T| from the renormalised gradient of the step's final temperatures
//!   (`solidification_gradient`);
//! - cooling rate −dT/dt = −(dh/dt)/c_l, the liquid side's rate of the step;
//! - position at the crossing, and how many crossings the particle has made.
//!
//! The host derives the solidification rate R = (cooling rate)/G, the speed of
//! the liquidus isotherm along the gradient. A particle that remelts and freezes
//! again overwrites its record: the last one is the one that froze the metal.
//! The host sees the records at samples, so two crossings of one particle
//! between samples show as the later one (its `crossings` count tells).

use crate::model::Model;
use crate::state::{State, SOL_COOLING, SOL_COUNT, SOL_GRADIENT, SOL_TIME};
use glam::{DMat3, DVec3};
use serde::Serialize;

pub const SOLIDIFICATION_TOPIC: &str = "/solidification";

/// One particle's last liquidus crossing on cooling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record {
    pub id: u32,
    /// s.
    pub time: f64,
    /// World coordinates, m.
    pub position: [f64; 3],
    /// G = |∇T|, K/m (0 where the particle had too few neighbours to tell).
    pub gradient: f64,
    /// G R, K/s: the cooling rate of the liquidus isotherm's passage.
    pub cooling_rate: f64,
    /// −dT/dt of the particle when it crossed, K/s (the device's, from the
    /// step's dh/dt over c_l).
    pub local_cooling_rate: f64,
    /// R, the liquidus isotherm's speed along its normal, m/s: 1/|∇t_l| of the
    /// crossing times around the record (`front_speeds`); local cooling rate / G
    /// where too few neighbouring records tell (0 where G is 0 too).
    pub rate: f64,
    /// Liquidus crossings on cooling so far.
    pub crossings: u32,
}

/// The record of particle id `k` as the device wrote it, if it has crossed the
/// liquidus while cooling (R and G R are the host's: `with_front_speeds`).
pub fn raw_record(m: &Model, st: &State, k: usize) -> Option<Record> {
    let n = st.solidification.len() / 2;
    let a = st.solidification.get(k)?;
    if a[SOL_COUNT] < 1.0 {
        return None;
    }
    let b = st.solidification[n + k];
    Some(Record {
        id: k as u32,
        time: a[SOL_TIME] as f64,
        position: m.to_world(b),
        gradient: a[SOL_GRADIENT].max(0.0) as f64,
        cooling_rate: 0.0,
        local_cooling_rate: a[SOL_COOLING] as f64,
        rate: 0.0,
        crossings: a[SOL_COUNT] as u32,
    })
}

/// Every particle's record, in id order, with R and G R.
pub fn records(m: &Model, st: &State) -> Vec<Record> {
    let raw: Vec<Record> = (0..st.solidification.len() / 2)
        .filter_map(|k| raw_record(m, st, k))
        .collect();
    with_front_speeds(m, raw)
}

/// R of each record from the field of crossing times t_l(x) around it: the
/// liquidus isotherm reaches x at t_l(x), so its speed along the normal is
/// 1/|∇t_l|. The gradient is the least-squares fit over the other records within
/// the kernel's support (weights (1 − r/support)², renormalised as on the device)
/// that crossed within the time the front takes to cross four supports at the
/// record's local R (local cooling rate / G): a later track's remelt does not mix
/// in. Why not R = (−dT/dt)/G alone: the latent heat leaves the front as a jump in
/// the gradient, which the SPH Laplacian smooths over the kernel, so a liquid
/// particle cools faster than the analytic liquid as the front reaches it
/// (+19% on solidification_1d, not falling with Δx); the crossing times carry no
/// such bias. Periodic images are not searched (a record at a periodic side
/// fits one-sided).
pub fn with_front_speeds(m: &Model, mut recs: Vec<Record>) -> Vec<Record> {
    let support = m.support;
    let cell_of = |x: &[f64; 3]| x.map(|c| (c / support).floor() as i64);
    let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
    for (k, r) in recs.iter().enumerate() {
        cells.entry(cell_of(&r.position)).or_default().push(k);
    }
    let reach_z = if m.dim == 3 { 1 } else { 0 };
    let offsets: Vec<[i64; 3]> = (-1..=1)
        .flat_map(|x| (-1..=1).flat_map(move |y| (-reach_z..=reach_z).map(move |z| [x, y, z])))
        .collect();
    let speeds: Vec<f64> = recs
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let local = if r.gradient > 0.0 {
                r.local_cooling_rate / r.gradient
            } else {
                0.0
            };
            let window = if local > 0.0 {
                4.0 * support / local
            } else {
                f64::INFINITY
            };
            let c = cell_of(&r.position);
            let (mut mm, mut b) = (DMat3::ZERO, DVec3::ZERO);
            let mut count = 0;
            for o in &offsets {
                let Some(list) = cells.get(&[c[0] + o[0], c[1] + o[1], c[2] + o[2]]) else {
                    continue;
                };
                for &j in list.iter().filter(|&&j| j != k) {
                    let q = &recs[j];
                    let d = DVec3::from(q.position) - DVec3::from(r.position);
                    let dist = d.length();
                    if dist >= support || dist == 0.0 || (q.time - r.time).abs() > window {
                        continue;
                    }
                    let w = (1.0 - dist / support).powi(2);
                    mm += DMat3::from_cols(d * d.x, d * d.y, d * d.z) * w;
                    b += d * (w * (q.time - r.time));
                    count += 1;
                }
            }
            match fit_gradient(m.dim, mm, b).filter(|_| count > m.dim as usize) {
                Some(g) if g > 0.0 => 1.0 / g,
                _ => local,
            }
        })
        .collect();
    for (r, v) in recs.iter_mut().zip(speeds) {
        r.rate = v;
        r.cooling_rate = r.gradient * v;
    }
    recs
}

/// |g| of M g = b (the weighted moments of the neighbours' offsets), in f64;
/// None where M is near singular relative to its size (the neighbours lie on a
/// line). In 2D the z row and column are empty: M_zz takes the mean of the
/// diagonal so that the 3×3 inverse solves the 2×2 block.
fn fit_gradient(dim: u32, mut m: DMat3, b: DVec3) -> Option<f64> {
    let trace = m.x_axis.x + m.y_axis.y + m.z_axis.z;
    let limit = if dim == 2 {
        m.z_axis.z = 0.5 * trace;
        1e-6 * trace * trace * m.z_axis.z
    } else {
        1e-9 * trace * trace * trace
    };
    (m.determinant() > limit).then(|| (m.inverse() * b).length())
}

/// One `/solidification` message: the records new since the previous sample,
/// as columns.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Batch {
    /// The sample's time, s.
    pub time: f64,
    pub id: Vec<u32>,
    pub t: Vec<f64>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    pub gradient: Vec<f64>,
    pub solidification_rate: Vec<f64>,
    pub cooling_rate: Vec<f64>,
    pub local_cooling_rate: Vec<f64>,
    pub crossings: Vec<u32>,
}

impl Batch {
    pub fn push(&mut self, r: &Record) {
        self.id.push(r.id);
        self.t.push(r.time);
        self.x.push(r.position[0]);
        self.y.push(r.position[1]);
        self.z.push(r.position[2]);
        self.gradient.push(r.gradient);
        self.solidification_rate.push(r.rate);
        self.cooling_rate.push(r.cooling_rate);
        self.local_cooling_rate.push(r.local_cooling_rate);
        self.crossings.push(r.crossings);
    }
}

/// JSON schema of a `/solidification` message.
pub fn schema() -> serde_json::Value {
    let col = |desc: &str| serde_json::json!({"type": "array", "items": {"type": "number"}, "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Solidification",
        "description": "Liquidus crossings on cooling recorded since the previous sample, one column entry per particle: the last crossing of each particle when it crossed more than once between samples.",
        "type": "object",
        "properties": {
            "time": {"type": "number", "description": "the sample's time, s"},
            "id": col("particle id"),
            "t": col("time the particle's temperature fell through the liquidus, s"),
            "x": col("position at the crossing, world coordinates, m"),
            "y": col("m"),
            "z": col("m"),
            "gradient": col("G = |grad T| there, K/m (renormalised SPH gradient; 0: too few neighbours)"),
            "solidification_rate": col("R, the liquidus isotherm's speed, m/s: 1/|grad t| of the crossing times of the records around it (local_cooling_rate / G where too few records are near)"),
            "cooling_rate": col("G R, K/s"),
            "local_cooling_rate": col("-dT/dt of the particle as it crossed, K/s (biased high near a front that releases latent heat: see crate::solidification)"),
            "crossings": col("liquidus crossings on cooling the particle has made so far")
        },
        "required": ["time", "id", "t", "x", "y", "z", "gradient", "solidification_rate", "cooling_rate", "local_cooling_rate", "crossings"]
    })
}

/// What `spatter run` prints of the records of the state it ends on: how many
/// particles froze from the liquid and the 10th, 50th and 90th percentiles of G,
/// R and the cooling rate over them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    pub particles: usize,
    /// K/m.
    pub gradient: [f64; 3],
    /// m/s.
    pub rate: [f64; 3],
    /// K/s.
    pub cooling_rate: [f64; 3],
}

impl Summary {
    /// None where no particle has crossed the liquidus while cooling.
    pub fn of(m: &Model, st: &State) -> Option<Summary> {
        let recs = records(m, st);
        if recs.is_empty() {
            return None;
        }
        let pct = |f: fn(&Record) -> f64| {
            let mut v: Vec<f64> = recs.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            [0.1, 0.5, 0.9].map(|q| v[((v.len() - 1) as f64 * q).round() as usize])
        };
        Some(Summary {
            particles: recs.len(),
            gradient: pct(|r| r.gradient),
            rate: pct(|r| r.rate),
            cooling_rate: pct(|r| r.cooling_rate),
        })
    }
    /// The `solidification:` line of `spatter run`.
    pub fn line(&self) -> String {
        let p = |v: [f64; 3], unit: &str| {
            format!("{:.3e} {unit} (10-90%: {:.3e} to {:.3e})", v[1], v[0], v[2])
        };
        format!(
            "solidification: {} particles froze from the liquid; median G {}, R {}, cooling rate {}",
            self.particles,
            p(self.gradient, "K/m"),
            p(self.rate, "m/s"),
            p(self.cooling_rate, "K/s")
        )
    }
}
