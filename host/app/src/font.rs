//! The bundled font for text drawn into PNGs (plots, contact sheets): no system fonts needed.

/// Family name under which the bundled font is registered with plotters.
pub const FONT: &str = "sans-serif";

/// Registers the bundled font once (in the browser build plotters draws text through the
/// page's own fonts instead).
pub fn register() {
    #[cfg(not(target_arch = "wasm32"))]
    register_bundled();
}

#[cfg(not(target_arch = "wasm32"))]
fn register_bundled() {
    use plotters::style::FontStyle;
    use std::sync::Once;

    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        )
        .is_err()
        {
            zoo_host::log::warn!("the bundled font could not be loaded");
        }
    });
}
