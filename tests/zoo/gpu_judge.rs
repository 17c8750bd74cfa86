//! The GPU judge (`compare --judge gpu`) against the CPU judge, the arbiter, on every standard
//! scene: how many of the pixels each light reaches change class (hard shadow or lit), off the
//! reference's shadow edges and in all, and how far area visibility (and, behind translucent
//! casters, its colour) moves.

use glam::UVec2;
use shadow_zoo::gpu_judge::trace_reference;
use zoo_host::judge::edge_band;
use zoo_host::judging::SceneReference;
use zoo_host::test_support::{gpu, standard_scenes};
use zoo_host::{Renderer, Scene};

const SIZE: UVec2 = UVec2::new(96, 72);
const SAMPLES: u32 = 16;

#[test]
fn the_gpu_judge_agrees_with_the_cpu_judge_on_every_standard_scene() {
    let (mut cpu_seconds, mut gpu_seconds) = (0.0, 0.0);
    for path in standard_scenes() {
        let scene = Scene::load(&path).unwrap();
        let name = scene.name.clone();
        let mut renderer = Renderer::new(gpu(), scene, SIZE).unwrap();
        let cpu = SceneReference::compute(&mut renderer, SAMPLES, |_| {}).unwrap();
        let traced = trace_reference(&mut renderer, SAMPLES).unwrap();
        let (mut pixels, mut changed, mut changed_core) = (0usize, 0usize, 0usize);
        let mut area_difference = 0.0f64;
        let (mut colour_difference, mut coloured) = (0.0f64, 0usize);
        assert_eq!(
            cpu.lights[0].color.is_some(),
            traced.lights[0].color.is_some(),
            "{name}: both keep colours, or neither"
        );
        for (c, g) in cpu.lights.iter().zip(&traced.lights) {
            assert_eq!(c.contributing, g.contributing, "{name}");
            let band = edge_band(c, SIZE.x as usize, SIZE.y as usize);
            for i in (0..c.contributing.len()).filter(|&i| c.contributing[i]) {
                let differs = (c.hard[i] < 0.5) != (g.hard[i] < 0.5);
                pixels += 1;
                changed += usize::from(differs);
                changed_core += usize::from(differs && !band[i]);
                area_difference += f64::from((c.area[i] - g.area[i]).abs());
                // Behind translucent casters both keep the colour that arrives.
                if let (Some(cc), Some(gc)) = (&c.color, &g.color) {
                    colour_difference += f64::from((cc[i] - gc[i]).abs().max_element());
                    coloured += 1;
                }
            }
        }
        let share = |n: usize| n as f64 / pixels.max(1) as f64;
        let (all, core) = (share(changed), share(changed_core));
        let area = area_difference / pixels.max(1) as f64;
        eprintln!(
            "{name}: {pixels} lit pixels, class changed {all:.5} ({core:.5} off shadow edges), \
             area mean difference {area:.4}; traced in {:.2} s (CPU) and {:.2} s (GPU)",
            cpu.seconds, traced.seconds
        );
        cpu_seconds += cpu.seconds;
        gpu_seconds += traced.seconds;
        // On a shadow edge's pixels the two origins (the judge's exact surface, the G-buffer's
        // reconstruction) can fall either side of a silhouette: off the edges they agree.
        assert!(
            core <= 0.0002,
            "{name}: {core} of the pixels off shadow edges change class"
        );
        assert!(all <= 0.005, "{name}: {all} of the pixels change class");
        assert!(
            area <= 0.01,
            "{name}: area visibility differs by {area} on average"
        );
        let colour = colour_difference / coloured.max(1) as f64;
        if coloured > 0 {
            eprintln!("{name}: area colour differs by {colour:.4} on average (largest channel)");
        }
        assert!(colour <= 0.01, "{name}: area colour differs by {colour}");
    }
    eprintln!("all scenes: CPU {cpu_seconds:.1} s, GPU {gpu_seconds:.1} s");
}
