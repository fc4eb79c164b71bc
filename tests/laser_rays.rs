//! The ray-traced laser (`laser.model = "ray_traced"`): absorption from the
//! materials' optical constants by the Fresnel equations, with specular
//! reflections, against closed-form totals; its energy balance; its inputs.

mod common;
use spatter::backend::cpu::CpuBackend;
use spatter::backend::{Backend, Stage};
use spatter::model::fresnel_absorptivity;
use spatter::params::Params;
use spatter::run::load;
use spatter::state::{State, H_RATE, RAYS_ABSORBED, RAYS_AT_LIMIT, RAYS_INCIDENT, RAYS_LEAVING};

/// Nickel at 1.07 µm (Rakić et al. 1998), as in the scene.
const N: f64 = 2.88;
const K: f64 = 5.26;

/// A flat plate absorbs the normal-incidence Fresnel value within 1%: every ray
/// meets the surface once, where the bins' filled fraction crosses ½ and its
/// gradient is vertical.
const FLAT_TOLERANCE: f64 = 0.01;
/// A 90° groove: every ray meets two walls at 45° (1 − (1 − A(45°))²) within 2%:
/// the walls are staircases of particles, smoothed to planes by the bins'
/// interpolation.
const GROOVE_TOLERANCE: f64 = 0.02;

struct Split {
    incident: f64,
    absorbed: f64,
    leaving: f64,
    at_limit: f64,
    /// Σ m q over the particles after the deposit (W; W/m in 2D).
    deposited: f64,
    unit: f64,
    counts: Vec<u32>,
}

/// One neighbour and laser stage of the scene (after `prepare`) on the CPU.
fn trace(
    path: &str,
    sets: &[&str],
    prepare: impl FnOnce(&spatter::model::Model, &mut State),
) -> Split {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let mut l = load(path, &sets).unwrap();
    prepare(&l.model, &mut l.state);
    let params = Params::new(&l.model, l.state.len() as u32);
    let mut cpu = CpuBackend::new(params, l.state);
    cpu.run_stage(Stage::Neighbors);
    cpu.run_stage(Stage::Laser);
    let st = &cpu.st;
    let unit = params.laser.power_unit as f64;
    let c = st.laser_rays.clone();
    let deposited = (0..st.active())
        .map(|i| st.mass[i] as f64 * st.heat[i][H_RATE] as f64)
        .sum();
    Split {
        incident: c[RAYS_INCIDENT] as f64 * unit,
        absorbed: c[RAYS_ABSORBED] as f64 * unit,
        leaving: c[RAYS_LEAVING] as f64 * unit,
        at_limit: c[RAYS_AT_LIMIT] as f64 * unit,
        deposited,
        unit,
        counts: c,
    }
}

fn plate() -> String {
    common::scene("laser_ray_plate")
}

/// The energy balance: incident = absorbed + leaving in the integer counts,
/// the launched power within 1e-6 of the beam's, the particles' sources within
/// 1e-6 of the absorbed sum.
fn assert_balance(s: &Split, power: f64) {
    assert_eq!(
        s.counts[RAYS_INCIDENT] as u64,
        s.counts[RAYS_ABSORBED] as u64 + s.counts[RAYS_LEAVING] as u64,
        "counts {:?}",
        s.counts
    );
    assert!((s.absorbed + s.leaving - s.incident).abs() <= 1e-6 * power);
    assert!(
        (s.incident - power).abs() < 1e-6 * power,
        "incident {} against {power} (unit {})",
        s.incident,
        s.unit
    );
    assert!(
        (s.deposited - s.absorbed).abs() < 1e-6 * s.absorbed,
        "deposited {} against absorbed {}",
        s.deposited,
        s.absorbed
    );
}

#[test]
fn flat_plate_absorbs_the_normal_incidence_fresnel_value_2d() {
    let s = trace(&plate(), &[], |_, _| {});
    let exact = fresnel_absorptivity(N, K, 1.0);
    let a = s.absorbed / s.incident;
    println!("2D flat plate: absorbed {a:.5} against Fresnel {exact:.5}");
    assert!((a - exact).abs() < FLAT_TOLERANCE * exact, "{a} {exact}");
    assert_eq!(s.at_limit, 0.0);
    assert_balance(&s, 2.0e4);
    // a top-hat beam of the same radius: the same single normal hit
    let t = trace(&plate(), &["laser.profile=\"top_hat\""], |_, _| {});
    let at = t.absorbed / t.incident;
    assert!((at - exact).abs() < FLAT_TOLERANCE * exact, "{at} {exact}");
    assert_balance(&t, 2.0e4);
}

/// A run's absorbed fraction (the closing line and `--summary`'s `laser`):
/// Σ absorbed / Σ incident over the states read back with the beam on, so the
/// flat plate's reads Fresnel's normal value over every sample.
#[test]
fn a_run_reports_its_absorbed_fraction_over_the_samples() {
    let r = common::run_path(&plate(), &["output_interval=2.5e-7"], None);
    let s = r
        .laser
        .expect("a ray-traced run reports its absorbed fraction");
    let exact = fresnel_absorptivity(N, K, 1.0);
    assert!(s.samples >= 4, "{} samples", s.samples);
    assert!(
        (s.absorbed_fraction - exact).abs() < FLAT_TOLERANCE * exact,
        "{} {exact}",
        s.absorbed_fraction
    );
    assert!(s.fraction_min <= s.absorbed_fraction && s.absorbed_fraction <= s.fraction_max);
    assert!(
        (s.incident_mean - 2.0e4).abs() < 1e-6 * 2.0e4,
        "{}",
        s.incident_mean
    );
}

/// The same plate in 3D (a 300 × 300 µm patch at Δx = 10 µm, beam r_w = 50 µm).
#[test]
fn flat_plate_absorbs_the_normal_incidence_fresnel_value_3d() {
    let text = std::fs::read_to_string(plate())
        .unwrap()
        .replace("dimension = 2", "dimension = 3")
        .replace("dx = 5.0e-6", "dx = 1.0e-5")
        .replace(
            "min = [0.0, 0.0]\nmax = [4.0e-4, 2.5e-4]",
            "min = [0.0, 0.0, 0.0]\nmax = [3.0e-4, 3.0e-4, 2.0e-4]",
        )
        .replace(
            "box = { min = [0.0, 0.0], max = [4.0e-4, 1.5e-4] }",
            "box = { min = [0.0, 0.0, 0.0], max = [3.0e-4, 3.0e-4, 1.0e-4] }",
        )
        .replace("open_sides = [\"y_max\"]", "open_sides = [\"z_max\"]")
        .replace("power = 2.0e4", "power = 100.0")
        .replace("path = [[0.0, 2.0e-4]]", "path = [[0.0, 1.5e-4, 1.5e-4]]");
    let dir = common::scratch("laser_rays_3d");
    let path = dir.join("plate_3d.toml");
    std::fs::write(&path, text).unwrap();
    let s = trace(path.to_str().unwrap(), &[], |_, _| {});
    let exact = fresnel_absorptivity(N, K, 1.0);
    let a = s.absorbed / s.incident;
    println!("3D flat plate: absorbed {a:.5} against Fresnel {exact:.5}");
    assert!((a - exact).abs() < FLAT_TOLERANCE * exact, "{a} {exact}");
    assert_balance(&s, 100.0);
}

/// A 90° V-groove 80 µm deep cut into the plate (its particles handed to the
/// void phase, which takes no light), the beam (r_w = 15 µm) centred on the
/// middle of its left wall: each ray hits the left wall at 45°, crosses the
/// groove level, hits the right wall at 45° and leaves straight up, so the
/// plate absorbs 1 − (1 − A(45°))², Fresnel at 45° on both hits.
#[test]
fn v_groove_absorbs_the_two_bounce_fresnel_total() {
    let vertex = [2.0e-4f32, 7.0e-5f32];
    let sets = ["laser.radius=1.5e-5", "laser.path=[[0.0, 1.6e-4]]"];
    let s = trace(&plate(), &sets, |m, st| groove(m, st, vertex));
    let a45 = fresnel_absorptivity(N, K, std::f64::consts::FRAC_1_SQRT_2);
    let exact = 1.0 - (1.0 - a45) * (1.0 - a45);
    let a = s.absorbed / s.incident;
    println!(
        "90° groove: absorbed {a:.5} against two bounces {exact:.5} (A(45°) = {a45:.5}, one flat hit {:.5})",
        fresnel_absorptivity(N, K, 1.0)
    );
    assert!((a - exact).abs() < GROOVE_TOLERANCE * exact, "{a} {exact}");
    assert_balance(&s, 2.0e4);
    // one bounce allowed: the power still in each ray after its first hit is
    // taken up there and reported apart, and the balance still holds
    let mut one = sets.to_vec();
    one.push("laser.max_bounces=1");
    let s1 = trace(&plate(), &one, |m, st| groove(m, st, vertex));
    assert!((s1.absorbed - s1.incident).abs() <= s1.unit * 1.0);
    let expected_limit = (1.0 - a45) * s1.incident;
    assert!(
        (s1.at_limit - expected_limit).abs() < GROOVE_TOLERANCE * expected_limit,
        "{} {expected_limit}",
        s1.at_limit
    );
    assert_balance(&s1, 2.0e4);
}

/// Hand the plate's particles above the 90° V with its vertex at `vertex` to
/// the void (wall, no temperature) phase.
fn groove(m: &spatter::model::Model, st: &mut State, vertex: [f32; 2]) {
    let id = |name: &str| m.phases.iter().position(|p| p.name == name).unwrap() as u32;
    let (plate, void) = (id("plate"), id("insulation"));
    for i in 0..st.len() {
        let w = m.to_world(st.pos[i]);
        let (x, y) = (w[0] as f32, w[1] as f32);
        if st.phase[i] == plate && y > vertex[1] + (x - vertex[0]).abs() {
            st.phase[i] = void;
        }
    }
}

/// Bad input names its key and exits 2.
#[test]
fn ray_traced_inputs_are_checked() {
    let p = plate();
    common::assert_input_error(
        &["validate", &p, "--set", "laser.absorptivity=0.3"],
        "laser.absorptivity",
    );
    common::assert_input_error(
        &[
            "validate",
            &p,
            "--set",
            "materials.nickel.refractive_index=[2.88]",
        ],
        "materials.nickel.refractive_index",
    );
    common::assert_input_error(
        &[
            "validate",
            &p,
            "--set",
            "materials.nickel.electrical_resistivity=1.29e-6",
        ],
        "materials.nickel.electrical_resistivity",
    );
    common::assert_input_error(
        &["validate", &p, "--set", "laser.max_bounces=0"],
        "laser.max_bounces",
    );
    common::assert_input_error(
        &["validate", &p, "--set", "laser.model=\"gaussian_surface\""],
        "laser.absorptivity",
    );
}
