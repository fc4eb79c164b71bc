//! Particles that leave through an open side are taken out, counted and
//! recorded, with the mass balance exact; the "stop" policy ends the run instead.
//! Walls hold splashes with the F22 (34) barrier.

mod common;
use common::{reader, scratch, spatter, text};
use spatter::model::EndCondition;
use spatter::outflow::{MassBalance, Outflow};
use spatter::run::{load, RunEnd};
use std::collections::{HashMap, HashSet};
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
    let l = load(&scene, &[]).unwrap();
    let mut out = common::mcap_outputs(&mcap, &l.model);
    let r = common::run_with_outputs(&scene, &[], None, &mut out);
    assert_eq!(r.end, RunEnd::Completed);

    let water = l.model.phase_index("water").unwrap() as u32;
    let x0: HashMap<u64, f64> = (0..l.state.len())
        .filter(|&i| l.state.phase[i] == water)
        .map(|i| (l.state.id[i] as u64, l.model.to_world(l.state.pos[i])[0]))
        .collect();
    let n_water = x0.len();
    assert!(n_water > 0);
    let removed = json_messages(&mcap, "/removed");
    let ids: HashSet<u64> = removed.iter().map(|r| r["id"].as_u64().unwrap()).collect();
    assert!(
        removed.len() == n_water && ids == x0.keys().copied().collect(),
        "every water particle left once"
    );
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
    assert_eq!(last["removed"]["water"], n_water, "{last}");
    assert_eq!(last["particles"]["water"], 0, "{last}");
    assert_eq!(last["removed"]["wall"], 0, "{last}");
    let mass = last["removed_mass"]["water"].as_f64().unwrap();
    assert!(
        (mass - n_water as f64 * m as f64).abs() < 1e-9 * mass,
        "{last}"
    );
    let counts: Vec<usize> = diags
        .iter()
        .map(|d| d["removed"]["water"].as_u64().unwrap() as usize)
        .collect();
    assert!(counts.windows(2).all(|w| w[0] <= w[1]), "{counts:?}");
    assert!(counts.iter().any(|&c| c > 0 && c < n_water), "{counts:?}");
    let sum = reader(&["summary", s(&mcap)]);
    let (o, e) = text(&sum);
    let sum: serde_json::Value = serde_json::from_str(&o).unwrap_or_else(|_| panic!("{o}{e}"));
    let walls = l.state.len() - n_water;
    assert_eq!(sum["particles_per_frame"][0], walls, "{sum}");
    assert_eq!(sum["removed"], n_water, "{sum}");

    // The run's outflow: every water particle, through x_max; the mass balance
    // exact.
    let outflow = Outflow::of(&l.model, &r.final_state);
    assert_eq!(
        outflow.per_phase["water"].0 as usize,
        n_water,
        "{}",
        outflow.summary()
    );
    assert_eq!(
        outflow.per_side,
        [("x_max", n_water as u64)].into_iter().collect(),
        "{}",
        outflow.summary()
    );
    let balance = MassBalance::of(&l.state, &r.final_state);
    assert!(balance.exact(), "{}", balance.summary());
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

/// The 3D dam break run on to t = 1 s (the scene ends at
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
    let path = common::scene("dam_break_3d");
    let (l, r) = common::run_loaded(&path, &[], Some(EndCondition::Time(1.0)));
    assert_eq!(r.end, RunEnd::Completed, "not the watchdog's stop");
    assert!(r.sim_time >= 1.0, "simulated time {}", r.sim_time);
    if let Some(c) = &r.check {
        println!("{}", c.line());
    }
    let outflow = Outflow::of(&l.model, &r.final_state);
    assert!(
        outflow.per_phase.keys().eq(["water"]) && outflow.per_side.keys().copied().eq(["z_max"]),
        "{}",
        outflow.summary()
    );
    let balance = MassBalance::of(&l.state, &r.final_state);
    assert!(balance.exact(), "{}", balance.summary());
    // Measured 0.51 Δx; one wall layer sits at 0.5 Δx, and the run stops at 3.
    assert!(r.leakage.deepest_dx < 1.0, "{}", r.leakage.summary());
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
    let sets = ["dt=6.25e-3", "dt_check=false"];
    let r = common::run_path(&common::scene("dam_break_2d"), &sets, None);
    let RunEnd::Unstable(trip) = r.end else {
        panic!("the run went on: {:?}", r.end)
    };
    assert!(trip.step <= 3, "{}", trip.message());
    assert!(trip.particle.is_some(), "{}", trip.message());
}
