#![allow(dead_code)]
use std::process::{Command, Output};

/// The test command exports XDG_RUNTIME_DIR; set it here too so a bare `cargo test`
/// keeps the Vulkan loader quiet.
pub fn spatter(args: &[&str]) -> Output {
    let dir = std::env::temp_dir().join("spatter-xdg");
    let _ = std::fs::create_dir_all(&dir);
    Command::new(env!("CARGO_BIN_EXE_spatter"))
        .args(args)
        .env("XDG_RUNTIME_DIR", dir)
        .output()
        .expect("run spatter")
}

pub fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

pub fn scene(name: &str) -> String {
    format!(
        "{}/scenarios/validation/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}
