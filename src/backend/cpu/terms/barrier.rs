//! F22 (34) barrier between a fluid particle i and a wall particle j closer than
//! r_b: F = (k_b g + d_b g ġ) e_ij, g = r_b − r, ġ = −e_ij·(u_i − U_wall), with the
//! wall's real velocity U_wall. It stops a particle that the wall pressure does not
//! (a splash with p = 0 under the pressure floor feels no Adami wall pressure).
//! Returns s with F = s d (d = r_i − r_j, e_ij = d/r). Twin of
//! shaders/terms/barrier.wgsl.

use crate::lanes::Lane;
use crate::params::Params;

/// On one pair or on eight (`Lane`), with the same operations.
#[inline(always)]
pub fn barrier<R: Lane>(pr: &Params, v_i: [R; 3], w: [R; 3], d: [R; 3], r: R) -> R {
    let f = &pr.flow;
    let g = R::splat(f.barrier_radius) - r;
    let un = d[0] * (v_i[0] - w[0]) + d[1] * (v_i[1] - w[1]) + d[2] * (v_i[2] - w[2]);
    let g_dot = -(un / r);
    let stiff = R::splat(f.barrier_stiffness) * g;
    let damp = (R::splat(f.barrier_damping) * g) * g_dot;
    (stiff + damp) / r
}

#[cfg(test)]
mod tests {
    use crate::params::Params;
    use bytemuck::Zeroable;

    fn params(radius: f32, stiffness: f32, damping: f32) -> Params {
        let mut p = Params::zeroed();
        p.flow.barrier_radius = radius;
        p.flow.barrier_stiffness = stiffness;
        p.flow.barrier_damping = damping;
        p
    }

    /// F22 (34) on one pair: r_b = 1 cm, particle 4 mm from a wall particle (g = 6
    /// mm) straight above it. At rest the spring alone, k_b g = 12 N, along e_ij;
    /// approaching at 2 m/s (ġ = +2) the damper adds d_b g ġ = 6 N; receding at
    /// 2 m/s it takes 6 N off. A moving wall counts by its relative velocity.
    #[test]
    fn spring_and_damper_along_the_pair_axis() {
        let p = params(0.01, 2000.0, 500.0);
        let d = [0.0, 0.0, 0.004];
        let force =
            |v: f32, w: f32| super::barrier(&p, [0.0, 0.0, v], [0.0, 0.0, w], d, 0.004) * d[2];
        assert!((force(0.0, 0.0) - 12.0).abs() < 1e-4, "{}", force(0.0, 0.0));
        assert!(
            (force(-2.0, 0.0) - 18.0).abs() < 1e-4,
            "{}",
            force(-2.0, 0.0)
        );
        assert!((force(2.0, 0.0) - 6.0).abs() < 1e-4, "{}", force(2.0, 0.0));
        assert!((force(-1.0, 1.0) - force(-2.0, 0.0)).abs() < 1e-4);
        // Tangential motion leaves it a spring.
        let slide = super::barrier(&p, [3.0, 0.0, 0.0], [0.0; 3], d, 0.004) * d[2];
        assert!((slide - 12.0).abs() < 1e-4, "{slide}");
    }
}
