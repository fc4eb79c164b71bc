//! MCAP stream: `/particles` (foxglove.PointCloud, protobuf), `/diagnostics`,
//! `/removed` (one message per particle leaving the domain) and, in scenes with a
//! laser and melting, `/track` (one message at the end: crate::track), in scenes
//! with rigid bodies `/bodies` (one message per frame) (JSON with
//! JSON schemas), zstd-compressed chunks, the resolved scenario as
//! metadata. Every message closes its chunk and flushes, so a process killed hard
//! leaves a file readable up to its last message; `finish` (or Drop) writes the
//! summary and footer on every other ending.

use super::pointcloud;
use super::{diagnostics_schema, particle_fields, time_ns, Diagnostics};
use crate::model::Model;
use crate::state::State;
use mcap::records::{MessageHeader, Metadata};
use mcap::{WriteOptions, Writer};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;

pub const PARTICLES_TOPIC: &str = "/particles";
pub const DIAGNOSTICS_TOPIC: &str = "/diagnostics";
pub const REMOVED_TOPIC: &str = "/removed";
pub const TRACK_TOPIC: &str = "/track";
pub const BODIES_TOPIC: &str = "/bodies";
/// Name of the metadata record holding the run's provenance.
pub const METADATA_NAME: &str = "spatter";

pub struct McapSink {
    path: String,
    writer: Option<Writer<BufWriter<File>>>,
    particles: u16,
    diagnostics: u16,
    removed: u16,
    track: Option<u16>,
    bodies: Option<u16>,
    /// Ids whose removal is written (None until the first state: a resumed run's
    /// earlier removals are in the earlier file).
    reported: Option<std::collections::HashSet<u32>>,
    sequence: u32,
    pub frames: u64,
    last_frame_step: Option<u32>,
}

/// What the file records so the run can be reproduced from it.
pub struct Provenance<'a> {
    pub backend: &'a str,
    pub command: &'a str,
}

impl McapSink {
    pub fn create(path: &str, m: &Model, prov: &Provenance) -> Result<McapSink, String> {
        let err = |e: &dyn std::fmt::Display| format!("{path}: cannot write MCAP: {e}");
        if let Some(dir) = std::path::Path::new(path)
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
        {
            std::fs::create_dir_all(dir).map_err(|e| err(&e))?;
        }
        let file = File::create(path).map_err(|e| err(&e))?;
        let mut w = WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .profile("")
            .library(format!("spatter {}", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(|e| err(&e))?;
        let pc_schema = w
            .add_schema(
                pointcloud::SCHEMA_NAME,
                "protobuf",
                &pointcloud::schema_descriptor_set(),
            )
            .map_err(|e| err(&e))?;
        let diag_schema = w
            .add_schema(
                "spatter.Diagnostics",
                "jsonschema",
                diagnostics_schema(m).to_string().as_bytes(),
            )
            .map_err(|e| err(&e))?;
        let removed_schema = w
            .add_schema(
                "spatter.Removal",
                "jsonschema",
                removal_schema().to_string().as_bytes(),
            )
            .map_err(|e| err(&e))?;
        let none = BTreeMap::new();
        let particles = w
            .add_channel(pc_schema, PARTICLES_TOPIC, "protobuf", &none)
            .map_err(|e| err(&e))?;
        let diagnostics = w
            .add_channel(diag_schema, DIAGNOSTICS_TOPIC, "json", &none)
            .map_err(|e| err(&e))?;
        let removed = w
            .add_channel(removed_schema, REMOVED_TOPIC, "json", &none)
            .map_err(|e| err(&e))?;
        let track = if crate::track::wanted(m) {
            let schema = w
                .add_schema(
                    "spatter.Track",
                    "jsonschema",
                    track_schema().to_string().as_bytes(),
                )
                .map_err(|e| err(&e))?;
            Some(
                w.add_channel(schema, TRACK_TOPIC, "json", &none)
                    .map_err(|e| err(&e))?,
            )
        } else {
            None
        };
        let bodies = if m.has_bodies() {
            let schema = w
                .add_schema(
                    "spatter.Bodies",
                    "jsonschema",
                    bodies_schema().to_string().as_bytes(),
                )
                .map_err(|e| err(&e))?;
            Some(
                w.add_channel(schema, BODIES_TOPIC, "json", &none)
                    .map_err(|e| err(&e))?,
            )
        } else {
            None
        };
        let meta = BTreeMap::from([
            (
                "spatter_version".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
            ("backend".to_string(), prov.backend.to_string()),
            ("command".to_string(), prov.command.to_string()),
            ("scenario_file".to_string(), m.file.clone()),
            ("scenario".to_string(), m.resolved_toml.clone()),
        ]);
        w.write_metadata(&Metadata {
            name: METADATA_NAME.into(),
            metadata: meta,
        })
        .map_err(|e| err(&e))?;
        w.flush().map_err(|e| err(&e))?;
        Ok(McapSink {
            path: path.to_string(),
            writer: Some(w),
            particles,
            diagnostics,
            removed,
            track,
            bodies,
            reported: None,
            sequence: 0,
            frames: 0,
            last_frame_step: None,
        })
    }

    fn write(&mut self, channel: u16, t: f64, data: &[u8]) -> Result<(), String> {
        let path = &self.path;
        let w = self
            .writer
            .as_mut()
            .ok_or_else(|| format!("{path}: MCAP already finished"))?;
        let header = MessageHeader {
            channel_id: channel,
            sequence: self.sequence,
            log_time: time_ns(t),
            publish_time: time_ns(t),
        };
        self.sequence += 1;
        w.write_to_known_channel(&header, data)
            .and_then(|_| w.flush())
            .map_err(|e| format!("{path}: cannot write MCAP: {e}"))
    }

    /// One `/particles` frame of the whole state (skipped if this step is written).
    pub fn frame(&mut self, m: &Model, st: &State) -> Result<(), String> {
        if self.last_frame_step == Some(st.sim.step) {
            return Ok(());
        }
        let t = st.sim.time as f64;
        let data = pointcloud::encode_frame(t, &particle_fields(m, st));
        self.write(self.particles, t, &data)?;
        if let Some(channel) = self.bodies {
            let json = serde_json::to_vec(&bodies_message(m, st)).map_err(|e| e.to_string())?;
            self.write(channel, t, &json)?;
        }
        self.frames += 1;
        self.last_frame_step = Some(st.sim.step);
        Ok(())
    }

    pub fn diagnostics(&mut self, d: &Diagnostics) -> Result<(), String> {
        let json = serde_json::to_vec(d).map_err(|e| e.to_string())?;
        self.write(self.diagnostics, d.time, &json)
    }

    /// One `/removed` message per particle that has left since the last state
    /// seen, logged at the time it left.
    pub fn removals(&mut self, m: &Model, st: &State) -> Result<(), String> {
        let Some(reported) = self.reported.as_mut() else {
            self.reported = Some(crate::outflow::removed_ids(st));
            return Ok(());
        };
        for e in crate::outflow::new_removals(m, st, reported) {
            let json = serde_json::to_vec(&e).map_err(|e| e.to_string())?;
            self.write(self.removed, e.time, &json)?;
        }
        Ok(())
    }

    /// The `/track` message (scenes with a track only), at the run's end time.
    pub fn track(&mut self, time: f64, profile: &crate::track::TrackProfile) -> Result<(), String> {
        let Some(channel) = self.track else {
            return Ok(());
        };
        let json = serde_json::to_vec(profile).map_err(|e| e.to_string())?;
        self.write(channel, time, &json)
    }

    /// Write the summary and footer. Safe to call more than once.
    pub fn finish(&mut self) -> Result<(), String> {
        if let Some(mut w) = self.writer.take() {
            w.finish()
                .map_err(|e| format!("{}: cannot finish MCAP: {e}", self.path))?;
        }
        Ok(())
    }
}

/// A `/bodies` message: every rigid body's motion at one frame.
fn bodies_message(m: &Model, st: &State) -> serde_json::Value {
    let bodies: Vec<serde_json::Value> = st
        .bodies
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let mo = crate::bodies::BodyMotion::of(m, b);
            serde_json::json!({
                "body": k + 1,
                "position": mo.position,
                "orientation": mo.orientation,
                "velocity": mo.velocity,
                "angular_velocity": mo.angular_velocity,
                "mass": mo.mass,
                "particles": b.count,
                "molten_fraction": b.molten_fraction(),
                "bonded": b.bonded != 0,
            })
        })
        .collect();
    serde_json::json!({"time": st.sim.time as f64, "bodies": bodies})
}

/// JSON schema of a `/bodies` message.
fn bodies_schema() -> serde_json::Value {
    let vec = |n: usize, desc: &str| serde_json::json!({"type": "array", "items": {"type": "number"}, "minItems": n, "maxItems": n, "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Bodies",
        "description": "Every rigid body's motion at one frame (issue 17).",
        "type": "object",
        "properties": {
            "time": {"type": "number", "description": "s"},
            "bodies": {"type": "array", "items": {
                "type": "object",
                "properties": {
                    "body": {"type": "integer", "description": "index + 1, as the frames' `body` channel"},
                    "position": vec(3, "centre of mass, world coordinates (m)"),
                    "orientation": vec(4, "unit quaternion (x, y, z, w) from the body's principal frame to world"),
                    "velocity": vec(3, "of the centre of mass (m/s)"),
                    "angular_velocity": vec(3, "world frame (rad/s)"),
                    "mass": {"type": "number", "description": "kg (kg per metre of depth in 2D)"},
                    "particles": {"type": "integer", "description": "member particles (melted ones have left)"},
                    "molten_fraction": {"type": "number", "description": "fraction of the body's initial particles that melted away"},
                    "bonded": {"type": "boolean", "description": "bonded into the substrate by melt that solidified against it (then fixed)"}
                },
                "required": ["body", "position", "orientation", "velocity", "angular_velocity", "mass", "particles", "molten_fraction", "bonded"]
            }}
        },
        "required": ["time", "bodies"]
    })
}

/// JSON schema of a `/removed` message (crate::outflow::RemovalEvent).
fn removal_schema() -> serde_json::Value {
    let num = |desc: &str| serde_json::json!({"type": "number", "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Removal",
        "type": "object",
        "properties": {
            "id": {"type": "integer", "description": "particle id"},
            "phase": {"type": "string", "description": "its phase"},
            "time": num("when it left, s"),
            "side": {"type": "string", "description": "the side it left through (x_min ... z_max)"},
            "x": num("where it was at the end of that step, m"),
            "y": num("m"),
            "z": num("m"),
            "speed": num("its speed then, m/s"),
            "mass": num("kg (per metre of depth in 2D)")
        },
        "required": ["id", "phase", "time", "side", "x", "y", "z", "speed", "mass"]
    })
}

/// JSON schema of the `/track` message (crate::track::TrackProfile).
fn track_schema() -> serde_json::Value {
    let num = |desc: &str| serde_json::json!({"type": "number", "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Track",
        "type": "object",
        "properties": {
            "dx": num("slice width along x, m"),
            "slices": {
                "type": "array",
                "description": "slices of width dx along x that the melt reached, in x order",
                "items": {
                    "type": "object",
                    "properties": {
                        "x": num("slice centre, m"),
                        "initial_surface": num("top of the condensed material at the start, m (up axis)"),
                        "depth": num("depth the melt reached below the initial surface, m"),
                        "width": num("extent of the melt along y, m (0 in 2D)"),
                        "height": num("resolidified surface minus initial surface, m (on the beam line in 3D)"),
                        "peak_temperature": num("K")
                    }
                }
            },
            "pool": {
                "type": "object",
                "description": "the melt pool's extremes over the run's samples",
                "properties": {
                    "max_temperature": num("K"),
                    "max_temperature_time": num("s"),
                    "max_depth": num("m, below the top of the condensed material"),
                    "max_depth_time": num("s"),
                    "max_length": num("extent along x, m"),
                    "max_width": num("extent along y, m (0 in 2D)"),
                    "max_depression": num("deepest the surface under the beam sank below the initial surface, m"),
                    "max_depression_time": num("s")
                }
            }
        },
        "required": ["dx", "slices", "pool"]
    })
}

impl Drop for McapSink {
    fn drop(&mut self) {
        // Any ending that skipped `finish` (an error path, a panic unwinding) still
        // leaves a complete file.
        let _ = self.finish();
    }
}
