// A frame's pixel over the terrain (firmament::render::Shader::shade with the scene's
// surfaces): the nearest of the terrain (terrain/heightfield.wgsl) and the planet's sphere
// under it, lit by each light past the terrain's shadows (an exact shadow ray at the hit) and
// by the sky (with the terrain's ambient occlusion), seen through aerial perspective with the
// light shafts (the single scattering over the lit intervals of terrain/shadow.wgsl, the
// multiple over the whole ray), the lights' disks and the background where the ray meets no
// surface, and the terrain's change of the air's light (render/air_volume.wgsl).

// scene::TIE_M: an earlier surface (the terrain) wins a tie with the sphere within it (m).
const TIE_M: f32 = 0.01;

struct SceneHit {
    hit: bool,
    terrain: bool,
    t_m: f32,
    q: vec3<f32>,
    normal: vec3<f32>,
    up: vec3<f32>,
}

// Sphere::intersect for the planet's sphere under the terrain (radius terrain.radius_m), from
// local coordinates: t² + 2bt + c = 0 with c = |o|² − R² without cancellation.
fn sphere_distance(ray: GridRay) -> f32 {
    let r = terrain.radius_m;
    let q = ray.origin;
    let b = -ray_closest(ray);
    let c = q.x * q.x + q.y * q.y + q.z * (2.0 * r + q.z);
    let disc = b * b - c;
    if (disc < 0.0) {
        return 3.4e38;
    }
    let root = sqrt(disc);
    if (c > 0.0) {
        if (b >= 0.0) {
            return 3.4e38;
        }
        return c / (-b + root);
    }
    return -b + root;
}

// Scene::nearest_hit: the terrain, then the sphere.
fn scene_hit(ray: GridRay) -> SceneHit {
    var h: SceneHit;
    let t_sphere = sphere_distance(ray);
    let t_terrain = intersect(ray, min(t_sphere + TIE_M, 3.4e38));
    h.hit = t_terrain >= 0.0 || t_sphere < 3.0e38;
    if (!h.hit) {
        h.t_m = 3.4e38;
        return h;
    }
    h.terrain = t_terrain >= 0.0;
    h.t_m = select(t_sphere, t_terrain, h.terrain);
    h.q = ray.origin + h.t_m * ray.dir;
    h.up = up_at(h.q);
    if (h.terrain) {
        h.normal = normal_at(h.q);
        if (dot(h.normal, ray.dir) > 0.0) {
            h.normal = -h.normal;
        }
    } else {
        h.normal = h.up;
    }
    return h;
}

// Σ over the lit intervals and the light's channel groups: the radiance scattered towards the
// observer (before the light's scale) into acc, per group; whether the light reaches the end.
// `start` and `endp` are the pieces at the ray's ends.
fn shafts(v: View, l: u32, vl: ViewLight, ray: GridRay, pray: PointRay, start: Piece, endp: Piece, end_m: f32, acc: ptr<function, array<vec4<f32>, MAX_CHANNEL_GROUPS>>) -> bool {
    for (var k = 0u; k < atm.groups; k++) {
        (*acc)[k] = whole_multiple(pray, start, endp, k);
    }
    let offset_km = pray.s.offset_km;
    var lit_at_end = true;
    // The lit intervals: all of the ray without shadows, the ray but a sliver at a shadowed
    // end without shafts, the walk through the light's shadow field with them.
    var lw: LitWalk;
    var walk: Walk;
    var mode = 0u;
    if ((terrain.flags & TERRAIN_CASTS_SHADOWS) != 0u) {
        if ((terrain.flags & TERRAIN_SHAFTS) != 0u && terrain.shadow[l].x != NONE) {
            mode = 2u;
            lw = lit_start(ray, l, vl.direction, end_m);
            walk = lit_walk(ray, l, end_m);
            lit_at_end = false;
        } else {
            mode = 1u;
        }
    }
    var once = vec3<f32>(0.0, end_m, 1.0);
    if (mode == 1u && end_in_shadow(ray, vl.direction, end_m) == 1) {
        once.y = end_m - merge_tolerance(end_m);
        lit_at_end = false;
    }
    loop {
        var li: vec3<f32>;
        if (mode == 2u) {
            li = lit_next(&lw, &walk);
        } else {
            li = once;
            once.z = 0.0;
        }
        if (li.z == 0.0) {
            break;
        }
        if (mode == 2u && li.y >= end_m) {
            lit_at_end = true;
        }
        let a_km = max(li.x * 1e-3 - offset_km, 0.0);
        let b_km = min(li.y * 1e-3 - offset_km, pray.end_km);
        if (b_km <= a_km) {
            continue;
        }
        let at_end = b_km >= pray.end_km;
        var pa = start;
        if (a_km > 0.0) {
            pa = piece_at(v, pray, vl, a_km, true);
        }
        var pb = endp;
        if (!at_end) {
            pb = piece_at(v, pray, vl, b_km, true);
        }
        let b_subtracts = !at_end || !pray.open_end;
        for (var k = 0u; k < atm.groups; k++) {
            (*acc)[k] += lit_single(v, pray, pa, pb, b_subtracts, k);
        }
    }
    return lit_at_end;
}

// Shader::shade over the terrain, summed to linear sRGB over the lights and channel groups,
// and the ray's depth (m; SKY_DEPTH_M towards the sky) for the temporal resolve.
fn shade_scene(dir: vec3<f32>) -> vec4<f32> {
    let o = observer();
    var v: View;
    v.mie_layout = frame.mie_layout;
    var ray: GridRay;
    ray.origin = vec3<f32>(0.0, 0.0, terrain.observer_height_m);
    ray.dir = dir;
    let hit = scene_hit(ray);
    var rgb = vec3<f32>(0.0);
    var weights: MaterialWeights;
    var visible_sky = 1.0;
    var altitude_km = 0.0;
    // The terrain's horizons at the hit, for the sky's light weighted by its radiance
    // (render/sky_dome.wgsl) in place of the uniform sky's visibility.
    var horizons: Horizons;
    var domes = false;
    if (hit.hit) {
        let height_m = ray_height(ray, hit.t_m);
        altitude_km = (height_m - terrain.zones.z) * 1e-3;
        if (hit.terrain) {
            let slope = degrees(acos(clamp(dot(hit.normal, hit.up), -1.0, 1.0)));
            weights = material_weights(hit.q.xy, height_m, slope);
            horizons = horizons_at(hit.q);
            domes = horizons.valid && terrain.per_light[0].y != NONE;
            if (!domes) {
                visible_sky = sky_visibility(hit.q);
            }
        }
    }
    // The planet's surface map where the ray meets the sphere beyond the terrain.
    let on_map = hit.hit && !hit.terrain && planet_on();
    var map: PlanetWeights;
    if (on_map) {
        map = planet_weights(ground_point(o.r_km, dir));
    }
    var acc: array<vec4<f32>, MAX_CHANNEL_GROUPS>;
    for (var light = 0u; light < frame.lights; light++) {
        let vl = view_light(light);
        let d_km = select(-1.0, hit.t_m * 1e-3, hit.hit);
        let pray = point_ray(o, vl, dir, d_km);
        var lit_at_end = true;
        var endp: Piece;
        if (pray.in_atmosphere) {
            let start = piece_at(v, pray, vl, 0.0, true);
            endp = piece_at(v, pray, vl, pray.end_km, true);
            lit_at_end = shafts(v, light, vl, ray, pray, start, endp, hit.t_m, &acc);
        } else {
            for (var k = 0u; k < atm.groups; k++) {
                acc[k] = vec4<f32>(0.0);
            }
        }
        if (hit.hit) {
            let g = point_light(vl, altitude_km, hit.up, hit.normal);
            var glint = 0.0;
            if (on_map) {
                glint = planet_specular(map, hit.up, -dir, vl.direction);
            }
            for (var k = 0u; k < atm.groups; k++) {
                let scale = light_scale(light, k);
                var albedo = ground_albedo(k);
                if (hit.terrain) {
                    albedo = terrain_albedo(weights, k);
                } else if (on_map) {
                    albedo = planet_albedo(map, k);
                }
                var e = point_irradiance(g, k);
                if (domes) {
                    // The sky's light under the horizon, weighted by its radiance, in place of
                    // the open plane's (1 + n·up)/2.
                    var f = vec4<f32>(0.0);
                    if (g.occlusion > 0.0) {
                        f = dome_share(light, hit.up, hit.normal, horizons, k) / g.occlusion;
                    }
                    e.sky *= f;
                }
                let direct = select(vec4<f32>(0.0), e.direct * light_irradiance(light, k), lit_at_end);
                let t = point_transmittance(pray, endp, k);
                let l = acc[k] * scale
                    + (albedo / PI * (direct + visible_sky * e.sky * scale) + glint * direct) * t;
                rgb += to_srgb(l, k);
            }
            continue;
        }
        // The sky, and the light's disk through the air.
        let disk = light_disk(light, dir);
        let background = light == 0u && lights.background.x > 0.0;
        var background_f = 0.0;
        if (background) {
            background_f = background_factor(o.r_km, dir.z);
        }
        let t_top = transmittance_filter(pray.s.r_km, pray.s.rho_km, pray.s.mu);
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
    // The terrain's change of the air's light, once (it holds every light).
    for (var k = 0u; k < atm.groups; k++) {
        rgb += to_srgb(air_volume_add(dir, hit.t_m, k), k);
    }
    return vec4<f32>(rgb, select(SKY_DEPTH_M, max(hit.t_m, 1e-3), hit.hit));
}
