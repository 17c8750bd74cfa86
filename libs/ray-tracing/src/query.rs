//! The hardware traversal: the casters in an acceleration structure built by the driver and
//! traversed by ray queries (`ray-tracing/query.wgsl`), on adapters with
//! `EXPERIMENTAL_RAY_QUERY`. Opaque casters are one geometry the hardware answers alone;
//! alpha-masked ones are a second, non-opaque geometry whose candidate hits the shader tests
//! with the shared alpha test before it commits them. Translucent casters are a second
//! instance (its own mask), a non-opaque geometry per object, whose candidates filter the ray.
//! A mesh instances share is one bottom level, placed by an instance of the top level for each
//! of theirs (a translucent instance's custom data locating its object's colour). Masked
//! instances are the exception: placed into the masked geometry in world space, since their
//! alpha test would read the candidate hit's instance data, which crashes lavapipe 25.0.7's
//! shader compiler in a closest-hit query.

use zoo_host::glam::{Mat4, Vec2, Vec3};
use zoo_host::gpu::gpu_bytes;
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::{
    BuildStats, CasterTriangle, Casters, SharedMesh, Tracer, or_one_zeroed, storage_buffer,
};

zoo_host::gpu_struct! {
    "ray-tracing/masked_triangle.wgsl" =>
    /// A masked caster's record in `ray-tracing/query.wgsl`: its corners' texture coordinates
    /// and its alpha test, in primitive order from its instance's custom data.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuMaskedTriangle {
        pub uv: [Vec2; 3],
        pub mask_layer: i32,
        pub alpha_cutoff: f32,
    }
}

/// A 3x4 row-major identity: the casters drawn once are in world space already.
const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// The layout of the hardware traversal's group.
pub(crate) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    bind_group_layout(device, "ray tracing layout (ray queries)", &entries())
}

/// The group's entries, binding by binding as `ray-tracing/query.wgsl` declares them.
pub(crate) fn entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let stages = crate::STAGES;
    let scene = wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: stages,
        ty: wgpu::BindingType::AccelerationStructure {
            vertex_return: false,
        },
        count: None,
    };
    vec![
        scene,
        storage(1, stages, true),
        texture(
            2,
            stages,
            wgpu::TextureSampleType::Float { filterable: true },
            wgpu::TextureViewDimension::D2Array,
        ),
        sampler(3, stages, wgpu::SamplerBindingType::Filtering),
        storage(4, stages, true),
    ]
}

/// Instance mask of the blocking casters (`RT_BLOCKING` in `ray-tracing/query.wgsl`).
pub const BLOCKING_MASK: u8 = 1;
/// Instance mask of the translucent casters (`RT_TRANSLUCENT` in `ray-tracing/query.wgsl`).
pub const TRANSLUCENT_MASK: u8 = 2;

/// One geometry of a bottom level: its corners, three a triangle, and whether the hardware
/// may decide its hits alone.
struct Geometry {
    corners: Vec<[f32; 3]>,
    opaque: bool,
}

impl Geometry {
    fn of(triangles: &[&CasterTriangle], opaque: bool) -> Geometry {
        let corners = triangles.iter().flat_map(|t| t.corners);
        Geometry {
            corners: corners.map(|p| p.to_array()).collect(),
            opaque,
        }
    }
}

/// A bottom level over `geometries` (empty ones left out; `None` if all are), its build
/// recorded in `encoder`.
fn bottom_level(
    device: &wgpu::Device,
    label: &str,
    geometries: &[Geometry],
    encoder: &mut wgpu::CommandEncoder,
) -> Option<wgpu::Blas> {
    let geometries: Vec<&Geometry> = geometries
        .iter()
        .filter(|g| !g.corners.is_empty())
        .collect();
    if geometries.is_empty() {
        return None;
    }
    let sizes: Vec<wgpu::BlasTriangleGeometrySizeDescriptor> = geometries
        .iter()
        .map(|g| wgpu::BlasTriangleGeometrySizeDescriptor {
            vertex_format: wgpu::VertexFormat::Float32x3,
            vertex_count: g.corners.len() as u32,
            index_format: None,
            index_count: None,
            flags: if g.opaque {
                wgpu::AccelerationStructureGeometryFlags::OPAQUE
            } else {
                wgpu::AccelerationStructureGeometryFlags::NO_DUPLICATE_ANY_HIT_INVOCATION
            },
        })
        .collect();
    let blas = device.create_blas(
        &wgpu::CreateBlasDescriptor {
            label: Some(label),
            flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
            update_mode: wgpu::AccelerationStructureUpdateMode::Build,
        },
        wgpu::BlasGeometrySizeDescriptors::Triangles {
            descriptors: sizes.clone(),
        },
    );
    let vertices: Vec<wgpu::Buffer> = geometries
        .iter()
        .map(|g| {
            use zoo_host::wgpu::util::DeviceExt;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("{label} vertices")),
                contents: bytemuck::cast_slice(&g.corners),
                usage: wgpu::BufferUsages::BLAS_INPUT,
            })
        })
        .collect();
    let triangles = sizes
        .iter()
        .zip(&vertices)
        .map(|(size, vertex_buffer)| wgpu::BlasTriangleGeometry {
            size,
            vertex_buffer,
            first_vertex: 0,
            vertex_stride: size_of::<[f32; 3]>() as wgpu::BufferAddress,
            index_buffer: None,
            first_index: None,
            transform_buffer: None,
            transform_buffer_offset: None,
        })
        .collect();
    let entry = wgpu::BlasBuildEntry {
        blas: &blas,
        geometry: wgpu::BlasGeometries::TriangleGeometries(triangles),
    };
    encoder.build_acceleration_structures([&entry], []);
    Some(blas)
}

/// The alpha tests of `triangles` (all masked), in order.
fn masked_records(triangles: &[&CasterTriangle]) -> Vec<GpuMaskedTriangle> {
    (triangles.iter())
        .filter_map(|t| {
            let mask = t.mask?;
            Some(GpuMaskedTriangle {
                uv: t.uv,
                mask_layer: mask.layer as i32,
                alpha_cutoff: mask.cutoff,
            })
        })
        .collect()
}

/// The row-major 3x4 form of an affine `transform`.
fn rows(transform: Mat4) -> [f32; 12] {
    let t = transform.transpose();
    let [a, b, c] = [t.x_axis, t.y_axis, t.z_axis].map(|r| r.to_array());
    [a, b, c].concat().try_into().expect("twelve numbers")
}

/// A top-level instance: its bottom level (`None`: no casters of its kind, so no instance),
/// its row-major 3x4 transform, its custom data and its mask.
type Level = (Option<wgpu::Blas>, [f32; 12], u32, u8);

/// Builds the acceleration structure of `ctx`'s scene (submitted to the queue) and its bind
/// group, with its size (without the time). Casters drawn once are two instances (blocking,
/// translucent) at the identity; each unmasked mesh instances share is one bottom level,
/// placed by each of its instances. A translucent instance's custom data is its object's
/// record (the world's translucent casters: a geometry per object, from record 0).
pub(crate) fn upload(
    ctx: &RenderContext<'_>,
    layout: &wgpu::BindGroupLayout,
) -> TechniqueResult<(wgpu::BindGroup, BuildStats)> {
    let casters = Casters::of(ctx.scene);
    let opaque = of_kind(&casters, |c| c.translucent.is_none() && c.mask.is_none());
    let placed_masked = placed_masked_triangles(&casters);
    let mut masked = of_kind(&casters, |c| c.mask.is_some());
    masked.extend(&placed_masked);
    let records = masked_records(&masked);
    let (translucent, mut transmittance) = translucent_geometries(&casters);

    let device = &ctx.gpu.device;
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("ray tracing acceleration structure build"),
    });
    let blocking = [Geometry::of(&opaque, true), Geometry::of(&masked, false)];
    let mut levels = vec![
        (
            bottom_level(
                device,
                "ray tracing blocking casters",
                &blocking,
                &mut encoder,
            ),
            IDENTITY,
            0,
            BLOCKING_MASK,
        ),
        (
            bottom_level(
                device,
                "ray tracing translucent casters",
                &translucent,
                &mut encoder,
            ),
            IDENTITY,
            0,
            TRANSLUCENT_MASK,
        ),
    ];
    levels.extend(shared_mesh_levels(
        device,
        &casters,
        &mut transmittance,
        &mut encoder,
    ));
    if transmittance.len() >= 1 << 24 {
        return Err(TechniqueError::Other(format!(
            "{} translucent objects: ray queries index at most 2^24",
            transmittance.len()
        )));
    }
    let tlas = top_level(device, &levels, &mut encoder);
    ctx.gpu.queue.submit([encoder.finish()]);

    let bind_group = query_bind_group(ctx, layout, &tlas, &records, &transmittance);
    let stats = BuildStats {
        tracer: Tracer::RayQuery,
        triangles: casters.traced_count(),
        hierarchy: None,
        milliseconds: 0.0,
    };
    Ok((bind_group, stats))
}

/// The casters drawn once (in world space) that `keep` keeps.
fn of_kind(casters: &Casters, keep: impl Fn(&CasterTriangle) -> bool) -> Vec<&CasterTriangle> {
    casters.triangles.iter().filter(|c| keep(c)).collect()
}

/// Whether any of a shared mesh's triangles has an alpha mask.
fn is_masked(mesh: &SharedMesh) -> bool {
    mesh.triangles.iter().any(|t| t.mask.is_some())
}

/// Every instance of the masked shared meshes, placed into world space. Their alpha tests
/// would need the candidate hit's instance data, and reading it in a closest-hit query
/// crashes lavapipe 25.0.7's shader compiler.
fn placed_masked_triangles(casters: &Casters) -> Vec<CasterTriangle> {
    (casters.instances.iter())
        .filter(|i| is_masked(&casters.meshes[i.mesh]))
        .flat_map(|i| {
            (casters.meshes[i.mesh].triangles.iter()).map(|t| CasterTriangle {
                corners: t.corners.map(|p| i.to_world.transform_point3(p)),
                mask: t.mask,
                uv: t.uv,
                translucent: None,
                object: i.object,
            })
        })
        .collect()
}

/// One geometry per translucent object with triangles drawn once, with its transmittance:
/// its geometry index is its record's.
fn translucent_geometries(casters: &Casters) -> (Vec<Geometry>, Vec<Vec3>) {
    (casters.transmittance.iter().enumerate())
        .map(|(object, colour)| {
            let triangles = of_kind(casters, |c| c.translucent == Some(object as u32));
            (Geometry::of(&triangles, false), *colour)
        })
        .filter(|(geometry, _)| !geometry.corners.is_empty())
        .unzip()
}

/// Each unmasked shared mesh's bottom level (opaque, or one translucent geometry), placed
/// by each of its instances; a translucent instance's transmittance is appended to
/// `transmittance`, its index the instance's custom data.
fn shared_mesh_levels(
    device: &wgpu::Device,
    casters: &Casters,
    transmittance: &mut Vec<Vec3>,
    encoder: &mut wgpu::CommandEncoder,
) -> Vec<Level> {
    let meshes: Vec<Option<wgpu::Blas>> = (casters.meshes.iter())
        .map(|mesh| {
            if is_masked(mesh) {
                return None;
            }
            let triangles: Vec<&CasterTriangle> = mesh.triangles.iter().collect();
            let geometry = [Geometry::of(&triangles, !mesh.translucent)];
            bottom_level(device, "ray tracing shared mesh", &geometry, encoder)
        })
        .collect();
    let mut levels = Vec::new();
    for instance in &casters.instances {
        let Some(blas) = &meshes[instance.mesh] else {
            continue;
        };
        let (custom, mask) = match instance.translucent {
            Some(object) => {
                transmittance.push(casters.transmittance[object as usize]);
                (transmittance.len() as u32 - 1, TRANSLUCENT_MASK)
            }
            None => (0, BLOCKING_MASK),
        };
        levels.push((Some(blas.clone()), rows(instance.to_world), custom, mask));
    }
    levels
}

/// The top level over `levels` (those with a bottom level), its build recorded in `encoder`.
fn top_level(
    device: &wgpu::Device,
    levels: &[Level],
    encoder: &mut wgpu::CommandEncoder,
) -> wgpu::Tlas {
    let instances: Vec<wgpu::TlasInstance> = (levels.iter())
        .filter_map(|(blas, transform, custom, mask)| {
            Some(wgpu::TlasInstance::new(
                blas.as_ref()?,
                *transform,
                *custom,
                *mask,
            ))
        })
        .collect();
    let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
        label: Some("ray tracing scene (top level)"),
        max_instances: instances.len().max(1) as u32,
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    });
    for (index, instance) in instances.into_iter().enumerate() {
        tlas[index] = Some(instance);
    }
    encoder.build_acceleration_structures([], [&tlas]);
    tlas
}

/// The ray queries' bind group: the scene's top level, the masked casters' alpha tests,
/// the material textures and the translucent objects' records.
fn query_bind_group(
    ctx: &RenderContext<'_>,
    layout: &wgpu::BindGroupLayout,
    tlas: &wgpu::Tlas,
    masked: &[GpuMaskedTriangle],
    transmittance: &[Vec3],
) -> wgpu::BindGroup {
    let device = &ctx.gpu.device;
    let masked_records = storage_buffer(
        device,
        "ray tracing masked casters' alpha tests",
        &or_one_zeroed::<GpuMaskedTriangle>(masked),
    );
    let translucent_records = storage_buffer(
        device,
        "ray tracing translucent objects",
        &gpu_bytes(&crate::translucent_records(transmittance)),
    );
    let materials = &ctx.scene_buffers.materials;
    bind_group(
        device,
        "ray tracing bind group (ray queries)",
        layout,
        &[
            tlas.as_binding(),
            masked_records.as_entire_binding(),
            wgpu::BindingResource::TextureView(&materials.textures),
            wgpu::BindingResource::Sampler(&materials.sampler),
            translucent_records.as_entire_binding(),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn instance_masks_match_the_shader() {
        let composed = zoo_host::ShaderLibrary::embedded()
            .compose("ray-tracing/query.wgsl")
            .unwrap();
        let constant = |name| zoo_host::gpu::layout::wgsl_integer_constant(&composed.source, name);
        assert_eq!(constant("RT_BLOCKING"), Ok(i64::from(BLOCKING_MASK)));
        assert_eq!(constant("RT_TRANSLUCENT"), Ok(i64::from(TRANSLUCENT_MASK)));
    }
}
