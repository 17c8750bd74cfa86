//! A whole shadow technique of moment maps: a plugin says what its method is and how its
//! parameters set the maps ([`MomentChoice`]); [`MomentShadows`] prepares, records, shows and
//! counts the library's [`MomentMaps`] for it.

use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo};

use crate::{MomentMaps, MomentMethod, MomentSettings};

/// What makes one moment-map technique: its method and its parameters.
pub trait MomentChoice: Send + 'static {
    /// The method's shader, map format and generated constants (read when the maps are built).
    fn method(&self) -> MomentMethod;
    /// What this frame's maps and lookups read of the parameters.
    fn settings(&self) -> MomentSettings;
    /// Takes new parameter values: applied in place, or a rebuild where the method's passes
    /// depend on them.
    fn update(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate>;
}

/// The technique of moment maps chosen by `C`.
pub struct MomentShadows<C> {
    choice: C,
    maps: LazyGpu<MomentMaps>,
}

impl<C: MomentChoice> MomentShadows<C> {
    /// The technique, boxed for a registration's `create`.
    pub fn boxed(choice: C) -> Box<dyn ShadowTechnique> {
        Box::new(MomentShadows {
            choice,
            maps: LazyGpu::default(),
        })
    }
}

impl<C: MomentChoice> ShadowTechnique for MomentShadows<C> {
    fn resources(&self) -> Vec<ResourceInfo> {
        self.maps.built().map_or(Vec::new(), MomentMaps::resources)
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let choice = &self.choice;
        let maps = (self.maps).prepare(false, || MomentMaps::new(ctx, &choice.method()))?;
        maps.prepare(ctx, changes, &choice.settings());
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let settings = self.choice.settings();
        self.maps.get_mut()?.record(ctx, recorder, &settings)
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        self.choice.update(values)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        self.maps.built()?.debug_view(resource)
    }

    fn counters(&self) -> Vec<(String, f64)> {
        self.maps.built().map_or(Vec::new(), MomentMaps::counters)
    }
}
