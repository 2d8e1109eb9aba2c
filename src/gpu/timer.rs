//! The device's time in each stage of a step (the neighbour search, the outer iteration,
//! the end of the step), from timestamps it writes at the start and the end of every compute
//! pass, where it has timestamp queries (wgpu's `TIMESTAMP_QUERY`, which a device projfluid
//! opens asks for); a step's statistics report them ([`crate::stats::StepTimings`]).
//! Without them the host's clock between waits stands in.

use super::context::Context;

/// Passes a step times at most; passes past them run untimed.
const PASSES: u32 = 512;

/// The stage of a step a compute pass belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stage {
    /// The prediction, the sort and the neighbour lists.
    Search,
    /// The outer iteration: local and global steps, their reductions and stopping rules.
    Iteration,
    /// The end of the step: velocities, densities, viscosity, vorticity confinement, XSPH
    /// and the statistics.
    End,
}

/// The timestamps of one step's compute passes.
#[derive(Default)]
pub(super) struct Timer {
    /// The query set, its resolve buffer and nanoseconds per tick, where the device has
    /// timestamp queries.
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, f64)>,
    /// The stage of every pass timed in this step, in the order of their queries.
    passes: Vec<Stage>,
}

impl Timer {
    /// The timer of `ctx`'s device: with queries where it has timestamp queries.
    pub fn new(ctx: &Context) -> Self {
        if !ctx
            .device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
        {
            return Timer::default();
        }
        let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * PASSES,
        });
        let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass timestamps"),
            size: u64::from(2 * PASSES) * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let period = f64::from(ctx.queue.get_timestamp_period());
        Timer {
            queries: Some((set, resolve, period)),
            passes: Vec::new(),
        }
    }

    /// Starts a step: no pass timed yet.
    pub fn start(&mut self) {
        self.passes.clear();
    }

    /// A compute pass of `stage` on `encoder`, timed where the device can and room is left.
    pub fn pass<'e>(
        &mut self,
        encoder: &'e mut wgpu::CommandEncoder,
        stage: Stage,
    ) -> wgpu::ComputePass<'e> {
        let first = 2 * self.passes.len() as u32;
        let timestamp_writes = match &self.queries {
            Some((set, _, _)) if first < 2 * PASSES => {
                self.passes.push(stage);
                Some(wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(first),
                    end_of_pass_write_index: Some(first + 1),
                })
            }
            _ => None,
        };
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: None,
            timestamp_writes,
        })
    }

    /// Records the resolve of the step's timestamps into their buffer, and returns it with
    /// the bytes to read back; `None` where the device has no timestamp queries.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) -> Option<(&wgpu::Buffer, u64)> {
        let (set, resolve, _) = self.queries.as_ref()?;
        let count = 2 * self.passes.len() as u32;
        if count == 0 {
            return None;
        }
        encoder.resolve_query_set(set, 0..count, resolve, 0);
        Some((resolve, u64::from(count) * 8))
    }

    /// The seconds the device spent in the search, the outer iteration and the end of the
    /// step, from the resolved timestamps `bytes`.
    pub fn seconds(&self, bytes: &[u8]) -> [f64; 3] {
        let period = self.queries.as_ref().map_or(0.0, |q| q.2);
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
            .collect();
        let mut seconds = [0.0; 3];
        for (stage, pair) in self.passes.iter().zip(ticks.chunks_exact(2)) {
            let slot = match stage {
                Stage::Search => 0,
                Stage::Iteration => 1,
                Stage::End => 2,
            };
            seconds[slot] += pair[1].saturating_sub(pair[0]) as f64 * period * 1e-9;
        }
        seconds
    }
}
