//! R18 §5.1.1's 2D powder-bed track power study (R18 Table 5.3): the
//! scene `scenarios/pbf/r18_track_2d.toml` swept over R18's 50, 100, 150 and
//! 200 W (P / 54 µm per metre of depth), each run to R18's t = 0.26 ms on the
//! coarse 8 µm lattice (3 690 particles, about 15 s a run). The `r18_track`
//! check writes each run's penetration, peak temperature and speed beside
//! R18's into the run's summary.
//!
//! What holds on the coarse track, and is asserted: the substrate penetration
//! rises with power (R18 0 / 6 / 30 / 42 µm; measured 0 / 4.2 / 12.4 / 14.6
//! µm), with none at 50 W, as R18. What is printed only: the peak temperature
//! and speed at 0.26 ms (neighbourhood means; measured 2117 / 2776 / 4732 /
//! 5112 K against R18's 2700 / 3833 / 4600 / 6100 K, and 2.4 / 1.7 / 1.9 /
//! 3.0 m/s against 1.2 / 2.8 / 3.5 / 6.0 m/s). They hang on single events: a
//! power of 1.8519e6 instead of 1.85185e6 W/m put a droplet lifted off the
//! 100 W pool at 6487 K.

mod common;
use common::{spatter, text};

const R18_WATTS: [f64; 4] = [50.0, 100.0, 150.0, 200.0];
const SLICE_DEPTH: f64 = 5.4e-5;

#[test]
fn r18_power_study_penetration_rises_with_power() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/pbf/r18_track_2d.toml"
    );
    let dir = common::scratch("r18_power");
    let _ = std::fs::remove_dir_all(&dir);
    let powers: Vec<String> = R18_WATTS
        .iter()
        .map(|w| format!("{:.5e}", w / SLICE_DEPTH))
        .collect();
    let vary = format!("laser.power={}", powers.join(","));
    let out = spatter(&[
        "sweep",
        scene,
        "--vary",
        &vary,
        "--jobs",
        "2",
        "--backend",
        "cpu",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let (o, e) = text(&out);
    let mut penetration = Vec::new();
    for (k, watts) in R18_WATTS.iter().enumerate() {
        let summary = dir.join(format!("cell_{k:03}")).join("summary.json");
        let s: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(&summary).unwrap_or_else(|e| panic!("{o}{e}: {e}")),
        )
        .unwrap();
        let f = &s["figures"]["check"]["figures"];
        let fig = |name: &str| f[name].as_f64().unwrap_or_else(|| panic!("{name} in {s}"));
        assert!((fig("watts") - watts).abs() < 0.01, "{s}");
        println!(
            "{watts:>4} W: penetration {:5.1} um (R18 {:4.1}), max T {:5.0} K (R18 {:4.0}), \
             max speed {:4.2} m/s (R18 {:3.1}), exit {}",
            fig("penetration_m") * 1e6,
            fig("r18_penetration_m") * 1e6,
            fig("max_temperature_K"),
            fig("r18_max_temperature_K"),
            fig("max_speed_m_s"),
            fig("r18_max_speed_m_s"),
            s["exit_code"]
        );
        let code = s["exit_code"].as_i64();
        assert!(
            matches!(code, Some(0 | 1)),
            "cell {k}: exit {code:?}: {o}{e}"
        );
        penetration.push(fig("penetration_m"));
    }
    // Exit 1 is the check's FAIL (150 and 200 W fall short of R18 by more
    // than 2 dx); an input error or an unstable run would be 2 or 3.
    assert_eq!(penetration[0], 0.0, "50 W melts no substrate (R18: 0 um)");
    for w in penetration.windows(2) {
        assert!(
            w[1] > w[0],
            "penetration does not rise with power: {penetration:?}"
        );
    }
}
