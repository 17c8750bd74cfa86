//! The hardware traversal: the casters in an acceleration structure built by the driver and
//! traversed by ray queries (`ray-tracing/query.wgsl`), on adapters with
//! `EXPERIMENTAL_RAY_QUERY`. Opaque casters are one geometry the hardware answers alone;
//! alpha-masked ones are a second, non-opaque geometry whose candidate hits the shader tests
//! with the shared alpha test before it commits them.

use bytemuck::{Pod, Zeroable};
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use zoo_host::{RenderContext, TechniqueResult, wgpu};

use crate::{BuildStats, CasterTriangle, Tracer, or_one_zeroed, storage_buffer};

/// `RtMaskedTriangle` in `ray-tracing/query.wgsl`: a masked caster's corners' texture
/// coordinates and its alpha test, in the masked geometry's primitive order.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuMaskedTriangle {
    pub uv: [[f32; 2]; 3],
    pub mask_layer: i32,
    pub alpha_cutoff: f32,
}

/// A 3x4 row-major identity: the casters are in world space already.
const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// The layout of the hardware traversal's group.
pub(crate) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let stages = crate::STAGES;
    let scene = wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: stages,
        ty: wgpu::BindingType::AccelerationStructure {
            vertex_return: false,
        },
        count: None,
    };
    bind_group_layout(
        device,
        "ray tracing layout (ray queries)",
        &[
            scene,
            storage(1, stages, true),
            texture(
                2,
                stages,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D2Array,
            ),
            sampler(3, stages, wgpu::SamplerBindingType::Filtering),
        ],
    )
}

/// One geometry of the acceleration structure: its corners, three a triangle, and whether the
/// hardware may decide its hits alone.
struct Geometry {
    corners: Vec<[f32; 3]>,
    opaque: bool,
}

/// Builds the acceleration structure of `ctx`'s scene (submitted to the queue) and its bind
/// group, with its size (without the time).
pub(crate) fn upload(
    ctx: &RenderContext<'_>,
    layout: &wgpu::BindGroupLayout,
) -> TechniqueResult<(wgpu::BindGroup, BuildStats)> {
    let casters = crate::caster_triangles(ctx.scene);
    let (masked, opaque): (Vec<&CasterTriangle>, Vec<&CasterTriangle>) =
        casters.iter().partition(|c| c.mask.is_some());
    let corners = |triangles: &[&CasterTriangle]| -> Vec<[f32; 3]> {
        let corners = triangles.iter().flat_map(|t| t.corners);
        corners.map(|p| p.to_array()).collect()
    };
    let geometries: Vec<Geometry> = [
        Geometry {
            corners: corners(&opaque),
            opaque: true,
        },
        Geometry {
            corners: corners(&masked),
            opaque: false,
        },
    ]
    .into_iter()
    .filter(|g| !g.corners.is_empty())
    .collect();
    let records: Vec<GpuMaskedTriangle> = masked
        .iter()
        .map(|t| {
            let mask = t.mask.expect("partitioned by mask");
            GpuMaskedTriangle {
                uv: t.uv.map(|uv| uv.to_array()),
                mask_layer: mask.layer as i32,
                alpha_cutoff: mask.cutoff,
            }
        })
        .collect();

    let device = &ctx.gpu.device;
    let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
        label: Some("ray tracing scene (top level)"),
        max_instances: 1,
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("ray tracing acceleration structure build"),
    });
    if geometries.is_empty() {
        // No casters: a top level without instances, which no ray hits.
        encoder.build_acceleration_structures([], [&tlas]);
    } else {
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
                label: Some("ray tracing casters (bottom level)"),
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
                    label: Some(if g.opaque {
                        "ray tracing opaque casters"
                    } else {
                        "ray tracing masked casters"
                    }),
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
        tlas[0] = Some(wgpu::TlasInstance::new(&blas, IDENTITY, 0, 0xff));
        let entry = wgpu::BlasBuildEntry {
            blas: &blas,
            geometry: wgpu::BlasGeometries::TriangleGeometries(triangles),
        };
        encoder.build_acceleration_structures([&entry], [&tlas]);
    }
    ctx.gpu.queue.submit([encoder.finish()]);

    let masked_records = storage_buffer(
        device,
        "ray tracing masked casters' alpha tests",
        &or_one_zeroed::<GpuMaskedTriangle>(&records),
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
        ],
    );
    let stats = BuildStats {
        tracer: Tracer::RayQuery,
        triangles: casters.len(),
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
}
