//! MCAP stream: `/particles` (foxglove.PointCloud, protobuf), the JSON topics the
//! run declares at creation (each with its JSON schema: crate::diagnostics::topics
//! lists `/diagnostics`, `/removed`, `/track` and `/bodies`), zstd-compressed
//! chunks, the resolved scenario as metadata. Every message closes its chunk and
//! flushes, so a process killed hard leaves a file readable up to its last
//! message; `finish` (or Drop) writes the summary and footer on every other
//! ending.

use super::pointcloud;
use super::{particle_fields, time_ns};
use crate::model::Model;
use crate::state::State;
use mcap::records::{MessageHeader, Metadata};
use mcap::{WriteOptions, Writer};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;

pub const PARTICLES_TOPIC: &str = "/particles";
/// Name of the metadata record holding the run's provenance.
pub const METADATA_NAME: &str = "spatter";

/// A JSON topic of the stream: its name, and the name and JSON schema of its
/// messages.
pub struct JsonTopic {
    pub topic: &'static str,
    pub schema_name: &'static str,
    pub schema: serde_json::Value,
}

pub struct McapSink {
    path: String,
    writer: Option<Writer<BufWriter<File>>>,
    particles: u16,
    /// The channel of each JSON topic, by topic name.
    json: BTreeMap<&'static str, u16>,
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
    /// A new stream at `path` with `/particles` and the JSON `topics`. Every
    /// schema is written before every channel (point cloud first, then the topics
    /// in order), so schema and channel ids follow the order of `topics`.
    pub fn create(
        path: &str,
        m: &Model,
        prov: &Provenance,
        topics: &[JsonTopic],
    ) -> Result<McapSink, String> {
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
        let mut schemas = Vec::new();
        for t in topics {
            let text = t.schema.to_string();
            schemas.push(
                w.add_schema(t.schema_name, "jsonschema", text.as_bytes())
                    .map_err(|e| err(&e))?,
            );
        }
        let none = BTreeMap::new();
        let particles = w
            .add_channel(pc_schema, PARTICLES_TOPIC, "protobuf", &none)
            .map_err(|e| err(&e))?;
        let mut json = BTreeMap::new();
        for (t, &schema) in topics.iter().zip(&schemas) {
            let channel = w
                .add_channel(schema, t.topic, "json", &none)
                .map_err(|e| err(&e))?;
            json.insert(t.topic, channel);
        }
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
            json,
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

    /// One `/particles` frame of the whole state; false, writing nothing, when
    /// this step's frame is written already.
    pub fn frame(&mut self, m: &Model, st: &State) -> Result<bool, String> {
        if self.last_frame_step == Some(st.sim.step) {
            return Ok(false);
        }
        let t = st.sim.time as f64;
        let data = pointcloud::encode_frame(t, &particle_fields(m, st));
        self.write(self.particles, t, &data)?;
        self.frames += 1;
        self.last_frame_step = Some(st.sim.step);
        Ok(true)
    }

    /// Whether the stream has the JSON topic `topic`.
    pub fn has(&self, topic: &str) -> bool {
        self.json.contains_key(topic)
    }

    /// One message on the JSON topic `topic`, logged at time `t`; nothing when
    /// the stream lacks the topic (a scene without a track, say).
    pub fn message(
        &mut self,
        topic: &str,
        t: f64,
        msg: &impl serde::Serialize,
    ) -> Result<(), String> {
        let Some(&channel) = self.json.get(topic) else {
            return Ok(());
        };
        let json = serde_json::to_vec(msg).map_err(|e| e.to_string())?;
        self.write(channel, t, &json)
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

impl Drop for McapSink {
    fn drop(&mut self) {
        // Any ending that skipped `finish` (an error path, a panic unwinding) still
        // leaves a complete file.
        let _ = self.finish();
    }
}
