// uses: params consts
// Portable exp, ln and pow. Twin of src/portable_math.rs (same operations, same
// order); coefficients come from the parameter block so the compiler cannot
// reassociate them (see consts.wgsl).

fn pm_exp(x: f32) -> f32 {
    if (x != x) { return x; }
    if (x > 88.0) { return bitcast<f32>(0x7f800000u); }
    if (x < -87.3) { return 0.0; }
    let log2e = P.consts.log2e;
    let ln2_hi = P.consts.ln2_hi;
    let ln2_lo = P.consts.ln2_lo;
    let c0 = P.consts.exp_c0;
    let c1 = P.consts.exp_c1;
    let c2 = P.consts.exp_c2;
    let c3 = P.consts.exp_c3;
    let c4 = P.consts.exp_c4;
    let c5 = P.consts.exp_c5;
    let one = c_one();
    let n = floor(x * log2e + c0);
    let r = (x - n * ln2_hi) - n * ln2_lo;
    let p = one + r * (one + r * (c0 + r * (c1 + r * (c2 + r * (c3 + r * (c4 + r * c5))))));
    let scale = bitcast<f32>(u32(i32(n) + 127) << 23u);
    return p * scale;
}

fn pm_ln(x: f32) -> f32 {
    if (!(x > 0.0)) {
        if (x == 0.0) { return bitcast<f32>(0xff800000u); }
        return bitcast<f32>(0x7fc00000u);
    }
    if (x == bitcast<f32>(0x7f800000u)) { return x; }
    let bits = bitcast<u32>(x);
    var e = i32((bits >> 23u) & 0xffu) - 127;
    var m = bitcast<f32>((bits & 0x007fffffu) | 0x3f800000u);
    if (m > 1.41421354) {
        m = m * c_half();
        e = e + 1;
    }
    let f = m - c_one();
    let s = f / (c_two() + f);
    let z = s * s;
    let l0 = P.consts.ln_c0;
    let l1 = P.consts.ln_c1;
    let l2 = P.consts.ln_c2;
    let l3 = P.consts.ln_c3;
    let l4 = P.consts.ln_c4;
    let poly = c_one() + z * (l0 + z * (l1 + z * (l2 + z * (l3 + z * l4))));
    let lnm = (s + s) * poly;
    let ef = f32(e);
    return ef * P.consts.ln2_hi + (ef * P.consts.ln2_lo + lnm);
}

fn pm_pow(x: f32, y: f32) -> f32 {
    return pm_exp(y * pm_ln(x));
}

// sin(2 pi x), x in cycles. Twin of portable_math::sin_cycles.
fn pm_sin_cycles(x: f32) -> f32 {
    var f = x - floor(x + c_half());
    if (f > 0.25) {
        f = c_half() - f;
    } else if (f < -0.25) {
        f = -c_half() - f;
    }
    let th = f * P.consts.two_pi;
    let z = th * th;
    let p = P.consts.sin_c0 + z * (P.consts.sin_c1 + z * (P.consts.sin_c2 + z * (P.consts.sin_c3 + z * P.consts.sin_c4)));
    return th + th * (z * p);
}

// M g = b for a symmetric M = (xx, xy, xz, yy, yz, zz) by cofactors (the 2x2
// block in 2D); 0 where |det M| <= 1e-3 (M is about the identity for a full
// kernel support: too few neighbours). The renormalised gradients (continuity's
// density, the solidification record's temperature). Twin of solve_symmetric in
// src/portable_math.rs.
fn solve_symmetric(xx: f32, xy: f32, xz: f32, yy: f32, yz: f32, zz: f32, b: vec3<f32>) -> vec3<f32> {
    var g = vec3<f32>(0.0);
    if (P.sizes.dim == 2u) {
        let det = xx * yy - xy * xy;
        if (abs(det) > 1.0e-3) {
            g.x = (yy * b.x - xy * b.y) / det;
            g.y = (xx * b.y - xy * b.x) / det;
        }
        return g;
    }
    let c00 = yy * zz - yz * yz;
    let c01 = xz * yz - xy * zz;
    let c02 = xy * yz - xz * yy;
    let c11 = xx * zz - xz * xz;
    let c12 = xy * xz - xx * yz;
    let c22 = xx * yy - xy * xy;
    let det = xx * c00 + xy * c01 + xz * c02;
    if (abs(det) > 1.0e-3) {
        g.x = (c00 * b.x + c01 * b.y + c02 * b.z) / det;
        g.y = (c01 * b.x + c11 * b.y + c12 * b.z) / det;
        g.z = (c02 * b.x + c12 * b.y + c22 * b.z) / det;
    }
    return g;
}

// Fresnel absorptivity 1 - (R_s + R_p)/2, unpolarised, index n + ik, incidence cosine.
fn fresnel(n: f32, k: f32, cos_in: f32) -> f32 {
    let c = clamp(cos_in, 1e-6, 1.0);
    let s2 = c_one() - c * c;
    let a_ = (n * n - s2) - k * k; // this order: lavapipe reassociates n*n - k*k - s2
    let b_ = sqrt(a_ * a_ + c_four() * (n * n) * (k * k));
    let a = sqrt(c_half() * (b_ + a_));
    let b2 = c_half() * (b_ - a_);
    let rs = ((a - c) * (a - c) + b2) / ((a + c) * (a + c) + b2);
    let st = s2 / c;
    let rp = rs * (((a - st) * (a - st) + b2) / ((a + st) * (a + st) + b2));
    return c_one() - c_half() * (rs + rp);
}
