//! Rigid bodies (src/bodies.rs, backend::cpu::bodies, shaders/bodies.wgsl)
//! through the command line: the rigid-body checks and their tolerances, bad
//! input, resume, the `/bodies` channel. The bit-match is in tests/bitmatch.rs.

mod common;
use common::{
    assert_check_passes, assert_input_error, assert_stated_tolerance, figure, reader, run_check,
    scene, scratch, spatter, text,
};
use spatter::bodies::BodyTally;
use spatter::checks::CheckResult;
use spatter::model::EndCondition;

/// The restitution coefficient against its analytic value: within 1%.
const RESTITUTION_TOLERANCE: f64 = 0.01;
/// The same at the contact limit's own step (10 steps per contact): 5%, the
/// force's jump at the first touch resolved to one step.
const COARSE_RESTITUTION_TOLERANCE: f64 = 0.05;
/// A free body's world angular momentum: max |L − L0|/|L0| within 1e-5; it
/// is the state and no torque acts, so it is kept exactly.
const ANGULAR_MOMENTUM_TOLERANCE: f64 = 1e-5;
/// Its rotational energy: max |E − E0|/E0 within 1e-4 (measured 1.3e-5, the
/// orientation's f32 rounding).
const ENERGY_TOLERANCE: f64 = 1e-4;
/// The floating box's immersed depth against h ρ_b/ρ_l: within one Δx.
const FLOTATION_TOLERANCE: f64 = 1.0;
/// A settled bed: no grain moves more than 0.1Δx over the last 10 340 steps.
const AT_REST_TOLERANCE: f64 = 0.1;
/// A grain melting in a melt: the momentum of melt plus grain within 1e-5 of
/// |P0|, between the f32 rounding left (5.4e-7 measured) and a departing
/// particle's dropped force (1.9e-5 measured in a first version).
const MELTING_GRAIN_TOLERANCE: f64 = 1e-5;
/// The settling disc against Faxén's terminal velocity: within 5%.
const SETTLING_TOLERANCE: f64 = 0.05;

/// Scene `name` with overrides, run on the CPU to `end` (None: its own); its
/// check must pass the tolerance the test states, which is the scene file's.
fn run_passes(name: &str, sets: &[&str], end: Option<EndCondition>, stated: f64) -> CheckResult {
    assert_stated_tolerance(&scene(name), stated);
    let r = common::run_path(&scene(name), sets, end);
    let c = r.check.expect("a completed run with a check");
    common::print_check(name, sets, &c);
    assert!(c.pass && c.tolerance == stated, "{}", c.line());
    c
}

/// Two single-particle bodies collide head-on: the coefficient of restitution
/// of F22's clipped spring–dashpot within 1% of its analytic value (measured
/// 6.9e-4 at 700 steps per contact). At the contact limit's own step (10 steps
/// per contact) the error stays below 5%.
#[test]
fn collision_restitution_within_one_percent() {
    let c = assert_check_passes("collision_2d", RESTITUTION_TOLERANCE);
    let e = figure(&c, "e");
    assert!(
        (e - 0.57174).abs() < RESTITUTION_TOLERANCE * 0.57174,
        "{}",
        c.line()
    );
    let coarse_tolerance = format!("check.tolerance={COARSE_RESTITUTION_TOLERANCE}");
    let coarse = run_check("collision_2d", &["run.dt=6.9e-3", &coarse_tolerance]);
    assert!(
        coarse.pass && coarse.tolerance == COARSE_RESTITUTION_TOLERANCE,
        "{}",
        coarse.line()
    );
}

/// A free asymmetric block spinning about its intermediate axis: over 10⁴ steps
/// the world angular momentum is kept exactly and the energy within 1e-4; the
/// spin flips (twice at this Δt).
#[test]
fn free_rotation_conserves_and_flips() {
    let path = scene("free_rotation_3d");
    assert_eq!(
        common::file_check_value(&path, "energy_tolerance"),
        ENERGY_TOLERANCE
    );
    let c = assert_check_passes("free_rotation_3d", ANGULAR_MOMENTUM_TOLERANCE);
    assert_eq!(figure(&c, "angular_momentum_drift"), 0.0, "{}", c.line());
    assert!(
        figure(&c, "energy_drift") <= ENERGY_TOLERANCE,
        "{}",
        c.line()
    );
    assert!(figure(&c, "flips") >= 1.0, "{}", c.line());
}

/// A flat box of half the water's density floats with half its height immersed
/// within one Δx (measured 0.14 Δx at Δx = 0.01 m, settled by 2 s).
#[test]
fn flotation_at_half_density() {
    let until = Some(EndCondition::Time(2.5));
    let c = run_passes("flotation_2d", &[], until, FLOTATION_TOLERANCE);
    let depth = figure(&c, "immersed_depth");
    let dx = 0.01; // the scene's
    assert!(
        (depth - 0.03).abs() < FLOTATION_TOLERANCE * dx,
        "{}",
        c.line()
    );
}

/// Bad input: a body of a flowing phase, a body without [contact], rotation of
/// a shape that is not a body, a periodic domain, a fixed step above the
/// contact limit: exit 2 naming the key.
#[test]
fn bad_body_input_exits_2_naming_the_key() {
    let s = scene("collision_2d");
    assert_input_error(
        &["validate", &s, "--set", "phases.grain.kind=\"liquid\""],
        "shapes[0].body",
    );
    let dir = scratch("bodies_bad_input");
    let text = std::fs::read_to_string(&s).unwrap();
    let no_contact = text.replace(
        "[contact]\nstiffness = 1.0\n",
        "[nothing]\nstiffness = 1.0\n",
    );
    let p = dir.join("no_contact.toml");
    std::fs::write(
        &p,
        no_contact.replace("[nothing]\nstiffness = 1.0\ndamping = 8.94427191e-3\n", ""),
    )
    .unwrap();
    assert_input_error(&["validate", p.to_str().unwrap()], "contact");
    let spin = text.replacen(
        "body = true\n",
        "body = false\nangular_velocity = [1.0]\n",
        1,
    );
    let p = dir.join("spin.toml");
    std::fs::write(&p, spin).unwrap();
    assert_input_error(
        &["validate", p.to_str().unwrap()],
        "shapes[0].angular_velocity",
    );
    assert_input_error(
        &[
            "validate",
            &s,
            "--set",
            "domain.periodic=[true, false]",
            "--set",
            "domain.open_sides=[\"y_min\", \"y_max\"]",
        ],
        "domain.periodic",
    );
    assert_input_error(&["validate", &s, "--set", "run.dt=0.01"], "run.dt");
    // Rigid grains of a phase that melts are bodies like any other (the coarse
    // PBF bed's): they validate, and need [contact] as any body does.
    let pbf = format!(
        "{}/scenarios/pbf/powder_bed_line_melt_coarse_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let ok = spatter(&["validate", &pbf]);
    assert_eq!(ok.status.code(), Some(0), "{:?}", common::text(&ok));
    let cut = std::fs::read_to_string(&pbf).unwrap();
    let start = cut.find("[contact]").unwrap();
    let end = start + cut[start..].find("[laser]").unwrap();
    let no_contact = dir.join("pbf_no_contact.toml");
    std::fs::write(&no_contact, format!("{}{}", &cut[..start], &cut[end..])).unwrap();
    assert_input_error(&["validate", no_contact.to_str().unwrap()], "contact");
    assert_input_error(
        &["validate", &s, "--set", "contact.stiffness=-1.0"],
        "contact.stiffness",
    );
}

/// A run resumed from a checkpoint continues bit-identically (the body table
/// and member list are in the checkpoint), on the tank of the flotation check.
#[test]
fn resume_with_bodies_is_bit_identical() {
    let dir = scratch("bodies_resume");
    // Without its check (which fails this early: exit 1).
    let text = std::fs::read_to_string(scene("flotation_2d")).unwrap();
    let cut = text.find("[check]").unwrap();
    let path = dir.join("flotation_no_check.toml");
    std::fs::write(&path, &text[..cut]).unwrap();
    let path = path.to_str().unwrap();
    let (mid, end) = common::assert_resume_bit_identical(&dir, path, "cpu", 150);
    let scene_bodies = spatter::run::load(path, &[]).unwrap().model.bodies.len();
    assert!(scene_bodies > 0 && mid.bodies.len() == scene_bodies);
    assert_ne!(mid.bodies[0].x, end.bodies[0].x, "the body moved");
}

/// The MCAP stream carries a `/bodies` message per frame (read back with
/// tools/spatter_read.py) and each frame a `body` channel.
#[test]
fn bodies_channel_is_written() {
    let dir = scratch("bodies_mcap");
    let out = dir.join("c.mcap");
    let run = spatter(&[
        "run",
        &scene("collision_2d"),
        "--backend",
        "cpu",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{:?}", text(&run));
    let s = reader(&["summary", out.to_str().unwrap()]);
    let (stdout, stderr) = text(&s);
    assert_eq!(s.status.code(), Some(0), "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let scene_bodies = spatter::run::load(&scene("collision_2d"), &[])
        .unwrap()
        .model
        .bodies
        .len();
    assert_eq!(v["bodies"], scene_bodies, "every body in /bodies: {stdout}");
    assert_eq!(v["schemas"]["/bodies"], "spatter.Bodies", "{stdout}");
    assert!(
        v["fields"].as_array().unwrap().iter().any(|f| f == "body"),
        "{stdout}"
    );
}

/// A levelled bed of rigid grains under gravity: once settled (12 ms), no grain
/// moves more than 0.1 Δx over the last 10 340 steps (measured 0.002 Δx); every
/// grain of the bed is a body.
#[test]
fn powder_bed_stays_at_rest() {
    let name = "powder_bed_at_rest_2d";
    assert_stated_tolerance(&scene(name), AT_REST_TOLERANCE);
    let (l, r) = common::run_loaded(&scene(name), &[], None);
    let c = r.check.expect("a completed run with a check");
    assert!(c.pass && c.tolerance == AT_REST_TOLERANCE, "{}", c.line());
    let grains = l.model.powder.as_ref().expect("a powder bed").grains.len();
    assert_eq!(r.final_state.bodies.len(), grains, "one body per grain");
}

/// Ejected grains: with gravity turned upwards the whole bed
/// lifts off, and every grain ends more than its diameter above the bed's
/// initial top; at rest none does.
#[test]
fn ejected_grains_are_counted() {
    let ejected = |sets: &[&str]| -> (usize, usize) {
        let path = scene("powder_bed_at_rest_2d");
        let (l, r) = common::run_loaded(&path, sets, Some(EndCondition::Steps(600)));
        spatter::bodies::ejected_grains(&l.model, &r.final_state).expect("a rigid bed")
    };
    let (up, grains) = ejected(&["gravity=[0.0, 2000.0]"]);
    assert!(grains > 0 && up == grains, "{up} of {grains} ejected");
    let (rest, _) = ejected(&[]);
    assert_eq!(rest, 0, "{rest} of {grains} ejected at rest");
}

/// The melting-grain check: a grain thrown into a melt at
/// 2500 K melts completely (52 particles leave one by one, F22 (37)); the melt
/// gains the grain's mass and the momentum of melt plus grain stays within 1e-5
/// of its start (measured 5.4e-7; 4.9e-7 with the solid–fluid viscosity, 7.0e-7
/// with the barrier).
#[test]
fn melting_grain_melts_conserving_mass_and_momentum() {
    let name = "melting_grain_2d";
    assert_stated_tolerance(&scene(name), MELTING_GRAIN_TOLERANCE);
    // The /bodies channel says so too: tools/spatter_read.py summary.
    let mcap = scratch("bodies_melting").join("m.mcap");
    let l = spatter::run::load(&scene(name), &[]).unwrap();
    let mut out = common::mcap_outputs(&mcap, &l.model);
    let r = common::run_with_outputs(&scene(name), &[], None, &mut out);
    let c = r.check.expect("a completed run with a check");
    assert!(
        c.pass && c.tolerance == MELTING_GRAIN_TOLERANCE,
        "{}",
        c.line()
    );
    let tally = BodyTally::of(&r.final_state);
    assert_eq!(
        (tally.molten, tally.whole, tally.partly_molten, tally.bonded),
        (tally.bodies, 0, 0, 0),
        "every body fully molten: {}",
        tally.summary()
    );
    assert_eq!(figure(&c, "particles_left"), 0.0, "{}", c.line());
    let s = reader(&["summary", mcap.to_str().unwrap()]);
    let (stdout, stderr) = text(&s);
    assert_eq!(s.status.code(), Some(0), "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(
        (v["bodies_molten"].as_u64(), v["bodies_bonded"].as_u64()),
        (Some(1), Some(0)),
        "{stdout}"
    );
    // With F22 (33)'s solid–fluid viscosity between the melt and the grain, whose
    // reaction the body pass sums too (without it: 16.5% of |P0| lost).
    run_passes(
        name,
        &["simulation.solid_fluid_viscosity={coefficient=1.0, width=300.0}"],
        None,
        MELTING_GRAIN_TOLERANCE,
    );
    // With F22 (34)'s barrier between the melt and the grain, whose reaction the
    // body pass sums (without it: 3.1e-5 of |P0|, above the
    // tolerance; with it 7.0e-7).
    run_passes(
        name,
        &["simulation.barrier={radius_dx=0.9, stiffness=1.0e4, damping=0.0}"],
        None,
        MELTING_GRAIN_TOLERANCE,
    );
}

/// The bonding rule: melt that solidifies within 1.5 Δx of a
/// rigid grain bonds it into the substrate (`common::BONDING_2D`). A cold grain
/// (1000 K) rests on a cold plate under a layer of melt at 1750 K: the melt
/// freezes against both and the grain is bonded; from then on its particles are fixed solid (velocity 0,
/// no body), and they stay where they were while the run goes on.
#[test]
fn solidifying_melt_bonds_a_grain_to_the_substrate() {
    use spatter::backend::{cpu::CpuBackend, Backend};
    let dir = scratch("bodies_bond");
    let path = dir.join("bond.toml");
    std::fs::write(&path, common::BONDING_2D).unwrap();
    let l = spatter::run::load(path.to_str().unwrap(), &[]).unwrap();
    let params = spatter::params::Params::new(&l.model, l.state.len() as u32);
    let mut cpu = CpuBackend::new(params, l.state.clone());
    cpu.prime();
    cpu.run_steps(150);
    let b = cpu.st.bodies[0];
    assert_eq!(b.bonded, 1, "{b:?}");
    assert!(b.count > 0 && b.count == b.initial_count, "{b:?}");
    let members: Vec<u32> = cpu.st.members[b.first as usize..(b.first + b.count) as usize].to_vec();
    let at = |st: &spatter::state::State| -> Vec<[f32; 4]> {
        let mut slot = vec![0usize; st.len()];
        for i in 0..st.active() {
            slot[st.id[i] as usize] = i;
        }
        members
            .iter()
            .map(|&id| st.pos[slot[id as usize]])
            .collect()
    };
    let before = at(&cpu.st);
    cpu.run_steps(150);
    assert_eq!(before, at(&cpu.st), "bonded particles stay put");
    for &id in &members {
        assert_eq!(cpu.st.body[id as usize], spatter::state::NO_BODY);
    }
    assert_eq!(cpu.st.bodies[0], b, "a bonded body is left alone");
}

/// The settling check: a disc of 1.5 times the liquid's density settles midway
/// between two walls at Faxén's Stokes terminal velocity within 5% (measured
/// 3.1% fast at a = 5 dx, Re = 0.008; 0.014% at a = 10 dx).
#[test]
fn settling_disc_reaches_faxen_terminal_velocity() {
    let c = assert_check_passes("settling_disc_2d", SETTLING_TOLERANCE);
    // The scene's geometry: a disc a quarter of the half-gap, to the lattice
    // fill of its area (measured k = 0.2523: the area radius of the filled disc).
    assert!((figure(&c, "k") - 0.25).abs() < 0.01, "{}", c.line());
}

/// A grain that leaves through an open side is removed (before 2026-12-06 it
/// flew on outside the domain, in the edge cells, until the watchdog called it
/// a wall crossing): collision_2d's left grain thrown out through x_min at
/// 0.1 m/s. Once its centre crosses the open face its members are removed as
/// leaving fluid is, its motion stops there, and the tally says so; the other
/// grain flies on.
#[test]
fn a_grain_leaving_through_an_open_side_is_removed() {
    let (l, r) = common::run_loaded(
        &scene("collision_2d"),
        &["shapes[0].velocity=[-0.1, 0.0]"],
        Some(EndCondition::Steps(600)),
    );
    let st = &r.final_state;
    let (gone, stays) = (&st.bodies[0], &st.bodies[1]);
    assert!(gone.left() && !gone.moves(), "{:?}", gone.x);
    assert!(stays.moves() && !stays.left());
    assert_eq!(
        st.sim.removed, gone.count,
        "its members are the removed ones"
    );
    // Its centre started 4.5 mm inside and crossed x_min at 0.045 s; it stops
    // within the step (0.1 m/s × 1e-4 s = 1e-5 m) that took it across.
    let x = l.model.to_world(gone.x)[0];
    assert!((-1.0e-5..0.0).contains(&x), "stopped at x = {x}");
    let tally = BodyTally::of(st);
    assert_eq!((tally.left, tally.whole), (1, 1), "{}", tally.summary());
    assert!(tally.summary().ends_with("1 left the domain"));
}

/// A grain of radius 15Δx thrown up out of a box's open top beside its closed
/// x_max wall: when its centre crosses the top, its members low on the wall's
/// side still stand inside, nearer the side wall's keep face (4Δx past the
/// wall) than the top (r (sin θ + cos θ) > 4Δx + the gap, from r ≈ 10Δx).
/// Their removal is named by the face the body's centre crossed, so the run
/// ends normally with every member out through y_max (named by each member's
/// own position, the watchdog took them for a wall crossing).
#[test]
fn a_large_grain_leaving_beside_a_wall_is_named_by_its_centre() {
    let scene_text = r#"
[simulation]
dimension = 2
kernel = "quintic"
dx = 1.0e-3
gravity = [0.0, 0.0]

[domain]
min = [0.0, 0.0]
max = [0.1, 0.1]
wall_phase = "wall"
open_sides = ["y_max"]

[materials.grain]
density = 1000.0
viscosity = 0.0
sound_speed = 10.0

[phases.grain]
kind = "wall"
material = "grain"

[phases.wall]
kind = "wall"
material = "grain"

[contact]
stiffness = 1.0
damping = 8.94427191e-3

[[shapes]]
phase = "grain"
body = true
sphere = { center = [0.0845, 0.08], radius = 1.5e-2 }
velocity = [0.0, 1.0]

[run]
dt = 1.0e-4
end_time = 0.03
"#;
    let path = scratch("grain_beside_wall").join("grain.toml");
    std::fs::write(&path, scene_text).unwrap();
    let out = spatter(&["run", path.to_str().unwrap(), "--backend", "cpu"]);
    let (o, e) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    let outflow = o.lines().find(|l| l.starts_with("outflow:")).expect(&o);
    assert!(
        outflow.contains("through y_max") && !outflow.contains("x_max"),
        "{outflow}"
    );
    assert!(o.contains("1 left the domain"), "{o}");
}
