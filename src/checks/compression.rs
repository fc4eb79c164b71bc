//! Liquid compression: the largest (ρ − ρ0)/ρ0 of any liquid particle over the
//! run's samples, with the mean for context (weakly compressible SPH should stay
//! within about 1%).

use super::{Check, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;

/// Liquid density relative to ρ0 over the samples of a run.
pub struct Compression {
    /// Largest (ρ − ρ0)/ρ0 seen, when, and which particle id.
    max: f64,
    t_max: f64,
    id_max: u32,
    /// Sum over samples of the mean (ρ − ρ0)/ρ0 of the liquid, the sample count and
    /// the last sample's time (`finish` observes the final state again).
    mean_sum: f64,
    samples: usize,
    last_t: f64,
}

impl Default for Compression {
    fn default() -> Self {
        Compression {
            max: f64::NEG_INFINITY,
            t_max: 0.0,
            id_max: 0,
            mean_sum: 0.0,
            samples: 0,
            last_t: f64::NEG_INFINITY,
        }
    }
}

impl Check for Compression {
    fn observe(&mut self, m: &Model, st: &State) {
        let t = st.sim.time as f64;
        if t <= self.last_t {
            return;
        }
        self.last_t = t;
        let (mut sum, mut n) = (0.0, 0usize);
        for i in 0..st.len() {
            let phase = &m.phases[st.phase[i] as usize];
            if phase.kind != PhaseKind::Liquid {
                continue;
            }
            let e = (st.rho[i] as f64 - phase.rho0) / phase.rho0;
            if e > self.max {
                (self.max, self.t_max, self.id_max) = (e, t, st.id[i]);
            }
            sum += e;
            n += 1;
        }
        if n > 0 {
            self.mean_sum += sum / n as f64;
            self.samples += 1;
        }
    }

    fn verdict(&mut self, _m: &Model, _st: &State) -> Verdict {
        if self.samples == 0 {
            return (
                "largest liquid compression".into(),
                f64::NAN,
                vec!["  no liquid".into()],
            )
                .into();
        }
        let details = vec![format!(
            "  largest at t = {:.4e} s (particle id {}); mean (ρ − ρ0)/ρ0 over the liquid, averaged over {} samples: {:+.3e}",
            self.t_max,
            self.id_max,
            self.samples,
            self.mean_sum / self.samples as f64
        )];
        (
            "largest liquid compression (ρ − ρ0)/ρ0".into(),
            self.max,
            details,
        )
            .into()
    }
}
