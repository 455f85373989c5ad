// Hillaire 2020 seen from one observer under one light (firmament::sky::hillaire2020::view):
// the sky method's module that render/render.wgsl composes after it, with the functions and
// structs bruneton4d/view.wgsl gives it (`sky_ray`/`sky_radiance`/`sky_transmittance`,
// `ground_ray`/`sky_radiance_to_point`/`transmittance_to_point`,
// `ground_light`/`transmittance_to_light`/`sun_and_sky_irradiance`), each split in a
// preparation per ray and an evaluation per channel group k. A sky ray from an observer in
// the atmosphere reads the sky-view table (sky_view.wgsl); views from space, rays with a
// shadowed length and the aerial perspective to the ground march per pixel (march.wgsl), as
// the CPU view does. Results are per the model's solar irradiance (the renderer multiplies
// by each light's scale against it).
//
// Bindings besides the common ones: 3 the optical depth (bruneton4d/lookup.wgsl), 8 and 9
// the sizes and data (config.wgsl), 11 the per-channel constants, 13 and 15 the sky-view
// tables and their coordinates (sky_view.wgsl), 20 Ψ_ms (march.wgsl), 21 the sky irradiance.

// Per channel group k, at k·CHANNEL_STRIDE: the linear sRGB rows of the colour matrix
// (spectrum::ColourMatrix::to_srgb, 3 vec4) and a row the 4D tables use (zero here).
@group(0) @binding(11) var<uniform> view_constants: array<vec4<f32>, CHANNEL_DATA_VEC4>;
// The sky's irradiance on a horizontal surface per unit light irradiance (Hillaire2020::
// irradiance): (μ_s, altitude) texel i, channel group k at i·groups + k.
@group(0) @binding(21) var<storage, read> sky_irradiance_table: array<vec4<f32>>;

// The observer (SkyMethod::view's `observer`), on the +z axis.
struct Observer {
    // Whether it is inside the atmosphere (r ≤ R_t): then the sky-view tables apply.
    inside: bool,
    r_km: f32,
    // ρ = sqrt(r² − R_g²) inside the atmosphere.
    rho_km: f32,
    // r − R_t, for an observer in space.
    above_top_km: f32,
}

// A light as the view needs it (scene::Light): its direction, its angular radius and the
// sine of it, and its sky-view table (`slice`, as the 4D tables' slice).
struct ViewLight {
    direction: vec3<f32>,
    angular_radius: f32,
    sin_angular_radius: f32,
    slice: u32,
}

// The 4D tables' per-frame options (render.wgsl sets `mie_layout`); none here.
struct View {
    mie_layout: u32,
}

// ---------------------------------------------------------------------------------------
// Where a view ray starts in the atmosphere (sky::entry::enter_atmosphere; the 4D view's
// `view_start`): the observer itself, or for an observer in space the point where the ray
// enters the top, through the impact parameter p (discriminants (R − p)(R + p)).

struct ViewStart {
    in_atmosphere: bool,
    r_km: f32,
    rho_km: f32,
    mu: f32,
    mu_s: f32,
    // r²μ² − ρ², the discriminant of the ground sphere along the ray.
    disc_ground_km2: f32,
    at_observer: bool,
    // Distance from the observer to the start.
    offset_km: f32,
}

// The start of the ray from the observer `o` along `dir` (ν = dir·light).
fn view_start(o: Observer, light: ViewLight, dir: vec3<f32>, nu: f32) -> ViewStart {
    var s: ViewStart;
    if (o.inside) {
        s.in_atmosphere = true;
        s.r_km = o.r_km;
        s.rho_km = o.rho_km;
        s.mu = clamp_cosine(dir.z);
        s.mu_s = clamp_cosine(light.direction.z);
        s.disc_ground_km2 = s.r_km * s.r_km * s.mu * s.mu - s.rho_km * s.rho_km;
        s.at_observer = true;
        s.offset_km = 0.0;
        return s;
    }
    let rc_km = o.r_km;
    let rmu_km = rc_km * dir.z;
    let p_km = rc_km * length(dir.xy);
    let disc = (atm.top_radius_km - p_km) * (atm.top_radius_km + p_km);
    if (disc < 0.0 || rmu_km >= 0.0) {
        s.in_atmosphere = false;
        return s;
    }
    let root = sqrt(disc);
    let d_km = o.above_top_km * (rc_km + atm.top_radius_km) / (-rmu_km + root);
    s.in_atmosphere = true;
    s.r_km = atm.top_radius_km;
    s.rho_km = atm.h_km;
    s.mu = clamp_cosine(-root / atm.top_radius_km);
    s.mu_s = clamp_cosine((rc_km * light.direction.z + d_km * nu) / atm.top_radius_km);
    s.disc_ground_km2 = (atm.bottom_radius_km - p_km) * (atm.bottom_radius_km + p_km);
    s.at_observer = false;
    s.offset_km = d_km;
    return s;
}

// geometry::ray_intersects_ground with the start's discriminant.
fn start_hits_ground(s: ViewStart) -> bool {
    return s.mu < 0.0 && s.disc_ground_km2 >= 0.0;
}

// Distance from the start to the ground (distance_to_bottom with the discriminant given).
fn distance_to_ground(s: ViewStart) -> f32 {
    let root = safe_sqrt(s.disc_ground_km2);
    let far = -s.r_km * s.mu + root;
    if (far > 0.0) {
        return max(s.rho_km * s.rho_km / far, 0.0);
    }
    return max(-s.r_km * s.mu - root, 0.0);
}

// The march of a view ray from its start over `length_km` (Hillaire2020View::march's
// MarchRay), lit by `light`.
fn view_march_ray(s: ViewStart, light: ViewLight, nu: f32, length_km: f32) -> MarchRay {
    return MarchRay(s.r_km, s.rho_km, s.mu, s.mu_s, nu, length_km, light.angular_radius);
}

// The groups' phase functions at ν.
fn view_phases(nu: f32) -> vec2<f32> {
    return vec2<f32>(group_phase(0u, nu), group_phase(1u, nu));
}

// ---------------------------------------------------------------------------------------
// SkyView::sky_radiance: radiance scattered towards the observer along a ray to the
// atmosphere boundary or the ground; with a shadowed length, nothing scattered over the
// ray's first km (Shadow::Length).

struct SkyRay {
    in_atmosphere: bool,
    ground: bool,
    s: ViewStart,
    // Whether the light's sky-view table answers (observer inside, no shadow), its index, and
    // the ray's azimuth cosine from the light in the observer's horizontal plane.
    table: bool,
    slice: u32,
    cos_phi: f32,
    // The march otherwise.
    march: MarchRay,
    phases: vec2<f32>,
    lighting: Lighting,
}

// The preparation of a sky ray along `dir` (Hillaire2020View::sky_radiance up to the
// evaluation), with a shadowed length over its first `shadow_length_km` when > 0.
fn sky_ray(v: View, o: Observer, light: ViewLight, dir: vec3<f32>, shadow_length_km: f32) -> SkyRay {
    var ray: SkyRay;
    let nu = clamp_cosine(dot(dir, light.direction));
    ray.s = view_start(o, light, dir, nu);
    ray.in_atmosphere = ray.s.in_atmosphere;
    if (!ray.in_atmosphere) {
        return ray;
    }
    ray.ground = start_hits_ground(ray.s);
    ray.table = ray.s.at_observer && shadow_length_km <= 0.0;
    ray.slice = light.slice;
    if (ray.table) {
        // The observer's up is +z: the horizontal parts are the xy components.
        let d = dir.xy;
        let l = light.direction.xy;
        let norm = sqrt(dot(d, d) * dot(l, l));
        ray.cos_phi = select(1.0, dot(d, l) / norm, norm > 1e-24);
        return ray;
    }
    var length_km = distance_to_top(ray.s.r_km, ray.s.rho_km, ray.s.mu);
    if (ray.ground) {
        length_km = distance_to_ground(ray.s);
    }
    ray.march = view_march_ray(ray.s, light, nu, length_km);
    ray.phases = view_phases(nu);
    ray.lighting = lighting_all();
    if (shadow_length_km > 0.0) {
        let lit = Lit(shadow_length_km - ray.s.offset_km, 3.4e38);
        ray.lighting = Lighting(lit, lit);
    }
    return ray;
}

// Channel group k of the ray's sky radiance (before the light's scale).
fn sky_radiance(v: View, ray: SkyRay, k: u32) -> vec4<f32> {
    if (!ray.in_atmosphere) {
        return vec4<f32>(0.0);
    }
    if (ray.table) {
        return sky_view_sample(ray.slice, ray.s.r_km, ray.s.rho_km, ray.s.mu, ray.cos_phi, k) * solar_irradiance(k);
    }
    return march(ray.march, hillaire.march_steps, ray.phases, ray.lighting, true, k).radiance * solar_irradiance(k);
}

// The transmittance along the ray to the top (0 towards the ground, 1 outside the
// atmosphere), channel group k.
fn sky_transmittance(ray: SkyRay, k: u32) -> vec4<f32> {
    if (!ray.in_atmosphere) {
        return vec4<f32>(1.0);
    }
    if (ray.ground) {
        return vec4<f32>(0.0);
    }
    return transmittance_to_top(ray.s.r_km, ray.s.rho_km, ray.s.mu, k);
}

// ---------------------------------------------------------------------------------------
// SkyView::sky_radiance_to_point for the point where the ray meets the ground: the march to
// it (aerial perspective) and the transmittance between; with a shadowed length, nothing
// scattered over the last km before the point.

struct GroundRay {
    // Whether the ray meets the ground in front of the observer.
    hit: bool,
    s: ViewStart,
    march: MarchRay,
    phases: vec2<f32>,
    lighting: Lighting,
    // The ray's zenith cosine at the ground point and the light's there.
    mu_p: f32,
    mu_s_ground: f32,
}

// The preparation of a ray along `dir` to the ground (Hillaire2020View::
// sky_radiance_to_point up to the march), with a shadowed length over its last
// `shadow_length_km` when > 0.
fn ground_ray(v: View, o: Observer, light: ViewLight, dir: vec3<f32>, shadow_length_km: f32) -> GroundRay {
    var ray: GroundRay;
    let nu = clamp_cosine(dot(dir, light.direction));
    ray.s = view_start(o, light, dir, nu);
    // An observer on the ground (ρ = 0) sees no ground point, as on the CPU.
    ray.hit = ray.s.in_atmosphere && start_hits_ground(ray.s) && ray.s.rho_km > 0.0;
    if (!ray.hit) {
        return ray;
    }
    let d_km = distance_to_ground(ray.s);
    ray.mu_p = clamp_cosine(-safe_sqrt(ray.s.disc_ground_km2) / atm.bottom_radius_km);
    ray.mu_s_ground = clamp_cosine((ray.s.r_km * ray.s.mu_s + d_km * nu) / atm.bottom_radius_km);
    ray.march = view_march_ray(ray.s, light, nu, d_km);
    ray.phases = view_phases(nu);
    ray.lighting = lighting_all();
    if (shadow_length_km > 0.0) {
        let lit = Lit(0.0, d_km - shadow_length_km);
        ray.lighting = Lighting(lit, lit);
    }
    return ray;
}

// Channel group k of the radiance scattered towards the observer before the ground point
// (before the light's scale).
fn sky_radiance_to_point(v: View, ray: GroundRay, k: u32) -> vec4<f32> {
    return march(ray.march, hillaire.march_steps, ray.phases, ray.lighting, true, k).radiance * solar_irradiance(k);
}

// The transmittance between the observer and the ground point, channel group k
// (Lookup::transmittance of the reversed ray: e^{−(τ(R_g, −μ_p) − τ(r, −μ))}).
fn transmittance_to_point(ray: GroundRay, k: u32) -> vec4<f32> {
    let a = optical_depth_to_top(atm.bottom_radius_km, 0.0, -ray.mu_p, k);
    let b = optical_depth_to_top(ray.s.r_km, ray.s.rho_km, -ray.s.mu, k);
    return transmittance_between(a, b);
}

// ---------------------------------------------------------------------------------------
// SkyView::transmittance_to_light and SkyView::sun_and_sky_irradiance at a ground point
// (sky::surface_irradiance with the normal straight up: the sky occlusion factor is 1).

struct GroundLight {
    mu_s: f32,
    // The visible fraction of the light's disk (sin θ_h = 1, cos θ_h = 0 at the ground).
    fraction: f32,
    cos_light: f32,
}

// The light at a ground point where its zenith cosine is `mu_s`.
fn ground_light(light: ViewLight, mu_s: f32) -> GroundLight {
    var g: GroundLight;
    g.mu_s = mu_s;
    let e = light.angular_radius;
    g.fraction = smoothstep_safe(-e, e, mu_s);
    g.cos_light = max(mu_s, 0.0);
    return g;
}

// SkyView::transmittance_to_light at the ground point (Lookup::transmittance_to_sun with the
// light's angular radius), channel group k.
fn transmittance_to_light(g: GroundLight, k: u32) -> vec4<f32> {
    if (g.fraction <= 0.0) {
        return vec4<f32>(0.0);
    }
    return transmittance_to_top(atm.bottom_radius_km, 0.0, g.mu_s, k) * g.fraction;
}

// The sky's irradiance on a horizontal surface `altitude_km` up under a light at zenith
// cosine `mu_s`, per unit light irradiance (Hillaire2020::sky_irradiance), channel group k.
fn sky_irradiance(altitude_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    let f = table2_filter(altitude_mu_s_uv(altitude_km, mu_s, hillaire.irradiance_mu_s, hillaire.irradiance_r), hillaire.irradiance_mu_s, hillaire.irradiance_r);
    return f.weight.x * sky_irradiance_table[f.index.x + k] + f.weight.y * sky_irradiance_table[f.index.y + k]
        + f.weight.z * sky_irradiance_table[f.index.z + k] + f.weight.w * sky_irradiance_table[f.index.w + k];
}

// The light's direct irradiance (per unit of its irradiance at the top: callers multiply by
// it) and the sky's (before the light's scale), channel group k.
struct Irradiance {
    direct: vec4<f32>,
    sky: vec4<f32>,
}

// SkyView::sun_and_sky_irradiance at the ground point (sky::surface_irradiance), channel
// group k.
fn sun_and_sky_irradiance(g: GroundLight, k: u32) -> Irradiance {
    var e: Irradiance;
    e.sky = sky_irradiance(0.0, g.mu_s, k) * solar_irradiance(k);
    e.direct = transmittance_to_light(g, k) * g.cos_light;
    return e;
}
