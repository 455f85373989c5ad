// A frame's pixel under clouds (firmament::render::Shader::shade with the scene's volumes):
// the ground (the planet's sphere, or with WITH_TERRAIN the terrain and the sphere under it,
// render/scene.wgsl) lit by each light under the clouds (their shadow map, their diffuse
// light and the ground–cloud interreflection: render/volumes.wgsl), the sky and the lights'
// disks, the air's light (its single scattering over the stretches of the ray outside the
// clouds' and the terrain's shadows, its multiple over the whole ray, dimmed below the
// clouds), and the clouds in front composited at their mean depth, their own aerial
// perspective under the same shadows.

// Whether the frame has a terrain: `main_clouds` is compiled twice, with and without, so
// that frames under clouds over the planet's sphere carry none of the terrain's code.
override WITH_TERRAIN: bool = false;

// The most lit intervals of the terrain's shadow a ray's air is summed over (beyond, the
// rest of the ray is taken as shadowed; the terrain's own frame walks them all).
const MAX_TERRAIN_LIT: u32 = 256u;

// The terrain's lit intervals along a view ray for one light (WITH_TERRAIN): none cast
// (mode 0: all lit), the shadow at the end only (1: one interval), or the walk through
// the light's shadow field (2: light shafts); `lit` is the current interval (z 0: no more).
struct TerrainLit {
    mode: u32,
    lit: vec3<f32>,
    lit_at_end: bool,
}

// The next lit interval of the terrain's walk after the current one.
fn terrain_lit_next(tl: ptr<function, TerrainLit>, lw: ptr<function, LitWalk>, walk: ptr<function, Walk>, end_m: f32) {
    if ((*tl).mode == 2u) {
        (*tl).lit = lit_next(lw, walk);
        if ((*tl).lit.z != 0.0 && (*tl).lit.y >= end_m) {
            (*tl).lit_at_end = true;
        }
    } else {
        (*tl).lit.z = 0.0;
    }
}

// The air's light along `pray` (from local `q` along `dir`) up to end_m for light l
// (Shadow::Lit, as the CPU's renderer gives it under clouds), per channel group into acc
// (before the light's scale), and the air's transmittance to the end into t_end: the
// multiple scattering over the whole ray, the single over the stretches outside the
// shadowed ones of `list` (scene::lit_intervals), and below the clouds' base only w of the
// multiple (render/shadowed_air.wgsl, over the CPU's ShadowedAir::weigh stretches: the
// shadow's boundaries cut the air below the base). One walk over the boundaries looks up
// the sky method's piece at each from one call site, and carries what the next stretch
// needs of it per channel group in arrays, not the piece itself: the driver inlines every
// call whole, and a large value carried around a loop slows LLVM's compile about twofold.
// `pray` ends at end_m (or is open towards the sky). With WITH_TERRAIN the terrain's
// shadow cuts the single scattering too (its lit intervals are boundaries of the walk, as
// in render/scene.wgsl's `shafts`; Shader::shadow's union of the two); returns whether
// the light reaches end_m past the terrain.
fn clouded_air(v: View, vl: ViewLight, l: u32, pray: PointRay, q: vec3<f32>, dir: vec3<f32>, list: ptr<function, ShadowList>, end_m: f32, t_end: ptr<function, array<vec4<f32>, MAX_CHANNEL_GROUPS>>, acc: ptr<function, array<vec4<f32>, MAX_CHANNEL_GROUPS>>) -> bool {
    for (var k = 0u; k < atm.groups; k++) {
        (*acc)[k] = vec4<f32>(0.0);
        (*t_end)[k] = vec4<f32>(1.0);
    }
    // The terrain's lit intervals (all of the ray without a terrain).
    var tl: TerrainLit;
    tl.mode = 0u;
    tl.lit = vec3<f32>(0.0, 3.4e38, 1.0);
    tl.lit_at_end = true;
    var lw: LitWalk;
    var walk: Walk;
    if (WITH_TERRAIN && (terrain.flags & TERRAIN_CASTS_SHADOWS) != 0u) {
        var ray: GridRay;
        ray.origin = vec3<f32>(0.0, 0.0, terrain.observer_height_m);
        ray.dir = dir;
        if ((terrain.flags & TERRAIN_SHAFTS) != 0u && terrain.shadow[l].x != NONE) {
            tl.mode = 2u;
            tl.lit_at_end = false;
            lw = lit_start(ray, l, vl.direction, end_m);
            walk = lit_walk(ray, l, end_m);
            terrain_lit_next(&tl, &lw, &walk, end_m);
        } else {
            tl.mode = 1u;
            tl.lit = vec3<f32>(0.0, end_m, 1.0);
            if (end_in_shadow(ray, vl.direction, end_m) == 1) {
                tl.lit.y = end_m - merge_tolerance(end_m);
                tl.lit_at_end = false;
            }
        }
    }
    if (!pray.in_atmosphere) {
        return tl.lit_at_end;
    }
    let offset_km = pray.s.offset_km;
    let n = (*list).n;
    let below = air_below(l, q, dir, end_m);
    // At the previous boundary, per channel group: single Rayleigh and Mie and the multiple
    // scattering, each times T(0, x); the multiple at the start.
    var prev_rayleigh: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    var prev_mie: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    var prev_multiple: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    var start_multiple: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    var i = 0u;
    var t = 0.0;
    var t_prev = 0.0;
    // At most the start, two boundaries per shadowed stretch, the two of the stretch below
    // the base, two per lit interval of the terrain and the end.
    let steps = 2u * MAX_SHADOWED + 8u + select(0u, 2u * MAX_TERRAIN_LIT, WITH_TERRAIN);
    for (var step = 0u; step < steps; step++) {
        let x_km = clamp(t * 1e-3 - offset_km, 0.0, pray.end_km);
        let p = piece_at(v, pray, vl, x_km, true);
        // The stretch [t_prev, t]: in the list's stretch i or before it, or before the
        // terrain's lit interval (or past the last).
        let shadowed = (i < n && t_prev >= (*list).s[i].x) || tl.lit.z == 0.0 || t_prev < tl.lit.x;
        let dimmed = below.x < below.y && t_prev >= below.x && t <= below.y;
        let b_subtracts = x_km < pray.end_km || !pray.open_end;
        let x = q + (0.5 * (t_prev + t)) * dir;
        let at_end = t >= end_m;
        for (var k = 0u; k < atm.groups; k++) {
            let c = piece_single(v, p, k);
            let m = piece_multiple(p, k);
            if (step == 0u) {
                start_multiple[k] = m;
            } else {
                if (!shadowed) {
                    // Bruneton4dView::lit_radiance's single scattering over the stretch.
                    var r = prev_rayleigh[k];
                    var mie = prev_mie[k];
                    if (b_subtracts) {
                        r = max(r - c.scattering, vec4<f32>(0.0));
                        mie = max(mie - c.mie, vec4<f32>(0.0));
                    }
                    (*acc)[k] += r * pray.pr + mie * pray.fade * pray.pm;
                }
                if (dimmed) {
                    let kept = air_weight(l, x, k);
                    (*acc)[k] -= (1.0 - kept) * max(prev_multiple[k] - m, vec4<f32>(0.0));
                }
            }
            prev_rayleigh[k] = c.scattering;
            prev_mie[k] = c.mie;
            prev_multiple[k] = m;
            if (at_end) {
                (*t_end)[k] = piece_transmittance(p, k);
            }
        }
        if (step > 0u && i < n && t >= (*list).s[i].y) {
            i++;
        }
        // Past the terrain's lit interval: the next (empty ones skipped).
        for (var skip = 0u; skip < 4u && tl.lit.z != 0.0 && t >= tl.lit.y; skip++) {
            terrain_lit_next(&tl, &lw, &walk, end_m);
        }
        if (at_end) {
            break;
        }
        // The next boundary: the list's, the stretch below the base's, or the end.
        var next = end_m;
        if (i < n) {
            next = min(next, select((*list).s[i].y, (*list).s[i].x, t < (*list).s[i].x));
        }
        if (below.x < below.y) {
            if (t < below.x) {
                next = min(next, below.x);
            } else if (t < below.y) {
                next = min(next, below.y);
            }
        }
        if (tl.lit.z != 0.0) {
            next = min(next, select(tl.lit.y, tl.lit.x, t < tl.lit.x));
        }
        t_prev = t;
        t = max(next, t);
    }
    // The multiple scattering over the whole ray (Bruneton4dView::shafted_radiance).
    for (var k = 0u; k < atm.groups; k++) {
        var whole = start_multiple[k];
        if (!pray.open_end) {
            whole = max(whole - prev_multiple[k], vec4<f32>(0.0));
        }
        (*acc)[k] = max((*acc)[k] + whole, vec4<f32>(0.0));
    }
    return tl.lit_at_end;
}

// Shader::shade under the clouds, summed to linear sRGB over the lights and channel groups,
// and the ray's depth (m) for the temporal resolve (render/temporal.wgsl): the clouds' mean
// depth where they hide more than half of what is behind them, else the ground's (or
// SKY_DEPTH_M).
// The clouds are marched first; then per light the air's light is summed over the whole ray
// and, where the ray meets a cloud, again to the cloud's mean depth (its aerial perspective),
// both from one call of clouded_air in a loop: every call site of a function is inlined
// whole by the driver, and lavapipe's compile grows faster than the code.
fn shade_clouds(dir: vec3<f32>) -> vec4<f32> {
    let o = observer();
    var v: View;
    v.mie_layout = frame.mie_layout;
    let q = vec3<f32>(0.0, 0.0, clouds.observer_alt_m);
    // The ground: the planet's sphere, or the terrain and the sphere under it (the two
    // frames share the observer's foot and the sphere: GpuClouds::uniform_words).
    var surface: SceneHit;
    if (WITH_TERRAIN) {
        var ray: GridRay;
        ray.origin = vec3<f32>(0.0, 0.0, terrain.observer_height_m);
        ray.dir = dir;
        surface = scene_hit(ray);
    } else {
        let ground = shell_sphere(q, dir, 0.0);
        surface.hit = ground.x <= ground.y && ground.x > 0.0;
        surface.terrain = false;
        surface.t_m = select(3.4e38, ground.x, surface.hit);
        surface.q = q + surface.t_m * dir;
        surface.up = cloud_point(surface.q).up;
        surface.normal = surface.up;
    }
    let hit = surface.hit;
    let end_m = surface.t_m;
    let x = q + end_m * dir;
    let up = surface.up;
    // The terrain's materials and the sky's light under its horizons at the hit (as
    // render/scene.wgsl's shade_scene), its height above the tables' ground.
    var weights: MaterialWeights;
    var visible_sky = 1.0;
    var horizons: Horizons;
    var domes = false;
    var altitude_km = 0.0;
    if (WITH_TERRAIN && hit) {
        var ray: GridRay;
        ray.origin = vec3<f32>(0.0, 0.0, terrain.observer_height_m);
        ray.dir = dir;
        let height_m = ray_height(ray, end_m);
        altitude_km = (height_m - terrain.zones.z) * 1e-3;
        if (surface.terrain) {
            let slope = degrees(acos(clamp(dot(surface.normal, up), -1.0, 1.0)));
            weights = material_weights(surface.q.xy, height_m, slope);
            horizons = horizons_at(surface.q);
            domes = horizons.valid && terrain.per_light[0].y != NONE;
            if (!domes) {
                visible_sky = sky_visibility(surface.q);
            }
        }
    }
    // The planet's surface map at the ground point (the sphere's, beyond a terrain).
    let on_map = hit && !surface.terrain && planet_on();
    var map: PlanetWeights;
    if (on_map) {
        map = planet_weights(ground_point(o.r_km, dir));
    }
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
            var t_end: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
            let lit_at_end = clouded_air(v, vl, light, pray, q, dir, &list, span_m, &t_end, &acc);
            if (to_cloud) {
                for (var k = 0u; k < atm.groups; k++) {
                    front += to_srgb(acc[k] * light_scale(light, k), k);
                    if (light == 0u) {
                        seen += to_srgb(t_end[k] * l_vol[k], k);
                    }
                }
                continue;
            }
            if (hit) {
                let g = point_light(vl, altitude_km, up, surface.normal);
                var glint = 0.0;
                if (on_map) {
                    glint = planet_specular(map, up, -dir, vl.direction);
                }
                for (var k = 0u; k < atm.groups; k++) {
                    let scale = light_scale(light, k);
                    let e = point_irradiance(g, k);
                    var s: SurfaceLight;
                    s.direct = select(vec4<f32>(0.0), e.direct * light_irradiance(light, k), lit_at_end);
                    s.sky = e.sky * scale;
                    let t_air = sample_transmittance(g.to_light, k) * g.fraction;
                    let clear = s.sky;
                    s = dim_surface_light(light, x, up, surface.normal, vl.direction, k, t_air, s);
                    s.sky = ground_sky(light, x, k, clear, s.sky);
                    if (domes) {
                        // The sky's light under the horizon, weighted by its radiance, in
                        // place of the open plane's (1 + n·up)/2 (after the clouds' dimming,
                        // as the CPU's Shader::shade).
                        var f = vec4<f32>(0.0);
                        if (g.occlusion > 0.0) {
                            f = dome_share(light, up, surface.normal, horizons, k) / g.occlusion;
                        }
                        s.sky *= f;
                    }
                    let t = t_end[k];
                    var albedo = ground_albedo(k);
                    if (surface.terrain) {
                        albedo = terrain_albedo(weights, k);
                    } else if (on_map) {
                        albedo = planet_albedo(map, k);
                    }
                    let l = acc[k] * scale + (albedo / PI * (s.direct + visible_sky * s.sky) + glint * s.direct) * t;
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
    // The terrain's change of the air's light, once (it holds every light), behind the
    // clouds in front.
    if (WITH_TERRAIN) {
        for (var k = 0u; k < atm.groups; k++) {
            rgb += to_srgb(air_volume_add(dir, end_m, k), k);
        }
    }
    let behind_m = max(select(SKY_DEPTH_M, end_m, hit), 1e-3);
    if (m.depth_m < 0.0) {
        return vec4<f32>(rgb, behind_m);
    }
    let depth_m = select(behind_m, max(m.depth_m, 1e-3), m.t_vol < 0.5);
    return vec4<f32>(front + seen + m.t_vol * (rgb - front), depth_m);
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
        var depth_m = SKY_DEPTH_M;
        // One ray, or DISK_SUBSAMPLES² over the footprint of a pixel on a disk's edge.
        let n = pixel_rays(p);
        for (var k = 0u; k < n; k++) {
            let r = pixel_ray(p, k, n);
            if (r.valid) {
                let shaded = shade_clouds(r.dir);
                rgb += shaded.xyz;
                depth_m = shaded.w;
            }
        }
        rgb /= f32(n);
        out = vec4<f32>(rgb * frame.balance.xyz, select(1.0, depth_m, depth_in_alpha()));
    }
    write_pixel(p.i, p.x, p.y, out);
}
