//! Particle state, structure of arrays, in the exact layout both backends use.

use bytemuck::{Pod, Zeroable};

/// Per-step scalars that live on the device (DESIGN rule 7) and are read back only
/// at output intervals.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable, Default)]
pub struct Sim {
    pub dt: f32,
    pub time: f32,
    pub step: u32,
    /// Which F22 (42) limit bound the last step: see `DT_LIMIT_NAMES`.
    pub dt_limit: u32,
    pub umax2: f32,
    pub amax2: f32,
    /// Particles taken out of the simulation (issue 18): the neighbour pass sorts
    /// them after every cell, so they are the last `removed` of the arrays, and
    /// every other pass stops at `n − removed`. Counted by that pass each step.
    pub removed: u32,
    pub _pad: u32,
}

pub const DT_LIMIT_NAMES: [&str; 7] = [
    "acoustic",
    "viscous",
    "force",
    "fixed",
    "conduction",
    "barrier",
    "capillary",
];

/// Name of the limit code the timestep pass wrote.
pub fn dt_limit_name(code: u32) -> &'static str {
    DT_LIMIT_NAMES
        .get(code as usize)
        .copied()
        .unwrap_or("unknown")
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct State {
    /// Position relative to the grid origin (xyz); w is 0, or for a removed
    /// particle the time it left the domain.
    pub pos: Vec<[f32; 4]>,
    /// Velocity of fluids; for walls, the velocity the wall pass extrapolated.
    pub vel: Vec<[f32; 4]>,
    /// Acceleration from F22 (22)/(23) plus body force.
    pub acc: Vec<[f32; 4]>,
    /// Transport-velocity (background pressure) acceleration.
    pub acc_b: Vec<[f32; 4]>,
    pub rho: Vec<f32>,
    pub press: Vec<f32>,
    pub mass: Vec<f32>,
    pub phase: Vec<u32>,
    pub id: Vec<u32>,
    /// Heat scenes only (empty otherwise): specific enthalpy h (J/kg), temperature
    /// T (K), liquid fraction f_l, dh/dt of the last step (W/kg). A Dirichlet
    /// wall particle has no enthalpy: its .x is its fixed temperature.
    pub heat: Vec<[f32; 4]>,
    /// Scenes that need interfaces only (empty otherwise), 2n entries: first the
    /// outward unit normal and surface delta (n.xyz, δ) per particle, then the
    /// Shepard sum Γ (in .x) the interface pass computes on the way.
    pub surface: Vec<[f32; 4]>,
    pub sim: Sim,
}

/// A field viewed as raw 32-bit words, for bit-exact comparison.
pub struct FieldView<'a> {
    pub name: &'static str,
    pub components: usize,
    pub words: &'a [u32],
    pub is_float: bool,
}

impl State {
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
    /// Particles still in the simulation: indices 0..active(); the removed ones
    /// follow, frozen where they left, the time they left in `pos[i][3]`.
    pub fn active(&self) -> usize {
        self.len() - (self.sim.removed as usize).min(self.len())
    }
    /// The compared fields this state holds, in registry order (crate::fields).
    pub fn fields(&self) -> Vec<FieldView<'_>> {
        let held = crate::fields::Held::of_state(self);
        crate::fields::FIELDS
            .iter()
            .filter(|f| f.compared && held.holds(f.holder))
            .map(|f| FieldView {
                name: f.name,
                components: f.components,
                words: (f.words)(self),
                is_float: f.is_float,
            })
            .collect()
    }
}

/// Device bytes per particle beyond its fields (crate::fields::bytes_per_particle):
/// the sort keys, padded to a power of two (at most 2 × 8 bytes).
pub const BYTES_PER_PARTICLE_SORT: u64 = 16;
/// Bytes per grid cell: start and end tables.
pub const BYTES_PER_CELL: u64 = 8;
