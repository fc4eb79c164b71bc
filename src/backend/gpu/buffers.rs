//! Device buffers and the bind groups over them. Every buffer a pass can bind is
//! a row of a registry: the per-particle fields and their reorder scratch
//! (crate::fields::FIELDS), the state's tables (crate::fields::TABLES) and the
//! device-only buffers below (`DEVICE_BUFFERS`). A pass binds only the buffers
//! its WGSL header names (`// reads:`, `// writes:`, and its libraries'
//! `// reads:`), numbered in registry order from 1 (0 is the parameter block);
//! its composed WGSL declares exactly those (backend::gpu::shaders), read-only
//! unless written, and its bind group layout says the same. tests/fields.rs holds
//! each pass's naga-reflected bindings to its header.

use super::sort::{stage_uniforms, SortStep};
use crate::fields::{Held, FIELDS, TABLES};
use crate::params::{Params, LASER_BEER_LAMBERT, LASER_RAY_TRACED};
use crate::state::{Sim, State};
use wgpu::util::DeviceExt;

/// Workgroups of the max-speed reduction (timestep.wgsl).
pub const REDUCE_WG: u32 = 256;

/// A buffer that lives on the device only: name (its WGSL binding) and WGSL type.
pub struct DeviceBuffer {
    pub name: &'static str,
    pub wgsl: &'static str,
}

/// The device-only buffers, in binding order after the fields and tables.
pub const DEVICE_BUFFERS: [DeviceBuffer; 9] = [
    // Neighbour search: sort keys (cell, index), the cell table.
    DeviceBuffer {
        name: "keys",
        wgsl: "array<vec2<u32>>",
    },
    DeviceBuffer {
        name: "cell_start",
        wgsl: "array<u32>",
    },
    DeviceBuffer {
        name: "cell_end",
        wgsl: "array<u32>",
    },
    // 1 where a cell holds a fluid particle (set in cell_bounds; the wall pass
    // skips wall particles with no such cell around them). Order-free integer
    // atomics.
    DeviceBuffer {
        name: "cell_fluid",
        wgsl: "array<atomic<u32>>",
    },
    // Per-step scalars (Δt, time, step, the binding limit, ...).
    DeviceBuffer {
        name: "sim",
        wgsl: "Sim",
    },
    // A reduction's per-workgroup partial maxima.
    DeviceBuffer {
        name: "partials",
        wgsl: "array<vec2<f32>>",
    },
    // Laser scenes: per bin (Σ w V, absorbed power, Σ w V n, Σ w V k).
    DeviceBuffer {
        name: "bins",
        wgsl: "array<vec4<f32>>",
    },
    // Ray-traced laser: per bin, the absorbed power in fixed-point counts
    // (order-free integer atomics).
    DeviceBuffer {
        name: "ray_counts",
        wgsl: "array<atomic<u32>>",
    },
    // Rigid bodies: each particle id's current index (body_slots).
    DeviceBuffer {
        name: "slots",
        wgsl: "array<u32>",
    },
];

/// One bindable buffer: its name and WGSL declaration type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bindable {
    pub name: &'static str,
    pub wgsl: String,
}

fn field_wgsl(components: usize, is_float: bool) -> String {
    let scalar = if is_float { "f32" } else { "u32" };
    match components {
        1 => format!("array<{scalar}>"),
        c => format!("array<vec{c}<{scalar}>>"),
    }
}

/// Every storage buffer a pass can bind, in binding order: the fields, their
/// scratch, the tables, the device-only buffers.
pub fn bindable() -> Vec<Bindable> {
    let mut out: Vec<Bindable> = FIELDS
        .iter()
        .map(|f| Bindable {
            name: f.binding,
            wgsl: field_wgsl(f.components, f.is_float),
        })
        .collect();
    out.extend(FIELDS.iter().filter_map(|f| {
        f.scratch.map(|s| Bindable {
            name: s,
            wgsl: field_wgsl(f.components, f.is_float),
        })
    }));
    out.extend(TABLES.iter().map(|t| Bindable {
        name: t.name,
        wgsl: format!("array<{}>", t.wgsl),
    }));
    out.extend(DEVICE_BUFFERS.iter().map(|d| Bindable {
        name: d.name,
        wgsl: d.wgsl.to_string(),
    }));
    out
}

/// One binding of a pass: the buffer, whether the pass writes it, its number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PassBinding {
    pub binding: u32,
    pub name: &'static str,
    pub wgsl: String,
    pub writable: bool,
}

impl PassBinding {
    /// Atomics stay read_write in WGSL even where the pass only reads them.
    pub fn read_write(&self) -> bool {
        self.writable || self.wgsl.contains("atomic<")
    }
}

/// A pass's bindings from the names it reads and writes: registry order,
/// numbered from 1. A name the registry does not know is an error.
pub fn pass_bindings(reads: &[&str], writes: &[&str]) -> Result<Vec<PassBinding>, String> {
    let all = bindable();
    for n in reads.iter().chain(writes) {
        if !all.iter().any(|b| b.name == *n) {
            return Err(format!(
                "no buffer named '{n}' (fields, tables, DEVICE_BUFFERS)"
            ));
        }
    }
    Ok(all
        .into_iter()
        .filter(|b| reads.contains(&b.name) || writes.contains(&b.name))
        .enumerate()
        .map(|(k, b)| PassBinding {
            binding: k as u32 + 1,
            name: b.name,
            writable: writes.contains(&b.name),
            wgsl: b.wgsl,
        })
        .collect())
}

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
    /// Laser bins (Σ wV, absorbed power, Σ wV n, Σ wV k); a 16-byte
    /// placeholder without a laser.
    pub bins: wgpu::Buffer,
    /// Ray-traced laser: each bin's absorbed count; a placeholder otherwise.
    pub ray_counts: wgpu::Buffer,
    /// One per `TABLES` row (a placeholder of `min_entries` where the scene lacks it).
    pub tables: Vec<wgpu::Buffer>,
    /// Rigid bodies: each id's current index (a placeholder without bodies).
    pub slots: wgpu::Buffer,
}

/// Laser bins in the scene (0 without a laser).
pub fn laser_bin_count(p: &Params) -> u32 {
    if p.laser.model != LASER_BEER_LAMBERT && p.laser.model != LASER_RAY_TRACED {
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
        st: &State,
        n_pad: u32,
        held: Held,
        sort: &[SortStep],
    ) -> Buffers {
        let n = st.len() as u32;
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
                contents: &params.uniform_bytes(),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            fields: FIELDS
                .iter()
                .map(|f| storage(device, f.binding, size(f)))
                .collect(),
            scratch: FIELDS
                .iter()
                .map(|f| {
                    let bytes = if f.sorted_in(held) { size(f) } else { 16 };
                    f.scratch.map(|s| storage(device, s, bytes))
                })
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
            bins: storage(device, "laser bins", laser_bin_count(params) as u64 * 16),
            ray_counts: storage(
                device,
                "ray counts",
                if params.laser.model == LASER_RAY_TRACED {
                    laser_bin_count(params) as u64 * 4
                } else {
                    0
                },
            ),
            tables: TABLES
                .iter()
                .map(|t| {
                    let entries = if held.holds(t.holder) {
                        t.entries(st)
                    } else {
                        0
                    };
                    let bytes = entries.max(t.min_entries) as u64 * t.components as u64 * 4;
                    storage(device, t.name, bytes)
                })
                .collect(),
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
        if let Some(k) = TABLES.iter().position(|t| t.name == name) {
            return &self.tables[k];
        }
        match name {
            "keys" => &self.keys,
            "cell_start" => &self.cell_start,
            "cell_end" => &self.cell_end,
            "cell_fluid" => &self.cell_fluid,
            "sim" => &self.sim,
            "partials" => &self.partials,
            "bins" => &self.bins,
            "ray_counts" => &self.ray_counts,
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
        for (t, buf) in TABLES.iter().zip(&self.tables) {
            let words = (t.words)(st);
            if held.holds(t.holder) && !words.is_empty() {
                queue.write_buffer(buf, 0, bytemuck::cast_slice(words));
            }
        }
        queue.write_buffer(&self.sim, 0, bytemuck::bytes_of(&st.sim));
        queue.submit([]);
    }

    /// After the sort: each sorted field's scratch back into the field.
    pub fn copy_back_sorted(&self, enc: &mut wgpu::CommandEncoder, held: Held) {
        for (k, f) in FIELDS.iter().enumerate() {
            if let (Some(src), true) = (&self.scratch[k], f.sorted_in(held)) {
                let dst = &self.fields[k];
                enc.copy_buffer_to_buffer(src, 0, dst, 0, dst.size());
            }
        }
    }
}

/// A pass's layout of group 0: the parameter block, then its own bindings,
/// read-only where the pass only reads them.
pub fn pass_layout(
    device: &wgpu::Device,
    pass: &str,
    bindings: &[PassBinding],
) -> wgpu::BindGroupLayout {
    let entry = |binding: u32, ty: wgpu::BufferBindingType| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let mut entries = vec![entry(0, wgpu::BufferBindingType::Uniform)];
    entries.extend(bindings.iter().map(|b| {
        entry(
            b.binding,
            wgpu::BufferBindingType::Storage {
                read_only: !b.read_write(),
            },
        )
    }));
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
    bindings: &[PassBinding],
    b: &Buffers,
) -> wgpu::BindGroup {
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: b.params.as_entire_binding(),
    }];
    entries.extend(bindings.iter().map(|p| wgpu::BindGroupEntry {
        binding: p.binding,
        resource: b.by_binding(p.name).as_entire_binding(),
    }));
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
