//! The RON scene format, exactly as written in `scenes/*.ron`.

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::{Deserialize, Serialize};

/// A whole scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// Human-readable title.
    #[serde(default)]
    pub name: String,
    /// The viewpoint.
    pub camera: CameraDesc,
    /// Ambient light colour (added to every pixel times its albedo).
    #[serde(default = "default_ambient")]
    pub ambient: Vec3,
    /// Light sources; at most [`crate::MAX_LIGHTS`].
    pub lights: Vec<LightDesc>,
    /// Geometry.
    pub objects: Vec<ObjectDesc>,
    /// Keyframed camera and light paths for benchmarks.
    #[serde(default)]
    pub paths: PathsDesc,
}

fn default_ambient() -> Vec3 {
    Vec3::splat(0.03)
}

/// A perspective camera.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position in world space.
    pub position: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view in degrees.
    #[serde(default = "default_fov")]
    pub fov_y_degrees: f32,
    /// Near plane distance.
    #[serde(default = "default_near")]
    pub near: f32,
    /// Far plane distance.
    #[serde(default = "default_far")]
    pub far: f32,
}

fn default_fov() -> f32 {
    50.0
}
fn default_near() -> f32 {
    0.1
}
fn default_far() -> f32 {
    200.0
}

/// A light source. Colours are linear RGB; `intensity` scales them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// Parallel light (the sun): `direction` is where the light travels.
    Directional {
        direction: Vec3,
        #[serde(default = "white")]
        color: Vec3,
        #[serde(default = "one")]
        intensity: f32,
        /// Angular radius of the light's disk in degrees (0.27 for the sun); 0 = hard.
        #[serde(default)]
        angular_radius_degrees: f32,
    },
    /// Omnidirectional light.
    Point {
        position: Vec3,
        #[serde(default = "white")]
        color: Vec3,
        #[serde(default = "one")]
        intensity: f32,
        /// Distance at which the light's contribution reaches zero.
        #[serde(default = "default_range")]
        range: f32,
        /// Radius of the emitting sphere; 0 = hard shadows.
        #[serde(default)]
        radius: f32,
    },
    /// Cone light.
    Spot {
        position: Vec3,
        direction: Vec3,
        #[serde(default = "white")]
        color: Vec3,
        #[serde(default = "one")]
        intensity: f32,
        #[serde(default = "default_range")]
        range: f32,
        /// Full cone half-angle in degrees (outside it the light contributes nothing).
        #[serde(default = "default_spot_angle")]
        angle_degrees: f32,
        /// Fraction of the cone over which the edge fades, in [0, 1].
        #[serde(default = "default_spot_softness")]
        softness: f32,
        /// Radius of the emitting disk; 0 = hard shadows.
        #[serde(default)]
        radius: f32,
    },
}

fn white() -> Vec3 {
    Vec3::ONE
}
fn one() -> f32 {
    1.0
}
fn default_range() -> f32 {
    30.0
}
fn default_spot_angle() -> f32 {
    30.0
}
fn default_spot_softness() -> f32 {
    0.15
}

/// One object: a mesh, where it is, and what it looks like.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// Optional name shown in the UI and in error messages.
    #[serde(default)]
    pub name: String,
    /// The geometry.
    pub mesh: MeshDesc,
    /// Placement.
    #[serde(default)]
    pub transform: TransformDesc,
    /// Instances: the mesh drawn once per transform (each applied after `transform`), its
    /// triangles stored once for the renderer and the judge. Empty (the default): the object
    /// once, at `transform`. Instances cannot mirror (every determinant must be positive).
    #[serde(default)]
    pub instances: Vec<TransformDesc>,
    /// Diffuse albedo (linear RGB).
    #[serde(default = "default_color")]
    pub color: Vec3,
    /// Specular strength in [0, 1].
    #[serde(default = "default_specular")]
    pub specular: f32,
    /// Blinn-Phong exponent.
    #[serde(default = "default_shininess")]
    pub shininess: f32,
    /// Marks a `Plane` as a receiver plane for planar projected shadows.
    #[serde(default)]
    pub receiver: bool,
    /// Whether the object casts shadows.
    #[serde(default = "yes")]
    pub casts_shadows: bool,
    /// How much light the object stops where a shadow ray crosses it, in [0, 1]: 1 (the
    /// default) is opaque; below 1 the object is a translucent caster that lets
    /// `(1 - opacity) * transmission` through.
    #[serde(default = "one")]
    pub opacity: f32,
    /// Colour of the light a translucent caster lets through (linear RGB in [0, 1]).
    #[serde(default = "white")]
    pub transmission: Vec3,
    /// Albedo image (PNG, JPEG or TGA, relative to the scene file) that multiplies `color`.
    #[serde(default)]
    pub texture: Option<String>,
    /// Alpha mask image: where its alpha (its grey level, for images without alpha) is below
    /// `alpha_cutoff`, the object has holes that neither show nor cast shadows.
    #[serde(default)]
    pub alpha_mask: Option<String>,
    /// Coverage below which a masked texel is a hole, in [0, 1].
    #[serde(default = "half")]
    pub alpha_cutoff: f32,
    /// For an OBJ file with an MTL library: whether its materials (colour, specular,
    /// shininess, opacity, albedo texture and mask) are used (the default), or this object's
    /// fields for every face instead.
    #[serde(default = "yes")]
    pub file_materials: bool,
}

fn half() -> f32 {
    0.5
}

fn default_color() -> Vec3 {
    Vec3::splat(0.8)
}
fn default_specular() -> f32 {
    0.2
}
fn default_shininess() -> f32 {
    32.0
}
fn yes() -> bool {
    true
}

/// Geometry source: an OBJ file or a procedural primitive (unit-sized, centred at the origin).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MeshDesc {
    /// A Wavefront OBJ file, relative to the scene file.
    Obj(String),
    /// A glTF 2.0 file (`.gltf` or binary `.glb`), relative to the scene file: its default
    /// scene with the node transforms applied.
    Gltf(String),
    /// A square in the XZ plane facing +Y, `size` on a side, split into `subdivisions`².
    Plane {
        size: f32,
        #[serde(default = "one_u32")]
        subdivisions: u32,
    },
    /// An axis-aligned box with the given edge lengths.
    Box { size: Vec3 },
    /// A UV sphere.
    Sphere {
        radius: f32,
        #[serde(default = "default_segments")]
        segments: u32,
        #[serde(default = "default_rings")]
        rings: u32,
    },
    /// A capped cylinder along Y, base at y = 0.
    Cylinder {
        radius: f32,
        height: f32,
        #[serde(default = "default_segments")]
        segments: u32,
    },
    /// A torus around Y.
    Torus {
        major_radius: f32,
        minor_radius: f32,
        #[serde(default = "default_segments")]
        segments: u32,
        #[serde(default = "default_rings")]
        rings: u32,
    },
    /// A capped cone along Y, base at y = 0.
    Cone {
        radius: f32,
        height: f32,
        #[serde(default = "default_segments")]
        segments: u32,
    },
}

fn one_u32() -> u32 {
    1
}
fn default_segments() -> u32 {
    32
}
fn default_rings() -> u32 {
    16
}

/// Translation, rotation (Euler angles in degrees, applied Y then X then Z) and scale.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TransformDesc {
    pub translation: Vec3,
    pub rotation_degrees: Vec3,
    pub scale: Vec3,
}

impl Default for TransformDesc {
    fn default() -> Self {
        Self {
            translation: Vec3::ZERO,
            rotation_degrees: Vec3::ZERO,
            scale: Vec3::ONE,
        }
    }
}

impl TransformDesc {
    /// The model matrix.
    pub fn matrix(&self) -> Mat4 {
        let r = self.rotation_degrees;
        let rotation = Quat::from_euler(
            EulerRot::YXZ,
            r.y.to_radians(),
            r.x.to_radians(),
            r.z.to_radians(),
        );
        Mat4::from_scale_rotation_translation(self.scale, rotation, self.translation)
    }
}

/// Keyframed paths, interpolated with Catmull-Rom splines by the benchmark.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PathsDesc {
    /// Camera keyframes.
    pub camera: Vec<CameraKey>,
    /// Per-light keyframes.
    pub lights: Vec<LightPathDesc>,
}

/// A camera keyframe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    pub time: f32,
    pub position: Vec3,
    pub target: Vec3,
}

/// The path of one light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightPathDesc {
    /// Index into `lights`.
    pub light: usize,
    pub keys: Vec<LightKey>,
}

/// A light keyframe: position for point and spot lights, direction for directional lights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightKey {
    pub time: f32,
    pub value: Vec3,
}

impl SceneDescription {
    /// The same scene with each instance an object of its own, its triangles copied (to
    /// compare instancing with copies). `None` when an instanced object has a transform of its
    /// own: a transform after another one is not always a translation, rotation and scale.
    pub fn instances_copied(&self) -> Option<SceneDescription> {
        let mut objects = Vec::new();
        for object in &self.objects {
            if object.instances.is_empty() {
                objects.push(object.clone());
                continue;
            }
            if object.transform != TransformDesc::default() {
                return None;
            }
            objects.extend(object.instances.iter().map(|transform| ObjectDesc {
                transform: *transform,
                instances: Vec::new(),
                ..object.clone()
            }));
        }
        Some(SceneDescription {
            objects,
            ..self.clone()
        })
    }

    /// The same scene with every procedural mesh's segment, ring and subdivision counts scaled
    /// by `factor` (for triangle-count sweeps). Mesh files are unchanged.
    pub fn with_tessellation(&self, factor: f32) -> SceneDescription {
        let scale = |n: u32, min: u32| ((n as f32 * factor).round() as u32).clamp(min, 4096);
        let mut out = self.clone();
        for object in &mut out.objects {
            match &mut object.mesh {
                MeshDesc::Plane { subdivisions, .. } => {
                    *subdivisions = scale(*subdivisions, 1).min(1024)
                }
                MeshDesc::Sphere {
                    segments, rings, ..
                }
                | MeshDesc::Torus {
                    segments, rings, ..
                } => {
                    *segments = scale(*segments, 3);
                    *rings = scale(*rings, 3);
                }
                MeshDesc::Cylinder { segments, .. } | MeshDesc::Cone { segments, .. } => {
                    *segments = scale(*segments, 3)
                }
                MeshDesc::Box { .. } | MeshDesc::Obj(_) | MeshDesc::Gltf(_) => {}
            }
        }
        out
    }
}
