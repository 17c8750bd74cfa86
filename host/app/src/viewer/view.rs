//! The central 3D view: the rendered image (or A/B split or difference), light handles,
//! the reference error map, and mouse and keyboard camera control.

use zoo_host::glam::{Vec2, Vec3};

use super::camera::FlyInput;
use super::lights;
use super::split::SplitMode;
use super::state::ViewerState;

/// Textures the window registered for the renderers' images.
#[derive(Debug, Clone, Copy, Default)]
pub struct ViewImages {
    /// The main (A) image.
    pub a: Option<egui::TextureId>,
    /// The B image in A/B mode.
    pub b: Option<egui::TextureId>,
    /// The A/B difference image.
    pub difference: Option<egui::TextureId>,
}

/// Points within which a click or drag grabs a light handle.
const HANDLE_GRAB_RADIUS: f32 = 12.0;
const FULL_UV: egui::Rect = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));

fn vec2(v: egui::Vec2) -> Vec2 {
    Vec2::new(v.x, v.y)
}

/// The colour the window is cleared to each frame: the panels' (which paint no fill of their
/// own).
pub fn clear_color(visuals: &egui::Visuals) -> [f32; 4] {
    visuals.panel_fill.to_normalized_gamma_f32()
}

impl ViewerState {
    /// The whole window: controls left, tools right, timings at the bottom, the view in the
    /// middle.
    pub fn ui(&mut self, ui: &mut egui::Ui, images: ViewImages) {
        // No panel fills: the window is cleared to the panels' colour ([`clear_color`]) and the
        // view's images cover the middle. On software adapters the window's own drawing bounds
        // the frame rate, and each fill paints its pixels once more.
        let side = egui::Frame::side_top_panel(ui.style()).fill(egui::Color32::TRANSPARENT);
        egui::Panel::left("controls")
            .default_size(280.0)
            .frame(side)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
            });
        egui::Panel::right("tools")
            .default_size(300.0)
            .frame(side)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.tools(ui));
            });
        egui::Panel::bottom("timings")
            .frame(side)
            .show(ui, |ui| self.timing_panel(ui));
        egui::CentralPanel::default()
            .frame(egui::Frame::central_panel(ui.style()).fill(egui::Color32::TRANSPARENT))
            .show(ui, |ui| self.central_view(ui, images));
        if ui.input(|i| i.key_pressed(egui::Key::F12))
            && let Err(e) = self.screenshot()
        {
            self.status = e.to_string();
        }
    }

    /// Size in points the central view had last frame (the window renders at this size).
    pub fn view_points(&self) -> egui::Vec2 {
        self.view_size
    }

    fn central_view(&mut self, ui: &mut egui::Ui, images: ViewImages) {
        let size = ui.available_size();
        self.view_size = size;
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        if images.a.is_none() {
            painter.rect_filled(rect, 0.0, egui::Color32::BLACK);
        }
        self.paint_images(ui, &painter, rect, images);
        // A stale error map would hide the live image; the metrics stay in the panel.
        let fresh = !self.reference.is_stale(&self.renderer);
        if let Some(texture) = self.reference.overlay_texture(ui.ctx()).filter(|_| fresh) {
            let tint = egui::Color32::from_white_alpha((self.reference.opacity * 255.0) as u8);
            painter.image(texture, rect, FULL_UV, tint);
        }
        let handles = self.paint_light_handles(&painter, rect);
        self.divider_control(ui, rect);
        self.view_input(ui, &response, rect, &handles);
        self.light_handles = handles;
    }

    fn paint_images(
        &self,
        ui: &egui::Ui,
        painter: &egui::Painter,
        rect: egui::Rect,
        images: ViewImages,
    ) {
        let Some(a) = images.a else {
            return;
        };
        let Some(ab) = &self.ab else {
            painter.image(a, rect, FULL_UV, egui::Color32::WHITE);
            return;
        };
        match (ab.mode, images.b, images.difference) {
            (SplitMode::Split, Some(b), _) => {
                let x = rect.left() + rect.width() * ab.divider;
                let left = egui::Rect::from_min_max(rect.min, egui::pos2(x, rect.bottom()));
                let right = egui::Rect::from_min_max(egui::pos2(x, rect.top()), rect.max);
                let uv = |r: egui::Rect| {
                    egui::Rect::from_min_max(
                        egui::pos2((r.left() - rect.left()) / rect.width(), 0.0),
                        egui::pos2((r.right() - rect.left()) / rect.width(), 1.0),
                    )
                };
                painter.image(a, left, uv(left), egui::Color32::WHITE);
                painter.image(b, right, uv(right), egui::Color32::WHITE);
                painter.line_segment(
                    [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
                    egui::Stroke::new(2.0, egui::Color32::WHITE),
                );
                let font = egui::FontId::proportional(14.0);
                let color = ui.visuals().strong_text_color();
                painter.text(
                    egui::pos2(x - 6.0, rect.top() + 6.0),
                    egui::Align2::RIGHT_TOP,
                    format!("A: {}", self.technique),
                    font.clone(),
                    color,
                );
                painter.text(
                    egui::pos2(x + 6.0, rect.top() + 6.0),
                    egui::Align2::LEFT_TOP,
                    format!("B: {}", self.technique_b),
                    font,
                    color,
                );
            }
            (SplitMode::Difference, _, Some(d)) => {
                painter.image(d, rect, FULL_UV, egui::Color32::WHITE);
            }
            _ => {
                painter.image(a, rect, FULL_UV, egui::Color32::WHITE);
            }
        }
    }

    /// Draws a handle per light (point/spot at their position, directional toward the sun)
    /// and returns the handles' screen positions.
    fn paint_light_handles(
        &self,
        painter: &egui::Painter,
        rect: egui::Rect,
    ) -> Vec<(usize, egui::Pos2)> {
        let camera = self.camera.camera();
        let view_proj = camera.projection(rect.aspect_ratio().max(1e-3)) * camera.view();
        let centre = self.camera.pivot();
        let mut handles = Vec::new();
        // Handles outside the view are pinned to its border (drawn hollow) so every light in
        // front of the camera can be grabbed.
        let inner = rect.shrink(HANDLE_GRAB_RADIUS);
        for (i, light) in self.lights.iter().enumerate().take(256) {
            let world = lights::handle_position(light, centre, self.directional_reach());
            let Some(p) = lights::project(view_proj, world, vec2(rect.size())) else {
                continue;
            };
            let exact = rect.min + egui::vec2(p.x, p.y);
            let pinned = !inner.contains(exact);
            let pos = inner.clamp(exact);
            let c = light.radiance / light.radiance.max_element().max(1e-6);
            let fill = egui::Color32::from_rgb(
                (c.x * 255.0) as u8,
                (c.y * 255.0) as u8,
                (c.z * 255.0) as u8,
            );
            let selected = i == self.selected_light;
            let stroke = if selected {
                egui::Stroke::new(3.0, egui::Color32::YELLOW)
            } else {
                egui::Stroke::new(1.5, egui::Color32::BLACK)
            };
            if light.kind != zoo_host::LightKind::Point && !pinned {
                // The direction the light travels.
                let tip = world + light.direction * self.extent * 0.08;
                if let Some(t) = lights::project(view_proj, tip, vec2(rect.size())) {
                    painter.line_segment([pos, rect.min + egui::vec2(t.x, t.y)], stroke);
                }
            }
            if pinned {
                painter.circle_stroke(pos, 7.0, egui::Stroke::new(2.5, fill));
                painter.circle_stroke(pos, 9.0, stroke);
            } else {
                painter.circle(pos, 7.0, fill, stroke);
            }
            painter.text(
                pos + egui::vec2(9.0, -9.0),
                egui::Align2::LEFT_BOTTOM,
                i.to_string(),
                egui::FontId::proportional(12.0),
                egui::Color32::WHITE,
            );
            handles.push((i, pos));
        }
        handles
    }

    /// In split mode, a strip around the divider drags it.
    fn divider_control(&mut self, ui: &mut egui::Ui, rect: egui::Rect) {
        let Some(ab) = self.ab.as_mut().filter(|ab| ab.mode == SplitMode::Split) else {
            return;
        };
        let x = rect.left() + rect.width() * ab.divider;
        let strip = egui::Rect::from_min_max(
            egui::pos2(x - 5.0, rect.top()),
            egui::pos2(x + 5.0, rect.bottom()),
        );
        let response = ui
            .interact(strip, ui.scope_id().with("ab divider"), egui::Sense::drag())
            .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
        if response.dragged() {
            ab.divider =
                (ab.divider + response.drag_delta().x / rect.width().max(1.0)).clamp(0.0, 1.0);
        }
    }

    /// Mouse: drag a light handle to move the light, else orbit or look; wheel zooms (orbit)
    /// or sets the fly speed. Keyboard (fly mode): WASD, Q/E, Shift.
    fn view_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        rect: egui::Rect,
        handles: &[(usize, egui::Pos2)],
    ) {
        let nearest = |pos: Option<egui::Pos2>| {
            let pos = pos?;
            handles
                .iter()
                .map(|(i, p)| (*i, p.distance(pos)))
                .filter(|(_, d)| *d <= HANDLE_GRAB_RADIUS)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(i, _)| i)
        };
        if response.drag_started() {
            // Where the button went down: the pointer may have moved on before the drag is
            // recognised.
            let origin = ui.input(|i| i.pointer.press_origin());
            self.dragging_light = nearest(origin.or(response.interact_pointer_pos()));
            if let Some(i) = self.dragging_light {
                self.selected_light = i;
            }
        }
        if response.clicked()
            && let Some(i) = nearest(response.interact_pointer_pos())
        {
            self.selected_light = i;
        }
        let delta = vec2(response.drag_delta());
        if response.dragged() && delta != Vec2::ZERO {
            match self.dragging_light {
                Some(i) => self.drag_light(i, delta, rect.height()),
                None => self.camera.drag(delta),
            }
        }
        if response.drag_stopped() {
            self.dragging_light = None;
        }
        if response.hovered() {
            self.camera.scroll(ui.input(|i| i.smooth_scroll_delta.y));
        }
        if !ui.ctx().egui_wants_keyboard_input() {
            let input = ui.input(|i| {
                let axis = |plus: egui::Key, minus: egui::Key| {
                    i.key_down(plus) as i32 as f32 - i.key_down(minus) as i32 as f32
                };
                (
                    FlyInput {
                        forward: axis(egui::Key::W, egui::Key::S),
                        right: axis(egui::Key::D, egui::Key::A),
                        up: axis(egui::Key::E, egui::Key::Q),
                        boost: i.modifiers.shift,
                    },
                    i.stable_dt,
                )
            });
            self.camera.fly(input.0, input.1);
        }
    }

    /// How far from the pivot directional handles sit: inside the view at any zoom.
    fn directional_reach(&self) -> f32 {
        self.camera.distance * 0.35
    }

    /// Moves light `index`'s handle by a drag of `delta` points on a view `height` points tall.
    pub fn drag_light(&mut self, index: usize, delta: Vec2, height: f32) {
        let centre = self.camera.pivot();
        let camera = self.camera.camera();
        let reach = self.directional_reach();
        let Some(light) = self.lights.get_mut(index) else {
            return;
        };
        let handle: Vec3 = lights::handle_position(light, centre, reach);
        let moved = handle + lights::drag_in_view_plane(&camera, handle, delta, height);
        lights::move_handle(light, moved, centre);
    }
}
