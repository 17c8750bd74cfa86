//! Instances on the GPU: every technique draws an instance's shared triangles where copies of
//! them would be, so it renders an instanced scene as it renders the scene with the triangles
//! copied.

use glam::UVec2;
use zoo_host::params::ParamValue;
use zoo_host::test_support::{cheapest_params, gpu, scene_path};
use zoo_host::{Renderer, Scene, View};

#[test]
fn every_technique_renders_instances_as_their_copies() {
    let path = scene_path("forest.ron");
    let description = zoo_host::scene::read_description(&path).unwrap();
    let base = path.parent().unwrap();
    let instanced = Scene::from_description(&description, &path, base).unwrap();
    let copies = description.instances_copied().unwrap();
    let copied = Scene::from_description(&copies, &path, base).unwrap();
    assert!(instanced.has_placed_objects() && !copied.has_placed_objects());
    assert_eq!(instanced.drawn_triangle_count(), copied.triangle_count());
    eprintln!(
        "forest: {} instanced, {} copied",
        instanced.triangle_summary(),
        copied.triangle_summary()
    );
    let size = UVec2::new(128, 96);
    let mut a = Renderer::new(gpu(), instanced, size).unwrap();
    let mut b = Renderer::new(gpu(), copied, size).unwrap();
    // Every technique at its cheapest, and the variants that read geometry another way: the
    // hybrid's exact test against the map's triangle ids, and a volume per triangle.
    let variants = [
        ("hybrid-edge", "restriction", "TriangleIds"),
        ("sv-zfail", "volumes", "PerTriangle"),
    ];
    let configurations = crate::shipped_techniques()
        .into_iter()
        .flat_map(|registration| {
            let values = cheapest_params(&(registration.params)());
            let variant = (variants.iter().filter(|(id, _, _)| *id == registration.id)).map(
                move |(_, key, choice)| {
                    let mut values = cheapest_params(&(registration.params)());
                    values.insert(key.to_string(), ParamValue::Choice(choice.to_string()));
                    (
                        registration,
                        format!("{} {key}={choice}", registration.id),
                        values,
                    )
                },
            );
            std::iter::once((registration, registration.id.to_string(), values)).chain(variant)
        });
    let mut differences = Vec::new();
    for (registration, label, values) in configurations {
        let frame = |renderer: &mut Renderer| {
            renderer.set_technique(registration.id, &values).unwrap();
            renderer.render(&View::Final).unwrap();
            assert_eq!(renderer.technique().id, registration.id, "disabled");
            renderer.read_output()
        };
        let (x, y) = (frame(&mut a), frame(&mut b));
        let off = x
            .pixels()
            .zip(y.pixels())
            .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > 3))
            .count() as f64
            / x.pixels().len() as f64;
        eprintln!("{label}: {off:.5} of the pixels differ by more than 3/255");
        differences.push((label, off));
    }
    for (id, off) in differences {
        // Placing vertices on the GPU rounds differently from placing them on the CPU, which
        // may move a pixel's coverage or a shadow-map texel on an edge (none moved on
        // lavapipe).
        assert!(off <= 0.0005, "{id}: {off} of the pixels differ");
    }
}
