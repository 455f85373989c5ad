// The scene of a Hillaire 2020 frame (the role of render/scene.wgsl for the 4D tables):
// the clear sky over the planet's ground sphere, which render.wgsl's `shade` draws. Hillaire
// 2020 has no terrain on the GPU: render.wgsl's `main_terrain` entry point calls this
// function but firmament_gpu::hillaire2020::render never dispatches it.

// Shader::shade of the clear sky (no surface but the ground sphere, no shadowed length).
// (The depth of render/scene.wgsl's shade_scene: none kept, as this is never interleaved.)
fn shade_scene(dir: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(shade(dir, 0.0), SKY_DEPTH_M);
}
