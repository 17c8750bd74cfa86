//! Recording one frame's passes with per-pass timing.
//!
//! Every render or compute pass is opened through a [`PassRecorder`], which names it, labels it
//! for frame captures and times it: with GPU timestamp queries where the device has them,
//! otherwise by submitting each pass on its own and measuring its execution on the CPU clock.

use std::time::Instant;

use super::GpuContext;

/// Passes one frame can time.
pub const MAX_TIMED_PASSES: u32 = 1024;

/// Who recorded a pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PassOwner {
    /// The host's own passes (G-buffer, lighting, ...).
    Host,
    /// The active technique.
    Technique,
}

/// How pass times were measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimingSource {
    /// GPU timestamp queries.
    GpuTimestamps,
    /// Each pass submitted alone and timed with the CPU clock until the queue was idle.
    CpuWallClock,
}

impl TimingSource {
    /// Short label for reports.
    pub fn label(self) -> &'static str {
        match self {
            TimingSource::GpuTimestamps => "GPU timestamps",
            TimingSource::CpuWallClock => "CPU time (no timestamp queries)",
        }
    }
}

/// Time of one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    pub name: String,
    pub owner: PassOwner,
    pub milliseconds: f64,
    /// Vertex, fragment and compute shader invocations, when pipeline statistics are on.
    pub invocations: Option<[u64; 3]>,
}

/// Times of one frame's passes, in recording order.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTimings {
    pub source: TimingSource,
    pub passes: Vec<PassTiming>,
}

impl FrameTimings {
    /// Names of the technique's passes, in recording order.
    pub fn technique_pass_names(&self) -> Vec<String> {
        self.passes
            .iter()
            .filter(|p| p.owner == PassOwner::Technique)
            .map(|p| p.name.clone())
            .collect()
    }

    /// Sum over the passes of `owner`.
    pub fn total(&self, owner: PassOwner) -> f64 {
        self.passes
            .iter()
            .filter(|p| p.owner == owner)
            .map(|p| p.milliseconds)
            .fold(0.0, |a, b| a + b)
    }

    /// Sum over all passes.
    pub fn frame_total(&self) -> f64 {
        self.passes
            .iter()
            .map(|p| p.milliseconds)
            .fold(0.0, |a, b| a + b)
    }
}

/// Reusable timestamp query storage.
pub struct TimestampQueries {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl TimestampQueries {
    /// Creates the query set and buffers, or `None` without timestamp support.
    pub fn new(gpu: &GpuContext) -> Option<TimestampQueries> {
        if !gpu.has_timestamps() {
            return None;
        }
        let count = MAX_TIMED_PASSES * 2;
        let size = count as u64 * 8;
        Some(TimestampQueries {
            set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timestamps resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timestamps readback"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
        })
    }
}

/// Pipeline-statistics query storage: vertex, fragment and compute invocations per pass.
pub struct StatisticsQueries {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl StatisticsQueries {
    /// Creates the query set, or `None` when the device lacks `PIPELINE_STATISTICS_QUERY`.
    pub fn new(gpu: &GpuContext) -> Option<StatisticsQueries> {
        if !gpu
            .device
            .features()
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
        {
            return None;
        }
        let size = MAX_TIMED_PASSES as u64 * 24;
        Some(StatisticsQueries {
            set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass pipeline statistics"),
                ty: wgpu::QueryType::PipelineStatistics(
                    wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
                        | wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS
                        | wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS,
                ),
                count: MAX_TIMED_PASSES,
            }),
            resolve: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass statistics resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass statistics readback"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
        })
    }
}

/// A render pass opened by a [`PassRecorder`]; use it like a `wgpu::RenderPass`.
pub struct RecordedRenderPass<'p> {
    pass: wgpu::RenderPass<'p>,
    statistics: bool,
}

impl<'p> std::ops::Deref for RecordedRenderPass<'p> {
    type Target = wgpu::RenderPass<'p>;
    fn deref(&self) -> &Self::Target {
        &self.pass
    }
}

impl std::ops::DerefMut for RecordedRenderPass<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.pass
    }
}

impl Drop for RecordedRenderPass<'_> {
    fn drop(&mut self) {
        if self.statistics {
            self.pass.end_pipeline_statistics_query();
        }
    }
}

/// A compute pass opened by a [`PassRecorder`]; use it like a `wgpu::ComputePass`.
pub struct RecordedComputePass<'p> {
    pass: wgpu::ComputePass<'p>,
    statistics: bool,
}

impl<'p> std::ops::Deref for RecordedComputePass<'p> {
    type Target = wgpu::ComputePass<'p>;
    fn deref(&self) -> &Self::Target {
        &self.pass
    }
}

impl std::ops::DerefMut for RecordedComputePass<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.pass
    }
}

impl Drop for RecordedComputePass<'_> {
    fn drop(&mut self) {
        if self.statistics {
            self.pass.end_pipeline_statistics_query();
        }
    }
}

/// Opens the passes of one frame and times them.
pub struct PassRecorder<'a> {
    gpu: &'a GpuContext,
    encoder: Option<wgpu::CommandEncoder>,
    queries: Option<&'a TimestampQueries>,
    statistics: Option<&'a StatisticsQueries>,
    owner: PassOwner,
    names: Vec<(String, PassOwner)>,
    cpu_times: Vec<f64>,
}

impl<'a> PassRecorder<'a> {
    /// Starts a frame. `queries` = `None` selects CPU timing.
    pub fn new(gpu: &'a GpuContext, queries: Option<&'a TimestampQueries>) -> PassRecorder<'a> {
        PassRecorder {
            gpu,
            encoder: None,
            queries,
            statistics: None,
            owner: PassOwner::Host,
            names: Vec::new(),
            cpu_times: Vec::new(),
        }
    }

    /// Also counts shader invocations per pass.
    pub fn with_statistics(
        mut self,
        statistics: Option<&'a StatisticsQueries>,
    ) -> PassRecorder<'a> {
        self.statistics = statistics;
        self
    }

    /// The device and queue.
    pub fn gpu(&self) -> &GpuContext {
        self.gpu
    }

    /// Marks whose passes follow.
    pub fn set_owner(&mut self, owner: PassOwner) {
        self.owner = owner;
    }

    /// The encoder, for copies and clears outside passes.
    pub fn encoder(&mut self) -> &mut wgpu::CommandEncoder {
        let gpu = self.gpu;
        self.encoder.get_or_insert_with(|| {
            gpu.device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("frame encoder"),
                })
        })
    }

    /// Submits recorded work (in CPU-timing mode, time it and charge it to the previous pass).
    fn flush(&mut self) {
        let Some(encoder) = self.encoder.take() else {
            return;
        };
        let start = Instant::now();
        self.gpu.queue.submit([encoder.finish()]);
        if self.queries.is_none() {
            self.gpu.wait_idle();
            let elapsed = start.elapsed().as_secs_f64() * 1e3;
            if self.cpu_times.len() < self.names.len() {
                self.cpu_times.push(elapsed);
            }
        }
    }

    fn next_pass(&mut self, name: &str) -> Option<(u32, u32)> {
        if self.queries.is_none() {
            self.flush();
        }
        let index = self.names.len() as u32;
        self.names.push((name.to_string(), self.owner));
        (self.queries.is_some() && index < MAX_TIMED_PASSES).then_some((2 * index, 2 * index + 1))
    }

    /// Opens a render pass; `desc.label` names it in timings and captures.
    pub fn render_pass(&mut self, desc: &wgpu::RenderPassDescriptor<'_>) -> RecordedRenderPass<'_> {
        let name = desc.label.unwrap_or("unnamed render pass").to_string();
        let slots = self.next_pass(&name);
        let index = self.names.len() as u32 - 1;
        let statistics = self.statistics.filter(|_| index < MAX_TIMED_PASSES);
        let queries = self.queries;
        let timestamp_writes = match (slots, queries) {
            (Some((begin, end)), Some(q)) => Some(wgpu::RenderPassTimestampWrites {
                query_set: &q.set,
                beginning_of_pass_write_index: Some(begin),
                end_of_pass_write_index: Some(end),
            }),
            _ => None,
        };
        let desc = wgpu::RenderPassDescriptor {
            label: desc.label,
            color_attachments: desc.color_attachments,
            depth_stencil_attachment: desc.depth_stencil_attachment.clone(),
            timestamp_writes,
            occlusion_query_set: desc.occlusion_query_set,
            multiview_mask: desc.multiview_mask,
        };
        let mut pass = self.encoder().begin_render_pass(&desc);
        if let Some(s) = statistics {
            pass.begin_pipeline_statistics_query(&s.set, index);
        }
        RecordedRenderPass {
            pass,
            statistics: statistics.is_some(),
        }
    }

    /// Opens a compute pass named `label`.
    pub fn compute_pass(&mut self, label: &str) -> RecordedComputePass<'_> {
        let slots = self.next_pass(label);
        let index = self.names.len() as u32 - 1;
        let statistics = self.statistics.filter(|_| index < MAX_TIMED_PASSES);
        let queries = self.queries;
        let timestamp_writes = match (slots, queries) {
            (Some((begin, end)), Some(q)) => Some(wgpu::ComputePassTimestampWrites {
                query_set: &q.set,
                beginning_of_pass_write_index: Some(begin),
                end_of_pass_write_index: Some(end),
            }),
            _ => None,
        };
        let mut pass = self
            .encoder()
            .begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes,
            });
        if let Some(s) = statistics {
            pass.begin_pipeline_statistics_query(&s.set, index);
        }
        RecordedComputePass {
            pass,
            statistics: statistics.is_some(),
        }
    }

    /// Submits the frame, waits for it and returns the pass times.
    pub fn finish(mut self) -> FrameTimings {
        let pass_count = (self.names.len() as u32).min(MAX_TIMED_PASSES);
        if let Some(q) = self.queries
            && pass_count > 0
        {
            let encoder = self.encoder();
            encoder.resolve_query_set(&q.set, 0..pass_count * 2, &q.resolve, 0);
            encoder.copy_buffer_to_buffer(&q.resolve, 0, &q.readback, 0, pass_count as u64 * 16);
        }
        if let Some(s) = self.statistics
            && pass_count > 0
        {
            let encoder = self.encoder();
            encoder.resolve_query_set(&s.set, 0..pass_count, &s.resolve, 0);
            encoder.copy_buffer_to_buffer(&s.resolve, 0, &s.readback, 0, pass_count as u64 * 24);
        }
        self.flush();
        self.gpu.wait_idle();
        let (source, times) = match self.queries {
            Some(q) if pass_count > 0 => {
                let bytes = super::readback::map_buffer(self.gpu, &q.readback);
                let period_ms = self.gpu.queue.get_timestamp_period() as f64 * 1e-6;
                let ticks: Vec<u64> = bytes
                    .chunks_exact(8)
                    .take(pass_count as usize * 2)
                    .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
                    .collect();
                let times = ticks
                    .chunks_exact(2)
                    .map(|t| t[1].saturating_sub(t[0]) as f64 * period_ms)
                    .collect();
                (TimingSource::GpuTimestamps, times)
            }
            Some(_) => (TimingSource::GpuTimestamps, Vec::new()),
            None => (
                TimingSource::CpuWallClock,
                std::mem::take(&mut self.cpu_times),
            ),
        };
        let invocations: Vec<[u64; 3]> = match self.statistics {
            Some(s) if pass_count > 0 => super::readback::map_buffer(self.gpu, &s.readback)
                .chunks_exact(24)
                .take(pass_count as usize)
                .map(|b| {
                    let word = |k: usize| {
                        u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("8 bytes"))
                    };
                    [word(0), word(1), word(2)]
                })
                .collect(),
            _ => Vec::new(),
        };
        FrameTimings {
            source,
            passes: self
                .names
                .into_iter()
                .zip(times.into_iter().chain(std::iter::repeat(0.0)))
                .enumerate()
                .map(|(i, ((name, owner), milliseconds))| PassTiming {
                    name,
                    owner,
                    milliseconds,
                    invocations: invocations.get(i).copied(),
                })
                .collect(),
        }
    }
}
