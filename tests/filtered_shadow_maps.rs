//! Variance shadow maps beside percentage-closer filtering: the same accuracy on planar-room,
//! and on stacked casters the light bleeding that only the moments show.

// Link the application, which links every plugin.
use shadow_zoo as _;
use zoo_host::glam::UVec2;
use zoo_host::test_support::{JudgeRun, judge};

const SIZE: UVec2 = UVec2::new(256, 256);

#[test]
fn filtered_moments_are_as_accurate_as_pcf() {
    let vsm = judge("planar-room.ron", "vsm", &[], SIZE);
    let pcf = judge("planar-room.ron", "sm-pcf", &[], SIZE);
    let pcss = judge("planar-room.ron", "sm-pcf", &[("filter", "Pcss")], SIZE);
    for light in 0..vsm.loaded.lights.len() {
        let (v, p, s) = (
            vsm.metrics(light).mae,
            pcf.metrics(light).mae,
            pcss.metrics(light).mae,
        );
        eprintln!("planar-room light {light}: mae vsm {v:.5}, pcf 3x3 {p:.5}, pcss {s:.5}");
        // A 5-tap Gaussian over the moments filters about as wide as 3x3 PCF.
        assert!(
            v <= 1.2 * p + 1e-4,
            "light {light}: vsm {v} against pcf {p}"
        );
    }
}

/// Mean visibility where the area reference sees none of light `light` (contributing pixels).
fn umbra_leak(run: &JudgeRun, light: usize) -> f64 {
    let reference = &run.reference.lights[light];
    let visibility = &run.judged.visibility[light];
    let umbra: Vec<usize> = (0..visibility.len())
        .filter(|&i| reference.contributing[i] && reference.area[i] == 0.0)
        .collect();
    assert!(umbra.len() > 500, "stacked has an umbra in view");
    umbra.iter().map(|&i| visibility[i] as f64).sum::<f64>() / umbra.len() as f64
}

#[test]
fn only_the_moments_bleed_light_under_stacked_casters() {
    let vsm = judge(
        "stacked.ron",
        "vsm",
        &[
            ("map_size", "512"),
            ("blur_radius", "16"),
            ("bleeding_reduction", "0"),
        ],
        SIZE,
    );
    let pcf = judge("stacked.ron", "sm-pcf", &[("map_size", "512")], SIZE);
    for light in 0..vsm.loaded.lights.len() {
        let (moments, depths) = (umbra_leak(&vsm, light), umbra_leak(&pcf, light));
        eprintln!("stacked light {light}: umbra leak vsm {moments:.5}, pcf {depths:.5}");
        assert!(
            moments > 4.0 * depths,
            "light {light}: {moments} vs {depths}"
        );
    }
}
