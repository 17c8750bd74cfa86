//! The side and bottom panels: scene, technique and generated parameters, views, lights,
//! camera, A/B, reference judge, settings and timings.

use std::collections::VecDeque;

use egui_plot::{Bar, BarChart, Line, Plot, PlotPoints};
use zoo_host::ShadowTechnique;
use zoo_host::View;
use zoo_host::gpu::{PassOwner, PassTiming};
use zoo_host::params::{ParamKind, ParamValue};

use super::camera::CameraMode;
use super::lights;
use super::split::SplitMode;
use super::state::ViewerState;

const ERROR_RED: egui::Color32 = egui::Color32::from_rgb(230, 60, 60);
const WARNING_AMBER: egui::Color32 = egui::Color32::from_rgb(235, 170, 40);

impl ViewerState {
    /// The left panel: errors and the technique's warnings, scene, technique, parameters,
    /// view, settings and screenshot.
    pub fn controls(&mut self, ui: &mut egui::Ui) {
        if let Some(error) = &self.error {
            ui.colored_label(ERROR_RED, format!("Technique failed: {error}"));
            if ui.button("Dismiss").clicked() {
                self.error = None;
            }
            ui.separator();
        }
        // What the running technique cannot meet here, for as long as it cannot, and the lights
        // a technique that adds light does not bounce.
        let mut warnings = self.renderer.technique_instance().warnings();
        if self.renderer.technique().adds_light {
            let technique = self.renderer.technique_instance();
            warnings.extend(
                (self.renderer.lights().iter().enumerate()).filter_map(|(i, l)| {
                    let why = technique.unbounced(l)?;
                    Some(zoo_host::technique::unbounced_sentence(i, l.kind, &why))
                }),
            );
        }
        for warning in &warnings {
            ui.colored_label(WARNING_AMBER, format!("Warning: {warning}"));
        }
        if !warnings.is_empty() {
            ui.separator();
        }
        if let Some(error) = &self.shader_error {
            ui.colored_label(ERROR_RED, format!("Shader error: {error}"));
            ui.label("The previous pipelines keep running until the file compiles.");
            ui.separator();
        }
        self.scene_picker(ui);
        ui.heading("Technique");
        if let Some(id) = technique_list(ui, &self.technique, "") {
            self.select_technique(id);
        }
        self.parameter_panel(ui);
        self.about_panel(ui);
        self.view_panel(ui);
        self.settings_panel(ui);
        if !self.status.is_empty() {
            ui.label(&self.status);
        }
    }

    /// The right panel: lights, camera, A/B and the reference judge.
    pub fn tools(&mut self, ui: &mut egui::Ui) {
        egui::CollapsingHeader::new("Lights")
            .default_open(true)
            .show(ui, |ui| {
                let edits = lights::lights_panel(
                    ui,
                    &mut self.lights,
                    &mut self.selected_light,
                    self.extent,
                );
                if edits.add {
                    self.add_light();
                }
                if let Some(i) = edits.remove {
                    self.remove_light(i);
                }
            });
        egui::CollapsingHeader::new("Camera")
            .default_open(true)
            .show(ui, |ui| self.camera_panel(ui));
        egui::CollapsingHeader::new("A/B compare")
            .default_open(true)
            .show(ui, |ui| self.ab_panel(ui));
        egui::CollapsingHeader::new("Reference judge")
            .default_open(true)
            .show(ui, |ui| {
                if let Some(e) = self.reference.panel(ui, &mut self.renderer) {
                    self.error = Some(e);
                }
            });
    }

    /// The selected technique's documentation (its crate's README), collapsed at first.
    fn about_panel(&self, ui: &mut egui::Ui) {
        let Ok(registration) = zoo_host::find_technique(&self.technique) else {
            return;
        };
        egui::CollapsingHeader::new(format!("About {}", registration.id))
            .id_salt("about technique")
            .show(ui, |ui| {
                ui.label(format!(
                    "{}

Source: {}",
                    registration.description, registration.source
                ));
                if !registration.readme.is_empty() {
                    ui.separator();
                    egui::ScrollArea::vertical()
                        .id_salt("technique readme")
                        .max_height(320.0)
                        .show(ui, |ui| ui.label(registration.readme));
                }
            });
    }

    fn scene_picker(&mut self, ui: &mut egui::Ui) {
        let mut open = None;
        egui::ComboBox::from_label("Scene")
            .selected_text(self.renderer.scene().name.clone())
            .show_ui(ui, |ui| {
                for file in &self.scene_files {
                    let name = file
                        .file_stem()
                        .map(|s| s.to_string_lossy().into_owned())
                        .unwrap_or_default();
                    if ui.selectable_label(false, name).clicked() {
                        open = Some(file.clone());
                    }
                }
            });
        ui.horizontal(|ui| {
            let label = ui.label("scene file");
            ui.add(
                egui::TextEdit::singleline(&mut self.scene_file)
                    .hint_text("a .ron scene or a model")
                    .desired_width(150.0),
            )
            .labelled_by(label.id);
            if ui.button("Open").clicked() {
                open = Some(std::path::PathBuf::from(self.scene_file.trim()));
            }
        });
        if let Some(path) = open {
            self.open_scene(&path);
        }
        if let Some(error) = &self.scene_error {
            ui.colored_label(ERROR_RED, format!("Scene error: {error}"));
        }
    }

    fn parameter_panel(&mut self, ui: &mut egui::Ui) {
        let Ok(registration) = zoo_host::find_technique(&self.technique) else {
            return;
        };
        let schema = (registration.params)();
        if schema.is_empty() {
            return;
        }
        ui.heading("Parameters");
        let values = self.params_for(&self.technique);
        let mut changed: Option<(String, ParamValue)> = None;
        for spec in &schema {
            let current = values
                .get(spec.key)
                .cloned()
                .unwrap_or_else(|| spec.default.clone());
            let response = match (&spec.kind, current) {
                (ParamKind::Bool, ParamValue::Bool(mut v)) => {
                    let r = ui.checkbox(&mut v, spec.key);
                    if r.changed() {
                        changed = Some((spec.key.to_string(), ParamValue::Bool(v)));
                    }
                    r
                }
                (ParamKind::Int { min, max, step }, ParamValue::Int(mut v)) => {
                    let r = ui.add(
                        egui::Slider::new(&mut v, *min..=*max)
                            .step_by(*step as f64)
                            .text(spec.key),
                    );
                    if r.drag_stopped() || (r.changed() && !r.dragged()) {
                        changed = Some((spec.key.to_string(), ParamValue::Int(v)));
                    }
                    r
                }
                (ParamKind::Float { min, max, step }, ParamValue::Float(mut v)) => {
                    let r = ui.add(
                        egui::Slider::new(&mut v, *min..=*max)
                            .step_by(*step)
                            .text(spec.key),
                    );
                    if r.drag_stopped() || (r.changed() && !r.dragged()) {
                        changed = Some((spec.key.to_string(), ParamValue::Float(v)));
                    }
                    r
                }
                (ParamKind::Choice { options }, ParamValue::Choice(v)) => {
                    let mut picked = None;
                    let r = egui::ComboBox::from_label(spec.key)
                        .selected_text(v.clone())
                        .show_ui(ui, |ui| {
                            for option in options.iter() {
                                if ui.selectable_label(v == *option, *option).clicked() {
                                    picked = Some(option.to_string());
                                }
                            }
                        })
                        .response;
                    if let Some(p) = picked {
                        changed = Some((spec.key.to_string(), ParamValue::Choice(p)));
                    }
                    r
                }
                (_, other) => ui.label(format!("{} = {other}", spec.key)),
            };
            response.on_hover_text(spec.doc);
        }
        if ui.button("Reset to defaults").clicked() {
            self.reset_params();
        } else if let Some((key, value)) = changed {
            self.set_param(&key, value);
        }
    }

    fn view_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("View");
        let mut views = vec![("final".to_string(), View::Final)];
        for light in 0..self.lights.len().min(64) {
            views.push((format!("visibility:{light}"), View::Visibility { light }));
        }
        for (name, view) in [
            ("normals", View::Normals),
            ("depth", View::Depth),
            ("albedo", View::Albedo),
        ] {
            views.push((name.to_string(), view));
        }
        for r in self
            .renderer
            .technique_instance()
            .resources()
            .into_iter()
            .filter(|r| r.viewable)
        {
            views.push((r.name.clone(), View::Resource(r.name)));
        }
        ui.horizontal_wrapped(|ui| {
            for (name, view) in views {
                if ui.selectable_label(self.view == view, name).clicked() {
                    self.view = view;
                }
            }
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.overlay_mode, "overlay")
                .on_hover_text("Blend the chosen view over the final image");
            ui.add_enabled(
                self.overlay_mode,
                egui::Slider::new(&mut self.overlay_opacity, 0.0..=1.0).text("opacity"),
            );
        });
    }

    fn settings_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Settings");
        ui.horizontal(|ui| {
            let label = ui.label("settings file");
            ui.text_edit_singleline(&mut self.settings_file)
                .labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            let path = std::path::PathBuf::from(&self.settings_file);
            if ui.button("Save settings").clicked() {
                self.status = match self.save_settings(&path) {
                    Ok(()) => format!("saved {}", path.display()),
                    Err(e) => e.to_string(),
                };
            }
            if ui.button("Load settings").clicked() {
                self.status = match self.load_settings(&path) {
                    Ok(()) => format!("loaded {}", path.display()),
                    Err(e) => e.to_string(),
                };
            }
            if ui.button("Screenshot (F12)").clicked()
                && let Err(e) = self.screenshot()
            {
                self.status = e.to_string();
            }
        });
    }

    fn camera_panel(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.camera.mode, CameraMode::Orbit, "orbit")
                .on_hover_text("Drag to orbit, wheel to zoom");
            ui.radio_value(&mut self.camera.mode, CameraMode::Fly, "fly")
                .on_hover_text(
                    "Drag to look, WASD to move, Q/E down/up, Shift faster, wheel: speed",
                );
        });
        ui.add(
            egui::Slider::new(&mut self.camera.speed, 0.01..=1000.0)
                .logarithmic(true)
                .text("fly speed"),
        );
        let mut fov = self.camera.fov_y.to_degrees();
        if ui
            .add(egui::Slider::new(&mut fov, 10.0..=120.0).text("field of view (°)"))
            .changed()
        {
            self.camera.fov_y = fov.to_radians();
        }
        if ui.button("Reset camera").clicked() {
            let scene_camera = self.renderer.scene().camera;
            self.camera
                .look_at(scene_camera.position, scene_camera.target);
            self.camera.fov_y = scene_camera.fov_y;
        }
        ui.horizontal(|ui| {
            let label = ui.label("bookmark name");
            ui.add(
                egui::TextEdit::singleline(&mut self.bookmark_name)
                    .hint_text("optional")
                    .desired_width(120.0),
            )
            .labelled_by(label.id);
            if ui.button("Add bookmark").clicked() {
                let name = std::mem::take(&mut self.bookmark_name);
                self.add_bookmark(&name);
            }
        });
        let scene = self.renderer.scene().name.clone();
        let names: Vec<String> = self
            .bookmarks
            .get(&scene)
            .map(|l| l.iter().map(|b| b.name.clone()).collect())
            .unwrap_or_default();
        let mut remove = None;
        for name in names {
            ui.horizontal(|ui| {
                if ui.button(format!("Go to {name}")).clicked() {
                    self.go_to_bookmark(&name);
                }
                if ui
                    .small_button("x")
                    .on_hover_text("Delete bookmark")
                    .clicked()
                {
                    remove = Some(name.clone());
                }
            });
        }
        if let Some(name) = remove
            && let Some(list) = self.bookmarks.get_mut(&scene)
        {
            list.retain(|b| b.name != name);
        }
    }

    fn ab_panel(&mut self, ui: &mut egui::Ui) {
        let mut on = self.ab.is_some();
        if ui
            .checkbox(&mut on, "compare with B")
            .on_hover_text("Render a second technique on the same frame")
            .changed()
        {
            self.set_ab(on);
        }
        let Some(ab) = &mut self.ab else {
            return;
        };
        ui.horizontal(|ui| {
            ui.radio_value(&mut ab.mode, SplitMode::Split, "split");
            ui.radio_value(&mut ab.mode, SplitMode::Difference, "difference");
        });
        match ab.mode {
            SplitMode::Split => {
                ui.add(egui::Slider::new(&mut ab.divider, 0.0..=1.0).text("divider"));
            }
            SplitMode::Difference => {
                ui.add(
                    egui::Slider::new(&mut ab.gain, 1.0..=64.0)
                        .logarithmic(true)
                        .text("gain"),
                )
                .on_hover_text("Red: A darker than B; blue: B darker than A");
            }
        }
        ui.label("B technique (its remembered parameters):");
        if let Some(id) = technique_list(ui, &self.technique_b, "B: ") {
            self.select_technique_b(id);
        }
    }

    /// The bottom panel: per-pass times, a rolling frame-time plot, counters and memory, and
    /// whether frames keep unchanged work (off shows every pass's full cost each frame).
    pub fn timing_panel(&mut self, ui: &mut egui::Ui) {
        self.reuse_toggle(ui);
        let Some(timings) = &self.timings else {
            return;
        };
        ui.horizontal(|ui| {
            ui.label(format!(
                "frame {:.2} ms ({}), technique {:.2} ms",
                timings.frame_total(),
                timings.source.label(),
                timings.total(PassOwner::Technique)
            ));
            if let Some(b) = &self.b_timings {
                ui.separator();
                ui.label(format!(
                    "B ({}): frame {:.2} ms, technique {:.2} ms",
                    self.technique_b,
                    b.frame_total(),
                    b.total(PassOwner::Technique)
                ));
            }
        });
        ui.columns(3, |columns| {
            pass_time_plot(&mut columns[0], &timings.passes);
            frame_history_plot(&mut columns[1], &self.history);
            pass_and_resource_list(
                &mut columns[2],
                &timings.passes,
                self.renderer.technique_instance(),
            );
        });
    }

    /// Whether frames keep unchanged shadow maps, for both renderers.
    fn reuse_toggle(&mut self, ui: &mut egui::Ui) {
        let mut reuse = self.renderer.reuse_unchanged();
        let toggled = ui
            .checkbox(&mut reuse, "keep unchanged shadow maps")
            .on_hover_text(
                "Off: every frame renders every map, so the pass times show its full cost",
            )
            .changed();
        if toggled {
            self.renderer.set_reuse_unchanged(reuse);
            if let Some(ab) = &mut self.ab {
                ab.renderer.set_reuse_unchanged(reuse);
            }
        }
    }
}

/// A bar chart of the frame's pass times, one bar per pass family.
fn pass_time_plot(ui: &mut egui::Ui, passes: &[PassTiming]) {
    let families = pass_families(passes);
    let bars: Vec<Bar> = families
        .iter()
        .enumerate()
        .map(|(i, f)| Bar::new(-(i as f64), f.milliseconds).name(f.label()))
        .collect();
    let labels: Vec<String> = families.iter().map(PassFamily::label).collect();
    Plot::new("pass times")
        .height(140.0)
        .allow_scroll(false)
        .y_axis_min_width(120.0)
        .y_axis_formatter(move |mark, _| {
            let index = -mark.value;
            if (index - index.round()).abs() > 1e-6 || index < 0.0 {
                return String::new();
            }
            labels
                .get(index.round() as usize)
                .cloned()
                .unwrap_or_default()
        })
        .show(ui, |plot| {
            plot.bar_chart(BarChart::new("pass time (ms)", bars).horizontal())
        });
}

/// The recent frames' times (ms), oldest first.
fn frame_history_plot(ui: &mut egui::Ui, history: &VecDeque<f64>) {
    let points: PlotPoints<'_> = history
        .iter()
        .enumerate()
        .map(|(i, v)| [i as f64, *v])
        .collect();
    Plot::new("frame history")
        .height(140.0)
        .allow_scroll(false)
        .show(ui, |plot| plot.line(Line::new("frame (ms)", points)));
}

/// Every pass's time, then the technique's resources (with their memory) and counters.
fn pass_and_resource_list(
    ui: &mut egui::Ui,
    passes: &[PassTiming],
    instance: &dyn ShadowTechnique,
) {
    egui::ScrollArea::vertical()
        .max_height(140.0)
        .show(ui, |ui| {
            for p in passes {
                ui.label(format!("{}: {:.2} ms", p.name, p.milliseconds));
            }
            for r in instance.resources() {
                ui.label(format!(
                    "{}: {:?} {} {:.1} MiB",
                    r.name,
                    r.size,
                    r.format,
                    r.bytes as f64 / 1048576.0
                ));
            }
            for (name, value) in instance.counters() {
                ui.label(format!("{name}: {value}"));
            }
        });
}

/// Passes of one family (the part of their names before `:`, e.g. "Shadow map" for
/// "Shadow map: light 2 face 3") and their summed time.
#[derive(Debug, Clone, PartialEq)]
pub struct PassFamily {
    pub name: String,
    pub passes: usize,
    pub milliseconds: f64,
}

impl PassFamily {
    /// The bar label: the family name, with the pass count when there are several.
    pub fn label(&self) -> String {
        match self.passes {
            1 => self.name.clone(),
            n => format!("{} ×{n}", self.name),
        }
    }
}

/// Groups passes into families in the order they first ran.
pub fn pass_families(passes: &[zoo_host::gpu::PassTiming]) -> Vec<PassFamily> {
    let mut families: Vec<PassFamily> = Vec::new();
    for pass in passes {
        let name = pass.name.split(':').next().unwrap_or("").trim();
        match families.iter_mut().find(|f| f.name == name) {
            Some(family) => {
                family.passes += 1;
                family.milliseconds += pass.milliseconds;
            }
            None => families.push(PassFamily {
                name: name.to_string(),
                passes: 1,
                milliseconds: pass.milliseconds,
            }),
        }
    }
    families
}

/// Every registered technique as a selectable list (labels prefixed with `prefix`); returns
/// the one clicked.
fn technique_list(ui: &mut egui::Ui, current: &str, prefix: &str) -> Option<&'static str> {
    let mut chosen = None;
    for r in zoo_host::registry() {
        let response = ui
            .selectable_label(current == r.id, format!("{prefix}{}", r.id))
            .on_hover_text(format!(
                "{}\n{}\nlights: {}",
                r.description,
                r.name,
                r.light_kind_names()
            ));
        if response.clicked() {
            chosen = Some(r.id);
        }
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::{PassOwner, PassTiming};

    fn pass(name: &str, milliseconds: f64) -> PassTiming {
        PassTiming {
            name: name.to_string(),
            owner: PassOwner::Technique,
            milliseconds,
            counts: None,
        }
    }

    #[test]
    fn passes_group_into_named_families_in_order() {
        let passes = [
            pass("G-buffer", 1.0),
            pass("Shadow map: light 0 face 0", 2.0),
            pass("Shadow map: light 0 face 1", 3.0),
            pass("Shadow lookup: light 0", 0.5),
            pass("Shadow map: light 1", 4.0),
            pass("Lighting", 0.25),
        ];
        let families = pass_families(&passes);
        let labels: Vec<String> = families.iter().map(PassFamily::label).collect();
        assert_eq!(
            labels,
            ["G-buffer", "Shadow map ×3", "Shadow lookup", "Lighting"]
        );
        assert_eq!(families[1].milliseconds, 9.0);
        assert_eq!(families[1].passes, 3);
    }
}
