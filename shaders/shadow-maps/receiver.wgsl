// What every shadow-map lookup needs of one light's maps (`MapHeader`, written by the
// library's `MapHeader::new`) and of the pixel it shades (`Receiver`). The importer binds the
// header and imports one map group (`depth_lookup.wgsl` or `color_lookup.wgsl`).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "shadow-maps/layers.wgsl"

#import "shadow-maps/map_header.wgsl"

// World size of one of the header's map texels at p.
fn header_texel_world(h: MapHeader, p: vec3<f32>) -> f32 {
    let light = lights[h.light];
    return map_texel_world(h.perspective == 1u, h.layer_count, h.texel_scale, light.position, light.direction, p);
}

// The layer of the header's maps that p projects into.
fn header_layer(h: MapHeader, p: vec3<f32>) -> u32 {
    return light_layer(h.first_layer, h.layer_count, lights[h.light].position, p);
}

// A pixel's surface as one light's lookup sees it.
struct Receiver {
    surface: Surface,
    // World size of one map texel at the surface.
    texel: f32,
    // The surface moved off along its normal by the header's normal offset: where lookups
    // project.
    lookup: vec3<f32>,
}

// The surface at `pixel` for the header's light. Pixels without a surface or outside the
// light's range and cone are discarded: they keep their slot's value (lit), and lights with
// disjoint influence can share a slot.
fn map_receiver(h: MapHeader, pixel: vec2<f32>) -> Receiver {
    var r: Receiver;
    r.surface = load_surface(vec2<i32>(pixel));
    if !r.surface.valid {
        discard;
    }
    let light = lights[h.light];
    if light.kind != LIGHT_DIRECTIONAL {
        let to_surface = r.surface.position - light.position;
        let distance = length(to_surface);
        if distance >= light.range
            || (light.kind == LIGHT_SPOT && dot(to_surface, light.direction) <= light.cos_outer * distance) {
            discard;
        }
    }
    r.texel = header_texel_world(h, r.surface.position);
    r.lookup = r.surface.position + r.surface.normal * (h.normal_offset * r.texel);
    return r;
}
