//! Heat reference solutions (classic, not from the papers; docs/validation.md):
//! conduction into a semi-infinite solid (erf), steady conduction through two
//! layers, and enthalpy conservation in an adiabatic box.

use super::{Check, Verdict};
use crate::model::Model;
use crate::state::State;

/// (axis coordinate, temperature, phase) of every conducting particle.
fn conducting(m: &Model, st: &State) -> Vec<(f64, f64, usize)> {
    let ax = m.dim as usize - 1;
    (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].conducts())
        .map(|i| {
            (
                m.to_world(st.pos[i])[ax],
                st.heat[i][1] as f64,
                st.phase[i] as usize,
            )
        })
        .collect()
}

/// Prescribed temperatures of the Dirichlet walls below and above the domain.
pub(super) fn wall_temperatures(m: &Model, st: &State) -> (Option<f64>, Option<f64>) {
    let ax = m.dim as usize - 1;
    let (mut lo, mut hi) = (None, None);
    for i in 0..st.len() {
        let ph = &m.phases[st.phase[i] as usize];
        let Some(th) = ph.thermal.filter(|_| !ph.conducts()) else {
            continue;
        };
        let x = m.to_world(st.pos[i])[ax];
        if x < m.domain_lo[ax] {
            lo = Some(th.temperature);
        } else if x > m.domain_hi[ax] {
            hi = Some(th.temperature);
        }
    }
    (lo, hi)
}

fn max_error(
    pts: &[(f64, f64, usize)],
    scale: f64,
    reference: impl Fn(f64, usize) -> f64,
) -> (f64, f64) {
    let (mut worst, mut se) = (0.0f64, 0.0);
    for &(x, t, ph) in pts {
        let e = (t - reference(x, ph)).abs() / scale;
        worst = worst.max(e);
        se += e * e;
    }
    (worst, (se / pts.len().max(1) as f64).sqrt())
}

/// T(y, t) = T_w + (T_0 − T_w) erf(y / (2√(αt))), y from the wall face at the
/// lower side of the last axis (Carslaw & Jaeger §2.4).
pub fn conduction_1d(m: &Model, st: &State) -> (String, f64, Vec<String>) {
    let pts = conducting(m, st);
    let (Some(tw), _) = wall_temperatures(m, st) else {
        return (
            "max |T - T_erf| / |T0 - Tw|".into(),
            f64::NAN,
            vec!["  no Dirichlet wall below the solid".into()],
        );
    };
    let ph = &m.phases[pts[0].2];
    let th = ph.thermal.unwrap();
    let alpha = th.conductivity / (ph.rho0 * th.heat_capacity);
    let t = st.sim.time as f64;
    let t0 = th.temperature;
    let y0 = m.domain_lo[m.dim as usize - 1];
    let depth = 2.0 * (alpha * t).sqrt();
    let (worst, rms) = max_error(&pts, (t0 - tw).abs(), |y, _| {
        tw + (t0 - tw) * libm::erf((y - y0) / depth)
    });
    let details = vec![format!(
        "  t = {t:.4e} s, alpha = {alpha:.4e} m^2/s, diffusion length 2 sqrt(alpha t) = {depth:.4e} m, {} particles, rms error {:.3e}",
        pts.len(),
        rms
    )];
    ("max |T - T_erf| / |T0 - Tw|".into(), worst, details)
}

/// Steady 1D conduction between two Dirichlet walls through a layer of
/// conductivity k_1 below `interface` and k_2 above: temperature linear in the
/// thermal resistance ∫dy/k.
pub fn two_materials(m: &Model, st: &State, interface: f64) -> (String, f64, Vec<String>) {
    let metric = "max |T - T_steady| / |T_hi - T_lo|".to_string();
    let pts = conducting(m, st);
    let (Some(t_lo), Some(t_hi)) = wall_temperatures(m, st) else {
        return (
            metric,
            f64::NAN,
            vec!["  needs Dirichlet walls on both sides".into()],
        );
    };
    let k_of = |below: bool| {
        pts.iter()
            .find(|p| (p.0 < interface) == below)
            .map(|p| m.phases[p.2].thermal.unwrap().conductivity)
            .unwrap_or(f64::NAN)
    };
    let (k1, k2) = (k_of(true), k_of(false));
    let ax = m.dim as usize - 1;
    let (y0, y1) = (m.domain_lo[ax], m.domain_hi[ax]);
    let resistance = |y: f64| {
        if y <= interface {
            (y - y0) / k1
        } else {
            (interface - y0) / k1 + (y - interface) / k2
        }
    };
    let total = resistance(y1);
    let (worst, rms) = max_error(&pts, (t_hi - t_lo).abs(), |y, _| {
        t_lo + (t_hi - t_lo) * resistance(y) / total
    });
    let t_if = t_lo + (t_hi - t_lo) * resistance(interface) / total;
    let details = vec![format!(
        "  k = {k1} / {k2} W/(m K), walls {t_lo} K / {t_hi} K, interface {t_if:.4} K, t = {:.4e} s, rms error {rms:.3e}",
        st.sim.time
    )];
    (metric, worst, details)
}

/// Σ m h over conducting particles (J per metre of depth in 2D).
pub fn total_enthalpy(m: &Model, st: &State) -> f64 {
    (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].conducts())
        .map(|i| {
            st.mass[i] as f64 * m.phases[st.phase[i] as usize].absolute_enthalpy(st.heat[i][0])
        })
        .sum()
}

pub fn adiabatic(m: &Model, st: &State, initial: f64) -> (String, f64, Vec<String>) {
    let now = total_enthalpy(m, st);
    let drift = (now - initial).abs() / initial.abs();
    let temps: Vec<f64> = conducting(m, st).iter().map(|p| p.1).collect();
    let (lo, hi) = temps
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &t| (a.0.min(t), a.1.max(t)));
    let details = vec![format!(
        "  {} steps; enthalpy {initial:.9e} -> {now:.9e}; temperatures now {lo:.3} .. {hi:.3} K",
        st.sim.step
    )];
    ("|H - H0| / |H0|".into(), drift, details)
}

/// λ of the one-phase Stefan problem: λ e^{λ²} erf(λ) = St/√π (Carslaw & Jaeger
/// §11.2), by bisection (the left side increases monotonically from 0).
pub fn stefan_lambda(stefan: f64) -> f64 {
    let target = stefan / std::f64::consts::PI.sqrt();
    let f = |l: f64| l * (l * l).exp() * libm::erf(l) - target;
    let (mut lo, mut hi) = (0.0, 1.0);
    while f(hi) < 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Exact and simulated melting fronts of the one-phase Stefan problem at the
/// state's time: a solid at its melting temperature, the surface held at T_w above
/// it. Exact s(t) = 2λ√(α_l t), St = c_p (T_w − T_m)/L, T_m the middle of the
/// melting band. Simulated: the melted depth, i.e. the liquid fraction integrated
/// over the volume and divided by the cross-section. None if the scene does not fit.
pub fn stefan_fronts(m: &Model, st: &State) -> Option<(f64, f64, String)> {
    let pts = conducting(m, st);
    let (Some(tw), _) = wall_temperatures(m, st) else {
        return None;
    };
    let ph = &m.phases[pts.first()?.2];
    let th = ph.thermal?;
    let (ts, tl, latent) = th.melting?;
    let alpha = th.conductivity / (ph.rho0 * th.heat_capacity);
    let stefan = th.heat_capacity * (tw - 0.5 * (ts + tl)) / latent;
    let lambda = stefan_lambda(stefan);
    let t = st.sim.time as f64;
    let exact = 2.0 * lambda * (alpha * t).sqrt();
    let cross: f64 = (0..m.dim as usize - 1)
        .map(|a| m.domain_hi[a] - m.domain_lo[a])
        .product();
    let cell = m.dx.powi(m.dim as i32);
    let melted: f64 = (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].conducts())
        .map(|i| st.heat[i][2] as f64 * cell)
        .sum();
    let info = format!("St = {stefan:.4}, lambda = {lambda:.6}");
    Some((melted / cross, exact, info))
}

/// RMS relative front error over the samples in the second half of the run. The
/// enthalpy method melts one particle layer at a time, so the front error at one
/// instant oscillates with the layer's progress; the RMS over many samples measures
/// the discretisation, and the early half (a front a few particles deep) is left out.
pub fn stefan_1d(m: &Model, samples: &[(f64, f64, f64)], info: &str) -> (String, f64, Vec<String>) {
    let metric = "rms |s - s_exact| / s_exact over t >= t_end/2".to_string();
    let mut details = vec![format!("  dx = {:.3e} m, {info}", m.dx)];
    let t_end = samples.last().map_or(0.0, |s| s.0);
    let (mut se, mut n) = (0.0, 0usize);
    for &(t, front, exact) in samples.iter().filter(|s| s.0 >= 0.5 * t_end && s.2 > 0.0) {
        let e = (front - exact) / exact;
        se += e * e;
        n += 1;
        details.push(format!(
            "  t = {t:.4e} s: front {front:.5e} m, exact {exact:.5e} m, error {:+.2}%",
            100.0 * e
        ));
    }
    let rms = if n > 0 {
        (se / n as f64).sqrt()
    } else {
        f64::NAN
    };
    (metric, rms, details)
}

/// Energy balance in an insulated scene: enthalpy gained = absorbed beam energy
/// ζ ∫P dt − heat lost through free surfaces (evaporation, radiation), the loss
/// integrated over the samples by the trapezoid rule. Relative to the energy
/// that moved, ζ E + E_loss. (Beer–Lambert needs a body thick enough to take the
/// beam: the transmitted fraction is reported.)
pub fn laser_energy(
    m: &Model,
    st: &State,
    initial: f64,
    losses: &[(f64, f64)],
) -> (String, f64, Vec<String>) {
    let metric = "|dH - (zeta E_beam - E_loss)| / (zeta E_beam + E_loss)".to_string();
    let lost: f64 = losses
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum();
    let delivered_by = |l: Option<&crate::model::Laser>| {
        l.map_or(0.0, |l| {
            l.absorptivity.unwrap_or(f64::NAN) * l.energy_until(st.sim.time as f64)
        })
    };
    // Each step applies the power at its start time: the integral below matches
    // that exactly while the power is constant, and to one step's energy
    // (P Δt) at a switch.
    let t = st.sim.time as f64;
    let delivered = delivered_by(m.laser.as_ref());
    let gained = total_enthalpy(m, st) - initial;
    let err = (gained - (delivered - lost)).abs() / (delivered + lost);
    let depth = m.domain_hi[m.dim as usize - 1] - m.domain_lo[m.dim as usize - 1];
    let transmission = m
        .laser
        .as_ref()
        .map_or(0.0, |l| (-l.absorption * depth).exp());
    let details = vec![format!(
        "  t = {t:.4e} s: enthalpy gained {gained:.6e}, zeta x beam energy {delivered:.6e}, surface losses {lost:.6e} ({} samples); transmission exp(-a H) = {transmission:.2e}",
        losses.len()
    )];
    (metric, err, details)
}

/// Modified Bessel function K0(x) = ∫_0^∞ exp(−x cosh t) dt (trapezoid rule; the
/// integrand decays double-exponentially, so 4000 panels over [0, 12] give better
/// than 1e-9 relative for x ≥ 1e-3).
pub fn bessel_k0(x: f64) -> f64 {
    let (n, top) = (4000, 12.0);
    let dt = top / n as f64;
    let f = |t: f64| (-x * t.cosh()).exp();
    (0..=n)
        .map(|k| {
            let w = if k == 0 || k == n { 0.5 } else { 1.0 };
            w * f(k as f64 * dt)
        })
        .sum::<f64>()
        * dt
}

/// Quasi-steady temperature rise around a source moving at speed v along x on the
/// surface of a half-space (Rosenthal 1946; Carslaw & Jaeger §10.7), ξ = x − x_beam,
/// depth d below the surface, lateral offset y (3D):
///   2D (line source, q' W/m): ΔT = q'/(π k) e^{−vξ/2α} K0(v r/2α), r = √(ξ² + d²)
///   3D (point source, q W):   ΔT = q/(2π k R) e^{−v(ξ + R)/2α}, R = √(ξ² + y² + d²)
#[allow(clippy::too_many_arguments)] // the reference's own parameters, each a number
pub fn rosenthal_rise(
    dim: u32,
    q: f64,
    k: f64,
    alpha: f64,
    v: f64,
    xi: f64,
    y: f64,
    d: f64,
) -> f64 {
    if dim == 2 {
        let r = (xi * xi + d * d).sqrt();
        q / (std::f64::consts::PI * k)
            * (-v * xi / (2.0 * alpha)).exp()
            * bessel_k0(v * r / (2.0 * alpha))
    } else {
        let r = (xi * xi + y * y + d * d).sqrt();
        q / (2.0 * std::f64::consts::PI * k * r) * (-v * (xi + r) / (2.0 * alpha)).exp()
    }
}

/// Surface temperatures along the scan line against Rosenthal's solution, at
/// particles more than two beam radii from the beam centre and within one
/// diffusion length 2α/v ahead of it and 1.5 behind it, the error relative to the
/// predicted rise two beam radii behind the beam. Further behind, the finite track
/// (the quasi-steady wake of a 2D line source builds up over many diffusion
/// lengths) and the plate's held sides and bottom decide the temperature, not the
/// half-space solution. The scan speed is that of the path's last segment.
pub fn rosenthal(m: &Model, st: &State) -> (String, f64, Vec<String>) {
    let metric =
        "max |T - T_R| / dT_R(-2 r_w), 2 r_w < |xi|, -3 alpha/v < xi < 2 alpha/v".to_string();
    let Some(l) = &m.laser else {
        return (metric, f64::NAN, vec!["  the scene has no laser".into()]);
    };
    let t = st.sim.time as f64;
    let n = l.path.len();
    if n < 2 {
        return (
            metric,
            f64::NAN,
            vec!["  the path needs two points (a moving source)".into()],
        );
    }
    let (t0, p0) = l.path[n - 2];
    let (t1, p1) = l.path[n - 1];
    let v = (p1[0] - p0[0]) / (t1 - t0);
    let beam = l.centre_at(t);
    let q = l.absorptivity.unwrap_or(f64::NAN) * l.power_at(t);
    let up = m.dim as usize - 1;
    let top = m.domain_hi[up];
    let pts: Vec<(f64, f64, f64, f64, usize)> = (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].conducts())
        .map(|i| {
            let world = m.to_world(st.pos[i]);
            let x = |a: usize| world[a];
            let lateral = if m.dim == 3 { x(1) - beam[1] } else { 0.0 };
            (
                x(0) - beam[0],
                lateral,
                top - x(up),
                st.heat[i][1] as f64,
                st.phase[i] as usize,
            )
        })
        .filter(|p| p.2 < m.dx && p.1.abs() < 0.5 * m.dx)
        .collect();
    let Some(first) = pts.first() else {
        return (
            metric,
            f64::NAN,
            vec!["  no surface particle on the scan line".into()],
        );
    };
    let ph = &m.phases[first.4];
    let th = ph.thermal.unwrap();
    let (k, alpha) = (
        th.conductivity,
        th.conductivity / (ph.rho0 * th.heat_capacity),
    );
    let t_init = th.temperature;
    let rise = |xi: f64, y: f64, d: f64| rosenthal_rise(m.dim, q, k, alpha, v, xi, y, d);
    let scale = rise(-2.0 * l.radius, 0.0, 0.5 * m.dx);
    let diffusion = 2.0 * alpha / v;
    let (mut worst, mut used) = (0.0f64, 0usize);
    let mut details = vec![format!(
        "  v = {v:.4e} m/s, q = {q:.4e}, k = {k}, alpha = {alpha:.4e} m^2/s, 2 alpha/v = {:.3e} m, beam at x = {:.4e} m, t = {t:.4e} s",
        2.0 * alpha / v,
        beam[0]
    )];
    let mut sorted = pts.clone();
    sorted.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    for (xi, y, d, temp, _) in sorted {
        if xi.abs() <= 2.0 * l.radius || xi < -1.5 * diffusion || xi > diffusion {
            continue;
        }
        let r = rise(xi, y, d);
        let e = (temp - t_init - r).abs() / scale;
        worst = worst.max(e);
        used += 1;
        if used % 4 == 1 {
            details.push(format!(
                "  xi = {xi:+.4e} m: T = {temp:.2} K, Rosenthal {:.2} K, error {:.2}%",
                t_init + r,
                100.0 * e
            ));
        }
    }
    if used == 0 {
        worst = f64::NAN;
    }
    details.push(format!("  {used} surface particles compared"));
    (metric, worst, details)
}

/// Conduction into a semi-infinite solid (erf profile).
pub struct Conduction1d;

impl Check for Conduction1d {
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        conduction_1d(m, st).into()
    }
}

/// Steady conduction through two layers meeting at `interface`.
pub struct TwoMaterials {
    pub interface: f64,
}

impl Check for TwoMaterials {
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        two_materials(m, st, self.interface).into()
    }
}

/// Total enthalpy of an insulated box against its first sample.
#[derive(Default)]
pub struct Adiabatic {
    initial: Option<f64>,
}

impl Check for Adiabatic {
    fn observe(&mut self, m: &Model, st: &State) {
        self.initial.get_or_insert_with(|| total_enthalpy(m, st));
    }
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        adiabatic(m, st, self.initial.unwrap_or(f64::NAN)).into()
    }
}

/// Melting front against Stefan's solution, sample by sample.
#[derive(Default)]
pub struct Stefan {
    /// (t, simulated front, exact front) per sample, and the header line.
    fronts: Vec<(f64, f64, f64)>,
    info: String,
}

impl Check for Stefan {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        if let Some((front, exact, info)) = stefan_fronts(m, st) {
            if self.fronts.last().is_none_or(|f| f.0 < t) {
                self.fronts.push((t, front, exact));
            }
            self.info = info;
        }
    }
    fn verdict(&mut self, m: &Model, _st: &State) -> Verdict {
        stefan_1d(m, &self.fronts, &self.info).into()
    }
}

/// Quasi-steady temperature around a moving source (Rosenthal).
pub struct Rosenthal;

impl Check for Rosenthal {
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        rosenthal(m, st).into()
    }
}

/// Laser energy balance: absorbed power against the enthalpy gained plus the heat
/// that left through free surfaces.
#[derive(Default)]
pub struct LaserEnergy {
    initial: Option<f64>,
    /// (t, heat leaving through free surfaces) per sample.
    losses: Vec<(f64, f64)>,
}

impl Check for LaserEnergy {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        self.initial.get_or_insert_with(|| total_enthalpy(m, st));
        let (evap, rad) = crate::diagnostics::surface_loss_power(m, st);
        if self.losses.last().is_none_or(|l| l.0 < t) {
            self.losses.push((t, evap + rad));
        }
    }
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        laser_energy(m, st, self.initial.unwrap_or(f64::NAN), &self.losses).into()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn stefan_lambda_matches_tabulated_values() {
        // Carslaw & Jaeger: St = 0.1 gives λ ≈ 0.2200, St = 1 gives λ ≈ 0.6201.
        assert!((super::stefan_lambda(0.1) - 0.2200).abs() < 1e-4);
        assert!((super::stefan_lambda(1.0) - 0.6201).abs() < 1e-4);
    }

    #[test]
    fn bessel_k0_matches_tabulated_values() {
        // Abramowitz & Stegun Table 9.8: K0(0.1) = 2.4270690, K0(1) = 0.4210244, K0(2) = 0.1138939.
        for (x, k) in [(0.1, 2.4270690), (1.0, 0.4210244), (2.0, 0.1138939)] {
            assert!((super::bessel_k0(x) / k - 1.0).abs() < 1e-6, "K0({x})");
        }
    }
}
