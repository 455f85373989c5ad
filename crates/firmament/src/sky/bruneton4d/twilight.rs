//! The sky lit by a sun below the tables' lowest one (μ_s < μ_s,min).
//!
//! The scattering tables end at μ_s,min (`min_sun_elevation_deg`). Below it the light the
//! sun still sends into the air (through the upper air, and scattered on from the lit air
//! beyond the horizon) is taken to keep falling as it falls over the tables' last rows:
//! geometrically in μ_s, at the rate of the sky's irradiance at the same radius between
//! the irradiance table's two lowest texels above μ_s,min. The twilight sky's brightness
//! falls near-exponentially with the sun's depression, and keeps its pattern (Rozenberg
//! 1966, *Twilight*, ch. 1–2: log brightness nearly linear in the depression), so one
//! factor per channel serves every direction. Continuous at μ_s,min, decreasing below it,
//! and 0 where the tables show no fall to extrapolate.
//!
//! The irradiance table itself covers μ_s ∈ [−1, 1], but its texels below μ_s,min were
//! gathered from scattering tables read at μ_s,min (every deeper sun then lit the ground
//! as the lowest tabulated one, and the sky's irradiance under a sun at −80° read above
//! that at −12°); [`sky_irradiance`] extrapolates below its lowest texel above μ_s,min
//! instead of reading them.

use super::lookup::Lookup;
use super::table::Table2;
use crate::spectrum::with_channel_buffers;

/// Tolerance of the texel index in [`lowest_texel`]: a μ_s,min this close below a texel
/// centre counts as on it (the WGSL twin computes it in f32).
const TEXEL_TOLERANCE: f64 = 1e-4;

/// μ_s of the irradiance table's lowest texel centre at or above μ_s,min, and the spacing
/// of texel centres in μ_s (the table is linear in μ_s over [−1, 1]).
fn lowest_texel(lookup: &Lookup) -> (f64, f64) {
    let n = lookup.sizes.irradiance_mu_s;
    let step = 2.0 / (n - 1) as f64;
    let x = ((lookup.radii.mu_s_min + 1.0) / step - TEXEL_TOLERANCE)
        .ceil()
        .min((n - 2) as f64);
    (x * step - 1.0, step)
}

/// E at the lowest texel at or above μ_s,min into `e0` and the per-texel ratio E(μ₀)/E(μ₀ +
/// step) into `ratio` (0 where the sky does not brighten with the sun there), at radius r.
fn decay(lookup: &Lookup, table: &Table2, r: f64, e0: &mut [f64], ratio: &mut [f64]) {
    let (mu0, step) = lowest_texel(lookup);
    lookup.irradiance(table, r, mu0, e0);
    lookup.irradiance(table, r, mu0 + step, ratio);
    for (q, &a) in ratio.iter_mut().zip(e0.iter()) {
        *q = if a > 0.0 && a < *q { a / *q } else { 0.0 };
    }
}

/// The factor per channel by which the light scattered at radius r under a sun at `mu_s`
/// below μ_s,min falls from what the tables hold at μ_s,min; 1 at and above μ_s,min.
/// `table`: the tables' sky irradiance.
pub fn fade(lookup: &Lookup, table: &Table2, r: f64, mu_s: f64, out: &mut [f64]) {
    let below = lookup.radii.mu_s_min - mu_s;
    if below <= 0.0 {
        out.iter_mut().for_each(|v| *v = 1.0);
        return;
    }
    let (_, step) = lowest_texel(lookup);
    with_channel_buffers(out.len(), |[e0]| {
        decay(lookup, table, r, e0, out);
        for q in out.iter_mut() {
            *q = q.powf(below / step);
        }
    });
}

/// The sky's irradiance (W·m⁻²·nm⁻¹) on a horizontal surface at (r, μ_s): the table above
/// its lowest texel at or above μ_s,min, extrapolated geometrically below it.
pub fn sky_irradiance(lookup: &Lookup, table: &Table2, r: f64, mu_s: f64, out: &mut [f64]) {
    let (mu0, step) = lowest_texel(lookup);
    if mu_s >= mu0 {
        lookup.irradiance(table, r, mu_s, out);
        return;
    }
    with_channel_buffers(out.len(), |[ratio]| {
        decay(lookup, table, r, out, ratio);
        for (e, q) in out.iter_mut().zip(ratio.iter()) {
            *e *= q.powf((mu0 - mu_s) / step);
        }
    });
}

/// What is approximated for a light at `mu_s` at the observer, when it is below the
/// tables' lowest sun (for `query`'s notes and `render`'s stderr); None above it.
pub fn note(mu_s_min: f64, mu_s: f64) -> Option<String> {
    (mu_s < mu_s_min).then(|| {
        let elevation = |m: f64| 90.0 - m.clamp(-1.0, 1.0).acos().to_degrees();
        format!(
            "twilight: the sun is {:.1}° high, below the lowest sun of these tables ({:.0}°, min_sun_elevation_deg): the sky it lights is the tables' at that sun, falling geometrically with the sun's depression at the rate of the sky's irradiance over the tables' last rows (docs/accuracy.md)",
            elevation(mu_s),
            elevation(mu_s_min)
        )
    })
}
