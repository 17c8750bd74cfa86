//! Variance shadow maps beside percentage-closer filtering: the same accuracy on planar-room,
//! and on stacked casters the light bleeding that only the moments show.

// Link the application, which links every plugin.
use shadow_zoo as _;
use zoo_host::glam::UVec2;
use zoo_host::test_support::judge;

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
        let (moments, depths) = (vsm.umbra_leak(light), pcf.umbra_leak(light));
        eprintln!("stacked light {light}: umbra leak vsm {moments:.5}, pcf {depths:.5}");
        assert!(
            moments > 4.0 * depths,
            "light {light}: {moments} vs {depths}"
        );
    }
}

#[test]
fn higher_moments_bleed_less_light_under_stacked_casters() {
    // Reductions off and a wide blur, as in vsm's own bleeding test: MSM < EVSM4 < VSM.
    let params = [
        ("map_size", "512"),
        ("blur_radius", "16"),
        ("bleeding_reduction", "0"),
    ];
    let runs =
        ["msm", "evsm4", "vsm"].map(|technique| judge("stacked.ron", technique, &params, SIZE));
    for light in 0..runs[0].loaded.lights.len() {
        let leaks = runs.each_ref().map(|run| run.umbra_leak(light));
        let maes = runs.each_ref().map(|run| run.metrics(light).mae);
        eprintln!(
            "stacked light {light}: umbra leak msm / evsm4 / vsm {:.5} / {:.5} / {:.5}; mae {:.5} / {:.5} / {:.5}",
            leaks[0], leaks[1], leaks[2], maes[0], maes[1], maes[2]
        );
        assert!(
            leaks[0] < leaks[1] && leaks[1] < leaks[2],
            "light {light}: bleeding not ordered MSM < EVSM4 < VSM: {leaks:?}"
        );
    }
}
