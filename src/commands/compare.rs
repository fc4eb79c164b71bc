//! `spatter compare`: the CPU against the GPU after every pass.

use spatter::backend::cpu::CpuBackend;
use spatter::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use spatter::compare;
use spatter::error::SpatterError;
use spatter::params::Params;
use spatter::run;
use std::process::ExitCode;

/// Hardware adapter: differences by tolerance (docs/backends.md), per field after one
/// free-running step and per pass with each pass started from the CPU state.
pub(crate) fn print_hardware_comparison(
    report: &compare::CompareReport,
    model: &spatter::model::Model,
    steps: u64,
) -> ExitCode {
    let rel = |d: &compare::FieldDifference| {
        if d.relative == 0.0 {
            return "0 (identical)".to_string();
        }
        format!(
            "{:.3e} (particle {} component {}: cpu {:e}, gpu {:e})",
            d.relative, d.particle, d.component, d.cpu, d.gpu
        )
    };
    println!("compared by tolerance, each difference relative to the field's scale (its largest magnitude; p0 for pressure, p0/(rho0 h) for accelerations)");
    println!("after one free-running step, per field:");
    for d in &report.max_rel {
        println!("  {}: {}", d.field, rel(d));
    }
    let tol = compare::HARDWARE_PASS_TOLERANCE;
    println!("per pass, each started from the CPU state, largest over {steps} steps:");
    for p in &report.per_pass {
        let phase = model
            .phases
            .get(p.phase as usize)
            .map_or("?", |ph| ph.name.as_str());
        if p.largest.relative == 0.0 {
            println!("  {}: 0 (identical)", p.pass);
            continue;
        }
        println!(
            "  {}: {} {} at step {}, id {}, phase {}",
            p.pass,
            p.largest.field,
            rel(&p.largest),
            p.step,
            p.id,
            phase
        );
    }
    let worst = report
        .per_pass
        .iter()
        .map(|p| p.largest.relative)
        .fold(0.0, f64::max);
    let exact = report.max_rel.iter().all(|d| d.relative == 0.0) && worst == 0.0;
    println!("bit-identical: {}", if exact { "yes" } else { "no" });
    let pass = worst <= tol;
    println!(
        "within hardware tolerance ({tol:e} per pass): {} (largest {worst:.3e})",
        if pass { "yes" } else { "no" }
    );
    if pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

pub(crate) fn cmd_compare(
    path: &str,
    steps: u64,
    sets: &[String],
    by_tolerance: bool,
) -> Result<ExitCode, SpatterError> {
    let loaded = run::load(path, sets)?;
    let params = Params::new(&loaded.model, loaded.state.len() as u32);
    let ctx = GpuContext::open(AdapterChoice::AnyGpu, false).map_err(SpatterError::Runtime)?;
    let mut gpu =
        GpuBackend::new(ctx, params, &loaded.state, false).map_err(SpatterError::Runtime)?;
    let mut cpu = CpuBackend::new(params, loaded.state.clone());
    use spatter::backend::Backend;
    let software = gpu.is_software() && !by_tolerance;
    println!("scenario: {path}, particles: {}", loaded.state.len());
    println!("reference: {}", cpu.describe());
    println!("device: {}", gpu.describe());
    let mode = if software {
        compare::CompareMode::Exact
    } else {
        compare::CompareMode::Tolerance(compare::ToleranceScales::new(&params))
    };
    let report = compare::compare(&mut cpu, &mut gpu, steps, &mode)
        .map_err(|e| SpatterError::Runtime(e.to_string()))?;
    if software {
        println!(
            "compared every field after {} passes ({} steps)",
            report.stages_compared, steps
        );
        if let Some(d) = &report.first_difference {
            println!(
                "first difference: step {}, pass {}, field {}, particle {} component {}: cpu {} vs gpu {}",
                d.step, d.pass, d.field, d.particle, d.component, d.cpu, d.gpu
            );
            println!("bit-identical: no");
            return Ok(ExitCode::from(1));
        }
        println!("bit-identical: yes");
    } else {
        return Ok(print_hardware_comparison(&report, &loaded.model, steps));
    }
    Ok(ExitCode::SUCCESS)
}
