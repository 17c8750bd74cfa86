//! The viewer's state and panels, independent of the window so they can be tested headless.

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui_plot::{Bar, BarChart, Line, Plot, PlotPoints};
use zoo_host::gpu::{FrameTimings, GpuContext, PassOwner};
use zoo_host::params::{self, ParamKind, ParamValue, ParamValues};
use zoo_host::scene::Camera;
use zoo_host::{Renderer, Scene, View};

/// Settings remembered per technique: parameter values by technique id.
pub type Settings = BTreeMap<String, ParamValues>;

/// An orbit around the scene camera's target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
}

impl Orbit {
    fn from_camera(camera: &Camera) -> Orbit {
        let offset = camera.position - camera.target;
        let distance = offset.length().max(0.1);
        Orbit {
            yaw: offset.x.atan2(offset.z),
            pitch: (offset.y / distance).clamp(-1.0, 1.0).asin(),
            distance,
        }
    }

    fn apply(&self, camera: &Camera) -> Camera {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let offset = zoo_host::glam::Vec3::new(sy * cp, sp, cy * cp) * self.distance;
        Camera {
            position: camera.target + offset,
            ..*camera
        }
    }
}

/// Everything the viewer shows and edits.
pub struct ViewerState {
    pub renderer: Renderer,
    /// Scene files offered by the picker.
    pub scene_files: Vec<PathBuf>,
    pub technique: String,
    pub settings: Settings,
    pub view: View,
    /// The last technique failure, shown as a banner.
    pub error: Option<String>,
    pub timings: Option<FrameTimings>,
    /// Recent frame times (ms) for the rolling plot.
    pub history: VecDeque<f64>,
    pub orbit: Orbit,
    base_camera: Camera,
    /// A message for the status line.
    pub status: String,
    frame: u64,
}

impl ViewerState {
    /// A viewer on `scene` at `size`.
    pub fn new(
        gpu: Arc<GpuContext>,
        scene: Scene,
        size: zoo_host::glam::UVec2,
    ) -> anyhow::Result<ViewerState> {
        let base_camera = scene.camera;
        let renderer = Renderer::new(gpu, scene, size)?;
        Ok(ViewerState {
            technique: renderer.technique().id.to_string(),
            renderer,
            scene_files: scene_files(),
            settings: Settings::new(),
            view: View::Final,
            error: None,
            timings: None,
            history: VecDeque::new(),
            orbit: Orbit::from_camera(&base_camera),
            base_camera,
            status: String::new(),
            frame: 0,
        })
    }

    /// Parameter values for `id`: remembered ones, or the defaults.
    pub fn params_for(&self, id: &str) -> ParamValues {
        match (self.settings.get(id), zoo_host::find_technique(id)) {
            (Some(values), _) => values.clone(),
            (None, Ok(r)) => params::defaults(&(r.params)()),
            (None, Err(_)) => ParamValues::new(),
        }
    }

    /// Switches technique (takes effect on the next frame).
    pub fn select_technique(&mut self, id: &str) {
        let values = self.params_for(id);
        match self.renderer.set_technique(id, &values) {
            Ok(()) => {
                self.technique = id.to_string();
                self.error = None;
                if matches!(self.view, View::Resource(_)) {
                    self.view = View::Final;
                }
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Sets one parameter of the current technique (clamped into range) and applies it.
    pub fn set_param(&mut self, key: &str, value: ParamValue) {
        let Ok(registration) = zoo_host::find_technique(&self.technique) else {
            return;
        };
        let schema = (registration.params)();
        let Ok(spec) = params::find_spec(&schema, key) else {
            return;
        };
        let mut values = self.params_for(&self.technique);
        values.insert(key.to_string(), spec.clamp(&value));
        self.settings.insert(self.technique.clone(), values);
        let id = self.technique.clone();
        self.select_technique(&id);
    }

    /// Back to the current technique's defaults.
    pub fn reset_params(&mut self) {
        self.settings.remove(&self.technique);
        let id = self.technique.clone();
        self.select_technique(&id);
    }

    /// Writes the remembered settings as RON.
    pub fn save_settings(&self, path: &Path) -> anyhow::Result<()> {
        let text = ron::ser::to_string_pretty(&self.settings, ron::ser::PrettyConfig::default())?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }

    /// Reads settings written by [`Self::save_settings`] and applies the current technique's.
    pub fn load_settings(&mut self, path: &Path) -> anyhow::Result<()> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        self.settings = ron::from_str(&text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{}:{}: {}",
                path.display(),
                e.span.start.line,
                e.span.start.col,
                e.code
            )
        })?;
        let id = self.technique.clone();
        self.select_technique(&id);
        Ok(())
    }

    /// Opens another scene.
    pub fn open_scene(&mut self, path: &Path) {
        match Scene::load(path) {
            Ok(scene) => {
                self.base_camera = scene.camera;
                self.orbit = Orbit::from_camera(&scene.camera);
                let size = self.renderer.size();
                match Renderer::new(self.renderer.gpu().clone(), scene, size) {
                    Ok(renderer) => {
                        self.renderer = renderer;
                        let id = self.technique.clone();
                        self.select_technique(&id);
                        self.status = format!("opened {}", path.display());
                    }
                    Err(e) => self.error = Some(e.to_string()),
                }
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Renders one frame at `size` and records its timings; a failing technique is replaced
    /// by `unshadowed` and its error shown.
    pub fn render(&mut self, size: zoo_host::glam::UVec2) {
        if let Err(e) = self.renderer.set_size(size) {
            self.error = Some(e.to_string());
            return;
        }
        self.renderer
            .set_camera(self.orbit.apply(&self.base_camera));
        match self.renderer.render(&self.view) {
            Ok(timings) => {
                self.history.push_back(timings.frame_total());
                if self.history.len() > 240 {
                    self.history.pop_front();
                }
                self.timings = Some(timings);
            }
            Err(e) => {
                self.error = Some(e.to_string());
                self.technique = self.renderer.technique().id.to_string();
                self.view = View::Final;
            }
        }
        self.frame += 1;
    }

    /// Saves the current image as PNG in the working folder and returns its path.
    pub fn screenshot(&mut self) -> anyhow::Result<PathBuf> {
        let path = PathBuf::from(format!("shadow-zoo-{}-{}.png", self.technique, self.frame));
        self.renderer.read_output().save(&path)?;
        self.status = format!("saved {}", path.display());
        Ok(path)
    }

    /// The side panel: scene, technique, parameters, view and settings.
    pub fn controls(&mut self, ui: &mut egui::Ui) {
        if let Some(error) = &self.error {
            ui.colored_label(
                egui::Color32::from_rgb(230, 60, 60),
                format!("Technique failed: {error}"),
            );
            if ui.button("Dismiss").clicked() {
                self.error = None;
            }
            ui.separator();
        }
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
        if let Some(path) = open {
            self.open_scene(&path);
        }
        ui.heading("Technique");
        let mut chosen = None;
        for r in zoo_host::registry() {
            let response = ui
                .selectable_label(self.technique == r.id, r.id)
                .on_hover_text(format!(
                    "{}\n{}\nlights: {}",
                    r.name,
                    r.description,
                    r.light_kind_names()
                ));
            if response.clicked() {
                chosen = Some(r.id);
            }
        }
        if let Some(id) = chosen {
            self.select_technique(id);
        }
        self.parameter_panel(ui);
        ui.heading("View");
        let mut views = vec![("final".to_string(), View::Final)];
        for light in 0..self.renderer.lights().len() {
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
        for (name, view) in views {
            if ui.selectable_label(self.view == view, name).clicked() {
                self.view = view;
            }
        }
        ui.separator();
        ui.horizontal(|ui| {
            if ui.button("Screenshot (F12)").clicked()
                && let Err(e) = self.screenshot()
            {
                self.status = e.to_string();
            }
        });
        if !self.status.is_empty() {
            ui.label(&self.status);
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

    /// The bottom panel: per-pass times, a rolling frame-time plot, counters and memory.
    pub fn timing_panel(&self, ui: &mut egui::Ui) {
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
        });
        ui.columns(3, |columns| {
            let bars: Vec<Bar> = timings
                .passes
                .iter()
                .enumerate()
                .map(|(i, p)| Bar::new(i as f64, p.milliseconds).name(&p.name))
                .collect();
            Plot::new("pass times")
                .height(140.0)
                .allow_scroll(false)
                .show(&mut columns[0], |plot| {
                    plot.bar_chart(BarChart::new("passes (ms)", bars))
                });
            let points: PlotPoints<'_> = self
                .history
                .iter()
                .enumerate()
                .map(|(i, v)| [i as f64, *v])
                .collect();
            Plot::new("frame history")
                .height(140.0)
                .allow_scroll(false)
                .show(&mut columns[1], |plot| {
                    plot.line(Line::new("frame (ms)", points))
                });
            let instance = self.renderer.technique_instance();
            egui::ScrollArea::vertical()
                .max_height(140.0)
                .show(&mut columns[2], |ui| {
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
        });
    }

    /// The whole window: controls at the left, timings at the bottom, the image (if any) in
    /// the middle, orbiting with the mouse.
    pub fn ui(&mut self, ui: &mut egui::Ui, image: Option<egui::TextureId>) {
        egui::Panel::left("controls").show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
        });
        egui::Panel::bottom("timings").show(ui, |ui| self.timing_panel(ui));
        egui::CentralPanel::default().show(ui, |ui| {
            let size = ui.available_size();
            let response = match image {
                Some(id) => ui.add(egui::Image::new((id, size)).sense(egui::Sense::drag())),
                None => ui.allocate_response(size, egui::Sense::drag()),
            };
            let delta = response.drag_delta();
            if delta != egui::Vec2::ZERO {
                self.orbit.yaw -= delta.x * 0.01;
                self.orbit.pitch = (self.orbit.pitch + delta.y * 0.01).clamp(-1.5, 1.5);
            }
            if response.hovered() {
                let scroll = ui.input(|i| i.smooth_scroll_delta.y);
                self.orbit.distance = (self.orbit.distance * (1.0 - scroll * 0.002)).max(0.2);
            }
        });
        if ui.input(|i| i.key_pressed(egui::Key::F12))
            && let Err(e) = self.screenshot()
        {
            self.status = e.to_string();
        }
    }
}

/// Scene files in `scenes/` (the working folder's, else the build's).
pub fn scene_files() -> Vec<PathBuf> {
    let local = Path::new("scenes");
    let dir = if local.is_dir() {
        local.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    files
}
