//! Run outputs: the sinks (MCAP stream, VTK series) and the per-particle
//! channels every frame carries. What else the stream records (diagnostics,
//! removals, the track, the bodies) is built in crate::diagnostics and handed to
//! the sinks as JSON messages.
//!
//! One list of fields (`particle_fields`) feeds both MCAP and VTK, so a field added
//! to the state appears in every format at once: each row of the field registry
//! (crate::fields) names the channels it writes to frames.

pub mod mcap_out;
pub mod pointcloud;
pub mod vtk;

use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::{State, H_ENTHALPY};

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
/// last `sim.removed` of the state) are left out, so they do not hang
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

/// Frame channels (MCAP and VTK), per particle in frame order:
/// `solidification_time` (s, −1 where the particle never froze from the
/// liquid), `thermal_gradient` G (K/m), `cooling_rate` (K/s) and
/// `solidification_rate` R (m/s), 0 where there is no record.
pub fn solidification_channels(m: &Model, st: &State) -> Vec<Field> {
    let mut by_id: Vec<Option<crate::solidification::Record>> =
        vec![None; st.solidification.len() / 2];
    for r in crate::solidification::records(m, st) {
        by_id[r.id as usize] = Some(r);
    }
    let recs: Vec<Option<crate::solidification::Record>> =
        st.id.iter().map(|&k| by_id[k as usize]).collect();
    let col = |f: fn(&crate::solidification::Record) -> f64, none: f32| {
        Values::F32(
            recs.iter()
                .map(|r| r.as_ref().map_or(none, |r| f(r) as f32))
                .collect(),
        )
    };
    vec![
        Field {
            name: "solidification_time",
            values: col(|r| r.time, -1.0),
        },
        Field {
            name: "thermal_gradient",
            values: col(|r| r.gradient, 0.0),
        },
        Field {
            name: "cooling_rate",
            values: col(|r| r.cooling_rate, 0.0),
        },
        Field {
            name: "solidification_rate",
            values: col(|r| r.rate, 0.0),
        },
    ]
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
/// A Dirichlet wall particle is written at its fixed temperature (heat.x), not
/// at the mirror temperature 2 T_wall − T̃ the conduction pass gives it
/// (measured down to −681 K beside a hot pool), with enthalpy 0: a wall has none.
pub fn heat_channels(m: &Model, st: &State) -> Vec<Field> {
    if st.heat.is_empty() {
        return Vec::new();
    }
    let ambient = m.ambient_temperature as f32;
    let wall = |i: usize| m.phases[st.phase[i] as usize].kind == PhaseKind::Wall;
    let has_temperature = |i: usize| m.phases[st.phase[i] as usize].thermal.is_some();
    let col = |k: usize| {
        Values::F32(
            (0..st.len())
                .map(|i| match (k, has_temperature(i), wall(i)) {
                    (1, false, _) => ambient,
                    (1, true, true) => st.heat[i][H_ENTHALPY],
                    _ => st.heat[i][k],
                })
                .collect(),
        )
    };
    let enthalpy = Values::F32(
        (0..st.len())
            .map(|i| match wall(i) {
                true => 0.0,
                false => m.phases[st.phase[i] as usize].absolute_enthalpy(st.heat[i][0]) as f32,
            })
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
