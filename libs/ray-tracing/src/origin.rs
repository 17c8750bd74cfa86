//! Where rays from a G-buffer surface start (`ray-tracing/origin.wgsl`): off the surface by the
//! judge's bound on the position's rounding ([`zoo_host::judge::reconstruction_error`]), then
//! along the ray past the rasteriser's error ([`RASTER_SUBPIXEL`]). Both factors are declared
//! once, here and in the judge; this module registers them as the generated shader module
//! [`ERROR_MODULE`].

use zoo_host::judge::{GBUFFER_POSITION_ERROR, SHADOW_RAY_TO_LIGHT};

/// How far the rasteriser may move a drawn surface off its plane, as a fraction of a pixel's
/// footprint at its distance: its snapping of vertices to a sub-pixel grid of 8 bits
/// (lavapipe's and common GPUs'; measured: 1/290 of a pixel on a grazing floor 170 m away).
pub const RASTER_SUBPIXEL: f32 = 1.0 / 256.0;

/// How many times the judge's rounding bound a G-buffer position may lie off its surface. On
/// lavapipe the bound holds as it is (its depth is interpolated in exact float). Browsers'
/// WebGPU keeps less depth precision than that, and says nothing of it: under Chromium on
/// SwiftShader rays from the G-buffer met their own surfaces at 8 times the bound (whole
/// walls in shadow) and agreed with lavapipe's frames at 100 times (tests/web.sh); the browser
/// build starts its rays 128 times the bound off the surface.
pub const POSITION_ERROR_FACTOR: f32 = if cfg!(target_arch = "wasm32") {
    128.0
} else {
    1.0
};

/// The generated module holding `RT_GBUFFER_POSITION_ERROR`, the judge's
/// [`GBUFFER_POSITION_ERROR`] (times [`POSITION_ERROR_FACTOR`]), `RT_RASTER_SUBPIXEL`,
/// [`RASTER_SUBPIXEL`], and `RT_TO_LIGHT`, the judge's [`SHADOW_RAY_TO_LIGHT`].
pub const ERROR_MODULE: &str = "ray-tracing/gbuffer_error.wgsl";

/// The text of [`ERROR_MODULE`]: the factors as WGSL literals that parse back to the same
/// `f32`s (Rust's shortest round-trip form).
fn error_module() -> String {
    let position_error = GBUFFER_POSITION_ERROR * POSITION_ERROR_FACTOR;
    format!(
        "// Generated from `zoo_judge::GBUFFER_POSITION_ERROR` (times\n\
         // `POSITION_ERROR_FACTOR`), `RASTER_SUBPIXEL` and `zoo_judge::SHADOW_RAY_TO_LIGHT`\n\
         // (libs/ray-tracing/src/origin.rs).\n\
         const RT_GBUFFER_POSITION_ERROR: f32 = {position_error:?};\n\
         const RT_RASTER_SUBPIXEL: f32 = {RASTER_SUBPIXEL:?};\n\
         const RT_TO_LIGHT: f32 = {SHADOW_RAY_TO_LIGHT:?};\n"
    )
}

zoo_host::link_anchor!("shader");
zoo_host::inventory::submit! {
    zoo_host::params::shader::GeneratedShader {
        name: ERROR_MODULE,
        source: error_module,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_generated_constants_are_the_judges_values() {
        let text = zoo_host::ShaderLibrary::embedded()
            .compose("ray-tracing/shadow_ray.wgsl")
            .unwrap()
            .source;
        let constant = |name: &str| -> f32 {
            let prefix = format!("const {name}: f32 = ");
            let line = (text.lines())
                .find_map(|l| l.strip_prefix(prefix.as_str()))
                .unwrap_or_else(|| panic!("the shadow rays import {name}"));
            line.trim_end_matches(';').parse().unwrap()
        };
        let position_error = constant("RT_GBUFFER_POSITION_ERROR");
        let expected = GBUFFER_POSITION_ERROR * POSITION_ERROR_FACTOR;
        assert_eq!(position_error.to_bits(), expected.to_bits());
        let to_light = constant("RT_TO_LIGHT");
        assert_eq!(to_light.to_bits(), SHADOW_RAY_TO_LIGHT.to_bits());
        assert!(to_light < 1.0);
    }
}
