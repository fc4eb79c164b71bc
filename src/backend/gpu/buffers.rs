//! Device buffers and the bind groups over them: one per pass file, the same
//! buffers at the same bindings, each pass's read-only ones marked read-only (the
//! pass's `// writes:` line, backend::gpu::shaders). The per-particle fields
//! come from the field registry (crate::fields); the rest is the cell table, the
//! sort keys, per-step scalars and scene-specific tables. `BINDINGS` names the
//! buffer at each binding of shaders/lib/bindings.wgsl (tests/fields.rs reads that
//! file through naga and holds the two to each other).

use super::sort::{stage_uniforms, SortStep};
use crate::fields::{Held, FIELDS};
use crate::params::{Params, LASER_BEER_LAMBERT};
use crate::state::{Sim, State};
use wgpu::util::DeviceExt;

/// Workgroups of the max-speed reduction (timestep.wgsl).
pub const REDUCE_WG: u32 = 256;

/// Group 0, binding by binding, grouped by concern.
pub const BINDINGS: [&str; 32] = [
    // The parameter block.
    "P",
    // Particle fields (crate::fields).
    "pos",
    "vel",
    "acc",
    "acc_b",
    "rho",
    "press",
    "mass",
    "phase",
    "id",
    // Neighbour search: sort keys and the cell table.
    "keys",
    "cell_start",
    "cell_end",
    // Reorder scratch of the sorted fields.
    "s_pos",
    "s_vel",
    "s_acc",
    "s_acc_b",
    "s_mass",
    "s_phase",
    "s_id",
    // Per-step scalars and the reduction's partial maxima.
    "sim",
    "partials",
    // Heat scenes: the heat field and its scratch.
    "heat",
    "s_heat",
    // Laser bins; interface normals; cells holding fluid (wall pass).
    "bins",
    "surface",
    "cell_fluid",
    // Rigid bodies: body and offset by particle id, the body table, the member
    // lists and the id -> index slots.
    "body",
    "body_offset",
    "bodies",
    "members",
    "slots",
];

pub fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub struct Buffers {
    pub params: wgpu::Buffer,
    /// One per `FIELDS` row (a 16-byte placeholder where the scene lacks it) …
    pub fields: Vec<wgpu::Buffer>,
    /// … and its reorder scratch, for the rows that have one.
    pub scratch: Vec<Option<wgpu::Buffer>>,
    pub keys: wgpu::Buffer,
    pub cell_start: wgpu::Buffer,
    pub cell_end: wgpu::Buffer,
    pub cell_fluid: wgpu::Buffer,
    pub sim: wgpu::Buffer,
    pub partials: wgpu::Buffer,
    pub sort_stages: wgpu::Buffer,
    /// Laser bins (Σ wV, absorbed power); a 16-byte placeholder without a laser.
    pub bins: wgpu::Buffer,
    /// Rigid bodies: the body table, the member lists, each id's current index
    /// (16-byte placeholders without bodies).
    pub bodies: wgpu::Buffer,
    pub members: wgpu::Buffer,
    pub slots: wgpu::Buffer,
}

/// Laser bins in the scene (0 without a laser).
pub fn laser_bin_count(p: &Params) -> u32 {
    if p.laser.model != LASER_BEER_LAMBERT {
        return 0;
    }
    p.laser.bins[0] * p.laser.bins[1] * p.laser.bins[2]
}

/// The largest single buffer a scene needs (bytes), for the adapter's binding limit.
pub fn largest_buffer(params: &Params, n: u32, n_pad: u32, held: Held) -> u64 {
    let fields = FIELDS
        .iter()
        .filter(|f| held.holds(f.holder))
        .map(|f| n as u64 * f.bytes_per_particle() as u64)
        .max()
        .unwrap_or(0);
    fields
        .max(n_pad as u64 * 8)
        .max(params.sizes.n_cells as u64 * 4)
}

impl Buffers {
    pub fn new(
        device: &wgpu::Device,
        params: &Params,
        n: u32,
        n_pad: u32,
        held: Held,
        sort: &[SortStep],
    ) -> Buffers {
        let n_cells = params.sizes.n_cells as u64;
        let size = |f: &crate::fields::FieldDef| {
            if held.holds(f.holder) {
                n as u64 * f.bytes_per_particle() as u64
            } else {
                16
            }
        };
        Buffers {
            params: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytemuck::bytes_of(params),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            fields: FIELDS
                .iter()
                .map(|f| storage(device, f.binding, size(f)))
                .collect(),
            scratch: FIELDS
                .iter()
                .map(|f| f.scratch.map(|s| storage(device, s, size(f))))
                .collect(),
            keys: storage(device, "keys", n_pad as u64 * 8),
            cell_start: storage(device, "cell_start", n_cells * 4),
            cell_end: storage(device, "cell_end", n_cells * 4),
            cell_fluid: storage(device, "cell_fluid", n_cells * 4),
            sim: storage(device, "sim", std::mem::size_of::<Sim>() as u64),
            partials: storage(device, "partials", n.div_ceil(REDUCE_WG) as u64 * 8),
            sort_stages: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sort stages"),
                contents: &stage_uniforms(sort),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            bins: storage(device, "laser bins", laser_bin_count(params) as u64 * 8),
            // At least one entry: the wall pass declares the table, and a binding
            // must hold one element of it (128 bytes) even where no body exists.
            bodies: storage(
                device,
                "bodies",
                params.bodies.n_bodies.max(1) as u64
                    * std::mem::size_of::<crate::state::Body>() as u64,
            ),
            members: storage(
                device,
                "members",
                if held.bodies { n as u64 * 4 } else { 0 },
            ),
            slots: storage(device, "slots", if held.bodies { n as u64 * 4 } else { 0 }),
        }
    }

    /// The buffer bound as `name` in the WGSL.
    pub fn by_binding(&self, name: &str) -> &wgpu::Buffer {
        if let Some(k) = FIELDS.iter().position(|f| f.binding == name) {
            return &self.fields[k];
        }
        if let Some(k) = FIELDS.iter().position(|f| f.scratch == Some(name)) {
            return self.scratch[k].as_ref().expect("scratch allocated");
        }
        match name {
            "P" => &self.params,
            "keys" => &self.keys,
            "cell_start" => &self.cell_start,
            "cell_end" => &self.cell_end,
            "cell_fluid" => &self.cell_fluid,
            "sim" => &self.sim,
            "partials" => &self.partials,
            "bins" => &self.bins,
            "bodies" => &self.bodies,
            "members" => &self.members,
            "slots" => &self.slots,
            other => panic!("no buffer for binding {other}"),
        }
    }

    /// Write every field the scene holds, and the Sim block.
    pub fn upload(&self, queue: &wgpu::Queue, st: &State, held: Held) {
        for (f, buf) in FIELDS.iter().zip(&self.fields) {
            let words = (f.words)(st);
            if held.holds(f.holder) && !words.is_empty() {
                queue.write_buffer(buf, 0, bytemuck::cast_slice(words));
            }
        }
        if held.bodies {
            queue.write_buffer(&self.bodies, 0, bytemuck::cast_slice(&st.bodies));
            queue.write_buffer(&self.members, 0, bytemuck::cast_slice(&st.members));
        }
        queue.write_buffer(&self.sim, 0, bytemuck::bytes_of(&st.sim));
        queue.submit([]);
    }

    /// After the sort: each sorted field's scratch back into the field.
    pub fn copy_back_sorted(&self, enc: &mut wgpu::CommandEncoder, held: Held) {
        for (k, f) in FIELDS.iter().enumerate() {
            if let (Some(src), true) = (&self.scratch[k], held.holds(f.holder)) {
                let dst = &self.fields[k];
                enc.copy_buffer_to_buffer(src, 0, dst, 0, dst.size());
            }
        }
    }
}

/// A pass's layout of group 0: the parameter block, then every storage buffer,
/// read-only where the pass only reads it (shaders::read_only_bindings).
pub fn pass_layout(device: &wgpu::Device, pass: &str, read_only: &[&str]) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = BINDINGS
        .iter()
        .enumerate()
        .map(|(b, name)| wgpu::BindGroupLayoutEntry {
            binding: b as u32,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: if b == 0 {
                    wgpu::BufferBindingType::Uniform
                } else {
                    wgpu::BufferBindingType::Storage {
                        read_only: read_only.contains(name),
                    }
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(pass),
        entries: &entries,
    })
}

/// The sort stage's layout (group 1: one uniform with a dynamic offset).
pub fn sort_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
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
    })
}

pub fn main_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    b: &Buffers,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = BINDINGS
        .iter()
        .enumerate()
        .map(|(i, name)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.by_binding(name).as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("particles"),
        layout,
        entries: &entries,
    })
}

pub fn sort_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    b: &Buffers,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sort stage"),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &b.sort_stages,
                offset: 0,
                size: wgpu::BufferSize::new(16),
            }),
        }],
    })
}
