//! `spatter inspect run.mcap`: what a run file holds — channels, schemas, message
//! counts, time span, particles per frame and the stored scenario. A file whose
//! writer was killed (no summary) is read record by record up to its last
//! complete chunk.

use crate::error::{InputError, SpatterError};
use crate::output::mcap_out::{METADATA_NAME, PARTICLES_TOPIC};
use crate::output::pointcloud::PointCloud;
use mcap::read::{LinearReader, Options};
use mcap::records::Record;
use prost::Message as _;
use std::collections::BTreeMap;
use std::fmt::Write as _;

#[derive(Default)]
struct ChannelStats {
    schema: String,
    encoding: String,
    messages: u64,
    first_ns: u64,
    last_ns: u64,
    /// Smallest and largest particle count per frame (`/particles` only).
    points: Option<(u64, u64)>,
}

pub struct Inspection {
    pub complete: bool,
    pub stopped_early: Option<String>,
    pub channels: BTreeMap<String, (u64, Option<(u64, u64)>)>,
    pub metadata: BTreeMap<String, String>,
    pub text: String,
}

pub fn inspect(path: &str) -> Result<Inspection, SpatterError> {
    let buf =
        std::fs::read(path).map_err(|e| InputError::new(path, "", format!("cannot read: {e}")))?;
    if !buf.starts_with(mcap::MAGIC) {
        return Err(InputError::new(path, "", "not an MCAP file (no magic bytes)").into());
    }
    let complete = matches!(mcap::Summary::read(&buf), Ok(Some(_)));
    let (stats, stopped_early) = message_stats(&buf);
    let metadata = spatter_metadata(&buf);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "file: {path} ({:.2} MiB)",
        buf.len() as f64 / 1048576.0
    );
    let _ = writeln!(
        text,
        "complete: {}",
        if complete {
            "yes (summary and footer present)"
        } else {
            "no (writer stopped before its summary; read up to the last complete chunk)"
        }
    );
    if let Some(e) = &stopped_early {
        let _ = writeln!(
            text,
            "reading stopped at a damaged or truncated record: {e}"
        );
    }
    for key in ["spatter_version", "backend", "command", "scenario_file"] {
        if let Some(v) = metadata.get(key) {
            let _ = writeln!(text, "{key}: {v}");
        }
    }
    let _ = writeln!(text, "channels:");
    for (topic, c) in &stats {
        let _ = write!(
            text,
            "  {topic}: schema {} ({}), {} messages, t = {:.6e} .. {:.6e} s",
            c.schema,
            c.encoding,
            c.messages,
            c.first_ns as f64 * 1e-9,
            c.last_ns as f64 * 1e-9
        );
        match c.points {
            Some((lo, hi)) if lo == hi => {
                let _ = write!(text, ", {lo} particles per frame");
            }
            Some((lo, hi)) => {
                let _ = write!(text, ", {lo}..{hi} particles per frame");
            }
            None => {}
        }
        text.push('\n');
    }
    if let Some(sc) = metadata.get("scenario") {
        let _ = writeln!(text, "scenario (resolved, after --set):");
        for line in sc.lines() {
            let _ = writeln!(text, "  {line}");
        }
    }
    Ok(Inspection {
        complete,
        stopped_early,
        channels: stats
            .iter()
            .map(|(k, v)| (k.clone(), (v.messages, v.points)))
            .collect(),
        metadata,
        text,
    })
}

fn message_stats(buf: &[u8]) -> (BTreeMap<String, ChannelStats>, Option<String>) {
    let mut stats: BTreeMap<String, ChannelStats> = BTreeMap::new();
    let stream = match mcap::MessageStream::new_with_options(buf, Options::IgnoreEndMagic.into()) {
        Ok(s) => s,
        Err(e) => return (stats, Some(e.to_string())),
    };
    for msg in stream {
        let msg = match msg {
            Ok(m) => m,
            Err(e) => return (stats, Some(e.to_string())),
        };
        let c = stats.entry(msg.channel.topic.clone()).or_default();
        if c.messages == 0 {
            c.first_ns = msg.log_time;
            if let Some(s) = &msg.channel.schema {
                (c.schema, c.encoding) = (s.name.clone(), s.encoding.clone());
            }
        }
        c.messages += 1;
        c.first_ns = c.first_ns.min(msg.log_time);
        c.last_ns = c.last_ns.max(msg.log_time);
        if msg.channel.topic == PARTICLES_TOPIC {
            if let Ok(pc) = PointCloud::decode(&*msg.data) {
                let n = pc.data.len() as u64 / pc.point_stride.max(1) as u64;
                c.points = Some(c.points.map_or((n, n), |(lo, hi)| (lo.min(n), hi.max(n))));
            }
        }
    }
    (stats, None)
}

fn spatter_metadata(buf: &[u8]) -> BTreeMap<String, String> {
    let Ok(reader) = LinearReader::new_with_options(buf, Options::IgnoreEndMagic.into()) else {
        return BTreeMap::new();
    };
    for rec in reader {
        match rec {
            Ok(Record::Metadata(m)) if m.name == METADATA_NAME => return m.metadata,
            Ok(_) => {}
            Err(_) => break,
        }
    }
    BTreeMap::new()
}
