//! Contact shadows (as in Filament, Bevy and Unreal): sm-pcf's maps, and a march of a few
//! samples toward the light through the depth buffer (`common/screen_space.wgsl`) that
//! shadows what the map misses near contacts, where depth bias and normal offset detach its
//! shadows from their casters (small maps, large offsets, thin casters on the ground).

use zoo_host::params::{ParamSpec, TechniqueParams, find_spec, values_of};
use zoo_host::prelude::*;

use crate::{ShadowMaps, SmParams};

zoo_host::technique_params! {
    /// The march toward the light.
    pub struct ContactParams {
        /// March length, in shadow-map texels at the receiver (what bias and normal offset
        /// cost the map near contacts).
        contact_texels: f32 = 16.0, range(1.0, 64.0), step(1.0);
        /// Depth-buffer samples along the march.
        contact_steps: u32 = 12, range(1, 64), step(1);
        /// Thickness assumed of what the depth buffer shows, in march lengths.
        contact_thickness: f32 = 0.1, range(0.02, 8.0), step(0.02);
    }
}

/// sm-pcf's parameters, then the march's.
fn schema() -> Vec<ParamSpec> {
    let mut schema = SmParams::schema();
    schema.extend(ContactParams::schema());
    schema
}

/// `values` split into the maps' and the march's, every key checked against both.
pub(crate) fn split_values(values: &ParamValues) -> TechniqueResult<(ParamValues, ContactParams)> {
    let all = schema();
    for (key, value) in values {
        find_spec(&all, key)?.check(value)?;
    }
    let contact = ContactParams::from_values(&values_of(&ContactParams::schema(), values))?;
    Ok((values_of(&SmParams::schema(), values), contact))
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let (params, contact) = split_values(values)?;
    Ok(Box::new(ShadowMaps {
        params: SmParams::from_values(&params)?,
        contact: Some(contact),
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "contact-shadows",
    name: "Contact shadows",
    description: "Shadow maps + PCF, and a short march toward the light through the depth buffer near contacts",
    source: "screen-space contact shadows (Filament, Bevy 0.19, Unreal Engine), on seed 000 section 7's maps",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    params: schema,
    create: create,
}
