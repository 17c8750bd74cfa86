//! The interactive viewer: `shadow-zoo` with no arguments. The 3D view renders off-screen
//! through the same renderer as the CLI and is shown in egui; panels switch techniques, edit
//! their generated parameters and the lights, pick debug views (full screen or overlaid),
//! compare two techniques (A/B split or difference), judge the view against the ray-traced
//! reference (in the background on the CPU, or live on the GPU as the view changes), and show
//! per-pass timings. Edits under `shaders/` are
//! reloaded while it runs. On a slow adapter a moving view renders fewer pixels
//! ([`adaptive`]).

pub mod adaptive;
pub mod camera;
pub mod hot_reload;
pub mod judgement;
pub mod lights;
mod live;
mod panels;
pub mod reference;
pub mod split;
pub mod state;
mod view;

#[cfg(feature = "window")]
mod window;

use std::path::Path;

pub use state::ViewerState;
pub use view::{ViewImages, clear_color};
#[cfg(all(feature = "window", not(target_arch = "wasm32")))]
pub use window::run;
#[cfg(feature = "window")]
pub use window::{ViewerApp, device_descriptor};

/// Without the `window` feature (the test build's choice), and in the browser build (whose
/// page starts the viewer, `web/`), there is no native viewer window.
#[cfg(not(all(feature = "window", not(target_arch = "wasm32"))))]
pub fn run() -> anyhow::Result<()> {
    anyhow::bail!(
        "this build has no viewer window (it was built without the `window` feature). Use the \
         headless commands: `shadow-zoo render --out frame.png`, `shadow-zoo compare ...`, \
         `shadow-zoo bench ...` (see `shadow-zoo --help`), or build with default features"
    )
}

/// Where remembered settings live between runs.
pub fn settings_path() -> std::path::PathBuf {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".config")))
        .unwrap_or_else(|| std::path::PathBuf::from("."));
    base.join("shadow-zoo").join("settings.ron")
}
