//! WGSL composition: each pass file names the library files it uses on its first
//! line (`// uses: params kernel grid`), and the host prepends those (with what
//! they use in turn) in one fixed order, declares the buffers the pass and its
//! libraries name on their `// reads:` and `// writes:` lines (and only those:
//! gpu::buffers::pass_bindings), then expands the neighbour-walk template. Plain
//! text, no preprocessor crate: naga_oil does not follow naga 30.
//!
//! The neighbour walk is written once, here. A pass writes
//!
//! ```text
//!     #for_each_neighbor(ci, zr, j) {
//!         ...body, with j the sorted index of a candidate neighbour...
//!     }
//! ```
//!
//! with `ci` the particle's cell and `zr` its z reach (`z_range()`), and the
//! template expands to the dz / dy / row-segment / j loops every pass had written
//! out before the template, character for character, so the compiled loops are the
//! ones that were measured on hardware. The Rust twin is
//! `backend::cpu::neighbors::for_each_neighbor`: same cells, same order.

use super::buffers::{pass_bindings as pass_bindings_of, PassBinding};
use crate::backend::entry_points;
use crate::params::Params;
use std::collections::HashMap;

/// Library files, in the order they are composed (each after what it uses).
const LIBS: [(&str, &str); 9] = [
    ("params", include_str!("../../../shaders/lib/params.wgsl")),
    ("consts", include_str!("../../../shaders/lib/consts.wgsl")),
    ("math", include_str!("../../../shaders/lib/math.wgsl")),
    ("kernel", include_str!("../../../shaders/lib/kernel.wgsl")),
    ("grid", include_str!("../../../shaders/lib/grid.wgsl")),
    ("phase", include_str!("../../../shaders/lib/phase.wgsl")),
    ("vapour", include_str!("../../../shaders/lib/vapour.wgsl")),
    ("rigid", include_str!("../../../shaders/lib/rigid.wgsl")),
    ("reduce", include_str!("../../../shaders/lib/reduce.wgsl")),
];

/// The pass files (one per compute pass, named as in the pass table).
pub const PASSES: [(&str, &str); 14] = [
    ("neighbors", include_str!("../../../shaders/neighbors.wgsl")),
    ("density", include_str!("../../../shaders/density.wgsl")),
    (
        "continuity",
        include_str!("../../../shaders/continuity.wgsl"),
    ),
    ("dfsph", include_str!("../../../shaders/dfsph.wgsl")),
    (
        "dfsph_viscosity",
        include_str!("../../../shaders/dfsph_viscosity.wgsl"),
    ),
    ("wall", include_str!("../../../shaders/wall.wgsl")),
    ("forces", include_str!("../../../shaders/forces.wgsl")),
    ("integrate", include_str!("../../../shaders/integrate.wgsl")),
    ("timestep", include_str!("../../../shaders/timestep.wgsl")),
    ("heat", include_str!("../../../shaders/heat.wgsl")),
    ("laser", include_str!("../../../shaders/laser.wgsl")),
    ("interface", include_str!("../../../shaders/interface.wgsl")),
    (
        "surface_forces",
        include_str!("../../../shaders/surface_forces.wgsl"),
    ),
    ("bodies", include_str!("../../../shaders/bodies.wgsl")),
];

const WALK_DIRECTIVE: &str = "#for_each_neighbor(";

/// The libraries a source names on its `// uses:` line.
fn uses(src: &str) -> Vec<&str> {
    src.lines()
        .next()
        .and_then(|l| l.strip_prefix("// uses:"))
        .map(|l| l.split_whitespace().collect())
        .unwrap_or_default()
}

/// The names on a source's `// {key}:` line among its first lines (none without one).
fn header<'a>(src: &'a str, key: &str) -> Vec<&'a str> {
    let prefix = format!("// {key}:");
    src.lines()
        .take(4)
        .find_map(|l| l.strip_prefix(prefix.as_str()))
        .map(|l| l.split_whitespace().collect())
        .unwrap_or_default()
}

/// A pass's bindings: what it and its libraries read (`// reads:`) and what it
/// writes (`// writes:`), in registry order (gpu::buffers::pass_bindings).
/// A pass with the reorder directive (neighbors.wgsl) also reads every sorted
/// field and writes its scratch (crate::fields), so a new sorted field needs no
/// header edit.
pub fn pass_bindings(pass: &str) -> Result<Vec<PassBinding>, String> {
    let mut reads = header(pass, "reads");
    let mut writes = header(pass, "writes");
    for k in resolve(&uses(pass))? {
        reads.extend(header(LIBS[k].1, "reads"));
    }
    if pass.contains(REORDER_DIRECTIVE) {
        for f in crate::fields::FIELDS.iter().filter(|f| f.scratch.is_some()) {
            reads.push(f.binding);
            writes.extend(f.scratch);
        }
    }
    pass_bindings_of(&reads, &writes)
}

/// The declarations of a pass's bindings, group 0 (binding 0: the parameter block).
fn declarations(bindings: &[PassBinding]) -> String {
    let mut out = String::from("@group(0) @binding(0) var<uniform> P: Params;\n");
    for b in bindings {
        let access = if b.read_write() { "read_write" } else { "read" };
        out.push_str(&format!(
            "@group(0) @binding({}) var<storage, {access}> {}: {};\n",
            b.binding, b.name, b.wgsl
        ));
    }
    out
}

/// `wanted` and everything it uses, in LIBS order.
fn resolve(wanted: &[&str]) -> Result<Vec<usize>, String> {
    let mut need = [false; LIBS.len()];
    let mut stack: Vec<&str> = wanted.to_vec();
    while let Some(name) = stack.pop() {
        let k = LIBS
            .iter()
            .position(|(n, _)| *n == name)
            .ok_or_else(|| format!("no WGSL library '{name}' (shaders/lib/)"))?;
        if !need[k] {
            need[k] = true;
            stack.extend(uses(LIBS[k].1));
        }
    }
    Ok((0..LIBS.len()).filter(|&k| need[k]).collect())
}

/// A pass's complete source: its libraries, the declarations of its bindings
/// (those it does not write `read`), its pair terms (backend::terms), then the
/// pass with every neighbour walk expanded.
pub fn compose(name: &str, pass: &str) -> Result<String, String> {
    let mut out = String::new();
    for k in resolve(&uses(pass))? {
        out.push_str(LIBS[k].1);
        out.push('\n');
    }
    out.push_str(&declarations(&pass_bindings(pass)?));
    out.push('\n');
    for term in crate::backend::terms::wgsl_for(name) {
        out.push_str(term);
        out.push('\n');
    }
    out.push_str(&expand_walks(&expand_reorder(pass)?)?);
    Ok(out)
}

const REORDER_DIRECTIVE: &str = "#reorder_sorted_fields(";

/// Replace a `#reorder_sorted_fields(k, s)` line with the copies of every sorted
/// field (crate::fields::wgsl_reorder), so the reorder pass follows the registry.
pub fn expand_reorder(src: &str) -> Result<String, String> {
    let mut out = String::with_capacity(src.len());
    for (n, line) in src.lines().enumerate() {
        let indent = &line[..line.len() - line.trim_start().len()];
        match line.trim_start().strip_prefix(REORDER_DIRECTIVE) {
            Some(args) => {
                let a: Vec<&str> = args
                    .strip_suffix(')')
                    .ok_or_else(|| format!("line {}: '{REORDER_DIRECTIVE}k, s)' expected", n + 1))?
                    .split(',')
                    .map(str::trim)
                    .collect();
                let [k, s] = a[..] else {
                    return Err(format!("line {}: the reorder takes (k, s)", n + 1));
                };
                out.push_str(&crate::fields::wgsl_reorder(k, s, indent));
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    if !src.ends_with('\n') {
        out.pop();
    }
    Ok(out)
}

/// Every library (for the arithmetic probe, which is not a pass).
pub fn all_libraries() -> String {
    let names: Vec<&str> = LIBS.iter().map(|(n, _)| *n).collect();
    let mut out = String::new();
    let (mut reads, mut writes) = (Vec::new(), Vec::new());
    for k in resolve(&names).expect("LIBS resolves") {
        out.push_str(LIBS[k].1);
        out.push('\n');
        reads.extend(header(LIBS[k].1, "reads"));
        writes.extend(header(LIBS[k].1, "writes"));
    }
    let bindings = pass_bindings_of(&reads, &writes).expect("library buffers are buffers");
    out.push_str(&declarations(&bindings));
    out
}

/// Replace each `#for_each_neighbor(cell, reach, j) {` … `}` block (closed by the
/// first `}` line at the directive's indentation) with the walk's loops.
pub fn expand_walks(src: &str) -> Result<String, String> {
    let lines: Vec<&str> = src.lines().collect();
    let mut out = Vec::with_capacity(lines.len() + 16);
    let mut k = 0;
    while k < lines.len() {
        let line = lines[k];
        let indent = &line[..line.len() - line.trim_start().len()];
        let Some(args) = line.trim_start().strip_prefix(WALK_DIRECTIVE) else {
            out.push(line.to_string());
            k += 1;
            continue;
        };
        let args = args.strip_suffix(") {").ok_or_else(|| {
            format!(
                "line {}: '{WALK_DIRECTIVE}cell, reach, j) {{' expected",
                k + 1
            )
        })?;
        let a: Vec<&str> = args.split(',').map(str::trim).collect();
        let [cell, reach, j] = a[..] else {
            return Err(format!(
                "line {}: the walk takes (cell, reach, index)",
                k + 1
            ));
        };
        let close = format!("{indent}}}");
        let end = (k + 1..lines.len())
            .find(|&e| lines[e] == close)
            .ok_or_else(|| format!("line {}: neighbour walk not closed", k + 1))?;
        let i = |extra: usize| format!("{indent}{}", " ".repeat(extra));
        out.push(format!(
            "{}for (var dz = -{reach}; dz <= {reach}; dz++) {{",
            i(0)
        ));
        out.push(format!("{}for (var dy = -1; dy <= 1; dy++) {{", i(4)));
        out.push(format!(
            "{}for (var seg = 0u; seg < row_segments(); seg++) {{",
            i(8)
        ));
        out.push(format!(
            "{}let rg = row_segment({cell}, dy, dz, seg);",
            i(12)
        ));
        out.push(format!(
            "{}for (var {j} = rg.x; {j} < rg.y; {j}++) {{",
            i(12)
        ));
        for body in &lines[k + 1..end] {
            // Body lines move 12 columns right, into the innermost loop.
            out.push(if body.is_empty() {
                String::new()
            } else {
                format!("            {body}")
            });
        }
        for extra in [12, 8, 4, 0] {
            out.push(format!("{}}}", i(extra)));
        }
        k = end + 1;
    }
    let mut s = out.join("\n");
    if src.ends_with('\n') {
        s.push('\n');
    }
    Ok(s)
}

/// Each pass's complete WGSL source (its libraries first, neighbour walks
/// expanded), by shader file name. Public so that a test can validate them without
/// an adapter.
pub fn shader_sources() -> Vec<(&'static str, String)> {
    PASSES
        .iter()
        .map(|(name, src)| {
            let full = compose(name, src).unwrap_or_else(|e| panic!("shaders/{name}.wgsl: {e}"));
            (*name, full)
        })
        .collect()
}

pub fn build_pipelines(
    device: &wgpu::Device,
    layouts: &HashMap<&'static str, wgpu::BindGroupLayout>,
    sort_layout: &wgpu::BindGroupLayout,
    params: &Params,
) -> HashMap<&'static str, wgpu::ComputePipeline> {
    let modules: HashMap<&str, wgpu::ShaderModule> = shader_sources()
        .into_iter()
        .map(|(name, source)| {
            let m = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            (name, m)
        })
        .collect();
    entry_points()
        .into_iter()
        .map(|(entry, file)| {
            // The sort's dispatches also bind their stage uniform (group 1).
            let groups: Vec<Option<&wgpu::BindGroupLayout>> = if entry.starts_with("bitonic") {
                vec![Some(&layouts[file]), Some(sort_layout)]
            } else {
                vec![Some(&layouts[file])]
            };
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry),
                bind_group_layouts: &groups,
                immediate_size: 0,
            });
            // The pass's switchable pair terms: a term the scene does not use is
            // compiled out here, not skipped per pair.
            let switches = crate::backend::terms::switches(file, params);
            let p = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pl),
                module: &modules[file],
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &switches,
                    ..Default::default()
                },
                cache: None,
            });
            (entry, p)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walk_expands_to_the_loops_with_the_body_innermost() {
        let src = "fn f() {\n    #for_each_neighbor(ci, zr, j) {\n        s = s + 1.0;\n    }\n}\n";
        let want = "fn f() {
    for (var dz = -zr; dz <= zr; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var seg = 0u; seg < row_segments(); seg++) {
                let rg = row_segment(ci, dy, dz, seg);
                for (var j = rg.x; j < rg.y; j++) {
                    s = s + 1.0;
                }
            }
        }
    }
}
";
        assert_eq!(expand_walks(src).unwrap(), want);
    }

    #[test]
    fn an_unclosed_walk_or_a_missing_library_is_an_error() {
        assert!(expand_walks("    #for_each_neighbor(ci, zr, j) {\n        x;\n").is_err());
        assert!(expand_walks("    #for_each_neighbor(ci, j) {\n    }\n").is_err());
        assert!(compose("x", "// uses: params nonsense\n").is_err());
    }

    /// The reorder expands to the copies the pass had written out before the
    /// field registry drove it: the same text, so the same compiled pass.
    #[test]
    fn reorder_expands_to_every_sorted_field() {
        let got = expand_reorder("    #reorder_sorted_fields(k, s)\n").unwrap();
        let want = "    s_pos[k] = pos[s];
    s_vel[k] = vel[s];
    s_acc[k] = acc[s];
    s_acc_b[k] = acc_b[s];
    if ((P.sizes.flags & FLAG_CONTINUITY) != 0u) {
        s_rho[k] = rho[s];
    }
    s_mass[k] = mass[s];
    s_phase[k] = phase[s];
    s_id[k] = id[s];
    if ((P.sizes.flags & FLAG_HEAT) != 0u) {
        s_heat[k] = heat[s];
    }
    if ((P.sizes.flags & FLAG_DFSPH) != 0u) {
        s_dfsph_warm[k] = dfsph_warm[s];
    }
";
        assert_eq!(got, want);
    }

    #[test]
    fn a_pass_declares_only_the_buffers_its_header_names() {
        let src = compose(
            "x",
            "// uses: params\n// reads: pos cell_fluid\n// writes: acc\nfn f() {}\n",
        )
        .unwrap();
        assert!(src.contains("var<storage, read_write> acc: array<vec4<f32>>;"));
        assert!(src.contains("var<storage, read> pos: array<vec4<f32>>;"));
        // Atomics stay read_write.
        assert!(src.contains("var<storage, read_write> cell_fluid: array<atomic<u32>>;"));
        assert!(!src.contains(" vel:"), "not named, not bound");
        // A library's reads come with it: grid reads the cell table and sim.
        let grid = compose("x", "// uses: grid\nfn f() {}\n").unwrap();
        assert!(grid.contains("var<storage, read> cell_start: array<u32>;"));
        // An unknown buffer is an error, not a silent omission.
        assert!(compose("x", "// uses: params\n// reads: nonsense\nfn f() {}\n").is_err());
    }

    #[test]
    fn libraries_come_before_their_users_and_once() {
        // kernel uses consts, which uses params: all three, in LIBS order.
        let src = compose("x", "// uses: kernel\nfn f() {}\n").unwrap();
        let at = |needle: &str| src.find(needle).unwrap();
        assert!(at("struct Params") < at("fn c_half") && at("fn c_half") < at("fn kernel_w"));
        assert_eq!(src.matches("struct Params").count(), 1);
        assert!(!src.contains("fn pm_exp"), "math not named, not included");
    }
}
