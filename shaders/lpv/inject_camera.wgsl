// Occluders seen by the camera (seed 002 §5.2): every G-buffer pixel is a surfel of the
// area its pixel covers on the surface, added to the camera's occluders.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "lpv/volume.wgsl"
#import "lpv/occluders.wgsl"

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
    add_occluder(1u, s.position, s.normal, area, 1.0);
}
