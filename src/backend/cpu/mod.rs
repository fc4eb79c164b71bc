//! CPU reference backend: the twin of every WGSL pass, rayon-parallel over particles.
//! Each particle gathers from its own neighbours, so the result does not depend on
//! the thread count or schedule.

mod bodies;
mod continuity;
mod density;
mod dfsph;
mod dfsph_pairs;
mod dfsph_viscosity;
mod forces;
#[cfg(target_arch = "x86_64")]
mod forces_avx2;
mod heat;
mod integrate;
mod interface;
pub mod laser;
mod neighbors;
mod recorded;
mod reduce;
mod surface_forces;
mod terms;
mod timestep;
/// The time step F22 (42) gives for given |u|max² and |a|max², as the pass
/// computes it: the host evaluates it for the longest step a run can take.
pub use timestep::next_dt;
mod wall;

use super::schedule::SolverSlot;
use super::{Backend, DeviceLost, Node, Pipeline, Stage, Twin};
use crate::params::Params;
use crate::state::{Sim, State};
use std::time::Instant;

pub struct CpuBackend {
    pub params: Params,
    pub st: State,
    pipeline: Pipeline,
    grid: neighbors::CellTable,
    /// This step's fluid neighbours, from the density pass (for forces).
    list: neighbors::NeighborList,
    /// This step's DFSPH pairs, from the factor pass (for the solves).
    pairs: dfsph_pairs::PairTable,
    /// The velocity system's pair coefficients, from its `begin` (for `apply`).
    couplings: dfsph_viscosity::Couplings,
    /// Laser bins: (Σ wV, absorbed power, Σ wV n, Σ wV k), laser scenes only.
    laser_bins: Vec<[f32; 4]>,
    /// Ray-traced laser: each bin's absorbed power in fixed-point counts.
    ray_counts: Vec<u32>,
    times: Vec<(&'static str, f64)>,
}

impl CpuBackend {
    pub fn new(params: Params, st: State) -> Self {
        let pipeline = Pipeline::for_scene(&params, &st);
        CpuBackend {
            params,
            pipeline,
            st,
            grid: neighbors::CellTable::default(),
            list: neighbors::NeighborList::default(),
            pairs: dfsph_pairs::PairTable::default(),
            couplings: dfsph_viscosity::Couplings::default(),
            laser_bins: Vec::new(),
            ray_counts: Vec::new(),
            times: Vec::new(),
        }
    }
}

impl CpuBackend {
    /// Interacting pairs (i fluid, j any, r_ij < support) in the current cell table,
    /// the unit of DualSPHysics' PIPS.
    pub fn pair_count(&self) -> u64 {
        use rayon::prelude::*;
        let (pr, st, grid) = (&self.params, &self.st, &self.grid);
        (0..st.active())
            .into_par_iter()
            .filter(|&i| !pr.is_wall(st.phase[i]))
            .map(|i| {
                let mut n = 0u64;
                neighbors::for_each_neighbor(pr, &st.pos, grid, i, |j, _, _| n += (j != i) as u64);
                n
            })
            .sum()
    }

    /// Entries the neighbour list holds for the current cell table (a
    /// neighbour index each, the particle itself included), 0 without one.
    pub fn listed_count(&self) -> u64 {
        self.list
            .chunks(&self.grid)
            .map_or(0, |c| c.iter().map(|chunk| chunk.items.len() as u64).sum())
    }
}

/// The CPU twin of each dispatch, named as in the pass table (backend/passes.rs),
/// which says when each runs.
impl CpuBackend {
    pub(crate) fn kick_drift(&mut self) {
        integrate::kick_drift(&self.params, &mut self.st)
    }
    pub(crate) fn neighbors(&mut self) {
        neighbors::run(&self.params, &mut self.st, &mut self.grid)
    }
    pub(crate) fn density(&mut self) {
        density::run(&self.params, &mut self.st, &self.grid, &mut self.list)
    }
    pub(crate) fn dfsph_boundary_volume(&mut self) {
        dfsph::boundary_volume(&self.params, &mut self.st)
    }
    pub(crate) fn dfsph_factor(&mut self) {
        dfsph::factor(
            &self.params,
            &mut self.st,
            &self.grid,
            &mut self.list,
            &mut self.pairs,
        )
    }
    pub(crate) fn dfsph_begin(&mut self, slot: SolverSlot) {
        dfsph::begin(&self.params, &mut self.st, &self.grid, &self.pairs, slot)
    }
    pub(crate) fn dfsph_kappa(&mut self, slot: SolverSlot) {
        dfsph::kappa(&self.params, &mut self.st, slot)
    }
    pub(crate) fn dfsph_velocity(&mut self, slot: SolverSlot) {
        dfsph::velocity(&self.params, &mut self.st, &self.grid, &self.pairs, slot)
    }
    pub(crate) fn dfsph_error(&mut self, slot: SolverSlot) {
        dfsph::error(&self.params, &mut self.st, &self.grid, &self.pairs, slot)
    }
    pub(crate) fn dfsph_residual(&mut self, slot: SolverSlot) {
        dfsph::residual(&self.params, &mut self.st, slot)
    }
    pub(crate) fn dfsph_predict(&mut self) {
        dfsph::predict(&self.params, &mut self.st, &self.grid, &self.pairs)
    }
    pub(crate) fn dfsph_viscosity_wall(&mut self) {
        dfsph_viscosity::wall_velocities(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn dfsph_viscosity_begin(&mut self) {
        dfsph_viscosity::begin(
            &self.params,
            &mut self.st,
            &self.grid,
            &self.pairs,
            &mut self.couplings,
        )
    }
    pub(crate) fn dfsph_viscosity_apply(&mut self) {
        dfsph_viscosity::apply(
            &self.params,
            &mut self.st,
            &self.grid,
            &self.pairs,
            &self.couplings,
        )
    }
    pub(crate) fn dfsph_viscosity_update(&mut self) {
        dfsph_viscosity::update(&self.params, &mut self.st)
    }
    pub(crate) fn dfsph_drift(&mut self) {
        dfsph::drift(&self.params, &mut self.st)
    }
    pub(crate) fn continuity_gradient(&mut self) {
        continuity::gradients(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn continuity_rate(&mut self) {
        continuity::rates(&self.params, &mut self.st, &self.grid, &mut self.list)
    }
    pub(crate) fn continuity_update(&mut self) {
        continuity::update(&self.params, &mut self.st)
    }
    pub(crate) fn wall(&mut self) {
        wall::run(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn shepard(&mut self) {
        interface::shepard(&self.params, &mut self.st, &self.grid, &self.list)
    }
    pub(crate) fn normals(&mut self) {
        interface::normals(&self.params, &mut self.st, &self.grid, &self.list)
    }
    pub(crate) fn wetting(&mut self) {
        interface::wetting(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn forces(&mut self) {
        forces::run(&self.params, &mut self.st, &self.grid, &self.list)
    }
    pub(crate) fn surface_tension(&mut self) {
        surface_forces::surface_tension(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn tension_curvature(&mut self) {
        surface_forces::tension_curvature(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn tension_smooth(&mut self) {
        surface_forces::tension_smooth(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn tension_colour(&mut self) {
        surface_forces::tension_colour(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn tension_laplacian(&mut self) {
        surface_forces::tension_laplacian(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn recoil(&mut self) {
        surface_forces::recoil(&self.params, &mut self.st)
    }
    pub(crate) fn laser_surface(&mut self) {
        laser::surface(&self.params, &mut self.st)
    }
    pub(crate) fn laser_bins(&mut self) {
        laser::bins(&self.params, &self.st, &self.grid, &mut self.laser_bins)
    }
    pub(crate) fn laser_columns(&mut self) {
        laser::columns(&self.params, self.st.sim.time, &mut self.laser_bins)
    }
    pub(crate) fn laser_rays(&mut self) {
        let t = self.st.sim.time;
        laser::rays(
            &self.params,
            t,
            &self.laser_bins,
            &mut self.ray_counts,
            &mut self.st.laser_rays,
        )
    }
    pub(crate) fn laser_ray_bins(&mut self) {
        laser::ray_bins(&self.params, &self.ray_counts, &mut self.laser_bins)
    }
    pub(crate) fn laser_deposit(&mut self) {
        laser::deposit(&self.params, &mut self.st, &self.laser_bins)
    }
    pub(crate) fn wall_temperature(&mut self) {
        heat::wall_temperature(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn conduct(&mut self) {
        heat::conduct(&self.params, &mut self.st, &self.grid, &self.list)
    }
    pub(crate) fn heat_begin(&mut self) {
        heat::begin(&self.params, &mut self.st)
    }
    pub(crate) fn iterate_temperature(&mut self) {
        heat::iterate_temperature(&self.params, &mut self.st)
    }
    pub(crate) fn iterate_wall_temperature(&mut self) {
        if !heat::heat_converged(&self.st) {
            heat::wall_temperature(&self.params, &mut self.st, &self.grid)
        }
    }
    pub(crate) fn iterate_conduct(&mut self) {
        heat::iterate_conduct(&self.params, &mut self.st, &self.grid, &self.list)
    }
    pub(crate) fn heat_residual(&mut self) {
        heat::residual(&self.params, &mut self.st)
    }
    pub(crate) fn temperature(&mut self) {
        heat::temperature(&self.params, &mut self.st)
    }
    pub(crate) fn solidification_gradient(&mut self) {
        heat::solidification_gradient(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn kick(&mut self) {
        integrate::kick(&self.params, &mut self.st)
    }
    pub(crate) fn timestep(&mut self) {
        timestep::run(&self.params, &mut self.st)
    }
    pub(crate) fn body_drift(&mut self) {
        bodies::drift(&self.params, &mut self.st)
    }
    pub(crate) fn body_place(&mut self) {
        bodies::place(&mut self.st)
    }
    pub(crate) fn body_forces(&mut self) {
        bodies::forces(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn body_sum(&mut self) {
        bodies::sum(&mut self.st)
    }
    pub(crate) fn body_bond(&mut self) {
        bodies::bond(&self.params, &mut self.st, &self.grid)
    }
    pub(crate) fn body_melt(&mut self) {
        bodies::melt(&self.params, &mut self.st)
    }
    pub(crate) fn body_kick(&mut self) {
        bodies::kick(&self.params, &mut self.st)
    }
}

impl Backend for CpuBackend {
    fn describe(&self) -> String {
        format!("cpu ({} threads)", rayon::current_num_threads())
    }
    fn is_software(&self) -> bool {
        true
    }
    fn pipeline(&self) -> &Pipeline {
        &self.pipeline
    }
    fn skip_stage(&mut self, stage: Stage) {
        self.pipeline.skip(stage);
    }
    fn run_stage(&mut self, stage: Stage) {
        let t0 = Instant::now();
        let features = self.pipeline.features;
        for d in stage
            .def()
            .dispatches
            .iter()
            .filter(|d| (d.when)(&features))
        {
            if let Twin::Run(twin) = d.cpu {
                twin(self);
            }
        }
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let name = stage.name();
        match self.times.iter_mut().find(|(n, _)| *n == name) {
            Some(e) => e.1 += ms,
            None => self.times.push((name, ms)),
        }
    }
    /// A repeat stops once its solver's flag is set: the GPU's remaining
    /// iterations return at once, so the state is the same.
    fn run_node(&mut self, node: &Node) {
        match node {
            Node::Stage(s) => self.run_stage(*s),
            Node::Repeat(r) => {
                self.run_stage(r.begin);
                for _ in 0..r.max_iterations {
                    if self.st.solvers[r.solver as usize].converged != 0 {
                        break;
                    }
                    for &s in &r.stages {
                        self.run_stage(s);
                    }
                }
            }
        }
    }
    fn read_state(&mut self) -> Result<State, DeviceLost> {
        Ok(self.st.clone())
    }
    fn read_sim(&mut self) -> Result<Sim, DeviceLost> {
        Ok(self.st.sim)
    }
    fn write_sim(&mut self, sim: &Sim) {
        self.st.sim = *sim;
    }
    fn load_state(&mut self, st: &State) {
        assert_eq!(
            st.len(),
            self.st.len(),
            "load_state: particle count changed"
        );
        self.st = st.clone();
        self.grid.invalidate();
    }
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        std::mem::take(&mut self.times)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Backend;

    /// The DFSPH solves read the step's recorded pairs and the velocity
    /// system's couplings (dfsph_pairs), or sweep and evaluate them per
    /// iteration when the table is over its bound: the same bits after whole
    /// steps with every solver iteration, on the 2D spray droplet (Weiler's
    /// viscosity, XSPH, free-slip walls, the mushy sink) and the periodic
    /// Poiseuille channel (F22's isotropic form, no-slip walls).
    #[test]
    fn recorded_pairs_give_the_bits_of_the_sweep() {
        for scene in ["spray/j22_fluent_case_2d", "validation/poiseuille_dfsph_2d"] {
            let path = format!("{}/scenarios/{scene}.toml", env!("CARGO_MANIFEST_DIR"));
            let l = crate::load::load(&path, &[]).unwrap();
            let params = || Params::new(&l.model, l.state.len() as u32);
            let mut recorded = CpuBackend::new(params(), l.state.clone());
            let mut swept = CpuBackend::new(params(), l.state.clone());
            swept.pairs = dfsph_pairs::PairTable::with_bound(0);
            for b in [&mut recorded, &mut swept] {
                b.prime();
                b.run_steps(30);
            }
            assert!(recorded.pairs.chunks(&recorded.grid).is_some(), "{scene}");
            assert!(swept.pairs.chunks(&swept.grid).is_none(), "{scene}");
            let bits = |s: &State| -> Vec<u32> {
                let n = s.active();
                s.pos[..n]
                    .iter()
                    .chain(&s.vel[..n])
                    .chain(&s.dfsph[..n])
                    .flatten()
                    .chain(&s.rho[..n])
                    .chain(&s.press[..n])
                    .map(|x| x.to_bits())
                    .collect()
            };
            let (a, b) = (bits(&recorded.st), bits(&swept.st));
            assert_eq!(a.len(), b.len());
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            assert_eq!(differ, 0, "{scene}: {differ} words differ");
            let moved = recorded.st.vel.iter().any(|v| v[0] != 0.0);
            assert!(moved, "{scene}: nothing moved");
        }
    }
}
