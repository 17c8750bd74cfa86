//! Which texture a debug view shows, and how.

use super::{RenderError, Renderer, View};
use crate::render::debug_view::DebugSource;
use crate::technique::ViewMapping;

impl Renderer {
    pub(super) fn debug_source(&self, view: &View) -> Result<DebugSource<'_>, RenderError> {
        let (lo, hi) = self.scene.bounds();
        let farthest = [lo, hi]
            .iter()
            .map(|c| c.distance(self.camera.position))
            .fold(0.0, f32::max);
        Ok(match view {
            View::Final => unreachable!("the final view is the lighting pass"),
            View::Visibility { light } => {
                if *light >= self.lights.len() {
                    return Err(RenderError::View(
                        format!("visibility:{light}"),
                        format!("the scene has {} lights", self.lights.len()),
                    ));
                }
                let (layer, channel) = self.visibility.slots.slot(*light);
                DebugSource {
                    view: &self.visibility.layer_views[layer as usize],
                    mapping: ViewMapping::Channel {
                        channel,
                        min: 0.0,
                        max: 1.0,
                    },
                    linearize: None,
                    slice: None,
                }
            }
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
            View::Depth => DebugSource {
                view: &self.gbuffer.depth_sample_view,
                mapping: ViewMapping::Depth {
                    min: self.camera.near,
                    max: farthest.min(self.camera.far),
                },
                linearize: Some((self.camera.near, self.camera.far)),
                slice: None,
            },
            View::Resource(name) => {
                if self.technique.instance.debug_view(name).is_none()
                    && let Some(volume) = self.technique.instance.debug_volume(name)
                {
                    return Ok(DebugSource {
                        view: volume.view,
                        mapping: volume.mapping,
                        linearize: None,
                        slice: Some(volume.slice),
                    });
                }
                let image = self.technique.instance.debug_view(name).ok_or_else(|| {
                    let viewable: Vec<String> = self
                        .technique
                        .instance
                        .resources()
                        .into_iter()
                        .filter(|r| r.viewable)
                        .map(|r| r.name)
                        .collect();
                    RenderError::View(
                        name.clone(),
                        format!(
                            "not a view of `{}`; choose final, visibility[:N], normals, depth, albedo{}",
                            self.technique.registration.id,
                            viewable.iter().map(|v| format!(", {v}")).collect::<String>()
                        ),
                    )
                })?;
                DebugSource {
                    view: image.view,
                    mapping: image.mapping,
                    linearize: None,
                    slice: None,
                }
            }
        })
    }
}
