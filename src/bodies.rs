//! Rigid bodies on the host (F22 §2.2, §3.4): the body table built from the
//! particles setup placed, in f64 and rounded once, and the views outputs and
//! checks read. The step's body passes are backend::cpu::bodies and
//! shaders/bodies.wgsl.
//!
//! Mass properties F22 (35)–(36) with the per-particle inertia of a sphere (3D)
//! or disc (2D) of the particle's volume (the printed (36), 0.4 m √(0.75/π) Δx,
//! is dimensionally a mass times a length). The body frame is the principal
//! frame, so the free rotation splits into three exact rotations
//! (backend::cpu::bodies).

use crate::model::Model;
use crate::state::{Body, State, NO_BODY};
use glam::{DMat3, DQuat, DVec3, DVec4};

/// Mass, centre of mass and inertia tensor about it (f64) of a set of particles.
pub struct MassProperties {
    pub mass: f64,
    pub center: DVec3,
    pub inertia: DMat3,
}

/// F22 (35)–(36) over particles at `x` (grid-relative) with masses `m`.
/// `particle_inertia`: I_r per unit mass about any axis through the particle (3D
/// sphere of volume Δx³: 0.4 (∛(3/4π) Δx)²); in 2D only I_zz matters (disc of
/// area Δx²: ½ Δx²/π).
pub fn mass_properties(x: &[DVec3], m: &[f64], particle_inertia: f64) -> MassProperties {
    let mass: f64 = m.iter().sum();
    let mut center = DVec3::ZERO;
    for (xi, mi) in x.iter().zip(m) {
        center += *mi * *xi / mass;
    }
    let mut inertia = DMat3::ZERO;
    for (xi, mi) in x.iter().zip(m) {
        let r = *xi - center;
        // m (I_r 1 + |r|² 1 − r rᵀ)
        let rrt = DMat3::from_cols(r * r.x, r * r.y, r * r.z);
        inertia += (DMat3::from_diagonal(DVec3::splat(particle_inertia + r.dot(r))) - rrt) * *mi;
    }
    MassProperties {
        mass,
        center,
        inertia,
    }
}

/// Entry (row i, column j) of a matrix.
fn at(a: &DMat3, i: usize, j: usize) -> f64 {
    a.col(j)[i]
}

fn set(a: &mut DMat3, i: usize, j: usize, v: f64) {
    a.col_mut(j)[i] = v;
}

fn diagonal(a: &DMat3) -> DVec3 {
    DVec3::new(a.x_axis.x, a.y_axis.y, a.z_axis.z)
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations:
/// (eigenvalues, Q) with the eigenvectors as Q's columns, Q a rotation (det +1).
/// A pair whose off-diagonal entry is exactly 0 is never rotated, so a planar
/// body's z axis stays a principal axis exactly.
pub fn principal_axes(a: DMat3) -> (DVec3, DMat3) {
    let mut a = a;
    let mut q = DMat3::IDENTITY;
    let scale = diagonal(&a).abs().max_element().max(f64::MIN_POSITIVE);
    for _sweep in 0..50 {
        let off = at(&a, 0, 1).abs() + at(&a, 0, 2).abs() + at(&a, 1, 2).abs();
        if off <= 1e-15 * scale {
            break;
        }
        for (p, r) in [(0, 1), (0, 2), (1, 2)] {
            let apr = at(&a, p, r);
            if apr == 0.0 {
                continue;
            }
            // The rotation in the (p, r) plane that zeroes a[p][r].
            let theta = 0.5 * (2.0 * apr).atan2(at(&a, r, r) - at(&a, p, p));
            let (s, c) = theta.sin_cos();
            let mut g = DMat3::IDENTITY;
            set(&mut g, p, p, c);
            set(&mut g, r, r, c);
            set(&mut g, p, r, s);
            set(&mut g, r, p, -s);
            a = g.transpose() * (a * g);
            set(&mut a, p, r, 0.0);
            set(&mut a, r, p, 0.0);
            q *= g;
        }
    }
    if q.determinant() < 0.0 {
        q.z_axis = -q.z_axis;
    }
    (diagonal(&a), q)
}

/// The unit quaternion of a rotation matrix (Shepperd's method: the largest of
/// the four squared components first, for accuracy). Not glam's
/// `DQuat::from_mat3`: this is the operation order of the f32 twin
/// (`backend::cpu::bodies::quaternion_of`, and `lib/rigid.wgsl`).
pub fn quaternion_of(r: &DMat3) -> DQuat {
    let e = |i: usize, j: usize| at(r, i, j);
    let t = e(0, 0) + e(1, 1) + e(2, 2);
    let q = if t > e(0, 0).max(e(1, 1)).max(e(2, 2)) {
        let w = 0.5 * (1.0 + t).sqrt();
        let f = 0.25 / w;
        DVec4::new(
            (e(2, 1) - e(1, 2)) * f,
            (e(0, 2) - e(2, 0)) * f,
            (e(1, 0) - e(0, 1)) * f,
            w,
        )
    } else if e(0, 0) >= e(1, 1) && e(0, 0) >= e(2, 2) {
        let x = 0.5 * (1.0 + e(0, 0) - e(1, 1) - e(2, 2)).sqrt();
        let f = 0.25 / x;
        DVec4::new(
            x,
            (e(0, 1) + e(1, 0)) * f,
            (e(0, 2) + e(2, 0)) * f,
            (e(2, 1) - e(1, 2)) * f,
        )
    } else if e(1, 1) >= e(2, 2) {
        let y = 0.5 * (1.0 - e(0, 0) + e(1, 1) - e(2, 2)).sqrt();
        let f = 0.25 / y;
        DVec4::new(
            (e(0, 1) + e(1, 0)) * f,
            y,
            (e(1, 2) + e(2, 1)) * f,
            (e(0, 2) - e(2, 0)) * f,
        )
    } else {
        let z = 0.5 * (1.0 - e(0, 0) - e(1, 1) + e(2, 2)).sqrt();
        let f = 0.25 / z;
        DVec4::new(
            (e(0, 2) + e(2, 0)) * f,
            (e(1, 2) + e(2, 1)) * f,
            z,
            (e(1, 0) - e(0, 1)) * f,
        )
    };
    DQuat::from_vec4(q / q.length())
}

/// v rotated by the unit quaternion q (f64): v + w t + u × t with t = 2 u × v,
/// the f32 twin's formula (glam's `q * v` orders the operations otherwise).
pub fn rotate(q: DQuat, v: DVec3) -> DVec3 {
    let u = q.xyz();
    let t = 2.0 * u.cross(v);
    v + q.w * t + u.cross(t)
}

/// I_r per unit mass of one particle (see `mass_properties`).
pub fn particle_inertia(dim: u32, dx: f64) -> f64 {
    if dim == 3 {
        let r = (0.75 / std::f64::consts::PI).cbrt() * dx;
        0.4 * r * r
    } else {
        0.5 * dx * dx / std::f64::consts::PI
    }
}

/// A vector and a fourth component rounded to f32, as the body table holds them.
fn f32x4(v: DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

/// Builds the body table: `body_of[i]` is particle i's body (`NO_BODY`: none),
/// particles in id order as setup placed them. Sets `State::body`,
/// `body_offset`, `bodies`, `members` and each member's velocity.
pub fn assemble(m: &Model, st: &mut State, body_of: &[u32]) {
    let n_bodies = m.bodies.len();
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n_bodies];
    for (i, &b) in body_of.iter().enumerate() {
        if b != NO_BODY {
            members[b as usize].push(st.id[i]);
        }
    }
    st.body = body_of.to_vec();
    st.body_offset = vec![[0.0; 4]; st.len()];
    st.bodies.clear();
    st.members.clear();
    let ip = particle_inertia(m.dim, m.dx);
    for (k, spec) in m.bodies.iter().enumerate() {
        let idx: Vec<usize> = members[k].iter().map(|&id| id as usize).collect();
        let x: Vec<DVec3> = idx
            .iter()
            .map(|&i| {
                let p = st.pos[i];
                DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
            })
            .collect();
        let mass: Vec<f64> = idx.iter().map(|&i| st.mass[i] as f64).collect();
        let mp = mass_properties(&x, &mass, ip);
        let (moments, axes) = principal_axes(mp.inertia);
        let q = quaternion_of(&axes);
        let (velocity, omega) = (
            DVec3::from(spec.velocity),
            DVec3::from(spec.angular_velocity),
        );
        // Angular momentum Q (I_p (Qᵀ ω)).
        let l = rotate(q, moments * rotate(q.conjugate(), omega));
        for (&i, xi) in idx.iter().zip(&x) {
            let r = *xi - mp.center;
            st.body_offset[i] = f32x4(rotate(q.conjugate(), r), 0.0);
            let u = velocity + omega.cross(r);
            for a in 0..3 {
                st.vel[i][a] = u[a] as f32;
            }
        }
        st.bodies.push(Body {
            x: f32x4(mp.center, mp.mass),
            q: q.to_array().map(|c| c as f32),
            v: f32x4(velocity, 0.0),
            l: f32x4(l, 0.0),
            inertia: f32x4(moments, ip),
            force: [0.0; 4],
            torque: [0.0; 4],
            first: st.members.len() as u32,
            count: members[k].len() as u32,
            bonded: 0,
            initial_count: members[k].len() as u32,
        });
        st.members.extend_from_slice(&members[k]);
    }
}

/// Rigid powder grains ejected from the bed: (ejected, grains), a grain counting
/// when its centre is more than its own diameter above the bed's initial top.
/// None without a rigid bed.
pub fn ejected_grains(m: &Model, st: &State) -> Option<(usize, usize)> {
    let list = ejected_grain_list(m, st)?;
    Some((list.iter().filter(|&&e| e).count(), list.len()))
}

/// Per grain of the rigid bed: is it ejected now (`ejected_grains`' rule)?
pub fn ejected_grain_list(m: &Model, st: &State) -> Option<Vec<bool>> {
    Some(grain_rise(m, st)?.iter().map(|&r| r > 1.0).collect())
}

/// Per grain of the rigid bed: how far its centre lies above the bed's initial
/// top, in its diameters (NaN for one molten away or bonded into the substrate).
pub fn grain_rise(m: &Model, st: &State) -> Option<Vec<f64>> {
    let bed = m.powder.as_ref().filter(|b| b.spec.rigid)?;
    let up = m.dim as usize - 1;
    let top = bed.spec.lo[up] + bed.thickness;
    let mut rise = vec![f64::NAN; bed.grains.len()];
    for (k, spec) in m.bodies.iter().enumerate() {
        let crate::model::BodySource::Grain(g) = spec.source else {
            continue;
        };
        // A grain that left through an open side counts where it left.
        if st.bodies[k].moves() || st.bodies[k].left() {
            let height = m.to_world(st.bodies[k].x)[up];
            rise[g] = (height - top) / (2.0 * bed.grains[g].radius);
        }
    }
    Some(rise)
}

/// What became of the rigid bodies: bonded into the
/// substrate, left the domain through an open side, fully molten, partly
/// molten, whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BodyTally {
    pub bodies: usize,
    pub bonded: usize,
    pub left: usize,
    pub molten: usize,
    pub partly_molten: usize,
    pub whole: usize,
}

impl BodyTally {
    pub fn of(st: &State) -> BodyTally {
        let mut t = BodyTally {
            bodies: st.bodies.len(),
            ..Default::default()
        };
        for b in &st.bodies {
            if b.bonded_in() {
                t.bonded += 1;
            } else if b.left() {
                t.left += 1;
            } else if b.count == 0 {
                t.molten += 1;
            } else if b.count < b.initial_count {
                t.partly_molten += 1;
            } else {
                t.whole += 1;
            }
        }
        t
    }
    pub fn summary(&self) -> String {
        let left = match self.left {
            0 => String::new(),
            n => format!(", {n} left the domain"),
        };
        format!(
            "{} rigid: {} whole, {} partly molten, {} fully molten, {} bonded into the substrate{left}",
            self.bodies, self.whole, self.partly_molten, self.molten, self.bonded
        )
    }
}

/// A body's motion in world terms, f64, for outputs and checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMotion {
    /// Centre of mass, world coordinates (m).
    pub position: DVec3,
    /// Orientation, body (principal) frame to world.
    pub orientation: DQuat,
    pub velocity: DVec3,
    /// World frame (rad/s).
    pub angular_velocity: DVec3,
    /// World frame (kg m²/s).
    pub angular_momentum: DVec3,
    /// The same in the body (principal) frame.
    pub body_angular_momentum: DVec3,
    pub mass: f64,
    /// Rotational kinetic energy ½ L·ω (J).
    pub rotational_energy: f64,
}

impl BodyMotion {
    pub fn of(m: &Model, b: &Body) -> BodyMotion {
        let xyz = |v: [f32; 4]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
        let q = DQuat::from_array(b.q.map(|c| c as f64));
        let l = xyz(b.l);
        let lb = rotate(q.conjugate(), l);
        let inertia = xyz(b.inertia);
        let w_body = DVec3::from_array([0, 1, 2].map(|a| {
            if inertia[a] > 0.0 {
                lb[a] / inertia[a]
            } else {
                0.0
            }
        }));
        BodyMotion {
            position: DVec3::from(m.to_world(b.x)),
            orientation: q,
            velocity: xyz(b.v),
            angular_velocity: rotate(q, w_body),
            angular_momentum: l,
            body_angular_momentum: lb,
            mass: b.x[3] as f64,
            rotational_energy: 0.5 * lb.dot(w_body),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box of 3 × 2 × 1 unit masses rotated about z: the principal moments are
    /// those of the axis-aligned box and the axes rotate it back.
    #[test]
    fn principal_axes_of_a_rotated_box() {
        let angle: f64 = 0.3;
        let (s, c) = angle.sin_cos();
        let mut x = Vec::new();
        for i in 0..3 {
            for j in 0..2 {
                let (px, py) = (i as f64 - 1.0, j as f64 - 0.5);
                x.push(DVec3::new(c * px - s * py, s * px + c * py, 0.0));
            }
        }
        let m = vec![1.0; x.len()];
        let mp = mass_properties(&x, &m, 0.0);
        let (moments, q) = principal_axes(mp.inertia);
        // Axis-aligned: I_xx = Σ y² = 1.5, I_yy = Σ x² = 4, I_zz = 5.5.
        let mut sorted = moments.to_array();
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for (got, want) in sorted.iter().zip([1.5, 4.0, 5.5]) {
            assert!((got - want).abs() < 1e-12, "{moments:?}");
        }
        // z stays a principal axis exactly (a planar body).
        assert_eq!(at(&q, 2, 2).abs(), 1.0);
        assert!((q.determinant() - 1.0).abs() < 1e-12);
        // Qᵀ I Q is diagonal.
        let d = q.transpose() * (mp.inertia * q);
        assert!(
            at(&d, 0, 1).abs() < 1e-12 && at(&d, 0, 2).abs() < 1e-12 && at(&d, 1, 2).abs() < 1e-12
        );
    }

    #[test]
    fn quaternion_reproduces_its_rotation_matrix() {
        let a = DMat3::from_cols_array_2d(&[[2.0, 0.3, -0.2], [0.3, 1.0, 0.4], [-0.2, 0.4, 3.0]]);
        let (_, q) = principal_axes(a);
        let quat = quaternion_of(&q);
        for col in 0..3 {
            let r = rotate(quat, DVec3::AXES[col]);
            assert!((r - q.col(col)).abs().max_element() < 1e-12);
        }
    }
}
