//! The interactive viewer: `shadow-zoo` with no arguments. The 3D view renders off-screen
//! through the same renderer as the CLI and is shown in egui; panels switch techniques, edit
//! their generated parameters, pick debug views and show per-pass timings.

pub mod state;

use std::path::Path;
use std::sync::Arc;

use anyhow::Context as _;
use zoo_host::GpuContext;
use zoo_host::glam::UVec2;

pub use state::ViewerState;

/// The eframe application around [`ViewerState`].
struct ViewerApp {
    state: ViewerState,
    texture: Option<egui::TextureId>,
    /// The output view the texture was registered for (re-registered after a resize).
    registered_size: UVec2,
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let Some(render_state) = frame.wgpu_render_state() else {
            return;
        };
        // Render at the size the image area had last frame (the side and bottom panels
        // take the rest).
        let available = ui.available_size();
        let size = UVec2::new(
            ((available.x - 300.0).max(64.0) * ui.pixels_per_point()) as u32,
            ((available.y - 200.0).max(64.0) * ui.pixels_per_point()) as u32,
        )
        .min(UVec2::splat(4096));
        self.state.render(size);
        let view = self.state.renderer.output_view();
        let mut renderer = render_state.renderer.write();
        match self.texture {
            Some(id) if self.registered_size == self.state.renderer.size() => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &render_state.device,
                    view,
                    wgpu::FilterMode::Linear,
                    id,
                );
            }
            _ => {
                if let Some(id) = self.texture.take() {
                    renderer.free_texture(&id);
                }
                self.texture = Some(renderer.register_native_texture(
                    &render_state.device,
                    view,
                    wgpu::FilterMode::Linear,
                ));
                self.registered_size = self.state.renderer.size();
            }
        }
        drop(renderer);
        self.state.ui(ui, self.texture);
        ui.ctx().request_repaint();
    }

    fn on_exit(&mut self) {
        // The last settings per technique are remembered between runs.
        if let Err(e) = self.state.save_settings(&settings_path()) {
            zoo_host::log::warn!("cannot save viewer settings: {e}");
        }
    }
}

use zoo_host::wgpu;

/// Opens the viewer on the default scene. Fails with a pointer to the headless commands when
/// no window or adapter is available.
pub fn run() -> anyhow::Result<()> {
    let mut options = eframe::NativeOptions {
        renderer: eframe::Renderer::Wgpu,
        viewport: egui::ViewportBuilder::default()
            .with_title("Shadow Zoo")
            .with_inner_size([1400.0, 900.0]),
        ..Default::default()
    };
    if let egui_wgpu::WgpuSetup::CreateNew(create) = &mut options.wgpu_options.wgpu_setup {
        create.device_descriptor = Arc::new(|adapter: &wgpu::Adapter| wgpu::DeviceDescriptor {
            label: Some("shadow-zoo viewer device"),
            required_features: GpuContext::wanted_features(adapter),
            required_limits: adapter.limits(),
            ..Default::default()
        });
    }
    let result = eframe::run_native(
        "Shadow Zoo",
        options,
        Box::new(|cc| {
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
            let scene = crate::commands::load_scene(None)?;
            let mut state = ViewerState::new(gpu, scene, UVec2::new(960, 640))?;
            let settings = settings_path();
            if settings.is_file()
                && let Err(e) = state.load_settings(&settings)
            {
                state.status = format!("ignored saved settings: {e}");
            }
            Ok(Box::new(ViewerApp {
                state,
                texture: None,
                registered_size: UVec2::ZERO,
            }))
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

/// Where remembered settings live between runs.
pub fn settings_path() -> std::path::PathBuf {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".config")))
        .unwrap_or_else(|| std::path::PathBuf::from("."));
    base.join("shadow-zoo").join("settings.ron")
}
