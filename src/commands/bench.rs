//! `spatter bench`: throughput, accuracy and stability benchmarks.

use crate::*;
use spatter::bench;
use spatter::error::SpatterError;
use std::process::ExitCode;

pub(crate) fn cmd_bench(which: BenchKind) -> Result<ExitCode, SpatterError> {
    match which {
        BenchKind::Throughput {
            json,
            sizes,
            scenes,
            pass_costs_at,
            steps,
            backend,
        } => bench::throughput(&bench::throughput::Options {
            sizes: &sizes,
            steps,
            backends: &backend,
            scenes: &scenes,
            pass_costs_at: (pass_costs_at > 0.0).then_some(pass_costs_at),
            json: json.as_deref(),
        })
        .map(|_| ExitCode::SUCCESS),
        BenchKind::Accuracy {
            scenes,
            backend,
            quick,
            json,
            plots,
        } => bench::accuracy::accuracy(&bench::accuracy::Options {
            scenes: &scenes,
            backend,
            quick,
            json: json.as_deref(),
            plots: plots.as_deref(),
        })
        .map(|_| ExitCode::SUCCESS),
        BenchKind::Stability {
            backend,
            quick,
            json,
            seed,
            only,
        } => bench::stability::stability(&bench::stability::Options {
            backend,
            quick,
            json: json.as_deref(),
            seed,
            only: only.as_deref(),
        })
        .map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
    }
}
