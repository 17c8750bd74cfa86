//! The viewer's window: eframe around [`ViewerState`], the renderer's images shown through
//! egui-wgpu. Built with the `window` feature (on by default); the browser build (`web/`)
//! runs the same [`ViewerApp`] on eframe's web runner.

#[cfg(not(target_arch = "wasm32"))]
use std::path::Path;
use std::sync::Arc;

use anyhow::Context as _;
use web_time::Instant;
use zoo_host::glam::UVec2;
use zoo_host::{Camera, GpuContext, Light, Scene, ShaderLibrary, wgpu};

use super::adaptive::{AdaptiveResolution, Motion};
use super::{ViewImages, ViewerState, settings_path};

/// A renderer image registered with egui, re-registered when its view changes size.
#[derive(Default)]
struct NativeTexture {
    id: Option<egui::TextureId>,
    size: UVec2,
}

impl NativeTexture {
    /// Points egui at `view` (of `size`) and returns the texture id; `None` frees it.
    fn update(
        &mut self,
        render_state: &egui_wgpu::RenderState,
        view: Option<(&wgpu::TextureView, UVec2)>,
    ) -> Option<egui::TextureId> {
        let mut renderer = render_state.renderer.write();
        let Some((view, size)) = view else {
            if let Some(id) = self.id.take() {
                renderer.free_texture(&id);
            }
            return None;
        };
        match self.id {
            Some(id) if self.size == size => renderer.update_egui_texture_from_wgpu_texture(
                &render_state.device,
                view,
                wgpu::FilterMode::Linear,
                id,
            ),
            _ => {
                if let Some(id) = self.id.take() {
                    renderer.free_texture(&id);
                }
                self.id = Some(renderer.register_native_texture(
                    &render_state.device,
                    view,
                    wgpu::FilterMode::Linear,
                ));
                self.size = size;
            }
        }
        self.id
    }
}

/// The eframe application around [`ViewerState`].
pub struct ViewerApp {
    pub state: ViewerState,
    /// Render at this size whatever the view's size (the browser test's fixed frames).
    pub fixed_size: Option<UVec2>,
    resolution: AdaptiveResolution,
    /// The camera and lights of the last frame, to tell a moving view from a still one.
    last_view: Option<(Camera, Vec<Light>)>,
    /// When the last frame started.
    last_frame: Option<Instant>,
    /// When the view last changed.
    motion: Motion,
    /// The clock `motion` reads.
    started: Instant,
    a: NativeTexture,
    b: NativeTexture,
    difference: NativeTexture,
}

impl eframe::App for ViewerApp {
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        super::clear_color(visuals)
    }

    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let Some(render_state) = frame.wgpu_render_state() else {
            return;
        };
        // Render at the size the central view had last frame (fewer pixels while it moves on
        // a slow adapter).
        let points = self.state.view_points();
        let full = if points.x < 16.0 || points.y < 16.0 {
            UVec2::new(960, 640)
        } else {
            UVec2::new(
                (points.x * ui.pixels_per_point()) as u32,
                (points.y * ui.pixels_per_point()) as u32,
            )
        }
        .clamp(UVec2::splat(16), UVec2::splat(4096));
        let now = Instant::now();
        if let Some(last) = self.last_frame.replace(now) {
            self.resolution.frame_took((now - last).as_secs_f64() * 1e3);
        }
        let view = (self.state.camera.camera(), self.state.lights.clone());
        let changed = self.last_view.as_ref().is_some_and(|last| *last != view);
        self.last_view = Some(view);
        let moving = (self.motion).moving(changed, (now - self.started).as_secs_f64() * 1e3);
        let size = match self.fixed_size {
            Some(size) => size,
            None => self.resolution.size(full, moving),
        };
        self.state.render(size);
        let state = &self.state;
        let output_size = state.renderer.size();
        let images = ViewImages {
            a: self.a.update(
                render_state,
                Some((state.renderer.output_view(), output_size)),
            ),
            b: self.b.update(
                render_state,
                state
                    .ab
                    .as_ref()
                    .map(|ab| (ab.renderer.output_view(), output_size)),
            ),
            difference: self.difference.update(
                render_state,
                state
                    .ab
                    .as_ref()
                    .and_then(|ab| ab.difference.view())
                    .map(|v| (v, output_size)),
            ),
        };
        self.state.ui(ui, images);
        ui.ctx().request_repaint();
    }

    fn on_exit(&mut self) {
        // The last settings per technique are remembered between runs.
        if let Err(e) = self.state.save_settings(&settings_path()) {
            zoo_host::log::warn!("cannot save viewer settings: {e}");
        }
    }
}

impl ViewerApp {
    /// The viewer of `scene` on eframe's wgpu device.
    pub fn new(
        cc: &eframe::CreationContext<'_>,
        scene: Scene,
        shaders: ShaderLibrary,
    ) -> anyhow::Result<ViewerApp> {
        let render_state = cc
            .wgpu_render_state
            .as_ref()
            .context("the viewer needs the wgpu renderer")?;
        let gpu = Arc::new(GpuContext::from_parts(
            render_state.instance.clone(),
            render_state.adapter.clone(),
            render_state.device.clone(),
            render_state.queue.clone(),
        ));
        let state = ViewerState::with_shaders(gpu, scene, UVec2::new(960, 640), shaders)?;
        Ok(ViewerApp {
            state,
            fixed_size: None,
            resolution: AdaptiveResolution::default(),
            last_view: None,
            last_frame: None,
            motion: Motion::default(),
            started: Instant::now(),
            a: NativeTexture::default(),
            b: NativeTexture::default(),
            difference: NativeTexture::default(),
        })
    }
}

/// The device the viewer asks eframe for: every feature a technique needs or would use.
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    let none_removed = wgpu::Features::empty();
    GpuContext::device_descriptor(adapter, "shadow-zoo viewer device", none_removed)
}

/// Shaders from the working folder's `shaders/` (or the build's), for hot reload; the
/// embedded copies when neither exists.
#[cfg(not(target_arch = "wasm32"))]
fn shader_library() -> ShaderLibrary {
    let local = Path::new("shaders");
    if local.is_dir() {
        let root = local.canonicalize().unwrap_or_else(|_| local.to_path_buf());
        return ShaderLibrary::from_disk(root);
    }
    match ShaderLibrary::build_time_root() {
        Some(root) => ShaderLibrary::from_disk(root),
        None => ShaderLibrary::embedded(),
    }
}

/// Opens the viewer on the default scene. Fails with a pointer to the headless commands when
/// no window or adapter is available.
#[cfg(not(target_arch = "wasm32"))]
pub fn run() -> anyhow::Result<()> {
    let mut options = eframe::NativeOptions {
        renderer: eframe::Renderer::Wgpu,
        viewport: egui::ViewportBuilder::default()
            .with_title("Shadow Zoo")
            .with_inner_size([1400.0, 900.0]),
        ..Default::default()
    };
    if let egui_wgpu::WgpuSetup::CreateNew(create) = &mut options.wgpu_options.wgpu_setup {
        create.device_descriptor = Arc::new(device_descriptor);
        create.native_adapter_selector = Some(Arc::new(
            |adapters: &[wgpu::Adapter], surface: Option<&wgpu::Surface<'_>>| {
                zoo_host::gpu::adapter::choose_adapter_with(
                    adapters,
                    wgpu::Backends::all(),
                    |adapter| {
                        surface
                            .filter(|s| !adapter.is_surface_supported(s))
                            .map(|_| "cannot present to the window".to_string())
                    },
                )
                .map_err(|e| e.to_string())
            },
        ));
    }
    let result = eframe::run_native(
        "Shadow Zoo",
        options,
        Box::new(|cc| {
            let scene = crate::setup::load_scene(None)?;
            let mut app = ViewerApp::new(cc, scene, shader_library())?;
            app.state.restore_settings(&settings_path());
            Ok(Box::new(app))
        }),
    );
    result.map_err(|e| {
        anyhow::anyhow!(
            "cannot open the viewer ({e}). Without a display or a usable adapter use the headless \
             commands: `shadow-zoo render --out frame.png`, `shadow-zoo compare ...`, \
             `shadow-zoo bench ...` (see `shadow-zoo --help`)"
        )
    })
}
