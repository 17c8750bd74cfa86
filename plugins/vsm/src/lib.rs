//! Variance shadow maps (Donnelly and Lauritzen 2006): each light's casters store the first two
//! moments of their light depth in a filterable float map, blurred by a separable Gaussian;
//! lookups bound the lit fraction of the filter region with Chebyshev's inequality, and a
//! light-bleeding reduction cuts the bound's loose tail where casters overlap. The method is
//! `shaders/vsm/vsm.wgsl`; maps, fitting, blur and lookup are the shadow-map library's moment
//! maps (spot cones, directional boxes, point cubes).

use zoo_host::prelude::*;
use zoo_shadow_maps::{
    MOMENTS_RG_FORMAT, MomentChoice, MomentMethod, MomentSettings, MomentShadows,
};

zoo_host::technique_params! {
    /// Parameters of variance shadow maps.
    pub struct VsmParams {
        /// Moment-map resolution in texels per side (clamped to the device and memory budget).
        map_size: u32 = 2048, range(256, 8192), step(256);
        /// Gaussian blur of the moments, in taps on each side (0: bilinear filtering only).
        blur_radius: u32 = 2, range(0, 16), step(1);
        /// Smallest variance, in squared light-depth units (0 to 1 over the map).
        min_variance: f32 = 0.000001, range(0.0, 0.001), step(0.000001);
        /// Light-bleeding reduction: bounds below it become 0 and the rest is rescaled.
        bleeding_reduction: f32 = 0.2, range(0.0, 0.95), step(0.05);
        /// Lookups move off the surface by this many map texels along the normal.
        normal_offset: f32 = 1.0, range(0.0, 8.0), step(0.1);
        /// Keep directional maps stable as the camera moves (no shimmering edges).
        stable_fit: bool = true;
    }
}

/// VSM's choice of the library's moment maps.
struct Vsm(VsmParams);

impl MomentChoice for Vsm {
    fn method(&self) -> MomentMethod {
        MomentMethod {
            label: "VSM",
            shader: "vsm/vsm.wgsl",
            prelude: String::new(),
            format: MOMENTS_RG_FORMAT,
        }
    }

    fn settings(&self) -> MomentSettings {
        let p = &self.0;
        MomentSettings {
            map_size: p.map_size,
            stable_fit: p.stable_fit,
            blur_radius: p.blur_radius,
            normal_offset: p.normal_offset,
            bias: p.min_variance,
            bleeding_reduction: p.bleeding_reduction,
        }
    }

    fn update(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // Everything, map size included, applies at the next `prepare`.
        Ok(self.0.update(values)?)
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(MomentShadows::boxed(Vsm(VsmParams::from_values(values)?)))
}

zoo_host::register_technique! {
    id: "vsm",
    name: "Variance shadow maps",
    description: "Blurred depth moments per light (spot, directional, point cube); Chebyshev bound with light-bleeding reduction",
    source: "seed 000 section 13.3 (Donnelly and Lauritzen 2006)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    params: VsmParams::schema,
    create: create,
}
