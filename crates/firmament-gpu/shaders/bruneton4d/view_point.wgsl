// The view's questions towards any point and over lit intervals (firmament::sky::bruneton4d::
// view): SkyView::sky_radiance_to_point towards a surface hit anywhere along a ray (the
// terrain, the planet's sphere below the tables' ground), the light shafts of Shadow::Lit
// (`lit_radiance`, `shafted_radiance`: the single scattering over the lit intervals, the
// multiple over the whole ray) and SkyView::sun_and_sky_irradiance at a point with a normal.
// The render shader walks the lit intervals (terrain/shadow.wgsl) and sums their pieces per
// channel group; everything here is prepared once per ray or interval end and evaluated per
// channel group k.

// A ray from the observer to a point `end_km` away (a surface hit), or to the atmosphere's
// boundary (a sky ray, `open_end`: nothing is scattered beyond it).
struct PointRay {
    in_atmosphere: bool,
    s: ViewStart,
    nu: f32,
    ground: bool,
    pr: f32,
    pm: f32,
    // Single Mie faded with the light below the horizon on rays to a point (Bruneton 2017).
    fade: f32,
    // The ray's length from its start (the observer, or where it enters the atmosphere).
    end_km: f32,
    open_end: bool,
}

// The ray in direction `dir` to the point `d_km` from the observer (d_km < 0: to the sky).
fn point_ray(o: Observer, light: ViewLight, dir: vec3<f32>, d_km: f32) -> PointRay {
    var ray: PointRay;
    ray.nu = clamp_cosine(dot(dir, light.direction));
    ray.s = view_start(o, light, dir, ray.nu);
    ray.in_atmosphere = ray.s.in_atmosphere;
    if (!ray.in_atmosphere) {
        return ray;
    }
    ray.ground = start_hits_ground(ray.s);
    ray.pr = group_phase(0u, ray.nu);
    ray.pm = group_phase(1u, ray.nu);
    ray.open_end = d_km < 0.0;
    if (ray.open_end) {
        ray.fade = 1.0;
        // Bruneton4dView::boundary_distance.
        if (ray.ground) {
            ray.end_km = distance_to_ground(ray.s);
        } else {
            ray.end_km = distance_to_top(ray.s.r_km, ray.s.rho_km, ray.s.mu);
        }
    } else {
        ray.fade = smoothstep_safe(0.0, 0.01, ray.s.mu_s);
        ray.end_km = max(d_km - ray.s.offset_km, 0.0);
    }
    return ray;
}

// The lookups at distance x_km from the ray's start (Bruneton4dView::combined_scattering and
// Lookup::transmittance from the start), for the single scattering (the red-only Mie ratio
// then taken against single Rayleigh, as Orders::Single does) or for the multiple.
struct Piece {
    at: At,
    at_start: bool,
    t: TransmittanceFilters,
}

fn piece_at(v: View, ray: PointRay, light: ViewLight, x_km: f32, single: bool) -> Piece {
    var p: Piece;
    let p_r = max(ray.pr, 1e-30);
    p.at_start = x_km <= 0.0;
    if (p.at_start) {
        p.at = at_start(ray.s, light, ray.nu, ray.ground);
    } else {
        p.at = at_along(ray.s, ray.nu, x_km, ray.ground);
        p.t = transmittance_filters(ray.s.r_km, ray.s.rho_km, ray.s.mu, x_km, ray.ground);
    }
    if (single && v.mie_layout != 0u) {
        if (p.at.sliced) {
            p.at.red = sample_slice(p.at.slice, p.at.slice_filter, 2u * atm.groups).x;
            p.at.scat0 = sample_slice(p.at.slice, p.at.slice_filter, 0u).x;
        } else {
            p.at.red = sample_mie_red(v, p.at.table);
            p.at.scat0 = sample_scattering_a(p.at.table, 0u).x;
        }
    }
    return p;
}

// T(0, x) of a piece, channel group k.
fn piece_transmittance(p: Piece, k: u32) -> vec4<f32> {
    if (p.at_start) {
        return vec4<f32>(1.0);
    }
    return sample_transmittance_between(p.t, k);
}

// Orders::Single at a piece: single Rayleigh and single Mie, times T(0, x).
fn piece_single(v: View, p: Piece, k: u32) -> Combined {
    var c: Combined;
    let a = p.at;
    if (a.sliced) {
        c.scattering = sample_slice(a.slice, a.slice_filter, k);
    } else {
        c.scattering = sample_scattering_a(a.table, k);
    }
    c.mie = single_mie(v, a, c.scattering, k);
    var t = piece_transmittance(p, k);
    if (a.mu_s < atm.mu_s_min) {
        t *= at_fade(a, k);
    }
    c.scattering *= t;
    c.mie *= t;
    return c;
}

// Orders::Multiple at a piece: the multiple scattering (radiance) times T(0, x).
fn piece_multiple(p: Piece, k: u32) -> vec4<f32> {
    var m: vec4<f32>;
    if (p.at.sliced) {
        m = sample_slice(p.at.slice, p.at.slice_filter, atm.groups + k);
    } else {
        m = sample_multiple(p.at.table, k);
    }
    var t = piece_transmittance(p, k);
    if (p.at.mu_s < atm.mu_s_min) {
        t *= at_fade(p.at, k);
    }
    return m * t;
}

// Bruneton4dView::lit_radiance of one lit interval [a, b] for the single scattering, channel
// group k, from its two pieces (`b_subtracts`: false when b is the open end of a sky ray),
// before the light's scale.
fn lit_single(v: View, ray: PointRay, a: Piece, b: Piece, b_subtracts: bool, k: u32) -> vec4<f32> {
    var ca = piece_single(v, a, k);
    if (b_subtracts) {
        let cb = piece_single(v, b, k);
        ca.scattering = max(ca.scattering - cb.scattering, vec4<f32>(0.0));
        ca.mie = max(ca.mie - cb.mie, vec4<f32>(0.0));
    }
    return ca.scattering * ray.pr + ca.mie * ray.fade * ray.pm;
}

// The multiple scattering over the whole ray (Bruneton4dView::shafted_radiance's first part),
// channel group k, before the light's scale.
fn whole_multiple(ray: PointRay, start: Piece, end: Piece, k: u32) -> vec4<f32> {
    var m = piece_multiple(start, k);
    if (!ray.open_end) {
        m = max(m - piece_multiple(end, k), vec4<f32>(0.0));
    }
    return m;
}

// The transmittance along the ray to its end (the point), channel group k.
fn point_transmittance(ray: PointRay, end: Piece, k: u32) -> vec4<f32> {
    if (!ray.in_atmosphere) {
        return vec4<f32>(1.0);
    }
    return piece_transmittance(end, k);
}

// ---------------------------------------------------------------------------------------
// SkyView::sun_and_sky_irradiance at a point `altitude_km` above the tables' ground with unit
// `normal`, `up` the local vertical there (both in the observer's frame).

struct PointLight {
    // The sky's irradiance at the point: altitude and μ_s (twilight_sky_irradiance).
    altitude_km: f32,
    mu_s: f32,
    to_light: Filter2,
    fraction: f32,
    // max(n·l, 0) and the sky's (1 + n·up)/2.
    cos_light: f32,
    occlusion: f32,
}

fn point_light(light: ViewLight, altitude_km: f32, up: vec3<f32>, normal: vec3<f32>) -> PointLight {
    var g: PointLight;
    let alt = max(altitude_km, 0.0);
    let r_km = atm.bottom_radius_km + alt;
    let rho_km = sqrt(alt * (2.0 * atm.bottom_radius_km + alt));
    let mu_s = clamp_cosine(dot(up, light.direction));
    g.altitude_km = alt;
    g.mu_s = mu_s;
    // Lookup::sun_visible_fraction: sin θ_h = R_g/r, cos θ_h = −ρ/r.
    let e = atm.bottom_radius_km / r_km * light.angular_radius;
    g.fraction = smoothstep_safe(-e, e, mu_s + rho_km / r_km);
    g.to_light = transmittance_filter(r_km, rho_km, mu_s);
    g.cos_light = max(dot(normal, light.direction), 0.0);
    g.occlusion = (1.0 + dot(normal, up)) * 0.5;
    return g;
}

// The light's direct irradiance (per unit of its irradiance at the top: callers multiply by
// it) and the sky's (before the light's scale), channel group k.
fn point_irradiance(g: PointLight, k: u32) -> Irradiance {
    var e: Irradiance;
    e.sky = twilight_sky_irradiance(g.altitude_km, g.mu_s, k) * g.occlusion;
    if (g.fraction > 0.0) {
        e.direct = sample_transmittance(g.to_light, k) * g.fraction * g.cos_light;
    }
    return e;
}
