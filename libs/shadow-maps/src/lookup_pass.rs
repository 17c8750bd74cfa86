//! The per-light lookup pass of a shadow-map technique: one full-screen draw per shaded light
//! into its visibility slot, inside the light's screen scissor, with the technique's per-light
//! uniform, the map set's lookup group and the technique's own groups. Its fragment shader usually starts with the library's
//! `map_receiver` and ends with `look_up` (`shaders/shadow-maps/header_lookup.wgsl`); the
//! diagnostics targets after the slot are written only for the debug light.

use zoo_host::kit::{
    SharedGroup, Stage, StageBindGroup, UniformSlots, UniformValue, light_pass_name,
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
    /// Groups others own that the shader reads besides the uniform and the maps.
    pub shared: &'a [&'a dyn SharedGroup],
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

/// Stages (without and with diagnostics) and per-light uniforms of a lookup.
pub struct LookupPass<U: UniformValue> {
    /// Pass family name: each pass is `"{name}: light {l}"`.
    name: String,
    uniforms: UniformSlots<U>,
    stages: [Stage; 2],
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
        let stages = [wgpu::ColorWrites::empty(), wgpu::ColorWrites::ALL].map(|write_mask| {
            let targets: Vec<_> = (shader.diagnostics.iter())
                .map(|&format| {
                    Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask,
                    })
                })
                .collect();
            Stage::fullscreen(shader.shader, shader.entry)
                .targets(&targets)
                .depth_stencil(shader.depth_stencil.clone())
                .shared(&[&uniforms.at(0), &set.lookup()])
                .shared(shader.shared)
                .build(ctx)
        });
        let [without, with] = stages;
        Ok(LookupPass {
            name: name.to_string(),
            uniforms,
            stages: [without?, with?],
        })
    }

    /// The stage without diagnostics, for binding the technique's own groups
    /// ([`Stage::bind`]; the stage with diagnostics has the same groups).
    pub fn stage(&self) -> &Stage {
        &self.stages[0]
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

    /// Records `lookup` with `colors` after the light's slot and `depth_stencil`, and the
    /// technique's `own` and further `shared` groups.
    #[allow(clippy::too_many_arguments)]
    pub fn record_one(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        set: &ShadowMapSet,
        lookup: &Lookup<'_>,
        colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        depth_stencil: Option<wgpu::RenderPassDepthStencilAttachment<'_>>,
        (own, shared): (&[&StageBindGroup], &[&dyn SharedGroup]),
    ) -> TechniqueResult {
        let light = lookup.maps.light;
        let name = self.pass_name(light);
        let mut pass = ctx.light_pass_with(recorder, &name, light, colors, depth_stencil);
        let (slot, maps) = (self.uniforms.at(lookup.slot), set.lookup());
        let mut all: Vec<&dyn SharedGroup> = vec![&slot, &maps];
        all.extend_from_slice(shared);
        self.stages[usize::from(lookup.debug)].set_on(ctx, &mut pass, own, &all)?;
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
            self.record_one(ctx, recorder, set, lookup, &colors, None, (&[], &[]))?;
        }
        Ok(())
    }

    /// The buffer of this frame's uniforms.
    pub fn uniform_buffer(&self) -> &wgpu::Buffer {
        self.uniforms.buffer()
    }
}
