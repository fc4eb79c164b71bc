//! VTK series for ParaView: one binary `.vtu` (XML UnstructuredGrid, raw appended
//! data, UInt64 headers) per frame with every per-particle field, and a `.pvd`
//! collection with the simulated times. Both are written to a temporary name and
//! renamed, so a run stopped at any moment leaves only complete files.

use super::{particle_fields, write_atomic, Field, Values};
use crate::model::Model;
use crate::state::State;
use std::fmt::Write as _;
use std::path::PathBuf;

pub const COLLECTION: &str = "particles.pvd";

pub struct VtkSink {
    dir: PathBuf,
    /// (simulated time, file name) of every frame written.
    frames: Vec<(f64, String)>,
    last_frame_step: Option<u32>,
}

impl VtkSink {
    pub fn create(dir: &str) -> Result<VtkSink, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{dir}: cannot create VTK folder: {e}"))?;
        Ok(VtkSink {
            dir: PathBuf::from(dir),
            frames: Vec::new(),
            last_frame_step: None,
        })
    }

    pub fn frame(&mut self, m: &Model, st: &State) -> Result<(), String> {
        if self.last_frame_step == Some(st.sim.step) {
            return Ok(());
        }
        let name = format!("frame_{:06}.vtu", self.frames.len());
        let bytes = vtu_bytes(&particle_fields(m, st));
        write_atomic(&self.dir.join(&name), &bytes)?;
        self.frames.push((st.sim.time as f64, name));
        self.last_frame_step = Some(st.sim.step);
        write_atomic(
            &self.dir.join(COLLECTION),
            pvd_text(&self.frames).as_bytes(),
        )
    }
}

fn pvd_text(frames: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, name) in frames {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t:e}\" part=\"0\" file=\"{name}\"/>"
        );
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// Raw appended blocks and the XML that points into them.
struct Appended {
    data: Vec<u8>,
    xml: String,
}

impl Appended {
    fn array(&mut self, vtk_type: &str, name: Option<&str>, components: usize, bytes: &[u8]) {
        let name = name.map(|n| format!(" Name=\"{n}\"")).unwrap_or_default();
        let _ = writeln!(
            self.xml,
            "        <DataArray type=\"{vtk_type}\"{name} NumberOfComponents=\"{components}\" format=\"appended\" offset=\"{}\"/>",
            self.data.len()
        );
        self.data
            .extend_from_slice(&(bytes.len() as u64).to_le_bytes());
        self.data.extend_from_slice(bytes);
    }
}

fn le_bytes(v: &Values) -> (Vec<u8>, &'static str) {
    match v {
        Values::F32(x) => (x.iter().flat_map(|f| f.to_le_bytes()).collect(), "Float32"),
        Values::U32(x) => (x.iter().flat_map(|f| f.to_le_bytes()).collect(), "UInt32"),
    }
}

fn interleave3(a: &Values, b: &Values, c: &Values) -> Vec<u8> {
    (0..a.len())
        .flat_map(|i| [a.le_bytes(i), b.le_bytes(i), c.le_bytes(i)])
        .flatten()
        .collect()
}

/// The whole `.vtu` file for one frame: x/y/z become the points, vx/vy/vz the
/// `velocity` vector, every other field a scalar array; each particle a vertex cell.
pub fn vtu_bytes(fields: &[Field]) -> Vec<u8> {
    let get = |n: &str| {
        &fields
            .iter()
            .find(|f| f.name == n)
            .expect("position/velocity fields")
            .values
    };
    let n = get("x").len();
    let mut point_data = Appended {
        data: Vec::new(),
        xml: String::new(),
    };
    point_data.array(
        "Float32",
        Some("velocity"),
        3,
        &interleave3(get("vx"), get("vy"), get("vz")),
    );
    for f in fields {
        if ["x", "y", "z", "vx", "vy", "vz"].contains(&f.name) {
            continue;
        }
        let (bytes, ty) = le_bytes(&f.values);
        point_data.array(ty, Some(f.name), 1, &bytes);
    }
    let pd_xml = std::mem::take(&mut point_data.xml);
    point_data.array(
        "Float32",
        None,
        3,
        &interleave3(get("x"), get("y"), get("z")),
    );
    let points_xml = std::mem::take(&mut point_data.xml);
    let idx: Vec<u8> = (0..n as i64).flat_map(|i| i.to_le_bytes()).collect();
    let offsets: Vec<u8> = (1..=n as i64).flat_map(|i| i.to_le_bytes()).collect();
    point_data.array("Int64", Some("connectivity"), 1, &idx);
    point_data.array("Int64", Some("offsets"), 1, &offsets);
    const VTK_VERTEX: u8 = 1;
    point_data.array("UInt8", Some("types"), 1, &vec![VTK_VERTEX; n]);
    let cells_xml = point_data.xml;
    let mut out = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">\n      <PointData Scalars=\"density\" Vectors=\"velocity\">\n{pd_xml}      </PointData>\n      <Points>\n{points_xml}      </Points>\n      <Cells>\n{cells_xml}      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _"
    )
    .into_bytes();
    out.extend_from_slice(&point_data.data);
    out.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    out
}
