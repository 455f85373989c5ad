// The sky lit by a sun below the tables' lowest one (μ_s < μ_s,min): the twin of
// sky/bruneton4d/twilight.rs. Below μ_s,min the light scattered in the air falls on from the
// tables' lowest sun geometrically in μ_s, at the rate of the sky's irradiance at the same
// radius between the irradiance table's two lowest texels at or above μ_s,min (Rozenberg
// 1966, Twilight: log brightness nearly linear in the sun's depression); the sky's irradiance
// is extrapolated the same way below that texel.

// μ_s of the irradiance table's lowest texel centre at or above μ_s,min (x) and the spacing
// of texel centres in μ_s (y); the table is linear in μ_s over [−1, 1].
fn twilight_lowest_texel() -> vec2<f32> {
    let n = atm.irradiance_mu_s;
    let step = 2.0 / f32(n - 1u);
    let x = min(ceil((atm.mu_s_min + 1.0) / step - TWILIGHT_TEXEL_TOLERANCE), f32(n - 2u));
    return vec2<f32>(x * step - 1.0, step);
}

// The tolerance of the texel index above (twilight.rs's TEXEL_TOLERANCE).
const TWILIGHT_TEXEL_TOLERANCE: f32 = 1e-4;

fn twilight_irradiance_at(altitude_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    return irradiance_at(irradiance_uv(altitude_km, mu_s), k);
}

struct TwilightDecay {
    // E at the lowest texel at or above μ_s,min.
    e0: vec4<f32>,
    // E(μ₀)/E(μ₀ + step): 0 where the sky does not brighten with the sun there.
    ratio: vec4<f32>,
}

fn twilight_decay(altitude_km: f32, k: u32) -> TwilightDecay {
    let t = twilight_lowest_texel();
    var d: TwilightDecay;
    d.e0 = twilight_irradiance_at(altitude_km, t.x, k);
    let e1 = twilight_irradiance_at(altitude_km, t.x + t.y, k);
    let falls = d.e0 > vec4<f32>(0.0) & d.e0 < e1;
    d.ratio = select(vec4<f32>(0.0), d.e0 / max(e1, vec4<f32>(1e-30)), falls);
    return d;
}

// ratio^exponent per channel, 0 where the ratio is 0 (pow of 0 is undefined in WGSL).
fn twilight_pow(ratio: vec4<f32>, exponent: f32) -> vec4<f32> {
    return select(vec4<f32>(0.0), pow(max(ratio, vec4<f32>(1e-30)), vec4<f32>(exponent)), ratio > vec4<f32>(0.0));
}

// twilight::fade: the factor by which the light scattered at `altitude_km` under a sun at
// `mu_s` falls from what the tables hold at μ_s,min; 1 at and above μ_s,min.
fn twilight_fade(altitude_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    let below = atm.mu_s_min - mu_s;
    if (below <= 0.0) {
        return vec4<f32>(1.0);
    }
    return twilight_pow(twilight_decay(altitude_km, k).ratio, below / twilight_lowest_texel().y);
}

// twilight::sky_irradiance: the sky's irradiance on a horizontal surface at (altitude, μ_s).
fn twilight_sky_irradiance(altitude_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    let t = twilight_lowest_texel();
    if (mu_s >= t.x) {
        return twilight_irradiance_at(altitude_km, mu_s, k);
    }
    let d = twilight_decay(altitude_km, k);
    return d.e0 * twilight_pow(d.ratio, (t.x - mu_s) / t.y);
}
