//! The pair-term registry. A pair term is one physical interaction summed over a
//! particle's neighbours inside a pass's single neighbour sweep (the forces pass
//! today). Each lives twice under one name: `shaders/terms/<name>.wgsl` (a WGSL
//! function `<name>`) and `src/backend/cpu/terms/<name>.rs` (a Rust function
//! `<name>` with the same arguments and operations). The pass calls them in the
//! order of `PAIR_TERMS` (a test holds both sweeps to it). A term with a `switch`
//! is removed from a scene that does not use it: on the GPU its override constant
//! is set false when the pipeline is created, on the CPU the sweep is
//! monomorphised without it; neither tests a flag per pair.

use crate::params::{Params, FLAG_VISCOUS_HEATING};

pub struct PairTerm {
    pub name: &'static str,
    /// The pass whose sweep calls it (and whose WGSL gets its file appended).
    pub pass: &'static str,
    pub wgsl: &'static str,
    /// WGSL override constant that keeps it in the pipeline (None: always there).
    pub switch: Option<&'static str>,
    /// Whether a scene uses it.
    pub active: fn(&Params) -> bool,
}

pub const PAIR_TERMS: [PairTerm; 7] = [
    PairTerm {
        name: "pressure",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/pressure.wgsl"),
        switch: None,
        active: |_| true,
    },
    PairTerm {
        name: "viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/viscosity.wgsl"),
        switch: None,
        active: |_| true,
    },
    PairTerm {
        name: "background_pressure",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/background_pressure.wgsl"),
        switch: Some("TERM_BACKGROUND_PRESSURE"),
        active: |p| p.flow.background_pressure != 0.0,
    },
    PairTerm {
        name: "interface_viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/interface_viscosity.wgsl"),
        switch: Some("TERM_INTERFACE_VISCOSITY"),
        active: |p| p.flow.interface_viscosity > 0.0,
    },
    PairTerm {
        name: "solid_fluid_viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/solid_fluid_viscosity.wgsl"),
        switch: Some("TERM_SOLID_FLUID_VISCOSITY"),
        active: |p| p.flow.solid_fluid_viscosity > 0.0,
    },
    PairTerm {
        name: "viscous_heating",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/viscous_heating.wgsl"),
        switch: Some("TERM_VISCOUS_HEATING"),
        active: |p| p.flag(FLAG_VISCOUS_HEATING),
    },
    PairTerm {
        name: "barrier",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/barrier.wgsl"),
        switch: Some("TERM_BARRIER"),
        active: |p| p.flow.barrier_radius > 0.0,
    },
];

/// Whether the scene uses the term `name`.
pub fn active(params: &Params, name: &str) -> bool {
    let t = PAIR_TERMS
        .iter()
        .find(|t| t.name == name)
        .unwrap_or_else(|| panic!("no pair term {name}"));
    (t.active)(params)
}

/// Terms another pass evaluates from the other side of the pair: the rigid-body
/// pass sums the fluid's pressure, viscous and solid–fluid viscous force on each
/// body particle (F22 (38), the reaction f_ri = −m_i a_ir) with the forces
/// pass's own functions (`interface_viscosity` because `solid_fluid_viscosity`
/// is written with it).
pub const REACTION_TERMS: (&str, [&str; 4]) = (
    "bodies",
    [
        "pressure",
        "viscosity",
        "interface_viscosity",
        "solid_fluid_viscosity",
    ],
);

/// Whether `pass`'s WGSL carries term `t` (its own, or a reaction term).
fn carried(pass: &str, t: &PairTerm) -> bool {
    t.pass == pass || (pass == REACTION_TERMS.0 && REACTION_TERMS.1.contains(&t.name))
}

/// The pass's term sources, in registry order (appended to the pass's WGSL).
pub fn wgsl_for(pass: &str) -> impl Iterator<Item = &'static str> + '_ {
    PAIR_TERMS
        .iter()
        .filter(move |t| carried(pass, t))
        .map(|t| t.wgsl)
}

/// Override constants for the pipelines of `pass`: 1 keeps a term, 0 removes it.
pub fn switches(pass: &str, params: &Params) -> Vec<(&'static str, f64)> {
    PAIR_TERMS
        .iter()
        .filter(|t| carried(pass, t))
        .filter_map(|t| {
            t.switch
                .map(|s| (s, if (t.active)(params) { 1.0 } else { 0.0 }))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::PAIR_TERMS;

    /// Positions of each term's call in a sweep's source: they must increase in
    /// registry order. `call` gives the call text for a term name.
    fn assert_in_order(label: &str, src: &str, call: impl Fn(&str) -> String) {
        let mut last = 0;
        for t in &PAIR_TERMS {
            let c = call(t.name);
            let at = src
                .find(&c)
                .unwrap_or_else(|| panic!("{label}: no call `{c}`"));
            assert!(at > last, "{label}: `{c}` is out of the registry's order");
            last = at;
        }
    }

    #[test]
    fn both_sweeps_call_the_terms_in_registry_order() {
        let wgsl = include_str!("../../shaders/forces.wgsl");
        assert_in_order("forces.wgsl", wgsl, |n| format!(" {n}("));
        let rust = include_str!("cpu/forces.rs");
        assert_in_order("cpu/forces.rs", rust, |n| format!("terms::{n}("));
    }

    #[test]
    fn each_term_file_defines_its_function_and_switch() {
        for t in &PAIR_TERMS {
            assert!(t.wgsl.contains(&format!("fn {}(", t.name)), "{}", t.name);
            if let Some(s) = t.switch {
                assert!(t.wgsl.contains(&format!("override {s}: bool;")), "{s}");
            }
        }
    }
}
