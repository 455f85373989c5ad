// Frame output into a storage buffer: pixel i of the band at i, vec4 (linear sRGB with Y in
// cd/m², 1 inside the projection or 0), the layout Frame is read back from.

@group(0) @binding(12) var<storage, read_write> frame_out: array<vec4<f32>>;

fn write_pixel(i: u32, x: u32, y: u32, value: vec4<f32>) {
    frame_out[i] = value;
}
