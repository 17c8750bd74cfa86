//! The bundled font for text drawn into PNGs (plots, contact sheets): no system fonts needed.

use std::sync::Once;

use plotters::style::FontStyle;

/// Family name under which the bundled font is registered with plotters.
pub const FONT: &str = "sans-serif";

/// Registers the bundled font once.
pub fn register() {
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
