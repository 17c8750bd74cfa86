//! Shadow-volume building blocks shared by techniques (sv-zfail and the hybrid SM/SV
//! technique): volume generation on the GPU from the scene's edge adjacency
//! ([`generation`], `shaders/shadow-volumes/volumes.wgsl`) in pieces that fit the device's
//! buffers ([`pieces`]), for the casters each light reaches ([`culling`]), its CPU mirror
//! ([`silhouette`]), the stages that count volumes in the stencil with z-fail or z-pass and
//! resolve the counts into visibility ([`stencil`]), Everitt and Kilgard's choice between the
//! two ([`near_clip`]), and the count view ([`counts`]).

pub mod counts;
pub mod culling;
pub mod generation;
pub mod near_clip;
pub mod pieces;
pub mod silhouette;
pub mod stencil;

pub use counts::{COUNT_LEVELS, COUNTS_FORMAT, StencilCounts};
pub use generation::{
    ARGS_BYTES, VolumeGenerator, VolumeShape, Volumes, dispatch_size, piece_pass_name,
    piece_vertices, triangle_flags,
};
pub use near_clip::{NearClipVolume, zpass_is_exact};
pub use stencil::{
    Counting, MARK_BIT, VOLUME_BUFFERS, VOLUME_VERTEX_LAYOUT, band_volume_depth_stencil,
    mark_depth_stencil, marked_resolve_stage, marked_volume_depth_stencil, resolve_stage,
    stencil_state, stencil_test, volume_depth_stencil, volume_primitive, volume_stage,
};
