//! Issue 18: particles that leave through an open side are taken out, counted and
//! recorded, with the mass balance exact; the "stop" policy ends the run instead.
//! Walls hold splashes with the F22 (34) barrier.

mod common;
use common::{reader, scratch, spatter, text};
use spatter::run::load;
use std::collections::HashMap;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The decoded JSON messages of one topic of an MCAP file.
fn json_messages(mcap: &Path, topic: &str) -> Vec<serde_json::Value> {
    let bytes = std::fs::read(mcap).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == topic)
        .map(|m| serde_json::from_slice(&m.data).unwrap())
        .collect()
}

/// jet_outflow_2d: a block flying at 1.5 m/s with nothing in its way leaves
/// through x_max, each particle at its ballistic time (0.3 m − x0) / 1.5 m/s.
/// The step removes a particle at the end of the step that carries it across, so
/// its recorded time is up to one Δt (7.6e-5 s) late; the pressure of the lattice
/// (ρ slightly above ρ0 inside the block) may spread the block a little, which the
/// tolerance of 2 Δt late, ½ Δt early covers (measured: 1.01 Δt late at most).
#[test]
fn a_jet_leaves_through_the_open_side_at_its_ballistic_times() {
    let dir = scratch("outflow_jet");
    let mcap = dir.join("jet.mcap");
    let scene = common::scene("jet_outflow_2d");
    let out = spatter(&["run", &scene, "--backend", "cpu", "--out", s(&mcap)]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");

    let l = load(&scene, &[]).unwrap();
    let water = l.model.phase_index("water").unwrap() as u32;
    let x0: HashMap<u64, f64> = (0..l.state.len())
        .filter(|&i| l.state.phase[i] == water)
        .map(|i| (l.state.id[i] as u64, l.model.to_world(l.state.pos[i])[0]))
        .collect();
    assert_eq!(x0.len(), 224);
    let removed = json_messages(&mcap, "/removed");
    assert_eq!(removed.len(), x0.len(), "every water particle left once");
    let dt = 0.25 * 0.005 / (15.0 + 1.5);
    let mut worst: f64 = 0.0;
    for r in &removed {
        assert_eq!(r["side"], "x_max", "{r}");
        assert_eq!(r["phase"], "water", "{r}");
        let id = r["id"].as_u64().unwrap();
        let ballistic = (0.3 - x0[&id]) / 1.5;
        let late = r["time"].as_f64().unwrap() - ballistic;
        worst = worst.max(late.abs() / dt);
        assert!(
            late > -0.5 * dt && late < 2.0 * dt,
            "particle {id} left at {} s, ballistic {ballistic} s",
            r["time"]
        );
        assert!(r["x"].as_f64().unwrap() > 0.3, "{r}");
    }
    eprintln!("largest departure from the ballistic time: {worst:.2} dt");

    // /diagnostics count them per phase with their mass; frames leave them out.
    let diags = json_messages(&mcap, "/diagnostics");
    let last = diags.last().unwrap();
    let m = l.state.mass[(0..l.state.len())
        .find(|&i| l.state.phase[i] == water)
        .unwrap()];
    assert_eq!(last["removed"]["water"], 224, "{last}");
    assert_eq!(last["particles"]["water"], 0, "{last}");
    assert_eq!(last["removed"]["wall"], 0, "{last}");
    let mass = last["removed_mass"]["water"].as_f64().unwrap();
    assert!((mass - 224.0 * m as f64).abs() < 1e-9 * mass, "{last}");
    let counts: Vec<u64> = diags
        .iter()
        .map(|d| d["removed"]["water"].as_u64().unwrap())
        .collect();
    assert!(counts.windows(2).all(|w| w[0] <= w[1]), "{counts:?}");
    assert!(counts.iter().any(|&c| c > 0 && c < 224), "{counts:?}");
    let sum = reader(&["summary", s(&mcap)]);
    let (o, e) = text(&sum);
    let sum: serde_json::Value = serde_json::from_str(&o).unwrap_or_else(|_| panic!("{o}{e}"));
    let walls = l.state.len() as u64 - 224;
    assert_eq!(sum["particles_per_frame"][0], walls, "{sum}");
    assert_eq!(sum["removed"], 224, "{sum}");

    // The run's summary: the count, and the mass balance exact.
    assert!(
        stdout.contains("outflow: 224 particle(s) left the domain: water 224")
            && stdout.contains("224 through x_max"),
        "{stdout}"
    );
    assert!(
        stdout.contains("equal to the initial mass exactly"),
        "{stdout}"
    );
}

/// With domain.open_sides_policy = "stop" the first particle out ends the run
/// with exit 3, naming it, its side and when it left: the block's front column
/// (x0 = 0.2875 m) crosses at (0.3 − 0.2875) / 1.5 = 8.33e-3 s, in step 111.
#[test]
fn the_stop_policy_ends_the_run_at_the_first_particle_out() {
    let out = spatter(&[
        "run",
        &common::scene("jet_outflow_2d"),
        "--backend",
        "cpu",
        "--set",
        "domain.open_sides_policy=\"stop\"",
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    assert!(
        stderr.contains("unstable at step 111")
            && stderr.contains("left the domain through its open x_max side at t = 8.408")
            && stderr.contains("field x"),
        "{stderr}"
    );
    common::assert_input_error(
        &[
            "validate",
            &common::scene("jet_outflow_2d"),
            "--set",
            "domain.open_sides_policy=\"keep\"",
        ],
        "open_sides_policy",
    );
}

/// A shape's velocity is for phases that flow, with one component per axis.
#[test]
fn a_shape_velocity_must_fit_its_phase_and_dimension() {
    let dir = scratch("outflow_shape_velocity");
    let text0 = std::fs::read_to_string(common::scene("jet_outflow_2d")).unwrap();
    for (from, to, says) in [
        (
            "velocity = [1.5, 0.0]",
            "velocity = [1.5, 0.0, 0.0]",
            "2 finite components",
        ),
        (
            "phase = \"water\"\nbox",
            "phase = \"wall\"\nbox",
            "does not flow",
        ),
    ] {
        assert!(text0.contains(from));
        let path = dir.join("bad.toml");
        std::fs::write(&path, text0.replace(from, to)).unwrap();
        let out = spatter(&["validate", s(&path)]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{to}: {stderr}");
        assert!(
            stderr.contains("bad.toml")
                && stderr.contains("shapes[0].velocity")
                && stderr.contains(says),
            "{to}: {stderr}"
        );
    }
}

/// Resume across removals is bit-identical: 300 steps straight against 150 +
/// resume 150 (the first particles leave in step 111, more in every later step).
fn resume_across_removals(backend: &str) {
    let dir = scratch(&format!("outflow_resume_{backend}"));
    let scene = common::scene("jet_outflow_2d");
    let (mid, last) = common::assert_resume_bit_identical(&dir, &scene, backend, 150);
    assert!(mid.sim.removed > 0, "particles have left by step 150");
    assert!(
        last.sim.removed > mid.sim.removed,
        "more left after the resume"
    );
}

#[test]
fn resume_across_removals_is_bit_identical_on_cpu() {
    resume_across_removals("cpu");
}

#[test]
fn resume_across_removals_is_bit_identical_on_the_software_adapter() {
    resume_across_removals("gpu");
}

/// The issue's own check: the 3D dam break run on to t = 1 s (the scene ends at
/// 0.18 s) completes. Splashes leave through the open top (54 of 15 296 particles,
/// all through z_max) and the mass balance is exact; the wall barrier keeps the
/// sloshing out of the walls (deepest penetration 0.51 Δx; without it a particle
/// went through all three layers of the y_max wall at t = 0.92 s). The exit code
/// is the surge-front check's: it samples T ≤ 2.5 whatever the end, and the front
/// runs 16% ahead of Koshizuka & Oka at this Δx (the known gap of the 2D
/// `dam_break_front_within_10_percent`, ignored with its reason), so exit 1 and
/// that FAIL line, never the watchdog's 3.
#[test]
fn dam_break_3d_runs_on_to_one_second() {
    let out = spatter(&[
        "run",
        &common::scene("dam_break_3d"),
        "--backend",
        "cpu",
        "--until",
        "1.0",
    ]);
    let (stdout, stderr) = text(&out);
    let check_fails = stdout
        .lines()
        .any(|l| l.starts_with("check dam_break_front:") && l.ends_with("FAIL"));
    let expected = if check_fails { 1 } else { 0 };
    assert_eq!(out.status.code(), Some(expected), "{stdout}{stderr}");
    assert!(!stderr.contains("unstable"), "{stderr}");
    assert!(stdout.contains("simulated time: 1.0000"), "{stdout}");
    let line = |start: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no `{start}` line: {stdout}"))
            .to_string()
    };
    let outflow = line("outflow: ");
    assert!(
        outflow.contains("particle(s) left the domain: water") && outflow.contains("through z_max"),
        "{outflow}"
    );
    assert!(line("mass: ").contains("equal to the initial mass exactly"));
    let leak = line("wall leakage: deepest fluid penetration ");
    let depth: f64 = leak
        .trim_start_matches("wall leakage: deepest fluid penetration ")
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    // Measured 0.51 Δx; one wall layer sits at 0.5 Δx, and the run stops at 3.
    assert!(depth < 1.0, "{leak}");
}

/// simulation.barrier: one radius, in metres or in Δx, below h.
#[test]
fn barrier_input_is_checked() {
    let scene = common::scene("dam_break_3d");
    for (set, key) in [
        (
            "simulation.barrier={radius_dx=1.0, stiffness=1.0}",
            "simulation.barrier.radius_dx",
        ),
        (
            "simulation.barrier={radius=0.005, radius_dx=0.5, stiffness=1.0}",
            "simulation.barrier",
        ),
        (
            "simulation.barrier={radius=0.005, stiffness=0.0}",
            "simulation.barrier.stiffness",
        ),
        (
            "simulation.barrier={radius=0.005, stiffness=1.0, damping=-1.0}",
            "simulation.barrier.damping",
        ),
        (
            "simulation.barrier={radius=0.005, stiffness=1.0, spring=1.0}",
            "spring",
        ),
    ] {
        common::assert_input_error(&["validate", &scene, "--set", set], key);
    }
    let ok = spatter(&["validate", &scene]);
    let (stdout, _) = text(&ok);
    assert!(stdout.contains("barrier 1.5556e-4 s"), "{stdout}");
}

/// Removal does not hide an instability: a fixed Δt 200 times the acoustic limit
/// (3.125e-5 s) blows dam_break_2d apart in its second step; particles flung
/// through the walls are removed like any other leaving the box, and the
/// watchdog names one of them as having passed through every wall layer.
#[test]
fn a_time_step_200_times_the_limit_still_stops_within_a_few_steps() {
    let out = spatter(&[
        "run",
        &common::scene("dam_break_2d"),
        "--backend",
        "cpu",
        "--set",
        "dt=6.25e-3",
        "--set",
        "dt_check=false",
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    let msg = stderr
        .lines()
        .find(|l| l.contains("unstable at step"))
        .expect("diagnosis");
    let step: u64 = msg
        .split("unstable at step ")
        .nth(1)
        .and_then(|s| s.split(',').next())
        .and_then(|s| s.parse().ok())
        .expect("step number");
    assert!(step <= 3, "{msg}");
    assert!(
        msg.contains(": particle ") && msg.contains(", field "),
        "{msg}"
    );
}
