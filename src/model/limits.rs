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
}

pub struct LimitDef {
    pub limit: Limit,
    pub name: &'static str,
    pub label: &'static str,
    /// The WGSL constant of its code.
    pub wgsl: &'static str,
}

/// Every limit, in code order.
pub const LIMITS: [LimitDef; 9] = [
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
