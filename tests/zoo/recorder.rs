//! The pass recorder times every pass of a frame, however many: frames with thousands of
//! passes (hundreds of lights with six cube faces each) take further query chunks.

use zoo_host::gpu::{PASSES_PER_CHUNK, PassRecorder, StatisticsQueries, TimestampQueries};
use zoo_host::test_support::gpu;
use zoo_host::wgpu;

#[test]
fn every_pass_of_a_long_frame_is_timed() {
    let gpu = gpu();
    let Some(queries) = TimestampQueries::new(&gpu) else {
        eprintln!("skipped: {} has no timestamp queries", gpu.describe());
        return;
    };
    let statistics = StatisticsQueries::new(&gpu);
    let (_, view) = zoo_host::gpu::render_target(
        &gpu.device,
        "recorder test target",
        zoo_host::glam::UVec2::new(64, 64),
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::empty(),
    );
    let count = 2 * PASSES_PER_CHUNK as usize + 300;
    for frame in 0..2 {
        let mut recorder =
            PassRecorder::new(&gpu, Some(&queries)).with_statistics(statistics.as_ref());
        for i in 0..count {
            let label = format!("clear {i}");
            let attachments = [zoo_host::gpu::color_attachment(
                &view,
                wgpu::LoadOp::Clear(wgpu::Color::WHITE),
            )];
            drop(recorder.render_pass(&zoo_host::gpu::color_pass(&label, &attachments)));
        }
        let timings = recorder.finish();
        assert_eq!(timings.passes.len(), count, "frame {frame}");
        for (i, pass) in timings.passes.iter().enumerate() {
            assert_eq!(pass.name, format!("clear {i}"));
            assert!(pass.milliseconds.is_finite() && pass.milliseconds >= 0.0);
        }
        // Every chunk measured its passes: as many timed (non-zero) passes after the first
        // chunk as in it, proportionally.
        let timed = |range: std::ops::Range<usize>| {
            let n = range.len();
            let nonzero = timings.passes[range]
                .iter()
                .filter(|p| p.milliseconds > 0.0)
                .count();
            nonzero as f64 / n as f64
        };
        let first = timed(0..PASSES_PER_CHUNK as usize);
        let later = timed(PASSES_PER_CHUNK as usize..count);
        assert!(first > 0.5, "the first chunk's passes were timed ({first})");
        assert!(
            later > 0.5 * first,
            "passes after the first chunk read 0 ms ({later} vs {first})"
        );
        if statistics.is_some() {
            let counted = timings.passes.iter().filter(|p| p.counts.is_some()).count();
            assert_eq!(counted, count, "pipeline statistics for every pass");
        }
    }
    assert!(gpu.take_uncaptured_errors().is_empty());
}

/// A depth-only pipeline drawing the screen-covering triangle at depth 0 (`common/fullscreen`).
fn depth_only_pipeline(
    gpu: &zoo_host::GpuContext,
    compare: wgpu::CompareFunction,
) -> wgpu::RenderPipeline {
    let shader = zoo_host::ShaderLibrary::embedded()
        .load(&gpu.device, "common/fullscreen.wgsl", None)
        .expect("the fullscreen shader");
    gpu.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("recorder test depth-only pipeline"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &shader.module,
                entry_point: Some("fullscreen_vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(false),
                depth_compare: Some(compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        })
}

#[test]
fn render_passes_count_the_samples_that_pass_the_depth_and_stencil_tests() {
    let gpu = gpu();
    let Some(statistics) = StatisticsQueries::new(&gpu) else {
        eprintln!("skipped: {} has no pipeline statistics", gpu.describe());
        return;
    };
    let depth = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("recorder test depth"),
        size: wgpu::Extent3d {
            width: 64,
            height: 64,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = depth.create_view(&Default::default());
    let less = depth_only_pipeline(&gpu, wgpu::CompareFunction::Less);
    // Three draws of the screen at depth 0 over depth cleared to `clear`, in a 10 x 7 scissor
    // where given; compute passes between them take no query.
    let draws: [(f32, Option<[u32; 4]>); 4] = [
        (1.0, None),
        (1.0, Some([5, 9, 10, 7])),
        (0.0, None),
        (0.5, Some([56, 60, 8, 2])),
    ];
    let mut recorder = PassRecorder::new(&gpu, None).with_statistics(Some(&statistics));
    for (k, (clear, scissor)) in draws.iter().enumerate() {
        drop(recorder.compute_pass(&format!("empty compute {k}")));
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some(&format!("draw {k}")),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(*clear),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&less);
        if let Some([x, y, w, h]) = scissor {
            pass.set_scissor_rect(*x, *y, *w, *h);
        }
        pass.draw(0..3, 0..1);
    }
    let timings = recorder.finish();
    let samples: Vec<(String, u64)> = (timings.passes.iter())
        .map(|p| (p.name.clone(), p.counts.expect("counted").samples_passed))
        .collect();
    let expected: Vec<(String, u64)> = (0..4)
        .flat_map(|k| {
            let drawn = [64 * 64, 70, 0, 16][k];
            [
                (format!("empty compute {k}"), 0),
                (format!("draw {k}"), drawn),
            ]
        })
        .collect();
    assert_eq!(samples, expected);
    assert!(gpu.take_uncaptured_errors().is_empty());
}
