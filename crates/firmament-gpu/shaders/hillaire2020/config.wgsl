// Hillaire 2020's sizes and sample counts (firmament::sky::hillaire2020::HillaireConfig) and
// its per-atmosphere data, as firmament_gpu::hillaire2020::config packs them (same field
// order). The atmosphere itself is the common `Atmosphere` uniform (its transmittance sizes
// are Hillaire's), so the 4D lookups (bruneton4d/lookup.wgsl) read the optical depth.

struct Hillaire {
    // Ψ_ms table: (μ_s, altitude) texels, the field's spherical-harmonic degree (0: the
    // isotropic model) and its coefficients per texel and channel group: the field the
    // march reads at binding 20 (the table's; in the copies the gathers of the higher orders
    // bind, the previous order's).
    ms_mu_s: u32,
    ms_r: u32,
    ms_degree: u32,
    ms_coefficients: u32,
    // The gather rule: Gauss–Legendre nodes in μ below and above the horizon, azimuths over
    // [0, π], and steps per gather ray.
    gather_below: u32,
    gather_above: u32,
    gather_phi: u32,
    ms_steps: u32,
    // Sky view: (azimuth, zenith) texels and steps per ray; steps of a per-pixel march.
    sky_view_azimuth: u32,
    sky_view_zenith: u32,
    sky_view_steps: u32,
    march_steps: u32,
    // Sky irradiance: (μ_s, altitude) texels, hemisphere directions, steps per direction.
    irradiance_mu_s: u32,
    irradiance_r: u32,
    irradiance_directions: u32,
    irradiance_steps: u32,
    // Offsets (vec4) in hillaire_data: the gather rules' (node, weight) on [−1, 1] (the
    // rule below the horizon, then the one above; the higher orders' copies point at their
    // coarser rule), the irradiance directions (xyz), the groups' phase moments k_ℓ (group
    // g's ℓ at moments_offset + g·moments_stride + ℓ, in x; the stride is the table's
    // degree + 1).
    gather_offset: u32,
    directions_offset: u32,
    moments_offset: u32,
    moments_stride: u32,
    // The explicit orders (multiple_scattering::compute's loop): the table's coefficients
    // (the sum of the orders), those of the field a pass writes to its order's buffer (the
    // first order's: the table's; a higher order's: degree ≤ HIGHER_ORDERS_DEGREE), and
    // HillaireConfig::multiple_scattering_orders.
    table_coefficients: u32,
    order_coefficients: u32,
    orders: u32,
    pad0: u32,
}

@group(0) @binding(8) var<uniform> hillaire: Hillaire;
@group(0) @binding(9) var<storage, read> hillaire_data: array<vec4<f32>>;
