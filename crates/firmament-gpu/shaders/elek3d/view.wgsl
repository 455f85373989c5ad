// The 3D tables evaluated for one observer and one light (firmament::sky::elek3d::view,
// Elek3dView: Bruneton & Neyret 2008 eq. 16 pieces from the azimuth-free tables): the sky
// method's module that render/render.wgsl composes after it, with the functions and structs
// bruneton4d/view.wgsl gives it (`sky_ray`/`sky_radiance`/`sky_transmittance`,
// `ground_ray`/`sky_radiance_to_point`/`transmittance_to_point`,
// `ground_light`/`transmittance_to_light`/`sun_and_sky_irradiance`), each split in a
// preparation per ray and an evaluation per channel group k. The single scattering is
// S₃,R·P_R(ν) + S₃,M·P_M(ν) with the ray's real ν; the multiple scattering is read as it
// is. Below the tables' lowest sun every lookup is faded as the 4D tables' sky is
// (bruneton4d/twilight.wgsl). Results are per the model's solar irradiance (the renderer
// multiplies by each light's scale against it).
//
// Bindings besides the common ones:
//   3 transmittance_table   τ(r, μ) to the top, the 4D tables' mapping (Elek3d::optical_depth)
//   4 delta_irradiance_table the sky's irradiance E(r, μ_s) (Elek3d::irradiance)
//   5, 6, 7                 single Rayleigh, single Mie, multiple (table.wgsl)
//   8 elek3d                the mappings' constants (params.wgsl)
//  11 view_constants        per channel group: linear sRGB rows (and a row unused here)
//  13 slice_table           the per-view cache: the tables at each light's (r, μ_s)
//  15 slice_coordinates     each light's (u_h, u_μs) at the observer

// Per channel group k, at k·CHANNEL_STRIDE: the linear sRGB rows of the colour matrix
// (spectrum::ColourMatrix::to_srgb, 3 vec4) and a row the 4D tables use (zero here).
@group(0) @binding(11) var<uniform> view_constants: array<vec4<f32>, CHANNEL_DATA_VEC4>;
// The slice of each light (Elek3dView's `slice`: the three tables filtered at the observer's
// (u_h, u_μs) for that light, Table3::slice), written by `camera_slice`: light l's
// view-zenith texel y at ((l·N_μ + y)·SLICE_TABLES + table)·groups + k, the tables in the
// CPU slice's order (single Rayleigh, single Mie, multiple).
@group(0) @binding(13) var<storage, read_write> slice_table: array<vec4<f32>>;

// The observer (SkyMethod::view's `observer`), on the +z axis.
struct Observer {
    // Whether it is inside the atmosphere (r ≤ R_t): then the slices apply.
    inside: bool,
    r_km: f32,
    // ρ = sqrt(r² − R_g²) inside the atmosphere.
    rho_km: f32,
    // r − R_t, for an observer in space.
    above_top_km: f32,
}

// A light as the view needs it (scene::Light): its direction, its angular radius and the
// sine of it, and its slice.
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
// Where a view ray starts in the atmosphere (sky::entry::enter_atmosphere; Elek3dView::
// start): the observer itself, or for an observer in space the point where the ray enters
// the top, through the impact parameter p (discriminants (R − p)(R + p)).

struct ViewStart {
    in_atmosphere: bool,
    r_km: f32,
    rho_km: f32,
    mu: f32,
    mu_s: f32,
    // r²μ² − ρ², the discriminant of the ground sphere along the ray.
    disc_ground_km2: f32,
    // Whether the ray starts at the observer (so the slice applies), and how far from it.
    at_observer: bool,
    offset_km: f32,
}

fn view_start(o: Observer, light: ViewLight, dir: vec3<f32>, nu: f32) -> ViewStart {
    var s: ViewStart;
    if (o.inside) {
        // The observer is on the +z axis: μ = dir.z, μ_s = light.z.
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
    // The nearer root, (r_c − R_t)(r_c + R_t) over the farther one.
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

// ---------------------------------------------------------------------------------------
// The 4D tables' lookups (bruneton4d::Lookup) with their filters computed once per ray and
// applied per channel group.

// τ to the top at a filter (Lookup::optical_depth_to_top).
fn sample_optical_depth(f: Filter2, k: u32) -> vec4<f32> {
    return f.weight.x * transmittance_table[f.index.x + k] + f.weight.y * transmittance_table[f.index.y + k]
        + f.weight.z * transmittance_table[f.index.z + k] + f.weight.w * transmittance_table[f.index.w + k];
}

fn sample_transmittance(f: Filter2, k: u32) -> vec4<f32> {
    return exp(-sample_optical_depth(f, k));
}

// Lookup::transmittance_to_top's filter.
fn transmittance_filter(r_km: f32, rho_km: f32, mu: f32) -> Filter2 {
    return table2_filter(transmittance_uv(r_km, rho_km, mu), atm.transmittance_mu, atm.transmittance_r);
}

// The filters of Lookup::transmittance over d_km from (r, μ): the optical depths to the top
// from both ends (of the reversed ray when it hits the ground).
struct TransmittanceFilters {
    a: Filter2,
    b: Filter2,
}

fn transmittance_filters(r_km: f32, rho_km: f32, mu: f32, d_km: f32, ground: bool) -> TransmittanceFilters {
    let rho_d_km = rho_at(r_km, rho_km, mu, d_km);
    let r_d_km = radius_from_rho(rho_d_km);
    let mu_d = clamp_cosine((r_km * mu + d_km) / r_d_km);
    var f: TransmittanceFilters;
    if (ground) {
        f.a = transmittance_filter(r_d_km, rho_d_km, -mu_d);
        f.b = transmittance_filter(r_km, rho_km, -mu);
    } else {
        f.a = transmittance_filter(r_km, rho_km, mu);
        f.b = transmittance_filter(r_d_km, rho_d_km, mu_d);
    }
    return f;
}

fn sample_transmittance_between(f: TransmittanceFilters, k: u32) -> vec4<f32> {
    return transmittance_between(sample_optical_depth(f.a, k), sample_optical_depth(f.b, k));
}

// Lookup::irradiance on the sky's irradiance table (slot 4; twilight.wgsl reads it).
fn sample_irradiance(f: Filter2, k: u32) -> vec4<f32> {
    return f.weight.x * delta_irradiance_table[f.index.x + k] + f.weight.y * delta_irradiance_table[f.index.y + k]
        + f.weight.z * delta_irradiance_table[f.index.z + k] + f.weight.w * delta_irradiance_table[f.index.w + k];
}

// ---------------------------------------------------------------------------------------
// The three tables at a point of a ray (Elek3dView::scattering_at): the light's slice at the
// observer, the 3D tables elsewhere.

// Where a lookup reads.
struct At {
    // The slice of light `slice` at the view-zenith filter `slice_lerp`, or the tables' taps.
    sliced: bool,
    slice: u32,
    slice_lerp: Lerp,
    taps: Taps3,
    // Where the lookup is: its altitude and μ_s (below the tables' lowest sun the light
    // falls off from there: twilight_fade).
    altitude_km: f32,
    mu_s: f32,
}

// The tables at (r, μ, μ_s) on a ray that meets the ground or not.
fn at_table(r_km: f32, rho_km: f32, mu: f32, mu_s: f32, ground: bool) -> At {
    var a: At;
    a.sliced = false;
    a.taps = table3_taps(elek3d_coords(r_km, rho_km, mu, mu_s, ground));
    a.altitude_km = altitude_of(rho_km, r_km);
    a.mu_s = mu_s;
    return a;
}

// The start of a ray: the slice when the ray starts at the observer, the tables otherwise.
fn at_start(s: ViewStart, light: ViewLight, ground: bool) -> At {
    if (!s.at_observer) {
        return at_table(s.r_km, s.rho_km, s.mu, s.mu_s, ground);
    }
    var a: At;
    a.sliced = true;
    a.slice = light.slice;
    a.slice_lerp = lerp_weights(elek3d_u_mu(s.r_km, s.rho_km, s.mu, ground), elek3d.nmu);
    a.altitude_km = altitude_of(s.rho_km, s.r_km);
    a.mu_s = s.mu_s;
    return a;
}

// The tables at distance d_km along the ray from its start, on the start's side of the
// horizon (geometry::advance for r and μ there, the law of cosines for μ_s).
fn at_along(s: ViewStart, nu: f32, d_km: f32, ground: bool) -> At {
    let rho_d_km = rho_at(s.r_km, s.rho_km, s.mu, d_km);
    let r_d_km = radius_from_rho(rho_d_km);
    let mu_d = clamp_cosine((s.r_km * s.mu + d_km) / r_d_km);
    let mu_s_d = clamp_cosine((s.r_km * s.mu_s + d_km * nu) / r_d_km);
    return at_table(r_d_km, rho_d_km, mu_d, mu_s_d, ground);
}

// Table3::sample_slice_into on light `slice`'s entries, channel group k.
fn sample_slice(slice: u32, l: Lerp, k: u32) -> Scattering3 {
    let g = atm.groups;
    let stride = SLICE_TABLES * g;
    let e0 = (slice * elek3d.nmu + l.i0) * stride + k;
    let e1 = (slice * elek3d.nmu + l.i1) * stride + k;
    let w0 = 1.0 - l.t;
    let w1 = l.t;
    var s: Scattering3;
    s.rayleigh = w0 * slice_table[e0] + w1 * slice_table[e1];
    s.mie = w0 * slice_table[e0 + g] + w1 * slice_table[e1 + g];
    s.multiple = w0 * slice_table[e0 + 2u * g] + w1 * slice_table[e1 + 2u * g];
    return s;
}

// Elek3dView::scattering_at (every order), channel group k: below the tables' lowest sun,
// faded as the 4D tables' sky is (twilight::fade).
fn scattering_at(a: At, k: u32) -> Scattering3 {
    var s: Scattering3;
    if (a.sliced) {
        s = sample_slice(a.slice, a.slice_lerp, k);
    } else {
        s = table3_sample(a.taps, k);
    }
    if (a.mu_s < atm.mu_s_min) {
        let f = twilight_fade(a.altitude_km, a.mu_s, k);
        s.rayleigh *= f;
        s.mie *= f;
        s.multiple *= f;
    }
    return s;
}

// ---------------------------------------------------------------------------------------
// SkyView::sky_radiance: radiance scattered towards the observer along a ray to the
// atmosphere boundary or the ground; with a shadowed length l, the light from beyond l
// (Shadow::Length: T(0, l)·S(l)).

struct SkyRay {
    in_atmosphere: bool,
    ground: bool,
    pr: f32,
    pm: f32,
    // The lookup: at the start, or with a shadowed length at the end of the shadow.
    at: At,
    shadowed: bool,
    // T(0, l) with a shadowed length.
    t_shadow: TransmittanceFilters,
    // The transmittance to the top (for a light's disk; 0 towards the ground).
    t_top: Filter2,
}

fn sky_ray(v: View, o: Observer, light: ViewLight, dir: vec3<f32>, shadow_length_km: f32) -> SkyRay {
    var ray: SkyRay;
    let nu = clamp_cosine(dot(dir, light.direction));
    let s = view_start(o, light, dir, nu);
    ray.in_atmosphere = s.in_atmosphere;
    if (!s.in_atmosphere) {
        return ray;
    }
    ray.pr = group_phase(0u, nu);
    ray.pm = group_phase(1u, nu);
    ray.ground = start_hits_ground(s);
    ray.t_top = transmittance_filter(s.r_km, s.rho_km, s.mu);
    ray.shadowed = shadow_length_km > 0.0;
    if (ray.shadowed) {
        ray.at = at_along(s, nu, shadow_length_km, ray.ground);
        ray.t_shadow = transmittance_filters(s.r_km, s.rho_km, s.mu, shadow_length_km, ray.ground);
    } else {
        ray.at = at_start(s, light, ray.ground);
    }
    return ray;
}

// Channel group k of the ray's sky radiance (before the light's scale).
fn sky_radiance(v: View, ray: SkyRay, k: u32) -> vec4<f32> {
    if (!ray.in_atmosphere) {
        return vec4<f32>(0.0);
    }
    let s = scattering_at(ray.at, k);
    var l = s.rayleigh * ray.pr + s.mie * ray.pm + s.multiple;
    if (ray.shadowed) {
        l *= sample_transmittance_between(ray.t_shadow, k);
    }
    return l;
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
    return sample_transmittance(ray.t_top, k);
}

// ---------------------------------------------------------------------------------------
// SkyView::sky_radiance_to_point for the point where the ray meets the ground: the
// in-scattering S(0) − T(0, b)·S(b) per table (each clamped at 0, as Elek3dView::
// lit_radiance does) and the transmittance to the point; with a shadowed length l, the lit
// part ends at b = d − l before the point (nothing when l ≥ d).

struct GroundRay {
    // Whether the ray meets the ground in front of the observer.
    hit: bool,
    pr: f32,
    pm: f32,
    // Single Mie faded out with the light below the horizon (as the 4D tables, Bruneton 2017).
    fade: f32,
    // Whether any of the ray is lit (a shadowed length shorter than the ray).
    lit: bool,
    at: At,
    at_end: At,
    // The transmittance to the point, and to the end of the lit part.
    t_point: TransmittanceFilters,
    t_end: TransmittanceFilters,
    // μ_s at the ground point, for sun_and_sky_irradiance.
    mu_s_ground: f32,
}

fn ground_ray(v: View, o: Observer, light: ViewLight, dir: vec3<f32>, shadow_length_km: f32) -> GroundRay {
    var ray: GroundRay;
    let nu = clamp_cosine(dot(dir, light.direction));
    let s = view_start(o, light, dir, nu);
    // An observer on the ground (ρ = 0) sees no ground point, as on the CPU.
    ray.hit = s.in_atmosphere && start_hits_ground(s) && s.rho_km > 0.0;
    if (!ray.hit) {
        return ray;
    }
    ray.pr = group_phase(0u, nu);
    ray.pm = group_phase(1u, nu);
    ray.fade = smoothstep_safe(0.0, 0.01, s.mu_s);
    ray.at = at_start(s, light, true);
    // The ground point: r = R_g, ρ = 0, zenith cosine −sqrt(r²μ² − ρ²)/R_g, and the light's
    // zenith cosine there by the law of cosines.
    let d_km = distance_to_ground(s);
    let mu_p = clamp_cosine(-safe_sqrt(s.disc_ground_km2) / atm.bottom_radius_km);
    ray.mu_s_ground = clamp_cosine((s.r_km * s.mu_s + d_km * nu) / atm.bottom_radius_km);
    // Lookup::transmittance for a ground ray: e^{−(τ(R_g, −μ_p) − τ(r, −μ))}.
    ray.t_point.a = transmittance_filter(atm.bottom_radius_km, 0.0, -mu_p);
    ray.t_point.b = transmittance_filter(s.r_km, s.rho_km, -s.mu);
    ray.lit = true;
    if (shadow_length_km > 0.0) {
        let e_km = d_km - shadow_length_km;
        ray.lit = e_km > 0.0;
        ray.at_end = at_along(s, nu, max(e_km, 0.0), true);
        ray.t_end = transmittance_filters(s.r_km, s.rho_km, s.mu, max(e_km, 0.0), true);
    } else {
        ray.at_end = at_table(atm.bottom_radius_km, 0.0, mu_p, ray.mu_s_ground, true);
        ray.t_end = ray.t_point;
    }
    return ray;
}

// Channel group k of the in-scattered radiance to the ground point (before the light's
// scale).
fn sky_radiance_to_point(v: View, ray: GroundRay, k: u32) -> vec4<f32> {
    if (!ray.lit) {
        return vec4<f32>(0.0);
    }
    let a = scattering_at(ray.at, k);
    let b = scattering_at(ray.at_end, k);
    let t = sample_transmittance_between(ray.t_end, k);
    let zero = vec4<f32>(0.0);
    return max(a.rayleigh - t * b.rayleigh, zero) * ray.pr
        + max(a.mie - t * b.mie, zero) * ray.pm * ray.fade
        + max(a.multiple - t * b.multiple, zero);
}

// The transmittance between the observer and the ground point, channel group k.
fn transmittance_to_point(ray: GroundRay, k: u32) -> vec4<f32> {
    return sample_transmittance_between(ray.t_point, k);
}

// ---------------------------------------------------------------------------------------
// SkyView::transmittance_to_light and SkyView::sun_and_sky_irradiance at a ground point
// (sky::surface_irradiance with the normal straight up: the sky occlusion factor is 1).

struct GroundLight {
    // The light's zenith cosine at the ground point.
    mu_s: f32,
    // The visible fraction of the light's disk (sin θ_h = 1, cos θ_h = 0 at the ground).
    fraction: f32,
    to_light: Filter2,
    cos_light: f32,
}

fn ground_light(light: ViewLight, mu_s: f32) -> GroundLight {
    var g: GroundLight;
    g.mu_s = mu_s;
    let e = light.angular_radius;
    g.fraction = smoothstep_safe(-e, e, mu_s);
    g.to_light = transmittance_filter(atm.bottom_radius_km, 0.0, mu_s);
    g.cos_light = max(mu_s, 0.0);
    return g;
}

// Lookup::transmittance_to_light at the ground point (with the light's angular radius),
// channel group k.
fn transmittance_to_light(g: GroundLight, k: u32) -> vec4<f32> {
    if (g.fraction <= 0.0) {
        return vec4<f32>(0.0);
    }
    return sample_transmittance(g.to_light, k) * g.fraction;
}

// The light's direct irradiance (per unit of its irradiance at the top: callers multiply by
// it) and the sky's (before the light's scale).
struct Irradiance {
    direct: vec4<f32>,
    sky: vec4<f32>,
}

// Elek3dView::sun_and_sky_irradiance at the ground point: the sky's from the irradiance
// table, extrapolated below its lowest sun (twilight::sky_irradiance), channel group k.
fn sun_and_sky_irradiance(g: GroundLight, k: u32) -> Irradiance {
    var e: Irradiance;
    e.sky = twilight_sky_irradiance(0.0, g.mu_s, k);
    e.direct = transmittance_to_light(g, k) * g.cos_light;
    return e;
}

// ---------------------------------------------------------------------------------------
// The per-view cache (Elek3dView::new's slice, Table3::slice): the three tables filtered at
// the observer's (u_h, u_μs) of each light, one invocation per view-zenith texel and light,
// channel group gid.z. The lights' (u_h, u_μs) come from the host (Params in f64).

struct SliceCoordinates {
    // Per light: (u_h, u_μs, 0, 0).
    at: array<vec4<f32>, MAX_LIGHTS>,
    lights: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(15) var<uniform> slice_coordinates: SliceCoordinates;

@compute @workgroup_size(64)
fn camera_slice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= elek3d.nmu * slice_coordinates.lights) {
        return;
    }
    let light = i / elek3d.nmu;
    let y = i % elek3d.nmu;
    let k = gid.z;
    let g = atm.groups;
    let at = slice_coordinates.at[light];
    let s = table3_slice(at.x, at.y, y, k);
    let o = i * SLICE_TABLES * g + k;
    slice_table[o] = s.rayleigh;
    slice_table[o + g] = s.mie;
    slice_table[o + 2u * g] = s.multiple;
}
