//! The buffer registry (spatter::fields::FIELDS and TABLES, the GPU's
//! DEVICE_BUFFERS) and the WGSL passes describe the same buffers: each pass binds
//! exactly what its header names (`// reads:`, `// writes:`, its libraries'
//! `// reads:`), numbered in registry order, read-only unless written; each
//! field's WGSL array has the field's element type. Checked through naga on the
//! composed sources, so a buffer used but not named, or named but declared
//! differently, fails here.

use spatter::backend::gpu::{bindable, pass_bindings, shader_sources};
use spatter::fields::{FIELDS, TABLES};

/// The per-stage storage-buffer limit this project must fit (lavapipe's and
/// wgpu's default `max_storage_buffers_per_shader_stage`).
const MAX_STORAGE_BUFFERS_PER_PASS: usize = 8 * 4;

/// (binding, name, writable) of every group-0 global of a composed pass.
fn reflected(name: &str, src: &str) -> Vec<(u32, String, bool)> {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(src)));
    let mut out: Vec<(u32, String, bool)> = module
        .global_variables
        .iter()
        .filter_map(|(_, g)| {
            // Group 1 is the sort's stage uniform (neighbors.wgsl), not a buffer.
            let b = g.binding.as_ref().filter(|b| b.group == 0)?;
            let writable = match g.space {
                naga::AddressSpace::Storage { access } => {
                    access.contains(naga::StorageAccess::STORE)
                }
                _ => false,
            };
            Some((b.binding, g.name.clone().unwrap_or_default(), writable))
        })
        .collect();
    out.sort_by_key(|b| b.0);
    out
}

fn pass_source(name: &str) -> &'static str {
    spatter::backend::gpu::shaders::PASSES
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap()
        .1
}

#[test]
fn each_pass_binds_what_its_header_names() {
    for (name, composed) in shader_sources() {
        let header = pass_bindings(pass_source(name)).unwrap();
        let mut want: Vec<(u32, String, bool)> = vec![(0, "P".to_string(), false)];
        want.extend(
            header
                .iter()
                .map(|b| (b.binding, b.name.to_string(), b.read_write())),
        );
        assert_eq!(reflected(name, &composed), want, "{name}.wgsl");
        assert!(
            header.len() <= MAX_STORAGE_BUFFERS_PER_PASS,
            "{name}: {} storage buffers",
            header.len()
        );
    }
}

/// A pass's `// writes:` line is complete: naga rejects a store to a buffer
/// declared `read`, so every pass validates only if it is (tests/shaders.rs
/// validates them all); here, the converse: a written buffer is declared
/// read_write and an unwritten one read-only.
#[test]
fn written_buffers_are_read_write_and_the_rest_read_only() {
    let src = "// uses: params\n// reads: pos vel\n// writes: acc\nfn f() {}\n";
    let b = pass_bindings(src).unwrap();
    let get = |n: &str| b.iter().find(|x| x.name == n).unwrap().read_write();
    assert!(get("acc"));
    assert!(!get("pos") && !get("vel"));
}

/// Every field, scratch and table is declared with its row's element type.
#[test]
fn every_buffer_has_its_rows_element_type() {
    let mut src = String::from(include_str!("../shaders/lib/params.wgsl"));
    for (k, b) in bindable().iter().enumerate() {
        src.push_str(&format!(
            "@group(0) @binding({}) var<storage, read_write> {}: {};\n",
            k + 1,
            b.name,
            b.wgsl
        ));
    }
    let module = naga::front::wgsl::parse_str(&src).unwrap();
    let elem = |name: &str| -> naga::TypeInner {
        let g = module
            .global_variables
            .iter()
            .find(|(_, g)| g.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no binding {name}"))
            .1;
        match &module.types[g.ty].inner {
            naga::TypeInner::Array { base, .. } => module.types[*base].inner.clone(),
            other => other.clone(),
        }
    };
    for f in &FIELDS {
        for name in std::iter::once(f.binding).chain(f.scratch) {
            let (components, scalar) = match elem(name) {
                naga::TypeInner::Scalar(s) => (1, s),
                naga::TypeInner::Vector { size, scalar } => (size as usize, scalar),
                other => panic!("{name}: {other:?}"),
            };
            assert_eq!(components, f.components, "{name}");
            assert_eq!(scalar.width, 4, "{name}");
            assert_eq!(scalar.kind == naga::ScalarKind::Float, f.is_float, "{name}");
        }
    }
    for t in &TABLES {
        let size = match elem(t.name) {
            naga::TypeInner::Struct { span, .. } => span as usize,
            naga::TypeInner::Scalar(s) => s.width as usize,
            naga::TypeInner::Atomic(s) => s.width as usize,
            other => panic!("{}: {other:?}", t.name),
        };
        assert_eq!(size, 4 * t.components, "{}", t.name);
    }
}

/// What setup allocates (fields::Held::of_model) is what the schedule runs on
/// (Pipeline::held), for every validation scene.
#[test]
fn the_models_holders_are_the_schedules() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/validation");
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let l = spatter::run::load(path.to_str().unwrap(), &[]).unwrap();
        let params = spatter::params::Params::new(&l.model, l.state.len() as u32);
        let pipeline = spatter::backend::Pipeline::for_scene(&params, &l.state);
        assert_eq!(
            spatter::fields::Held::of_model(&l.model),
            pipeline.held(),
            "{}",
            path.display()
        );
        assert_eq!(
            spatter::fields::Held::of_state(&l.state),
            pipeline.held(),
            "{}",
            path.display()
        );
    }
}

/// A scene runs only its formulation's passes and holds only their fields:
/// summation density and no continuity state on WCSPH; the continuity pass,
/// its fields and the sorted density on δ-SPH (and no summation-density pass).
#[test]
fn a_formulation_runs_and_holds_only_its_own() {
    use spatter::backend::{Pipeline, Stage};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/validation/dam_break_2d.toml"
    );
    for (sets, delta) in [
        (vec![], false),
        (
            vec!["simulation.formulation=\"delta_wcsph\"".to_string()],
            true,
        ),
    ] {
        let l = spatter::run::load(path, &sets).unwrap();
        let params = spatter::params::Params::new(&l.model, l.state.len() as u32);
        let p = Pipeline::for_scene(&params, &l.state);
        let stages = p.step_stages();
        assert_eq!(stages.contains(&Stage::Continuity), delta, "{sets:?}");
        assert_eq!(stages.contains(&Stage::Density), !delta, "{sets:?}");
        assert_eq!(p.held().continuity, delta);
        assert_eq!(!l.state.continuity.is_empty(), delta);
        assert_eq!(!l.state.density_gradient.is_empty(), delta);
        let rho = FIELDS.iter().find(|f| f.binding == "rho").unwrap();
        assert_eq!(
            rho.sorted_in(p.held()),
            delta,
            "the density is state only on δ-SPH"
        );
    }
}
