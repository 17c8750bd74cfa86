// Screen-space helpers for passes that read the G-buffer's depth: where a world point lands on
// screen and how deep, and a march along a world segment through the depth buffer (contact
// shadows). The importer imports `common/frame.wgsl` and `common/gbuffer.wgsl`.

// View-space depth of world point p, in the G-buffer's depth units (distance along the view
// axis).
fn view_depth(p: vec3<f32>) -> f32 {
    return -(camera.view * vec4<f32>(p, 1.0)).z;
}

// Screen position of world point p in pixels (origin at the top-left corner; p in front of
// the camera).
fn screen_position(p: vec3<f32>) -> vec2<f32> {
    let clip = camera.view_proj * vec4<f32>(p, 1.0);
    let ndc = clip.xy / clip.w;
    return vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * camera.size;
}

// How far world point p lies behind the surface the G-buffer shows at `pixel`, along the view
// ray through p (negative in front of it; 0 where the pixel has no surface). The surface is
// extended by its tangent plane to p's ray, so a flat surface never hides points above it,
// however it is seen: the pixel's centre and p's position on screen may differ.
fn behind_depth_buffer(p: vec3<f32>, pixel: vec2<i32>) -> f32 {
    let s = load_surface(pixel);
    if !s.valid {
        return 0.0;
    }
    let ray = p - camera.position;
    let facing = dot(ray, s.normal);
    let depth = view_depth(p);
    if abs(facing) < 1e-6 * length(ray) {
        // A plane seen edge-on: compare depths.
        return depth - view_depth(s.position);
    }
    // The plane meets p's view ray at camera.position + ray * k.
    let k = dot(s.position - camera.position, s.normal) / facing;
    return (1.0 - k) * depth;
}

// A march through the depth buffer along a world segment.
struct ScreenMarch {
    start: vec3<f32>,
    // Unit direction and length of the segment.
    direction: vec3<f32>,
    length: f32,
    steps: u32,
    // What the depth buffer hides counts only this far behind it (world units): surfaces
    // are assumed this thick.
    thickness: f32,
    // Offset of the samples, in [0, 1) of a step (per pixel noise turns banding into grain).
    jitter: f32,
}

// 0 when a sample of the march lies behind the depth buffer by more than a thousandth of its
// depth and less than the thickness, else 1. Samples off screen or behind the camera end the
// march (lit).
fn screen_space_visibility(m: ScreenMarch) -> f32 {
    let step = m.length / f32(m.steps);
    for (var i = 0u; i < m.steps; i++) {
        let p = m.start + m.direction * (step * (f32(i) + m.jitter));
        let depth = view_depth(p);
        if depth <= camera.near {
            return 1.0;
        }
        let position = screen_position(p);
        if any(position < vec2<f32>(0.0)) || any(position >= camera.size) {
            return 1.0;
        }
        let behind = behind_depth_buffer(p, vec2<i32>(position));
        if behind > 1e-3 * depth && behind < m.thickness {
            return 0.0;
        }
    }
    return 1.0;
}
