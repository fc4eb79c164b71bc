//! Initial particles: a lattice fill of the scene's shapes plus wall layers.
//!
//! Lattice sites sit at cell centres lo + (i + ½)Δx inside the domain and at
//! lo − (k + ½)Δx, hi + (k + ½)Δx in the wall layers. Later shapes override earlier
//! ones at the same site, so "gas everywhere, then liquid in a box" works.

use crate::error::InputError;
use crate::model::{BodySource, Model};
use crate::random::SplitMix;
use crate::scene::{SceneFile, ShapeDef};
use crate::state::{State, BYTES_PER_CELL, BYTES_PER_PARTICLE_SORT, NO_BODY};
use glam::DVec3;

/// Lattice coordinates along one axis: positions and whether each is in a wall layer.
fn axis_sites(m: &Model, a: usize) -> Vec<(f64, bool)> {
    if a >= m.dim as usize {
        return vec![(0.0, false)];
    }
    let (lo, hi, dx) = (m.domain_lo[a], m.domain_hi[a], m.dx);
    let n = m.sites[a] as i64;
    let mut out: Vec<(f64, bool)> = Vec::with_capacity(n as usize + 2 * m.wall_layers as usize);
    let walls = if m.periodic[a] {
        0
    } else {
        m.wall_layers as i64
    };
    for k in (0..walls).rev() {
        out.push((lo - (k as f64 + 0.5) * dx, true));
    }
    for i in 0..n {
        out.push((lo + (i as f64 + 0.5) * dx, false));
    }
    for k in 0..walls {
        out.push((hi + (k as f64 + 0.5) * dx, true));
    }
    out
}

/// J22 (24), Akinci et al. (2012): a wall particle's volume is
/// V_b = 1/Σ_b' W_bb' over the wall particles within the support, itself
/// included, and its mass ρ0_b V_b, so every pass that takes a wall's volume as
/// m/ρ0 (DFSPH's density, pressure and viscosity, conduction, the interface
/// normals) reads Akinci's. A single layer so gets about the weight the
/// missing layers had; inside a thick wall shape V_b is the lattice volume.
/// Walls sit on lattice sites and never move on DFSPH, so the sum runs once, in
/// f64, over integer site offsets (periodic axes wrap).
fn akinci_wall_masses(m: &Model, st: &mut State) {
    use std::collections::HashSet;
    let dim = m.dim as usize;
    let site = |p: [f32; 4]| -> [i64; 3] {
        let x = m.to_world(p);
        std::array::from_fn(|a| {
            if a < dim {
                ((x[a] - m.domain_lo[a]) / m.dx - 0.5).round() as i64
            } else {
                0
            }
        })
    };
    let is_wall = |ph: u32| m.phases[ph as usize].kind == crate::scene::PhaseKind::Wall;
    let walls: Vec<usize> = (0..st.len()).filter(|&i| is_wall(st.phase[i])).collect();
    let occupied: HashSet<[i64; 3]> = walls.iter().map(|&i| site(st.pos[i])).collect();
    let wrap = |k: i64, a: usize| -> i64 {
        if m.periodic[a] {
            k.rem_euclid(m.sites[a] as i64)
        } else {
            k
        }
    };
    let reach = (m.support / m.dx).ceil() as i64;
    let z = if dim == 3 { reach } else { 0 };
    for i in walls {
        let c = site(st.pos[i]);
        let mut sum = 0.0;
        for da in -reach..=reach {
            for db in -reach..=reach {
                for dc in -z..=z {
                    let r = m.dx * ((da * da + db * db + dc * dc) as f64).sqrt();
                    let other = [wrap(c[0] + da, 0), wrap(c[1] + db, 1), wrap(c[2] + dc, 2)];
                    if r < m.support && occupied.contains(&other) {
                        sum += crate::params::kernel_w_f64(m.kernel, m.dim, m.h, r);
                    }
                }
            }
        }
        st.mass[i] = (m.phases[st.phase[i] as usize].rho0 / sum) as f32;
    }
}

/// Upper bound of the particle count (every lattice site occupied), for the memory
/// check before anything is allocated.
pub fn site_count(m: &Model) -> f64 {
    (0..3).map(|a| axis_sites_len(m, a)).product()
}

fn axis_sites_len(m: &Model, a: usize) -> f64 {
    if a >= m.dim as usize {
        return 1.0;
    }
    let n = m.sites[a] as f64;
    let walls = if m.periodic[a] {
        0.0
    } else {
        2.0 * m.wall_layers as f64
    };
    n + walls
}

/// Estimated memory of the scene in bytes.
pub fn memory_estimate(m: &Model, particles: f64) -> f64 {
    let held = crate::fields::Held::of_model(m);
    let per_particle = crate::fields::bytes_per_particle(held) as u64 + BYTES_PER_PARTICLE_SORT;
    particles * per_particle as f64 + m.n_cells() as f64 * BYTES_PER_CELL as f64
}

/// A shape's point or direction (`dim` components) as a DVec3, 0 beyond `dim`
/// like the lattice sites.
fn vec3(v: &[f64]) -> DVec3 {
    let mut a = [0.0; 3];
    a[..v.len()].copy_from_slice(v);
    DVec3::from(a)
}

fn inside(shape: &ShapeDef, x: DVec3, dim: usize) -> bool {
    if let Some(b) = &shape.box_ {
        return (0..dim).all(|a| x[a] >= b.min[a] && x[a] <= b.max[a]);
    }
    if let Some(s) = &shape.sphere {
        return x.distance_squared(vec3(&s.center)) <= s.radius * s.radius;
    }
    if let Some(c) = &shape.cylinder {
        // t: where x projects onto the axis (0 at the base, 1 at its end).
        let (base, axis) = (vec3(&c.base), vec3(&c.axis));
        let t = (x - base).dot(axis) / axis.length_squared();
        if !(0.0..=1.0).contains(&t) {
            return false;
        }
        return (x - base - t * axis).length_squared() <= c.radius * c.radius;
    }
    false
}

fn validate_shapes(m: &Model, scene: &SceneFile) -> Result<Vec<usize>, InputError> {
    let dim = m.dim as usize;
    let mut phase_of = Vec::new();
    for (i, s) in scene.shapes.iter().enumerate() {
        let key = |k: &str| format!("shapes[{i}].{k}");
        let Some(pi) = m.phase_index(&s.phase) else {
            return Err(InputError::new(
                &m.file,
                &key("phase"),
                format!("no phase named `{}`", s.phase),
            ));
        };
        let count =
            s.box_.is_some() as u32 + s.sphere.is_some() as u32 + s.cylinder.is_some() as u32;
        if count != 1 {
            return Err(InputError::new(
                &m.file,
                &format!("shapes[{i}]"),
                "give exactly one of box, sphere, cylinder",
            ));
        }
        let vec_ok = |v: &[f64]| v.len() == dim && v.iter().all(|x| x.is_finite());
        let (lo, hi, which) = if let Some(b) = &s.box_ {
            if !vec_ok(&b.min) || !vec_ok(&b.max) {
                return Err(InputError::new(
                    &m.file,
                    &key("box"),
                    format!("min and max need {dim} finite components"),
                ));
            }
            if (0..dim).any(|a| b.max[a] <= b.min[a]) {
                return Err(InputError::new(
                    &m.file,
                    &key("box.max"),
                    "must exceed box.min on every axis",
                ));
            }
            (b.min.clone(), b.max.clone(), "box")
        } else if let Some(sp) = &s.sphere {
            if !vec_ok(&sp.center) || !(sp.radius > 0.0) {
                return Err(InputError::new(
                    &m.file,
                    &key("sphere"),
                    format!("needs a {dim}-component center and a positive radius"),
                ));
            }
            let lo = (0..dim).map(|a| sp.center[a] - sp.radius).collect();
            let hi = (0..dim).map(|a| sp.center[a] + sp.radius).collect();
            (lo, hi, "sphere")
        } else {
            let c = s.cylinder.as_ref().unwrap();
            let len2: f64 = c.axis.iter().map(|v| v * v).sum();
            if !vec_ok(&c.base) || !vec_ok(&c.axis) || !(c.radius > 0.0) || !(len2 > 0.0) {
                return Err(InputError::new(
                    &m.file,
                    &key("cylinder"),
                    format!("needs {dim}-component base and non-zero axis, positive radius"),
                ));
            }
            // The end discs reach r √(1 − u_a²) beyond the axis along axis a (u the
            // unit axis): nothing along the axis itself, r across it.
            let reach = |a: usize| c.radius * (1.0 - c.axis[a] * c.axis[a] / len2).max(0.0).sqrt();
            let lo = (0..dim)
                .map(|a| c.base[a].min(c.base[a] + c.axis[a]) - reach(a))
                .collect();
            let hi = (0..dim)
                .map(|a| c.base[a].max(c.base[a] + c.axis[a]) + reach(a))
                .collect();
            (lo, hi, "cylinder")
        };
        if let Some(v) = &s.velocity {
            if !vec_ok(v) {
                return Err(InputError::new(
                    &m.file,
                    &key("velocity"),
                    format!("needs {dim} finite components (m/s)"),
                ));
            }
            if !m.phases[pi].is_fluid() && !s.body {
                return Err(InputError::new(
                    &m.file,
                    &key("velocity"),
                    format!("phase `{}` does not flow: only liquid and gas shapes start moving (a moving wall takes its phase's velocity)", s.phase),
                ));
            }
        }
        // A fluid shape must lie in the domain: particles outside would start in the walls.
        if m.phases[pi].kind != crate::scene::PhaseKind::Wall {
            let tol = 1e-9 * m.dx;
            for a in 0..dim {
                if lo[a] < m.domain_lo[a] - tol || hi[a] > m.domain_hi[a] + tol {
                    return Err(InputError::new(
                        &m.file,
                        &key(which),
                        format!("fluid shape extends outside the domain along axis {a} ([{}, {}] vs domain [{}, {}])", lo[a], hi[a], m.domain_lo[a], m.domain_hi[a]),
                    ));
                }
            }
        }
        phase_of.push(pi);
    }
    Ok(phase_of)
}

fn wall_phase_at(m: &Model, scene: &SceneFile, x: [f64; 3]) -> Option<usize> {
    use crate::scene::SIDE_NAMES as SIDES;
    for a in 0..m.dim as usize {
        let side = if x[a] < m.domain_lo[a] {
            0
        } else if x[a] > m.domain_hi[a] {
            1
        } else {
            continue;
        };
        if scene.domain.open_sides.iter().any(|s| s == SIDES[a][side]) {
            return None;
        }
        let name = scene
            .domain
            .wall_sides
            .get(SIDES[a][side])
            .or(scene.domain.wall_phase.as_ref())?;
        return m.phase_index(name);
    }
    None
}

/// Generate the initial particles. Fails if the scene would not fit in memory or has
/// no fluid particle.
pub fn generate(m: &Model, scene: &SceneFile) -> Result<State, InputError> {
    let sites = site_count(m);
    let bytes = memory_estimate(m, sites);
    if let Some(avail) = crate::host::available_memory() {
        if bytes > 0.8 * avail {
            return Err(InputError::new(
                &m.file,
                "simulation.dx",
                format!("scene needs about {:.1} GiB for up to {sites:.3e} particles but {:.1} GiB is free; use a larger dx", bytes / 1073741824.0, avail / 1073741824.0),
            ));
        }
    }
    if sites > u32::MAX as f64 / 2.0 {
        return Err(InputError::new(
            &m.file,
            "simulation.dx",
            format!("{sites:e} lattice sites exceed the 2^31 particle limit"),
        ));
    }
    let shape_phase = validate_shapes(m, scene)?;
    let axes: Vec<Vec<(f64, bool)>> = (0..3).map(|a| axis_sites(m, a)).collect();
    let mut rng = SplitMix(m.seed);
    let mut st = State::default();
    // Lattice index of every particle, for the hydrostatic start's columns.
    let mut sites: Vec<[u32; 3]> = Vec::new();
    // Each shape's body (NO_BODY: not a body), and each particle's.
    let mut body_index = vec![NO_BODY; scene.shapes.len()];
    let mut grain_body = NO_BODY;
    for (k, b) in m.bodies.iter().enumerate() {
        match b.source {
            BodySource::Shape(i) => body_index[i] = k as u32,
            BodySource::Grain(0) => grain_body = k as u32,
            BodySource::Grain(_) => {}
        }
    }
    let mut body_of: Vec<u32> = Vec::new();
    for (iz, &(z, wz)) in axes[2].iter().enumerate() {
        for (iy, &(y, wy)) in axes[1].iter().enumerate() {
            for (ix, &(x, wx)) in axes[0].iter().enumerate() {
                let p = [x, y, z];
                // The grain at this site: the bed's phase and, rigid, its body.
                let grain = || {
                    let bed = m.powder.as_ref()?;
                    let g = bed.grain_at(p, m.dim as usize)?;
                    let body = if grain_body == NO_BODY {
                        NO_BODY
                    } else {
                        grain_body + g as u32
                    };
                    Some((bed.spec.phase, body))
                };
                let mut site_body = NO_BODY;
                let (phase, shape) = if wx || wy || wz {
                    (wall_phase_at(m, scene, p), None)
                } else if let Some((grain, body)) = grain() {
                    // The bed overrides the shapes (gas everywhere, then powder).
                    site_body = body;
                    (Some(grain), None)
                } else {
                    scene
                        .shapes
                        .iter()
                        .enumerate()
                        .zip(&shape_phase)
                        .rev()
                        .find(|((_, s), _)| inside(s, DVec3::from(p), m.dim as usize))
                        .map_or((None, None), |(s, &pi)| (Some(pi), Some(s)))
                };
                let Some(pi) = phase else { continue };
                let mut q = p;
                if m.jitter > 0.0 && m.phases[pi].is_fluid() {
                    for c in q.iter_mut().take(m.dim as usize) {
                        *c += (rng.next_f64() - 0.5) * 2.0 * m.jitter * m.dx;
                    }
                }
                push_particle(m, &mut st, q, pi);
                body_of.push(shape.map_or(site_body, |(k, _)| body_index[k]));
                let fluid_shape = shape.map(|(_, s)| s).filter(|s| !s.body);
                if let Some(v) = fluid_shape.and_then(|s| s.velocity.as_ref()) {
                    let last = st.vel.len() - 1;
                    for (a, c) in v.iter().enumerate() {
                        st.vel[last][a] = *c as f32;
                    }
                }
                sites.push([ix as u32, iy as u32, iz as u32]);
            }
        }
    }
    if m.has_bodies() {
        let mut covered = vec![false; m.bodies.len()];
        for &b in body_of.iter().filter(|&&b| b != NO_BODY) {
            covered[b as usize] = true;
        }
        if let Some(k) = covered.iter().position(|c| !c) {
            let (key, what) = match m.bodies[k].source {
                BodySource::Shape(i) => (
                    format!("shapes[{i}]"),
                    "this body covers no lattice site (too small, or covered by later shapes)",
                ),
                BodySource::Grain(_) => (
                    "powder.diameter.min".to_string(),
                    "a grain covers no lattice site at this dx: raise min or refine dx",
                ),
            };
            return Err(InputError::new(&m.file, &key, what));
        }
        crate::bodies::assemble(m, &mut st, &body_of);
    }
    if !st
        .phase
        .iter()
        .any(|&p| m.phases[p as usize].is_fluid() || m.phases[p as usize].conducts())
        && !m.has_bodies()
    {
        return Err(InputError::new(&m.file, "shapes", "the scene contains no fluid or solid particle (no shape of a liquid, gas or solid phase covers a lattice site)"));
    }
    if let Some(axis) = m.hydrostatic_axis {
        hydrostatic_start(m, &mut st, &sites, axis);
    }
    let held = crate::fields::Held::of_model(m);
    if held.interface {
        st.surface = vec![[0.0; 4]; 2 * st.len()];
    }
    if held.implicit_heat {
        st.heat_start = vec![[0.0; 4]; st.len()];
    }
    if held.dfsph {
        st.dfsph = vec![[0.0; 4]; st.len()];
        st.dfsph_warm = vec![[0.0; 2]; st.len()];
        st.dfsph_cg = vec![[0.0; 4]; 4 * st.len()];
        // DFSPH corrects any density above ρ0, so a lattice whose summation
        // density is ρ0 (1 + ε) would be pushed apart at the first step (0.26%
        // for the quintic at h = Δx in 2D: the top of a 0.4 m column left at
        // 0.8 m/s). Every particle's mass is ρ0 Δx^d over the lattice's kernel
        // sum (a wall particle's volume is m/ρ0: backend/cpu/dfsph.rs).
        let ratio = crate::params::lattice_density_ratio(m.kernel, m.dim, m.h, m.dx, m.support);
        for mass in st.mass.iter_mut() {
            *mass = (*mass as f64 / ratio) as f32;
        }
        if m.akinci_walls {
            akinci_wall_masses(m, &mut st);
        }
    }
    if held.continuity {
        st.continuity = vec![[0.0, 1.0]; st.len()];
        st.density_gradient = vec![[0.0; 4]; st.len()];
    }
    if held.solidification {
        st.solidification = unrecorded_solidification(st.len());
    }
    if held.solvers {
        st.solvers = vec![crate::state::Solver::default(); crate::state::SOLVER_SLOTS.len()];
    }
    if m.laser.as_ref().is_some_and(|l| l.rays.is_some()) {
        st.laser_rays = vec![0; 4];
    }
    Ok(st)
}

/// The solidification record before any crossing: no time (−1), no gradient,
/// no count; nothing pending.
pub fn unrecorded_solidification(n: usize) -> Vec<[f32; 4]> {
    let mut v = vec![[0.0; 4]; 2 * n];
    for r in &mut v[..n] {
        r[crate::state::SOL_TIME] = -1.0;
    }
    v
}

/// Hydrostatic start: each fluid particle begins at the pressure of the fluid
/// stacked above it along gravity,
///   p_i = Σ_{j above} ρ0_j |g| Δx + ½ ρ0_i |g| Δx,
/// counting contiguous fluid lattice sites up to the first empty, wall or solid site
/// (a wall or a gap carries the load above it). Its mass is scaled by
/// 1 + p_i/(ρ0_i c_i²): summation density ρ_i = m_i Σ_j W_ij then gives that pressure
/// through the EOS on the lattice. Without this a layer at rest starts at p = 0,
/// sinks by g H/c² of its height and rings acoustically; at density ratio 1000 that
/// start-up transient pushes liquid particles through a liquid–gas interface.
fn hydrostatic_start(m: &Model, st: &mut State, sites: &[[u32; 3]], axis: usize) {
    let g = m.gravity[axis].abs();
    // Walk each column from the top down: "top" is the far end against gravity.
    let height = |i: usize| -> i64 {
        let k = sites[i][axis] as i64;
        if m.gravity[axis] < 0.0 {
            -k
        } else {
            k
        }
    };
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut order: Vec<usize> = (0..st.len()).collect();
    order.sort_by_key(|&i| (sites[i][b], sites[i][c], height(i)));
    let mut load = 0.0f64;
    let mut prev: Option<usize> = None;
    for &i in &order {
        let contiguous = prev.is_some_and(|j| {
            sites[j][b] == sites[i][b] && sites[j][c] == sites[i][c] && height(i) == height(j) + 1
        });
        prev = Some(i);
        let ph = &m.phases[st.phase[i] as usize];
        if !contiguous || !ph.is_fluid() {
            load = 0.0;
        }
        if !ph.is_fluid() {
            continue;
        }
        // The particle's own ρ0 (a density law's at its temperature).
        let (rho0, mass) = if ph.density_law.is_some() {
            (st.rho[i] as f64, st.mass[i] as f64)
        } else {
            (ph.rho0, ph.mass)
        };
        let weight = rho0 * g * m.dx;
        let p = load + 0.5 * weight;
        load += weight;
        let compression = p / (rho0 * ph.sound_speed * ph.sound_speed);
        st.mass[i] = (mass * (1.0 + compression)) as f32;
        st.rho[i] = (rho0 * (1.0 + compression)) as f32;
        st.press[i] = p as f32;
    }
}

fn push_particle(m: &Model, st: &mut State, x: [f64; 3], pi: usize) {
    let ph = &m.phases[pi];
    let l = m.to_local(x);
    let id = st.pos.len() as u32;
    st.pos.push([l[0] as f32, l[1] as f32, l[2] as f32, 0.0]);
    let v = if ph.is_fluid() {
        [0.0; 4]
    } else {
        [
            ph.velocity[0] as f32,
            ph.velocity[1] as f32,
            ph.velocity[2] as f32,
            0.0,
        ]
    };
    st.vel.push(v);
    st.acc.push([0.0; 4]);
    st.acc_b.push([0.0; 4]);
    // A density law: the particle starts at rest at its own ρ0(T0), its mass
    // that density times the lattice volume (δ-SPH, R18 (3.52)).
    let (rho0, mass) = match (&ph.density_law, ph.thermal) {
        (Some(law), Some(t)) => {
            let rho0 = law.at(t.temperature_at(x));
            (rho0, rho0 * m.dx.powi(m.dim as i32))
        }
        _ => (ph.rho0, ph.mass),
    };
    st.rho.push(rho0 as f32);
    st.press.push(0.0);
    st.mass.push(mass as f32);
    st.phase.push(pi as u32);
    st.id.push(id);
    if m.is_thermal() {
        st.heat.push(initial_heat(ph, x));
    }
}

/// Enthalpy and temperature at setup (x absolute). The heat.temperature pass
/// recomputes T and f_l from h before the first step. A Dirichlet wall particle
/// holds its fixed temperature in heat.x (it has no enthalpy), which the
/// wall_temperature pass mirrors through the wall every step.
fn initial_heat(ph: &crate::model::PhaseInfo, x: [f64; 3]) -> [f32; 4] {
    match ph.thermal {
        Some(t) if ph.conducts() => {
            let temp = t.temperature_at(x);
            [
                (t.enthalpy(temp) - t.reference_enthalpy()) as f32,
                temp as f32,
                0.0,
                0.0,
            ]
        }
        Some(t) => {
            let temp = t.temperature_at(x) as f32;
            [temp, temp, 0.0, 0.0]
        }
        None => [0.0; 4],
    }
}
