//! The f32 parameter block both backends read (DESIGN rule 6): computed once on the
//! host in f64 and rounded to f32, so the CPU twin and the WGSL pass see the same bits.

use crate::model::{Model, MAX_LASER_POINTS, MAX_PHASES};
use crate::scene::{KernelKind, PhaseKind, Slip};
use bytemuck::{Pod, Zeroable};
use std::f64::consts::PI;

pub const FLAG_PERIODIC_X: u32 = 1;
pub const FLAG_PERIODIC_Y: u32 = 2;
pub const FLAG_PERIODIC_Z: u32 = 4;
pub const FLAG_PRESSURE_FLOOR: u32 = 8;
/// Forces pass writes the viscous dissipation (W/kg) into acc.w; heat adds it.
pub const FLAG_VISCOUS_HEATING: u32 = 16;

pub const KIND_LIQUID: f32 = 0.0;
pub const KIND_GAS: f32 = 1.0;
pub const KIND_WALL: f32 = 2.0;
pub const KIND_SOLID: f32 = 3.0;

/// `phase_d.w` flag bits (stored as an exact small integer in f32).
pub const HEAT_DIRICHLET: u32 = 1;
pub const HEAT_MELTS: u32 = 2;
pub const HEAT_LIQUID: u32 = 4;
/// Bits 8..11 of the flags: 1 + the phase this one switches to on melting or
/// solidifying (0: none).
pub const HEAT_SWITCH_SHIFT: u32 = 8;

/// `laser.w` model codes.
pub const LASER_BEER_LAMBERT: f32 = 1.0;
pub const LASER_SURFACE: f32 = 2.0;

/// Mirrors `struct Params` in shaders/lib/params.wgsl field for field.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct Params {
    /// n_particles, n_cells, dimension, kernel code (0 quintic, 1 Wendland C2, 2 cubic).
    pub counts: [u32; 4],
    /// cells along x, y, z; flags (periodic axes, pressure floor).
    pub grid: [u32; 4],
    /// 1 / cell size per axis.
    pub cell_inv: [f32; 4],
    /// Period length per axis (0 where not periodic).
    pub period: [f32; 4],
    /// Half the period per axis, for the minimum-image test.
    pub half_period: [f32; 4],
    /// h, 1/h, kernel normalisation σ, support radius squared.
    pub kernel: [f32; 4],
    /// Gravity xyz, background pressure p_b.
    pub gravity: [f32; 4],
    /// h, max sound speed, viscous limit 0.125 h²/ν (f32::MAX if inviscid), fixed Δt (0: adaptive).
    pub dt: [f32; 4],
    /// Per phase: ρ0, c², η, kind (0 liquid, 1 gas, 2 wall).
    pub phase_a: [[f32; 4]; MAX_PHASES],
    /// Per phase: wall velocity xyz, slip (0 no-slip, 1 free-slip).
    pub phase_b: [[f32; 4]; MAX_PHASES],
    /// Per phase (heat): solid conductivity k_s, solid heat capacity c_s, reference
    /// temperature T_ref (particles store h − h(T_ref), `Thermal::reference_temperature`),
    /// band enthalpy h(T_l) − h(T_s) for a melting material.
    pub phase_c: [[f32; 4]; MAX_PHASES],
    /// Per phase (heat): solidus T_s, liquidus T_l, b = c_s + L/(T_l − T_s), flags
    /// (HEAT_DIRICHLET, HEAT_MELTS, HEAT_LIQUID). A Dirichlet wall keeps its fixed
    /// temperature in the first slot.
    pub phase_d: [[f32; 4]; MAX_PHASES],
    /// Surface losses per phase: evaporation C_p (Pa), C_T (K), 1/T_v (1/K), h_v (J/kg)
    /// (all 0 without evaporation).
    pub phase_e: [[f32; 4]; MAX_PHASES],
    /// Surface losses per phase: T_h0 (K), C_M, 0.82 c_s, ε σ_B (radiation).
    pub phase_f: [[f32; 4]; MAX_PHASES],
    /// Per phase: mushy-zone sink C (1/s, liquids), liquid conductivity k_l, liquid
    /// heat capacity c_l, a = (c_l − c_s)/(2 (T_l − T_s)) (0 without melting).
    pub phase_g: [[f32; 4]; MAX_PHASES],
    /// Heat: conduction Δt limit 0.1 ρ c_p h²/k (f32::MAX without heat), η² = 0.01 h²
    /// (Cleary–Monaghan regularisation), 1 for a heat scene, 1 when the scene
    /// needs interface normals (interface pass).
    pub heat: [f32; 4],
    /// Laser: absorptivity ζ, beam radius r_w, absorption coefficient a, model
    /// (0 none, LASER_BEER_LAMBERT, LASER_SURFACE).
    pub laser: [f32; 4],
    /// Interface pass: 1/κ, the normalisation of the surface delta (κ = Σ δ V per
    /// unit area across a planar lattice surface, `surface_delta_integral` or
    /// `gas_delta_integral`); T_ambient⁴ for radiation; 1 in F22 gas mode (the
    /// scene has gas particles); F22 (32) interface viscosity α_0^lg (0 = off).
    pub interface: [f32; 4],
    /// Laser bins: size (= Δx), peak irradiance per watt (2/(π r_w²) in 3D,
    /// √(2/π)/r_w in 2D), bin volume Δx^d, column cross-section Δx^(d−1).
    pub laser_grid: [f32; 4],
    /// Bins per axis (1 beyond the dimension), path points + 256 × power steps.
    pub laser_bins: [u32; 4],
    /// Lower corner of the bin grid in grid-relative coordinates.
    pub laser_lo: [f32; 4],
    /// Scan path: time, lateral beam centre (grid-relative), unused.
    pub laser_path: [[f32; 4]; MAX_LASER_POINTS],
    /// Power schedule: time, power from then on, unused, unused.
    pub laser_power: [[f32; 4]; MAX_LASER_POINTS],
    /// Arithmetic literals for the shaders (`SHADER_CONSTS`). lavapipe's compiler
    /// reassociates a product with a literal constant (measured: `6.0 * (a * a)`
    /// differs from Rust in 10% of inputs, the same 6.0 from a buffer never), so
    /// shaders read every multiplying or adding literal from here.
    pub consts: [[f32; 4]; 8],
    /// Wall pass: Shepard weight floor ε (`WALL_WEIGHT_FLOOR` × W(0)); bit i set
    /// (as an exact integer) when wall phase i moves with its velocity; unused ×2.
    pub wall: [f32; 4],
}

/// The wall pass divides by Σ W + ε with ε this fraction of W(0) (src/backend/cpu/wall.rs).
pub const WALL_WEIGHT_FLOOR: f64 = 1e-9;

/// Mirrors the `c_*` and portable-math constants in shaders/lib/params.wgsl and
/// shaders/lib/math.wgsl; src/portable_math.rs uses the same f32 values.
pub const SHADER_CONSTS: [[f32; 4]; 8] = {
    use crate::portable_math as pm;
    [
        [0.5, 0.25, 2.0, 1.0],
        [3.0, 6.0, 15.0, 5.0],
        [30.0, 75.0, 1.5, 0.75],
        [2.25, pm::LOG2E, pm::LN2_HI, pm::LN2_LO],
        [pm::EXP_C[0], pm::EXP_C[1], pm::EXP_C[2], pm::EXP_C[3]],
        [pm::EXP_C[4], pm::EXP_C[5], pm::LN_C[0], pm::LN_C[1]],
        [pm::LN_C[2], pm::LN_C[3], pm::LN_C[4], 4.0],
        [0.1, 0.0, 0.0, 0.0],
    ]
};

/// Kernel normalisation σ so that ∫W = 1 (Morris 1997 quintic, Wendland C2, cubic spline).
pub fn kernel_sigma(kind: KernelKind, dim: u32, h: f64) -> f64 {
    let hd = h.powi(dim as i32);
    let s = match (kind, dim) {
        (KernelKind::Quintic, 2) => 7.0 / (478.0 * PI),
        // ∫(a−q)⁵q²dq = a⁸/168 ⇒ 4π/168·(3⁸ − 6·2⁸ + 15) = 120π.
        (KernelKind::Quintic, _) => 1.0 / (120.0 * PI),
        (KernelKind::WendlandC2, 2) => 7.0 / (4.0 * PI),
        (KernelKind::WendlandC2, _) => 21.0 / (16.0 * PI),
        (KernelKind::Cubic, 2) => 10.0 / (7.0 * PI),
        (KernelKind::Cubic, _) => 1.0 / PI,
    };
    s / hd
}

impl Params {
    pub fn new(m: &Model, n_particles: u32) -> Params {
        let mut flags = 0;
        let mut period = [0.0f32; 4];
        let mut half = [0.0f32; 4];
        for a in 0..3 {
            if m.periodic[a] {
                flags |= 1 << a;
                let len = m.domain_hi[a] - m.domain_lo[a];
                period[a] = len as f32;
                half[a] = (0.5 * len) as f32;
            }
        }
        if m.pressure_floor {
            flags |= FLAG_PRESSURE_FLOOR;
        }
        if m.viscous_heating && m.is_thermal() {
            flags |= FLAG_VISCOUS_HEATING;
        }
        let mut phase_a = [[0.0f32; 4]; MAX_PHASES];
        let mut phase_b = [[0.0f32; 4]; MAX_PHASES];
        for (i, ph) in m.phases.iter().enumerate() {
            let kind = match ph.kind {
                PhaseKind::Liquid => KIND_LIQUID,
                PhaseKind::Gas => KIND_GAS,
                PhaseKind::Wall => KIND_WALL,
                PhaseKind::Solid => KIND_SOLID,
            };
            let c2 = ph.sound_speed * ph.sound_speed;
            phase_a[i] = [ph.rho0 as f32, c2 as f32, ph.viscosity as f32, kind];
            let slip = if ph.slip == Slip::FreeSlip { 1.0 } else { 0.0 };
            phase_b[i] = [
                ph.velocity[0] as f32,
                ph.velocity[1] as f32,
                ph.velocity[2] as f32,
                slip,
            ];
        }
        let (phase_c, phase_d) = heat_tables(m);
        let (phase_e, phase_f) = loss_tables(m);
        let mut phase_g = [[0.0f32; 4]; MAX_PHASES];
        for (i, ph) in m.phases.iter().enumerate() {
            let Some(t) = ph.thermal else { continue };
            if ph.kind == PhaseKind::Liquid {
                phase_g[i][0] = t.mushy_damping as f32;
            }
            let (kl, cl) = t.liquid;
            let a = t.melting.map_or(0.0, |(ts, tl, _)| {
                (cl - t.heat_capacity) / (2.0 * (tl - ts))
            });
            phase_g[i][1] = kl as f32;
            phase_g[i][2] = cl as f32;
            phase_g[i][3] = a as f32;
        }
        let viscous = if m.limits.viscous.is_finite() {
            m.limits.viscous as f32
        } else {
            f32::MAX
        };
        let mut p = Params {
            counts: [n_particles, m.n_cells() as u32, m.dim, m.kernel.code()],
            grid: [m.grid[0], m.grid[1], m.grid[2], flags],
            cell_inv: [
                (1.0 / m.cell_size[0]) as f32,
                (1.0 / m.cell_size[1]) as f32,
                (1.0 / m.cell_size[2]) as f32,
                0.0,
            ],
            period,
            half_period: half,
            kernel: [
                m.h as f32,
                (1.0 / m.h) as f32,
                kernel_sigma(m.kernel, m.dim, m.h) as f32,
                (m.support * m.support) as f32,
            ],
            gravity: [
                m.gravity[0] as f32,
                m.gravity[1] as f32,
                m.gravity[2] as f32,
                m.background_pressure as f32,
            ],
            dt: [
                m.h as f32,
                m.max_sound_speed() as f32,
                viscous,
                m.fixed_dt.unwrap_or(0.0) as f32,
            ],
            phase_a,
            phase_b,
            phase_c,
            phase_d,
            phase_e,
            phase_f,
            phase_g,
            heat: [
                finite_or_max(m.limits.conduction),
                (0.01 * m.h * m.h) as f32,
                if m.is_thermal() { 1.0 } else { 0.0 },
                if m.needs_interface() { 1.0 } else { 0.0 },
            ],
            consts: SHADER_CONSTS,
            ..laser_block(m)
        };
        if m.needs_interface() {
            let gas = m.phases.iter().find(|ph| ph.kind == PhaseKind::Gas);
            // The condensed side of F22's interface: a conducting liquid or solid,
            // or (interface viscosity without heat) the liquid.
            let condensed = m.phases.iter().find(|ph| {
                matches!(ph.kind, PhaseKind::Liquid | PhaseKind::Solid)
                    && (ph.conducts() || m.interface_viscosity > 0.0)
            });
            let kappa = match (gas, condensed) {
                (Some(g), Some(c)) => {
                    p.interface[2] = 1.0;
                    gas_delta_integral(&p, m.dx, c.rho0, g.rho0)
                }
                _ => surface_delta_integral(&p, m.dx),
            };
            p.interface[0] = (1.0 / kappa) as f32;
            p.interface[1] = m.ambient_temperature.powi(4) as f32;
            p.interface[3] = m.interface_viscosity as f32;
        }
        p.wall[0] = (WALL_WEIGHT_FLOOR * crate::kernel::w(&p, 0.0) as f64) as f32;
        let moving: u32 = m
            .phases
            .iter()
            .enumerate()
            .filter(|(_, ph)| ph.moves)
            .map(|(i, _)| 1u32 << i)
            .sum();
        p.wall[1] = moving as f32;
        p
    }
    pub fn n(&self) -> usize {
        self.counts[0] as usize
    }
    /// A wall for the fluid passes: wall or solid particles (they do not move).
    pub fn is_wall(&self, phase: u32) -> bool {
        self.phase_a[phase as usize][3] >= KIND_WALL
    }
    /// A wall phase whose particles move with its velocity (`phase_b`).
    pub fn wall_moves(&self, phase: u32) -> bool {
        (self.wall[1] as u32 >> phase) & 1 != 0
    }
    /// Carries an evolving temperature (liquid, gas or solid in a heat scene).
    pub fn conducts(&self, phase: u32) -> bool {
        self.heat[2] != 0.0 && self.phase_a[phase as usize][3] != KIND_WALL
    }
    /// Particles F22's gas-interface pass gives a normal and δ: conducting ones (for
    /// the surface fluxes) and, with the interface viscosity on, every fluid one.
    pub fn gets_gas_interface(&self, phase: u32) -> bool {
        self.conducts(phase) || (self.interface[3] > 0.0 && !self.is_wall(phase))
    }
    pub fn heat_flags(&self, phase: u32) -> u32 {
        self.phase_d[phase as usize][3] as u32
    }
    /// The phase a particle of `phase` switches to on melting/solidifying.
    pub fn switch_target(&self, phase: u32) -> Option<u32> {
        let t = (self.heat_flags(phase) >> HEAT_SWITCH_SHIFT) & 15;
        (t > 0).then(|| t - 1)
    }
}

/// κ = ∫δ dn of the interface pass's surface delta across a planar surface of the
/// particle lattice (spacing Δx, half-space below the surface), per unit area.
/// The Shepard-corrected colour gradient (R18 (3.25)) overshoots the unit jump of
/// the colour by a few percent (quintic h = Δx: 1.059, Wendland C2 1.2Δx: 1.028,
/// cubic: 1.108, measured as absorbed laser power on a flat plate); dividing δ by
/// κ makes a surface flux ∫ s δ dV deposit exactly s per unit area on a flat
/// surface (F22 (17)).
pub fn surface_delta_integral(p: &Params, dx: f64) -> f64 {
    let dim = p.counts[2] as i64;
    let support = (p.kernel[3] as f64).sqrt();
    let reach = (support / dx).ceil() as i64 + 1;
    let depth = 3 * reach;
    let vol = dx.powi(dim as i32);
    let lateral: Vec<[i64; 2]> = (-reach..=reach)
        .flat_map(|a| (-reach..=reach).map(move |b| [a, b]))
        .filter(|l| dim == 3 || l[1] == 0)
        .collect();
    // Offsets from a particle in layer k to every lattice site within the support.
    let sites = |k: i64| {
        let lat = &lateral;
        (0..depth + reach).flat_map(move |kj| {
            lat.iter().filter_map(move |l| {
                let dz = (kj - k) as f64 * dx;
                let r2 = (l[0] * l[0] + l[1] * l[1]) as f64 * dx * dx + dz * dz;
                (r2 < support * support).then_some((kj, dz, r2.sqrt()))
            })
        })
    };
    let gamma: Vec<f64> = (0..depth + reach)
        .map(|k| {
            sites(k)
                .map(|(_, _, r)| vol * crate::kernel::w(p, r as f32) as f64)
                .sum()
        })
        .collect();
    (0..depth)
        .map(|k| {
            let g: f64 = sites(k)
                .filter(|s| s.2 > 0.0)
                .map(|(kj, dz, r)| {
                    vol * (1.0 / gamma[k as usize] + 1.0 / gamma[kj as usize])
                        * crate::kernel::dw(p, r as f32) as f64
                        / r
                        * -dz
                })
                .sum();
            // Layers below the normal threshold get no normal and absorb nothing.
            if g.abs() > 0.1 * p.kernel[1] as f64 {
                g.abs() * dx
            } else {
                0.0
            }
        })
        .sum()
}

/// κ_F22: the condensed side's ∫δ dn for the F22 (19) colour gradient across a
/// planar lattice interface between condensed material (density ρ_c, below) and
/// gas (ρ_g, above). The density weight ρ_i/(ρ_i + ρ_j) gives the condensed side
/// nearly all of the jump (F22 Remark 3) when ρ_c ≫ ρ_g.
pub fn gas_delta_integral(p: &Params, dx: f64, rho_c: f64, rho_g: f64) -> f64 {
    let dim = p.counts[2] as i64;
    let support = (p.kernel[3] as f64).sqrt();
    let reach = (support / dx).ceil() as i64 + 1;
    let vol_c = dx.powi(dim as i32);
    // Every lattice site holds volume Δx^d whatever its phase (m = ρ0 Δx^d).
    let vol_g = vol_c;
    let weight = rho_c / (rho_c + rho_g);
    (0..2 * reach)
        .map(|k| {
            // Condensed particle at depth (k + ½)Δx; gas sites at heights (kg + ½)Δx.
            let mut g = 0.0;
            for kg in 0..reach {
                let dz = (k + kg + 1) as f64 * dx; // vertical distance (condensed below)
                for a in -reach..=reach {
                    for b in -reach..=reach {
                        if dim == 2 && b != 0 {
                            continue;
                        }
                        let r2 = (a * a + b * b) as f64 * dx * dx + dz * dz;
                        if r2 >= support * support {
                            continue;
                        }
                        let r = r2.sqrt();
                        let f = (vol_c * vol_c + vol_g * vol_g)
                            * weight
                            * crate::kernel::dw(p, r as f32) as f64
                            / r;
                        g += f * -dz;
                    }
                }
            }
            let g = g / vol_c;
            if g.abs() > 0.1 * p.kernel[1] as f64 {
                g.abs() * dx
            } else {
                0.0
            }
        })
        .sum()
}

/// The laser part of the block; every other field zero (filled by `Params::new`).
fn laser_block(m: &Model) -> Params {
    let mut p = Params::zeroed();
    let Some(l) = &m.laser else { return p };
    let d = m.dim as i32;
    let dx = m.dx;
    let model = match l.model {
        crate::scene::LaserModel::BeerLambert => LASER_BEER_LAMBERT,
        crate::scene::LaserModel::GaussianSurface => LASER_SURFACE,
    };
    p.laser = [
        l.absorptivity as f32,
        l.radius as f32,
        l.absorption as f32,
        model,
    ];
    let peak = if m.dim == 3 {
        2.0 / (PI * l.radius * l.radius)
    } else {
        (2.0 / PI).sqrt() / l.radius
    };
    p.laser_grid = [
        dx as f32,
        peak as f32,
        dx.powi(d) as f32,
        dx.powi(d - 1) as f32,
    ];
    let mut bins = [1u32; 4];
    for a in 0..m.dim as usize {
        bins[a] = ((m.domain_hi[a] - m.domain_lo[a]) / dx - 1e-9)
            .ceil()
            .max(1.0) as u32;
    }
    bins[3] = l.path.len() as u32 + 256 * l.power.len() as u32;
    p.laser_bins = bins;
    let lo = m.to_local(m.domain_lo);
    p.laser_lo = [lo[0] as f32, lo[1] as f32, lo[2] as f32, 0.0];
    for (k, (t, x)) in l.path.iter().enumerate() {
        let mut abs = m.domain_lo;
        abs[0] = x[0];
        if m.dim == 3 {
            abs[1] = x[1];
        }
        let loc = m.to_local(abs);
        p.laser_path[k] = [
            *t as f32,
            loc[0] as f32,
            if m.dim == 3 { loc[1] as f32 } else { 0.0 },
            0.0,
        ];
    }
    for (k, (t, pw)) in l.power.iter().enumerate() {
        p.laser_power[k] = [*t as f32, *pw as f32, 0.0, 0.0];
    }
    p
}

fn finite_or_max(v: f64) -> f32 {
    if v.is_finite() {
        v as f32
    } else {
        f32::MAX
    }
}

/// Stefan–Boltzmann constant (W m⁻² K⁻⁴).
const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;

fn loss_tables(m: &Model) -> ([[f32; 4]; MAX_PHASES], [[f32; 4]; MAX_PHASES]) {
    let mut e = [[0.0f32; 4]; MAX_PHASES];
    let mut f = [[0.0f32; 4]; MAX_PHASES];
    for (i, ph) in m.phases.iter().enumerate() {
        let Some(t) = ph.thermal else { continue };
        if let Some(v) = t.evaporation {
            e[i] = [
                v.pressure_constant as f32,
                v.temperature_constant as f32,
                (1.0 / v.boiling_temperature) as f32,
                v.latent_heat as f32,
            ];
            f[i][0] = v.enthalpy_reference as f32;
            f[i][1] = v.vapor_constant as f32;
            f[i][2] = (0.82 * v.sticking) as f32;
        }
        f[i][3] = (t.emissivity * STEFAN_BOLTZMANN) as f32;
    }
    (e, f)
}

fn heat_tables(m: &Model) -> ([[f32; 4]; MAX_PHASES], [[f32; 4]; MAX_PHASES]) {
    let mut c = [[0.0f32; 4]; MAX_PHASES];
    let mut d = [[0.0f32; 4]; MAX_PHASES];
    for (i, ph) in m.phases.iter().enumerate() {
        let Some(t) = ph.thermal else { continue };
        let mut flags = 0;
        if ph.kind == PhaseKind::Wall {
            flags |= HEAT_DIRICHLET;
        }
        if ph.is_fluid() {
            flags |= HEAT_LIQUID;
        }
        let (ts, tl, l) = match (ph.kind, t.melting) {
            (PhaseKind::Wall, _) => (t.temperature, 0.0, 0.0),
            (_, Some(m)) => m,
            (_, None) => (0.0, 0.0, 0.0),
        };
        if t.melting.is_some() {
            flags |= HEAT_MELTS;
        }
        if let Some(target) = ph.switch_to {
            flags |= (target as u32 + 1) << HEAT_SWITCH_SHIFT;
        }
        let cp = t.heat_capacity;
        let (band, b) = match t.melting {
            Some(_) => (t.enthalpy(tl) - t.enthalpy(ts), cp + l / (tl - ts)),
            None => (0.0, 0.0),
        };
        c[i] = [
            t.conductivity as f32,
            cp as f32,
            t.reference_temperature() as f32,
            band as f32,
        ];
        d[i] = [ts as f32, tl as f32, b as f32, flags as f32];
    }
    (c, d)
}

#[cfg(test)]
mod tests {
    /// κ for the three kernels at their default h/Δx, as measured by the absorbed
    /// power on a flat plate without normalisation (1.0595, 1.0284, 1.1081).
    #[test]
    fn surface_delta_integral_matches_the_flat_plate_measurement() {
        let expected = [
            ("quintic", 1.0595),
            ("wendland_c2", 1.0284),
            ("cubic", 1.1081),
        ];
        for (k, kappa) in expected {
            let path = concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/scenarios/validation/laser_flat_plate.toml"
            );
            let sets = vec![
                format!("kernel=\"{k}\""),
                "laser.model=\"gaussian_surface\"".to_string(),
            ];
            let l = crate::run::load(path, &sets).unwrap();
            let p = super::Params::new(&l.model, l.state.len() as u32);
            let got = super::surface_delta_integral(&p, l.model.dx);
            assert!((got - kappa).abs() < 1e-4, "{k}: {got}");
        }
    }
}
