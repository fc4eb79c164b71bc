// uses: params consts
// Rigid-body math: twin of the helpers in src/backend/cpu/bodies.rs, same
// operations in the same order. Every sum is written as one left-to-right chain
// of products, never "a + (b - c)": lavapipe rewrites that as (a + b) - c (found
// with the arithmetic probe: an accumulated cross product and a point velocity
// V + w x r differed from the CPU by several ULP); a chain it leaves alone.

fn cross3(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

// v turned by the unit quaternion q: v + 2 (w c + u x c) with c = u x v, u = q.xyz;
// the doubling as two additions (a factor 2 inside each product, lavapipe factored
// out of the sum).
fn quat_rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let u = q.xyz;
    let c = cross3(u, v);
    let s = vec3<f32>(
        q.w * c.x + u.y * c.z - u.z * c.y,
        q.w * c.y + u.z * c.x - u.x * c.z,
        q.w * c.z + u.x * c.y - u.y * c.x);
    return vec3<f32>(v.x + s.x + s.x, v.y + s.y + s.y, v.z + s.z + s.z);
}

fn quat_conj(q: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(-q.x, -q.y, -q.z, q.w);
}

// The angular velocity (world) from the world angular momentum: R (R^T L / I).
fn body_angular_velocity(b: Body) -> vec3<f32> {
    let lb = quat_rotate(quat_conj(b.q), b.l.xyz);
    let wb = vec3<f32>(lb.x / b.inertia.x, lb.y / b.inertia.y, lb.z / b.inertia.z);
    return quat_rotate(b.q, wb);
}

// The velocity of body b's material point at x: V + w x (x - X).
fn body_point_velocity(b: Body, x: vec4<f32>) -> vec3<f32> {
    let w = body_angular_velocity(b);
    let r = vec3<f32>(x.x - b.x.x, x.y - b.x.y, x.z - b.x.z);
    return vec3<f32>(
        b.v.x + w.y * r.z - w.z * r.y,
        b.v.y + w.z * r.x - w.x * r.z,
        b.v.z + w.x * r.y - w.y * r.x);
}

// Still a free body: members left and not bonded (the body passes skip the rest).
fn body_moves(b: Body) -> bool {
    return b.count > 0u && b.bonded == 0u;
}
