// writes: partials
// A fixed two-level tree sum of one vec2 per thread: each workgroup of DWG
// threads sums its values pairwise (s = 128, 64, ..., 1), thread 0 stores the
// group's sum in partials; then one workgroup adds the partials, thread t
// the ones at t, t + DWG, ... in order, and sums those pairwise. The CPU twin
// (backend::cpu::reduce::tree_total) adds the same pairs, so a solver's
// residual and dot products bit-match. A pass that uses it names partials
// on its own `// writes:` line too (a library's writes bind only in the
// arithmetic probe, which composes every library).

const DWG: u32 = 256u;
var<workgroup> dred: array<vec2<f32>, 256>;

fn tree_sum(t: u32) {
    for (var s = DWG / 2u; s > 0u; s = s / 2u) {
        workgroupBarrier();
        if (t < s) {
            dred[t] = dred[t] + dred[t + s];
        }
    }
    workgroupBarrier();
}

// Level one: thread t of workgroup g holds `value` (0 past the particles).
fn tree_level_one(t: u32, g: u32, value: vec2<f32>) {
    dred[t] = value;
    tree_sum(t);
    if (t == 0u) {
        partials[g] = dred[0];
    }
}

// Level two (one workgroup): the total over every group's partial.
fn tree_level_two(t: u32) -> vec2<f32> {
    let groups = (P.sizes.n_particles + DWG - 1u) / DWG;
    var m = vec2<f32>(0.0, 0.0);
    for (var g = t; g < groups; g += DWG) {
        m = m + partials[g];
    }
    dred[t] = m;
    tree_sum(t);
    return dred[0];
}
