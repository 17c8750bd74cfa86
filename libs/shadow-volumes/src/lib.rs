//! Shadow-volume building blocks shared by techniques (sv-zfail today; the hybrid SM/SV
//! technique next): volume generation on the GPU from the scene's edge adjacency
//! ([`generation`], `shaders/shadow-volumes/volumes.wgsl`) in pieces that fit the device's
//! buffers ([`pieces`]), for the casters each light reaches ([`culling`]), its CPU mirror
//! ([`silhouette`]), and the stencil states that count volumes with z-fail or z-pass
//! ([`stencil`]).

pub mod culling;
pub mod generation;
pub mod pieces;
pub mod silhouette;
pub mod stencil;

pub use generation::{
    ARGS_BYTES, VolumeGenerator, Volumes, dispatch_size, piece_pass_name, piece_vertices,
    triangle_flags,
};
pub use stencil::{
    Counting, VOLUME_VERTEX_LAYOUT, band_volume_depth_stencil, band_volume_pipeline, stencil_state,
    volume_depth_stencil, volume_primitive,
};
