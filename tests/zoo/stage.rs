//! The kit's one stage type: groups read from the WGSL, the host's groups and shared ones
//! recognised by what they declare, own resources bound by name, and clear errors for names
//! that are not the shader's and for groups that mix shared and own variables (unless the
//! shared group is joinable).

use std::sync::Mutex;

use glam::UVec2;
use zoo_host::kit::{
    Joinable, NamedGroup, SharedGroup, Stage, StageBindGroup, bind_group_layout, storage,
};
use zoo_host::params::ParamValues;
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::wgpu::{self, util::DeviceExt};
use zoo_host::{
    Changes, GpuContext, LightKind, PassRecorder, RenderContext, Renderer, Scene, ShadowTechnique,
    TechniqueResult, View,
};

/// A full-screen stage: the frame group (`lights`, by its name), an own storage buffer, and
/// a second one that only another entry reads.
const SHADER: &str = r#"
#import "common/frame.wgsl"
#import "common/fullscreen.wgsl"

@group(2) @binding(0) var<storage, read> levels: array<f32>;
@group(2) @binding(1) var<storage, read> offsets: array<f32>;

@fragment
fn fs_offset_level() -> @location(0) vec4<f32> {
    return vec4<f32>(levels[0] + offsets[0]);
}

@fragment
fn fs_level() -> @location(0) vec4<f32> {
    // Every light of the scene has a slot; light k writes levels[k] into its own.
    let count = arrayLength(&lights);
    return vec4<f32>(levels[min(u32(levels[3]), count - 1u)]);
}
"#;

/// Group 0 holds `camera` (the host's) and an own buffer: not allowed.
const MIXED: &str = r#"
#import "common/frame.wgsl"

@group(0) @binding(7) var<storage, read_write> mine: array<u32>;

@compute @workgroup_size(1)
fn cs_mixed() {
    mine[0] = u32(camera.position.x);
}
"#;

/// Group 2 holds `levels`, a shared group's, and an own buffer: allowed where the shared group
/// is joinable, the stage then binding both.
const JOINED: &str = r#"
#import "common/frame.wgsl"

@group(2) @binding(0) var<storage, read> levels: array<f32>;
@group(2) @binding(1) var<storage, read_write> mine: array<f32>;

@compute @workgroup_size(1)
fn cs_joined() {
    mine[0] = levels[0] + f32(arrayLength(&lights));
}
"#;

/// The levels each light writes (the last element picks the light, see [`SHADER`]).
const LEVELS: [f32; 3] = [0.25, 0.5, 0.75];

/// Errors the technique met while preparing, for the test to read.
static ERRORS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Writes `LEVELS[light]` into each light's slot, one stage per light.
#[derive(Default)]
struct Levels {
    passes: Vec<(Stage, StageBindGroup)>,
}

impl ShadowTechnique for Levels {
    fn prepare(&mut self, ctx: &RenderContext<'_>, _: Changes) -> TechniqueResult {
        let mut errors = ERRORS.lock().unwrap();
        errors.clear();
        self.passes.clear();
        for light in 0..ctx.lights.len() {
            let stage = Stage::fullscreen("test/levels.wgsl", "fs_level")
                .text(SHADER)
                .build(ctx)?;
            let mut values = LEVELS.to_vec();
            values.push(light as f32);
            let buffer = (ctx.gpu.device).create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("test levels"),
                contents: zoo_host::bytemuck::cast_slice(&values),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let misnamed = [("levls", buffer.as_entire_binding())];
            errors.push(
                stage
                    .bind(ctx, "test", &misnamed)
                    .err()
                    .unwrap()
                    .to_string(),
            );
            // One list serves every entry of the shader: `offsets`, declared in the group but
            // not read by `fs_level`, is left out (and may come first).
            let shared_list = [
                ("offsets", buffer.as_entire_binding()),
                ("levels", buffer.as_entire_binding()),
            ];
            // Lists of groups the stage has not (`camera` is the host's) are skipped.
            let host = [("camera", buffer.as_entire_binding())];
            let mut groups = stage.bind_own(ctx, "test", &[&host, &shared_list])?;
            errors.push(format!("own groups: {}", groups.len()));
            self.passes.push((stage, groups.remove(0)));
        }
        let mixed = Stage::compute("test/mixed.wgsl", "cs_mixed")
            .text(MIXED)
            .build(ctx);
        errors.push(mixed.err().unwrap().to_string());
        errors.extend(joined(ctx)?);
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        for (light, (stage, group)) in self.passes.iter().enumerate() {
            let mut pass = ctx.light_pass(rec, "Test levels", light, None);
            stage.set_on(ctx, &mut pass, &[group], &[])?;
            pass.draw(0..3, 0..1);
        }
        Ok(())
    }
}

/// A stage whose group joins a shared one's: refused while the group is not joinable, built
/// once it is; binding it needs the shared variable too. Returns what each step said.
fn joined(ctx: &RenderContext<'_>) -> TechniqueResult<Vec<String>> {
    let device = &ctx.gpu.device;
    let layout = bind_group_layout(
        device,
        "test levels layout",
        &[storage(0, wgpu::ShaderStages::COMPUTE, true)],
    );
    let levels = NamedGroup {
        names: &["levels"],
        layout: &layout,
        group: None,
    };
    let build = |shared: &dyn SharedGroup| {
        Stage::compute("test/joined.wgsl", "cs_joined")
            .text(JOINED)
            .shared(&[shared])
            .build(ctx)
    };
    let mut said = vec![build(&levels).err().unwrap().to_string()];
    let stage = build(&Joinable(levels))?;
    let buffer = |label| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        })
    };
    let (levels, mine) = (buffer("test levels"), buffer("test mine"));
    let own_only = [("mine", mine.as_entire_binding())];
    said.push(
        stage
            .bind(ctx, "test", &own_only)
            .err()
            .unwrap()
            .to_string(),
    );
    let both = [
        ("levels", levels.as_entire_binding()),
        ("mine", mine.as_entire_binding()),
    ];
    said.push(match stage.bind(ctx, "test", &both) {
        Ok(_) => "joined group bound".into(),
        Err(e) => e.to_string(),
    });
    Ok(said)
}

zoo_host::register_technique! {
    id: "test-stage",
    name: "Test: stages",
    description: "Writes a level per light through a kit stage (test only)",
    source: "test",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    create: |_: &GpuContext, _: &ParamValues| {
        Ok(Box::new(Levels::default()) as Box<dyn ShadowTechnique>)
    },
}

#[test]
fn stages_bind_by_name_and_say_which_names_and_groups_are_wrong() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    assert_eq!(scene.lights.len(), LEVELS.len());
    let mut renderer = Renderer::new(gpu(), scene, UVec2::new(16, 16)).unwrap();
    renderer
        .set_technique("test-stage", &ParamValues::new())
        .unwrap();
    renderer.render(&View::Final).unwrap();
    for (light, level) in LEVELS.iter().enumerate() {
        let visibility = renderer.read_visibility(light);
        let off = visibility
            .iter()
            .filter(|v| (*v - level).abs() > 1.0 / 255.0);
        assert_eq!(off.count(), 0, "light {light} should read {level}");
    }
    let errors = ERRORS.lock().unwrap().clone();
    assert_eq!(errors.len(), 2 * LEVELS.len() + 4, "{errors:?}");
    assert!(
        (errors.iter()).filter(|e| *e == "own groups: 1").count() == LEVELS.len(),
        "{errors:?}"
    );
    assert!(
        errors[0].contains("test/levels.wgsl fullscreen_vs/fs_level")
            && errors[0].contains("`levls` is not a variable of the stage's own groups")
            && errors[0].contains("`levels`"),
        "{}",
        errors[0]
    );
    let [mixed, not_joinable, not_given, joined] = &errors[errors.len() - 4..] else {
        unreachable!("four checked above")
    };
    assert!(
        mixed.contains("test/mixed.wgsl cs_mixed")
            && mixed.contains("`camera` belongs to a shared group")
            && mixed.contains("`mine`"),
        "{mixed}"
    );
    assert!(
        not_joinable.contains("test/joined.wgsl cs_joined")
            && not_joinable.contains("`levels` belongs to a shared group")
            && not_joinable.contains("`mine`"),
        "{not_joinable}"
    );
    assert!(not_given.contains("`levels`"), "{not_given}");
    assert_eq!(joined, "joined group bound");
}
