//! Counting volume crossings in the stencil buffer.

use zoo_host::RenderContext;
use zoo_host::kit::{pipeline_layout, slot_target};
use zoo_host::render::gbuffer::DEPTH_FORMAT;
use zoo_host::wgpu;

zoo_host::param_choice! {
    /// How volume crossings are counted.
    pub enum Counting { ZFail, ZPass }
}

/// Volume vertices: `vec4<f32>` positions, w = 0 for points at infinity.
pub const VOLUME_VERTEX_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 16,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &wgpu::vertex_attr_array![0 => Float32x4],
};

/// Volumes are drawn two-sided with unclipped depth (`DEPTH_CLIP_CONTROL`), so vertices at
/// infinity are counted wherever the camera is.
pub fn volume_primitive() -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        cull_mode: None,
        unclipped_depth: true,
        ..Default::default()
    }
}

/// Depth-stencil state of the volume draw on the G-buffer's depth-stencil: z-fail counts the
/// crossings behind the visible surface (back faces increment, front faces decrement where
/// the depth test fails), z-pass those in front of it (front faces increment where it passes),
/// with wrapping; depth is tested, never written.
pub fn volume_depth_stencil(
    counting: Counting,
    bias: wgpu::DepthBiasState,
) -> wgpu::DepthStencilState {
    let keep = wgpu::StencilOperation::Keep;
    let face = |pass_op, depth_fail_op| wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Always,
        fail_op: keep,
        depth_fail_op,
        pass_op,
    };
    let (increment, decrement) = (
        wgpu::StencilOperation::IncrementWrap,
        wgpu::StencilOperation::DecrementWrap,
    );
    let (front, back) = match counting {
        Counting::ZFail => (face(keep, decrement), face(keep, increment)),
        Counting::ZPass => (face(increment, keep), face(decrement, keep)),
    };
    stencil_state(wgpu::CompareFunction::Less, front, back, bias)
}

/// Counting like z-fail against a depth image in which only marked pixels hold the scene's
/// depth and all others hold 1 (the hybrid technique's edge band): a volume fragment behind the
/// surface passes the `Greater` test (back faces increment, front faces decrement), and at
/// pixels holding 1 every fragment fails, so early depth tests reject it before any stencil
/// or fragment work.
pub fn band_volume_depth_stencil(bias: wgpu::DepthBiasState) -> wgpu::DepthStencilState {
    let keep = wgpu::StencilOperation::Keep;
    let face = |pass_op| wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Always,
        fail_op: keep,
        depth_fail_op: keep,
        pass_op,
    };
    let front = face(wgpu::StencilOperation::DecrementWrap);
    let back = face(wgpu::StencilOperation::IncrementWrap);
    stencil_state(wgpu::CompareFunction::Greater, front, back, bias)
}

/// A pipeline that counts volumes in a band ([`band_volume_depth_stencil`]) from vertex stage
/// `vertex_entry` and fragment `fs_volume` of `module`, inside a light pass whose colour
/// attachment is the light's visibility slot (left untouched), with the host's groups and then
/// `groups`.
pub fn band_volume_pipeline(
    ctx: &RenderContext<'_>,
    label: &str,
    module: &wgpu::ShaderModule,
    vertex_entry: &str,
    groups: &[&wgpu::BindGroupLayout],
    bias: wgpu::DepthBiasState,
) -> wgpu::RenderPipeline {
    let layout = pipeline_layout(ctx, &format!("{label} layout"), groups);
    let untouched = Some(wgpu::ColorTargetState {
        write_mask: wgpu::ColorWrites::empty(),
        ..slot_target()
    });
    ctx.gpu
        .device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(vertex_entry),
                compilation_options: Default::default(),
                buffers: &[Some(VOLUME_VERTEX_LAYOUT)],
            },
            primitive: volume_primitive(),
            depth_stencil: Some(band_volume_depth_stencil(bias)),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_volume"),
                compilation_options: Default::default(),
                targets: &[untouched],
            }),
            multiview_mask: None,
            cache: None,
        })
}

/// A state on the G-buffer's depth-stencil that tests depth with `depth_compare` (never
/// writing it) and applies the `front` and `back` stencil faces: the volume draw, and the
/// passes that read its counts.
pub fn stencil_state(
    depth_compare: wgpu::CompareFunction,
    front: wgpu::StencilFaceState,
    back: wgpu::StencilFaceState,
    bias: wgpu::DepthBiasState,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(false),
        depth_compare: Some(depth_compare),
        stencil: wgpu::StencilState {
            front,
            back,
            read_mask: 0xff,
            write_mask: 0xff,
        },
        bias,
    }
}
