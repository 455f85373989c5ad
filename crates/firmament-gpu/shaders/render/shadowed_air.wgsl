// The air under the clouds keeps w of its multiple scattering and the ground takes g of
// the clear sky's light (firmament::render::shadowed_air, whose tables the CPU tabulates
// and uploads after each light's shadow map and coarse map: AIR_TEXELS² texels of channel
// groups over the same square, w's then g's); render/cloud_frame.wgsl's clouded_air takes
// the multiple scattering out over the stretches and its surface shading calls ground_sky.

// ShadowedAir::weight: w over the ground below local `x` for light l, channel group k (the
// edge texels beyond the square).
fn air_weight(l: u32, x: vec3<f32>, k: u32) -> vec4<f32> {
    return air_sample(l, 0u, x, k);
}

// ShadowedAir::ground_sky: the sky's light on the ground at local `x` under light l's
// clouds, `clear` (the sky method's, before the clouds) times the neighbourhood's g, in
// place of `sky` (dim_surface_light's column-local estimate); `sky` at or above the base or
// without the light's map.
fn ground_sky(l: u32, x: vec3<f32>, k: u32, clear: vec4<f32>, sky: vec4<f32>) -> vec4<f32> {
    if (clouds.shadow_at[l] == NONE || cloud_point(x).alt_m >= clouds.shadow_base_m) {
        return sky;
    }
    return clear * air_sample(l, 1u, x, k);
}

// ShadowedAir::sample: table `which` (0: w, 1: g, one after the other) below local `x`.
fn air_sample(l: u32, which: u32, x: vec3<f32>, k: u32) -> vec4<f32> {
    let z = clouds.planet_radius_m + x.z;
    if (z <= 0.0) {
        return vec4<f32>(1.0);
    }
    let stride = 4u * atm.groups;
    let at = clouds.shadow_at[l] + SHADOW_TEXELS * SHADOW_TEXELS + COARSE_TEXELS * COARSE_TEXELS + which * AIR_TEXELS * AIR_TEXELS * stride;
    let step = 2.0 * SHADOW_HALF_EXTENT_M / f32(AIR_TEXELS);
    let max_f = f32(AIR_TEXELS - 1u);
    let f = clamp((x.xy * (clouds.planet_radius_m / z) + SHADOW_HALF_EXTENT_M) / step - 0.5, vec2<f32>(0.0), vec2<f32>(max_f));
    let i = min(vec2<u32>(f), vec2<u32>(AIR_TEXELS - 2u));
    let t = f - vec2<f32>(i);
    let p00 = at + (i.y * AIR_TEXELS + i.x) * stride + 4u * k;
    let p10 = p00 + stride;
    let p01 = p00 + AIR_TEXELS * stride;
    let p11 = p01 + stride;
    let lo = mix(air_texel(p00), air_texel(p10), t.x);
    let hi = mix(air_texel(p01), air_texel(p11), t.x);
    return mix(lo, hi, t.y);
}

fn air_texel(p: u32) -> vec4<f32> {
    return vec4<f32>(cloud_data[p], cloud_data[p + 1u], cloud_data[p + 2u], cloud_data[p + 3u]);
}

// ShadowedAir::weigh's stretch of the ray from local `q` along `dir` below the clouds' base
// and before end_m (m) for light l: [x, y], empty (x ≥ y) without the light's map.
fn air_below(l: u32, q: vec3<f32>, dir: vec3<f32>, end_m: f32) -> vec2<f32> {
    if (clouds.shadow_at[l] == NONE) {
        return vec2<f32>(1.0, 0.0);
    }
    let below = shell_sphere(q, dir, clouds.shadow_base_m);
    if (below.x > below.y) {
        return vec2<f32>(1.0, 0.0);
    }
    return vec2<f32>(max(below.x, 0.0), min(below.y, end_m));
}
