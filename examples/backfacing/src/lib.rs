//! The README's example technique: surfaces facing away from a light are shadowed.

use zoo_host::prelude::*;

zoo_host::technique_params! {
    /// Parameters of the back-facing technique.
    pub struct BackfacingParams {
        /// Visibility written where a surface faces away from the light.
        darkness: f32 = 0.0, range(0.0, 1.0), step(0.05);
    }
}

zoo_host::gpu_struct! {
    "backfacing/pass.wgsl" =>
    /// The uniform of `shaders/backfacing/mask.wgsl`: the light and the darkness to write.
    #[derive(Debug, Clone, Copy)]
    pub struct Pass {
        pub light: u32,
        pub darkness: f32,
    }
}

const NAME: &str = "Back-facing test";

struct Backfacing {
    params: BackfacingParams,
    pass: Option<FullscreenLightPass<Pass>>,
}

impl ShadowTechnique for Backfacing {
    fn prepare(&mut self, ctx: &RenderContext<'_>, _: Changes) -> TechniqueResult {
        FullscreenLightPass::ensure(&mut self.pass, ctx, "backfacing/mask.wgsl", "fs_main")?;
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let darkness = self.params.darkness;
        let pass = (self.pass.as_mut()).ok_or_else(TechniqueError::not_prepared)?;
        pass.record(ctx, rec, NAME, |light| Pass {
            light: light as u32,
            darkness,
        })
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = BackfacingParams::from_values(values)?;
    Ok(Box::new(Backfacing { params, pass: None }))
}

zoo_host::register_technique! {
    id: "backfacing",
    name: "Back-facing test",
    description: "Shadows surfaces facing away from each light (example)",
    source: "README example",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    params: BackfacingParams::schema,
    create: create,
}
