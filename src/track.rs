//! The melt track a laser scan leaves: per slice of width Δx
//! along x (the scan axis of the scenes), the depth the melt reached below the
//! initial surface, the track's width (3D), the height of the resolidified
//! surface relative to the initial one and the peak temperature; and the melt
//! pool's figures over the whole run (hottest, deepest, longest).
//!
//! Host side, from the states the run reads back anyway (every frame and
//! diagnostics sample): the depth and width are the extremes of the samples, so a
//! pool that reaches deeper between two samples is seen at the next one only if
//! it is still there (output_interval × scan speed is the resolution along the
//! track: 20 µm at 1e-5 s and 2 m/s). A resumed run starts its track at the resume.
//!
//! - The pool (crate::pool): the largest connected region of melt (liquid
//!   fraction ≥ ½, neighbours within 1.5Δx); a droplet flying, or landed on
//!   the surface or in the track (which sinks below the initial surface), is
//!   detached melt, not the pool. Melt in the pool counts for a slice where its
//!   lower edge is below the slice's initial surface.
//! - Pool length and width at a sample: the extent of the pool (written into
//!   `/diagnostics`, with its volume and the detached melt); its depth: the
//!   deepest of its particles below the initial surface of their slices, − ½Δx.
//! - Initial surface: per slice, the highest condensed (liquid or solid) particle
//!   at the first state, + ½Δx.
//! - Depth: initial surface − (lowest melt particle ever seen in the slice − ½Δx);
//!   the track is the slices whose depth exceeds ½Δx.
//! - Width (3D): extent along y of the melt ever seen in the slice, + Δx.
//! - Height: the top of the slice's condensed column at the end + ½Δx − initial
//!   surface, on the beam's line in 3D (|y − y_beam| ≤ Δx); the column is read
//!   from the bottom up and ends at the first gap wider than 1.5Δx, so a droplet
//!   flying above the surface does not count as surface.

use crate::model::Model;
use crate::pool::PoolFigures;
use crate::scene::PhaseKind;
use crate::state::State;
use serde::Serialize;

pub struct Track {
    x0: f64,
    dx: f64,
    up: usize,
    /// Beam line (y) in 3D.
    y_beam: f64,
    initial_top: Vec<f64>,
    lowest_melt: Vec<f64>,
    melt_y: Vec<[f64; 2]>,
    peak_t: Vec<f64>,
    /// The depression under the beam at the last state observed.
    depression_now: Option<f64>,
    /// The pool's figures at the last state observed (depth below the
    /// initial surface).
    pool_now: PoolFigures,
    pub pool: PoolPeaks,
    /// Powder scenes: which particles (by id) have been seen molten.
    molten_ids: Vec<bool>,
}

/// Powder scenes: the grains by how much of them melted over the samples (a
/// particle counts once seen with liquid fraction ≥ ½; it may have resolidified
/// since).
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct GrainMelting {
    pub grains: usize,
    pub fully_molten: usize,
    pub partially_molten: usize,
    pub untouched: usize,
}

/// The melt pool's extremes over the samples of the run: the hottest particle
/// (any), the deepest melt below the initial surface, the longest (x) and widest
/// (y, 3D) extent of the melt in the pool.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct PoolPeaks {
    pub max_temperature: f64,
    pub max_temperature_time: f64,
    pub max_depth: f64,
    pub max_depth_time: f64,
    pub max_length: f64,
    pub max_width: f64,
    /// Deepest the surface under the beam sank below the initial surface.
    pub max_depression: f64,
    pub max_depression_time: f64,
}

/// One slice of the track (only slices the melt reached).
#[derive(Debug, Clone, Serialize)]
pub struct Slice {
    /// Slice centre, m.
    pub x: f64,
    /// The initial surface (top of the condensed material + ½Δx), m.
    pub initial_surface: f64,
    pub depth: f64,
    /// 0 in 2D.
    pub width: f64,
    pub height: f64,
    pub peak_temperature: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct TrackProfile {
    pub dx: f64,
    pub slices: Vec<Slice>,
    pub pool: PoolPeaks,
    /// Powder scenes only.
    pub grains: Option<GrainMelting>,
}

pub(crate) fn condensed(m: &Model, st: &State, i: usize) -> bool {
    let ph = &m.phases[st.phase[i] as usize];
    ph.conducts() && matches!(ph.kind, PhaseKind::Liquid | PhaseKind::Solid)
}

/// Scenes with a laser and a phase that melts have a track.
pub fn wanted(m: &Model) -> bool {
    m.laser.is_some()
        && m.phases
            .iter()
            .any(|p| p.thermal.and_then(|t| t.melting).is_some())
}

impl Track {
    pub fn new(m: &Model, st: &State) -> Option<Track> {
        if !wanted(m) || st.heat.is_empty() {
            return None;
        }
        let laser = m.laser.as_ref()?;
        let slices = ((m.domain_hi[0] - m.domain_lo[0]) / m.dx).ceil().max(1.0) as usize;
        let y_beam =
            laser.path.iter().map(|p| p.1[1]).sum::<f64>() / laser.path.len().max(1) as f64;
        let mut t = Track {
            x0: m.domain_lo[0],
            dx: m.dx,
            up: m.dim as usize - 1,
            y_beam,
            initial_top: vec![f64::NEG_INFINITY; slices],
            lowest_melt: vec![f64::INFINITY; slices],
            melt_y: vec![[f64::INFINITY, f64::NEG_INFINITY]; slices],
            peak_t: vec![f64::NEG_INFINITY; slices],
            depression_now: None,
            pool_now: PoolFigures::default(),
            pool: PoolPeaks::default(),
            molten_ids: m
                .powder
                .as_ref()
                .map_or(Vec::new(), |b| vec![false; b.members.len()]),
        };
        for i in 0..st.active() {
            if condensed(m, st, i) {
                if let Some(k) = t.slice(m, st, i) {
                    let z = m.to_world(st.pos[i])[t.up] + 0.5 * m.dx;
                    t.initial_top[k] = t.initial_top[k].max(z);
                }
            }
        }
        t.observe(m, st);
        Some(t)
    }

    fn slice(&self, m: &Model, st: &State, i: usize) -> Option<usize> {
        let x = m.to_world(st.pos[i])[0];
        let k = ((x - self.x0) / self.dx).floor();
        (k >= 0.0 && (k as usize) < self.initial_top.len()).then_some(k as usize)
    }

    /// Take in one state read back during the run.
    pub fn observe(&mut self, m: &Model, st: &State) {
        // Powder scenes only (the tally is empty otherwise).
        let tally = if self.molten_ids.is_empty() {
            0
        } else {
            st.active()
        };
        for i in 0..tally {
            if st.heat[i][2] >= 0.5 {
                if let Some(seen) = self.molten_ids.get_mut(st.id[i] as usize) {
                    *seen = true;
                }
            }
        }
        let time = st.sim.time as f64;
        let regions = crate::pool::melt_regions(m, st);
        let mut in_pool = vec![false; st.active()];
        regions.pool.iter().for_each(|&i| in_pool[i] = true);
        let mut deepest = f64::NEG_INFINITY;
        for i in 0..st.active() {
            if !condensed(m, st, i) {
                continue;
            }
            let t = st.heat[i][1];
            if t as f64 > self.pool.max_temperature {
                self.pool.max_temperature = t as f64;
                self.pool.max_temperature_time = time;
            }
            let Some(k) = self.slice(m, st, i) else {
                continue;
            };
            self.peak_t[k] = self.peak_t[k].max(t as f64);
            let x = m.to_world(st.pos[i]);
            let z = x[self.up];
            if !in_pool[i] || z - 0.5 * self.dx >= self.initial_top[k] {
                continue;
            }
            self.lowest_melt[k] = self.lowest_melt[k].min(z);
            deepest = deepest.max(self.initial_top[k] - (z - 0.5 * self.dx));
            if m.dim == 3 {
                let y = x[1];
                self.melt_y[k] = [self.melt_y[k][0].min(y), self.melt_y[k][1].max(y)];
            }
        }
        self.pool_now = PoolFigures::of(m, st, &regions, Some(deepest.max(0.0)));
        self.pool.max_length = self.pool.max_length.max(self.pool_now.length);
        self.pool.max_width = self.pool.max_width.max(self.pool_now.width);
        self.depression_now = self.depression(m, st);
        if let Some(d) = self.depression_now {
            if d > self.pool.max_depression {
                self.pool.max_depression = d;
                self.pool.max_depression_time = time;
            }
        }
        if deepest > self.pool.max_depth {
            self.pool.max_depth = deepest;
            self.pool.max_depth_time = time;
        }
    }

    /// The depression under the beam at the state last observed (`/diagnostics`).
    pub fn depression_now(&self) -> Option<f64> {
        self.depression_now
    }

    /// The pool's figures at the state last observed (`/diagnostics`).
    pub fn pool_now(&self) -> PoolFigures {
        self.pool_now
    }

    /// Depth of the surface under the beam below the initial surface (m; > 0:
    /// sunk): the column top of the slice under the beam centre (on the beam line
    /// in 3D), as `finish` reads it. None while the beam is outside the slices or
    /// the column is empty.
    fn depression(&self, m: &Model, st: &State) -> Option<f64> {
        let laser = m.laser.as_ref()?;
        let c = laser.centre_at(st.sim.time as f64);
        let k = ((c[0] - self.x0) / self.dx).floor();
        if k < 0.0 || k as usize >= self.initial_top.len() {
            return None;
        }
        let k = k as usize;
        let mut zs: Vec<f64> = (0..st.active())
            .filter(|&i| condensed(m, st, i) && self.slice(m, st, i) == Some(k))
            .map(|i| m.to_world(st.pos[i]))
            .filter(|x| m.dim < 3 || (x[1] - c[1]).abs() <= self.dx)
            .map(|x| x[self.up])
            .collect();
        let top = column_top(&mut zs, self.dx)? + 0.5 * self.dx;
        Some(self.initial_top[k] - top)
    }

    /// The profile from the final state (the resolidified surface).
    pub fn finish(&self, m: &Model, st: &State) -> TrackProfile {
        let n = self.initial_top.len();
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); n];
        for i in 0..st.active() {
            if !condensed(m, st, i) {
                continue;
            }
            let x = m.to_world(st.pos[i]);
            if m.dim == 3 && (x[1] - self.y_beam).abs() > self.dx {
                continue;
            }
            if let Some(k) = self.slice(m, st, i) {
                columns[k].push(x[self.up]);
            }
        }
        // Slices the melt reached at least half a row below the initial surface.
        let remelted =
            |k: usize| self.initial_top[k] - (self.lowest_melt[k] - 0.5 * self.dx) > 0.5 * self.dx;
        let slices = (0..n)
            .filter(|&k| self.initial_top[k].is_finite() && remelted(k))
            .map(|k| {
                let top =
                    column_top(&mut columns[k], self.dx).map_or(f64::NAN, |z| z + 0.5 * self.dx);
                Slice {
                    x: self.x0 + (k as f64 + 0.5) * self.dx,
                    initial_surface: self.initial_top[k],
                    depth: self.initial_top[k] - (self.lowest_melt[k] - 0.5 * self.dx),
                    width: if m.dim == 3 {
                        self.melt_y[k][1] - self.melt_y[k][0] + self.dx
                    } else {
                        0.0
                    },
                    height: top - self.initial_top[k],
                    peak_temperature: self.peak_t[k],
                }
            })
            .collect();
        TrackProfile {
            dx: self.dx,
            slices,
            pool: self.pool,
            grains: self.grain_melting(m),
        }
    }

    fn grain_melting(&self, m: &Model) -> Option<GrainMelting> {
        let bed = m.powder.as_ref()?;
        let n = bed.grains.len();
        let (mut size, mut molten) = (vec![0usize; n], vec![0usize; n]);
        for (id, &g) in bed.members.iter().enumerate() {
            if g == crate::powder::NO_GRAIN {
                continue;
            }
            size[g as usize] += 1;
            if self.molten_ids.get(id).copied().unwrap_or(false) {
                molten[g as usize] += 1;
            }
        }
        let mut out = GrainMelting {
            grains: n,
            ..GrainMelting::default()
        };
        for (s, k) in size.iter().zip(&molten) {
            match (*k, *s) {
                (0, _) => out.untouched += 1,
                (k, s) if k == s => out.fully_molten += 1,
                _ => out.partially_molten += 1,
            }
        }
        Some(out)
    }
}

/// The top of the column that stands on the bottom: up from the lowest particle
/// while each next one is within 1.5Δx.
pub(crate) fn column_top(zs: &mut [f64], dx: f64) -> Option<f64> {
    zs.sort_by(|a, b| a.total_cmp(b));
    let last = *zs.last()?;
    Some(
        zs.windows(2)
            .find(|w| w[1] - w[0] > 1.5 * dx)
            .map_or(last, |w| w[0]),
    )
}

impl TrackProfile {
    /// The mean remelt depth of the first and of the last tenth of the melted
    /// slices (where the scan starts and where it ends); None when nothing melted.
    pub fn end_depths(&self) -> Option<(f64, f64)> {
        let s = &self.slices;
        if s.is_empty() {
            return None;
        }
        let tenth = (s.len() / 10).max(1);
        let mean_depth =
            |part: &[Slice]| part.iter().map(|x| x.depth).sum::<f64>() / part.len() as f64;
        Some((mean_depth(&s[..tenth]), mean_depth(&s[s.len() - tenth..])))
    }

    /// The mean of a slice figure over the slices where it is finite.
    /// How much the track's width varies along x in its steady part (the
    /// slices between a tenth and nine tenths of the melted length): the
    /// coefficient of variation std/mean of the widths; NaN in 2D (no width)
    /// or with fewer than three slices there.
    pub fn width_spread(&self) -> f64 {
        let w: Vec<f64> = self
            .steady()
            .iter()
            .map(|s| s.width)
            .filter(|w| w.is_finite() && *w > 0.0)
            .collect();
        if w.len() < 3 {
            return f64::NAN;
        }
        let mean = w.iter().sum::<f64>() / w.len() as f64;
        let var = w.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / w.len() as f64;
        var.sqrt() / mean
    }

    /// The steady part of the track: the slices between a tenth and nine
    /// tenths of the melted length (the start and the end are transients).
    pub fn steady(&self) -> &[Slice] {
        let n = self.slices.len();
        &self.slices[n / 10..n - n / 10]
    }

    /// The mean of `f` over the steady slices (NaN without any).
    pub fn steady_mean(&self, f: impl Fn(&Slice) -> f64) -> f64 {
        let v: Vec<f64> = self
            .steady()
            .iter()
            .map(f)
            .filter(|v| v.is_finite())
            .collect();
        if v.is_empty() {
            return f64::NAN;
        }
        v.iter().sum::<f64>() / v.len() as f64
    }

    pub fn mean(&self, f: impl Fn(&Slice) -> f64) -> f64 {
        let v: Vec<f64> = self
            .slices
            .iter()
            .map(f)
            .filter(|v| v.is_finite())
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }

    /// Lines for the end of a run.
    pub fn summary(&self, dim: u32) -> Vec<String> {
        let p = &self.pool;
        let mut lines = vec![format!(
            "melt pool: peak temperature {:.1} K (t = {:.4e} s), deepest {:.3e} m (t = {:.4e} s), longest {:.3e} m, surface under the beam at most {:.3e} m below the initial surface (t = {:.4e} s){}",
            p.max_temperature,
            p.max_temperature_time,
            p.max_depth,
            p.max_depth_time,
            p.max_length,
            p.max_depression,
            p.max_depression_time,
            if dim == 3 { format!(", widest {:.3e} m", p.max_width) } else { String::new() }
        )];
        if let Some(g) = &self.grains {
            lines.push(format!(
                "powder: of {} grains {} fully molten, {} partially, {} untouched (a particle counts once seen with liquid fraction >= 1/2 at a sample)",
                g.grains, g.fully_molten, g.partially_molten, g.untouched
            ));
        }
        let s = &self.slices;
        if s.is_empty() {
            lines.push("track: nothing melted".into());
            return lines;
        }
        let stats = |f: &dyn Fn(&Slice) -> f64| {
            let v: Vec<f64> = s.iter().map(f).filter(|v| v.is_finite()).collect();
            let mean = self.mean(f);
            let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            format!("mean {mean:.3e} m (min {lo:.3e}, max {hi:.3e})")
        };
        let (first_tenth, last_tenth) = self.end_depths().expect("slices melted");
        let mut track = format!(
            "track: {} slices of {:.1e} m melted, x from {:.4e} to {:.4e} m: remelt depth {}; first tenth {:.3e} m, last tenth {:.3e} m; surface height {} relative to the initial surface",
            s.len(),
            self.dx,
            s[0].x,
            s[s.len() - 1].x,
            stats(&|x| x.depth),
            first_tenth,
            last_tenth,
            stats(&|x| x.height),
        );
        if dim == 3 {
            track.push_str(&format!("; width {}", stats(&|x| x.width)));
        }
        lines.push(track);
        lines
    }
}
