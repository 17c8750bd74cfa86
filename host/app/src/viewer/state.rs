//! The viewer's state and actions, independent of the window so they can be tested headless.

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use zoo_host::glam::UVec2;
use zoo_host::gpu::{FrameTimings, GpuContext};
use zoo_host::params::{self, ParamValue, ParamValues};
use zoo_host::render::{ImageDifference, Overlay};
use zoo_host::scene::Light;
use zoo_host::{Renderer, Scene, ShaderLibrary, View};

use super::camera::{Bookmark, CameraController};
use super::hot_reload::ShaderWatcher;
use super::lights;
use super::reference::ReferenceOverlay;
use super::split::{AbCompare, SplitMode};

/// Settings remembered per technique: parameter values by technique id.
pub type Settings = BTreeMap<String, ParamValues>;

/// What the settings file holds.
#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct SettingsFile {
    /// The technique shown last.
    pub technique: Option<String>,
    /// Parameter values per technique.
    pub techniques: Settings,
    /// Camera bookmarks per scene name.
    pub bookmarks: BTreeMap<String, Vec<Bookmark>>,
}

/// Everything the viewer shows and edits.
pub struct ViewerState {
    pub renderer: Renderer,
    /// Where shaders come from (the `shaders/` folder when present, for hot reload).
    pub shaders: ShaderLibrary,
    /// Scene files offered by the picker.
    pub scene_files: Vec<PathBuf>,
    pub technique: String,
    pub settings: Settings,
    /// Camera bookmarks per scene name.
    pub bookmarks: BTreeMap<String, Vec<Bookmark>>,
    pub view: View,
    /// Show `view` blended over the final image instead of full screen.
    pub overlay_mode: bool,
    pub overlay_opacity: f32,
    /// The last technique failure, shown as a banner.
    pub error: Option<String>,
    /// The last scene that failed to open, with the reason (file:line:col where known).
    pub scene_error: Option<String>,
    /// Path typed into the "open scene" field.
    pub scene_file: String,
    /// The last shader reload failure (file:line:col), shown while the old pipelines run.
    pub shader_error: Option<String>,
    pub timings: Option<FrameTimings>,
    /// Recent frame times (ms) for the rolling plot.
    pub history: VecDeque<f64>,
    pub camera: CameraController,
    /// The lights being rendered (edited in the lights panel).
    pub lights: Vec<Light>,
    pub selected_light: usize,
    /// The A/B comparison, when on.
    pub ab: Option<AbCompare>,
    /// Technique shown on the B side.
    pub technique_b: String,
    pub b_timings: Option<FrameTimings>,
    pub reference: ReferenceOverlay,
    watcher: Option<ShaderWatcher>,
    /// A message for the status line.
    pub status: String,
    /// Path typed into the settings save/load field.
    pub settings_file: String,
    /// Name typed for the next bookmark.
    pub bookmark_name: String,
    /// Screen positions (points) of the light handles drawn last frame.
    pub light_handles: Vec<(usize, egui::Pos2)>,
    /// The light whose handle is being dragged.
    pub(super) dragging_light: Option<usize>,
    /// The scene's diagonal, for default light ranges and speeds.
    pub(super) extent: f32,
    /// Size in points of the central view last frame.
    pub(super) view_size: egui::Vec2,
    frame: u64,
}

impl ViewerState {
    /// A viewer on `scene` at `size` with the embedded shaders.
    pub fn new(gpu: Arc<GpuContext>, scene: Scene, size: UVec2) -> anyhow::Result<ViewerState> {
        Self::with_shaders(gpu, scene, size, ShaderLibrary::embedded())
    }

    /// A viewer whose shaders come from `shaders`; when that reads a folder, edits there are
    /// watched and reloaded.
    pub fn with_shaders(
        gpu: Arc<GpuContext>,
        scene: Scene,
        size: UVec2,
        shaders: ShaderLibrary,
    ) -> anyhow::Result<ViewerState> {
        let (lo, hi) = scene.bounds();
        let extent = lo.distance(hi).max(1.0);
        let camera = CameraController::new(&scene.camera, extent);
        let lights = scene.lights.clone();
        let renderer = Renderer::with_shaders(gpu, scene, size, shaders.clone())?;
        let (watcher, status) = match shaders.disk_root() {
            Some(root) => match ShaderWatcher::new(root) {
                Ok(w) => (
                    Some(w),
                    format!("watching {} for shader edits", root.display()),
                ),
                Err(e) => (None, format!("no shader hot reload: {e}")),
            },
            None => (None, String::new()),
        };
        Ok(ViewerState {
            technique: renderer.technique().id.to_string(),
            renderer,
            shaders,
            scene_files: scene_files(),
            settings: Settings::new(),
            bookmarks: BTreeMap::new(),
            view: View::Final,
            overlay_mode: false,
            overlay_opacity: 0.5,
            error: None,
            shader_error: None,
            scene_error: None,
            scene_file: String::new(),
            timings: None,
            history: VecDeque::new(),
            camera,
            lights,
            selected_light: 0,
            ab: None,
            technique_b: zoo_host::builtin::UNSHADOWED_ID.to_string(),
            b_timings: None,
            reference: ReferenceOverlay::new(),
            watcher,
            status,
            settings_file: "shadow-zoo-settings.ron".to_string(),
            bookmark_name: String::new(),
            light_handles: Vec::new(),
            dragging_light: None,
            extent,
            view_size: egui::Vec2::ZERO,
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
        // Applied to the live technique when it can take them; rebuilt otherwise.
        match self.renderer.set_params(&values) {
            Ok(_) => {
                self.settings.insert(self.technique.clone(), values);
                self.error = None;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
        self.refresh_b();
    }

    /// Back to the current technique's defaults.
    pub fn reset_params(&mut self) {
        self.settings.remove(&self.technique);
        let id = self.technique.clone();
        self.select_technique(&id);
        self.refresh_b();
    }

    /// Writes the remembered settings (technique parameters, current technique, bookmarks)
    /// as RON.
    pub fn save_settings(&self, path: &Path) -> anyhow::Result<()> {
        let file = SettingsFile {
            technique: Some(self.technique.clone()),
            techniques: self.settings.clone(),
            bookmarks: self.bookmarks.clone(),
        };
        let text = ron::ser::to_string_pretty(&file, ron::ser::PrettyConfig::default())?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
        }
        std::fs::write(path, text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }

    /// Reads settings written by [`Self::save_settings`] and switches to the saved technique
    /// with its parameters (out-of-range values are clamped).
    pub fn load_settings(&mut self, path: &Path) -> anyhow::Result<()> {
        let file: SettingsFile = crate::ron_file::load(path)?;
        self.settings = file
            .techniques
            .into_iter()
            .map(|(id, values)| {
                let values = clamp_to_schema(&id, values);
                (id, values)
            })
            .collect();
        self.bookmarks = file.bookmarks;
        let id = file
            .technique
            .filter(|id| zoo_host::find_technique(id).is_ok())
            .unwrap_or_else(|| self.technique.clone());
        self.select_technique(&id);
        self.refresh_b();
        Ok(())
    }

    /// Starts where the last run ended: the settings at `path` (technique, parameters,
    /// bookmarks) when they exist and parse, else the first-run technique. A file that does not
    /// parse is reported in the status line.
    pub fn restore_settings(&mut self, path: &Path) {
        let restored = path.is_file()
            && match self.load_settings(path) {
                Ok(()) => true,
                Err(e) => {
                    self.status = format!("ignored saved settings: {e}");
                    false
                }
            };
        if !restored && let Some(id) = self.first_run_technique() {
            self.select_technique(id);
        }
    }

    /// The technique to open on when no settings remember one: the shadow-map technique when
    /// it is available, else the first available technique that casts shadows.
    pub fn first_run_technique(&self) -> Option<&'static str> {
        let gpu = self.renderer.gpu();
        let casting: Vec<&'static str> = zoo_host::registry()
            .into_iter()
            .filter(|r| r.id != "unshadowed" && r.unavailable_reason(gpu).is_none())
            .map(|r| r.id)
            .collect();
        casting
            .iter()
            .find(|id| **id == "sm-pcf")
            .or(casting.first())
            .copied()
    }

    /// Opens another scene: its camera and lights replace the current ones. On error the
    /// current scene stays and `scene_error` says why.
    pub fn open_scene(&mut self, path: &Path) {
        let scene = match Scene::load(path) {
            Ok(scene) => scene,
            Err(e) => {
                self.scene_error = Some(e.to_string());
                return;
            }
        };
        let size = self.renderer.size();
        let gpu = self.renderer.gpu().clone();
        let renderer = match Renderer::with_shaders(gpu, scene.clone(), size, self.shaders.clone())
        {
            Ok(mut renderer) => {
                renderer.set_reuse_unchanged(self.renderer.reuse_unchanged());
                renderer
            }
            Err(e) => {
                self.scene_error = Some(format!("{}: {e}", path.display()));
                return;
            }
        };
        self.scene_error = None;
        let (lo, hi) = scene.bounds();
        self.extent = lo.distance(hi).max(1.0);
        self.camera = CameraController::new(&scene.camera, self.extent);
        self.lights = scene.lights.clone();
        self.selected_light = 0;
        self.renderer = renderer;
        self.reference = ReferenceOverlay::new();
        let id = self.technique.clone();
        self.select_technique(&id);
        if self.ab.is_some() {
            self.ab = None;
            self.set_ab(true);
        }
        self.status = format!("opened {}", path.display());
    }

    /// Turns the A/B comparison on or off.
    pub fn set_ab(&mut self, on: bool) {
        if !on {
            self.ab = None;
            self.b_timings = None;
            return;
        }
        if self.ab.is_some() {
            return;
        }
        let gpu = self.renderer.gpu().clone();
        let scene = self.renderer.scene().clone();
        match AbCompare::new(gpu, scene, self.renderer.size(), self.shaders.clone()) {
            Ok(mut ab) => {
                ab.renderer
                    .set_reuse_unchanged(self.renderer.reuse_unchanged());
                self.ab = Some(ab);
                let id = self.technique_b.clone();
                self.select_technique_b(&id);
            }
            Err(e) => self.error = Some(format!("cannot start the A/B view: {e}")),
        }
    }

    /// Chooses the B side's technique (with its remembered parameters).
    pub fn select_technique_b(&mut self, id: &str) {
        let values = self.params_for(id);
        let Some(ab) = &mut self.ab else {
            self.technique_b = id.to_string();
            return;
        };
        match ab.renderer.set_technique(id, &values) {
            Ok(()) => self.technique_b = id.to_string(),
            Err(e) => self.error = Some(format!("B: {e}")),
        }
    }

    /// Re-applies B's remembered parameters (after A's changed, if they are the same technique).
    fn refresh_b(&mut self) {
        if self.ab.is_some() && self.technique_b == self.technique {
            let id = self.technique_b.clone();
            self.select_technique_b(&id);
        }
    }

    /// Adds a point light above the camera's pivot and selects it.
    pub fn add_light(&mut self) {
        if self.lights.len() >= zoo_host::MAX_LIGHTS {
            return;
        }
        let position = self.camera.pivot() + zoo_host::glam::Vec3::Y * self.extent * 0.25;
        self.lights
            .push(lights::new_point_light(position, self.extent));
        self.selected_light = self.lights.len() - 1;
    }

    /// Removes light `index` (a scene keeps at least one).
    pub fn remove_light(&mut self, index: usize) {
        if self.lights.len() > 1 && index < self.lights.len() {
            self.lights.remove(index);
            self.selected_light = self.selected_light.min(self.lights.len() - 1);
            if let View::Visibility { light } = self.view
                && light >= self.lights.len()
            {
                self.view = View::Final;
            }
        }
    }

    /// Stores the current camera as a bookmark of this scene.
    pub fn add_bookmark(&mut self, name: &str) {
        let list = self
            .bookmarks
            .entry(self.renderer.scene().name.clone())
            .or_default();
        let name = if name.trim().is_empty() {
            format!("view {}", list.len() + 1)
        } else {
            name.trim().to_string()
        };
        list.retain(|b| b.name != name);
        list.push(Bookmark::of(&name, &self.camera));
    }

    /// Moves the camera to the bookmark called `name` of this scene.
    pub fn go_to_bookmark(&mut self, name: &str) -> bool {
        let scene = &self.renderer.scene().name;
        match self
            .bookmarks
            .get(scene)
            .and_then(|l| l.iter().find(|b| b.name == name))
        {
            Some(mark) => {
                mark.apply(&mut self.camera);
                true
            }
            None => false,
        }
    }

    /// Re-reads the shaders and rebuilds the pipelines of A (and B). On a WGSL error the
    /// message (file:line:col) is kept in `shader_error` and the old pipelines keep running.
    pub fn reload_shaders(&mut self) {
        let mut result = self.renderer.reload_shaders().map_err(anyhow::Error::from);
        if result.is_ok()
            && let Some(ab) = &mut self.ab
        {
            result = ab
                .renderer
                .reload_shaders()
                .map_err(Into::into)
                .and_then(|()| {
                    ab.difference = ImageDifference::new(ab.renderer.gpu(), &self.shaders)?;
                    Ok(())
                });
        }
        match result {
            Ok(()) => {
                self.shader_error = None;
                self.status = "shaders reloaded".to_string();
            }
            Err(e) => self.shader_error = Some(e.to_string()),
        }
    }

    /// The debug view blended over the final image, when overlay mode is on.
    fn overlay(&self) -> Option<Overlay> {
        (self.overlay_mode && self.view != View::Final).then(|| Overlay {
            view: self.view.clone(),
            opacity: self.overlay_opacity,
        })
    }

    /// The view the main renderer draws (final when the debug view is an overlay).
    fn main_view(&self) -> View {
        if self.overlay_mode {
            View::Final
        } else {
            self.view.clone()
        }
    }

    /// Renders one frame at `size` (both sides in A/B mode) and records its timings; a
    /// failing technique is replaced by `unshadowed` and its error shown.
    pub fn render(&mut self, size: UVec2) {
        if self.watcher.as_mut().is_some_and(ShaderWatcher::poll) {
            self.reload_shaders();
        }
        if let Err(e) = self.reference.poll() {
            self.error = Some(e.to_string());
        }
        if let Err(e) = self.renderer.set_size(size) {
            self.error = Some(e.to_string());
            return;
        }
        let camera = self.camera.camera();
        self.renderer.set_camera(camera);
        self.renderer.set_lights(self.lights.clone());
        let view = self.main_view();
        match self
            .renderer
            .render_with_overlay(&view, self.overlay().as_ref())
        {
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
        if let Err(e) = self.reference.follow(&self.renderer) {
            self.error = Some(e.to_string());
        }
        self.render_b(size, camera, &view);
        self.frame += 1;
    }

    /// Renders the B side and, in difference mode, the difference image.
    fn render_b(&mut self, size: UVec2, camera: zoo_host::Camera, view: &View) {
        let Some(ab) = &mut self.ab else {
            return;
        };
        // B shows the same view where it has it; technique resources are A's own.
        let view_b = match view {
            View::Resource(_) => View::Final,
            other => other.clone(),
        };
        let rendered = ab.renderer.set_size(size).and_then(|()| {
            ab.renderer.set_camera(camera);
            ab.renderer.set_lights(self.lights.clone());
            ab.renderer.render(&view_b)
        });
        match rendered {
            Ok(timings) => self.b_timings = Some(timings),
            Err(e) => {
                self.error = Some(format!("B: {e}"));
                self.technique_b = ab.renderer.technique().id.to_string();
            }
        }
        if ab.mode == SplitMode::Difference {
            ab.difference.update(
                self.renderer.gpu(),
                self.renderer.output_view(),
                ab.renderer.output_view(),
                size,
                ab.gain,
            );
        }
    }

    /// Saves the current image as PNG in the working folder and returns its path.
    pub fn screenshot(&mut self) -> anyhow::Result<PathBuf> {
        if cfg!(target_arch = "wasm32") {
            anyhow::bail!("the browser build writes no files: no screenshots");
        }
        let path = PathBuf::from(format!("shadow-zoo-{}-{}.png", self.technique, self.frame));
        self.renderer.read_output().save(&path)?;
        self.status = format!("saved {}", path.display());
        Ok(path)
    }
}

/// `values` of technique `id` with each known parameter clamped into its range.
fn clamp_to_schema(id: &str, values: ParamValues) -> ParamValues {
    let Ok(registration) = zoo_host::find_technique(id) else {
        return values;
    };
    let schema = (registration.params)();
    values
        .into_iter()
        .filter_map(|(key, value)| {
            let spec = params::find_spec(&schema, &key).ok()?;
            Some((key, spec.clamp(&value)))
        })
        .collect()
}

/// Scene files in `scenes/` (the working folder's, else the build's), and those mounted there
/// (the browser build's).
pub fn scene_files() -> Vec<PathBuf> {
    let local = Path::new("scenes");
    let dir = if local.is_dir() {
        local.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
    };
    let on_disk = (std::fs::read_dir(dir).into_iter().flatten()).filter_map(|e| e.ok());
    let mounted = zoo_host::scene::files::mounted_in(Path::new("scenes"));
    let mut files: Vec<PathBuf> = (on_disk.map(|e| e.path()).chain(mounted))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    files
}
