//! Shadow Zoo's core library: the [`ShadowTechnique`] contract every plugin implements, the
//! link-time technique registry, scenes, the GPU context and the deferred renderer that shades
//! every technique identically from the per-light visibility it produces.
//!
//! A plugin crate depends on this crate only. See `docs/writing-a-technique.md` for a
//! complete minimal plugin.

// Lets the macros name this crate as `zoo_host` from inside it too.
#[allow(unused_extern_crates)]
extern crate self as zoo_host;

pub mod builtin;
pub mod gpu;
pub mod judging;
pub mod kit;
pub mod params;
pub mod render;
pub mod technique;
#[cfg(feature = "test-support")]
pub mod test_support;

pub use gpu::{GpuContext, PassRecorder, ShaderLibrary};
pub use params::{ParamSpec, ParamValue, ParamValues, TechniqueParams};
pub use render::{Renderer, View};
pub use scene::{Camera, Light, LightKind, MAX_LIGHTS, Scene};
pub use technique::{
    Changes, DebugImage, DebugVolume, MaskedCasters, ParamUpdate, RenderContext, ResourceInfo,
    ShadowTechnique, TechniqueError, TechniqueRegistration, TechniqueResult, ViewMapping,
    VolumeAxis, VolumeSlice, find_technique, registry,
};

/// What a technique's crate usually needs: `use zoo_host::prelude::*;`.
pub mod prelude {
    pub use crate::kit::{self, FullscreenLightPass, LazyGpu, LightSlot, UniformSlots};
    pub use crate::params::TechniqueParams;
    pub use crate::{
        Changes, GpuContext, LightKind, ParamUpdate, ParamValues, PassRecorder, RenderContext,
        ShadowTechnique, TechniqueError, TechniqueResult,
    };
    pub use crate::{bytemuck, glam, wgpu};
}

// Re-exported so plugins and the macros need no direct dependency on them.
/// The reference judge (the GPU-free `zoo-judge` crate).
pub use zoo_judge as judge;
/// Scenes, lights, meshes and adjacency (the GPU-free `zoo-scene` crate).
pub use zoo_scene as scene;
pub use {bytemuck, glam, image, inventory, log, serde, wgpu};
