// Planar projected shadows, second pass: the casters flattened onto the marked receiver plane
// with Blinn's matrix M = (P.L) I - L P^T. Alpha-masked casters are tested at their own
// texture coordinates (`covered`, the judge's rule), so a mask's holes cast no shadow.

#import "common/frame.wgsl"
#import "common/materials.wgsl"
#import "planar/projection.wgsl"
#import "common/vertices.wgsl"

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    // The unprojected caster point: exact per fragment, since the whole transform is one
    // projective map and interpolation is perspective-correct.
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) object: u32,
}

@vertex
fn vs_shadow(
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @builtin(instance_index) object: u32,
    placement: Placement,
) -> ShadowOut {
    let world = placed_position(placement, position);
    var out: ShadowOut;
    var flattened = projection.shadow_matrix * vec4<f32>(world, 1.0);
    // A point beyond the light projects with w < 0, which clipping removes. Unless caster
    // parts on the wrong side are discarded (`params.w` 0, to show the artifact), it lands
    // mirrored on the plane, as a Cartesian projection along the light's rays puts it: an
    // anti-shadow.
    if projection.params.w < 0.5 && flattened.w < 0.0 {
        flattened = -flattened;
    }
    out.clip = camera.view_proj * flattened;
    out.world = world;
    out.uv = uv;
    out.object = object;
    return out;
}

@fragment
fn fs_shadow(in: ShadowOut) -> Targets {
    let height = dot(projection.plane, vec4<f32>(in.world, 1.0));
    let light_height = dot(projection.plane, projection.light);
    // Below the plane: a false shadow. At or beyond the light: an anti-shadow (both kept where
    // `params.w` is 0, to show them). A hole of the caster's mask: no shadow.
    let wrong_side = height < 0.0 || (projection.light.w > 0.0 && height >= light_height);
    if (wrong_side && projection.params.w > 0.5) || !covered(in.object, in.uv) {
        discard;
    }
    var out: Targets;
    out.visibility = vec4<f32>(projection.params.x);
    out.plane_id = 0u;
    return out;
}
