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
//! - A `[scan]` of several tracks (3D): each track's own melt in its frame
//!   (`Hatch`; docs/outputs.md, "Each track of a hatch").

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
    /// A scan of several tracks: each track's own melt.
    hatch: Option<Hatch>,
}

/// The melt of each track of a `[scan]` of several tracks, in the track's own
/// frame (along its direction from its start, across to its left). A melt
/// event is a particle (by id) seen with liquid fraction ≥ ½ at a sample
/// after being seen below it (or never seen); it belongs to the last track
/// whose beam came on by that sample, and the particle stays that track's
/// melt until it is seen solid again, so melt of track k − 1 still liquid
/// while track k runs stays track k − 1's. A track's extent across, per
/// slice, is that of its melt in the pool below the initial surface; its
/// overlap with the track before is where the two extents meet, at the same
/// point of the plate.
struct Hatch {
    tracks: Vec<crate::model::ScanTrack>,
    /// Per track, per slice of Δx along it: the extent across of its melt
    /// (particle centres) and the deepest it reached below the initial surface.
    across: Vec<Vec<[f64; 2]>>,
    depth: Vec<Vec<f64>>,
    /// Per particle (by id): the track (+1; 0 none) of its last melt event
    /// and whether it was molten at the last sample.
    events: Vec<(u8, bool)>,
}

const EMPTY: [f64; 2] = [f64::INFINITY, f64::NEG_INFINITY];

impl Hatch {
    fn new(m: &Model) -> Option<Hatch> {
        let laser = m.laser.as_ref()?;
        if m.dim != 3 || laser.tracks.len() < 2 {
            return None;
        }
        let tracks: Vec<_> = laser.tracks.iter().take(255).copied().collect();
        let slices = |t: &crate::model::ScanTrack| (t.length / m.dx).ceil().max(1.0) as usize;
        Some(Hatch {
            across: tracks.iter().map(|t| vec![EMPTY; slices(t)]).collect(),
            depth: tracks.iter().map(|t| vec![f64::NAN; slices(t)]).collect(),
            events: Vec::new(),
            tracks,
        })
    }

    /// The track a sample at time t belongs to.
    fn at(&self, t: f64) -> Option<usize> {
        self.tracks.iter().rposition(|k| k.t_on <= t)
    }

    /// Take in one particle's state at a sample in track k (None: before the
    /// first): a melt event starts when it is molten and was not. Returns the
    /// track of its melt event (None: not molten, or molten before any track).
    fn event(&mut self, k: Option<usize>, id: u32, molten: bool) -> Option<usize> {
        let id = id as usize;
        if id >= self.events.len() {
            self.events.resize(id + 1, (0, false));
        }
        let e = &mut self.events[id];
        if molten && !e.1 {
            if let Some(k) = k {
                e.0 = k as u8 + 1;
            }
        }
        e.1 = molten;
        (molten && e.0 > 0).then(|| e.0 as usize - 1)
    }

    /// Take in one particle of the pool below the initial surface, `depth`
    /// under it, at lateral position (x, y), melted by track k.
    fn melt(&mut self, k: usize, x: [f64; 2], depth: f64, dx: f64) {
        let (along, across) = self.frame(k, x);
        let s = (along / dx).floor();
        if s < 0.0 || s as usize >= self.across[k].len() {
            return;
        }
        let s = s as usize;
        let e = &mut self.across[k][s];
        *e = [e[0].min(across), e[1].max(across)];
        let d = &mut self.depth[k][s];
        *d = if d.is_nan() { depth } else { d.max(depth) };
    }

    /// A lateral point in track k's frame: (along, across).
    fn frame(&self, k: usize, x: [f64; 2]) -> (f64, f64) {
        let t = &self.tracks[k];
        let rel = [x[0] - t.start[0], x[1] - t.start[1]];
        (
            rel[0] * t.dir[0] + rel[1] * t.dir[1],
            rel[1] * t.dir[0] - rel[0] * t.dir[1],
        )
    }

    /// The lateral point `along`, `across` of track k.
    fn point(&self, k: usize, along: f64, across: f64) -> [f64; 2] {
        let t = &self.tracks[k];
        [
            t.start[0] + along * t.dir[0] - across * t.dir[1],
            t.start[1] + along * t.dir[1] + across * t.dir[0],
        ]
    }

    /// Slice s of track k's melt and of the track before at the same point
    /// of the plate: the width across of their overlap, + Δx (0 where they do
    /// not meet; NaN where track k did not melt or the track before has no
    /// slice there).
    fn overlap(&self, k: usize, s: usize, dx: f64) -> f64 {
        let e = self.across[k][s];
        if k == 0 || e[1] < e[0] {
            return f64::NAN;
        }
        let along = (s as f64 + 0.5) * dx;
        let (along_before, _) = self.frame(k - 1, self.point(k, along, 0.0));
        let sb = (along_before / dx).floor();
        if sb < 0.0 || sb as usize >= self.across[k - 1].len() {
            return f64::NAN;
        }
        let b = self.across[k - 1][sb as usize];
        if b[1] < b[0] {
            return 0.0;
        }
        // the track before's extent, in track k's frame
        let ends = [b[0], b[1]].map(|a| self.frame(k, self.point(k - 1, along_before, a)).1);
        let (lo, hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
        (e[1].min(hi) - e[0].max(lo) + dx).max(0.0)
    }

    fn figures(&self, dx: f64) -> Vec<HatchTrack> {
        // the distance between the first two tracks' lines
        let (a, b) = (&self.tracks[0], &self.tracks[1]);
        let hatch_spacing =
            ((b.start[1] - a.start[1]) * a.dir[0] - (b.start[0] - a.start[0]) * a.dir[1]).abs();
        let mean = |v: &mut dyn Iterator<Item = f64>| {
            let (n, sum) = v
                .filter(|x| x.is_finite())
                .fold((0usize, 0.0), |(n, s), x| (n + 1, s + x));
            if n == 0 {
                f64::NAN
            } else {
                sum / n as f64
            }
        };
        let width = |e: &[f64; 2]| {
            if e[1] >= e[0] {
                e[1] - e[0] + dx
            } else {
                f64::NAN
            }
        };
        (0..self.tracks.len())
            .map(|k| {
                let t = &self.tracks[k];
                let n = self.across[k].len();
                // the steady part: a tenth of the track's length in from either end
                let steady = n / 10..n - n / 10;
                let melted = self.across[k].iter().filter(|e| e[1] >= e[0]).count();
                let w = mean(&mut self.across[k][steady.clone()].iter().map(width));
                // over the slices it melted: the overlap there, 0 where none
                let r = mean(&mut steady.clone().map(|j| self.overlap(k, j, dx)));
                HatchTrack {
                    track: k + 1,
                    t_on: t.t_on,
                    t_off: t.t_off,
                    line: [t.start[0], t.start[1]],
                    direction: t.dir,
                    melted_slices: melted,
                    width: w,
                    depth: mean(&mut self.depth[k][steady.clone()].iter().copied()),
                    centre_offset: mean(
                        &mut self.across[k][steady.clone()]
                            .iter()
                            .filter(|e| e[1] >= e[0])
                            .map(|e| 0.5 * (e[0] + e[1])),
                    ),
                    overlap_width: r,
                    overlap: r / w,
                    hatch_spacing,
                }
            })
            .collect()
    }
}

/// One track of a scan of several tracks (`/track`'s `tracks`): its own melt,
/// as the means over its steady part (a tenth of its length in from either
/// end) of the slices of Δx along it.
#[derive(Debug, Clone, Serialize)]
pub struct HatchTrack {
    /// 1, 2, ... in scan order.
    pub track: usize,
    pub t_on: f64,
    pub t_off: f64,
    /// Where the beam starts it (x, y), m, and the way it moves.
    pub line: [f64; 2],
    pub direction: [f64; 2],
    /// Slices along it that its melt reached.
    pub melted_slices: usize,
    /// Extent across of its melt below the initial surface, + Δx, m.
    pub width: f64,
    /// Deepest its melt reached below the initial surface, m.
    pub depth: f64,
    /// Centre of its melt across, from the beam's line (+ to the left of its
    /// direction), m.
    pub centre_offset: f64,
    /// Width across where its melt and the previous track's meet at the same
    /// point of the plate, + Δx (0 where they do not), m; NaN for the first
    /// track.
    pub overlap_width: f64,
    /// overlap_width / width.
    pub overlap: f64,
    /// The scan's distance between centre lines, m.
    pub hatch_spacing: f64,
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
    /// A scan of several tracks (3D): each track's own melt, in scan order.
    pub tracks: Vec<HatchTrack>,
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
            hatch: Hatch::new(m),
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
        let scan_track = self.hatch.as_ref().and_then(|h| h.at(time));
        for i in 0..st.active() {
            if !condensed(m, st, i) {
                continue;
            }
            let melted_by = self
                .hatch
                .as_mut()
                .and_then(|h| h.event(scan_track, st.id[i], st.heat[i][2] >= 0.5));
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
            let depth = self.initial_top[k] - (z - 0.5 * self.dx);
            deepest = deepest.max(depth);
            if m.dim == 3 {
                let y = x[1];
                self.melt_y[k] = [self.melt_y[k][0].min(y), self.melt_y[k][1].max(y)];
            }
            if let (Some(h), Some(t)) = (self.hatch.as_mut(), melted_by) {
                h.melt(t, [x[0], x[1]], depth, self.dx);
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
            tracks: self
                .hatch
                .as_ref()
                .map_or(Vec::new(), |h| h.figures(self.dx)),
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

impl HatchTrack {
    /// Its line at the end of a run.
    pub fn line(&self, of: usize) -> String {
        let mut l = format!(
            "track {} of {of} (beam on {:.4e} to {:.4e} s, from ({:.4e}, {:.4e}) m along ({:.3}, {:.3})): {} slices melted; over its steady part width {:.3e} m, depth {:.3e} m, melt centred {:+.2e} m across its line",
            self.track,
            self.t_on,
            self.t_off,
            self.line[0],
            self.line[1],
            self.direction[0],
            self.direction[1],
            self.melted_slices,
            self.width,
            self.depth,
            self.centre_offset,
        );
        if self.track > 1 {
            l.push_str(&format!(
                "; overlaps track {}'s melt by {:.3e} m ({:.2} of its width; hatch spacing {:.3e} m)",
                self.track - 1,
                self.overlap_width,
                self.overlap,
                self.hatch_spacing,
            ));
        }
        l
    }
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
        if !self.tracks.is_empty() {
            track.push_str(&format!(
                " (the {} tracks together; each below)",
                self.tracks.len()
            ));
        }
        lines.push(track);
        for t in &self.tracks {
            lines.push(t.line(self.tracks.len()));
        }
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::{Hatch, EMPTY};
    use crate::model::ScanTrack;

    /// Two tracks of a serpentine, 100 µm apart: +x at y = 100 µm, then −x at
    /// y = 200 µm, 200 µm long, Δx = 10 µm, with melt placed by hand.
    fn serpentine() -> Hatch {
        let track = |t_on: f64, start: [f64; 2], dir: [f64; 2]| ScanTrack {
            t_on,
            t_off: t_on + 1e-4,
            start,
            dir,
            length: 2e-4,
        };
        let tracks = vec![
            track(0.0, [1e-4, 1e-4], [1.0, 0.0]),
            track(2e-4, [3e-4, 2e-4], [-1.0, 0.0]),
        ];
        Hatch {
            across: vec![vec![EMPTY; 20]; 2],
            depth: vec![vec![f64::NAN; 20]; 2],
            events: Vec::new(),
            tracks,
        }
    }

    /// Melt of track 0 over y ∈ [40, 160] µm and of track 1 over [150, 260] µm
    /// at every x of the plate the two share: each track's width is its own
    /// extent + Δx, its centre its offset from its line (+ to the left of its
    /// way: −y for the track along −x), and the overlap the shared 10 µm + Δx.
    #[test]
    fn each_track_its_own_melt_and_the_overlap_where_they_meet() {
        let dx = 1e-5;
        let mut h = serpentine();
        for s in 0..20 {
            let x = 1e-4 + (s as f64 + 0.5) * dx;
            for (k, ys) in [(0, [40e-6, 160e-6]), (1, [150e-6, 260e-6])] {
                for y in ys {
                    h.melt(k, [x, y], 3e-5, dx);
                }
            }
        }
        let f = h.figures(dx);
        assert_eq!(f.len(), 2);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(
            close(f[0].width, 130e-6) && close(f[1].width, 120e-6),
            "{f:?}"
        );
        // track 0 centred at 100 µm on its line; track 1's melt at 205 µm is
        // 5 µm to the right of its way (−x), i.e. −5 µm across its line
        assert!(close(f[0].centre_offset, 0.0), "{f:?}");
        assert!(close(f[1].centre_offset, -5e-6), "{f:?}");
        assert!(f[0].overlap_width.is_nan(), "{f:?}");
        assert!(close(f[1].overlap_width, 20e-6), "{f:?}");
        assert!(close(f[1].overlap, 20.0 / 120.0), "{f:?}");
        assert!(
            close(f[1].hatch_spacing, 1e-4) && close(f[1].depth, 3e-5),
            "{f:?}"
        );
        // apart by more than their half widths: no overlap
        let mut apart = serpentine();
        for s in 0..20 {
            let x = 1e-4 + (s as f64 + 0.5) * dx;
            apart.melt(0, [x, 60e-6], 3e-5, dx);
            apart.melt(0, [x, 140e-6], 3e-5, dx);
            apart.melt(1, [x, 160e-6], 3e-5, dx);
            apart.melt(1, [x, 240e-6], 3e-5, dx);
        }
        assert_eq!(apart.figures(dx)[1].overlap_width, 0.0);
    }

    /// A particle belongs to the track in which it melted until it freezes:
    /// still liquid when the next track starts, it is the first track's;
    /// melted again after freezing, the second's.
    #[test]
    fn melt_belongs_to_the_track_it_melted_in() {
        let mut h = serpentine();
        assert_eq!(h.event(h.at(-1.0), 7, true), None); // molten before any track
        assert_eq!(h.event(h.at(5e-5), 7, false), None);
        assert_eq!(h.event(h.at(5e-5), 7, true), Some(0));
        assert_eq!(h.event(h.at(2.5e-4), 7, true), Some(0)); // still liquid
        assert_eq!(h.event(h.at(2.6e-4), 7, false), None); // froze
        assert_eq!(h.event(h.at(2.7e-4), 7, true), Some(1)); // remelted
        assert_eq!(h.event(h.at(2.7e-4), 3, true), Some(1)); // first melt, track 1
    }
}
