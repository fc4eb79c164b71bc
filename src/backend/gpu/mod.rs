//! GPU backend: one WGSL file per pass (shaders/), dispatched through wgpu on Vulkan.
//! A whole step (or many) is recorded into one command encoder; nothing is read
//! back inside a step.

mod context;
pub mod probe;
pub mod shaders;

pub use context::{AdapterChoice, GpuContext};

use super::{entry_points, Backend, Pipeline, Stage, Work};
use crate::params::{Params, FLAG_HEAT, FLAG_INTERFACE, LASER_BEER_LAMBERT};
use crate::state::{Sim, State};
use std::collections::HashMap;
use wgpu::util::DeviceExt;

const WG: u32 = 64;
const REDUCE_WG: u32 = 256;
/// Stride between sort-stage uniforms (the usual min_uniform_buffer_offset_alignment).
const STAGE_STRIDE: u64 = 256;

struct Buffers {
    params: wgpu::Buffer,
    pos: wgpu::Buffer,
    vel: wgpu::Buffer,
    acc: wgpu::Buffer,
    acc_b: wgpu::Buffer,
    rho: wgpu::Buffer,
    p: wgpu::Buffer,
    mass: wgpu::Buffer,
    phase: wgpu::Buffer,
    id: wgpu::Buffer,
    keys: wgpu::Buffer,
    cell_start: wgpu::Buffer,
    cell_end: wgpu::Buffer,
    cell_fluid: wgpu::Buffer,
    scratch: [wgpu::Buffer; 7],
    sim: wgpu::Buffer,
    partials: wgpu::Buffer,
    sort_stages: wgpu::Buffer,
    /// (h, T, f_l, dh/dt) and its reorder scratch; 16-byte placeholders without heat.
    heat: wgpu::Buffer,
    s_heat: wgpu::Buffer,
    /// Laser bins (Σ wV, absorbed power); a 16-byte placeholder without a laser.
    bins: wgpu::Buffer,
    /// Interface normals and deltas, then Shepard sums (2n); placeholder otherwise.
    surface: wgpu::Buffer,
}

pub struct GpuBackend {
    ctx: GpuContext,
    params: Params,
    pipeline: Pipeline,
    n: u32,
    n_pad: u32,
    sort_steps: Vec<SortStep>,
    buf: Buffers,
    bind: wgpu::BindGroup,
    sort_bind: wgpu::BindGroup,
    pipelines: HashMap<&'static str, wgpu::ComputePipeline>,
    profiler: Option<Profiler>,
}

struct Profiler {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    period_ns: f32,
    totals: Vec<(&'static str, f64)>,
}

fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl GpuBackend {
    pub fn new(ctx: GpuContext, params: Params, st: &State, profile: bool) -> Result<Self, String> {
        let n = st.len() as u32;
        let n_pad = n.next_power_of_two().max(2);
        let device = &ctx.device;
        let n_cells = params.sizes.n_cells as u64;
        let limit = ctx.limits.max_storage_buffer_binding_size as u64;
        let biggest = (n as u64 * 16).max(n_pad as u64 * 8).max(n_cells * 4);
        if biggest > limit {
            return Err(format!(
                "scene needs a {biggest}-byte GPU buffer but the adapter allows {limit} bytes per binding; use the cpu backend or a larger dx"
            ));
        }
        let pipeline = Pipeline::for_scene(&params, st);
        let v4 = n as u64 * 16;
        let s1 = n as u64 * 4;
        let thermal = !st.heat.is_empty();
        let heat_bytes = if thermal { v4 } else { 16 };
        let stages = sort_stages(n_pad);
        let mut stage_bytes = vec![0u8; stages.len().max(1) * STAGE_STRIDE as usize];
        for (s, step) in stages.iter().enumerate() {
            let o = s * STAGE_STRIDE as usize;
            for (w, word) in step.uniform().iter().enumerate() {
                stage_bytes[o + 4 * w..o + 4 * w + 4].copy_from_slice(&word.to_le_bytes());
            }
        }
        let buf = Buffers {
            params: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            pos: storage(device, "pos", v4),
            vel: storage(device, "vel", v4),
            acc: storage(device, "acc", v4),
            acc_b: storage(device, "acc_b", v4),
            rho: storage(device, "rho", s1),
            p: storage(device, "p", s1),
            mass: storage(device, "mass", s1),
            phase: storage(device, "phase", s1),
            id: storage(device, "id", s1),
            keys: storage(device, "keys", n_pad as u64 * 8),
            cell_start: storage(device, "cell_start", n_cells * 4),
            cell_end: storage(device, "cell_end", n_cells * 4),
            cell_fluid: storage(device, "cell_fluid", n_cells * 4),
            scratch: [
                storage(device, "s_pos", v4),
                storage(device, "s_vel", v4),
                storage(device, "s_acc", v4),
                storage(device, "s_acc_b", v4),
                storage(device, "s_mass", s1),
                storage(device, "s_phase", s1),
                storage(device, "s_id", s1),
            ],
            sim: storage(device, "sim", std::mem::size_of::<Sim>() as u64),
            partials: storage(device, "partials", n.div_ceil(REDUCE_WG) as u64 * 8),
            sort_stages: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sort stages"),
                contents: &stage_bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            heat: storage(device, "heat", heat_bytes),
            s_heat: storage(device, "s_heat", heat_bytes),
            bins: storage(device, "laser bins", laser_bin_count(&params) as u64 * 8),
            surface: storage(device, "surface", st.surface.len() as u64 * 16),
        };
        let (layout, sort_layout) = layouts(device);
        let bind = main_bind_group(device, &layout, &buf);
        let sort_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sort stage"),
            layout: &sort_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buf.sort_stages,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
            }],
        });
        // A shader the driver rejects is an error of this run, not a panic.
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let pipelines = build_pipelines(device, &layout, &sort_layout, &params);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(format!("GPU pipeline creation failed: {e}"));
        }
        let profiler = if profile
            && ctx
                .device
                .features()
                .contains(wgpu::Features::TIMESTAMP_QUERY)
        {
            Some(Profiler::new(
                device,
                ctx.queue.get_timestamp_period(),
                pipeline.step.len(),
            ))
        } else {
            None
        };
        let mut g = GpuBackend {
            ctx,
            params,
            pipeline,
            n,
            n_pad,
            sort_steps: stages,
            buf,
            bind,
            sort_bind,
            pipelines,
            profiler,
        };
        g.upload(st);
        Ok(g)
    }

    fn upload(&mut self, st: &State) {
        let q = &self.ctx.queue;
        let b = &self.buf;
        q.write_buffer(&b.pos, 0, bytemuck::cast_slice(&st.pos));
        q.write_buffer(&b.vel, 0, bytemuck::cast_slice(&st.vel));
        q.write_buffer(&b.acc, 0, bytemuck::cast_slice(&st.acc));
        q.write_buffer(&b.acc_b, 0, bytemuck::cast_slice(&st.acc_b));
        q.write_buffer(&b.rho, 0, bytemuck::cast_slice(&st.rho));
        q.write_buffer(&b.p, 0, bytemuck::cast_slice(&st.p));
        q.write_buffer(&b.mass, 0, bytemuck::cast_slice(&st.mass));
        q.write_buffer(&b.phase, 0, bytemuck::cast_slice(&st.phase));
        q.write_buffer(&b.id, 0, bytemuck::cast_slice(&st.id));
        q.write_buffer(&b.sim, 0, bytemuck::bytes_of(&st.sim));
        if self.thermal() {
            q.write_buffer(&b.heat, 0, bytemuck::cast_slice(&st.heat));
        }
        if !st.surface.is_empty() {
            q.write_buffer(&b.surface, 0, bytemuck::cast_slice(&st.surface));
        }
        q.submit([]);
    }

    fn thermal(&self) -> bool {
        self.params.flag(FLAG_HEAT)
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
            Work::Reduction => self.n.div_ceil(REDUCE_WG),
            Work::Single => 1,
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
        self.begin_pass_marked(enc, stage.name(), idx, true, true)
    }

    /// A compute pass writing the stage's begin and/or end timestamp when profiling.
    fn begin_pass_marked<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        label: &str,
        idx: u32,
        begin: bool,
        end: bool,
    ) -> wgpu::ComputePass<'e> {
        let timestamp_writes = self
            .profiler
            .as_ref()
            .map(|p| wgpu::ComputePassTimestampWrites {
                query_set: &p.queries,
                beginning_of_pass_write_index: begin.then_some(2 * idx),
                end_of_pass_write_index: end.then_some(2 * idx + 1),
            });
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes,
        });
        pass.set_bind_group(0, &self.bind, &[]);
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
        for d in stage.def().gpu.iter().filter(|d| (d.when)(features)) {
            self.dispatch(&mut pass, d.entry, d.work);
        }
    }

    fn encode_neighbors(&self, enc: &mut wgpu::CommandEncoder, idx: u32) {
        {
            let mut pass = self.begin_pass_marked(enc, "neighbors.sort", idx, true, false);
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
        let targets = [&b.pos, &b.vel, &b.acc, &b.acc_b, &b.mass, &b.phase, &b.id];
        for (src, dst) in b.scratch.iter().zip(targets) {
            enc.copy_buffer_to_buffer(src, 0, dst, 0, dst.size());
        }
        if self.thermal() {
            enc.copy_buffer_to_buffer(&b.s_heat, 0, &b.heat, 0, b.heat.size());
        }
        enc.clear_buffer(&b.cell_start, 0, None);
        enc.clear_buffer(&b.cell_end, 0, None);
        enc.clear_buffer(&b.cell_fluid, 0, None);
        let mut pass = self.begin_pass_marked(enc, "neighbors.cell_bounds", idx, false, true);
        self.dispatch(&mut pass, "cell_bounds", Work::Particles);
    }

    fn submit(&self, enc: wgpu::CommandEncoder) {
        self.ctx.queue.submit([enc.finish()]);
    }

    fn read_bytes(&self, src: &wgpu::Buffer, bytes: u64) -> Vec<u8> {
        let device = &self.ctx.device;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(src, 0, &staging, 0, bytes.max(4));
        self.submit(enc);
        staging.map_async(wgpu::MapMode::Read, .., |r| r.expect("map readback buffer"));
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("GPU device lost while reading back");
        let out = staging.get_mapped_range(..).expect("mapped range").to_vec();
        staging.unmap();
        out[..bytes as usize].to_vec()
    }

    fn read_vec<T: bytemuck::Pod>(&self, src: &wgpu::Buffer) -> Vec<T> {
        let bytes = self.n as u64 * std::mem::size_of::<T>() as u64;
        bytemuck::cast_slice(&self.read_bytes(src, bytes)).to_vec()
    }

    fn collect_profile(&mut self) {
        let Some(p) = &self.profiler else { return };
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        let stages = self.pipeline.step.len();
        enc.resolve_query_set(&p.queries, 0..2 * stages as u32, &p.resolve, 0);
        self.submit(enc);
        let ticks: Vec<u64> =
            bytemuck::cast_slice(&self.read_bytes(&p.resolve, 16 * stages as u64)).to_vec();
        let period = p.period_ns as f64;
        let p = self.profiler.as_mut().unwrap();
        for (k, s) in self.pipeline.step.iter().enumerate() {
            let ms = ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * period * 1e-6;
            match p.totals.iter_mut().find(|(n, _)| *n == s.name()) {
                Some(e) => e.1 += ms,
                None => p.totals.push((s.name(), ms)),
            }
        }
    }
}

impl Profiler {
    fn new(device: &wgpu::Device, period_ns: f32, stages: usize) -> Self {
        let count = 2 * stages as u32;
        Profiler {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: count as u64 * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            period_ns,
            totals: Vec::new(),
        }
    }
}

/// Laser bins in the scene (0 without a laser).
fn laser_bin_count(p: &Params) -> u32 {
    if p.laser.model != LASER_BEER_LAMBERT {
        return 0;
    }
    p.laser.bins[0] * p.laser.bins[1] * p.laser.bins[2]
}

/// Workgroup grid for `groups` groups: x up to 65535, the rest in y.
fn grid_for(groups: u32) -> (u32, u32) {
    if groups <= 65535 {
        (groups.max(1), 1)
    } else {
        (65535, groups.div_ceil(65535))
    }
}

/// Keys per workgroup-memory block of the bitonic sort (twin of neighbors.wgsl).
const SORT_BLOCK: u32 = 2048;

/// One dispatch of the bitonic sort (neighbors.wgsl).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SortStep {
    /// Compare-exchange stage (j, k) with j >= SORT_BLOCK, through global memory.
    Global { j: u32, k: u32 },
    /// Every stage with j < SORT_BLOCK of k = k_first..=k_last, in workgroup memory.
    Local { k_first: u32, k_last: u32 },
}

impl SortStep {
    /// The SortStage uniform: (j, k, k_last, 0).
    fn uniform(&self) -> [u32; 4] {
        match *self {
            SortStep::Global { j, k } => [j, k, 0, 0],
            SortStep::Local { k_first, k_last } => [0, k_first, k_last, 0],
        }
    }
}

/// The dispatches of a bitonic sort over n_pad keys (a power of two): all of
/// k <= SORT_BLOCK at once in workgroup memory, then per larger k its global stages
/// down to j = SORT_BLOCK and one local dispatch for the rest.
fn sort_stages(n_pad: u32) -> Vec<SortStep> {
    let block = SORT_BLOCK.min(n_pad);
    let mut out = vec![SortStep::Local {
        k_first: 2,
        k_last: block,
    }];
    let mut k = 2 * block;
    while k <= n_pad {
        let mut j = k / 2;
        while j >= block {
            out.push(SortStep::Global { j, k });
            j /= 2;
        }
        out.push(SortStep::Local {
            k_first: k,
            k_last: k,
        });
        k *= 2;
    }
    out
}

fn layouts(device: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::BindGroupLayout) {
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }];
    for b in 1..=26 {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: b,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        });
    }
    let main = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("particles"),
        entries: &entries,
    });
    let sort = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("sort stage"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(16),
            },
            count: None,
        }],
    });
    (main, sort)
}

fn main_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    b: &Buffers,
) -> wgpu::BindGroup {
    let list: [&wgpu::Buffer; 27] = [
        &b.params,
        &b.pos,
        &b.vel,
        &b.acc,
        &b.acc_b,
        &b.rho,
        &b.p,
        &b.mass,
        &b.phase,
        &b.id,
        &b.keys,
        &b.cell_start,
        &b.cell_end,
        &b.scratch[0],
        &b.scratch[1],
        &b.scratch[2],
        &b.scratch[3],
        &b.scratch[4],
        &b.scratch[5],
        &b.scratch[6],
        &b.sim,
        &b.partials,
        &b.heat,
        &b.s_heat,
        &b.bins,
        &b.surface,
        &b.cell_fluid,
    ];
    let entries: Vec<wgpu::BindGroupEntry> = list
        .iter()
        .enumerate()
        .map(|(i, buf)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: buf.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("particles"),
        layout,
        entries: &entries,
    })
}

/// Each pass's complete WGSL source (its libraries first, neighbour walks
/// expanded), by shader file name. Public so that a test can validate them without
/// an adapter.
pub fn shader_sources() -> Vec<(&'static str, String)> {
    shaders::PASSES
        .iter()
        .map(|(name, src)| {
            let full =
                shaders::compose(name, src).unwrap_or_else(|e| panic!("shaders/{name}.wgsl: {e}"));
            (*name, full)
        })
        .collect()
}

fn build_pipelines(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    sort_layout: &wgpu::BindGroupLayout,
    params: &Params,
) -> HashMap<&'static str, wgpu::ComputePipeline> {
    let modules: HashMap<&str, wgpu::ShaderModule> = shader_sources()
        .into_iter()
        .map(|(name, source)| {
            let m = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            (name, m)
        })
        .collect();
    let plain = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("particles"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    let sorting = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("particles + sort stage"),
        bind_group_layouts: &[Some(layout), Some(sort_layout)],
        immediate_size: 0,
    });
    entry_points()
        .into_iter()
        .map(|(entry, file)| {
            let pl = if entry.starts_with("bitonic") {
                &sorting
            } else {
                &plain
            };
            // The pass's switchable pair terms: a term the scene does not use is
            // compiled out here, not skipped per pair.
            let switches = super::terms::switches(file, params);
            let p = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(pl),
                module: &modules[file],
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &switches,
                    ..Default::default()
                },
                cache: None,
            });
            (entry, p)
        })
        .collect()
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
    fn run_stage(&mut self, stage: Stage) {
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        let idx = self
            .pipeline
            .step
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
                for (k, s) in self.pipeline.step.iter().enumerate() {
                    self.encode_stage(&mut enc, *s, k as u32);
                }
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
                for (k, s) in self.pipeline.step.iter().enumerate() {
                    self.encode_stage(&mut enc, *s, k as u32);
                }
            }
            self.submit(enc);
            left -= chunk;
        }
    }
    fn read_state(&mut self) -> State {
        let b = &self.buf;
        State {
            pos: self.read_vec(&b.pos),
            vel: self.read_vec(&b.vel),
            acc: self.read_vec(&b.acc),
            acc_b: self.read_vec(&b.acc_b),
            rho: self.read_vec(&b.rho),
            p: self.read_vec(&b.p),
            mass: self.read_vec(&b.mass),
            phase: self.read_vec(&b.phase),
            id: self.read_vec(&b.id),
            heat: if self.thermal() {
                self.read_vec(&b.heat)
            } else {
                Vec::new()
            },
            surface: if self.params.flag(FLAG_INTERFACE) {
                bytemuck::cast_slice(&self.read_bytes(&b.surface, 2 * self.n as u64 * 16)).to_vec()
            } else {
                Vec::new()
            },
            sim: self.read_sim(),
        }
    }
    fn load_state(&mut self, st: &State) {
        assert_eq!(
            st.len() as u32,
            self.params.sizes.n_particles,
            "load_state: particle count changed"
        );
        self.upload(st);
    }
    fn read_sim(&mut self) -> Sim {
        *bytemuck::from_bytes(&self.read_bytes(&self.buf.sim, std::mem::size_of::<Sim>() as u64))
    }
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        self.profiler
            .as_mut()
            .map(|p| std::mem::take(&mut p.totals))
            .unwrap_or_default()
    }
}

impl GpuBackend {
    pub fn params(&self) -> &Params {
        &self.params
    }
}
