//! The per-light lookup pass of a shadow-map technique: one full-screen draw per shaded light
//! into its visibility slot, inside the light's screen scissor, with the technique's per-light
//! uniform (group 2, at a dynamic offset), the map set's lookup group (group 3) and the
//! technique's own groups from 4 on. Its fragment shader usually starts with the library's
//! `map_receiver` and ends with `look_up` (`shaders/shadow-maps/header_lookup.wgsl`); the
//! diagnostics targets after the slot are written only for the debug light.

use zoo_host::kit::{
    SlotPipeline, UniformSlots, UniformValue, diagnostics_pipelines, light_pass_name,
};
use zoo_host::prelude::*;

use crate::{LightMaps, ShadowMapSet};

/// A lookup pass's shader, targets and extra groups.
pub struct LookupShader<'a> {
    /// Library shader holding the fragment `entry` (and `common/fullscreen.wgsl`).
    pub shader: &'a str,
    pub entry: &'a str,
    /// Formats of the diagnostics targets, at locations 1, 2, ...
    pub diagnostics: &'a [wgpu::TextureFormat],
    /// For passes that write a depth-stencil attachment of their own.
    pub depth_stencil: Option<wgpu::DepthStencilState>,
    /// The technique's own bind group layouts: groups 4, 5, ...
    pub groups: &'a [&'a wgpu::BindGroupLayout],
}

/// One light's lookup this frame.
#[derive(Debug, Clone, Copy)]
pub struct Lookup<'s> {
    pub maps: &'s LightMaps,
    /// Whether its diagnostics are written.
    pub debug: bool,
    /// Its uniform's slot.
    slot: usize,
}

/// Pipelines (without and with diagnostics) and per-light uniforms of a lookup.
pub struct LookupPass<U: UniformValue> {
    /// Pass family name: each pass is `"{name}: light {l}"`.
    name: String,
    uniforms: UniformSlots<U>,
    pipelines: [wgpu::RenderPipeline; 2],
}

impl<U: UniformValue> LookupPass<U> {
    /// The pass family `name` (also the label of its pipelines and uniforms) reading `set`.
    pub fn new(
        ctx: &RenderContext<'_>,
        set: &ShadowMapSet,
        name: &str,
        shader: LookupShader<'_>,
    ) -> TechniqueResult<LookupPass<U>> {
        let stage = wgpu::ShaderStages::FRAGMENT;
        let label = format!("{name} uniforms");
        let uniforms = UniformSlots::new(ctx.gpu, &label, ctx.lights.len(), stage);
        let module = ctx.shaders.create_module(&ctx.gpu.device, shader.shader)?;
        let mut groups = vec![uniforms.layout(), set.lookup_layout()];
        groups.extend_from_slice(shader.groups);
        let pipeline = SlotPipeline {
            label: name,
            module: &module,
            entry: shader.entry,
            groups: &groups,
            more_targets: &[],
            depth_stencil: shader.depth_stencil,
        };
        let pipelines = diagnostics_pipelines(ctx, pipeline, shader.diagnostics);
        Ok(LookupPass {
            name: name.to_string(),
            uniforms,
            pipelines,
        })
    }

    /// The name of light `light`'s pass.
    pub fn pass_name(&self, light: usize) -> String {
        light_pass_name(&self.name, light)
    }

    /// Writes this frame's uniforms, `uniform(maps, debug)` for every light of `set` it gives
    /// one for (`debug` for the light `set.debug_light(debug_light)` picks), and returns their
    /// lookups in order. Once per frame.
    pub fn write<'s>(
        &mut self,
        ctx: &RenderContext<'_>,
        set: &'s ShadowMapSet,
        debug_light: u32,
        uniform: impl Fn(&LightMaps, bool) -> Option<U>,
    ) -> Vec<Lookup<'s>> {
        let debug = set.debug_light(debug_light).map(|l| l.light);
        let mut values = Vec::new();
        let mut lookups = Vec::new();
        for maps in set.lights() {
            let is_debug = Some(maps.light) == debug;
            if let Some(value) = uniform(maps, is_debug) {
                lookups.push(Lookup {
                    maps,
                    debug: is_debug,
                    slot: values.len(),
                });
                values.push(value);
            }
        }
        self.uniforms.write(ctx.gpu, &values);
        lookups
    }

    /// Records `lookup` with `colors` after the light's slot and `depth_stencil`; `bind` sets
    /// the technique's own groups.
    #[allow(clippy::too_many_arguments)]
    pub fn record_one(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        set: &ShadowMapSet,
        lookup: &Lookup<'_>,
        colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        depth_stencil: Option<wgpu::RenderPassDepthStencilAttachment<'_>>,
        bind: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) -> TechniqueResult {
        let group = set
            .lookup_group()
            .ok_or_else(TechniqueError::not_prepared)?;
        let light = lookup.maps.light;
        let name = self.pass_name(light);
        let mut pass = ctx.light_pass_with(recorder, &name, light, colors, depth_stencil);
        pass.set_pipeline(&self.pipelines[usize::from(lookup.debug)]);
        let offset = self.uniforms.offset(lookup.slot);
        pass.set_bind_group(2, self.uniforms.bind_group(), &[offset]);
        pass.set_bind_group(3, group, &[]);
        bind(&mut pass);
        let [x, y, width, height] = lookup.maps.scissor;
        if width > 0 && height > 0 {
            pass.set_scissor_rect(x, y, width, height);
            pass.draw(0..3, 0..1);
        }
        Ok(())
    }

    /// Writes the uniforms (see [`Self::write`]) and records every lookup, the first clearing
    /// the `diagnostics` targets.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        set: &ShadowMapSet,
        debug_light: u32,
        diagnostics: &[&wgpu::TextureView],
        uniform: impl Fn(&LightMaps, bool) -> Option<U>,
    ) -> TechniqueResult {
        let lookups = self.write(ctx, set, debug_light, uniform);
        for (k, lookup) in lookups.iter().enumerate() {
            let clear = zoo_host::gpu::clear_first(k == 0, wgpu::Color::TRANSPARENT);
            let colors: Vec<_> = (diagnostics.iter())
                .map(|view| zoo_host::gpu::color_attachment(view, clear))
                .collect();
            self.record_one(ctx, recorder, set, lookup, &colors, None, |_| ())?;
        }
        Ok(())
    }

    /// The buffer of this frame's uniforms.
    pub fn uniform_buffer(&self) -> &wgpu::Buffer {
        self.uniforms.buffer()
    }
}
