// uses: params consts
// Smoothing kernels. Twin of src/kernel.rs.

fn p4(t: f32) -> f32 { return t * t * t * t; }
fn p5(t: f32) -> f32 { return t * t * t * t * t; }

fn kernel_w(r: f32) -> f32 {
    let sigma = P.kernel.sigma;
    let q = r * P.kernel.inv_h;
    switch P.kernel.kind {
        case 0u: {
            let t1 = max(c_one() - q, 0.0);
            let t2 = max(c_two() - q, 0.0);
            let t3 = max(c_three() - q, 0.0);
            return sigma * (p5(t3) - c_six() * p5(t2) + c_fifteen() * p5(t1));
        }
        case 1u: {
            let t = max(c_one() - c_half() * q, 0.0);
            return sigma * p4(t) * (c_two() * q + c_one());
        }
        default: {
            if (q < 1.0) {
                return sigma * (c_one() - c_one_and_half() * q * q + c_three_quarters() * q * q * q);
            } else if (q < 2.0) {
                let t = c_two() - q;
                return sigma * c_quarter() * t * t * t;
            }
            return 0.0;
        }
    }
}

// Negated literals are written as the exact negation of a product, so the operation
// order matches the Rust twin's `-5.0 * x`.
fn kernel_dw(r: f32) -> f32 {
    let sigma_h = P.kernel.sigma * P.kernel.inv_h;
    let q = r * P.kernel.inv_h;
    switch P.kernel.kind {
        case 0u: {
            let t1 = max(c_one() - q, 0.0);
            let t2 = max(c_two() - q, 0.0);
            let t3 = max(c_three() - q, 0.0);
            return sigma_h * (-(c_five() * p4(t3)) + c_thirty() * p4(t2) - c_seventy_five() * p4(t1));
        }
        case 1u: {
            let t = max(c_one() - c_half() * q, 0.0);
            return sigma_h * (-(c_five() * q) * t * t * t);
        }
        default: {
            if (q < 1.0) {
                return sigma_h * (-(c_three() * q) + c_nine_quarters() * q * q);
            } else if (q < 2.0) {
                let t = c_two() - q;
                return sigma_h * (-(c_three_quarters() * t) * t);
            }
            return 0.0;
        }
    }
}
