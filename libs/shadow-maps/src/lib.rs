//! Shadow-map building blocks shared by techniques (sm-pcf today; VSM, PSSM, the hybrid and
//! SSSS next): light frusta fitted to spot cones, cube faces and what the camera sees
//! ([`light_space`]), the per-light layer plan with screen scissors ([`planning`]), the depth
//! array under a memory budget ([`maps`]) and the depth pass that fills it ([`depth`]).
//!
//! Filters that read the maps live in WGSL: `shaders/shadow-maps/`.

pub mod depth;
pub mod light_space;
pub mod maps;
pub mod planning;

pub use depth::{CAMERA_STRIDE, DepthPass, DepthState};
pub use maps::{CUBE_GUARD, MAP_FORMAT, MEMORY_BUDGET, MapArray, effective_resolution};
pub use planning::{
    LightMaps, PlanInputs, layers_needed, light_scissor, light_size, object_bounds, plan,
};
