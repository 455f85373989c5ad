// The stars' and small disks' shares added into an HDR frame that stays on the device
// (firmament::render::stars's splat: the CPU projects each point and weighs its four
// pixels; this adds the merged shares, one entry per pixel, so no two threads meet).
// Twin of the accumulation in `firmament::render::stars::draw_points`.

struct Splat {
    index: u32,
    r: f32,
    g: f32,
    b: f32,
};

struct Params {
    count: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

@group(0) @binding(0) var<storage, read_write> frame: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> splats: array<Splat>;
@group(0) @binding(2) var<uniform> params: Params;

@compute @workgroup_size(64)
fn add_points(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x + id.y * 65535u * 64u;
    if (k >= params.count) {
        return;
    }
    let s = splats[k];
    let p = frame[s.index];
    // Outside the projection (mask 0) nothing is drawn, as on the CPU.
    if (p.w > 0.5) {
        frame[s.index] = vec4<f32>(p.xyz + vec3<f32>(s.r, s.g, s.b), p.w);
    }
}
