// Where rays from a G-buffer surface start (`zoo_ray_tracing::origin`). A G-buffer position
// lies off its surface by two errors, and a ray leaves it past both:
//
// - rounding (`zoo_judge::reconstruction_error`, a generated factor of the eye's and the
//   position's largest coordinates and the view distance): the origin moves off the surface
//   along its normal by that much, as the judge's rays start (`rt_gbuffer_ray_origin`);
// - the rasteriser's snapping of vertices to a sub-pixel grid, which moves the drawn plane by
//   a fraction of a pixel's footprint at the surface's distance: the ray skips the stretch
//   along its own direction over which it could meet its own surface again
//   (`rt_gbuffer_raster_skip`). Moving along the ray, rather than off the surface, keeps the
//   ray's line: where it crosses casters (the texels of a fine alpha mask, a contact shadow's
//   edge) is where the judge's ray crosses them.

#import "ray-tracing/gbuffer_error.wgsl"

// Directions closer to the surface than this cosine skip as much as at this cosine.
const RT_GRAZING_COSINE: f32 = 0.01;

// The ray origin for G-buffer position `position` seen from `eye`, leaving along `side` (its
// unit normal on the side the rays leave).
fn rt_gbuffer_ray_origin(position: vec3<f32>, side: vec3<f32>, eye: vec3<f32>) -> vec3<f32> {
    let magnitude = max(max(abs(eye.x), abs(eye.y)), abs(eye.z))
        + max(max(abs(position.x), abs(position.y)), abs(position.z));
    return position + side * (RT_GBUFFER_POSITION_ERROR * (magnitude + distance(position, eye)));
}

// How far a ray from G-buffer position `position` (seen from `eye`, leaving along `side`) in
// unit direction `dir` goes before it can no longer meet its own surface; `pixel` is a
// pixel's side at unit distance from the eye.
fn rt_gbuffer_raster_skip(position: vec3<f32>, side: vec3<f32>, eye: vec3<f32>, dir: vec3<f32>, pixel: f32) -> f32 {
    let drift = RT_RASTER_SUBPIXEL * pixel * distance(position, eye);
    return drift / max(dot(side, dir), RT_GRAZING_COSINE);
}
