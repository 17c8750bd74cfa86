//! Shadow maps with percentage-closer filtering (seed 000 section 7, seed 004 sections 3.4 and
//! 9.1), with PCSS as the soft research variant.
//!
//! Each light renders its casters into depth layers of one `Depth32Float` array: spot lights
//! through a perspective frustum fitted to the cone, directional lights through an orthographic
//! box fitted to what the camera sees and the casters that can shadow it, point lights into six
//! cube faces widened by a guard band. A full-screen pass per light then compares each pixel's
//! light-space depth with the map and writes the light's visibility. Points outside a map are
//! lit. Bias: constant and slope-scaled pipeline depth bias, normal offset in texels, and
//! optional front-face culling in the depth pass. Maps, fitting and the lookup's map access
//! come from the shadow-map library.
//!
//! The crate also registers `contact-shadows`: the same maps, and a short march toward the
//! light through the depth buffer (`contact.rs`) that restores the shadow near contacts.

mod contact;

use contact::ContactParams;

use zoo_host::kit::{NamedTextures, TextureSpec};
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_shadow_maps::{
    DepthState, FilterParams, LightMaps, LookupPass, LookupShader, MapFilter, MapFilters,
    MapHeader, MapParams, ShadowMapSet, light_size,
};

zoo_host::technique_params! {
    /// Parameters of shadow maps with PCF.
    pub struct SmParams {
        use map: MapParams;
        use filtering: FilterParams;
        /// Constant depth bias of the depth pass, in units of the depth format's resolution. Too
        /// much pushes shadows away from where casters touch receivers (peter-panning).
        constant_bias: u32 = 0, range(0, 100000), step(100), flags(rebuild);
        /// Cull front faces in the depth pass (stores back faces).
        cull_front: bool = false, flags(rebuild);
        /// Keep directional maps stable as the camera moves (extent on a geometric ladder, centre
        /// snapped to whole texels), so shadow edges do not shimmer.
        stable_fit: bool = true;
        /// Light whose maps and diagnostics the debug views show.
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

zoo_host::gpu_struct! {
    "sm-pcf/shadow_light.wgsl" =>
    /// One light's lookup (`sm-pcf/lookup.wgsl`), at a dynamic offset.
    #[derive(Debug, Clone, Copy)]
    struct ShadowLight {
        map: MapHeader,
        map_filter: MapFilter,
        /// 1 when this light's diagnostics are written.
        debug: u32,
        /// Contact shadows: the march's length in map texels at the receiver, its samples (0:
        /// no march) and the thickness assumed of what the depth buffer shows, in march
        /// lengths.
        contact_texels: f32,
        contact_steps: u32,
        contact_thickness: f32,
    }
}

const SHADER: &str = "sm-pcf/lookup.wgsl";
/// Base name of the depth passes (see `zoo_shadow_maps::layer_pass_name`).
const DEPTH_PASS: &str = "Shadow map";
const LOOKUP_PASS: &str = "Shadow lookup";
const DIAGNOSTICS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Maps and the lookup, built at the first `prepare`.
struct Gpu {
    maps: ShadowMapSet,
    lookup: LookupPass<ShadowLight>,
    filters: MapFilters,
    /// Coverage (r) and receiver minus stored depth in texels (g), for the debug light.
    diagnostics: NamedTextures,
}

const DIAGNOSTICS: &str = "diagnostics";

/// The diagnostics target, shown as its coverage and depth-difference channels.
fn diagnostics_target() -> NamedTextures {
    let mut spec = TextureSpec::screen_target(DIAGNOSTICS, DIAGNOSTICS_FORMAT, None);
    spec.aliases = vec![
        (
            "coverage",
            ViewMapping::Channel {
                channel: 0,
                min: 0.0,
                max: 1.0,
            },
        ),
        (
            "depth difference",
            ViewMapping::Channel {
                channel: 1,
                min: -2.0,
                max: 2.0,
            },
        ),
    ];
    NamedTextures::new("sm-pcf", [spec])
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, params: &SmParams) -> TechniqueResult<Gpu> {
        let state = DepthState {
            constant_bias: params.constant_bias as i32,
            slope_bias: params.map.slope_bias,
            cull_front: params.cull_front,
            ..DepthState::default()
        };
        let maps = ShadowMapSet::new(ctx, "sm-pcf shadow maps", state, None)?;
        let shader = LookupShader {
            shader: SHADER,
            entry: "fs_lookup",
            diagnostics: &[DIAGNOSTICS_FORMAT],
            depth_stencil: None,
            shared: &[],
        };
        Ok(Gpu {
            lookup: LookupPass::new(ctx, &maps, LOOKUP_PASS, shader)?,
            maps,
            filters: MapFilters::read(ctx.shaders)?,
            diagnostics: diagnostics_target(),
        })
    }
}

/// The lookup's uniform for one light's maps.
fn shadow_light(
    p: &SmParams,
    contact: Option<&ContactParams>,
    filters: &MapFilters,
    maps: &LightMaps,
    light: &zoo_host::Light,
    debug: bool,
) -> ShadowLight {
    let size = light_size(light);
    ShadowLight {
        map: MapHeader::new(maps, p.map.normal_offset),
        map_filter: filters.filter(&p.filtering, size),
        debug: u32::from(debug),
        contact_texels: contact.map_or(0.0, |c| c.contact_texels),
        contact_steps: contact.map_or(0, |c| c.contact_steps),
        contact_thickness: contact.map_or(0.0, |c| c.contact_thickness),
    }
}

/// Shadow maps with PCF, and contact shadows where `contact` is set.
pub struct ShadowMaps {
    params: SmParams,
    contact: Option<ContactParams>,
    gpu: LazyGpu<Gpu>,
}

impl ShadowTechnique for ShadowMaps {
    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut out = Vec::new();
        if let Some(maps) = gpu.maps.maps() {
            out.push(ResourceInfo::texture("shadow maps", &maps.texture, true));
        }
        out.extend(gpu.diagnostics.resources());
        if let Some(cameras) = gpu.maps.cameras() {
            out.push(ResourceInfo::buffer(
                "layer cameras",
                cameras,
                "LayerCamera",
            ));
        }
        out.push(ResourceInfo::buffer(
            "shadow lights",
            gpu.lookup.uniform_buffer(),
            "ShadowLight",
        ));
        out
    }

    fn assign_slots(
        &self,
        request: &zoo_host::render::SlotRequest<'_>,
    ) -> zoo_host::TechniqueResult<zoo_host::render::SlotAssignment> {
        // The lookup writes only inside each light's range and cone.
        Ok(zoo_host::render::SlotAssignment::packed(request.lights))
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let gpu = self.gpu.prepare(false, || Gpu::new(ctx, &self.params))?;
        gpu.diagnostics.prepare(ctx);
        // Directional maps follow the camera; spot and point maps follow their lights.
        let p = &self.params;
        gpu.maps.prepare(ctx, changes, p.map.map_size, p.stable_fit);
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let (p, contact) = (&self.params, self.contact.as_ref());
        let Gpu {
            maps,
            lookup,
            filters,
            diagnostics,
        } = self.gpu.get_mut()?;
        maps.record(ctx, recorder, DEPTH_PASS)?;
        let diagnostics =
            (diagnostics.view(DIAGNOSTICS)).ok_or_else(TechniqueError::not_prepared)?;
        let uniform = |l: &LightMaps, debug| {
            let light = &ctx.lights[l.light];
            Some(shadow_light(p, contact, filters, l, light, debug))
        };
        lookup.record(ctx, recorder, maps, p.debug_light, &[diagnostics], uniform)
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // Biases and culling live in the depth pipeline (`flags(rebuild)`); the map size is
        // applied by the map set at the next `prepare`, the rest reaches the shader through the
        // per-light uniforms written every frame.
        if self.contact.is_some() {
            let (params, contact) = contact::split_values(values)?;
            let update = self.params.update(&params)?;
            self.contact = Some(contact);
            return Ok(update);
        }
        Ok(self.params.update(values)?)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let gpu = self.gpu.built()?;
        match resource {
            "shadow maps" => gpu.maps.debug_image(self.params.debug_light),
            _ => gpu.diagnostics.debug_view(resource),
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        self.gpu
            .built()
            .map_or(Vec::new(), |gpu| gpu.maps.counters())
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = SmParams::from_values(values)?;
    Ok(Box::new(ShadowMaps {
        params,
        contact: None,
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "sm-pcf",
    name: "Shadow maps + PCF",
    description: "Depth maps from each light (spot frustum, fitted directional box, point cube) with PCF or PCSS",
    source: "seed 000 section 7; seed 004 sections 3.4 and 9.1 (Williams 1978; Reeves 1987; Fernando 2005)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    params: SmParams::schema,
    create: create,
}
