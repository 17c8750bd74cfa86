//! A scene around one model file: the model as it is, a ground under it, a camera that frames
//! it and a sun, a spot and a point light, all scaled to the model's size. Opening an OBJ or
//! glTF file where a scene is expected builds one ([`crate::Scene::load`]).

use std::path::Path;

use glam::Vec3;

use crate::{Scene, SceneError};

/// Whether `path` names a model file (`.obj`, `.gltf`, `.glb`) rather than a scene.
pub fn is_model(path: &Path) -> bool {
    let extension = path.extension().and_then(|e| e.to_str());
    extension.is_some_and(|e| ["obj", "gltf", "glb"].contains(&e.to_ascii_lowercase().as_str()))
}

/// The RON of a scene holding the model file `file` (a name beside the scene) as `mesh`,
/// with `setting` (camera, ambient and lights) and `objects` after the model.
fn scene_text(mesh: &str, file: &str, setting: &str, objects: &str) -> String {
    format!(
        "(name: {file:?}, {setting}\n objects: [(name: {file:?}, mesh: {mesh}({file:?}), \
         color: (0.8, 0.78, 0.74)), {objects}])"
    )
}

/// The scene around the model at `path` (see the module's description).
pub fn around_model(path: &Path) -> Result<Scene, SceneError> {
    let invalid = |message: String| SceneError::Invalid {
        path: path.to_path_buf(),
        field: "model".into(),
        message,
    };
    let file = (path.file_name().and_then(|f| f.to_str()))
        .ok_or_else(|| invalid("the file name is not UTF-8".into()))?;
    let mesh = match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("obj") => "Obj",
        _ => "Gltf",
    };
    let base = path.parent().unwrap_or(Path::new("."));
    // The model alone first, for its bounds.
    let alone = "camera: (position: (0, 0, 1), target: (0, 0, 0), fov_y_degrees: 50, near: 0.1, \
                 far: 100), lights: [Directional(direction: (0, -1, 0), color: (1, 1, 1), \
                 intensity: 1, angular_radius_degrees: 0.27)],";
    let probe = Scene::from_ron(&scene_text(mesh, file, alone, ""), path, base)?;
    let (lo, hi) = probe.bounds();
    let extent = lo.distance(hi);
    if !(extent.is_finite() && extent > 0.0) {
        return Err(invalid(format!(
            "the model has no extent (bounds {lo} to {hi})"
        )));
    }
    let center = (lo + hi) / 2.0;
    let v = |p: Vec3| format!("({:?}, {:?}, {:?})", p.x, p.y, p.z);
    let eye = center + Vec3::new(0.75, 0.55, 1.05) * extent;
    let point = center + Vec3::new(-0.6, 1.1, 0.5) * extent;
    let spot = center + Vec3::new(0.5, 1.3, 0.9) * extent;
    // Intensities fall off with the square of distance: the default scene's at its scale.
    let falloff = (extent / 5.0).powi(2);
    let setting = format!(
        "camera: (position: {eye}, target: {center}, fov_y_degrees: 50, near: {near:?}, far: {far:?}),
         ambient: (0.04, 0.04, 0.045),
         lights: [
             Directional(direction: (-0.35, -1.0, -0.45), color: (1.0, 1.0, 0.95), intensity: 0.35,
                         angular_radius_degrees: 0.27),
             Point(position: {point}, color: (1.0, 0.95, 0.85), intensity: {point_power:?},
                   range: {range:?}, radius: {radius:?}),
             Spot(position: {spot}, direction: {spot_direction}, color: (0.8, 0.9, 1.0),
                  intensity: {spot_power:?}, range: {range:?}, angle_degrees: 40, softness: 0.2,
                  radius: {radius:?}),
         ],",
        eye = v(eye),
        center = v(center),
        near = extent * 1e-3,
        far = extent * 50.0,
        point = v(point),
        point_power = 40.0 * falloff,
        range = extent * 10.0,
        radius = extent * 0.02,
        spot = v(spot),
        spot_direction = v(center - spot),
        spot_power = 50.0 * falloff,
    );
    let ground = format!(
        "(name: \"ground\", mesh: Plane(size: {size:?}), color: (0.75, 0.75, 0.72), \
         receiver: true, transform: (translation: {at}))",
        size = extent * 6.0,
        at = v(Vec3::new(center.x, lo.y, center.z)),
    );
    Scene::from_ron(&scene_text(mesh, file, &setting, &ground), path, base)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_is_staged_on_a_ground_it_rests_on_at_any_scale() {
        let dir = std::env::temp_dir().join(format!("zoo-stage-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for scale in [1e-3_f32, 1.0, 1e4] {
            let obj = dir.join(format!("tetra-{scale}.obj"));
            let s = scale;
            let text = format!(
                "v 0 0 0\nv {s} 0 0\nv 0 {s} 0\nv 0 0 {s}\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
            );
            std::fs::write(&obj, text).unwrap();
            let scene = around_model(&obj).unwrap();
            assert_eq!(scene.objects.len(), 2);
            assert_eq!(scene.lights.len(), 3);
            let (lo, hi) = scene.bounds();
            // The ground is at the model's foot and six times its size.
            assert_eq!(lo.y, 0.0);
            let extent = Vec3::splat(s).length();
            assert!(
                (hi.x - lo.x - 6.0 * extent).abs() <= 1e-3 * extent.max(1.0),
                "{lo} {hi}"
            );
            assert!(scene.camera.near < extent && scene.camera.far > 10.0 * extent);
        }
        let empty = dir.join("empty.obj");
        std::fs::write(&empty, "v 0 0 0\n").unwrap();
        assert!(around_model(&empty).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
