//! Thermocapillary flow in a two-layer channel (Pendse & Esmaeeli 2010), the
//! standard steady test of a Marangoni stress: liquid (1) in −a ≤ y ≤ 0 under a
//! second fluid (2) in 0 ≤ y ≤ b, periodic in x, no-slip walls; the bottom wall
//! held at T_h + T_0 cos(ωx), the top one at T_c; α(T) = α0 + α0' (T − T_α0).
//! At zero Reynolds and Marangoni numbers with a flat interface the temperature
//! is conduction only and the flow is Stokes flow, driven by the interface's
//! shear-stress jump μ1 ∂u1/∂y − μ2 ∂u2/∂y = ∂α/∂x.
//!
//! The solution written here is ours, derived for this check (the cited paper
//! gives the same problem in closed form):
//! - Temperature: T = T_lin(y) + T_0 cos(ωx) f(y), T_lin piecewise linear with the
//!   interface at T_I = (k1 T_h/a + k2 T_c/b)/(k1/a + k2/b); f'' = ω² f in each
//!   layer with f(−a) = 1, f(b) = 0, f and k f' continuous at y = 0:
//!   f1 = cosh ω(y+a) + B sinh ω(y+a), f2 = C sinh ω(b−y),
//!   B = −(cosh ωa + K sinh ωa)/(sinh ωa + K cosh ωa), K = (k1/k2) tanh ωb,
//!   so the interface amplitude is g = f(0) = K/(sinh ωa + K cosh ωa).
//! - Flow: stream function ψ = sin(ωx) F(y), u = sin(ωx) F'(y), v = −ω cos(ωx) F(y),
//!   F'''' − 2ω² F'' + ω⁴ F = 0, so F = (A + By) cosh ωy + (C + Dy) sinh ωy per
//!   layer; F(0) = 0 (flat interface) gives A = 0; no slip F = F' = 0 at y = −a
//!   and y = b; F' continuous at 0; and the stress jump with ∂α/∂x =
//!   −α0' T_0 g ω sin(ωx): 2ω (μ1 D1 − μ2 D2) = −α0' T_0 g ω. Six linear equations
//!   in (B1, C1, D1, B2, C2, D2), solved by Gaussian elimination.

use super::{particles, Check, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;
use std::f64::consts::TAU;

/// Points of the compared interface-velocity profile per wavelength.
const PROFILE_BINS: usize = 20;

/// The channel's parameters (SI) and its analytic solution.
#[derive(Debug, Clone, Copy)]
pub struct Channel {
    /// Layer thicknesses: liquid below the interface, second fluid above.
    pub a: f64,
    pub b: f64,
    pub mu1: f64,
    pub mu2: f64,
    pub k1: f64,
    pub k2: f64,
    pub t_hot: f64,
    pub t_cold: f64,
    /// T_0, the bottom wall's cosine amplitude.
    pub amplitude: f64,
    /// ω = 2π / wavelength.
    pub omega: f64,
    /// α0' (N/(m K)), ≤ 0.
    pub slope: f64,
}

/// F(y) = B y cosh ωy + (C + D y) sinh ωy of one layer.
#[derive(Debug, Clone, Copy)]
struct Layer {
    b: f64,
    c: f64,
    d: f64,
}

impl Layer {
    fn f(&self, w: f64, y: f64) -> f64 {
        self.b * y * (w * y).cosh() + (self.c + self.d * y) * (w * y).sinh()
    }
    fn df(&self, w: f64, y: f64) -> f64 {
        let (ch, sh) = ((w * y).cosh(), (w * y).sinh());
        self.b * (ch + w * y * sh) + self.d * sh + (self.c + self.d * y) * w * ch
    }
}

/// The solved flow: the two layers' stream-function profiles.
#[derive(Debug, Clone, Copy)]
pub struct Solution {
    ch: Channel,
    lower: Layer,
    upper: Layer,
}

impl Channel {
    /// g: the interface temperature's cosine amplitude over T_0.
    pub fn interface_amplitude(&self) -> f64 {
        let (w, a, b) = (self.omega, self.a, self.b);
        let k = self.k1 / self.k2 * (w * b).tanh();
        k / ((w * a).sinh() + k * (w * a).cosh())
    }

    /// Steady temperature at (x, y), y from the interface.
    pub fn temperature(&self, x: f64, y: f64) -> f64 {
        let (w, a, b) = (self.omega, self.a, self.b);
        let (r1, r2) = (self.k1 / a, self.k2 / b);
        let t_i = (r1 * self.t_hot + r2 * self.t_cold) / (r1 + r2);
        let k = self.k1 / self.k2 * (w * b).tanh();
        let (lin, f) = if y <= 0.0 {
            let bb = -((w * a).cosh() + k * (w * a).sinh()) / ((w * a).sinh() + k * (w * a).cosh());
            (
                t_i + (t_i - self.t_hot) * y / a,
                (w * (y + a)).cosh() + bb * (w * (y + a)).sinh(),
            )
        } else {
            let c = self.interface_amplitude() / (w * b).sinh();
            (t_i + (self.t_cold - t_i) * y / b, c * (w * (b - y)).sinh())
        };
        lin + self.amplitude * (w * x).cos() * f
    }

    pub fn solve(&self) -> Solution {
        let (w, a, b) = (self.omega, self.a, self.b);
        // Rows of F, F' at a point y for the unknowns (B, C, D) of one layer.
        let f_row = |y: f64| [y * (w * y).cosh(), (w * y).sinh(), y * (w * y).sinh()];
        let df_row = |y: f64| {
            let (ch, sh) = ((w * y).cosh(), (w * y).sinh());
            [ch + w * y * sh, w * ch, sh + w * y * ch]
        };
        let mut m = [[0.0f64; 7]; 6];
        let mut put = |row: usize, off: usize, v: [f64; 3]| {
            m[row][off..off + 3].copy_from_slice(&v);
        };
        put(0, 0, f_row(-a));
        put(1, 0, df_row(-a));
        put(2, 3, f_row(b));
        put(3, 3, df_row(b));
        // F1'(0) − F2'(0) = 0: B1 + ω C1 − B2 − ω C2.
        m[4] = [1.0, w, 0.0, -1.0, -w, 0.0, 0.0];
        // 2ω (μ1 D1 − μ2 D2) = −α0' T_0 g ω.
        let tau = -self.slope * self.amplitude * self.interface_amplitude() * w;
        m[5] = [
            0.0,
            0.0,
            2.0 * w * self.mu1,
            0.0,
            0.0,
            -2.0 * w * self.mu2,
            tau,
        ];
        let x = gauss6(m);
        Solution {
            ch: *self,
            lower: Layer {
                b: x[0],
                c: x[1],
                d: x[2],
            },
            upper: Layer {
                b: x[3],
                c: x[4],
                d: x[5],
            },
        }
    }
}

impl Solution {
    /// Steady velocity (u, v) at (x, y), y from the interface.
    pub fn velocity(&self, x: f64, y: f64) -> [f64; 2] {
        let w = self.ch.omega;
        let l = if y <= 0.0 { &self.lower } else { &self.upper };
        [(w * x).sin() * l.df(w, y), -w * (w * x).cos() * l.f(w, y)]
    }
    /// The interface velocity's amplitude: u(x, 0) = U sin(ωx).
    pub fn interface_speed(&self) -> f64 {
        self.lower.df(self.ch.omega, 0.0)
    }
}

/// Solves a 6×6 system given as an augmented matrix, partial pivoting.
fn gauss6(mut m: [[f64; 7]; 6]) -> [f64; 6] {
    for col in 0..6 {
        let piv = (col..6)
            .max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))
            .unwrap();
        m.swap(col, piv);
        for row in col + 1..6 {
            let f = m[row][col] / m[col][col];
            for k in col..7 {
                m[row][k] -= f * m[col][k];
            }
        }
    }
    let mut x = [0.0; 6];
    for row in (0..6).rev() {
        let s: f64 = (row + 1..6).map(|k| m[row][k] * x[k]).sum();
        x[row] = (m[row][6] - s) / m[row][row];
    }
    x
}

/// The channel a validated scene describes (model/mod.rs checks the layout:
/// 2D, periodic in x, F22's surface tension with α0' < 0, a Dirichlet wall
/// phase with a temperature wave along x and one without).
pub fn channel(m: &Model, surface: f64) -> Channel {
    let st = m
        .surface_tension
        .as_ref()
        .expect("validated: surface tension");
    let gas = st.gas.expect("validated: F22's form");
    let conductivity = |p: usize| m.phases[p].thermal.map_or(f64::NAN, |t| t.conductivity);
    let walls = || {
        m.phases
            .iter()
            .filter(|p| p.kind == PhaseKind::Wall)
            .filter_map(|p| p.thermal)
    };
    let hot = walls().find(|t| t.wave.is_some()).expect("validated: wave");
    let cold = walls()
        .find(|t| t.wave.is_none())
        .expect("validated: cold wall");
    let wave = hot.wave.unwrap();
    Channel {
        a: surface - m.domain_lo[1],
        b: m.domain_hi[1] - surface,
        mu1: m.phases[st.liquid].viscosity,
        mu2: m.phases[gas].viscosity,
        k1: conductivity(st.liquid),
        k2: conductivity(gas),
        t_hot: hot.temperature,
        t_cold: cold.temperature,
        amplitude: wave.amplitude,
        omega: TAU / wave.wavelength,
        slope: st.slope,
    }
}

/// The velocity of the particles within Δx of the interface (the rows on both
/// sides, between which the interface lies) against the analytic field at their
/// own positions: residuals averaged in 20 bins per wavelength along x (the
/// profile at 20 points whatever Δx, so that the figure compares across
/// resolutions; single particles carry the flow's noise, and the rows shear by
/// about a Δx along x over the run), the largest bin's |mean residual| over the
/// interface speed's amplitude U (the tolerance is a share of that maximum). Taken
/// at the last sample (steady state). Reported beside it: each side's amplitude
/// against the analytic one at the same particles, and the change of the band's
/// fitted amplitude over the run's last quarter (steadiness).
pub struct Thermocapillary {
    surface: f64,
    samples: Vec<(f64, f64)>,
}

impl Thermocapillary {
    pub fn new(surface: f64) -> Thermocapillary {
        Thermocapillary {
            surface,
            samples: Vec::new(),
        }
    }

    /// Particles of the two fluids within Δx of the interface: (x, y from the
    /// interface, u_x).
    fn band(&self, m: &Model, st: &State) -> Vec<(f64, f64, f64)> {
        particles(m, st)
            .filter(|p| matches!(p.kind, PhaseKind::Liquid | PhaseKind::Gas))
            .map(|p| (p.x[0], p.x[1] - self.surface, p.v[0]))
            .filter(|p| p.1.abs() < m.dx)
            .collect()
    }

    /// Least-squares amplitude of u_x = U sin(ωx) over the band.
    fn fitted_speed(band: &[(f64, f64, f64)], omega: f64) -> f64 {
        let (num, den) = band.iter().fold((0.0, 0.0), |acc, &(x, _, u)| {
            let s = (omega * x).sin();
            (acc.0 + u * s, acc.1 + s * s)
        });
        num / den
    }
}

impl Check for Thermocapillary {
    fn observe(&mut self, m: &Model, st: &State) {
        let ch = channel(m, self.surface);
        let band = self.band(m, st);
        self.samples
            .push((st.sim.time as f64, Self::fitted_speed(&band, ch.omega)));
    }

    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let ch = channel(m, self.surface);
        let sol = ch.solve();
        let u_max = sol.interface_speed().abs();
        let band = self.band(m, st);
        let period = TAU / ch.omega;
        let bins = PROFILE_BINS;
        let mut sums = vec![(0.0f64, 0usize); bins];
        let mut squares = 0.0;
        for &(x, y, u) in &band {
            let r = u - sol.velocity(x, y)[0];
            let k = ((x - m.domain_lo[0]).rem_euclid(period) / period * bins as f64) as usize;
            let s = &mut sums[k.min(bins - 1)];
            *s = (s.0 + r, s.1 + 1);
            squares += r * r;
        }
        let worst = sums
            .iter()
            .filter(|s| s.1 > 0)
            .map(|s| (s.0 / s.1 as f64).abs())
            .fold(0.0, f64::max);
        let rms = (squares / band.len().max(1) as f64).sqrt();
        // Each side's sin(ωx) amplitude against the analytic one at its particles.
        let side = |keep: &dyn Fn(f64) -> bool| {
            let (num, den) =
                band.iter()
                    .filter(|p| keep(p.1))
                    .fold((0.0, 0.0), |acc, &(x, y, u)| {
                        let s = (ch.omega * x).sin();
                        (acc.0 + u * s, acc.1 + sol.velocity(x, y)[0] * s)
                    });
            num / den
        };
        let (liquid_ratio, fluid2_ratio) = (side(&|y| y < 0.0), side(&|y| y >= 0.0));
        let band_ratio = side(&|_| true);
        let fitted = Self::fitted_speed(&band, ch.omega);
        let end = st.sim.time as f64;
        let earlier = self
            .samples
            .iter()
            .rev()
            .find(|s| s.0 <= 0.75 * end)
            .map_or(f64::NAN, |s| s.1);
        let drift = (fitted - earlier).abs() / u_max;
        let details = vec![
            format!(
                "  channel: a = {:.1} dx, b = {:.1} dx, interface amplitude g = {:.4} of T_0 = {} K, stress amplitude {:.4e} Pa",
                ch.a / m.dx,
                ch.b / m.dx,
                ch.interface_amplitude(),
                ch.amplitude,
                -ch.slope * ch.amplitude * ch.interface_amplitude() * ch.omega
            ),
            format!(
                "  interface speed amplitude U (analytic, at the interface) {:.5e} m/s; the {} particles within dx of it move at {:+.2}% of the analytic speed at their positions",
                sol.interface_speed(),
                band.len(),
                100.0 * (band_ratio - 1.0)
            ),
            format!(
                "  against the analytic speed at the same particles: liquid side {:+.2}%, second fluid {:+.2}%",
                100.0 * (liquid_ratio - 1.0),
                100.0 * (fluid2_ratio - 1.0)
            ),
            format!(
                "  residual u_x - u_analytic: largest {}-bin mean {:.4e} m/s, rms per particle {:.4e} m/s ({:.2}% of U); change of the fitted amplitude over the last quarter {:.2}% of U",
                bins,
                worst,
                rms,
                100.0 * rms / u_max,
                100.0 * drift
            ),
        ];
        Verdict {
            metric: "largest binned interface-velocity error over the analytic amplitude".into(),
            value: worst / u_max,
            details,
            figures: vec![
                ("band_ratio".into(), band_ratio),
                ("analytic_speed".into(), sol.interface_speed()),
                ("rms_error".into(), rms / u_max),
                ("drift".into(), drift),
                ("liquid_ratio".into(), liquid_ratio),
                ("fluid2_ratio".into(), fluid2_ratio),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel() -> Channel {
        Channel {
            a: 2.5e-4,
            b: 2.5e-4,
            mu1: 1.0,
            mu2: 0.5,
            k1: 1000.0,
            k2: 500.0,
            t_hot: 310.0,
            t_cold: 300.0,
            amplitude: 10.0,
            omega: TAU / 1e-3,
            slope: -2e-3,
        }
    }

    /// The solved profiles meet every condition they were solved for, and the
    /// temperature meets its own (walls, continuity of T and k ∂T/∂y).
    #[test]
    fn solution_meets_its_boundary_conditions() {
        let ch = channel();
        let s = ch.solve();
        let w = ch.omega;
        let u = s.interface_speed();
        for l in [(&s.lower, -ch.a), (&s.upper, ch.b)] {
            assert!(l.0.f(w, l.1).abs() < 1e-12 * u.abs() / w);
            assert!(l.0.df(w, l.1).abs() < 1e-12 * u.abs());
            assert!(l.0.f(w, 0.0).abs() < 1e-15);
        }
        assert!((s.lower.df(w, 0.0) - s.upper.df(w, 0.0)).abs() < 1e-12 * u.abs());
        // Stress jump against ∂α/∂x at x = quarter period (sin = 1), by differences.
        let e = 1e-9;
        let x = 0.25 * TAU / w;
        let dudy = |y: f64| (s.velocity(x, y + e)[0] - s.velocity(x, y - e)[0]) / (2.0 * e);
        let jump = ch.mu1 * dudy(-2.0 * e) - ch.mu2 * dudy(2.0 * e);
        let dadx = ch.slope * (ch.temperature(x + e, 0.0) - ch.temperature(x - e, 0.0)) / (2.0 * e);
        assert!((jump - dadx).abs() < 1e-4 * dadx.abs(), "{jump} vs {dadx}");
        // Temperature: walls, and the flux k ∂T/∂y continuous at the interface.
        for x in [0.0, 1e-4, 3.3e-4] {
            let wall = ch.t_hot + ch.amplitude * (w * x).cos();
            assert!((ch.temperature(x, -ch.a) - wall).abs() < 1e-9);
            assert!((ch.temperature(x, ch.b) - ch.t_cold).abs() < 1e-9);
            let q1 = ch.k1 * (ch.temperature(x, 0.0) - ch.temperature(x, -e)) / e;
            let q2 = ch.k2 * (ch.temperature(x, e) - ch.temperature(x, 0.0)) / e;
            assert!((q1 - q2).abs() < 1e-3 * q1.abs().max(1.0), "{q1} vs {q2}");
        }
    }

    /// Long waves under an inviscid second fluid: a lubrication film with a
    /// surface stress τ and no net flux, whose surface speed is τ a /(4 μ1).
    #[test]
    fn long_wave_limit_is_the_thin_film() {
        let mut ch = channel();
        ch.omega = 0.01 / ch.a;
        ch.mu2 = 1e-9;
        let s = ch.solve();
        let tau = -ch.slope * ch.amplitude * ch.interface_amplitude() * ch.omega;
        let film = tau * ch.a / (4.0 * ch.mu1);
        assert!(
            (s.interface_speed() / film - 1.0).abs() < 1e-3,
            "{} vs {film}",
            s.interface_speed()
        );
    }
}
