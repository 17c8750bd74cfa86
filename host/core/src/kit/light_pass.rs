//! A full-screen pass per light with per-light uniforms: the shape of most screen-space
//! visibility passes (shadow-map lookups, back-facing tests, screen-space filters).

use super::{UniformSlots, UniformValue, slot_fullscreen_pipeline};
use crate::gpu::PassRecorder;
use crate::technique::{RenderContext, TechniqueError};

/// A full-screen fragment shader run once per light into that light's visibility slot, with
/// the frame (group 0), the G-buffer (group 1), one `T` per light (group 2, binding 0) and the
/// technique's own `groups` from 3 on. The fragment returns the light's visibility in every
/// channel (or discards to leave it lit).
pub struct FullscreenLightPass<T: UniformValue> {
    pipeline: wgpu::RenderPipeline,
    uniforms: UniformSlots<T>,
}

/// The name of light `light`'s pass: `"{base}: light {light}"` (passes of one family share
/// `base`, which timing views group by).
pub fn light_pass_name(base: &str, light: usize) -> String {
    format!("{base}: light {light}")
}

impl<T: UniformValue> FullscreenLightPass<T> {
    /// Builds the pipeline from fragment `entry` of library shader `shader` (for example
    /// `"backfacing/mask.wgsl"`), with extra bind group layouts `groups` (3, 4, ...).
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        entry: &str,
        groups: &[&wgpu::BindGroupLayout],
    ) -> Result<FullscreenLightPass<T>, TechniqueError> {
        let module = ctx.shaders.create_module(&ctx.gpu.device, shader)?;
        Ok(Self::with_module(ctx, shader, &module, entry, groups))
    }

    /// As [`Self::new`] with WGSL `text` (its `#import`s resolved from the library) instead of
    /// a library file; `label` names the module, the pipeline and the uniforms.
    pub fn from_source(
        ctx: &RenderContext<'_>,
        label: &str,
        text: &str,
        entry: &str,
        groups: &[&wgpu::BindGroupLayout],
    ) -> Result<FullscreenLightPass<T>, TechniqueError> {
        let module = (ctx.shaders).create_module_from_source(&ctx.gpu.device, label, text)?;
        Ok(Self::with_module(ctx, label, &module, entry, groups))
    }

    fn with_module(
        ctx: &RenderContext<'_>,
        label: &str,
        module: &wgpu::ShaderModule,
        entry: &str,
        groups: &[&wgpu::BindGroupLayout],
    ) -> FullscreenLightPass<T> {
        let stages = wgpu::ShaderStages::FRAGMENT;
        let uniforms = UniformSlots::new(ctx.gpu, label, ctx.lights.len(), stages);
        let mut layouts = vec![uniforms.layout()];
        layouts.extend_from_slice(groups);
        let pipeline = slot_fullscreen_pipeline(ctx, label, module, entry, &layouts);
        FullscreenLightPass { pipeline, uniforms }
    }

    /// The pass in `slot`, built there first if it is empty (a technique's `prepare` keeps
    /// its pass in an `Option` and calls this).
    pub fn ensure<'s>(
        slot: &'s mut Option<FullscreenLightPass<T>>,
        ctx: &RenderContext<'_>,
        shader: &str,
        entry: &str,
    ) -> Result<&'s mut FullscreenLightPass<T>, TechniqueError> {
        if slot.is_none() {
            *slot = Some(Self::new(ctx, shader, entry, &[])?);
        }
        Ok(slot.as_mut().expect("just filled"))
    }

    /// Records one pass per light, named `"{base}: light {l}"` ([`light_pass_name`]), with
    /// the uniform `per_light(light)`. Once per frame (see [`UniformSlots::write`]).
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        base: &str,
        per_light: impl Fn(usize) -> T,
    ) {
        self.record_with(ctx, recorder, base, per_light, |_, _| ());
    }

    /// As [`Self::record`], with `bind(light, pass)` setting the technique's own groups.
    pub fn record_with(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        base: &str,
        per_light: impl Fn(usize) -> T,
        bind: impl Fn(usize, &mut wgpu::RenderPass<'_>),
    ) {
        let values: Vec<T> = (0..ctx.lights.len()).map(per_light).collect();
        self.uniforms.write(ctx.gpu, &values);
        for light in 0..values.len() {
            let name = light_pass_name(base, light);
            let mut pass = ctx.light_pass(recorder, &name, light, None);
            pass.set_pipeline(&self.pipeline);
            let offset = self.uniforms.offset(light);
            pass.set_bind_group(2, self.uniforms.bind_group(), &[offset]);
            bind(light, &mut pass);
            pass.draw(0..3, 0..1);
        }
    }
}
