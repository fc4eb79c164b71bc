//! Twin of shaders/lib/reduce.wgsl: the fixed two-level tree sum the GPU's
//! solvers reduce with (per workgroup of `DWG` values pairwise, then one
//! workgroup over the partials), so a residual or a dot product has the same
//! bits on both backends.

/// Threads per workgroup of the tree (`DWG` in the WGSL).
pub const DWG: usize = 256;

/// One workgroup's tree: s = 128, 64, ..., 1, red[t] += red[t + s].
fn tree_sum(red: &mut [[f32; 2]; DWG]) -> [f32; 2] {
    let mut s = DWG / 2;
    while s > 0 {
        for t in 0..s {
            red[t] = [red[t][0] + red[t + s][0], red[t][1] + red[t + s][1]];
        }
        s /= 2;
    }
    red[0]
}

/// The total of `value(i)` over slots 0..n (n the particle capacity, the GPU's
/// dispatch; `value` gives 0 for slots that do not count).
pub fn tree_total(n: usize, value: impl Fn(usize) -> [f32; 2] + Sync) -> [f32; 2] {
    use rayon::prelude::*;
    let groups = n.div_ceil(DWG);
    let partials: Vec<[f32; 2]> = (0..groups)
        .into_par_iter()
        .map(|g| {
            let mut red = [[0.0f32; 2]; DWG];
            for (t, e) in red.iter_mut().enumerate() {
                let i = g * DWG + t;
                if i < n {
                    *e = value(i);
                }
            }
            tree_sum(&mut red)
        })
        .collect();
    let mut red = [[0.0f32; 2]; DWG];
    for (t, m) in red.iter_mut().enumerate() {
        for p in partials.iter().skip(t).step_by(DWG) {
            *m = [m[0] + p[0], m[1] + p[1]];
        }
    }
    tree_sum(&mut red)
}
