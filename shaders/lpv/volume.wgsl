// Light propagation volumes: the data every LPV pass reads, the grid layout and the two-band
// spherical harmonics (seed 002 §5). Each of up to MAX_CASCADES grids has size³ cells (index
// x + size (y + size z), cascades one after another); a cell holds one SH4 vector per colour
// channel: the intensity of the light flowing through it, by direction.

const MAX_CASCADES: u32 = 4u;

// `zoo_plugin_lpv::gpu::LpvData`: the settings (`LpvSettings`: the generated `LpvParams` and
// the passes' own), where reflective-shadow-map positions are relative to, and each grid's
// `GpuCascade`.
#import "lpv/lpv_data.wgsl"

// 1/(2 sqrt(pi)) and sqrt(3)/(2 sqrt(pi)).
const SH_Y0: f32 = 0.2820948;
const SH_Y1: f32 = 0.4886025;
// The clamped cosine lobe: sqrt(pi)/2 and sqrt(pi/3).
const SH_COS0: f32 = 0.8862269;
const SH_COS1: f32 = 1.0233267;

// The SH basis in unit direction d.
fn sh_basis(d: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(SH_Y0, -SH_Y1 * d.y, SH_Y1 * d.z, -SH_Y1 * d.x);
}

// The SH projection of max(d . w, 0) around unit d.
fn sh_cosine_lobe(d: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(SH_COS0, -SH_COS1 * d.y, SH_COS1 * d.z, -SH_COS1 * d.x);
}

fn cells_per_grid() -> u32 {
    let n = lpv.settings.params.grid_size;
    return n * n * n;
}

// Whether integer cell `c` lies inside a grid.
fn inside_grid(c: vec3<i32>) -> bool {
    let n = i32(lpv.settings.params.grid_size);
    return all(c >= vec3<i32>(0)) && all(c < vec3<i32>(n));
}

// Index of cell `c` of cascade `k` over all grids.
fn cell_index(k: u32, c: vec3<i32>) -> u32 {
    let n = i32(lpv.settings.params.grid_size);
    return k * cells_per_grid() + u32(c.x + n * (c.y + n * c.z));
}

// The cell of cascade `k` holding world point `p`.
fn cell_of(k: u32, p: vec3<f32>) -> vec3<i32> {
    let g = lpv.cascades[k];
    return vec3<i32>(floor((p - g.min) / g.cell));
}
