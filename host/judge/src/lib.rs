//! The reference judge: exact ray-traced visibility for the pixels of a rendered G-buffer, and
//! the metrics that score a technique's visibility against it. No GPU dependency.
//!
//! Each pixel's surface is found on the scene's exact triangles (the ray from the eye through
//! the G-buffer's position). For every pixel whose surface a light reaches (facing it, inside
//! its range and cone), shadow rays go from that point, moved off its triangle along the
//! triangle's normal by the bound on its floating-point error (nothing scales with the scene's
//! size), to the light: one ray to the light's centre for hard visibility, and stratified
//! samples over the light's disk (point and spot: a disk of the light's radius facing the
//! surface; directional: the cone of the light's angular radius) for area visibility.

mod bvh;
mod indirect;
mod leak;
mod metrics;
mod occluders;
mod placed;
mod reference;
mod robust;
mod sampling;
mod surfaces;

pub use bvh::{FlatBvh, FlatNode, has_no_area};
pub use indirect::{ReflectorHit, Reflectors, one_bounce, reflected_direct, relative_rmse};
pub use leak::{leak, lit_points, unlit_by_one_bounce};
pub use metrics::{ErrorClass, Metric, Metrics, edge_band, error_class, percentile};
pub use occluders::Occluders;
pub use placed::placed_box;
pub use reference::{DEFAULT_AREA_SAMPLES, LightReference, reference_visibility};
pub use robust::SHADOW_RAY_TO_LIGHT;
pub use sampling::{concentric_disk, stratified_disk};
pub use surfaces::{
    GBUFFER_POSITION_ERROR, SurfaceHit, SurfacePoint, Surfaces, reconstruction_error,
};
