// Occluders seen by the camera (seed 002 §5.2): every G-buffer pixel is a surfel of the
// area its pixel covers on the surface, added to the camera's half of the geometry volume.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "lpv/volume.wgsl"

@group(2) @binding(0) var<storage, read> lpv: LpvData;
@group(2) @binding(1) var<storage, read_write> occluder_sums: array<atomic<i32>>;

@compute @workgroup_size(8, 8, 1)
fn cs_inject_camera(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let s = load_surface(pixel);
    if !s.valid {
        return;
    }
    let distance = length(s.position - camera.position);
    // A pixel's width at unit distance, and its footprint on the surface.
    let pixel_width = 2.0 / (camera.proj[1][1] * camera.size.y);
    let facing = max(abs(dot(s.normal, normalize(camera.position - s.position))), 0.05);
    let area = pow(distance * pixel_width, 2.0) / facing;
    let total = cells_per_grid() * lpv.settings.cascade_count;
    for (var k = 0u; k < lpv.settings.cascade_count; k++) {
        let g = lpv.cascades[k];
        let c = vec3<i32>(round((s.position - g.min) / g.cell));
        if !inside_grid(c) {
            continue;
        }
        let b = min(area / (g.cell * g.cell), 1.0) * sh_cosine_lobe(s.normal);
        let base = (total + cell_index(k, c)) * 4u;
        let scaled = vec4<i32>(round(b * lpv.settings.occluder_scale));
        for (var j = 0u; j < 4u; j++) {
            if scaled[j] != 0 {
                atomicAdd(&occluder_sums[base + j], scaled[j]);
            }
        }
    }
}
