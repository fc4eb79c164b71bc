//! The melt pool's time series as CSV (`spatter run --out RUN.mcap
//! --pool-csv`): one row per `/diagnostics` record of a heat scene,
//! written beside the MCAP as RUN.pool.csv and flushed per row, so a run that
//! stops leaves every row so far readable. The figures are the record's
//! (crate::pool: the largest connected region of melt, detached melt apart).

use crate::diagnostics::Diagnostics;
use std::io::Write;

pub const HEADER: &str = "time_s,pool_length_m,pool_width_m,pool_depth_m,pool_volume,detached_melt_regions,detached_melt_particles,detached_melt_mass_kg,max_temperature_K,depression_depth_m";

pub struct PoolCsv {
    path: String,
    file: std::io::BufWriter<std::fs::File>,
}

impl PoolCsv {
    pub fn create(path: &str) -> Result<PoolCsv, String> {
        let f = std::fs::File::create(path).map_err(|e| format!("{path}: cannot create: {e}"))?;
        let mut s = PoolCsv {
            path: path.to_string(),
            file: std::io::BufWriter::new(f),
        };
        s.line(HEADER)?;
        Ok(s)
    }

    fn line(&mut self, text: &str) -> Result<(), String> {
        writeln!(self.file, "{text}")
            .and_then(|_| self.file.flush())
            .map_err(|e| format!("{}: cannot write: {e}", self.path))
    }

    /// A row for a record (nothing outside heat scenes).
    pub fn record(&mut self, d: &Diagnostics) -> Result<(), String> {
        let Some(h) = &d.heat else {
            return Ok(());
        };
        let row = format!(
            "{:e},{:e},{:e},{:e},{:e},{},{},{:e},{:e},{}",
            d.time,
            h.pool_length,
            h.pool_width,
            h.pool_depth,
            h.pool_volume,
            h.detached_melt_regions,
            h.detached_melt_particles,
            h.detached_melt_mass,
            h.max_temperature,
            d.depression_depth
                .map_or(String::new(), |v| format!("{v:e}")),
        );
        self.line(&row)
    }
}
