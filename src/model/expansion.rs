//! Thermal expansion on δ-SPH (R18 §3.4): a reference density that follows the
//! temperature, ρ0(T) (R18 (3.52), the 304 SS law of §4.4), and a temperature
//! imposed on a phase by a program (R18 Tests 1 and 3 heat their fluids
//! uniformly). Validated here; both backends evaluate the law from the phase's
//! row of the parameter block (params::phase_block) with the same operations as
//! `DensityLaw::at`.

use super::{Ctx, PhaseInfo};
use crate::error::InputError;
use crate::scene::{Formulation, HeatIntegrator, PhaseKind, SceneFile};

/// The most points a density law may have (the parameter block holds 8).
pub const MAX_DENSITY_POINTS: usize = 8;

/// ρ0(T): piecewise linear through `points` (T, ρ0), continued along the end
/// segments; where a temperature repeats, the later point holds from it on.
#[derive(Debug, Clone, PartialEq)]
pub struct DensityLaw {
    pub points: Vec<(f64, f64)>,
}

impl DensityLaw {
    /// Segment k's slope dρ0/dT (0 for a step), the last point's the last segment's.
    pub fn slopes(&self) -> Vec<f64> {
        let p = &self.points;
        let mut s: Vec<f64> = p
            .windows(2)
            .map(|w| {
                if w[1].0 > w[0].0 {
                    (w[1].1 - w[0].1) / (w[1].0 - w[0].0)
                } else {
                    0.0
                }
            })
            .collect();
        // Beyond the last point: the last segment that is not a step.
        let last = s.iter().rev().copied().find(|v| *v != 0.0).unwrap_or(0.0);
        s.push(last);
        // Below the first point: the first segment's slope (s[0]).
        s
    }
    /// The segment T falls in: the last point at or below T (the first below all).
    pub fn segment(&self, t: f64) -> usize {
        let mut k = 0;
        for (i, p) in self.points.iter().enumerate().skip(1) {
            if t >= p.0 {
                k = i;
            }
        }
        k
    }
    /// ρ0(T) in f64 (setup: the initial density and mass).
    pub fn at(&self, t: f64) -> f64 {
        let k = self.segment(t);
        let (tk, rk) = self.points[k];
        rk + self.slopes()[k] * (t - tk)
    }
    /// The lowest and highest ρ0 the law reaches over [t_min, t_max]: at the
    /// ends, and at each point inside on both sides (a step has two values).
    pub fn range(&self, t_min: f64, t_max: f64) -> (f64, f64) {
        let slopes = self.slopes();
        let mut v = vec![self.at(t_min), self.at(t_max)];
        for (i, &(t, rho)) in self.points.iter().enumerate().skip(1) {
            if t > t_min && t < t_max {
                let (t_prev, rho_prev) = self.points[i - 1];
                v.extend([rho, rho_prev + slopes[i - 1] * (t - t_prev)]);
            }
        }
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }
}

/// T(t) = T0 + (A + Ȧ t) sin(2π t / P) + Ṫ min(t, t_end)
/// (`phases.<name>.temperature_program`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TemperatureProgram {
    pub amplitude: f64,
    /// Ȧ, K/s.
    pub amplitude_rate: f64,
    /// 1/P (0 without a cycle).
    pub frequency: f64,
    pub rate: f64,
    /// t_end (∞: the ramp never stops).
    pub until: f64,
}

impl TemperatureProgram {
    /// The temperature above (or below) the phase's `temperature` at time t.
    pub fn offset(&self, t: f64) -> f64 {
        (self.amplitude + self.amplitude_rate * t)
            * (std::f64::consts::TAU * self.frequency * t).sin()
            + self.rate * t.min(self.until)
    }
}

/// Reads `materials.<m>.density_law` and `phases.<name>.temperature_program`
/// into the phase table (after the thermal table: both need a temperature).
pub(super) fn expansion_table(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &mut [PhaseInfo],
) -> Result<(), InputError> {
    // A solid or wall phase keeps its place, so a law cannot expand it; it may
    // share the law's material with a fluid phase (the liquid a solid melts
    // into must share its material), and then the fluid alone takes the law.
    let fluid_materials: Vec<&String> = phases
        .iter()
        .filter(|ph| ph.is_fluid())
        .map(|ph| &scene.phases[&ph.name].material)
        .collect();
    for ph in phases.iter_mut() {
        let def = &scene.phases[&ph.name];
        if let Some(points) = &scene.materials[&def.material].density_law {
            if !ph.is_fluid() && fluid_materials.contains(&&def.material) {
                continue;
            }
            let key = format!("materials.{}.density_law", def.material);
            ph.density_law = Some(density_law(cx, scene, ph, &key, points)?);
        }
        if let Some(p) = &def.temperature_program {
            let key = format!("phases.{}.temperature_program", ph.name);
            let program = temperature_program(cx, scene, ph, &key, p)?;
            if ph.thermal.is_some_and(|t| t.enthalpy_table.is_some()) {
                return Err(cx.err(
                    &key,
                    "imposes T through h = c_p (T - T_ref): not with an enthalpy_table",
                ));
            }
            if let Some(t) = ph.thermal.as_mut() {
                t.program = Some(program);
            }
        }
    }
    Ok(())
}

fn density_law(
    cx: &Ctx,
    scene: &SceneFile,
    ph: &PhaseInfo,
    key: &str,
    points: &[Vec<f64>],
) -> Result<DensityLaw, InputError> {
    if scene.simulation.formulation != Formulation::DeltaWcsph {
        return Err(cx.err(
            key,
            "needs formulation = \"delta_wcsph\": summation density takes the density from \
             the particles' spacing, and the law enters through the continuity density's EOS \
             and diffusion (R18 (3.52)-(3.53))",
        ));
    }
    if !ph.is_fluid() {
        return Err(cx.err(
            key,
            format!(
                "phase `{}` is a wall or solid: its particles stay in place, so a density \
                 law cannot expand them (give it to a fluid phase's material)",
                ph.name
            ),
        ));
    }
    if ph.thermal.is_none() {
        return Err(cx.err(
            key,
            format!(
                "phase `{}` needs a temperature (phases.{}.temperature)",
                ph.name, ph.name
            ),
        ));
    }
    if !(2..=MAX_DENSITY_POINTS).contains(&points.len()) {
        return Err(cx.err(
            key,
            format!(
                "give 2 to {MAX_DENSITY_POINTS} points [T, density] (got {})",
                points.len()
            ),
        ));
    }
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let [t, rho] = p[..] else {
            return Err(cx.err(key, format!("point {i}: give [T in K, density in kg/m^3]")));
        };
        if !(t.is_finite() && t > 0.0 && rho.is_finite() && rho > 0.0) {
            return Err(cx.err(
                key,
                format!("point {i}: T and density must be positive (got [{t}, {rho}])"),
            ));
        }
        if let Some(&(t_prev, _)) = out.last() {
            if t < t_prev {
                return Err(cx.err(
                    key,
                    format!("point {i}: temperatures must rise ({t} K after {t_prev} K)"),
                ));
            }
            if i >= 2 && t == t_prev && out[i - 2].0 == t {
                return Err(cx.err(key, format!("point {i}: {t} K given three times")));
            }
        }
        out.push((t, rho));
    }
    let law = DensityLaw { points: out };
    // The law must stay positive over every temperature the phase can start at.
    let t = ph.thermal.expect("checked above");
    let hottest = t.temperature + (t.temperature - t.coldest());
    let (lo, _) = law.range(t.coldest(), hottest);
    if lo <= 0.0 {
        return Err(cx.err(
            key,
            "the law falls to 0 kg/m^3 at the phase's initial temperatures",
        ));
    }
    Ok(law)
}

fn temperature_program(
    cx: &Ctx,
    scene: &SceneFile,
    ph: &PhaseInfo,
    key: &str,
    p: &crate::scene::TemperatureProgramDef,
) -> Result<TemperatureProgram, InputError> {
    let k = |n: &str| format!("{key}.{n}");
    let Some(t) = ph.thermal else {
        return Err(cx.err(key, format!("phase `{}` needs a temperature", ph.name)));
    };
    if ph.kind == PhaseKind::Wall {
        return Err(cx.err(
            key,
            "a wall's temperature is fixed (Dirichlet); programs are for liquid, gas and \
             solid phases",
        ));
    }
    if t.melting.is_some() || ph.switch_to.is_some() {
        return Err(cx.err(
            key,
            format!(
                "phase `{}` melts: an imposed temperature would move its particles through \
                 the band without the latent heat; not built",
                ph.name
            ),
        ));
    }
    if scene
        .heat
        .is_some_and(|h| h.integrator == HeatIntegrator::Trapezoidal)
    {
        return Err(cx.err(
            key,
            "needs heat.integrator = \"euler\" (the trapezoidal iteration would solve for \
             the imposed particles too)",
        ));
    }
    let amplitude = cx.non_negative(&k("amplitude"), p.amplitude)?;
    let amplitude_rate = cx.non_negative(&k("amplitude_rate"), p.amplitude_rate)?;
    let frequency = match p.period {
        Some(period) => 1.0 / cx.positive(&k("period"), period)?,
        None if amplitude > 0.0 || amplitude_rate > 0.0 => {
            return Err(cx.err(&k("period"), "missing: an amplitude needs a period"))
        }
        None => 0.0,
    };
    if !p.rate.is_finite() {
        return Err(cx.err(&k("rate"), "must be finite"));
    }
    let until = match p.until {
        Some(u) => cx.positive(&k("until"), u)?,
        None => f64::INFINITY,
    };
    let program = TemperatureProgram {
        amplitude,
        amplitude_rate,
        frequency,
        rate: p.rate,
        until,
    };
    // T stays positive over the run (end_time, or the ramp's end).
    let horizon = scene.run.end_time.unwrap_or(until).min(until);
    let peak_amplitude = if amplitude_rate > 0.0 {
        let Some(end) = scene.run.end_time else {
            return Err(cx.err(
                &k("amplitude_rate"),
                "needs run.end_time (the amplitude grows over the run: the temperature must \
                 stay above 0 K to its end)",
            ));
        };
        amplitude + amplitude_rate * end
    } else {
        amplitude
    };
    let low = t.coldest() - peak_amplitude + (p.rate * horizon).min(0.0);
    if !(low > 0.0) {
        return Err(cx.err(
            key,
            format!("the programmed temperature falls to {low:.1} K (it must stay above 0 K)"),
        ));
    }
    Ok(program)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R18 §4.4's 304 SS law: solid 8020 − 0.501 (T − 298), mushy 7443 −
    /// 6.03 (T − 1673) from the solidus, liquid 6840 − 0.70 (T − 1773).
    #[test]
    fn the_304_law_steps_at_the_solidus_and_continues_past_the_last_point() {
        let law = DensityLaw {
            points: vec![
                (298.0, 8020.0),
                (1673.0, 8020.0 - 0.501 * 1375.0),
                (1673.0, 7443.0),
                (1773.0, 6840.0),
                (2773.0, 6140.0),
            ],
        };
        assert!((law.at(298.0) - 8020.0).abs() < 1e-9);
        assert!((law.at(1000.0) - (8020.0 - 0.501 * 702.0)).abs() < 1e-9);
        assert!((law.at(1672.999) - (8020.0 - 0.501 * 1374.999)).abs() < 1e-6);
        assert_eq!(law.at(1673.0), 7443.0);
        assert!((law.at(1723.0) - (7443.0 - 6.03 * 50.0)).abs() < 1e-9);
        assert!((law.at(3773.0) - (6840.0 - 0.70 * 2000.0)).abs() < 1e-9);
        // Below the first point along the first segment.
        assert!((law.at(198.0) - (8020.0 + 0.501 * 100.0)).abs() < 1e-9);
        let (lo, hi) = law.range(298.0, 1773.0);
        assert_eq!((lo, hi), (6840.0, 8020.0));
    }

    #[test]
    fn a_program_cycles_and_ramps() {
        let mut p = TemperatureProgram {
            amplitude: 50.0,
            amplitude_rate: 0.0,
            frequency: 1.0,
            rate: 10.0,
            until: 0.5,
        };
        assert!((p.offset(0.25) - (50.0 + 2.5)).abs() < 1e-9);
        assert!((p.offset(2.0) - 5.0).abs() < 1e-9);
        // R18 Test 2: the amplitude grows by 20 K/s.
        p.amplitude_rate = 20.0;
        assert!((p.offset(2.25) - (50.0 + 45.0 + 5.0)).abs() < 1e-9);
    }
}
