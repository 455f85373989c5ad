// The ray march of Hillaire 2020 (firmament::sky::hillaire2020::march; §4, eq. 1–5, and the
// released demo's `IntegrateScatteredLuminance`): along a ray, at samples spread
// quadratically from its start, the light scattered once from the light (its transmittance
// from the optical-depth table, the planet's shadow included) and the multiple scattering
// σ_s·Ψ_ms (eq. 10), each step integrated analytically over its length with the sample's
// extinction, ∫₀^Δ S·e^{−σ_t t} dt = S·(1 − e^{−σ_t Δ})/σ_t (Hillaire 2015's
// energy-conserving step), times the throughput so far. Per unit light irradiance at the top
// of the atmosphere, channel group k; lengths in km, coefficients in km⁻¹.

// Ψ_ms per unit light irradiance, as the multiple-scattering pass leaves it: (μ_s, altitude)
// texel i, coefficient c (harmonics.wgsl), channel group k at (i·ms_coefficients + c)·groups
// + k (MultipleScattering::table, coefficient-major as on the CPU). In the gathers of the
// higher orders (multiple_scattering.wgsl), the previous order's field.
@group(0) @binding(20) var<storage, read> multiple_scattering_table: array<vec4<f32>>;

// The air at an altitude (Medium::coefficients): the extinction σ_t and the scattering σ_s of
// each scattering group (km⁻¹), channel group k. A group's constituents share its phase
// function (firmament_gpu::hillaire2020::config refuses atmospheres where they do not).
struct Coefficients {
    sigma_t: vec4<f32>,
    molecules: vec4<f32>,
    aerosols: vec4<f32>,
}

// The coefficients at `altitude_km`, channel group k (one pass over the constituents).
fn coefficients(altitude_km: f32, k: u32) -> Coefficients {
    var c: Coefficients;
    for (var i = 0u; i < atm.constituents; i++) {
        let density = constituent_density(i, altitude_km);
        if (density <= 0.0) {
            continue;
        }
        c.sigma_t += density * constituent_extinction(i, k);
        let group = i32(data[constituent_base(i)].z);
        if (group == 0) {
            c.molecules += density * constituent_scattering(i, k);
        } else if (group == 1) {
            c.aerosols += density * constituent_scattering(i, k);
        }
    }
    return c;
}

// A ray in the atmosphere (MarchRay): its start's (r, ρ), the zenith cosines μ of its
// direction and μ_s of the light there, ν = cos(view, light), its length to the boundary it
// ends on or to the point it is marched to, and the light's angular radius (rad; the
// visible fraction of its disk above the horizon: the model's sun in the passes, the
// frame's light in views).
struct MarchRay {
    r_km: f32,
    rho_km: f32,
    mu: f32,
    mu_s: f32,
    nu: f32,
    length_km: f32,
    angular_radius: f32,
}

// (r, ρ, μ_s) `t_km` along the ray (MarchRay::at), ρ² = t² + 2rμt + ρ₀² without the
// cancellation of r² − R_g².
fn march_at(ray: MarchRay, t_km: f32) -> vec3<f32> {
    let rho_sq = max(t_km * t_km + 2.0 * ray.r_km * ray.mu * t_km + ray.rho_km * ray.rho_km, 0.0);
    let r_km = sqrt(rho_sq + atm.bottom_radius_km * atm.bottom_radius_km);
    let mu_s = clamp_cosine((ray.r_km * ray.mu_s + t_km * ray.nu) / max(r_km, 1e-3));
    return vec3<f32>(r_km, sqrt(rho_sq), mu_s);
}

// One lit interval [start, end] (km from the ray's start; Lit::Intervals with one interval,
// the shadowed length of a frame): (−∞, ∞) for Lit::All.
struct Lit {
    start_km: f32,
    end_km: f32,
}

// Lit::All.
fn lit_all() -> Lit {
    return Lit(-3.4e38, 3.4e38);
}

// Lit::Intervals(&[]): nowhere (the higher orders' gathers, which have no single
// scattering).
fn lit_none() -> Lit {
    return Lit(-1.0, -1.0);
}

// The fraction of [a, b] that is lit (Lit::fraction).
fn lit_fraction(lit: Lit, a: f32, b: f32) -> f32 {
    if (b <= a) {
        return 0.0;
    }
    return clamp((min(lit.end_km, b) - max(lit.start_km, a)) / (b - a), 0.0, 1.0);
}

// What lights the march: the single scattering's and the multiple scattering's lit parts
// (Lighting).
struct Lighting {
    single: Lit,
    multiple: Lit,
}

// Lighting::ALL.
fn lighting_all() -> Lighting {
    return Lighting(lit_all(), lit_all());
}

// The distance from the start to the far end of step i of `steps` over `length_km`,
// quadratic (step_end).
fn step_end(i: u32, steps: u32, length_km: f32) -> f32 {
    let f = f32(i) / f32(steps);
    return length_km * f * f;
}

// Δ·(1 − e^{−τ})/τ for a step of length Δ and optical depth τ = σ_t·Δ, per lane (the march's
// (1 − e^{−σ_t Δ})/σ_t, → Δ as σ_t → 0): below τ = 0.01 its series, where f32's 1 − e^{−τ}
// loses digits (the CPU, in f64, divides directly above τ = 1e-9).
fn step_length(tau: vec4<f32>, dt_km: f32) -> vec4<f32> {
    let series = 1.0 - tau * (0.5 - tau * (1.0 / 6.0 - tau / 24.0));
    let closed = (1.0 - exp(-tau)) / max(tau, vec4<f32>(1e-30));
    return dt_km * select(closed, series, tau < vec4<f32>(0.01));
}

// Lookup::sun_visible_fraction for a light of `angular_radius` (rad) at (r, ρ, μ_s):
// smoothstep in μ_s over ± its angular radius around the horizon (cos θ_h = −ρ/r).
fn light_visible_fraction(r_km: f32, rho_km: f32, mu_s: f32, angular_radius: f32) -> f32 {
    let e = atm.bottom_radius_km / r_km * angular_radius;
    return smoothstep_safe(-e, e, mu_s + rho_km / r_km);
}

// Lookup::transmittance_to_sun for that light, channel group k.
fn transmittance_to_light_at(r_km: f32, rho_km: f32, mu_s: f32, angular_radius: f32, k: u32) -> vec4<f32> {
    let fraction = light_visible_fraction(r_km, rho_km, mu_s, angular_radius);
    if (fraction <= 0.0) {
        return vec4<f32>(0.0);
    }
    return transmittance_to_top(r_km, rho_km, mu_s, k) * fraction;
}

// Group g's phase moment k_ℓ (MultipleScattering::moments; 1 for the isotropic model).
fn phase_moment(g: u32, l: u32) -> f32 {
    return hillaire_data[hillaire.moments_offset + g * hillaire.moments_stride + l].x;
}

// σ_s·Ψ_ms at a step (Marcher::march's multiple-scattering source): the field bilinear at
// (altitude, μ_s), each coefficient seen through each group's phase function by its moment
// (Funk–Hecke) along the ray's direction in the step's frame (zenith cosine `mu_v`, azimuth
// cosine `cos_phi` from the light's), channel group k.
fn multiple_scattering_source(altitude_km: f32, mu_s: f32, mu_v: f32, cos_phi: f32, c: Coefficients, k: u32) -> vec4<f32> {
    let w = hillaire.ms_mu_s;
    let uv = altitude_mu_s_uv(altitude_km, mu_s, w, hillaire.ms_r);
    let lx = lerp_weights(uv.x, w);
    let ly = lerp_weights(uv.y, hillaire.ms_r);
    let n = hillaire.ms_coefficients;
    let texels = vec4<u32>(ly.i0 * w + lx.i0, ly.i0 * w + lx.i1, ly.i1 * w + lx.i0, ly.i1 * w + lx.i1) * n;
    let weights = vec4<f32>((1.0 - lx.t) * (1.0 - ly.t), lx.t * (1.0 - ly.t), (1.0 - lx.t) * ly.t, lx.t * ly.t);
    let g = atm.groups;
    var psi = vec4<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        let lm = harmonic_degree_order(i);
        let field = weights.x * multiple_scattering_table[(texels.x + i) * g + k]
            + weights.y * multiple_scattering_table[(texels.y + i) * g + k]
            + weights.z * multiple_scattering_table[(texels.z + i) * g + k]
            + weights.w * multiple_scattering_table[(texels.w + i) * g + k];
        let moment = phase_moment(0u, lm.x) * c.molecules + phase_moment(1u, lm.x) * c.aerosols;
        psi += moment * harmonic(lm.x, lm.y, mu_v, cos_phi) * field;
    }
    return psi;
}

// What a march returns (Marcher::march's outputs): the radiance per unit light irradiance,
// the ray's throughput, and ∫ T·σ_s dt (what f_ms sums, Hillaire's eq. 8 before its phase).
struct March {
    radiance: vec4<f32>,
    transmittance: vec4<f32>,
    scattered: vec4<f32>,
}

// Marcher::march along `ray` in `steps` steps, channel group k: `phases` holds the molecules'
// and the aerosols' phase functions at the ray's ν, `lighting` the lit parts, `multiple`
// whether to add the multiple-scattering field (false in the multiple-scattering pass).
fn march(ray: MarchRay, steps: u32, phases: vec2<f32>, lighting: Lighting, multiple: bool, k: u32) -> March {
    var m: March;
    m.radiance = vec4<f32>(0.0);
    m.transmittance = vec4<f32>(1.0);
    m.scattered = vec4<f32>(0.0);
    if (ray.length_km <= 0.0) {
        return m;
    }
    var t0 = 0.0;
    for (var i = 1u; i <= steps; i++) {
        let t1 = step_end(i, steps, ray.length_km);
        let dt = t1 - t0;
        let t_mid = 0.5 * (t0 + t1);
        let at = march_at(ray, t_mid);
        let altitude_km = altitude_of(at.y, at.x);
        let c = coefficients(altitude_km, k);
        let lit_single = lit_fraction(lighting.single, t0, t1);
        let lit_multiple = lit_fraction(lighting.multiple, t0, t1);
        var source = vec4<f32>(0.0);
        if (lit_single > 0.0) {
            let t_light = transmittance_to_light_at(at.x, at.y, at.z, ray.angular_radius, k);
            source = lit_single * (phases.x * c.molecules + phases.y * c.aerosols) * t_light;
        }
        if (multiple && lit_multiple > 0.0) {
            // The ray's direction in the step's frame, where the field's harmonics are
            // expressed (degree 0 needs none).
            var mu_v = 1.0;
            var cos_phi = 1.0;
            if (hillaire.ms_degree > 0u) {
                mu_v = clamp_cosine((ray.r_km * ray.mu + t_mid) / max(at.x, 1e-3));
                let sines = safe_sqrt((1.0 - mu_v * mu_v) * (1.0 - at.z * at.z));
                if (sines > 1e-12) {
                    cos_phi = clamp_cosine((ray.nu - mu_v * at.z) / sines);
                }
            }
            source += lit_multiple * multiple_scattering_source(altitude_km, at.z, mu_v, cos_phi, c, k);
        }
        let tau = c.sigma_t * dt;
        let span = step_length(tau, dt);
        m.radiance += m.transmittance * source * span;
        m.scattered += m.transmittance * (c.molecules + c.aerosols) * span;
        m.transmittance *= exp(-tau);
        t0 = t1;
    }
    return m;
}
