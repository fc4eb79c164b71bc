//! Two fluid layers at rest (liquid under gas): no particle may cross the
//! interface, and the pressure must be continuous across it.

use super::{g_mag, linear_fit_at_zero, liquid_rho0, particles, Check, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;
use rayon::prelude::*;

#[derive(Default)]
pub struct TwoLayer {
    /// Largest overlap of the liquid's top and the gas's bottom over the samples.
    max_penetration: f64,
    /// The sample with the lowest own-phase colour, and the most particles across
    /// the interface in any sample.
    crossing: Option<Crossing>,
    max_crossed: usize,
}

impl Check for TwoLayer {
    fn observe(&mut self, m: &Model, st: &State) {
        let (top_liq, bottom_gas) = layer_extent(m, st);
        self.max_penetration = self.max_penetration.max(top_liq - bottom_gas);
        let c = crossing(m, st);
        self.max_crossed = self.max_crossed.max(c.count);
        if self.crossing.is_none_or(|w| c.colour < w.colour) {
            self.crossing = Some(c);
        }
    }

    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let (top_liq, bottom_gas) = layer_extent(m, st);
        let s = 0.5 * (top_liq + bottom_gas);
        let ax = m.dim as usize - 1;
        // Pressure on each side extrapolated to the interface by a least-squares line
        // through the particles within 3Δx of it: the hydrostatic gradient differs by
        // the density ratio, so raw side averages would differ by ρ_l g Δx.
        let band = 3.0 * m.dx;
        let fit = |kind: PhaseKind| {
            let pts: Vec<(f64, f64)> = particles(m, st)
                .filter(|p| p.kind == kind && (p.x[ax] - s).abs() < band)
                .map(|p| (p.x[ax] - s, p.p))
                .collect();
            linear_fit_at_zero(&pts)
        };
        let (pl, pg) = (fit(PhaseKind::Liquid), fit(PhaseKind::Gas));
        let depth = s - m.domain_lo[ax];
        // Scale: the liquid's hydrostatic head, the pressure range the scene spans.
        let head = liquid_rho0(m) * g_mag(m) * depth;
        let jump = (pl - pg).abs() / head;
        let mut details = vec![
            format!("  interface at {s:.5} m; liquid top {top_liq:.5}, gas bottom {bottom_gas:.5}; largest overlap of the two {:.3e} m ({:.2} dx)", self.max_penetration.max(0.0), self.max_penetration.max(0.0) / m.dx),
            format!("  interface pressure: liquid side {pl:.4e} Pa, gas side {pg:.4e} Pa, liquid head {head:.4e} Pa"),
        ];
        if let Some(c) = self.crossing {
            details.push(format!(
                "  lowest own-phase colour {:.3} ({:?} particle id {} at t = {:.4e} s, x = [{:.5}, {:.5}, {:.5}]); below 1/2 means crossed",
                c.colour, c.kind, c.id, c.t, c.x[0], c.x[1], c.x[2]
            ));
        }
        if self.max_crossed > 0 {
            return (
                "particles across the interface (own-phase colour < 1/2)".into(),
                self.max_crossed as f64,
                details,
            )
                .into();
        }
        (
            "interface pressure jump / liquid head".into(),
            jump,
            details,
        )
            .into()
    }
}

/// The fluid particle most on the other phase's side of the liquid–gas interface.
#[derive(Clone, Copy, Debug)]
struct Crossing {
    /// Particles with own-phase colour below ½ in the sample.
    count: usize,
    /// The lowest own-phase colour, and that particle's id, kind, time and position.
    colour: f64,
    id: u32,
    kind: PhaseKind,
    t: f64,
    x: [f64; 3],
}

/// Finds the particles that crossed the liquid–gas interface. A particle's
/// own-phase colour is the kernel-weighted share of the fluid around it, itself
/// included, that is of its own phase:
///   c_i = Σ_{j of i's phase} V_j W_ij / Σ_{j fluid} V_j W_ij,  V_j = m_j/ρ_j.
/// The interface is where the colour function is ½ (the F22 (19) normal is its
/// gradient), so c_i < ½ means particle i sits on the other phase's side. This
/// asks what the check is for, whether a particle crossed, and not whether the
/// interface stays flat: a meniscus at a wall can lift the liquid's top above
/// the gas's bottom a few particles away, yet every particle stays on its own
/// side (tests/validation.rs, two_layer_ratio_1000_no_crossing). Walls do not count, so a corner particle's
/// share is of the fluid it touches.
fn crossing(m: &Model, st: &State) -> Crossing {
    let pr = crate::params::Params::new(m, st.len() as u32);
    let fluid = |i: usize| matches!(kind_of(m, st, i), PhaseKind::Liquid | PhaseKind::Gas);
    let grid = HostGrid::new(m, st, &fluid);
    let mut worst = Crossing {
        count: 0,
        colour: f64::INFINITY,
        id: 0,
        kind: PhaseKind::Liquid,
        t: st.sim.time as f64,
        x: [0.0; 3],
    };
    let colours: Vec<(usize, f64)> = (0..st.len())
        .into_par_iter()
        .filter(|&i| fluid(i))
        .map(|i| {
            let (mut own, mut all) = (0.0, 0.0);
            grid.for_each_near(m, st, i, |j, r| {
                let vw = (st.mass[j] / st.rho[j]) as f64 * crate::kernel::w(&pr, r as f32) as f64;
                all += vw;
                if kind_of(m, st, j) == kind_of(m, st, i) {
                    own += vw;
                }
            });
            (i, own / all)
        })
        .collect();
    for (i, c) in colours {
        if c < 0.5 {
            worst.count += 1;
        }
        if c < worst.colour {
            let x = m.to_world(st.pos[i]);
            (worst.colour, worst.id, worst.kind, worst.x) = (c, st.id[i], kind_of(m, st, i), x);
        }
    }
    worst
}

fn kind_of(m: &Model, st: &State, i: usize) -> PhaseKind {
    m.phases[st.phase[i] as usize].kind
}

/// Cells of at least one kernel support holding the particles `keep` selects, so
/// that a check can visit a particle's neighbours on the host (periodic axes wrap).
struct HostGrid {
    cell: [f64; 3],
    cells: [i64; 3],
    bins: std::collections::HashMap<[i64; 3], Vec<usize>>,
}

impl HostGrid {
    fn new(m: &Model, st: &State, keep: &dyn Fn(usize) -> bool) -> HostGrid {
        let mut cell = [m.support; 3];
        let mut cells = [0i64; 3];
        for a in 0..m.dim as usize {
            if m.periodic[a] {
                let len = m.domain_hi[a] - m.domain_lo[a];
                cells[a] = (len / m.support).floor() as i64;
                cell[a] = len / cells[a] as f64;
            }
        }
        let mut grid = HostGrid {
            cell,
            cells,
            bins: Default::default(),
        };
        for i in (0..st.len()).filter(|&i| keep(i)) {
            let key = grid.key(m, st.pos[i]);
            grid.bins.entry(key).or_default().push(i);
        }
        grid
    }

    fn key(&self, m: &Model, x: [f32; 4]) -> [i64; 3] {
        let mut k = [0i64; 3];
        for a in 0..m.dim as usize {
            let lo = m.domain_lo[a] - m.origin[a];
            k[a] = ((x[a] as f64 - lo) / self.cell[a]).floor() as i64;
            if self.cells[a] > 0 {
                k[a] = k[a].rem_euclid(self.cells[a]);
            }
        }
        k
    }

    /// Calls `f(j, r_ij)` for every kept particle j within the support of i, i included.
    fn for_each_near(&self, m: &Model, st: &State, i: usize, mut f: impl FnMut(usize, f64)) {
        let dim = m.dim as usize;
        let k = self.key(m, st.pos[i]);
        let span = |a: usize| if a < dim { -1..=1 } else { 0..=0 };
        for dz in span(2) {
            for dy in span(1) {
                for dx in span(0) {
                    let mut c = [k[0] + dx, k[1] + dy, k[2] + dz];
                    for (a, ca) in c.iter_mut().enumerate() {
                        if self.cells[a] > 0 {
                            *ca = ca.rem_euclid(self.cells[a]);
                        }
                    }
                    for &j in self.bins.get(&c).map(Vec::as_slice).unwrap_or(&[]) {
                        let r = self.distance(m, st.pos[i], st.pos[j]);
                        if r < m.support {
                            f(j, r);
                        }
                    }
                }
            }
        }
    }

    fn distance(&self, m: &Model, a: [f32; 4], b: [f32; 4]) -> f64 {
        let mut r2 = 0.0;
        for ax in 0..m.dim as usize {
            let mut d = a[ax] as f64 - b[ax] as f64;
            if m.periodic[ax] {
                let len = m.domain_hi[ax] - m.domain_lo[ax];
                d -= len * (d / len).round();
            }
            r2 += d * d;
        }
        r2.sqrt()
    }
}

fn layer_extent(m: &Model, st: &State) -> (f64, f64) {
    let ax = m.dim as usize - 1;
    let mut top_liq = f64::MIN;
    let mut bottom_gas = f64::MAX;
    for p in particles(m, st) {
        match p.kind {
            PhaseKind::Liquid => top_liq = top_liq.max(p.x[ax]),
            PhaseKind::Gas => bottom_gas = bottom_gas.min(p.x[ax]),
            PhaseKind::Wall | PhaseKind::Solid => {}
        }
    }
    (top_liq, bottom_gas)
}
