//! Divergence-free SPH: the hydrostatic column holds its pressure,
//! the implicit viscosity gives Poiseuille's profile at 100× the explicit
//! step, the solves stop at their tolerance, and DFSPH's keys are refused
//! where they do not apply. Bit-match on lavapipe is in tests/bitmatch.rs.

mod common;

/// The number that follows `label` in a line of a run's output.
fn number_after(line: &str, label: &str) -> f64 {
    let rest = line.split(label).nth(1).expect(line);
    rest.split_whitespace().next().unwrap().parse().expect(line)
}

/// hydrostatic_dfsph_2d: p within 2% rms of ρ g (H − y) (the check's tolerance,
/// J22's "pressure within 2%"), measured 0.51% at the scene's tolerances;
/// each `/diagnostics` record carries the three solves' iterations and
/// residuals, and at rest all end at their tolerance (the density solve after
/// at least two).
#[test]
fn hydrostatic_column_holds_its_pressure_within_2_percent() {
    let mcap = common::scratch("dfsph_column").join("column.mcap");
    let out = common::spatter(&[
        "run",
        &common::scene("hydrostatic_dfsph_2d"),
        "--backend",
        "cpu",
        "--out",
        mcap.to_str().unwrap(),
    ]);
    let (o, e) = common::text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    let line = o
        .lines()
        .find(|l| l.starts_with("check hydrostatic"))
        .expect(&o);
    assert!(line.ends_with("PASS"), "{line}");
    let value = number_after(line, " = ");
    assert!(value < 0.01, "{line}: measured 0.51% when this landed");
    let bytes = std::fs::read(&mcap).unwrap();
    let last: serde_json::Value = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/diagnostics")
        .map(|m| serde_json::from_slice(&m.data).unwrap())
        .last()
        .unwrap();
    let density = &last["solvers"]["dfsph_density"];
    let divergence = &last["solvers"]["dfsph_divergence"];
    assert_eq!(density["converged"], true, "{last}");
    assert_eq!(divergence["converged"], true, "{last}");
    assert!(density["iterations"].as_u64().unwrap() >= 2, "{last}");
    assert!(density["residual"].as_f64().unwrap() <= 5.0e-4, "{last}");
    assert!(divergence["residual"].as_f64().unwrap() <= 1.0e-3, "{last}");
    let viscosity = &last["solvers"]["dfsph_viscosity"];
    assert_eq!(viscosity["converged"], true, "{last}");
    assert!(viscosity["residual"].as_f64().unwrap() <= 1.0e-3, "{last}");
}

/// poiseuille_dfsph_2d: the implicit viscosity (F22 (23)'s form solved by
/// conjugate gradients) at a fixed step 100× the explicit limit 0.125 h²/ν
/// (64 steps where the explicit one needs 6 400) within 2% of the series
/// solution (the check's tolerance, as on WCSPH's Poiseuille); measured 0.17%.
/// Weiler et al.'s projected form (`viscosity_form = "marrone"`, J22 (17)'s) is
/// 0.83× the Laplacian at h = Δx with the quintic (terms/marrone_viscosity.rs)
/// and measures 18%: it is reported, not asserted to pass.
#[test]
fn implicit_viscosity_gives_poiseuille_at_100_times_the_explicit_step() {
    let scene = common::scene("poiseuille_dfsph_2d");
    // A check that fails exits 1.
    let run = |sets: &[&str], code: i32| {
        let mut args = vec!["run", scene.as_str(), "--backend", "cpu"];
        for s in sets {
            args.extend(["--set", s]);
        }
        let out = common::spatter(&args);
        let (o, e) = common::text(&out);
        assert_eq!(out.status.code(), Some(code), "{o}{e}");
        o
    };
    let o = run(&[], 0);
    assert!(o.contains("steps: 64,"), "{o}");
    let line = o
        .lines()
        .find(|l| l.starts_with("check poiseuille"))
        .expect(&o);
    assert!(line.ends_with("PASS"), "{line}");
    let value = number_after(line, " = ");
    assert!(value < 0.005, "{line}: measured 0.17% when this landed");
    let o = run(&["simulation.viscosity_form=\"marrone\""], 1);
    let line = o
        .lines()
        .find(|l| l.starts_with("check poiseuille"))
        .expect(&o);
    println!("Weiler / Marrone form: {line}");
}

/// scenarios/spray/j22_fluent_case_2d (J22's Fluent comparison, 2D coarse):
/// impact, mean vertical velocity through zero and stop within 15% of J22's
/// 0.5, 1.0 and 2.0 µs (the check's tolerance); measured
/// (0.501, 0.982, 1.90 µs: 1.8%). The splat spreads (a cylinder: 3.76 D0).
#[test]
fn spray_droplet_impact_matches_j22_timings() {
    let out = common::spatter(&[
        "run",
        &common::scene_at("spray/j22_fluent_case_2d"),
        "--backend",
        "cpu",
    ]);
    let (o, e) = common::text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    let line = o.lines().find(|l| l.starts_with("check splat")).expect(&o);
    assert!(line.ends_with("PASS"), "{o}");
    let summary = o.lines().find(|l| l.contains("spread factor")).expect(&o);
    let xi = number_after(summary, "spread factor ");
    assert!(xi > 2.0, "{summary}: the splat must spread");
}

/// J22 (23)–(24)'s single-layer Akinci boundary (`dfsph.boundary = "akinci"`)
/// with J22's kernel, the cubic spline at h = Δx (support 2Δx). On the column
/// at rest one layer holds the pressure as the two-layer lattice does with the
/// same kernel (measured 5.13% against 4.89% of ρgH; the quintic on three
/// layers 0.51%: the cubic at h = Δx is the coarser kernel, docs/physics.md),
/// with 924 particles instead of 1 056; nothing leaks through the floor. The
/// 2D spray droplet keeps J22's timings (measured 3.5%).
#[test]
fn akinci_boundary_holds_the_column_with_one_layer() {
    let cubic = ["simulation.kernel=\"cubic\"", "simulation.h_over_dx=1.0"];
    let run = |boundary: &str| {
        let set = format!("simulation.dfsph.boundary=\"{boundary}\"");
        let mut sets = cubic.to_vec();
        sets.push(&set);
        let r = common::run_path(&common::scene("hydrostatic_dfsph_2d"), &sets, None);
        assert_eq!(r.end, spatter::run::RunEnd::Completed, "{boundary}");
        (r.final_state.len(), r.check.expect("a check").value)
    };
    let (n_lattice, e_lattice) = run("lattice");
    let (n_akinci, e_akinci) = run("akinci");
    assert!(n_akinci < n_lattice, "{n_akinci} against {n_lattice}");
    // Within 10% of the lattice walls' error with the same kernel (5.13 / 4.89
    // = 1.05 measured), and below the cubic's 6%.
    assert!(
        e_akinci <= 1.1 * e_lattice && e_akinci < 0.06,
        "akinci {e_akinci:.4} against lattice {e_lattice:.4}"
    );
    let out = common::spatter(&[
        "run",
        &common::scene_at("spray/j22_fluent_case_2d"),
        "--backend",
        "cpu",
        "--set",
        cubic[0],
        "--set",
        cubic[1],
        "--set",
        "simulation.dfsph.boundary=\"akinci\"",
    ]);
    let (o, e) = common::text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    assert!(
        o.lines()
            .any(|l| l.starts_with("check splat") && l.ends_with("PASS")),
        "{o}"
    );
}

/// The solves' keys need the formulation, and DFSPH refuses what it does not
/// take yet, each with exit 2 naming the key.
#[test]
fn dfsph_keys_are_checked() {
    let wcsph = common::scene("hydrostatic_2d");
    let dfsph = common::scene("hydrostatic_dfsph_2d");
    common::assert_input_error(
        &[
            "validate",
            &wcsph,
            "--set",
            "simulation.dfsph={ density_tolerance = 1e-4 }",
        ],
        "simulation.dfsph",
    );
    common::assert_input_error(
        &[
            "validate",
            &dfsph,
            "--set",
            "simulation.dfsph.density_tolerance=0.0",
        ],
        "simulation.dfsph.density_tolerance",
    );
    common::assert_input_error(
        &[
            "validate",
            &dfsph,
            "--set",
            "simulation.dfsph.max_iterations=0",
        ],
        "simulation.dfsph.max_iterations",
    );
    common::assert_input_error(
        &[
            "validate",
            &dfsph,
            "--set",
            "simulation.pressure_floor=true",
        ],
        "simulation.pressure_floor",
    );
    for (set, key) in [
        ("simulation.dfsph.xsph=1.5", "simulation.dfsph.xsph"),
        (
            "simulation.dfsph.cohesion=-1.0",
            "simulation.dfsph.cohesion",
        ),
        (
            "simulation.dfsph={ viscosity = \"explicit\", adhesion = 1e14 }",
            "simulation.dfsph.adhesion",
        ),
        (
            "simulation.dfsph.viscosity_max_iterations=0",
            "simulation.dfsph.viscosity_max_iterations",
        ),
        (
            "simulation.dfsph.viscosity_tolerance=-1.0",
            "simulation.dfsph.viscosity_tolerance",
        ),
        (
            "simulation.dfsph={ viscosity = \"explicit\", xsph = 0.3 }",
            "simulation.dfsph.xsph",
        ),
        ("run.dt=1e-3", "run.max_dt"),
        ("run.max_dt=0.0", "run.max_dt"),
        // One Akinci layer under the quintic's three-spacing support.
        (
            "simulation.dfsph.boundary=\"akinci\"",
            "simulation.dfsph.boundary",
        ),
        (
            "simulation.dfsph.boundary=\"one_layer\"",
            "simulation.dfsph.boundary",
        ),
    ] {
        common::assert_input_error(&["validate", &dfsph, "--set", set], key);
    }
    // The splat check's droplet phase and reference spread factor.
    let spray = common::scene_at("spray/j22_fluent_case_2d");
    for (set, key) in [
        ("check.phase=\"substrate\"", "check.phase"),
        ("check.spread_factor=0.5", "check.spread_factor"),
    ] {
        common::assert_input_error(&["validate", &spray, "--set", set], key);
    }
    // Weiler's form is the implicit solve's option only.
    common::assert_input_error(
        &[
            "validate",
            &dfsph,
            "--set",
            "simulation.dfsph.viscosity=\"explicit\"",
            "--set",
            "simulation.viscosity_form=\"marrone\"",
        ],
        "simulation.viscosity_form",
    );
    common::assert_input_error(
        &[
            "validate",
            &dfsph,
            "--set",
            "simulation.kernel=\"wendland_c2\"",
        ],
        "simulation.kernel",
    );
    let out = common::spatter(&["validate", &dfsph]);
    let (o, e) = common::text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    assert!(
        o.contains("repeat <= 100 until converged [dfsph.divergence_iterate"),
        "{o}"
    );
    assert!(
        o.contains("repeat <= 100 until converged [dfsph.viscosity_apply"),
        "{o}"
    );
    assert!(o.contains("viscous none (implicit"), "{o}");
    assert!(
        o.contains("passes: neighbors, dfsph, dfsph_viscosity, forces, timestep"),
        "{o}"
    );
}

/// The droplet impact of `bench accuracy` (scenarios/validation/drop_impact_3d):
/// F22's steel, D = 50 µm at 50 m/s, on δ-SPH as written and on DFSPH. The
/// wall force's peak (triangle-filtered over D/(12 V)) against the inertial-regime 0.8 ρV²D²
/// within 10%, the scene's tolerance: the literature quotes the prefactor to a
/// few percent, and the peak of a sampled particle force scatters by a few
/// percent more. Measured at the scene's D = 16 Δx: 0.801 (δ-SPH) and 0.853
/// (DFSPH); at 20 and 24 Δx 0.838, 0.831 and 0.807, 0.874; at 12 Δx 1.056 and
/// 0.948 (docs/benchmarks.md). The force rises only after the contact less
/// the kernel's reach.
#[test]
fn droplet_impact_force_within_10_percent_on_both_formulations() {
    const TOLERANCE: f64 = 0.1;
    common::assert_stated_tolerance(&common::scene("drop_impact_3d"), TOLERANCE);
    for sets in [
        &[][..],
        &[
            "simulation.formulation=\"dfsph\"",
            "simulation.initial_pressure=\"zero\"",
        ][..],
    ] {
        let c = common::run_check("drop_impact_3d", sets);
        assert!(c.pass, "{sets:?}: {}", c.line());
        let (peak, when) = (
            common::figure(&c, "peak_force"),
            common::figure(&c, "peak_time"),
        );
        assert!(when > 0.0 && when < 0.5, "{sets:?}: peak at t V/D = {when}");
        assert!(common::figure(&c, "raw_peak_force") >= peak, "{sets:?}");
        let d = common::figure(&c, "diameter");
        assert!((d - 5.0e-5).abs() < 0.02 * 5.0e-5, "{sets:?}: D = {d}");
    }
}

/// impact_force takes a 3D droplet (its reference is a sphere's).
#[test]
fn impact_force_check_refuses_a_2d_scene() {
    common::assert_input_error(
        &[
            "validate",
            &common::scene_at("spray/j22_fluent_case_2d"),
            "--set",
            "check.kind=\"impact_force\"",
        ],
        "check.kind",
    );
}

/// A run ends at its end time, not after it: the timestep pass shortens the
/// last steps to land on it and the run loop never runs a chunk past that
/// step. Before, a DFSPH splat whose Δt grew inside a chunk overshot by up to a
/// third of the run (36 µs asked, 48.5 µs run). Checked on DFSPH (the 2D spray
/// droplet, Δt following the flow, one frame a microsecond) and on WCSPH (the
/// dam break, an end that is no multiple of anything), both against the
/// printed simulated time, to f32 time's rounding (END_SLACK, 1e-6 of it).
#[test]
fn runs_end_at_their_end_time() {
    let cases = [
        (
            common::scene_at("spray/j22_fluent_case_2d"),
            vec!["dx=4e-6", "end_time=3.3e-6", "output_interval=1e-6"],
            3.3e-6,
        ),
        (
            common::scene("dam_break_2d"),
            vec!["dx=0.01", "end_time=0.0123457", "output_interval=0.01"],
            0.0123457,
        ),
    ];
    for (scene, sets, end) in cases {
        let out_dir = common::scratch(&format!("end_time_{end:e}"));
        let mut args = vec!["run", &scene, "--backend", "cpu"];
        let out_arg = out_dir.join("run.mcap").to_string_lossy().to_string();
        args.extend(["--out", &out_arg]);
        for s in &sets {
            args.extend(["--set", s]);
        }
        let out = common::spatter(&args);
        let (o, e) = common::text(&out);
        let all = format!("{o}{e}");
        let line = all
            .lines()
            .find(|l| l.contains("simulated time:"))
            .expect(&all);
        let t = number_after(line, "simulated time: ");
        assert!(
            (t - end).abs() <= 1e-6 * end,
            "{scene}: ended at {t:e} s, asked {end:e} s\n{all}"
        );
    }
}

/// A particle with fewer neighbours than a quarter of the lattice's
/// (`Solve::dfsph_min_neighbours`) takes no part in the divergence solve: its
/// factor α = ρ / Σ|m ∇W|² grows as (3 − r/Δx)⁻⁸ as a neighbour nears the
/// support's edge, and κ with it. Before the rule, this pair (each at a sixth
/// of ρ0, not in contact) read 4e7 / 4e11 / 4e15 / 4e19 Pa when it met at
/// 2.9 / 2.99 / 2.999 / 2.9999 Δx, and the solve stopped its approach there;
/// in the 3D spread at D0/Δx = 25 a lone droplet particle took κ = 6e15 from
/// the sheet at 2.985 Δx and, warm-started on the next step with the pair
/// closer, left at 1e4 m/s through the floor (exit 3). Now the pair passes
/// through each other's support at its speed (within 1%: the viscosity acts),
/// at zero pressure.
#[test]
fn a_lone_pair_meeting_at_the_support_edge_keeps_its_speed() {
    use spatter::backend::cpu::CpuBackend;
    use spatter::backend::Backend;
    use spatter::params::Params;
    let l = spatter::run::load_str("lone_pair.toml", common::DFSPH_LONE_PAIR, &[]).unwrap();
    let params = Params::new(&l.model, l.state.len() as u32);
    assert_eq!(
        params.solve.dfsph_min_neighbours, 6,
        "24 lattice neighbours / 4"
    );
    for gap in [2.9f32, 2.99, 2.999, 2.9999] {
        let mut st = l.state.clone();
        let moving = common::close_lone_pair(&mut st, gap);
        let mut cpu = CpuBackend::new(params, st);
        cpu.prime();
        for step in 0..10 {
            cpu.run_steps(1);
            let s = cpu.read_state().unwrap();
            for i in 0..s.len() {
                let v = s.vel[i];
                let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
                let expected = if s.id[i] == l.state.id[moving] {
                    1.0
                } else {
                    0.0
                };
                assert!(
                    // The implicit viscosity (1 mPa s) shares 0.13% of the
                    // momentum by step 7 (1.15 Δx apart).
                    (speed - expected).abs() < 1.0e-2 && s.press[i] == 0.0,
                    "gap {gap} dx, step {step}: particle {} at {speed} m/s, {} Pa",
                    s.id[i],
                    s.press[i]
                );
            }
        }
    }
}

/// J22 §4.2's 30 µm spread on its meltable 440C substrate, the coarse variant
/// (D0/Δx = 15, 48 540 particles, about 75 s on 2 cores): the splat's D/D0 at
/// 2 µs within the scene's 10% of J22's 2.00 (measured 1.955, 2.2%). This is
/// the spread that converges to J22's figure (2.084 and 2.059 at D0/Δx = 20
/// and 25); the 45 and 62 µm spreads stay FAIL at every resolution run (their
/// figures and the cause are in docs/validation.md), so only this one is held here.
/// The transient sheet's D_max/D0 is printed beside 0.5 Re^0.25 (2.725 against
/// 2.307).
#[test]
fn j22_spread_30um_within_10_percent_of_j22() {
    let out = common::spatter(&[
        "run",
        &common::scene_at("spray/j22_spread_30um_3d"),
        "--backend",
        "cpu",
    ]);
    let (o, e) = common::text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    let line = o.lines().find(|l| l.starts_with("check splat")).expect(&o);
    assert!(line.ends_with("PASS"), "{line}");
    assert!(line.contains("(tolerance 1.0000e-1)"), "{line}");
    let summary = o.lines().find(|l| l.contains("spread factor")).expect(&o);
    assert!(summary.contains("0.5 Re^0.25"), "{summary}");
}
