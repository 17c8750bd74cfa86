//! Shadow Zoo in the browser: the native viewer ([`shadow_zoo::viewer::ViewerApp`]) on
//! eframe's web runner, drawing through the browser's WebGPU. `web/build.sh` builds it into a
//! static folder; `tests/web.sh` runs it in headless Chromium.
//!
//! The page calls [`start`] with its canvas. The address's query picks what to show first:
//! `scene=NAME.ron` (a bundled scene), `technique=ID`, `set=KEY=VALUE` (its parameters),
//! `size=WxH` (render at that size whatever the view's, as the test does), `capture=N`
//! (keep frame N for [`frame`]) and `judge=live` (judge the view live on the GPU; [`status`]
//! reports the verdict).
#![cfg(target_arch = "wasm32")]

mod app;
mod bundle;
mod capture;
mod constructors;
mod query;

use wasm_bindgen::prelude::*;

pub use app::{frame, open_file, status, techniques};

/// Starts the viewer in `canvas`.
#[wasm_bindgen]
pub async fn start(canvas: web_sys::HtmlCanvasElement) -> Result<(), JsValue> {
    constructors::register_techniques();
    eframe::WebLogger::init(log::LevelFilter::Warn).ok();
    bundle::mount_scenes();
    let query = query::Query::from_location();
    app::start(canvas, query).await
}
