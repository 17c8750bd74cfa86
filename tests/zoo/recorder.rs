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
            let counted = timings
                .passes
                .iter()
                .filter(|p| p.invocations.is_some())
                .count();
            assert_eq!(counted, count, "pipeline statistics for every pass");
        }
    }
    assert!(gpu.take_uncaptured_errors().is_empty());
}
