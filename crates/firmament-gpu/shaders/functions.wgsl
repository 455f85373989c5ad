// Shared by every table pass: the atmosphere parameters, density profiles, phase functions,
// ray geometry, the table parameterisations and the table lookups. Mirrors, function for
// function, crates/firmament/src/{geometry.rs, lut/params.rs, lut/context.rs,
// lut/table.rs, medium/profile.rs, medium/phase.rs} (Bruneton 2017 `functions.glsl`).
//
// Units: lengths in km (f32 precision), coefficients in km⁻¹, angles as cosines.
// Wherever a radius difference would cancel in f32 (r − R_g at 6360 km), the shaders carry
// ρ = sqrt(r² − R_g²), the distance to the horizon, and use r² − R_g² = ρ²,
// R_t² − r² = H² − ρ² (exact identities, no cancellation).
//
// Tables are storage buffers of vec4<f32>: channel group k (wavelengths 4k..4k+3) of texel i
// at index i·groups + k, texels in the CPU order (firmament::lut::table). The host drops
// the padding lanes when it converts them to `Tables`.

const PI: f32 = 3.14159265358979;

// Atmosphere and table sizes; one uniform buffer per precomputation (never baked into the
// shader source). Filled by firmament_gpu::lut::atmosphere (same field order).
struct Atmosphere {
    bottom_radius: f32,
    top_radius: f32,
    h: f32,
    h_sq: f32,
    mu_s_min: f32,
    mu_s_big_a: f32,
    sun_angular_radius: f32,
    channels: u32,
    groups: u32,
    constituents: u32,
    transmittance_mu: u32,
    transmittance_r: u32,
    scattering_r: u32,
    scattering_mu: u32,
    scattering_mu_s: u32,
    scattering_nu: u32,
    irradiance_mu_s: u32,
    irradiance_r: u32,
    solar_offset: u32,
    albedo_offset: u32,
    constituent_offset: u32,
    layer_offset: u32,
    phase0_kind: u32,
    phase0_offset: u32,
    phase0_count: u32,
    phase0_a: f32,
    phase0_b: f32,
    phase0_c: f32,
    phase1_kind: u32,
    phase1_offset: u32,
    phase1_count: u32,
    phase1_a: f32,
    phase1_b: f32,
    phase1_c: f32,
    group0_present: u32,
    group1_present: u32,
}

// Which radiance field a pass reads (0: single scattering, phase functions applied at lookup;
// 1: the previous order's ΔS as it is) and the scattering order.
struct PassParams {
    mode: u32,
    order: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> atm: Atmosphere;
@group(0) @binding(1) var<uniform> pass_params: PassParams;
// Per-wavelength data (vec4 per channel group), constituents, layers, tabulated phases.
@group(0) @binding(2) var<storage, read> data: array<vec4<f32>>;

const WORKGROUP: u32 = 64u;

// Flat invocation index of a 2D dispatch over 64-wide workgroups.
fn invocation_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WORKGROUP;
}

fn solar_irradiance(k: u32) -> vec4<f32> {
    return data[atm.solar_offset + k];
}

fn ground_albedo(k: u32) -> vec4<f32> {
    return data[atm.albedo_offset + k];
}

// ---------------------------------------------------------------------------------------
// Density profiles (medium/profile.rs): per layer exp_term·exp(−h/H) + a·h + c, ≥ 0.

fn constituent_base(c: u32) -> u32 {
    return atm.constituent_offset + c * (1u + 2u * atm.groups);
}

fn constituent_scattering(c: u32, k: u32) -> vec4<f32> {
    return data[constituent_base(c) + 1u + k];
}

fn constituent_extinction(c: u32, k: u32) -> vec4<f32> {
    return data[constituent_base(c) + 1u + atm.groups + k];
}

fn layer_density(l: u32, altitude: f32) -> f32 {
    let a = data[l];
    let b = data[l + 1u];
    var e = 0.0;
    if (a.y != 0.0) {
        e = a.y * exp(-altitude * a.z);
    }
    return max(e + a.w * altitude + b.x, 0.0);
}

// Dimensionless density of constituent c at `altitude` km above the ground.
fn constituent_density(c: u32, altitude: f32) -> f32 {
    let info = data[constituent_base(c)];
    let first = atm.layer_offset + 2u * u32(info.x);
    let count = u32(info.y);
    var base = 0.0;
    for (var i = 0u; i < count; i++) {
        let l = first + 2u * i;
        let width = data[l].x;
        if (i + 1u == count || altitude < base + width) {
            return layer_density(l, altitude);
        }
        base += width;
    }
    return 0.0;
}

// Scattering coefficient (km⁻¹) of group g (0 molecules, 1 aerosols) at `altitude` km.
fn group_scattering(g: u32, altitude: f32, k: u32) -> vec4<f32> {
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < atm.constituents; c++) {
        let info = data[constituent_base(c)];
        if (i32(info.z) == i32(g)) {
            let rho = constituent_density(c, altitude);
            if (rho > 0.0) {
                out += rho * constituent_scattering(c, k);
            }
        }
    }
    return out;
}

// Extinction coefficient (km⁻¹) of the whole atmosphere at `altitude` km.
fn extinction(altitude: f32, k: u32) -> vec4<f32> {
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < atm.constituents; c++) {
        let rho = constituent_density(c, altitude);
        if (rho > 0.0) {
            out += rho * constituent_extinction(c, k);
        }
    }
    return out;
}

// ---------------------------------------------------------------------------------------
// Phase functions (medium/phase.rs), normalised to 1 over the sphere.

const INV_4PI: f32 = 0.0795774715459477;

fn hg(g: f32, mu: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) * INV_4PI / (d * sqrt(d));
}

fn tabulated_phase(offset: u32, count: u32, mu: f32) -> f32 {
    let t = acos(mu);
    // partition_point(theta ≤ t)
    var lo = 0u;
    var hi = count;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (data[offset + mid].x <= t) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let i = clamp(lo, 1u, count - 1u) - 1u;
    let a = data[offset + i];
    let b = data[offset + i + 1u];
    let f = clamp((t - a.x) / (b.x - a.x), 0.0, 1.0);
    return a.y + f * (b.y - a.y);
}

fn phase_eval(kind: u32, offset: u32, count: u32, a: f32, b: f32, c: f32, cos_theta: f32) -> f32 {
    let mu = clamp(cos_theta, -1.0, 1.0);
    switch kind {
        case 0u: {
            return INV_4PI;
        }
        case 1u: {
            // Rayleigh with depolarisation: 3/(4π(3a+b))·(a + bμ²).
            return 3.0 / (4.0 * PI * (3.0 * a + b)) * (a + b * mu * mu);
        }
        case 2u: {
            return hg(a, mu);
        }
        case 3u: {
            // Cornette–Shanks (Bruneton & Neyret 2008 eq. 4).
            let g2 = a * a;
            let d = 1.0 + g2 - 2.0 * a * mu;
            return 3.0 / (8.0 * PI) * (1.0 - g2) / (2.0 + g2) * (1.0 + mu * mu) / (d * sqrt(d));
        }
        case 4u: {
            // Schlick, a = k.
            let d = 1.0 - a * mu;
            return (1.0 - a * a) * INV_4PI / (d * d);
        }
        case 5u: {
            return c * hg(a, mu) + (1.0 - c) * hg(b, mu);
        }
        default: {
            return tabulated_phase(offset, count, mu);
        }
    }
}

// Phase function of scattering group g (0 molecules, 1 aerosols).
fn group_phase(g: u32, nu: f32) -> f32 {
    if (g == 0u) {
        return phase_eval(atm.phase0_kind, atm.phase0_offset, atm.phase0_count, atm.phase0_a, atm.phase0_b, atm.phase0_c, nu);
    }
    return phase_eval(atm.phase1_kind, atm.phase1_offset, atm.phase1_count, atm.phase1_a, atm.phase1_b, atm.phase1_c, nu);
}

// ---------------------------------------------------------------------------------------
// Ray geometry (geometry.rs), with ρ = sqrt(r² − R_g²) carried along.

fn safe_sqrt(x: f32) -> f32 {
    return sqrt(max(x, 0.0));
}

fn clamp_cosine(mu: f32) -> f32 {
    return clamp(mu, -1.0, 1.0);
}

// r from ρ.
fn radius_from_rho(rho: f32) -> f32 {
    return sqrt(rho * rho + atm.bottom_radius * atm.bottom_radius);
}

// Distance to the top along (r, μ): the positive root of d² + 2rμd + r² − R_t² = 0, in the
// form without cancellation for rays going up.
fn distance_to_top(r: f32, rho: f32, mu: f32) -> f32 {
    let c = max(atm.h_sq - rho * rho, 0.0);
    let root = safe_sqrt(r * r * mu * mu + c);
    if (mu > 0.0) {
        return c / (r * mu + root);
    }
    return max(-r * mu + root, 0.0);
}

// Distance to the ground along (r, μ) (the smaller root; meaningful for ground rays).
fn distance_to_bottom(r: f32, rho: f32, mu: f32) -> f32 {
    let root = safe_sqrt(r * r * mu * mu - rho * rho);
    let far = -r * mu + root;
    if (far > 0.0) {
        return max(rho * rho / far, 0.0);
    }
    return max(-r * mu - root, 0.0);
}

fn ray_intersects_ground(r: f32, rho: f32, mu: f32) -> bool {
    return mu < 0.0 && r * r * mu * mu - rho * rho >= 0.0;
}

// ρ at distance d along (r, μ), clamped into the atmosphere (geometry::advance).
fn rho_at(r: f32, rho: f32, mu: f32, d: f32) -> f32 {
    return sqrt(clamp(d * d + 2.0 * r * mu * d + rho * rho, 0.0, atm.h_sq));
}

// Altitude (km) of a point given its ρ and r: (r² − R_g²)/(r + R_g).
fn altitude_of(rho: f32, r: f32) -> f32 {
    return rho * rho / (r + atm.bottom_radius);
}

// ---------------------------------------------------------------------------------------
// Parameterisations (lut/params.rs).

fn texcoord_from_unit(x: f32, n: u32) -> f32 {
    return 0.5 / f32(n) + x * (1.0 - 1.0 / f32(n));
}

// Transmittance table (u, v) for (r, μ).
fn transmittance_uv(r: f32, rho: f32, mu: f32) -> vec2<f32> {
    let d = distance_to_top(r, rho, mu);
    let d_min = (atm.h_sq - rho * rho) / (atm.top_radius + r);
    let d_max = rho + atm.h;
    var x_mu = 0.0;
    if (d_max > d_min) {
        x_mu = (d - d_min) / (d_max - d_min);
    }
    return vec2<f32>(texcoord_from_unit(x_mu, atm.transmittance_mu), texcoord_from_unit(rho / atm.h, atm.transmittance_r));
}

// (r, ρ, μ) at the centre of transmittance texel (x, y).
fn transmittance_texel(x: u32, y: u32) -> vec3<f32> {
    let x_mu = f32(x) / f32(atm.transmittance_mu - 1u);
    let x_r = f32(y) / f32(atm.transmittance_r - 1u);
    let rho = atm.h * x_r;
    let r = radius_from_rho(rho);
    let d_min = (atm.h_sq - rho * rho) / (atm.top_radius + r);
    let d_max = rho + atm.h;
    let d = d_min + x_mu * (d_max - d_min);
    var mu = 1.0;
    if (d != 0.0) {
        mu = clamp_cosine((atm.h_sq - rho * rho - d * d) / (2.0 * r * d));
    }
    return vec3<f32>(r, rho, mu);
}

// Irradiance table: (u, v) for (altitude, μ_s), linear in both.
fn irradiance_uv(altitude: f32, mu_s: f32) -> vec2<f32> {
    let x_r = altitude / (atm.top_radius - atm.bottom_radius);
    let x_mu_s = mu_s * 0.5 + 0.5;
    return vec2<f32>(texcoord_from_unit(x_mu_s, atm.irradiance_mu_s), texcoord_from_unit(x_r, atm.irradiance_r));
}

// (r, ρ, μ_s) at the centre of irradiance texel (x, y).
fn irradiance_texel(x: u32, y: u32) -> vec3<f32> {
    let x_mu_s = f32(x) / f32(atm.irradiance_mu_s - 1u);
    let x_r = f32(y) / f32(atm.irradiance_r - 1u);
    let altitude = x_r * (atm.top_radius - atm.bottom_radius);
    let r = atm.bottom_radius + altitude;
    let rho = sqrt(altitude * (r + atm.bottom_radius));
    return vec3<f32>(r, rho, clamp_cosine(2.0 * x_mu_s - 1.0));
}

// The non-linear μ_s coordinate in [0, 1] (params::x_mu_s).
fn x_mu_s(mu_s: f32) -> f32 {
    let d_min = atm.top_radius - atm.bottom_radius;
    let d_max = atm.h;
    let d = distance_to_top(atm.bottom_radius, 0.0, mu_s);
    let a = (d - d_min) / (d_max - d_min);
    return clamp(max(1.0 - a / atm.mu_s_big_a, 0.0) / (1.0 + a), 0.0, 1.0);
}

fn mu_s_from_x(x: f32) -> f32 {
    let d_min = atm.top_radius - atm.bottom_radius;
    let d_max = atm.h;
    let big_a = atm.mu_s_big_a;
    let a = (big_a - x * big_a) / (1.0 + x * big_a);
    let d = d_min + min(a, big_a) * (d_max - d_min);
    if (d == 0.0) {
        return 1.0;
    }
    return clamp_cosine((atm.h_sq - d * d) / (2.0 * atm.bottom_radius * d));
}

// (u_ν, u_μs, u_μ, u_r) of the scattering table (params::scattering_uvwz).
fn scattering_uvwz(r: f32, rho: f32, mu: f32, mu_s: f32, nu: f32, ground: bool) -> vec4<f32> {
    let u_r = texcoord_from_unit(rho / atm.h, atm.scattering_r);
    let u_mu = scattering_u_mu(r, rho, mu, ground);
    let u_mu_s = texcoord_from_unit(x_mu_s(mu_s), atm.scattering_mu_s);
    return vec4<f32>(u_nu_from_nu(mu, mu_s, nu), u_mu_s, u_mu, u_r);
}

// The u_μ coordinate alone (params::scattering_u_mu): the distance to the ground mapped to
// the lower half for rays that hit it, the distance to the top to the upper half otherwise.
fn scattering_u_mu(r: f32, rho: f32, mu: f32, ground: bool) -> f32 {
    let half = atm.scattering_mu / 2u;
    if (ground) {
        let d = distance_to_bottom(r, rho, mu);
        let d_min = rho * rho / (r + atm.bottom_radius);
        let d_max = rho;
        // x = √f of the distance fraction (params::ground_x_from_distance_fraction).
        var x = 0.0;
        if (d_max != d_min) {
            x = sqrt(clamp((d - d_min) / (d_max - d_min), 0.0, 1.0));
        }
        return 0.5 - 0.5 * texcoord_from_unit(x, half);
    }
    let d = distance_to_top(r, rho, mu);
    let d_min = (atm.h_sq - rho * rho) / (atm.top_radius + r);
    let d_max = rho + atm.h;
    var x = 0.0;
    if (d_max > d_min) {
        x = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
    }
    return 0.5 + 0.5 * texcoord_from_unit(x, half);
}

// A scattering texel's parameters.
struct ScatteringTexel {
    r: f32,
    rho: f32,
    mu: f32,
    mu_s: f32,
    nu: f32,
    ground: bool,
}

// (r, ρ, μ, μ_s, ν, ground) at the centre of texel (x = ν·N_μs + μ_s, y = μ, z = r), ν
// clamped to the range μ and μ_s allow (params::scattering_texel). Texel centres map to
// exact unit coordinates i/(n − 1).
fn scattering_texel(x: u32, y: u32, z: u32) -> ScatteringTexel {
    var t: ScatteringTexel;
    let i_nu = x / atm.scattering_mu_s;
    let i_mu_s = x % atm.scattering_mu_s;
    t.rho = atm.h * f32(z) / f32(atm.scattering_r - 1u);
    t.r = radius_from_rho(t.rho);
    let half = atm.scattering_mu / 2u;
    if (y < half) {
        let x_mu = f32(half - 1u - y) / f32(half - 1u);
        let d_min = t.rho * t.rho / (t.r + atm.bottom_radius);
        let d_max = t.rho;
        let d = d_min + (d_max - d_min) * x_mu * x_mu;
        t.mu = -1.0;
        if (d != 0.0) {
            t.mu = clamp_cosine(-(t.rho * t.rho + d * d) / (2.0 * t.r * d));
        }
        t.ground = true;
    } else {
        let x_mu = f32(y - half) / f32(half - 1u);
        let d_min = (atm.h_sq - t.rho * t.rho) / (atm.top_radius + t.r);
        let d_max = t.rho + atm.h;
        let d = d_min + (d_max - d_min) * x_mu;
        t.mu = 1.0;
        if (d != 0.0) {
            t.mu = clamp_cosine((atm.h_sq - t.rho * t.rho - d * d) / (2.0 * t.r * d));
        }
        t.ground = false;
    }
    t.mu_s = mu_s_from_x(f32(i_mu_s) / f32(atm.scattering_mu_s - 1u));
    // ν from u_ν once μ and μ_s are known (params::scattering_r_mu_mu_s_nu).
    let nu = nu_from_u_nu(t.mu, t.mu_s, f32(i_nu) / f32(atm.scattering_nu - 1u));
    let spread = sqrt(max((1.0 - t.mu * t.mu) * (1.0 - t.mu_s * t.mu_s), 0.0));
    t.nu = clamp(nu, t.mu * t.mu_s - spread, t.mu * t.mu_s + spread);
    return t;
}

fn scattering_width() -> u32 {
    return atm.scattering_nu * atm.scattering_mu_s;
}

fn scattering_texels() -> u32 {
    return scattering_width() * atm.scattering_mu * atm.scattering_r;
}

// ---------------------------------------------------------------------------------------
// Filtering with GPU texture semantics (lut/table.rs), done by hand on storage buffers so
// the weights are exact f32 (hardware samplers quantise them).

// (i0, i1, t) of linear filtering at texture coordinate u over n texels (clamp to edge).
struct Lerp {
    i0: u32,
    i1: u32,
    t: f32,
}

fn lerp_weights(u: f32, n: u32) -> Lerp {
    let x = clamp(u * f32(n) - 0.5, 0.0, f32(n - 1u));
    var l: Lerp;
    l.i0 = min(u32(floor(x)), n - 1u);
    l.i1 = min(l.i0 + 1u, n - 1u);
    l.t = x - f32(l.i0);
    return l;
}

// The 16 texels and weights of a 4D scattering lookup (Table4::sample_rows_into): trilinear
// in (μ_s, μ, r) at the two nearest ν slices, then a lerp in ν. Texel (i, j) is
// row[i] + col[j] with weight wrow[i]·wcol[j]: rows are the (r, μ) pairs (z0 y0, z0 y1,
// z1 y0, z1 y1), columns the (ν, μ_s) pairs (ν0 s0, ν0 s1, ν1 s0, ν1 s1). Vectors, not
// arrays: no dynamically indexed private memory (slow on software rasterisers).
struct Filter4 {
    row: vec4<u32>,
    col: vec4<u32>,
    wrow: vec4<f32>,
    wcol: vec4<f32>,
}

fn scattering_filter_rows(u_nu: f32, u_mu_s: f32, ly: Lerp, lz: Lerp) -> Filter4 {
    let nnu = atm.scattering_nu;
    let nmu_s = atm.scattering_mu_s;
    let tex_x = u_nu * f32(nnu - 1u);
    let nu0 = min(u32(floor(tex_x)), nnu - 1u);
    let nu1 = min(nu0 + 1u, nnu - 1u);
    let tnu = tex_x - f32(nu0);
    let ls = lerp_weights(u_mu_s, nmu_s);
    let width = scattering_width();
    let z = vec4<u32>(lz.i0, lz.i0, lz.i1, lz.i1);
    let y = vec4<u32>(ly.i0, ly.i1, ly.i0, ly.i1);
    let n = vec4<u32>(nu0, nu0, nu1, nu1);
    let ms = vec4<u32>(ls.i0, ls.i1, ls.i0, ls.i1);
    var f: Filter4;
    f.row = (z * atm.scattering_mu + y) * width;
    f.col = n * nmu_s + ms;
    f.wrow = vec4<f32>(1.0 - lz.t, 1.0 - lz.t, lz.t, lz.t) * vec4<f32>(1.0 - ly.t, ly.t, 1.0 - ly.t, ly.t);
    f.wcol = vec4<f32>(1.0 - tnu, 1.0 - tnu, tnu, tnu) * vec4<f32>(1.0 - ls.t, ls.t, 1.0 - ls.t, ls.t);
    return f;
}

fn scattering_filter(uvwz: vec4<f32>) -> Filter4 {
    return scattering_filter_rows(uvwz.x, uvwz.y, lerp_weights(uvwz.z, atm.scattering_mu), lerp_weights(uvwz.w, atm.scattering_r));
}

// Bilinear filter of a 2D table: the four texels (vec4 indices without the group) and weights.
struct Filter2 {
    index: vec4<u32>,
    weight: vec4<f32>,
}

fn table2_filter(uv: vec2<f32>, width: u32, height: u32) -> Filter2 {
    let lx = lerp_weights(uv.x, width);
    let ly = lerp_weights(uv.y, height);
    var f: Filter2;
    f.index = vec4<u32>(ly.i0 * width + lx.i0, ly.i0 * width + lx.i1, ly.i1 * width + lx.i0, ly.i1 * width + lx.i1) * atm.groups;
    f.weight = vec4<f32>((1.0 - lx.t) * (1.0 - ly.t), lx.t * (1.0 - ly.t), (1.0 - lx.t) * ly.t, lx.t * ly.t);
    return f;
}

// ---------------------------------------------------------------------------------------
// Quadrature along view rays (lut::precompute::RaySamples): 50 intervals, integrated pair of
// intervals by pair with an exponentially fitted Simpson rule (a Filon-type product rule):
// ∫ g(d)·T(d) dd with the transmittance T factored out as an exponential over each pair and
// g quadratic, exact for g quadratic and T exponential, Simpson's rule as Δτ → 0. Plain
// Simpson on g·T overestimates optically thick intervals (horizontal rays near the ground
// in the blue). The end weight of a pair with Δτ > 2.9 is slightly negative, so the passes
// clamp their sums at 0 (as the CPU does). Per channel, on the four lanes of a channel group
// at once.

// ∫₀² e^{−a·s} L_j(s) ds for the quadratic Lagrange basis on the nodes 0, 1, 2, per lane
// (lut::precompute::lagrange_exponential_moments): a series for a < 1 (no cancellation for
// small a), the closed form above. In f32 the switch at a = 1 is also the most accurate one
// (largest error 8e-7 of ∫₀² e^{−a·s} ds over a ∈ [0, 60], against 6e-6 switching at 2 and
// 2e-6 at 0.5); 16 terms of the series, not the CPU's 30: the 17th is below 2e-9.
struct Moments {
    m0: vec4<f32>,
    m1: vec4<f32>,
    m2: vec4<f32>,
}

// For a < 0 by the reflection s → 2 − s: M_j(a) = e^{−2a}·M_{2−j}(−a).
fn lagrange_exponential_moments(a_signed: vec4<f32>) -> Moments {
    let a = abs(a_signed);
    // I_m = ∫₀² s^m e^{−a·s} ds. Series Σ_k (−a)^k/k! · 2^{m+k+1}/(m+k+1), on lanes a < 1
    // (the others evaluate it at a = 1, unused).
    let a_series = min(a, vec4<f32>(1.0));
    var s0 = vec4<f32>(0.0);
    var s1 = vec4<f32>(0.0);
    var s2 = vec4<f32>(0.0);
    var c = vec4<f32>(1.0); // (−a)^k/k! · 2^k
    for (var k = 0u; k < 16u; k++) {
        let kf = f32(k);
        s0 += c * (2.0 / (kf + 1.0));
        s1 += c * (4.0 / (kf + 2.0));
        s2 += c * (8.0 / (kf + 3.0));
        c *= -2.0 * a_series / (kf + 1.0);
    }
    // Closed form, on lanes a ≥ 1 (the others evaluate it at a = 1, unused).
    let b = max(a, vec4<f32>(1.0));
    let e = exp(-2.0 * b);
    let c0 = (1.0 - e) / b;
    let c1 = (1.0 - e * (1.0 + 2.0 * b)) / (b * b);
    let c2 = (2.0 - e * (2.0 + 4.0 * b + 4.0 * b * b)) / (b * b * b);
    let series = a < vec4<f32>(1.0);
    let i0 = select(c0, s0, series);
    let i1 = select(c1, s1, series);
    let i2 = select(c2, s2, series);
    let p0 = 0.5 * (i2 - 3.0 * i1 + 2.0 * i0);
    let p1 = 2.0 * i1 - i2;
    let p2 = 0.5 * (i2 - i1);
    let negative = a_signed < vec4<f32>(0.0);
    let reflect = exp(select(vec4<f32>(0.0), 2.0 * a, negative));
    var m: Moments;
    m.m0 = select(p0, reflect * p2, negative);
    m.m1 = reflect * p1;
    m.m2 = select(p2, reflect * p0, negative);
    return m;
}

// Weights (in units of the step) on the three samples of one pair of intervals, per lane,
// from their transmittances T and the fitted quantity F = β·T (lut::precompute::
// exponential_simpson_weights, one pair): a = ln(F_0/F_2)/2 (ln(F_0/F_1) when F_2 = 0, 0
// when F_1 = 0 too; from T the same way where F_0 = 0) clamped to [−30, 300], weights
// T_0·M_0, T_1·e^a·M_1, T_2·e^{2a}·M_2; all 0 when T_0 ≤ 0. T_j·e^{j·a} is taken as
// exp(ln T_j + j·a): e^{2a} alone leaves f32 when T_2 is below ~1e-38.
struct PairWeights {
    w0: vec4<f32>,
    w1: vec4<f32>,
    w2: vec4<f32>,
}

// The decay rate per step through a pair's samples v (see exponential_simpson_weights).
fn pair_rate(v0: vec4<f32>, v1: vec4<f32>, v2: vec4<f32>) -> vec4<f32> {
    let zero = vec4<f32>(0.0);
    let one = vec4<f32>(1.0);
    let l0 = log(select(one, v0, v0 > zero));
    let l1 = log(select(one, v1, v1 > zero));
    let l2 = log(select(one, v2, v2 > zero));
    return select(select(zero, l0 - l1, v1 > zero), 0.5 * (l0 - l2), v2 > zero);
}

fn exponential_simpson_weights(t0: vec4<f32>, t1: vec4<f32>, t2: vec4<f32>, f0: vec4<f32>, f1: vec4<f32>, f2: vec4<f32>) -> PairWeights {
    let zero = vec4<f32>(0.0);
    let one = vec4<f32>(1.0);
    let p0 = t0 > zero;
    let p1 = t1 > zero;
    let p2 = t2 > zero;
    let l1 = log(select(one, t1, p1));
    let l2 = log(select(one, t2, p2));
    let rate = select(pair_rate(t0, t1, t2), pair_rate(f0, f1, f2), f0 > zero);
    let a = clamp(rate, vec4<f32>(-30.0), vec4<f32>(300.0));
    let m = lagrange_exponential_moments(a);
    var w: PairWeights;
    w.w0 = select(zero, t0 * m.m0, p0);
    // Exponents only where T_j > 0 (no infinities in unused lanes).
    w.w1 = select(zero, exp(select(zero, l1 + a, p1)) * m.m1, p0 & p1);
    w.w2 = select(zero, exp(select(zero, l2 + 2.0 * a, p2)) * m.m2, p0 & p2);
    return w;
}

// GLSL smoothstep with the CPU's handling of an empty edge interval.
fn smoothstep_safe(e0: f32, e1: f32, x: f32) -> f32 {
    if (e1 <= e0) {
        return select(1.0, 0.0, x < e0);
    }
    let t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// ---------------------------------------------------------------------------------------
// Table lookups (lut/context.rs). Passes bind the tables they read at these slots.

// Slot 3 holds the optical depth τ(r, μ) = −ln T to the top (Tables::optical_depth);
// lookups interpolate τ and take e^{−τ}.
@group(0) @binding(3) var<storage, read> transmittance_table: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> delta_irradiance_table: array<vec4<f32>>;
// Order 2: ΔS_Rayleigh and ΔS_Mie (single scattering); order ≥ 3: ΔS twice. Also ΔJ for the
// multiple-scattering pass (slot a).
@group(0) @binding(5) var<storage, read> scattering_a: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> scattering_b: array<vec4<f32>>;

// The optical depth the table stands for T = 0 with (table::MAX_OPTICAL_DEPTH).
const MAX_OPTICAL_DEPTH: f32 = 104.0;

// τ(r, μ) to the top of the atmosphere (Lookup::optical_depth_to_top).
fn optical_depth_to_top(r: f32, rho: f32, mu: f32, k: u32) -> vec4<f32> {
    let f = table2_filter(transmittance_uv(r, rho, mu), atm.transmittance_mu, atm.transmittance_r);
    return f.weight.x * transmittance_table[f.index.x + k] + f.weight.y * transmittance_table[f.index.y + k]
        + f.weight.z * transmittance_table[f.index.z + k] + f.weight.w * transmittance_table[f.index.w + k];
}

// T(r, μ) to the top of the atmosphere (ray assumed not to hit the ground).
fn transmittance_to_top(r: f32, rho: f32, mu: f32, k: u32) -> vec4<f32> {
    return exp(-optical_depth_to_top(r, rho, mu, k));
}

// e^{−(τ_a − τ_b)} for the optical depths to the top from a ray's two ends, 0 where the far
// end's τ stands for T = 0 (Lookup::transmittance).
fn transmittance_between(tau_a: vec4<f32>, tau_b: vec4<f32>) -> vec4<f32> {
    return select(vec4<f32>(0.0), exp(-max(tau_a - tau_b, vec4<f32>(0.0))), tau_b < vec4<f32>(MAX_OPTICAL_DEPTH));
}

// Transmittance over d km from (r, μ), from differences of table optical depths; the
// reversed ray when it hits the ground (Bruneton 2017 `GetTransmittance`).
fn transmittance(r: f32, rho: f32, mu: f32, d: f32, ground: bool, k: u32) -> vec4<f32> {
    let rho_d = rho_at(r, rho, mu, d);
    let r_d = radius_from_rho(rho_d);
    let mu_d = clamp_cosine((r * mu + d) / r_d);
    var a: vec4<f32>;
    var b: vec4<f32>;
    if (ground) {
        a = optical_depth_to_top(r_d, rho_d, -mu_d, k);
        b = optical_depth_to_top(r, rho, -mu, k);
    } else {
        a = optical_depth_to_top(r, rho, mu, k);
        b = optical_depth_to_top(r_d, rho_d, mu_d, k);
    }
    return transmittance_between(a, b);
}

// Visible fraction of the sun's disk above the planet (smoothstep in μ_s over ± the sun's
// angular radius around the horizon).
fn sun_visible_fraction(r: f32, rho: f32, mu_s: f32) -> f32 {
    let sin_theta_h = atm.bottom_radius / r;
    let cos_theta_h = -rho / r;
    let e = sin_theta_h * atm.sun_angular_radius;
    return smoothstep_safe(-e, e, mu_s - cos_theta_h);
}

// Transmittance to the sun times its visible fraction (Bruneton 2017 `GetTransmittanceToSun`).
fn transmittance_to_sun(r: f32, rho: f32, mu_s: f32, k: u32) -> vec4<f32> {
    let fraction = sun_visible_fraction(r, rho, mu_s);
    if (fraction <= 0.0) {
        return vec4<f32>(0.0);
    }
    return transmittance_to_top(r, rho, mu_s, k) * fraction;
}

// ΔE at (altitude, μ_s).
fn delta_irradiance(altitude: f32, mu_s: f32, k: u32) -> vec4<f32> {
    let f = table2_filter(irradiance_uv(altitude, mu_s), atm.irradiance_mu_s, atm.irradiance_r);
    return f.weight.x * delta_irradiance_table[f.index.x + k] + f.weight.y * delta_irradiance_table[f.index.y + k]
        + f.weight.z * delta_irradiance_table[f.index.z + k] + f.weight.w * delta_irradiance_table[f.index.w + k];
}

// Σ over the four (ν, μ_s) columns of one (r, μ) row, channel group k.
fn scattering_a_row(f: Filter4, row: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    return f.wcol.x * scattering_a[(row + f.col.x) * g + k] + f.wcol.y * scattering_a[(row + f.col.y) * g + k]
        + f.wcol.z * scattering_a[(row + f.col.z) * g + k] + f.wcol.w * scattering_a[(row + f.col.w) * g + k];
}

fn scattering_b_row(f: Filter4, row: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    return f.wcol.x * scattering_b[(row + f.col.x) * g + k] + f.wcol.y * scattering_b[(row + f.col.y) * g + k]
        + f.wcol.z * scattering_b[(row + f.col.z) * g + k] + f.wcol.w * scattering_b[(row + f.col.w) * g + k];
}

fn sample_scattering_a(f: Filter4, k: u32) -> vec4<f32> {
    return f.wrow.x * scattering_a_row(f, f.row.x, k) + f.wrow.y * scattering_a_row(f, f.row.y, k)
        + f.wrow.z * scattering_a_row(f, f.row.z, k) + f.wrow.w * scattering_a_row(f, f.row.w, k);
}

fn sample_scattering_b(f: Filter4, k: u32) -> vec4<f32> {
    return f.wrow.x * scattering_b_row(f, f.row.x, k) + f.wrow.y * scattering_b_row(f, f.row.y, k)
        + f.wrow.z * scattering_b_row(f, f.row.z, k) + f.wrow.w * scattering_b_row(f, f.row.w, k);
}

// Radiance of the previous order towards (r, μ) for the sun at (μ_s, ν): single scattering
// with the phase functions applied (mode 0), or ΔS (mode 1).
fn previous_radiance(r: f32, rho: f32, mu: f32, mu_s: f32, nu: f32, ground: bool, k: u32) -> vec4<f32> {
    let f = scattering_filter(scattering_uvwz(r, rho, mu, mu_s, nu, ground));
    if (pass_params.mode == 0u) {
        return sample_scattering_a(f, k) * group_phase(0u, nu) + sample_scattering_b(f, k) * group_phase(1u, nu);
    }
    return sample_scattering_a(f, k);
}

// The ν coordinate relative to the range of ν that (μ, μ_s) allow (params::u_nu): the
// azimuth φ between the view and the sun around the zenith, cos φ = (ν − μμ_s)/s with
// s = sqrt((1 − μ²)(1 − μ_s²)), and u_ν = 1 − sin(φ/2). (1 − μ)(1 + μ) for 1 − μ²: the
// same value, without the cancellation of f32 near μ = ±1.
fn u_nu_from_nu(mu: f32, mu_s: f32, nu: f32) -> f32 {
    let s = sqrt(max((1.0 - mu) * (1.0 + mu) * (1.0 - mu_s) * (1.0 + mu_s), 0.0));
    if (s <= 1e-12) {
        // φ is undefined and every u_ν holds the same value.
        return 1.0;
    }
    // (1 − cos φ)/2 = sin²(φ/2).
    let x = clamp((mu * mu_s + s - nu) / (2.0 * s), 0.0, 1.0);
    return 1.0 - sqrt(x);
}

// Inverse of u_nu_from_nu at (μ, μ_s) (params::nu_from_u_nu).
fn nu_from_u_nu(mu: f32, mu_s: f32, u_nu: f32) -> f32 {
    let s = sqrt(max((1.0 - mu) * (1.0 + mu) * (1.0 - mu_s) * (1.0 + mu_s), 0.0));
    let x = 1.0 - clamp(u_nu, 0.0, 1.0);
    return clamp_cosine(mu * mu_s + s * (1.0 - 2.0 * x * x));
}
