//! The laser source: beam, absorption model, power schedule and scan path.

use super::*;

/// Most path points and power steps the parameter block holds.
pub const MAX_LASER_POINTS: usize = 8;

/// A validated laser source (issue 4). Lateral coordinates are absolute.
#[derive(Debug, Clone)]
pub struct Laser {
    pub model: crate::scene::LaserModel,
    pub absorptivity: f64,
    pub radius: f64,
    pub absorption: f64,
    /// (time, power) steps.
    pub power: Vec<(f64, f64)>,
    /// (time, lateral position) of the beam centre; unused lateral axes are 0.
    pub path: Vec<(f64, [f64; 2])>,
}

impl Laser {
    /// Beam power at time t (held from each step's time on; off before the first).
    pub fn power_at(&self, t: f64) -> f64 {
        self.power
            .iter()
            .rev()
            .find(|p| p.0 <= t)
            .map_or(0.0, |p| p.1)
    }
    /// Lateral beam centre at time t (absolute; linear along the path, held at
    /// its ends), as the laser pass moves it.
    pub fn centre_at(&self, t: f64) -> [f64; 2] {
        let path = &self.path;
        if path.is_empty() {
            return [0.0; 2];
        }
        if t <= path[0].0 {
            return path[0].1;
        }
        for w in path.windows(2) {
            let ((t0, p0), (t1, p1)) = (w[0], w[1]);
            if t < t1 {
                let f = (t - t0) / (t1 - t0);
                return [p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1])];
            }
        }
        path[path.len() - 1].1
    }
    /// Energy the beam delivers over [0, t] (J; J per metre of depth in 2D).
    pub fn energy_until(&self, t: f64) -> f64 {
        let mut e = 0.0;
        for (k, &(t0, p)) in self.power.iter().enumerate() {
            let t1 = self.power.get(k + 1).map_or(f64::INFINITY, |n| n.0).min(t);
            if t1 > t0 {
                e += p * (t1 - t0);
            }
        }
        e
    }
}

pub(super) fn laser_source(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
    phases: &[PhaseInfo],
) -> Result<Option<Laser>, InputError> {
    let Some(l) = &scene.laser else {
        return Ok(None);
    };
    if !phases.iter().any(|p| p.conducts()) {
        return Err(cx.err(
            "laser",
            "a laser needs a heat scene (phases with a temperature)",
        ));
    }
    let absorptivity = cx.positive("laser.absorptivity", l.absorptivity)?;
    if absorptivity > 1.0 {
        return Err(cx.err(
            "laser.absorptivity",
            format!("must lie in (0, 1] (got {absorptivity})"),
        ));
    }
    let radius = cx.positive("laser.radius", l.radius)?;
    let absorption = match (l.model, l.absorption_coefficient) {
        (_, Some(a)) => cx.positive("laser.absorption_coefficient", a)?,
        (crate::scene::LaserModel::BeerLambert, None) => {
            return Err(cx.err(
                "laser.absorption_coefficient",
                "missing: the beer_lambert model needs it (1/m)",
            ))
        }
        (crate::scene::LaserModel::GaussianSurface, None) => 0.0,
    };
    let points =
        |key: &str, list: &Vec<Vec<f64>>, width: usize| -> Result<Vec<Vec<f64>>, InputError> {
            if list.is_empty() || list.len() > MAX_LASER_POINTS {
                return Err(cx.err(key, format!("give 1 to {MAX_LASER_POINTS} entries")));
            }
            let mut last = f64::NEG_INFINITY;
            for (k, e) in list.iter().enumerate() {
                if e.len() != width || e.iter().any(|v| !v.is_finite()) {
                    return Err(cx.err(
                        &format!("{key}[{k}]"),
                        format!("expected {width} finite numbers"),
                    ));
                }
                if e[0] < 0.0 || e[0] <= last {
                    return Err(cx.err(
                        &format!("{key}[{k}]"),
                        "times must start at >= 0 and increase",
                    ));
                }
                last = e[0];
            }
            Ok(list.clone())
        };
    let schedule = match &l.power {
        crate::scene::PowerDef::Constant(p) => vec![vec![0.0, *p]],
        crate::scene::PowerDef::Schedule(list) => list.clone(),
    };
    let mut power = points("laser.power", &schedule, 2)?
        .iter()
        .map(|e| (e[0], e[1]))
        .collect::<Vec<_>>();
    if let Some(k) = power.iter().position(|p| p.1 < 0.0) {
        let key = match l.power {
            crate::scene::PowerDef::Constant(_) => "laser.power".to_string(),
            crate::scene::PowerDef::Schedule(_) => format!("laser.power[{k}]"),
        };
        return Err(cx.err(&key, "power must be >= 0"));
    }
    if let Some(t_off) = l.power_until {
        power = switch_off(power, t_off).map_err(|why| cx.err("laser.power_until", why))?;
    }
    let path = points("laser.path", &l.path, dim as usize)?
        .iter()
        .map(|e| (e[0], [e[1], if dim == 3 { e[2] } else { 0.0 }]))
        .collect();
    Ok(Some(Laser {
        model: l.model,
        absorptivity,
        radius,
        absorption,
        power,
        path,
    }))
}

/// The schedule with the beam off from t_off on: steps at or after t_off are
/// dropped and a [t_off, 0] step ends it.
fn switch_off(mut power: Vec<(f64, f64)>, t_off: f64) -> Result<Vec<(f64, f64)>, String> {
    if !t_off.is_finite() || t_off <= power[0].0 {
        return Err(format!(
            "must be a time after the first power step ({} s), got {t_off}",
            power[0].0
        ));
    }
    power.retain(|p| p.0 < t_off);
    if power.len() >= MAX_LASER_POINTS {
        return Err(format!(
            "the schedule and its switch-off hold more than {MAX_LASER_POINTS} steps"
        ));
    }
    power.push((t_off, 0.0));
    Ok(power)
}

#[cfg(test)]
mod tests {
    use super::switch_off;

    #[test]
    fn power_until_ends_any_schedule_with_the_beam_off() {
        let one = switch_off(vec![(0.0, 150.0)], 3.7e-4).unwrap();
        assert_eq!(one, vec![(0.0, 150.0), (3.7e-4, 0.0)]);
        // steps at or after the switch-off go; the schedule before it stays
        let table = vec![(0.0, 100.0), (1.0e-4, 200.0), (4.0e-4, 50.0)];
        let cut = switch_off(table, 3.0e-4).unwrap();
        assert_eq!(cut, vec![(0.0, 100.0), (1.0e-4, 200.0), (3.0e-4, 0.0)]);
        assert!(switch_off(vec![(1.0e-4, 1.0)], 1.0e-4).is_err());
        assert!(switch_off(vec![(0.0, 1.0)], f64::NAN).is_err());
    }
}
