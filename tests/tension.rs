//! Surface tension (CSF, F22 (24)–(26)) with gas particles. Each
//! check's tolerance is stated and justified here and must be its scene file's;
//! a test that holds a check to what the method gives today states that bound
//! apart.

mod common;
use common::{assert_stated_tolerance, figure, print_check, run_check, scene, spatter, text};
use spatter::checks::CheckResult;

/// The Laplace pressure of the disc in gas: the target 3% at R = 20Δx (F22's
/// form). Not met today (the ignored test says why).
const LAPLACE_TOLERANCE: f64 = 0.03;
/// The free-surface form (no gas): the target 5% at R = 20Δx. Not met today.
const FREE_SURFACE_LAPLACE_TOLERANCE: f64 = 0.05;
/// The 3D sphere in gas: the target 5% at R = 10Δx. Not met today.
const LAPLACE_SPHERE_TOLERANCE: f64 = 0.05;
/// The recoil momentum balance: the momentum gained within 2% of −∫ p_v A dt.
const RECOIL_TOLERANCE: f64 = 0.02;
/// A square drop relaxed to a disc: the outline's radius spread below 0.5Δx.
const DROP_SHAPE_TOLERANCE: f64 = 0.5;
/// Sessile drops: the contact angle within 5° of the static one.
const CONTACT_ANGLE_TOLERANCE: f64 = 5.0;
/// The thermocapillary channel: the interface velocity within 5% of the
/// analytic amplitude at the finest resolution.
const THERMOCAPILLARY_TOLERANCE: f64 = 0.05;
/// Spurious currents, as the capillary number η|u|/σ: below 0.1 in every scene
/// at rest (measured 2e-2 to 6.5e-2).
const CAPILLARY_BOUND: f64 = 0.1;

fn run_laplace(sets: &[&str]) -> CheckResult {
    run_check("laplace_disc_2d", sets)
}

/// The target: Δp within 3% of σ/R at R = 20Δx (F22's form with gas).
/// Not met: +12.4%, +9.3%, +11.4% at R = 10, 20, 40Δx with F22's background
/// pressure 5p0 (−11% at 20Δx without it, where a gap opens between the phases
/// and the surface delta integrates to 0.91): a bias of about 10% that does not
/// fall with Δx. At 20Δx the force's row (the first liquid row, the only one with
/// normals at density ratio 10) has Σ V δ = 1.04 per unit length of the circle
/// and mean curvature 1.05/R. Kept at the target tolerance; see the
/// evidence-based test below and docs/validation.md ("Surface tension and
/// wetting").
#[test]
#[ignore = "Laplace pressure +9.3% at R = 20 dx, +11.4% at 40 dx (target 3%): a ~10% bias from the one-row normals and curvature; see docs/validation.md"]
fn laplace_pressure_within_3_percent_at_20_dx() {
    assert_stated_tolerance(&scene("laplace_disc_2d"), LAPLACE_TOLERANCE);
    let c = run_laplace(&[]);
    assert!(c.pass && c.value <= LAPLACE_TOLERANCE, "{}", c.line());
}

/// What the method gives today, at the coarsest resolution (R = 10Δx, 14 s):
/// +12.4% measured; the bound 15% leaves room for the machine's rounding order
/// only. Spurious currents: capillary number η|u|/σ measured 6.5e-2 at R = 10Δx
/// and 4.8e-2 at 20Δx (falling with resolution, as it should); bound 0.1.
#[test]
fn laplace_pressure_at_10_dx_as_measured() {
    let c = run_laplace(&["dx=2e-3"]);
    assert!(c.value <= 0.15, "{}", c.line());
    assert!(
        figure(&c, "capillary_number") < CAPILLARY_BOUND,
        "{}",
        c.line()
    );
}

/// R18 §4.2's own case (R = 1 m, σ = 10 N/m, Δx = 0.05 m) against the 2D
/// jump σ/R = 10 Pa, not R18's printed σ/(2R): 9.60 Pa, −4.0% (R18 measured 6,
/// −40%). Unprinted ρ, η, c chosen so that it is the disc below scaled up (12 s).
#[test]
fn r18_young_laplace_case_within_5_percent() {
    let name = "laplace_free_disc_r18_2d";
    assert_stated_tolerance(&scene(name), FREE_SURFACE_LAPLACE_TOLERANCE);
    let c = run_check(name, &[]);
    assert!(c.pass, "{}", c.line());
}

/// The same R18 disc with its particles displaced by up to 0.1Δx (`jitter`,
/// uniform) should hold its place and its jump as the lattice does. Before the
/// tension skipped particles with a full support (Shepard sum ≥ 0.95), 1 102 of
/// 1 264 particles left by 35 s and the jump read +376%: the Shepard-corrected
/// gradient gave 54% of the interior a normal in a random direction. With the
/// rule (measured 2026-12-06) none leaves and the jump reads −1.6%, but the
/// centroid still accelerates, to 25 mm/s at 35 s (0.7 mm/s², 7% of σ/(ρR²)):
/// Σ V δ κ n does not vanish on a disordered closed surface (docs/physics.md,
/// free-surface form, "Disorder"). The net force taken off the disc as one
/// body (a CPU experiment) held it still; that is valid for one free drop only.
#[test]
#[ignore = "a free drop on disordered particles drifts: with 0.1 dx of jitter the R18 disc holds its jump (-1.6%, none out) but its centroid reaches 25 mm/s at 35 s (bound 2.9 mm/s); docs/physics.md, Disorder"]
fn r18_young_laplace_disc_holds_with_disordered_particles() {
    let path = scene("laplace_free_disc_r18_2d");
    let (l, r) = common::run_loaded(&path, &["jitter=0.1"], None);
    let st = &r.final_state;
    let liquid = l.model.phase_index("liquid").unwrap() as u32;
    let ids: Vec<usize> = (0..st.active())
        .filter(|&i| st.phase[i] == liquid)
        .collect();
    let mass: f32 = ids.iter().map(|&i| st.mass[i]).sum();
    let centroid_speed = (0..2)
        .map(|a| ids.iter().map(|&i| st.mass[i] * st.vel[i][a]).sum::<f32>() / mass)
        .map(|v| v * v)
        .sum::<f32>()
        .sqrt();
    let check = r.check.expect("the scene has a check");
    print_check("laplace_free_disc_r18_2d", &["jitter=0.1"], &check);
    // None leaves: the lattice run loses none.
    assert_eq!(st.sim.removed, 0, "particles left the domain");
    // A drop at rest stays at rest: 1% of the capillary speed σ/μ = 0.29 m/s.
    assert!(centroid_speed < 2.9e-3, "centroid at {centroid_speed} m/s");
    assert!(check.pass, "{}", check.line());
}

/// What a user of the free-surface form on summation density is told of the
/// disorder defect: the run warns once when 30% or more of the liquid's surface
/// measure Σ V δ lies on particles with a full support (`interior_normals` in
/// /diagnostics), where the tension acts on noise normals. R18's disc on `wcsph`
/// from the lattice is not warned over 0.2 s; with 0.2Δx of jitter it reads 0.51
/// and is warned (at 0.075 s; 0.32 at 0.1Δx). On δ-SPH the tension skips those
/// particles and no run is warned, though the jittered disc reads 0.39.
#[test]
fn a_free_surface_on_disordered_particles_is_warned_about() {
    let path = scene("laplace_free_disc_r18_2d");
    let dir = common::scratch("interior_normals");
    std::fs::create_dir_all(&dir).unwrap();
    let summation = [
        "simulation.formulation=\"wcsph\"",
        "simulation.pressure_floor=true",
    ];
    for (jitter, extra, warned) in [
        ("0.1", &[][..], false),
        ("0.0", &summation[..], false),
        ("0.2", &summation[..], true),
    ] {
        let out = dir.join(format!("disc_{jitter}_{}.mcap", extra.len()));
        let jitter_set = format!("jitter={jitter}");
        let mut args = vec![
            "run",
            &path,
            "--backend",
            "cpu",
            "--out",
            out.to_str().unwrap(),
            "--set",
            &jitter_set,
            "--set",
            "run.end_time=0.2",
        ];
        for s in extra {
            args.extend(["--set", s]);
        }
        let (o, e) = text(&spatter(&args));
        let warning = e.lines().find(|l| l.contains("free-surface measure"));
        assert_eq!(
            warning.is_some(),
            warned,
            "jitter {jitter} {extra:?}:\n{o}{e}"
        );
        if let Some(w) = warning {
            assert!(
                w.contains("Disorder") && w.starts_with("warning: t = "),
                "{w}"
            );
        }
    }
}

/// The free-surface Laplace disc (R = 20Δx, no gas) on R18's δ-SPH,
/// the scene's formulation, without a pressure floor: −4.6% measured (5% asked;
/// +13.2% at 10Δx, +3.8% at 40Δx). On summation density the
/// same disc gave +211 / +285 / +764% at R = 10, 20, 40Δx: the surface row's
/// density is short (737 kg/m³ at t = 0), the pressure floor leaves it at p = 0
/// and it compacts from 56 particles at 1.00Δx to 92 at 0.49Δx, buckling at the
/// particle scale. R18's own Young–Laplace run measured 6 against the 2D
/// σ/R = 10 (−40%; R18 §4.2).
#[test]
fn free_surface_laplace_within_5_percent_at_20_dx() {
    let name = "laplace_free_disc_2d";
    assert_stated_tolerance(&scene(name), FREE_SURFACE_LAPLACE_TOLERANCE);
    let c = run_check(name, &[]);
    assert!(
        c.pass && c.value <= FREE_SURFACE_LAPLACE_TOLERANCE,
        "{}",
        c.line()
    );
}

/// The same disc at R = 10Δx (2 s) on both formulations: δ-SPH +13.2% measured
/// (bound 0.3: first order in Δx/R from here), summation density +211% (bound
/// 2.5: it only keeps the old form's gap from growing unseen). Both drops stay
/// together and nearly still (capillary number below 0.1).
#[test]
fn free_surface_laplace_at_10_dx_on_both_formulations() {
    for (sets, bound) in [
        (&["dx=2e-3"][..], 0.3),
        (
            &[
                "dx=2e-3",
                "simulation.formulation=\"wcsph\"",
                "simulation.pressure_floor=true",
            ][..],
            2.5,
        ),
    ] {
        let r = common::run_path(&scene("laplace_free_disc_2d"), sets, None);
        assert_eq!(r.end, spatter::run::RunEnd::Completed);
        assert_eq!(r.final_state.sim.removed, 0, "no particle left the domain");
        let c = r.check.expect("a check");
        assert!(c.value <= bound, "{sets:?}: {}", c.line());
        assert!(
            figure(&c, "capillary_number") < CAPILLARY_BOUND,
            "{sets:?}: {}",
            c.line()
        );
    }
}

/// J22 (5)–(8) (`surface_tension.model = "muller"`) on the free disc, kept at
/// the free-surface form's 5%. It cannot hold a free surface as printed
/// (docs/physics.md, "J22's colour Laplacian"): measured over 1 s, DFSPH (J22's
/// formulation) −99.997% (1.4e-4 Pa against σ/R = 5 Pa), WCSPH −99.99%,
/// δ-SPH −98.8% with 40 of 1 264 particles blown off.
#[test]
#[ignore = "J22's colour-Laplacian tension as printed gives no Laplace jump at a free surface (-99.997% on DFSPH); see j22_colour_laplacian_at_a_free_surface_as_measured"]
fn j22_colour_laplacian_laplace_within_5_percent() {
    let c = run_check(
        "laplace_free_disc_2d",
        &[
            "surface_tension.model=\"muller\"",
            "simulation.formulation=\"dfsph\"",
        ],
    );
    assert!(c.value <= FREE_SURFACE_LAPLACE_TOLERANCE, "{}", c.line());
}

/// What J22's form does at a free surface, and why. On summation density (DFSPH,
/// as J22) the colour c_i = Σ m_j/ρ_j W_ij is a Shepard sum: 0.99 on the surface
/// row of the disc at rest, so |∇c| stays under the interface threshold 0.1/h
/// and no particle gets a force: the interior pressure stays below 1% of σ/R
/// (measured 1.4e-4 Pa of 5 Pa at 1 s; 0.2 s here). On δ-SPH's continuity
/// density c falls to 0.84 on the outer row, whose one-sided Laplacian is
/// positive: κ = −∇²c/|∇c| reads −330 1/m against 1/R = 50 (a numpy evaluation
/// of (5)–(7) on this lattice), an outward force, and the row's particles leave
/// (40 of 1 264 by 0.29 s).
#[test]
fn j22_colour_laplacian_at_a_free_surface_as_measured() {
    let muller = "surface_tension.model=\"muller\"";
    let r = common::run_path(
        &scene("laplace_free_disc_2d"),
        &[muller, "simulation.formulation=\"dfsph\"", "end_time=0.2"],
        None,
    );
    assert_eq!(r.end, spatter::run::RunEnd::Completed);
    let c = r.check.expect("a check");
    assert!(
        c.value > 0.99,
        "no Laplace jump on summation density: {}",
        c.line()
    );
    let r = common::run_path(
        &scene("laplace_free_disc_2d"),
        &[muller, "end_time=0.4"],
        None,
    );
    assert!(
        r.final_state.sim.removed > 0,
        "the outer row is pushed out on delta_wcsph"
    );
}

/// A scene with gas particles must name its gas: the free-surface form is for
/// scenes without them.
#[test]
fn surface_tension_without_gas_key_in_a_gas_scene_is_refused() {
    let text = std::fs::read_to_string(common::scene("laplace_disc_2d"))
        .unwrap()
        .replace("gas = \"gas\"\n", "");
    let path = common::scratch("tension_no_gas_key").join("drop.toml");
    std::fs::write(&path, text).unwrap();
    common::assert_input_error(&["validate", path.to_str().unwrap()], "surface_tension.gas");
}

/// `validate` lists the pass and the capillary limit for a scene with surface
/// tension, and neither for one without.
#[test]
fn validate_lists_the_pass_and_the_capillary_limit_only_when_needed() {
    let out = spatter(&["validate", &common::scene("laplace_disc_2d")]);
    let (stdout, _) = text(&out);
    assert!(stdout.contains("surface_forces"), "{stdout}");
    assert!(stdout.contains("capillary 9.9736e-5 s"), "{stdout}");
    let out = spatter(&["validate", &common::scene("two_layer_2d")]);
    let (stdout, _) = text(&out);
    assert!(
        !stdout.contains("surface_tension") && !stdout.contains("capillary"),
        "{stdout}"
    );
}

/// Bad [surface_tension] input names its key and exits 2.
#[test]
fn bad_surface_tension_input_names_the_key() {
    let scene = common::scene("laplace_disc_2d");
    for (set, key) in [
        ("surface_tension.liquid=\"gas\"", "surface_tension.liquid"),
        ("surface_tension.gas=\"nothing\"", "surface_tension.gas"),
        (
            "surface_tension.coefficient=0.0",
            "surface_tension.coefficient",
        ),
        (
            "surface_tension.temperature_coefficient=1.0e-3",
            "surface_tension.temperature_coefficient",
        ),
        ("surface_tension.minimum=0.2", "surface_tension.minimum"),
        (
            "surface_tension.melting_width=5.0",
            "surface_tension.melting_width",
        ),
        ("surface_tension.smoothing=1.0", "smoothing"),
        (
            "surface_tension.contact_angle=180.0",
            "surface_tension.contact_angle",
        ),
        (
            "surface_tension.contact_angle={ gas = 60.0 }",
            "surface_tension.contact_angle.gas",
        ),
    ] {
        common::assert_input_error(&["validate", &scene, "--set", set], key);
    }
    // J22's colour Laplacian: the free-surface form, a constant σ, no thin-film
    // rule; and the model's name itself.
    let free = common::scene("laplace_free_disc_2d");
    for (sets, key) in [
        (
            &["surface_tension.model=\"j22\""][..],
            "surface_tension.model",
        ),
        (
            &[
                "surface_tension.model=\"muller\"",
                "surface_tension.thin_layer_rows=2",
            ][..],
            "surface_tension.thin_layer_rows",
        ),
    ] {
        let mut args = vec!["validate", &free];
        for s in sets {
            args.extend(["--set", s]);
        }
        common::assert_input_error(&args, key);
    }
    common::assert_input_error(
        &[
            "validate",
            &scene,
            "--set",
            "surface_tension.model=\"muller\"",
        ],
        "surface_tension.gas",
    );
    // Wetting prescribes the CSF normal (with gas or at a free surface): J22's
    // colour Laplacian has none.
    common::assert_input_error(
        &[
            "validate",
            &common::scene("laplace_free_disc_2d"),
            "--set",
            "surface_tension.model=\"muller\"",
            "--set",
            "surface_tension.contact_angle=60.0",
        ],
        "surface_tension.contact_angle",
    );
}

/// Recoil momentum balance (recoil_layer_2d): a free layer with its top above
/// T_v gains −∫ p_v A dt within 2% (measured 1.0% over 1 µs), and nothing with
/// the recoil switched off (the pair forces cancel: 1e-14 of it measured).
#[test]
fn recoil_momentum_balance_and_nothing_without_it() {
    let name = "recoil_layer_2d";
    assert_stated_tolerance(&scene(name), RECOIL_TOLERANCE);
    let c = run_check(name, &[]);
    assert!(c.pass && c.tolerance == RECOIL_TOLERANCE, "{}", c.line());
    let with = figure(&c, "momentum_gained");
    let off = run_check(name, &["materials.steel.evaporation.recoil=false"]);
    let without = figure(&off, "momentum_gained");
    assert!(with < 0.0, "pushed down: {with}");
    assert!(
        without.abs() < 1e-9 * with.abs(),
        "{without} against {with}"
    );
}

/// /diagnostics of surface-force scenes: the disc's surface Σ V δ against 2πR
/// (measured +1.4% at R = 10Δx, t = 0.3 s) and its mean curvature against 1/R
/// (+8.7%, the bias of the Laplace check); the recoil layer's recoil power is
/// positive (the vapour pushes the surface the way it moves).
#[test]
fn surface_diagnostics_reach_the_mcap() {
    let dir = common::scratch("tension_diagnostics");
    let last = |scene: &str, sets: &[&str]| -> serde_json::Value {
        let mcap = dir.join(format!("{scene}.mcap"));
        let path = common::scene(scene);
        let mut args = vec![
            "run",
            path.as_str(),
            "--backend",
            "cpu",
            "--out",
            mcap.to_str().unwrap(),
        ];
        for s in sets {
            args.extend_from_slice(&["--set", s]);
        }
        let out = spatter(&args);
        assert!(
            matches!(out.status.code(), Some(0) | Some(1)),
            "{:?}",
            text(&out)
        );
        let sum = common::reader(&["summary", mcap.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_slice(&sum.stdout).expect("summary JSON");
        v["last_diagnostics"].clone()
    };
    let d = last("laplace_disc_2d", &["dx=2e-3", "end_time=0.3"]);
    let (r, area, kappa) = (
        0.02,
        d["surface_area"].as_f64().unwrap(),
        d["mean_curvature"].as_f64().unwrap(),
    );
    assert!(
        (area / (2.0 * std::f64::consts::PI * r) - 1.0).abs() < 0.1,
        "{d}"
    );
    assert!((kappa * r - 1.0).abs() < 0.15, "{d}");
    assert_eq!(d["recoil_power"], 0.0, "{d}");
    // η max|u| / σ of the liquid: the spurious currents, well below 0.1.
    let ca = d["capillary_number"].as_f64().unwrap();
    assert!(ca > 0.0 && ca < 0.1, "{d}");
    let d = last("recoil_layer_2d", &[]);
    assert!(d["recoil_power"].as_f64().unwrap() > 0.0, "{d}");
    assert_eq!(d["mean_curvature"], 0.0, "{d}");
    assert_eq!(d["capillary_number"], 0.0, "{d}");
}

/// F22 (33)'s solid–fluid viscosity needs a melting liquid and positive values;
/// `validate` folds it into the viscous Δt limit (α h c/(2(d + 2)): 2.7248e-7 s
/// for the coarse line melt, α = 1, h = 10 µm, c = 36.7 m/s), added to F22 (31)'s
/// interface viscosity (the scene's α_0^lg = 1.2: α = 2.2, 1.2385e-7 s).
#[test]
fn solid_fluid_viscosity_input_and_limit() {
    let line = format!(
        "{}/scenarios/pbf/line_melt_coarse_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let limit = |sets: &[&str]| {
        let mut args = vec!["validate", &line];
        for s in sets {
            args.extend(["--set", s]);
        }
        text(&spatter(&args)).0
    };
    let alone = limit(&["simulation.interface_viscosity=0.0"]);
    assert!(alone.contains("viscous 2.7248e-7 s"), "{alone}");
    let both = limit(&[]);
    assert!(both.contains("viscous 1.2385e-7 s"), "{both}");
    common::assert_input_error(
        &[
            "validate",
            &common::scene("laplace_free_disc_2d"),
            "--set",
            "simulation.solid_fluid_viscosity={coefficient=1.0, width=300.0}",
        ],
        "simulation.solid_fluid_viscosity",
    );
    common::assert_input_error(
        &[
            "validate",
            &line,
            "--set",
            "simulation.solid_fluid_viscosity={coefficient=1.0, width=0.0}",
        ],
        "simulation.solid_fluid_viscosity.width",
    );
}

/// A square drop in gas relaxes to a disc: the outline's radius
/// spread over its sectors below 0.5Δx (the target; measured 0.14Δx at
/// R = 9Δx, from 3.3Δx at the start) and spurious currents with capillary number
/// below 0.1 (measured 4.4e-2; 4.8e-2 and 5.5e-2 at R = 4.5 and 16.9Δx: not
/// falling with Δx, as it should; see docs/validation.md, "Surface tension and
/// wetting").
#[test]
fn square_drop_relaxes_to_a_disc() {
    let c = common::assert_check_passes("square_drop_2d", DROP_SHAPE_TOLERANCE);
    assert!(
        figure(&c, "capillary_number") < CAPILLARY_BOUND,
        "{}",
        c.line()
    );
}

/// The 3D sphere in gas: Δp within 5% of 2σ/R at R = 10Δx (the target). Measured
/// +11.3% (24 min on 2 cores): the ~10% bias of the 2D disc. Too long for CI.
#[test]
#[ignore = "24 min on 2 cores; measured +11.3% at R = 10 dx (target 5%), the 2D disc's ~10% bias; see docs/validation.md"]
fn laplace_sphere_3d_within_5_percent_at_10_dx() {
    common::assert_check_passes("laplace_sphere_3d", LAPLACE_SPHERE_TOLERANCE);
}

/// The sessile drop's check (angle error in degrees), held to the scene's
/// tolerance, which must be `CONTACT_ANGLE_TOLERANCE`.
fn contact_angle(sets: &[&str]) -> CheckResult {
    assert_stated_tolerance(&scene("sessile_drop_2d"), CONTACT_ANGLE_TOLERANCE);
    run_check("sessile_drop_2d", sets)
}

/// Sessile drops settle at their static contact angle within 5° (the target),
/// at R ≈ 10Δx: 90° measured 86.2° (1.5 s), 60° measured 63.3° (3 s: it spreads
/// slowly).
#[test]
fn sessile_drops_at_60_and_90_degrees_within_5() {
    let c = contact_angle(&[]);
    assert!(c.value <= CONTACT_ANGLE_TOLERANCE, "{}", c.line());
    let c = contact_angle(&["surface_tension.contact_angle=60.0", "end_time=3.0"]);
    assert!(c.value <= CONTACT_ANGLE_TOLERANCE, "{}", c.line());
}

/// Wetting on the free-surface CSF (no gas, δ-SPH; sessile_free_drop_2d, 10 s):
/// at 90° and 60° the cap settles within 5° (91.8° and 62.6° measured); 120°
/// reads 111.6°, outside 5° as the gas form's drop of this size is (106.6°),
/// but the three are in the order of their angles, each more than 15° from the
/// others.
#[test]
fn free_surface_sessile_drops_take_their_angles_in_order() {
    let free = |sets: &[&str]| {
        assert_stated_tolerance(&scene("sessile_free_drop_2d"), CONTACT_ANGLE_TOLERANCE);
        run_check("sessile_free_drop_2d", sets)
    };
    let right = free(&[]);
    assert!(right.value <= CONTACT_ANGLE_TOLERANCE, "{}", right.line());
    let angle = |c: &CheckResult| figure(c, "contact_angle_deg");
    let acute = free(&["surface_tension.contact_angle=60.0"]);
    assert!(acute.value <= CONTACT_ANGLE_TOLERANCE, "{}", acute.line());
    let obtuse = free(&["surface_tension.contact_angle=120.0"]);
    let (a, b, c) = (angle(&acute), angle(&right), angle(&obtuse));
    assert!(
        a + 15.0 < b && b + 15.0 < c,
        "60/90/120 read {a:.1}/{b:.1}/{c:.1}"
    );
}

/// A 2D disc of molten steel at rest without gas (R = 25 µm = 6.25 Δx, σ = 1.8
/// N/m, μ = 6 mPa s: grid Ohnesorge number 0.026), free-surface CSF on δ-SPH.
const STEEL_DISC: &str = r#"
[simulation]
dimension = 2
formulation = "delta_wcsph"
kernel = "quintic"
dx = 4.0e-6
gravity = [0.0, 0.0]
pressure_floor = false

[domain]
min = [0.0, 0.0]
max = [1.6e-4, 1.6e-4]
wall_phase = "walls"
open_sides = ["y_max"]

[materials.steel]
density = 7430.0
viscosity = 6.0e-3
sound_speed = 36.7

[phases.melt]
kind = "liquid"
material = "steel"

[phases.walls]
kind = "wall"
material = "steel"

[[shapes]]
phase = "melt"
sphere = { center = [8.0e-5, 8.0e-5], radius = 2.5e-5 }

[surface_tension]
liquid = "melt"
coefficient = 1.8

[run]
end_time = 1.0e-4
"#;

/// The largest distance of a melt particle from the melt's centroid, over R.
fn spread_over_radius(st: &spatter::state::State, melt: u32) -> f32 {
    let ids: Vec<usize> = (0..st.active()).filter(|&i| st.phase[i] == melt).collect();
    let c = |a: usize| ids.iter().map(|&i| st.pos[i][a]).sum::<f32>() / ids.len() as f32;
    let (cx, cy) = (c(0), c(1));
    let r = |i: usize| (st.pos[i][0] - cx).hypot(st.pos[i][1] - cy);
    ids.iter().map(|&i| r(i)).fold(0.0, f32::max) / 2.5e-5
}

/// The free-surface CSF on a low-viscosity melt needs F22 (31)-(32)'s interface
/// viscosity, as F22's CSF with gas does: without it the disc above tears into
/// pieces of 2–5 particles from about 0.07 ms (before 2026-12-06 the run went on
/// to 0.1 ms with exit 0: particles at 3–5 m/s, the farthest 4.3 R from the
/// centroid; run to 1.2 ms it lost 73 of 120 particles that way, none ever
/// alone). The watchdog now stops it, exit 3, naming the pieces, and `validate`
/// warns; with F22's α_0^lg = 7.2 it stays round (farthest 0.94 R, speeds below
/// 1 cm/s) and the warning is gone.
#[test]
fn a_low_viscosity_free_disc_holds_only_with_the_interface_viscosity() {
    let dir = common::scratch("steel_disc");
    let path = dir.join("steel_disc.toml");
    std::fs::write(&path, STEEL_DISC).unwrap();
    let path = path.to_str().unwrap();
    for (alpha, holds) in [(0.0, false), (7.2, true)] {
        let set = format!("simulation.interface_viscosity={alpha}");
        let (stdout, stderr) = text(&spatter(&["validate", path, "--set", &set]));
        let warned = (stdout + &stderr).contains("Ohnesorge");
        assert_eq!(warned, !holds, "alpha {alpha}: the breakup warning");
        if !holds {
            let out = spatter(&["run", path, "--backend", "cpu", "--set", &set]);
            let (o, e) = text(&out);
            assert_eq!(out.status.code(), Some(3), "alpha {alpha}: {o}{e}");
            assert!(
                e.contains("field liquid_dispersion")
                    && e.contains("the free surface is breaking up"),
                "alpha {alpha}: {e}"
            );
            continue;
        }
        let (l, r) = common::run_loaded(path, &[&set], None);
        let melt = l.model.phase_index("melt").unwrap() as u32;
        let st = &r.final_state;
        let spread = spread_over_radius(st, melt);
        let speed = (0..st.active())
            .map(|i| st.vel[i][0].hypot(st.vel[i][1]))
            .fold(0.0, f32::max);
        println!("alpha {alpha}: farthest {spread:.2} R, fastest {speed:.3} m/s");
        assert!(
            spread < 1.1 && speed < 0.05,
            "alpha {alpha}: {spread} R, {speed} m/s"
        );
    }
}

/// 120° within 5°: not met at R ≈ 10Δx, measured 106.6° after 3 s (109.3° at
/// 1.5 s): the drop beads up but stops short, a bias towards 90° that the 60°
/// and 90° drops show too (63.3°, 85.4°). At Δx = 1 mm (R ≈ 20Δx, 2 s, 7 min)
/// 113.7°: the gap halves with Δx. See docs/validation.md ("Surface tension and
/// wetting").
#[test]
#[ignore = "contact angle 106.6 deg for 120 (target within 5 deg) at R = 10 dx; see docs/validation.md"]
fn sessile_drop_at_120_degrees_within_5() {
    let c = contact_angle(&["surface_tension.contact_angle=120.0", "end_time=3.0"]);
    assert!(c.value <= CONTACT_ANGLE_TOLERANCE, "{}", c.line());
}

/// Thermocapillary channel (Pendse & Esmaeeli 2010, scenarios/validation/
/// thermocapillary_2d.toml): the interface velocity profile (20 points per
/// wavelength) within 5% of the analytic amplitude, the target tolerance, at
/// a = 20Δx, and the error falling from a = 10Δx. Measured 8.97% / 4.49% /
/// 2.78% at a = 10 / 20 / 40Δx (8 s, 61 s, 33 min on 2 cores): first order, the
/// Marangoni stress acting over the liquid side's surface delta (liquid rows
/// +27.6% / +14.4% / +7.2% fast, the second fluid's first row −15.5% / −6.2% /
/// −2.4% slow). The target applies at the finest of three resolutions
/// (met at 40Δx, too long for CI); `spatter bench accuracy --scenes
/// thermocapillary_2d` runs all three.
#[test]
fn thermocapillary_interface_velocity_within_5_percent_and_converging() {
    let name = "thermocapillary_2d";
    assert_stated_tolerance(&scene(name), THERMOCAPILLARY_TOLERANCE);
    let coarse = run_check(name, &[]);
    let fine = run_check(name, &["dx=1.25e-5"]);
    assert!(fine.value <= THERMOCAPILLARY_TOLERANCE, "{}", fine.line());
    assert!(
        fine.value < 0.75 * coarse.value,
        "{} then {}",
        coarse.line(),
        fine.line()
    );
    // Steady: the band's amplitude moved less than 1% of U over the last quarter.
    let drift = figure(&fine, "drift");
    assert!(drift < 0.01, "drift {drift} of U: {}", fine.line());
}

/// A wall heated as a cosine (`temperature_wave`) and the thermocapillary check's
/// layout: bad input exits 2 naming the key.
#[test]
fn bad_temperature_wave_and_channel_input_names_the_key() {
    let scene = common::scene("thermocapillary_2d");
    let wave = "phases.hot_wall.temperature_wave";
    for (set, key) in [
        (
            format!("{wave}.amplitude=400.0"),
            format!("{wave}.amplitude"),
        ),
        (
            format!("{wave}.amplitude=-1.0"),
            format!("{wave}.amplitude"),
        ),
        // 1 mm period: 0.3 mm does not divide it.
        (
            format!("{wave}.wavelength=3.0e-4"),
            format!("{wave}.wavelength"),
        ),
        (format!("{wave}.axis=\"z\""), format!("{wave}.axis")),
        (format!("{wave}.axis=\"up\""), format!("{wave}.axis")),
        ("check.surface=1.0".to_string(), "check.surface".to_string()),
        (
            "surface_tension.temperature_coefficient=0.0".to_string(),
            "check.kind".to_string(),
        ),
    ] {
        common::assert_input_error(&["validate", &scene, "--set", &set], &key);
    }
}

/// Per-phase contact angles (F22: per liquid–solid pair): a table naming every
/// wall and solid phase; one phase's table gives the same run as the number
/// (the weighted direction of one angle is that angle to rounding: the sessile
/// drop's figure agrees to the printed digits). Bad tables name the key.
#[test]
fn contact_angle_per_phase() {
    let scene = common::scene("sessile_drop_2d");
    let line = |angle: &str| {
        let set = format!("surface_tension.contact_angle={angle}");
        let c = run_check("sessile_drop_2d", &[&set, "end_time=0.3"]);
        c.details
            .iter()
            .find(|l| l.trim_start().starts_with("contact angle "))
            .unwrap_or_else(|| panic!("no contact angle line: {:?}", c.details))
            .clone()
    };
    assert_eq!(line("60.0"), line("{ substrate = 60.0 }"));
    for (set, key) in [
        (
            "{ substrate = 190.0 }",
            "surface_tension.contact_angle.substrate",
        ),
        ("{ }", "missing the angle on `substrate`"),
    ] {
        common::assert_input_error(
            &[
                "validate",
                &scene,
                "--set",
                &format!("surface_tension.contact_angle={set}"),
            ],
            key,
        );
    }
}

/// `validate` warns on surface tension with gas at a density ratio of
/// 10 or more without F22's interface viscosity, naming F22's values; with it
/// set, no such warning.
#[test]
fn tension_with_gas_and_no_interface_viscosity_warns() {
    let sq = common::scene("square_drop_2d");
    let warned = |sets: &[&str]| {
        let mut args = vec!["validate", sq.as_str()];
        for s in sets {
            args.extend(["--set", s]);
        }
        let out = common::spatter(&args);
        let (o, e) = common::text(&out);
        assert_eq!(out.status.code(), Some(0), "{o}{e}");
        format!("{o}{e}").contains("simulation.interface_viscosity")
    };
    assert!(warned(&["materials.gas.density=10.0"]));
    assert!(warned(&[]), "ratio 10");
    assert!(!warned(&["simulation.interface_viscosity=7.2"]));
    assert!(!warned(&["materials.gas.density=200.0"]), "ratio 5");
}

/// A liquid film on a floor wall: 2 rows thick on the left, 6 on the right, in
/// the free-surface form on δ-SPH.
const FILM: &str = r#"
[simulation]
dimension = 2
formulation = "delta_wcsph"
kernel = "quintic"
dx = 1.0e-3
pressure_floor = false

[domain]
min = [0.0, 0.0]
max = [0.06, 0.02]
periodic = [true, false]
wall_phase = "wall"
open_sides = ["y_max"]

[materials.liquid]
density = 1000.0
viscosity = 0.5
reference_pressure = 1000.0

[phases.liquid]
kind = "liquid"
material = "liquid"

[phases.wall]
kind = "wall"
material = "liquid"

[[shapes]]
phase = "liquid"
box = { min = [0.0, 0.0], max = [0.03, 0.002] }

[[shapes]]
phase = "liquid"
box = { min = [0.03, 0.0], max = [0.06, 0.006] }

[surface_tension]
liquid = "liquid"
coefficient = 0.1

[run]
end_time = 1.0
"#;

/// R18 §4.4's thin-film rule (`thin_layer_rows = 2`): the top row of the
/// 2-row film is flagged and gets no tension force; the 6-row film's top row
/// keeps it. Away from the step between them (one support) and the periodic seam.
#[test]
fn no_tension_on_a_film_of_two_rows() {
    use spatter::backend::Backend;
    use spatter::state::{S_DELTA, S_THIN};
    let run = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let l = spatter::run::load_str("film", FILM, &sets).unwrap();
        let params = spatter::params::Params::new(&l.model, l.state.len() as u32);
        let mut cpu = spatter::backend::cpu::CpuBackend::new(params, l.state.clone());
        // The prime computes the first accelerations: tension included.
        cpu.prime();
        (l.model, cpu.st)
    };
    let (m, on) = run(&["surface_tension.thin_layer_rows=2"]);
    let (_, off) = run(&[]);
    let n = on.len();
    let (mut thin, mut thick) = (0, 0);
    for i in 0..n {
        let x = m.to_world(on.pos[i]);
        let top_thin = (x[1] - 1.5e-3).abs() < 2e-4 && x[0] > 0.006 && x[0] < 0.024;
        let top_thick = (x[1] - 5.5e-3).abs() < 2e-4 && x[0] > 0.036 && x[0] < 0.054;
        if !(top_thin || top_thick) {
            continue;
        }
        assert!(
            on.surface[i][S_DELTA] > 0.0,
            "a top-row particle has a surface delta"
        );
        let flagged = on.surface[n + i][S_THIN] != 0.0;
        assert_eq!(flagged, top_thin, "particle at {x:?}");
        assert_eq!(off.surface[n + i][S_THIN], 0.0);
        if top_thin {
            thin += 1;
            // Without its force the film's top row keeps the forces sweep's
            // acceleration only.
            assert_ne!(on.acc[i], off.acc[i], "tension acts where not flagged");
        } else {
            thick += 1;
            assert_eq!(on.acc[i], off.acc[i], "the thick film keeps its tension");
        }
    }
    assert!(thin >= 15 && thick >= 15, "{thin} {thick}");
    // Bad input: the gas form, and a support too short for the rows asked.
    common::assert_input_error(
        &[
            "validate",
            &common::scene("laplace_disc_2d"),
            "--set",
            "surface_tension.thin_layer_rows=2",
        ],
        "surface_tension.thin_layer_rows",
    );
}
