//! Checkpoints: the full particle state plus the scenario that produced it, so
//! `spatter run --resume FILE` continues bit-identically on the same backend.
//!
//! Layout (little-endian): magic `SPATCKPT`, u32 format version, u32 reserved,
//! u64 header length, JSON header, then the arrays in `State` order (pos, vel, acc,
//! acc_b as 4×f32; rho, p, mass as f32; phase, id as u32; heat as 4×f32 in heat
//! scenes; the interface, body and heat_start arrays where held), the tables
//! (crate::fields::TABLES: body table, member list, solver slots; their lengths
//! in the header), the 32-byte `Sim`
//! block, and a CRC-32 of everything before it. Files are written to a temporary
//! name and renamed, so a checkpoint on disk is always complete.

use crate::error::InputError;
use crate::fields::{Held, FIELDS, TABLES};
use crate::model::Model;
use crate::output::write_atomic;
use crate::state::{Sim, State};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"SPATCKPT";
// 2: a Dirichlet wall particle's fixed temperature is its heat.x (was 0; version 1
// files would resume with 0 K walls).
// 3: rigid bodies (body, body_offset, the body table and member list).
// 4: a body's particle inertia (inertia.w), bonded flag and initial member count
// (melting bodies; version 3 bodies would recompute with zero particle inertia).
// 5: every table of crate::fields::TABLES (bodies, members, solvers) with its
// length in the header's `tables`; the implicit heat's heat_start field.
// 6: a body's bonded flag may be BODY_LEFT (2: its centre left through an open
// side, its members stamped to leave). A binary older than that flag would read
// such a body as free and move it again. Version 5 files read as 6: the layout
// is the same, and those written since the flag (6883f4b) already carry it.
const FORMAT_VERSION: u32 = 6;
/// The oldest version this spatter reads (same layout as the current one).
const OLDEST_READ: u32 = 5;
/// Checkpoints kept per folder: the newest two, in case the newest is the one
/// a failing disk truncated.
const KEEP: usize = 2;

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Header {
    pub spatter_version: String,
    pub scenario_file: String,
    /// Resolved scenario TOML (after `--set`).
    pub scenario: String,
    pub backend: String,
    pub particles: u64,
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    /// The only random stream is the seeded setup jitter; the step loop draws no
    /// random numbers, so the seed is the whole RNG state.
    pub rng_seed: u64,
    pub rng_draws_after_setup: u64,
    /// The heat array (h, T, f_l, dh/dt) follows `id` (heat scenes).
    #[serde(default)]
    pub heat: bool,
    /// The interface array (2n × 4 f32) follows the heat array.
    #[serde(default)]
    pub surface: bool,
    /// Rigid bodies: the body and body_offset arrays follow the interface array.
    #[serde(default)]
    pub bodies: bool,
    /// Trapezoidal (Crank–Nicolson) heat: the heat_start array follows.
    #[serde(default)]
    pub heat_start: bool,
    /// δ-SPH: the continuity array follows (and the density is state).
    #[serde(default)]
    pub continuity: bool,
    /// A phase melts: the solidification record (2n × 4 f32, by id) follows.
    #[serde(default)]
    pub solidification: bool,
    /// DFSPH: the dfsph array follows.
    #[serde(default)]
    pub dfsph: bool,
    /// Entries of each table (crate::fields::TABLES), stored after the particle
    /// arrays in registry order; a table not named here is empty.
    #[serde(default)]
    pub tables: std::collections::BTreeMap<String, u64>,
}

pub struct Checkpoint {
    pub header: Header,
    pub state: State,
}

fn push<T: bytemuck::Pod>(out: &mut Vec<u8>, v: &[T]) {
    out.extend_from_slice(bytemuck::cast_slice(v));
}

pub fn encode(m: &Model, st: &State, backend: &str) -> Vec<u8> {
    let header = Header {
        spatter_version: env!("CARGO_PKG_VERSION").into(),
        scenario_file: m.file.clone(),
        scenario: m.resolved_toml.clone(),
        backend: backend.into(),
        particles: st.len() as u64,
        step: st.sim.step as u64,
        time: st.sim.time as f64,
        dt: st.sim.dt as f64,
        rng_seed: m.seed,
        rng_draws_after_setup: 0,
        heat: !st.heat.is_empty(),
        surface: !st.surface.is_empty(),
        bodies: !st.body.is_empty(),
        heat_start: !st.heat_start.is_empty(),
        continuity: !st.continuity.is_empty(),
        solidification: !st.solidification.is_empty(),
        dfsph: !st.dfsph.is_empty(),
        tables: TABLES
            .iter()
            .map(|t| (t.name.to_string(), t.entries(st) as u64))
            .collect(),
    };
    let json = serde_json::to_vec(&header).expect("checkpoint header serializes");
    let mut out = Vec::with_capacity(64 + json.len() + st.len() * 100);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(json.len() as u64).to_le_bytes());
    out.extend_from_slice(&json);
    // Every checkpointed field in registry order (an unheld one is empty).
    for f in FIELDS.iter().filter(|f| f.checkpointed) {
        push(&mut out, (f.words)(st));
    }
    for t in &TABLES {
        push(&mut out, (t.words)(st));
    }
    out.extend_from_slice(bytemuck::bytes_of(&st.sim));
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

struct Cursor<'a> {
    buf: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let s = self.buf.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(s)
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
}

pub fn decode(path: &str, bytes: &[u8]) -> Result<Checkpoint, InputError> {
    let bad = |msg: &str| {
        InputError::new(
            path,
            "",
            format!("not a readable spatter checkpoint: {msg}"),
        )
    };
    if bytes.len() < 28 || &bytes[..8] != MAGIC {
        return Err(bad("wrong magic bytes"));
    }
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    if crc32fast::hash(body).to_le_bytes() != crc {
        return Err(bad("CRC mismatch (file truncated or damaged)"));
    }
    let mut c = Cursor { buf: body, at: 8 };
    let version = c.u32().ok_or_else(|| bad("short file"))?;
    if !(OLDEST_READ..=FORMAT_VERSION).contains(&version) {
        return Err(bad(&format!(
            "format version {version}, this spatter reads {OLDEST_READ} to {FORMAT_VERSION}"
        )));
    }
    c.u32();
    let hlen = c.u64().ok_or_else(|| bad("short file"))? as usize;
    let header: Header = c
        .take(hlen)
        .and_then(|h| serde_json::from_slice(h).ok())
        .ok_or_else(|| bad("damaged header"))?;
    let n = header.particles as usize;
    let short = || bad("particle arrays shorter than the header says");
    let held = Held {
        heat: header.heat,
        interface: header.surface,
        bodies: header.bodies,
        implicit_heat: header.heat_start,
        solvers: false, // a table, not a particle array
        continuity: header.continuity,
        solidification: header.solidification,
        dfsph: header.dfsph,
    };
    let mut state = State::default();
    for f in FIELDS.iter().filter(|f| f.checkpointed) {
        let count = if held.holds(f.holder) { n } else { 0 };
        let bytes = c.take(count * f.bytes_per_particle()).ok_or_else(short)?;
        (f.set)(&mut state, bytes);
    }
    for t in &TABLES {
        let entries = header.tables.get(t.name).copied().unwrap_or(0) as usize;
        let bytes = c.take(entries * t.components * 4).ok_or_else(short)?;
        (t.set)(&mut state, bytes);
    }
    state.sim =
        bytemuck::pod_read_unaligned::<Sim>(c.take(std::mem::size_of::<Sim>()).ok_or_else(short)?);
    if c.at != body.len() {
        return Err(bad("trailing bytes after the state"));
    }
    Ok(Checkpoint { header, state })
}

pub fn load(path: &str) -> Result<Checkpoint, InputError> {
    let bytes = std::fs::read(path)
        .map_err(|e| InputError::new(path, "", format!("cannot read checkpoint: {e}")))?;
    decode(path, &bytes)
}

/// Writes numbered checkpoints into one folder and keeps the newest `KEEP`.
pub struct CheckpointSink {
    dir: PathBuf,
    written: Vec<PathBuf>,
}

impl CheckpointSink {
    /// The folder is made on the first write, so a run that never checkpoints
    /// leaves none behind.
    pub fn create(dir: &str) -> Result<CheckpointSink, String> {
        if Path::new(dir).is_file() {
            return Err(format!("{dir}: is a file, not a folder for checkpoints"));
        }
        Ok(CheckpointSink {
            dir: PathBuf::from(dir),
            written: Vec::new(),
        })
    }

    /// Write a checkpoint named by its step; returns its path.
    pub fn write(&mut self, m: &Model, st: &State, backend: &str) -> Result<PathBuf, String> {
        let path = self.dir.join(format!("step_{:010}.ckpt", st.sim.step));
        if self.written.last() == Some(&path) {
            return Ok(path);
        }
        std::fs::create_dir_all(&self.dir).map_err(|e| {
            format!(
                "{}: cannot create checkpoint folder: {e}",
                self.dir.display()
            )
        })?;
        write_atomic(&path, &encode(m, st, backend))?;
        self.written.push(path.clone());
        while self.written.len() > KEEP {
            let old = self.written.remove(0);
            let _ = std::fs::remove_file(old);
        }
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::{decode, FORMAT_VERSION, MAGIC, OLDEST_READ};

    /// A file of the given version whose header is not JSON, with a valid CRC:
    /// the version gate is the only check it can pass.
    fn file_of_version(version: u32) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&version.to_le_bytes());
        out.extend_from_slice(&0u32.to_le_bytes());
        out.extend_from_slice(&4u64.to_le_bytes());
        out.extend_from_slice(b"junk");
        out.extend_from_slice(&[0u8; 8]);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// Version 5 files (the same layout) pass the gate and fail only on
    /// their junk header; older and newer versions are refused by number.
    #[test]
    fn only_versions_oldest_read_to_current_pass_the_gate() {
        for v in OLDEST_READ..=FORMAT_VERSION {
            let e = decode("f.ckpt", &file_of_version(v)).err().unwrap();
            assert!(e.to_string().contains("damaged header"), "{v}: {e}");
        }
        for v in [OLDEST_READ - 1, FORMAT_VERSION + 1] {
            let e = decode("f.ckpt", &file_of_version(v)).err().unwrap();
            assert!(
                e.to_string().contains(&format!("format version {v}")),
                "{v}: {e}"
            );
        }
    }
}
