//! The deferred renderer shared by every technique.

pub mod debug_view;
pub mod difference;
pub mod frame;
pub mod gbuffer;
pub mod lighting;
pub mod materials;
mod renderer;
pub mod scene_buffers;
pub mod visibility;

pub use difference::ImageDifference;
pub use frame::{CameraMatrices, FrameBindings};
pub use gbuffer::GBuffer;
pub use materials::MaterialBindings;
pub use renderer::{
    GBufferData, MAX_OUTPUT_SIDE, Overlay, PendingReadout, Readout, ReadoutRequest, RenderError,
    Renderer, View,
};
pub use scene_buffers::{Placement, SceneBuffers, Vertex, drawn_runs};
pub use visibility::{
    IndirectTarget, SlotAssignment, SlotRequest, TransmittanceTargets, VisibilityTargets,
};
