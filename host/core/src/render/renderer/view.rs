//! What a frame shows: the lit image, a G-buffer channel, a light's visibility or a technique
//! resource, full screen or as an overlay.

use std::str::FromStr;

/// What the output image shows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum View {
    /// The lit image.
    Final,
    /// Visibility of one light as greyscale.
    Visibility { light: usize },
    /// World normals as colour.
    Normals,
    /// Linearised depth.
    Depth,
    /// Albedo.
    Albedo,
    /// A resource the technique marks viewable.
    Resource(String),
}

impl FromStr for View {
    type Err = std::convert::Infallible;

    /// `final`, `visibility` (light 0), `visibility:N`, `normals`, `depth`, `albedo`, or a
    /// technique resource name.
    fn from_str(s: &str) -> Result<View, Self::Err> {
        Ok(match s {
            "final" => View::Final,
            "visibility" => View::Visibility { light: 0 },
            "normals" => View::Normals,
            "depth" => View::Depth,
            "albedo" => View::Albedo,
            other => match other
                .strip_prefix("visibility:")
                .and_then(|n| n.parse().ok())
            {
                Some(light) => View::Visibility { light },
                None => View::Resource(other.to_string()),
            },
        })
    }
}

/// A debug view blended over the final image.
#[derive(Debug, Clone, PartialEq)]
pub struct Overlay {
    pub view: View,
    /// 0 (invisible) to 1 (opaque).
    pub opacity: f32,
}
