//! Diagnostics: what the run records about each state it reads back,
//! besides the frames. The `/diagnostics` record (energy, mass, density, per-phase
//! counts, with the wall-leakage and outflow roll-ups and the heat and surface
//! figures), the `/bodies` message, and the JSON schemas of every JSON topic of the
//! MCAP stream (`topics`). The sinks in `output/` write what they are given;
//! which topics exist and what their messages say is decided here.

mod heat;
mod leakage;
mod schema;
mod surface;

pub use heat::{
    heat_diagnostics, set_pool, surface_loss_power, HeatDiagnostics, LaserBalance, LaserSummary,
};
pub use leakage::Leakage;
pub use schema::{bodies_schema, check_schema, diagnostics_schema, removal_schema, track_schema};
pub use surface::{surface_diagnostics, SurfaceDiagnostics, INTERIOR_SHEPARD};

use crate::model::Model;
use crate::outflow::Outflow;
use crate::output::mcap_out::JsonTopic;
use crate::state::{dt_limit_name, State};
use serde::Serialize;

pub const DIAGNOSTICS_TOPIC: &str = "/diagnostics";
pub const REMOVED_TOPIC: &str = "/removed";
pub const TRACK_TOPIC: &str = "/track";
pub const BODIES_TOPIC: &str = "/bodies";
pub const CHECK_TOPIC: &str = "/check";

/// The JSON topics of a scene's MCAP stream, in channel order: `/diagnostics`
/// and `/removed` always, `/track` in scenes with a melt track (crate::track),
/// `/solidification` in scenes with a melting phase (crate::solidification),
/// `/bodies` in scenes with rigid bodies, `/check` in scenes with a `[check]`.
pub fn topics(m: &Model) -> Vec<JsonTopic> {
    let mut t = vec![
        JsonTopic {
            topic: DIAGNOSTICS_TOPIC,
            schema_name: "spatter.Diagnostics",
            schema: diagnostics_schema(m),
        },
        JsonTopic {
            topic: REMOVED_TOPIC,
            schema_name: "spatter.Removal",
            schema: removal_schema(),
        },
    ];
    if crate::track::wanted(m) {
        t.push(JsonTopic {
            topic: TRACK_TOPIC,
            schema_name: "spatter.Track",
            schema: track_schema(),
        });
    }
    if m.melts() {
        t.push(JsonTopic {
            topic: crate::solidification::SOLIDIFICATION_TOPIC,
            schema_name: "spatter.Solidification",
            schema: crate::solidification::schema(),
        });
    }
    if m.has_bodies() {
        t.push(JsonTopic {
            topic: BODIES_TOPIC,
            schema_name: "spatter.Bodies",
            schema: bodies_schema(),
        });
    }
    if m.check.is_some() {
        t.push(JsonTopic {
            topic: CHECK_TOPIC,
            schema_name: "spatter.Check",
            schema: check_schema(),
        });
    }
    t
}

/// One `/diagnostics` record. Fluid particles in the domain only: wall particles
/// carry extrapolated velocities and pressures, not a state of their own, and the
/// removed ones are counted apart (`removed`, `removed_mass`).
#[derive(Debug, Clone, Serialize)]
pub struct Diagnostics {
    pub time: f64,
    pub step: u64,
    pub dt: f64,
    pub dt_limit: String,
    /// J (per metre of depth in 2D).
    pub kinetic_energy: f64,
    /// kg (per metre of depth in 2D).
    pub total_mass: f64,
    pub max_speed: f64,
    pub min_density: f64,
    pub max_density: f64,
    /// Particles in the domain per phase.
    pub particles: std::collections::BTreeMap<String, u64>,
    /// Particles that have left the domain per phase, and their mass (kg; per
    /// metre of depth in 2D).
    pub removed: std::collections::BTreeMap<String, u64>,
    pub removed_mass: std::collections::BTreeMap<String, f64>,
    /// Deepest fluid penetration behind a wall face, in Δx.
    pub wall_penetration_max_dx: f64,
    /// Fluid particles more than ½Δx behind a wall face.
    pub wall_penetration_count: u64,
    /// Heat scenes only.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub heat: Option<HeatDiagnostics>,
    /// Scenes with surface tension or recoil only.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub surface: Option<SurfaceDiagnostics>,
    /// Scenes with a melt track (crate::track): depth of the surface under the
    /// beam below the initial surface, m (set by the run, which holds the track).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depression_depth: Option<f64>,
    /// Scenes with iterative solves (R18's trapezoidal heat, DFSPH's two
    /// pressure solves and implicit viscosity): each solve's iterations and
    /// final residual in the last step before the sample.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solvers: Option<std::collections::BTreeMap<String, SolverFigures>>,
}

/// One solve's figures of the last step (`State::solvers`).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SolverFigures {
    pub iterations: u32,
    pub residual: f64,
    /// The residual reached the tolerance (else the iteration bound stopped it).
    pub converged: bool,
    /// Steps since the run began that this solve ended at its bound unconverged.
    pub capped_steps: u32,
}

/// The solves the scene's schedule runs, by `SOLVER_SLOTS` name.
pub fn solver_names(m: &Model) -> Vec<&'static str> {
    use crate::backend::SolverSlot;
    let trapezoidal =
        m.is_thermal() && m.heat.integrator == crate::scene::HeatIntegrator::Trapezoidal;
    let dfsph = m.formulation == crate::scene::Formulation::Dfsph;
    crate::backend::SOLVER_SLOTS
        .iter()
        .filter(|(slot, _)| match slot {
            SolverSlot::Heat => trapezoidal,
            SolverSlot::Density | SolverSlot::Divergence => dfsph,
            SolverSlot::Viscosity => m.implicit_viscosity(),
        })
        .map(|(_, name)| *name)
        .collect()
}

fn solver_figures(
    m: &Model,
    st: &State,
) -> Option<std::collections::BTreeMap<String, SolverFigures>> {
    let names = solver_names(m);
    if names.is_empty() || st.solvers.is_empty() {
        return None;
    }
    Some(
        crate::backend::SOLVER_SLOTS
            .iter()
            .filter(|(_, name)| names.contains(name))
            .map(|(slot, name)| {
                let s = st.solvers[*slot as usize];
                let figures = SolverFigures {
                    iterations: s.iterations,
                    residual: s.residual as f64,
                    converged: s.converged != 0,
                    capped_steps: s.capped,
                };
                (name.to_string(), figures)
            })
            .collect(),
    )
}

/// The `/diagnostics` record of `st`, with its wall-leakage and outflow roll-ups;
/// `depression_depth` is left to the run's observers (`run::Observer::annotate`).
pub fn record(m: &Model, st: &State) -> Diagnostics {
    let mut d = Diagnostics {
        time: st.sim.time as f64,
        step: st.sim.step as u64,
        dt: st.sim.dt as f64,
        dt_limit: dt_limit_name(st.sim.dt_limit).to_string(),
        kinetic_energy: 0.0,
        total_mass: 0.0,
        max_speed: 0.0,
        min_density: f64::INFINITY,
        max_density: f64::NEG_INFINITY,
        particles: m.phases.iter().map(|p| (p.name.clone(), 0)).collect(),
        removed: m.phases.iter().map(|p| (p.name.clone(), 0)).collect(),
        removed_mass: m.phases.iter().map(|p| (p.name.clone(), 0.0)).collect(),
        wall_penetration_max_dx: 0.0,
        wall_penetration_count: 0,
        heat: heat_diagnostics(m, st),
        surface: surface_diagnostics(m, st),
        depression_depth: None,
        solvers: solver_figures(m, st),
    };
    let leak = Leakage::of(m, st);
    (d.wall_penetration_max_dx, d.wall_penetration_count) = (leak.deepest_dx, leak.beyond_half_dx);
    for (phase, (n, mass)) in Outflow::of(m, st).per_phase {
        d.removed.insert(phase.clone(), n);
        d.removed_mass.insert(phase, mass);
    }
    for i in 0..st.active() {
        let phase = &m.phases[st.phase[i] as usize];
        *d.particles.entry(phase.name.clone()).or_default() += 1;
        if !phase.is_fluid() {
            continue;
        }
        let v = st.vel[i];
        let v2 = (0..3).map(|a| (v[a] as f64).powi(2)).sum::<f64>();
        let mass = st.mass[i] as f64;
        d.kinetic_energy += 0.5 * mass * v2;
        d.total_mass += mass;
        d.max_speed = d.max_speed.max(v2.sqrt());
        d.min_density = d.min_density.min(st.rho[i] as f64);
        d.max_density = d.max_density.max(st.rho[i] as f64);
    }
    if !d.min_density.is_finite() {
        (d.min_density, d.max_density) = (0.0, 0.0);
    }
    d
}

/// A `/bodies` message: every rigid body's motion at one frame.
pub fn bodies_message(m: &Model, st: &State) -> serde_json::Value {
    let bodies: Vec<serde_json::Value> = st
        .bodies
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let mo = crate::bodies::BodyMotion::of(m, b);
            serde_json::json!({
                "body": k + 1,
                "position": mo.position.to_array(),
                "orientation": mo.orientation.to_array(),
                "velocity": mo.velocity.to_array(),
                "angular_velocity": mo.angular_velocity.to_array(),
                "mass": mo.mass,
                "particles": b.count,
                "molten_fraction": b.molten_fraction(),
                "bonded": b.bonded_in(),
                "left": b.left(),
            })
        })
        .collect();
    serde_json::json!({"time": st.sim.time as f64, "bodies": bodies})
}
