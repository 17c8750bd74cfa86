//! Which layers each light gets, their cameras, and the screen area each light can touch.

use zoo_host::glam::{Mat4, UVec2, Vec2, Vec3};
use zoo_host::scene::{Camera, Light, LightKind, Scene};

use crate::atlas::{Allocation, allocate, wanted_tier};
use crate::atlas_pages::{AtlasLimits, MapTile};
use crate::light_space::{
    Aabb, LightFrustum, Projection, cube_frustums, directional_frustum, spot_frustum,
};
use crate::maps::CUBE_GUARD;

/// One light's layers: their cameras and their tiles in the atlas.
#[derive(Debug, Clone)]
pub struct LightMaps {
    /// Index of the scene light.
    pub light: usize,
    /// Index of its first layer among all lights' layers (and layer cameras).
    pub first_layer: u32,
    /// Texels per side of each of its maps (its tier's tile size).
    pub resolution: u32,
    /// Where each layer's map lies in the atlas, one per frustum.
    pub tiles: Vec<MapTile>,
    /// One frustum per layer: 1 (spot, directional) or 6 (point: cube faces) under the
    /// standard plan; a technique's own plan may use others (cascade splits), or none for a
    /// light it does not shadow.
    pub frustums: Vec<LightFrustum>,
    /// What one of its layers is called in pass names ("face", "split").
    pub layer_word: &'static str,
    /// Screen rectangle (x, y, width, height) its lookups can touch.
    pub scissor: [u32; 4],
}

/// How a light's layers project, as lookups need it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapScale {
    /// World size of a texel: per unit of distance along the layer's axis (perspective) or
    /// absolute (orthographic).
    pub texel_scale: f32,
    pub perspective: bool,
    pub near: f32,
    pub far: f32,
}

impl LightMaps {
    /// The projection of this light's layers (all alike) at its resolution.
    pub fn scale(&self) -> MapScale {
        let resolution = self.resolution;
        match self.frustums[0].projection {
            Projection::Perspective {
                tan_half_fov,
                near,
                far,
            } => MapScale {
                texel_scale: 2.0 * tan_half_fov / resolution as f32,
                perspective: true,
                near,
                far,
            },
            // Texel sizes vary over warped maps: lookups measure them per point.
            Projection::Warped => MapScale {
                texel_scale: 0.0,
                perspective: false,
                near: 0.0,
                far: 1.0,
            },
            Projection::Orthographic { extent, near, far } => MapScale {
                texel_scale: extent / resolution as f32,
                perspective: false,
                near,
                far,
            },
        }
    }
}

/// How a technique lays out and fits each light's layers. [`StandardLayers`] is the usual
/// plan; techniques with their own (cascades, warped maps) implement this.
pub trait LayerPlan {
    /// Layers `light` needs (the same until the lights or the plan's settings change).
    fn layers(&self, light: &Light) -> u32;
    /// The frusta of `light`, exactly [`Self::layers`] of them, fitted to `inputs` for maps
    /// of `resolution` texels.
    fn frustums(
        &self,
        light: &Light,
        resolution: u32,
        inputs: &PlanInputs<'_>,
    ) -> Vec<LightFrustum>;
    /// What one layer of a light with several is called in pass names.
    fn layer_word(&self, _light: &Light) -> &'static str {
        "face"
    }
}

/// The usual plan: a perspective frustum on a spot cone, six guarded cube faces for a point
/// light, and for a directional light one orthographic box fitted to the receivers the camera
/// sees, reaching back to every caster.
#[derive(Debug, Clone, Copy, Default)]
pub struct StandardLayers;

impl LayerPlan for StandardLayers {
    fn layers(&self, light: &Light) -> u32 {
        if light.kind == LightKind::Point { 6 } else { 1 }
    }

    fn frustums(
        &self,
        light: &Light,
        resolution: u32,
        inputs: &PlanInputs<'_>,
    ) -> Vec<LightFrustum> {
        let aspect = inputs.size.x as f32 / inputs.size.y.max(1) as f32;
        match light.kind {
            LightKind::Spot => vec![spot_frustum(light)],
            LightKind::Point => cube_frustums(light, resolution, CUBE_GUARD).to_vec(),
            LightKind::Directional => vec![directional_frustum(
                light.direction,
                inputs.camera,
                aspect,
                inputs.objects,
                inputs.casters,
                inputs.stable.then_some(resolution),
            )],
        }
    }
}

/// What [`plan_with`] fits the maps to.
pub struct PlanInputs<'a> {
    pub lights: &'a [Light],
    pub camera: &'a Camera,
    /// The camera's view-projection and output size, for the scissors.
    pub view_proj: Mat4,
    pub size: UVec2,
    /// World bounds of every object and of each caster ([`object_bounds`]).
    pub objects: &'a [Aabb],
    pub casters: &'a [Aabb],
    /// With `stable`, directional maps keep a stable fit (extent on a ladder, centre snapped
    /// to whole texels) so edges do not shimmer as the camera moves.
    pub stable: bool,
}

/// Consecutive layers for every light with the frusta `layout` fits, each light's maps at
/// the tier the atlas gives it within `limits` (from its span on screen, [`wanted_tier`]).
/// With the `previous` frame's allocation, lights keep their wanted tiers within the
/// hysteresis and their tiles where their tiers hold ([`allocate`]).
pub fn plan_with(
    inputs: &PlanInputs<'_>,
    layout: &dyn LayerPlan,
    limits: &AtlasLimits,
    previous: Option<&Allocation>,
) -> (Vec<LightMaps>, Allocation) {
    let layers: Vec<u32> = inputs.lights.iter().map(|l| layout.layers(l)).collect();
    let scissors: Vec<[u32; 4]> = (inputs.lights.iter())
        .map(|light| light_scissor(light, inputs.view_proj, inputs.size))
        .collect();
    let previous = previous.filter(|p| p.layers == layers);
    let wanted: Vec<u32> = (scissors.iter().enumerate())
        .map(|(i, &scissor)| wanted_tier(scissor, inputs.size, previous.map(|p| p.wanted[i])))
        .collect();
    let allocation = allocate(&layers, &wanted, limits, previous);
    let mut next_layer = 0;
    let lights = (inputs.lights.iter().enumerate())
        .map(|(i, light)| {
            let resolution = limits.tile_size(allocation.tiers[i]);
            let frustums = layout.frustums(light, resolution, inputs);
            debug_assert_eq!(frustums.len() as u32, layers[i]);
            let first = next_layer as usize;
            next_layer += layers[i];
            LightMaps {
                light: i,
                first_layer: first as u32,
                resolution,
                tiles: allocation.tiles[first..next_layer as usize].to_vec(),
                frustums,
                layer_word: layout.layer_word(light),
                scissor: scissors[i],
            }
        })
        .collect();
    (lights, allocation)
}

/// The screen rectangle covering `light`'s range sphere (the whole screen for directional
/// lights or when the sphere reaches behind the camera); width 0 when it is off screen.
pub fn light_scissor(light: &Light, view_proj: Mat4, size: UVec2) -> [u32; 4] {
    let full = [0, 0, size.x, size.y];
    if light.kind == LightKind::Directional {
        return full;
    }
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for i in 0..8 {
        let corner = light.position
            + light.range
                * Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                );
        let clip = view_proj * corner.extend(1.0);
        if clip.w <= 1e-4 {
            return full;
        }
        let ndc = clip.truncate().truncate() / clip.w;
        let pixel = Vec2::new(
            (ndc.x * 0.5 + 0.5) * size.x as f32,
            (0.5 - ndc.y * 0.5) * size.y as f32,
        );
        lo = lo.min(pixel);
        hi = hi.max(pixel);
    }
    let x0 = lo.x.floor().clamp(0.0, size.x as f32) as u32;
    let y0 = lo.y.floor().clamp(0.0, size.y as f32) as u32;
    let x1 = hi.x.ceil().clamp(0.0, size.x as f32) as u32;
    let y1 = hi.y.ceil().clamp(0.0, size.y as f32) as u32;
    [x0, y0, x1.saturating_sub(x0), y1.saturating_sub(y0)]
}

/// World-space bounds of the objects (only shadow casters when `casters_only`).
pub fn object_bounds(scene: &Scene, casters_only: bool) -> Vec<Aabb> {
    let casters = scene
        .objects
        .iter()
        .map(|o| o.casts_shadows || !casters_only);
    (scene.each_object_bounds().into_iter().zip(casters))
        .filter_map(|(bounds, kept)| bounds.filter(|_| kept))
        .collect()
}

/// The light's size for penumbra estimates: its radius (point, spot) or the tangent of its
/// angular radius (directional).
pub fn light_size(light: &Light) -> f32 {
    match light.kind {
        LightKind::Directional => light.radius.tan(),
        _ => light.radius,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scissor_covers_the_light_sphere_on_screen() {
        let camera = zoo_host::scene::Camera {
            position: Vec3::new(0.0, 5.0, 10.0),
            target: Vec3::ZERO,
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        };
        let size = UVec2::new(200, 100);
        let view_proj = camera.projection(2.0) * camera.view();
        let mut light = Light {
            kind: LightKind::Point,
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            radiance: Vec3::ONE,
            range: 1.0,
            spot_angle: 0.0,
            spot_softness: 0.0,
            radius: 0.0,
        };
        let [x, y, w, h] = light_scissor(&light, view_proj, size);
        assert!(w > 0 && h > 0 && w < 200 && h < 100, "{x} {y} {w} {h}");
        // Every point of the sphere projects inside the rectangle.
        for k in 0..200 {
            let t = k as f32;
            let p = Vec3::new((t * 1.7).sin(), (t * 0.9).cos(), (t * 2.3).sin()).normalize() * 0.99;
            let ndc = view_proj.project_point3(p);
            let px = (ndc.x * 0.5 + 0.5) * 200.0;
            let py = (0.5 - ndc.y * 0.5) * 100.0;
            assert!(
                px >= x as f32 && px <= (x + w) as f32 && py >= y as f32 && py <= (y + h) as f32
            );
        }
        // A sphere reaching behind the camera, or a directional light, covers the screen.
        light.range = 20.0;
        assert_eq!(light_scissor(&light, view_proj, size), [0, 0, 200, 100]);
        light.kind = LightKind::Directional;
        assert_eq!(light_scissor(&light, view_proj, size), [0, 0, 200, 100]);
    }
}
