//! GPU backend: the pass table's WGSL entry points (shaders/), dispatched through
//! wgpu on Vulkan. A whole step (or many) is recorded into one command encoder;
//! nothing is read back inside a step.
//!
//! buffers.rs: device buffers and the bind group; shaders.rs: WGSL composition and
//! pipelines; sort.rs: the bitonic sort's schedule; profiler.rs: `--profile`.

mod buffers;
mod context;
pub mod probe;
mod profiler;
pub mod shaders;
mod sort;

pub use buffers::{bindable, Bindable, PassBinding, DEVICE_BUFFERS};
pub use context::{AdapterChoice, GpuContext};
pub use shaders::{pass_bindings, shader_sources};

use super::{Backend, DeviceLost, Node, Pipeline, Stage, Work};
use crate::fields::{Held, FIELDS, TABLES};
use crate::params::Params;
use crate::state::{Sim, State};
use buffers::{laser_bin_count, Buffers, REDUCE_WG};
use profiler::Profiler;
use sort::{sort_stages, SortStep, SORT_BLOCK, STAGE_STRIDE};
use std::collections::HashMap;

/// Threads per workgroup of the per-particle passes.
const WG: u32 = 64;

pub struct GpuBackend {
    ctx: GpuContext,
    params: Params,
    pipeline: Pipeline,
    /// The optional fields this scene holds.
    held: Held,
    n: u32,
    n_pad: u32,
    sort_steps: Vec<SortStep>,
    /// Entries of each table (crate::fields::TABLES) the state holds: fixed
    /// for the run (bodies and members keep their ranges; solver slots).
    table_entries: Vec<usize>,
    buf: Buffers,
    /// Group 0 per pass file (same buffers, each pass's read-only ones marked).
    binds: HashMap<&'static str, wgpu::BindGroup>,
    sort_bind: wgpu::BindGroup,
    pipelines: HashMap<&'static str, wgpu::ComputePipeline>,
    profiler: Option<Profiler>,
}

impl GpuBackend {
    pub fn new(ctx: GpuContext, params: Params, st: &State, profile: bool) -> Result<Self, String> {
        let n = st.len() as u32;
        let n_pad = n.next_power_of_two().max(2);
        let device = &ctx.device;
        let pipeline = Pipeline::for_scene(&params, st);
        let held = pipeline.held();
        let limit = ctx.limits.max_storage_buffer_binding_size;
        let biggest = buffers::largest_buffer(&params, n, n_pad, held);
        if biggest > limit {
            return Err(format!(
                "scene needs a {biggest}-byte GPU buffer but the adapter allows {limit} bytes per binding; use the cpu backend or a larger dx"
            ));
        }
        let stages = sort_stages(n_pad);
        let buf = Buffers::new(device, &params, st, n_pad, held, &stages);
        // A shader the driver rejects is an error of this run, not a panic.
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let bindings: HashMap<&'static str, Vec<PassBinding>> = shaders::PASSES
            .iter()
            .map(|(file, src)| {
                let b = shaders::pass_bindings(src)
                    .unwrap_or_else(|e| panic!("shaders/{file}.wgsl: {e}"));
                (*file, b)
            })
            .collect();
        let layouts: HashMap<&'static str, wgpu::BindGroupLayout> = bindings
            .iter()
            .map(|(file, b)| (*file, buffers::pass_layout(device, file, b)))
            .collect();
        let binds = layouts
            .iter()
            .map(|(file, layout)| {
                let group = buffers::main_bind_group(device, layout, &bindings[file], &buf);
                (*file, group)
            })
            .collect();
        let sort_layout = buffers::sort_layout(device);
        let sort_bind = buffers::sort_bind_group(device, &sort_layout, &buf);
        let pipelines = shaders::build_pipelines(device, &layouts, &sort_layout, &params);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(format!("GPU pipeline creation failed: {e}"));
        }
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let profiler = (profile && timestamps).then(|| {
            Profiler::new(
                device,
                ctx.queue.get_timestamp_period(),
                pipeline.recorded_step().len(),
            )
        });
        let g = GpuBackend {
            ctx,
            params,
            pipeline,
            held,
            n,
            n_pad,
            sort_steps: stages,
            table_entries: TABLES.iter().map(|t| t.entries(st)).collect(),
            buf,
            binds,
            sort_bind,
            pipelines,
            profiler,
        };
        g.buf.upload(&g.ctx.queue, st, held);
        Ok(g)
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Dispatch entry point `entry` over its work (a thread per particle, per
    /// laser bin, ...; the pass table says which).
    fn dispatch(&self, pass: &mut wgpu::ComputePass, entry: &str, work: Work) {
        pass.set_pipeline(&self.pipelines[entry]);
        let p = &self.params;
        let groups = match work {
            Work::Particles => self.n.div_ceil(WG),
            Work::SortKeys => self.n_pad.div_ceil(WG),
            Work::LaserBins => laser_bin_count(p).div_ceil(WG),
            Work::LaserColumns => {
                let b = p.laser.bins;
                let cols = if p.sizes.dim == 3 { b[0] * b[1] } else { b[0] };
                cols.div_ceil(WG)
            }
            Work::LaserRays => {
                let r = p.laser.rays_per_side;
                let rays = if p.sizes.dim == 3 { r * r } else { r };
                rays.div_ceil(WG)
            }
            Work::Reduction => self.n.div_ceil(REDUCE_WG),
            Work::Single => 1,
            Work::Bodies => p.bodies.n_bodies.div_ceil(WG),
            Work::Sort => unreachable!("the bitonic sort is scheduled by encode_neighbors"),
        };
        let (x, y) = grid_for(groups);
        pass.dispatch_workgroups(x, y, 1);
    }

    fn begin_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        stage: Stage,
        idx: u32,
    ) -> wgpu::ComputePass<'e> {
        self.begin_pass_marked(enc, stage.name(), stage.pass(), idx, true, true)
    }

    /// A compute pass of WGSL file `file` (its bind group), writing the stage's
    /// begin and/or end timestamp when profiling.
    fn begin_pass_marked<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        label: &str,
        file: &str,
        idx: u32,
        begin: bool,
        end: bool,
    ) -> wgpu::ComputePass<'e> {
        let timestamp_writes = self.profiler.as_ref().map(|p| p.writes(idx, begin, end));
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes,
        });
        pass.set_bind_group(0, &self.binds[file], &[]);
        pass
    }

    /// Record one stage: its entry points in the pass table's order, those the
    /// scene's features call for. `idx` is the stage's timestamp slot when profiling.
    fn encode_stage(&self, enc: &mut wgpu::CommandEncoder, stage: Stage, idx: u32) {
        if stage == Stage::Neighbors {
            return self.encode_neighbors(enc, idx);
        }
        let features = &self.pipeline.features;
        let mut pass = self.begin_pass(enc, stage, idx);
        for d in stage.def().dispatches.iter().filter(|d| (d.when)(features)) {
            self.dispatch(&mut pass, d.entry, d.work);
        }
    }

    /// Record one node: a repeat's begin, then every iteration of its stages (a
    /// finished loop's kernels return at once after reading the solver's flag).
    /// `idx` is the node's first timestamp slot; returns the next one.
    fn encode_node(&self, enc: &mut wgpu::CommandEncoder, node: &Node, idx: u32) -> u32 {
        let mut k = idx;
        for s in node.recorded() {
            self.encode_stage(enc, s, k);
            k += 1;
        }
        k
    }

    /// Record one whole step.
    fn encode_step(&self, enc: &mut wgpu::CommandEncoder) {
        let mut idx = 0;
        for node in &self.pipeline.step {
            idx = self.encode_node(enc, node, idx);
        }
    }

    fn encode_neighbors(&self, enc: &mut wgpu::CommandEncoder, idx: u32) {
        {
            let mut pass =
                self.begin_pass_marked(enc, "neighbors.sort", "neighbors", idx, true, false);
            self.dispatch(&mut pass, "cell_keys", Work::SortKeys);
            for (s, step) in self.sort_steps.iter().enumerate() {
                let (name, groups) = match step {
                    SortStep::Global { .. } => ("bitonic_global", (self.n_pad / 2).div_ceil(WG)),
                    SortStep::Local { .. } => ("bitonic_local", self.n_pad.div_ceil(SORT_BLOCK)),
                };
                pass.set_pipeline(&self.pipelines[name]);
                pass.set_bind_group(1, &self.sort_bind, &[s as u32 * STAGE_STRIDE as u32]);
                let (x, y) = grid_for(groups);
                pass.dispatch_workgroups(x, y, 1);
            }
            self.dispatch(&mut pass, "reorder", Work::Particles);
        }
        let b = &self.buf;
        b.copy_back_sorted(enc, self.held);
        enc.clear_buffer(&b.cell_start, 0, None);
        enc.clear_buffer(&b.cell_end, 0, None);
        enc.clear_buffer(&b.cell_fluid, 0, None);
        let mut pass =
            self.begin_pass_marked(enc, "neighbors.cell_bounds", "neighbors", idx, false, true);
        self.dispatch(&mut pass, "cell_bounds", Work::Particles);
    }

    fn submit(&self, enc: wgpu::CommandEncoder) {
        self.ctx.queue.submit([enc.finish()]);
    }

    /// The first `bytes` bytes of `src`, or why the device could not give them.
    fn read_bytes(&self, src: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, DeviceLost> {
        Ok(self.read_many(&[(src, bytes)])?.remove(0))
    }

    /// The first bytes of each buffer, all copied into one staging buffer by one
    /// submission and mapped once: a whole state comes back in one round trip
    /// instead of one per field (the bit-match compares the state after every
    /// stage, so that round trip was most of its time on the software adapter).
    fn read_many(&self, parts: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>, DeviceLost> {
        let device = &self.ctx.device;
        // Copies need 4-byte aligned offsets and sizes.
        let padded = |b: u64| b.max(4).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
        let total: u64 = parts.iter().map(|&(_, b)| padded(b)).sum();
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: total.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = device.create_command_encoder(&Default::default());
        let mut at = 0;
        for &(src, bytes) in parts {
            enc.copy_buffer_to_buffer(src, 0, &staging, at, padded(bytes));
            at += padded(bytes);
        }
        self.submit(enc);
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| DeviceLost(format!("GPU device lost while reading back: {e}")))?;
        match rx.try_recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(DeviceLost(format!("GPU readback failed: {e}"))),
            Err(_) => return Err(DeviceLost("GPU readback never completed".into())),
        }
        let out = {
            let all = staging
                .get_mapped_range(..)
                .map_err(|e| DeviceLost(format!("GPU readback could not be mapped: {e}")))?;
            let mut at = 0;
            parts
                .iter()
                .map(|&(_, bytes)| {
                    let part = all[at as usize..(at + bytes) as usize].to_vec();
                    at += padded(bytes);
                    part
                })
                .collect()
        };
        staging.unmap();
        Ok(out)
    }

    fn collect_profile(&mut self) {
        let Some(p) = &self.profiler else { return };
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        let stages = self.pipeline.recorded_step().len();
        enc.resolve_query_set(&p.queries, 0..2 * stages as u32, &p.resolve, 0);
        self.submit(enc);
        // A failed readback here surfaces at the run's next read_sim.
        let Ok(bytes) = self.read_bytes(&p.resolve, 16 * stages as u64) else {
            return;
        };
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        let step = self.pipeline.recorded_step();
        if let Some(p) = self.profiler.as_mut() {
            p.record(&step, &ticks);
        }
    }
}

/// Workgroup grid for `groups` groups: x up to 65535, the rest in y.
fn grid_for(groups: u32) -> (u32, u32) {
    if groups <= 65535 {
        (groups.max(1), 1)
    } else {
        (65535, groups.div_ceil(65535))
    }
}

impl Backend for GpuBackend {
    fn describe(&self) -> String {
        self.ctx.describe()
    }
    fn is_software(&self) -> bool {
        self.ctx.is_software()
    }
    fn pipeline(&self) -> &Pipeline {
        &self.pipeline
    }
    fn skip_stage(&mut self, stage: Stage) {
        self.pipeline.skip(stage);
    }
    fn run_stage(&mut self, stage: Stage) {
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        let idx = self
            .pipeline
            .recorded_step()
            .iter()
            .position(|s| *s == stage)
            .unwrap_or(0) as u32;
        self.encode_stage(&mut enc, stage, idx);
        self.submit(enc);
    }
    fn run_steps(&mut self, n: u32) {
        if self.profiler.is_some() {
            // One step per submission so each pass's timestamps can be collected.
            for _ in 0..n {
                let mut enc = self.ctx.device.create_command_encoder(&Default::default());
                self.encode_step(&mut enc);
                self.submit(enc);
                self.collect_profile();
            }
            return;
        }
        // Several steps per encoder; bounded so command buffers stay small.
        let mut left = n;
        while left > 0 {
            let chunk = left.min(32);
            let mut enc = self.ctx.device.create_command_encoder(&Default::default());
            for _ in 0..chunk {
                self.encode_step(&mut enc);
            }
            self.submit(enc);
            left -= chunk;
        }
    }
    /// Every field and table the scene holds (crate::fields), then the Sim block.
    fn read_state(&mut self) -> Result<State, DeviceLost> {
        // Every held field and table and the Sim in one readback.
        let mut parts: Vec<(&wgpu::Buffer, u64)> = Vec::new();
        let mut fields = Vec::new();
        for (f, buf) in FIELDS.iter().zip(&self.buf.fields) {
            if self.held.holds(f.holder) {
                parts.push((buf, self.n as u64 * f.bytes_per_particle() as u64));
                fields.push(f);
            }
        }
        let mut tables = Vec::new();
        for ((t, buf), &entries) in TABLES.iter().zip(&self.buf.tables).zip(&self.table_entries) {
            if self.held.holds(t.holder) && entries > 0 {
                parts.push((buf, (entries * t.components * 4) as u64));
                tables.push(t);
            }
        }
        parts.push((&self.buf.sim, std::mem::size_of::<Sim>() as u64));
        let bytes = self.read_many(&parts)?;
        let mut st = State::default();
        for (f, b) in fields.iter().zip(&bytes) {
            (f.set)(&mut st, b);
        }
        for (t, b) in tables.iter().zip(&bytes[fields.len()..]) {
            (t.set)(&mut st, b);
        }
        st.sim = bytemuck::pod_read_unaligned(&bytes[bytes.len() - 1]);
        Ok(st)
    }
    fn load_state(&mut self, st: &State) {
        assert_eq!(
            st.len() as u32,
            self.params.sizes.n_particles,
            "load_state: particle count changed"
        );
        self.buf.upload(&self.ctx.queue, st, self.held);
    }
    fn read_sim(&mut self) -> Result<Sim, DeviceLost> {
        let bytes = self.read_bytes(&self.buf.sim, std::mem::size_of::<Sim>() as u64)?;
        Ok(bytemuck::pod_read_unaligned(&bytes))
    }
    fn write_sim(&mut self, sim: &Sim) {
        self.ctx
            .queue
            .write_buffer(&self.buf.sim, 0, bytemuck::bytes_of(sim));
    }
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        self.profiler
            .as_mut()
            .map(|p| std::mem::take(&mut p.totals))
            .unwrap_or_default()
    }
}
