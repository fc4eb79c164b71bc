// uses: params
// Every buffer a pass can bind, in binding order (src/backend/gpu/mod.rs).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> acc_b: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> rho: array<f32>;
@group(0) @binding(6) var<storage, read_write> press: array<f32>;
@group(0) @binding(7) var<storage, read_write> mass: array<f32>;
@group(0) @binding(8) var<storage, read_write> phase: array<u32>;
@group(0) @binding(9) var<storage, read_write> id: array<u32>;
@group(0) @binding(10) var<storage, read_write> keys: array<vec2<u32>>;
@group(0) @binding(11) var<storage, read_write> cell_start: array<u32>;
@group(0) @binding(12) var<storage, read_write> cell_end: array<u32>;
@group(0) @binding(13) var<storage, read_write> s_pos: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> s_vel: array<vec4<f32>>;
@group(0) @binding(15) var<storage, read_write> s_acc: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> s_acc_b: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read_write> s_mass: array<f32>;
@group(0) @binding(18) var<storage, read_write> s_phase: array<u32>;
@group(0) @binding(19) var<storage, read_write> s_id: array<u32>;
@group(0) @binding(20) var<storage, read_write> sim: Sim;
@group(0) @binding(21) var<storage, read_write> partials: array<vec2<f32>>;
// Heat scenes: (h, T, f_l, dh/dt) and its reorder scratch; a 16-byte placeholder
// otherwise (no heat pass is dispatched).
@group(0) @binding(22) var<storage, read_write> heat: array<vec4<f32>>;
@group(0) @binding(23) var<storage, read_write> s_heat: array<vec4<f32>>;
// Laser scenes: per bin (sum of w V, absorbed power); a placeholder otherwise.
@group(0) @binding(24) var<storage, read_write> bins: array<vec2<f32>>;
// Interface scenes: (normal, delta) per particle, then the Shepard sums; a
// placeholder otherwise.
@group(0) @binding(25) var<storage, read_write> surface: array<vec4<f32>>;
// 1 where a cell holds a fluid particle (set in cell_bounds; the wall pass skips
// wall particles with no such cell around them). Order-free integer atomics.
@group(0) @binding(26) var<storage, read_write> cell_fluid: array<atomic<u32>>;
// Rigid-body scenes: each particle's body (NO_BODY: none) and its body-frame
// offset, both indexed by particle id (body[id[i]]: they never change, so they
// are not sorted and need no scratch); the body table, the members of every body
// by particle id (body after body) and each id's current index (body_slots).
// Placeholders otherwise.
@group(0) @binding(27) var<storage, read_write> body: array<u32>;
@group(0) @binding(28) var<storage, read_write> body_offset: array<vec4<f32>>;
@group(0) @binding(29) var<storage, read_write> bodies: array<Body>;
@group(0) @binding(30) var<storage, read_write> members: array<u32>;
@group(0) @binding(31) var<storage, read_write> slots: array<u32>;
