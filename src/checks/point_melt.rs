//! F22 §4.5's PBF point melting: a beam held still on a powder bed, then
//! switched off. F22 prints no number for it, only an order of events; the
//! check holds the run to four observables from that order, each measured
//! on the samples:
//! 1. **Peak temperature above T_v**: the hottest condensed particle at any
//!    sample against the melting material's boiling temperature
//!    (`evaporation.boiling_temperature`, F22's T_v).
//! 2. **A depression deeper than a quarter of its width while the beam is on**:
//!    per slice of width Δx along x (in 3D on the beam line, |y − y_beam| ≤ Δx)
//!    the top of the condensed column standing on the floor (crate::track's
//!    `column_top`, as the track's depression), against the initial surface:
//!    the mean over the slices of their tops at the first sample (a bed's tops
//!    are uneven, so no one slice's top is the level). Depth: that level less
//!    the top under the beam; width: the run of slices around the beam whose
//!    top lies below half that depth (the width at half depth: a depression's
//!    rim is as uneven as the bed). A sample counts when melt lies under the
//!    beam (a gap between grains is not a depression) and the beam is on; the
//!    largest depth/width counts.
//! 3. **At least one ejected grain**: a rigid grain whose centre is ever seen
//!    more than its diameter above the bed's top (crate::bodies' rule).
//! 4. **An indentation after solidification**: at the end no melt lies under
//!    the beam (its slice is frozen; the melt left elsewhere below the bed's
//!    top, against the most seen at a sample, is printed) and the surface under the
//!    beam lies more than ½Δx below the plate's initial top (F22 Fig. 20's
//!    "initial substrate surface", not the bed's top: consolidating powder
//!    sinks below that anyway).
//!
//! The verdict is the number of these that fail (tolerance 0).

use super::{Check, Series, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;
use crate::track::condensed;

pub struct PointMelt {
    layout: Option<Layout>,
    /// The hottest condensed particle and when.
    peak: (f64, f64),
    /// (time, depth, width) of the steepest depression while the beam is on.
    steepest: Option<(f64, f64, f64)>,
    /// Grains seen ejected, by grain index, and the highest a grain's centre
    /// rose above the bed's top (diameters) and when.
    ejected: Vec<bool>,
    highest_rise: (f64, f64),
    /// (time, depression depth, width, peak T now, grains ejected so far).
    series: Vec<[f64; 5]>,
    /// At the last sample: melt particles below the bed's top, surface under
    /// the beam.
    last_melt: usize,
    most_melt: usize,
    melt_under_beam: bool,
    last_top: f64,
}

/// Where things are, from the first sample.
struct Layout {
    x0: f64,
    slices: usize,
    beam_slice: usize,
    beam_y: f64,
    /// The mean and the highest of the slices' tops at the first sample.
    level: f64,
    highest: f64,
    plate_top: f64,
    boiling: f64,
    switch_off: f64,
}

impl PointMelt {
    pub fn new() -> PointMelt {
        PointMelt {
            layout: None,
            peak: (f64::NEG_INFINITY, f64::NAN),
            steepest: None,
            ejected: Vec::new(),
            highest_rise: (f64::NEG_INFINITY, f64::NAN),
            series: Vec::new(),
            last_melt: 0,
            most_melt: 0,
            melt_under_beam: false,
            last_top: f64::NAN,
        }
    }
}

/// The time the beam goes off for good: the last power step, when it is 0.
pub(super) fn switch_off_time(m: &Model) -> f64 {
    m.laser
        .as_ref()
        .and_then(|l| l.power.last().filter(|p| p.1 == 0.0).map(|p| p.0))
        .unwrap_or(f64::INFINITY)
}

/// The melting material's boiling temperature (F22's T_v).
pub(super) fn boiling_temperature(m: &Model) -> f64 {
    m.phases
        .iter()
        .filter_map(|p| p.thermal.and_then(|t| t.evaporation))
        .map(|e| e.boiling_temperature)
        .fold(f64::NAN, f64::min)
}

impl Layout {
    fn of(m: &Model, st: &State) -> Layout {
        let up = m.dim as usize - 1;
        let beam = m
            .laser
            .as_ref()
            .map_or([0.0; 2], |l| l.centre_at(st.sim.time as f64));
        let x0 = m.domain_lo[0];
        let slices = ((m.domain_hi[0] - x0) / m.dx).ceil().max(1.0) as usize;
        let beam_slice = (((beam[0] - x0) / m.dx).floor().max(0.0) as usize).min(slices - 1);
        let grain_of = |id: u32| {
            m.powder
                .as_ref()
                .and_then(|b| b.members.get(id as usize).copied())
                .unwrap_or(crate::powder::NO_GRAIN)
        };
        let plate_top = (0..st.active())
            .filter(|&i| {
                let ph = &m.phases[st.phase[i] as usize];
                ph.kind == PhaseKind::Solid
                    && ph.switch_to.is_some()
                    && grain_of(st.id[i]) == crate::powder::NO_GRAIN
            })
            .map(|i| m.to_world(st.pos[i])[up])
            .fold(f64::NEG_INFINITY, f64::max)
            + 0.5 * m.dx;
        let mut l = Layout {
            x0,
            slices,
            beam_slice,
            beam_y: beam[1],
            level: f64::NAN,
            highest: f64::NAN,
            plate_top,
            boiling: boiling_temperature(m),
            switch_off: switch_off_time(m),
        };
        let tops: Vec<f64> = l
            .surface(m, st)
            .into_iter()
            .filter(|z| z.is_finite())
            .collect();
        l.level = tops.iter().sum::<f64>() / tops.len().max(1) as f64;
        l.highest = tops.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        l
    }

    /// The top (+½Δx) of each slice's condensed column (NaN: empty).
    fn surface(&self, m: &Model, st: &State) -> Vec<f64> {
        let up = m.dim as usize - 1;
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); self.slices];
        for i in 0..st.active() {
            if !condensed(m, st, i) {
                continue;
            }
            let x = m.to_world(st.pos[i]);
            if m.dim == 3 && (x[1] - self.beam_y).abs() > m.dx {
                continue;
            }
            let k = ((x[0] - self.x0) / m.dx).floor();
            if k >= 0.0 && (k as usize) < self.slices {
                columns[k as usize].push(x[up]);
            }
        }
        columns
            .iter_mut()
            .map(|c| crate::track::column_top(c, m.dx).map_or(f64::NAN, |z| z + 0.5 * m.dx))
            .collect()
    }

    /// Depth under the beam and the width at half depth (m).
    fn depression(&self, surface: &[f64], dx: f64) -> (f64, f64) {
        let depth = self.level - surface[self.beam_slice];
        let below = |k: usize| surface[k] < self.level - 0.5 * depth;
        if depth.is_nan() || depth <= 0.5 * dx {
            return (depth.max(0.0), 0.0);
        }
        let lo = (0..=self.beam_slice)
            .rev()
            .take_while(|&k| below(k))
            .count();
        let hi = (self.beam_slice..self.slices)
            .take_while(|&k| below(k))
            .count();
        (depth, (lo + hi - 1) as f64 * dx)
    }
}

impl Check for PointMelt {
    fn observe(&mut self, m: &Model, st: &State) {
        let layout = self.layout.get_or_insert_with(|| Layout::of(m, st));
        let time = st.sim.time as f64;
        let hottest = (0..st.active())
            .filter(|&i| condensed(m, st, i))
            .map(|i| st.heat[i][1] as f64)
            .fold(f64::NEG_INFINITY, f64::max);
        if hottest > self.peak.0 {
            self.peak = (hottest, time);
        }
        let surface = layout.surface(m, st);
        let (depth, width) = layout.depression(&surface, m.dx);
        let melt_under_beam = (0..st.active()).any(|i| {
            crate::pool::is_melt(m, st, i) && {
                let x = m.to_world(st.pos[i]);
                ((x[0] - layout.x0) / m.dx).floor() == layout.beam_slice as f64
                    && (m.dim < 3 || (x[1] - layout.beam_y).abs() <= m.dx)
            }
        });
        if time <= layout.switch_off && width > 0.0 && melt_under_beam {
            let steeper = self.steepest.is_none_or(|(_, d, w)| depth / width > d / w);
            if steeper {
                self.steepest = Some((time, depth, width));
            }
        }
        if let Some(rise) = crate::bodies::grain_rise(m, st) {
            self.ejected.resize(rise.len(), false);
            for (seen, r) in self.ejected.iter_mut().zip(rise) {
                *seen |= r > 1.0;
                if r > self.highest_rise.0 {
                    self.highest_rise = (r, time);
                }
            }
        }
        let ejected = self.ejected.iter().filter(|&&e| e).count();
        self.series
            .push([time, depth, width, hottest, ejected as f64]);
        let up = m.dim as usize - 1;
        self.last_melt = (0..st.active())
            .filter(|&i| crate::pool::is_melt(m, st, i))
            .filter(|&i| m.to_world(st.pos[i])[up] < layout.highest)
            .count();
        self.most_melt = self.most_melt.max(self.last_melt);
        self.melt_under_beam = melt_under_beam;
        self.last_top = surface[layout.beam_slice];
    }

    fn series(&self) -> Option<Series> {
        Some(Series {
            columns: vec![
                "time",
                "depression_depth",
                "depression_width",
                "peak_temperature",
                "grains_ejected",
            ],
            rows: self.series.iter().map(|r| r.to_vec()).collect(),
        })
    }

    fn verdict(&mut self, m: &Model, _st: &State) -> Verdict {
        let Some(l) = self.layout.as_ref() else {
            return ("failed criteria".into(), f64::INFINITY, Vec::new()).into();
        };
        let mut details = vec![
            "  t (s), depression under the beam (m), its width (m), peak T now (K), grains ejected so far:"
                .to_string(),
        ];
        for s in &self.series {
            details.push(format!(
                "  {:.4e} {:.4e} {:.4e} {:.1} {}",
                s[0], s[1], s[2], s[3], s[4]
            ));
        }
        let mark = |ok: bool| if ok { "yes" } else { "NO" };
        let hot = self.peak.0 > l.boiling;
        details.push(format!(
            "  1. peak temperature {:.1} K at t = {:.4e} s against T_v = {:.1} K: {}",
            self.peak.0,
            self.peak.1,
            l.boiling,
            mark(hot)
        ));
        let (ratio, keyhole_line) = match self.steepest {
            Some((t, d, w)) => (
                d / w,
                format!(
                    "  2. steepest depression while the beam is on (to {:.4e} s): {d:.4e} m deep, \
                     {w:.4e} m wide at half depth, depth/width {:.3} at t = {t:.4e} s \
                     against 1/4",
                    l.switch_off,
                    d / w
                ),
            ),
            None => (
                0.0,
                "  2. no depression below the initial surface while the beam is on".to_string(),
            ),
        };
        let keyhole = ratio > 0.25;
        details.push(format!("{keyhole_line}: {}", mark(keyhole)));
        let ejected = self.ejected.iter().filter(|&&e| e).count();
        details.push(format!(
            "  3. grains ejected (centre more than a diameter above the bed's top at a sample): \
             {ejected} of {} (highest centre {:.2} diameters above it, t = {:.4e} s): {}",
            self.ejected.len(),
            self.highest_rise.0,
            self.highest_rise.1,
            mark(ejected >= 1)
        ));
        let indentation = l.plate_top - self.last_top;
        let indented = !self.melt_under_beam && indentation > 0.5 * m.dx;
        details.push(format!(
            "  4. at the end: {} under the beam, {} melt particles below the bed's top (most at \
             a sample: {}); surface under the beam {:.4e} m below the plate's initial top \
             ({:.4e} m): {}",
            if self.melt_under_beam {
                "melt"
            } else {
                "no melt"
            },
            self.last_melt,
            self.most_melt,
            indentation,
            l.plate_top,
            mark(indented)
        ));
        let failed = [hot, keyhole, ejected >= 1, indented]
            .iter()
            .filter(|&&ok| !ok)
            .count();
        Verdict {
            metric: "criteria of F22 §4.5 missed (of 4)".into(),
            value: failed as f64,
            details,
            figures: vec![
                ("peak_temperature".into(), self.peak.0),
                ("depression_aspect".into(), ratio),
                ("ejected_grains".into(), ejected as f64),
                ("highest_grain_rise".into(), self.highest_rise.0),
                ("indentation".into(), indentation),
                ("melt_at_end".into(), self.last_melt as f64),
            ],
        }
    }
}
