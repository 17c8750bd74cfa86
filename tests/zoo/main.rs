//! The workspace's integration tests, one module per subject, in one test binary (each binary
//! links wgpu, egui and every plugin, so one link instead of fifteen keeps the suite fast).
//!
//! Modules that register test-only techniques (`source: "test"`) share this binary's registry;
//! tests that walk every shipped technique use `test_support::shipped_techniques`.

mod bench;
mod bias_artifacts;
mod claims;
mod cli;
mod contact_sheet;
mod exact_methods;
mod filtered_shadow_maps;
mod foliage;
mod gl_backend;
mod gpu_judge;
mod indirect_light;
mod indirect_scenes;
mod instances;
mod judge;
mod kit;
mod many_lights;
mod map_caching;
mod perspective_aliasing;
mod plugin_failure;
mod recorder;
mod slots;
mod soft_ray_tracing;
mod stage;
mod techniques;
mod viewer;

/// The techniques a user's build registers: every one except the test-only techniques that
/// this binary's modules register (their package is this one's).
fn shipped_techniques() -> Vec<&'static zoo_host::technique::TechniqueRegistration> {
    zoo_host::registry()
        .into_iter()
        .filter(|r| r.package != env!("CARGO_PKG_NAME"))
        .collect()
}
