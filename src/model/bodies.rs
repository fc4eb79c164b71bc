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

/// One body as the scene declares it: the shape its particles come from and its
/// initial velocity and angular velocity (world frame, rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySpec {
    pub shape: usize,
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
}

/// The body shapes and `[contact]`, validated. Bodies are made of a wall or solid
/// phase that does not melt (melting bodies are not built yet), need `[contact]`
/// (without it they would pass through the walls and each other) and a domain
/// without periodic axes (a body is not wrapped).
pub(super) fn bodies(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
    dim: u32,
    periodic: [bool; 3],
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
        let Some(ph) = phases.iter().find(|p| p.name == s.phase) else {
            continue; // setup names the unknown phase
        };
        if !matches!(ph.kind, PhaseKind::Wall | PhaseKind::Solid) {
            return Err(cx.err(
                &key("body"),
                format!(
                    "a rigid body is made of a wall or solid phase; `{}` flows",
                    s.phase
                ),
            ));
        }
        if ph.switch_to.is_some() {
            return Err(cx.err(
                &key("body"),
                format!(
                    "phase `{}` melts: melting rigid bodies are not supported yet",
                    s.phase
                ),
            ));
        }
        if ph.moves {
            return Err(cx.err(
                &key("body"),
                format!(
                    "phase `{}` moves with a prescribed velocity; a body moves by its forces",
                    s.phase
                ),
            ));
        }
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
            shape: i,
            velocity,
            angular_velocity,
        });
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

/// F22 (42): 0.22 √(m/k_c) with the lightest particle of any body (∞ without
/// bodies).
pub(super) fn contact_limit(
    scene: &SceneFile,
    specs: &[BodySpec],
    phases: &[PhaseInfo],
    contact: Option<Contact>,
) -> f64 {
    let Some(c) = contact else {
        return f64::INFINITY;
    };
    specs
        .iter()
        .filter_map(|b| {
            phases
                .iter()
                .find(|p| p.name == scene.shapes[b.shape].phase)
        })
        .map(|p| 0.22 * (p.mass / c.stiffness).sqrt())
        .fold(f64::INFINITY, f64::min)
}
