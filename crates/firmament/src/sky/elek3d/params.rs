//! The 3D table's parameterisation (Yusov 2013, *Outdoor Light Scattering Sample*,
//! `LightScattering.fx`: `WorldParams2InsctrLUTCoords` with `NON_LINEAR_PARAMETERIZATION`),
//! texel-centre exact as in Bruneton 2017:
//!
//! - altitude: u_h = (h/H)^p, p = 0.5 (`HeightPower`): texels dense near the ground, where
//!   the air is;
//! - view zenith: split at the horizon μ_h = −√(1 − (R_g/r)²) (`GetCosHorizonAnlge`); each
//!   half holds the fraction of its range of μ from the horizon, raised to p = 0.2
//!   (`ViewZenithPower`), so that texels crowd towards the horizon, where the sky changes
//!   fastest. Yusov puts the horizon at the first texel of each half; here the lower half
//!   is mirrored (straight down at texel 0, the horizon at the centre, as in the 4D tables'
//!   mapping), and a ray's half is chosen by whether it meets the ground, never by μ, so
//!   that both ends of a ray read the same half (Yusov passes the previous coordinate for
//!   the same reason);
//! - sun zenith ([`SunZenithMapping`]): Bruneton & Neyret 2008's
//!   u_μs = (atan(μ_s·tan 1.386)/1.1 + 0.74)/2, which Yusov uses, with its lower end moved
//!   from his fixed μ_s = −0.1975 to the model's μ_s,min; or the 4D tables' mapping.
//!
//! (r, μ) as in [`crate::math::sphere`]; all in f64.

use super::config::Elek3dConfig;
use crate::atmosphere::Model;
use crate::math::sphere::{clamp_cosine, horizon_mu};
use crate::sky::bruneton4d::params::{texcoord_from_unit, unit_from_texcoord, MuSMap, Radii};

/// How the sun's zenith cosine maps to the table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SunZenithMapping {
    /// Bruneton & Neyret 2008's arctangent, as Yusov 2013 uses it, from μ_s,min: dense near
    /// the horizon, sparse above: of 32 texels the last two lie at 45° and 90° elevation.
    #[default]
    Yusov,
    /// The 4D tables' mapping ([`crate::sky::bruneton4d::params::x_mu_s`]): Bruneton 2017's
    /// up to 18° elevation, linear in the sun's zenith angle above (of 32 texels, 11 above
    /// 18°). The multiple scattering's aureole around the sun lies along μ ≈ μ_s in a 3D
    /// table, so interpolating between a 45° and a zenith sun puts part of the zenith sun's
    /// aureole into the zenith sky of a 60° sun: +14 % in `hazy` with the arctangent, −0.3 %
    /// with this mapping (but no change in the sky's median error, which the azimuth's loss
    /// dominates: `examples/elek3d_accuracy.rs`).
    Tables4d,
}

/// The largest argument of Bruneton & Neyret 2008's sun-zenith mapping, 1.26·1.1: μ_s = 1
/// there.
pub const SUN_ZENITH_T_MAX: f64 = 1.26 * 1.1;

/// The mappings of one model's tables.
#[derive(Clone, Copy, Debug)]
pub struct Params {
    /// Ground radius R_g (m).
    pub bottom: f64,
    /// Top radius R_t (m).
    pub top: f64,
    /// The lowest sun's zenith cosine the table covers.
    pub mu_s_min: f64,
    /// Altitude texels.
    pub nh: usize,
    /// View-zenith texels (even).
    pub nmu: usize,
    /// Sun-zenith texels.
    pub nmu_s: usize,
    /// u_h = (h/H)^height_power.
    pub height_power: f64,
    /// The power of each half's view-zenith fraction.
    pub view_zenith_power: f64,
    /// atan(μ_s,min·tan t_max): the sun mapping's lower end.
    t_min: f64,
    /// tan(t_max).
    tan_t_max: f64,
    /// The sun's mapping, and the 4D tables' constants when it is theirs.
    sun_mapping: SunZenithMapping,
    tables4d: MuSMap,
}

impl Params {
    /// The mappings for `model`'s radii and lowest sun with `config`'s sizes and powers.
    pub fn new(model: &Model, config: &Elek3dConfig) -> Params {
        let tan_t_max = SUN_ZENITH_T_MAX.tan();
        Params {
            bottom: model.bottom_radius_m,
            top: model.top_radius_m,
            mu_s_min: model.mu_s_min,
            nh: config.altitude,
            nmu: config.view_zenith,
            nmu_s: config.sun_zenith,
            height_power: config.height_power,
            view_zenith_power: config.view_zenith_power,
            t_min: (model.mu_s_min * tan_t_max).atan(),
            tan_t_max,
            sun_mapping: config.sun_zenith_mapping,
            tables4d: MuSMap::new(&Radii::of(model)),
        }
    }

    /// Thickness of the atmosphere H = R_t − R_g (m).
    #[inline]
    pub fn height_m(&self) -> f64 {
        self.top - self.bottom
    }

    /// The altitude's unit coordinate (h/H)^p, clamped to [0, 1].
    #[inline]
    pub fn x_h(&self, r: f64) -> f64 {
        let f = ((r - self.bottom) / self.height_m()).clamp(0.0, 1.0);
        if self.height_power == 0.5 {
            f.sqrt()
        } else {
            f.powf(self.height_power)
        }
    }

    /// Inverse of [`Params::x_h`]: the radius (m).
    #[inline]
    pub fn r_of_x_h(&self, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        let f = if self.height_power == 0.5 {
            x * x
        } else {
            x.powf(1.0 / self.height_power)
        };
        self.bottom + self.height_m() * f
    }

    /// The view zenith's unit coordinate within its half: 0 at the horizon, 1 straight up
    /// (`ground` false) or straight down (`ground` true).
    #[inline]
    pub fn x_mu(&self, r: f64, mu: f64, ground: bool) -> f64 {
        let mu_h = horizon_mu(r.max(self.bottom), self.bottom);
        let f = if ground {
            (mu_h - mu) / (1.0 + mu_h)
        } else {
            (mu - mu_h) / (1.0 - mu_h)
        };
        self.power(f.clamp(0.0, 1.0), self.view_zenith_power)
    }

    /// Inverse of [`Params::x_mu`]: μ.
    #[inline]
    pub fn mu_of_x_mu(&self, r: f64, x: f64, ground: bool) -> f64 {
        let mu_h = horizon_mu(r.max(self.bottom), self.bottom);
        let f = self.power(x.clamp(0.0, 1.0), 1.0 / self.view_zenith_power);
        clamp_cosine(if ground {
            mu_h - f * (1.0 + mu_h)
        } else {
            mu_h + f * (1.0 - mu_h)
        })
    }

    /// The sun zenith's unit coordinate: Bruneton & Neyret 2008's
    /// (atan(μ_s·tan t_max) − t_min)/(t_max − t_min), with t_min the value at μ_s,min
    /// (clamped there), or the 4D tables' ([`SunZenithMapping`]).
    #[inline]
    pub fn x_mu_s(&self, mu_s: f64) -> f64 {
        if self.sun_mapping == SunZenithMapping::Tables4d {
            return self.tables4d.x(mu_s);
        }
        let t = (mu_s.max(self.mu_s_min) * self.tan_t_max).atan();
        ((t - self.t_min) / (SUN_ZENITH_T_MAX - self.t_min)).clamp(0.0, 1.0)
    }

    /// Inverse of [`Params::x_mu_s`]: μ_s.
    #[inline]
    pub fn mu_s_of_x(&self, x: f64) -> f64 {
        if self.sun_mapping == SunZenithMapping::Tables4d {
            return self.tables4d.mu_s(x.clamp(0.0, 1.0));
        }
        let t = self.t_min + x.clamp(0.0, 1.0) * (SUN_ZENITH_T_MAX - self.t_min);
        clamp_cosine(t.tan() / self.tan_t_max)
    }

    /// u_h, a texture coordinate.
    #[inline]
    pub fn u_h(&self, r: f64) -> f64 {
        texcoord_from_unit(self.x_h(r), self.nh)
    }

    /// u_μ, a texture coordinate: ground rays in [0, ½) (straight down at texel 0, the
    /// horizon at texel N/2 − 1), the others in (½, 1] (the horizon at texel N/2).
    #[inline]
    pub fn u_mu(&self, r: f64, mu: f64, ground: bool) -> f64 {
        let half = texcoord_from_unit(self.x_mu(r, mu, ground), self.nmu / 2);
        if ground {
            0.5 - 0.5 * half
        } else {
            0.5 + 0.5 * half
        }
    }

    /// u_μs, a texture coordinate.
    #[inline]
    pub fn u_mu_s(&self, mu_s: f64) -> f64 {
        texcoord_from_unit(self.x_mu_s(mu_s), self.nmu_s)
    }

    /// The three texture coordinates (u_h, u_μ, u_μs) of (r, μ, μ_s) on a ray that meets the
    /// ground or not.
    #[inline]
    pub fn coords(&self, r: f64, mu: f64, mu_s: f64, ground: bool) -> [f64; 3] {
        [self.u_h(r), self.u_mu(r, mu, ground), self.u_mu_s(mu_s)]
    }

    /// Inverse of [`Params::coords`]: (r, μ, μ_s, ground).
    pub fn from_coords(&self, [u_h, u_mu, u_mu_s]: [f64; 3]) -> (f64, f64, f64, bool) {
        let r = self.r_of_x_h(unit_from_texcoord(u_h, self.nh));
        let half = self.nmu / 2;
        let ground = u_mu < 0.5;
        let x = if ground {
            unit_from_texcoord(1.0 - 2.0 * u_mu, half)
        } else {
            unit_from_texcoord(2.0 * u_mu - 1.0, half)
        };
        let mu = self.mu_of_x_mu(r, x, ground);
        let mu_s = self.mu_s_of_x(unit_from_texcoord(u_mu_s, self.nmu_s));
        (r, mu, mu_s, ground)
    }

    /// The radius (m) of altitude texel z's centre.
    #[inline]
    pub fn texel_r(&self, z: usize) -> f64 {
        self.r_of_x_h(z as f64 / (self.nh - 1) as f64)
    }

    /// (μ, ground) of view-zenith texel y's centre at radius r.
    #[inline]
    pub fn texel_mu(&self, r: f64, y: usize) -> (f64, bool) {
        let half = self.nmu / 2;
        if y < half {
            let x = (half - 1 - y) as f64 / (half - 1) as f64;
            (self.mu_of_x_mu(r, x, true), true)
        } else {
            let x = (y - half) as f64 / (half - 1) as f64;
            (self.mu_of_x_mu(r, x, false), false)
        }
    }

    /// μ_s of sun-zenith texel x's centre.
    #[inline]
    pub fn texel_mu_s(&self, x: usize) -> f64 {
        self.mu_s_of_x(x as f64 / (self.nmu_s - 1) as f64)
    }

    #[inline]
    fn power(&self, f: f64, p: f64) -> f64 {
        if p == 1.0 {
            f
        } else {
            f.powf(p)
        }
    }
}

/// [`Params::u_mu_s`] tabulated as texel positions for the hot loops (the multiple
/// scattering reads the table at a new μ_s per ray sample and azimuth): position(μ_s) =
/// u·n − 0.5 in [0, n − 1], linear in a 4097-entry table over μ_s ∈ [−1, 1]. The mapping is
/// smooth (an arctangent) but for its clamp at μ_s,min; the table is within 10⁻⁴ texel of it
/// away from that kink.
pub struct SunZenithPositions {
    n: usize,
    table: Vec<f64>,
}

impl SunZenithPositions {
    /// For the sun-zenith texels of `params`.
    pub fn new(params: &Params) -> SunZenithPositions {
        let k = 4096;
        let n = params.nmu_s;
        let table = (0..=k)
            .map(|j| {
                let mu_s = -1.0 + 2.0 * j as f64 / k as f64;
                (params.u_mu_s(mu_s) * n as f64 - 0.5).clamp(0.0, (n - 1) as f64)
            })
            .collect();
        SunZenithPositions { n, table }
    }

    /// (s0, s1, t): the two texels and the weight of s1.
    #[inline]
    pub fn filter(&self, mu_s: f64) -> (usize, usize, f64) {
        let k = self.table.len() - 1;
        let f = (mu_s.clamp(-1.0, 1.0) + 1.0) * 0.5 * k as f64;
        // 0 ≤ f ≤ k and 0 ≤ p ≤ n − 1, far below 2³¹: truncation is floor, and through i32
        // it is one instruction on baseline x86-64 (through usize a branchy sequence).
        let j = (f as i32 as usize).min(k - 1);
        let t = f - j as f64;
        let p = self.table[j] + t * (self.table[j + 1] - self.table[j]);
        let s0 = (p as i32 as usize).min(self.n - 1);
        (s0, (s0 + 1).min(self.n - 1), p - s0 as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::math::sphere::ray_intersects_ground;
    use crate::spectrum::Wavelengths;

    fn params() -> Params {
        params_with(SunZenithMapping::Yusov)
    }

    fn params_with(sun_zenith_mapping: SunZenithMapping) -> Params {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let config = Elek3dConfig {
            sun_zenith_mapping,
            ..Elek3dConfig::default()
        };
        Params::new(&model, &config)
    }

    #[test]
    fn coordinates_round_trip_on_both_sides_of_the_horizon() {
        for mapping in [SunZenithMapping::Yusov, SunZenithMapping::Tables4d] {
            round_trips(&params_with(mapping));
        }
    }

    fn round_trips(p: &Params) {
        for &h in &[1.0, 150.0, 2_000.0, 10_000.0, 59_000.0] {
            let r = p.bottom + h;
            let mu_h = horizon_mu(r, p.bottom);
            for &mu in &[
                -0.95,
                mu_h - 0.05,
                mu_h - 1e-4,
                mu_h + 1e-4,
                0.01,
                0.3,
                0.99,
            ] {
                for &mu_s in &[p.mu_s_min, -0.1, 0.0, 0.02, 0.5, 1.0] {
                    let ground = ray_intersects_ground(r, mu, p.bottom);
                    let u = p.coords(r, mu, mu_s, ground);
                    // The horizon split: ground rays in the lower half, sky rays above.
                    assert_eq!(u[1] < 0.5, ground, "h {h} μ {mu}");
                    let (r2, mu2, mu_s2, ground2) = p.from_coords(u);
                    assert_eq!(ground2, ground);
                    assert!((r2 - r).abs() < 1e-6 * h.max(1.0), "h {h}: r {r} → {r2}");
                    assert!((mu2 - mu).abs() < 1e-9, "h {h}: μ {mu} → {mu2}");
                    assert!((mu_s2 - mu_s).abs() < 1e-9, "μ_s {mu_s} → {mu_s2}");
                }
            }
        }
    }

    #[test]
    fn texel_centres_are_the_mapping_at_texel_centres() {
        for mapping in [SunZenithMapping::Yusov, SunZenithMapping::Tables4d] {
            texel_centres(&params_with(mapping));
        }
        // Yusov's constants: his μ_s = −0.1975 lower end is t = −0.74·1.1 to 0.5 %.
        let yusov_t_min = (-0.1975 * SUN_ZENITH_T_MAX.tan()).atan();
        assert!((yusov_t_min / (-0.74 * 1.1) - 1.0).abs() < 5e-3);
    }

    fn texel_centres(p: &Params) {
        for z in 0..p.nh {
            let r = p.texel_r(z);
            let u_h = (z as f64 + 0.5) / p.nh as f64;
            assert!((p.u_h(r) - u_h).abs() < 1e-12, "z {z}");
            let mut last = -2.0;
            for y in 0..p.nmu {
                let (mu, ground) = p.texel_mu(r, y);
                let u_mu = (y as f64 + 0.5) / p.nmu as f64;
                assert!((p.u_mu(r, mu, ground) - u_mu).abs() < 1e-9, "z {z} y {y}");
                assert_eq!(ground, y < p.nmu / 2);
                // μ grows with the texel index through both halves.
                assert!(mu >= last, "z {z} y {y}: {mu} after {last}");
                last = mu;
            }
        }
        for x in 0..p.nmu_s {
            let u = (x as f64 + 0.5) / p.nmu_s as f64;
            assert!((p.u_mu_s(p.texel_mu_s(x)) - u).abs() < 1e-9);
        }
        assert!((p.texel_mu_s(0) - p.mu_s_min).abs() < 1e-9);
        assert!((p.texel_mu_s(p.nmu_s - 1) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn view_zenith_texels_crowd_towards_the_horizon() {
        // From the ground, Yusov's power 0.2 puts a third of the sky half within 0.25° of the
        // horizon, and the last texel below the zenith at 67° (a step of 0.08 in μ).
        let p = params();
        let r = p.bottom + 1.0;
        let half = p.nmu / 2;
        let elevation = |y| p.texel_mu(r, y).0.asin().to_degrees();
        assert!(elevation(half + half / 3) < 0.25);
        assert!(elevation(half + 1) < 1e-3);
        for y in half..p.nmu - 1 {
            assert!(elevation(y + 1) - elevation(y) < 25.0, "texel {y}");
        }
    }

    #[test]
    fn sun_zenith_positions_follow_the_mapping() {
        let p = params();
        let table = SunZenithPositions::new(&p);
        let n = p.nmu_s as f64;
        for i in 0..=400 {
            let mu_s = -1.0 + 2.0 * i as f64 / 400.0;
            if (mu_s - p.mu_s_min).abs() < 1e-3 {
                continue;
            }
            let want = (p.u_mu_s(mu_s) * n - 0.5).clamp(0.0, n - 1.0);
            let (s0, _, t) = table.filter(mu_s);
            assert!(
                (s0 as f64 + t - want).abs() < 1e-4,
                "μ_s {mu_s}: {} vs {want}",
                s0 as f64 + t
            );
        }
    }
}
