//! Surface tension between a liquid and a gas phase, F22 (24)–(26) with the law
//! F22 (8) and the regularisation F22 (21), or at a liquid's free surface in a
//! scene without gas particles (R18 §3.1.1–3.1.2), from `[surface_tension]`.

use super::*;

/// F22 (8): α(T) = max(α0 + α0' (T − T_α0), α_min); α' = α0' where α is not
/// clipped, 0 where it is (α is constant there, so the Marangoni stress is 0).
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceTension {
    /// Phase indices.
    pub liquid: usize,
    /// The gas phase of F22's form; None: the free-surface form (no gas particles).
    pub gas: Option<usize>,
    pub coefficient: f64,
    pub slope: f64,
    pub reference_temperature: f64,
    pub minimum: f64,
    /// (T_m, ΔT_s): the liquid's solidus and the ramp width above it, in heat
    /// scenes whose liquid melts; None: no regularisation (f = 1).
    pub ramp: Option<(f64, f64)>,
    /// F22 (27)–(29) static contact angle (radians) per phase: Some for every
    /// wall and solid phase when the scene has wetting, None for the others.
    pub contact_angle: Option<Vec<Option<f64>>>,
}

impl SurfaceTension {
    pub fn coefficient_at(&self, t: f64) -> f64 {
        (self.coefficient + self.slope * (t - self.reference_temperature)).max(self.minimum)
    }
    /// The largest α any particle can feel (for the capillary Δt limit): at the
    /// ramp's start when regularised, else at the coldest temperature the scene
    /// starts with (α falls with T).
    pub fn max_coefficient(&self, phases: &[PhaseInfo]) -> f64 {
        let t_low = match self.ramp {
            Some((t_m, _)) => t_m,
            None => phases
                .iter()
                .filter_map(|p| p.thermal.map(|t| t.coldest()))
                .fold(self.reference_temperature, f64::min),
        };
        self.coefficient_at(t_low)
    }
}

pub(super) fn surface_tension(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
) -> Result<Option<SurfaceTension>, InputError> {
    let Some(d) = &scene.surface_tension else {
        return Ok(None);
    };
    let phase = |key: &str, name: &str, kind: PhaseKind| -> Result<usize, InputError> {
        let i = phases
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| cx.err(key, format!("no phase named `{name}`")))?;
        if phases[i].kind != kind {
            return Err(cx.err(
                key,
                format!("`{name}` is not a phase of kind {kind:?}").to_lowercase(),
            ));
        }
        Ok(i)
    };
    let liquid = phase("surface_tension.liquid", &d.liquid, PhaseKind::Liquid)?;
    let gas = match &d.gas {
        Some(name) => Some(phase("surface_tension.gas", name, PhaseKind::Gas)?),
        None => {
            if let Some(g) = phases.iter().find(|p| p.kind == PhaseKind::Gas) {
                return Err(cx.err(
                    "surface_tension.gas",
                    format!("missing: the scene has the gas phase `{}`; name it (F22's form), or drop the gas particles for the free-surface form", g.name),
                ));
            }
            None
        }
    };
    let coefficient = cx.positive("surface_tension.coefficient", d.coefficient)?;
    if !(d.temperature_coefficient.is_finite() && d.temperature_coefficient <= 0.0) {
        return Err(cx.err(
            "surface_tension.temperature_coefficient",
            format!("must be zero or negative (F22 (8): surface tension falls with temperature), got {}", d.temperature_coefficient),
        ));
    }
    let heat = phases[liquid].thermal.is_some();
    let reference_temperature = match (d.temperature_coefficient != 0.0, d.reference_temperature) {
        (_, Some(t)) => cx.positive("surface_tension.reference_temperature", t)?,
        (true, None) => return Err(cx.err(
            "surface_tension.reference_temperature",
            "missing: a temperature coefficient needs the temperature T_α0 where α = coefficient",
        )),
        (false, None) => 0.0,
    };
    if d.temperature_coefficient != 0.0 && !heat {
        return Err(cx.err(
            "surface_tension.temperature_coefficient",
            format!(
                "needs a heat scene (phase `{}` has no temperature)",
                d.liquid
            ),
        ));
    }
    let minimum = cx.non_negative("surface_tension.minimum", d.minimum)?;
    if minimum >= coefficient {
        return Err(cx.err(
            "surface_tension.minimum",
            format!("must be below the coefficient {coefficient} N/m, got {minimum}"),
        ));
    }
    let solidus = phases[liquid].thermal.and_then(|t| t.melting).map(|m| m.0);
    let ramp = match (solidus, d.melting_width) {
        (Some(t_m), Some(w)) => Some((t_m, cx.positive("surface_tension.melting_width", w)?)),
        (Some(_), None) => {
            return Err(cx.err(
                "surface_tension.melting_width",
                format!("missing: the liquid `{}` melts, and F22 (21) ramps its surface tension in over ΔT_s above the solidus (F22: 5 K)", d.liquid),
            ))
        }
        (None, Some(_)) => {
            return Err(cx.err(
                "surface_tension.melting_width",
                format!("the liquid `{}` has no melting range (solidus) to ramp from", d.liquid),
            ))
        }
        (None, None) => None,
    };
    let contact_angle = match &d.contact_angle {
        None => None,
        Some(def) => Some(contact_angles(cx, def, phases, gas.is_some())?),
    };
    Ok(Some(SurfaceTension {
        contact_angle,
        liquid,
        gas,
        coefficient,
        slope: d.temperature_coefficient,
        reference_temperature,
        minimum,
        ramp,
    }))
}

/// `surface_tension.contact_angle`, one angle or a table of every wall and solid
/// phase, to radians per phase index (None for fluid phases).
fn contact_angles(
    cx: &Ctx,
    def: &crate::scene::ContactAngleDef,
    phases: &[PhaseInfo],
    gas_form: bool,
) -> Result<Vec<Option<f64>>, InputError> {
    use crate::scene::ContactAngleDef;
    let key = "surface_tension.contact_angle";
    if !gas_form {
        return Err(cx.err(
            key,
            "wetting (F22 (27)-(29)) prescribes the liquid-gas normal: it needs F22's form with a gas phase",
        ));
    }
    let check = |k: &str, a: f64| -> Result<f64, InputError> {
        if a.is_finite() && a > 0.0 && a < 180.0 {
            Ok(a.to_radians())
        } else {
            Err(cx.err(
                k,
                format!("must lie strictly between 0 and 180 degrees, got {a}"),
            ))
        }
    };
    let solid = |p: &PhaseInfo| matches!(p.kind, PhaseKind::Wall | PhaseKind::Solid);
    match def {
        ContactAngleDef::All(a) => {
            let a = check(key, *a)?;
            Ok(phases.iter().map(|p| solid(p).then_some(a)).collect())
        }
        ContactAngleDef::PerPhase(table) => {
            for name in table.keys() {
                if !phases.iter().any(|p| &p.name == name && solid(p)) {
                    return Err(cx.err(
                        &format!("{key}.{name}"),
                        format!("`{name}` is not a wall or solid phase of the scene"),
                    ));
                }
            }
            phases
                .iter()
                .map(|p| match (solid(p), table.get(&p.name)) {
                    (false, _) => Ok(None),
                    (true, Some(a)) => check(&format!("{key}.{}", p.name), *a).map(Some),
                    (true, None) => Err(cx.err(
                        key,
                        format!(
                            "missing the angle on `{}`: a table names every wall and solid phase",
                            p.name
                        ),
                    )),
                })
                .collect()
        }
    }
}
