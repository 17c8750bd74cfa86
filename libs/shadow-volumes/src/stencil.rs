//! Counting volume crossings in the stencil buffer.

use zoo_host::kit::{Stage, StageBuilder, slot_target};
use zoo_host::render::gbuffer::DEPTH_FORMAT;
use zoo_host::{RenderContext, TechniqueResult, wgpu};

/// The shader of the passes that read the counts.
pub(crate) const STENCIL_READ: &str = "shadow-volumes/stencil_read.wgsl";

zoo_host::param_choice! {
    /// How volume crossings are counted: z-fail (exact wherever the camera is), z-pass (wrong
    /// where a volume reaches the near plane), or for each light the cheaper one that is exact
    /// (Everitt and Kilgard: z-pass unless the light's near-clip volume meets a caster,
    /// [`crate::near_clip`]).
    pub enum Counting { ZFail, ZPass, Auto }
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
        // A light counted by `Auto` takes one of the other two, chosen by the technique.
        Counting::ZFail | Counting::Auto => (face(keep, decrement), face(keep, increment)),
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

/// The stencil bit that marks a pixel whose volumes are counted, where a mark restricts them
/// (seed 003's stencil restriction): the counts wrap in the seven bits below it.
pub const MARK_BIT: u32 = 0x80;

/// A full-screen mark on the G-buffer's depth-stencil (stencil reference [`MARK_BIT`]): sets
/// the bit wherever a fragment is drawn (the marking shader discards the others), leaving
/// depth as it is.
pub fn mark_depth_stencil() -> wgpu::DepthStencilState {
    let keep = wgpu::StencilOperation::Keep;
    let face = wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Always,
        fail_op: keep,
        depth_fail_op: keep,
        pass_op: wgpu::StencilOperation::Replace,
    };
    let mut state = stencil_state(
        wgpu::CompareFunction::Always,
        face,
        face,
        Default::default(),
    );
    state.stencil.write_mask = MARK_BIT;
    state
}

/// Counting like [`band_volume_depth_stencil`] (z-fail as a `Greater` test, so the samples
/// that pass are the ones counted) on the G-buffer's depth, which holds every pixel's surface,
/// but only at pixels marked with [`MARK_BIT`] (stencil reference [`MARK_BIT`]): the stencil
/// test alone rejects the fragments elsewhere, and the counts wrap in the bits below the mark.
pub fn marked_volume_depth_stencil(bias: wgpu::DepthBiasState) -> wgpu::DepthStencilState {
    let mut state = band_volume_depth_stencil(bias);
    for face in [&mut state.stencil.front, &mut state.stencil.back] {
        face.compare = wgpu::CompareFunction::Equal;
    }
    state.stencil.read_mask = MARK_BIT;
    state.stencil.write_mask = MARK_BIT - 1;
    state
}

/// The volume vertex buffers of a draw ([`VOLUME_VERTEX_LAYOUT`]).
pub const VOLUME_BUFFERS: &[Option<wgpu::VertexBufferLayout<'static>>] =
    &[Some(VOLUME_VERTEX_LAYOUT)];

/// A stage that draws volumes with `depth_stencil` ([`volume_depth_stencil`],
/// [`band_volume_depth_stencil`]) from vertex entry `vertex` of `shader` and its fragment
/// `fs_volume`, inside a light pass whose colour attachment is the light's visibility slot
/// (left untouched). `shadow-volumes/draw.wgsl` has both entries.
pub fn volume_stage<'a>(
    shader: &'a str,
    vertex: &'a str,
    depth_stencil: wgpu::DepthStencilState,
) -> StageBuilder<'a> {
    let untouched = Some(wgpu::ColorTargetState {
        write_mask: wgpu::ColorWrites::empty(),
        ..slot_target()
    });
    Stage::render(shader, vertex)
        .vertex_buffers(VOLUME_BUFFERS)
        .primitive(volume_primitive())
        .depth_stencil(depth_stencil)
        .fragment("fs_volume")
        .targets(&[untouched])
}

/// A state that keeps depth and stencil and passes where the stencil `compare`s true with the
/// reference: the passes that read the counts.
pub fn stencil_test(compare: wgpu::CompareFunction) -> wgpu::DepthStencilState {
    let keep = wgpu::StencilOperation::Keep;
    let face = wgpu::StencilFaceState {
        compare,
        fail_op: keep,
        depth_fail_op: keep,
        pass_op: keep,
    };
    stencil_state(
        wgpu::CompareFunction::Always,
        face,
        face,
        Default::default(),
    )
}

/// The resolve: in a light pass over the counted stencil (reference 0), writes visibility 0
/// wherever the count is not 0.
pub fn resolve_stage(ctx: &RenderContext<'_>) -> TechniqueResult<Stage> {
    Stage::fullscreen(STENCIL_READ, "fs_shadowed")
        .depth_stencil(stencil_test(wgpu::CompareFunction::NotEqual))
        .build(ctx)
}

/// The resolve of counts below a mark ([`marked_volume_depth_stencil`]; stencil reference
/// 0): visibility 0 wherever those bits are not 0.
pub fn marked_resolve_stage(ctx: &RenderContext<'_>) -> TechniqueResult<Stage> {
    let mut state = stencil_test(wgpu::CompareFunction::NotEqual);
    state.stencil.read_mask = MARK_BIT - 1;
    Stage::fullscreen(STENCIL_READ, "fs_shadowed")
        .depth_stencil(state)
        .build(ctx)
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
