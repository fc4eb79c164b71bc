//! The field registry (spatter::fields), the GPU binding table
//! (backend::gpu::BINDINGS) and shaders/lib/bindings.wgsl describe the same
//! buffers: each binding number holds the buffer the table names, and each field's
//! WGSL array has the field's element type. Checked through naga, so a field added
//! or moved on one side only fails here.

use spatter::backend::gpu::BINDINGS;
use spatter::fields::FIELDS;

const BINDINGS_WGSL: &str = concat!(
    include_str!("../shaders/lib/params.wgsl"),
    "\n",
    include_str!("../shaders/lib/bindings.wgsl")
);

/// (binding number, name, element type) of every global in group 0.
fn wgsl_bindings() -> Vec<(u32, String, naga::TypeInner)> {
    let module = naga::front::wgsl::parse_str(BINDINGS_WGSL).unwrap();
    let mut out: Vec<(u32, String, naga::TypeInner)> = module
        .global_variables
        .iter()
        .filter_map(|(_, g)| {
            let b = g.binding.as_ref()?;
            assert_eq!(b.group, 0);
            let elem = match &module.types[g.ty].inner {
                naga::TypeInner::Array { base, .. } => module.types[*base].inner.clone(),
                other => other.clone(),
            };
            Some((b.binding, g.name.clone().unwrap_or_default(), elem))
        })
        .collect();
    out.sort_by_key(|b| b.0);
    out
}

#[test]
fn binding_table_matches_the_wgsl() {
    let wgsl = wgsl_bindings();
    let names: Vec<(u32, &str)> = wgsl.iter().map(|(b, n, _)| (*b, n.as_str())).collect();
    let table: Vec<(u32, &str)> = BINDINGS
        .iter()
        .enumerate()
        .map(|(b, n)| (b as u32, *n))
        .collect();
    assert_eq!(table, names);
}

#[test]
fn every_field_and_scratch_is_bound_with_its_element_type() {
    let wgsl = wgsl_bindings();
    for f in &FIELDS {
        for name in std::iter::once(f.binding).chain(f.scratch) {
            let (_, _, elem) = wgsl
                .iter()
                .find(|(_, n, _)| n == name)
                .unwrap_or_else(|| panic!("{}: no WGSL binding {name}", f.name));
            let (components, scalar) = match elem {
                naga::TypeInner::Scalar(s) => (1, *s),
                naga::TypeInner::Vector { size, scalar } => (*size as usize, *scalar),
                other => panic!("{name}: {other:?}"),
            };
            assert_eq!(components, f.components, "{name}");
            assert_eq!(scalar.width, 4, "{name}");
            let float = scalar.kind == naga::ScalarKind::Float;
            assert_eq!(float, f.is_float, "{name}");
        }
    }
}
