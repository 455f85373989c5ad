// The 4D tables evaluated for one observer and one light (firmament::sky::bruneton4d::view,
// Bruneton & Neyret 2008 eq. 16 pieces; Bruneton 2017 `GetSkyRadiance`,
// `GetSkyRadianceToPoint`, `GetSunAndSkyIrradiance`): the sky method's module, which the
// renderer (render/render.wgsl) or an engine's own shader composes with the common modules.
// Functions carry the names of the Rust view's methods; each is split in a preparation per
// ray (filters, geometry: `sky_ray`, `ground_ray`, `ground_light`) and an evaluation per
// channel group k (wavelengths 4k..4k+3), so that a pixel computes its filters once.
//
// The final tables are bound at the slots lookup.wgsl declares for the precomputation:
//   3 transmittance_table     τ(r, μ) = −ln T to the top (Tables::optical_depth)
//   4 delta_irradiance_table  the final indirect irradiance E(r, μ_s) (Tables::irradiance)
//   5 scattering_a            single Rayleigh scattering (Tables::single_rayleigh)
//   6 scattering_b            single Mie (Tables::single_mie; see View.mie_layout)
//   7 multiple_table          multiple scattering, radiance (Tables::multiple)
//  11 view_constants          per channel group: linear sRGB rows, red-only Mie ratios
//  13 slice_table             the per-view cache: the tables at each light's (r, μ_s)
//
// Geometry is in km relative to the planet centre, but never through planet-scale
// differences: the observer's ρ = sqrt(r² − R_g²) and its height above the top of the
// atmosphere come from the host in f64, an observer in space enters the atmosphere through
// the impact parameter p (discriminants (R − p)(R + p), no cancellation), and the ground
// point of a ray is (r = R_g, ρ = 0) with its zenith cosine from the ray's discriminant.

@group(0) @binding(7) var<storage, read> multiple_table: array<vec4<f32>>;
// Per channel group k, at k·CHANNEL_STRIDE: the linear sRGB rows of the colour matrix
// (spectrum::ColourMatrix::to_srgb, 3 vec4) and the red-only Mie ratio factors
// (Tables::mie_ratio, 1 vec4).
@group(0) @binding(11) var<uniform> view_constants: array<vec4<f32>, CHANNEL_DATA_VEC4>;
// The slice of each light (Slice::new: the single, multiple and single Mie tables filtered at
// the observer's (u_μs, u_r) for that light), written by `camera_slice`: light l's entry
// e = y·N_ν + ν at (l·entries + e)·3·groups + k for single scattering, + groups for multiple
// scattering ([single; multiple] interleaved as in the CPU slice), + 2·groups for Mie
// (channel 0 in x when red-only).
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

// A light as the view needs it (scene::Light): its direction, the sine of its angular
// radius, and its slice.
struct ViewLight {
    direction: vec3<f32>,
    // Angular radius (rad) and its sine.
    angular_radius: f32,
    sin_angular_radius: f32,
    // The index of its slice in slice_table.
    slice: u32,
}

// How single Mie is stored: 0 all channels, 1 channel 0 only with one vec4 per texel
// (red-only tables from the CPU), 2 channel 0 read from the full layout (red-only, GPU
// tables). Set by the host (GpuSky).
struct View {
    mie_layout: u32,
}

// ---------------------------------------------------------------------------------------
// Where a view ray starts in the atmosphere (Bruneton4dView::start): the observer itself,
// or for an observer in space the point where the ray enters the top.

struct ViewStart {
    // False when the ray misses the atmosphere.
    in_atmosphere: bool,
    r_km: f32,
    rho_km: f32,
    mu: f32,
    mu_s: f32,
    // r²μ² − ρ², the discriminant of the ground sphere along the ray (≥ 0: the line meets it).
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
    // The nearer root of d² + 2 r_c μ d + r_c² − R_t² = 0, positive iff μ < 0; with the
    // impact parameter p = r_c sin θ the discriminant is (R_t − p)(R_t + p), and the nearer
    // root is the product of the roots (r_c − R_t)(r_c + R_t) over the farther one.
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
    // (r_c μ + d)/R_t = −sqrt(disc)/R_t.
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

// params::scattering_u_mu at the start, the distance to the ground from its discriminant.
fn start_u_mu(s: ViewStart, ground: bool) -> f32 {
    if (!ground) {
        return scattering_u_mu(s.r_km, s.rho_km, s.mu, false);
    }
    let d_km = distance_to_ground(s);
    let d_min_km = s.rho_km * s.rho_km / (s.r_km + atm.bottom_radius_km);
    let d_max_km = s.rho_km;
    var x = 0.0;
    if (d_max_km != d_min_km) {
        x = sqrt(clamp((d_km - d_min_km) / (d_max_km - d_min_km), 0.0, 1.0));
    }
    return 0.5 - 0.5 * texcoord_from_unit(x, atm.scattering_mu / 2u);
}

// The scattering-table coordinates at d_km along the ray from the start (the law of
// cosines for r, μ and μ_s there: geometry::advance, Bruneton4dView::combined_scattering).
// The 4D lookup at distance d along the ray (Bruneton4dView::combined_scattering away from
// the start), dark when μ_s there is below the tables' lowest sun.
fn at_along(s: ViewStart, nu: f32, d_km: f32, ground: bool) -> At {
    let rho_d_km = rho_at(s.r_km, s.rho_km, s.mu, d_km);
    let r_d_km = radius_from_rho(rho_d_km);
    let mu_d = clamp_cosine((s.r_km * s.mu + d_km) / r_d_km);
    let mu_s_d = clamp_cosine((s.r_km * s.mu_s + d_km * nu) / r_d_km);
    return at_table(scattering_uvwz(r_d_km, rho_d_km, mu_d, mu_s_d, nu, ground), r_d_km, mu_s_d);
}

// ---------------------------------------------------------------------------------------
// Table lookups with their filters computed once per ray and applied per channel group.

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

// Channel 0 of a red-only single Mie table: texel t at t (one vec4 per texel, from the CPU)
// or at t·groups (the full layout of the GPU precomputation).
fn mie_red_columns(v: View, f: Filter4, row: u32) -> Columns {
    var g = atm.groups;
    if (v.mie_layout == 1u) {
        g = 1u;
    }
    let a0 = vec4<f32>(scattering_b[(row + f.col.x) * g].x);
    let a1 = vec4<f32>(scattering_b[(row + f.col.y) * g].x);
    let d0 = vec4<f32>(scattering_b[(row + f.col.z) * g].x);
    let d1 = vec4<f32>(scattering_b[(row + f.col.w) * g].x);
    if (f.mu_s.twilight) {
        return twilight_columns(f, vec4<f32>(scattering_b[(row + f.colb.x) * g].x), a0, a1, vec4<f32>(scattering_b[(row + f.cola.x) * g].x),
            vec4<f32>(scattering_b[(row + f.colb.y) * g].x), d0, d1, vec4<f32>(scattering_b[(row + f.cola.y) * g].x));
    }
    return linear_columns(f, a0, a1, d0, d1);
}

fn sample_mie_red(v: View, f: Filter4) -> f32 {
    return blend_rows(f, mie_red_columns(v, f, f.row.x), mie_red_columns(v, f, f.row.y),
        mie_red_columns(v, f, f.row.z), mie_red_columns(v, f, f.row.w)).x;
}

// Multiple scattering of channel group k at a 4D filter (Table4::sample_into on
// Tables::multiple), as sample_scattering_a does for slot a.
fn multiple_columns(f: Filter4, row: u32, k: u32) -> Columns {
    let g = atm.groups;
    let a0 = multiple_table[(row + f.col.x) * g + k];
    let a1 = multiple_table[(row + f.col.y) * g + k];
    let d0 = multiple_table[(row + f.col.z) * g + k];
    let d1 = multiple_table[(row + f.col.w) * g + k];
    if (f.mu_s.twilight) {
        return twilight_columns(f, multiple_table[(row + f.colb.x) * g + k], a0, a1, multiple_table[(row + f.cola.x) * g + k],
            multiple_table[(row + f.colb.y) * g + k], d0, d1, multiple_table[(row + f.cola.y) * g + k]);
    }
    return linear_columns(f, a0, a1, d0, d1);
}

fn sample_multiple(f: Filter4, k: u32) -> vec4<f32> {
    return blend_rows(f, multiple_columns(f, f.row.x, k), multiple_columns(f, f.row.y, k),
        multiple_columns(f, f.row.z, k), multiple_columns(f, f.row.w, k));
}

// The bilinear (ν, μ) filter of a slice (Table4::sample_slice_channels_into); indices are
// slice entries (y·N_ν + ν).
fn slice_filter(u_nu: f32, u_mu: f32) -> Filter2 {
    let nnu = atm.scattering_nu;
    let tex_x = u_nu * f32(nnu - 1u);
    let nu0 = min(u32(floor(max(tex_x, 0.0))), nnu - 1u);
    let nu1 = min(nu0 + 1u, nnu - 1u);
    let tnu = tex_x - f32(nu0);
    let ly = lerp_weights(u_mu, atm.scattering_mu);
    var f: Filter2;
    f.index = vec4<u32>(ly.i0 * nnu + nu0, ly.i0 * nnu + nu1, ly.i1 * nnu + nu0, ly.i1 * nnu + nu1);
    f.weight = vec4<f32>((1.0 - ly.t) * (1.0 - tnu), (1.0 - ly.t) * tnu, ly.t * (1.0 - tnu), ly.t * tnu);
    return f;
}

fn slice_entries() -> u32 {
    return atm.scattering_mu * atm.scattering_nu;
}

fn sample_slice(slice: u32, f: Filter2, offset: u32) -> vec4<f32> {
    let stride = SLICE_TABLES * atm.groups;
    let base = slice * slice_entries();
    return f.weight.x * slice_table[(base + f.index.x) * stride + offset] + f.weight.y * slice_table[(base + f.index.y) * stride + offset]
        + f.weight.z * slice_table[(base + f.index.z) * stride + offset] + f.weight.w * slice_table[(base + f.index.w) * stride + offset];
}

// ---------------------------------------------------------------------------------------
// Combined scattering (Bruneton4dView::combined_scattering): single Rayleigh plus multiple
// scattering divided by the molecular phase function (callers multiply by it), and single
// Mie, of channel group k.

struct Combined {
    scattering: vec4<f32>,
    mie: vec4<f32>,
}

// Where a lookup reads: the slice of light `slice` at a (ν, μ) filter, or the 4D tables.
struct At {
    sliced: bool,
    slice: u32,
    slice_filter: Filter2,
    table: Filter4,
    // Channel 0 of single Mie and of the combined scattering (multiple included) for the
    // red-only ratio rule; computed once per ray by `at_red`.
    red: f32,
    scat0: f32,
    // Where the lookup is: its altitude and μ_s (below the tables' lowest sun the light
    // falls on from there: twilight_fade, Bruneton4dView::combined_scattering).
    altitude_km: f32,
    mu_s: f32,
}

// twilight_fade at the lookup, channel group k (1 at and above μ_s,min).
fn at_fade(a: At, k: u32) -> vec4<f32> {
    return twilight_fade(a.altitude_km, a.mu_s, k);
}

fn at_table(uvwz: vec4<f32>, r_km: f32, mu_s: f32) -> At {
    var a: At;
    a.sliced = false;
    a.table = scattering_filter(uvwz);
    a.altitude_km = r_km - atm.bottom_radius_km;
    a.mu_s = mu_s;
    return a;
}

// The start of a ray: the slice when the ray starts at the observer, the 4D tables
// otherwise.
fn at_start(s: ViewStart, light: ViewLight, nu: f32, ground: bool) -> At {
    var a: At;
    a.sliced = s.at_observer;
    a.slice = light.slice;
    a.altitude_km = s.r_km - atm.bottom_radius_km;
    a.mu_s = s.mu_s;
    let u_nu = u_nu_from_nu(s.mu, s.mu_s, nu);
    if (a.sliced) {
        a.slice_filter = slice_filter(u_nu, start_u_mu(s, ground));
    } else {
        let u_mu_s = texcoord_from_unit(x_mu_s(s.mu_s), atm.scattering_mu_s);
        let u_r = texcoord_from_unit(s.rho_km / atm.h_km, atm.scattering_r);
        a.table = scattering_filter(vec4<f32>(u_nu, u_mu_s, start_u_mu(s, ground), u_r));
    }
    return a;
}

fn rayleigh_and_multiple(a: At, k: u32, p_r: f32) -> vec4<f32> {
    if (a.sliced) {
        return sample_slice(a.slice, a.slice_filter, k) + sample_slice(a.slice, a.slice_filter, atm.groups + k) / p_r;
    }
    return sample_scattering_a(a.table, k) + sample_multiple(a.table, k) / p_r;
}

// The red-only ratio rule's channel-0 values at `a` (nothing to do for separate Mie).
fn at_red(v: View, a_in: At, p_r: f32) -> At {
    var a = a_in;
    if (v.mie_layout != 0u) {
        if (a.sliced) {
            a.red = sample_slice(a.slice, a.slice_filter, 2u * atm.groups).x;
        } else {
            a.red = sample_mie_red(v, a.table);
        }
        a.scat0 = rayleigh_and_multiple(a, 0u, p_r).x;
    }
    return a;
}

fn combined_scattering(v: View, a: At, k: u32, p_r: f32) -> Combined {
    var c: Combined;
    c.scattering = rayleigh_and_multiple(a, k, p_r);
    c.mie = single_mie(v, a, c.scattering, k);
    if (a.mu_s < atm.mu_s_min) {
        let f = at_fade(a, k);
        c.scattering *= f;
        c.mie *= f;
    }
    return c;
}

// Single Mie of channel group k at `a`: the table's (or the slice's), or with red-only
// storage the ratio rule of MieStorage::RedOnly, scat[k]·red/scat[0]·ratio[k], from
// `scattering` (the lookup's Rayleigh part, with or without the multiple scattering as the
// caller's orders are).
fn single_mie(v: View, a: At, scattering: vec4<f32>, k: u32) -> vec4<f32> {
    if (v.mie_layout == 0u) {
        if (a.sliced) {
            return sample_slice(a.slice, a.slice_filter, 2u * atm.groups + k);
        }
        return sample_scattering_b(a.table, k);
    }
    if (a.scat0 > 0.0) {
        return scattering * a.red / a.scat0 * view_constants[k * CHANNEL_STRIDE + CHANNEL_MIE_RATIO];
    }
    return vec4<f32>(0.0);
}

// ---------------------------------------------------------------------------------------
// SkyView::sky_radiance: radiance scattered towards the observer along a ray to the
// atmosphere boundary or the ground, with a shadowed length over the first km of the ray.

struct SkyRay {
    in_atmosphere: bool,
    ground: bool,
    pr: f32,
    pm: f32,
    // The lookup: at the start, or with a shadowed length at the end of the shadow.
    at: At,
    shadowed: bool,
    // T(0, shadow length) with a shadowed length.
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
    let p_r = max(ray.pr, 1e-30);
    ray.ground = start_hits_ground(s);
    ray.t_top = transmittance_filter(s.r_km, s.rho_km, s.mu);
    ray.shadowed = shadow_length_km > 0.0;
    if (ray.shadowed) {
        // The scattering beyond the shadow, attenuated by T(0, l).
        ray.at = at_along(s, nu, shadow_length_km, ray.ground);
        ray.t_shadow = transmittance_filters(s.r_km, s.rho_km, s.mu, shadow_length_km, ray.ground);
    } else {
        ray.at = at_start(s, light, nu, ray.ground);
    }
    ray.at = at_red(v, ray.at, p_r);
    return ray;
}

// Channel group k of the ray's sky radiance (before the light's irradiance scale).
fn sky_radiance(v: View, ray: SkyRay, k: u32) -> vec4<f32> {
    if (!ray.in_atmosphere) {
        return vec4<f32>(0.0);
    }
    let c = combined_scattering(v, ray.at, k, max(ray.pr, 1e-30));
    var l = c.scattering * ray.pr + c.mie * ray.pm;
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
// in-scattering S|x − T(x, x_s)·S|x_s and the transmittance between, with a shadowed length
// over the last km before the point.

struct GroundRay {
    // Whether the ray meets the ground in front of the observer.
    hit: bool,
    pr: f32,
    pm: f32,
    // Single Mie faded out with the light below the horizon (Bruneton 2017).
    fade: f32,
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
    // ray_sphere(..).filter(near > 0): an observer on the ground (ρ = 0) sees no ground point.
    ray.hit = s.in_atmosphere && start_hits_ground(s) && s.rho_km > 0.0;
    if (!ray.hit) {
        return ray;
    }
    ray.pr = group_phase(0u, nu);
    ray.pm = group_phase(1u, nu);
    let p_r = max(ray.pr, 1e-30);
    ray.fade = smoothstep_safe(0.0, 0.01, s.mu_s);
    ray.at = at_red(v, at_start(s, light, nu, true), p_r);
    // The ground point: r = R_g, ρ = 0, zenith cosine −sqrt(r²μ² − ρ²)/R_g, and the light's
    // zenith cosine there by the law of cosines.
    let d_km = distance_to_ground(s);
    let mu_p = clamp_cosine(-safe_sqrt(s.disc_ground_km2) / atm.bottom_radius_km);
    ray.mu_s_ground = clamp_cosine((s.r_km * s.mu_s + d_km * nu) / atm.bottom_radius_km);
    // Lookup::transmittance for a ground ray: e^{−(τ(R_g, −μ_p) − τ(r, −μ))}.
    ray.t_point.a = transmittance_filter(atm.bottom_radius_km, 0.0, -mu_p);
    ray.t_point.b = transmittance_filter(s.r_km, s.rho_km, -s.mu);
    if (shadow_length_km > 0.0) {
        // The lit part ends `shadow_length_km` before the point.
        let e_km = max(d_km - shadow_length_km, 0.0);
        ray.at_end = at_red(v, at_along(s, nu, e_km, true), p_r);
        ray.t_end = transmittance_filters(s.r_km, s.rho_km, s.mu, e_km, true);
    } else {
        ray.at_end = at_red(v, at_table(scattering_uvwz(atm.bottom_radius_km, 0.0, mu_p, ray.mu_s_ground, nu, true), atm.bottom_radius_km, ray.mu_s_ground), p_r);
        ray.t_end = ray.t_point;
    }
    return ray;
}

// Channel group k of the in-scattered radiance to the ground point (before the light's
// irradiance scale).
fn sky_radiance_to_point(v: View, ray: GroundRay, k: u32) -> vec4<f32> {
    let p_r = max(ray.pr, 1e-30);
    let c = combined_scattering(v, ray.at, k, p_r);
    let c_end = combined_scattering(v, ray.at_end, k, p_r);
    let t = sample_transmittance_between(ray.t_end, k);
    return max(c.scattering - t * c_end.scattering, vec4<f32>(0.0)) * ray.pr
        + max(c.mie - t * c_end.mie, vec4<f32>(0.0)) * ray.fade * ray.pm;
}

// The transmittance between the observer and the ground point, channel group k.
fn transmittance_to_point(ray: GroundRay, k: u32) -> vec4<f32> {
    return sample_transmittance_between(ray.t_point, k);
}

// ---------------------------------------------------------------------------------------
// SkyView::transmittance_to_light and SkyView::sun_and_sky_irradiance at a ground point
// (normal straight up: the sky occlusion factor is 1).

struct GroundLight {
    // The sky's irradiance at the ground: μ_s (twilight_sky_irradiance).
    mu_s: f32,
    fraction: f32,
    to_light: Filter2,
    cos_light: f32,
}

fn ground_light(light: ViewLight, mu_s: f32) -> GroundLight {
    var g: GroundLight;
    g.mu_s = mu_s;
    // Lookup::sun_visible_fraction with the light's angular radius (sin θ_h = 1 at the ground).
    let e = light.angular_radius;
    g.fraction = smoothstep_safe(-e, e, mu_s);
    g.to_light = transmittance_filter(atm.bottom_radius_km, 0.0, mu_s);
    g.cos_light = max(mu_s, 0.0);
    return g;
}

fn transmittance_to_light(g: GroundLight, k: u32) -> vec4<f32> {
    if (g.fraction <= 0.0) {
        return vec4<f32>(0.0);
    }
    return sample_transmittance(g.to_light, k) * g.fraction;
}

// The light's direct and the sky's irradiance, per unit of the light's irradiance at the top
// of the atmosphere for the direct part (callers multiply by it) and before the light's
// scale for the sky.
struct Irradiance {
    direct: vec4<f32>,
    sky: vec4<f32>,
}

fn sun_and_sky_irradiance(g: GroundLight, k: u32) -> Irradiance {
    var e: Irradiance;
    e.sky = twilight_sky_irradiance(0.0, g.mu_s, k);
    e.direct = transmittance_to_light(g, k) * g.cos_light;
    return e;
}

// ---------------------------------------------------------------------------------------
// The per-view cache (Slice::new): the single, multiple and single Mie tables filtered at the
// observer's (u_μs, u_r) of each light, one invocation per (μ, ν) entry, channel group and
// light. The lights' (u_μs, u_r) come from the host (computed in f64).

struct SliceCoordinates {
    // Per light: (u_μs, u_r, 0, 0).
    at: array<vec4<f32>, MAX_LIGHTS>,
    lights: u32,
    mie_layout: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(15) var<uniform> slice_coordinates: SliceCoordinates;

// One r row of a slice entry: the three tables' texels at the row's ν column `base`,
// blended along μ_s (mu_s_blend.wgsl in a twilight cell, else linear). Red-only Mie
// (mie_layout 1) in .x of channel group 0.
struct SliceRow {
    scattering: vec4<f32>,
    multiple: vec4<f32>,
    mie: vec4<f32>,
}

fn mu_s_blend_row(m: MuSFilter, below: vec4<f32>, a: vec4<f32>, b: vec4<f32>, above: vec4<f32>) -> vec4<f32> {
    if (m.twilight) {
        return mu_s_blend_at(m, below, a, b, above);
    }
    return a + m.t * (b - a);
}
// (Outside a twilight cell the slice reads below = s0 and above = s1: no extra texels.)

fn slice_row(m: MuSFilter, base: u32, k: u32, mie_layout: u32) -> SliceRow {
    let g = atm.groups;
    let below = select(m.s0, m.below, m.twilight);
    let above = select(m.s1, m.above, m.twilight);
    let t = vec4<u32>(base + below, base + m.s0, base + m.s1, base + above);
    var s: SliceRow;
    s.scattering = mu_s_blend_row(m, scattering_a[t.x * g + k], scattering_a[t.y * g + k], scattering_a[t.z * g + k], scattering_a[t.w * g + k]);
    s.multiple = mu_s_blend_row(m, multiple_table[t.x * g + k], multiple_table[t.y * g + k], multiple_table[t.z * g + k], multiple_table[t.w * g + k]);
    if (mie_layout == 0u) {
        s.mie = mu_s_blend_row(m, scattering_b[t.x * g + k], scattering_b[t.y * g + k], scattering_b[t.z * g + k], scattering_b[t.w * g + k]);
    } else if (k == 0u) {
        let gm = select(g, 1u, mie_layout == 1u);
        s.mie = vec4<f32>(mu_s_blend_row(m, vec4<f32>(scattering_b[t.x * gm].x), vec4<f32>(scattering_b[t.y * gm].x),
            vec4<f32>(scattering_b[t.z * gm].x), vec4<f32>(scattering_b[t.w * gm].x)).x, 0.0, 0.0, 0.0);
    }
    return s;
}

@compute @workgroup_size(64)
fn camera_slice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let entries = slice_entries();
    if (i >= entries * slice_coordinates.lights) {
        return;
    }
    let light = i / entries;
    let e = i % entries;
    let k = gid.z;
    let g = atm.groups;
    let y = e / atm.scattering_nu;
    let nu = e % atm.scattering_nu;
    let at = slice_coordinates.at[light];
    let m = mu_s_filter(at.x, atm.scattering_mu_s, atm.mu_s_twilight_cells);
    let rf = r_filter(at.y, atm.scattering_r);
    let width = scattering_width();
    // Table4::slice: each r row blended along μ_s, then along r (r_blend.wgsl).
    let rows = (vec2<u32>(rf.z0, rf.z1) * atm.scattering_mu + y) * width + nu * atm.scattering_mu_s;
    let lower = slice_row(m, rows.x, k, slice_coordinates.mie_layout);
    let upper = slice_row(m, rows.y, k, slice_coordinates.mie_layout);
    let scattering = r_blend(lower.scattering, upper.scattering, rf);
    let multiple = r_blend(lower.multiple, upper.multiple, rf);
    let mie = r_blend(lower.mie, upper.mie, rf);
    let o = i * SLICE_TABLES * g;
    slice_table[o + k] = scattering;
    slice_table[o + g + k] = multiple;
    slice_table[o + 2u * g + k] = mie;
}
