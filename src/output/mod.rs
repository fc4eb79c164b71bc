//! Run outputs (issue 3): the per-particle fields every format writes, the
//! diagnostics record, and the sinks (MCAP stream, VTK series, checkpoints).
//!
//! One list of fields (`particle_fields`) feeds both MCAP and VTK, so a field added
//! to the state appears in every format at once: each row of the field registry
//! (crate::fields) names the channels it writes to frames.

pub mod mcap_out;
pub mod pointcloud;
pub mod vtk;

use crate::model::Model;
use crate::scene::PhaseKind;

use crate::state::{dt_limit_name, State, DT_LIMIT_NAMES};
use serde::Serialize;

/// Values of one per-particle field, in particle (array) order.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    F32(Vec<f32>),
    U32(Vec<u32>),
}

impl Values {
    pub fn len(&self) -> usize {
        match self {
            Values::F32(v) => v.len(),
            Values::U32(v) => v.len(),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Little-endian bytes of element `i`.
    pub fn le_bytes(&self, i: usize) -> [u8; 4] {
        match self {
            Values::F32(v) => v[i].to_le_bytes(),
            Values::U32(v) => v[i].to_le_bytes(),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: &'static str,
    pub values: Values,
}

/// Every per-particle field a frame carries, from the field registry's `frames`
/// channels in registry order: x, y, z (m), vx, vy, vz (m/s), density (kg/m³),
/// pressure (Pa), mass (kg), phase (index into the scene's phases), id (the
/// particle's index at setup, stable across reordering), and in heat scenes
/// temperature (K), liquid fraction and specific enthalpy (J/kg); in powder
/// scenes `grain` (index + 1 of the grain the particle was poured in, 0 none);
/// in scenes with rigid bodies `body` (index + 1 of its body, 0 none).
///
/// Frames hold the particles still in the simulation only: the removed ones (the
/// last `sim.removed` of the state, issue 18) are left out, so they do not hang
/// frozen where they left in every later frame; `/removed` records them.
pub fn particle_fields(m: &Model, st: &State) -> Vec<Field> {
    let held = crate::fields::Held::of_state(st);
    let active = st.active();
    let mut fields: Vec<Field> = crate::fields::FIELDS
        .iter()
        .filter(|f| held.holds(f.holder))
        .filter_map(|f| f.frames)
        .flat_map(|channels| channels(m, st))
        .collect();
    if let Some(b) = &m.powder {
        // The grain each particle was poured in (index + 1; 0: none), by id.
        let grain = st
            .id
            .iter()
            .map(|&id| match b.members.get(id as usize) {
                Some(&g) if g != crate::powder::NO_GRAIN => g + 1,
                _ => 0,
            })
            .collect();
        fields.push(Field {
            name: "grain",
            values: Values::U32(grain),
        });
    }
    for f in &mut fields {
        match &mut f.values {
            Values::F32(v) => v.truncate(active),
            Values::U32(v) => v.truncate(active),
        }
    }
    fields
}

/// One channel.
pub fn channel(name: &'static str, values: Values) -> Vec<Field> {
    vec![Field { name, values }]
}

/// Scenes with rigid bodies: `body`, index + 1 of the body the particle belongs
/// to (0: none).
pub fn body_channels(_m: &Model, st: &State) -> Vec<Field> {
    let body = st
        .id
        .iter()
        .map(|&id| match st.body[id as usize] {
            crate::state::NO_BODY => 0,
            b => b + 1,
        })
        .collect();
    channel("body", Values::U32(body))
}

/// Position channels: world coordinates x, y, z (m), `Model::to_world` rounded
/// once to f32.
pub fn position_channels(m: &Model, st: &State) -> Vec<Field> {
    let world: Vec<[f64; 3]> = st.pos.iter().map(|&p| m.to_world(p)).collect();
    let coord = |a: usize| Values::F32(world.iter().map(|x| x[a] as f32).collect());
    ["x", "y", "z"]
        .into_iter()
        .enumerate()
        .map(|(a, name)| Field {
            name,
            values: coord(a),
        })
        .collect()
}

/// Velocity channels vx, vy, vz (m/s).
pub fn velocity_channels(_m: &Model, st: &State) -> Vec<Field> {
    let vel = |a: usize| Values::F32(st.vel.iter().map(|v| v[a]).collect());
    ["vx", "vy", "vz"]
        .into_iter()
        .enumerate()
        .map(|(a, name)| Field {
            name,
            values: vel(a),
        })
        .collect()
}

/// Heat scenes: temperature (K), liquid fraction and specific enthalpy (J/kg).
/// A particle of a phase without thermal properties (a wall with no temperature,
/// which insulates) has no temperature: it is written as the scene's ambient
/// temperature, with liquid fraction and enthalpy 0, so that a colour scale over
/// the frame stays within the temperatures the scene has (0 K used to stretch it).
pub fn heat_channels(m: &Model, st: &State) -> Vec<Field> {
    if st.heat.is_empty() {
        return Vec::new();
    }
    let ambient = m.ambient_temperature as f32;
    let has_temperature = |i: usize| m.phases[st.phase[i] as usize].thermal.is_some();
    let col = |k: usize| {
        Values::F32(
            (0..st.len())
                .map(|i| match (k, has_temperature(i)) {
                    (1, false) => ambient,
                    _ => st.heat[i][k],
                })
                .collect(),
        )
    };
    let enthalpy = Values::F32(
        (0..st.len())
            .map(|i| m.phases[st.phase[i] as usize].absolute_enthalpy(st.heat[i][0]) as f32)
            .collect(),
    );
    vec![
        Field {
            name: "temperature",
            values: col(1),
        },
        Field {
            name: "liquid_fraction",
            values: col(2),
        },
        Field {
            name: "enthalpy",
            values: enthalpy,
        },
    ]
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
    /// metre of depth in 2D) (issue 18).
    pub removed: std::collections::BTreeMap<String, u64>,
    pub removed_mass: std::collections::BTreeMap<String, f64>,
    /// Deepest fluid penetration behind a wall face, in Δx (issue 18).
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
}

/// Surface-force diagnostics (issue 16): the liquid's surface as the interface
/// pass sees it (Σ V δ over liquid particles with a normal: m² in 3D, m per metre
/// of depth in 2D), its δ-weighted mean curvature (1/m; scenes with surface
/// tension, 0 otherwise), the power the recoil pressure does on the liquid,
/// Σ V p_v δ (−n·u) (W; W/m in 2D; 0 without recoil), and the largest liquid
/// speed as a capillary number η|u|/α0 (the spurious currents of a scene at
/// rest; 0 without surface tension).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SurfaceDiagnostics {
    pub surface_area: f64,
    pub mean_curvature: f64,
    pub recoil_power: f64,
    pub capillary_number: f64,
}

pub fn surface_diagnostics(m: &Model, st: &State) -> Option<SurfaceDiagnostics> {
    let any_recoil = m.phases.iter().any(|p| p.recoil().is_some());
    if st.surface.is_empty() || (m.surface_tension.is_none() && !any_recoil) {
        return None;
    }
    let n = st.len();
    let mut d = SurfaceDiagnostics {
        surface_area: 0.0,
        mean_curvature: 0.0,
        recoil_power: 0.0,
        capillary_number: 0.0,
    };
    let mut fastest: f64 = 0.0;
    for i in 0..st.active() {
        let ph = &m.phases[st.phase[i] as usize];
        let s = st.surface[i];
        if ph.kind == PhaseKind::Liquid {
            let v = st.vel[i];
            fastest = fastest.max((0..3).map(|a| (v[a] as f64).powi(2)).sum::<f64>().sqrt());
        }
        if ph.kind != PhaseKind::Liquid || s[3] == 0.0 {
            continue;
        }
        let area = st.mass[i] as f64 / ph.rho0 * s[3] as f64;
        d.surface_area += area;
        d.mean_curvature += area * st.surface[n + i][1] as f64;
        if let Some(e) = ph.recoil() {
            let v = st.vel[i];
            let un = (0..3).map(|a| s[a] as f64 * v[a] as f64).sum::<f64>();
            d.recoil_power -= area * e.pressure(st.heat[i][1] as f64) * un;
        }
    }
    if m.surface_tension.is_some() && d.surface_area > 0.0 {
        d.mean_curvature /= d.surface_area;
    } else {
        d.mean_curvature = 0.0;
    }
    if let Some(t) = &m.surface_tension {
        d.capillary_number = m.phases[t.liquid].viscosity * fastest / t.coefficient;
    }
    Some(d)
}

/// Heat diagnostics (issue 4). Melt pool: particles with liquid fraction ≥ ½
/// among the liquid and solid ones; depth below the top of the condensed
/// material, width across and length along x (3D: width along y).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct HeatDiagnostics {
    pub max_temperature: f64,
    /// J (per metre of depth in 2D), Σ m h over conducting particles.
    pub total_enthalpy: f64,
    /// ζ P(t) of the laser (W; W/m in 2D); 0 without a laser.
    pub absorbed_laser_power: f64,
    /// Σ f_l V over liquid and solid particles (m³; m² in 2D).
    pub melted_volume: f64,
    pub pool_depth: f64,
    pub pool_width: f64,
    pub pool_length: f64,
    /// Heat leaving through free surfaces by evaporation F22 (18) (W; W/m in 2D).
    pub evaporated_power: f64,
    /// Heat leaving through free surfaces by radiation (W; W/m in 2D).
    pub radiated_power: f64,
}

/// (evaporated, radiated) power through free surfaces, host-side in f64 from the
/// temperatures and surface deltas of the state.
pub fn surface_loss_power(m: &Model, st: &State) -> (f64, f64) {
    if st.surface.is_empty() {
        return (0.0, 0.0);
    }
    let (mut evap, mut rad) = (0.0, 0.0);
    for i in 0..st.active() {
        let ph = &m.phases[st.phase[i] as usize];
        let Some(th) = ph.thermal.filter(|_| ph.conducts()) else {
            continue;
        };
        let t = st.heat[i][1] as f64;
        let area = st.surface[i][3] as f64 * st.mass[i] as f64 / ph.rho0;
        if let Some(e) = th.evaporation {
            evap += e.flux(t, th.heat_capacity) * area;
        }
        rad += th.radiated_flux(t, m.ambient_temperature) * area;
    }
    (evap, rad)
}

pub fn heat_diagnostics(m: &Model, st: &State) -> Option<HeatDiagnostics> {
    if st.heat.is_empty() {
        return None;
    }
    let up = m.dim as usize - 1;
    let cell = m.dx.powi(m.dim as i32);
    let mut d = HeatDiagnostics {
        max_temperature: f64::NEG_INFINITY,
        total_enthalpy: 0.0,
        absorbed_laser_power: m
            .laser
            .as_ref()
            .map_or(0.0, |l| l.absorptivity * l.power_at(st.sim.time as f64)),
        melted_volume: 0.0,
        pool_depth: 0.0,
        pool_width: 0.0,
        pool_length: 0.0,
        evaporated_power: 0.0,
        radiated_power: 0.0,
    };
    (d.evaporated_power, d.radiated_power) = surface_loss_power(m, st);
    let mut top = f64::NEG_INFINITY;
    let mut pool = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
    for i in 0..st.active() {
        let ph = &m.phases[st.phase[i] as usize];
        if !ph.conducts() {
            continue;
        }
        let [_, t, fl, _] = st.heat[i];
        d.max_temperature = d.max_temperature.max(t as f64);
        d.total_enthalpy += st.mass[i] as f64 * ph.absolute_enthalpy(st.heat[i][0]);
        if ph.kind == PhaseKind::Gas {
            continue;
        }
        let x = m.to_world(st.pos[i]);
        top = top.max(x[up]);
        d.melted_volume += fl as f64 * cell;
        if fl >= 0.5 {
            for a in 0..3 {
                pool[a] = [pool[a][0].min(x[a]), pool[a][1].max(x[a])];
            }
        }
    }
    if pool[0][0].is_finite() {
        let extent = |a: usize| pool[a][1] - pool[a][0] + m.dx;
        d.pool_depth = top - pool[up][0] + 0.5 * m.dx;
        d.pool_length = extent(0);
        d.pool_width = if m.dim == 3 { extent(1) } else { 0.0 };
    }
    Some(d)
}

pub fn diagnostics(m: &Model, st: &State) -> Diagnostics {
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
    };
    let leak = crate::watchdog::leakage(m, st);
    (d.wall_penetration_max_dx, d.wall_penetration_count) = (leak.deepest_dx, leak.beyond_half_dx);
    for (phase, (n, mass)) in crate::outflow::Outflow::of(m, st).per_phase {
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

/// JSON schema of a `/diagnostics` message (Foxglove's plot panel reads the numbers).
pub fn diagnostics_schema(m: &Model) -> serde_json::Value {
    let num = |desc: &str| serde_json::json!({"type": "number", "description": desc});
    let per_depth = if m.dim == 2 {
        " per metre of depth"
    } else {
        ""
    };
    let phases: serde_json::Map<String, serde_json::Value> = m
        .phases
        .iter()
        .map(|p| (p.name.clone(), serde_json::json!({"type": "integer"})))
        .collect();
    let phase_masses: serde_json::Map<String, serde_json::Value> = m
        .phases
        .iter()
        .map(|p| (p.name.clone(), serde_json::json!({"type": "number"})))
        .collect();
    let mut schema = serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Diagnostics",
        "type": "object",
        "properties": {
            "time": num("simulated time, s"),
            "step": {"type": "integer", "description": "step number"},
            "dt": num("time step the next step takes, s"),
            "dt_limit": {"type": "string", "enum": DT_LIMIT_NAMES,
                         "description": "F22 (42) limit that binds dt"},
            "kinetic_energy": num(&format!("fluid kinetic energy, J{per_depth}")),
            "total_mass": num(&format!("fluid mass, kg{per_depth}")),
            "max_speed": num("largest fluid speed, m/s"),
            "min_density": num("smallest fluid density, kg/m^3"),
            "max_density": num("largest fluid density, kg/m^3"),
            "particles": {"type": "object", "properties": phases,
                          "description": "particles in the domain per phase"},
            "removed": {"type": "object", "properties": phases,
                        "description": "particles that have left the domain per phase"},
            "removed_mass": {"type": "object", "properties": phase_masses,
                             "description": format!("mass of the particles that have left the domain per phase, kg{per_depth}")},
            "wall_penetration_max_dx": num("deepest fluid penetration behind a wall face, dx"),
            "wall_penetration_count": {"type": "integer",
                                       "description": "fluid particles more than 0.5 dx behind a wall face"}
        },
        "required": ["time", "step", "dt", "dt_limit", "kinetic_energy", "total_mass",
                     "max_speed", "min_density", "max_density", "particles",
                     "removed", "removed_mass",
                     "wall_penetration_max_dx", "wall_penetration_count"]
    });
    let any_recoil = m.phases.iter().any(|p| p.recoil().is_some());
    if m.surface_tension.is_some() || (any_recoil && m.needs_interface()) {
        let area = if m.dim == 2 {
            "m per metre of depth"
        } else {
            "m^2"
        };
        schema["properties"]["surface_area"] = num(&format!(
            "liquid surface, sum of V delta over liquid particles with a normal, {area}"
        ));
        schema["properties"]["mean_curvature"] = num(
            "delta-weighted mean curvature of the liquid surface, 1/m (0 without surface tension)",
        );
        schema["properties"]["recoil_power"] = num(&format!(
            "power of the recoil pressure on the liquid, W{per_depth}"
        ));
        schema["properties"]["capillary_number"] = num(
            "largest liquid speed as eta |u| / alpha0 (spurious currents of a drop at rest; 0 without surface tension)",
        );
    }
    if m.is_thermal() {
        let unit = if m.dim == 2 {
            " per metre of depth"
        } else {
            ""
        };
        let vol = if m.dim == 2 { "m^2" } else { "m^3" };
        let extra = [
            ("max_temperature", "largest temperature, K".to_string()),
            (
                "total_enthalpy",
                format!("sum of m h over conducting particles, J{unit}"),
            ),
            (
                "absorbed_laser_power",
                format!("absorptivity x beam power, W{unit}"),
            ),
            (
                "melted_volume",
                format!("liquid-fraction-weighted volume of liquid and solid, {vol}"),
            ),
            (
                "pool_depth",
                "melt pool depth below the top of the condensed material, m".into(),
            ),
            ("pool_width", "melt pool extent along y (3D), m".into()),
            ("pool_length", "melt pool extent along x, m".into()),
            (
                "evaporated_power",
                format!("evaporation heat loss, W{unit}"),
            ),
            ("radiated_power", format!("radiation heat loss, W{unit}")),
        ];
        for (k, desc) in extra {
            schema["properties"][k] = num(&desc);
        }
    }
    if crate::track::wanted(m) {
        schema["properties"]["depression_depth"] = num(
            "depth of the surface under the beam below the initial surface, m (> 0: sunk; absent while the beam is outside the domain)",
        );
    }
    schema
}

/// Write a file under a temporary name and rename it: a run stopped at any moment
/// leaves either the old file or the complete new one.
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<(), String> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, bytes)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

/// Simulated time in nanoseconds, the MCAP log time of a frame.
pub fn time_ns(t: f64) -> u64 {
    (t.max(0.0) * 1e9).round() as u64
}
