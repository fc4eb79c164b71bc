//! The laser source: beam, absorption model, power schedule and scan path.

use super::*;

/// Most path points and power steps the parameter block holds.
pub const MAX_LASER_POINTS: usize = 32;

/// Default rays per Δx across the beam (ray-traced model).
pub const DEFAULT_RAYS_PER_DX: u32 = 2;
/// Default surface hits per ray (ray-traced model).
pub const DEFAULT_MAX_BOUNCES: u32 = 8;
/// The ray bundle reaches out to this many beam radii r_w (a Gaussian beam
/// carries exp(−8) = 3.4e-4 of its power beyond 2 r_w; the bundle's weights are
/// normalised to the whole power).
pub const RAY_EXTENT_RADII: f64 = 2.0;
/// Vacuum permittivity ε0 (F/m) and the speed of light c (m/s), for Hagen–Rubens.
const EPSILON_0: f64 = 8.854_187_812_8e-12;
const LIGHT_SPEED: f64 = 2.997_924_58e8;

/// The ray-traced model's bundle and the materials' optics.
#[derive(Debug, Clone, PartialEq)]
pub struct RayTracing {
    pub profile: crate::scene::BeamProfile,
    pub rays_per_dx: u32,
    pub max_bounces: u32,
    /// Complex refractive index (n, k) of each phase at the laser's wavelength,
    /// None where the phase does not absorb (walls, gas).
    pub optics: Vec<Option<(f64, f64)>>,
}

impl RayTracing {
    /// Rays per lateral axis: an odd count centred on the beam, spacing
    /// Δx / rays_per_dx, out to RAY_EXTENT_RADII r_w (a top hat: its radius).
    pub fn rays_per_side(&self, dx: f64, radius: f64) -> u32 {
        let spacing = dx / self.rays_per_dx as f64;
        let reach = match self.profile {
            crate::scene::BeamProfile::Gaussian => RAY_EXTENT_RADII * radius,
            crate::scene::BeamProfile::TopHat => radius,
        };
        2 * (reach / spacing).ceil() as u32 + 1
    }
}

/// Fresnel absorptivity 1 − (R_s + R_p)/2 of a surface of complex index n + ik
/// for unpolarised light at incidence cosine `cos` (Born & Wolf §14.2; the
/// real form of Bass, Handbook of Optics vol. I ch. 12). At normal incidence
/// 4n / ((n + 1)² + k²).
pub fn fresnel_absorptivity(n: f64, k: f64, cos: f64) -> f64 {
    let c = cos.clamp(1e-6, 1.0);
    let s2 = 1.0 - c * c;
    let a_ = n * n - k * k - s2;
    let b_ = (a_ * a_ + 4.0 * n * n * k * k).sqrt();
    let a = (0.5 * (b_ + a_)).sqrt();
    let b2 = 0.5 * (b_ - a_);
    let rs = ((a - c).powi(2) + b2) / ((a + c).powi(2) + b2);
    let st = s2 / c;
    let rp = rs * ((a - st).powi(2) + b2) / ((a + st).powi(2) + b2);
    1.0 - 0.5 * (rs + rp)
}

/// Hagen–Rubens: n = k = 1/√(2 ε0 ω ρ_e) for a metal of DC resistivity ρ_e
/// (Ω m) at vacuum wavelength λ (m), ω = 2π c/λ.
pub fn hagen_rubens_index(resistivity: f64, wavelength: f64) -> f64 {
    let omega = 2.0 * std::f64::consts::PI * LIGHT_SPEED / wavelength;
    1.0 / (2.0 * EPSILON_0 * omega * resistivity).sqrt()
}

/// A validated laser source. Lateral coordinates are absolute.
#[derive(Debug, Clone)]
pub struct Laser {
    pub model: crate::scene::LaserModel,
    /// ζ of the Beer–Lambert and surface models; None for the ray-traced one,
    /// whose absorbed fraction follows from the surface it meets.
    pub absorptivity: Option<f64>,
    pub radius: f64,
    /// The ray-traced model's bundle and optics.
    pub rays: Option<RayTracing>,
    pub absorption: f64,
    /// (time, power) steps.
    pub power: Vec<(f64, f64)>,
    /// (time, lateral position) of the beam centre; unused lateral axes are 0.
    pub path: Vec<(f64, [f64; 2])>,
    /// The tracks of a `[scan]` in scan order (empty for an explicit path).
    pub tracks: Vec<ScanTrack>,
}

/// One track of a `[scan]`: the beam on at `t_on` at `start`, along `dir`
/// for `length`, off at `t_off` (lateral coordinates, m; unused axes 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanTrack {
    pub t_on: f64,
    pub t_off: f64,
    pub start: [f64; 2],
    /// Unit vector along the track, the way the beam moves.
    pub dir: [f64; 2],
    pub length: f64,
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
        if scene.scan.is_some() {
            return Err(cx.err("scan", "a [scan] moves a beam: it needs a [laser]"));
        }
        return Ok(None);
    };
    if !phases.iter().any(|p| p.conducts()) {
        return Err(cx.err(
            "laser",
            "a laser needs a heat scene (phases with a temperature)",
        ));
    }
    use crate::scene::LaserModel;
    let traced = l.model == LaserModel::RayTraced;
    let absorptivity = match (l.absorptivity, traced) {
        (Some(_), true) => {
            return Err(cx.err(
                "laser.absorptivity",
                "the ray_traced model takes the absorbed fraction from the materials' \
                 optical constants (refractive_index or electrical_resistivity); remove it",
            ))
        }
        (None, true) => None,
        (None, false) => {
            return Err(cx.err(
                "laser.absorptivity",
                "missing: the beer_lambert and gaussian_surface models need ζ in (0, 1]",
            ))
        }
        (Some(z), false) => {
            let z = cx.positive("laser.absorptivity", z)?;
            if z > 1.0 {
                return Err(cx.err(
                    "laser.absorptivity",
                    format!("must lie in (0, 1] (got {z})"),
                ));
            }
            Some(z)
        }
    };
    let radius = cx.positive("laser.radius", l.radius)?;
    let absorption = match (l.model, l.absorption_coefficient) {
        (LaserModel::RayTraced, Some(_)) => {
            return Err(cx.err(
                "laser.absorption_coefficient",
                "not used by the ray_traced model (rays are absorbed at the surface)",
            ))
        }
        (_, Some(a)) => cx.positive("laser.absorption_coefficient", a)?,
        (LaserModel::BeerLambert, None) => {
            return Err(cx.err(
                "laser.absorption_coefficient",
                "missing: the beer_lambert model needs it (1/m)",
            ))
        }
        (_, None) => 0.0,
    };
    let rays = if traced {
        Some(ray_tracing(cx, scene, phases)?)
    } else {
        for (key, given) in [
            (
                "laser.profile",
                l.profile != crate::scene::BeamProfile::Gaussian,
            ),
            ("laser.rays_per_dx", l.rays_per_dx.is_some()),
            ("laser.max_bounces", l.max_bounces.is_some()),
        ] {
            if given {
                return Err(cx.err(key, "only the ray_traced model uses it"));
            }
        }
        None
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
    let (path, tracks) = match &scene.scan {
        Some(scan) => {
            let s = scan_tables(cx, scan, l, &scene.domain, dim)?;
            power = s.power;
            (s.path, s.tracks)
        }
        None => (
            points("laser.path", &l.path, dim as usize)?
                .iter()
                .map(|e| (e[0], [e[1], if dim == 3 { e[2] } else { 0.0 }]))
                .collect(),
            Vec::new(),
        ),
    };
    Ok(Some(Laser {
        model: l.model,
        absorptivity,
        radius,
        rays,
        absorption,
        power,
        path,
        tracks,
    }))
}

/// The ray-traced model's keys and every absorbing phase's optical constants.
fn ray_tracing(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
) -> Result<RayTracing, InputError> {
    let l = scene.laser.as_ref().expect("a laser section");
    let rays_per_dx = l.rays_per_dx.unwrap_or(DEFAULT_RAYS_PER_DX);
    if !(1..=8).contains(&rays_per_dx) {
        return Err(cx.err(
            "laser.rays_per_dx",
            format!("must be 1 to 8 (got {rays_per_dx})"),
        ));
    }
    let max_bounces = l.max_bounces.unwrap_or(DEFAULT_MAX_BOUNCES);
    if !(1..=64).contains(&max_bounces) {
        return Err(cx.err(
            "laser.max_bounces",
            format!("must be 1 to 64 (got {max_bounces})"),
        ));
    }
    let wavelength = match l.wavelength {
        Some(w) => Some(cx.positive("laser.wavelength", w)?),
        None => None,
    };
    let mut optics = Vec::with_capacity(phases.len());
    for p in phases {
        if !p.conducts() || p.kind == crate::scene::PhaseKind::Gas {
            optics.push(None);
            continue;
        }
        let mat = &scene.materials[&p.material];
        let key = |k: &str| format!("materials.{}.{k}", p.material);
        let nk = match (&mat.refractive_index, mat.electrical_resistivity) {
            (Some(_), Some(_)) => {
                return Err(cx.err(
                    &key("electrical_resistivity"),
                    "give refractive_index or electrical_resistivity, not both",
                ))
            }
            (Some(v), None) => {
                if v.len() != 2 || !v.iter().all(|x| x.is_finite() && *x >= 0.0) || v[0] <= 0.0 {
                    return Err(cx.err(
                        &key("refractive_index"),
                        "expected [n, k] with n > 0 and k >= 0",
                    ));
                }
                (v[0], v[1])
            }
            (None, Some(r)) => {
                let r = cx.positive(&key("electrical_resistivity"), r)?;
                let Some(w) = wavelength else {
                    return Err(cx.err(
                        "laser.wavelength",
                        format!(
                            "missing: materials.{}.electrical_resistivity needs the \
                             laser's wavelength (m) for Hagen–Rubens",
                            p.material
                        ),
                    ));
                };
                let n = hagen_rubens_index(r, w);
                (n, n)
            }
            (None, None) => {
                return Err(cx.err(
                    &key("refractive_index"),
                    format!(
                        "missing: phase '{}' absorbs the ray-traced laser; give its \
                         material's refractive_index [n, k] at the laser's wavelength \
                         or its electrical_resistivity",
                        p.name
                    ),
                ))
            }
        };
        optics.push(Some(nk));
    }
    Ok(RayTracing {
        profile: l.profile,
        rays_per_dx,
        max_bounces,
        optics,
    })
}

/// `[scan]` compiled to the laser's tables: per track k, the beam at its start
/// from t_k (on, held for the dwell), then along the track at the scan speed
/// to its end (off there); the turnaround moves it, off, to the next start.
/// Tracks are `hatch_spacing` apart to the left of the first's direction;
/// `alternating` reverses every other one.
fn scan_tables(
    cx: &Ctx,
    scan: &crate::scene::ScanDef,
    l: &crate::scene::LaserDef,
    domain: &crate::scene::Domain,
    dim: u32,
) -> Result<ScanTables, InputError> {
    let p = match l.power {
        crate::scene::PowerDef::Constant(p) => p,
        crate::scene::PowerDef::Schedule(_) => {
            return Err(cx.err(
                "laser.power",
                "with a [scan] the power is one number: the scan switches it on and off",
            ))
        }
    };
    if !l.path.is_empty() {
        return Err(cx.err("laser.path", "give the path or a [scan], not both"));
    }
    if l.power_until.is_some() {
        return Err(cx.err(
            "laser.power_until",
            "with a [scan] the beam goes off at the end of the last track",
        ));
    }
    let lateral = dim as usize - 1;
    let in_plane = |key: &str, v: &[f64]| {
        if v.len() != lateral || v.iter().any(|x| !x.is_finite()) {
            return Err(cx.err(
                key,
                format!(
                    "{lateral} finite number(s) in the plate's plane for a {dim}D scene, got {v:?}"
                ),
            ));
        }
        Ok(())
    };
    in_plane("scan.start", &scan.start)?;
    let speed = cx.positive("scan.speed", scan.speed)?;
    let length = cx.positive("scan.length", scan.length)?;
    for (key, v) in [
        ("scan.start_time", scan.start_time),
        ("scan.dwell", scan.dwell),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(cx.err(key, format!("must be a time >= 0 (s), got {v}")));
        }
    }
    let mut dir = [1.0, 0.0];
    if let Some(d) = &scan.direction {
        in_plane("scan.direction", d)?;
        let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 0.0) {
            return Err(cx.err("scan.direction", "must not be zero"));
        }
        for (a, v) in d.iter().enumerate() {
            dir[a] = v / norm;
        }
    }
    let n = scan.tracks as usize;
    let per_track = if scan.dwell > 0.0 { 3 } else { 2 };
    if n == 0 || n * per_track > MAX_LASER_POINTS {
        return Err(cx.err(
            "scan.tracks",
            format!(
                "1 to {} tracks ({MAX_LASER_POINTS} path points, {per_track} a track), got {n}",
                MAX_LASER_POINTS / per_track
            ),
        ));
    }
    let (hatch, turn) = if n > 1 {
        if dim != 3 {
            return Err(cx.err("scan.tracks", "a 2D scene has one track"));
        }
        let need = |key: &str, v: Option<f64>| match v {
            Some(v) => cx.positive(key, v),
            None => Err(cx.err(key, "missing: a scan of several tracks needs it")),
        };
        (
            need("scan.hatch_spacing", scan.hatch_spacing)?,
            need("scan.turnaround", scan.turnaround)?,
        )
    } else {
        for (key, given) in [
            ("scan.hatch_spacing", scan.hatch_spacing.is_some()),
            ("scan.turnaround", scan.turnaround.is_some()),
        ] {
            if given {
                return Err(cx.err(key, "only a scan of several tracks uses it"));
            }
        }
        (0.0, 0.0)
    };
    let left = [-dir[1], dir[0]];
    let pass = length / speed;
    let (mut path, mut power, mut tracks) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..n {
        let back = scan.pattern == crate::scene::HatchPattern::Alternating && k % 2 == 1;
        let s = if back { length } else { 0.0 };
        let e = length - s;
        let at = |along: f64| {
            let mut x = [0.0; 2];
            for (a, xa) in x.iter_mut().enumerate().take(lateral) {
                *xa = scan.start[a] + along * dir[a] + k as f64 * hatch * left[a];
            }
            x
        };
        let t = scan.start_time + k as f64 * (scan.dwell + pass + turn);
        path.push((t, at(s)));
        if scan.dwell > 0.0 {
            path.push((t + scan.dwell, at(s)));
        }
        path.push((t + scan.dwell + pass, at(e)));
        power.push((t, p));
        power.push((t + scan.dwell + pass, 0.0));
        // every track on the plate: its start and end inside the domain
        for (end, x) in [("start", at(s)), ("end", at(e))] {
            let outside = (0..lateral).find(|&a| {
                domain.min.get(a).is_some_and(|lo| x[a] < *lo)
                    || domain.max.get(a).is_some_and(|hi| x[a] > *hi)
            });
            if let Some(a) = outside {
                let key = match (k, end) {
                    (0, "start") => "scan.start",
                    (0, _) => "scan.length",
                    _ => "scan.hatch_spacing",
                };
                return Err(cx.err(
                    key,
                    format!(
                        "track {} of {n} {end}s at {:?} m, outside the domain along {} ([{}, {}] m)",
                        k + 1,
                        &x[..lateral],
                        ["x", "y"][a],
                        domain.min[a],
                        domain.max[a]
                    ),
                ));
            }
        }
        let way = if back { -1.0 } else { 1.0 };
        tracks.push(ScanTrack {
            t_on: t,
            t_off: t + scan.dwell + pass,
            start: at(s),
            dir: [way * dir[0], way * dir[1]],
            length,
        });
    }
    Ok(ScanTables {
        path,
        power,
        tracks,
    })
}

/// What a `[scan]` compiles to: the beam's path and power tables and its tracks.
struct ScanTables {
    path: Vec<(f64, [f64; 2])>,
    power: Vec<(f64, f64)>,
    tracks: Vec<ScanTrack>,
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
    use super::{fresnel_absorptivity, hagen_rubens_index, switch_off};

    #[test]
    fn fresnel_absorptivity_at_normal_incidence_and_grazing() {
        // 4n / ((n + 1)² + k²) at normal incidence, for a metal and a dielectric
        for (n, k) in [(2.6, 5.2), (4.96, 4.96), (1.5, 0.0)] {
            let exact = 4.0 * n / ((n + 1.0) * (n + 1.0) + k * k);
            assert!((fresnel_absorptivity(n, k, 1.0) - exact).abs() < 1e-12);
        }
        // a metal absorbs more p-light towards grazing: the unpolarised mean
        // rises to a maximum near the principal angle, then falls to 0 at 90°
        let a = |deg: f64| fresnel_absorptivity(2.6, 5.2, deg.to_radians().cos());
        assert!(a(60.0) > a(0.0) && a(80.0) > a(60.0));
        assert!(a(89.999) < 0.01);
        // glass: R_s = R_p = 0.04 at normal incidence, Brewster's angle
        // tan θ_B = n gives R_p = 0, so A = 1 − R_s/2 there
        let tb = 1.5f64.atan();
        let rs = ((tb.cos() - 1.5 * (1.0 - (tb.sin() / 1.5).powi(2)).sqrt())
            / (tb.cos() + 1.5 * (1.0 - (tb.sin() / 1.5).powi(2)).sqrt()))
        .powi(2);
        assert!((fresnel_absorptivity(1.5, 0.0, tb.cos()) - (1.0 - 0.5 * rs)).abs() < 1e-12);
    }

    #[test]
    fn hagen_rubens_gives_the_metals_normal_absorptivity() {
        // IN625's 1.29 µΩ m at 1.07 µm: n = k ≈ 5.0, A ≈ 0.33
        let n = hagen_rubens_index(1.29e-6, 1.07e-6);
        assert!((n - 5.0).abs() < 0.1, "{n}");
        // Bramson's series for the same metal (ρ_e in Ω cm, λ in cm; Bramson
        // 1968, "Infrared radiation: a handbook for applications"):
        // A = 0.365 √(ρ/λ) − 0.0667 (ρ/λ) + 0.006 (ρ/λ)^1.5, which is the
        // expansion of 4n/((n + 1)² + n²) in 1/n
        let a = fresnel_absorptivity(n, n, 1.0);
        let x: f64 = 1.29e-4 / 1.07e-4;
        let bramson = 0.365 * x.sqrt() - 0.0667 * x + 0.006 * x.powf(1.5);
        assert!((a - bramson).abs() < 0.01 * bramson, "{a} {bramson}");
    }

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
