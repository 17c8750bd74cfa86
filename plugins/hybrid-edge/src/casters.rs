//! Passes that render every caster triangle from one shadow-map layer with the vertices pulled
//! from the scene's storage buffers (`shaders/hybrid-edge/casters.wgsl`): the triangle-id maps
//! and the coverage maps. Group 1 holds the layer camera (a dynamic offset into the map set's
//! camera buffer) and the scene's vertices and indices.

use zoo_host::gpu::GpuType;
use zoo_host::kit::{bind_group, bind_group_layout, storage};
use zoo_host::render::drawn_runs;
use zoo_host::{RenderContext, wgpu};
use zoo_shadow_maps::{CAMERA_STRIDE, LayerCamera, TilePass};

/// Group 1 of a caster pass.
pub(crate) fn caster_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let vertex = wgpu::ShaderStages::VERTEX;
    bind_group_layout(
        device,
        label,
        &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: vertex,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
                },
                count: None,
            },
            storage(1, vertex, true),
            storage(2, vertex, true),
        ],
    )
}

/// Group 1 of a caster pass over the layer cameras `cameras` and the context's scene.
pub(crate) fn caster_group(
    ctx: &RenderContext<'_>,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    cameras: &wgpu::Buffer,
) -> wgpu::BindGroup {
    let buffers = ctx.scene_buffers;
    bind_group(
        &ctx.gpu.device,
        label,
        layout,
        &[
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: cameras,
                offset: 0,
                size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
            }),
            buffers.vertices.as_entire_binding(),
            buffers.indices.as_entire_binding(),
        ],
    )
}

/// Draws every caster triangle `reaches(light, object)` accepts with `pipeline` from the
/// camera of `tile_pass`'s layer, each object's stored index range with the object as the
/// instance.
pub(crate) fn draw_casters(
    ctx: &RenderContext<'_>,
    pass: &mut wgpu::RenderPass<'_>,
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
    tile_pass: &TilePass<'_>,
    reaches: &dyn Fn(usize, usize) -> bool,
) {
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
    let offset = (tile_pass.layer as u64 * CAMERA_STRIDE) as u32;
    pass.set_bind_group(1, group, &[offset]);
    let light = tile_pass.maps.light;
    for (indices, objects) in drawn_runs(ctx.scene, |i, o| o.casts_shadows && reaches(light, i)) {
        pass.draw(indices, objects);
    }
}
