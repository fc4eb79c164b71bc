//! Instability watchdog: scans a state for the first sign that a run has
//! gone wrong and names the step, time, particle, field and value.
//!
//! It looks at every state the run reads back (each diagnostics interval) and at
//! Δt after every chunk; when it trips, the run replays from the last good state
//! one step at a time, so the report names the first bad step, not the scan that
//! noticed it.

use crate::model::Model;
use crate::scene::{DispersionAction, OpenSidesPolicy, PhaseKind};
use crate::state::{Sim, State};

#[derive(Debug, Clone, PartialEq)]
pub struct Trip {
    pub step: u64,
    pub time: f64,
    /// Particle id (stable across reordering); None for a global quantity (Δt).
    pub particle: Option<u32>,
    pub field: String,
    pub value: f64,
    pub reason: String,
}

impl Trip {
    pub fn message(&self) -> String {
        let who = match self.particle {
            Some(id) => format!("particle {id}"),
            None => "whole run".to_string(),
        };
        format!(
            "unstable at step {}, t = {:.6e} s: {who}, field {} = {:e} ({})",
            self.step, self.time, self.field, self.value, self.reason
        )
    }
}

/// Δt not finite, not positive or collapsed below the floor; or, when the scene's
/// open sides stop the run, a particle has left (the scan then names it).
/// The floor is `watchdog.min_dt_ratio` of the scene's smallest initial limit;
/// where every limit is infinite (DFSPH without gravity, heat or an explicit
/// viscosity: its step follows the flow alone), of `start_dt`, the step the
/// run started with (a resumed run's: the checkpoint's); none where that too is
/// unbounded (such a scene at rest).
pub fn check_sim(m: &Model, sim: &Sim, start_dt: f32) -> Option<Trip> {
    let reference = match m.limits.min().0 {
        lim if lim.is_finite() => lim,
        _ if start_dt > 0.0 && start_dt < f32::MAX => start_dt as f64,
        _ => f64::INFINITY,
    };
    let floor = m.watchdog.min_dt_ratio * reference;
    let floor = if floor.is_finite() { floor } else { 0.0 };
    let dt = sim.dt as f64;
    if m.open_sides_policy == OpenSidesPolicy::Stop && sim.removed > 0 {
        return Some(Trip {
            step: sim.step as u64,
            time: sim.time as f64,
            particle: None,
            field: "removed".into(),
            value: sim.removed as f64,
            reason: "particles left the domain and domain.open_sides_policy is \"stop\"".into(),
        });
    }
    let reason = if !dt.is_finite() {
        "time step is not finite".to_string()
    } else if dt <= 0.0 {
        "time step is not positive".to_string()
    } else if dt < floor {
        format!(
            "time step collapsed below {floor:e} s ({} of the initial limit)",
            m.watchdog.min_dt_ratio
        )
    } else {
        return None;
    };
    Some(Trip {
        step: sim.step as u64,
        time: sim.time as f64,
        particle: None,
        field: "dt".into(),
        value: dt,
        reason,
    })
}

/// The first problem in `st`, by particle id, or None when the state is sane.
pub fn scan(m: &Model, st: &State) -> Option<Trip> {
    if !m.watchdog.enabled {
        return None;
    }
    let mut worst: Option<(u32, &'static str, f64, String)> = None;
    for i in 0..st.len() {
        let id = st.id[i];
        if worst.as_ref().is_some_and(|w| w.0 <= id) {
            continue;
        }
        if let Some((field, value, reason)) = particle_problem(m, st, i) {
            worst = Some((id, field, value, reason));
        }
    }
    let Some((id, field, value, reason)) = worst else {
        return match m.dispersion_action() {
            DispersionAction::Stop => dispersion_trip(m, st),
            DispersionAction::Warn => None,
        };
    };
    Some(Trip {
        step: st.sim.step as u64,
        time: st.sim.time as f64,
        particle: Some(id),
        field: field.into(),
        value,
        reason,
    })
}

/// Particles alone in the gas below which a share does not count (the first
/// few molten particles of a melt pool under gas may have no liquid beside them).
pub const MIN_DISPERSED: usize = 10;

/// A liquid dispersing into its gas: its particles with no liquid,
/// solid or wall particle within 1.5 Δx (crate::pool::LINK_DX). Without gas, a
/// free surface under tension breaking up: its particles in fragments too small
/// for the kernel to resolve (`fragment_limit`). A gas-free liquid torn apart
/// by the free-surface tension's currents sheds fragments of a few particles
/// that the tension holds together, not single particles: R = 6.25Δx of molten
/// steel without the interface viscosity lost 73 of its 120 particles in
/// fragments of 2 to 5, none ever alone. A piece with a particle within a
/// kernel support of an open side and moving out through it is not counted:
/// it is leaving, or it is the last of a drop the side has cut (a free sphere
/// drifting out of its box was stopped as "breaking up" when its last 14
/// particles were inside); the same holds for a particle alone in a gas.
#[derive(Debug, Clone, PartialEq)]
pub struct Dispersion {
    /// Liquid particles alone (with gas) or in fragments (without).
    pub alone: usize,
    pub liquid: usize,
    /// The lowest id among them.
    pub first_id: u32,
    /// The largest region that counts: 1 with gas, `fragment_limit` without.
    pub fragment: usize,
}

/// Without gas, the most particles in a region that counts as a fragment: those
/// of a drop of radius 1.5Δx (the link length), π 1.5² = 7 in 2D and
/// 4/3 π 1.5³ = 14 in 3D. Below that radius the kernel (support 3h) cannot
/// resolve the drop's curvature, so such a piece is the method's debris, not a
/// droplet the run resolves.
pub fn fragment_limit(dim: u32) -> usize {
    let r = crate::pool::LINK_DX;
    let area_or_volume = if dim == 3 {
        4.0 / 3.0 * std::f64::consts::PI * r * r * r
    } else {
        std::f64::consts::PI * r * r
    };
    area_or_volume.floor() as usize
}

impl Dispersion {
    pub fn share(&self) -> f64 {
        self.alone as f64 / self.liquid.max(1) as f64
    }
    /// Past the scene's bound (`watchdog.liquid_dispersion`)?
    pub fn beyond(&self, m: &Model) -> bool {
        self.alone >= MIN_DISPERSED && self.share() > m.watchdog.liquid_dispersion
    }
    pub fn describe(&self, m: &Model) -> String {
        let (n, all, share, link, bound) = (
            self.alone,
            self.liquid,
            100.0 * self.share(),
            crate::pool::LINK_DX,
            m.watchdog.liquid_dispersion,
        );
        if self.fragment == 1 {
            return format!(
                "{n} of {all} liquid particles ({share:.1}%) have no liquid, solid or wall particle within {link} dx, beyond watchdog.liquid_dispersion = {bound}: the liquid is dispersing into its gas (F22's liquid-gas interface viscosity, simulation.interface_viscosity, 7.2 for molten steel, holds an interface together)"
            );
        }
        format!(
            "{n} of {all} liquid particles ({share:.1}%) are in fragments of at most {} particles (pieces linked within {link} dx, smaller than a drop of radius {link} dx, which the kernel cannot resolve), beyond watchdog.liquid_dispersion = {bound}: the free surface is breaking up below the resolution (spatter too small for this dx, or the free-surface tension's spurious currents, which simulation.interface_viscosity damps: docs/physics.md, Surface tension, free-surface form)",
            self.fragment
        )
    }
}

/// The dispersion of the liquid of `st`; None in scenes without a liquid, and
/// in those without a gas unless the liquid's free surface bears the
/// free-surface tension (without it a gas-free liquid sheds single particles by
/// splashing, as a dam break's front does, and nothing tears its surface apart).
pub fn dispersion(m: &Model, st: &State) -> Option<Dispersion> {
    let kind = |i: usize| m.phases[st.phase[i] as usize].kind;
    let gas = !m.free_surface_interface();
    let fragment = match (gas, m.free_surface_csf()) {
        (true, _) => 1,
        (false, true) => fragment_limit(m.dim),
        (false, false) => return None,
    };
    if !m.phases.iter().any(|p| p.kind == PhaseKind::Liquid) {
        return None;
    }
    let dense: Vec<usize> = (0..st.active())
        .filter(|&i| kind(i) != PhaseKind::Gas)
        .collect();
    let pos: Vec<[f64; 3]> = dense.iter().map(|&i| m.to_world(st.pos[i])).collect();
    let (label, n) = crate::pool::connected_regions(&pos, crate::pool::LINK_DX * m.dx, m.dim);
    let mut size = vec![0usize; n];
    label.iter().for_each(|&r| size[r] += 1);
    let leaving = leaving_pieces(m, st, &dense, &pos, &label, n);
    let mut d = Dispersion {
        alone: 0,
        liquid: 0,
        first_id: u32::MAX,
        fragment,
    };
    for (k, &i) in dense.iter().enumerate() {
        if kind(i) != PhaseKind::Liquid {
            continue;
        }
        d.liquid += 1;
        if size[label[k]] <= d.fragment && !leaving[label[k]] {
            d.alone += 1;
            d.first_id = d.first_id.min(st.id[i]);
        }
    }
    Some(d)
}

/// The pieces leaving through an open side: a member within a kernel support
/// of the side and the piece's mean velocity outward through it. Such a piece
/// is on its way out, or is what the side has left of a drop that crossed it,
/// not debris; a piece that stays beside an open side or moves inward counts.
fn leaving_pieces(
    m: &Model,
    st: &State,
    dense: &[usize],
    pos: &[[f64; 3]],
    label: &[usize],
    n: usize,
) -> Vec<bool> {
    // Per piece, the sum of its velocities: the mean velocity's direction.
    let mut velocity = vec![[0.0f64; 3]; n];
    let mut faces: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for (k, &i) in dense.iter().enumerate() {
        let r = label[k];
        for (sum, &v) in velocity[r].iter_mut().zip(&st.vel[i]) {
            *sum += v as f64;
        }
        for f in m.open_faces_near(pos[k], m.support) {
            if !faces[r].contains(&f) {
                faces[r].push(f);
            }
        }
    }
    (0..n)
        .map(|r| faces[r].iter().any(|&(a, out)| velocity[r][a] * out > 0.0))
        .collect()
}

fn dispersion_trip(m: &Model, st: &State) -> Option<Trip> {
    let d = dispersion(m, st).filter(|d| d.beyond(m))?;
    Some(Trip {
        step: st.sim.step as u64,
        time: st.sim.time as f64,
        particle: Some(d.first_id),
        field: "liquid_dispersion".into(),
        value: d.share(),
        reason: d.describe(m),
    })
}

const AXES: [&str; 3] = ["x", "y", "z"];

fn particle_problem(m: &Model, st: &State, i: usize) -> Option<(&'static str, f64, String)> {
    let vec_fields: [(&'static str, &[f32; 4]); 4] = [
        ("position", &st.pos[i]),
        ("velocity", &st.vel[i]),
        ("acceleration", &st.acc[i]),
        ("transport_acceleration", &st.acc_b[i]),
    ];
    for (name, v) in vec_fields {
        if let Some(&x) = v[..m.dim as usize].iter().find(|x| !x.is_finite()) {
            return Some((name, x as f64, "not finite".into()));
        }
    }
    for (name, x) in [("density", st.rho[i]), ("pressure", st.press[i])] {
        if !x.is_finite() {
            return Some((name, x as f64, "not finite".into()));
        }
    }
    let phase = &m.phases[st.phase[i] as usize];
    if i >= st.active() {
        return removal_problem(m, st, i);
    }
    if phase.kind == PhaseKind::Wall {
        return None;
    }
    if let Some(p) = position_problem(m, st, i) {
        return Some(p);
    }
    let ratio = st.rho[i] as f64 / phase.rho0;
    let wd = &m.watchdog;
    if ratio < wd.min_density_ratio || ratio > wd.max_density_ratio {
        return Some((
            "density",
            st.rho[i] as f64,
            format!(
                "outside {}..{} x rho0 of phase {}",
                wd.min_density_ratio, wd.max_density_ratio, phase.name
            ),
        ));
    }
    None
}

/// A fluid particle still in the simulation deeper behind a wall face than the
/// watchdog allows. (One beyond an open face has been removed by the step.) A
/// particle beyond an open face is out of the domain, where no wall stands (a
/// rigid grain's members stand there until the body's centre is out too).
fn position_problem(m: &Model, st: &State, i: usize) -> Option<(&'static str, f64, String)> {
    let depth = m.wall_stop_depth() * m.dx;
    let faces = m.beyond_faces(m.to_world(st.pos[i]));
    if faces.iter().any(|&(_, _, _, open)| open) {
        return None;
    }
    for (a, side, beyond, _) in faces {
        if beyond <= depth {
            continue;
        }
        return Some(wall_trip(m, st, i, a, side, beyond));
    }
    None
}

fn wall_trip(
    m: &Model,
    st: &State,
    i: usize,
    a: usize,
    side: usize,
    beyond: f64,
) -> (&'static str, f64, String) {
    let name = crate::scene::SIDE_NAMES[a][side];
    let d = beyond / m.dx;
    let what = match m.watchdog.wall_penetration {
        Some(t) if t < m.wall_layers as f64 => format!(
            "penetrated the {name} wall by {d:.2} dx, beyond watchdog.wall_penetration = {t}"
        ),
        _ => format!(
            "passed through all {} layers of the {name} wall ({d:.2} dx behind its face)",
            m.wall_layers
        ),
    };
    (AXES[a], m.to_world(st.pos[i])[a], what)
}

/// A particle the step removed: leaving through an open side is normal
/// unless the scene's policy is "stop"; leaving behind a walled side means it went
/// through every wall layer, which always stops the run.
fn removal_problem(m: &Model, st: &State, i: usize) -> Option<(&'static str, f64, String)> {
    let world = crate::outflow::exit_point(m, st, i);
    let (a, side, open) = m.exit_face(world);
    let x = world[a];
    if !open {
        let face = [m.domain_lo[a], m.domain_hi[a]][side];
        return Some(wall_trip(m, st, i, a, side, (x - face).abs()));
    }
    if m.open_sides_policy == OpenSidesPolicy::Stop {
        let name = crate::scene::SIDE_NAMES[a][side];
        return Some((
            AXES[a],
            x,
            format!(
                "left the domain through its open {name} side at t = {:.6e} s (domain.open_sides_policy = \"stop\")",
                st.pos[i][3]
            ),
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> (Model, State) {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/dam_break_2d.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        (l.model, l.state)
    }

    fn fluid(m: &Model, st: &State) -> Vec<usize> {
        (0..st.len())
            .filter(|&i| m.phases[st.phase[i] as usize].kind != PhaseKind::Wall)
            .collect()
    }

    #[test]
    fn initial_state_is_sane() {
        let (m, mut st) = scene();
        st.rho.iter_mut().for_each(|r| *r = 1000.0);
        assert_eq!(scan(&m, &st), None);
    }

    #[test]
    fn names_the_lowest_id_with_a_non_finite_value() {
        let (m, mut st) = scene();
        st.rho.iter_mut().for_each(|r| *r = 1000.0);
        let f = fluid(&m, &st);
        st.vel[f[7]][1] = f32::NAN;
        st.press[f[3]] = f32::INFINITY;
        let t = scan(&m, &st).expect("trip");
        assert_eq!(t.particle, Some(st.id[f[3]].min(st.id[f[7]])));
        assert!(t.reason.contains("not finite"));
    }

    #[test]
    fn catches_wall_penetration_and_density_outside_the_band() {
        let (mut m, mut st) = scene();
        st.rho.iter_mut().for_each(|r| *r = 1000.0);
        let f = fluid(&m, &st);
        let x_lo = m.to_local(m.domain_lo)[0];
        // By default a leak into the wall layers is measured, not fatal; through
        // all of them (3 for the quintic) it stops the run.
        st.pos[f[0]][0] = (x_lo - 0.6 * m.dx) as f32;
        assert_eq!(scan(&m, &st), None);
        st.pos[f[0]][0] = (x_lo - 3.2 * m.dx) as f32;
        let t = scan(&m, &st).expect("through the wall");
        assert_eq!((t.field.as_str(), t.particle), ("x", Some(st.id[f[0]])));
        assert!(
            t.reason.contains("all 3 layers of the x_min wall"),
            "{}",
            t.reason
        );
        // The strict threshold, when the scene asks for it.
        m.watchdog.wall_penetration = Some(0.5);
        st.pos[f[0]][0] = (x_lo - 0.6 * m.dx) as f32;
        let t = scan(&m, &st).expect("penetration");
        assert_eq!((t.field.as_str(), t.particle), ("x", Some(st.id[f[0]])));
        assert!(
            t.reason.contains("penetrated the x_min wall"),
            "{}",
            t.reason
        );
        st.pos[f[0]][0] = (x_lo + 0.5 * m.dx) as f32;
        st.rho[f[1]] = 5000.0;
        let t = scan(&m, &st).expect("density");
        assert_eq!(t.field, "density");
    }

    /// Above the open top (dam_break_2d's y_max) a particle beyond the x_max
    /// wall's line is outside the domain, not in the wall: no trip. Below the
    /// top the same x is through the wall.
    #[test]
    fn beyond_an_open_face_no_wall_is_crossed() {
        let (m, mut st) = scene();
        st.rho.iter_mut().for_each(|r| *r = 1000.0);
        let f = fluid(&m, &st);
        let [x_hi, y_hi, _] = m.to_local(m.domain_hi);
        st.pos[f[0]][0] = (x_hi + 3.2 * m.dx) as f32;
        st.pos[f[0]][1] = (y_hi + 5.0 * m.dx) as f32;
        assert_eq!(scan(&m, &st), None);
        st.pos[f[0]][1] = (y_hi - 5.0 * m.dx) as f32;
        let t = scan(&m, &st).expect("through the x_max wall");
        assert!(t.reason.contains("x_max wall"), "{}", t.reason);
    }

    #[test]
    fn dt_collapse_and_nan_dt_trip() {
        let (m, st) = scene();
        let mut sim = st.sim;
        sim.dt = (m.limits.min().0 * 1e-4) as f32;
        assert!(check_sim(&m, &sim, 0.0)
            .unwrap()
            .reason
            .contains("collapsed"));
        sim.dt = f32::NAN;
        assert!(check_sim(&m, &sim, 0.0).is_some());
        sim.dt = m.limits.min().0 as f32;
        assert!(check_sim(&m, &sim, 0.0).is_none());
        // Every limit infinite (DFSPH following the flow alone): the floor is
        // the run's first step's; none when that was unbounded too.
        let mut free = m.clone();
        free.limits = crate::model::DtLimits {
            acoustic: f64::INFINITY,
            viscous: f64::INFINITY,
            body_force: f64::INFINITY,
            conduction: f64::INFINITY,
            barrier: f64::INFINITY,
            capillary: f64::INFINITY,
            contact: f64::INFINITY,
            maximum: f64::INFINITY,
        };
        sim.dt = 1e-12;
        assert!(check_sim(&free, &sim, 1e-8)
            .unwrap()
            .reason
            .contains("collapsed"));
        assert!(check_sim(&free, &sim, 1e-10).is_none());
        assert!(check_sim(&free, &sim, f32::MAX).is_none());
    }

    /// Liquid particles alone in the gas past the scene's share stop
    /// the run (the lowest id named), or only warn; a drop that holds together
    /// and a share below the bound pass.
    #[test]
    fn catches_a_liquid_dispersing_into_its_gas() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/square_drop_2d.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        let (mut m, mut st) = (l.model, l.state);
        assert_eq!(scan(&m, &st), None);
        let liquid: Vec<usize> = (0..st.len())
            .filter(|&i| m.phases[st.phase[i] as usize].kind == PhaseKind::Liquid)
            .collect();
        let d = dispersion(&m, &st).unwrap();
        assert_eq!((d.alone, d.liquid), (0, liquid.len()));
        // Scatter 14 of the 256 (5.5%) along a row of the gas, 3 dx apart.
        let y = 0.01; // the gas below the liquid square (0.025..0.055 m)
        for (k, &i) in liquid.iter().take(14).enumerate() {
            st.pos[i][0] = (0.005 + 3.0 * m.dx * k as f64) as f32;
            st.pos[i][1] = y;
        }
        let first = liquid.iter().take(14).map(|&i| st.id[i]).min().unwrap();
        let t = scan(&m, &st).expect("dispersion");
        assert_eq!(
            (t.field.as_str(), t.particle),
            ("liquid_dispersion", Some(first))
        );
        assert!(t.reason.contains("14 of 256"), "{}", t.reason);
        m.watchdog.liquid_dispersion = 0.06;
        assert_eq!(scan(&m, &st), None);
        m.watchdog.liquid_dispersion = 0.05;
        m.watchdog.on_dispersion = Some(DispersionAction::Warn);
        assert_eq!(scan(&m, &st), None);
        assert!(dispersion(&m, &st).unwrap().beyond(&m));
    }

    /// Without gas, a liquid under the free-surface tension that sheds pieces
    /// of up to 7 particles (2D) is breaking up; a piece of 8 is a droplet the
    /// run resolves, and a dam break's liquid (no tension) is not watched.
    #[test]
    fn catches_a_gas_free_surface_breaking_into_fragments() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/laplace_free_disc_2d.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        let (m, mut st) = (l.model, l.state);
        assert_eq!(fragment_limit(2), 7);
        assert_eq!(fragment_limit(3), 14);
        assert_eq!(scan(&m, &st), None);
        let liquid: Vec<usize> = (0..st.len())
            .filter(|&i| m.phases[st.phase[i] as usize].kind == PhaseKind::Liquid)
            .collect();
        let d = dispersion(&m, &st).unwrap();
        assert_eq!((d.alone, d.fragment), (0, 7));
        // Pieces of `size` particles in a line 1 dx apart, the pieces 4 dx
        // apart, six to a row, the first row `bottom` dx up, below the drop
        // (which starts 20 dx up): just over 5% of the liquid in all.
        let pieces = |st: &mut State, size: usize, bottom: f64| {
            let n = (0.05 * liquid.len() as f64).ceil() as usize + size;
            for (k, &i) in liquid.iter().take(n - n % size).enumerate() {
                let (piece, at) = (k / size, k % size);
                let (column, row) = ((piece % 6) as f64, (piece / 6) as f64);
                let x = m.dx * (5.0 + (size + 4) as f64 * column + at as f64);
                let y = m.dx * (bottom + 4.0 * row);
                st.pos[i][0] = (x - m.origin[0]) as f32;
                st.pos[i][1] = (y - m.origin[1]) as f32;
            }
        };
        let mut torn = st.clone();
        pieces(&mut torn, 7, 5.0);
        let t = scan(&m, &torn).expect("a surface breaking up");
        assert!(t.reason.contains("fragments of at most 7"), "{}", t.reason);
        // The first row 1 dx above the open y_min side, within a support of
        // it. At rest its six pieces count; moving down through the side they
        // are leaving, and the second row's four (28 particles, 2.2%) are
        // below the bound.
        let mut cut = st.clone();
        pieces(&mut cut, 7, 1.0);
        assert!(
            scan(&m, &cut).is_some(),
            "pieces at rest beside a side count"
        );
        let near = |st: &State, i: usize| m.to_world(st.pos[i])[1] < m.support;
        for i in 0..cut.len() {
            if near(&cut, i) {
                cut.vel[i][1] = -0.01;
            }
        }
        assert_eq!(dispersion(&m, &cut).unwrap().alone, 28);
        assert_eq!(scan(&m, &cut), None, "pieces leaving through a side");
        pieces(&mut st, 8, 5.0);
        assert_eq!(scan(&m, &st), None, "pieces of 8 are droplets");
        let dam = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/dam_break_2d.toml"
        );
        let l = crate::load::load(dam, &[]).unwrap();
        assert!(dispersion(&l.model, &l.state).is_none());
    }
}
