//! Process scenes (issue 31) that are too long for CI to run: each validates
//! (exit 0, its check named), and its check's keys exit 2 when missing. Their
//! measured figures are in their headers and docs/validation.md.

mod common;

#[test]
fn material_jetting_scenes_validate_and_need_their_reference_depth() {
    for name in [
        "mjt/drop_on_hot_substrate_3d",
        "mjt/drop_on_cold_substrate_3d",
    ] {
        let scene = common::scene_at(name);
        let out = common::spatter(&["validate", &scene]);
        let (o, e) = common::text(&out);
        assert_eq!(out.status.code(), Some(0), "{name}: {o}{e}");
        assert!(o.contains("substrate (Solid): 8000"), "{name}: {o}");
        common::assert_input_error(
            &["validate", &scene, "--set", "check.depth=-1.0"],
            "check.depth",
        );
    }
}
