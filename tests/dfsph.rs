//! Divergence-free SPH (issue 30): the hydrostatic column holds its pressure,
//! the solves stop at their tolerance, and DFSPH's keys are refused where they
//! do not apply. Bit-match on lavapipe is in tests/bitmatch.rs.

mod common;

/// hydrostatic_dfsph_2d: p within 2% rms of ρ g (H − y) (the check's tolerance,
/// J22's "pressure within 2%"), measured 1.2% at the default tolerance; each
/// `/diagnostics` record carries both solves' iterations and residuals, and at
/// rest both end at their tolerance (the density solve after at least two).
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
    let value: f64 = line
        .split(" = ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(value < 0.015, "{line}: measured 1.2% when this landed");
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
    assert!(density["residual"].as_f64().unwrap() <= 1.0e-3, "{last}");
    assert!(divergence["residual"].as_f64().unwrap() <= 1.0e-3, "{last}");
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
        o.contains("passes: neighbors, dfsph, forces, timestep"),
        "{o}"
    );
}
