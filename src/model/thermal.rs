//! Heat: each phase's thermal material (conduction, melting band, evaporation,
//! radiation) from the scene's heat keys, and the host-side heat physics the
//! diagnostics and checks evaluate in f64 (absolute enthalpy, radiated flux).

use super::phases::{LawTable, MAX_LAW_POINTS};
use super::*;

/// Stefan–Boltzmann constant σ (W m⁻² K⁻⁴; CODATA 2018, exact in SI). The one
/// definition: the parameter block's ε σ (params.rs) and the host's radiated
/// flux both read it.
pub const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;

impl PhaseInfo {
    /// Specific enthalpy h(T) (J/kg) of a particle of this phase whose stored
    /// enthalpy (`heat.x`, relative to the phase's reference enthalpy, J/kg) is
    /// `stored`; 0 for a phase that does not conduct.
    pub fn absolute_enthalpy(&self, stored: f32) -> f64 {
        if !self.conducts() {
            return 0.0; // a Dirichlet wall's heat.x is its fixed temperature
        }
        stored as f64 + self.thermal.map_or(0.0, |t| t.reference_enthalpy())
    }
}

impl Thermal {
    /// Heat flux radiated by a free surface at temperature `t` into surroundings at
    /// `ambient` (K): ε σ (T⁴ − T_a⁴), W/m².
    pub fn radiated_flux(&self, t: f64, ambient: f64) -> f64 {
        self.emissivity * STEFAN_BOLTZMANN * (t.powi(4) - ambient.powi(4))
    }
}

/// Heat properties: a scene is a heat scene when any phase has a temperature.
/// Then every non-wall phase needs a temperature, conductivity and heat capacity.
pub(super) fn thermal_table(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &mut [PhaseInfo],
) -> Result<(), InputError> {
    let heat_scene = scene.phases.values().any(|p| p.temperature.is_some());
    for ph in phases.iter_mut() {
        let def = &scene.phases[&ph.name];
        let mat = &scene.materials[&def.material];
        let mkey = |k: &str| format!("materials.{}.{k}", def.material);
        let tkey = format!("phases.{}.temperature", ph.name);
        let Some(t) = def.temperature else {
            if heat_scene && ph.kind != PhaseKind::Wall {
                return Err(cx.err(&tkey, "missing: a heat scene needs the initial temperature of every liquid, gas and solid phase"));
            }
            if ph.kind == PhaseKind::Solid {
                return Err(cx.err(
                    &tkey,
                    "missing: solid phases conduct heat and need a temperature",
                ));
            }
            continue;
        };
        cx.positive(&tkey, t)?;
        let wave = temperature_wave(cx, scene, &ph.name, t)?;
        if ph.kind == PhaseKind::Wall {
            // A Dirichlet wall takes the conducting particle's own k (J22 (25)).
            ph.thermal = Some(Thermal {
                temperature: t,
                conductivity: 0.0,
                heat_capacity: 0.0,
                melting: None,
                liquid: (0.0, 0.0),
                evaporation: None,
                emissivity: 0.0,
                mushy_damping: 0.0,
                wave,
                program: None,
                enthalpy_table: None,
                conductivity_table: None,
            });
            continue;
        }
        let need = |k: &str, v: Option<f64>| -> Result<f64, InputError> {
            match v {
                Some(v) => cx.positive(&mkey(k), v),
                None => Err(cx.err(&mkey(k), "missing: needed by a phase with a temperature")),
            }
        };
        // A table replaces the constants it tabulates: giving both is refused.
        let table = |name: &str,
                     points: &Option<Vec<Vec<f64>>>,
                     replaced: &[(&str, Option<f64>)],
                     rising: bool|
         -> Result<Option<LawTable>, InputError> {
            let Some(points) = points else {
                return Ok(None);
            };
            if let Some((k, _)) = replaced.iter().find(|(_, v)| v.is_some()) {
                return Err(cx.err(
                    &mkey(k),
                    format!("the {name} holds it: give one or the other"),
                ));
            }
            law_table(cx, &mkey(name), points, rising).map(Some)
        };
        let enthalpy_table = table(
            "enthalpy_table",
            &mat.enthalpy_table,
            &[
                ("heat_capacity", mat.heat_capacity),
                ("liquid_heat_capacity", mat.liquid_heat_capacity),
                ("latent_heat", mat.latent_heat),
            ],
            true,
        )?;
        let conductivity_table = table(
            "conductivity_table",
            &mat.conductivity_table,
            &[
                ("conductivity", mat.conductivity),
                ("liquid_conductivity", mat.liquid_conductivity),
            ],
            false,
        )?;
        // With a table, the constants the time-step limit reads are its
        // extremes: the largest λ and the smallest dh/dT.
        let conductivity = match &conductivity_table {
            Some(t) => t.points().iter().map(|p| p.1).fold(0.0, f64::max),
            None => need("conductivity", mat.conductivity)?,
        };
        let heat_capacity = match &enthalpy_table {
            Some(t) => (0..t.n - 1)
                .map(|k| t.slope(k))
                .fold(f64::INFINITY, f64::min),
            None => need("heat_capacity", mat.heat_capacity)?,
        };
        let band = |ts: f64, tl: f64| -> Result<(), InputError> {
            cx.positive(&mkey("solidus"), ts)?;
            if !(tl > ts && tl.is_finite()) {
                return Err(cx.err(
                    &mkey("liquidus"),
                    format!("must exceed the solidus {ts} K (got {tl})"),
                ));
            }
            Ok(())
        };
        let melting = match (mat.solidus, mat.liquidus, mat.latent_heat, &enthalpy_table) {
            (None, None, None, _) => None,
            (Some(ts), Some(tl), None, Some(t)) => {
                band(ts, tl)?;
                // The latent heat is in the table; what the diagnostics read
                // as L is the band's enthalpy beyond the sensible heat of the
                // slope just below the solidus.
                let rise = t.extrapolated(tl) - t.extrapolated(ts);
                let below = (1..t.n).rfind(|&i| ts > t.points[i].0).unwrap_or(0);
                Some((ts, tl, (rise - t.slope(below) * (tl - ts)).max(0.0)))
            }
            (Some(ts), Some(tl), Some(l), None) => {
                band(ts, tl)?;
                Some((ts, tl, cx.non_negative(&mkey("latent_heat"), l)?))
            }
            _ => return Err(cx.err(
                &mkey("solidus"),
                if enthalpy_table.is_some() {
                    "give solidus and liquidus together (the enthalpy_table holds the latent heat)"
                } else {
                    "give solidus, liquidus and latent_heat together"
                },
            )),
        };
        let evaporation = match &mat.evaporation {
            None => None,
            Some(_) if ph.kind != PhaseKind::Liquid => None,
            Some(e) => {
                let k = |n: &str| mkey(&format!("evaporation.{n}"));
                cx.positive(&k("pressure_constant"), e.pressure_constant)?;
                cx.positive(&k("temperature_constant"), e.temperature_constant)?;
                cx.positive(&k("boiling_temperature"), e.boiling_temperature)?;
                cx.positive(&k("latent_heat"), e.latent_heat)?;
                cx.non_negative(&k("enthalpy_reference"), e.enthalpy_reference)?;
                cx.positive(&k("vapor_constant"), e.vapor_constant)?;
                cx.positive(&k("sticking"), e.sticking)?;
                Some(*e)
            }
        };
        let emissivity = match mat.emissivity {
            Some(e) if !(0.0..=1.0).contains(&e) => {
                return Err(cx.err(&mkey("emissivity"), format!("must lie in [0, 1] (got {e})")))
            }
            Some(e) => e,
            None => 0.0,
        };
        let mushy_damping = match mat.mushy_damping {
            Some(_) if melting.is_none() => {
                return Err(cx.err(
                    &mkey("mushy_damping"),
                    "needs a melting band (solidus, liquidus, latent_heat)",
                ));
            }
            Some(c) => cx.non_negative(&mkey("mushy_damping"), c)?,
            None => 0.0,
        };
        let liquid = match (mat.liquid_conductivity, mat.liquid_heat_capacity) {
            (None, None) => (
                conductivity,
                enthalpy_table.map_or(heat_capacity, |t| t.slope(t.n - 1)),
            ),
            _ if melting.is_none() => {
                return Err(cx.err(
                    &mkey("liquid_conductivity"),
                    "liquid properties need a melting band (solidus, liquidus, latent_heat)",
                ))
            }
            (k, c) => (
                match k {
                    Some(k) => cx.positive(&mkey("liquid_conductivity"), k)?,
                    None => conductivity,
                },
                match c {
                    Some(c) => cx.positive(&mkey("liquid_heat_capacity"), c)?,
                    None => enthalpy_table.map_or(heat_capacity, |t| t.slope(t.n - 1)),
                },
            ),
        };
        ph.thermal = Some(Thermal {
            temperature: t,
            conductivity,
            heat_capacity,
            melting,
            liquid,
            evaporation,
            emissivity,
            mushy_damping,
            wave,
            program: None,
            enthalpy_table,
            conductivity_table,
        });
    }
    Ok(())
}

/// `enthalpy_table` or `conductivity_table`: 2 to MAX_LAW_POINTS points [T, y],
/// T rising and positive; y positive, and rising for an enthalpy (so T(h) is
/// one-valued).
fn law_table(
    cx: &Ctx,
    key: &str,
    points: &[Vec<f64>],
    rising: bool,
) -> Result<LawTable, InputError> {
    let what = if rising {
        "h in J/kg"
    } else {
        "lambda in W/(m K)"
    };
    if !(2..=MAX_LAW_POINTS).contains(&points.len()) {
        return Err(cx.err(
            key,
            format!(
                "give 2 to {MAX_LAW_POINTS} points [T in K, {what}] (got {})",
                points.len()
            ),
        ));
    }
    let mut table = LawTable {
        points: [(0.0, 0.0); MAX_LAW_POINTS],
        n: points.len(),
    };
    for (i, p) in points.iter().enumerate() {
        let [t, y] = p[..] else {
            return Err(cx.err(key, format!("point {i}: give [T in K, {what}]")));
        };
        if !(t.is_finite() && t > 0.0 && y.is_finite() && y > 0.0) {
            return Err(cx.err(
                key,
                format!("point {i}: T and the value must be finite and positive, got [{t}, {y}]"),
            ));
        }
        if i > 0 {
            let (t0, y0) = table.points[i - 1];
            if t <= t0 || (rising && y <= y0) {
                return Err(cx.err(
                    key,
                    format!(
                        "point {i}: T must rise{} from point to point, got [{t0}, {y0}] then [{t}, {y}]",
                        if rising { " and h with it" } else { "" }
                    ),
                ));
            }
        }
        table.points[i] = (t, y);
    }
    Ok(table)
}

/// `phases.<name>.temperature_wave`: amplitude below the temperature (T > 0
/// everywhere), an axis of the scene, and along a periodic axis a wavelength that
/// divides the period (else the cosine jumps at the seam).
fn temperature_wave(
    cx: &Ctx,
    scene: &SceneFile,
    name: &str,
    t: f64,
) -> Result<Option<TemperatureWave>, InputError> {
    let Some(w) = scene.phases[name].temperature_wave.as_ref() else {
        return Ok(None);
    };
    let key = |k: &str| format!("phases.{name}.temperature_wave.{k}");
    let amplitude = cx.positive(&key("amplitude"), w.amplitude)?;
    if amplitude >= t {
        return Err(cx.err(
            &key("amplitude"),
            format!("must be below the phase's temperature {t} K (T must stay positive), got {amplitude}"),
        ));
    }
    let wavelength = cx.positive(&key("wavelength"), w.wavelength)?;
    let dim = scene.simulation.dimension as usize;
    let axis = match w.axis.as_str() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        other => {
            return Err(cx.err(
                &key("axis"),
                format!("must be \"x\", \"y\" or \"z\", got \"{other}\""),
            ))
        }
    };
    if axis >= dim {
        return Err(cx.err(
            &key("axis"),
            format!("`{}` is not an axis of a {dim}D scene", w.axis),
        ));
    }
    let d = &scene.domain;
    if d.periodic.get(axis).copied().unwrap_or(false) {
        let periods = (d.max[axis] - d.min[axis]) / wavelength;
        if (periods - periods.round()).abs() > 1e-9 * periods.max(1.0) || periods.round() < 1.0 {
            return Err(cx.err(
                &key("wavelength"),
                format!("the domain is periodic along {} with length {} m: the wavelength must divide it (got {wavelength} m, {periods:.6} periods)", w.axis, d.max[axis] - d.min[axis]),
            ));
        }
    }
    Ok(Some(TemperatureWave {
        amplitude,
        wavelength,
        axis,
    }))
}
