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
    /// R18 (4.2)'s solute term (`sahoo`): None for F22's linear law alone.
    pub sahoo: Option<Sahoo>,
    /// F22 (27)–(29) static contact angle (radians) per phase: Some for every
    /// wall and solid phase when the scene has wetting, None for the others.
    pub contact_angle: Option<Vec<Option<f64>>>,
    /// R18 §4.4: no tension where the liquid under a surface particle is at most
    /// this many rows thick (0: off; free-surface form only).
    pub thin_layer_rows: u32,
    /// J22 (5)-(8)'s colour-Laplacian force (`model = "muller"`) in place of CSF.
    pub colour_laplacian: bool,
}

/// R's gas constant, J/(mol K).
pub const GAS_CONSTANT: f64 = 8.314_462_618;

/// R18 (4.2)'s solute term − R T Γ ln(1 + K a), K = k_l e^{−ΔH0/(R T)}, in the
/// constants the device evaluates: RΓ (J/(m² K)), k_l a_s, q = −ΔH0/R (K) and
/// ΓΔH0 (J/m²), Γ in mol/m².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sahoo {
    pub r_gamma: f64,
    pub k_a: f64,
    pub q: f64,
    pub gamma_h: f64,
}

impl Sahoo {
    pub fn of(d: &crate::scene::SahooDef) -> Sahoo {
        let gamma = d.surface_excess * 1e3; // kmol/m² → mol/m²
        Sahoo {
            r_gamma: GAS_CONSTANT * gamma,
            k_a: d.segregation_constant * d.activity,
            q: -d.adsorption_enthalpy / GAS_CONSTANT,
            gamma_h: gamma * d.adsorption_enthalpy,
        }
    }
    /// (the term, its T-derivative) at T: −RΓT ln(1 + Ka) and
    /// −RΓ ln(1 + Ka) − ΓΔH0 Ka/(T (1 + Ka)).
    pub fn term(&self, t: f64) -> (f64, f64) {
        let ka = self.k_a * (self.q / t).exp();
        let l = (1.0 + ka).ln();
        (
            -self.r_gamma * t * l,
            -self.r_gamma * l - self.gamma_h * ka / (t * (1.0 + ka)),
        )
    }
}

impl SurfaceTension {
    /// (α, dα/dT) at T: F22 (8)'s linear law plus R18 (4.2)'s solute term,
    /// clipped at α_min (where dα/dT is 0).
    pub fn law(&self, t: f64) -> (f64, f64) {
        let mut alpha = self.coefficient + self.slope * (t - self.reference_temperature);
        let mut slope = self.slope;
        if let Some(s) = self.sahoo {
            let (a, da) = s.term(t);
            alpha += a;
            slope += da;
        }
        if alpha <= self.minimum {
            (self.minimum, 0.0)
        } else {
            (alpha, slope)
        }
    }
    pub fn coefficient_at(&self, t: f64) -> f64 {
        self.law(t).0
    }
    /// α does not depend on the temperature.
    pub fn is_constant(&self) -> bool {
        self.slope == 0.0 && self.sahoo.is_none()
    }
    /// The largest α any particle can feel (for the capillary Δt limit): at the
    /// ramp's start when regularised, else at the coldest temperature the scene
    /// starts with (the linear law falls with T); with the solute term, whose α
    /// rises up to where dα/dT changes sign, the largest over 1 K steps from
    /// there to 10^4 K.
    pub fn max_coefficient(&self, phases: &[PhaseInfo]) -> f64 {
        let t_low = match self.ramp {
            Some((t_m, _)) => t_m,
            None => phases
                .iter()
                .filter_map(|p| p.thermal.map(|t| t.coldest()))
                .fold(self.reference_temperature, f64::min),
        };
        if self.sahoo.is_none() {
            return self.coefficient_at(t_low);
        }
        (0..10_000)
            .map(|k| t_low.max(1.0) + k as f64)
            .map(|t| self.coefficient_at(t))
            .fold(0.0, f64::max)
    }
}

pub(super) fn surface_tension(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
    support: f64,
    dx: f64,
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
    let sahoo = match &d.sahoo {
        None => None,
        Some(def) => {
            let k = |n: &str| format!("surface_tension.sahoo.{n}");
            cx.positive(&k("surface_excess"), def.surface_excess)?;
            cx.positive(&k("segregation_constant"), def.segregation_constant)?;
            cx.positive(&k("activity"), def.activity)?;
            if !(def.adsorption_enthalpy.is_finite() && def.adsorption_enthalpy < 0.0) {
                return Err(cx.err(
                    &k("adsorption_enthalpy"),
                    format!(
                        "must be negative (adsorption releases heat; R18: -1.66e5 J/mol), got {}",
                        def.adsorption_enthalpy
                    ),
                ));
            }
            if !heat || d.reference_temperature.is_none() {
                return Err(cx.err(
                    &k("surface_excess"),
                    "the solute term needs a heat scene and surface_tension.reference_temperature (T_m of R18 (4.2))",
                ));
            }
            Some(Sahoo::of(def))
        }
    };
    let contact_angle = match &d.contact_angle {
        None => None,
        Some(def) => Some(contact_angles(cx, def, phases, d.model)?),
    };
    let thin_layer_rows = thin_layer_rows(cx, d, gas.is_some(), support, dx)?;
    let colour_laplacian = colour_laplacian(cx, d, gas.is_some())?;
    Ok(Some(SurfaceTension {
        colour_laplacian,
        thin_layer_rows,
        contact_angle,
        liquid,
        gas,
        coefficient,
        slope: d.temperature_coefficient,
        reference_temperature,
        minimum,
        sahoo,
        ramp,
    }))
}

/// `surface_tension.thin_layer_rows`: free-surface form only, and the kernel's
/// support must reach the row below the layer it tests for (rows + ½ spacings).
fn thin_layer_rows(
    cx: &Ctx,
    d: &crate::scene::SurfaceTensionDef,
    gas: bool,
    support: f64,
    dx: f64,
) -> Result<u32, InputError> {
    let key = "surface_tension.thin_layer_rows";
    let rows = d.thin_layer_rows.unwrap_or(0);
    if rows == 0 {
        return Ok(0);
    }
    if gas {
        return Err(cx.err(
            key,
            "applies to the free-surface form (no `gas`): F22's form with gas has no such rule",
        ));
    }
    if support < (rows as f64 + 0.5) * dx {
        return Err(cx.err(
            key,
            format!(
                "{rows} rows need a kernel support of at least {:.3e} m to see the row under them, got {support:.3e} m",
                (rows as f64 + 0.5) * dx
            ),
        ));
    }
    Ok(rows)
}

/// `surface_tension.model = "muller"`: J22's form is written for a liquid without
/// gas particles and a constant σ; what it does not define is refused rather than
/// dropped in silence.
fn colour_laplacian(
    cx: &Ctx,
    d: &crate::scene::SurfaceTensionDef,
    gas: bool,
) -> Result<bool, InputError> {
    if d.model != crate::scene::TensionModel::Muller {
        return Ok(false);
    }
    let refuse =
        |key: &str, why: &str| Err(cx.err(key, format!("model = \"muller\" (J22 (5)-(8)) {why}")));
    if gas {
        return refuse(
            "surface_tension.gas",
            "is the free-surface form: drop `gas` and the gas particles, or use model = \"csf\"",
        );
    }
    if d.temperature_coefficient != 0.0 || d.sahoo.is_some() {
        return refuse(
            "surface_tension.temperature_coefficient",
            "has a constant coefficient and no Marangoni stress: use model = \"csf\" for α(T)",
        );
    }
    if d.thin_layer_rows.unwrap_or(0) > 0 {
        return refuse(
            "surface_tension.thin_layer_rows",
            "has no thin-film rule (R18 §4.4 is the CSF form's)",
        );
    }
    Ok(true)
}

/// `surface_tension.contact_angle`, one angle or a table of every wall and solid
/// phase, to radians per phase index (None for fluid phases).
fn contact_angles(
    cx: &Ctx,
    def: &crate::scene::ContactAngleDef,
    phases: &[PhaseInfo],
    model: crate::scene::TensionModel,
) -> Result<Vec<Option<f64>>, InputError> {
    use crate::scene::ContactAngleDef;
    let key = "surface_tension.contact_angle";
    // Wetting prescribes the CSF normal near solids (F22 (27)-(29)), with gas or
    // at a free surface; J22's colour Laplacian has no normal to prescribe.
    if model == crate::scene::TensionModel::Muller {
        return Err(cx.err(
            key,
            "wetting (F22 (27)-(29)) prescribes the CSF normal: model = \"muller\" (J22 (5)-(8)) has none; use model = \"csf\"",
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

#[cfg(test)]
mod tests {
    use super::*;

    /// R18 (4.2) for 304 SS (σ0 = 1.943 N/m, A = 5e-4 N/(m K), T_m = 1723 K,
    /// k_l = 0.0032, a_s = 0.0022 wt%, ΔH0 = −1.66e5 J/mol): with Γ_s in kmol/m²
    /// (Sahoo's unit) σ(T_m) = 1.8379 N/m and dσ/dT changes sign at 1713.06 K
    /// (positive below: +2.62e-4 at 1600 K; −4.50e-4 at 2200 K). R18 prints
    /// Γ_s = 1.3e-8 without its unit; read as mol/m² (1.3e-11 kmol/m² here) the
    /// term is 1e-4 N/m and dσ/dT within 1% of −A everywhere. The derivative is the
    /// analytic one: it matches a central difference to 1e-9 N/(m K).
    #[test]
    fn sahoo_law_changes_sign_near_1713_k_in_kmol() {
        let law = |gamma_kmol: f64| SurfaceTension {
            liquid: 0,
            gas: None,
            coefficient: 1.943,
            slope: -0.5e-3,
            reference_temperature: 1723.0,
            minimum: 0.0,
            ramp: None,
            sahoo: Some(Sahoo::of(&crate::scene::SahooDef {
                surface_excess: gamma_kmol,
                segregation_constant: 0.0032,
                activity: 0.0022,
                adsorption_enthalpy: -1.66e5,
            })),
            contact_angle: None,
            thin_layer_rows: 0,
            colour_laplacian: false,
        };
        let s = law(1.3e-8);
        assert!(
            (s.law(1723.0).0 - 1.837_88).abs() < 1e-4,
            "{:?}",
            s.law(1723.0)
        );
        assert!((s.law(1600.0).1 - 2.62e-4).abs() < 1e-6);
        assert!((s.law(2200.0).1 + 4.50e-4).abs() < 1e-6);
        let (mut lo, mut hi) = (1600.0, 1800.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if s.law(mid).1 > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert!((lo - 1713.06).abs() < 0.05, "sign change at {lo} K");
        for t in [1500.0, 1713.0, 1900.0, 2500.0] {
            let fd = (s.law(t + 1e-3).0 - s.law(t - 1e-3).0) / 2e-3;
            assert!(
                (fd - s.law(t).1).abs() < 1e-9,
                "T = {t}: {fd} vs {}",
                s.law(t).1
            );
        }
        let mol = law(1.3e-11);
        // (at 1000 K the term's slope is +1.3e-6, 0.3% of A: no sign change)
        for t in [1000.0, 1713.0, 3000.0] {
            assert!(
                (mol.law(t).1 + 0.5e-3).abs() < 0.01 * 0.5e-3,
                "mol reading at {t} K"
            );
        }
        // The capillary limit's α: the largest from the coldest temperature on
        // (here T_α0 = 1723 K, above the peak, where α falls).
        let top = s.max_coefficient(&[]);
        assert_eq!(top, s.law(1723.0).0);
        assert!(s.law(1713.06).0 > top);
    }
}
