//! Which texture a debug view shows, and how.

use super::{RenderError, Renderer, View};
use crate::render::debug_view::DebugSource;
use crate::technique::ViewMapping;

impl Renderer {
    /// The texture `view` shows and how its values map to colours; an error names a view
    /// that does not exist here.
    pub(super) fn debug_source(&self, view: &View) -> Result<DebugSource<'_>, RenderError> {
        Ok(match view {
            View::Final => unreachable!("the final view is the lighting pass"),
            View::Visibility { light } => self.visibility_source(*light)?,
            View::Normals => DebugSource {
                view: &self.gbuffer.normal_view,
                mapping: ViewMapping::Color {
                    min: -1.0,
                    max: 1.0,
                },
                linearize: None,
                slice: None,
            },
            View::Albedo => DebugSource {
                view: &self.gbuffer.albedo_view,
                mapping: ViewMapping::Color { min: 0.0, max: 1.0 },
                linearize: None,
                slice: None,
            },
            View::Depth => self.depth_source(),
            View::Resource(name) => self.resource_source(name)?,
        })
    }

    /// Light `light`'s channel of the visibility targets.
    fn visibility_source(&self, light: usize) -> Result<DebugSource<'_>, RenderError> {
        if light >= self.lights.len() {
            return Err(RenderError::View(
                format!("visibility:{light}"),
                format!("the scene has {} lights", self.lights.len()),
            ));
        }
        let (layer, channel) = self.visibility.slots.slot(light);
        Ok(DebugSource {
            view: &self.visibility.layer_views[layer as usize],
            mapping: ViewMapping::Channel {
                channel,
                min: 0.0,
                max: 1.0,
            },
            linearize: None,
            slice: None,
        })
    }

    /// The G-buffer's depth, linearized, from the near plane to the scene's farthest corner
    /// (or the far plane, if nearer).
    fn depth_source(&self) -> DebugSource<'_> {
        let (lo, hi) = self.scene.bounds();
        let farthest = [lo, hi]
            .iter()
            .map(|c| c.distance(self.camera.position))
            .fold(0.0, f32::max);
        DebugSource {
            view: &self.gbuffer.depth_sample_view,
            mapping: ViewMapping::Depth {
                min: self.camera.near,
                max: farthest.min(self.camera.far),
            },
            linearize: Some((self.camera.near, self.camera.far)),
            slice: None,
        }
    }

    /// The technique's debug image `name`, or else its debug volume `name`.
    fn resource_source(&self, name: &str) -> Result<DebugSource<'_>, RenderError> {
        let instance = &self.technique.instance;
        if instance.debug_view(name).is_none()
            && let Some(volume) = instance.debug_volume(name)
        {
            return Ok(DebugSource {
                view: volume.view,
                mapping: volume.mapping,
                linearize: None,
                slice: Some(volume.slice),
            });
        }
        let image = instance
            .debug_view(name)
            .ok_or_else(|| self.unknown_view(name))?;
        Ok(DebugSource {
            view: image.view,
            mapping: image.mapping,
            linearize: None,
            slice: None,
        })
    }

    /// The error for a view named `name` that neither the host nor the technique has,
    /// listing those there are.
    fn unknown_view(&self, name: &str) -> RenderError {
        let viewable: Vec<String> = self
            .technique
            .instance
            .resources()
            .into_iter()
            .filter(|r| r.viewable)
            .map(|r| r.name)
            .collect();
        RenderError::View(
            name.to_string(),
            format!(
                "not a view of `{}`; choose final, visibility[:N], normals, depth, albedo{}",
                self.technique.registration.id,
                viewable
                    .iter()
                    .map(|v| format!(", {v}"))
                    .collect::<String>()
            ),
        )
    }
}
