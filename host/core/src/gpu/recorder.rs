//! Recording one frame's passes with per-pass timing.
//!
//! Every render or compute pass is opened through a [`PassRecorder`], which names it, labels it
//! for frame captures and times it: with GPU timestamp queries where the device has them,
//! otherwise by submitting each pass on its own and measuring its execution on the CPU clock.

use web_time::Instant;

use super::GpuContext;

/// Passes timed per query chunk. A frame with more passes takes further chunks (created on
/// first use and kept), so every pass is timed however many a technique records.
pub const PASSES_PER_CHUNK: u32 = 1024;

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
    /// What the device counted in the pass, when pipeline statistics are on.
    pub counts: Option<PassCounts>,
}

/// What the device counted in one pass (pipeline statistics and an occlusion query).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PassCounts {
    pub vertex_invocations: u64,
    pub fragment_invocations: u64,
    pub compute_invocations: u64,
    /// Samples that passed the depth and stencil tests (render passes; 0 in compute passes).
    /// A device may run fragment shaders before those tests (lavapipe does), so this, not the
    /// fragment invocations, is the work that early tests leave on a GPU.
    pub samples_passed: u64,
}

impl PassCounts {
    /// The counts in the order of [`PassCounts::NAMES`].
    pub fn values(&self) -> [u64; 4] {
        [
            self.vertex_invocations,
            self.fragment_invocations,
            self.compute_invocations,
            self.samples_passed,
        ]
    }

    /// Counts from [`PassCounts::values`]' order.
    pub fn from_values([v, f, c, s]: [u64; 4]) -> PassCounts {
        PassCounts {
            vertex_invocations: v,
            fragment_invocations: f,
            compute_invocations: c,
            samples_passed: s,
        }
    }

    /// Short names of the counts, in [`PassCounts::values`]' order.
    pub const NAMES: [&'static str; 4] = ["vertices", "fragments", "compute", "samples"];
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

/// One chunk of queries for [`PASSES_PER_CHUNK`] passes, with its resolve and readback
/// buffers (handles are shared, so a recorder holds clones).
#[derive(Clone)]
struct QueryChunk {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

/// Query chunks of one kind, created as frames need them.
struct QueryChunks {
    label: &'static str,
    ty: wgpu::QueryType,
    /// Queries per pass (two timestamps, or one statistics query).
    queries_per_pass: u32,
    /// Bytes one query resolves to.
    bytes_per_query: u64,
    chunks: std::sync::Mutex<Vec<QueryChunk>>,
}

impl QueryChunks {
    fn new(
        label: &'static str,
        ty: wgpu::QueryType,
        queries_per_pass: u32,
        bytes_per_query: u64,
    ) -> QueryChunks {
        QueryChunks {
            label,
            ty,
            queries_per_pass,
            bytes_per_query,
            chunks: std::sync::Mutex::new(Vec::new()),
        }
    }

    /// Bytes of one chunk's results.
    fn chunk_bytes(&self) -> u64 {
        u64::from(PASSES_PER_CHUNK * self.queries_per_pass) * self.bytes_per_query
    }

    /// Chunk `index`, created (with any before it) on first use.
    fn chunk(&self, gpu: &GpuContext, index: usize) -> QueryChunk {
        let mut chunks = self
            .chunks
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        while chunks.len() <= index {
            let n = chunks.len();
            let buffer = |what: &str, usage| {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("{} {what} (chunk {n})", self.label)),
                    size: self.chunk_bytes(),
                    usage,
                    mapped_at_creation: false,
                })
            };
            chunks.push(QueryChunk {
                set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some(&format!("{} (chunk {n})", self.label)),
                    ty: self.ty,
                    count: PASSES_PER_CHUNK * self.queries_per_pass,
                }),
                resolve: buffer(
                    "resolve",
                    wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                ),
                readback: buffer(
                    "readback",
                    wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                ),
            });
        }
        chunks[index].clone()
    }
}

/// Reusable timestamp query storage.
pub struct TimestampQueries {
    chunks: QueryChunks,
}

impl TimestampQueries {
    /// Creates the query storage, or `None` without timestamp support.
    pub fn new(gpu: &GpuContext) -> Option<TimestampQueries> {
        if !gpu.has_timestamps() {
            return None;
        }
        let chunks = QueryChunks::new("pass timestamps", wgpu::QueryType::Timestamp, 2, 8);
        chunks.chunk(gpu, 0);
        Some(TimestampQueries { chunks })
    }
}

/// Pipeline-statistics query storage (vertex, fragment and compute invocations per pass) and
/// occlusion query storage (samples passing the depth and stencil tests per render pass).
pub struct StatisticsQueries {
    chunks: QueryChunks,
    occlusion: QueryChunks,
}

impl StatisticsQueries {
    /// Creates the query storage, or `None` when the device lacks `PIPELINE_STATISTICS_QUERY`.
    pub fn new(gpu: &GpuContext) -> Option<StatisticsQueries> {
        if !gpu
            .device
            .features()
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
        {
            return None;
        }
        let chunks = QueryChunks::new(
            "pass pipeline statistics",
            wgpu::QueryType::PipelineStatistics(
                wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
                    | wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS
                    | wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS,
            ),
            1,
            24,
        );
        chunks.chunk(gpu, 0);
        let occlusion = QueryChunks::new("pass samples passed", wgpu::QueryType::Occlusion, 1, 8);
        occlusion.chunk(gpu, 0);
        Some(StatisticsQueries { chunks, occlusion })
    }
}

/// A render pass opened by a [`PassRecorder`]; use it like a `wgpu::RenderPass`.
pub struct RecordedRenderPass<'p> {
    pass: wgpu::RenderPass<'p>,
    statistics: bool,
    occlusion: bool,
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
        if self.occlusion {
            self.pass.end_occlusion_query();
        }
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

/// Query slots of a pass being opened.
struct NextPass {
    /// The chunk's timestamp set and the pass's first query.
    timestamps: Option<(wgpu::QuerySet, u32)>,
    /// The chunk's statistics set and the pass's query.
    statistics: Option<(wgpu::QuerySet, u32)>,
}

/// Occlusion queries of one frame's render passes: each render pass takes the next query, so
/// only written queries are resolved.
#[derive(Default)]
struct OcclusionSlots {
    /// Chunks this frame has used, in order.
    chunks: Vec<QueryChunk>,
    /// Each pass's query, in pass order (`None`: a compute pass, or one with its own set).
    of_pass: Vec<Option<u32>>,
    /// Queries taken.
    used: u32,
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
    /// Chunks this frame has used, in order.
    timestamp_chunks: Vec<QueryChunk>,
    statistics_chunks: Vec<QueryChunk>,
    occlusion: OcclusionSlots,
    /// Whether a render pass was recorded since the last compute pass.
    rendered: bool,
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
            timestamp_chunks: Vec::new(),
            statistics_chunks: Vec::new(),
            occlusion: OcclusionSlots::default(),
            rendered: false,
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
    /// A technique that must read back results of this frame's passes before recording the
    /// rest (sdsm's depth range) calls it, then waits for the GPU.
    pub fn flush(&mut self) {
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

    /// Names the next pass and returns its index and the query chunk slots it writes:
    /// (timestamp set, begin, end) and (statistics set, index).
    fn next_pass(&mut self, name: &str) -> NextPass {
        if self.queries.is_none() {
            self.flush();
        }
        let index = self.names.len() as u32;
        self.names.push((name.to_string(), self.owner));
        let (chunk, local) = (
            (index / PASSES_PER_CHUNK) as usize,
            index % PASSES_PER_CHUNK,
        );
        let gpu = self.gpu;
        let timestamps = self.queries.map(|q| {
            if self.timestamp_chunks.len() <= chunk {
                self.timestamp_chunks.push(q.chunks.chunk(gpu, chunk));
            }
            (self.timestamp_chunks[chunk].set.clone(), 2 * local)
        });
        let statistics = self.statistics.map(|s| {
            if self.statistics_chunks.len() <= chunk {
                self.statistics_chunks.push(s.chunks.chunk(gpu, chunk));
            }
            (self.statistics_chunks[chunk].set.clone(), local)
        });
        NextPass {
            timestamps,
            statistics,
        }
    }

    /// Opens a render pass; `desc.label` names it in timings and captures.
    pub fn render_pass(&mut self, desc: &wgpu::RenderPassDescriptor<'_>) -> RecordedRenderPass<'_> {
        let name = desc.label.unwrap_or("unnamed render pass").to_string();
        let next = self.next_pass(&name);
        let timestamp_writes =
            next.timestamps
                .as_ref()
                .map(|(set, begin)| wgpu::RenderPassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(*begin),
                    end_of_pass_write_index: Some(begin + 1),
                });
        let occlusion = match desc.occlusion_query_set {
            None => self.next_occlusion_query(),
            Some(_) => None,
        };
        self.occlusion
            .of_pass
            .push(occlusion.as_ref().map(|(_, i)| *i));
        let desc = wgpu::RenderPassDescriptor {
            label: desc.label,
            color_attachments: desc.color_attachments,
            depth_stencil_attachment: desc.depth_stencil_attachment.clone(),
            timestamp_writes,
            occlusion_query_set: desc
                .occlusion_query_set
                .or(occlusion.as_ref().map(|(set, _)| set)),
            multiview_mask: desc.multiview_mask,
        };
        self.rendered = true;
        let mut pass = self.encoder().begin_render_pass(&desc);
        if let Some((set, index)) = &next.statistics {
            pass.begin_pipeline_statistics_query(set, *index);
        }
        if let Some((_, index)) = &occlusion {
            pass.begin_occlusion_query(index % PASSES_PER_CHUNK);
        }
        RecordedRenderPass {
            pass,
            statistics: next.statistics.is_some(),
            occlusion: occlusion.is_some(),
        }
    }

    /// The next render pass's occlusion query (its chunk's set and the frame's query index),
    /// when statistics are on.
    fn next_occlusion_query(&mut self) -> Option<(wgpu::QuerySet, u32)> {
        let statistics = self.statistics?;
        let index = self.occlusion.used;
        self.occlusion.used += 1;
        let chunk = (index / PASSES_PER_CHUNK) as usize;
        if self.occlusion.chunks.len() <= chunk {
            (self.occlusion.chunks).push(statistics.occlusion.chunk(self.gpu, chunk));
        }
        Some((self.occlusion.chunks[chunk].set.clone(), index))
    }

    /// Opens a compute pass named `label`.
    pub fn compute_pass(&mut self, label: &str) -> RecordedComputePass<'_> {
        let next = self.next_pass(label);
        self.occlusion.of_pass.push(None);
        let timestamp_writes =
            next.timestamps
                .as_ref()
                .map(|(set, begin)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(*begin),
                    end_of_pass_write_index: Some(begin + 1),
                });
        if std::mem::take(&mut self.rendered) {
            let gpu = self.gpu;
            gpu.order_raster_before_compute(self.encoder());
        }
        let mut pass = self
            .encoder()
            .begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes,
            });
        if let Some((set, index)) = &next.statistics {
            pass.begin_pipeline_statistics_query(set, *index);
        }
        RecordedComputePass {
            pass,
            statistics: next.statistics.is_some(),
        }
    }

    /// Resolves the used part of every chunk (`passes` passes' queries) into its readback
    /// buffer.
    fn resolve_chunks(
        &mut self,
        chunks: &[QueryChunk],
        passes: u32,
        queries_per_pass: u32,
        bytes: u64,
    ) {
        for (k, chunk) in chunks.iter().enumerate() {
            let used = (passes - k as u32 * PASSES_PER_CHUNK).min(PASSES_PER_CHUNK);
            let queries = used * queries_per_pass;
            let encoder = self.encoder();
            encoder.resolve_query_set(&chunk.set, 0..queries, &chunk.resolve, 0);
            encoder.copy_buffer_to_buffer(
                &chunk.resolve,
                0,
                &chunk.readback,
                0,
                u64::from(queries) * bytes,
            );
        }
    }

    /// The resolved results of every chunk, in pass order (`bytes_per_pass` each).
    fn read_chunks(&self, chunks: &[QueryChunk], passes: usize, bytes_per_pass: usize) -> Vec<u8> {
        let mut all = Vec::new();
        for chunk in chunks {
            all.extend(super::readback::map_buffer(self.gpu, &chunk.readback));
        }
        all.truncate(passes * bytes_per_pass);
        all
    }

    /// Each pass's counts, where statistics were on.
    fn read_counts(&self, statistics: &[QueryChunk], occlusion: &[QueryChunk]) -> Vec<PassCounts> {
        let words = |bytes: Vec<u8>| -> Vec<u64> {
            (bytes.chunks_exact(8))
                .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
                .collect()
        };
        let invocations = words(self.read_chunks(statistics, self.names.len(), 24));
        let samples = words(self.read_chunks(occlusion, self.occlusion.used as usize, 8));
        (invocations.chunks_exact(3).zip(&self.occlusion.of_pass))
            .map(|(i, query)| PassCounts {
                vertex_invocations: i[0],
                fragment_invocations: i[1],
                compute_invocations: i[2],
                samples_passed: query.map_or(0, |q| samples[q as usize]),
            })
            .collect()
    }

    /// Submits the frame, waits for it and returns the pass times.
    pub fn finish(mut self) -> FrameTimings {
        let timestamp_chunks = std::mem::take(&mut self.timestamp_chunks);
        let statistics_chunks = std::mem::take(&mut self.statistics_chunks);
        let occlusion_chunks = std::mem::take(&mut self.occlusion.chunks);
        let passes = self.names.len() as u32;
        self.resolve_chunks(&timestamp_chunks, passes, 2, 8);
        self.resolve_chunks(&statistics_chunks, passes, 1, 24);
        self.resolve_chunks(&occlusion_chunks, self.occlusion.used, 1, 8);
        self.flush();
        self.gpu.wait_idle();
        let (source, times) = match self.queries {
            Some(_) => {
                let bytes = self.read_chunks(&timestamp_chunks, self.names.len(), 16);
                let period_ms = self.gpu.queue.get_timestamp_period() as f64 * 1e-6;
                let times = bytes
                    .chunks_exact(16)
                    .map(|b| {
                        let tick = |k: usize| {
                            u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("8 bytes"))
                        };
                        tick(1).saturating_sub(tick(0)) as f64 * period_ms
                    })
                    .collect();
                (TimingSource::GpuTimestamps, times)
            }
            None => (
                TimingSource::CpuWallClock,
                std::mem::take(&mut self.cpu_times),
            ),
        };
        let counts = self.read_counts(&statistics_chunks, &occlusion_chunks);
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
                    counts: counts.get(i).copied(),
                })
                .collect(),
        }
    }
}
