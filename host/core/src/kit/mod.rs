//! The technique kit: helpers that leave a technique's code to state its idea.
//!
//! - [`slot`]: write a light's visibility slot with one pipeline (the blend constant selects
//!   the channel) and open a pass on it with the frame and G-buffer groups bound.
//! - [`uniforms`]: per-light (or per-draw) uniforms in one buffer, at the device's dynamic
//!   offset alignment.
//! - [`layouts`]: terse bind group layout entries, bind groups by position, and pipeline
//!   layouts that put the frame (group 0) and G-buffer (group 1) layouts first.
//! - [`lazy`]: GPU state built at the first `prepare`, with the not-prepared error once.
//! - [`light_pass`]: a full-screen fragment shader run once per light into its slot, with
//!   per-light uniforms.
//! - [`compute`]: a compute pass with the technique's own group, after the host's groups or
//!   alone, its layout and workgroup size read from the WGSL ([`reflect`]) and its resources
//!   bound by name.
//!
//! Shader modules from inline WGSL with `#import`s come from
//! [`ShaderLibrary::create_module_from_source`](crate::ShaderLibrary::create_module_from_source).

pub mod compute;
pub mod layouts;
pub mod lazy;
pub mod light_pass;
pub mod reflect;
pub mod slot;
pub mod uniforms;

pub use compute::{ComputeStage, StageGroups};
pub use layouts::{
    SlotPipeline, bind_group, bind_group_layout, diagnostics_pipelines, pipeline_layout, sampler,
    slot_fullscreen_pipeline, storage, texture, uniform,
};
pub use lazy::LazyGpu;
pub use light_pass::{FullscreenLightPass, light_pass_name};
pub use slot::{LightSlot, slot_target};
pub use uniforms::{UniformSlots, UniformValue};
