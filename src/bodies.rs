//! Rigid bodies on the host (F22 §2.2, §3.4): the body table built from the
//! particles setup placed, in f64 and rounded once, and the views outputs and
//! checks read. The step's body passes are backend::cpu::bodies and
//! shaders/bodies.wgsl.
//!
//! Mass properties F22 (35)–(36) with the per-particle inertia of a sphere (3D)
//! or disc (2D) of the particle's volume (PAPERS-EXTRACT §2.1 flags the printed
//! (36) as dimensionally wrong). The body frame is the principal frame, so the
//! free rotation splits into three exact rotations (backend::cpu::bodies).

use crate::model::Model;
use crate::state::{Body, State, NO_BODY};

/// Mass, centre of mass and inertia tensor about it (f64) of a set of particles.
pub struct MassProperties {
    pub mass: f64,
    pub center: [f64; 3],
    pub inertia: [[f64; 3]; 3],
}

/// F22 (35)–(36) over particles at `x` (grid-relative) with masses `m`.
/// `particle_inertia`: I_r per unit mass about any axis through the particle (3D
/// sphere of volume Δx³: 0.4 (∛(3/4π) Δx)²); in 2D only I_zz matters (disc of
/// area Δx²: ½ Δx²/π).
pub fn mass_properties(x: &[[f64; 3]], m: &[f64], particle_inertia: f64) -> MassProperties {
    let mass: f64 = m.iter().sum();
    let mut c = [0.0; 3];
    for (xi, mi) in x.iter().zip(m) {
        for a in 0..3 {
            c[a] += mi * xi[a] / mass;
        }
    }
    let mut inertia = [[0.0; 3]; 3];
    for (xi, mi) in x.iter().zip(m) {
        let r = [xi[0] - c[0], xi[1] - c[1], xi[2] - c[2]];
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for a in 0..3 {
            for b in 0..3 {
                let delta = if a == b { 1.0 } else { 0.0 };
                inertia[a][b] += mi * (particle_inertia * delta + r2 * delta - r[a] * r[b]);
            }
        }
    }
    MassProperties {
        mass,
        center: c,
        inertia,
    }
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations:
/// (eigenvalues, Q) with the eigenvectors as Q's columns, Q a rotation (det +1).
/// A pair whose off-diagonal entry is exactly 0 is never rotated, so a planar
/// body's z axis stays a principal axis exactly.
pub fn principal_axes(a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut a = a;
    let mut q = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let scale = (0..3)
        .map(|k| a[k][k].abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    for _sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off <= 1e-15 * scale {
            break;
        }
        for (p, r) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][r] == 0.0 {
                continue;
            }
            // The rotation in the (p, r) plane that zeroes a[p][r].
            let theta = 0.5 * (2.0 * a[p][r]).atan2(a[r][r] - a[p][p]);
            let (s, c) = theta.sin_cos();
            let mut g = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            g[p][p] = c;
            g[r][r] = c;
            g[p][r] = s;
            g[r][p] = -s;
            a = mul(&transpose(&g), &mul(&a, &g));
            a[p][r] = 0.0;
            a[r][p] = 0.0;
            q = mul(&q, &g);
        }
    }
    if det(&q) < 0.0 {
        for row in q.iter_mut() {
            row[2] = -row[2];
        }
    }
    ([a[0][0], a[1][1], a[2][2]], q)
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

fn det(a: &[[f64; 3]; 3]) -> f64 {
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

/// The unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method: the
/// largest of the four squared components first, for accuracy).
pub fn quaternion_of(r: &[[f64; 3]; 3]) -> [f64; 4] {
    let t = r[0][0] + r[1][1] + r[2][2];
    let q = if t > r[0][0].max(r[1][1]).max(r[2][2]) {
        let w = 0.5 * (1.0 + t).sqrt();
        let f = 0.25 / w;
        [
            (r[2][1] - r[1][2]) * f,
            (r[0][2] - r[2][0]) * f,
            (r[1][0] - r[0][1]) * f,
            w,
        ]
    } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
        let x = 0.5 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / x;
        [
            x,
            (r[0][1] + r[1][0]) * f,
            (r[0][2] + r[2][0]) * f,
            (r[2][1] - r[1][2]) * f,
        ]
    } else if r[1][1] >= r[2][2] {
        let y = 0.5 * (1.0 - r[0][0] + r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / y;
        [
            (r[0][1] + r[1][0]) * f,
            y,
            (r[1][2] + r[2][1]) * f,
            (r[0][2] - r[2][0]) * f,
        ]
    } else {
        let z = 0.5 * (1.0 - r[0][0] - r[1][1] + r[2][2]).sqrt();
        let f = 0.25 / z;
        [
            (r[0][2] + r[2][0]) * f,
            (r[1][2] + r[2][1]) * f,
            z,
            (r[1][0] - r[0][1]) * f,
        ]
    };
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
}

/// v rotated by the unit quaternion q (f64).
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let u = [q[0], q[1], q[2]];
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [
        v[0] + q[3] * t[0] + ut[0],
        v[1] + q[3] * t[1] + ut[1],
        v[2] + q[3] * t[2] + ut[2],
    ]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
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
        let x: Vec<[f64; 3]> = idx
            .iter()
            .map(|&i| {
                [
                    st.pos[i][0] as f64,
                    st.pos[i][1] as f64,
                    st.pos[i][2] as f64,
                ]
            })
            .collect();
        let mass: Vec<f64> = idx.iter().map(|&i| st.mass[i] as f64).collect();
        let mp = mass_properties(&x, &mass, ip);
        let (moments, axes) = principal_axes(mp.inertia);
        let q = quaternion_of(&axes);
        let conj = [-q[0], -q[1], -q[2], q[3]];
        // Angular momentum Q (I_p (Qᵀ ω)).
        let w_body = rotate(conj, spec.angular_velocity);
        let l = rotate(q, [0, 1, 2].map(|a| moments[a] * w_body[a]));
        for (&i, xi) in idx.iter().zip(&x) {
            let r = [
                xi[0] - mp.center[0],
                xi[1] - mp.center[1],
                xi[2] - mp.center[2],
            ];
            let r0 = rotate(conj, r);
            st.body_offset[i] = [r0[0] as f32, r0[1] as f32, r0[2] as f32, 0.0];
            let u = cross(spec.angular_velocity, r);
            for a in 0..3 {
                st.vel[i][a] = (spec.velocity[a] + u[a]) as f32;
            }
        }
        st.bodies.push(Body {
            x: [
                mp.center[0] as f32,
                mp.center[1] as f32,
                mp.center[2] as f32,
                mp.mass as f32,
            ],
            q: q.map(|c| c as f32),
            v: [
                spec.velocity[0] as f32,
                spec.velocity[1] as f32,
                spec.velocity[2] as f32,
                0.0,
            ],
            l: [l[0] as f32, l[1] as f32, l[2] as f32, 0.0],
            inertia: [
                moments[0] as f32,
                moments[1] as f32,
                moments[2] as f32,
                ip as f32,
            ],
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
/// when its centre is more than its own diameter above the bed's initial top
/// (issue 17 item 6). None without a rigid bed.
pub fn ejected_grains(m: &Model, st: &State) -> Option<(usize, usize)> {
    let bed = m.powder.as_ref().filter(|b| b.spec.rigid)?;
    let up = m.dim as usize - 1;
    let top = bed.spec.lo[up] + bed.thickness;
    let mut ejected = 0;
    for (k, spec) in m.bodies.iter().enumerate() {
        let crate::model::BodySource::Grain(g) = spec.source else {
            continue;
        };
        if !st.bodies[k].moves() {
            continue; // molten away or bonded into the substrate
        }
        let height = m.to_world(st.bodies[k].x)[up];
        if height > top + 2.0 * bed.grains[g].radius {
            ejected += 1;
        }
    }
    Some((ejected, bed.grains.len()))
}

/// What became of the rigid bodies (issue 17 item 6): bonded into the
/// substrate, fully molten, partly molten, whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BodyTally {
    pub bodies: usize,
    pub bonded: usize,
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
            if b.bonded != 0 {
                t.bonded += 1;
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
        format!(
            "{} rigid: {} whole, {} partly molten, {} fully molten, {} bonded into the substrate",
            self.bodies, self.whole, self.partly_molten, self.molten, self.bonded
        )
    }
}

/// A body's motion in world terms, f64, for outputs and checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMotion {
    /// Centre of mass, world coordinates (m).
    pub position: [f64; 3],
    /// Orientation quaternion (x, y, z, w), body (principal) frame to world.
    pub orientation: [f64; 4],
    pub velocity: [f64; 3],
    /// World frame (rad/s).
    pub angular_velocity: [f64; 3],
    /// World frame (kg m²/s).
    pub angular_momentum: [f64; 3],
    /// The same in the body (principal) frame.
    pub body_angular_momentum: [f64; 3],
    pub mass: f64,
    /// Rotational kinetic energy ½ L·ω (J).
    pub rotational_energy: f64,
}

impl BodyMotion {
    pub fn of(m: &Model, b: &Body) -> BodyMotion {
        let q = b.q.map(|c| c as f64);
        let l = [b.l[0] as f64, b.l[1] as f64, b.l[2] as f64];
        let lb = rotate([-q[0], -q[1], -q[2], q[3]], l);
        let inertia = [
            b.inertia[0] as f64,
            b.inertia[1] as f64,
            b.inertia[2] as f64,
        ];
        let w_body = [0, 1, 2].map(|a| {
            if inertia[a] > 0.0 {
                lb[a] / inertia[a]
            } else {
                0.0
            }
        });
        let energy = 0.5 * (0..3).map(|a| lb[a] * w_body[a]).sum::<f64>();
        BodyMotion {
            position: m.to_world(b.x),
            orientation: q,
            velocity: [b.v[0] as f64, b.v[1] as f64, b.v[2] as f64],
            angular_velocity: rotate(q, w_body),
            angular_momentum: l,
            body_angular_momentum: lb,
            mass: b.x[3] as f64,
            rotational_energy: energy,
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
                x.push([c * px - s * py, s * px + c * py, 0.0]);
            }
        }
        let m = vec![1.0; x.len()];
        let mp = mass_properties(&x, &m, 0.0);
        let (moments, q) = principal_axes(mp.inertia);
        // Axis-aligned: I_xx = Σ y² = 1.5, I_yy = Σ x² = 4, I_zz = 5.5.
        let mut sorted = moments;
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for (got, want) in sorted.iter().zip([1.5, 4.0, 5.5]) {
            assert!((got - want).abs() < 1e-12, "{moments:?}");
        }
        // z stays a principal axis exactly (a planar body).
        assert_eq!(q[2][2].abs(), 1.0);
        assert!((det(&q) - 1.0).abs() < 1e-12);
        // Qᵀ I Q is diagonal.
        let d = mul(&transpose(&q), &mul(&mp.inertia, &q));
        assert!(d[0][1].abs() < 1e-12 && d[0][2].abs() < 1e-12 && d[1][2].abs() < 1e-12);
    }

    #[test]
    fn quaternion_reproduces_its_rotation_matrix() {
        let (_, q) = principal_axes([[2.0, 0.3, -0.2], [0.3, 1.0, 0.4], [-0.2, 0.4, 3.0]]);
        let quat = quaternion_of(&q);
        for col in 0..3 {
            let e = [0, 1, 2].map(|a| if a == col { 1.0 } else { 0.0 });
            let r = rotate(quat, e);
            for a in 0..3 {
                assert!((r[a] - q[a][col]).abs() < 1e-12);
            }
        }
    }
}
