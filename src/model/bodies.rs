//! Rigid bodies (F22 §2.2, §3.4): which shapes are bodies, their initial motion,
//! and the `[contact]` spring–dashpot F22 (39)–(40) with its time-step limit.

use super::{Ctx, PhaseInfo};
use crate::error::InputError;
use crate::scene::{PhaseKind, SceneFile};

/// F22 (39)–(40): stiffness k_c (kg/s²) and damping d_c (kg/s); contact acts
/// within one particle spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    pub stiffness: f64,
    pub damping: f64,
}

/// One body as the scene declares it: where its particles come from (a shape,
/// or a grain of a rigid `[powder]` bed), its phase and its initial velocity and
/// angular velocity (world frame, rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySpec {
    pub source: BodySource,
    pub phase: usize,
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodySource {
    /// `shapes[i]` with `body = true`.
    Shape(usize),
    /// Grain g of the rigid powder bed.
    Grain(usize),
}

/// The body shapes and `[contact]`, validated. Bodies are made of a wall or solid
/// phase, need `[contact]`
/// (without it they would pass through the walls and each other) and a domain
/// without periodic axes (a body is not wrapped).
pub(super) fn bodies(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
    dim: u32,
    periodic: [bool; 3],
    powder: Option<&crate::powder::PowderBed>,
) -> Result<(Vec<BodySpec>, Option<Contact>), InputError> {
    let mut specs = Vec::new();
    for (i, s) in scene.shapes.iter().enumerate() {
        let key = |k: &str| format!("shapes[{i}].{k}");
        if !s.body {
            if s.angular_velocity.is_some() {
                return Err(cx.err(
                    &key("angular_velocity"),
                    "only a rigid body (body = true) rotates",
                ));
            }
            continue;
        }
        let Some(phase) = phases.iter().position(|p| p.name == s.phase) else {
            continue; // setup names the unknown phase
        };
        body_phase(cx, &key("body"), &phases[phase])?;
        let velocity = match &s.velocity {
            Some(v) => cx.vector(&key("velocity"), v, dim)?,
            None => [0.0; 3],
        };
        let angular_velocity = match &s.angular_velocity {
            Some(w) if dim == 2 => {
                let w2 = cx.vector(&key("angular_velocity"), w, 1)?;
                [0.0, 0.0, w2[0]]
            }
            Some(w) => cx.vector(&key("angular_velocity"), w, 3)?,
            None => [0.0; 3],
        };
        specs.push(BodySpec {
            source: BodySource::Shape(i),
            phase,
            velocity,
            angular_velocity,
        });
    }
    if let Some(bed) = powder.filter(|b| b.spec.rigid) {
        body_phase(cx, "powder.rigid", &phases[bed.spec.phase])?;
        for g in 0..bed.grains.len() {
            specs.push(BodySpec {
                source: BodySource::Grain(g),
                phase: bed.spec.phase,
                velocity: [0.0; 3],
                angular_velocity: [0.0; 3],
            });
        }
    }
    let contact = match &scene.contact {
        Some(c) => Some(Contact {
            stiffness: cx.positive("contact.stiffness", c.stiffness)?,
            damping: cx.non_negative("contact.damping", c.damping)?,
        }),
        None => None,
    };
    if !specs.is_empty() {
        if contact.is_none() {
            return Err(cx.err(
                "contact",
                "a scene with rigid bodies needs [contact] stiffness and damping (F22 (39)-(40); F22 uses 1.0 kg/s^2 and 1e-4 kg/s)",
            ));
        }
        if periodic.iter().any(|&p| p) {
            return Err(cx.err(
                "domain.periodic",
                "rigid bodies need a domain without periodic axes (bodies are not wrapped)",
            ));
        }
    }
    Ok((specs, contact))
}

/// A body's phase: a wall or solid (one that melts too: its melted particles
/// leave the body, `bodies.melt`) with no prescribed motion.
fn body_phase(cx: &Ctx, key: &str, ph: &PhaseInfo) -> Result<(), InputError> {
    let name = &ph.name;
    if !matches!(ph.kind, PhaseKind::Wall | PhaseKind::Solid) {
        return Err(cx.err(
            key,
            format!("a rigid body is made of a wall or solid phase; `{name}` flows"),
        ));
    }
    if ph.moves {
        return Err(cx.err(
            key,
            format!("phase `{name}` moves with a prescribed velocity; a body moves by its forces"),
        ));
    }
    Ok(())
}

/// F22 (42): 0.22 √(m/k_c) with the lightest particle of any body (∞ without
/// bodies).
pub(super) fn contact_limit(
    specs: &[BodySpec],
    phases: &[PhaseInfo],
    contact: Option<Contact>,
) -> f64 {
    let Some(c) = contact else {
        return f64::INFINITY;
    };
    specs
        .iter()
        .map(|b| 0.22 * (phases[b.phase].mass / c.stiffness).sqrt())
        .fold(f64::INFINITY, f64::min)
}
