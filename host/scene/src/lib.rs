//! Shadow Zoo scenes: the RON description, loaded and validated into geometry (world space,
//! or shared by instances and placed by their transforms), lights and a camera that every
//! technique and the reference judge share. No GPU dependency.

pub mod adjacency;
pub mod description;
pub mod files;
pub mod gltf_file;
#[cfg(any(test, feature = "test-support"))]
pub mod gltf_writer;
pub mod image_source;
pub mod material;
pub mod mesh;
pub mod paths;
pub mod shading;
pub mod stage;

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3, Vec4};

pub use adjacency::{Adjacency, EdgeKind, EdgeRecord};
pub use description::*;
pub use gltf_file::{GltfError, GltfFile};
pub use image_source::ImageSource;
pub use material::{AlphaMask, TextureLayer, TextureUse, Textures};
pub use mesh::{MeshData, MeshReport};

use material::{FileMaterial, ObjectMaterial, TextureRequests, check_material, mesh_folder};

/// Most lights a scene may hold.
pub const MAX_LIGHTS: usize = 1024;

/// Why a scene could not be loaded. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: cannot read scene: {message}")]
    Io { path: PathBuf, message: String },
    /// The RON text is malformed or has unknown or missing fields.
    #[error("{path}:{line}:{col}: {message}")]
    Parse {
        path: PathBuf,
        line: usize,
        col: usize,
        message: String,
    },
    /// A value is out of its domain (non-finite coordinates, negative sizes, ...).
    #[error("{path}: {field}: {message}")]
    Invalid {
        path: PathBuf,
        field: String,
        message: String,
    },
    /// A referenced OBJ file is missing or malformed.
    #[error("{path}: {field}: {obj}: {message}")]
    Obj {
        path: PathBuf,
        field: String,
        obj: PathBuf,
        message: String,
    },
    /// A referenced glTF file is missing or malformed.
    #[error("{path}: {field}: {file}: {message}")]
    Gltf {
        path: PathBuf,
        field: String,
        file: PathBuf,
        message: String,
    },
}

/// The kinds of light a technique may support.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LightKind {
    Directional,
    Point,
    Spot,
}

impl LightKind {
    /// Every kind.
    pub const ALL: [LightKind; 3] = [LightKind::Directional, LightKind::Point, LightKind::Spot];

    /// Lower-case name as used in reports.
    pub fn name(self) -> &'static str {
        match self {
            LightKind::Directional => "directional",
            LightKind::Point => "point",
            LightKind::Spot => "spot",
        }
    }
}

/// A light in world space, ready for rendering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    /// Position (point and spot).
    pub position: Vec3,
    /// Unit direction the light travels (directional and spot).
    pub direction: Vec3,
    /// Linear colour times intensity.
    pub radiance: Vec3,
    /// Distance at which the contribution reaches zero (point and spot); infinite otherwise.
    pub range: f32,
    /// Cone half-angle in radians (spot).
    pub spot_angle: f32,
    /// Fraction of the cone over which the edge fades (spot).
    pub spot_softness: f32,
    /// Emitter radius in world units (point, spot) or angular radius in radians (directional).
    pub radius: f32,
}

impl Light {
    /// Homogeneous light position: (x, y, z, 1) for point and spot lights, (-d, 0) toward the
    /// light for directional ones.
    pub fn homogeneous(&self) -> Vec4 {
        match self.kind {
            LightKind::Directional => (-self.direction).extend(0.0),
            _ => self.position.extend(1.0),
        }
    }

    /// Whether a surface point receives any light from this light, ignoring occlusion: inside
    /// the range and the spot cone.
    pub fn reaches(&self, point: Vec3) -> bool {
        match self.kind {
            LightKind::Directional => true,
            LightKind::Point => point.distance(self.position) < self.range,
            LightKind::Spot => {
                let to_point = point - self.position;
                let distance = to_point.length();
                distance < self.range
                    && distance > 0.0
                    && to_point.dot(self.direction) / distance > self.spot_angle.cos()
            }
        }
    }

    /// Unit vector from `point` toward the light.
    pub fn direction_to_light(&self, point: Vec3) -> Vec3 {
        match self.kind {
            LightKind::Directional => -self.direction,
            _ => (self.position - point).normalize_or_zero(),
        }
    }
}

/// A perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// The same camera in a world scaled by `factor` about the origin: position, target and
    /// the near and far planes scaled, the field of view kept.
    pub fn scaled(&self, factor: f32) -> Camera {
        Camera {
            position: self.position * factor,
            target: self.target * factor,
            near: self.near * factor,
            far: self.far * factor,
            ..*self
        }
    }

    /// World-to-view matrix (right-handed, Y up).
    pub fn view(&self) -> Mat4 {
        let forward = (self.target - self.position).normalize_or_zero();
        let up = if forward.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        glam::camera::rh::view::look_at_mat4(self.position, self.target, up)
    }

    /// View-to-clip matrix for the given aspect ratio (depth 0 at near, 1 at far).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        glam::camera::rh::proj::directx::perspective(self.fov_y, aspect, self.near, self.far)
    }
}

/// One object after loading: its slice of the shared buffers and its material.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    pub name: String,
    /// Model matrix: the object's transform, and for an instance its placement after it.
    pub transform: Mat4,
    /// What takes the stored vertices of [`Self::indices`] to world space: the identity for
    /// an object drawn once (its vertices are stored in world space), the instance's transform
    /// for an instance (the instances of one object share their triangles).
    pub placement: Mat4,
    /// For an instance, its number among its object's instances.
    pub instance: Option<usize>,
    /// Its world-space bounds (exact for instances too), `None` without triangles.
    pub bounds: Option<(Vec3, Vec3)>,
    /// Index range in [`Scene::mesh`] indices (the same range for every instance of an
    /// object).
    pub indices: Range<usize>,
    pub color: Vec3,
    pub specular: f32,
    pub shininess: f32,
    pub casts_shadows: bool,
    /// Opacity of a shadow caster in [0, 1] (1: opaque).
    pub opacity: f32,
    /// Colour a translucent caster lets through.
    pub transmission: Vec3,
    /// Layer of [`Scene::textures`] that multiplies `color`.
    pub albedo_texture: Option<u32>,
    /// The alpha test of a masked material.
    pub alpha_mask: Option<AlphaMask>,
    /// Whether the camera sees its back faces (false only for single-sided glTF materials;
    /// both sides cast shadows either way).
    pub double_sided: bool,
    /// What loading changed.
    pub report: MeshReport,
}

impl SceneObject {
    /// Whether it is an instance: its triangles are shared with its object's other instances,
    /// and [`Self::placement`] takes them to world space.
    pub fn is_placed(&self) -> bool {
        self.instance.is_some()
    }

    /// The colour fraction of light a shadow ray keeps when it crosses this object, or `None`
    /// for an opaque caster (opacity 1) or one that casts no shadow.
    pub fn transmittance(&self) -> Option<Vec3> {
        (self.casts_shadows && self.opacity < 1.0).then(|| self.transmission * (1.0 - self.opacity))
    }
}

/// A receiver plane for planar projected shadows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceiverPlane {
    /// Index of the object whose geometry is the plane.
    pub object: usize,
    /// Plane (n, d) with n . x + d = 0 and n the front side.
    pub plane: Vec4,
    /// The four world-space corners.
    pub corners: [Vec3; 4],
}

/// A loaded scene in world space.
#[derive(Debug, Clone)]
pub struct Scene {
    pub name: String,
    /// File it came from (or a label for embedded scenes).
    pub path: PathBuf,
    pub camera: Camera,
    pub ambient: Vec3,
    pub lights: Vec<Light>,
    pub objects: Vec<SceneObject>,
    /// All geometry, stored once: in world space for objects drawn once, and in its object's
    /// space for the triangles instances share. Objects own index ranges of it.
    pub mesh: MeshData,
    pub adjacency: Adjacency,
    pub receivers: Vec<ReceiverPlane>,
    pub paths: PathsDesc,
    /// The materials' textures.
    pub textures: Textures,
    /// What loading left out but could render without (unreadable textures and material
    /// libraries), each naming the file; also logged.
    pub warnings: Vec<String>,
}

impl Scene {
    /// Loads a RON scene file (OBJ paths are relative to it), or stages a model file
    /// (`.obj`, `.gltf`, `.glb`) in a scene of its own ([`stage::around_model`]).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        if stage::is_model(path) {
            return stage::around_model(path);
        }
        let text = files::read_to_string(path).map_err(|e| SceneError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Scene::from_ron(&text, path, base)
    }

    /// Parses RON `text`; `path` names it in errors and `base` resolves OBJ paths.
    pub fn from_ron(text: &str, path: &Path, base: &Path) -> Result<Scene, SceneError> {
        let description: SceneDescription = ron::from_str(text).map_err(|e| SceneError::Parse {
            path: path.to_path_buf(),
            line: e.span.start.line,
            col: e.span.start.col,
            message: e.code.to_string(),
        })?;
        Scene::from_description(&description, path, base)
    }

    /// Validates and builds a scene from its description.
    pub fn from_description(
        desc: &SceneDescription,
        path: &Path,
        base: &Path,
    ) -> Result<Scene, SceneError> {
        let camera = build_camera(&desc.camera).map_err(|(f, m)| invalid(path, f, m))?;
        check_vec(desc.ambient, "ambient").map_err(|(f, m)| invalid(path, f, m))?;
        let lights = build_lights(&desc.lights).map_err(|(f, m)| invalid(path, f, m))?;
        let SceneObjects {
            mesh,
            objects,
            receivers,
            textures,
            mut warnings,
        } = SceneObjects::build(&desc.objects, path, base)?;
        let textures = textures.load(&mut warnings);
        for warning in &warnings {
            log::warn!("{warning}");
        }

        validate_paths(&desc.paths, lights.len()).map_err(|(f, m)| invalid(path, f, m))?;

        let ranges: Vec<_> = objects.iter().map(|o| o.indices.clone()).collect();
        let adjacency = Adjacency::build(&mesh, &ranges);
        Ok(Scene {
            name: scene_name(desc, path),
            path: path.to_path_buf(),
            camera,
            ambient: desc.ambient,
            lights,
            objects,
            mesh,
            adjacency,
            receivers,
            paths: desc.paths.clone(),
            textures,
            warnings,
        })
    }

    /// Triangles stored (instances' shared triangles once: [`Self::drawn_triangle_count`]
    /// counts them per instance).
    pub fn triangle_count(&self) -> usize {
        self.mesh.triangle_count()
    }

    /// Whether any shadow caster has an alpha mask.
    pub fn has_masked_casters(&self) -> bool {
        self.objects
            .iter()
            .any(|o| o.casts_shadows && o.alpha_mask.is_some())
    }

    /// Whether any shadow caster is translucent (opacity below 1).
    pub fn has_translucent_casters(&self) -> bool {
        self.objects.iter().any(|o| o.transmittance().is_some())
    }

    /// World-space bounds of all geometry.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.each_object_bounds().into_iter().flatten())
            .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
            .unwrap_or((Vec3::ZERO, Vec3::ZERO))
    }

    /// World-space bounds of each object, in object order (none for an object without
    /// triangles).
    pub fn each_object_bounds(&self) -> Vec<Option<(Vec3, Vec3)>> {
        self.objects.iter().map(|o| o.bounds).collect()
    }

    /// Triangles drawn: each object's, instances counted (at least [`Self::triangle_count`],
    /// the triangles stored).
    pub fn drawn_triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.indices.len() / 3).sum()
    }

    /// "N triangles", or with instances "N triangles drawn, M stored".
    pub fn triangle_summary(&self) -> String {
        let (drawn, stored) = (self.drawn_triangle_count(), self.triangle_count());
        if drawn == stored {
            format!("{stored} triangles")
        } else {
            format!("{drawn} triangles drawn, {stored} stored")
        }
    }

    /// Whether any object is placed by an instance transform ([`SceneObject::is_placed`]).
    pub fn has_placed_objects(&self) -> bool {
        self.objects.iter().any(SceneObject::is_placed)
    }

    /// The same scene uniformly scaled by `factor` about the world origin: geometry,
    /// transforms, light positions, ranges and radii (angular radii stay), receiver planes,
    /// the camera with its near and far planes, and the paths' positions. Visibility is the
    /// same at every scale, so the judge and every technique should score it the same.
    /// `factor` must be positive and finite (a negative one would mirror the geometry without
    /// turning its normals).
    pub fn scaled(&self, factor: f32) -> Scene {
        debug_assert!(factor.is_finite() && factor > 0.0, "scale factor {factor}");
        let mut out = self.clone();
        let scale = Mat4::from_scale(Vec3::splat(factor));
        for p in &mut out.mesh.positions {
            *p *= factor;
        }
        // Stored vertices scale about the origin, so a placement p becomes s p s⁻¹.
        let unscale = Mat4::from_scale(Vec3::splat(1.0 / factor));
        for object in &mut out.objects {
            object.transform = scale * object.transform;
            if object.is_placed() {
                object.placement = scale * object.placement * unscale;
            }
            object.bounds = object.bounds.map(|(lo, hi)| (lo * factor, hi * factor));
        }
        for light in &mut out.lights {
            light.position *= factor;
            light.range *= factor;
            if light.kind != LightKind::Directional {
                light.radius *= factor;
            }
        }
        for receiver in &mut out.receivers {
            receiver.plane.w *= factor;
            for corner in &mut receiver.corners {
                *corner *= factor;
            }
        }
        out.camera = self.camera.scaled(factor);
        for key in &mut out.paths.camera {
            key.position *= factor;
            key.target *= factor;
        }
        for path in &mut out.paths.lights {
            let moves = out
                .lights
                .get(path.light)
                .is_some_and(|l| l.kind != LightKind::Directional);
            if moves {
                for key in &mut path.keys {
                    key.value *= factor;
                }
            }
        }
        out
    }

    /// The vertex indices of each of `object`'s triangles.
    pub fn triangle_indices(&self, object: &SceneObject) -> impl Iterator<Item = [usize; 3]> + '_ {
        self.mesh.indices[object.indices.clone()]
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]].map(|i| i as usize))
    }

    /// The stored corners of each of `object`'s triangles (world space unless the object
    /// [`SceneObject::is_placed`]).
    pub fn stored_triangles(&self, object: &SceneObject) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        self.triangle_indices(object)
            .map(|t| t.map(|i| self.mesh.positions[i]))
    }

    /// The world-space corners of each of `object`'s triangles (computed, for an instance,
    /// from the triangles it shares).
    pub fn object_triangles(&self, object: &SceneObject) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        let placement = object.placement;
        let placed = object.is_placed();
        self.stored_triangles(object).map(move |t| match placed {
            true => t.map(|p| placement.transform_point3(p)),
            false => t,
        })
    }
}

/// Parses a scene description without building it.
pub fn parse_description(text: &str, path: &Path) -> Result<SceneDescription, SceneError> {
    ron::from_str(text).map_err(|e| SceneError::Parse {
        path: path.to_path_buf(),
        line: e.span.start.line,
        col: e.span.start.col,
        message: e.code.to_string(),
    })
}

/// Reads and parses a scene file's description (a model file's is staged:
/// [`stage::description`]).
pub fn read_description(path: &Path) -> Result<SceneDescription, SceneError> {
    if stage::is_model(path) {
        return stage::description(path);
    }
    let text = files::read_to_string(path).map_err(|e| SceneError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    parse_description(&text, path)
}

/// A [`SceneError::Invalid`]: `field` of the scene file at `path` is wrong.
fn invalid(path: &Path, field: String, message: impl Into<String>) -> SceneError {
    SceneError::Invalid {
        path: path.to_path_buf(),
        field,
        message: message.into(),
    }
}

/// The scene's name: the description's, else the file's stem.
fn scene_name(desc: &SceneDescription, path: &Path) -> String {
    if desc.name.is_empty() {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    } else {
        desc.name.clone()
    }
}

/// Builds the lights, of which a scene needs at least one and at most [`MAX_LIGHTS`].
fn build_lights(lights: &[LightDesc]) -> Result<Vec<Light>, (String, String)> {
    if lights.is_empty() {
        return Err(("lights".into(), "a scene needs at least one light".into()));
    }
    if lights.len() > MAX_LIGHTS {
        return Err((
            "lights".into(),
            format!(
                "{} lights given, at most {MAX_LIGHTS} are supported",
                lights.len()
            ),
        ));
    }
    lights
        .iter()
        .enumerate()
        .map(|(i, l)| build_light(l, &format!("lights[{i}]")))
        .collect()
}

/// A scene's objects as they are built from its description: one [`SceneObject`] per part
/// and instance, their triangles in one shared mesh.
#[derive(Default)]
struct SceneObjects {
    mesh: MeshData,
    objects: Vec<SceneObject>,
    receivers: Vec<ReceiverPlane>,
    /// The textures and masks the materials ask for, not yet loaded.
    textures: TextureRequests,
    warnings: Vec<String>,
}

/// What every part of one described object shares as it is placed in the scene.
struct PlacedObject<'a> {
    desc: &'a ObjectDesc,
    name: String,
    transform: Mat4,
    /// One per instance (the identity when the object is not instanced).
    placements: Vec<Mat4>,
    report: MeshReport,
}

impl SceneObjects {
    /// Validates and builds the described objects, within the limits of the GPU passes.
    fn build(descs: &[ObjectDesc], path: &Path, base: &Path) -> Result<Self, SceneError> {
        if descs.is_empty() {
            return Err(invalid(
                path,
                "objects".into(),
                "a scene needs at least one object",
            ));
        }
        let mut built = SceneObjects {
            objects: Vec::with_capacity(descs.len()),
            ..SceneObjects::default()
        };
        for (i, desc) in descs.iter().enumerate() {
            built.add(i, desc, path, base)?;
        }
        built
            .check_limits()
            .map_err(|m| invalid(path, "objects".into(), m))?;
        Ok(built)
    }

    /// Adds object `i`: each part of its mesh, once per instance, and its receiver plane.
    fn add(
        &mut self,
        i: usize,
        desc: &ObjectDesc,
        path: &Path,
        base: &Path,
    ) -> Result<(), SceneError> {
        let field = format!("objects[{i}]");
        let (parts, report, file_warnings) = build_mesh(&desc.mesh, &field, path, base)?;
        self.warnings.extend(
            file_warnings
                .into_iter()
                .map(|w| format!("{}: {field}.mesh: {w}", path.display())),
        );
        let placements = check_object(desc, &field).map_err(|(f, m)| invalid(path, f, m))?;
        let transform = desc.transform.matrix();
        if let (true, MeshDesc::Plane { size, .. }) = (desc.receiver, &desc.mesh) {
            let object = self.objects.len();
            self.receivers
                .push(receiver_plane(object, transform, *size));
        }
        if report.degenerate_removed > 0 {
            log::warn!(
                "{}: {field}: removed {} degenerate triangles",
                path.display(),
                report.degenerate_removed
            );
        }
        let placed = PlacedObject {
            desc,
            name: if desc.name.is_empty() {
                format!("object {i}")
            } else {
                desc.name.clone()
            },
            transform,
            placements,
            report,
        };
        let own = ObjectMaterial::of(desc, base, &mut self.textures);
        let folder = mesh_folder(&desc.mesh, base);
        let several = parts.len() > 1;
        // Part-major order: an instanced part's objects are consecutive, so a pass draws
        // them in one call.
        for (local, file_material) in parts {
            let material = match file_material {
                Some(m) if desc.file_materials => {
                    ObjectMaterial::from_file(&m, &own, &folder, &mut self.textures)
                }
                _ => own.clone(),
            };
            let part = match (several, &material.name) {
                (true, Some(part)) => format!("/{part}"),
                _ => String::new(),
            };
            self.add_part(&placed, &local, &material, &part);
        }
        Ok(())
    }

    /// Appends one part's triangles to the mesh and adds one object per placement, named
    /// after the object, the instance and (with `part` as `/<name>`) the part.
    fn add_part(
        &mut self,
        placed: &PlacedObject<'_>,
        local: &MeshData,
        material: &ObjectMaterial,
        part: &str,
    ) {
        let start = self.mesh.indices.len();
        self.mesh.append(&local.transformed(placed.transform));
        let indices = start..self.mesh.indices.len();
        let name = &placed.name;
        for (instance, &placement) in placed.placements.iter().enumerate() {
            let instance = (!placed.desc.instances.is_empty()).then_some(instance);
            self.objects.push(SceneObject {
                name: match instance {
                    Some(k) => format!("{name}[{k}]{part}"),
                    None => format!("{name}{part}"),
                },
                transform: placement * placed.transform,
                placement,
                instance,
                bounds: placed_bounds(&self.mesh, indices.clone(), placement),
                indices: indices.clone(),
                color: material.color,
                specular: material.specular,
                shininess: material.shininess,
                casts_shadows: placed.desc.casts_shadows,
                opacity: material.opacity,
                transmission: placed.desc.transmission,
                albedo_texture: material.albedo_texture,
                alpha_mask: material.alpha_mask,
                double_sided: material.double_sided,
                report: placed.report,
            });
        }
    }

    /// Checks the counts the GPU passes bound: objects, triangles drawn and textures.
    fn check_limits(&self) -> Result<(), String> {
        if self.objects.len() > MAX_OBJECTS {
            return Err(format!(
                "{} objects with instances and model parts, at most {MAX_OBJECTS} are supported",
                self.objects.len()
            ));
        }
        // Triangles drawn are numbered in 32 bits on the GPU, the largest number meaning none.
        let drawn: usize = self.objects.iter().map(|o| o.indices.len() / 3).sum();
        if drawn >= u32::MAX as usize {
            return Err(format!(
                "{drawn} triangles drawn (instances counted), at most {} are supported",
                u32::MAX - 1
            ));
        }
        if self.textures.len() > material::MAX_TEXTURE_LAYERS {
            return Err(format!(
                "{} distinct textures and masks, at most {} are supported",
                self.textures.len(),
                material::MAX_TEXTURE_LAYERS
            ));
        }
        Ok(())
    }
}

/// Checks an object's transform, material, instances and receiver flag; returns its
/// placements.
fn check_object(object: &ObjectDesc, field: &str) -> Result<Vec<Mat4>, (String, String)> {
    let lift = |(f, m): FieldError| (f, m.to_string());
    check_transform(&object.transform, &format!("{field}.transform")).map_err(lift)?;
    check_material(object, field).map_err(lift)?;
    let placements = instance_placements(object, field)?;
    if object.receiver && !object.instances.is_empty() {
        return Err((
            format!("{field}.instances"),
            "receiver planes cannot be instanced".into(),
        ));
    }
    if object.receiver && !matches!(object.mesh, MeshDesc::Plane { .. }) {
        return Err((
            format!("{field}.receiver"),
            "only Plane meshes can be receiver planes".into(),
        ));
    }
    Ok(placements)
}

/// Bounds of the vertices of `indices` placed by `placement`.
fn placed_bounds(mesh: &MeshData, indices: Range<usize>, placement: Mat4) -> Option<(Vec3, Vec3)> {
    let points: Vec<Vec3> = (mesh.indices[indices].iter())
        .map(|&i| placement.transform_point3(mesh.positions[i as usize]))
        .collect();
    mesh::bounds(&points)
}

type FieldError = (String, &'static str);

/// Most instances one object may have.
pub const MAX_INSTANCES: usize = 65536;

/// Most objects a scene may have, instances and model parts counted (each has a record on the
/// GPU, and a caster instance a 256-byte slot for shadow volumes).
pub const MAX_OBJECTS: usize = 1 << 18;

fn check_transform(t: &TransformDesc, field: &str) -> Result<(), FieldError> {
    for (v, name) in [
        (t.translation, "translation"),
        (t.rotation_degrees, "rotation_degrees"),
        (t.scale, "scale"),
    ] {
        check_vec(v, &format!("{field}.{name}"))?;
    }
    if t.scale.cmpeq(Vec3::ZERO).any() {
        return Err((
            format!("{field}.scale"),
            "scale components must be non-zero",
        ));
    }
    Ok(())
}

/// Where `object`'s copies go after its transform: the identity alone for an object drawn
/// once, else each instance's matrix.
fn instance_placements(object: &ObjectDesc, field: &str) -> Result<Vec<Mat4>, (String, String)> {
    if object.instances.is_empty() {
        return Ok(vec![Mat4::IDENTITY]);
    }
    if object.instances.len() > MAX_INSTANCES {
        return Err((
            format!("{field}.instances"),
            format!(
                "{} instances given, at most {MAX_INSTANCES} are supported",
                object.instances.len()
            ),
        ));
    }
    (object.instances.iter().enumerate())
        .map(|(k, t)| {
            let field = format!("{field}.instances[{k}]");
            check_transform(t, &field).map_err(|(f, m)| (f, m.to_string()))?;
            // Shared triangles keep one winding: an instance cannot turn it over.
            if t.scale.x * t.scale.y * t.scale.z < 0.0 {
                return Err((
                    format!("{field}.scale"),
                    "an instance cannot mirror (an odd number of negative scale components)"
                        .to_string(),
                ));
            }
            let matrix = t.matrix();
            // The judge traces rays into an instance through its inverse.
            if !matrix.inverse().is_finite() {
                return Err((
                    format!("{field}.scale"),
                    "the instance's scale is too small to invert in 32-bit floats".to_string(),
                ));
            }
            Ok(matrix)
        })
        .collect()
}

fn check_vec(v: Vec3, field: &str) -> Result<(), FieldError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err((field.to_string(), "coordinates must be finite numbers"))
    }
}

fn check_positive(v: f32, field: &str) -> Result<(), FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err((
            field.to_string(),
            "must be a finite number greater than zero",
        ))
    }
}

fn build_camera(c: &CameraDesc) -> Result<Camera, FieldError> {
    check_vec(c.position, "camera.position")?;
    check_vec(c.target, "camera.target")?;
    if c.position.distance(c.target) < 1e-6 {
        return Err(("camera.target".into(), "must differ from camera.position"));
    }
    if !(c.fov_y_degrees > 1.0 && c.fov_y_degrees < 179.0) {
        return Err(("camera.fov_y_degrees".into(), "must be between 1 and 179"));
    }
    check_positive(c.near, "camera.near")?;
    if !(c.far.is_finite() && c.far > c.near) {
        return Err(("camera.far".into(), "must be finite and greater than near"));
    }
    Ok(Camera {
        position: c.position,
        target: c.target,
        fov_y: c.fov_y_degrees.to_radians(),
        near: c.near,
        far: c.far,
    })
}

/// Validates and builds one light; `field` (`lights[i]`) names it in errors.
fn build_light(desc: &LightDesc, field: &str) -> Result<Light, (String, String)> {
    let err = |sub: &str, message: &str| light_error(field, sub, message);
    let lift = |r: Result<(), FieldError>| r.map_err(|(f, m)| (f, m.to_string()));
    Ok(match *desc {
        LightDesc::Directional {
            direction: d,
            color: c,
            intensity,
            angular_radius_degrees,
        } => {
            if !(0.0..45.0).contains(&angular_radius_degrees) {
                return Err(err("angular_radius_degrees", "must be in [0, 45)"));
            }
            Light {
                kind: LightKind::Directional,
                position: Vec3::ZERO,
                direction: light_direction(d, field)?,
                radiance: light_radiance(c, intensity, field)?,
                range: f32::INFINITY,
                spot_angle: 0.0,
                spot_softness: 0.0,
                radius: angular_radius_degrees.to_radians(),
            }
        }
        LightDesc::Point {
            position,
            color: c,
            intensity,
            range,
            radius: r,
        } => {
            lift(check_vec(position, &format!("{field}.position")))?;
            lift(check_positive(range, &format!("{field}.range")))?;
            Light {
                kind: LightKind::Point,
                position,
                direction: Vec3::NEG_Y,
                radiance: light_radiance(c, intensity, field)?,
                range,
                spot_angle: 0.0,
                spot_softness: 0.0,
                radius: light_radius(r, field)?,
            }
        }
        LightDesc::Spot {
            position,
            direction: d,
            color: c,
            intensity,
            range,
            angle_degrees,
            softness,
            radius: r,
        } => {
            lift(check_vec(position, &format!("{field}.position")))?;
            lift(check_positive(range, &format!("{field}.range")))?;
            if !(angle_degrees > 0.5 && angle_degrees < 89.0) {
                return Err(err("angle_degrees", "must be between 0.5 and 89"));
            }
            if !(0.0..=1.0).contains(&softness) {
                return Err(err("softness", "must be in [0, 1]"));
            }
            Light {
                kind: LightKind::Spot,
                position,
                direction: light_direction(d, field)?,
                radiance: light_radiance(c, intensity, field)?,
                range,
                spot_angle: angle_degrees.to_radians(),
                spot_softness: softness,
                radius: light_radius(r, field)?,
            }
        }
    })
}

/// A light's error: `field.sub` is wrong.
fn light_error(field: &str, sub: &str, message: &str) -> (String, String) {
    (format!("{field}.{sub}"), message.to_string())
}

/// A light's direction, normalized.
fn light_direction(d: Vec3, field: &str) -> Result<Vec3, (String, String)> {
    check_vec(d, &format!("{field}.direction")).map_err(|(f, m)| (f, m.to_string()))?;
    d.try_normalize()
        .ok_or_else(|| light_error(field, "direction", "must not be zero"))
}

/// A light's radiance: its colour scaled by its intensity.
fn light_radiance(c: Vec3, intensity: f32, field: &str) -> Result<Vec3, (String, String)> {
    check_vec(c, &format!("{field}.color")).map_err(|(f, m)| (f, m.to_string()))?;
    if c.min_element() < 0.0 {
        return Err(light_error(
            field,
            "color",
            "components must not be negative",
        ));
    }
    if !(intensity.is_finite() && intensity >= 0.0) {
        return Err(light_error(
            field,
            "intensity",
            "must be a finite number >= 0",
        ));
    }
    Ok(c * intensity)
}

/// A point or spot light's radius.
fn light_radius(r: f32, field: &str) -> Result<f32, (String, String)> {
    if r.is_finite() && r >= 0.0 {
        Ok(r)
    } else {
        Err(light_error(field, "radius", "must be a finite number >= 0"))
    }
}

/// A mesh's parts (each with its file material, if any), what loading changed, and warnings.
type BuiltMesh = (
    Vec<(MeshData, Option<FileMaterial>)>,
    MeshReport,
    Vec<String>,
);

/// Builds an object's mesh: the parts of an OBJ or glTF file, or one generated shape.
fn build_mesh(
    desc: &MeshDesc,
    field: &str,
    path: &Path,
    base: &Path,
) -> Result<BuiltMesh, SceneError> {
    match desc {
        MeshDesc::Obj(file) => load_obj_mesh(&base.join(file), field, path),
        MeshDesc::Gltf(file) => load_gltf_mesh(&base.join(file), field, path),
        shape => {
            let mesh = shape_mesh(shape).map_err(|message| SceneError::Invalid {
                path: path.to_path_buf(),
                field: format!("{field}.mesh"),
                message: message.to_string(),
            })?;
            Ok((vec![(mesh, None)], MeshReport::default(), Vec::new()))
        }
    }
}

/// Loads the OBJ file `obj`, each part with its MTL material.
fn load_obj_mesh(obj: &Path, field: &str, path: &Path) -> Result<BuiltMesh, SceneError> {
    let loaded = mesh::load_obj(obj).map_err(|e| SceneError::Obj {
        path: path.to_path_buf(),
        field: format!("{field}.mesh"),
        obj: obj.to_path_buf(),
        message: e.to_string(),
    })?;
    let parts = loaded
        .parts
        .into_iter()
        .map(|p| (p.mesh, p.material.map(|m| FileMaterial::Mtl(Box::new(m)))))
        .collect();
    Ok((parts, loaded.report, loaded.warnings))
}

/// Loads the glTF file `gltf`, each part with its material.
fn load_gltf_mesh(gltf: &Path, field: &str, path: &Path) -> Result<BuiltMesh, SceneError> {
    let loaded = gltf_file::load_gltf(gltf).map_err(|e| SceneError::Gltf {
        path: path.to_path_buf(),
        field: format!("{field}.mesh"),
        file: gltf.to_path_buf(),
        message: e.to_string(),
    })?;
    let parts = loaded
        .parts
        .into_iter()
        .map(|p| (p.mesh, Some(FileMaterial::Gltf(p.material))))
        .collect();
    Ok((parts, loaded.report, loaded.warnings))
}

/// Generates a shape's mesh; the error says which of its sizes or counts is out of range.
fn shape_mesh(desc: &MeshDesc) -> Result<MeshData, &'static str> {
    let positive = |values: &[f32]| values.iter().all(|v| v.is_finite() && *v > 0.0);
    let count_ok = |n: u32| (3..=4096).contains(&n);
    Ok(match *desc {
        MeshDesc::Obj(_) | MeshDesc::Gltf(_) => {
            return Err("names a model file, which is loaded rather than generated");
        }
        MeshDesc::Plane { size, subdivisions } => {
            if !positive(&[size]) || !(1..=1024).contains(&subdivisions) {
                return Err("Plane needs size > 0 and 1..=1024 subdivisions");
            }
            mesh::plane(size, subdivisions)
        }
        MeshDesc::Box { size } => {
            if !positive(&size.to_array()) {
                return Err("Box sizes must be finite and > 0");
            }
            mesh::cuboid(size)
        }
        MeshDesc::Sphere {
            radius,
            segments,
            rings,
        } => {
            if !positive(&[radius]) || !count_ok(segments) || !count_ok(rings) {
                return Err("Sphere needs radius > 0 and 3..=4096 segments and rings");
            }
            mesh::sphere(radius, segments, rings)
        }
        MeshDesc::Cylinder {
            radius,
            height,
            segments,
        } => {
            if !positive(&[radius, height]) || !count_ok(segments) {
                return Err("Cylinder needs radius, height > 0 and 3..=4096 segments");
            }
            mesh::cylinder(radius, height, segments)
        }
        MeshDesc::Torus {
            major_radius,
            minor_radius,
            segments,
            rings,
        } => {
            if !positive(&[major_radius, minor_radius]) || !count_ok(segments) || !count_ok(rings) {
                return Err("Torus needs radii > 0 and 3..=4096 segments and rings");
            }
            mesh::torus(major_radius, minor_radius, segments, rings)
        }
        MeshDesc::Cone {
            radius,
            height,
            segments,
        } => {
            if !positive(&[radius, height]) || !count_ok(segments) {
                return Err("Cone needs radius, height > 0 and 3..=4096 segments");
            }
            mesh::cone(radius, height, segments)
        }
    })
}

fn receiver_plane(object: usize, transform: Mat4, size: f32) -> ReceiverPlane {
    let h = size * 0.5;
    let corners = [(-h, -h), (h, -h), (h, h), (-h, h)]
        .map(|(x, z)| transform.transform_point3(Vec3::new(x, 0.0, z)));
    let origin = transform.transform_point3(Vec3::ZERO);
    let normal = (glam::Mat3::from_mat4(transform).inverse().transpose() * Vec3::Y).normalize();
    ReceiverPlane {
        object,
        plane: normal.extend(-normal.dot(origin)),
        corners,
    }
}

fn validate_paths(paths: &PathsDesc, light_count: usize) -> Result<(), (String, String)> {
    let times_increase = |times: &[f32], field: String| -> Result<(), (String, String)> {
        if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] <= w[0]) {
            Err((
                field,
                "key times must be finite and strictly increasing".into(),
            ))
        } else {
            Ok(())
        }
    };
    let camera_times: Vec<f32> = paths.camera.iter().map(|k| k.time).collect();
    times_increase(&camera_times, "paths.camera".into())?;
    for (i, k) in paths.camera.iter().enumerate() {
        if !(k.position.is_finite() && k.target.is_finite()) {
            return Err((
                format!("paths.camera[{i}]"),
                "coordinates must be finite numbers".into(),
            ));
        }
    }
    for (i, path) in paths.lights.iter().enumerate() {
        if path.light >= light_count {
            return Err((
                format!("paths.lights[{i}].light"),
                format!("light {} does not exist ({light_count} lights)", path.light),
            ));
        }
        let times: Vec<f32> = path.keys.iter().map(|k| k.time).collect();
        times_increase(&times, format!("paths.lights[{i}]"))?;
        if path.keys.iter().any(|k| !k.value.is_finite()) {
            return Err((
                format!("paths.lights[{i}]"),
                "coordinates must be finite numbers".into(),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod fuzz_tests;
