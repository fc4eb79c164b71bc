//! Per-pass GPU timestamps (`--profile`): a begin and an end query per stage, read
//! back after every step and summed per stage name.

use crate::backend::Stage;

pub struct Profiler {
    pub queries: wgpu::QuerySet,
    pub resolve: wgpu::Buffer,
    pub period_ns: f32,
    pub totals: Vec<(&'static str, f64)>,
}

impl Profiler {
    pub fn new(device: &wgpu::Device, period_ns: f32, stages: usize) -> Self {
        let count = 2 * stages as u32;
        Profiler {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: count as u64 * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            period_ns,
            totals: Vec::new(),
        }
    }

    /// The compute-pass timestamp writes of stage slot `idx`.
    pub fn writes(&self, idx: u32, begin: bool, end: bool) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.queries,
            beginning_of_pass_write_index: begin.then_some(2 * idx),
            end_of_pass_write_index: end.then_some(2 * idx + 1),
        }
    }

    /// Add one step's resolved ticks (begin, end per stage) to the totals.
    pub fn record(&mut self, stages: &[Stage], ticks: &[u64]) {
        let period = self.period_ns as f64;
        for (k, s) in stages.iter().enumerate() {
            let ms = ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * period * 1e-6;
            match self.totals.iter_mut().find(|(n, _)| *n == s.name()) {
                Some(e) => e.1 += ms,
                None => self.totals.push((s.name(), ms)),
            }
        }
    }
}
