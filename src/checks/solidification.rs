//! The solidification record against the two-phase Stefan
//! (Neumann) problem: a superheated melt at T_0 freezing from a wall held at
//! T_w below its melting temperature T_m (Carslaw & Jaeger §11.2, Neumann's
//! solution). With α_s, α_l the solid's and liquid's diffusivities and
//! ν = √(α_s/α_l), the front is s(t) = 2λ√(α_s t), where λ solves
//!   k_s (T_m − T_w) e^{−λ²} / (erf λ √(π α_s))
//!     − k_l (T_0 − T_m) e^{−λ²ν²} / (erfc(λν) √(π α_l)) = ρ L λ √α_s,
//! and at the front, when it passes depth x (t*(x) = x² / (4 λ² α_s)):
//!   V = λ √(α_s / t*),
//!   G_s = (T_m − T_w) e^{−λ²} / (erf λ √(π α_s t*)),
//!   G_l = (T_0 − T_m) e^{−λ²ν²} / (erfc(λν) √(π α_l t*)),
//! The gradient jumps across the front by ρ L V / k (the latent heat released).
//! A kernel-smoothed gradient of a particle on the front averages the two
//! sides, so the reference G is (G_s + G_l)/2; R (the record's, from its
//! neighbours' crossing times) is compared with V, the cooling rate G R with
//! V (G_s + G_l)/2. T_m is the middle of the melting band.

use super::Check;
use super::Verdict;
use crate::model::Model;
use crate::solidification::records;
use crate::state::State;
use std::f64::consts::PI;

/// G and R of every record whose crossing lies in the second half of the
/// front's travel, against Neumann's solution at the record's depth.
pub struct Front;

/// Neumann's solution of one scene.
struct Neumann {
    lambda: f64,
    alpha_s: f64,
    alpha_l: f64,
    /// T_m − T_w, T_0 − T_m.
    undercooling: f64,
    superheat: f64,
}

impl Neumann {
    fn of(m: &Model, st: &State) -> Result<Neumann, String> {
        let (Some(t_w), _) = super::heat::wall_temperatures(m, st) else {
            return Err("needs a Dirichlet wall below the domain".into());
        };
        let ph = m
            .phases
            .iter()
            .find(|p| p.thermal.is_some_and(|t| t.melting.is_some()) && p.conducts())
            .ok_or("needs a melting phase")?;
        let th = ph.thermal.unwrap();
        let (ts, tl, latent) = th.melting.unwrap();
        let t_m = 0.5 * (ts + tl);
        let (k_s, c_s) = (th.conductivity, th.heat_capacity);
        let (k_l, c_l) = th.liquid;
        let rho = ph.rho0;
        let alpha_s = k_s / (rho * c_s);
        let alpha_l = k_l / (rho * c_l);
        let (undercooling, superheat) = (t_m - t_w, th.temperature - t_m);
        if undercooling <= 0.0 || superheat < 0.0 {
            return Err("needs T_wall < T_m <= the melt's initial temperature".into());
        }
        let lambda = neumann_lambda(
            [k_s, k_l],
            [alpha_s, alpha_l],
            [undercooling, superheat],
            rho * latent,
        );
        Ok(Neumann {
            lambda,
            alpha_s,
            alpha_l,
            undercooling,
            superheat,
        })
    }
    /// When the front passes depth x.
    fn time_at(&self, x: f64) -> f64 {
        x * x / (4.0 * self.lambda * self.lambda * self.alpha_s)
    }
    /// (V, G_s, G_l) when the front passes depth x.
    fn at(&self, x: f64) -> (f64, f64, f64) {
        let t = self.time_at(x);
        let l = self.lambda;
        let nu = (self.alpha_s / self.alpha_l).sqrt();
        let v = l * (self.alpha_s / t).sqrt();
        let g_s =
            self.undercooling * (-l * l).exp() / (libm::erf(l) * (PI * self.alpha_s * t).sqrt());
        let g_l = self.superheat * (-l * l * nu * nu).exp()
            / (libm::erfc(l * nu) * (PI * self.alpha_l * t).sqrt());
        (v, g_s, g_l)
    }
}

/// λ of Neumann's problem, by bisection: the heat drawn into the solid minus
/// the heat from the liquid, less the latent heat (ρ L) at the front, falls
/// with λ and is positive near 0. [solid, liquid] conductivities,
/// diffusivities, and (T_m − T_w, T_0 − T_m).
fn neumann_lambda(k: [f64; 2], alpha: [f64; 2], dt: [f64; 2], rho_latent: f64) -> f64 {
    let nu = (alpha[0] / alpha[1]).sqrt();
    let balance = |l: f64| {
        k[0] * dt[0] * (-l * l).exp() / (libm::erf(l) * (PI * alpha[0]).sqrt())
            - k[1] * dt[1] * (-l * l * nu * nu).exp()
                / (libm::erfc(l * nu) * (PI * alpha[1]).sqrt())
            - rho_latent * l * alpha[0].sqrt()
    };
    let (mut lo, mut hi) = (1e-9, 1.0);
    while balance(hi) > 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if balance(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

impl Check for Front {
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let metric =
            "max(rms |G/G_ref - 1|, rms |R/V - 1|) over the front's second half".to_string();
        let neumann = match Neumann::of(m, st) {
            Ok(n) => n,
            Err(e) => return (metric, f64::NAN, vec![format!("  {e}")]).into(),
        };
        let ax = m.dim as usize - 1;
        let wall = m.domain_lo[ax];
        let end = st.sim.time as f64;
        let s_end = 2.0 * neumann.lambda * (neumann.alpha_s * end).sqrt();
        let mut details = vec![format!(
            "  lambda = {:.6}, front at {s_end:.4e} m at t = {end:.4e} s; records at depths {:.4e} to {s_end:.4e} m",
            neumann.lambda,
            0.5 * s_end
        )];
        let (mut eg, mut er, mut ec, mut et, mut n) = (0.0, 0.0, 0.0, 0.0, 0usize);
        let mut bias = [0.0f64; 3];
        for r in records(m, st) {
            let x = r.position[ax] - wall;
            if x < 0.5 * s_end || x > s_end {
                continue;
            }
            let (v, g_s, g_l) = neumann.at(x);
            let g_ref = 0.5 * (g_s + g_l);
            eg += (r.gradient / g_ref - 1.0).powi(2);
            er += (r.rate / v - 1.0).powi(2);
            ec += (r.cooling_rate / (v * g_ref) - 1.0).powi(2);
            et += (r.time / neumann.time_at(x) - 1.0).powi(2);
            bias[0] += r.gradient / g_ref - 1.0;
            bias[1] += r.rate / v - 1.0;
            bias[2] += r.cooling_rate / (v * g_ref) - 1.0;
            n += 1;
        }
        if n == 0 {
            details.push("  no record in the front's second half".into());
            return (metric, f64::NAN, details).into();
        }
        let rms = |s: f64| (s / n as f64).sqrt();
        let mid = neumann.at(0.75 * s_end);
        details.push(format!(
            "  mean signed error G {:+.2}%, R {:+.2}%, cooling rate {:+.2}%",
            100.0 * bias[0] / n as f64,
            100.0 * bias[1] / n as f64,
            100.0 * bias[2] / n as f64
        ));
        details.push(format!(
            "  {n} records: rms error G {:.2}%, R {:.2}%, cooling rate {:.2}%, crossing time {:.2}%",
            100.0 * rms(eg),
            100.0 * rms(er),
            100.0 * rms(ec),
            100.0 * rms(et)
        ));
        details.push(format!(
            "  at 3/4 of the front's travel: V = {:.4e} m/s, G_s = {:.4e}, G_l = {:.4e} K/m (jump {:.1}%)",
            mid.0,
            mid.1,
            mid.2,
            200.0 * (mid.1 - mid.2) / (mid.1 + mid.2)
        ));
        let value = rms(eg).max(rms(er));
        Verdict {
            metric,
            value,
            details,
            figures: vec![
                ("gradient_rms_error".into(), rms(eg)),
                ("rate_rms_error".into(), rms(er)),
                ("cooling_rms_error".into(), rms(ec)),
                ("time_rms_error".into(), rms(et)),
                ("records".into(), n as f64),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    /// With no latent heat and equal properties the front is the T_m isotherm
    /// of plain conduction, T = T_w + (T_0 − T_w) erf(x / 2√(αt)): with T_m
    /// midway erf λ = 1/2, λ = 0.476936, and the two sides' gradients agree
    /// with that profile's. Latent heat slows the front.
    #[test]
    fn neumann_without_latent_heat_is_an_isotherm() {
        let l = super::neumann_lambda([1.0; 2], [1e-6; 2], [100.0; 2], 0.0);
        assert!((l - 0.476936276204470).abs() < 1e-9, "{l}");
        let n = super::Neumann {
            lambda: l,
            alpha_s: 1e-6,
            alpha_l: 1e-6,
            undercooling: 100.0,
            superheat: 100.0,
        };
        let (_, g_s, g_l) = n.at(0.01);
        assert!((g_s / g_l - 1.0).abs() < 1e-9, "{g_s} {g_l}");
        let t = n.time_at(0.01);
        let exact = 200.0 / std::f64::consts::PI.sqrt() * (-l * l).exp() / (1e-6 * t).sqrt();
        assert!((g_s / exact - 1.0).abs() < 1e-9, "{g_s} {exact}");
        let slower = super::neumann_lambda([1.0; 2], [1e-6; 2], [100.0; 2], 1e7);
        assert!((slower - 0.4629015).abs() < 1e-6, "{slower}");
    }
}
