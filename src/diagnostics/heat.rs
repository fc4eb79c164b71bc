//! Heat figures of a `/diagnostics` record: the hottest particle, the
//! enthalpy, the laser's absorbed power, the losses through free surfaces and the
//! melt pool.

use crate::model::Model;
use crate::pool::{melt_regions, PoolFigures};
use crate::scene::PhaseKind;
use crate::state::State;
use serde::Serialize;

/// Heat diagnostics. Melt pool (crate::pool): the largest
/// connected region of melt (liquid fraction ≥ ½); in scenes with a melt track
/// the track sets its figures with the depth below the initial surface
/// (crate::track), elsewhere the depth is its height. Melt in other regions
/// (splashed droplets) is detached.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct HeatDiagnostics {
    pub max_temperature: f64,
    /// J (per metre of depth in 2D), Σ m h over conducting particles.
    pub total_enthalpy: f64,
    /// Laser power absorbed in the last step (W; W/m in 2D): ζ P(t), or the
    /// ray-traced bundle's absorbed sum; 0 without a laser.
    pub absorbed_laser_power: f64,
    /// The beam power of the last step (the bundle's launched sum).
    pub incident_laser_power: f64,
    /// Beam power not absorbed: rays that left the domain, or (1 − ζ) P.
    pub leaving_laser_power: f64,
    /// absorbed / incident (0 with the beam off).
    pub laser_absorbed_fraction: f64,
    /// Of the absorbed power, what rays still carried at their bounce limit.
    pub bounce_limit_laser_power: f64,
    /// Σ f_l V over liquid and solid particles (m³; m² in 2D).
    pub melted_volume: f64,
    pub pool_depth: f64,
    pub pool_width: f64,
    pub pool_length: f64,
    /// The pool's particles × Δx^dim (m³; m² in 2D).
    pub pool_volume: f64,
    /// Melt regions apart from the pool, their particles and mass (kg; per
    /// metre of depth in 2D).
    pub detached_melt_regions: u64,
    pub detached_melt_particles: u64,
    pub detached_melt_mass: f64,
    /// Heat leaving through free surfaces by evaporation F22 (18) (W; W/m in 2D).
    pub evaporated_power: f64,
    /// Heat leaving through free surfaces by radiation (W; W/m in 2D).
    pub radiated_power: f64,
}

/// The laser's power split in the state's last step (W; W/m in 2D).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaserBalance {
    pub incident: f64,
    pub absorbed: f64,
    pub leaving: f64,
    /// Of `absorbed`, what rays carried at their bounce limit (ray-traced).
    pub at_limit: f64,
}

impl LaserBalance {
    /// From the ray counts the device wrote (ray-traced), or ζ P(t) at the
    /// state's time; None without a laser.
    pub fn of(m: &Model, st: &State) -> Option<LaserBalance> {
        use crate::state::{RAYS_ABSORBED, RAYS_AT_LIMIT, RAYS_INCIDENT, RAYS_LEAVING};
        let l = m.laser.as_ref()?;
        match l.absorptivity {
            Some(z) => {
                let p = l.power_at(st.sim.time as f64);
                Some(LaserBalance {
                    incident: p,
                    absorbed: z * p,
                    leaving: (1.0 - z) * p,
                    at_limit: 0.0,
                })
            }
            None => {
                let c = &st.laser_rays;
                if c.len() < 4 {
                    return None;
                }
                let unit = crate::params::ray_power_unit(l) as f64;
                Some(LaserBalance {
                    incident: c[RAYS_INCIDENT] as f64 * unit,
                    absorbed: c[RAYS_ABSORBED] as f64 * unit,
                    leaving: c[RAYS_LEAVING] as f64 * unit,
                    at_limit: c[RAYS_AT_LIMIT] as f64 * unit,
                })
            }
        }
    }
    pub fn fraction(&self) -> f64 {
        if self.incident > 0.0 {
            self.absorbed / self.incident
        } else {
            0.0
        }
    }
}

/// The ray-traced laser's split over a run: summed over the states read back
/// (each output interval's last step) while the beam was on, so a user reads
/// the absorbed fraction a calorimeter would, not the last step's (zero once
/// the beam is off).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct LaserSummary {
    /// States read back with the beam on.
    pub samples: u32,
    /// Mean incident and absorbed power over them (W; W/m in 2D).
    pub incident_mean: f64,
    pub absorbed_mean: f64,
    /// Σ absorbed / Σ incident.
    pub absorbed_fraction: f64,
    /// The least and largest fraction of one sample.
    pub fraction_min: f64,
    pub fraction_max: f64,
    /// Mean power absorbed at the bounce limit (W; W/m in 2D).
    pub at_limit_mean: f64,
}

impl LaserSummary {
    /// Takes in one state's split; a step without incident power is skipped.
    pub fn add(&mut self, b: &LaserBalance) {
        if b.incident <= 0.0 {
            return;
        }
        let f = b.fraction();
        let n = self.samples as f64;
        if self.samples == 0 {
            self.fraction_min = f;
            self.fraction_max = f;
        } else {
            self.fraction_min = self.fraction_min.min(f);
            self.fraction_max = self.fraction_max.max(f);
        }
        self.incident_mean = (self.incident_mean * n + b.incident) / (n + 1.0);
        self.absorbed_mean = (self.absorbed_mean * n + b.absorbed) / (n + 1.0);
        self.at_limit_mean = (self.at_limit_mean * n + b.at_limit) / (n + 1.0);
        self.absorbed_fraction = self.absorbed_mean / self.incident_mean;
        self.samples += 1;
    }
}

/// (evaporated, radiated) power through free surfaces, host-side in f64 from the
/// temperatures and surface deltas of the state.
pub fn surface_loss_power(m: &Model, st: &State) -> (f64, f64) {
    if st.surface.is_empty() {
        return (0.0, 0.0);
    }
    let (mut evap, mut rad) = (0.0, 0.0);
    for i in 0..st.active() {
        let ph = &m.phases[st.phase[i] as usize];
        let Some(th) = ph.thermal.filter(|_| ph.conducts()) else {
            continue;
        };
        let t = st.heat[i][1] as f64;
        let area = st.surface[i][3] as f64 * st.mass[i] as f64 / ph.rho0;
        if let Some(e) = th.evaporation {
            // The liquid's c_p, as the solver's loss (surface_loss in heat.wgsl).
            evap += e.flux(t, th.liquid.1) * area;
        }
        rad += th.radiated_flux(t, m.ambient_temperature) * area;
    }
    (evap, rad)
}

/// The heat figures of `st`; None outside heat scenes.
pub fn heat_diagnostics(m: &Model, st: &State) -> Option<HeatDiagnostics> {
    if st.heat.is_empty() {
        return None;
    }
    let cell = m.dx.powi(m.dim as i32);
    let mut d = HeatDiagnostics {
        max_temperature: f64::NEG_INFINITY,
        total_enthalpy: 0.0,
        absorbed_laser_power: 0.0,
        incident_laser_power: 0.0,
        leaving_laser_power: 0.0,
        laser_absorbed_fraction: 0.0,
        bounce_limit_laser_power: 0.0,
        melted_volume: 0.0,
        pool_depth: 0.0,
        pool_width: 0.0,
        pool_length: 0.0,
        pool_volume: 0.0,
        detached_melt_regions: 0,
        detached_melt_particles: 0,
        detached_melt_mass: 0.0,
        evaporated_power: 0.0,
        radiated_power: 0.0,
    };
    if let Some(b) = LaserBalance::of(m, st) {
        d.incident_laser_power = b.incident;
        d.absorbed_laser_power = b.absorbed;
        d.leaving_laser_power = b.leaving;
        d.bounce_limit_laser_power = b.at_limit;
        d.laser_absorbed_fraction = b.fraction();
    }
    (d.evaporated_power, d.radiated_power) = surface_loss_power(m, st);
    for i in 0..st.active() {
        let ph = &m.phases[st.phase[i] as usize];
        if !ph.conducts() {
            continue;
        }
        let [_, t, fl, _] = st.heat[i];
        d.max_temperature = d.max_temperature.max(t as f64);
        d.total_enthalpy += st.mass[i] as f64 * ph.absolute_enthalpy(st.heat[i][0]);
        if ph.kind != PhaseKind::Gas {
            d.melted_volume += fl as f64 * cell;
        }
    }
    set_pool(&mut d, &PoolFigures::of(m, st, &melt_regions(m, st), None));
    Some(d)
}

/// Write a state's pool figures into its heat record.
pub fn set_pool(h: &mut HeatDiagnostics, f: &PoolFigures) {
    h.pool_depth = f.depth;
    h.pool_width = f.width;
    h.pool_length = f.length;
    h.pool_volume = f.volume;
    h.detached_melt_regions = f.detached_regions;
    h.detached_melt_particles = f.detached_particles;
    h.detached_melt_mass = f.detached_mass;
}
