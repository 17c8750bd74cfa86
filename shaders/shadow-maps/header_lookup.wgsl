// Depth-map lookups through one light's `MapHeader`: projection into the layer a point falls
// in (cube faces included), depths along the map's axis, and the filters' map access
// (`shadow_tap`, `shadow_depths`) for the header set by `look_up`. The maps come from
// `depth_lookup.wgsl` (group 3); the importer binds the header.

#import "shadow-maps/receiver.wgsl"
#import "shadow-maps/filters.wgsl"
#import "shadow-maps/depth_lookup.wgsl"

// Where p lands in the header's maps.
fn header_point(h: MapHeader, p: vec3<f32>) -> MapPoint {
    return map_point(header_layer(h, p), p);
}

// Distance along the map's axis for a [0, 1] depth value of the header's maps.
fn header_linear_depth(h: MapHeader, d: f32) -> f32 {
    if h.perspective == 1u {
        return h.near * h.far / (h.far - d * (h.far - h.near));
    }
    return h.near + d * (h.far - h.near);
}

// Unit direction the header's light rays travel at p.
fn header_ray(h: MapHeader, p: vec3<f32>) -> vec3<f32> {
    let light = lights[h.light];
    if h.perspective == 1u {
        return normalize(p - light.position);
    }
    return light.direction;
}

// Receiver depth minus stored depth at p, along the map's axis (0 outside the maps).
fn header_depth_difference(h: MapHeader, p: vec3<f32>) -> f32 {
    let m = header_point(h, p);
    if !m.inside {
        return 0.0;
    }
    return header_linear_depth(h, m.depth) - header_linear_depth(h, stored_map_depth(m));
}

// The header the filters' map access reads (set by `look_up`).
var<private> looked_up: MapHeader;

// One comparison tap (the filters' map access): 1 = lit; outside the maps = lit.
fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    return compare_map(header_point(looked_up, p), linear);
}

// (inside, receiver depth, stored depth) at p, depths along the map's axis.
fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    let m = header_point(looked_up, p);
    if !m.inside {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(1.0, header_linear_depth(looked_up, m.depth), header_linear_depth(looked_up, stored_map_depth(m)));
}

// Visibility of receiver `r` from the header's light through filter `f`, at `pixel`.
fn look_up(h: MapHeader, f: MapFilter, r: Receiver, pixel: vec2<f32>) -> f32 {
    looked_up = h;
    let frame = tangent_frame(header_ray(h, r.lookup));
    let light = lights[h.light];
    let parallel = h.perspective == 0u;
    let plane = TapPlane(r.lookup, r.surface.normal, select(light.position, light.direction, parallel), parallel);
    return filter_map(f, plane, frame, r.texel, filter_noise(pixel, camera.frame), h.near, h.perspective == 1u);
}
