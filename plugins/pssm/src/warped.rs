//! Warped single maps: light-space perspective shadow maps (`lispsm`) and trapezoidal shadow
//! maps (`tsm`) for directional lights, and perspective shadow maps (`psm`, directional and
//! spot lights), fitted by the shadow-map library (`zoo_shadow_maps::warped`). One layer per light; the lookup measures texel sizes
//! where it filters. Where PSM cannot hold the view in one map (the light inside the view's
//! post-perspective box) the light falls back to the ordinary fitted map, and the counters
//! say how often.

use std::cell::Cell;

use zoo_host::kit::{NamedTextures, TextureSpec};
use zoo_host::params::ParamError;
use zoo_host::prelude::*;
use zoo_host::scene::Light;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_shadow_maps::cascades::slice_corners;
use zoo_shadow_maps::cascades::visible_depth_range;
use zoo_shadow_maps::light_space::LightFrustum;
use zoo_shadow_maps::warped::{
    lispsm_frustum, psm_frustum, receiver_box, tsm_frustum, worst_texel_to_pixel,
};
use zoo_shadow_maps::{
    DepthState, FilterParams, LayerPlan, LightMaps, LookupPass, LookupShader, MapFilter,
    MapFilters, MapParams, PlanInputs, ShadowMapSet, StandardLayers, light_size,
};

zoo_host::technique_params! {
    /// What both warped techniques read beside their warp.
    pub struct WarpedParams {
        use map: MapParams;
        use filtering: FilterParams;
        /// Light whose diagnostics the debug views show (the first shadowed light if it has none).
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

zoo_host::technique_params! {
    /// Parameters of light-space perspective shadow maps.
    pub struct LispsmParams {
        use shared: WarpedParams;
        /// Warp strength: 1 puts the warp's centre at the optimal n, larger values nearer
        /// (stronger warp), 0 gives a uniform map.
        strength: f32 = 1.0, range(0.0, 4.0), step(0.05);
    }
}

zoo_host::technique_params! {
    /// Parameters of trapezoidal shadow maps.
    pub struct TsmParams {
        use shared: WarpedParams;
        /// The focus region, as a fraction of the visible depth range from the near plane: it
        /// takes 80 % of the map's rows (the trapezoid's apex is placed for it).
        focus: f32 = 0.3, range(0.01, 1.0), step(0.01);
    }
}

zoo_host::technique_params! {
    /// Parameters of perspective shadow maps.
    pub struct PsmParams {
        use shared: WarpedParams;
        /// Smallest near plane of the virtual camera, as a fraction of the view's far depth
        /// (a nearer plane warps harder and loses depth precision).
        near_fraction: f32 = 0.002, range(0.0001, 0.1), step(0.0001);
    }
}

/// Which warp.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Warp {
    /// LiSPSM with this strength.
    Lispsm(f32),
    /// TSM with this focus region (fraction of the visible depth range).
    Tsm(f32),
    /// PSM with this smallest virtual near plane (fraction of far).
    Psm(f32),
}

/// The parameters of one of the two techniques.
#[derive(Debug, Clone)]
enum Params {
    Lispsm(LispsmParams),
    Tsm(TsmParams),
    Psm(PsmParams),
}

impl Params {
    /// The technique's id, which names its passes and resources.
    fn id(&self) -> &'static str {
        match self {
            Params::Lispsm(_) => "lispsm",
            Params::Tsm(_) => "tsm",
            Params::Psm(_) => "psm",
        }
    }

    fn warp(&self) -> Warp {
        match self {
            Params::Lispsm(p) => Warp::Lispsm(p.strength),
            Params::Tsm(p) => Warp::Tsm(p.focus),
            Params::Psm(p) => Warp::Psm(p.near_fraction),
        }
    }

    fn shared(&self) -> &WarpedParams {
        match self {
            Params::Lispsm(p) => &p.shared,
            Params::Tsm(p) => &p.shared,
            Params::Psm(p) => &p.shared,
        }
    }

    fn update(&mut self, values: &ParamValues) -> Result<ParamUpdate, ParamError> {
        match self {
            Params::Lispsm(p) => p.update(values),
            Params::Tsm(p) => p.update(values),
            Params::Psm(p) => p.update(values),
        }
    }
}

/// One warped layer per supported light; the standard fit where PSM cannot warp.
struct WarpedLayers {
    warp: Warp,
    /// Lights fitted, and of those, PSM fits that fell back to the standard map.
    fitted: Cell<u32>,
    fallbacks: Cell<u32>,
}

impl WarpedLayers {
    /// Whether the `warped` map of a spot `light` resolves the view more finely than the
    /// light's standard cone map: seen from a light low over the ground, behind or beside the
    /// viewer, post-perspective space can spend the map's texels worse than the cone does.
    fn sharper(
        &self,
        warped: &LightFrustum,
        light: &Light,
        resolution: u32,
        inputs: &PlanInputs<'_>,
    ) -> bool {
        let aspect = inputs.size.x as f32 / inputs.size.y.max(1) as f32;
        let (near, far) = visible_depth_range(inputs.camera, aspect, inputs.objects);
        let slice = slice_corners(inputs.camera, aspect, near, far);
        let receivers = receiver_box(&slice, inputs.objects);
        let coarseness = |frustum: &LightFrustum| {
            worst_texel_to_pixel(
                frustum,
                light,
                inputs.camera,
                inputs.size,
                resolution,
                &receivers,
            )
        };
        let standard = StandardLayers.frustums(light, resolution, inputs);
        standard
            .first()
            .is_none_or(|s| coarseness(warped) < coarseness(s))
    }
}

impl LayerPlan for WarpedLayers {
    fn layers(&self, light: &Light) -> u32 {
        match (self.warp, light.kind) {
            (_, LightKind::Directional) | (Warp::Psm(_), LightKind::Spot) => 1,
            _ => 0,
        }
    }

    fn frustums(
        &self,
        light: &Light,
        resolution: u32,
        inputs: &PlanInputs<'_>,
    ) -> Vec<LightFrustum> {
        if self.layers(light) == 0 {
            return Vec::new();
        }
        self.fitted.set(self.fitted.get() + 1);
        let aspect = inputs.size.x as f32 / inputs.size.y.max(1) as f32;
        let range = visible_depth_range(inputs.camera, aspect, inputs.objects);
        let fit = match self.warp {
            Warp::Lispsm(strength) => Some(
                lispsm_frustum(
                    light.direction,
                    inputs.camera,
                    aspect,
                    range,
                    inputs.casters,
                    strength,
                )
                .frustum,
            ),
            Warp::Tsm(focus) => Some(
                tsm_frustum(
                    light.direction,
                    inputs.camera,
                    aspect,
                    range,
                    inputs.casters,
                    focus,
                )
                .frustum,
            ),
            Warp::Psm(near_fraction) => psm_frustum(
                light,
                inputs.camera,
                aspect,
                range,
                inputs.objects,
                inputs.casters,
                near_fraction,
            )
            .map(|fit| fit.frustum)
            .filter(|warped| {
                light.kind != LightKind::Spot || self.sharper(warped, light, resolution, inputs)
            }),
        };
        fit.map(|f| vec![f]).unwrap_or_else(|| {
            self.fallbacks.set(self.fallbacks.get() + 1);
            StandardLayers.frustums(light, resolution, inputs)
        })
    }
}

zoo_host::gpu_struct! {
    "pssm/warped_light.wgsl" =>
    /// One light's lookup (`pssm/warped.wgsl`): its settings; everything that changes from
    /// frame to frame (the layer's matrices) is read from the layer cameras instead.
    #[derive(Debug, Clone, Copy)]
    struct WarpedLight {
        /// Index of the scene light.
        light: u32,
        layer: u32,
        /// 1 when this light's diagnostics are written.
        diagnostics: u32,
        /// Map resolution in texels.
        resolution: f32,
        map_filter: MapFilter,
        normal_offset: f32,
    }
}

const SHADER: &str = "pssm/warped.wgsl";
const DIAGNOSTICS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DENSITY_VIEW: &str = "texel density";

/// Maps and the lookup, built at the first `prepare`.
struct Gpu {
    maps: ShadowMapSet,
    lookup: LookupPass<WarpedLight>,
    filters: MapFilters,
    /// The texel-density view.
    density: NamedTextures,
    fallbacks: u32,
}

/// A warped-map technique (LiSPSM, TSM or PSM).
struct WarpedMaps {
    params: Params,
    gpu: LazyGpu<Gpu>,
}

fn density_target() -> NamedTextures {
    let colour = Some(ViewMapping::Color { min: 0.0, max: 1.0 });
    let spec = TextureSpec::screen_target(DENSITY_VIEW, DIAGNOSTICS_FORMAT, colour);
    NamedTextures::new("warped", [spec])
}

impl WarpedMaps {
    fn map_pass(&self) -> String {
        format!("{} map", self.params.id().to_uppercase())
    }
}

impl Gpu {
    /// The maps and lookup of technique `id` (`lispsm`, `tsm` or `psm`).
    fn new(ctx: &RenderContext<'_>, id: &str, p: &WarpedParams) -> TechniqueResult<Gpu> {
        let state = DepthState {
            constant_bias: 0,
            slope_bias: p.map.slope_bias,
            ..DepthState::default()
        };
        let label = format!("{id} maps");
        let maps = ShadowMapSet::new(ctx, &label, state, None)?;
        let shader = LookupShader {
            shader: SHADER,
            entry: "fs_warped",
            diagnostics: &[DIAGNOSTICS_FORMAT],
            depth_stencil: None,
            shared: &[],
        };
        Ok(Gpu {
            lookup: LookupPass::new(ctx, &maps, &format!("{} lookup", id.to_uppercase()), shader)?,
            maps,
            filters: MapFilters::read(ctx.shaders)?,
            density: density_target(),
            fallbacks: 0,
        })
    }
}

impl ShadowTechnique for WarpedMaps {
    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut out = gpu.density.resources();
        if let Some(maps) = gpu.maps.maps() {
            out.push(ResourceInfo::texture("shadow maps", &maps.texture, true));
        }
        if let Some(cameras) = gpu.maps.cameras() {
            out.push(ResourceInfo::buffer(
                "layer cameras",
                cameras,
                "LayerCamera",
            ));
        }
        out
    }

    fn assign_slots(
        &self,
        request: &zoo_host::render::SlotRequest<'_>,
    ) -> zoo_host::TechniqueResult<zoo_host::render::SlotAssignment> {
        // Spot lookups write only inside the light's range and cone; directional lights
        // cover the screen and are never packed with others.
        Ok(zoo_host::render::SlotAssignment::packed(request.lights))
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let (id, shared) = (self.params.id(), self.params.shared());
        self.gpu.prepare(false, || Gpu::new(ctx, id, shared))?;
        let layout = WarpedLayers {
            warp: self.params.warp(),
            fitted: Cell::new(0),
            fallbacks: Cell::new(0),
        };
        let gpu = self.gpu.get_mut()?;
        gpu.density.prepare(ctx);
        // Warped maps follow the camera: the set refits them on every change.
        (gpu.maps).prepare_with(ctx, changes, shared.map.map_size, false, &layout);
        if layout.fitted.get() > 0 {
            gpu.fallbacks = layout.fallbacks.get();
        }
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let map_pass = self.map_pass();
        let s = self.params.shared();
        let Gpu {
            maps,
            lookup,
            filters,
            density,
            ..
        } = self.gpu.get_mut()?;
        maps.record(ctx, recorder, &map_pass)?;
        // Lights without a layer (point lights, spot lights under LiSPSM) are not shadowed.
        let uniform = |l: &LightMaps, debug| {
            let size = light_size(&ctx.lights[l.light]);
            (!l.frustums.is_empty()).then(|| WarpedLight {
                light: l.light as u32,
                layer: l.first_layer,
                diagnostics: u32::from(debug),
                resolution: l.resolution as f32,
                map_filter: filters.filter(&s.filtering, size),
                normal_offset: s.map.normal_offset,
            })
        };
        let density = (density.view(DENSITY_VIEW)).ok_or_else(TechniqueError::not_prepared)?;
        lookup.record(ctx, recorder, maps, s.debug_light, &[density], uniform)
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // The slope bias lives in the depth pipeline (`flags(rebuild)`); everything else
        // applies at `prepare`.
        Ok(self.params.update(values)?)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let gpu = self.gpu.built()?;
        match resource {
            "shadow maps" => gpu.maps.debug_image(self.params.shared().debug_light),
            _ => gpu.density.debug_view(resource),
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut counters = gpu.maps.counters();
        counters.push(("standard-fit fallbacks".into(), gpu.fallbacks as f64));
        counters
    }
}

fn create_lispsm(
    _: &GpuContext,
    values: &ParamValues,
) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(WarpedMaps {
        params: Params::Lispsm(LispsmParams::from_values(values)?),
        gpu: LazyGpu::default(),
    }))
}

fn create_tsm(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(WarpedMaps {
        params: Params::Tsm(TsmParams::from_values(values)?),
        gpu: LazyGpu::default(),
    }))
}

fn create_psm(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(WarpedMaps {
        params: Params::Psm(PsmParams::from_values(values)?),
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "lispsm",
    name: "Light-space perspective shadow maps",
    description: "Directional lights: one map warped by a perspective in light space along the view direction (n_opt), uniform as light and view align",
    source: "seed 000 section 13.2 (Wimmer, Scherzer and Purgathofer 2004)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional],
    params: LispsmParams::schema,
    create: create_lispsm,
}

zoo_host::register_technique! {
    id: "tsm",
    name: "Trapezoidal shadow maps",
    description: "Directional lights: one map warped so a trapezoid around the view's outline in light space fills it, its focus region taking 80 % of the rows",
    source: "seed 000 section 3.5.3 (Martin and Tan 2004)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional],
    params: TsmParams::schema,
    create: create_tsm,
}

zoo_host::register_technique! {
    id: "psm",
    name: "Perspective shadow maps",
    description: "Directional and spot lights: one map in the camera's post-perspective space, virtual camera slid back for casters behind the viewer, inverted lights handled",
    source: "seed 000 section 7.9 (Stamminger and Drettakis 2002)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Spot],
    params: PsmParams::schema,
    create: create_psm,
}
