//! The virtual layers of every light and where their pages lie in the page table.
//!
//! A directional light's virtual map is a clipmap: `levels` square levels centred on the
//! camera, level k covering `first_level_size` · 2^k with `pages` pages a side, each
//! level's centre snapped to its page grid: a level scrolls by whole pages as the camera
//! crosses them, and its page table is a window over the level's endless page grid, addressed
//! modulo its size, so the pages still inside the window keep their entries. A spot light's
//! virtual map is one frustum around its cone with mip levels (level k: `pages` >> k pages a
//! side), a point light's six cube faces with mip levels each. The page table holds one entry
//! per page of every layer, layer after layer.

use zoo_host::glam::camera::rh::{proj::directx, view::look_to_mat4};
use zoo_host::glam::{IVec2, Mat4, Vec3};
use zoo_host::scene::{Camera, Light, LightKind};
use zoo_shadow_maps::light_space::{CUBE_FACES, perspective_near, resolvable, spot_frustum};

/// The layers' sizes, from the parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sizes {
    /// Pages a side of a clipmap level, and of a spot or point light's finest mip.
    pub pages: u32,
    /// Clipmap levels of a directional light.
    pub clip_levels: u32,
    /// Metres the finest clipmap level covers.
    pub first_level_size: f32,
    /// Texels a page side.
    pub page_size: u32,
}

impl Sizes {
    /// Mip levels of a spot or point light's face: down to one page a side.
    pub fn mip_levels(&self) -> u32 {
        self.pages.max(1).ilog2() + 1
    }
}

/// One light's layers: `faces` x `levels`, face by face, finest level first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightLayers {
    pub kind: LightKind,
    pub first_layer: u32,
    pub faces: u32,
    pub levels: u32,
    pub clipmap: bool,
}

/// Where every light's layers and their pages lie.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub sizes: Sizes,
    pub lights: Vec<LightLayers>,
    /// Each layer's pages a side and first page-table entry.
    pub layers: Vec<(u32, u32)>,
    /// Each page-table entry's layer.
    pub entry_layers: Vec<u32>,
}

impl Layout {
    /// The layout for `lights` at `sizes`.
    pub fn new(lights: &[Light], sizes: Sizes) -> Layout {
        let mut layout = Layout {
            sizes,
            lights: Vec::new(),
            layers: Vec::new(),
            entry_layers: Vec::new(),
        };
        for light in lights {
            let (faces, levels, clipmap) = match light.kind {
                LightKind::Directional => (1, sizes.clip_levels, true),
                LightKind::Spot => (1, sizes.mip_levels(), false),
                LightKind::Point => (6, sizes.mip_levels(), false),
            };
            layout.lights.push(LightLayers {
                kind: light.kind,
                first_layer: layout.layers.len() as u32,
                faces,
                levels,
                clipmap,
            });
            for _face in 0..faces {
                for level in 0..levels {
                    let pages = if clipmap {
                        sizes.pages
                    } else {
                        (sizes.pages >> level).max(1)
                    };
                    let layer = layout.layers.len() as u32;
                    let first_entry = layout.entry_layers.len() as u32;
                    layout.layers.push((pages, first_entry));
                    let entries = (pages * pages) as usize;
                    layout
                        .entry_layers
                        .extend(std::iter::repeat_n(layer, entries));
                }
            }
        }
        layout
    }

    /// The light kinds it was laid out for.
    pub fn kinds(&self) -> Vec<LightKind> {
        self.lights.iter().map(|l| l.kind).collect()
    }

    /// Page-table entries in all.
    pub fn entries(&self) -> u32 {
        self.entry_layers.len() as u32
    }
}

/// Depth range along a directional light's direction holding every caster: the scene's box
/// seen along it, widened a little.
pub fn depth_range(direction: Vec3, bounds: (Vec3, Vec3)) -> (f32, f32) {
    let (lo, hi) = bounds;
    let corners = (0..8).map(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    });
    let (near, far) = corners
        .map(|c| c.dot(direction))
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), d| {
            (a.min(d), b.max(d))
        });
    let margin = resolvable((far - near) * 0.01, near.abs().max(far.abs()));
    (near - margin, far + margin)
}

/// Where a layer lies this frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerView {
    /// Its view and projection.
    pub view_proj: Mat4,
    /// The same with its window centred on the light's axis: what stays while a clipmap level
    /// only scrolls.
    pub unscrolled: Mat4,
    /// Its window's first page (left, top) on the level's page grid, whose pages keep their
    /// page-table entries (modulo the window's size) as it scrolls; 0 for mip levels.
    pub origin: IVec2,
}

impl LayerView {
    /// A layer that does not scroll.
    fn fixed(view_proj: Mat4) -> LayerView {
        LayerView {
            view_proj,
            unscrolled: view_proj,
            origin: IVec2::ZERO,
        }
    }
}

/// Clipmap level `level` of a light along `direction`, centred on `camera` snapped to the
/// level's page grid, over the depth range of `bounds`.
pub fn clip_level(
    direction: Vec3,
    sizes: &Sizes,
    level: u32,
    camera: Vec3,
    bounds: (Vec3, Vec3),
) -> LayerView {
    let direction = direction.normalize();
    let rotation = look_to_mat4(Vec3::ZERO, direction, up_for(direction));
    let extent = sizes.first_level_size * (1u64 << level.min(62)) as f32;
    let page = extent / sizes.pages as f32;
    let centre = rotation.transform_point3(camera);
    let (kx, ky) = ((centre.x / page).round(), (centre.y / page).round());
    let (x, y) = (kx * page, ky * page);
    let (near, far) = depth_range(direction, bounds);
    let h = extent * 0.5;
    debug_assert!(near < far);
    // Pages run left to right and top (largest y) down.
    let half = (sizes.pages / 2) as i32;
    LayerView {
        view_proj: directx::orthographic(x - h, x + h, y - h, y + h, near, far) * rotation,
        unscrolled: directx::orthographic(-h, h, -h, h, near, far) * rotation,
        origin: IVec2::new(kx as i32 - half, -(ky as i32 + half)),
    }
}

/// The clipmap level whose pages are at least as wide as the whole of `bounds` seen from
/// `camera` along `direction` (at most `levels - 1`): every pixel of the scene reads one of at
/// most 2x2 of its pages, the fallback that is allocated first, so a pool too small for the
/// finer levels still shadows every pixel, coarsely.
pub fn fallback_level(direction: Vec3, sizes: &Sizes, camera: Vec3, bounds: (Vec3, Vec3)) -> u32 {
    let (lo, hi) = bounds;
    let rotation = look_to_mat4(Vec3::ZERO, direction.normalize(), up_for(direction));
    let centre = rotation.transform_point3(camera);
    let reach = (0..8)
        .map(|i| {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let q = rotation.transform_point3(corner) - centre;
            q.x.abs().max(q.y.abs())
        })
        .fold(0.0f32, f32::max);
    // A page of level k is first_level_size · 2^k / pages wide.
    let page = 2.0 * reach * sizes.pages as f32;
    let level = (page / sizes.first_level_size).max(1.0).log2().ceil();
    (level as u32).min(sizes.clip_levels.saturating_sub(1))
}

/// An up vector for a view along `direction`.
fn up_for(direction: Vec3) -> Vec3 {
    if direction.normalize().y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Where every layer of `light` (`layers` of the layout) lies this frame.
pub fn light_layers(
    light: &Light,
    layers: &LightLayers,
    sizes: &Sizes,
    camera: &Camera,
    bounds: (Vec3, Vec3),
) -> Vec<LayerView> {
    if layers.clipmap {
        return (0..layers.levels)
            .map(|level| clip_level(light.direction, sizes, level, camera.position, bounds))
            .collect();
    }
    let faces: Vec<Mat4> = match light.kind {
        LightKind::Point => CUBE_FACES
            .iter()
            .map(|&(direction, up)| {
                let near = perspective_near(light.range);
                let projection =
                    directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, near, light.range);
                projection * look_to_mat4(light.position, direction, up)
            })
            .collect(),
        _ => vec![spot_frustum(light).view_proj],
    };
    // Mip levels share their face's projection.
    faces
        .into_iter()
        .flat_map(|m| std::iter::repeat_n(LayerView::fixed(m), layers.levels as usize))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::glam::{Vec2, Vec4Swizzles};

    fn sizes() -> Sizes {
        Sizes {
            pages: 16,
            clip_levels: 6,
            first_level_size: 8.0,
            page_size: 128,
        }
    }

    fn light(kind: LightKind) -> Light {
        Light {
            kind,
            position: Vec3::new(1.0, 5.0, 2.0),
            direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
            radiance: Vec3::ONE,
            range: 20.0,
            spot_angle: 0.5,
            spot_softness: 0.1,
            radius: 0.1,
        }
    }

    #[test]
    fn layers_and_entries_follow_the_light_kinds() {
        let lights = [
            light(LightKind::Directional),
            light(LightKind::Spot),
            light(LightKind::Point),
        ];
        let layout = Layout::new(&lights, sizes());
        // 16 pages: mips of 16, 8, 4, 2 and 1 pages a side (341 entries a face).
        assert_eq!(sizes().mip_levels(), 5);
        let counts: Vec<(u32, u32, u32)> = (layout.lights.iter())
            .map(|l| (l.first_layer, l.faces, l.levels))
            .collect();
        assert_eq!(counts, [(0, 1, 6), (6, 1, 5), (11, 6, 5)]);
        assert_eq!(layout.layers.len(), 41);
        assert_eq!(layout.entries(), 6 * 256 + 341 + 6 * 341);
        // Entries run layer by layer.
        assert_eq!(layout.layers[7], (8, 6 * 256 + 256));
        assert_eq!(layout.entry_layers[6 * 256 + 256], 7);
        assert_eq!(layout.entry_layers[6 * 256 + 255], 6);
    }

    #[test]
    fn clip_levels_double_and_move_only_with_whole_pages() {
        let s = sizes();
        let bounds = (Vec3::splat(-50.0), Vec3::splat(50.0));
        let dir = Vec3::new(0.3, -1.0, 0.2);
        let camera = Vec3::new(3.1, 1.0, -2.2);
        let m0 = clip_level(dir, &s, 0, camera, bounds).view_proj;
        let m3 = clip_level(dir, &s, 3, camera, bounds).view_proj;
        // The camera lies inside every level, within a page of the centre.
        for (m, pages) in [(m0, 16.0), (m3, 16.0)] {
            let ndc = (m * camera.extend(1.0)).xy();
            assert!(ndc.abs().max_element() <= 2.0 / pages + 1e-5, "{ndc}");
        }
        // Level 3 covers 8x level 0: a world step maps to an eighth of the NDC distance.
        let step = Vec3::new(1.0, 0.0, 0.0);
        let d0 = (m0 * (camera + step).extend(1.0)).xy() - (m0 * camera.extend(1.0)).xy();
        let d3 = (m3 * (camera + step).extend(1.0)).xy() - (m3 * camera.extend(1.0)).xy();
        assert!((d0.length() / d3.length() - 8.0).abs() < 1e-3);
        // Moving less than a page (level 0: 0.5 m) leaves it, or moves it by one page exactly.
        let moved = clip_level(dir, &s, 0, camera + Vec3::new(0.05, 0.0, 0.0), bounds).view_proj;
        let shift = (moved * camera.extend(1.0)).xy() - (m0 * camera.extend(1.0)).xy();
        let pages = shift.abs() * 16.0 / 2.0;
        assert!(pages.max_element() < 1e-3 || (pages.max_element() - 1.0).abs() < 1e-3);
        // Every caster of the scene lies in the depth range.
        for corner in [bounds.0, bounds.1, Vec3::new(-50.0, 50.0, -50.0)] {
            let z = (m0 * corner.extend(1.0)).z;
            assert!((0.0..=1.0).contains(&z), "{z}");
        }
    }

    /// The page of the level's grid a world point falls in: its page in the window plus the
    /// window's origin (as the shaders address the page table).
    fn grid_page(view: &LayerView, pages: u32, p: Vec3) -> IVec2 {
        let ndc = (view.view_proj * p.extend(1.0)).xy();
        let uv = Vec2::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        (uv * pages as f32).floor().as_ivec2() + view.origin
    }

    #[test]
    fn a_scrolling_level_keeps_each_world_page_on_its_grid_page() {
        let s = sizes();
        let bounds = (Vec3::splat(-50.0), Vec3::splat(50.0));
        let dir = Vec3::new(0.3, -1.0, 0.2);
        let camera = Vec3::new(3.1, 1.0, -2.2);
        let points = [camera, camera + Vec3::new(1.3, 0.2, -0.7), camera - Vec3::X];
        let before = clip_level(dir, &s, 1, camera, bounds);
        // Level 1's pages are 1 m wide: walk 0.25 m at a time across several of them.
        let mut scrolled = 0;
        for step in 1..40 {
            let walked = camera + Vec3::new(0.25, 0.0, 0.1) * step as f32;
            let after = clip_level(dir, &s, 1, walked, bounds);
            assert_eq!(after.unscrolled, before.unscrolled);
            scrolled += usize::from(after.origin != before.origin);
            for p in points {
                assert_eq!(
                    grid_page(&before, 16, p),
                    grid_page(&after, 16, p),
                    "{step}"
                );
            }
        }
        assert!(
            scrolled > 30,
            "the window left its first place in {scrolled} steps of 39"
        );
        // A turning light moves the whole level.
        let turned = clip_level(dir + Vec3::X * 0.1, &s, 1, camera, bounds);
        assert_ne!(turned.unscrolled, before.unscrolled);
    }

    #[test]
    fn the_fallback_level_holds_the_scene_in_two_by_two_pages() {
        let s = Sizes {
            clip_levels: 16,
            ..sizes()
        };
        let dir = Vec3::new(0.3, -1.0, 0.2);
        let camera = Vec3::new(3.1, 1.0, -2.2);
        for half in [0.01f32, 0.5, 3.0, 20.0, 90.0] {
            let bounds = (Vec3::splat(-half), Vec3::splat(half));
            let level = fallback_level(dir, &s, camera, bounds);
            let m = clip_level(dir, &s, level, camera, bounds).view_proj;
            // The pages (of 16 a side) each corner falls in, over both axes.
            let page = |c: Vec3| {
                let ndc = (m * c.extend(1.0)).xy();
                assert!(
                    ndc.abs().max_element() <= 1.0,
                    "half {half}: outside level {level}"
                );
                ((ndc * 0.5 + 0.5) * 16.0).floor()
            };
            let corners = (0..8).map(|i| {
                Vec3::new(
                    if i & 1 == 0 { -half } else { half },
                    if i & 2 == 0 { -half } else { half },
                    if i & 4 == 0 { -half } else { half },
                )
            });
            let pages: Vec<_> = corners.map(page).collect();
            let span = pages
                .iter()
                .fold((pages[0], pages[0]), |(a, b), p| (a.min(*p), b.max(*p)));
            assert!(
                (span.1 - span.0).max_element() <= 1.0,
                "half {half}: {span:?}"
            );
        }
        // Past the last level it stops there.
        let huge = (Vec3::splat(-1e7), Vec3::splat(1e7));
        assert_eq!(fallback_level(dir, &s, camera, huge), 15);
    }

    #[test]
    fn local_lights_repeat_their_faces_over_the_mips() {
        let s = sizes();
        let bounds = (Vec3::splat(-50.0), Vec3::splat(50.0));
        let camera = Camera {
            position: Vec3::new(0.0, 2.0, 8.0),
            target: Vec3::ZERO,
            fov_y: 0.9,
            near: 0.1,
            far: 100.0,
        };
        let point = light(LightKind::Point);
        let layout = Layout::new(std::slice::from_ref(&point), s);
        let layers = light_layers(&point, &layout.lights[0], &s, &camera, bounds);
        assert_eq!(layers.len(), 30);
        assert_eq!(layers[0], layers[4]);
        assert_ne!(layers[4], layers[5]);
        assert!(layers.iter().all(|l| l.origin == IVec2::ZERO));
        // A point below the light projects into face -Y's centre.
        let clip = layers[3 * 5].view_proj * (point.position - Vec3::Y).extend(1.0);
        let ndc = clip.xyz() / clip.w;
        assert!(ndc.truncate().length() < 1e-4 && (0.0..1.0).contains(&ndc.z));
    }
}
