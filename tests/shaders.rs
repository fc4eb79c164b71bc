//! Every WGSL pass parses and validates with naga, the compiler wgpu uses. A broken
//! shader then fails here with its line and message instead of as a pipeline error
//! at run time.

use spatter::backend::entry_points;
use spatter::backend::gpu::shader_sources;

#[test]
fn every_shader_validates() {
    let sources = shader_sources();
    // Every pass file of the pass table is composed, and every composed file
    // belongs to a stage.
    for d in spatter::backend::STAGES.iter() {
        assert!(
            sources.iter().any(|(n, _)| *n == d.file),
            "no shaders/{}.wgsl",
            d.file
        );
    }
    for (name, _) in &sources {
        assert!(
            spatter::backend::STAGES.iter().any(|d| d.file == *name),
            "shaders/{name}.wgsl has no stage"
        );
    }
    for (name, source) in sources {
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(&source)));
        // Every pipeline the backend builds from this file finds its entry point.
        for (entry, _) in entry_points().into_iter().filter(|e| e.1 == name) {
            assert!(
                module.entry_points.iter().any(|ep| ep.name == *entry),
                "pass table: no entry point {entry} in {name}.wgsl"
            );
        }
    }
}
