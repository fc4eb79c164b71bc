//! A laser track's melt pool against a measured one (`kind = "measured_track"`,
//! `[check.measured]`): NIST AM-Bench AMB2018-02's single tracks on IN625
//! (Lane et al. 2020) are the scenes that use it.
//!
//! - Width and depth: the fusion zone of the solidified cross-section, as the
//!   etched sections measure it: per slice of the track (crate::track), the
//!   extent along y of the melt ever seen + Δx, and the initial surface less the
//!   lowest melt ever seen − ½Δx; averaged over the slices whose centre lies in
//!   the steady part [x0, x1].
//! - Length: the largest connected region of melt's extent along x (the pool,
//!   crate::pool) at each sample with the beam centre in [x0, x1], averaged (the
//!   thermography measures the moving pool's length in the steady part).
//! - The verdict counts the figures outside their relative tolerance (width and
//!   depth 10%, length 20% by default); the scene's tolerance is 0.5, so one
//!   miss fails it. Each figure is printed beside the measurement.

use super::{Check, Series, Verdict};
use crate::model::Model;
use crate::scene::MeasuredTrackDef;
use crate::state::State;
use crate::track::Track;

pub struct MeasuredTrack {
    def: MeasuredTrackDef,
    track: Option<Track>,
    /// (time, beam centre x, pool length) per sample.
    samples: Vec<(f64, f64, f64)>,
}

impl MeasuredTrack {
    pub fn new(measured: &MeasuredTrackDef) -> MeasuredTrack {
        MeasuredTrack {
            def: measured.clone(),
            track: None,
            samples: Vec::new(),
        }
    }
}

impl Check for MeasuredTrack {
    fn observe(&mut self, m: &Model, st: &State) {
        match self.track.as_mut() {
            None => self.track = Track::new(m, st),
            Some(t) => t.observe(m, st),
        }
        let Some(t) = self.track.as_ref() else {
            return;
        };
        let time = st.sim.time as f64;
        let beam = m.laser.as_ref().map_or(f64::NAN, |l| l.centre_at(time)[0]);
        self.samples.push((time, beam, t.pool_now().length));
    }

    fn every_sample(&self) -> bool {
        true
    }

    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        let d = &self.def;
        let metric = "figures outside their tolerance (width, depth, length)".to_string();
        let Some(t) = self.track.as_ref() else {
            return (
                metric,
                f64::NAN,
                vec!["  no track: nothing to measure".into()],
            )
                .into();
        };
        let profile = t.finish(m, st);
        let (x0, x1) = (d.steady[0], d.steady[1]);
        let steady: Vec<_> = profile
            .slices
            .iter()
            .filter(|s| s.x >= x0 && s.x <= x1)
            .collect();
        let mean = |f: &dyn Fn(&crate::track::Slice) -> f64| {
            if steady.is_empty() {
                f64::NAN
            } else {
                steady.iter().map(|s| f(s)).sum::<f64>() / steady.len() as f64
            }
        };
        let width = mean(&|s| s.width);
        let depth = mean(&|s| s.depth);
        let lengths: Vec<f64> = self
            .samples
            .iter()
            .filter(|s| s.1 >= x0 && s.1 <= x1)
            .map(|s| s.2)
            .collect();
        let length = if lengths.is_empty() {
            f64::NAN
        } else {
            lengths.iter().sum::<f64>() / lengths.len() as f64
        };
        let wd = d
            .width_depth_tolerance
            .unwrap_or(MeasuredTrackDef::WIDTH_DEPTH_TOLERANCE);
        let lt = d
            .length_tolerance
            .unwrap_or(MeasuredTrackDef::LENGTH_TOLERANCE);
        let rows = [
            ("width", width, d.width, wd),
            ("depth", depth, d.depth, wd),
            ("length", length, d.length, lt),
        ];
        let mut misses = 0.0;
        let mut details = vec![format!(
            "  steady part x in [{x0:.3e}, {x1:.3e}] m: {} slices, {} samples of the pool (dx = {:.1e} m)",
            steady.len(),
            lengths.len(),
            m.dx
        )];
        let mut figures = Vec::new();
        for (name, sim, measured, tol) in rows {
            let err = (sim - measured) / measured;
            let within = err.abs() <= tol;
            if !within {
                misses += 1.0;
            }
            details.push(format!(
                "  {name}: {:.1} um against {:.1} um measured ({:+.1}%, tolerance {:.0}%: {})",
                sim * 1e6,
                measured * 1e6,
                100.0 * err,
                100.0 * tol,
                if within { "within" } else { "outside" }
            ));
            figures.push((name.to_string(), sim));
            figures.push((format!("{name}_error"), err));
        }
        Verdict {
            metric,
            value: misses,
            details,
            figures,
        }
    }

    fn series(&self) -> Option<Series> {
        Some(Series {
            columns: vec!["time", "beam_x", "pool_length"],
            rows: self.samples.iter().map(|s| vec![s.0, s.1, s.2]).collect(),
        })
    }
}
