//! CPU reference vs GPU path, field by field after every pass (the bit-match
//! contract, docs/backends.md). On a software adapter any difference is a
//! failure; on hardware the two are compared by tolerance: the largest relative
//! difference per field after one free-running step, and per pass with each
//! pass started from the CPU's state, so that a pass's own difference is not
//! mixed with those of the passes before it.

use crate::backend::{Backend, DeviceLost, Node, Stage};
use crate::params::{Params, KIND_WALL};
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

/// Largest difference of one float field between two states, relative to the
/// field's largest magnitude in the reference (so near-zero entries do not blow up).
#[derive(Debug, Clone)]
pub struct FieldDifference {
    pub field: &'static str,
    pub relative: f64,
    pub particle: usize,
    pub component: usize,
    pub cpu: f32,
    pub gpu: f32,
}

/// Hardware mode, one pass: its largest field difference over the steps compared.
#[derive(Debug, Clone)]
pub struct PassDifference {
    pub step: u64,
    pub pass: &'static str,
    pub largest: FieldDifference,
    /// Particle id and phase index at the largest difference.
    pub id: u32,
    pub phase: u32,
}

/// Hardware tolerance per pass, relative to each field's scale (`ToleranceScales`).
/// One pass sums about 100 neighbour terms in f32 (ε = 6e-8), each at most about the
/// scale; fused multiply-adds and the driver's division and square root (Vulkan
/// allows 2.5–3 ULP) change each term by a few ULP, so a sum may move by up to
/// ~100 × 3 ε ≈ 2e-5 of the scale; 1e-3 leaves room for that and still flags a
/// neighbour-set or branch mismatch, where a whole term (O(1e-2) or more) differs.
pub const HARDWARE_PASS_TOLERANCE: f64 = 1e-3;

/// The magnitude each field's difference is measured against on hardware. For most
/// fields it is the field's largest magnitude. Pressure and accelerations are sums
/// of terms much larger than the result where they cancel (a fluid at rest, a gas
/// with a large background pressure): there the scale is that of one term, the
/// stiffness p0 = ρ0c² (or the background pressure p_b) and p/(ρ0 h) for the
/// accelerations. Against the field's largest value, a rounding of ρ by one ULP times
/// c² in the EOS already reads as 4e-3 in a gas at rest.
#[derive(Debug, Clone, Copy)]
pub struct ToleranceScales {
    pub pressure: f64,
    pub acceleration: f64,
}

impl ToleranceScales {
    pub fn new(p: &Params) -> ToleranceScales {
        let pb = p.flow.background_pressure.abs() as f64;
        let h = p.kernel.h as f64;
        let (mut pressure, mut acceleration) = (pb, 0.0f64);
        for ph in p.phases.iter().filter(|ph| ph.rho0 > 0.0) {
            let p0 = ph.rho0 as f64 * ph.c2 as f64;
            pressure = pressure.max(p0);
            if ph.kind < KIND_WALL {
                acceleration = acceleration.max(p0.max(pb) / (ph.rho0 as f64 * h));
            }
        }
        ToleranceScales {
            pressure,
            acceleration,
        }
    }

    fn for_field(&self, field: &str) -> Option<f64> {
        match field {
            "pressure" => Some(self.pressure),
            "acceleration" | "transport_acceleration" => Some(self.acceleration),
            _ => None,
        }
    }
}

/// How `compare` judges the two backends.
pub enum CompareMode {
    /// Software adapter: every word of every field after every pass.
    Exact,
    /// Hardware: by tolerance, against these scales.
    Tolerance(ToleranceScales),
}

pub struct CompareReport {
    pub first_difference: Option<Difference>,
    pub stages_compared: u64,
    /// Largest relative difference per field after one free-running step (hardware).
    pub max_rel: Vec<FieldDifference>,
    /// Per pass, each started from the CPU state (hardware), in pipeline order.
    pub per_pass: Vec<PassDifference>,
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

/// Largest difference per float field, relative to the field's scale: `scales` where
/// it names one, else the field's largest magnitude in `a` (the reference).
pub fn largest_differences(a: &State, b: &State, scales: &ToleranceScales) -> Vec<FieldDifference> {
    let mut out = field_differences(a, b, scales);
    // The time step the device computed (timestep pass) is state too.
    out.push(FieldDifference {
        field: "dt",
        relative: (a.sim.dt as f64 - b.sim.dt as f64).abs()
            / (a.sim.dt.abs() as f64).max(f64::MIN_POSITIVE),
        particle: 0,
        component: 0,
        cpu: a.sim.dt,
        gpu: b.sim.dt,
    });
    out
}

fn field_differences(a: &State, b: &State, scales: &ToleranceScales) -> Vec<FieldDifference> {
    a.fields()
        .iter()
        .zip(b.fields().iter())
        .filter(|(f, _)| f.is_float)
        .map(|(fa, fb)| {
            let value = |w: u32| f32::from_bits(w);
            let largest = fa
                .words
                .iter()
                .map(|&w| value(w).abs() as f64)
                .fold(0.0, f64::max);
            let scale = scales
                .for_field(fa.name)
                .map_or(largest, |s| s.max(largest))
                .max(f64::MIN_POSITIVE);
            let (k, d) = fa
                .words
                .iter()
                .zip(fb.words)
                .map(|(&x, &y)| {
                    let d = (value(x) as f64 - value(y) as f64).abs();
                    // A NaN on one side must fail, not read as "no difference".
                    if d.is_nan() && x != y {
                        f64::INFINITY
                    } else if x == y {
                        0.0
                    } else {
                        d
                    }
                })
                .enumerate()
                .fold(
                    (0, 0.0),
                    |best, (k, d)| if d > best.1 { (k, d) } else { best },
                );
            FieldDifference {
                field: fa.name,
                relative: d / scale,
                particle: k / fa.components,
                component: k % fa.components,
                cpu: fa.words.get(k).map_or(0.0, |&w| value(w)),
                gpu: fb.words.get(k).map_or(0.0, |&w| value(w)),
            }
        })
        .collect()
}

/// Hardware mode: run `steps` steps, loading the CPU state into the device before
/// every pass, and keep each pass's largest field difference.
fn compare_passes_isolated(
    cpu: &mut dyn Backend,
    gpu: &mut dyn Backend,
    steps: u64,
    scales: &ToleranceScales,
) -> Result<Vec<PassDifference>, DeviceLost> {
    let pipeline = cpu.pipeline().clone();
    let mut worst: Vec<PassDifference> = Vec::new();
    for step in 1..=steps {
        for stage in pipeline.recorded_step() {
            let before = cpu.read_state()?;
            gpu.load_state(&before);
            cpu.run_stage(stage);
            gpu.run_stage(stage);
            let (a, b) = (cpu.read_state()?, gpu.read_state()?);
            let Some(largest) = largest_differences(&a, &b, scales)
                .into_iter()
                .max_by(|x, y| x.relative.total_cmp(&y.relative))
            else {
                continue;
            };
            let found = PassDifference {
                step,
                pass: stage.name(),
                id: a.id[largest.particle],
                phase: a.phase[largest.particle],
                largest,
            };
            match worst.iter_mut().find(|w| w.pass == found.pass) {
                Some(w) if w.largest.relative < found.largest.relative => *w = found,
                Some(_) => {}
                None => worst.push(found),
            }
        }
    }
    Ok(worst)
}

/// Run both backends stage by stage for `steps` steps (after priming), comparing the
/// whole state after every stage. Stops at the first difference when `exact`.
pub fn compare(
    cpu: &mut dyn Backend,
    gpu: &mut dyn Backend,
    steps: u64,
    mode: &CompareMode,
) -> Result<CompareReport, DeviceLost> {
    let exact = matches!(mode, CompareMode::Exact);
    let mut report = CompareReport {
        first_difference: None,
        stages_compared: 0,
        max_rel: Vec::new(),
        per_pass: Vec::new(),
    };
    let check = |cpu: &mut dyn Backend,
                 gpu: &mut dyn Backend,
                 step: u64,
                 stage: Stage,
                 report: &mut CompareReport|
     -> Result<bool, DeviceLost> {
        cpu.run_stage(stage);
        gpu.run_stage(stage);
        let (a, b) = (cpu.read_state()?, gpu.read_state()?);
        report.stages_compared += 1;
        if !exact {
            return Ok(true);
        }
        if let Some(d) = first_difference(&a, &b, step, stage.name()) {
            report.first_difference = Some(d);
            return Ok(false);
        }
        Ok(true)
    };
    assert_eq!(
        cpu.pipeline(),
        gpu.pipeline(),
        "both backends run the same stages"
    );
    // A repeat's stages as often as the GPU records them (both backends' twins
    // return at once after the solver's flag is set).
    let pipeline = cpu.pipeline().clone();
    for s in pipeline.prime.iter().flat_map(Node::recorded) {
        if !check(cpu, gpu, 0, s, &mut report)? {
            return Ok(report);
        }
    }
    if let CompareMode::Tolerance(scales) = mode {
        // Hardware: one free-running step, then every pass on its own.
        cpu.run_steps(1);
        gpu.run_steps(1);
        report.max_rel = largest_differences(&cpu.read_state()?, &gpu.read_state()?, scales);
        report.per_pass = compare_passes_isolated(cpu, gpu, steps, scales)?;
        return Ok(report);
    }
    for step in 1..=steps {
        for s in pipeline.recorded_step() {
            if !check(cpu, gpu, step, s, &mut report)? {
                return Ok(report);
            }
        }
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_particle(rho: f32) -> State {
        State {
            pos: vec![[0.0; 4]],
            vel: vec![[0.0; 4]],
            acc: vec![[0.0; 4]],
            acc_b: vec![[0.0; 4]],
            rho: vec![rho],
            press: vec![0.0],
            mass: vec![1.0],
            phase: vec![0],
            id: vec![0],
            ..State::default()
        }
    }

    /// A NaN on the device side is an infinite difference, never "identical".
    #[test]
    fn nan_on_one_side_is_an_infinite_difference() {
        let scales = ToleranceScales {
            pressure: 1.0,
            acceleration: 1.0,
        };
        let d = largest_differences(&one_particle(1000.0), &one_particle(f32::NAN), &scales);
        let rho = d.iter().find(|f| f.field == "density").unwrap();
        assert_eq!(rho.relative, f64::INFINITY);
        let same = largest_differences(&one_particle(1000.0), &one_particle(1000.0), &scales);
        assert!(same.iter().all(|f| f.relative == 0.0));
    }
}
