// A frame, one invocation per pixel (firmament::render, Shader::shade): the ray through the
// pixel (camera.wgsl) meets the planet's ground, lit by each light and the sky and seen
// through aerial perspective, or goes to the sky and the lights' disks; every piece comes
// from the sky method's functions (bruneton4d/view.wgsl), summed over the lights and the
// channel groups into linear sRGB. An optional per-pixel shadowed length (paper eq. 17–18:
// from shadow volumes or a shadow map) leaves the light shafts out.

// The shadowed length of each pixel (m), when frame.shadow_input is set.
@group(0) @binding(16) var shadow_lengths: texture_2d<f32>;

fn observer() -> Observer {
    var o: Observer;
    o.inside = frame.inside != 0u;
    o.r_km = frame.camera_r_km;
    o.rho_km = frame.camera_rho_km;
    o.above_top_km = frame.camera_above_top_km;
    return o;
}

// ColourMatrix::to_srgb of channel group k.
fn to_srgb(l: vec4<f32>, k: u32) -> vec3<f32> {
    let base = k * CHANNEL_STRIDE + CHANNEL_SRGB;
    return vec3<f32>(dot(view_constants[base], l), dot(view_constants[base + 1u], l), dot(view_constants[base + 2u], l));
}

// Shader::shade for one ray, summed to linear sRGB over the lights and channel groups.
fn shade(dir: vec3<f32>, shadow_length_km: f32) -> vec3<f32> {
    let o = observer();
    var v: View;
    v.mie_layout = frame.mie_layout;
    var rgb = vec3<f32>(0.0);
    // The planet's surface map at the ray's ground point (planet.wgsl), when one is bound.
    var map: PlanetWeights;
    var ground_normal = vec3<f32>(0.0, 0.0, 1.0);
    if (planet_on() && dir.z < 0.0) {
        let p = ground_point(o.r_km, dir);
        map = planet_weights(p);
        ground_normal = normalize(p);
    }
    for (var light = 0u; light < frame.lights; light++) {
        let vl = view_light(light);
        let g = ground_ray(v, o, vl, dir, shadow_length_km);
        if (g.hit) {
            // The ground lit by the light and the sky, seen through aerial perspective.
            let gl = ground_light(vl, g.mu_s_ground);
            var glint = 0.0;
            if (planet_on()) {
                glint = planet_specular(map, ground_normal, -dir, vl.direction);
            }
            for (var k = 0u; k < atm.groups; k++) {
                let scale = light_scale(light, k);
                let t = transmittance_to_point(g, k);
                let e = sun_and_sky_irradiance(gl, k);
                // A shadowed length on a ray to the ground ends at the ground point: in shadow.
                let direct = select(e.direct * light_irradiance(light, k), vec4<f32>(0.0), shadow_length_km > 0.0);
                var albedo = ground_albedo(k);
                if (planet_on()) {
                    albedo = planet_albedo(map, k);
                }
                // The sea's glint on the direct beam (render::Shader::shade).
                let l = sky_radiance_to_point(v, g, k) * scale
                    + (albedo / PI * (direct + e.sky * scale) + glint * direct) * t;
                rgb += to_srgb(l, k);
            }
            continue;
        }
        // The sky, and the light's disk through the air (never towards the ground).
        let s = sky_ray(v, o, vl, dir, shadow_length_km);
        let disk = light_disk(light, dir);
        // The background once (with the first light's ray: the transmittance is the same).
        let background = light == 0u && lights.background.x > 0.0;
        var background_f = 0.0;
        if (background) {
            // The observer is on the +z axis: the ray's cosine of the zenith angle is dir.z.
            background_f = background_factor(o.r_km, dir.z);
        }
        for (var k = 0u; k < atm.groups; k++) {
            var l = sky_radiance(v, s, k) * light_scale(light, k);
            if (disk.inside) {
                l += light_disk_radiance(light, disk, dir, k) * sky_transmittance(s, k);
            }
            if (background) {
                l += lights.background_radiance[k] * background_f * sky_transmittance(s, k);
            }
            rgb += to_srgb(l, k);
        }
    }
    return rgb;
}

// The pixel of invocation (gid, nwg) and its camera ray (CameraRay.valid false outside
// the band or the projection).
struct Pixel {
    i: u32,
    x: u32,
    y: u32,
    in_band: bool,
    ray: CameraRay,
}

// An interleaved frame (render/frame.wgsl) draws pixel (phase.x, phase.y) of each k×k block
// of the band only: invocation n is the n-th of those, i its index in the band.
fn pixel(gid: vec3<u32>, nwg: vec3<u32>) -> Pixel {
    var p: Pixel;
    let n = invocation_index(gid, nwg);
    let k = interleave_step();
    let phase = interleave_phase();
    // The pixels drawn per row of the band, and the rows drawn.
    let start_x = frame.interleave_columns & 0xffffu;
    let end_x = select(frame.width, frame.interleave_columns >> 16u, frame.interleave_columns > 0xffffu);
    let cols = select(0u, (end_x - start_x - phase.x + k - 1u) / k, end_x > start_x + phase.x);
    let rows = select(0u, (frame.rows - phase.y + k - 1u) / k, frame.rows > phase.y);
    p.in_band = n < cols * rows;
    if (!p.in_band) {
        return p;
    }
    p.x = start_x + (n % cols) * k + phase.x;
    let row = (n / cols) * k + phase.y;
    p.y = frame.first_row + row;
    p.i = row * frame.width + p.x;
    p.ray = camera_ray(f32(p.x) + 0.5, f32(p.y) + 0.5);
    return p;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = pixel(gid, nwg);
    if (!p.in_band) {
        return;
    }
    var out = vec4<f32>(0.0);
    if (p.ray.valid) {
        var shadow_km = 0.0;
        if (frame.shadow_input != 0u) {
            shadow_km = textureLoad(shadow_lengths, vec2<u32>(p.x, p.y), 0).x * 1e-3;
        }
        var rgb = vec3<f32>(0.0);
        // One ray, or DISK_SUBSAMPLES² over the footprint of a pixel on a disk's edge.
        let n = pixel_rays(p);
        for (var k = 0u; k < n; k++) {
            let r = pixel_ray(p, k, n);
            if (r.valid) {
                rgb += shade(r.dir, shadow_km);
            }
        }
        rgb /= f32(n);
        out = vec4<f32>(rgb * frame.balance.xyz, 1.0);
    }
    write_pixel(p.i, p.x, p.y, out);
}

// The frame over a terrain (render/scene.wgsl): an entry point of its own, so that frames
// without one carry none of its code.
@compute @workgroup_size(64)
fn main_terrain(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = pixel(gid, nwg);
    if (!p.in_band) {
        return;
    }
    var out = vec4<f32>(0.0);
    if (p.ray.valid) {
        var rgb = vec3<f32>(0.0);
        var depth_m = SKY_DEPTH_M;
        // One ray, or DISK_SUBSAMPLES² over the footprint of a pixel on a disk's edge.
        let n = pixel_rays(p);
        for (var k = 0u; k < n; k++) {
            let r = pixel_ray(p, k, n);
            if (r.valid) {
                let shaded = shade_scene(r.dir);
                rgb += shaded.xyz;
                depth_m = shaded.w;
            }
        }
        rgb /= f32(n);
        out = vec4<f32>(rgb * frame.balance.xyz, select(1.0, depth_m, depth_in_alpha()));
    }
    write_pixel(p.i, p.x, p.y, out);
}
