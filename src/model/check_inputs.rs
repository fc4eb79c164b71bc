//! A scene's `[check]`: what each check kind needs from the scene, checked
//! before anything runs (the verdicts themselves are in crate::checks).

use super::*;
use crate::scene::{BinderCheck, CheckKind, DepositionCheck};

/// What the scene around a check must give it: the parts of the model the
/// check kinds read.
pub(super) struct Around<'a> {
    pub dim: u32,
    pub phases: &'a [PhaseInfo],
    pub surface_tension: Option<&'a SurfaceTension>,
    pub has_laser: bool,
}

/// Every input a check kind reads, and what it needs of the rest of the scene.
pub(super) fn validate(
    cx: &Ctx,
    scene: &SceneFile,
    c: &CheckDef,
    at: &Around,
) -> Result<(), InputError> {
    use CheckDef as D;
    let (dim, phases) = (at.dim, at.phases);
    cx.positive("check.tolerance", c.tolerance())?;
    reference_needs(cx, scene, c.kind(), phases)?;
    match c {
        D::Hydrostatic(d) => {
            finite(cx, "check.surface", d.surface)?;
            if let Some(e) = d.exclude_depth {
                cx.positive("check.exclude_depth", e)?;
            }
        }
        D::DamBreakFront(d) => {
            cx.positive("check.column_width", d.column_width)?;
        }
        D::FreeRotation(d) => {
            cx.positive("check.energy_tolerance", d.energy_tolerance)?;
        }
        D::RecoilImpulse(d) => {
            cx.positive("check.area", d.area)?;
        }
        D::ThermalExpansion(d) => {
            if let Some(b) = d.band_tolerance {
                cx.positive("check.band_tolerance", b)?;
            }
            density_law_needed(cx, phases)?;
        }
        D::RisingAmplitude(d) => {
            if let Some(s) = d.swing {
                cx.positive("check.swing", s)?;
            }
            density_law_needed(cx, phases)?;
        }
        D::ColumnExpansion(d) => {
            cx.positive("check.area", d.area)?;
            density_law_needed(cx, phases)?;
        }
        D::DropShape(_) | D::ContactAngle(_) => tension_needs(cx, c.kind(), at)?,
        D::Laplace(d) => {
            cx.vector("check.center", &d.center, dim)?;
            cx.positive("check.radius", d.radius)?;
            tension_needs(cx, c.kind(), at)?;
        }
        D::Thermocapillary(d) => {
            thermocapillary_layout(cx, scene, dim, phases, at.surface_tension, d.surface)?
        }
        D::ConductionTwoMaterials(d) => finite(cx, "check.surface", d.surface)?,
        D::Splat(d) => {
            if let Some(xi) = d.spread_factor {
                if !(xi.is_finite() && xi >= 1.0) {
                    return Err(cx.err(
                        "check.spread_factor",
                        format!("a spread factor D/D0 is at least 1, got {xi}"),
                    ));
                }
            }
            droplet_needs(cx, c.kind(), d.phase.as_deref(), dim, phases)?
        }
        D::ImpactForce(d) => droplet_needs(cx, c.kind(), d.phase.as_deref(), dim, phases)?,
        D::DropContact(_)
            if !phases.iter().any(|p| {
                p.kind == PhaseKind::Liquid && p.thermal.is_some_and(|t| t.melting.is_some())
            }) =>
        {
            return Err(cx.err(
                "check.kind",
                "\"drop_contact\" needs liquid drops whose material melts (solidus, liquidus)",
            ));
        }
        D::Remelt(d) => {
            if !(d.depth.is_finite() && d.depth >= 0.0) {
                return Err(cx.err(
                    "check.depth",
                    "\"remelt\" needs the reference depth (m, >= 0)",
                ));
            }
            if !phases
                .iter()
                .any(|p| p.kind == PhaseKind::Solid && p.switch_to.is_some())
            {
                return Err(cx.err("check.kind", "\"remelt\" needs a solid phase that melts"));
            }
        }
        D::PointMelt(_) => point_melt_needs(cx, scene, phases)?,
        D::Deposition(d) => deposition_needs(cx, scene, d)?,
        D::Binder(d) => binder_needs(cx, scene, d)?,
        D::MeasuredTrack(d) => {
            if scene.laser.is_none() {
                return Err(cx.err("check.kind", "\"measured_track\" needs a [laser]"));
            }
            d.measured.validate(cx.file, dim)?
        }
        D::R18Track(d) => {
            cx.positive("check.r18_slice_depth", d.r18_slice_depth)?;
            finite(cx, "check.surface", d.surface)?;
            if !at.has_laser || dim != 2 {
                return Err(cx.err(
                    "check.kind",
                    "\"r18_track\" needs a 2D scene with a [laser]",
                ));
            }
        }
        _ => {}
    }
    Ok(())
}

/// A height or position that must be a number (m).
fn finite(cx: &Ctx, key: &str, v: f64) -> Result<(), InputError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(cx.err(key, format!("must be a finite length in m, got {v}")))
    }
}

/// The expansion checks compare with a density law ρ0(T).
fn density_law_needed(cx: &Ctx, phases: &[PhaseInfo]) -> Result<(), InputError> {
    if phases.iter().any(|p| p.density_law.is_some()) {
        Ok(())
    } else {
        Err(cx.err(
            "check.kind",
            "the expansion checks need a liquid with a density law (materials.<m>.density_law)",
        ))
    }
}

/// The checks against a closed-form reference: a fixed absorptivity (not
/// ray-traced), constant properties (no varying table).
fn reference_needs(
    cx: &Ctx,
    scene: &SceneFile,
    kind: CheckKind,
    phases: &[PhaseInfo],
) -> Result<(), InputError> {
    use CheckKind as K;
    let traced = scene
        .laser
        .as_ref()
        .is_some_and(|l| l.model == crate::scene::LaserModel::RayTraced);
    if traced && matches!(kind, K::Rosenthal | K::LaserEnergy) {
        return Err(cx.err(
            "check.kind",
            format!(
                "\"{}\" compares with a fixed absorptivity ζ: not with \
                 laser.model = \"ray_traced\"",
                kind.name()
            ),
        ));
    }
    let constant_reference = matches!(
        kind,
        K::Conduction1d
            | K::ConductionTwoMaterials
            | K::Stefan1d
            | K::SolidificationFront
            | K::Rosenthal
    );
    // A table that varies: λ not constant, or h(T) not one straight line.
    let tabled = phases.iter().any(|p| {
        p.thermal.is_some_and(|t| {
            t.conductivity_table
                .is_some_and(|tb| tb.points().iter().any(|q| q.1 != tb.points[0].1))
                || t.enthalpy_table.is_some_and(|tb| {
                    (1..tb.n - 1).any(|k| (tb.slope(k) - tb.slope(0)).abs() > 1e-9 * tb.slope(0))
                })
        })
    });
    if constant_reference && tabled {
        return Err(cx.err(
            "check.kind",
            format!(
                "\"{}\"'s reference solution takes constant properties: not with a \
                 varying enthalpy_table or conductivity_table",
                kind.name()
            ),
        ));
    }
    Ok(())
}

/// The surface-tension checks: a 2D drop's shape or contact angle, a drop's
/// Laplace jump.
fn tension_needs(cx: &Ctx, kind: CheckKind, at: &Around) -> Result<(), InputError> {
    let st = at.surface_tension;
    match kind {
        CheckKind::DropShape => {
            if at.dim != 2 || !st.is_some_and(|s| s.is_constant()) {
                return Err(cx.err(
                    "check.kind",
                    "\"drop_shape\" needs a 2D scene with [surface_tension] of constant coefficient",
                ));
            }
        }
        CheckKind::ContactAngle => {
            if at.dim != 2 || st.is_none_or(|s| s.contact_angle.is_none()) {
                return Err(cx.err(
                    "check.kind",
                    "\"contact_angle\" needs a 2D scene with surface_tension.contact_angle",
                ));
            }
        }
        _ => {
            if !st.is_some_and(|s| s.is_constant()) {
                return Err(cx.err(
                    "check.kind",
                    "\"laplace\" needs [surface_tension] with a constant coefficient",
                ));
            }
        }
    }
    Ok(())
}

/// The droplet checks (`splat`, `impact_force`): the droplet's phase, named
/// where there are several liquids.
fn droplet_needs(
    cx: &Ctx,
    kind: CheckKind,
    phase: Option<&str>,
    dim: u32,
    phases: &[PhaseInfo],
) -> Result<(), InputError> {
    if kind == CheckKind::ImpactForce && dim != 3 {
        return Err(cx.err(
            "check.kind",
            "\"impact_force\" needs a 3D scene (its reference, 0.8 rho V^2 D^2, is a sphere's)",
        ));
    }
    if let Some(name) = phase {
        if !phases
            .iter()
            .any(|p| p.name == name && p.kind == PhaseKind::Liquid)
        {
            return Err(cx.err(
                "check.phase",
                format!("`{name}` is not a liquid phase of the scene (the droplet)"),
            ));
        }
    }
    let liquids = phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Liquid)
        .count();
    if phase.is_none() && liquids > 1 {
        return Err(cx.err(
            "check.phase",
            format!(
                "missing: \"{}\" in a scene with several liquid phases needs the droplet's",
                kind.name()
            ),
        ));
    }
    Ok(())
}

/// `binder` (F22 §4.2) measures a liquid in a rigid powder bed and judges at
/// least one thing; its lengths are positive.
fn binder_needs(cx: &Ctx, scene: &SceneFile, c: &BinderCheck) -> Result<(), InputError> {
    if !scene.powder.as_ref().is_some_and(|p| p.rigid) {
        return Err(cx.err(
            "check.kind",
            "\"binder\" needs a [powder] bed of rigid grains (`rigid = true`)",
        ));
    }
    if let Some(p) = c.penetration_below {
        cx.positive("check.penetration_below", p)?;
    }
    if let Some(w) = c.spread_above {
        cx.positive("check.spread_above", w)?;
    }
    if c.ejected == Some(0) {
        return Err(cx.err(
            "check.ejected",
            "at least 1 (0 grains ejected is no criterion)",
        ));
    }
    if c.penetration_below.is_none()
        && c.spread_above.is_none()
        && c.reaches_walls != Some(true)
        && c.ejected.is_none()
        && c.sinking != Some(true)
    {
        return Err(cx.err(
            "check.kind",
            "\"binder\" needs something to judge: check.penetration_below, check.spread_above, \
             check.reaches_walls = true, check.ejected or check.sinking = true",
        ));
    }
    Ok(())
}

/// `deposition` (F22 §4.4) follows the scene's shape bodies (the grains) into a
/// laser's pool; its references are positive, a diameter comes with its time,
/// and it judges at least one thing.
fn deposition_needs(cx: &Ctx, scene: &SceneFile, c: &DepositionCheck) -> Result<(), InputError> {
    if scene.laser.is_none() || !scene.shapes.iter().any(|s| s.body) {
        return Err(cx.err(
            "check.kind",
            "\"deposition\" needs a [laser] and grains as shapes with `body = true`",
        ));
    }
    if let Some(t) = c.arrival {
        cx.positive("check.arrival", t)?;
    }
    if let Some(d) = c.diameter {
        cx.positive("check.diameter", d)?;
        cx.positive("check.diameter_time", c.diameter_time.unwrap_or(f64::NAN))?;
    }
    if let Some(tol) = c.diameter_tolerance {
        cx.positive("check.diameter_tolerance", tol)?;
    }
    if c.arrival.is_none() && c.diameter.is_none() && c.unmolten != Some(true) {
        return Err(cx.err(
            "check.kind",
            "\"deposition\" needs something to judge: check.arrival, check.diameter (with \
             check.diameter_time) or check.unmolten = true",
        ));
    }
    Ok(())
}

/// `point_melt` (F22 §4.5) reads the beam's switch-off, T_v and the plate's
/// top: a laser whose power ends at 0 (`laser.power_until`), a material with
/// `evaporation`, a solid phase that melts.
fn point_melt_needs(cx: &Ctx, scene: &SceneFile, phases: &[PhaseInfo]) -> Result<(), InputError> {
    if scene.laser.as_ref().and_then(|l| l.power_until).is_none() {
        return Err(cx.err(
            "laser.power_until",
            "missing: \"point_melt\" judges the depression while the beam is on and the indentation after it goes off",
        ));
    }
    if !phases
        .iter()
        .any(|p| p.thermal.is_some_and(|t| t.evaporation.is_some()))
    {
        return Err(cx.err(
            "check.kind",
            "\"point_melt\" needs a material with `evaporation` (its boiling_temperature is F22's T_v)",
        ));
    }
    if !phases
        .iter()
        .any(|p| p.kind == PhaseKind::Solid && p.switch_to.is_some())
    {
        return Err(cx.err(
            "check.kind",
            "\"point_melt\" needs a solid phase that melts (the plate)",
        ));
    }
    Ok(())
}

/// `check.kind = "thermocapillary"`: the channel the check's analytic solution
/// describes. 2D, periodic in x, walls on y; F22's surface tension with α0' < 0;
/// one Dirichlet wall phase with a temperature wave along x (the bottom) and one
/// without (the top); `check.surface` (the interface height) inside the domain.
fn thermocapillary_layout(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
    phases: &[PhaseInfo],
    tension: Option<&SurfaceTension>,
    y: f64,
) -> Result<(), InputError> {
    let bad = |msg: &str| Err(cx.err("check.kind", format!("\"thermocapillary\" needs {msg}")));
    let d = &scene.domain;
    if dim != 2
        || !d.periodic.first().copied().unwrap_or(false)
        || d.periodic.get(1).copied().unwrap_or(false)
    {
        return bad("a 2D scene periodic in x with walls on y");
    }
    if !tension.is_some_and(|t| t.gas.is_some() && t.slope < 0.0 && t.sahoo.is_none()) {
        return bad("[surface_tension] with a gas phase and a negative temperature_coefficient");
    }
    let walls: Vec<&Thermal> = phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Wall)
        .filter_map(|p| p.thermal.as_ref())
        .collect();
    let waves = walls
        .iter()
        .filter(|t| t.wave.is_some_and(|w| w.axis == 0))
        .count();
    if waves != 1 || walls.len() != 2 {
        return bad(
            "two Dirichlet wall phases, one with a temperature_wave along x (the y_min wall)",
        );
    }
    if !(y > d.min[1] && y < d.max[1]) {
        return Err(cx.err(
            "check.surface",
            format!("the interface height must lie inside the domain's y range, got {y}"),
        ));
    }
    Ok(())
}
