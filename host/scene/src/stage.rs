//! A scene around one model file: the model as it is, a ground under it, a camera that frames
//! it and a sun, a spot and a point light, all scaled to the model's size. Opening an OBJ or
//! glTF file where a scene is expected builds one ([`crate::Scene::load`],
//! [`crate::read_description`]).

use std::path::Path;

use glam::Vec3;

use crate::description::SceneDescription;
use crate::{Scene, SceneError, parse_description};

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
    let base = path.parent().unwrap_or(Path::new("."));
    Scene::from_description(&description(path)?, path, base)
}

/// The description of the scene around the model at `path`: the model is loaded once, alone,
/// for its bounds.
pub fn description(path: &Path) -> Result<SceneDescription, SceneError> {
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
        "camera: (position: {eye}, target: {center}, fov_y_degrees: 50, near: {near:?},
                  far: {far:?}),
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
    parse_description(&scene_text(mesh, file, &setting, &ground), path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_is_staged_on_a_ground_at_its_foot_at_any_scale() {
        let dir = std::env::temp_dir().join(format!("zoo-stage-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for s in [1e-3_f32, 1.0, 1e4] {
            // A tetrahedron of side `s` away from the origin.
            let at = Vec3::new(3.0, 5.0, -2.0) * s;
            let corners = [Vec3::ZERO, Vec3::X * s, Vec3::Y * s, Vec3::Z * s].map(|c| c + at);
            let mut text = String::new();
            for c in corners {
                text += &format!("v {} {} {}\n", c.x, c.y, c.z);
            }
            text += "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
            let obj = dir.join(format!("tetra-{s}.obj"));
            std::fs::write(&obj, text).unwrap();
            let scene = around_model(&obj).unwrap();
            assert_eq!(scene.lights.len(), 3);
            let bounds = scene.each_object_bounds();
            let ((model_lo, model_hi), (ground_lo, ground_hi)) =
                (bounds[0].unwrap(), bounds[1].unwrap());
            let extent = model_lo.distance(model_hi);
            let close = |a: f32, b: f32| (a - b).abs() <= 1e-4 * extent;
            // The ground is flat at the model's foot, six times its size, centred under it.
            assert!(close(ground_lo.y, model_lo.y) && close(ground_hi.y, model_lo.y));
            assert!(
                close(ground_hi.x - ground_lo.x, 6.0 * extent),
                "{ground_lo} {ground_hi}"
            );
            let centre = (model_lo + model_hi) / 2.0;
            assert!(close((ground_lo.x + ground_hi.x) / 2.0, centre.x));
            // The camera looks at the model from outside it, its planes around it.
            assert!(scene.camera.position.distance(centre) > extent);
            assert!(scene.camera.near < extent && scene.camera.far > 10.0 * extent);
            // A model path works wherever a scene file does.
            assert_eq!(crate::read_description(&obj).unwrap().objects.len(), 2);
        }
        let empty = dir.join("empty.obj");
        std::fs::write(&empty, "v 0 0 0\n").unwrap();
        assert!(around_model(&empty).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
