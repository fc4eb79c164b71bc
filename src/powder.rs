//! Powder-bed generator: grains of log-normal diameter,
//! clipped to a range, poured one at a time into the scene's `[powder]` box
//! and levelled at its top, as a recoater does.
//!
//! Deposition is sequential and quasi-static, a "drop and roll" packing
//! (Visscher & Bolsterli 1972): each grain enters at a seeded random lateral
//! position above the bed and descends under gravity until it rests on the
//! floor (the box's bottom face) or in a pocket of grains already laid. The
//! descent is a projected gradient walk: step down, then push the grain out of
//! every overlap along the contact normal and back inside the side walls; a
//! grain resting on one neighbour slides off it (frictionless: F22's contact
//! has no friction either), one resting on two or three (2D: two) stays. The
//! step halves whenever a step gains no height, down to a millionth of the
//! radius. A grain that comes to rest above the levelling height is removed
//! (the recoater), and pouring stops after `POUR_MISSES` removals in a row.
//! With `max_grains` instead, exactly that many grains are poured and none is
//! removed (the box's top is only where the pour starts), so the bed keeps the
//! drawn diameter distribution, which levelling does not (small grains fit
//! where large ones are removed). Deterministic: the same keys and seed give the same bed.
//!
//! The vertical is the last axis (y in 2D, z in 3D); in 2D the grains are discs.
//! Each grain is a lattice fill of its sphere with the powder phase: fixed
//! solid particles, or with `[powder] rigid = true` one rigid body per grain
//! (model/bodies.rs, crate::bodies).

use crate::error::InputError;
use crate::random::SplitMix;
use crate::scene::PowderDef;
use glam::DVec3;

/// Consecutive grains removed by the levelling before pouring stops.
const POUR_MISSES: usize = 200;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grain {
    /// In 2D the last component is 0.
    pub center: DVec3,
    pub radius: f64,
}

/// Log-normal diameters: ln d ~ N(ln median, log_sigma²), redrawn outside
/// [min, max] (a truncated log-normal, as a sieve leaves it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diameters {
    pub median: f64,
    pub log_sigma: f64,
    pub min: f64,
    pub max: f64,
}

impl Diameters {
    pub(crate) fn sample(&self, rng: &mut SplitMix) -> f64 {
        loop {
            // Box–Muller; 1 − u keeps the logarithm's argument in (0, 1].
            let (u1, u2) = (1.0 - rng.next_f64(), rng.next_f64());
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            let d = self.median * (self.log_sigma * z).exp();
            if d >= self.min && d <= self.max {
                return d;
            }
        }
    }

    /// P(d ≤ x) of the truncated distribution.
    pub fn cdf(&self, x: f64) -> f64 {
        let phi = |d: f64| {
            0.5 * (1.0
                + libm::erf((d / self.median).ln() / (self.log_sigma * std::f64::consts::SQRT_2)))
        };
        let (lo, hi) = (phi(self.min), phi(self.max));
        ((phi(x.clamp(self.min, self.max)) - lo) / (hi - lo)).clamp(0.0, 1.0)
    }
}

/// A validated `[powder]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct PowderSpec {
    /// Phase index of the grains.
    pub phase: usize,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub diameters: Diameters,
    pub seed: u64,
    pub max_grains: Option<usize>,
    /// Each grain is a rigid body (`[powder] rigid`).
    pub rigid: bool,
}

/// The poured bed.
#[derive(Debug, Clone, PartialEq)]
pub struct PowderBed {
    pub spec: PowderSpec,
    pub grains: Vec<Grain>,
    /// Highest grain top above the floor (m).
    pub thickness: f64,
    /// Grain volume over the box's volume up to the levelling height (2D: areas).
    pub packing_fraction: f64,
    /// Lookup grid over the box: cell → grains overlapping it.
    grid: Grid,
    /// The grain of each particle by its id (`NO_GRAIN` for none), from the
    /// initial state (`attach`).
    pub members: Vec<u32>,
}

/// `PowderBed::members` of a particle outside every grain.
pub const NO_GRAIN: u32 = u32::MAX;

impl PowderBed {
    /// Records each particle's grain (by id) from the initial fill: (id, phase,
    /// world position) of each of its `count` particles, the positions being the
    /// lattice sites setup filled.
    pub fn attach(
        &mut self,
        dim: usize,
        count: usize,
        particles: impl IntoIterator<Item = (u32, u32, [f64; 3])>,
    ) {
        let mut members = vec![NO_GRAIN; count];
        for (id, phase, x) in particles {
            if phase as usize != self.spec.phase {
                continue;
            }
            if let Some(k) = self.grain_at(x, dim) {
                members[id as usize] = k as u32;
            }
        }
        self.members = members;
    }

    /// The grain whose sphere holds x, if any.
    pub fn grain_at(&self, x: [f64; 3], dim: usize) -> Option<usize> {
        let x = DVec3::from(x);
        self.grid
            .near(x)
            .find(|&k| dist2(self.grains[k].center, x, dim) <= self.grains[k].radius.powi(2))
    }

    /// The one-line summary `validate` and `run` print.
    pub fn summary(&self, dim: usize) -> String {
        let n = self.grains.len();
        let ds: Vec<f64> = self.grains.iter().map(|g| 2.0 * g.radius).collect();
        let mean = ds.iter().sum::<f64>() / n.max(1) as f64;
        let (lo, hi) = ds.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &d| {
            (a.0.min(d), a.1.max(d))
        });
        let box_height = (self.spec.hi[dim - 1] - self.spec.lo[dim - 1]) * 1e6;
        format!(
            "powder: {n} grains ({}), diameters {:.2}-{:.2} um (mean {:.2} um), bed {:.2} um thick {}, packing fraction {:.3} {}",
            if dim == 2 { "discs" } else { "spheres" },
            lo * 1e6,
            hi * 1e6,
            mean * 1e6,
            self.thickness * 1e6,
            match self.spec.max_grains {
                None => format!("in a box {box_height:.2} um high (levelled there)"),
                Some(_) => "(max_grains: poured, not levelled)".to_string(),
            },
            self.packing_fraction,
            match self.spec.max_grains {
                None => "of the box",
                Some(_) => "of the footprint up to the bed's top",
            }
        )
    }
}

/// |a − b|² over the first `dim` axes.
fn dist2(a: DVec3, b: DVec3, dim: usize) -> f64 {
    let d = a - b;
    if dim == 2 {
        d.truncate().length_squared()
    } else {
        d.length_squared()
    }
}

/// Uniform cells over the box's lateral extent and height, each listing the
/// grains whose bounding box touches it.
#[derive(Debug, Clone, PartialEq)]
struct Grid {
    lo: DVec3,
    size: f64,
    n: [usize; 3],
    cells: Vec<Vec<usize>>,
}

impl Grid {
    fn new(lo: DVec3, hi: DVec3, size: f64, dim: usize) -> Grid {
        let mut n = [1; 3];
        for k in 0..dim {
            n[k] = (((hi[k] - lo[k]) / size).ceil() as usize).max(1);
        }
        Grid {
            lo,
            size,
            n,
            cells: vec![Vec::new(); n[0] * n[1] * n[2]],
        }
    }
    fn cell(&self, x: DVec3) -> [usize; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            let i = ((x[k] - self.lo[k]) / self.size).floor();
            c[k] = (i.max(0.0) as usize).min(self.n[k] - 1);
        }
        c
    }
    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }
    fn insert(&mut self, k: usize, g: &Grain) {
        let a = self.cell(g.center - g.radius);
        let b = self.cell(g.center + g.radius);
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    let i = self.index([x, y, z]);
                    self.cells[i].push(k);
                }
            }
        }
    }
    /// Grains listed in x's cell (every grain that can hold x).
    fn near(&self, x: DVec3) -> impl Iterator<Item = usize> + '_ {
        self.cells[self.index(self.cell(x))].iter().copied()
    }
    /// Grains listed within `reach` of x (candidates for contact).
    fn around(&self, x: DVec3, reach: f64) -> Vec<usize> {
        let a = self.cell(x - reach);
        let b = self.cell(x + reach);
        let mut out = Vec::new();
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    out.extend_from_slice(&self.cells[self.index([x, y, z])]);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Pours the bed a `[powder]` section describes.
pub fn pour(spec: PowderSpec, dim: usize) -> PowderBed {
    let up = dim - 1;
    let (lo, hi) = (DVec3::from(spec.lo), DVec3::from(spec.hi));
    let d_max = spec.diameters.max;
    // The grid reaches a grain diameter above the levelling height: grains
    // enter there before settling.
    let mut top = hi;
    top[up] += 2.0 * d_max;
    let mut grid = Grid::new(lo, top, d_max, dim);
    let mut rng = SplitMix(spec.seed);
    let mut grains: Vec<Grain> = Vec::new();
    // With a grain count nothing is levelled: every drawn grain stays, so the
    // bed keeps the drawn distribution (levelling removes grains resting above
    // the top and redraws, which favours small grains: chi-square 114 on
    // F22's 1500-grain bed).
    let levelled = spec.max_grains.is_none();
    let mut misses = 0;
    let mut bed_top = lo[up];
    while misses < POUR_MISSES && spec.max_grains.is_none_or(|m| grains.len() < m) {
        let radius = 0.5 * spec.diameters.sample(&mut rng);
        let mut x = DVec3::ZERO;
        for k in 0..up {
            x[k] = lo[k] + radius + rng.next_f64() * (hi[k] - lo[k] - 2.0 * radius);
        }
        x[up] = hi[up].max(bed_top) + radius;
        let g = settle(&grains, &grid, x, radius, &spec, dim);
        if levelled && g.center[up] + radius > hi[up] {
            misses += 1;
            continue;
        }
        misses = 0;
        bed_top = bed_top.max(g.center[up] + radius);
        grid.insert(grains.len(), &g);
        grains.push(g);
    }
    let thickness = grains
        .iter()
        .map(|g| g.center[up] + g.radius - lo[up])
        .fold(0.0, f64::max);
    let unit = |r: f64| {
        if dim == 2 {
            std::f64::consts::PI * r * r
        } else {
            4.0 / 3.0 * std::f64::consts::PI * r * r * r
        }
    };
    let solid: f64 = grains.iter().map(|g| unit(g.radius)).sum();
    // Levelled: the box; counted: the box's footprint up to the bed's top.
    let height = if levelled { hi[up] - lo[up] } else { thickness };
    let container: f64 = (0..up).map(|k| hi[k] - lo[k]).product::<f64>() * height;
    PowderBed {
        spec,
        grains,
        thickness,
        packing_fraction: solid / container,
        grid,
        members: Vec::new(),
    }
}

/// Quasi-static descent of one grain from x to its resting place.
fn settle(
    grains: &[Grain],
    grid: &Grid,
    mut x: DVec3,
    r: f64,
    spec: &PowderSpec,
    dim: usize,
) -> Grain {
    let up = dim - 1;
    let mut step = 0.25 * r;
    let reach = r + 0.5 * spec.diameters.max;
    // A grain near the top of another slides off slowly at first (the height it
    // loses per step is ~ step sin²θ): any descent counts as progress; the step
    // halves only when blocked. The cap bounds a grain rattling in its pocket.
    for _ in 0..SETTLE_STEPS {
        if step <= SETTLE_PRECISION * r {
            break;
        }
        let before = x[up];
        let mut trial = x;
        trial[up] -= step;
        let near = grid.around(trial, reach + step);
        let clear = project(&mut trial, r, grains, &near, spec, dim);
        if clear && trial[up] < before - 1e-9 * r {
            x = trial;
        } else {
            step *= 0.5;
        }
    }
    let near = grid.around(x, reach);
    lift_clear(&mut x, r, grains, &near, dim);
    Grain {
        center: x,
        radius: r,
    }
}

/// The descent stops when its step falls below this fraction of the radius:
/// a grain rests within about that distance of each of its supports.
const SETTLE_PRECISION: f64 = 1e-6;

/// Descent steps per grain at most.
const SETTLE_STEPS: usize = 200_000;

/// Raises x until it overlaps no grain beyond the tolerance (a safety net: the
/// accepted descent steps end clear): for each overlap, the height at which the
/// two spheres just touch above the other's centre. Only ever up, so it ends.
fn lift_clear(x: &mut DVec3, r: f64, grains: &[Grain], near: &[usize], dim: usize) {
    let up = dim - 1;
    loop {
        let mut lifted = false;
        for &k in near {
            let g = &grains[k];
            let reach = r + g.radius;
            // The projection's tolerance: a side contact within it is a
            // contact, and lifting would float the grain off the floor.
            if dist2(*x, g.center, dim) >= (reach * (1.0 - OVERLAP_TOLERANCE)).powi(2) {
                continue;
            }
            let lateral: f64 = (0..up).map(|a| (x[a] - g.center[a]).powi(2)).sum();
            let z = g.center[up] + (reach * reach - lateral).max(0.0).sqrt() * (1.0 + 1e-12);
            if z > x[up] {
                x[up] = z;
                lifted = true;
            }
        }
        if !lifted {
            return;
        }
    }
}

/// Pushes a grain at x out of its overlaps, then inside the walls and above the
/// floor; Gauss–Seidel sweeps settle several contacts at once. True when the
/// last sweep found no overlap deeper than 1e-9 of the radius (a wedge between
/// the floor and a grain converges slowly: such a trial counts as blocked).
fn project(
    x: &mut DVec3,
    r: f64,
    grains: &[Grain],
    near: &[usize],
    spec: &PowderSpec,
    dim: usize,
) -> bool {
    let up = dim - 1;
    for _ in 0..PROJECT_SWEEPS {
        // Walls and floor first: a sweep that then finds no overlap ends clear.
        for a in 0..up {
            x[a] = x[a].clamp(spec.lo[a] + r, spec.hi[a] - r);
        }
        x[up] = x[up].max(spec.lo[up] + r);
        let mut moved = false;
        for &k in near {
            let g = &grains[k];
            let d2 = dist2(*x, g.center, dim);
            let reach = r + g.radius;
            if d2 < (reach * (1.0 - OVERLAP_TOLERANCE)).powi(2) {
                let d = d2.sqrt().max(1e-12 * reach);
                // Out along the centre line to the contact distance (in 2D the
                // last components are 0 and stay 0).
                *x += (*x - g.center) * ((reach - d) / d);
                moved = true;
            }
        }
        if !moved {
            return true;
        }
    }
    false
}

/// Relative overlap of two grains that counts as touching.
const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Gauss–Seidel sweeps of one projection at most.
const PROJECT_SWEEPS: usize = 256;

/// Checks a `[powder]` section against the scene (file name for messages).
pub fn spec(
    file: &str,
    def: &PowderDef,
    phase: usize,
    dim: usize,
) -> Result<PowderSpec, InputError> {
    let err = |k: &str, m: String| InputError::new(file, &format!("powder.{k}"), m);
    let positive = |k: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(err(
                k,
                format!("must be a positive finite number (got {v})"),
            ))
        }
    };
    let d = &def.diameter;
    let diameters = Diameters {
        median: positive("diameter.median", d.median)?,
        log_sigma: positive("diameter.log_sigma", d.log_sigma)?,
        min: positive("diameter.min", d.min)?,
        max: positive("diameter.max", d.max)?,
    };
    if diameters.min >= diameters.max {
        return Err(err(
            "diameter.max",
            format!("must exceed diameter.min {} m (got {})", d.min, d.max),
        ));
    }
    // Rejection sampling needs a reasonable share of the distribution inside.
    let inside = {
        let phi = |x: f64| {
            0.5 * (1.0 + libm::erf((x / d.median).ln() / (d.log_sigma * std::f64::consts::SQRT_2)))
        };
        phi(d.max) - phi(d.min)
    };
    if inside < 1e-3 {
        return Err(err("diameter", format!("[min, max] holds {inside:.1e} of the log-normal: median or log_sigma do not fit the range")));
    }
    let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
    for (key, v, out) in [
        ("box.min", &def.box_.min, &mut lo),
        ("box.max", &def.box_.max, &mut hi),
    ] {
        if v.len() != dim || v.iter().any(|c| !c.is_finite()) {
            return Err(err(
                key,
                format!("needs {dim} finite components (got {v:?})"),
            ));
        }
        out[..dim].copy_from_slice(v);
    }
    for k in 0..dim {
        if hi[k] - lo[k] < diameters.max {
            return Err(err(
                "box.max",
                format!(
                    "the box must be at least one largest diameter ({} m) wide along every axis",
                    diameters.max
                ),
            ));
        }
    }
    if let Some(0) = def.max_grains {
        return Err(err("max_grains", "must be at least 1".into()));
    }
    Ok(PowderSpec {
        phase,
        lo,
        hi,
        diameters,
        seed: def.seed,
        max_grains: def.max_grains,
        rigid: def.rigid,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f22_diameters() -> Diameters {
        Diameters {
            median: 22e-6,
            log_sigma: 0.25,
            min: 16e-6,
            max: 32e-6,
        }
    }

    /// The sampled diameters follow the truncated log-normal: Pearson's χ² over
    /// 10 equiprobable bins of 20 000 draws below its 99.9% quantile for 9
    /// degrees of freedom (27.9), and every draw inside [min, max].
    #[test]
    fn diameters_follow_the_truncated_log_normal() {
        let d = f22_diameters();
        let mut rng = SplitMix(42);
        let n = 20_000;
        let mut counts = [0usize; 10];
        for _ in 0..n {
            let x = d.sample(&mut rng);
            assert!(x >= d.min && x <= d.max);
            let bin = ((d.cdf(x) * 10.0) as usize).min(9);
            counts[bin] += 1;
        }
        let e = n as f64 / 10.0;
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
        assert!(chi2 < 27.9, "chi2 = {chi2}, counts {counts:?}");
    }

    /// With a grain count (no levelling) the poured bed keeps the requested
    /// distribution: F22 §4.5's 1500 grains on 960 × 320 µm, Pearson's χ² over
    /// 10 equiprobable bins below 27.9 (99.9%, 9 degrees of freedom). (Levelled,
    /// the same pour measured χ² = 114: small grains favoured.)
    #[test]
    fn counted_bed_keeps_the_diameter_distribution() {
        let d = f22_diameters();
        let b = pour(
            PowderSpec {
                phase: 0,
                lo: [0.0; 3],
                hi: [9.6e-4, 3.2e-4, 6.0e-5],
                diameters: d,
                seed: 1,
                max_grains: Some(1500),
                rigid: false,
            },
            3,
        );
        // A counted pour pours exactly max_grains.
        assert_eq!(Some(b.grains.len()), b.spec.max_grains);
        let mut counts = [0usize; 10];
        for g in &b.grains {
            counts[((d.cdf(2.0 * g.radius) * 10.0) as usize).min(9)] += 1;
        }
        let e = b.grains.len() as f64 / 10.0;
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
        assert!(chi2 < 27.9, "chi2 = {chi2}, counts {counts:?}");
    }

    fn bed(dim: usize, seed: u64) -> PowderBed {
        let mut hi = [0.0; 3];
        hi[..dim].fill(240e-6);
        hi[dim - 1] = 100e-6;
        pour(
            PowderSpec {
                phase: 0,
                lo: [0.0; 3],
                hi,
                diameters: f22_diameters(),
                seed,
                max_grains: None,
                rigid: false,
            },
            dim,
        )
    }

    /// A poured 3D bed: no two grains overlap (beyond 1e-9 of a radius), every
    /// grain inside the box, the packing fraction in the poured range 0.5–0.65,
    /// and the same seed gives the same bed.
    #[test]
    fn poured_bed_is_packed_and_deterministic() {
        let b = bed(3, 7);
        for (i, g) in b.grains.iter().enumerate() {
            for a in 0..3 {
                assert!(g.center[a] - g.radius >= b.spec.lo[a] - 1e-12);
                assert!(g.center[a] + g.radius <= b.spec.hi[a] + 1e-12);
            }
            for h in &b.grains[..i] {
                let d = dist2(g.center, h.center, 3).sqrt();
                assert!(d >= (g.radius + h.radius) * (1.0 - 1e-9), "overlap {d}");
            }
        }
        assert!(
            (0.5..=0.65).contains(&b.packing_fraction),
            "{}",
            b.summary(3)
        );
        assert_eq!(b, bed(3, 7));
        assert_ne!(b.grains, bed(3, 8).grains);
    }

    /// Contact normals of grain i (unit, pointing into it): touching grains
    /// (gap below 1e-6 of its radius), the floor and the side walls.
    fn contact_normals(b: &PowderBed, i: usize, dim: usize) -> Vec<[f64; 3]> {
        let g = &b.grains[i];
        let up = dim - 1;
        // Ten times the descent's precision.
        let tol = 10.0 * SETTLE_PRECISION * g.radius;
        let mut out = Vec::new();
        for (j, h) in b.grains.iter().enumerate() {
            let d = dist2(g.center, h.center, dim).sqrt();
            if j != i && d - g.radius - h.radius < tol {
                let mut n = [0.0; 3];
                for a in 0..dim {
                    n[a] = (g.center[a] - h.center[a]) / d;
                }
                out.push(n);
            }
        }
        let mut wall = |a: usize, sign: f64| {
            let mut n = [0.0; 3];
            n[a] = sign;
            out.push(n);
        };
        if g.center[up] - g.radius - b.spec.lo[up] < tol {
            wall(up, 1.0);
        }
        for a in 0..up {
            if g.center[a] - g.radius - b.spec.lo[a] < tol {
                wall(a, 1.0);
            }
            if b.spec.hi[a] - g.center[a] - g.radius < tol {
                wall(a, -1.0);
            }
        }
        out
    }

    /// Every grain rests (frictionless): in 2D the upward direction lies in
    /// the cone of its contact normals, so the contact forces can carry its
    /// weight (a grain on one neighbour beside its top would roll off; the
    /// floor alone carries it); in 3D it touches the floor or at least two
    /// things (a necessary condition; the descent rolls grains out of saddles).
    #[test]
    fn every_grain_is_supported() {
        for dim in [2, 3] {
            let b = bed(dim, 3);
            for i in 0..b.grains.len() {
                let normals = contact_normals(&b, i, dim);
                let carried = if dim == 2 {
                    normals.iter().any(|n| n[1] > 1.0 - 1e-9)
                        || normals.iter().any(|ni| {
                            normals.iter().any(|nj| {
                                let det = ni[0] * nj[1] - ni[1] * nj[0];
                                det.abs() > 1e-12 && -nj[0] / det >= 0.0 && ni[0] / det >= 0.0
                            })
                        })
                } else {
                    normals.iter().any(|n| n[2] > 1.0 - 1e-9) || normals.len() >= 2
                };
                assert!(
                    carried,
                    "{dim}D grain {i}: {:?}, normals {normals:?}",
                    b.grains[i]
                );
            }
        }
    }
}
