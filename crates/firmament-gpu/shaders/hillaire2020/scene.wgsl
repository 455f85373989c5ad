// The scene of a Hillaire 2020 frame (the role of render/scene.wgsl for the 4D tables):
// the clear sky over the planet's ground sphere, which render.wgsl's `shade` draws. Hillaire
// 2020 has no terrain on the GPU: render.wgsl's `main_terrain` entry point calls this
// function but firmament_gpu::hillaire2020::render never dispatches it.

// Shader::shade of the clear sky (no surface but the ground sphere, no shadowed length).
fn shade_scene(dir: vec3<f32>) -> vec3<f32> {
    return shade(dir, 0.0);
}
