//! Device, shaders, readback and per-pass timing.

pub mod adapter;
mod context;
pub mod gpu_struct;
pub mod layout;
pub mod readback;
mod recorder;
mod shaders;
mod targets;

pub use context::{GpuContext, GpuError};
pub use gpu_struct::{GpuStruct, GpuType, gpu_bytes, gpu_bytes_padded};
pub use recorder::{
    FrameTimings, PASSES_PER_CHUNK, PassCounts, PassOwner, PassRecorder, PassTiming,
    RecordedComputePass, RecordedRenderPass, StatisticsQueries, TimestampQueries, TimingSource,
};
pub use shaders::{ComposedShader, LoadedShader, ShaderError, ShaderLibrary};
pub use targets::{
    array_layers, clear_first, color_attachment, color_pass, fullscreen_pipeline, render_target,
    stencil_attachment,
};
