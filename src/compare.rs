//! CPU reference vs GPU path, field by field after every pass (DESIGN.md bit-match
//! contract). On a software adapter any difference is a failure; on hardware the
//! largest relative difference per field after one step is reported instead.

use crate::backend::{Backend, Stage};
use crate::state::State;

#[derive(Debug, Clone)]
pub struct Difference {
    pub step: u64,
    pub pass: &'static str,
    pub field: &'static str,
    pub particle: usize,
    pub component: usize,
    pub cpu: String,
    pub gpu: String,
}

pub struct CompareReport {
    pub first_difference: Option<Difference>,
    pub stages_compared: u64,
    /// Largest relative difference per field (hardware mode).
    pub max_rel: Vec<(&'static str, f64)>,
}

impl CompareReport {
    pub fn identical(&self) -> bool {
        self.first_difference.is_none()
    }
}

fn show(word: u32, is_float: bool) -> String {
    if is_float {
        format!("{:e} (0x{word:08x})", f32::from_bits(word))
    } else {
        word.to_string()
    }
}

/// First field word that differs between the two states, if any.
pub fn first_difference(a: &State, b: &State, step: u64, pass: &'static str) -> Option<Difference> {
    for (fa, fb) in a.fields().iter().zip(b.fields().iter()) {
        if let Some(k) = fa.words.iter().zip(fb.words).position(|(x, y)| x != y) {
            return Some(Difference {
                step,
                pass,
                field: fa.name,
                particle: k / fa.components,
                component: k % fa.components,
                cpu: show(fa.words[k], fa.is_float),
                gpu: show(fb.words[k], fb.is_float),
            });
        }
    }
    let (sa, sb) = (bytemuck::bytes_of(&a.sim), bytemuck::bytes_of(&b.sim));
    if sa != sb {
        return Some(Difference {
            step,
            pass,
            field: "sim (dt, time, step)",
            particle: 0,
            component: 0,
            cpu: format!("dt {:e} t {:e} step {}", a.sim.dt, a.sim.time, a.sim.step),
            gpu: format!("dt {:e} t {:e} step {}", b.sim.dt, b.sim.time, b.sim.step),
        });
    }
    None
}

fn max_relative(a: &State, b: &State) -> Vec<(&'static str, f64)> {
    a.fields()
        .iter()
        .zip(b.fields().iter())
        .filter(|(f, _)| f.is_float)
        .map(|(fa, fb)| {
            let scale = fa
                .words
                .iter()
                .map(|&w| f32::from_bits(w).abs() as f64)
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            let d = fa
                .words
                .iter()
                .zip(fb.words)
                .map(|(&x, &y)| (f32::from_bits(x) as f64 - f32::from_bits(y) as f64).abs())
                .fold(0.0, f64::max);
            (fa.name, d / scale)
        })
        .collect()
}

/// Run both backends stage by stage for `steps` steps (after priming), comparing the
/// whole state after every stage. Stops at the first difference when `exact`.
pub fn compare(
    cpu: &mut dyn Backend,
    gpu: &mut dyn Backend,
    steps: u64,
    exact: bool,
) -> CompareReport {
    let mut report = CompareReport {
        first_difference: None,
        stages_compared: 0,
        max_rel: Vec::new(),
    };
    let check = |cpu: &mut dyn Backend,
                 gpu: &mut dyn Backend,
                 step: u64,
                 stage: Stage,
                 report: &mut CompareReport|
     -> bool {
        cpu.run_stage(stage);
        gpu.run_stage(stage);
        let (a, b) = (cpu.read_state(), gpu.read_state());
        report.stages_compared += 1;
        if !exact {
            return true;
        }
        if let Some(d) = first_difference(&a, &b, step, stage.name()) {
            report.first_difference = Some(d);
            return false;
        }
        true
    };
    assert_eq!(
        cpu.pipeline(),
        gpu.pipeline(),
        "both backends run the same stages"
    );
    let pipeline = cpu.pipeline().clone();
    for &s in &pipeline.prime {
        if !check(cpu, gpu, 0, s, &mut report) {
            return report;
        }
    }
    if !exact {
        // Hardware: one step, then tolerances per field.
        cpu.run_steps(1);
        gpu.run_steps(1);
        report.max_rel = max_relative(&cpu.read_state(), &gpu.read_state());
        return report;
    }
    for step in 1..=steps {
        for &s in &pipeline.step {
            if !check(cpu, gpu, step, s, &mut report) {
                return report;
            }
        }
    }
    report
}
