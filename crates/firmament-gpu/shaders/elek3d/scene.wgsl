// The scene of an Elek 2009 / Yusov 2013 frame (the role of render/scene.wgsl for the 4D
// tables): the clear sky over the planet's ground sphere, which render.wgsl's `shade` draws.
// The 3D tables have no terrain on the GPU: render.wgsl's `main_terrain` entry point calls
// this function but firmament_gpu::elek3d::render never dispatches it.

// Shader::shade of the clear sky (no surface but the ground sphere, no shadowed length).
// (The depth of render/scene.wgsl's shade_scene: none kept, as this is never interleaved.)
fn shade_scene(dir: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(shade(dir, 0.0), SKY_DEPTH_M);
}
