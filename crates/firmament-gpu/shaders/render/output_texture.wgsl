// Frame output into a storage texture the caller owns (format substituted by the host):
// texel (x, y) holds linear sRGB with Y in cd/m² and, in alpha, 1 inside the projection.

@group(0) @binding(12) var frame_out: texture_storage_2d<OUTPUT_FORMAT, write>;

fn write_pixel(i: u32, x: u32, y: u32, value: vec4<f32>) {
    textureStore(frame_out, vec2<u32>(x, y), value);
}
