//! `bench accuracy --quick` and `bench stability --quick` as CI runs them:
//! their JSON holds finite figures, errors fall with Δx where the method converges,
//! and no stability case crashes.

mod common;
use serde_json::Value;

fn run_json(args: &[&str], name: &str) -> Value {
    let json = common::scratch(name).join("bench.json");
    let json_s = json.to_string_lossy().into_owned();
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--backend", "cpu", "--json", &json_s]);
    let out = common::spatter(&all);
    let (stdout, stderr) = common::text(&out);
    println!("{stdout}");
    assert!(out.status.success(), "{stdout}\n{stderr}");
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {v}"))
}

/// For Poiseuille, Couette, conduction_1d and Stefan the error falls with
/// Δx. Measured (quick pair, quintic, 2026-12-02): Poiseuille 7.96e-3 → 4.49e-3 and
/// Couette 9.26e-4 → 5.17e-4 (order 2.0), Stefan 4.07e-3 → 3.38e-3 (0.8), and
/// conduction_1d 1.69e-3 → 1.62e-3: already on its discretisation floor (order 0.2,
/// README, Benchmarks), so it is held to falling but not to an order.
const FALLING: [&str; 4] = ["poiseuille_2d", "couette_2d", "stefan_1d", "conduction_1d"];
/// Those of them whose quick pair must also show an order above ½.
const CONVERGING: [&str; 3] = ["poiseuille_2d", "couette_2d", "stefan_1d"];

#[test]
fn accuracy_quick_reports_finite_figures_and_converges() {
    let plots = common::scratch("bench-accuracy-plots");
    let plots_s = plots.to_string_lossy().into_owned();
    let v = run_json(
        &["bench", "accuracy", "--quick", "--plots", &plots_s],
        "bench-accuracy",
    );
    for name in ["summary", "poiseuille_2d", "stefan_1d"] {
        let png = std::fs::read(plots.join(format!("{name}.png"))).unwrap();
        assert!(
            png.starts_with(b"\x89PNG") && png.len() > 10_000,
            "{name}.png"
        );
    }
    let runs = v["runs"].as_array().unwrap();
    let orders = v["orders"].as_array().unwrap();
    // Each fitted order rests on runs of its scene at two resolutions at least.
    for f in orders {
        let dxs: std::collections::BTreeSet<String> = runs
            .iter()
            .filter(|r| r["scene"] == f["scene"])
            .map(|r| num(r, "dx").to_string())
            .collect();
        assert!(dxs.len() >= 2, "{}: runs at dx {dxs:?}", f["scene"]);
    }
    for r in runs {
        for key in [
            "dx",
            "wall_s",
            "particle_steps_per_s",
            "state_bytes",
            "error",
        ] {
            let x = num(r, key);
            assert!(x.is_finite() && x >= 0.0, "{key} = {x} in {r}");
        }
        assert!(r["steps"].as_u64().unwrap() > 0);
        assert_eq!(r["end"], "completed");
        assert!(r["warnings"].as_array().unwrap().is_empty(), "{r}");
        assert!(r["pass"].as_bool().unwrap(), "{r}");
    }
    let fit = |scene: &str| {
        orders
            .iter()
            .find(|f| f["scene"] == scene)
            .unwrap_or_else(|| panic!("no order fitted for {scene}"))
            .clone()
    };
    for scene in FALLING {
        assert!(fit(scene)["monotone"].as_bool().unwrap(), "{}", fit(scene));
    }
    for scene in CONVERGING {
        assert!(num(&fit(scene), "observed_order") > 0.5, "{}", fit(scene));
    }
}

#[test]
fn stability_quick_has_no_crash() {
    let v = run_json(&["bench", "stability", "--quick"], "bench-stability");
    let cases = v["cases"].as_array().unwrap();
    // Every case is a different one.
    let names: std::collections::HashSet<String> = cases
        .iter()
        .map(|c| {
            format!(
                "{} {} {} {}",
                c["group"], c["family"], c["name"], c["value"]
            )
        })
        .collect();
    assert_eq!(names.len(), cases.len(), "a case ran twice");
    for c in cases {
        assert_ne!(c["outcome"], "crashed", "{c}");
        assert_eq!(num(c, "mass_drift"), 0.0, "{c}");
        assert!(c["steps"].as_u64().unwrap() > 0, "{c}");
        assert!(num(c, "wall_s").is_finite());
        // Every case is a clean lattice: rows that do not fit would be a leak of
        // their own (the random scenes place shapes freely and may warn).
        if c["group"] != "random" {
            assert!(c["warnings"].as_array().unwrap().is_empty(), "{c}");
        }
    }
    for group in ["long run", "extreme", "random"] {
        assert!(cases.iter().any(|c| c["group"] == group), "no {group} case");
    }
}

/// `--only` keeps the cases whose group, family or name contains its text:
/// J22's droplet at 200 m/s alone (`--quick`); a text that matches nothing
/// exits 2 and lists the groups and families.
#[test]
fn stability_only_runs_the_cases_it_names() {
    let v = run_json(
        &["bench", "stability", "--quick", "--only", "impact speed"],
        "bench-stability-only",
    );
    let cases = v["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 1, "{v}");
    assert_eq!(cases[0]["family"], "impact speed (m/s)");
    assert_ne!(cases[0]["outcome"], "crashed", "{}", cases[0]);
    let out = common::spatter(&["bench", "stability", "--quick", "--only", "no such case"]);
    let (_, stderr) = common::text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--only") && stderr.contains("impact speed"),
        "{stderr}"
    );
}

#[test]
fn unknown_accuracy_scene_is_an_input_error() {
    let out = common::spatter(&["bench", "accuracy", "--scenes", "no_such_scene"]);
    let (_, stderr) = common::text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--scenes") && stderr.contains("poiseuille_2d"),
        "{stderr}"
    );
}

/// `bench throughput` over a size the scene refuses: the powder bed's 16 µm
/// grains cover no lattice site at the spacing 1e4 particles need, so that size
/// is skipped with the reason and the next one is measured. Until 2026-12-06 the
/// whole command (as the README gives it, all scenes) ended there with exit 2
/// and wrote no JSON.
#[test]
fn throughput_skips_a_size_its_scene_refuses() {
    let v = run_json(
        &[
            "bench",
            "throughput",
            "--scenes",
            "powder_bed",
            "--sizes",
            "1e4,3e4",
            "--steps",
            "1",
            "--pass-costs-at",
            "0",
        ],
        "throughput_refused_size",
    );
    let skipped = v["skipped"].as_array().expect("skipped");
    assert_eq!(skipped.len(), 1, "{v}");
    let why = skipped[0].as_str().unwrap();
    assert!(
        why.contains("about 10000 particles skipped") && why.contains("powder.diameter.min"),
        "{why}"
    );
    let rows = v["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 1, "{v}");
    assert!(num(&rows[0], "particle_steps_per_s") > 0.0, "{v}");
}
