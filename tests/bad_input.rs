//! Every malformed scenario in tests/bad_input/ exits with code 2 and a message that
//! names the file and the key (listed in expected.txt), never a panic.

mod common;
use common::{spatter, text};

#[test]
fn malformed_scenarios_exit_2_naming_the_key() {
    let dir = format!("{}/tests/bad_input", env!("CARGO_MANIFEST_DIR"));
    let expected = std::fs::read_to_string(format!("{dir}/expected.txt")).unwrap();
    let mut checked = 0;
    for line in expected.lines() {
        let (file, key) = line.split_once(' ').unwrap();
        let path = format!("{dir}/{file}");
        for cmd in ["validate", "run"] {
            let out =
                spatter(&[cmd, &path, "--backend", "cpu"][..if cmd == "run" { 4 } else { 2 }]);
            let (stdout, stderr) = text(&out);
            assert_eq!(
                out.status.code(),
                Some(2),
                "{cmd} {file}: exit {:?}\n{stdout}{stderr}",
                out.status.code()
            );
            assert!(
                stderr.contains(file),
                "{file}: message does not name the file: {stderr}"
            );
            assert!(
                stderr.contains(key),
                "{file}: message does not name `{key}`: {stderr}"
            );
            assert!(!stderr.contains("panicked"), "{file}: panicked: {stderr}");
        }
        checked += 1;
    }
    assert!(checked >= 12, "only {checked} malformed scenarios");
}

#[test]
fn bad_overrides_exit_2() {
    let scene = common::scene("poiseuille_2d");
    for (set, key) in [
        ("dx=-1", "simulation.dx"),
        ("materials.fluid.density=0", "materials.fluid.density"),
        ("noequals", "noequals"),
    ] {
        let out = spatter(&["validate", &scene, "--set", set]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "--set {set}: {stderr}");
        assert!(stderr.contains(key), "--set {set}: {stderr}");
    }
}

#[test]
fn missing_file_exits_2() {
    let out = spatter(&["validate", "/nonexistent/scene.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("/nonexistent/scene.toml"));
}
