//! `spatter inspect`: an MCAP file's channels and the scenario it stored.

use spatter::error::SpatterError;
use std::process::ExitCode;

pub(crate) fn cmd_inspect(path: &str) -> Result<ExitCode, SpatterError> {
    let i = spatter::inspect::inspect(path)?;
    print!("{}", i.text);
    Ok(ExitCode::SUCCESS)
}
