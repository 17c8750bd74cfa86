//! Ray tracing on any adapter: rays against the scene's shadow casters, uploaded once per
//! scene: any-hit shadow rays (`rt_occluded(origin, dir, tmax)`), closest-hit rays
//! (`rt_closest`, the nearest caster's distance and barycentric coordinates,
//! `ray-tracing/hit.wgsl`) and translucent filtering (`rt_transmittance`). The portable
//! traversal also names the surface a closest-hit ray meets (`rt_closest_surface`: its
//! triangle, instance, normal and texture coordinates; [`RayTracing::object_buffer`] its
//! object). Two traversals give
//! the same answers:
//!
//! - [`Tracer::Compute`]: the judge's own bounding volume hierarchy
//!   ([`zoo_host::judge::FlatBvh`]) walked in WGSL (`ray-tracing/trace.wgsl`), on every
//!   adapter with storage buffers;
//! - [`Tracer::RayQuery`]: an acceleration structure built by the driver and traversed by
//!   hardware ray queries (`ray-tracing/query.wgsl`), where the device has
//!   `EXPERIMENTAL_RAY_QUERY`.
//!
//! Instances share their mesh's triangles in both: a hierarchy (or bottom level) per shared
//! mesh, in its stored space, which rays enter through each instance's placement.
//!
//! Alpha-masked casters are tested at the hit with the alpha test every pass shares
//! (`common/alpha_test.wgsl`). Translucent casters (opacity below 1) do not block
//! (`rt_occluded`); `rt_transmittance` filters a ray by the transmittance colour of each
//! translucent object it crosses, once per object however many of its surfaces it passes, as
//! the judge does (`ray-tracing/translucent.wgsl`).
//!
//! A shader imports `ray-tracing/trace.wgsl`; [`shader_source`] swaps the import for the
//! chosen tracer (both define the same three functions). The bindings are one group, group
//! [`GROUP`], which stages share as [`Tracer::group`].

use zoo_host::glam::{Mat4, Vec2, Vec3};
use zoo_host::gpu::{GpuType, gpu_bytes};
use zoo_host::scene::{AlphaMask, Scene};
use zoo_host::{RenderContext, ShaderLibrary, TechniqueError, TechniqueResult, wgpu};

mod compute;
mod light_pass;
mod origin;
mod query;

pub use compute::{
    CasterGeometry, GpuBatch, GpuInstance, GpuNode, GpuRoots, GpuTexcoords, GpuTriangle,
    NO_INSTANCE, NO_OBJECT, STACK_SIZE, SurfaceObjects,
};
pub use light_pass::{TraceEntry, TracePass, replace_target, transmittance_slot};
pub use origin::{ERROR_MODULE, RASTER_SUBPIXEL};
pub use query::GpuMaskedTriangle;

/// The bind group index both traversals declare their bindings in.
pub const GROUP: u32 = 3;

/// The module a tracing shader imports (the portable traversal).
pub const TRACE_MODULE: &str = "ray-tracing/trace.wgsl";
/// The module [`shader_source`] imports instead for hardware ray queries.
pub const QUERY_MODULE: &str = "ray-tracing/query.wgsl";
/// The exact per-triangle methods' resolve: a full-screen `fs_resolve` that shadows each pixel
/// flagged in its `shadowed` buffer (one `u32` a pixel).
pub const RESOLVE_SHADOWED_SHADER: &str = "ray-tracing/shadowed.wgsl";
/// Shadow rays from a G-buffer surface to a light's centre or disk, as the judge's references
/// trace them (`rt_light_visibility`), for a technique's direct shadows.
pub const LIGHT_RAYS_MODULE: &str = "ray-tracing/light_rays.wgsl";

/// The device limits of the exact per-triangle methods (per-triangle-volumes, frustum-traced):
/// in compute, the frame's lights and objects, the casters' five buffers and five of the
/// method's own; a fifth group for the method's buffers beside the frame, G-buffer, per-light
/// and casters' groups.
pub fn per_triangle_limits() -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffers_per_shader_stage: 12,
        max_bind_groups: 5,
        ..wgpu::Limits::downlevel_defaults()
    }
}

/// Stages that may trace rays.
const STAGES: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

zoo_host::param_choice! {
    /// How shadow rays find casters: hardware ray queries where the device has them (`Auto`),
    /// or always the portable BVH walk in a shader (`Compute`), or always ray queries
    /// (`RayQuery`, an error on devices without them).
    pub enum Traversal { Auto, Compute, RayQuery }
}

/// The traversal a device runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tracer {
    /// The BVH walked in WGSL (`ray-tracing/trace.wgsl`).
    Compute,
    /// Hardware ray queries (`ray-tracing/query.wgsl`).
    RayQuery,
}

impl Tracer {
    /// Whether `device` can trace with ray queries.
    pub fn has_ray_queries(device: &wgpu::Device) -> bool {
        device
            .features()
            .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY)
    }

    /// The tracer `traversal` asks for on `device`; technique `id` is unavailable when it
    /// asks for ray queries the device lacks.
    pub fn choose(
        traversal: Traversal,
        device: &wgpu::Device,
        id: &str,
    ) -> TechniqueResult<Tracer> {
        let queries = Self::has_ray_queries(device);
        match traversal {
            Traversal::Auto if queries => Ok(Tracer::RayQuery),
            Traversal::Auto | Traversal::Compute => Ok(Tracer::Compute),
            Traversal::RayQuery if queries => Ok(Tracer::RayQuery),
            Traversal::RayQuery => Err(TechniqueError::Unavailable {
                id: id.to_string(),
                reason: "traversal RayQuery needs hardware ray queries (EXPERIMENTAL_RAY_QUERY), \
                         which this device lacks; use Auto or Compute"
                    .into(),
            }),
        }
    }

    /// The layout of its group.
    pub fn layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        match self {
            Tracer::Compute => compute::layout(device),
            Tracer::RayQuery => query::layout(device),
        }
    }

    /// The variables its module declares in group [`GROUP`] (a test checks them).
    pub fn variables(self) -> &'static [&'static str] {
        match self {
            Tracer::Compute => &[
                "rt_nodes",
                "rt_triangles",
                "rt_texcoords",
                "rt_textures",
                "rt_sampler",
                "rt_translucent",
                "rt_instances",
                "rt_roots",
            ],
            Tracer::RayQuery => &[
                "rt_scene",
                "rt_masked",
                "rt_textures",
                "rt_sampler",
                "rt_translucent",
            ],
        }
    }

    /// Its group as stages share it: `layout` ([`Self::layout`]) and, once uploaded,
    /// `tracing`'s bind group.
    pub fn group<'a>(
        self,
        layout: &'a wgpu::BindGroupLayout,
        tracing: Option<&'a RayTracing>,
    ) -> zoo_host::kit::NamedGroup<'a> {
        zoo_host::kit::NamedGroup {
            names: self.variables(),
            layout,
            group: tracing.map(|t| &t.bind_group),
        }
    }

    /// How `list`, counters and notes name it.
    pub fn describe(self) -> &'static str {
        match self {
            Tracer::Compute => "BVH walked in a shader",
            Tracer::RayQuery => "hardware ray queries",
        }
    }
}

/// The text of library shader `shader` (which imports [`TRACE_MODULE`]) for `tracer`: as
/// written for the portable traversal, with [`QUERY_MODULE`] imported instead for ray queries.
pub fn shader_source(
    library: &ShaderLibrary,
    shader: &str,
    tracer: Tracer,
) -> Result<String, zoo_host::gpu::ShaderError> {
    let text = library.source(shader)?;
    let import = |module: &str| format!("#import \"{module}\"");
    let portable = import(TRACE_MODULE);
    let Some(line) = text.lines().position(|l| l.trim() == portable) else {
        return Err(zoo_host::gpu::ShaderError::Import {
            file: shader.to_string(),
            line: 1,
            message: format!(
                "no line `#import \"{TRACE_MODULE}\"`, which the chosen traversal replaces"
            ),
        });
    };
    Ok(match tracer {
        Tracer::Compute => text,
        Tracer::RayQuery => {
            let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
            lines[line] = import(QUERY_MODULE);
            lines.join("\n")
        }
    })
}

/// One shadow-casting triangle as both traversals store it.
pub(crate) struct CasterTriangle {
    /// Its corners where they are stored: world space, or its shared mesh's space.
    pub corners: [Vec3; 3],
    /// Its alpha mask (never on a translucent one: translucency wins, as in the judge).
    pub mask: Option<AlphaMask>,
    pub uv: [Vec2; 3],
    /// For a translucent caster, its object's index in [`Casters::transmittance`].
    pub translucent: Option<u32>,
    /// Its object's index in the scene (a shared mesh's: its first instance's).
    pub object: u32,
}

/// A mesh that instances share, in its stored space: its casters (their translucent object
/// unset: each instance names its own).
pub(crate) struct SharedMesh {
    pub triangles: Vec<CasterTriangle>,
    /// Whether its object is a translucent caster.
    pub translucent: bool,
}

/// One instance: its mesh, its placement and, for a translucent caster, its object's index in
/// [`Casters::transmittance`].
pub(crate) struct CasterInstance {
    pub mesh: usize,
    /// Its object's index in the scene.
    pub object: u32,
    pub to_world: Mat4,
    pub translucent: Option<u32>,
}

/// The scene's shadow casters as both traversals store them: the triangles of objects drawn
/// once in world space, and each mesh instances share once, with the instances.
pub(crate) struct Casters {
    pub triangles: Vec<CasterTriangle>,
    /// The colour each translucent object (instances included) lets through
    /// ([`zoo_host::scene::SceneObject::transmittance`]), in object order.
    pub transmittance: Vec<Vec3>,
    pub meshes: Vec<SharedMesh>,
    pub instances: Vec<CasterInstance>,
}

impl Casters {
    /// Every shadow-casting triangle of `scene` with an area (the judge's rule,
    /// [`zoo_host::judge::has_no_area`], in the space it is stored in), in object order; an
    /// instance's triangles once for all the instances of its object.
    pub fn of(scene: &Scene) -> Casters {
        let mut casters = Casters {
            triangles: Vec::new(),
            transmittance: Vec::new(),
            meshes: Vec::new(),
            instances: Vec::new(),
        };
        let mut shared = std::collections::HashMap::new();
        let casting = (scene.objects.iter().enumerate()).filter(|(_, o)| o.casts_shadows);
        for (object, o) in casting {
            let object = object as u32;
            let translucent = o.transmittance().map(|t| {
                casters.transmittance.push(t);
                casters.transmittance.len() as u32 - 1
            });
            let stored = |translucent: Option<u32>| {
                let uvs = scene.triangle_indices(o);
                (scene.stored_triangles(o).zip(uvs))
                    .filter(|(corners, _)| !zoo_host::judge::has_no_area(corners))
                    .map(|(corners, tri)| CasterTriangle {
                        corners,
                        mask: o.alpha_mask.filter(|_| o.transmittance().is_none()),
                        uv: tri.map(|i| scene.mesh.uvs.get(i).copied().unwrap_or_default()),
                        translucent,
                        object,
                    })
                    .collect::<Vec<_>>()
            };
            if !o.is_placed() {
                casters.triangles.extend(stored(translucent));
                continue;
            }
            let mesh = *shared.entry(o.indices.clone()).or_insert_with(|| {
                casters.meshes.push(SharedMesh {
                    triangles: stored(None),
                    translucent: translucent.is_some(),
                });
                casters.meshes.len() - 1
            });
            casters.instances.push(CasterInstance {
                mesh,
                object,
                to_world: o.placement,
                translucent,
            });
        }
        casters
    }

    /// Triangles traced: an instance's each time.
    pub fn traced_count(&self) -> usize {
        let shared: usize = (self.instances.iter())
            .map(|i| self.meshes[i.mesh].triangles.len())
            .sum();
        self.triangles.len() + shared
    }
}

zoo_host::gpu_struct! {
    "ray-tracing/translucent_object.wgsl" =>
    /// A translucent object's record in `ray-tracing/translucent.wgsl`: its transmittance
    /// colour.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuTranslucent {
        pub transmittance: Vec3,
    }
}

/// A root of [`GpuRoots`] where there is no such hierarchy (`RT_NO_HIERARCHY` in
/// `ray-tracing/trace.wgsl`).
pub const NO_HIERARCHY: u32 = u32::MAX;

/// Distinct translucent objects one ray is filtered by (`RT_MAX_CROSSED` in
/// `ray-tracing/translucent.wgsl`); further ones let it through unfiltered.
pub const MAX_CROSSED: u32 = 8;

/// The records of translucent objects letting `transmittance` through (one record, of no
/// object, without any).
pub(crate) fn translucent_records(transmittance: &[Vec3]) -> Vec<GpuTranslucent> {
    let record = |t: Vec3| GpuTranslucent { transmittance: t };
    match transmittance.is_empty() {
        true => vec![record(Vec3::ONE)],
        false => transmittance.iter().map(|t| record(*t)).collect(),
    }
}

/// A read-only storage buffer holding `contents`.
pub(crate) fn storage_buffer(device: &wgpu::Device, label: &str, contents: &[u8]) -> wgpu::Buffer {
    use zoo_host::wgpu::util::DeviceExt;
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// The bytes of `records`, or of one zeroed record (storage buffers cannot be empty).
pub(crate) fn or_one_zeroed<T: GpuType>(records: &[T]) -> Vec<u8> {
    if records.is_empty() {
        vec![0; T::SIZE]
    } else {
        gpu_bytes(records)
    }
}

/// The size of the portable traversal's hierarchy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hierarchy {
    pub nodes: usize,
    /// Levels below the root.
    pub depth: u32,
}

/// What building and uploading the casters took, for counters and benchmarks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildStats {
    pub tracer: Tracer,
    pub triangles: usize,
    /// The hierarchy the shader walks (the portable traversal only; the driver's is opaque).
    pub hierarchy: Option<Hierarchy>,
    /// CPU time of the build and the upload, in milliseconds (for ray queries, the driver's
    /// build is recorded then and runs on the GPU before the first trace).
    pub milliseconds: f64,
}

impl BuildStats {
    /// The statistics as named counters (`ShadowTechnique::counters`).
    pub fn counters(&self) -> Vec<(String, f64)> {
        let mut counters = vec![
            ("BVH triangles".to_string(), self.triangles as f64),
            ("BVH build ms".to_string(), self.milliseconds),
            (
                "hardware ray queries".to_string(),
                f64::from(u8::from(self.tracer == Tracer::RayQuery)),
            ),
        ];
        if let Some(h) = self.hierarchy {
            counters.push(("BVH nodes".to_string(), h.nodes as f64));
            counters.push(("BVH depth".to_string(), f64::from(h.depth)));
        }
        counters
    }
}

/// The uploaded casters and their bind group (group [`GROUP`]).
pub struct RayTracing {
    pub bind_group: wgpu::BindGroup,
    pub stats: BuildStats,
    /// The casters as runs of triangles for per-triangle passes
    /// ([`CasterGeometry::caster_batches`]; the portable traversal's only, empty for ray
    /// queries).
    pub batches: Vec<GpuBatch>,
    /// The scene object of each triangle and instance the portable traversal stores (empty
    /// for ray queries, whose hits `rt_closest_surface` does not name).
    pub objects: SurfaceObjects,
    /// The scene vertex buffer it was built from (a new scene has a new one).
    vertices: wgpu::Buffer,
}

impl RayTracing {
    /// Uploads the casters of `ctx`'s scene for `tracer`, whose group layout is `layout`
    /// ([`Tracer::layout`]); an error when the portable hierarchy is deeper than its
    /// traversal's stack holds.
    pub fn new(
        ctx: &RenderContext<'_>,
        tracer: Tracer,
        layout: &wgpu::BindGroupLayout,
    ) -> TechniqueResult<RayTracing> {
        let start = web_time::Instant::now();
        let ((bind_group, mut stats), (batches, objects)) = match tracer {
            Tracer::Compute => compute::upload(ctx, layout)?,
            Tracer::RayQuery => (query::upload(ctx, layout)?, Default::default()),
        };
        stats.milliseconds = start.elapsed().as_secs_f64() * 1000.0;
        Ok(RayTracing {
            bind_group,
            stats,
            batches,
            objects,
            vertices: ctx.scene_buffers.vertices.clone(),
        })
    }

    /// The casters' [`Self::batches`] in a storage buffer, for `caster_batches` of
    /// `ray-tracing/casters.wgsl` (one empty batch when there are none: a binding is never
    /// empty).
    pub fn batch_buffer(&self, ctx: &RenderContext<'_>, label: &str) -> wgpu::Buffer {
        let empty = [GpuBatch {
            first: 0,
            count: 0,
            start: 0,
            instance: NO_INSTANCE,
        }];
        let batches = if self.batches.is_empty() {
            &empty[..]
        } else {
            &self.batches[..]
        };
        let bytes = gpu_bytes(batches);
        let buffer = ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.len() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.gpu.queue.write_buffer(&buffer, 0, &bytes);
        buffer
    }

    /// [`Self::objects`] in one storage buffer of `u32`, for shaders that name the object of
    /// `rt_closest_surface`'s hits: the object of each stored triangle, then of each instance
    /// (one entry of [`NO_OBJECT`] where there are none); and where the instances' start.
    pub fn object_buffer(&self, ctx: &RenderContext<'_>, label: &str) -> (wgpu::Buffer, u32) {
        let objects = &self.objects;
        let mut all: Vec<u32> = objects
            .triangles
            .iter()
            .chain(&objects.instances)
            .copied()
            .collect();
        if all.is_empty() {
            all.push(NO_OBJECT);
        }
        let bytes: Vec<u8> = all.iter().flat_map(|o| o.to_le_bytes()).collect();
        let buffer = storage_buffer(&ctx.gpu.device, label, &bytes);
        (buffer, objects.triangles.len() as u32)
    }

    /// The number of caster triangles of [`Self::batches`]' flat numbering.
    pub fn caster_triangles(&self) -> u32 {
        self.batches.last().map_or(0, |b| b.start + b.count)
    }

    /// Whether it was built for `ctx`'s scene.
    pub fn is_for(&self, ctx: &RenderContext<'_>) -> bool {
        self.vertices == ctx.scene_buffers.vertices
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_match_the_shader() {
        use zoo_host::gpu::layout::wgsl_integer_constant;
        let module = "ray-tracing/translucent.wgsl";
        let source = ShaderLibrary::embedded().compose(module).unwrap().source;
        let constant = |name| wgsl_integer_constant(&source, name);
        assert_eq!(constant("RT_MAX_CROSSED"), Ok(i64::from(MAX_CROSSED)));
        let source = ShaderLibrary::embedded()
            .compose(TRACE_MODULE)
            .unwrap()
            .source;
        let constant = |name| wgsl_integer_constant(&source, name);
        assert_eq!(constant("RT_NO_HIERARCHY"), Ok(i64::from(NO_HIERARCHY)));
        let source = ShaderLibrary::embedded()
            .compose("ray-tracing/casters.wgsl")
            .unwrap()
            .source;
        let constant = |name| wgsl_integer_constant(&source, name);
        let no_instance = i64::from(NO_INSTANCE);
        assert_eq!(constant("CASTER_NO_INSTANCE"), Ok(no_instance));
    }

    /// Each traversal's layout has the shader's bindings of group [`GROUP`], in number and
    /// kind, and read-only storage where the shader reads.
    #[test]
    fn layouts_match_the_shaders_bindings() {
        use naga::{AddressSpace, StorageAccess, TypeInner};
        for (tracer, module, entries) in [
            (Tracer::Compute, TRACE_MODULE, compute::entries()),
            (Tracer::RayQuery, QUERY_MODULE, query::entries()),
        ] {
            let composed = ShaderLibrary::embedded().compose(module).unwrap();
            let parsed = naga::front::wgsl::parse_str(&composed.source).unwrap();
            let names = zoo_host::kit::reflect::declared_variables(&parsed, GROUP);
            assert_eq!(names, tracer.variables(), "{module}");
            let mut declared: Vec<(u32, String)> = (parsed.global_variables.iter())
                .filter_map(|(_, var)| {
                    let binding = var.binding.as_ref().filter(|b| b.group == GROUP)?;
                    let kind = match (&parsed.types[var.ty].inner, var.space) {
                        (_, AddressSpace::Storage { access }) => {
                            format!(
                                "storage read-only {}",
                                !access.contains(StorageAccess::STORE)
                            )
                        }
                        (_, AddressSpace::Uniform) => "uniform".to_string(),
                        (TypeInner::Image { .. }, _) => "texture".to_string(),
                        (TypeInner::Sampler { .. }, _) => "sampler".to_string(),
                        (TypeInner::AccelerationStructure { .. }, _) => "scene".to_string(),
                        (other, _) => format!("{other:?}"),
                    };
                    Some((binding.binding, kind))
                })
                .collect();
            declared.sort();
            let laid_out: Vec<(u32, String)> = (entries.iter())
                .map(|e| {
                    let kind = match e.ty {
                        wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Storage { read_only },
                            ..
                        } => format!("storage read-only {read_only}"),
                        wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            ..
                        } => "uniform".to_string(),
                        wgpu::BindingType::Texture { .. } => "texture".to_string(),
                        wgpu::BindingType::Sampler(_) => "sampler".to_string(),
                        wgpu::BindingType::AccelerationStructure { .. } => "scene".to_string(),
                        ref other => format!("{other:?}"),
                    };
                    (e.binding, kind)
                })
                .collect();
            assert_eq!(declared, laid_out, "{tracer:?} ({module})");
        }
    }

    /// A tracing shader of this crate's own (a technique's, such as rt-shadows', needs modules
    /// its crate registers).
    const TRACING_SHADER: &str = "\
// Each kind of shadow ray once.
#import \"ray-tracing/trace.wgsl\"

@fragment
fn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let origin = vec3<f32>(p.xy, 0.0);
    let dir = vec3<f32>(0.0, 1.0, 0.0);
    let hit = rt_closest(origin, dir, 10.0);
    let lit = select(1.0, 0.0, rt_occluded(origin, dir, 10.0));
    return vec4<f32>(rt_transmittance(origin, dir, 10.0) * lit, hit.t);
}
";

    #[test]
    fn the_query_variant_of_a_tracing_shader_validates_and_errors_point_home() {
        let dir = std::env::temp_dir().join(format!("zoo-ray-tracing-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("test")).unwrap();
        std::fs::write(dir.join("test/tracing.wgsl"), TRACING_SHADER).unwrap();
        let library = ShaderLibrary::from_disk(dir.clone());
        let shader = "test/tracing.wgsl";
        let portable = shader_source(&library, shader, Tracer::Compute).unwrap();
        assert_eq!(portable, library.source(shader).unwrap());
        library.validate_source(shader, &portable).unwrap();
        let query = shader_source(&library, shader, Tracer::RayQuery).unwrap();
        assert!(query.contains("#import \"ray-tracing/query.wgsl\""));
        assert!(!query.contains(&format!("#import \"{TRACE_MODULE}\"")));
        let (composed, _) = library.validate_source(shader, &query).unwrap();
        assert!(composed.source.starts_with("enable wgpu_ray_query;"));
        // A shader that does not import the portable traversal is refused by name.
        let err = shader_source(&library, "common/frame.wgsl", Tracer::RayQuery).unwrap_err();
        assert!(err.to_string().contains("common/frame.wgsl"), "{err}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
