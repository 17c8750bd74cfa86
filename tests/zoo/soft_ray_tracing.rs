//! Ray-traced soft shadows against PCSS on the same reference: four rays a pixel, averaged
//! over the frames of a still view and filtered, keep half of PCSS's mean error or less on the
//! standard soft scenes (`soft`: one large light; `many-lights`: 64 small ones).

// Link the application, which links every plugin.
use shadow_zoo as _;
use zoo_host::glam::UVec2;
use zoo_host::judging::{DEFAULT_SAMPLES, Judged, SceneReference, judge_technique};
use zoo_host::params::{apply_assignments, defaults};
use zoo_host::test_support::{counter, gpu, scene_path};
use zoo_host::{Renderer, Scene};

const SIZE: UVec2 = UVec2::new(192, 144);

/// `technique` with `assignments` judged against `reference`.
fn judged(
    renderer: &mut Renderer,
    reference: &SceneReference,
    technique: &str,
    assignments: &[(&str, &str)],
) -> Judged {
    let schema = (zoo_host::find_technique(technique).unwrap().params)();
    let mut values = defaults(&schema);
    let pairs: Vec<_> = (assignments.iter())
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    apply_assignments(&schema, &mut values, &pairs).unwrap();
    judge_technique(renderer, reference, technique, &values).unwrap()
}

/// The mean of the lights' mae.
fn mean_mae(judged: &Judged) -> f64 {
    let scores: Vec<_> = judged.scores.iter().filter_map(|s| s.metrics).collect();
    scores.iter().map(|m| m.mae).sum::<f64>() / scores.len() as f64
}

#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn accumulated_rays_keep_half_of_pcss_error_on_soft_scenes() {
    for scene in ["soft.ron", "many-lights.ron"] {
        let loaded = Scene::load(&scene_path(scene)).unwrap();
        let mut renderer = Renderer::new(gpu(), loaded, SIZE).unwrap();
        let reference = SceneReference::compute(&mut renderer, DEFAULT_SAMPLES, |_| {}).unwrap();
        let pcss = mean_mae(&judged(
            &mut renderer,
            &reference,
            "sm-pcf",
            &[("filter", "Pcss")],
        ));
        let rays = [("rays_per_pixel", "4")];
        let one_frame = [("accumulation", "1")];
        let single = judged(
            &mut renderer,
            &reference,
            "rt-shadows",
            &[rays, one_frame].concat(),
        );
        let accumulated = judged(&mut renderer, &reference, "rt-shadows", &rays);
        let frames = counter(
            &renderer.technique_instance().counters(),
            "frames accumulated",
        );
        let (single, accumulated) = (mean_mae(&single), mean_mae(&accumulated));
        eprintln!(
            "{scene}: PCSS mae {pcss:.4}; rt-shadows at 4 rays, filtered: one frame {single:.4}, \
             {frames:?} frames {accumulated:.4} ({:.2} of PCSS)",
            accumulated / pcss
        );
        assert_eq!(
            frames,
            Some(16.0),
            "{scene}: the judge lets the default 16 frames add up"
        );
        assert!(
            accumulated < single,
            "{scene}: accumulation lowers the error"
        );
        assert!(
            accumulated <= 0.5 * pcss,
            "{scene}: rt-shadows {accumulated:.4} against PCSS {pcss:.4}"
        );
    }
}
