//! Table parameterisations of Bruneton & Neyret 2008 §4 as refined in Bruneton 2017
//! (`functions.glsl`): texel-centre-exact mappings, `u_r = ρ/H`, a `u_μ` split at the
//! horizon into rays that hit the ground and rays that do not, a non-linear `u_μs` with a
//! minimum sun elevation, and `u_ν` by the azimuth from the sun (see [`u_nu`]). All in f64;
//! (r, μ) as in [`crate::math::sphere`].

use crate::atmosphere::model::Model;
use crate::math::sphere::{clamp_cosine, distance_to_top_atmosphere_boundary, safe_sqrt};

pub use super::mu_s_map::{
    mu_s_from_x, x_mu_s, MuSMap, MU_S_JOINT_BRUNETON_X, MU_S_JOINT_MIN_ELEVATION_DEG, MU_S_JOINT_X,
};

/// Table sizes. Defaults from Bruneton 2017 (transmittance 256×64, scattering 32×128×32×8,
/// irradiance 64×16), but 40 μ_s samples in place of 32: Bruneton's 32-sample grid up to
/// 18° sun elevation and 13 more above it (see [`x_mu_s`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableSizes {
    /// Transmittance width (μ).
    pub transmittance_mu: usize,
    /// Transmittance height (r).
    pub transmittance_r: usize,
    /// Scattering r size.
    pub scattering_r: usize,
    /// Scattering μ size (even: two halves).
    pub scattering_mu: usize,
    /// Scattering μ_s size.
    pub scattering_mu_s: usize,
    /// Scattering ν size.
    pub scattering_nu: usize,
    /// Irradiance width (μ_s).
    pub irradiance_mu_s: usize,
    /// Irradiance height (r).
    pub irradiance_r: usize,
}

impl Default for TableSizes {
    fn default() -> Self {
        TableSizes {
            transmittance_mu: 256,
            transmittance_r: 64,
            scattering_r: 32,
            scattering_mu: 128,
            scattering_mu_s: 40,
            scattering_nu: 8,
            irradiance_mu_s: 64,
            // 64 rows (0.94 km apart for `earth`; Bruneton's 16, 3.75 km apart, lit a
            // surface at 1–3 km 23–32 % too brightly: the sky's irradiance falls ×0.55
            // over the first 1.8 km with the haze; docs/accuracy.md, "The irradiance table
            // along r").
            irradiance_r: 64,
        }
    }
}

impl TableSizes {
    /// Small tables for fast tests.
    pub fn small() -> Self {
        TableSizes {
            transmittance_mu: 128,
            transmittance_r: 32,
            scattering_r: 16,
            scattering_mu: 64,
            scattering_mu_s: 20,
            scattering_nu: 8,
            irradiance_mu_s: 32,
            irradiance_r: 16,
        }
    }

    /// Check sizes: every dimension ≥ 2, μ even, and at most `max` texels per table.
    pub fn validate(&self) -> crate::Result<()> {
        let dims = [
            ("transmittance_mu", self.transmittance_mu),
            ("transmittance_r", self.transmittance_r),
            ("scattering_r", self.scattering_r),
            ("scattering_mu", self.scattering_mu),
            ("scattering_mu_s", self.scattering_mu_s),
            ("scattering_nu", self.scattering_nu),
            ("irradiance_mu_s", self.irradiance_mu_s),
            ("irradiance_r", self.irradiance_r),
        ];
        for (name, v) in dims {
            if !(2..=4096).contains(&v) {
                return Err(crate::Error::invalid(
                    format!("tables.{name}"),
                    v,
                    "an integer in [2, 4096]",
                ));
            }
        }
        if !self.scattering_mu.is_multiple_of(2) || self.scattering_mu < 4 {
            return Err(crate::Error::invalid(
                "tables.scattering_mu",
                self.scattering_mu,
                "an even integer ≥ 4 (two halves split at the horizon)",
            ));
        }
        let texels =
            self.scattering_r * self.scattering_mu * self.scattering_mu_s * self.scattering_nu;
        if texels > 64 << 20 {
            return Err(crate::Error::invalid(
                "tables",
                format!("{texels} scattering texels"),
                "at most 67108864 texels",
            ));
        }
        Ok(())
    }
}

/// Texel-centre-exact mapping of x ∈ [0, 1] to a texture coordinate for `n` texels
/// (Bruneton 2017 `GetTextureCoordFromUnitRange`).
#[inline]
pub fn texcoord_from_unit(x: f64, n: usize) -> f64 {
    0.5 / n as f64 + x * (1.0 - 1.0 / n as f64)
}

/// Inverse of [`texcoord_from_unit`].
#[inline]
pub fn unit_from_texcoord(u: f64, n: usize) -> f64 {
    (u - 0.5 / n as f64) / (1.0 - 1.0 / n as f64)
}

/// Geometry constants the mappings need (metres).
#[derive(Clone, Copy, Debug)]
pub struct Radii {
    /// Ground radius (m).
    pub bottom: f64,
    /// Top radius (m).
    pub top: f64,
    /// cos of the largest sun zenith angle covered.
    pub mu_s_min: f64,
}

impl Radii {
    /// The radii and lowest sun of `model`'s tables.
    pub fn of(model: &Model) -> Radii {
        Radii {
            bottom: model.bottom_radius_m,
            top: model.top_radius_m,
            mu_s_min: model.mu_s_min,
        }
    }

    /// H = sqrt(R_t² − R_g²) (m): the distance to the top along the horizon from the ground.
    #[inline]
    pub fn h(&self) -> f64 {
        (self.top * self.top - self.bottom * self.bottom).sqrt()
    }
}

/// (u, v) ∈ [0, 1]² of the transmittance table for (r, μ) (paper §4, Bruneton 2017).
#[inline]
pub fn transmittance_uv(radii: &Radii, r: f64, mu: f64, nmu: usize, nr: usize) -> (f64, f64) {
    let h = radii.h();
    let rho = safe_sqrt(r * r - radii.bottom * radii.bottom);
    let d = distance_to_top_atmosphere_boundary(r, mu, radii.top);
    let d_min = radii.top - r;
    let d_max = rho + h;
    let x_mu = if d_max > d_min {
        (d - d_min) / (d_max - d_min)
    } else {
        0.0
    };
    let x_r = rho / h;
    (texcoord_from_unit(x_mu, nmu), texcoord_from_unit(x_r, nr))
}

/// Inverse of [`transmittance_uv`].
#[inline]
pub fn transmittance_r_mu(radii: &Radii, u: f64, v: f64, nmu: usize, nr: usize) -> (f64, f64) {
    let h = radii.h();
    let x_mu = unit_from_texcoord(u, nmu);
    let x_r = unit_from_texcoord(v, nr);
    let rho = h * x_r;
    let r = (rho * rho + radii.bottom * radii.bottom).sqrt();
    let d_min = radii.top - r;
    let d_max = rho + h;
    let d = d_min + x_mu * (d_max - d_min);
    let mu = if d == 0.0 {
        1.0
    } else {
        clamp_cosine((h * h - rho * rho - d * d) / (2.0 * r * d))
    };
    (r, mu)
}

/// (u, v) of the irradiance table for (r, μ_s): linear in both.
#[inline]
pub fn irradiance_uv(radii: &Radii, r: f64, mu_s: f64, nmu_s: usize, nr: usize) -> (f64, f64) {
    let x_r = (r - radii.bottom) / (radii.top - radii.bottom);
    let x_mu_s = mu_s * 0.5 + 0.5;
    (
        texcoord_from_unit(x_mu_s, nmu_s),
        texcoord_from_unit(x_r, nr),
    )
}

/// Inverse of [`irradiance_uv`].
#[inline]
pub fn irradiance_r_mu_s(radii: &Radii, u: f64, v: f64, nmu_s: usize, nr: usize) -> (f64, f64) {
    let x_mu_s = unit_from_texcoord(u, nmu_s);
    let x_r = unit_from_texcoord(v, nr);
    (
        radii.bottom + x_r * (radii.top - radii.bottom),
        clamp_cosine(2.0 * x_mu_s - 1.0),
    )
}

/// (r, μ_s) at the centre of irradiance texel (x, y) of tables of `sizes`.
#[inline]
pub fn irradiance_texel(radii: &Radii, sizes: &TableSizes, x: usize, y: usize) -> (f64, f64) {
    let (nmu_s, nr) = (sizes.irradiance_mu_s, sizes.irradiance_r);
    irradiance_r_mu_s(
        radii,
        (x as f64 + 0.5) / nmu_s as f64,
        (y as f64 + 0.5) / nr as f64,
        nmu_s,
        nr,
    )
}

/// The four coordinates (u_ν, u_μs, u_μ, u_r) ∈ [0, 1]⁴ of the scattering table.
#[inline]
pub fn scattering_uvwz(
    radii: &Radii,
    s: &TableSizes,
    r: f64,
    mu: f64,
    mu_s: f64,
    nu: f64,
    ray_r_mu_intersects_ground: bool,
) -> [f64; 4] {
    let rho = safe_sqrt(r * r - radii.bottom * radii.bottom);
    let u_r = texcoord_from_unit(rho / radii.h(), s.scattering_r);
    let u_mu = scattering_u_mu(radii, s, r, mu, ray_r_mu_intersects_ground);
    let u_mu_s = texcoord_from_unit(x_mu_s(radii, mu_s), s.scattering_mu_s);
    [u_nu(mu, mu_s, nu), u_mu_s, u_mu, u_r]
}

/// The u_μ coordinate of [`scattering_uvwz`] alone (for lookups at a known (r, μ_s)).
#[inline]
pub fn scattering_u_mu(
    radii: &Radii,
    s: &TableSizes,
    r: f64,
    mu: f64,
    ray_r_mu_intersects_ground: bool,
) -> f64 {
    let h = radii.h();
    let rho = safe_sqrt(r * r - radii.bottom * radii.bottom);
    let r_mu = r * mu;
    let discriminant = r_mu * r_mu - r * r + radii.bottom * radii.bottom;
    let half = s.scattering_mu / 2;
    if ray_r_mu_intersects_ground {
        // Distance to the ground, mapped to the lower half [0, 0.5] by
        // [`ground_x_from_distance_fraction`].
        let d = -r_mu - safe_sqrt(discriminant);
        let d_min = r - radii.bottom;
        let d_max = rho;
        let x = if d_max == d_min {
            0.0
        } else {
            ground_x_from_distance_fraction((d - d_min) / (d_max - d_min))
        };
        0.5 - 0.5 * texcoord_from_unit(x, half)
    } else {
        // Distance to the top, mapped to the upper half [0.5, 1].
        let d = -r_mu + safe_sqrt(discriminant + h * h);
        let d_min = radii.top - r;
        let d_max = rho + h;
        let x = if d_max > d_min {
            sky_x_from_distance_fraction((d - d_min) / (d_max - d_min))
        } else {
            0.0
        };
        0.5 + 0.5 * texcoord_from_unit(x, half)
    }
}

/// The unit coordinate of a sky ray (one that leaves through the top) from the fraction
/// f = (d − d_min)/(d_max − d_min) of its distance to the top between straight up
/// (d_min = R_t − r) and the horizon (d_max = ρ + H): x = (s + s³)/2 with s = √f.
/// Bruneton's x = f grows with the square of the zenith angle near the zenith (d ≈
/// d_min/cos θ), so that from the ground his first row above the zenith lies at 38°: the
/// multiple scattering of a hazy sky under a high sun, forward-peaked around the sun like
/// the aerosols' phase function, was interpolated across that gap and read +6 % 25–30° from
/// a zenith sun (`hazy`, order 2; 512 rows: +0.8 %). s is linear in the angle near the
/// zenith (the first row at 9.4° from the ground) and dx/df = 1 at the horizon as in
/// Bruneton's mapping, which keeps the horizon's resolution; the mid-sky keeps ≥ 0.87 of its
/// rows (the least at f = 1/3). Inverse: [`distance_fraction_from_sky_x`].
#[inline]
pub fn sky_x_from_distance_fraction(f: f64) -> f64 {
    let s = f.clamp(0.0, 1.0).sqrt();
    0.5 * (s + s * s * s)
}

/// Inverse of [`sky_x_from_distance_fraction`]: s³ + s = 2x solved by the hyperbolic form
/// of Cardano's formula (one real root, p = 1 > 0), s = (2/√3)·sinh(asinh(3√3·x)/3); f = s².
#[inline]
pub fn distance_fraction_from_sky_x(x: f64) -> f64 {
    const SQRT_3: f64 = 1.732_050_807_568_877_2;
    let s = 2.0 / SQRT_3 * ((3.0 * SQRT_3 * x.clamp(0.0, 1.0)).asinh() / 3.0).sinh();
    (s * s).min(1.0)
}

/// The unit coordinate of a ground ray from the fraction f = (d − d_min)/(d_max − d_min)
/// of its distance to the ground between straight down (d_min = r − R_g) and the horizon
/// (d_max = ρ): x = √f. Bruneton's x = f puts every direction steeper than 60° below the
/// horizon into the first texel row at low altitude (d from h to 2h is f ≈ √(h/2R_g):
/// 0.4 of a row of 64 at 500 m), where the scattering density interpolated between
/// straight down and ≈ 20° below the horizon read the multiple scattering of downward views
/// ×2 too high (validate: +17 % luminance looking 60° down towards a 10° sun from 1 km);
/// √f gives those directions 5 rows there and keeps half the linear resolution at the
/// horizon. Inverse: f = x².
#[inline]
pub fn ground_x_from_distance_fraction(f: f64) -> f64 {
    f.clamp(0.0, 1.0).sqrt()
}

/// The ν coordinate, relative to the range of ν that (μ, μ_s) allow. Bruneton uses
/// u_ν = (ν + 1)/2 and clamps ν per texel to [μμ_s − s, μμ_s + s], s = √((1−μ²)(1−μ_s²)):
/// most ν texels then hold clamped, repeated values, and interpolating in μ_s mixes
/// texels for which the same ν means a different direction (the anti-solar sky near the
/// horizon under a high sun read +11 % in `firmament validate`). We parameterise by the
/// azimuth φ between the view and the sun around the zenith, cos φ = (ν − μμ_s)/s, with
/// u_ν = 1 − sin(φ/2): every texel is a real direction, samples are denser towards the
/// sun (φ = 0°, 16°, 33°, 51°, 69°, 91°, 117°, 180° for 8), and a fixed u_ν is the same
/// relative geometry at every (μ, μ_s).
#[inline]
pub fn u_nu(mu: f64, mu_s: f64, nu: f64) -> f64 {
    let s = ((1.0 - mu * mu) * (1.0 - mu_s * mu_s)).max(0.0).sqrt();
    // (1 − cos φ)/2 = sin²(φ/2).
    let x = ((mu * mu_s + s - nu) / (2.0 * s)).clamp(0.0, 1.0);
    // Where s ≈ 0, φ is undefined and every u_ν holds the same value. A select rather than
    // an early return, so that loops over many texels vectorise.
    if s <= 1e-12 {
        1.0
    } else {
        1.0 - x.sqrt()
    }
}

/// Inverse of [`u_nu`] at (μ, μ_s).
#[inline]
pub fn nu_from_u_nu(mu: f64, mu_s: f64, u_nu: f64) -> f64 {
    let s = ((1.0 - mu * mu) * (1.0 - mu_s * mu_s)).max(0.0).sqrt();
    let x = 1.0 - u_nu.clamp(0.0, 1.0);
    clamp_cosine(mu * mu_s + s * (1.0 - 2.0 * x * x))
}

/// The ρ (m) whose ground-ray directions the ground row's texels take: the second row's.
/// At ρ = 0 every ray that hits the ground is of zero length, so single and multiple
/// scattering are 0 there whatever the direction, but the scattering density J is not, and
/// the multiple scattering along a ray down to the ground interpolates J between the
/// ground row and the next. With every ground texel of the ground row at the nadir, J
/// looking straight down stood for every direction down there: over a shell 0.3 of a
/// Titan-sized planet's radius, whose second row is 0.92 km up, order 2 looking 3° down
/// from 0.92 km read −11 % (docs/accuracy.md); Earth's second row is 52 m up.
#[inline]
pub fn ground_row_rho(h: f64, scattering_r: usize) -> f64 {
    h / (scattering_r - 1) as f64
}

/// Inverse of [`scattering_uvwz`]: (r, μ, μ_s, ν, ray hits ground).
#[inline]
pub fn scattering_r_mu_mu_s_nu(
    radii: &Radii,
    s: &TableSizes,
    uvwz: [f64; 4],
) -> (f64, f64, f64, f64, bool) {
    let [u_nu, u_mu_s, u_mu, u_r] = uvwz;
    let h = radii.h();
    let rho = h * unit_from_texcoord(u_r, s.scattering_r);
    let r = (rho * rho + radii.bottom * radii.bottom).sqrt();
    let half = s.scattering_mu / 2;
    let (mu, ground) = if u_mu < 0.5 {
        // At the ground (ρ = 0) every ray that hits it is of zero length, and the distance
        // mapping would put the whole half at the nadir: the directions of the next row's
        // texels instead ([`ground_row_rho`]).
        let (rho, r) = if rho == 0.0 {
            let rho = ground_row_rho(h, s.scattering_r);
            (rho, (rho * rho + radii.bottom * radii.bottom).sqrt())
        } else {
            (rho, r)
        };
        let d_min = r - radii.bottom;
        let d_max = rho;
        let x = unit_from_texcoord(1.0 - 2.0 * u_mu, half);
        let d = d_min + (d_max - d_min) * x * x;
        let mu = if d == 0.0 {
            -1.0
        } else {
            clamp_cosine(-(rho * rho + d * d) / (2.0 * r * d))
        };
        (mu, true)
    } else {
        let d_min = radii.top - r;
        let d_max = rho + h;
        let f = distance_fraction_from_sky_x(unit_from_texcoord(2.0 * u_mu - 1.0, half));
        let d = d_min + (d_max - d_min) * f;
        let mu = if d == 0.0 {
            1.0
        } else {
            clamp_cosine((h * h - rho * rho - d * d) / (2.0 * r * d))
        };
        (mu, false)
    };
    let mu_s = mu_s_from_x(radii, unit_from_texcoord(u_mu_s, s.scattering_mu_s));
    let nu = nu_from_u_nu(mu, mu_s, u_nu);
    (r, mu, mu_s, nu, ground)
}

/// (r, μ, μ_s, ν, ground) at the centre of scattering texel (x = ν·N_μs + μ_s, y = μ,
/// z = r); ν is clamped to the range allowed by μ and μ_s (Bruneton 2017
/// `GetRMuMuSNuFromScatteringTextureFragCoord`; the ν grid includes −1 and 1).
pub fn scattering_texel(
    radii: &Radii,
    s: &TableSizes,
    x: usize,
    y: usize,
    z: usize,
) -> (f64, f64, f64, f64, bool) {
    let i_nu = x / s.scattering_mu_s;
    let i_mu_s = x % s.scattering_mu_s;
    let uvwz = texel_uvwz(s, i_nu, i_mu_s, y, z);
    let (r, mu, mu_s, nu, ground) = scattering_r_mu_mu_s_nu(radii, s, uvwz);
    (r, mu, mu_s, clamp_nu(mu, mu_s, nu), ground)
}

/// The texture coordinates of a scattering texel's centre (the ν grid includes its ends).
pub(crate) fn texel_uvwz(
    s: &TableSizes,
    i_nu: usize,
    i_mu_s: usize,
    y: usize,
    z: usize,
) -> [f64; 4] {
    [
        i_nu as f64 / (s.scattering_nu - 1) as f64,
        (i_mu_s as f64 + 0.5) / s.scattering_mu_s as f64,
        (y as f64 + 0.5) / s.scattering_mu as f64,
        (z as f64 + 0.5) / s.scattering_r as f64,
    ]
}

/// ν clamped to the range that view and sun directions with these μ and μ_s allow.
#[inline]
pub(crate) fn clamp_nu(mu: f64, mu_s: f64, nu: f64) -> f64 {
    let spread = ((1.0 - mu * mu) * (1.0 - mu_s * mu_s)).max(0.0).sqrt();
    nu.clamp(mu * mu_s - spread, mu * mu_s + spread)
}

/// Earth's radii with μ_s,min = cos 102° (Bruneton 2017), for the unit tests of the table
/// mappings.
#[cfg(test)]
pub(crate) const EARTH_RADII: Radii = Radii {
    bottom: 6_360_000.0,
    top: 6_420_000.0,
    mu_s_min: -0.2079116908177593,
};

#[cfg(test)]
mod tests {
    use super::*;

    const G: Radii = EARTH_RADII;

    #[test]
    fn transmittance_mapping_round_trips() {
        for &(r, mu) in &[
            (6_360_000.0, 0.0),
            (6_365_000.0, 0.3),
            (6_400_000.0, -0.1),
            (6_419_000.0, 0.99),
            (6_370_000.0, -0.05),
        ] {
            let (u, v) = transmittance_uv(&G, r, mu, 256, 64);
            let (r2, mu2) = transmittance_r_mu(&G, u, v, 256, 64);
            assert!((r2 - r).abs() / r < 1e-9, "r {r} {r2}");
            assert!((mu2 - mu).abs() < 1e-6, "mu {mu} {mu2}");
        }
    }

    #[test]
    fn scattering_mapping_round_trips_and_splits_at_the_horizon() {
        let s = TableSizes::default();
        for &r in &[6_360_100.0, 6_362_000.0, 6_380_000.0, 6_419_000.0] {
            let mu_h = crate::math::sphere::horizon_mu(r, G.bottom);
            for &mu in &[-0.9, mu_h - 1e-3, mu_h + 1e-3, 0.2, 0.95] {
                for &mu_s in &[-0.15, 0.0, 0.3, 0.9] {
                    let ground = crate::math::sphere::ray_intersects_ground(r, mu, G.bottom);
                    // A direction that exists: azimuth 72.5° from the sun (cos φ = 0.3).
                    let spread = ((1.0 - mu * mu) * (1.0 - mu_s * mu_s)).sqrt();
                    let nu = mu * mu_s + 0.3 * spread;
                    let uvwz = scattering_uvwz(&G, &s, r, mu, mu_s, nu, ground);
                    // Horizon discontinuity: ground rays in the lower half, sky rays in the upper.
                    assert_eq!(uvwz[2] < 0.5, ground);
                    let (r2, mu2, mu_s2, nu2, g2) = scattering_r_mu_mu_s_nu(&G, &s, uvwz);
                    assert_eq!(g2, ground);
                    assert!((r2 - r).abs() / r < 1e-9);
                    assert!((mu2 - mu).abs() < 1e-6, "mu {mu} -> {mu2} at r {r}");
                    assert!((mu_s2 - mu_s).abs() < 1e-6, "mu_s {mu_s} -> {mu_s2}");
                    assert!((nu2 - nu).abs() < 1e-6, "nu {nu} -> {nu2}");
                }
            }
        }
    }

    /// Downward views from low altitude get texel rows of their own: at 500 m and 1 km, with
    /// the default 128 μ rows (64 per half), at least 4 ground-half rows lie between straight
    /// down and 30° below the horizon (Bruneton's distance-linear mapping gives 1: only the
    /// straight-down row), and the rows stay ordered from straight down to the horizon.
    #[test]
    fn ground_rows_resolve_steep_downward_views() {
        let s = TableSizes::default();
        for altitude in [500.0, 1000.0] {
            let r = G.bottom + altitude;
            let u_r =
                texcoord_from_unit((r * r - G.bottom * G.bottom).sqrt() / G.h(), s.scattering_r);
            let half = s.scattering_mu / 2;
            let mut steep = 0;
            let mut last = -1.0 - 1e-12;
            for y in (0..half).rev() {
                let u_mu = (y as f64 + 0.5) / s.scattering_mu as f64;
                let (r2, mu, _, _, ground) = scattering_r_mu_mu_s_nu(&G, &s, [0.5, 0.5, u_mu, u_r]);
                assert!(ground && (r2 - r).abs() < 1e-3);
                assert!(mu > last, "row {y}: μ {mu} after {last}");
                last = mu;
                if mu < -0.5 {
                    steep += 1;
                }
            }
            assert!(steep >= 4, "{altitude} m: {steep} rows below −30°");
        }
    }

    #[test]
    fn nu_mapping_is_the_azimuth_within_the_valid_range() {
        for &(mu, mu_s) in &[(0.0, 0.866), (0.5, 0.5), (-0.3, 0.1), (0.99, -0.2)] {
            let spread = ((1.0f64 - mu * mu) * (1.0 - mu_s * mu_s)).sqrt();
            let mut last = -1.0;
            for j in 0..=36 {
                let phi = std::f64::consts::PI * j as f64 / 36.0;
                let nu = mu * mu_s + spread * phi.cos();
                let u = u_nu(mu, mu_s, nu);
                // u_ν = 1 − sin(φ/2): 1 towards the sun, 0 opposite, every texel valid.
                assert!(
                    (u - (1.0 - (0.5 * phi).sin())).abs() < 1e-7,
                    "u {u} at φ {phi}"
                );
                assert!((nu_from_u_nu(mu, mu_s, u) - nu).abs() < 1e-9);
                assert!(j == 0 || u < last);
                last = u;
            }
        }
        // Degenerate range (view or sun at the zenith): every u_ν is the same direction.
        assert_eq!(nu_from_u_nu(1.0, 0.3, 0.2), 0.3);
    }

    #[test]
    fn sky_rows_are_linear_in_angle_at_the_zenith_and_keep_the_horizon() {
        for i in 0..=1000 {
            let x = i as f64 / 1000.0;
            let f = distance_fraction_from_sky_x(x);
            assert!((sky_x_from_distance_fraction(f) - x).abs() < 1e-12, "{x}");
        }
        // dx/df at the horizon is Bruneton's (1).
        let e = 1e-6;
        let slope = (1.0 - sky_x_from_distance_fraction(1.0 - e)) / e;
        assert!((slope - 1.0).abs() < 1e-5, "{slope}");
        // From the ground, the first sky row above the zenith lies at 9–10° (38° with x = f),
        // and the rows are nearly evenly spaced in angle there.
        let s = TableSizes::default();
        let angle = |y: usize| {
            let u = (y as f64 + 0.5) / s.scattering_mu as f64;
            let (_, mu, _, _, ground) =
                scattering_r_mu_mu_s_nu(&G, &s, [0.5, 0.5, u, 0.5 / s.scattering_r as f64]);
            assert!(!ground);
            mu.acos().to_degrees()
        };
        let half = s.scattering_mu / 2;
        let (first, second) = (angle(half + 1), angle(half + 2));
        assert!(
            angle(half) < 1e-3 && (9.0..10.0).contains(&first),
            "{first}"
        );
        assert!(
            (second - 2.0 * first).abs() < 0.1 * first,
            "{first} {second}"
        );
    }

    #[test]
    fn irradiance_mapping_round_trips() {
        let (u, v) = irradiance_uv(&G, 6_390_000.0, -0.2, 64, 16);
        let (r, mu_s) = irradiance_r_mu_s(&G, u, v, 64, 16);
        assert!((r - 6_390_000.0).abs() < 1e-6 && (mu_s + 0.2).abs() < 1e-12);
    }

    #[test]
    fn texel_centres_map_exactly() {
        assert!((texcoord_from_unit(0.0, 32) - 0.5 / 32.0).abs() < 1e-15);
        assert!((texcoord_from_unit(1.0, 32) - (1.0 - 0.5 / 32.0)).abs() < 1e-15);
        assert!((unit_from_texcoord(texcoord_from_unit(0.37, 7), 7) - 0.37).abs() < 1e-15);
    }
}
