// A frame's pixel under clouds (firmament::render::Shader::shade with the scene's volumes,
// no terrain): the planet's ground lit by each light under the clouds (their shadow map,
// their diffuse light and the ground–cloud interreflection: render/volumes.wgsl), the sky
// and the lights' disks, the air's light (its single scattering over the stretches of the
// ray outside the clouds' shadow, its multiple over the whole ray), and the clouds in front
// composited at their mean depth, their own aerial perspective under the same shadows.

// The air's light along `pray` up to end_m (Shadow::Lit, as the CPU's renderer gives it
// under clouds): the multiple scattering over the whole ray (the sky still lights the air in
// a cloud's shadow; `endp` is the ray's end piece) and the single scattering over the
// stretches outside the shadowed ones (the complement of `list` in [0, end_m],
// scene::lit_intervals), per channel group into acc (before the light's scale). `pray` ends
// at end_m (or is open towards the sky).
fn clouded_air(v: View, vl: ViewLight, pray: PointRay, list: ptr<function, ShadowList>, end_m: f32, endp: Piece, acc: ptr<function, array<vec4<f32>, MAX_CHANNEL_GROUPS>>) {
    for (var k = 0u; k < atm.groups; k++) {
        (*acc)[k] = vec4<f32>(0.0);
    }
    if (!pray.in_atmosphere) {
        return;
    }
    let start = piece_at(v, pray, vl, 0.0, false);
    for (var k = 0u; k < atm.groups; k++) {
        (*acc)[k] = whole_multiple(pray, start, endp, k);
    }
    let offset_km = pray.s.offset_km;
    var lit_from = 0.0;
    for (var i = 0u; i <= (*list).n; i++) {
        var a = lit_from;
        var b = end_m;
        if (i < (*list).n) {
            b = min((*list).s[i].x, end_m);
            lit_from = max(lit_from, (*list).s[i].y);
        }
        if (b <= a) {
            if (lit_from >= end_m) {
                break;
            }
            continue;
        }
        let a_km = max(a * 1e-3 - offset_km, 0.0);
        let b_km = min(b * 1e-3 - offset_km, pray.end_km);
        if (b_km > a_km) {
            let at_end = b_km >= pray.end_km;
            let pa = piece_at(v, pray, vl, a_km, true);
            let pb = piece_at(v, pray, vl, b_km, true);
            let b_subtracts = !at_end || !pray.open_end;
            for (var k = 0u; k < atm.groups; k++) {
                (*acc)[k] += lit_single(v, pray, pa, pb, b_subtracts, k);
            }
        }
        if (lit_from >= end_m) {
            break;
        }
    }
}

// Shader::shade under the clouds, summed to linear sRGB over the lights and channel groups.
// The clouds are marched first; then per light the air's light is summed over the whole ray
// and, where the ray meets a cloud, again to the cloud's mean depth (its aerial perspective),
// both from one call of clouded_air in a loop: every call site of a function is inlined
// whole by the driver, and lavapipe's compile grows faster than the code.
fn shade_clouds(dir: vec3<f32>) -> vec3<f32> {
    let o = observer();
    var v: View;
    v.mie_layout = frame.mie_layout;
    let q = vec3<f32>(0.0, 0.0, clouds.observer_alt_m);
    let ground = shell_sphere(q, dir, 0.0);
    let hit = ground.x <= ground.y && ground.x > 0.0;
    var end_m = 3.4e38;
    if (hit) {
        end_m = ground.x;
    }
    let x = q + end_m * dir;
    let up = cloud_point(x).up;
    // The clouds in front, seen through the air to their mean depth under the same shadows.
    var l_vol: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    let m = march_clouds(q, dir, end_m, &l_vol);
    let spans = select(1u, 2u, m.depth_m >= 0.0);
    var rgb = vec3<f32>(0.0);
    var front = vec3<f32>(0.0);
    var seen = vec3<f32>(0.0);
    var acc: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    for (var light = 0u; light < frame.lights; light++) {
        let vl = view_light(light);
        var list = shadowed_intervals(light, vl.direction, q, dir, end_m);
        for (var span = 0u; span < spans; span++) {
            // Span 0: the whole ray; span 1: the air in front of the clouds.
            let to_cloud = span == 1u;
            let span_m = select(end_m, m.depth_m, to_cloud);
            let d_km = select(select(-1.0, end_m * 1e-3, hit), m.depth_m * 1e-3, to_cloud);
            let pray = point_ray(o, vl, dir, d_km);
            var endp: Piece;
            if (pray.in_atmosphere) {
                endp = piece_at(v, pray, vl, pray.end_km, false);
            }
            clouded_air(v, vl, pray, &list, span_m, endp, &acc);
            if (to_cloud) {
                for (var k = 0u; k < atm.groups; k++) {
                    front += to_srgb(acc[k] * light_scale(light, k), k);
                    if (light == 0u) {
                        seen += to_srgb(point_transmittance(pray, endp, k) * l_vol[k], k);
                    }
                }
                continue;
            }
            if (hit) {
                let g = point_light(vl, 0.0, up, up);
                for (var k = 0u; k < atm.groups; k++) {
                    let scale = light_scale(light, k);
                    let e = point_irradiance(g, k);
                    var s: SurfaceLight;
                    s.direct = e.direct * light_irradiance(light, k);
                    s.sky = e.sky * scale;
                    let t_air = sample_transmittance(g.to_light, k) * g.fraction;
                    s = dim_surface_light(light, x, up, vl.direction, k, t_air, s);
                    let t = point_transmittance(pray, endp, k);
                    let l = acc[k] * scale + ground_albedo(k) / PI * (s.direct + s.sky) * t;
                    rgb += to_srgb(l, k);
                }
                continue;
            }
            let disk = light_disk(light, dir);
            let background = light == 0u && lights.background.x > 0.0;
            var background_f = 0.0;
            if (background) {
                background_f = background_factor(o.r_km, dir.z);
            }
            var t_top: Filter2;
            if (pray.in_atmosphere) {
                t_top = transmittance_filter(pray.s.r_km, pray.s.rho_km, pray.s.mu);
            }
            for (var k = 0u; k < atm.groups; k++) {
                var l = acc[k] * light_scale(light, k);
                var t = vec4<f32>(1.0);
                if (pray.in_atmosphere) {
                    t = select(sample_transmittance(t_top, k), vec4<f32>(0.0), pray.ground);
                }
                if (disk.inside) {
                    l += light_disk_radiance(light, disk, dir, k) * t;
                }
                if (background) {
                    l += lights.background_radiance[k] * background_f * t;
                }
                rgb += to_srgb(l, k);
            }
        }
    }
    if (m.depth_m < 0.0) {
        return rgb;
    }
    return front + seen + m.t_vol * (rgb - front);
}

// The frame under clouds: an entry point of its own, so that frames without them carry none
// of its code.
@compute @workgroup_size(64)
fn main_clouds(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = pixel(gid, nwg);
    if (!p.in_band) {
        return;
    }
    var out = vec4<f32>(0.0);
    if (p.ray.valid) {
        var rgb = vec3<f32>(0.0);
        // One ray, or DISK_SUBSAMPLES² over the footprint of a pixel on a disk's edge.
        let n = pixel_rays(p);
        for (var k = 0u; k < n; k++) {
            let r = pixel_ray(p, k, n);
            if (r.valid) {
                rgb += shade_clouds(r.dir);
            }
        }
        rgb /= f32(n);
        out = vec4<f32>(rgb * frame.balance.xyz, 1.0);
    }
    write_pixel(p.i, p.x, p.y, out);
}
