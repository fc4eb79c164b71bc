//! The forces sweep (cpu/forces.rs) eight neighbours at a time, for scenes whose
//! forces pass has only F22 (23)'s pressure and viscosity and, optionally, the
//! background pressure and the wall barrier F22 (34): no periodic axis, no
//! interface or solid–fluid viscosity, no viscous heating, no δ-SPH pressure; on
//! a CPU with AVX2.
//!
//! Why: the scalar sweep spends about 50 cycles per pair, most of them waiting on
//! one pair's chain of square root, kernel and three divisions. Eight pairs in
//! eight lanes share that wait. The kernel and the terms are the same functions
//! (`kernel::dw`, `terms::pressure`, `terms::viscosity`,
//! `terms::background_pressure`, `terms::barrier`, generic over `Lane`), so each
//! lane does the scalar sweep's operations; the eight contributions are then
//! added to the sums one by one in the list's order. So the bits are the scalar sweep's, and the
//! GPU twin's (`eight_wide_forces_match_the_scalar_sweep`, and the bit-match
//! suite on lavapipe). A lane past the list's end, or a neighbour at r = 0, which
//! the scalar sweep skips, adds +0 instead: a sum that starts at +0 never becomes
//! −0, so adding +0 leaves its bits as they are.

use super::forces::{accelerations, Sums};
use super::neighbors::{with_listed, CellTable, NeighborList};
use super::terms;
use crate::backend::terms::{active, TermId, PAIR_TERMS};
use crate::kernel;
use crate::lanes::{Lane, AVX2, F8};
use crate::model::MAX_PHASES;
use crate::params::Params;
use crate::state::State;
use rayon::prelude::*;
use std::arch::x86_64::*;

/// The forces-pass terms this sweep evaluates. A scene using any other term
/// (a new one included, until it is added here and below) takes the scalar sweep.
const TERMS: [TermId; 4] = [
    TermId::Pressure,
    TermId::Viscosity,
    TermId::BackgroundPressure,
    TermId::Barrier,
];

/// Whether this scene's forces pass can run eight-wide on this CPU.
pub fn applies(pr: &Params) -> bool {
    let others = PAIR_TERMS
        .iter()
        .filter(|t| t.pass == "forces" && !TERMS.contains(&t.id))
        .any(|t| (t.active)(pr));
    *AVX2 && pr.sizes.flags & 7 == 0 && !others
}

/// Bit 31 of a neighbour record's fourth word: the neighbour is a wall particle.
const WALL_BIT: u32 = 1 << 31;

/// The sweep for a scene where `applies` holds.
pub fn run(
    pr: &Params,
    st: &mut State,
    grid: &CellTable,
    list: &NeighborList,
    eta: &[[f32; MAX_PHASES]; MAX_PHASES],
) {
    assert!(*AVX2, "the eight-wide forces sweep needs AVX2 (`applies`)");
    let (bg, br) = (
        active(pr, TermId::BackgroundPressure),
        active(pr, TermId::Barrier),
    );
    // Each phase's wall velocity (the barrier's U_wall), one table per axis.
    let wall_velocity: [[f32; MAX_PHASES]; 3] =
        std::array::from_fn(|a| std::array::from_fn(|ph| pr.phases[ph].velocity[a]));
    let n = st.active();
    // What a pair reads of its neighbour besides position and velocity, packed in
    // one 16-byte record so that eight of them load and transpose as a block:
    // ρ, p, V = m/ρ (the scalar sweep's division) and the phase with the wall bit.
    // (Into the last step's array: a fresh one would be mapped and cleared page
    // by page, 160 MB a step at 1e7 particles.)
    let mut records = RECORDS.with(|r| r.take());
    (0..st.pos.len())
        .into_par_iter()
        .map(|j| {
            let ph = st.phase[j];
            // The gathers from the per-phase tables below read index ph unchecked.
            assert!((ph as usize) < MAX_PHASES, "particle {j}: phase {ph}");
            let wall = if pr.is_wall(ph) { WALL_BIT } else { 0 };
            [
                st.rho[j],
                st.press[j],
                st.mass[j] / st.rho[j],
                f32::from_bits(ph | wall),
            ]
        })
        .collect_into_vec(&mut records);
    let (pos, vel, mass, phase) = (&st.pos, &st.vel, &st.mass, &st.phase);
    let (acc, acc_b) = (&mut st.acc[..n], &mut st.acc_b[..n]);
    accelerations(pr, phase, mass, acc, acc_b, |i| {
        with_listed(pr, pos, grid, list, i, |js| {
            let p = Pair {
                pr,
                pos,
                vel,
                records: &records,
                mass,
                phase,
                eta: &eta[phase[i] as usize],
                wall_velocity: &wall_velocity,
            };
            // SAFETY: `applies` checked that this CPU has AVX2.
            let (f, fb) = unsafe {
                match (bg, br) {
                    (false, false) => p.sums::<false, false>(i, js),
                    (false, true) => p.sums::<false, true>(i, js),
                    (true, false) => p.sums::<true, false>(i, js),
                    (true, true) => p.sums::<true, true>(i, js),
                }
            };
            // No viscous heating here: its sum stays +0, as in the scalar sweep.
            let xyz = |v: [f32; 4]| [v[0], v[1], v[2]];
            Sums {
                f: xyz(f),
                fb: xyz(fb),
                heating: 0.0,
            }
        })
    });
    RECORDS.with(|r| r.replace(records));
}

thread_local! {
    /// The neighbour records of the last sweep, whose memory the next reuses.
    static RECORDS: std::cell::RefCell<Vec<[f32; 4]>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// What the pair sums of one particle read.
struct Pair<'a> {
    pr: &'a Params,
    pos: &'a [[f32; 4]],
    vel: &'a [[f32; 4]],
    records: &'a [[f32; 4]],
    mass: &'a [f32],
    phase: &'a [u32],
    /// η̃ of i's phase with each phase (forces.rs `PairViscosity`).
    eta: &'a [f32; MAX_PHASES],
    wall_velocity: &'a [[f32; MAX_PHASES]; 3],
}

impl Pair<'_> {
    /// Σ_j of F22 (23)'s force, (BR) the barrier's and (BG) the
    /// background-pressure force over the neighbours `js` of particle i, eight at
    /// a time, added in the order of `js` (a pair's barrier after its F22 (23)).
    #[target_feature(enable = "avx2")]
    unsafe fn sums<const BG: bool, const BR: bool>(
        &self,
        i: usize,
        js: &[u32],
    ) -> ([f32; 4], [f32; 4]) {
        let pr = self.pr;
        let c = F8::splat;
        let [xi, yi, zi, _] = self.pos[i];
        let [ui, vi, wi, _] = self.vel[i];
        let [rho_i, p_i, vol_i, _] = self.records[i];
        let mat_i = pr.phase(self.phase[i]);
        let (rho0_i, c2_i) = (mat_i.rho0, mat_i.c2);
        let m_i = c(self.mass[i]);
        let vv_i = c(vol_i) * c(vol_i);
        let pb = c(pr.flow.background_pressure);
        let mut f = _mm_setzero_ps();
        let mut fb = _mm_setzero_ps();
        for k in (0..js.len()).step_by(8) {
            // Eight neighbours; the last batch is padded with i itself (r = 0).
            let mut idx = [i as u32; 8];
            let end = js.len().min(k + 8);
            idx[..end - k].copy_from_slice(&js[k..end]);
            let [x, y, z, _] = transpose(self.pos, &idx);
            let [u, v, w, _] = transpose(self.vel, &idx);
            let [rho_r, p_j, vol_r, tag] = transpose(self.records, &idx);
            let (dx, dy, dz) = (c(xi) - x, c(yi) - y, c(zi) - z);
            let r2 = dx * dx + dy * dy + dz * dz;
            // The scalar sweep skips r² <= 0 (and keeps a NaN): NLE_UQ.
            let keep = _mm256_cmp_ps::<_CMP_NLE_UQ>(r2.0, _mm256_setzero_ps());
            let r = F8(_mm256_sqrt_ps(r2.0));
            let dwdr = kernel::dw(pr, r);
            // A wall neighbour: the density the fluid's EOS gives at the wall's
            // pressure, and the fluid's own mass.
            let tag = _mm256_castps_si256(tag.0);
            let wall = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_setzero_si256(), tag));
            // Most batches hold no wall neighbour: their two divisions are
            // skipped (the blend would keep ρ and V of the record anyway).
            let (rho_j, vol_j) = if _mm256_movemask_ps(wall) == 0 {
                (rho_r, vol_r)
            } else {
                let rho_w = c(rho0_i) + p_j / c(c2_i);
                let vol_w = m_i / rho_w;
                (
                    F8(_mm256_blendv_ps(rho_r.0, rho_w.0, wall)),
                    F8(_mm256_blendv_ps(vol_r.0, vol_w.0, wall)),
                )
            };
            let vv = vv_i + vol_j * vol_j;
            let fp = terms::pressure(c(p_i), p_j, c(rho_i), rho_j, dwdr, r);
            let phase = _mm256_and_si256(tag, _mm256_set1_epi32(!WALL_BIT as i32));
            // η̃ of i's phase with each neighbour's: one load when the eight
            // share a phase (a gather is slow on some CPUs), else a gather.
            let first = _mm256_permutevar8x32_epi32(phase, _mm256_setzero_si256());
            let same = _mm256_movemask_epi8(_mm256_cmpeq_epi32(phase, first)) == -1;
            let eta = if same {
                c(self.eta[_mm256_cvtsi256_si32(phase) as usize])
            } else {
                F8(_mm256_i32gather_ps::<4>(self.eta.as_ptr(), phase))
            };
            let fv = terms::viscosity(eta, dwdr, r);
            let part = |d: F8, du: F8| F8(_mm256_and_ps((vv * (fp * d + fv * du)).0, keep));
            let main = [
                part(dx, c(ui) - u),
                part(dy, c(vi) - v),
                part(dz, c(wi) - w),
            ];
            // F22 (34) on the wall neighbours inside the barrier radius.
            let near = _mm256_cmp_ps::<_CMP_LT_OQ>(r.0, _mm256_set1_ps(pr.flow.barrier_radius));
            let hit = _mm256_and_ps(_mm256_and_ps(near, wall), keep);
            if BR && _mm256_movemask_ps(hit) != 0 {
                let table = |a: usize| {
                    F8(_mm256_i32gather_ps::<4>(
                        self.wall_velocity[a].as_ptr(),
                        phase,
                    ))
                };
                let s = terms::barrier(
                    pr,
                    [c(ui), c(vi), c(wi)],
                    [table(0), table(1), table(2)],
                    [dx, dy, dz],
                    r,
                );
                let part = |d: F8| F8(_mm256_and_ps((s * d).0, hit));
                f = add_interleaved(f, main, [part(dx), part(dy), part(dz)]);
            } else {
                f = add_in_order(f, main);
            }
            if BG {
                let fbg = terms::background_pressure(pb, dwdr, r);
                let part = |d: F8| F8(_mm256_and_ps((vv * (fbg * d)).0, keep));
                fb = add_in_order(fb, [part(dx), part(dy), part(dz)]);
            }
        }
        let mut out = ([0.0f32; 4], [0.0f32; 4]);
        _mm_storeu_ps(out.0.as_mut_ptr(), f);
        _mm_storeu_ps(out.1.as_mut_ptr(), fb);
        out
    }
}

/// The records of particles `idx[0..8]`, four fields as four vectors of eight
/// lanes (lane k from particle idx[k]).
#[inline(always)]
unsafe fn transpose(records: &[[f32; 4]], idx: &[u32; 8]) -> [F8; 4] {
    let at = |k: usize| records[idx[k] as usize].as_ptr();
    // a_k = [record k | record k + 4]
    let a0 = _mm256_loadu2_m128(at(4), at(0));
    let a1 = _mm256_loadu2_m128(at(5), at(1));
    let a2 = _mm256_loadu2_m128(at(6), at(2));
    let a3 = _mm256_loadu2_m128(at(7), at(3));
    let t0 = _mm256_unpacklo_ps(a0, a1);
    let t1 = _mm256_unpackhi_ps(a0, a1);
    let t2 = _mm256_unpacklo_ps(a2, a3);
    let t3 = _mm256_unpackhi_ps(a2, a3);
    [
        F8(_mm256_shuffle_ps::<0x44>(t0, t2)),
        F8(_mm256_shuffle_ps::<0xEE>(t0, t2)),
        F8(_mm256_shuffle_ps::<0x44>(t1, t3)),
        F8(_mm256_shuffle_ps::<0xEE>(t1, t3)),
    ]
}

/// sum + (x_k, y_k, z_k, 0) for k = 0..8 in turn: the scalar sweep's sequence of
/// additions, each of the three components in its own lane.
#[inline(always)]
unsafe fn add_in_order(mut sum: __m128, xyz: [F8; 3]) -> __m128 {
    for p in per_pair(xyz) {
        sum = _mm_add_ps(sum, p);
    }
    sum
}

/// sum + a_k, then sum + b_k, for k = 0..8 in turn.
#[inline(always)]
unsafe fn add_interleaved(mut sum: __m128, a: [F8; 3], b: [F8; 3]) -> __m128 {
    for (a, b) in per_pair(a).into_iter().zip(per_pair(b)) {
        sum = _mm_add_ps(_mm_add_ps(sum, a), b);
    }
    sum
}

/// Three vectors of eight lanes (x, y, z of pairs 0..8) as eight (x, y, z, 0).
#[inline(always)]
unsafe fn per_pair([x, y, z]: [F8; 3]) -> [__m128; 8] {
    let zero = _mm256_setzero_ps();
    let t0 = _mm256_unpacklo_ps(x.0, y.0);
    let t1 = _mm256_unpackhi_ps(x.0, y.0);
    let t2 = _mm256_unpacklo_ps(z.0, zero);
    let t3 = _mm256_unpackhi_ps(z.0, zero);
    // p_k = [pair k | pair k + 4], each (x, y, z, 0).
    let p = [
        _mm256_shuffle_ps::<0x44>(t0, t2),
        _mm256_shuffle_ps::<0xEE>(t0, t2),
        _mm256_shuffle_ps::<0x44>(t1, t3),
        _mm256_shuffle_ps::<0xEE>(t1, t3),
    ];
    let lo = |k: usize| _mm256_castps256_ps128(p[k]);
    let hi = |k: usize| _mm256_extractf128_ps::<1>(p[k]);
    [lo(0), lo(1), lo(2), lo(3), hi(0), hi(1), hi(2), hi(3)]
}

#[cfg(test)]
mod tests {
    use super::super::{density, forces, neighbors, wall};
    use super::*;

    /// The eight-wide sweep gives the scalar sweep's bits, acc and acc_b, on the
    /// walled 3D dam break jittered by 0.3 Δx with scattered velocities: F22 (23)
    /// with Adami walls, the barrier (which the jitter brings into play on some
    /// wall pairs), and the background pressure switched on; lists whose length
    /// is not a multiple of eight, and the fallback without a list.
    #[test]
    fn eight_wide_forces_match_the_scalar_sweep() {
        if !*AVX2 {
            return;
        }
        let path = format!(
            "{}/scenarios/validation/dam_break_3d.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let l = crate::load::load(&path, &["jitter=0.3".into()]).unwrap();
        let mut pr = Params::new(&l.model, 2);
        let mut st = l.state.clone();
        for (k, v) in st.vel.iter_mut().enumerate() {
            let s = |m: usize| ((k * m % 97) as f32 / 97.0 - 0.5) * 2.0;
            *v = [s(13), s(29), s(53), 0.0];
        }
        let mut grid = CellTable::default();
        neighbors::run(&pr, &mut st, &mut grid);
        let mut list = NeighborList::default();
        density::run(&pr, &mut st, &grid, &mut list);
        wall::run(&pr, &mut st, &grid);
        assert!(applies(&pr) && active(&pr, TermId::Barrier));
        let barrier_pairs = barrier_pairs(&pr, &st, &grid, &list);
        assert!(barrier_pairs > 0, "the barrier is never in play");
        for background in [0.0, 2.5e3] {
            pr.flow.background_pressure = background;
            for listed in [true, false] {
                if !listed {
                    grid.invalidate();
                }
                let mut scalar = st.clone();
                forces::scalar(&pr, &mut scalar, &grid, &list);
                let mut wide = st.clone();
                forces::run(&pr, &mut wide, &grid, &list);
                let bits = |s: &State| -> Vec<u32> {
                    let n = s.active();
                    s.acc[..n]
                        .iter()
                        .chain(&s.acc_b[..n])
                        .flatten()
                        .map(|x| x.to_bits())
                        .collect()
                };
                let (a, b) = (bits(&scalar), bits(&wide));
                let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
                assert_eq!(
                    differ, 0,
                    "p_b {background}, listed {listed}: {differ} words differ"
                );
                assert!(scalar.acc_b.iter().any(|a| a[0] != 0.0) == (background != 0.0));
            }
        }
    }

    /// Wall pairs inside the barrier radius.
    fn barrier_pairs(pr: &Params, st: &State, grid: &CellTable, list: &NeighborList) -> usize {
        let mut count = 0;
        for i in 0..st.active() {
            if pr.is_wall(st.phase[i]) {
                continue;
            }
            neighbors::for_each_listed(pr, &st.pos, grid, list, i, |j, _, r2| {
                let near = r2 > 0.0 && r2.sqrt() < pr.flow.barrier_radius;
                count += (near && pr.is_wall(st.phase[j])) as usize;
            });
        }
        count
    }
}
