//! Resolution sweeps must not depend on rounding. A domain
//! extent within 1e-6 spacings of a whole number fills that many rows; any other
//! extent, and a box face that sits on a row of lattice sites, is reported naming
//! the key, the axis and the gap.

mod common;
use spatter::run::load;

/// poiseuille_2d with its liquid box's `max` replaced (and the domain's too when
/// `domain_max` is given), written to a temporary file.
fn variant(name: &str, box_max: &str, domain_max: Option<&str>) -> String {
    let original = std::fs::read_to_string(common::scene("poiseuille_2d")).unwrap();
    let mut text = original.replace(
        "box = { min = [0.0, 0.0], max = [6.0e-4, 1.0e-3] }",
        &format!("box = {{ min = [0.0, 0.0], max = {box_max} }}"),
    );
    assert_ne!(
        text, original,
        "poiseuille_2d's box line changed; update this test"
    );
    if let Some(d) = domain_max {
        text = text.replace("max = [6.0e-4, 1.0e-3]\n", &format!("max = {d}\n"));
    }
    let path = std::env::temp_dir().join(format!(
        "spatter-lattice-{name}-{}.toml",
        std::process::id()
    ));
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

fn liquid_count(l: &spatter::run::Loaded) -> usize {
    let liquid = l.model.phase_index("liquid").unwrap() as u32;
    l.state.phase.iter().filter(|&&p| p == liquid).count()
}

/// poiseuille_2d's channel is L = 1 mm high and 0.6 mm long. Δx = L/30 written to
/// eight digits is 30 × (1 − 1e-8) spacings across: before, 29 rows and a one-Δx
/// gap under the top wall.
#[test]
fn a_spacing_written_to_eight_digits_fills_every_row() {
    let l = load(&common::scene("poiseuille_2d"), &["dx=3.3333333e-5".into()]).unwrap();
    assert_eq!(l.model.sites, [18, 30, 1]);
    assert!(l.model.warnings.is_empty(), "{:?}", l.model.warnings);
    assert_eq!(liquid_count(&l), 18 * 30);
}

/// The case that once filled 29: an extent of 30 Δx (1 − 1e-8) fills 30 rows.
#[test]
fn an_extent_a_hair_under_thirty_spacings_fills_thirty_rows() {
    let dx = 5.0e-5;
    let top = format!("[6.0e-4, {:e}]", 30.0 * dx * (1.0 - 1e-8));
    let file = variant("hair", &top, Some(&top));
    let l = load(&file, &[]).unwrap();
    let _ = std::fs::remove_file(&file);
    assert_eq!(l.model.sites[1], 30);
    assert!(l.model.warnings.is_empty(), "{:?}", l.model.warnings);
    assert_eq!(liquid_count(&l), 12 * 30);
}

/// An extent of 29.5 Δx leaves half a spacing empty: reported with its key, axis
/// and gap, by `validate` too (a warning: the run still starts, exit 0).
#[test]
fn an_extent_of_twenty_nine_and_a_half_spacings_is_reported() {
    let set = "domain.max=[6.0e-4, 1.475e-3]";
    let l = load(&common::scene("poiseuille_2d"), &[set.into()]).unwrap();
    assert_eq!(l.model.sites[1], 29);
    let w = l.model.warnings.join("\n");
    assert!(
        w.contains("`domain.max`") && w.contains("along y") && w.contains("0.500 dx gap"),
        "{w}"
    );
    let out = common::spatter(&["validate", &common::scene("poiseuille_2d"), "--set", set]);
    let (_, stderr) = common::text(&out);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        stderr.contains("warning:") && stderr.contains("0.500 dx gap"),
        "{stderr}"
    );
}

/// A box face on a row of sites (here 10.5 Δx up) fills or skips that row by
/// rounding: reported with the shape's key and the axis.
#[test]
fn a_box_face_on_a_row_of_sites_is_reported() {
    let file = variant("face", "[6.0e-4, 5.25e-4]", None);
    let l = load(&file, &[]).unwrap();
    let _ = std::fs::remove_file(&file);
    let w = l.model.warnings.join("\n");
    assert!(
        w.contains("`shapes[0].box.max`") && w.contains("along y") && w.contains("10.500000 dx"),
        "{w}"
    );
    // The scene's own faces lie on cell faces, half a spacing from any site.
    let own = load(&common::scene("poiseuille_2d"), &[]).unwrap();
    assert!(own.model.warnings.is_empty(), "{:?}", own.model.warnings);
}

/// A periodic axis of exactly three kernel supports is accepted whatever the
/// rounding of Δx = L/n: poiseuille_2d's 0.6 mm period at Δx = 1 mm/15 is 3 × 3Δx
/// (quintic), but 6e-4 / (3 · 6.666…e-5) evaluates to 2.9999999999999996. Before,
/// that floor gave 2 cells and the scene was refused; poiseuille_2d at its own Δx
/// (3.999… supports) had 3 cells of 1.33 supports instead of 4.
#[test]
fn periodic_cells_do_not_depend_on_rounding() {
    let l = load(
        &common::scene("poiseuille_2d"),
        &["dx=6.666666666666667e-5".into()],
    )
    .unwrap();
    assert_eq!(l.model.grid[0], 3);
    let l = load(&common::scene("poiseuille_2d"), &[]).unwrap();
    assert_eq!(l.model.grid[0], 4);
}
