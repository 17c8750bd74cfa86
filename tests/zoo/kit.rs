//! The technique kit's helpers: uniforms at the device's alignment, inline shaders with
//! imports, and slot writes that leave the other lights' channels untouched.

use glam::{UVec2, UVec3};
use zoo_host::ShaderLibrary;
use zoo_host::gpu::ShaderError;
use zoo_host::kit::{
    LightSlot, NamedTextures, TextureSize, TextureSpec, UniformSlots, UniformValue,
};
use zoo_host::render::frame::GpuLight;
use zoo_host::technique::{ViewMapping, VolumeAxis, VolumeSlice};
use zoo_host::test_support::gpu;
use zoo_host::wgpu;

#[test]
fn uniform_slots_follow_the_device_alignment_and_grow() {
    let gpu = gpu();
    let alignment = u64::from(gpu.device.limits().min_uniform_buffer_offset_alignment);
    let stages = zoo_host::wgpu::ShaderStages::FRAGMENT;
    let mut slots = UniformSlots::<GpuLight>::new(&gpu, "kit test", 2, stages);
    assert_eq!(slots.stride() % alignment, 0);
    assert!(slots.stride() >= <GpuLight as UniformValue>::SIZE as u64);
    assert_eq!(slots.offset(3) as u64, 3 * slots.stride());
    // More values than room: the buffer grows and keeps the stride.
    let scene =
        zoo_host::Scene::load(&zoo_host::test_support::scene_path("planar-room.ron")).unwrap();
    let light = GpuLight::new(&scene.lights[0], (0, 0));
    slots.write(&gpu, &[light; 9]);
    assert!(slots.buffer().size() >= 9 * slots.stride());
    assert!(gpu.take_uncaptured_errors().is_empty());
}

#[test]
fn inline_shaders_resolve_imports_and_report_their_own_lines() {
    let library = ShaderLibrary::embedded();
    let text =
        "#import \"common/frame.wgsl\"\n\nfn eye() -> vec3<f32> { return camera.position; }\n";
    let composed = library
        .compose_source("my-technique (inline)", text)
        .unwrap();
    assert!(composed.source.contains("struct Camera"));
    assert!(composed.source.contains("fn eye()"));
    let device = &gpu().device;
    library
        .create_module_from_source(device, "my-technique (inline)", text)
        .unwrap();
    let broken = "#import \"common/frame.wgsl\"\n\nfn eye() -> vec3<f32> { return nope; }\n";
    match library.create_module_from_source(device, "my-technique (inline)", broken) {
        Err(ShaderError::Compile { file, line, .. }) => {
            assert_eq!((file.as_str(), line), ("my-technique (inline)", 3));
        }
        other => panic!("expected a compile error at line 3, got {other:?}"),
    }
}

#[test]
fn light_slots_select_one_channel_each() {
    use zoo_host::Renderer;
    use zoo_host::glam::UVec2;
    let scene =
        zoo_host::Scene::load(&zoo_host::test_support::scene_path("planar-room.ron")).unwrap();
    let renderer = Renderer::new(gpu(), scene, UVec2::new(16, 16)).unwrap();
    let (layer_of, channels): (Vec<u32>, Vec<[f64; 4]>) = (0..3)
        .map(|light| {
            let LightSlot {
                blend_constant: c, ..
            } = renderer.visibility().light_slot(light);
            (renderer.slots().slot(light).0, [c.r, c.g, c.b, c.a])
        })
        .unzip();
    assert_eq!(layer_of, [0, 0, 0]);
    assert_eq!(
        channels,
        [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0]
        ]
    );
}

#[test]
fn readback_ring_delivers_the_newest_results_without_waiting() {
    use zoo_host::gpu::readback::ReadbackRing;
    use zoo_host::wgpu::util::DeviceExt;
    let gpu = gpu();
    let device = &gpu.device;
    let mut ring = ReadbackRing::new(device, "kit test", 8, 2);
    let frame = |ring: &mut ReadbackRing, value: u32| -> bool {
        let Some(target) = ring.target().cloned() else {
            return false;
        };
        let source = device.create_buffer_init(&zoo_host::wgpu::util::BufferInitDescriptor {
            label: Some("kit test source"),
            contents: zoo_host::bytemuck::cast_slice(&[value, value + 1]),
            usage: zoo_host::wgpu::BufferUsages::COPY_SRC,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&source, 0, &target, 0, 8);
        gpu.queue.submit([encoder.finish()]);
        true
    };
    assert!(ring.latest(device).is_none(), "nothing was written yet");
    assert!(frame(&mut ring, 10));
    assert!(frame(&mut ring, 20));
    // Both buffers hold unread results: the oldest is reused, so frames are never skipped
    // while nobody reads, and the newest result is the last frame's.
    assert!(frame(&mut ring, 30));
    gpu.wait_idle();
    let _ = ring.latest(device);
    gpu.wait_idle();
    let (frame_index, bytes) = ring.latest(device).expect("results arrived");
    assert_eq!(frame_index, 3);
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(words, [30, 31]);
    // The buffers are free again.
    assert!(frame(&mut ring, 40));
}

#[test]
fn textures_are_made_again_only_when_their_shape_or_the_output_changes() {
    let gpu = gpu();
    let format = wgpu::TextureFormat::R8Uint;
    let layered = TextureSpec {
        name: "layered",
        size: TextureSize::Screen { divisor: 2 },
        layers: 3,
        ..TextureSpec::screen_target("layered", format, None)
    };
    let mut named = NamedTextures::new(
        "test",
        [
            TextureSpec::screen_target("ids", format, Some(ViewMapping::Integer)),
            layered,
        ],
    );
    assert!(named.resources().is_empty() && named.view("ids").is_none());
    let screen = UVec2::new(16, 8);
    assert!(named.prepare_at(&gpu, screen));
    assert!(!named.prepare_at(&gpu, screen), "nothing changed");
    let texture = named.texture("ids").unwrap().clone();
    // A new view is not a new texture.
    named.respec("ids", |s| {
        s.view = Some(ViewMapping::Color { min: 0.0, max: 1.0 })
    });
    assert!(!named.prepare_at(&gpu, screen));
    assert_eq!(named.texture("ids").unwrap(), &texture);
    let shown = named.debug_view("ids").unwrap().mapping;
    assert_eq!(shown, ViewMapping::Color { min: 0.0, max: 1.0 });
    assert!(named.debug_view("layered").is_none(), "not viewable");
    assert!(named.layer_view("layered", 2).is_some());
    assert!(named.layer_view("layered", 3).is_none());
    let listed: Vec<_> = (named.resources().into_iter())
        .map(|r| (r.name, r.size, r.viewable))
        .collect();
    assert_eq!(
        listed,
        [
            ("ids".to_string(), [16, 8, 1], true),
            ("layered".to_string(), [8, 4, 3], false)
        ]
    );
    // A new output size or shape makes them again.
    assert!(named.prepare_at(&gpu, UVec2::new(32, 8)));
    assert_ne!(named.texture("ids").unwrap(), &texture);
    named.respec("layered", |s| s.layers = 4);
    assert!(named.prepare_at(&gpu, UVec2::new(32, 8)));
    assert_eq!(named.resources()[1].size, [16, 4, 4]);
    assert!(gpu.take_uncaptured_errors().is_empty());
}

#[test]
fn volumes_one_layer_arrays_and_aliases_are_made_and_shown_as_declared() {
    let gpu = gpu();
    let color = |max| ViewMapping::Color { min: 0.0, max };
    let volume = TextureSpec {
        size: TextureSize::Volume(UVec3::new(4, 4, 8)),
        usage: wgpu::TextureUsages::STORAGE_BINDING,
        aliases: vec![("grid b", color(2.0))],
        ..TextureSpec::screen_target("grid a", wgpu::TextureFormat::Rgba16Float, Some(color(1.0)))
    };
    let array = TextureSpec {
        size: TextureSize::Fixed(UVec2::new(16, 8)),
        array: true,
        ..TextureSpec::screen_target("array", wgpu::TextureFormat::R8Unorm, Some(color(1.0)))
    };
    let mut named = NamedTextures::new("test", [volume, array]);
    assert!(named.prepare_at(&gpu, UVec2::new(16, 8)));
    let grid = named.texture("grid a").unwrap();
    assert_eq!(grid.dimension(), wgpu::TextureDimension::D3);
    assert_eq!(grid.depth_or_array_layers(), 8);
    assert!(
        named.layer_view("grid a", 0).is_none(),
        "a volume has no layers"
    );
    // A volume is shown as a slice, under each of its names, never as a 2D image.
    let slice = VolumeSlice {
        axis: VolumeAxis::Z,
        index: 3,
    };
    assert!(named.debug_view("grid b").is_none());
    assert_eq!(
        named.debug_volume("grid b", slice).unwrap().mapping,
        color(2.0)
    );
    assert_eq!(named.debug_volume("grid a", slice).unwrap().slice, slice);
    assert!(named.debug_volume("array", slice).is_none());
    assert_eq!(named.debug_view("array").unwrap().mapping, color(1.0));
    assert!(named.layer_view("array", 0).is_some());
    // The alias is listed after its texture, with no memory of its own.
    let listed: Vec<_> = (named.resources().into_iter())
        .map(|r| (r.name, r.size, r.bytes > 0))
        .collect();
    assert_eq!(
        listed,
        [
            ("grid a".to_string(), [4, 4, 8], true),
            ("grid b".to_string(), [4, 4, 8], false),
            (
                "array".to_string(),
                [
                    16,
                    8,
                    named.texture("array").unwrap().depth_or_array_layers()
                ],
                true
            ),
        ]
    );
    // Neither follows the output's size.
    assert!(!named.prepare_at(&gpu, UVec2::new(32, 8)));
    assert!(gpu.take_uncaptured_errors().is_empty());
}
