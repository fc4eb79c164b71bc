//! The module graph of src/ has no cycle that ARCHITECTURE.md ("Module
//! boundaries") and tools/module_graph.py's EXPLAINED table do not explain.

#[test]
fn module_graph_has_no_unexplained_cycle() {
    let out = std::process::Command::new("python3")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tools/module_graph.py"
        ))
        .output()
        .expect("python3 runs tools/module_graph.py");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
