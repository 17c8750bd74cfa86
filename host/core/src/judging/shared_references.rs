//! Reference visibility shared between processes through a folder: the same scene, light,
//! pixels and samples give the same reference, so processes that judge the same views (the
//! test binaries of one `tests/run.sh`, each its own process, judge the standard scenes again
//! and again) trace each light once.
//!
//! Off unless `ZOO_SHARED_REFERENCES` names a folder. `tests/run.sh` makes a fresh one for each
//! run and removes it afterwards, so a reference is only ever reused by the code that traced
//! it. Entries are keyed by a digest of every input of [`reference_visibility`]: the scene's
//! triangles, objects and textures (the occluders are built from them), the light, each
//! pixel's surface point and the sample count.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};

use glam::Vec3;
use zoo_judge::{LightReference, Occluders, SurfacePoint, reference_visibility};

use crate::scene::{Light, Scene};

/// The environment variable naming the folder.
pub const SHARED_REFERENCES_VARIABLE: &str = "ZOO_SHARED_REFERENCES";

/// The first bytes of an entry (and its format's version).
const MAGIC: &[u8; 8] = b"zoo-ref1";

/// Where references are shared, when they are.
pub(crate) fn folder() -> Option<PathBuf> {
    std::env::var_os(SHARED_REFERENCES_VARIABLE)
        .map(PathBuf::from)
        .filter(|dir| dir.is_dir())
}

/// A digest of what the occluders of `scene` are built from.
pub(crate) fn scene_digest(scene: &Scene) -> u64 {
    let mut hasher = DefaultHasher::new();
    let mesh = &scene.mesh;
    hasher.write(bytemuck::cast_slice(&mesh.positions));
    hasher.write(bytemuck::cast_slice(&mesh.uvs));
    hasher.write(bytemuck::cast_slice(&mesh.indices));
    format!("{:?}", scene.objects).hash(&mut hasher);
    scene.textures.size.hash(&mut hasher);
    for layer in &scene.textures.layers {
        hasher.write(&layer.rgba);
    }
    hasher.finish()
}

/// `light`'s reference over `points`, read from `folder` when an earlier process traced it,
/// traced (and left there) otherwise.
pub(crate) fn light_reference(
    folder: &Path,
    (scene, occluders): (u64, &Occluders),
    light: &Light,
    points: &[Option<SurfacePoint>],
    samples: u32,
) -> LightReference {
    let mut hasher = DefaultHasher::new();
    scene.hash(&mut hasher);
    format!("{light:?}").hash(&mut hasher);
    samples.hash(&mut hasher);
    for point in points {
        match point {
            Some(p) => {
                let v = [p.position, p.normal, p.geometric_normal];
                hasher.write(bytemuck::cast_slice(&v));
                hasher.write_u32(p.offset.to_bits());
            }
            None => hasher.write_u8(0),
        }
    }
    let path = folder.join(format!("{:016x}.bin", hasher.finish()));
    if let Some(reference) = std::fs::read(&path)
        .ok()
        .and_then(|b| decode(&b, points.len()))
    {
        return reference;
    }
    let reference = reference_visibility(occluders, light, points, samples);
    // Written whole under another name, then renamed: a reader never sees half an entry.
    let partial = path.with_extension(format!("{}.part", std::process::id()));
    if std::fs::write(&partial, encode(&reference)).is_ok() {
        let _ = std::fs::rename(&partial, &path);
    }
    reference
}

fn encode(r: &LightReference) -> Vec<u8> {
    let mut bytes = MAGIC.to_vec();
    bytes.extend((r.hard.len() as u64).to_le_bytes());
    bytes.extend(r.samples.to_le_bytes());
    bytes.extend(r.contributing.iter().map(|&c| u8::from(c)));
    bytes.extend(bytemuck::cast_slice(&r.hard));
    bytes.extend(bytemuck::cast_slice(&r.area));
    if let Some(color) = &r.color {
        bytes.extend(bytemuck::cast_slice(color));
    }
    bytes
}

/// The reference of an entry for `pixels` pixels, or `None` where the entry is not one.
fn decode(bytes: &[u8], pixels: usize) -> Option<LightReference> {
    let rest = bytes.strip_prefix(MAGIC)?;
    let (len, rest) = rest.split_first_chunk::<8>()?;
    let (samples, rest) = rest.split_first_chunk::<4>()?;
    if u64::from_le_bytes(*len) != pixels as u64 {
        return None;
    }
    let (contributing, rest) = rest.split_at_checked(pixels)?;
    let floats = |bytes: &[u8]| -> Vec<f32> {
        let words = bytes.chunks_exact(4);
        words
            .map(|w| f32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .collect()
    };
    let (hard, rest) = rest.split_at_checked(4 * pixels)?;
    let (area, rest) = rest.split_at_checked(4 * pixels)?;
    let color = match rest.len() {
        0 => None,
        n if n == 12 * pixels => Some(floats(rest).chunks_exact(3).map(Vec3::from_slice).collect()),
        _ => return None,
    };
    Some(LightReference {
        contributing: contributing.iter().map(|&c| c != 0).collect(),
        hard: floats(hard),
        area: floats(area),
        color,
        samples: u32::from_le_bytes(*samples),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_read_back_as_written() {
        let reference = LightReference {
            contributing: vec![true, false, true],
            hard: vec![0.0, 1.0, 0.25],
            area: vec![0.5, 1.0, 0.125],
            color: Some(vec![Vec3::new(0.1, 0.2, 0.3); 3]),
            samples: 64,
        };
        let back = decode(&encode(&reference), 3).unwrap();
        assert_eq!(back.contributing, reference.contributing);
        assert_eq!(back.hard, reference.hard);
        assert_eq!(back.area, reference.area);
        assert_eq!(back.color, reference.color);
        assert_eq!(back.samples, 64);
        let plain = LightReference {
            color: None,
            ..reference
        };
        assert_eq!(decode(&encode(&plain), 3).unwrap().color, None);
        // Another size, a cut entry or foreign bytes are not read.
        assert!(decode(&encode(&plain), 4).is_none());
        let bytes = encode(&plain);
        assert!(decode(&bytes[..bytes.len() - 1], 3).is_none());
        assert!(decode(b"not an entry", 3).is_none());
    }
}
