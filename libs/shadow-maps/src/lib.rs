//! Shadow-map building blocks shared by the shadow-map techniques (sm-pcf, the moment family,
//! PSSM and the warped maps, the hybrid, SSSS, LPV): light frusta fitted to spot cones, cube
//! faces and what the camera sees ([`light_space`]), the per-light layer plan with screen
//! scissors ([`planning`]), the shadow atlas that gives every layer a tile at its light's
//! tier within the device's limits and a memory budget ([`atlas`], [`maps`]), the depth pass
//! that fills it with the casters whose boxes meet each layer's frustum ([`culling`]),
//! optionally with a colour map such as moments ([`depth`]), and a separable
//! blur of colour map layers ([`blur`]). [`ShadowMapSet`] keeps them up to date for a
//! technique in one call per frame.
//!
//! Lookups read a light's maps through its [`MapHeader`] in a [`LookupPass`], filtered as one
//! [`Filter`] choice says; the header, receivers, texel sizes, the map groups and the filters
//! live in WGSL: `shaders/shadow-maps/`.

pub mod atlas;
pub mod atlas_pages;
pub mod atlas_space;
pub mod blur;
pub mod cascades;
pub mod culling;
pub mod depth;
pub mod filter;
pub mod header;
pub mod light_space;
pub mod lookup;
pub mod lookup_pass;
pub mod maps;
pub mod moment_technique;
pub mod moments;
pub mod params;
pub mod planning;
pub mod sample_fit;
pub mod set;
pub mod tile_pass;
pub mod translucent;
pub mod warped;

pub use atlas_pages::{AtlasLimits, MEMORY_BUDGET, MapTile};
pub use blur::LayerBlur;
pub use cascades::Cascades;
pub use depth::{CAMERA_STRIDE, ColorOutput, DepthPass, DepthState, LayerCamera};
pub use filter::{Filter, MapFilter, MapFilters};
pub use header::MapHeader;
pub use lookup_pass::{Lookup, LookupPass, LookupShader};
pub use maps::{CUBE_GUARD, MAP_FORMAT, MOMENTS_RG_FORMAT, MOMENTS_RGBA_FORMAT, MapArray};
pub use moment_technique::{MomentChoice, MomentShadows};
pub use moments::{MomentMaps, MomentMethod, MomentSettings};
pub use params::{FilterParams, MapParams};
pub use planning::{
    LayerPlan, LightMaps, MapScale, PlanInputs, StandardLayers, light_scissor, light_size,
    object_bounds, plan_with,
};
pub use sample_fit::{SampleFit, SampleReduction};
pub use set::ShadowMapSet;
pub use tile_pass::{TilePass, layer_pass_name};
pub use translucent::{TRANSLUCENT_FORMAT, TranslucentPass};
