//! A failing plugin (panic or GPU validation error) is disabled with a message; rendering
//! continues with `unshadowed`.

use glam::UVec2;
use zoo_host::params::{ParamSpec, ParamValues};
use zoo_host::technique::TechniqueRegistration;
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::{
    Changes, GpuContext, LightKind, PassRecorder, RenderContext, Renderer, Scene, ShadowTechnique,
    TechniqueError, View, render::RenderError,
};

enum Failure {
    Panic,
    Validation,
}

struct Failing(Failure);

impl ShadowTechnique for Failing {
    fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> Result<(), TechniqueError> {
        Ok(())
    }
    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        _: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        match self.0 {
            Failure::Panic => panic!("deliberate test panic"),
            Failure::Validation => {
                // MAP_READ may only be combined with COPY_DST: a validation error.
                let _ = ctx
                    .gpu
                    .device
                    .create_buffer(&zoo_host::wgpu::BufferDescriptor {
                        label: Some("invalid buffer"),
                        size: 16,
                        usage: zoo_host::wgpu::BufferUsages::MAP_READ
                            | zoo_host::wgpu::BufferUsages::STORAGE,
                        mapped_at_creation: false,
                    });
                Ok(())
            }
        }
    }
}

fn create_panicking(
    _: &GpuContext,
    _: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(Failing(Failure::Panic)))
}

fn create_invalid(
    _: &GpuContext,
    _: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(Failing(Failure::Validation)))
}

fn create_refusing(
    _: &GpuContext,
    _: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Err(TechniqueError::Other("refuses to start".into()))
}

zoo_host::register_technique! {
    id: "test-panics",
    name: "Test: panics",
    description: "Panics while recording (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    required_features: zoo_host::wgpu::Features::empty,
    optional_features: zoo_host::wgpu::Features::empty,
    required_limits: zoo_host::wgpu::Limits::downlevel_defaults,
    params: Vec::<ParamSpec>::new,
    create: create_panicking,
}

zoo_host::register_technique! {
    id: "test-invalid",
    name: "Test: validation error",
    description: "Makes a wgpu validation error while recording (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    required_features: zoo_host::wgpu::Features::empty,
    optional_features: zoo_host::wgpu::Features::empty,
    required_limits: zoo_host::wgpu::Limits::downlevel_defaults,
    params: Vec::<ParamSpec>::new,
    create: create_invalid,
}

zoo_host::register_technique! {
    id: "test-refuses",
    name: "Test: factory error",
    description: "Its factory fails (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    required_features: zoo_host::wgpu::Features::empty,
    optional_features: zoo_host::wgpu::Features::empty,
    required_limits: zoo_host::wgpu::Limits::downlevel_defaults,
    params: Vec::<ParamSpec>::new,
    create: create_refusing,
}

zoo_host::register_technique! {
    id: "test-needs-more",
    name: "Test: impossible limits",
    description: "Needs more than any device has (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    required_features: zoo_host::wgpu::Features::empty,
    optional_features: zoo_host::wgpu::Features::empty,
    required_limits: || zoo_host::wgpu::Limits {
        max_texture_dimension_2d: u32::MAX,
        ..zoo_host::wgpu::Limits::downlevel_defaults()
    },
    params: Vec::<ParamSpec>::new,
    create: create_refusing,
}

fn renderer() -> Renderer {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    Renderer::new(gpu(), scene, UVec2::new(64, 64)).unwrap()
}

#[test]
fn a_panicking_plugin_is_disabled_and_rendering_continues() {
    let mut renderer = renderer();
    renderer
        .set_technique("test-panics", &ParamValues::new())
        .unwrap();
    let err = renderer.render(&View::Final).unwrap_err();
    assert!(
        matches!(&err, RenderError::Technique(TechniqueError::Panicked { id, message })
            if id == "test-panics" && message == "deliberate test panic"),
        "{err}"
    );
    assert_eq!(renderer.technique().id, "unshadowed");
    renderer.render(&View::Final).unwrap();
}

#[test]
fn a_plugin_with_a_validation_error_is_disabled_and_rendering_continues() {
    let mut renderer = renderer();
    renderer
        .set_technique("test-invalid", &ParamValues::new())
        .unwrap();
    let err = renderer.render(&View::Final).unwrap_err();
    assert!(
        matches!(&err, RenderError::Technique(TechniqueError::Validation { id, .. }) if id == "test-invalid"),
        "{err}"
    );
    assert_eq!(renderer.technique().id, "unshadowed");
    renderer.render(&View::Final).unwrap();
    assert!(gpu().take_uncaptured_errors().is_empty());
}

#[test]
fn factory_errors_and_unmet_limits_keep_the_current_technique() {
    let mut renderer = renderer();
    let err = renderer
        .set_technique("test-refuses", &ParamValues::new())
        .unwrap_err();
    assert_eq!(err.to_string(), "refuses to start");
    let err = renderer
        .set_technique("test-needs-more", &ParamValues::new())
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("needs limits max_texture_dimension_2d"),
        "{err}"
    );
    let err = renderer
        .set_technique("no-such", &ParamValues::new())
        .unwrap_err();
    assert!(
        err.to_string().starts_with("unknown technique `no-such`"),
        "{err}"
    );
    assert_eq!(renderer.technique().id, "unshadowed");
    renderer.render(&View::Final).unwrap();
}

#[test]
fn registration_records_the_package() {
    let r: Vec<&TechniqueRegistration> = zoo_host::registry();
    let test = r.iter().find(|r| r.id == "test-panics").unwrap();
    assert_eq!(test.package, "shadow-zoo");
    let builtin = r.iter().find(|r| r.id == "unshadowed").unwrap();
    assert_eq!(builtin.package, "zoo-host");
}
