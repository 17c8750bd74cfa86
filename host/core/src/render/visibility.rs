//! Per-light visibility storage.
//!
//! Visibility lives in an `Rgba8Unorm` 2D array texture; each light maps to a slot = (layer,
//! channel). By default every light has its own slot. A technique that writes a light's
//! visibility only inside that light's influence volume may let lights whose volumes do not
//! overlap share a slot, so memory does not grow with one full-screen channel per light.

use glam::{UVec2, Vec3};

use crate::gpu::GpuContext;
use crate::scene::{Camera, Light, LightKind};

/// Texture format of the visibility array.
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// How the visibility array is used: written as attachments or storage, read by lighting,
/// copied for readback.
pub const VISIBILITY_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::STORAGE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// What a technique assigns visibility slots for ([`crate::ShadowTechnique::assign_slots`]).
#[derive(Debug, Clone, Copy)]
pub struct SlotRequest<'a> {
    /// The current lights.
    pub lights: &'a [Light],
    /// The current camera.
    pub camera: &'a Camera,
    /// Output width over height.
    pub aspect: f32,
}

impl SlotRequest<'_> {
    /// The camera's world-to-clip matrix (depth 0 at near, 1 at far).
    pub fn view_proj(&self) -> glam::Mat4 {
        self.camera.projection(self.aspect) * self.camera.view()
    }
}

/// Which slot each light writes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlotAssignment {
    /// Slot index per light; slot `s` is layer `s / 4`, channel `s % 4`.
    slots: Vec<u32>,
    slot_count: u32,
}

impl SlotAssignment {
    /// One slot per light.
    pub fn one_per_light(light_count: usize) -> SlotAssignment {
        SlotAssignment {
            slots: (0..light_count as u32).collect(),
            slot_count: light_count as u32,
        }
    }

    /// Slot `slots[i]` for light `i`; the slot count is one more than the largest.
    pub fn from_slots(slots: Vec<u32>) -> SlotAssignment {
        let slot_count = slots.iter().max().map_or(0, |s| s + 1);
        SlotAssignment { slots, slot_count }
    }

    /// Greedy colouring: each light takes the first slot none of whose lights' influence
    /// spheres intersect its own. Directional lights reach everywhere and keep a slot alone.
    pub fn packed(lights: &[Light]) -> SlotAssignment {
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut slots = Vec::with_capacity(lights.len());
        for (i, light) in lights.iter().enumerate() {
            let free = members.iter().position(|group| {
                group
                    .iter()
                    .all(|&j| !influences_overlap(light, &lights[j]))
            });
            let slot = match free {
                Some(s) => s,
                None => {
                    members.push(Vec::new());
                    members.len() - 1
                }
            };
            members[slot].push(i);
            slots.push(slot as u32);
        }
        SlotAssignment {
            slots,
            slot_count: members.len() as u32,
        }
    }

    /// (layer, channel) of light `light`.
    pub fn slot(&self, light: usize) -> (u32, u32) {
        let s = self.slots[light];
        (s / 4, s % 4)
    }

    /// Number of lights assigned.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether no light is assigned.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Number of distinct slots.
    pub fn slot_count(&self) -> u32 {
        self.slot_count
    }

    /// Array layers needed (at least one).
    pub fn layer_count(&self) -> u32 {
        self.slot_count.div_ceil(4).max(1)
    }

    /// The lights sharing slot `slot`.
    pub fn lights_in_slot(&self, slot: u32) -> impl Iterator<Item = usize> + '_ {
        self.slots
            .iter()
            .enumerate()
            .filter(move |(_, s)| **s == slot)
            .map(|(i, _)| i)
    }
}

/// Bounding sphere of a light's influence, or `None` if unbounded.
fn influence_sphere(light: &Light) -> Option<(Vec3, f32)> {
    match light.kind {
        LightKind::Directional => None,
        LightKind::Point | LightKind::Spot => Some((light.position, light.range)),
    }
}

fn influences_overlap(a: &Light, b: &Light) -> bool {
    match (influence_sphere(a), influence_sphere(b)) {
        (Some((pa, ra)), Some((pb, rb))) => pa.distance(pb) < ra + rb,
        _ => true,
    }
}

/// The visibility array texture and its views.
pub struct VisibilityTargets {
    pub texture: wgpu::Texture,
    /// All layers, for the lighting pass.
    pub array_view: wgpu::TextureView,
    /// One 2D view per layer, for render attachments.
    pub layer_views: Vec<wgpu::TextureView>,
    pub slots: SlotAssignment,
}

impl VisibilityTargets {
    /// Creates storage for `slots` at `size`.
    pub fn new(gpu: &GpuContext, size: UVec2, slots: SlotAssignment) -> VisibilityTargets {
        let layers = slots.layer_count();
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("visibility slots"),
            size: wgpu::Extent3d {
                width: size.x,
                height: size.y,
                depth_or_array_layers: crate::gpu::array_layers(gpu, size.x, size.y, layers),
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: VISIBILITY_FORMAT,
            usage: VISIBILITY_USAGE,
            view_formats: &[],
        });
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("visibility slots (array)"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            array_layer_count: Some(layers),
            ..Default::default()
        });
        let layer_views = (0..layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("visibility layer {layer}")),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        VisibilityTargets {
            texture,
            array_view,
            layer_views,
            slots,
        }
    }
}

/// Per-light transmittance colour: the light a technique lets through translucent casters,
/// which the lighting pass multiplies into each light's contribution besides its visibility.
/// One `Rgba8Unorm` array layer per visibility slot (rgb; a unused), cleared to white each
/// frame, for techniques that write it ([`crate::ShadowTechnique::writes_transmittance`]);
/// otherwise a single white texel that every light reads.
pub struct TransmittanceTargets {
    /// The array texture (a layer per slot, or one white texel).
    pub texture: wgpu::Texture,
    /// All layers, for the lighting pass.
    pub array_view: wgpu::TextureView,
    /// One 2D view per slot, for render attachments (empty when not in use).
    pub slot_views: Vec<wgpu::TextureView>,
    /// Whether the technique writes it (a layer per slot at the output size).
    pub in_use: bool,
}

impl TransmittanceTargets {
    /// A layer per slot of `slots` at `size` when `in_use`, else one white texel.
    pub fn new(
        gpu: &GpuContext,
        size: UVec2,
        slots: &SlotAssignment,
        in_use: bool,
    ) -> TransmittanceTargets {
        let (extent, layers) = if in_use {
            (size, slots.slot_count().max(1))
        } else {
            (UVec2::ONE, 1)
        };
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("transmittance slots"),
            size: wgpu::Extent3d {
                width: extent.x,
                height: extent.y,
                depth_or_array_layers: crate::gpu::array_layers(gpu, extent.x, extent.y, layers),
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: VISIBILITY_FORMAT,
            usage: VISIBILITY_USAGE | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        if !in_use {
            // Every layer of the white texel: GL binds the whole texture, spare layers included.
            fill_white_texels(gpu, &texture);
        }
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("transmittance slots (array)"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            array_layer_count: Some(layers),
            ..Default::default()
        });
        let slot_views = if in_use {
            slot_views(&texture, layers)
        } else {
            Vec::new()
        };
        TransmittanceTargets {
            texture,
            array_view,
            slot_views,
            in_use,
        }
    }

    /// The view light `light`'s transmittance is written to under `slots` (the slot of its
    /// visibility channel, `layer * 4 + channel`, as the lighting pass reads it); `None` when
    /// not in use.
    pub fn slot_view(&self, slots: &SlotAssignment, light: usize) -> Option<&wgpu::TextureView> {
        let (layer, channel) = slots.slot(light);
        self.slot_views.get((layer * 4 + channel) as usize)
    }

    /// Whether this storage fits `slots` at `size` for a technique that does (or does not)
    /// write transmittance.
    pub fn fits(&self, size: UVec2, slots: &SlotAssignment, in_use: bool) -> bool {
        if in_use != self.in_use {
            return false;
        }
        !in_use
            || (self.texture.width() == size.x
                && self.texture.height() == size.y
                && self.slot_views.len() as u32 == slots.slot_count().max(1))
    }
}

/// Writes white into the one texel of every layer of `texture`.
fn fill_white_texels(gpu: &GpuContext, texture: &wgpu::Texture) {
    for layer in 0..texture.depth_or_array_layers() {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            &[255; 4],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
}

/// One 2D view per layer of the transmittance slots, for render attachments.
fn slot_views(texture: &wgpu::Texture, layers: u32) -> Vec<wgpu::TextureView> {
    (0..layers)
        .map(|slot| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("transmittance slot {slot}")),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: slot,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect()
}

/// Indirect light (`Rgba16Float`), cleared to zero each frame, for techniques that add light:
/// irradiance over π in the units of a light's direct term (a light of radiance R that
/// reaches a surface at n · l contributes R · falloff · n · l), so the lighting pass adds
/// `albedo × indirect`, a diffuse bounce. Writable as an attachment or from compute (storage),
/// and readable back ([`crate::Renderer::read_indirect`]).
pub struct IndirectTarget {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

/// Format of the indirect target.
pub const INDIRECT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// How the indirect target is used: written as an attachment or storage, read by lighting,
/// copied for readback.
pub const INDIRECT_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::STORAGE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

impl IndirectTarget {
    /// Creates the target at `size`.
    pub fn new(gpu: &GpuContext, size: UVec2) -> IndirectTarget {
        let (texture, view) = crate::gpu::render_target(
            &gpu.device,
            "indirect light",
            size,
            INDIRECT_FORMAT,
            INDIRECT_USAGE,
        );
        IndirectTarget { texture, view }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(x: f32, range: f32) -> Light {
        Light {
            kind: LightKind::Point,
            position: Vec3::new(x, 1.0, 0.0),
            direction: Vec3::NEG_Y,
            radiance: Vec3::ONE,
            range,
            spot_angle: 0.0,
            spot_softness: 0.0,
            radius: 0.0,
        }
    }

    #[test]
    fn one_per_light_fills_channels_then_layers() {
        let s = SlotAssignment::one_per_light(6);
        assert_eq!(s.slot(0), (0, 0));
        assert_eq!(s.slot(3), (0, 3));
        assert_eq!(s.slot(5), (1, 1));
        assert_eq!(s.layer_count(), 2);
        assert_eq!(SlotAssignment::one_per_light(0).layer_count(), 1);
    }

    #[test]
    fn distant_lights_share_slots_and_overlapping_ones_do_not() {
        // A row of 64 lights 10 apart with range 4: neighbours never overlap.
        let lights: Vec<Light> = (0..64).map(|i| point(i as f32 * 10.0, 4.0)).collect();
        let s = SlotAssignment::packed(&lights);
        assert_eq!(s.slot_count(), 1);
        assert_eq!(s.layer_count(), 1);

        // Range 6: neighbours (10 apart) overlap, next-but-one (20 apart) do not.
        let lights: Vec<Light> = (0..64).map(|i| point(i as f32 * 10.0, 6.0)).collect();
        let s = SlotAssignment::packed(&lights);
        assert_eq!(s.slot_count(), 2);
        for slot in 0..s.slot_count() {
            let members: Vec<_> = s.lights_in_slot(slot).collect();
            for (k, &a) in members.iter().enumerate() {
                for &b in &members[k + 1..] {
                    assert!(!influences_overlap(&lights[a], &lights[b]));
                }
            }
        }
    }

    #[test]
    fn directional_lights_are_never_packed() {
        let mut lights = vec![point(0.0, 1.0), point(100.0, 1.0)];
        lights.push(Light {
            kind: LightKind::Directional,
            ..point(0.0, f32::INFINITY)
        });
        let s = SlotAssignment::packed(&lights);
        assert_eq!(s.slot(0), s.slot(1));
        assert_ne!(s.slot(2), s.slot(0));
        assert_eq!(s.slot_count(), 2);
    }

    #[test]
    fn overlapping_many_lights_need_many_slots() {
        let lights: Vec<Light> = (0..256).map(|i| point(i as f32 * 0.01, 5.0)).collect();
        let s = SlotAssignment::packed(&lights);
        assert_eq!(s.slot_count(), 256);
        assert_eq!(s.layer_count(), 64);
    }
}
