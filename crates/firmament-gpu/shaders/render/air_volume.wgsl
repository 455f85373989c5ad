// The terrain's change of the air's light along the observer's views
// (firmament::render::air_volume::AirVolume::add): ΔS on AIR_AZIMUTHS × AIR_ELEVATIONS
// directions × AIR_STEPS + 1 distances, read with one trilinear lookup at a pixel's direction
// and hit distance. In terrain_data at terrain.air: the reach D of each direction (m), then
// per direction the cumulative ΔS at d_j = D·(j/J)², channel-minor. The observer's frame is
// the local one (east, north, up: x, y, z).

fn air_volume_add(dir: vec3<f32>, end_m: f32, k: u32) -> vec4<f32> {
    if (terrain.air == NONE) {
        return vec4<f32>(0.0);
    }
    let n = atm.channels;
    let elevation = degrees(asin(clamp(dir.z, -1.0, 1.0)));
    var azimuth = atan2(dir.x, dir.y);
    if (azimuth < 0.0) {
        azimuth += 2.0 * PI;
    }
    let s = sign(elevation) * sqrt(abs(elevation) / 90.0);
    let row = clamp((s + 1.0) * 0.5 * f32(AIR_ELEVATIONS - 1u), 0.0, f32(AIR_ELEVATIONS - 1u));
    let col = azimuth / (2.0 * PI) * f32(AIR_AZIMUTHS);
    let r0 = min(u32(row), AIR_ELEVATIONS - 2u);
    let fr = row - f32(r0);
    let c0 = u32(col) % AIR_AZIMUTHS;
    let fc = col - floor(col);
    let per_dir = (AIR_STEPS + 1u) * n;
    let values = terrain.air + AIR_AZIMUTHS * AIR_ELEVATIONS;
    var out = vec4<f32>(0.0);
    for (var corner = 0u; corner < 4u; corner++) {
        let dr = corner >> 1u;
        let dc = corner & 1u;
        let w = select(1.0 - fr, fr, dr == 1u) * select(1.0 - fc, fc, dc == 1u);
        if (w == 0.0) {
            continue;
        }
        let d = (r0 + dr) * AIR_AZIMUTHS + (c0 + dc) % AIR_AZIMUTHS;
        let reach = terrain_data[terrain.air + d];
        if (reach <= 0.0) {
            continue;
        }
        let j = min(f32(AIR_STEPS) * sqrt(min(end_m, reach) / reach), f32(AIR_STEPS));
        let j0 = min(u32(j), AIR_STEPS - 1u);
        let f = j - f32(j0);
        let base = values + d * per_dir;
        for (var lane = 0u; lane < 4u; lane++) {
            let c = 4u * k + lane;
            if (c < n) {
                let a = terrain_data[base + j0 * n + c];
                let b = terrain_data[base + (j0 + 1u) * n + c];
                out[lane] += w * ((1.0 - f) * a + f * b);
            }
        }
    }
    return out;
}
