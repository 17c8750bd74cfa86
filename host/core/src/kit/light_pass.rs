//! A full-screen pass per light with per-light uniforms: the shape of most screen-space
//! visibility passes (shadow-map lookups, back-facing tests, screen-space filters).

use super::stage::{SharedGroup, Stage, StageBindGroup, StageBuilder};
use super::{UniformSlots, UniformValue};
use crate::gpu::PassRecorder;
use crate::technique::{RenderContext, TechniqueError};

/// A full-screen fragment shader run once per light into that light's visibility slot (a
/// full-screen [`Stage`]), with one `T` per light (the uniform of type `T` it declares) and
/// the technique's own and shared groups. The fragment returns the light's visibility in
/// every channel (or discards to leave it lit).
pub struct FullscreenLightPass<T: UniformValue> {
    stage: Stage,
    uniforms: UniformSlots<T>,
}

/// The name of light `light`'s pass: `"{base}: light {light}"` (passes of one family share
/// `base`, which timing views group by).
pub fn light_pass_name(base: &str, light: usize) -> String {
    format!("{base}: light {light}")
}

impl<T: UniformValue> FullscreenLightPass<T> {
    /// Builds the pass from fragment `entry` of library shader `shader` (for example
    /// `"backfacing/mask.wgsl"`), with `shared` groups besides the host's.
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        entry: &str,
        shared: &[&dyn SharedGroup],
    ) -> Result<FullscreenLightPass<T>, TechniqueError> {
        Self::build(ctx, Stage::fullscreen(shader, entry), shader, shared)
    }

    /// As [`Self::new`] with WGSL `text` (its `#import`s resolved from the library) instead of
    /// a library file; `label` names the module, the pipeline and the uniforms.
    pub fn from_source(
        ctx: &RenderContext<'_>,
        label: &str,
        text: &str,
        entry: &str,
        shared: &[&dyn SharedGroup],
    ) -> Result<FullscreenLightPass<T>, TechniqueError> {
        Self::build(
            ctx,
            Stage::fullscreen(label, entry).text(text),
            label,
            shared,
        )
    }

    fn build(
        ctx: &RenderContext<'_>,
        stage: StageBuilder<'_>,
        label: &str,
        shared: &[&dyn SharedGroup],
    ) -> Result<FullscreenLightPass<T>, TechniqueError> {
        let stages = wgpu::ShaderStages::FRAGMENT;
        let uniforms = UniformSlots::new(ctx.gpu, label, ctx.lights.len(), stages);
        let stage = stage.shared(&[&uniforms.at(0)]).shared(shared).build(ctx)?;
        Ok(FullscreenLightPass { stage, uniforms })
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

    /// The stage, for binding its own groups ([`Stage::bind`]).
    pub fn stage(&self) -> &Stage {
        &self.stage
    }

    /// Records one pass per light, named `"{base}: light {l}"` ([`light_pass_name`]), with
    /// the uniform `per_light(light)`. Once per frame (see [`UniformSlots::write`]).
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        base: &str,
        per_light: impl Fn(usize) -> T,
    ) -> Result<(), TechniqueError> {
        self.record_with(ctx, recorder, base, per_light, &[], &[])
    }

    /// As [`Self::record`], with the stage's `own` bind groups and `shared` groups.
    pub fn record_with(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        base: &str,
        per_light: impl Fn(usize) -> T,
        own: &[&StageBindGroup],
        shared: &[&dyn SharedGroup],
    ) -> Result<(), TechniqueError> {
        let whole = |_| None;
        self.record_scissored(ctx, recorder, (base, per_light, &whole), own, shared)
    }

    /// As [`Self::record_with`], each light's pass restricted to `scissor(light)` where it
    /// gives a rectangle (x, y, width, height: the pixels the light can reach); a light whose
    /// rectangle is empty records no pass (its slot stays as the frame cleared it, lit).
    pub fn record_scissored(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (base, per_light, scissor): (
            &str,
            impl Fn(usize) -> T,
            &dyn Fn(usize) -> Option<[u32; 4]>,
        ),
        own: &[&StageBindGroup],
        shared: &[&dyn SharedGroup],
    ) -> Result<(), TechniqueError> {
        let values: Vec<T> = (0..ctx.lights.len()).map(per_light).collect();
        self.uniforms.write(ctx.gpu, &values);
        for light in 0..values.len() {
            let rect = scissor(light);
            if rect.is_some_and(|[_, _, w, h]| w == 0 || h == 0) {
                continue;
            }
            let name = light_pass_name(base, light);
            let mut pass = ctx.light_pass(recorder, &name, light, None);
            if let Some([x, y, w, h]) = rect {
                pass.set_scissor_rect(x, y, w, h);
            }
            let slot = self.uniforms.at(light);
            let mut all: Vec<&dyn SharedGroup> = vec![&slot];
            all.extend_from_slice(shared);
            self.stage.set_on(ctx, &mut pass, own, &all)?;
            pass.draw(0..3, 0..1);
        }
        Ok(())
    }
}
