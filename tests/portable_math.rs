//! Portable exp, ln and pow give the same bits on the GPU (software adapter) as
//! their Rust twins, over their whole domain. Accuracy is tested in the library.

mod common;
use bytemuck::Zeroable;
use spatter::backend::gpu::{probe::eval_f32, AdapterChoice, GpuContext};
use spatter::params::{Params, SHADER_CONSTS};
use spatter::portable_math as pm;

fn lcg(seed: &mut u64) -> f32 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 40) as f32 / (1u64 << 24) as f32
}

/// The software adapter and a parameter block holding only the shader constants.
fn software_adapter() -> (GpuContext, Params) {
    std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    let ctx = GpuContext::open(AdapterChoice::AnyGpu, false)
        .expect("a Vulkan adapter (the test command installs lavapipe)");
    assert!(ctx.is_software(), "bit-match needs the software adapter");
    let mut params = Params::zeroed();
    params.consts = SHADER_CONSTS;
    (ctx, params)
}

#[test]
fn portable_math_bit_identical_on_software_adapter() {
    let (ctx, params) = software_adapter();
    let mut seed = 7u64;
    let n = 1 << 16;
    // exp over [-100, 100] (including both saturations), ln over 1e-37..1e38 and a
    // few specials, pow over x in (0, 50], y in [-20, 20].
    let xs: Vec<f32> = (0..n).map(|_| -100.0 + 200.0 * lcg(&mut seed)).collect();
    let mut ls: Vec<f32> = (0..n)
        .map(|_| 10f32.powf(-37.0 + 75.0 * lcg(&mut seed)))
        .collect();
    ls[..4].copy_from_slice(&[0.0, -1.0, 1.0, f32::INFINITY]);
    let px: Vec<f32> = (0..n).map(|_| 50.0 * lcg(&mut seed) + 1e-3).collect();
    let py: Vec<f32> = (0..n).map(|_| -20.0 + 40.0 * lcg(&mut seed)).collect();
    let zero = vec![0.0f32; n];
    type Case<'a> = (&'a str, &'a [f32], &'a [f32], fn(f32, f32) -> f32);
    let cases: [Case; 3] = [
        ("pm_exp(a)", &xs, &zero, |a, _| pm::exp(a)),
        ("pm_ln(a)", &ls, &zero, |a, _| pm::ln(a)),
        ("pm_pow(a, b)", &px, &py, |a, b| pm::pow(a, b)),
    ];
    for (expr, a, b, f) in cases {
        let gpu = eval_f32(&ctx, &params, expr, a, b, &zero);
        for i in 0..n {
            let cpu = f(a[i], b[i]);
            let same = gpu[i].to_bits() == cpu.to_bits() || (gpu[i].is_nan() && cpu.is_nan());
            assert!(
                same,
                "{expr} at a = {:e}, b = {:e}: gpu {:e} vs cpu {:e}",
                a[i], b[i], gpu[i], cpu
            );
        }
    }
}

/// The ray-traced laser's Fresnel absorptivity (lib/math.wgsl `fresnel`, twin
/// `backend::cpu::laser::fresnel`) gives the same bits on the software adapter
/// over metals' and dielectrics' indices and every incidence. Written as
/// (n² − s²) − k²: lavapipe reassociates n² − k² − s².
#[test]
fn fresnel_bit_identical_on_software_adapter() {
    let (ctx, params) = software_adapter();
    let mut seed = 11u64;
    let n = 1 << 14;
    let ns: Vec<f32> = (0..n).map(|_| 0.1 + 6.0 * lcg(&mut seed)).collect();
    let ks: Vec<f32> = (0..n).map(|_| 8.0 * lcg(&mut seed)).collect();
    let cs: Vec<f32> = (0..n).map(|_| lcg(&mut seed)).collect();
    let gpu = eval_f32(&ctx, &params, "fresnel(a, b, c)", &ns, &ks, &cs);
    for i in 0..n {
        let cpu = spatter::backend::cpu::laser::fresnel(ns[i], ks[i], cs[i]);
        assert_eq!(
            gpu[i].to_bits(),
            cpu.to_bits(),
            "fresnel({}, {}, {}): gpu {:e} cpu {:e}",
            ns[i],
            ks[i],
            cs[i],
            gpu[i],
            cpu
        );
    }
}
