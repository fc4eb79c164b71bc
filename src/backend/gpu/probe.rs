//! Evaluate a WGSL expression of `a`, `b`, `c` element-wise on the device, with the
//! shared shader code (every library in shaders/lib/) and a parameter block bound
//! as in the real passes. Used by the tests that pin down the adapter's arithmetic.

use super::GpuContext;
use crate::params::Params;
use wgpu::util::DeviceExt;

pub fn eval_f32(
    ctx: &GpuContext,
    params: &Params,
    expr: &str,
    a: &[f32],
    b: &[f32],
    c: &[f32],
) -> Vec<f32> {
    let n = a.len();
    let libs = super::shaders::all_libraries();
    let src = format!(
        "{libs}
@group(1) @binding(0) var<storage, read_write> va: array<f32>;
@group(1) @binding(1) var<storage, read_write> vb: array<f32>;
@group(1) @binding(2) var<storage, read_write> vc: array<f32>;
@group(1) @binding(3) var<storage, read_write> out: array<f32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {{
    let i = gid.x;
    if (i >= arrayLength(&out)) {{ return; }}
    let a = va[i];
    let b = vb[i];
    let c = vc[i];
    out[i] = {expr};
}}"
    );
    let d = &ctx.device;
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("probe"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
    let mk = |data: &[f32]| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(data),
            usage,
        })
    };
    let bufs = [mk(a), mk(b), mk(c), mk(&vec![0.0f32; n])];
    let layout = pipeline.get_bind_group_layout(1);
    let entries: Vec<wgpu::BindGroupEntry> = bufs
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &entries,
    });
    let pbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("params"),
        contents: &params.uniform_bytes(),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let pbg = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: pbuf.as_entire_binding(),
        }],
    });
    let staging = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (n * 4) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &pbg, &[]);
        pass.set_bind_group(1, &bg, &[]);
        pass.dispatch_workgroups((n as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&bufs[3], 0, &staging, 0, (n * 4) as u64);
    ctx.queue.submit([enc.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |r| r.expect("map probe output"));
    d.poll(wgpu::PollType::wait_indefinitely())
        .expect("device lost");
    let out = bytemuck::cast_slice(&staging.get_mapped_range(..).expect("mapped")).to_vec();
    out
}
