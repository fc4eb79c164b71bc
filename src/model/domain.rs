//! The domain: its box and periodic axes, walls and open sides, the cell grid, and
//! the axis a hydrostatic start stacks the fluid along.

use super::*;

/// The box's low and high corners and its periodic axes.
type DomainBox = ([f64; 3], [f64; 3], [bool; 3]);
/// The cell grid: its origin, cells per axis and cell size.
type CellGrid = ([f64; 3], [u32; 3], [f64; 3]);

pub(super) fn domain_box(cx: &Ctx, scene: &SceneFile, dim: u32) -> Result<DomainBox, InputError> {
    let lo = cx.vector("domain.min", &scene.domain.min, dim)?;
    let hi = cx.vector("domain.max", &scene.domain.max, dim)?;
    for a in 0..dim as usize {
        if hi[a] <= lo[a] {
            return Err(cx.err(
                "domain.max",
                format!("must exceed domain.min on every axis (axis {a})"),
            ));
        }
    }
    let mut periodic = [false; 3];
    if !scene.domain.periodic.is_empty() {
        if scene.domain.periodic.len() != dim as usize {
            return Err(cx.err("domain.periodic", format!("needs {dim} entries")));
        }
        periodic[..dim as usize].copy_from_slice(&scene.domain.periodic);
    }
    Ok((lo, hi, periodic))
}

/// How close (in particle spacings) a length must come to a whole number of
/// spacings to count as one: far above the rounding of a spacing written to eight
/// digits (L/30 as 6.6666667e-5 leaves 1.5e-7), far below any gap a user means.
pub const LATTICE_TOLERANCE: f64 = 1e-6;

/// Lattice sites along an extent: the nearest whole number of spacings when the
/// extent is within `LATTICE_TOLERANCE` of one, else Err(the fractional gap the
/// last site would leave, in spacings).
pub fn lattice_sites(extent: f64, dx: f64) -> Result<u64, f64> {
    let r = extent / dx;
    let n = r.round();
    if (r - n).abs() <= LATTICE_TOLERANCE * r.max(1.0) && n >= 1.0 {
        Ok(n as u64)
    } else {
        Err(r - r.floor())
    }
}

/// Sites per axis inside the domain. An extent within `LATTICE_TOLERANCE` of a
/// whole number of spacings gets that number; any other leaves a gap of less than
/// one spacing empty before the far wall (or inside the period), which a warning
/// names (the peer-comparison scene keeps its peer's box on purpose).
pub(super) fn domain_sites(
    cx: &Ctx,
    dim: u32,
    lo: [f64; 3],
    hi: [f64; 3],
    dx: f64,
    warnings: &mut Vec<String>,
) -> [u64; 3] {
    let mut sites = [1u64; 3];
    for a in 0..dim as usize {
        let extent = hi[a] - lo[a];
        sites[a] = lattice_sites(extent, dx).unwrap_or_else(|gap| {
            warnings.push(format!(
                "{}: key `domain.max`: the extent along {} is {:.6} particle spacings \
                 (dx = {dx} m), not a whole number: a {gap:.3} dx gap stays empty before \
                 the far side; make the extent a multiple of dx",
                cx.file,
                AXES[a],
                extent / dx
            ));
            (extent / dx).floor().max(1.0) as u64
        });
    }
    sites
}

pub const AXES: [&str; 3] = ["x", "y", "z"];

/// A box face on a lattice site (within `LATTICE_TOLERANCE` of lo + (k + ½) dx)
/// fills or skips that whole row depending on rounding: warn, naming the shape,
/// the axis and where the face sits.
pub(super) fn box_face_warnings(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
    lo: [f64; 3],
    dx: f64,
    warnings: &mut Vec<String>,
) {
    for (i, s) in scene.shapes.iter().enumerate() {
        let Some(b) = &s.box_ else { continue };
        for (face, values) in [("min", &b.min), ("max", &b.max)] {
            for (a, &x) in values.iter().enumerate().take(dim as usize) {
                let u = (x - lo[a]) / dx - 0.5;
                if (u - u.round()).abs() <= LATTICE_TOLERANCE * u.abs().max(1.0) {
                    warnings.push(format!(
                        "{}: key `shapes[{i}].box.{face}`: along {} the face sits on a row of \
                         lattice sites ({:.6} dx from domain.min), so whether that row is \
                         filled depends on rounding; move the face by half a spacing",
                        cx.file,
                        AXES[a],
                        u + 0.5
                    ));
                }
            }
        }
    }
}

/// The axis a hydrostatic start stacks the fluid along: gravity must point along
/// exactly one axis, and that axis must not be periodic (no top to hang from).
pub(super) fn hydrostatic_axis(
    cx: &Ctx,
    gravity: [f64; 3],
    periodic: [bool; 3],
) -> Result<usize, InputError> {
    let key = "simulation.initial_pressure";
    let axes: Vec<usize> = (0..3).filter(|&a| gravity[a] != 0.0).collect();
    let &[a] = axes.as_slice() else {
        return Err(cx.err(
            key,
            format!(
                "\"hydrostatic\" needs simulation.gravity along exactly one axis (got {gravity:?})"
            ),
        ));
    };
    if periodic[a] {
        return Err(cx.err(
            key,
            format!("\"hydrostatic\" needs a non-periodic gravity axis (axis {a} is periodic)"),
        ));
    }
    Ok(a)
}

#[allow(clippy::too_many_arguments)]
pub(super) fn cell_grid(
    cx: &Ctx,
    dim: u32,
    lo: [f64; 3],
    hi: [f64; 3],
    periodic: [bool; 3],
    support: f64,
    dx: f64,
    wall_layers: u32,
) -> Result<CellGrid, InputError> {
    let mut origin = [0.0; 3];
    let mut grid = [1u32; 3];
    let mut cell = [1.0; 3];
    for a in 0..dim as usize {
        let len = hi[a] - lo[a];
        if periodic[a] {
            // Cells tile the period exactly so wrapped neighbours land in whole cells.
            // A period within LATTICE_TOLERANCE of a whole number of supports (Δx =
            // L/n written in decimal) gets that many cells: they are then shorter
            // than the support by at most that fraction, where the kernel is 0 to
            // far below f32 resolution (quintic: (3 − q)^5 < 1e-27).
            let n = (len / support * (1.0 + LATTICE_TOLERANCE)).floor();
            if n < 3.0 {
                return Err(cx.err(
                    "domain.max",
                    format!("periodic axis {a} must span at least 3 kernel supports ({:.3e} m), got {len:.3e} m", 3.0 * support),
                ));
            }
            let sites = len / dx;
            if (sites - sites.round()).abs() > 1e-6 * sites.max(1.0) {
                return Err(cx.err(
                    "simulation.dx",
                    format!("periodic length {len:e} m along axis {a} is not a multiple of dx"),
                ));
            }
            origin[a] = lo[a];
            grid[a] = n as u32;
            cell[a] = len / n;
        } else {
            let pad = (wall_layers as f64 + 1.0) * dx;
            origin[a] = lo[a] - pad;
            let n = ((len + 2.0 * pad) / support).ceil().max(1.0);
            if n > 1.0e6 {
                return Err(cx.err(
                    "simulation.dx",
                    format!("cell grid too large along axis {a} ({n} cells)"),
                ));
            }
            grid[a] = n as u32;
            cell[a] = support;
        }
    }
    let total: f64 = grid.iter().map(|&g| g as f64).product();
    if total > 4.0e8 {
        return Err(cx.err(
            "simulation.dx",
            format!("cell grid of {total:e} cells does not fit in memory"),
        ));
    }
    Ok((origin, grid, cell))
}

pub(super) fn check_walls(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
    dim: u32,
    periodic: [bool; 3],
) -> Result<(), InputError> {
    let is_wall = |name: &str| {
        phases
            .iter()
            .any(|p| p.name == name && p.kind == PhaseKind::Wall)
    };
    // Walls go on every non-periodic side that is not open.
    let open = open_side_flags(scene);
    let needs_walls = (0..dim as usize).any(|a| !periodic[a] && open[a].iter().any(|o| !o));
    match &scene.domain.wall_phase {
        Some(w) if !is_wall(w) => {
            return Err(cx.err(
                "domain.wall_phase",
                format!("`{w}` is not a phase of kind \"wall\""),
            ))
        }
        None if needs_walls => {
            return Err(cx.err(
                "domain.wall_phase",
                "a domain with a non-periodic axis needs wall_phase",
            ))
        }
        _ => {}
    }
    for side in &scene.domain.open_sides {
        check_side(cx, "domain.open_sides", side, dim, periodic)?;
    }
    for (side, w) in &scene.domain.wall_sides {
        let key = format!("domain.wall_sides.{side}");
        check_side(cx, &key, side, dim, periodic)?;
        if !is_wall(w) {
            return Err(cx.err(&key, format!("`{w}` is not a phase of kind \"wall\"")));
        }
    }
    Ok(())
}

pub(super) fn open_side_flags(scene: &SceneFile) -> [[bool; 2]; 3] {
    let mut open = [[false; 2]; 3];
    for (a, pair) in crate::scene::SIDE_NAMES.iter().enumerate() {
        for (k, name) in pair.iter().enumerate() {
            open[a][k] = scene.domain.open_sides.iter().any(|s| s == name);
        }
    }
    open
}

/// A side named in the domain must exist and have walls (not absent, not periodic).
fn check_side(
    cx: &Ctx,
    key: &str,
    side: &str,
    dim: u32,
    periodic: [bool; 3],
) -> Result<(), InputError> {
    let Some(axis) = crate::scene::side_axis(side) else {
        return Err(cx.err(
            key,
            format!("unknown side `{side}` (use x_min, x_max, y_min, y_max, z_min, z_max)"),
        ));
    };
    if axis >= dim as usize || periodic[axis] {
        return Err(cx.err(
            key,
            format!("side `{side}` has no wall (axis absent or periodic)"),
        ));
    }
    Ok(())
}

impl Model {
    /// How far the world point `x` is beyond each face of the domain: (axis,
    /// side, distance in m, the side is open) for every non-periodic face it is
    /// outside of. The watchdog and the wall-leakage tally measure penetration
    /// with it.
    pub fn beyond_faces(&self, x: [f64; 3]) -> Vec<(usize, usize, f64, bool)> {
        let mut out = Vec::new();
        for a in 0..self.dim as usize {
            if self.periodic[a] {
                continue;
            }
            let (lo, hi) = (self.domain_lo[a], self.domain_hi[a]);
            for (side, beyond) in [(0, lo - x[a]), (1, x[a] - hi)] {
                if beyond > 0.0 {
                    out.push((a, side, beyond, self.open_sides[a][side]));
                }
            }
        }
        out
    }

    /// The open faces world point `x` lies within `within` of (inside or
    /// beyond them), as the outward unit vectors' (axis, sign).
    pub fn open_faces_near(&self, x: [f64; 3], within: f64) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        for a in (0..self.dim as usize).filter(|&a| !self.periodic[a]) {
            let [open_lo, open_hi] = self.open_sides[a];
            if open_lo && x[a] - self.domain_lo[a] < within {
                out.push((a, -1.0));
            }
            if open_hi && self.domain_hi[a] - x[a] < within {
                out.push((a, 1.0));
            }
        }
        out
    }

    /// The face a removed particle at world point `x` left through: the one of
    /// the keep box (`keep_box`) it is farthest beyond, open or walled, as (axis,
    /// side, the side is open). The step decides removal in f32 against the same
    /// faces, so a particle within rounding of a face is still given that face.
    pub fn exit_face(&self, x: [f64; 3]) -> (usize, usize, bool) {
        let mut best = (0, 0, f64::NEG_INFINITY, false);
        for a in (0..self.dim as usize).filter(|&a| !self.periodic[a]) {
            let (lo, hi) = self.keep_box(a);
            let (lo, hi) = (lo + self.origin[a], hi + self.origin[a]);
            for (side, beyond) in [(0, lo - x[a]), (1, x[a] - hi)] {
                if beyond > best.2 {
                    best = (a, side, beyond, self.open_sides[a][side]);
                }
            }
        }
        (best.0, best.1, best.3)
    }
}
