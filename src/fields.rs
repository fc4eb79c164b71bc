//! The per-particle field registry: one row per array of `State`, and everything
//! that handles fields generically reads it: GPU allocation, upload, readback and
//! the copies after the sort (backend::gpu), the sort itself (the CPU permutation in
//! backend::cpu::neighbors, the WGSL reorder body from `wgsl_reorder`), checkpoints
//! (checkpoint.rs), `compare` (State::fields), the MCAP/VTK frame channels
//! (output::particle_fields) and the memory estimate. The passes use the arrays by
//! name.
//!
//! Adding a field: its array in `State`, one row here, its WGSL binding in
//! shaders/lib/bindings.wgsl (and its scratch's when it is reordered) and in
//! `backend::gpu::BINDINGS`; tests/fields.rs checks that the rows, the bindings and
//! the WGSL agree.

use crate::output::{self, Values};
use crate::state::State;

/// Which scenes hold a field (elsewhere its array is empty and its GPU buffer a
/// 16-byte placeholder).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Holder {
    Every,
    /// Scenes with temperature.
    Heat,
    /// Scenes with interface normals.
    Interface,
    /// Scenes with rigid bodies.
    Bodies,
    /// Heat integrated by the trapezoidal rule (R18 Algorithm 3.1).
    ImplicitHeat,
    /// Scenes whose schedule holds a repeat (solver slots).
    Solvers,
    /// The δ-SPH formulation (continuity density: ρ is state, sorted).
    Continuity,
    /// The DFSPH formulation (the solvers' per-particle values).
    Dfsph,
    /// Scenes with a phase that melts (the solidification record).
    Solidification,
}

/// The scene's holders, from the pipeline's features.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Held {
    pub heat: bool,
    pub interface: bool,
    pub bodies: bool,
    pub implicit_heat: bool,
    pub solvers: bool,
    pub continuity: bool,
    pub solidification: bool,
    pub dfsph: bool,
}

impl Held {
    pub fn holds(&self, h: Holder) -> bool {
        match h {
            Holder::Every => true,
            Holder::Heat => self.heat,
            Holder::Interface => self.interface,
            Holder::Bodies => self.bodies,
            Holder::ImplicitHeat => self.implicit_heat,
            Holder::Solvers => self.solvers,
            Holder::Continuity => self.continuity,
            Holder::Dfsph => self.dfsph,
            Holder::Solidification => self.solidification,
        }
    }
    /// What a state holds (its optional arrays are empty when not held).
    pub fn of_state(st: &State) -> Held {
        Held {
            heat: !st.heat.is_empty(),
            interface: !st.surface.is_empty(),
            bodies: !st.body.is_empty(),
            implicit_heat: !st.heat_start.is_empty(),
            solvers: !st.solvers.is_empty(),
            continuity: !st.continuity.is_empty(),
            solidification: !st.solidification.is_empty(),
            dfsph: !st.dfsph.is_empty(),
        }
    }
    /// What a scene holds, from its model (the same as its schedule's features:
    /// `backend::Pipeline::held`, checked in tests/fields.rs).
    pub fn of_model(m: &crate::model::Model) -> Held {
        let implicit_heat =
            m.is_thermal() && m.heat.integrator == crate::scene::HeatIntegrator::Trapezoidal;
        let dfsph = m.formulation == crate::scene::Formulation::Dfsph;
        Held {
            heat: m.is_thermal(),
            interface: m.needs_interface(),
            bodies: m.has_bodies(),
            implicit_heat,
            solvers: implicit_heat || dfsph,
            continuity: m.formulation == crate::scene::Formulation::DeltaWcsph,
            solidification: m.melts(),
            dfsph,
        }
    }
}

pub struct FieldDef {
    /// Name in `compare` reports.
    pub name: &'static str,
    /// Its WGSL storage binding.
    pub binding: &'static str,
    /// The binding of its reorder scratch: the neighbour pass sorts it with the
    /// particles. None: recomputed after every sort (pressure, normals).
    pub scratch: Option<&'static str>,
    /// The scenes that sort it (`Every` where it is held, or e.g. `Continuity`:
    /// the density is state under δ-SPH and recomputed by summation otherwise).
    pub sorted_when: Holder,
    /// 32-bit words per entry (4 for a vec4).
    pub components: usize,
    /// Entries per particle (2 for `surface`: normal and δ, then the Shepard sum).
    pub per_particle: usize,
    pub is_float: bool,
    pub holder: Holder,
    /// In checkpoints (everything needed to continue bit-identically).
    pub checkpointed: bool,
    /// Compared field by field by `spatter compare` and the bit-match tests.
    pub compared: bool,
    /// The array as 32-bit words.
    pub words: fn(&State) -> &[u32],
    /// Replace the array from little-endian bytes (length checked by the caller).
    pub set: fn(&mut State, &[u8]),
    /// Reorder the array: entry k becomes old entry perm[k] (sorted fields).
    pub permute: fn(&mut State, &[usize]),
    /// The channels it writes to MCAP and VTK frames (None: not written).
    pub frames: Option<Channels>,
}

/// A field's output channels (crate::output).
pub type Channels = fn(&crate::model::Model, &State) -> Vec<crate::output::Field>;

impl FieldDef {
    /// Whether the neighbour pass carries it through the sort in a scene.
    pub fn sorted_in(&self, held: Held) -> bool {
        self.scratch.is_some() && held.holds(self.holder) && held.holds(self.sorted_when)
    }
    pub fn bytes_per_particle(&self) -> usize {
        4 * self.components * self.per_particle
    }
}

/// Declares one field row from its `State` array.
macro_rules! field {
    ($name:literal, $array:ident, $binding:literal, $scratch:expr, $components:literal,
     $per:literal, $float:literal, $holder:expr, $frames:expr) => {
        field!(
            $name,
            $array,
            $binding,
            $scratch,
            $components,
            $per,
            $float,
            $holder,
            $frames,
            Holder::Every
        )
    };
    ($name:literal, $array:ident, $binding:literal, $scratch:expr, $components:literal,
     $per:literal, $float:literal, $holder:expr, $frames:expr, $sorted:expr) => {
        FieldDef {
            name: $name,
            binding: $binding,
            scratch: $scratch,
            sorted_when: $sorted,
            components: $components,
            per_particle: $per,
            is_float: $float,
            holder: $holder,
            checkpointed: true,
            compared: true,
            words: |s| bytemuck::cast_slice(&s.$array),
            set: |s, b| s.$array = bytemuck::pod_collect_to_vec(b),
            permute: |s, perm| permute(&mut s.$array, perm),
            frames: $frames,
        }
    };
}

/// Every per-particle field, in checkpoint, `compare` and frame order. Columns:
/// name, State array, binding, scratch, words per entry, entries per particle,
/// float, holder, frame channels.
#[rustfmt::skip]
pub const FIELDS: [FieldDef; 20] = [
    field!("position", pos, "pos", Some("s_pos"), 4, 1, true, Holder::Every,
        Some(output::position_channels)),
    field!("velocity", vel, "vel", Some("s_vel"), 4, 1, true, Holder::Every,
        Some(output::velocity_channels)),
    field!("acceleration", acc, "acc", Some("s_acc"), 4, 1, true, Holder::Every, None),
    field!("transport_acceleration", acc_b, "acc_b", Some("s_acc_b"), 4, 1, true,
        Holder::Every, None),
    // Summation density (recomputed after the sort), or under δ-SPH the
    // continuity equation's state (sorted).
    field!("density", rho, "rho", Some("s_rho"), 1, 1, true, Holder::Every,
        Some(|_, s| output::channel("density", Values::F32(s.rho.clone()))),
        Holder::Continuity),
    field!("pressure", press, "press", None, 1, 1, true, Holder::Every,
        Some(|_, s| output::channel("pressure", Values::F32(s.press.clone())))),
    field!("mass", mass, "mass", Some("s_mass"), 1, 1, true, Holder::Every,
        Some(|_, s| output::channel("mass", Values::F32(s.mass.clone())))),
    field!("phase", phase, "phase", Some("s_phase"), 1, 1, false, Holder::Every,
        Some(|_, s| output::channel("phase", Values::U32(s.phase.clone())))),
    field!("id", id, "id", Some("s_id"), 1, 1, false, Holder::Every,
        Some(|_, s| output::channel("id", Values::U32(s.id.clone())))),
    field!("heat", heat, "heat", Some("s_heat"), 4, 1, true, Holder::Heat,
        Some(output::heat_channels)),
    field!("surface", surface, "surface", None, 4, 2, true, Holder::Interface, None),
    // Indexed by particle id, not sorted (no scratch: they never change).
    field!("body", body, "body", None, 1, 1, false, Holder::Bodies,
        Some(output::body_channels)),
    field!("body_offset", body_offset, "body_offset", None, 4, 1, true, Holder::Bodies,
        None),
    // δ-SPH: (dρ/dt, Shepard sum Γ), written by the continuity pass every step
    // after the sort.
    field!("continuity", continuity, "continuity", None, 2, 1, true, Holder::Continuity,
        None),
    // δ-SPH: the renormalised gradient of rho - rho0 (xyz) for the diffusion's
    // correction, written by the continuity pass every step after the sort.
    field!("density_gradient", density_gradient, "density_gradient", None, 4, 1, true,
        Holder::Continuity, None),
    // DFSPH: written by the factor pass every step after the sort.
    field!("dfsph", dfsph, "dfsph", None, 4, 1, true, Holder::Dfsph, None),
    // DFSPH: the warm starts (Δt² Σκ of the density solve, Δt Σκ of the
    // divergence solve), carried to the next step (sorted).
    field!("dfsph_warm", dfsph_warm, "dfsph_warm", Some("s_dfsph_warm"), 2, 1, true,
        Holder::Dfsph, None),
    // DFSPH: the implicit viscosity's CG vectors (residual, direction, A times
    // the direction, diag(A)), written from scratch every step after the sort.
    field!("dfsph_cg", dfsph_cg, "dfsph_cg", None, 4, 4, true, Holder::Dfsph, None),
    // Written by heat.begin every step after the sort (no scratch needed).
    field!("heat_start", heat_start, "heat_start", None, 4, 1, true, Holder::ImplicitHeat,
        None),
    // Indexed by particle id, not sorted: the last liquidus crossing on cooling
    // (time, G, cooling rate, count; position, pending), written by
    // heat.temperature when it happens.
    field!("solidification", solidification, "solidification", None, 4, 2, true,
        Holder::Solidification, Some(output::solidification_channels)),
];

/// The state's arrays that are not per particle: one row each, read the same way
/// as a field by checkpoints (which store each table's length in their header),
/// `compare`, the GPU upload and readback.
pub struct TableDef {
    /// Name in `compare` reports and checkpoint headers; also its WGSL binding.
    pub name: &'static str,
    /// 32-bit words per entry.
    pub components: usize,
    pub is_float: bool,
    /// Its WGSL element type (the buffer is `array<wgsl>`).
    pub wgsl: &'static str,
    pub holder: Holder,
    pub words: fn(&State) -> &[u32],
    pub set: fn(&mut State, &[u8]),
    /// Entries the GPU buffer holds at least (a binding must hold one element).
    pub min_entries: usize,
}

macro_rules! table {
    ($name:literal, $array:ident, $components:literal, $float:literal, $wgsl:literal,
     $holder:expr, $min:literal) => {
        TableDef {
            name: $name,
            components: $components,
            is_float: $float,
            wgsl: $wgsl,
            holder: $holder,
            words: |s| bytemuck::cast_slice(&s.$array),
            set: |s, b| s.$array = bytemuck::pod_collect_to_vec(b),
            min_entries: $min,
        }
    };
}

/// Every table, in checkpoint and `compare` order.
#[rustfmt::skip]
pub const TABLES: [TableDef; 4] = [
    // One row per rigid body (state::Body, 32 words); the wall pass declares the
    // table in every scene, so its buffer holds one entry at least.
    table!("bodies", bodies, 32, true, "Body", Holder::Bodies, 1),
    // Member particle ids, body after body.
    table!("members", members, 1, false, "u32", Holder::Bodies, 0),
    // One state::Solver per solver slot (state::SOLVER_SLOTS).
    table!("solvers", solvers, 8, false, "Solver", Holder::Solvers, 1),
    // Ray-traced laser scenes: this step's beam power split (state::RAYS_*),
    // integer atomics summed in any thread order.
    table!("ray_split", laser_rays, 1, false, "atomic<u32>", Holder::Heat, 0),
];

impl TableDef {
    pub fn entries(&self, st: &State) -> usize {
        (self.words)(st).len() / self.components
    }
}

/// out[k] = v[perm[k]], in parallel, into a scratch array that then trades
/// places with v. The scratch is the last permuted array of the same type, kept
/// for the next: a fresh allocation per field and step would be mapped anew by
/// the allocator and cleared page by page by the kernel (at 1e7 particles about
/// 700 MB a step, two thirds of the neighbour pass).
fn permute<T: Copy + Send + Sync + 'static>(v: &mut Vec<T>, perm: &[usize]) {
    use rayon::prelude::*;
    let mut out: Vec<T> = SCRATCH.with(|s| {
        let mut s = s.borrow_mut();
        s.remove(&std::any::TypeId::of::<T>())
            .and_then(|b| b.downcast::<Vec<T>>().ok())
            .map_or_else(Vec::new, |b| *b)
    });
    out.clear();
    out.reserve(perm.len());
    perm.par_iter().map(|&s| v[s]).collect_into_vec(&mut out);
    std::mem::swap(v, &mut out);
    SCRATCH.with(|s| {
        s.borrow_mut()
            .insert(std::any::TypeId::of::<T>(), Box::new(out));
    });
}

thread_local! {
    /// `permute`'s spare array, one per element type.
    static SCRATCH: std::cell::RefCell<
        std::collections::HashMap<std::any::TypeId, Box<dyn std::any::Any>>,
    > = std::cell::RefCell::new(std::collections::HashMap::new());
}

/// The WGSL reorder body (neighbors.wgsl `#reorder_sorted_fields(k, s)`): every
/// sorted field's scratch at k takes the field at s; a field only some scenes hold
/// is guarded by that scene flag.
pub fn wgsl_reorder(k: &str, s: &str, indent: &str) -> String {
    let flag = |h: Holder| match h {
        Holder::Heat => Some("FLAG_HEAT"),
        Holder::Bodies => Some("FLAG_BODIES"),
        Holder::Interface => Some("FLAG_INTERFACE"),
        Holder::Continuity => Some("FLAG_CONTINUITY"),
        Holder::Dfsph => Some("FLAG_DFSPH"),
        Holder::Every => None,
        other => panic!("no scene flag for sorted fields of {other:?}"),
    };
    let mut out = String::new();
    for f in FIELDS.iter() {
        let Some(scratch) = f.scratch else { continue };
        let copy = format!("{scratch}[{k}] = {}[{s}];", f.binding);
        let guards: Vec<&str> = [f.holder, f.sorted_when]
            .into_iter()
            .filter_map(flag)
            .collect();
        match guards.first() {
            None => out.push_str(&format!("{indent}{copy}\n")),
            Some(g) => out.push_str(&format!(
                "{indent}if ((P.sizes.flags & {g}) != 0u) {{\n{indent}    {copy}\n{indent}}}\n"
            )),
        }
    }
    out
}

/// Bytes per particle the fields of a scene take on the device, scratch included.
pub fn bytes_per_particle(held: Held) -> usize {
    FIELDS
        .iter()
        .filter(|f| held.holds(f.holder))
        .map(|f| f.bytes_per_particle() * if f.sorted_in(held) { 2 } else { 1 })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_read_and_write_their_own_array() {
        let mut st = State::default();
        for (k, f) in FIELDS.iter().enumerate() {
            let words: Vec<u32> = (0..(f.components * f.per_particle) as u32)
                .map(|w| 100 * k as u32 + w)
                .collect();
            (f.set)(&mut st, bytemuck::cast_slice(&words));
            assert_eq!((f.words)(&st), &words[..], "{}", f.name);
        }
        // Each row wrote a different array: none was overwritten by a later one.
        for (k, f) in FIELDS.iter().enumerate() {
            assert_eq!((f.words)(&st)[0], 100 * k as u32, "{}", f.name);
        }
    }

    #[test]
    fn names_and_bindings_are_unique() {
        let mut names: Vec<&str> = FIELDS.iter().flat_map(|f| [f.name, f.binding]).collect();
        names.extend(FIELDS.iter().filter_map(|f| f.scratch));
        names.extend(TABLES.iter().map(|t| t.name));
        for (k, a) in names.iter().enumerate() {
            // A field's name may equal its own binding; nothing else may repeat.
            let own = FIELDS.iter().any(|f| f.name == *a && f.binding == *a);
            let again = names[k + 1..].iter().filter(|b| *b == a).count();
            assert!(again <= own as usize, "{a} repeats");
        }
    }

    #[test]
    fn table_rows_read_and_write_their_own_array() {
        let mut st = State::default();
        for (k, t) in TABLES.iter().enumerate() {
            let words: Vec<u32> = (0..t.components as u32)
                .map(|w| 100 * k as u32 + w)
                .collect();
            (t.set)(&mut st, bytemuck::cast_slice(&words));
            assert_eq!((t.words)(&st), &words[..], "{}", t.name);
            assert_eq!(t.entries(&st), 1, "{}", t.name);
        }
    }
}
