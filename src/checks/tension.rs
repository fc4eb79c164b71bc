//! Surface-tension checks.

use super::{particles, Check, Verdict};
use crate::model::Model;
use crate::scene::{LaplaceCheck, PhaseKind};
use crate::state::State;

/// Laplace pressure of a drop at rest: the mean pressure of the liquid more than
/// one kernel support inside the surface, minus that of the gas more than one
/// support outside it (0, the ambient pressure of a free surface, in the
/// free-surface form without gas particles), against σ/R (2D) or 2σ/R (3D). The jump is averaged over
/// the samples of the run's second half (the drop oscillates about rest and
/// settles; one sample carries the acoustic noise). The largest speed of those
/// samples (spurious currents) is reported, and as a capillary number η|u|/σ.
pub struct Laplace {
    center: [f64; 3],
    radius: f64,
    samples: Vec<Sample>,
}

struct Sample {
    time: f64,
    jump: f64,
    max_speed: f64,
}

impl Laplace {
    pub fn new(m: &Model, c: &LaplaceCheck) -> Laplace {
        let mut center = [0.0; 3];
        for (a, x) in c.center.iter().enumerate().take(m.dim as usize) {
            center[a] = *x;
        }
        Laplace {
            center,
            radius: c.radius,
            samples: Vec::new(),
        }
    }

    fn reference(&self, m: &Model) -> f64 {
        let sigma = m
            .surface_tension
            .as_ref()
            .map_or(f64::NAN, |s| s.coefficient);
        (m.dim as f64 - 1.0) * sigma / self.radius
    }
}

impl Check for Laplace {
    fn observe(&mut self, m: &Model, st: &State) {
        let band = m.support;
        let (mut inside, mut outside) = ((0.0, 0usize), (0.0, 0usize));
        let mut max_speed: f64 = 0.0;
        for p in particles(m, st) {
            let r = (0..3)
                .map(|a| (p.x[a] - self.center[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            let speed = (p.v[0] * p.v[0] + p.v[1] * p.v[1] + p.v[2] * p.v[2]).sqrt();
            if p.kind == PhaseKind::Liquid || p.kind == PhaseKind::Gas {
                max_speed = max_speed.max(speed);
            }
            if p.kind == PhaseKind::Liquid && r < self.radius - band {
                inside = (inside.0 + p.p, inside.1 + 1);
            } else if p.kind == PhaseKind::Gas && r > self.radius + band {
                outside = (outside.0 + p.p, outside.1 + 1);
            }
        }
        let free_surface = m.surface_tension.as_ref().is_some_and(|s| s.gas.is_none());
        if inside.1 == 0 || (outside.1 == 0 && !free_surface) {
            return;
        }
        let ambient = if free_surface {
            0.0
        } else {
            outside.0 / outside.1 as f64
        };
        self.samples.push(Sample {
            time: st.sim.time as f64,
            jump: inside.0 / inside.1 as f64 - ambient,
            max_speed,
        });
    }

    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let reference = self.reference(m);
        let end = st.sim.time as f64;
        let late: Vec<&Sample> = self
            .samples
            .iter()
            .filter(|s| s.time >= 0.5 * end)
            .collect();
        let metric =
            "relative error of the mean pressure jump over the run's second half".to_string();
        if late.is_empty() {
            return (
                metric,
                f64::NAN,
                vec!["  no sample in the run's second half".into()],
            )
                .into();
        }
        let jump = late.iter().map(|s| s.jump).sum::<f64>() / late.len() as f64;
        let speed = late.iter().map(|s| s.max_speed).fold(0.0, f64::max);
        let st_def = m
            .surface_tension
            .as_ref()
            .expect("laplace needs surface tension");
        let eta = m.phases[st_def.liquid].viscosity;
        let sigma = st_def.coefficient;
        let error = (jump - reference).abs() / reference;
        let details = vec![
            format!(
                "  pressure jump {jump:.5e} Pa (mean of {} samples from t = {:.3e} s), Laplace {reference:.5e} Pa (R = {:.4e} m = {:.1} dx)",
                late.len(),
                0.5 * end,
                self.radius,
                self.radius / m.dx
            ),
            format!(
                "  spurious currents: largest speed {speed:.3e} m/s, capillary number eta |u| / sigma = {:.3e}",
                eta * speed / sigma
            ),
        ];
        Verdict {
            metric,
            value: error,
            details,
            figures: vec![
                ("pressure_jump".into(), jump),
                ("laplace_pressure".into(), reference),
                ("max_speed".into(), speed),
                ("capillary_number".into(), eta * speed / sigma),
            ],
        }
    }
}

/// Recoil momentum balance: a layer with no walls and no gravity gains momentum
/// only from the recoil pressure F22 (30) on its surfaces. Along the up axis it
/// must gain −∫ p_v(T_s) A dt, T_s the mean temperature of the particles of the
/// top surface (normal within 60° of up) and A the scene's `area`; integrated by
/// the trapezoid rule over the samples.
pub struct RecoilImpulse {
    area: f64,
    /// (time, momentum along up, p_v at the top surface's mean temperature).
    samples: Vec<(f64, f64, f64)>,
}

impl RecoilImpulse {
    pub fn new(area: f64) -> RecoilImpulse {
        RecoilImpulse {
            area,
            samples: Vec::new(),
        }
    }
}

impl Check for RecoilImpulse {
    fn observe(&mut self, m: &Model, st: &State) {
        let up = m.dim as usize - 1;
        let (mut momentum, mut t_sum, mut t_n, mut pv_law) = (0.0, 0.0, 0usize, None);
        for i in 0..st.active() {
            let ph = &m.phases[st.phase[i] as usize];
            if !ph.is_fluid() {
                continue;
            }
            momentum += st.mass[i] as f64 * st.vel[i][up] as f64;
            let s = st.surface.get(i).copied().unwrap_or([0.0; 4]);
            if s[3] > 0.0 && s[up] > 0.5 {
                t_sum += st.heat[i][1] as f64;
                t_n += 1;
                pv_law = pv_law.or(ph.thermal.and_then(|t| t.evaporation));
            }
        }
        let pv = match (pv_law, t_n) {
            (Some(e), n) if n > 0 => e.pressure(t_sum / n as f64),
            _ => 0.0,
        };
        let t = st.sim.time as f64;
        if self.samples.last().is_some_and(|s| s.0 == t) {
            return;
        }
        self.samples.push((t, momentum, pv));
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        let metric = "relative error of the momentum gained against -integral p_v A dt".to_string();
        let (Some(first), Some(last)) = (self.samples.first(), self.samples.last()) else {
            return (metric, f64::NAN, Vec::new()).into();
        };
        let impulse: f64 = self
            .samples
            .windows(2)
            .map(|w| -0.5 * (w[0].2 + w[1].2) * (w[1].0 - w[0].0) * self.area)
            .sum();
        let gained = last.1 - first.1;
        let error = (gained - impulse).abs() / impulse.abs();
        let details = vec![format!(
            "  momentum gained {gained:.6e} kg m/s, -integral p_v A dt {impulse:.6e} (p_v {:.4e} -> {:.4e} Pa, t = {:.3e} -> {:.3e} s)",
            first.2, last.2, first.0, last.0
        )];
        Verdict {
            metric,
            value: error,
            details,
            figures: vec![
                ("momentum_gained".into(), gained),
                ("recoil_impulse".into(), impulse),
            ],
        }
    }
}

/// A 2D drop that starts as a square relaxes to a disc under surface tension:
/// at the end, the outline's radius (the farthest liquid particle from the
/// liquid's centroid, + ½Δx) in each of up to 32 equal sectors (fewer on a
/// coarse drop: about two outline particles each), and its spread max − min in
/// Δx (the verdict; a lattice-cut disc already shows a few tenths).
/// Also printed: the mean outline radius against √(A/π) of the liquid's area
/// (mass / ρ0), and the spurious currents of the run's second half as the
/// largest speed and the capillary number η|u|/σ.
#[derive(Default)]
pub struct DropShape {
    /// (time, largest liquid or gas speed).
    speeds: Vec<(f64, f64)>,
}

const MAX_SECTORS: usize = 32;

impl Check for DropShape {
    fn observe(&mut self, m: &Model, st: &State) {
        let speed = particles(m, st)
            .filter(|p| p.kind == PhaseKind::Liquid || p.kind == PhaseKind::Gas)
            .map(|p| (p.v[0] * p.v[0] + p.v[1] * p.v[1]).sqrt())
            .fold(0.0, f64::max);
        self.speeds.push((st.sim.time as f64, speed));
    }

    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let liquid: Vec<[f64; 3]> = particles(m, st)
            .filter(|p| p.kind == PhaseKind::Liquid)
            .map(|p| p.x)
            .collect();
        let metric = "spread of the drop outline's radius over its sectors, in dx".to_string();
        if liquid.is_empty() {
            return (metric, f64::NAN, vec!["  no liquid".into()]).into();
        }
        let n = liquid.len() as f64;
        let c = [
            liquid.iter().map(|x| x[0]).sum::<f64>() / n,
            liquid.iter().map(|x| x[1]).sum::<f64>() / n,
        ];
        let st_def = m
            .surface_tension
            .as_ref()
            .expect("drop_shape needs surface tension");
        let liquid_phase = &m.phases[st_def.liquid];
        let area: f64 = (0..st.active())
            .filter(|&i| st.phase[i] as usize == st_def.liquid)
            .map(|i| st.mass[i] as f64 / liquid_phase.rho0)
            .sum();
        let r_eq = (area / std::f64::consts::PI).sqrt();
        // At least two outline particles per sector (one spacing per particle).
        let sectors =
            ((std::f64::consts::TAU * r_eq / (2.0 * m.dx)) as usize).clamp(8, MAX_SECTORS);
        let mut outline = vec![f64::NEG_INFINITY; sectors];
        for x in &liquid {
            let (dx, dy) = (x[0] - c[0], x[1] - c[1]);
            let angle = dy.atan2(dx) + std::f64::consts::PI;
            let k = ((angle / std::f64::consts::TAU * sectors as f64) as usize).min(sectors - 1);
            outline[k] = outline[k].max((dx * dx + dy * dy).sqrt() + 0.5 * m.dx);
        }
        outline.retain(|r| r.is_finite());
        let lo = outline.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = outline.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let mean = outline.iter().sum::<f64>() / outline.len() as f64;
        let end = st.sim.time as f64;
        let speed = self
            .speeds
            .iter()
            .filter(|s| s.0 >= 0.5 * end)
            .map(|s| s.1)
            .fold(0.0, f64::max);
        let ca = liquid_phase.viscosity * speed / st_def.coefficient;
        let spread = (hi - lo) / m.dx;
        Verdict {
            metric,
            value: spread,
            details: vec![
                format!(
                    "  outline radius {lo:.4e} to {hi:.4e} m over {} sectors (mean {mean:.4e} m; sqrt(A/pi) = {r_eq:.4e} m = {:.1} dx)",
                    outline.len(),
                    r_eq / m.dx
                ),
                format!(
                    "  spurious currents (second half): largest speed {speed:.3e} m/s, capillary number eta |u| / sigma = {ca:.3e}"
                ),
            ],
            figures: vec![
                ("outline_spread_dx".into(), spread),
                ("max_speed".into(), speed),
                ("capillary_number".into(), ca),
            ],
        }
    }
}

/// θ0 on the floor under the drop: the angle of the wall or solid particle
/// nearest to the liquid's lowest point.
fn floor_angle(m: &Model, st: &State) -> Option<f64> {
    let angles = m.surface_tension.as_ref()?.contact_angle.as_ref()?;
    let lowest = particles(m, st)
        .filter(|p| p.kind == PhaseKind::Liquid)
        .map(|p| p.x)
        .min_by(|a, b| a[1].total_cmp(&b[1]))?;
    let d2 = |i: usize| {
        let x = m.to_world(st.pos[i]);
        (0..2).map(|a| (x[a] - lowest[a]).powi(2)).sum::<f64>()
    };
    (0..st.active())
        .filter(|&i| angles[st.phase[i] as usize].is_some())
        .min_by(|&i, &j| d2(i).total_cmp(&d2(j)))
        .and_then(|i| angles[st.phase[i] as usize])
}

/// A 2D sessile drop on the y_min wall settles at its static contact angle θ0
/// (`surface_tension.contact_angle`): from the cap's height h (highest liquid
/// particle + ½Δx above the wall face) and base width w (the extent of the
/// bottom row of liquid + Δx), a circular cap has θ = 2 atan(2h/w). The verdict
/// is |θ − θ0| in degrees, θ averaged over the samples of the run's second half.
#[derive(Default)]
pub struct ContactAngle {
    /// (time, θ in degrees, h, w).
    samples: Vec<(f64, f64, f64, f64)>,
}

impl Check for ContactAngle {
    fn observe(&mut self, m: &Model, st: &State) {
        let floor = m.domain_lo[1];
        let liquid: Vec<[f64; 3]> = particles(m, st)
            .filter(|p| p.kind == PhaseKind::Liquid)
            .map(|p| p.x)
            .collect();
        let top = liquid
            .iter()
            .map(|x| x[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let bottom: Vec<f64> = liquid
            .iter()
            .filter(|x| x[1] < floor + m.dx)
            .map(|x| x[0])
            .collect();
        if bottom.is_empty() {
            return;
        }
        let lo = bottom.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = bottom.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let (h, w) = (top + 0.5 * m.dx - floor, hi - lo + m.dx);
        let theta = 2.0 * (2.0 * h / w).atan();
        self.samples
            .push((st.sim.time as f64, theta.to_degrees(), h, w));
    }

    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let metric =
            "|contact angle - static angle| over the run's second half, degrees".to_string();
        let target = floor_angle(m, st).map_or(f64::NAN, f64::to_degrees);
        let end = st.sim.time as f64;
        let late: Vec<_> = self.samples.iter().filter(|s| s.0 >= 0.5 * end).collect();
        if late.is_empty() {
            return (
                metric,
                f64::NAN,
                vec!["  no sample with a drop on the wall".into()],
            )
                .into();
        }
        let k = late.len() as f64;
        let theta = late.iter().map(|s| s.1).sum::<f64>() / k;
        let h = late.iter().map(|s| s.2).sum::<f64>() / k;
        let w = late.iter().map(|s| s.3).sum::<f64>() / k;
        Verdict {
            metric,
            value: (theta - target).abs(),
            details: vec![format!(
                "  contact angle {theta:.2} deg against {target:.1} deg (cap height {h:.4e} m, base width {w:.4e} m, mean of {} samples)",
                late.len()
            )],
            figures: vec![("contact_angle_deg".into(), theta)],
        }
    }
}
