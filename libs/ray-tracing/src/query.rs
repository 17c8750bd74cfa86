//! The hardware traversal: the casters in an acceleration structure built by the driver and
//! traversed by ray queries (`ray-tracing/query.wgsl`), on adapters with
//! `EXPERIMENTAL_RAY_QUERY`. Opaque casters are one geometry the hardware answers alone;
//! alpha-masked ones are a second, non-opaque geometry whose candidate hits the shader tests
//! with the shared alpha test before it commits them. Translucent casters are a second
//! instance (its own mask), a non-opaque geometry per object, whose candidates filter the ray.

use bytemuck::{Pod, Zeroable};
use zoo_host::glam::{Mat4, Vec3};
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::{BuildStats, CasterTriangle, Casters, Tracer, or_one_zeroed, storage_buffer};

/// `RtMaskedTriangle` in `ray-tracing/query.wgsl`: a masked caster's corners' texture
/// coordinates and its alpha test, in the masked geometry's primitive order.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuMaskedTriangle {
    pub uv: [[f32; 2]; 3],
    pub mask_layer: i32,
    pub alpha_cutoff: f32,
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
                uv: t.uv.map(|uv| uv.to_array()),
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

/// Builds the acceleration structure of `ctx`'s scene (submitted to the queue) and its bind
/// group, with its size (without the time). Casters drawn once are two instances (blocking,
/// translucent) at the identity; each mesh instances share is one bottom level, placed by each
/// of its instances. An instance's custom data is where its records start: the masked
/// triangles' alpha tests (blocking instances) or its translucent object (translucent ones, one
/// geometry each; the world's translucent casters, a geometry per object).
pub(crate) fn upload(
    ctx: &RenderContext<'_>,
    layout: &wgpu::BindGroupLayout,
) -> TechniqueResult<(wgpu::BindGroup, BuildStats)> {
    let casters = Casters::of(ctx.scene);
    let of_kind = |keep: &dyn Fn(&CasterTriangle) -> bool| -> Vec<&CasterTriangle> {
        casters.triangles.iter().filter(|c| keep(c)).collect()
    };
    let opaque = of_kind(&|c| c.translucent.is_none() && c.mask.is_none());
    let masked = of_kind(&|c| c.mask.is_some());
    let mut records = masked_records(&masked);
    // One geometry per translucent object with triangles: its geometry index is its record's.
    let (translucent, mut transmittance): (Vec<Geometry>, Vec<Vec3>) =
        (casters.transmittance.iter().enumerate())
            .map(|(object, colour)| {
                let triangles = of_kind(&|c| c.translucent == Some(object as u32));
                (Geometry::of(&triangles, false), *colour)
            })
            .filter(|(geometry, _)| !geometry.corners.is_empty())
            .unzip();

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
    // Each shared mesh's bottom level, and where its masked records start.
    let meshes: Vec<(Option<wgpu::Blas>, u32)> = (casters.meshes.iter())
        .map(|mesh| {
            let triangles: Vec<&CasterTriangle> = mesh.triangles.iter().collect();
            let opaque = !mesh.translucent && triangles.iter().all(|t| t.mask.is_none());
            let first = records.len() as u32;
            records.extend(masked_records(&triangles));
            let geometry = [Geometry::of(&triangles, opaque)];
            let blas = bottom_level(device, "ray tracing shared mesh", &geometry, &mut encoder);
            (blas, first)
        })
        .collect();
    for instance in &casters.instances {
        let (blas, first) = &meshes[instance.mesh];
        let Some(blas) = blas else { continue };
        let (custom, mask) = match instance.translucent {
            Some(object) => {
                transmittance.push(casters.transmittance[object as usize]);
                (transmittance.len() as u32 - 1, TRANSLUCENT_MASK)
            }
            None => (*first, BLOCKING_MASK),
        };
        levels.push((Some(blas.clone()), rows(instance.to_world), custom, mask));
    }
    if records.len().max(transmittance.len()) >= 1 << 24 {
        return Err(TechniqueError::Other(format!(
            "{} masked triangles and {} translucent objects: ray queries index at most 2^24",
            records.len(),
            transmittance.len()
        )));
    }
    let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
        label: Some("ray tracing scene (top level)"),
        max_instances: levels.len() as u32,
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    });
    // A missing level (no casters of its kind) is an empty instance, which no ray hits.
    for (index, (blas, transform, custom, mask)) in levels.iter().enumerate() {
        tlas[index] =
            (blas.as_ref()).map(|b| wgpu::TlasInstance::new(b, *transform, *custom, *mask));
    }
    encoder.build_acceleration_structures([], [&tlas]);
    ctx.gpu.queue.submit([encoder.finish()]);

    let masked_records = storage_buffer(
        device,
        "ray tracing masked casters' alpha tests",
        &or_one_zeroed::<GpuMaskedTriangle>(&records),
    );
    let translucent_records = storage_buffer(
        device,
        "ray tracing translucent objects",
        bytemuck::cast_slice(&crate::translucent_records(&transmittance, 0)),
    );
    let materials = &ctx.scene_buffers.materials;
    let bind_group = bind_group(
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
    );
    let stats = BuildStats {
        tracer: Tracer::RayQuery,
        triangles: casters.traced_count(),
        hierarchy: None,
        milliseconds: 0.0,
    };
    Ok((bind_group, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::{SizeRule, check_embedded_mirror};

    #[test]
    fn masked_record_mirrors_the_shader() {
        let record = zoo_host::mirror_fields!(GpuMaskedTriangle {
            uv,
            mask_layer,
            alpha_cutoff
        });
        check_embedded_mirror(
            "ray-tracing/query.wgsl",
            "RtMaskedTriangle",
            record,
            SizeRule::Equal,
        )
        .unwrap();
    }

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
