//! The browser's application: the native viewer plus what the page asks of it (the first
//! scene, technique and size from the address, a kept frame, the user's files), and the
//! functions the page calls.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use serde::Serialize;
use shadow_zoo::viewer::{ViewerApp, ViewerState, device_descriptor};
use wasm_bindgen::prelude::*;
use zoo_host::params::{self, ParamValues};
use zoo_host::{Scene, ShaderLibrary, wgpu};

use crate::capture::{Capture, Frame};
use crate::query::Query;

/// Where files the user opens are mounted.
const USER_FOLDER: &str = "user";

/// What the page can read at any time (as JSON from [`status`]).
#[derive(Debug, Default, Clone, Serialize)]
struct Status {
    /// Frames rendered so far.
    frames: u64,
    /// The scene shown (its file, or the built-in default).
    scene: String,
    technique: String,
    /// The size the 3D view rendered at last frame (fewer pixels while it moves on a slow
    /// adapter).
    size: [u32; 2],
    /// The adapter, backend and driver.
    adapter: String,
    /// The last technique failure or scene error, if any.
    error: Option<String>,
    /// The live judge's latest verdict, while it is on and once one has arrived.
    judge: Option<Verdict>,
}

/// The live GPU judge's verdict on the view, as the page reads it.
#[derive(Debug, Clone, Serialize)]
struct Verdict {
    technique: String,
    /// Area rays a pixel traced for the reference (0: hard visibility only).
    samples: u32,
    /// Per light: its scores, or `null` where the technique does not support its kind.
    lights: Vec<Option<LightScores>>,
}

/// A light's scores against the reference (fractions of the pixels it reaches).
#[derive(Debug, Clone, Serialize)]
struct LightScores {
    pixels: usize,
    false_shadow: f64,
    false_lit: f64,
    false_shadow_core: f64,
    false_lit_core: f64,
    mae: f64,
}

impl Verdict {
    /// The live judge's latest verdict in `state`, while it is on.
    fn of(state: &ViewerState) -> Option<Verdict> {
        state.reference.live_samples()?;
        let result = state.reference.result.as_ref()?;
        let lights = (result.metrics.iter())
            .map(|m| {
                m.map(|m| LightScores {
                    pixels: m.pixels,
                    false_shadow: m.false_shadow,
                    false_lit: m.false_lit,
                    false_shadow_core: m.false_shadow_core,
                    false_lit_core: m.false_lit_core,
                    mae: m.mae,
                })
            })
            .collect();
        Some(Verdict {
            technique: result.view.technique.clone(),
            samples: result.live_samples?,
            lights,
        })
    }
}

/// One technique as the page lists it (JSON from [`techniques`]).
#[derive(Debug, Clone, Serialize)]
struct TechniqueEntry {
    id: &'static str,
    name: &'static str,
    /// Why it cannot run on this browser's device, if it cannot.
    unavailable: Option<String>,
}

/// State shared between the running application and the page's calls.
#[derive(Default)]
struct Page {
    status: Status,
    techniques: Vec<TechniqueEntry>,
    kept: Option<Arc<Mutex<Option<Frame>>>>,
    /// A scene or model the user opened, waiting for the next frame.
    to_open: Option<PathBuf>,
}

thread_local! {
    static PAGE: RefCell<Page> = RefCell::default();
}

/// The viewer and the page's requests.
struct WebApp {
    viewer: ViewerApp,
    capture: Capture,
    frames: u64,
    scene: String,
}

impl WebApp {
    fn new(cc: &eframe::CreationContext<'_>, query: Query) -> anyhow::Result<WebApp> {
        let (scene, scene_name) = match &query.scene {
            Some(name) => {
                let path = Path::new("scenes").join(name);
                (Scene::load(&path)?, path.display().to_string())
            }
            None => (
                shadow_zoo::setup::load_scene(None)?,
                shadow_zoo::DEFAULT_SCENE_NAME.to_string(),
            ),
        };
        let mut viewer = ViewerApp::new(cc, scene, ShaderLibrary::embedded())?;
        viewer.fixed_size = query.size;
        if let Some(id) = &query.technique {
            viewer.state.select_technique(id);
        }
        if let Err(e) = set_params(&mut viewer.state, &query.set) {
            viewer.state.error = Some(format!("the address's `set`: {e}"));
        }
        viewer.state.reference.live = query.judge_live;
        let gpu = viewer.state.renderer.gpu().clone();
        let techniques = (zoo_host::technique::registry().into_iter())
            .map(|r| TechniqueEntry {
                id: r.id,
                name: r.name,
                unavailable: r.unavailable_reason(&gpu),
            })
            .collect();
        let capture = Capture::new(query.capture);
        PAGE.with_borrow_mut(|page| {
            page.techniques = techniques;
            page.kept = Some(capture.kept.clone());
            page.status.adapter = gpu.describe();
        });
        Ok(WebApp {
            viewer,
            capture,
            frames: 0,
            scene: scene_name,
        })
    }

    /// Opens what the user picked last, if anything.
    fn open_picked(&mut self) {
        let Some(path) = PAGE.with_borrow_mut(|page| page.to_open.take()) else {
            return;
        };
        self.viewer.state.open_scene(&path);
        if self.viewer.state.scene_error.is_none() {
            self.scene = path.display().to_string();
        }
    }
}

impl eframe::App for WebApp {
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        shadow_zoo::viewer::clear_color(visuals)
    }

    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.open_picked();
        self.viewer.ui(ui, frame);
        self.frames += 1;
        let state = &self.viewer.state;
        self.capture.after_frame(self.frames, &state.renderer);
        let status = Status {
            frames: self.frames,
            scene: self.scene.clone(),
            technique: state.technique.clone(),
            size: state.renderer.size().to_array(),
            adapter: String::new(),
            error: state.error.clone().or_else(|| state.scene_error.clone()),
            judge: Verdict::of(state),
        };
        PAGE.with_borrow_mut(|page| {
            page.status = Status {
                adapter: std::mem::take(&mut page.status.adapter),
                ..status
            };
        });
    }
}

/// Sets parameters of the technique shown from `KEY=VALUE` pairs.
fn set_params(state: &mut ViewerState, assignments: &[(String, String)]) -> anyhow::Result<()> {
    if assignments.is_empty() {
        return Ok(());
    }
    let registration = zoo_host::find_technique(&state.technique)?;
    let mut values = ParamValues::new();
    params::apply_assignments(&(registration.params)(), &mut values, assignments)?;
    for (key, value) in values {
        state.set_param(&key, value);
    }
    Ok(())
}

/// Runs the viewer in `canvas` on the browser's WebGPU.
pub async fn start(canvas: web_sys::HtmlCanvasElement, query: Query) -> Result<(), JsValue> {
    let mut options = eframe::WebOptions {
        // Dithering costs every pixel of the window a noise function, dear on software
        // adapters; the view's images are 8-bit sRGB already.
        dithering: false,
        ..Default::default()
    };
    if let egui_wgpu::WgpuSetup::CreateNew(create) = &mut options.wgpu_options.wgpu_setup {
        create.instance_descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
        create.device_descriptor = Arc::new(device_descriptor);
    }
    eframe::WebRunner::new()
        .start(
            canvas,
            options,
            Box::new(move |cc| Ok(Box::new(WebApp::new(cc, query)?))),
        )
        .await
}

/// The viewer's state as JSON: frames rendered, scene, technique, adapter, last error and the
/// live judge's verdict.
#[wasm_bindgen]
pub fn status() -> String {
    PAGE.with_borrow(|page| serde_json::to_string(&page.status).unwrap_or_default())
}

/// Every registered technique as JSON: id, name, and why it cannot run here (or null).
#[wasm_bindgen]
pub fn techniques() -> String {
    PAGE.with_borrow(|page| serde_json::to_string(&page.techniques).unwrap_or_default())
}

/// The frame the address's `capture=N` kept, once it has been read back: an object with
/// `number`, `width`, `height` and `rgba` (sRGB RGBA8, rows from the top); `null` before.
#[wasm_bindgen]
pub fn frame() -> JsValue {
    let kept = PAGE.with_borrow(|page| page.kept.clone());
    let Some(kept) = kept else {
        return JsValue::NULL;
    };
    let Ok(kept) = kept.lock() else {
        return JsValue::NULL;
    };
    let Some(frame) = kept.as_ref() else {
        return JsValue::NULL;
    };
    let object = js_sys::Object::new();
    let set = |key: &str, value: JsValue| {
        js_sys::Reflect::set(&object, &JsValue::from_str(key), &value).is_ok()
    };
    let complete = set("number", JsValue::from_f64(frame.number as f64))
        && set("width", JsValue::from(frame.width))
        && set("height", JsValue::from(frame.height))
        && set(
            "rgba",
            js_sys::Uint8Array::from(frame.rgba.as_slice()).into(),
        );
    if complete {
        object.into()
    } else {
        JsValue::NULL
    }
}

/// Takes a file the user picked (a scene, OBJ, MTL, glTF or image): mounts it under `user/`
/// (by its name alone: the files a scene or model names must sit beside it) and, when it is a
/// scene or a model, opens it on the next frame (a model in a scene of its own, on a ground
/// and lit). Give it the files a scene or model names first.
#[wasm_bindgen]
pub fn open_file(name: &str, bytes: Vec<u8>) {
    let file_name = Path::new(name).file_name().map(PathBuf::from);
    let Some(file_name) = file_name else {
        log::warn!("{name}: not a file name");
        return;
    };
    let path = Path::new(USER_FOLDER).join(file_name);
    zoo_host::scene::files::mount(&path, bytes);
    let scene = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ron"));
    if scene || zoo_host::scene::stage::is_model(&path) {
        PAGE.with_borrow_mut(|page| page.to_open = Some(path));
    }
}
