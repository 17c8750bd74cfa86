//! The lights panel (add, remove, edit) and dragging lights in the view.

use zoo_host::glam::{Mat4, Vec2, Vec3};
use zoo_host::scene::{Camera, Light, LightKind, MAX_LIGHTS};

/// Where a light's handle is drawn and grabbed. Point and spot lights: their position.
/// Directional lights: a proxy point `reach` away from `centre`, against the light's travel.
pub fn handle_position(light: &Light, centre: Vec3, reach: f32) -> Vec3 {
    match light.kind {
        LightKind::Directional => centre - light.direction * reach,
        LightKind::Point | LightKind::Spot => light.position,
    }
}

/// Moves `light` so its handle lands on `handle` (a directional light turns to shine from
/// there toward `centre`).
pub fn move_handle(light: &mut Light, handle: Vec3, centre: Vec3) {
    match light.kind {
        LightKind::Directional => {
            let direction = (centre - handle).normalize_or_zero();
            if direction != Vec3::ZERO {
                light.direction = direction;
            }
        }
        LightKind::Point | LightKind::Spot => light.position = handle,
    }
}

/// Projects `point` to view coordinates in points (origin top-left of a `view_size` image);
/// `None` behind the camera.
pub fn project(view_proj: Mat4, point: Vec3, view_size: Vec2) -> Option<Vec2> {
    let clip = view_proj * point.extend(1.0);
    if clip.w <= 1e-6 {
        return None;
    }
    let ndc = clip.truncate() / clip.w;
    Some(Vec2::new(
        (ndc.x * 0.5 + 0.5) * view_size.x,
        (0.5 - ndc.y * 0.5) * view_size.y,
    ))
}

/// The world-space move of a point at `point` that follows a drag of `delta` points on a view
/// `view_height` points tall: in the plane facing the camera, so the point stays under the
/// mouse.
pub fn drag_in_view_plane(camera: &Camera, point: Vec3, delta: Vec2, view_height: f32) -> Vec3 {
    let forward = (camera.target - camera.position).normalize_or_zero();
    let up_hint = if forward.cross(Vec3::Y).length_squared() < 1e-6 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let right = forward.cross(up_hint).normalize_or_zero();
    let up = right.cross(forward);
    let depth = (point - camera.position).dot(forward).max(camera.near);
    let world_per_point = 2.0 * depth * (camera.fov_y * 0.5).tan() / view_height.max(1.0);
    (right * delta.x - up * delta.y) * world_per_point
}

/// A new point light at `position` suited to a scene of diagonal `extent`.
pub fn new_point_light(position: Vec3, extent: f32) -> Light {
    Light {
        kind: LightKind::Point,
        position,
        direction: Vec3::NEG_Y,
        radiance: Vec3::splat(8.0),
        range: extent.max(1.0),
        spot_angle: 35f32.to_radians(),
        spot_softness: 0.2,
        radius: 0.0,
    }
}

/// Changes `light`'s kind, giving the new kind sensible values where the old had none.
pub fn set_kind(light: &mut Light, kind: LightKind, extent: f32) {
    if light.kind == kind {
        return;
    }
    if light.kind == LightKind::Directional {
        // Radius was an angle; range was infinite.
        light.radius = 0.0;
        light.range = extent.max(1.0);
    }
    match kind {
        LightKind::Directional => {
            light.radius = 0.0;
            light.range = f32::INFINITY;
            light.radiance = light.radiance.min(Vec3::splat(4.0));
        }
        LightKind::Spot if light.spot_angle <= 0.0 => light.spot_angle = 35f32.to_radians(),
        _ => {}
    }
    light.kind = kind;
}

/// What the lights panel did this frame.
#[derive(Debug, Default)]
pub struct LightEdits {
    pub changed: bool,
    pub add: bool,
    pub remove: Option<usize>,
}

/// The lights panel: a list to pick from, add/remove buttons and the selected light's fields.
pub fn lights_panel(
    ui: &mut egui::Ui,
    lights: &mut [Light],
    selected: &mut usize,
    extent: f32,
) -> LightEdits {
    let mut edits = LightEdits::default();
    light_list(ui, lights, selected);
    ui.horizontal(|ui| {
        edits.add = ui
            .add_enabled(lights.len() < MAX_LIGHTS, egui::Button::new("Add light"))
            .clicked();
        edits.remove = ui
            .add_enabled(lights.len() > 1, egui::Button::new("Remove light"))
            .on_hover_text("A scene keeps at least one light")
            .clicked()
            .then_some(*selected);
    });
    let Some(light) = lights.get_mut(*selected) else {
        return edits;
    };
    let mut changed = kind_edit(ui, light, extent);
    changed |= radiance_edit(ui, light);
    if light.kind == LightKind::Directional {
        changed |= angular_radius_edit(ui, light);
    } else {
        changed |= emitter_edit(ui, light, extent);
    }
    if light.kind == LightKind::Spot {
        changed |= spot_edit(ui, light);
    }
    if light.kind != LightKind::Point {
        changed |= direction_edit(ui, light);
    }
    ui.label("Drag a light's handle in the view to move it.");
    edits.changed = changed;
    edits
}

/// The lights by index and kind; clicking one selects it.
fn light_list(ui: &mut egui::Ui, lights: &[Light], selected: &mut usize) {
    ui.horizontal_wrapped(|ui| {
        for (i, light) in lights.iter().enumerate() {
            let label = format!("{i}: {}", light.kind.name());
            if ui.selectable_label(*selected == i, label).clicked() {
                *selected = i;
            }
        }
    });
}

/// The light's kind; returns whether it changed.
fn kind_edit(ui: &mut egui::Ui, light: &mut Light, extent: f32) -> bool {
    let mut kind = light.kind;
    egui::ComboBox::from_label("kind")
        .selected_text(kind.name())
        .show_ui(ui, |ui| {
            for k in LightKind::ALL {
                ui.selectable_value(&mut kind, k, k.name());
            }
        });
    if kind == light.kind {
        return false;
    }
    set_kind(light, kind, extent);
    true
}

/// The light's colour and intensity, stored together as radiance; returns whether either
/// changed.
fn radiance_edit(ui: &mut egui::Ui, light: &mut Light) -> bool {
    let intensity = light.radiance.max_element();
    let mut colour = if intensity > 0.0 {
        (light.radiance / intensity).to_array()
    } else {
        [1.0; 3]
    };
    let mut new_intensity = intensity;
    let mut changed = false;
    ui.horizontal(|ui| {
        changed |= ui.color_edit_button_rgb(&mut colour).changed();
        ui.label("colour");
    });
    changed |= ui
        .add(
            egui::Slider::new(&mut new_intensity, 0.0..=100.0)
                .logarithmic(true)
                .text("intensity"),
        )
        .changed();
    light.radiance = Vec3::from(colour) * new_intensity;
    changed
}

/// A directional light's angular radius, in degrees; returns whether it changed.
fn angular_radius_edit(ui: &mut egui::Ui, light: &mut Light) -> bool {
    let mut degrees = light.radius.to_degrees();
    let changed = ui
        .add(egui::Slider::new(&mut degrees, 0.0..=10.0).text("angular radius (°)"))
        .on_hover_text("Half-angle of the emitter disc, for soft shadows")
        .changed();
    light.radius = degrees.to_radians();
    changed
}

/// A point or spot light's emitter radius, range and position; returns whether any changed.
fn emitter_edit(ui: &mut egui::Ui, light: &mut Light, extent: f32) -> bool {
    let mut changed = ui
        .add(egui::Slider::new(&mut light.radius, 0.0..=extent * 0.1).text("radius"))
        .on_hover_text("Emitter radius, for soft shadows")
        .changed();
    changed |= ui
        .add(
            egui::Slider::new(&mut light.range, 0.05..=extent * 4.0)
                .logarithmic(true)
                .text("range"),
        )
        .changed();
    ui.horizontal(|ui| {
        ui.label("position");
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            let label = ui.label(name);
            changed |= ui
                .add(egui::DragValue::new(&mut light.position[axis]).speed(0.02))
                .labelled_by(label.id)
                .changed();
        }
    });
    changed
}

/// A spot light's cone angle and softness; returns whether either changed.
fn spot_edit(ui: &mut egui::Ui, light: &mut Light) -> bool {
    let mut degrees = light.spot_angle.to_degrees();
    let mut changed = ui
        .add(egui::Slider::new(&mut degrees, 1.0..=89.0).text("spot angle (°)"))
        .changed();
    light.spot_angle = degrees.to_radians();
    changed |= ui
        .add(egui::Slider::new(&mut light.spot_softness, 0.0..=1.0).text("spot softness"))
        .changed();
    changed
}

/// The light's direction as yaw and pitch; returns whether it was turned.
fn direction_edit(ui: &mut egui::Ui, light: &mut Light) -> bool {
    let mut yaw = light.direction.x.atan2(light.direction.z).to_degrees();
    let mut pitch = light.direction.y.clamp(-1.0, 1.0).asin().to_degrees();
    let mut turned = ui
        .add(egui::Slider::new(&mut yaw, -180.0..=180.0).text("direction yaw (°)"))
        .changed();
    turned |= ui
        .add(egui::Slider::new(&mut pitch, -90.0..=90.0).text("direction pitch (°)"))
        .changed();
    if turned {
        let (sy, cy) = yaw.to_radians().sin_cos();
        let (sp, cp) = pitch.to_radians().sin_cos();
        light.direction = Vec3::new(sy * cp, sp, cy * cp).normalize();
    }
    turned
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 2.0, 10.0),
            target: Vec3::new(0.0, 2.0, 0.0),
            fov_y: 60f32.to_radians(),
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn a_dragged_point_stays_under_the_mouse() {
        let camera = camera();
        let size = Vec2::new(400.0, 300.0);
        let view_proj = camera.projection(size.x / size.y) * camera.view();
        let point = Vec3::new(1.0, 3.0, -2.0);
        let before = project(view_proj, point, size).unwrap();
        let delta = Vec2::new(37.0, -21.0);
        let moved = point + drag_in_view_plane(&camera, point, delta, size.y);
        let after = project(view_proj, moved, size).unwrap();
        assert!(
            (after - before - delta).length() < 1e-2,
            "{before} -> {after}"
        );
        // The move keeps the depth.
        assert!((moved.z - point.z).abs() < 1e-5);
    }

    #[test]
    fn points_behind_the_camera_have_no_handle() {
        let camera = camera();
        let view_proj = camera.projection(1.0) * camera.view();
        assert!(project(view_proj, Vec3::new(0.0, 2.0, 20.0), Vec2::splat(100.0)).is_none());
        let centre = project(view_proj, camera.target, Vec2::splat(100.0)).unwrap();
        assert!((centre - Vec2::splat(50.0)).length() < 1e-3);
    }

    #[test]
    fn directional_handles_turn_the_light() {
        let mut light = new_point_light(Vec3::ZERO, 10.0);
        set_kind(&mut light, LightKind::Directional, 10.0);
        assert_eq!(light.range, f32::INFINITY);
        let centre = Vec3::new(0.0, 1.0, 0.0);
        light.direction = Vec3::new(0.0, -1.0, 0.0);
        let handle = handle_position(&light, centre, 5.0);
        assert!(handle.abs_diff_eq(Vec3::new(0.0, 6.0, 0.0), 1e-6));
        move_handle(&mut light, Vec3::new(5.0, 6.0, 0.0), centre);
        assert!(
            light
                .direction
                .abs_diff_eq(Vec3::new(-1.0, -1.0, 0.0).normalize(), 1e-6)
        );
        // Back to a point light: a finite range again.
        set_kind(&mut light, LightKind::Point, 10.0);
        assert!(light.range.is_finite() && light.range > 0.0);
        move_handle(&mut light, Vec3::ONE, centre);
        assert_eq!(light.position, Vec3::ONE);
    }
}
