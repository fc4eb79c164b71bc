//! The parameter block is declared twice, in src/params.rs and in
//! shaders/lib/params.wgsl. naga (wgpu's shader compiler) lays the WGSL struct out
//! by the uniform-buffer rules; every member must have the same name, type and
//! byte offset as the Rust field `offset_of!` reports, and the named bits and
//! codes must have the same values. A member renamed, retyped or moved on one side
//! only fails here, not as a silently wrong number in a pass.

use spatter::gpu_layout::{flatten, GpuLayout, GpuType};
use spatter::params as rs;

const PARAMS_WGSL: &str = include_str!("../shaders/lib/params.wgsl");

/// The WGSL struct `name` as the same flattened lines `gpu_layout::flatten` prints.
fn wgsl_layout(src: &str, name: &str) -> Result<Vec<String>, String> {
    let module = naga::front::wgsl::parse_str(src).map_err(|e| e.emit_to_string(src))?;
    let (handle, _) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .ok_or_else(|| format!("no struct {name} in the WGSL"))?;
    let mut out = Vec::new();
    walk(&module, handle, "", 0, &mut out)?;
    Ok(out)
}

fn walk(
    module: &naga::Module,
    ty: naga::Handle<naga::Type>,
    path: &str,
    base: u32,
    out: &mut Vec<String>,
) -> Result<(), String> {
    use naga::{ScalarKind, TypeInner, VectorSize};
    let t = &module.types[ty];
    let four_byte = |s: &naga::Scalar| s.width == 4;
    match &t.inner {
        TypeInner::Struct { members, .. } => {
            for m in members {
                let name = m.name.clone().unwrap_or_default();
                let p = if path.is_empty() {
                    name
                } else {
                    format!("{path}.{name}")
                };
                walk(module, m.ty, &p, base + m.offset, out)?;
            }
        }
        TypeInner::Array {
            base: elem,
            size,
            stride,
        } => {
            let naga::ArraySize::Constant(len) = size else {
                return Err(format!("{path}: runtime-sized array"));
            };
            out.push(format!("{path} @{base} array len {len} stride {stride}"));
            walk(module, *elem, &format!("{path}[]"), base, out)?;
        }
        TypeInner::Scalar(s) if four_byte(s) && s.kind == ScalarKind::Float => {
            out.push(format!("{path} @{base} {:?}", GpuType::F32))
        }
        TypeInner::Scalar(s) if four_byte(s) && s.kind == ScalarKind::Uint => {
            out.push(format!("{path} @{base} {:?}", GpuType::U32))
        }
        TypeInner::Vector {
            size: VectorSize::Quad,
            scalar,
        } if four_byte(scalar) => {
            let ty = match scalar.kind {
                ScalarKind::Float => GpuType::Vec4F32,
                ScalarKind::Uint => GpuType::Vec4U32,
                other => return Err(format!("{path}: vec4 of {other:?}")),
            };
            out.push(format!("{path} @{base} {ty:?}"));
        }
        other => {
            return Err(format!(
                "{path}: {other:?} has no Rust twin (f32, u32, vec4 only)"
            ))
        }
    }
    Ok(())
}

fn rust_layout() -> Vec<String> {
    flatten(&rs::Params::gpu_type())
}

/// The lines that differ, each side's own, in order.
fn mismatches(rust: &[String], wgsl: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    for k in 0..rust.len().max(wgsl.len()) {
        let (a, b) = (rust.get(k), wgsl.get(k));
        if a != b {
            out.push(format!(
                "rust: {}  |  wgsl: {}",
                a.map_or("-", |s| s),
                b.map_or("-", |s| s)
            ));
        }
    }
    out
}

fn naga_struct_size(src: &str, name: &str) -> u32 {
    let module = naga::front::wgsl::parse_str(src).unwrap();
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (h, _) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap();
    layouter[h].size
}

#[test]
fn wgsl_params_match_rust_member_for_member() {
    let wgsl = wgsl_layout(PARAMS_WGSL, "Params").unwrap();
    let rust = rust_layout();
    let bad = mismatches(&rust, &wgsl);
    assert!(bad.is_empty(), "Params differ:\n{}", bad.join("\n"));
    assert!(
        rust.len() > 100,
        "every member is compared ({} lines)",
        rust.len()
    );
    assert_eq!(
        naga_struct_size(PARAMS_WGSL, "Params") as usize,
        std::mem::size_of::<rs::Params>(),
        "block size"
    );
    // The Sim block and the body table are read back by bytes: same size.
    assert_eq!(
        naga_struct_size(PARAMS_WGSL, "Sim") as usize,
        std::mem::size_of::<spatter::state::Sim>()
    );
    assert_eq!(
        naga_struct_size(PARAMS_WGSL, "Body") as usize,
        std::mem::size_of::<spatter::state::Body>()
    );
    assert_eq!(
        naga_struct_size(PARAMS_WGSL, "Solver") as usize,
        std::mem::size_of::<spatter::state::Solver>()
    );
}

/// The check itself: a member renamed or moved on one side only is reported.
#[test]
fn a_member_renamed_or_moved_on_one_side_is_reported() {
    let rust = rust_layout();
    // Renamed in WGSL only.
    let renamed = PARAMS_WGSL.replacen("    support2: f32,", "    support_sq: f32,", 1);
    let bad = mismatches(&rust, &wgsl_layout(&renamed, "Params").unwrap());
    assert!(
        bad.iter()
            .any(|l| l.contains("kernel.support2") && l.contains("kernel.support_sq")),
        "{bad:?}"
    );
    // Two members swapped in WGSL only: same names, different offsets.
    let swapped = PARAMS_WGSL.replacen(
        "    h: f32,\n    inv_h: f32,",
        "    inv_h: f32,\n    h: f32,",
        1,
    );
    assert_ne!(swapped, PARAMS_WGSL);
    let bad = mismatches(&rust, &wgsl_layout(&swapped, "Params").unwrap());
    assert_eq!(bad.len(), 2, "{bad:?}");
    // Renamed on the Rust side only (its flattened line as the macro would print it).
    let mut rust_renamed = rust.clone();
    let k = rust
        .iter()
        .position(|l| l.starts_with("phases[].eta @"))
        .unwrap();
    rust_renamed[k] = rust[k].replace("eta", "viscosity");
    let wgsl = wgsl_layout(PARAMS_WGSL, "Params").unwrap();
    assert_eq!(mismatches(&rust_renamed, &wgsl).len(), 1);
    // A type WGSL has and Rust cannot mirror is an error, not a pass.
    let vec3 = PARAMS_WGSL.replacen("    gravity: vec4<f32>,", "    gravity: vec3<f32>,", 1);
    assert!(wgsl_layout(&vec3, "Params").is_err());
}

/// Named bits and codes: the WGSL constants equal the Rust ones.
#[test]
fn flag_and_code_constants_match() {
    let module = naga::front::wgsl::parse_str(PARAMS_WGSL).unwrap();
    let value = |name: &str| -> u32 {
        let c = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no WGSL constant {name}"))
            .1;
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref other => panic!("{name}: {other:?}"),
        }
    };
    let expected = [
        ("FLAG_PRESSURE_FLOOR", rs::FLAG_PRESSURE_FLOOR),
        ("FLAG_VISCOUS_HEATING", rs::FLAG_VISCOUS_HEATING),
        ("FLAG_HEAT", rs::FLAG_HEAT),
        ("FLAG_INTERFACE", rs::FLAG_INTERFACE),
        ("FLAG_GAS_INTERFACE", rs::FLAG_GAS_INTERFACE),
        ("FLAG_SURFACE_TENSION", rs::FLAG_SURFACE_TENSION),
        ("FLAG_RECOIL", rs::FLAG_RECOIL),
        ("FLAG_FREE_SURFACE_TENSION", rs::FLAG_FREE_SURFACE_TENSION),
        ("FLAG_WETTING", rs::FLAG_WETTING),
        ("FLAG_BODIES", rs::FLAG_BODIES),
        ("FLAG_CONTINUITY", rs::FLAG_CONTINUITY),
        ("FLAG_MARRONE_VISCOSITY", rs::FLAG_MARRONE_VISCOSITY),
        ("NO_BODY", spatter::state::NO_BODY),
        ("NO_PHASE", rs::NO_PHASE),
        ("KIND_LIQUID", rs::KIND_LIQUID),
        ("KIND_GAS", rs::KIND_GAS),
        ("KIND_WALL", rs::KIND_WALL),
        ("KIND_SOLID", rs::KIND_SOLID),
        ("HEAT_DIRICHLET", rs::HEAT_DIRICHLET),
        ("HEAT_MELTS", rs::HEAT_MELTS),
        ("HEAT_LIQUID", rs::HEAT_LIQUID),
        ("HEAT_SWITCH_SHIFT", rs::HEAT_SWITCH_SHIFT),
        ("PHASE_FREE_SLIP", rs::PHASE_FREE_SLIP),
        ("PHASE_MOVES", rs::PHASE_MOVES),
        ("LASER_BEER_LAMBERT", rs::LASER_BEER_LAMBERT),
        ("LASER_SURFACE", rs::LASER_SURFACE),
        ("HEAT_EULER", rs::HEAT_EULER),
        ("HEAT_TRAPEZOIDAL", rs::HEAT_TRAPEZOIDAL),
        ("SOLVER_HEAT", spatter::backend::SolverSlot::Heat as u32),
    ];
    for (name, v) in expected {
        assert_eq!(value(name), v, "{name}");
    }
    use spatter::state as st;
    let slots = [
        ("H_ENTHALPY", st::H_ENTHALPY),
        ("H_TEMPERATURE", st::H_TEMPERATURE),
        ("H_LIQUID", st::H_LIQUID),
        ("H_RATE", st::H_RATE),
        ("S_DELTA", st::S_DELTA),
        ("S_SHEPARD", st::S_SHEPARD),
        ("S_CURVATURE", st::S_CURVATURE),
        ("S_RAW_CURVATURE", st::S_RAW_CURVATURE),
    ];
    for (name, v) in slots {
        assert_eq!(value(name), v as u32, "{name}");
    }
    for d in &spatter::model::limits::LIMITS {
        assert_eq!(value(d.wgsl), d.limit.code(), "{}", d.wgsl);
    }
}
