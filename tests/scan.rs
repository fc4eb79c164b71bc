//! `[scan]`: tracks as a process engineer gives them (start, direction, speed,
//! length, dwell; hatches of parallel tracks), compiled to the laser's path
//! and power tables.

mod common;
use spatter::load;
use spatter::params::Params;

/// A scene's text with its explicit path and switch-off taken out, written
/// where the test can name it: the scan supplies both.
fn without_path(name: &str) -> (String, String) {
    let path = common::scene_at(name);
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with("power_until") && !l.starts_with("path ="))
        .collect::<Vec<_>>()
        .join("\n");
    let out = format!(
        "{}/scan_{}.toml",
        env!("CARGO_TARGET_TMPDIR"),
        name.replace('/', "_")
    );
    std::fs::write(&out, &text).unwrap();
    (out, text)
}

/// The README's 2D line melt gives its beam as an explicit path (held at
/// x = 160 µm for 50 µs, then to 800 µm at 2 m/s, off at 370 µs);
/// line_melt_scan_2d.toml gives the same line as a [scan]: the two pack into
/// the same parameter block, bit for bit.
#[test]
fn a_scan_packs_as_the_explicit_path_it_stands_for() {
    let explicit = load::load(&common::scene_at("pbf/line_melt_coarse_2d"), &[]).unwrap();
    let scanned = load::load(&common::scene_at("pbf/line_melt_scan_2d"), &[]).unwrap();
    let (a, b) = (
        explicit.model.laser.as_ref().unwrap(),
        scanned.model.laser.as_ref().unwrap(),
    );
    assert_eq!((b.path.len(), b.power.len()), (3, 2), "{b:?}");
    for (p, q) in a.path.iter().zip(&b.path) {
        assert!(
            (p.0 - q.0).abs() < 1e-15 && p.1 == q.1,
            "{:?} {:?}",
            a.path,
            b.path
        );
    }
    let pa = Params::new(&explicit.model, explicit.state.len() as u32);
    let pb = Params::new(&scanned.model, scanned.state.len() as u32);
    assert!(
        pa.uniform_bytes() == pb.uniform_bytes(),
        "the parameter blocks differ"
    );
}

/// Three alternating tracks 100 µm apart along +x, 500 µm at 1 m/s with a
/// 200 µs turnaround: each track starts where the serpentine says, the beam
/// is on only along the tracks, and the energy is P times the time on them.
#[test]
fn a_hatch_of_alternating_tracks() {
    let scene = without_path("pbf/amb2018_02_c").0;
    let sets: Vec<String> = [
        "dx=4e-5",
        "scan.start=[2.0e-4, 1.0e-4]",
        "scan.speed=1.0",
        "scan.length=5.0e-4",
        "scan.tracks=3",
        "scan.hatch_spacing=1.0e-4",
        "scan.pattern=\"alternating\"",
        "scan.turnaround=2.0e-4",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let l = load::load(&scene, &sets).unwrap();
    let laser = l.model.laser.unwrap();
    let ends: Vec<(f64, [f64; 2])> = laser.path.clone();
    let expect = [
        (0.0, [2.0e-4, 1.0e-4]),
        (5.0e-4, [7.0e-4, 1.0e-4]),
        (7.0e-4, [7.0e-4, 2.0e-4]),
        (1.2e-3, [2.0e-4, 2.0e-4]),
        (1.4e-3, [2.0e-4, 3.0e-4]),
        (1.9e-3, [7.0e-4, 3.0e-4]),
    ];
    assert_eq!(ends.len(), expect.len(), "{ends:?}");
    for (got, want) in ends.iter().zip(&expect) {
        assert!((got.0 - want.0).abs() < 1e-12, "{ends:?}");
        for a in 0..2 {
            assert!((got.1[a] - want.1[a]).abs() < 1e-12, "{ends:?}");
        }
    }
    // on along the tracks, off in the turns and after the last
    for (t, on) in [
        (2.5e-4, true),
        (6.0e-4, false),
        (1.0e-3, true),
        (1.3e-3, false),
        (2.0e-3, false),
    ] {
        assert_eq!(laser.power_at(t) > 0.0, on, "t = {t}: {:?}", laser.power);
    }
    let e = laser.energy_until(1.0);
    assert!((e - 195.0 * 1.5e-3).abs() < 1e-9, "energy {e}");
}

/// What a scan cannot be: each exits 2 naming its key.
#[test]
fn bad_scans_exit_2_naming_the_key() {
    let melt_3d = without_path("pbf/amb2018_02_c").0;
    let melt_2d = without_path("pbf/line_melt_coarse_2d").0;
    let scan3 = [
        "scan.start=[2e-4, 1e-4]",
        "scan.speed=1.0",
        "scan.length=5e-4",
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        scan3.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    for (extra, key) in [
        (
            &[
                "scan.tracks=40",
                "scan.hatch_spacing=1e-4",
                "scan.turnaround=1e-4",
            ][..],
            "scan.tracks",
        ),
        (
            &["scan.tracks=2", "scan.turnaround=1e-4"][..],
            "scan.hatch_spacing",
        ),
        (
            &["scan.tracks=2", "scan.hatch_spacing=1e-4"][..],
            "scan.turnaround",
        ),
        (&["scan.hatch_spacing=1e-4"][..], "scan.hatch_spacing"),
        (&["scan.speed=0.0"][..], "scan.speed"),
        (&["scan.direction=[0.0, 0.0]"][..], "scan.direction"),
        (&["scan.start=[2e-4]"][..], "scan.start"),
        (&["scan.pattern=\"zigzag\""][..], "scan.pattern"),
    ] {
        let mut args = vec!["validate".to_string(), melt_3d.clone()];
        for s in with(extra) {
            args.push("--set".into());
            args.push(s);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        common::assert_input_error(&refs, key);
    }
    // the explicit path and a scan together; a 2D hatch
    common::assert_input_error(
        &[
            "validate",
            &melt_3d,
            "--set",
            "laser.path=[[0.0, 2.0e-4, 2.0e-4]]",
            "--set",
            "scan.start=[2e-4, 1e-4]",
            "--set",
            "scan.speed=1.0",
            "--set",
            "scan.length=5e-4",
        ],
        "laser.path",
    );
    common::assert_input_error(
        &[
            "validate",
            &melt_2d,
            "--set",
            "laser.path=[]",
            "--set",
            "laser.power_until=1e-3",
            "--set",
            "scan.start=[1e-4]",
            "--set",
            "scan.speed=1.0",
            "--set",
            "scan.length=5e-4",
        ],
        "laser.power_until",
    );
    common::assert_input_error(
        &[
            "validate",
            &melt_2d,
            "--set",
            "scan.start=[1e-4]",
            "--set",
            "scan.speed=1.0",
            "--set",
            "scan.length=5e-4",
            "--set",
            "scan.tracks=2",
        ],
        "scan.tracks",
    );
}

/// A track that starts or ends off the plate is exit 2 naming the key that
/// put it there; `laser.speed` (where a new user looks first) points to
/// `scan.speed`.
#[test]
fn scans_off_the_domain_and_misplaced_keys_exit_2() {
    let hatch = common::scene_at("pbf/hatch_bare_plate_3d");
    for (set, key) in [
        ("scan.hatch_spacing=2e-4", "scan.hatch_spacing"),
        ("scan.length=1e-3", "scan.length"),
        ("scan.start=[1.6e-4, -1e-5]", "scan.start"),
        ("laser.speed=1.0", "laser.speed"),
    ] {
        common::assert_input_error(&["validate", &hatch, "--set", set], key);
    }
    let out = common::spatter(&["validate", &hatch, "--set", "laser.speed=1.0"]);
    let (_, err) = common::text(&out);
    assert!(err.contains("`scan.speed`"), "{err}");
}

/// The hatch scene (scenarios/pbf/hatch_bare_plate_3d.toml): three tracks
/// 100 µm apart in y, a serpentine, the beam off in the 0.1 ms turnarounds,
/// and the run long enough for the last track (no warning).
#[test]
fn the_hatch_scene_compiles_to_three_tracks() {
    let l = load::load(
        &common::scene_at("pbf/hatch_bare_plate_3d"),
        &["dx=2e-5".into()],
    )
    .unwrap();
    assert!(l.model.warnings.is_empty(), "{:?}", l.model.warnings);
    let laser = l.model.laser.unwrap();
    let y: Vec<f64> = laser.path.iter().map(|p| p.1[1]).collect();
    let x: Vec<f64> = laser.path.iter().map(|p| p.1[0]).collect();
    for (got, want) in y.iter().zip([1e-4, 1e-4, 2e-4, 2e-4, 3e-4, 3e-4]) {
        assert!((got - want).abs() < 1e-12, "{y:?}");
    }
    for (got, want) in x.iter().zip([1.6e-4, 8e-4, 8e-4, 1.6e-4, 1.6e-4, 8e-4]) {
        assert!((got - want).abs() < 1e-12, "{x:?}");
    }
    assert_eq!(laser.power.len(), 6);
    assert!(laser.power_at(4.0e-4) == 0.0 && laser.power_at(5.0e-4) > 0.0);
}

/// The hatch scene's figures per track, on a short serpentine of two tracks
/// 100 µm apart on a plate cut to 480 µm at Δx = 40 µm (a few seconds): each
/// track's own melt is measured in its frame, centred nearer its own line than
/// its neighbour's (within half the hatch spacing), and the second overlaps
/// the first (the beam's 140 µm is wider than the hatch). The geometry of the
/// figures is tested exactly in src/track.rs; this is the run's wiring, and
/// the summary's `track.tracks`.
#[test]
fn a_hatch_run_reports_each_track_and_their_overlap() {
    let scene = common::scene_at("pbf/hatch_bare_plate_3d");
    let (_, r) = common::run_loaded(
        &scene,
        &[
            "dx=4e-5",
            "domain.max=[4.8e-4, 4.0e-4, 1.2e-4]",
            "shapes[0].box={ min = [0.0, 0.0, 0.0], max = [4.8e-4, 4.0e-4, 8.0e-5] }",
            "scan.start=[8e-5, 1.4e-4]",
            "scan.length=3.2e-4",
            "scan.tracks=2",
            "run.end_time=5e-4",
        ],
        None,
    );
    let track = r.track.expect("a track");
    let t = &track.tracks;
    assert_eq!(t.len(), 2, "{t:?}");
    for k in t {
        assert!(k.melted_slices >= 4, "{k:?}");
        assert!(k.width > 2.0 * 4e-5 && k.depth > 0.0, "{k:?}");
        assert!(k.centre_offset.abs() < 0.5 * k.hatch_spacing, "{k:?}");
    }
    assert!(t[0].overlap_width.is_nan(), "{:?}", t[0]);
    assert!(
        t[1].overlap_width > 0.0 && t[1].overlap <= 1.0,
        "{:?}",
        t[1]
    );
    assert!((t[1].hatch_spacing - 1e-4).abs() < 1e-12);
    let lines = track.summary(3);
    assert!(
        lines.iter().any(|l| l.starts_with("track 2 of 2")),
        "{lines:?}"
    );
}
