//! The built-in `unshadowed` baseline: every light fully visible everywhere.

use crate::gpu::{GpuContext, PassRecorder};
use crate::params::{ParamSpec, ParamValues};
use crate::scene::LightKind;
use crate::technique::{Changes, RenderContext, ShadowTechnique, TechniqueError};

/// Id of the baseline technique.
pub const UNSHADOWED_ID: &str = "unshadowed";

/// Visibility 1 for every light: the host's cleared visibility is left as it is.
pub struct Unshadowed;

impl ShadowTechnique for Unshadowed {
    fn assign_slots(
        &self,
        request: &crate::render::SlotRequest<'_>,
    ) -> crate::technique::TechniqueResult<crate::render::SlotAssignment> {
        // It writes nothing, so any sharing is exact.
        Ok(crate::render::SlotAssignment::packed(request.lights))
    }

    fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> Result<(), TechniqueError> {
        Ok(())
    }

    fn record(
        &mut self,
        _: &RenderContext<'_>,
        _: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        Ok(())
    }
}

fn create(_: &GpuContext, _: &ParamValues) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(Unshadowed))
}

crate::register_technique! {
    id: UNSHADOWED_ID,
    name: "Unshadowed",
    description: "Baseline without shadows: visibility 1 for every light",
    source: "host baseline",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_features: wgpu::Features::empty,
    optional_features: wgpu::Features::empty,
    required_limits: wgpu::Limits::downlevel_defaults,
    params: Vec::<ParamSpec>::new,
    create: create,
}
