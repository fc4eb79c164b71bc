//! Twin of shaders/wall.wgsl: generalized wall boundary (Adami, Hu & Adams 2012).
//! Each wall particle w gathers from its fluid neighbours f:
//!   p_w = (Σ p_f W_wf + g·Σ ρ_f r_wf W_wf) / Σ W_wf        (stationary wall, a_w = 0)
//!   ũ_w = Σ u_f W_wf / Σ W_wf,  u_w = 2 u_wall − ũ_w        (no-slip velocity)
//! with Σ W_wf + ε as the divisor (see `run`), so u_w = u_wall + (u_wall Σ W − Σ u W)/(Σ W + ε).
//! The wall's displayed density is its material's EOS inverted at p_w.

use super::neighbors::{
    cell_coord, cell_index, fluid_nearby, for_each_neighbor_among, Among, CellTable,
};
use crate::kernel;
use crate::params::{Params, FLAG_PRESSURE_FLOOR};
use crate::state::{State, NO_BODY};
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State, grid: &CellTable) {
    run_among(pr, st, grid, true)
}

/// `run`, sweeping the fluid candidates only (`fluid_only`: the sums want
/// fluid neighbours, about half of a wall particle's candidates) or every
/// candidate with the walls skipped (the tests' reference). Either way the
/// same neighbours in the same order with the same d and r², so the same bits.
fn run_among(pr: &Params, st: &mut State, grid: &CellTable, fluid_only: bool) {
    let n = st.active();
    let (pos, phase) = (&st.pos, &st.phase);
    let among = if fluid_only {
        Among::phases(phase, |p| !pr.is_wall(p))
    } else {
        Among::All
    };
    let (rho_in, p_in, vel_in) = (&st.rho, &st.press, &st.vel);
    let (body, bodies, st_id) = (&st.body, &st.bodies, &st.id);
    let out: Vec<Option<(f32, f32, [f32; 4])>> = (0..n)
        .into_par_iter()
        // The last cell whose neighbourhood was checked for fluid: particles
        // are sorted by cell, so consecutive wall particles share the answer.
        .map_init(
            || (u32::MAX, false),
            |checked, i| {
                let ph = phase[i];
                if !pr.is_wall(ph) {
                    return None;
                }
                let mut sw = 0.0f32;
                let mut sp = 0.0f32;
                let mut sr = [0.0f32; 3];
                let mut sv = [0.0f32; 3];
                // Without fluid in the cells around, the sums stay zero: skip the loop
                // (most of a substrate in a heat scene).
                let cell = cell_index(pr, cell_coord(pr, &pos[i]));
                if checked.0 != cell {
                    *checked = (cell, fluid_nearby(pr, grid, &pos[i]));
                }
                let gather = checked.1;
                let visit = |j: usize, d: [f32; 3], r2: f32| {
                    if pr.is_wall(phase[j]) {
                        return;
                    }
                    let wk = kernel::w(pr, r2.sqrt());
                    sw += wk;
                    sp += p_in[j] * wk;
                    let rw = rho_in[j] * wk;
                    let v = vel_in[j];
                    for a in 0..3 {
                        sr[a] += rw * d[a];
                        sv[a] += v[a] * wk;
                    }
                };
                if gather {
                    for_each_neighbor_among(pr, pos, grid, i, among, visit);
                }
                // The wall's own velocity: its phase's, or a body particle's rigid motion.
                let mut b = pr.phase(ph).velocity.to_array();
                let by_id = body.get(st_id[i] as usize);
                if let Some(&k) = by_id.filter(|&&k| k != NO_BODY) {
                    let u = super::bodies::point_velocity(&bodies[k as usize], &pos[i]);
                    b = [u[0], u[1], u[2], 0.0];
                }
                let m = pr.phase(ph);
                // Regularised Shepard division: Σ W + ε instead of Σ W, ε = 1e-9 W(0).
                // At an exact lattice tie a fluid particle sits at the edge of the
                // support, where W is 0 or a few ULP above it depending on rounding; a
                // plain division then jumps between p = 0 (nothing gathered) and a full
                // extrapolated pressure (tiny/tiny), and a GPU that fuses r² differently
                // picks the other side. With ε the result goes to 0 continuously as
                // Σ W -> 0, and for Σ W ≥ 1e-4 W(0) (every fluid neighbour closer than
                // 2.6h with the quintic) ε changes it by at most 1e-5 relative.
                let g = pr.flow.gravity;
                let den = sw + pr.flow.wall_weight_floor;
                let mut p = (sp + (g[0] * sr[0] + g[1] * sr[1] + g[2] * sr[2])) / den;
                let v = [
                    b[0] + (b[0] * sw - sv[0]) / den,
                    b[1] + (b[1] * sw - sv[1]) / den,
                    b[2] + (b[2] * sw - sv[2]) / den,
                    0.0,
                ];
                if pr.flag(FLAG_PRESSURE_FLOOR) {
                    p = p.max(0.0);
                }
                Some((m.rho0 + p / m.c2, p, v))
            },
        )
        .collect();
    st.rho[..n]
        .par_iter_mut()
        .zip(st.press[..n].par_iter_mut())
        .zip(st.vel[..n].par_iter_mut())
        .zip(out.into_par_iter())
        .for_each(|(((rho, p), v), o)| {
            if let Some(o) = o {
                (*rho, *p, *v) = o;
            }
        });
}

#[cfg(test)]
mod tests {
    use super::super::neighbors::{self, CellTable};
    use crate::params::Params;
    use crate::state::State;

    /// A wall particle of dam_break_2d with one water particle straight above it
    /// at distance r (pressure 1000 Pa, density 1000, velocity 0.1 m/s along x):
    /// the wall's pressure and velocity after the wall pass.
    fn wall_with_one_neighbour(r: f32) -> (f32, [f32; 4], f32) {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/dam_break_2d.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        let water = l.model.phase_index("water").unwrap() as u32;
        let st0 = &l.state;
        let w = (0..st0.len()).find(|&i| st0.phase[i] != water).unwrap();
        let f = (0..st0.len()).find(|&i| st0.phase[i] == water).unwrap();
        let mut st = State::default();
        for i in [w, f] {
            st.pos.push(st0.pos[i]);
            st.vel.push([0.0; 4]);
            st.acc.push([0.0; 4]);
            st.acc_b.push([0.0; 4]);
            st.rho.push(1000.0);
            st.press.push(1000.0);
            st.mass.push(st0.mass[i]);
            st.phase.push(st0.phase[i]);
            st.id.push(i as u32);
        }
        st.pos[1] = [st.pos[0][0], st.pos[0][1] + r, st.pos[0][2], 0.0];
        st.vel[1] = [0.1, 0.0, 0.0, 0.0];
        let pr = Params::new(&l.model, 2);
        let mut grid = CellTable::default();
        neighbors::run(&pr, &mut st, &mut grid);
        super::run(&pr, &mut st, &grid);
        let k = st.id.iter().position(|&id| id == w as u32).unwrap();
        (st.press[k], st.vel[k], pr.kernel.support2.sqrt())
    }

    /// The sweep over fluid candidates gives the bits of the sweep over every
    /// candidate with the walls skipped: the jittered 3D dam break with scattered
    /// velocities, and the 2D one, every wall particle's ρ, p and u.
    #[test]
    fn fluid_candidates_give_the_bits_of_every_candidate() {
        for scene in ["dam_break_3d", "dam_break_2d"] {
            let path = format!(
                "{}/scenarios/validation/{scene}.toml",
                env!("CARGO_MANIFEST_DIR")
            );
            let l = crate::load::load(&path, &["jitter=0.3".into()]).unwrap();
            let pr = Params::new(&l.model, 2);
            let mut st = l.state.clone();
            for (k, (v, p)) in st.vel.iter_mut().zip(st.press.iter_mut()).enumerate() {
                let s = |m: usize| ((k * m % 97) as f32 / 97.0 - 0.5) * 2.0;
                *v = [s(13), s(29), s(53), 0.0];
                *p = 1.0e3 * s(71);
            }
            let mut grid = CellTable::default();
            neighbors::run(&pr, &mut st, &mut grid);
            let mut every = st.clone();
            super::run_among(&pr, &mut every, &grid, false);
            super::run_among(&pr, &mut st, &grid, true);
            let bits = |s: &State| -> Vec<u32> {
                let n = s.active();
                let v = s.vel[..n].iter().flatten();
                s.rho[..n]
                    .iter()
                    .chain(&s.press[..n])
                    .chain(v)
                    .map(|x| x.to_bits())
                    .collect()
            };
            let (a, b) = (bits(&every), bits(&st));
            assert_eq!(a.len(), b.len());
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            assert_eq!(differ, 0, "{scene}: {differ} words differ");
            let walls = (0..st.active())
                .filter(|&i| pr.is_wall(st.phase[i]))
                .count();
            let pressed = (0..st.active())
                .filter(|&i| pr.is_wall(st.phase[i]) && st.press[i] != 0.0)
                .count();
            // The layers beside the water column (a tenth of the 3D tank's walls).
            assert!(
                pressed > walls / 20,
                "{scene}: {pressed} of {walls} walls pressed"
            );
        }
    }

    /// Adami's extrapolation p_w = p_f + ρ_f g·(r_w − r_f) with one neighbour well
    /// inside the support (the weight floor changes it by < 1e-5 relative there),
    /// and a pressure that falls to 0 continuously at the support's edge instead of
    /// jumping from the full extrapolated value to 0 (the hardware mismatch the
    /// floor removes).
    #[test]
    fn wall_pressure_is_adami_inside_and_continuous_at_the_support_edge() {
        let h = 0.0025f32;
        let (p, v, support) = wall_with_one_neighbour(2.5 * h);
        let adami = 1000.0 + 1000.0 * 9.81 * 2.5 * h;
        assert!((p - adami).abs() / adami < 1e-5, "p_w = {p}, Adami {adami}");
        assert!((v[0] + 0.1).abs() < 1e-6, "no-slip mirror: u_w = {}", v[0]);
        // Just inside the edge W is a few ULP above 0: p_w is already ~0.
        let (p_edge, v_edge, _) = wall_with_one_neighbour(support * (1.0 - 1e-6));
        assert!(p_edge.abs() < 1e-3, "p_w at the edge = {p_edge}");
        assert!(v_edge[0].abs() < 1e-6, "u_w at the edge = {}", v_edge[0]);
        // Beyond the support nothing is gathered: exactly the wall's own state.
        let (p_out, v_out, _) = wall_with_one_neighbour(support * 1.01);
        assert_eq!((p_out, v_out[0]), (0.0, 0.0));
    }
}
