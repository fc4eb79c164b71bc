//! Loading a scene: the scenario parsed (with `--set`), the model built and
//! validated, the initial particles generated; or a run continued from a
//! checkpoint. Everything that reads a scene goes through here (the run, the
//! benchmarks, the unit tests), so nothing needs the step loop to load one.

use crate::checkpoint;
use crate::error::InputError;
use crate::model::{self, Model};
use crate::scene;
use crate::setup;
use crate::state::State;

/// A scene ready to run: validated model and initial particles.
pub struct Loaded {
    pub model: Model,
    pub state: State,
}

pub fn load(path: &str, sets: &[String]) -> Result<Loaded, InputError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::new(path, "", format!("cannot read scenario: {e}")))?;
    load_str(path, &text, sets)
}

/// A scene from scenario text (named `label` in messages): the benchmarks' scenes
/// are compiled into the binary.
pub fn load_str(label: &str, text: &str, sets: &[String]) -> Result<Loaded, InputError> {
    let (scene, resolved) = scene::parse_str(label, text, sets)?;
    let mut model = model::build(label, &scene, &resolved)?;
    let state = setup::generate(&model, &scene)?;
    attach_grains(&mut model, &state);
    Ok(Loaded { model, state })
}

/// A powder scene's grain of each particle id, from the initial state.
fn attach_grains(model: &mut Model, initial: &State) {
    if model.powder.is_none() {
        return;
    }
    let particles: Vec<(u32, u32, [f64; 3])> = (0..initial.len())
        .map(|i| {
            (
                initial.id[i],
                initial.phase[i],
                model.to_world(initial.pos[i]),
            )
        })
        .collect();
    let dim = model.dim as usize;
    if let Some(b) = model.powder.as_mut() {
        b.attach(dim, initial.len(), particles);
    }
}

/// A run continued from a checkpoint: its stored scenario (with any `--set`
/// applied on top) and its state.
pub fn load_checkpoint(path: &str, sets: &[String]) -> Result<Loaded, InputError> {
    let ck = checkpoint::load(path)?;
    let label = format!("{path} (stored scenario {})", ck.header.scenario_file);
    let (scene, resolved) = scene::parse_str(&label, &ck.header.scenario, sets)?;
    let mut model = model::build(&label, &scene, &resolved)?;
    if model.powder.is_some() {
        // Grain membership comes from the initial lattice fill, which the
        // checkpoint no longer shows (melt moves): regenerate it.
        let initial = setup::generate(&model, &scene)?;
        attach_grains(&mut model, &initial);
    }
    model.file = ck.header.scenario_file.clone();
    if ck
        .state
        .phase
        .iter()
        .any(|&p| p as usize >= model.phases.len())
    {
        return Err(InputError::new(
            path,
            "",
            "checkpoint phases do not match its scenario",
        ));
    }
    let mut state = ck.state;
    if model.melts() && state.solidification.is_empty() {
        // A checkpoint written before the solidification record existed.
        state.solidification = setup::unrecorded_solidification(state.len());
    }
    Ok(Loaded { model, state })
}
