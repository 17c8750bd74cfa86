//! Sample-distribution shadow maps (`sdsm`; Lauritzen, Salvi and Lefohn 2010): pssm's splits,
//! lookup and blending, fitted to the samples the pixels really hold. Each frame the shadow-map
//! library's sample reduction gives the nearest and farthest view depth of the G-buffer's
//! surfaces, which the splits span, and each directional light's light-space box of the
//! surfaces in each split, to which its crop is cut. A view without surfaces keeps pssm's
//! range and crops.

use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo};
use zoo_shadow_maps::SampleReduction;

use crate::{Pssm, PssmParams};

struct Sdsm {
    pssm: Pssm,
    reduction: LazyGpu<SampleReduction>,
}

impl ShadowTechnique for Sdsm {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        self.reduction
            .prepare(false, || SampleReduction::new(ctx))?;
        self.pssm.prepare(ctx, changes)
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let fit = self.reduction.get_mut()?.fit(ctx, rec)?;
        let samples = fit.range.is_some().then_some(fit);
        if samples != self.pssm.samples {
            self.pssm.samples = samples;
            let moved = Changes {
                camera: true,
                ..Changes::default()
            };
            self.pssm.prepare(ctx, moved)?;
        }
        self.pssm.record(ctx, rec)
    }

    /// pssm's, and the range the splits cover.
    fn counters(&self) -> Vec<(String, f64)> {
        let mut out = self.pssm.counters();
        if let Some((near, far)) = self.pssm.samples.as_ref().and_then(|s| s.range) {
            out.push(("sdsm near".into(), near.into()));
            out.push(("sdsm far".into(), far.into()));
        }
        out
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        self.pssm.resources()
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        self.pssm.update_params(values)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        self.pssm.debug_view(resource)
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(Sdsm {
        pssm: Pssm::new(values)?,
        reduction: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "sdsm",
    name: "Sample-distribution shadow maps",
    description: "Directional lights: pssm's splits over the view depths of the depth buffer's surfaces and crops cut to each split's samples, reduced on the GPU",
    source: "Lauritzen, Salvi and Lefohn 2010 (sample distribution shadow maps)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional],
    params: PssmParams::schema,
    required_downlevel: || wgpu::DownlevelFlags::COMPUTE_SHADERS,
    create: create,
}
