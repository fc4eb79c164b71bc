//! The parameter block is declared twice, in src/params.rs and in
//! shaders/lib/params.wgsl. encase lays the Rust struct out by WGSL's rules and
//! writes the bytes the passes bind; naga (wgpu's shader compiler) lays the WGSL
//! struct out by the same rules. Held against each other here: every member has
//! the same name and type in the same order on both sides, the block has the same
//! size, and a value probe (a distinct value in every word of the Rust struct,
//! written by encase) finds each member's value at the offset naga gives that
//! member, array elements and vector components included. The named bits and
//! codes must have the same values too. A member renamed, retyped or moved on one
//! side only fails here, not as a silently wrong number in a pass.

use spatter::gpu_layout::{flatten, GpuLayout, GpuType};
use spatter::params as rs;
use std::collections::HashMap;

const PARAMS_WGSL: &str = include_str!("../shaders/lib/params.wgsl");

/// One scalar or vector of the WGSL struct as naga lays it out: its path (array
/// elements as `name[k]`), byte offset and 4-byte words.
#[derive(Debug)]
struct Leaf {
    path: String,
    offset: u32,
    words: u32,
}

/// The WGSL struct `name`: the flattened lines `gpu_layout::flatten` prints, and
/// every leaf with its offset.
struct WgslLayout {
    lines: Vec<String>,
    leaves: Vec<Leaf>,
    size: u32,
}

fn wgsl_layout(src: &str, name: &str) -> Result<WgslLayout, String> {
    let module = naga::front::wgsl::parse_str(src).map_err(|e| e.emit_to_string(src))?;
    let (handle, _) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .ok_or_else(|| format!("no struct {name} in the WGSL"))?;
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| format!("{e:?}"))?;
    let mut out = WgslLayout {
        lines: Vec::new(),
        leaves: Vec::new(),
        size: layouter[handle].size,
    };
    walk(&module, handle, "", &mut out.lines)?;
    leaves(&module, handle, "", 0, &mut out.leaves)?;
    Ok(out)
}

/// The type of a scalar or vector member as `GpuType`, or why it has no Rust twin.
fn leaf_type(inner: &naga::TypeInner, path: &str) -> Result<Option<GpuType>, String> {
    use naga::{ScalarKind, TypeInner, VectorSize};
    let four_byte = |s: &naga::Scalar| s.width == 4;
    Ok(Some(match inner {
        TypeInner::Struct { .. } | TypeInner::Array { .. } => return Ok(None),
        TypeInner::Scalar(s) if four_byte(s) && s.kind == ScalarKind::Float => GpuType::F32,
        TypeInner::Scalar(s) if four_byte(s) && s.kind == ScalarKind::Uint => GpuType::U32,
        TypeInner::Vector {
            size: VectorSize::Quad,
            scalar,
        } if four_byte(scalar) => match scalar.kind {
            ScalarKind::Float => GpuType::Vec4F32,
            ScalarKind::Uint => GpuType::Vec4U32,
            other => return Err(format!("{path}: vec4 of {other:?}")),
        },
        other => {
            return Err(format!(
                "{path}: {other:?} has no Rust twin (f32, u32, vec4 only)"
            ))
        }
    }))
}

/// The flattened lines, as `gpu_layout::flatten` prints the Rust side.
fn walk(
    module: &naga::Module,
    ty: naga::Handle<naga::Type>,
    path: &str,
    out: &mut Vec<String>,
) -> Result<(), String> {
    use naga::TypeInner;
    match &module.types[ty].inner {
        TypeInner::Struct { members, .. } => {
            for m in members {
                let name = m.name.clone().unwrap_or_default();
                walk(module, m.ty, &spatter::gpu_layout::join(path, &name), out)?;
            }
        }
        TypeInner::Array {
            base: elem, size, ..
        } => {
            let naga::ArraySize::Constant(len) = size else {
                return Err(format!("{path}: runtime-sized array"));
            };
            out.push(format!("{path} array len {len}"));
            walk(module, *elem, &format!("{path}[]"), out)?;
        }
        other => {
            let ty = leaf_type(other, path)?.unwrap();
            out.push(format!("{path} {ty:?}"));
        }
    }
    Ok(())
}

/// Every leaf with naga's offset, each array element at its stride.
fn leaves(
    module: &naga::Module,
    ty: naga::Handle<naga::Type>,
    path: &str,
    base: u32,
    out: &mut Vec<Leaf>,
) -> Result<(), String> {
    use naga::TypeInner;
    match &module.types[ty].inner {
        TypeInner::Struct { members, .. } => {
            for m in members {
                let name = m.name.clone().unwrap_or_default();
                let p = spatter::gpu_layout::join(path, &name);
                leaves(module, m.ty, &p, base + m.offset, out)?;
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
            for k in 0..len.get() {
                leaves(
                    module,
                    *elem,
                    &format!("{path}[{k}]"),
                    base + k * stride,
                    out,
                )?;
            }
        }
        other => {
            let words = match leaf_type(other, path)?.unwrap() {
                GpuType::F32 | GpuType::U32 => 1,
                _ => 4,
            };
            out.push(Leaf {
                path: path.to_string(),
                offset: base,
                words,
            });
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

/// The value probe: every word of a Rust `Params` set to a distinct value
/// (1, 2, 3, … as bit patterns), the block serialised by encase as the GPU path
/// uploads it, and each WGSL leaf read at naga's offset. Returns the leaves whose
/// words are not the Rust member's of the same path (a member moved, or named
/// differently, on one side), and the Rust leaves no WGSL leaf names.
fn probe(wgsl: &WgslLayout) -> Vec<String> {
    let mut p: rs::Params = bytemuck::Zeroable::zeroed();
    let mut next = 0u32;
    let mut want: HashMap<String, Vec<u32>> = HashMap::new();
    p.visit_words("", &mut |path, words| {
        for w in words.iter_mut() {
            next += 1;
            *w = next;
        }
        want.insert(path.to_string(), words.to_vec());
    });
    let bytes = p.uniform_bytes();
    let word_at = |offset: u32| -> Option<u32> {
        let o = offset as usize;
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
    };
    let mut bad = Vec::new();
    for leaf in &wgsl.leaves {
        let got: Vec<Option<u32>> = (0..leaf.words)
            .map(|k| word_at(leaf.offset + 4 * k))
            .collect();
        match want.remove(&leaf.path) {
            Some(w) if w.iter().map(|&v| Some(v)).eq(got.iter().copied()) => {}
            Some(w) => bad.push(format!(
                "{} @{}: encase wrote {w:?} there, naga reads {got:?}",
                leaf.path, leaf.offset
            )),
            None => bad.push(format!("{}: no Rust member of that path", leaf.path)),
        }
    }
    let mut missing: Vec<String> = want.into_keys().collect();
    missing.sort();
    bad.extend(
        missing
            .into_iter()
            .map(|p| format!("{p}: no WGSL member of that path")),
    );
    bad
}

#[test]
fn wgsl_params_match_rust_member_for_member() {
    let wgsl = wgsl_layout(PARAMS_WGSL, "Params").unwrap();
    let rust = rust_layout();
    let bad = mismatches(&rust, &wgsl.lines);
    assert!(bad.is_empty(), "Params differ:\n{}", bad.join("\n"));
    assert!(
        rust.len() > 100,
        "every member is compared ({} lines)",
        rust.len()
    );
    // Every word encase writes is where naga reads that member.
    let bad = probe(&wgsl);
    assert!(
        bad.is_empty(),
        "Params values misplaced:\n{}",
        bad.join("\n")
    );
    assert!(
        wgsl.leaves.len() > 300,
        "{} leaves probed",
        wgsl.leaves.len()
    );
    // The block's size, as encase computes it and as it uploads it.
    let encase_size = <rs::Params as encase::ShaderType>::min_size().get();
    assert_eq!(encase_size, wgsl.size as u64, "block size");
    let zero: rs::Params = bytemuck::Zeroable::zeroed();
    assert_eq!(
        zero.uniform_bytes().len(),
        wgsl.size as usize,
        "uploaded size"
    );
    // The Sim block and the body table are read back by bytes: same size.
    let size = |name: &str| wgsl_layout(PARAMS_WGSL, name).unwrap().size as usize;
    assert_eq!(size("Sim"), std::mem::size_of::<spatter::state::Sim>());
    assert_eq!(size("Body"), std::mem::size_of::<spatter::state::Body>());
    assert_eq!(
        size("Solver"),
        std::mem::size_of::<spatter::state::Solver>()
    );
}

/// The check itself: a member renamed or moved on one side only is reported.
#[test]
fn a_member_renamed_or_moved_on_one_side_is_reported() {
    let rust = rust_layout();
    // Renamed in WGSL only: both the member lists and the probe see it.
    let renamed = PARAMS_WGSL.replacen("    support2: f32,", "    support_sq: f32,", 1);
    let wgsl = wgsl_layout(&renamed, "Params").unwrap();
    let bad = mismatches(&rust, &wgsl.lines);
    assert!(
        bad.iter()
            .any(|l| l.contains("kernel.support2") && l.contains("kernel.support_sq")),
        "{bad:?}"
    );
    let bad = probe(&wgsl);
    assert!(
        bad.iter().any(|l| l.starts_with("kernel.support_sq:")),
        "{bad:?}"
    );
    assert!(
        bad.iter().any(|l| l.starts_with("kernel.support2:")),
        "{bad:?}"
    );
    // Two members swapped in WGSL only: same names, other order and offsets.
    let swapped = PARAMS_WGSL.replacen(
        "    h: f32,\n    inv_h: f32,",
        "    inv_h: f32,\n    h: f32,",
        1,
    );
    assert_ne!(swapped, PARAMS_WGSL);
    let wgsl = wgsl_layout(&swapped, "Params").unwrap();
    assert_eq!(mismatches(&rust, &wgsl.lines).len(), 2);
    assert_eq!(probe(&wgsl).len(), 2, "{:?}", probe(&wgsl));
    // Moved in WGSL only, names and order unchanged: without the uniform
    // alignment time_step starts 8 bytes early; only the probe can see that.
    let moved = PARAMS_WGSL.replacen(
        "    @align(16) time_step: TimeStep,",
        "    time_step: TimeStep,",
        1,
    );
    assert_ne!(moved, PARAMS_WGSL);
    let wgsl = wgsl_layout(&moved, "Params").unwrap();
    assert!(mismatches(&rust, &wgsl.lines).is_empty());
    let bad = probe(&wgsl);
    assert_eq!(bad.len(), 8, "every time_step member: {bad:?}");
    assert!(bad.iter().all(|l| l.starts_with("time_step.")), "{bad:?}");
    // An array's stride changed in WGSL only (PathPoint without its alignment:
    // 12 bytes): the first element is in place, the next ones are not.
    let strided = PARAMS_WGSL.replacen(
        "    @align(16) time: f32,    // 16: the uniform array stride\n    x: f32,",
        "    time: f32,\n    x: f32,",
        1,
    );
    assert_ne!(strided, PARAMS_WGSL);
    let bad = probe(&wgsl_layout(&strided, "Params").unwrap());
    assert!(
        bad.iter().any(|l| l.starts_with("laser.path[1].time @")),
        "{:?}",
        &bad[..3]
    );
    assert!(
        !bad.iter().any(|l| l.starts_with("laser.path[0].")),
        "{:?}",
        &bad[..3]
    );
    // Renamed on the Rust side only (its flattened line as the macro would print it).
    let mut rust_renamed = rust.clone();
    let k = rust
        .iter()
        .position(|l| l.starts_with("phases[].eta "))
        .unwrap();
    rust_renamed[k] = rust[k].replace("eta", "viscosity");
    let wgsl = wgsl_layout(PARAMS_WGSL, "Params").unwrap();
    assert_eq!(mismatches(&rust_renamed, &wgsl.lines).len(), 1);
    // A type WGSL has and Rust cannot mirror is an error, not a pass.
    let vec3 = PARAMS_WGSL.replacen("    gravity: vec4<f32>,", "    gravity: vec3<f32>,", 1);
    assert!(wgsl_layout(&vec3, "Params").is_err());
}

/// Named bits and codes: the WGSL constants equal the Rust ones.
#[test]
fn flag_and_code_constants_match() {
    let module = naga::front::wgsl::parse_str(PARAMS_WGSL).unwrap();
    let literal = |name: &str| -> naga::Literal {
        let c = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no WGSL constant {name}"))
            .1;
        match module.global_expressions[c.init] {
            naga::Expression::Literal(l) => l,
            ref other => panic!("{name}: {other:?}"),
        }
    };
    let value = |name: &str| -> u32 {
        match literal(name) {
            naga::Literal::U32(v) => v,
            other => panic!("{name}: {other:?}"),
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
        ("FLAG_SOLIDIFICATION", rs::FLAG_SOLIDIFICATION),
        ("FLAG_CONTINUITY", rs::FLAG_CONTINUITY),
        ("FLAG_MARRONE_VISCOSITY", rs::FLAG_MARRONE_VISCOSITY),
        ("FLAG_DFSPH", rs::FLAG_DFSPH),
        ("FLAG_COLOUR_TENSION", rs::FLAG_COLOUR_TENSION),
        ("FLAG_CONDUCTIVITY_TABLE", rs::FLAG_CONDUCTIVITY_TABLE),
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
        ("S_THIN", st::S_THIN),
        ("S_COLOUR", st::S_COLOUR),
        ("SOL_TIME", st::SOL_TIME),
        ("SOL_GRADIENT", st::SOL_GRADIENT),
        ("SOL_COOLING", st::SOL_COOLING),
        ("SOL_COUNT", st::SOL_COUNT),
        ("SOL_PENDING", st::SOL_PENDING),
        ("BODY_BONDED", st::BODY_BONDED as usize),
        ("BODY_LEFT", st::BODY_LEFT as usize),
    ];
    for (name, v) in slots {
        assert_eq!(value(name), v as u32, "{name}");
    }
    for d in &spatter::model::limits::LIMITS {
        assert_eq!(value(d.wgsl), d.limit.code(), "{}", d.wgsl);
    }
    match literal("INTERIOR_SHEPARD") {
        naga::Literal::F32(w) => assert_eq!(w, st::INTERIOR_SHEPARD),
        other => panic!("INTERIOR_SHEPARD: {other:?}"),
    }
}
