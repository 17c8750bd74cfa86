//! The technique kit: helpers that leave a technique's code to state its idea.
//!
//! - [`slot`]: write a light's visibility slot with one pipeline (the blend constant selects
//!   the channel) and open a pass on it with the frame and G-buffer groups bound.
//! - [`uniforms`]: per-light (or per-draw) uniforms in one buffer, at the device's dynamic
//!   offset alignment.
//! - [`layouts`]: terse bind group layout entries and bind groups by position, for the owners
//!   of shared groups.
//! - [`lazy`]: GPU state built at the first `prepare`, with the not-prepared error once.
//! - [`light_pass`]: a full-screen fragment shader run once per light into its slot, with
//!   per-light uniforms.
//! - [`resources`]: textures declared once by name and spec, made and remade by the kit,
//!   listed and viewed from their declarations.
//! - [`stage`]: the one way to write a pass: a compute, full-screen or raster pipeline whose
//!   groups, layouts and workgroup size are read from the WGSL ([`reflect`]), its own
//!   resources bound by name and shared groups recognised by what they declare (a
//!   [`Joinable`] one's index may hold a stage's own variables too).
//!
//! Shader modules from inline WGSL with `#import`s come from
//! [`ShaderLibrary::create_module_from_source`](crate::ShaderLibrary::create_module_from_source).

pub mod layouts;
pub mod lazy;
pub mod light_pass;
pub mod reflect;
pub mod resources;
pub mod slot;
pub mod stage;
pub mod uniforms;

pub use layouts::{bind_group, bind_group_layout, sampler, storage, texture, uniform};
pub use lazy::LazyGpu;
pub use light_pass::{FullscreenLightPass, light_pass_name};
pub use resources::{NamedTextures, TextureSize, TextureSpec};
pub use slot::{LightSlot, slot_target};
pub use stage::{Joinable, NamedGroup, SharedGroup, Stage, StageBindGroup, StageBuilder};
pub use uniforms::{UniformSlot, UniformSlots, UniformValue};
