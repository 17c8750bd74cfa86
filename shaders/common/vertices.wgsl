// The scene's vertex buffer read as storage (`array<f32>`): each vertex is
// `zoo_host::render::Vertex` (position, normal, texture coordinates), whose size a test checks
// against this.
const VERTEX_FLOATS: u32 = 8u;
