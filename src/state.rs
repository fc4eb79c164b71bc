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
    /// Which limit bound the last step: its code in crate::model::limits::LIMITS.
    pub dt_limit: u32,
    pub umax2: f32,
    pub amax2: f32,
    /// Particles taken out of the simulation: the neighbour pass sorts
    /// them after every cell, so they are the last `removed` of the arrays, and
    /// every other pass stops at `n − removed`. Counted by that pass each step.
    pub removed: u32,
    /// The run's end time, written by the run loop (0: the run ends after a
    /// number of steps). The timestep pass shortens the last steps to land on
    /// it, so a run and its last frame end at the time asked for.
    pub end_time: f32,
}

/// The limits' short names in code order (crate::model::limits::LIMITS).
pub const DT_LIMIT_NAMES: [&str; 10] = crate::model::limits::LIMIT_NAMES;

impl Sim {
    /// The time at the end of the step being taken, t + Δt in f32, the
    /// departure time a particle that leaves in this step carries in pos.w
    /// (the WGSL twins write `sim.time + sim.dt`).
    pub fn step_end(&self) -> f32 {
        self.time + self.dt
    }
}

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
    /// Scenes with rigid bodies only (empty otherwise): the body a particle
    /// belongs to (`NO_BODY` for the rest) and its offset from the body's centre of
    /// mass in the body (principal) frame (xyz; w 0). Both indexed by particle
    /// id (`body[id[i]]`), not sorted: they never change, and unsorted they need
    /// no reorder scratch (lavapipe allows 32 storage buffers per pass).
    pub body: Vec<u32>,
    pub body_offset: Vec<[f32; 4]>,
    /// One entry per rigid body (crate::bodies), in body order.
    pub bodies: Vec<Body>,
    /// Particle ids of every body's members, body after body in ascending id
    /// (`Body::first`, `Body::count`): the fixed order of the per-body sums.
    pub members: Vec<u32>,
    /// δ-SPH only (empty otherwise): dρ/dt of the continuity equation and the
    /// Shepard sum Γ of the particle's support.
    pub continuity: Vec<[f32; 2]>,
    /// δ-SPH only: the renormalised gradient ⟨∇ρ̄⟩^L (xyz) of the excess density.
    pub density_gradient: Vec<[f32; 4]>,
    /// DFSPH only (empty otherwise): fluid (α, the solve's error, κ, Σκ of the
    /// density solve); wall (the Akinci volume V_b, 0, 0, 0).
    pub dfsph: Vec<[f32; 4]>,
    /// DFSPH only: the warm-start store (Δt² Σκ density, Δt Σκ divergence).
    pub dfsph_warm: Vec<[f32; 2]>,
    /// DFSPH implicit viscosity's conjugate gradients, 4 per particle:
    /// residual, direction, A times the direction, diag(A).
    pub dfsph_cg: Vec<[f32; 4]>,
    /// Trapezoidal (Crank–Nicolson) heat only (empty otherwise): h^n, the laser
    /// source of the step, the first iteration's rate ḣ_0 and the last
    /// iteration's |ḣ_k − ḣ_{k−1}|.
    pub heat_start: Vec<[f32; 4]>,
    /// Scenes whose schedule holds a repeat (empty otherwise): one entry per
    /// solver slot (SOLVER_SLOTS, below), this step's iterations,
    /// flag and residual.
    pub solvers: Vec<Solver>,
    /// Ray-traced laser scenes (empty otherwise): this step's beam power in
    /// fixed-point units (`Params::laser.power_unit` W each), [incident,
    /// absorbed, leaving the domain, absorbed at the bounce limit]; incident =
    /// absorbed + leaving exactly (`laser.wgsl`, `cpu/laser.rs`).
    pub laser_rays: Vec<u32>,
    /// Scenes with a phase that melts, and heat (empty otherwise), 2n entries
    /// indexed by particle id (`solidification[id]`, `solidification[n + id]`),
    /// not sorted: the record of the particle's last liquidus crossing on cooling.
    /// First (time of the crossing, |∇T| there (K/m; −1 until the
    /// gradient dispatch has computed it), cooling rate −dT/dt (K/s), crossings so
    /// far); then (position xyz at the crossing, 1 while the gradient is pending).
    pub solidification: Vec<[f32; 4]>,
    pub sim: Sim,
}

/// One solver's progress in the current step (WGSL twin `Solver` in
/// shaders/lib/params.wgsl): reset by its repeat's begin stage (all but
/// `capped`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable, Default)]
pub struct Solver {
    pub iterations: u32,
    /// 1 once the residual fell to the tolerance: the loop's kernels return at once.
    pub converged: u32,
    pub residual: f32,
    /// Steps whose repeat ended at its bound unconverged, since the run
    /// began (kept by the begin stage's reset; the run's warnings read it).
    pub capped: u32,
    /// A solver's own scalars across its iterations (the implicit viscosity's
    /// conjugate gradients: r·z, r0·r0, step length, direction update).
    pub scalars: [f32; 4],
}

impl Solver {
    /// The begin stage's reset: a fresh count, the capped steps kept.
    pub fn reset(&self) -> Solver {
        Solver {
            capped: self.capped,
            ..Solver::default()
        }
    }
    /// One iteration's end: the count, the residual and the converged flag;
    /// a step that ends at the bound unconverged counts as capped.
    pub fn finish(&mut self, residual: f32, converged: bool, max_iterations: u32) {
        self.iterations += 1;
        self.residual = residual;
        self.converged = converged as u32;
        if !converged && self.iterations >= max_iterations {
            self.capped += 1;
        }
    }
}

/// Slots of the packed per-particle vectors (WGSL twins in lib/params.wgsl):
/// `heat[i]` is (h, T, f_l, dh/dt).
pub const H_ENTHALPY: usize = 0;
pub const H_TEMPERATURE: usize = 1;
pub const H_LIQUID: usize = 2;
pub const H_RATE: usize = 3;
/// Slots of `State::laser_rays`.
pub const RAYS_INCIDENT: usize = 0;
pub const RAYS_ABSORBED: usize = 1;
pub const RAYS_LEAVING: usize = 2;
pub const RAYS_AT_LIMIT: usize = 3;
/// `surface[i]` is (outward normal xyz, surface delta δ); `surface[n + i]` is
/// (Shepard sum Γ, curvature κ, the free-surface form's raw κ, thin-layer flag: R18 §4.4).
pub const S_DELTA: usize = 3;
pub const S_SHEPARD: usize = 0;
pub const S_CURVATURE: usize = 1;
pub const S_RAW_CURVATURE: usize = 2;
/// Free-surface tension with `thin_layer_rows`: 1 on a thin layer's particle.
pub const S_THIN: usize = 3;
/// Γ from which a particle's support reads as full. In 2D (quintic, h = Δx) a
/// lattice's surface row reads 0.78, and 0.69–0.85 under 0.1Δx of disorder
/// (0.63–0.93 under 0.2Δx); the rows under it and the interior 0.91–1.05 under
/// 0.1Δx (0.84–1.19 under 0.2Δx) (Python check on lattice patches, 2026-12-06).
/// The row under a lattice surface has no normal (|g|h = 0.045, under the 0.1
/// threshold); under 0.1Δx of disorder 54% of the interior has one.
/// The free-surface form's tension skips particles with a full support and a
/// colour gradient |g| h below `INTERIOR_GRADIENT` (their normals are disorder's
/// noise: docs/physics.md, free-surface form, "Disorder"). WGSL twin in
/// lib/params.wgsl.
pub const INTERIOR_SHEPARD: f32 = 0.95;

/// `Body::bonded`: bonded into the substrate (WGSL twin in shaders/lib/params.wgsl).
pub const BODY_BONDED: u32 = 1;
/// `Body::bonded`: the body's centre left the keep box through an open side.
pub const BODY_LEFT: u32 = 2;
/// |g| h below which a full-support particle's gradient is disorder's noise: up
/// to 0.24 at 0.1Δx of disorder and about 0.5 at 0.2Δx; a planar lattice's
/// surface row reads 1.06 (quintic, h = Δx). The passes read it as a δ,
/// `Surfaces::interior_delta`.
pub const INTERIOR_GRADIENT: f32 = 0.5;
/// J22 (5)'s colour c_i (`model = "muller"`), in the raw curvature's slot: the two
/// free-surface forms never run in one scene.
pub const S_COLOUR: usize = 2;
/// `solidification[id]` is (time, G, cooling rate, crossings);
/// `solidification[n + id]` is (position xyz, gradient pending).
pub const SOL_TIME: usize = 0;
pub const SOL_GRADIENT: usize = 1;
pub const SOL_COOLING: usize = 2;
pub const SOL_COUNT: usize = 3;
pub const SOL_PENDING: usize = 3;

/// `State::body` of a particle that belongs to no body.
pub const NO_BODY: u32 = u32::MAX;

/// `State::body` of a particle that solidified in this step, from the
/// temperature pass until `bodies.melt` has bonded the bodies it touches (it is
/// `NO_BODY` again after that pass).
pub const BODY_SOLIDIFIED: u32 = u32::MAX - 1;

/// One rigid body (F22 §2.2, §3.4): its state and mass properties in f32, the
/// same bits on both backends (WGSL twin `Body` in shaders/lib/params.wgsl).
/// Vectors are world-frame unless said; positions are grid-relative.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable, Default)]
pub struct Body {
    /// Centre of mass (xyz), mass (w).
    pub x: [f32; 4],
    /// Orientation: the unit quaternion (x, y, z, w) taking body-frame vectors to
    /// world vectors.
    pub q: [f32; 4],
    /// Velocity of the centre of mass (w 0).
    pub v: [f32; 4],
    /// Angular momentum about the centre of mass (w 0).
    pub l: [f32; 4],
    /// Principal moments of inertia (xyz); w: the inertia per unit mass of one
    /// particle about its own centre (for recomputing them when members melt).
    pub inertia: [f32; 4],
    /// Σ f over the members at the last force evaluation (contact and fluid;
    /// gravity is added in the kicks), world frame.
    pub force: [f32; 4],
    /// Σ (x_r − x_k) × f_r, world frame.
    pub torque: [f32; 4],
    /// The body's members: `State::members[first..first + count]`.
    /// Members that left (melted) are dropped from the range, so `count` is the
    /// body's particles now.
    pub first: u32,
    pub count: u32,
    /// 0 while free; BODY_BONDED once bonded into the substrate by melt that
    /// solidified next to it: its members are fixed solid particles from then
    /// on (still listed, `count` of them) and no body pass moves it; BODY_LEFT
    /// once its centre has left the domain through an open side: its members
    /// are removed as leaving fluid is (still listed), and no pass moves it.
    pub bonded: u32,
    /// Members at the start: the range `first..first + initial_count` is the
    /// body's own in `State::members`.
    pub initial_count: u32,
}

impl Body {
    /// Still a free body: members remain, not bonded, not gone (the body passes
    /// skip the rest).
    pub fn moves(&self) -> bool {
        self.count > 0 && self.bonded == 0
    }
    /// Bonded into the substrate (`BODY_BONDED`).
    pub fn bonded_in(&self) -> bool {
        self.bonded == BODY_BONDED
    }
    /// Its centre left the domain through an open side (`BODY_LEFT`).
    pub fn left(&self) -> bool {
        self.bonded == BODY_LEFT
    }
    /// The fraction of its particles that melted away.
    pub fn molten_fraction(&self) -> f64 {
        1.0 - self.count as f64 / self.initial_count.max(1) as f64
    }
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
    /// The compared fields this state holds, in registry order (crate::fields),
    /// then its tables (crate::fields::TABLES) that are not empty.
    pub fn fields(&self) -> Vec<FieldView<'_>> {
        let held = crate::fields::Held::of_state(self);
        let mut out: Vec<FieldView<'_>> = crate::fields::FIELDS
            .iter()
            .filter(|f| f.compared && held.holds(f.holder))
            .map(|f| FieldView {
                name: f.name,
                components: f.components,
                words: (f.words)(self),
                is_float: f.is_float,
            })
            .collect();
        out.extend(
            crate::fields::TABLES
                .iter()
                .filter(|t| !(t.words)(self).is_empty())
                .map(|t| FieldView {
                    name: t.name,
                    components: t.components,
                    words: (t.words)(self),
                    is_float: t.is_float,
                }),
        );
        out
    }
}

/// Device bytes per particle beyond its fields (crate::fields::bytes_per_particle):
/// the sort keys, padded to a power of two (at most 2 × 8 bytes).
pub const BYTES_PER_PARTICLE_SORT: u64 = 16;
/// Bytes per grid cell: start and end tables.
pub const BYTES_PER_CELL: u64 = 8;

/// Solver slots: one `Solver` entry (iterations, converged flag, residual) per
/// repeat a scene's schedule can hold, in `State::solvers` and the `solvers`
/// buffer. The WGSL names the same slots (`SOLVER_*` in shaders/lib/params.wgsl).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverSlot {
    /// R18 Algorithm 3.1: the trapezoidal heat iteration.
    Heat = 0,
    /// DFSPH's constant-density solve.
    Density = 1,
    /// DFSPH's divergence-free solve.
    Divergence = 2,
    /// DFSPH's implicit viscosity (conjugate gradients).
    Viscosity = 3,
}

/// Solver slots in the `solvers` buffer (every scene with a repeat holds them all).
pub const SOLVER_SLOTS: [(SolverSlot, &str); 4] = [
    (SolverSlot::Heat, "heat"),
    (SolverSlot::Density, "dfsph_density"),
    (SolverSlot::Divergence, "dfsph_divergence"),
    (SolverSlot::Viscosity, "dfsph_viscosity"),
];
