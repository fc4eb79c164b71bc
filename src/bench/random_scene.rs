//! Seeded random scenes for `bench stability`: random boxes, spheres and cylinders
//! of liquid (and sometimes gas) inside a random 2D or 3D domain with random
//! periodic and open sides, kernel, viscosity and jitter — all within the ranges a
//! scene file accepts. The same seed gives the same TOML text on every machine.

use crate::random::SplitMix;
use std::fmt::Write as _;

pub struct RandomScene {
    pub toml: String,
    /// One line: dimension, kernel, phases, shapes, sides.
    pub summary: String,
    /// Fully periodic without gravity or walls: momentum is conserved.
    pub conserves_momentum: bool,
}

/// Lattice spacing of every random scene (m): water-like scales.
const DX: f64 = 0.01;

struct Rng(SplitMix);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.0.next_f64()
    }
    fn int(&mut self, lo: u32, hi: u32) -> u32 {
        (lo + (self.0.next_f64() * (hi - lo + 1) as f64) as u32).min(hi)
    }
    fn chance(&mut self, p: f64) -> bool {
        self.0.next_f64() < p
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (self.uniform(lo.ln(), hi.ln())).exp()
    }
}

fn vec_text(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:e}")).collect();
    format!("[{}]", parts.join(", "))
}

/// A random shape of `phase` inside [0, ext], 3 to 8 Δx across.
fn shape(r: &mut Rng, dim: usize, ext: &[f64], phase: &str) -> (String, &'static str) {
    let kind = r.int(0, if dim == 3 { 2 } else { 1 });
    let mut t = format!("\n[[shapes]]\nphase = \"{phase}\"\n");
    let size = |r: &mut Rng| r.uniform(3.0, 8.0) * DX;
    match kind {
        0 => {
            let (mut lo, mut hi) = (Vec::new(), Vec::new());
            for &e in ext.iter().take(dim) {
                let s = size(r).min(e);
                let a = r.uniform(0.0, e - s);
                lo.push(a);
                hi.push(a + s);
            }
            let _ = writeln!(
                t,
                "box = {{ min = {}, max = {} }}",
                vec_text(&lo),
                vec_text(&hi)
            );
            (t, "box")
        }
        1 => {
            let rad = 0.5 * size(r).min(ext.iter().take(dim).cloned().fold(f64::MAX, f64::min));
            let c: Vec<f64> = (0..dim).map(|a| r.uniform(rad, ext[a] - rad)).collect();
            let _ = writeln!(
                t,
                "sphere = {{ center = {}, radius = {rad:e} }}",
                vec_text(&c)
            );
            (t, "sphere")
        }
        _ => {
            // Along a random axis, the whole of its length across the domain.
            let axis = r.int(0, 2) as usize;
            let rad = 0.5 * size(r).min(ext.iter().take(dim).cloned().fold(f64::MAX, f64::min));
            let mut base: Vec<f64> = (0..dim).map(|a| r.uniform(rad, ext[a] - rad)).collect();
            base[axis] = 0.0;
            let mut dir = vec![0.0; dim];
            dir[axis] = ext[axis];
            let _ = writeln!(
                t,
                "cylinder = {{ base = {}, axis = {}, radius = {rad:e} }}",
                vec_text(&base),
                vec_text(&dir)
            );
            (t, "cylinder")
        }
    }
}

pub fn generate(seed: u64) -> RandomScene {
    let mut r = Rng(SplitMix(seed ^ 0x5EED_5CE7E));
    let dim = if r.chance(0.6) { 2 } else { 3 };
    use crate::scene::KernelKind;
    let kernels = [
        KernelKind::Quintic,
        KernelKind::WendlandC2,
        KernelKind::Cubic,
    ];
    let k = kernels[r.int(0, 2) as usize];
    let kernel = k.name();
    let cells: Vec<u32> = (0..dim)
        .map(|_| {
            if dim == 2 {
                r.int(12, 30)
            } else {
                r.int(10, 14)
            }
        })
        .collect();
    // One scene in six is fully periodic without gravity: momentum is then conserved.
    let periodic: Vec<bool> = match r.chance(1.0 / 6.0) {
        true => vec![true; dim],
        false => (0..dim).map(|_| r.chance(0.25)).collect(),
    };
    // A periodic axis spans at least three kernel supports (validation's rule),
    // at the kernel's default h/Δx.
    let support_cells = (3.0 * k.support_factor() * k.default_h_over_dx()).ceil() as u32;
    let ext: Vec<f64> = cells
        .iter()
        .zip(&periodic)
        .map(|(&n, &p)| if p { n.max(support_cells) } else { n } as f64 * DX)
        .collect();
    let all_periodic = periodic.iter().all(|&p| p);
    let up = dim - 1;
    // Gravity needs a floor: never along a periodic axis (endless free fall).
    let gravity = !periodic[up] && r.chance(0.7);
    let open_top = gravity && !periodic[up] && r.chance(0.5);
    let gas = !open_top && r.chance(0.3);
    let height = ext[up];
    // WCSPH: sound speed ten times the fastest free-fall speed over the domain.
    let c = 10.0 * (2.0 * 9.81 * height).sqrt().max(1.0);
    let p0 = 1000.0 * c * c;
    // Dynamic viscosity (Pa s): water to a thick oil.
    let mu = r.log_uniform(1e-3, 1e-1);
    let jitter = if r.chance(0.5) {
        r.uniform(0.0, 0.2)
    } else {
        0.0
    };
    let mut t = String::new();
    let _ = writeln!(
        t,
        "[simulation]\ndimension = {dim}\nkernel = \"{kernel}\"\ndx = {DX:e}"
    );
    let mut g = vec![0.0; dim];
    if gravity {
        g[up] = -9.81;
    }
    let _ = writeln!(t, "gravity = {}", vec_text(&g));
    if gas {
        let _ = writeln!(t, "background_pressure = {:e}", 5.0 * p0);
    } else {
        let _ = writeln!(t, "pressure_floor = true");
    }
    let _ = writeln!(t, "jitter = {jitter:e}\nseed = {seed}");
    let _ = writeln!(
        t,
        "\n[domain]\nmin = {}\nmax = {}",
        vec_text(&vec![0.0; dim]),
        vec_text(&ext)
    );
    let flags: Vec<String> = periodic.iter().map(|p| p.to_string()).collect();
    let _ = writeln!(t, "periodic = [{}]", flags.join(", "));
    if !all_periodic {
        let _ = writeln!(t, "wall_phase = \"wall\"");
    }
    if open_top {
        let _ = writeln!(t, "open_sides = [\"{}_max\"]", ["x", "y", "z"][up]);
    }
    let _ = writeln!(
        t,
        "\n[materials.liquid]\ndensity = 1000.0\nviscosity = {mu:e}\nreference_pressure = {p0:e}"
    );
    let ratio = if r.chance(0.5) { 10.0 } else { 100.0 };
    if gas {
        let _ = writeln!(
            t,
            "\n[materials.gas]\ndensity = {:e}\nviscosity = {:e}\nreference_pressure = {p0:e}",
            1000.0 / ratio,
            mu / 10.0
        );
    }
    let _ = writeln!(
        t,
        "\n[phases.liquid]\nkind = \"liquid\"\nmaterial = \"liquid\""
    );
    if gas {
        let _ = writeln!(t, "\n[phases.gas]\nkind = \"gas\"\nmaterial = \"gas\"");
    }
    if !all_periodic {
        let _ = writeln!(t, "\n[phases.wall]\nkind = \"wall\"\nmaterial = \"liquid\"");
    }
    if gas {
        let _ = writeln!(
            t,
            "\n[[shapes]]\nphase = \"gas\"\nbox = {{ min = {}, max = {} }}",
            vec_text(&vec![0.0; dim]),
            vec_text(&ext)
        );
    }
    let mut kinds = Vec::new();
    for _ in 0..r.int(1, 3) {
        let (text, kind) = shape(&mut r, dim, &ext, "liquid");
        t.push_str(&text);
        kinds.push(kind);
    }
    // The runner's step budget ends the run first; a scene needs an end to be valid.
    let _ = writeln!(t, "\n[run]\nsteps = 1000000");
    let axes: Vec<&str> = (0..dim)
        .filter(|&a| periodic[a])
        .map(|a| ["x", "y", "z"][a])
        .collect();
    let summary = format!(
        "{dim}D {kernel}, {}{}, {}, periodic [{}]{}",
        if gas {
            format!("liquid/gas {ratio}")
        } else {
            "liquid".into()
        },
        if gravity { " under gravity" } else { "" },
        kinds.join("+"),
        axes.join(""),
        if open_top { ", open top" } else { "" }
    );
    RandomScene {
        toml: t,
        summary,
        conserves_momentum: all_periodic && !gravity,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_scene() {
        for seed in 0..8 {
            assert_eq!(generate(seed).toml, generate(seed).toml);
        }
        assert_ne!(generate(1).toml, generate(2).toml);
    }

    /// Every random scene parses, builds and fills: the generator stays within the
    /// valid input ranges.
    #[test]
    fn random_scenes_are_valid_input() {
        for seed in 0..64 {
            let s = generate(seed);
            let label = format!("seed {seed}");
            let (sc, resolved) = crate::scene::parse_str(&label, &s.toml, &[])
                .unwrap_or_else(|e| panic!("{e}\n{}", s.toml));
            let m = crate::model::build(&label, &sc, &resolved)
                .unwrap_or_else(|e| panic!("{e}\n{}", s.toml));
            let st = crate::setup::generate(&m, &sc).unwrap_or_else(|e| panic!("{e}\n{}", s.toml));
            assert!(!st.is_empty(), "{}", s.toml);
        }
    }
}
