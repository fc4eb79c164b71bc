//! The pair-term registry. A pair term is one physical interaction summed over a
//! particle's neighbours inside a pass's single neighbour sweep (the forces pass
//! today). Each lives twice under one name: `shaders/terms/<name>.wgsl` (a WGSL
//! function `<name>`) and `src/backend/cpu/terms/<name>.rs` (a Rust function
//! `<name>` with the same arguments and operations). The pass calls them in the
//! order of `PAIR_TERMS` (a test holds both sweeps to it). A term with a `switch`
//! is removed from a scene that does not use it: on the GPU its override constant
//! is set false when the pipeline is created, on the CPU the sweep is
//! monomorphised without it; neither tests a flag per pair.

use crate::params::{Params, FLAG_CONTINUITY, FLAG_MARRONE_VISCOSITY, FLAG_VISCOUS_HEATING};

/// The neighbours a term acts between a fluid particle and: other fluid
/// particles, wall (and fixed solid) particles, rigid-body particles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Acts {
    pub fluid: bool,
    pub wall: bool,
    pub body: bool,
}

const ALL: Acts = Acts {
    fluid: true,
    wall: true,
    body: true,
};
const FLUID: Acts = Acts {
    fluid: true,
    wall: false,
    body: false,
};
const SOLIDS: Acts = Acts {
    fluid: false,
    wall: true,
    body: true,
};

/// What a term's sum is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sum {
    /// A force on the fluid particle: a body neighbour takes its reaction (F22
    /// (38)), so the body pass evaluates it from the fluid's side.
    Force,
    /// The transport-velocity acceleration (no momentum is exchanged).
    Transport,
    /// Heat (W/kg), not momentum.
    Heating,
}

/// A pair term, by its place in `PAIR_TERMS` (a test holds the two in step):
/// code asks for a term by id, so a misspelt term does not compile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TermId {
    Pressure = 0,
    Viscosity = 1,
    ShepardPressure = 2,
    MarroneViscosity = 3,
    BackgroundPressure = 4,
    InterfaceViscosity = 5,
    SolidFluidViscosity = 6,
    ViscousHeating = 7,
    Barrier = 8,
}

pub struct PairTerm {
    pub id: TermId,
    pub name: &'static str,
    /// The pass whose sweep calls it (and whose WGSL gets its file appended).
    pub pass: &'static str,
    pub wgsl: &'static str,
    /// WGSL override constant that keeps it in the pipeline (None: always there).
    pub switch: Option<&'static str>,
    /// Whether a scene uses it.
    pub active: fn(&Params) -> bool,
    pub acts: Acts,
    pub sum: Sum,
    /// Terms whose WGSL functions this one's file calls (carried with it).
    pub needs: &'static [TermId],
}

pub const PAIR_TERMS: [PairTerm; 9] = [
    PairTerm {
        id: TermId::Pressure,
        name: "pressure",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/pressure.wgsl"),
        switch: None,
        active: |_| true,
        acts: ALL,
        sum: Sum::Force,
        needs: &[],
    },
    PairTerm {
        id: TermId::Viscosity,
        name: "viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/viscosity.wgsl"),
        switch: None,
        active: |_| true,
        acts: ALL,
        sum: Sum::Force,
        needs: &[],
    },
    PairTerm {
        id: TermId::ShepardPressure,
        name: "shepard_pressure",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/shepard_pressure.wgsl"),
        switch: Some("TERM_SHEPARD_PRESSURE"),
        active: |p| p.flag(FLAG_CONTINUITY),
        acts: ALL,
        sum: Sum::Force,
        needs: &[],
    },
    PairTerm {
        id: TermId::MarroneViscosity,
        name: "marrone_viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/marrone_viscosity.wgsl"),
        switch: Some("TERM_MARRONE_VISCOSITY"),
        active: |p| p.flag(FLAG_MARRONE_VISCOSITY),
        acts: ALL,
        sum: Sum::Force,
        needs: &[],
    },
    PairTerm {
        id: TermId::BackgroundPressure,
        name: "background_pressure",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/background_pressure.wgsl"),
        switch: Some("TERM_BACKGROUND_PRESSURE"),
        active: |p| p.flow.background_pressure != 0.0,
        acts: ALL,
        sum: Sum::Transport,
        needs: &[],
    },
    PairTerm {
        id: TermId::InterfaceViscosity,
        name: "interface_viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/interface_viscosity.wgsl"),
        switch: Some("TERM_INTERFACE_VISCOSITY"),
        active: |p| p.flow.interface_viscosity > 0.0,
        acts: FLUID,
        sum: Sum::Force,
        needs: &[],
    },
    PairTerm {
        id: TermId::SolidFluidViscosity,
        name: "solid_fluid_viscosity",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/solid_fluid_viscosity.wgsl"),
        switch: Some("TERM_SOLID_FLUID_VISCOSITY"),
        active: |p| p.flow.solid_fluid_viscosity > 0.0,
        acts: SOLIDS,
        sum: Sum::Force,
        needs: &[TermId::InterfaceViscosity],
    },
    PairTerm {
        id: TermId::ViscousHeating,
        name: "viscous_heating",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/viscous_heating.wgsl"),
        switch: Some("TERM_VISCOUS_HEATING"),
        active: |p| p.flag(FLAG_VISCOUS_HEATING),
        acts: ALL,
        sum: Sum::Heating,
        needs: &[],
    },
    PairTerm {
        id: TermId::Barrier,
        name: "barrier",
        pass: "forces",
        wgsl: include_str!("../../shaders/terms/barrier.wgsl"),
        switch: Some("TERM_BARRIER"),
        active: |p| p.flow.barrier_radius > 0.0,
        acts: SOLIDS,
        sum: Sum::Force,
        needs: &[],
    },
];

/// Whether the scene uses the term `id`.
pub fn active(params: &Params, id: TermId) -> bool {
    (PAIR_TERMS[id as usize].active)(params)
}

/// The pass that evaluates the fluid's reaction on body particles (F22 (38),
/// f_ri = −m_i a_ir) with the forces pass's own term functions.
pub const REACTION_PASS: &str = "bodies";

/// The terms whose reaction the bodies take: every force that acts on body
/// neighbours, in registry order.
pub fn reaction_terms() -> impl Iterator<Item = &'static PairTerm> {
    PAIR_TERMS
        .iter()
        .filter(|t| t.sum == Sum::Force && t.acts.body)
}

/// Whether `pass`'s WGSL carries term `t`: its own, a reaction term in the
/// bodies pass, or a term one of those needs.
/// Passes outside a term's sweep that call its WGSL functions (DFSPH's
/// implicit viscosity takes the viscous term's pair mean).
const BORROWED: [(&str, TermId); 1] = [("dfsph_viscosity", TermId::Viscosity)];

fn carried(pass: &str, t: &PairTerm) -> bool {
    let direct = |u: &PairTerm| {
        u.pass == pass
            || (pass == REACTION_PASS && reaction_terms().any(|r| r.id == u.id))
            || BORROWED.contains(&(pass, u.id))
    };
    direct(t)
        || PAIR_TERMS
            .iter()
            .any(|u| direct(u) && u.needs.contains(&t.id))
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

    /// The bodies pass calls every reaction term from the fluid's side, in
    /// registry order, on both backends (a missing one leaks momentum: the
    /// melting-grain check measured 16.5% for the solid–fluid viscosity).
    #[test]
    fn the_bodies_pass_calls_every_reaction_term() {
        let section = |src: &'static str, from: &str| -> &'static str {
            let at = src.find(from).unwrap_or_else(|| panic!("no {from}"));
            &src[at..]
        };
        let wgsl = section(include_str!("../../shaders/bodies.wgsl"), "fn body_forces(");
        let rust = section(include_str!("cpu/bodies.rs"), "pub fn forces(");
        let mut last = (0, 0);
        for t in super::reaction_terms() {
            let w = wgsl
                .find(&format!(" {}(", t.name))
                .unwrap_or_else(|| panic!("bodies.wgsl: {}", t.name));
            let r = rust
                .find(&format!("terms::{}(", t.name))
                .unwrap_or_else(|| panic!("cpu/bodies.rs: {}", t.name));
            assert!(w > last.0 && r > last.1, "{} out of order", t.name);
            last = (w, r);
        }
    }

    /// Each row sits at its id's place, so `active` reads the right row.
    #[test]
    fn each_term_sits_at_its_id() {
        for (k, t) in PAIR_TERMS.iter().enumerate() {
            assert_eq!(t.id as usize, k, "{}", t.name);
        }
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
