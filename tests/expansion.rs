//! Thermal expansion on δ-SPH (R18 §4.3.1): a density law ρ0(T) drives each
//! particle to the volume its temperature asks for, with mass exact.

mod common;
use common::{figure, run_check, scene};

/// R18 Test 1, a load-free drop cycled ±50 K (±5% density): the interior's mean
/// volume error below R18's 0.4%, the band 0.8–0.9 R below its 0.8%, not
/// growing. The scene's full 10 cycles measure 2.5e-3 interior; here two
/// cycles (CI time), where the start's acoustic ringing (amplitude about u/c =
/// 0.16/40) is at its largest, so the figure is the run's worst. The tolerances
/// are the scene file's.
#[test]
fn thermal_cycle_drop_takes_the_volume_its_temperature_asks_for() {
    let path = scene("thermal_cycle_drop_2d");
    common::assert_stated_tolerance(&path, 0.004);
    assert_eq!(common::file_check_value(&path, "band_tolerance"), 0.008);
    let c = run_check("thermal_cycle_drop_2d", &["run.end_time=2.0"]);
    assert!(c.pass, "{}", c.line());
    assert!(figure(&c, "band_error") < 0.008, "{}", c.line());
    assert!(
        figure(&c, "late_error") <= figure(&c, "early_error"),
        "{}",
        c.line()
    );
}

/// R18 Test 3: the lower fluid's ρ0 falls 10% under a fluid that keeps its
/// own; each fluid's height against its true volume over the tank's width. The
/// scene (dx = L0/20) measures 0.72%, within R18's 1% (its stated tolerance);
/// that run takes 81 s, so CI runs dx = L0/10 (22 s), where the error is
/// first order in dx: 1.70% (the upper column, 10 particles wide, in its
/// vertical mode at t = 2.85 s), 0.72% at L0/15. Held here to 2%, the coarse
/// figure with a margin of 0.3 points; the lower fluid's true volume must grow
/// by the law's 1000/900 − 1 = 11.1%.
#[test]
fn column_expands_with_its_lower_fluid() {
    common::assert_stated_tolerance(&scene("column_expansion_2d"), 0.01);
    let c = run_check("column_expansion_2d", &["simulation.dx=0.1"]);
    assert!(c.value < 0.02, "{}", c.line());
    let grown = figure(&c, "expansion");
    assert!((grown - 1.0 / 9.0).abs() < 1e-3, "true volume grew {grown}");
}

/// R18 Test 4, a 2000 kg/m³ blob sinking in 1000 kg/m³: the interior pressure
/// noise (RMS departure from the neighbours' smooth mean, over ρ_l g H) of the
/// compatible δ-SPH (diffusion on ρ − ρ0) within the scene's 0.02 (one particle
/// row's hydrostatic step), and R18's contrast: the raw-ρ diffusion and
/// summation density noisier. Over the first 0.4 s (CI time) measured 7.5e-3,
/// 6.2e-2 and 2.5e-2; held to 3× and 2× the compatible figure.
#[test]
fn sinking_blob_pressure_is_smooth_only_with_the_compatible_diffusion() {
    common::assert_stated_tolerance(&scene("sinking_blob_2d"), 0.02);
    let short = "run.end_time=0.4";
    let compatible = run_check("sinking_blob_2d", &[short]);
    assert!(compatible.pass, "{}", compatible.line());
    let raw = run_check(
        "sinking_blob_2d",
        &[short, "simulation.density_diffusion=\"raw\""],
    );
    assert!(raw.value > 3.0 * compatible.value, "raw: {}", raw.line());
    let wcsph = run_check(
        "sinking_blob_2d",
        &[
            short,
            "simulation.formulation=\"wcsph\"",
            "simulation.pressure_floor=true",
        ],
    );
    assert!(
        wcsph.value > 2.0 * compatible.value,
        "wcsph: {}",
        wcsph.line()
    );
}

/// R18 Test 2, the drop of Test 1 under a cycle whose amplitude grows until
/// the drop splits: the density increase ρ_max/ρ_min − 1 reached before the
/// first piece comes off (farther than the kernel's support from the rest)
/// within 5% of R18's "about 140%" (read off a plot; 1.41/0.59 − 1 = 139%).
/// The scene (dx = R/20, h = 3 dx, 249 s) measures 136%; CI runs dx = R/10
/// (30 s), which measures 136% too. At h = 2 dx the drop split at 23% (R/20)
/// and 110% (R/10): the scene says why it departs from the kernel's default.
#[test]
fn rising_amplitude_drop_holds_to_r18s_density_increase() {
    common::assert_stated_tolerance(&scene("rising_amplitude_drop_2d"), 0.05);
    let c = run_check("rising_amplitude_drop_2d", &["simulation.dx=0.1"]);
    assert!(c.pass, "{}", c.line());
    let reached = figure(&c, "density_ratio_increase");
    assert!(reached > 1.3 && reached < 1.6, "{}", c.line());
}
