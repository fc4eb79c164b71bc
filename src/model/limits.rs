//! The time-step limits, one table: F22 (42) and R18 (3.56)–(3.61). Each row is
//! a code (what the timestep pass writes to `Sim::dt_limit`, `DT_*` in
//! shaders/lib/params.wgsl), a short name (diagnostics, progress lines) and the
//! label `validate` prints with its formula. The host evaluates the limits that
//! are constants of the scene (model::DtLimits, into `Params::time_step`); the
//! timestep pass (shaders/timestep.wgsl, backend/cpu/timestep.rs) takes the
//! smallest with the ones that follow the flow (acoustic with |u|max, force with
//! |a|max), in the table's order.

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Limit {
    Acoustic = 0,
    Viscous = 1,
    Force = 2,
    Fixed = 3,
    Conduction = 4,
    Barrier = 5,
    Capillary = 6,
    Contact = 7,
    Maximum = 8,
    End = 9,
}

/// The end time counts as reached once less than this fraction of it remains:
/// time is f32 (an ulp is 6e-8 of it), so landing on the end can miss it by a
/// few ulps. Both twins of the timestep pass and the run loop use it.
pub const END_SLACK: f32 = 1e-6;

/// The run's last steps are shared out equally over the time left once it is
/// within this many steps of the end, so the approach shortens each by at most
/// an eighth (the step before it left more than 8 steps, so at least 7: 7/8 of
/// the limit or more while the limit holds still). One step of dt/2 would double
/// DFSPH's correction pressure: measured 3.9% against 0.51% of ρgH on the
/// column at rest.
pub const END_STEPS: f32 = 8.0;

/// A step may be this factor longer than the limits where that lands the run on
/// its end: f32 time drifts from Σ Δt by about 1e-4 of a step over a few
/// hundred steps, and without it an end that is a whole number of steps would
/// cost a step more, each shortened by a ninth.
pub const END_STRETCH: f32 = 1.001;

/// The next Δt where the run's end is near: the time left when it is within one
/// step; within END_STEPS steps of it (at dt × END_STRETCH), the time left
/// divided into the fewest equal steps, so the last lands on the end. None when
/// the run has no end time (0), the end is reached (within END_SLACK of it) or
/// is further. The timestep pass's rule (backend/cpu/timestep.rs and
/// shaders/timestep.wgsl, f32 as here, with the same positive tests so a NaN
/// takes the same branch); the run loop applies it to the step computed before
/// the end time was set. A Δt that nothing bounds (f32::MAX) takes the time left.
pub fn toward_end(end: f32, time: f32, dt: f32) -> Option<f32> {
    let left = end - time;
    if !(end > 0.0 && left > END_SLACK * end) {
        return None;
    }
    if left <= dt {
        return Some(left);
    }
    let reach = dt * END_STRETCH;
    if !(left <= END_STEPS * reach) {
        return None;
    }
    let steps = (left / reach).ceil();
    Some(left / steps)
}

pub struct LimitDef {
    pub limit: Limit,
    pub name: &'static str,
    pub label: &'static str,
    /// The WGSL constant of its code.
    pub wgsl: &'static str,
}

/// Every limit, in code order.
pub const LIMITS: [LimitDef; 10] = [
    LimitDef {
        limit: Limit::Acoustic,
        name: "acoustic",
        label: "acoustic CFL 0.25 h/(c+|u|)",
        wgsl: "DT_ACOUSTIC",
    },
    LimitDef {
        limit: Limit::Viscous,
        name: "viscous",
        label: "viscous 0.125 h^2/nu",
        wgsl: "DT_VISCOUS",
    },
    LimitDef {
        limit: Limit::Force,
        name: "force",
        label: "body force 0.25 sqrt(h/|b|)",
        wgsl: "DT_FORCE",
    },
    LimitDef {
        limit: Limit::Fixed,
        name: "fixed",
        label: "fixed run.dt",
        wgsl: "DT_FIXED",
    },
    LimitDef {
        limit: Limit::Conduction,
        name: "conduction",
        label: "conduction 0.1 rho c_p h^2/k",
        wgsl: "DT_CONDUCTION",
    },
    LimitDef {
        limit: Limit::Barrier,
        name: "barrier",
        label: "barrier 0.22 sqrt(m/k_b)",
        wgsl: "DT_BARRIER",
    },
    LimitDef {
        limit: Limit::Capillary,
        name: "capillary",
        label: "capillary 0.25 sqrt(rho h^3/(2 pi alpha))",
        wgsl: "DT_CAPILLARY",
    },
    LimitDef {
        limit: Limit::Contact,
        name: "contact",
        label: "contact 0.22 sqrt(m/k_c)",
        wgsl: "DT_CONTACT",
    },
    LimitDef {
        limit: Limit::Maximum,
        name: "maximum",
        label: "maximum run.max_dt",
        wgsl: "DT_MAXIMUM",
    },
    LimitDef {
        limit: Limit::End,
        name: "end",
        label: "the run's end time (the last steps land on it)",
        wgsl: "DT_END",
    },
];

impl Limit {
    pub fn def(self) -> &'static LimitDef {
        &LIMITS[self as usize]
    }
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// The short names in code order (the `/diagnostics` schema's enum).
pub const LIMIT_NAMES: [&str; LIMITS.len()] = {
    let mut names = [""; LIMITS.len()];
    let mut k = 0;
    while k < LIMITS.len() {
        names[k] = LIMITS[k].name;
        k += 1;
    }
    names
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The approach to the end: within 8 steps the time left is divided into
    /// equal steps that land on it (never shorter than 7/8 of a steady limit, at
    /// most 0.1% longer); reached within END_SLACK; no end time, no clamp; an
    /// unbounded Δt takes the time left.
    #[test]
    fn steps_land_on_the_end_in_equal_parts() {
        assert_eq!(toward_end(0.0, 1.0, 0.01), None);
        assert_eq!(toward_end(1.0, 0.5, 0.01), None);
        assert_eq!(toward_end(1.0, 1.0, 0.01), None);
        assert_eq!(toward_end(1.0, 1.0 - 0.5 * END_SLACK, 0.01), None);
        assert_eq!(toward_end(1.0, f32::NAN, 0.01), None);
        assert_eq!(toward_end(1.0, 0.5, f32::MAX), Some(0.5));
        // 7.5 steps left: 8 equal steps.
        let dt = toward_end(1.0, 1.0 - 0.075, 0.01).unwrap();
        assert!((dt - 0.075 / 8.0).abs() < 1e-8, "{dt}");
        // A whole number of steps, off by f32 drift: as many steps, stretched.
        let dt = toward_end(1.0, 1.0 - 0.0500002, 0.01).unwrap();
        assert!((dt / 0.01 - 1.0).abs() < 1e-3 && dt > 0.01, "{dt}");
        // Walking the approach from full steps: equal steps, none shorter than
        // 7/8 of the limit (0.9299: just over 8 steps left, then just over 7).
        for start in [0.9, 0.91234, 0.9299, 0.93, 0.95] {
            let mut t = start as f32;
            let mut n = 0;
            loop {
                let dt = match toward_end(1.0, t, 0.01) {
                    Some(dt) => {
                        assert!(
                            (0.01 * 7.0 / 8.0..=0.01 * END_STRETCH).contains(&dt),
                            "{dt}"
                        );
                        dt
                    }
                    None if 1.0 - t <= END_SLACK => break,
                    None => 0.01,
                };
                t += dt;
                n += 1;
                assert!(n < 20, "{start}: {n} steps");
            }
        }
    }

    #[test]
    fn rows_are_in_code_order_and_both_twins_name_every_device_limit() {
        for (k, d) in LIMITS.iter().enumerate() {
            assert_eq!(d.limit as usize, k, "{}", d.name);
        }
        let wgsl = include_str!("../../shaders/timestep.wgsl");
        let rust = include_str!("../backend/cpu/timestep.rs");
        for d in &LIMITS {
            assert!(wgsl.contains(d.wgsl), "timestep.wgsl never sets {}", d.wgsl);
            assert!(
                rust.contains(&format!("Limit::{:?}", d.limit)),
                "cpu/timestep.rs never sets {:?}",
                d.limit
            );
        }
    }
}
