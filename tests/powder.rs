//! The powder-bed generator (`[powder]`, src/powder.rs) as a
//! scene sees it. The generator's own checks (diameters against the truncated
//! log-normal, no overlaps, every grain carried, the 3D packing fraction in
//! 0.5–0.65, determinism) are unit tests in src/powder.rs.

mod common;
use common::{spatter, text};

/// The coarse PBF bed's scene (a powder bed with a line melt).
const SCENE: &str = "scenarios/pbf/powder_bed_line_melt_coarse_2d.toml";

fn validate(sets: &[&str]) -> String {
    let mut args = vec!["validate", SCENE];
    for s in sets {
        args.extend_from_slice(&["--set", s]);
    }
    let out = spatter(&args);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    stdout
}

/// `validate` prints the bed (grain count, diameters, thickness, packing
/// fraction); the grains become particles of the powder's phase (more plate
/// particles than the plate alone); the same seed gives the same bed and
/// another seed another one.
#[test]
fn powder_bed_is_reported_and_filled() {
    let load = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        spatter::run::load(SCENE, &sets).unwrap()
    };
    let l = load(&[]);
    let bed = l.model.powder.as_ref().expect("a powder bed");
    let out = validate(&[]);
    assert!(
        out.lines().any(|line| line == bed.summary(2)),
        "validate prints the bed: {out}"
    );
    // 960 um of 16-32 um discs, two to three deep.
    let grains = bed.grains.len();
    assert!((40..=120).contains(&grains), "{}", bed.summary(2));
    // Discs poured into a box with walls and a levelled top: below the 0.82
    // of dense random discs, above a loose 0.5.
    let fraction = bed.packing_fraction;
    assert!((0.5..0.82).contains(&fraction), "{}", bed.summary(2));
    // The plate alone is 192 x 16 sites at dx = 5 um; the grains add about
    // their area over dx² = the packing fraction times the box's 192 x 8 sites
    // (measured 1011 against 989: a lattice fill of discs 3-6 sites across).
    let plate = l.model.phase_index("plate").unwrap() as u32;
    let plate_particles = l.state.phase.iter().filter(|&&p| p == plate).count();
    let fill = plate_particles as f64 - (192 * 16) as f64;
    let area = fraction * (192 * 8) as f64;
    assert!(
        (fill / area - 1.0).abs() < 0.05,
        "{fill} sites for {area}: {}",
        bed.summary(2)
    );
    let again = load(&[]);
    assert!(
        again.model.powder.as_ref() == Some(bed),
        "the same seed, the same bed"
    );
    let other = load(&["powder.seed=2"]);
    assert_ne!(
        other.model.powder.as_ref().unwrap().grains,
        bed.grains,
        "another seed, another bed"
    );
}

#[test]
fn bad_powder_input_names_the_key() {
    let scene = "scenarios/pbf/powder_bed_line_melt_coarse_2d.toml";
    for (set, key) in [
        ("powder.phase=\"melt\"", "powder.phase"),
        ("powder.phase=\"nothing\"", "powder.phase"),
        ("powder.diameter.min=4.0e-5", "powder.diameter.max"),
        ("powder.diameter.log_sigma=0.0", "powder.diameter.log_sigma"),
        ("powder.diameter.median=1.0e-3", "powder.diameter"),
        ("powder.box.max=[9.6e-4, 3.0e-4]", "powder.box"),
        ("powder.box.max=[9.6e-4, 9.0e-5]", "powder.box.max"),
        ("powder.max_grains=0", "powder.max_grains"),
        // 2000 unlevelled discs stand far above the 200 um domain.
        ("powder.max_grains=2000", "powder.max_grains"),
        ("powder.colour=1", "colour"),
    ] {
        common::assert_input_error(&["validate", scene, "--set", set], key);
    }
}

/// A line melt over the bed tallies the grains it melted (`powder: of N grains
/// F fully molten, P partially, U untouched`), and a run resumed from a
/// checkpoint knows each particle's grain as the fresh run does (regenerated from
/// the initial fill; the melt has moved since). Coarse: dx = 10 um, 0.2 ms (the
/// beam has passed about half the bed; measured 16 / 12 / 42 of 70).
#[test]
fn grain_melting_is_tallied_and_survives_a_resume() {
    let dir = common::scratch("powder_tally");
    let scene = "scenarios/pbf/powder_bed_line_melt_coarse_2d.toml";
    let ck = dir.join("ck");
    let sets = ["dx=1e-5", "end_time=2e-4"];
    let mut out = spatter::run::Outputs::default();
    out.checkpoints =
        Some(spatter::checkpoint::CheckpointSink::create(ck.to_str().unwrap()).unwrap());
    out.checkpoint_every = Some(1e-4);
    let r = common::run_with_outputs(scene, &sets, None, &mut out);
    assert_eq!(r.end, spatter::run::RunEnd::Completed);
    assert!(r.check.as_ref().is_none_or(|c| c.pass));
    let g = r
        .track
        .and_then(|t| t.grains)
        .expect("a melt track over a powder bed");
    assert_eq!(
        g.fully_molten + g.partially_molten + g.untouched,
        g.grains,
        "{g:?}"
    );
    assert!(g.fully_molten >= 1 && g.untouched >= 1, "{g:?}");
    let sets = sets.map(String::from);
    let fresh = spatter::run::load(scene, &sets).unwrap();
    let ckpt = std::fs::read_dir(&ck)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "ckpt"))
        .expect("a checkpoint");
    let resumed = spatter::run::load_checkpoint(ckpt.to_str().unwrap(), &[]).unwrap();
    let members = |l: &spatter::run::Loaded| l.model.powder.as_ref().unwrap().members.clone();
    assert_eq!(members(&fresh), members(&resumed));
    assert!(
        members(&fresh)
            .iter()
            .filter(|&&g| g != spatter::powder::NO_GRAIN)
            .count()
            > 0
    );
}
