// The clouds' tileable 3D noise (firmament::scene::clouds::noise_volume::NoiseVolume::sample):
// a cube of `size`³ texels in cloud_data from `offset`, x fastest, read trilinearly with
// wrap-around at texel centres, p in tiles (any real: the volume repeats).

fn noise_sample(offset: u32, size: u32, p: vec3<f32>) -> f32 {
    let n = f32(size);
    let x = (p - floor(p)) * n - 0.5;
    let c = floor(x);
    let f = x - c;
    // c ≥ −1: −1 wraps to the last texel.
    let i0 = vec3<u32>(select(vec3<i32>(c), vec3<i32>(i32(size) - 1), c < vec3<f32>(0.0)));
    let i1 = select(i0 + 1u, vec3<u32>(0u), i0 + 1u >= vec3<u32>(size));
    let row00 = offset + (i0.z * size + i0.y) * size;
    let row10 = offset + (i0.z * size + i1.y) * size;
    let row01 = offset + (i1.z * size + i0.y) * size;
    let row11 = offset + (i1.z * size + i1.y) * size;
    let x00 = mix(cloud_data[row00 + i0.x], cloud_data[row00 + i1.x], f.x);
    let x10 = mix(cloud_data[row10 + i0.x], cloud_data[row10 + i1.x], f.x);
    let x01 = mix(cloud_data[row01 + i0.x], cloud_data[row01 + i1.x], f.x);
    let x11 = mix(cloud_data[row11 + i0.x], cloud_data[row11 + i1.x], f.x);
    let y0 = mix(x00, x10, f.y);
    let y1 = mix(x01, x11, f.y);
    return mix(y0, y1, f.z);
}
