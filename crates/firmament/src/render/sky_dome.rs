//! The sky's irradiance on a surface under a horizon, weighted by the sky's radiance.
//!
//! A sky method's irradiance is that of a horizontal plane under the whole sky; the
//! terrain's ambient occlusion (`scene::terrain::occlusion`, Dozier & Frew 1990) scales it
//! by the cosine-weighted share of the sky its horizon leaves, which is right for a uniform
//! sky. At golden hour the sky is far from uniform: the low sky round the sun (its aureole
//! and the bright horizon beneath it) is ten to a hundred times the rest, and it is exactly
//! what a ridge hides from a valley in its shadow. Shaded point by point with 2 048
//! directions (the terrain's own light included), the valley's shadowed floor gets 0.80 to
//! 0.92 of the irradiance the uniform share gives it (docs/accuracy.md).
//!
//! A [`SkyDome`] holds, for one light, the sky's radiance L(ω) from the sky method at one
//! point, integrated over [`HORIZON_AZIMUTHS`] sectors of azimuth (centred on the
//! horizon's azimuths) from each elevation b up to the zenith, as the three moments
//! M(b) = ∫∫_{e > b} L(e, φ) ω cos e de dφ (ω = (east, north, up); cos e de dφ the solid
//! angle). The irradiance on a surface with normal n under horizons β_k is then
//! Σ_k n·M_k(max(β_k, e₀,k)), e₀,k where the surface's own plane cuts the sky in sector k:
//! the integral of L(ω) max(0, n·ω) over the visible sky (to the sector's width). It is
//! used as a share of the open plane's, Σ_k M_k,up(0), times the sky method's irradiance,
//! so the dome gives only the sky's shape.

use crate::math::Vec3;
use crate::scene::surface::HORIZON_AZIMUTHS;
use crate::sky::{Shadow, SkyView};
use crate::spectrum::MAX_CHANNELS;

/// Azimuths sampled per sector.
const SUBSECTORS: usize = 12;

/// Elevation nodes (degrees): uniform pieces [start, end) with their steps, closest near
/// the horizon and the low sun; the last node is 90° (`DOME_PIECES` in WGSL).
pub const PIECES: [(f64, f64, f64); 3] = [(0.0, 20.0, 0.5), (20.0, 50.0, 1.5), (50.0, 90.0, 2.5)];

/// Nodes in each piece.
pub fn piece_len(p: (f64, f64, f64)) -> usize {
    ((p.1 - p.0) / p.2).round() as usize
}

/// Elevation nodes (degrees, 0 to 90).
fn nodes_deg() -> Vec<f64> {
    let mut e: Vec<f64> = (PIECES.iter())
        .flat_map(|&p| (0..piece_len(p)).map(move |i| p.0 + p.2 * i as f64))
        .collect();
    e.push(90.0);
    e
}

/// The node below elevation `b` (rad, in [0, 90°)) and the fraction towards the next.
fn node_of(b: f64) -> (usize, f64) {
    let d = b.to_degrees();
    let mut first = 0;
    for p in PIECES {
        if d < p.1 {
            let x = (d - p.0).max(0.0) / p.2;
            let i = (x as usize).min(piece_len(p) - 1);
            return (first + i, x - i as f64);
        }
        first += piece_len(p);
    }
    (first - 1, 1.0)
}

/// The sky's radiance moments per sector (module doc) for one light.
pub struct SkyDome {
    channels: usize,
    /// Node elevations (rad).
    nodes: Vec<f64>,
    /// M_k(b) at each node: `((k·nodes + j)·3 + axis)·channels + c`, axis 0 east, 1 north,
    /// 2 up.
    moments: Vec<f64>,
    /// Σ_k M_k,up(0): the open plane's irradiance per channel.
    open: [f64; MAX_CHANNELS],
    /// (cos θ_k, sin θ_k) of each sector's centre.
    centres: [(f64, f64); HORIZON_AZIMUTHS],
}

impl SkyDome {
    /// The dome of `view`'s light seen from its observer (planet-centred, with the world's
    /// east and north: the x and y axes, as at the terrain's plane), `channels` channels.
    pub fn new(view: &dyn SkyView, channels: usize) -> SkyDome {
        let n = channels;
        let nodes: Vec<f64> = nodes_deg().into_iter().map(f64::to_radians).collect();
        let m = nodes.len();
        let width = std::f64::consts::TAU / HORIZON_AZIMUTHS as f64;
        let mut moments = vec![0.0; HORIZON_AZIMUTHS * m * 3 * n];
        let mut l = [0.0; MAX_CHANNELS];
        // ∫ L ω cos e dφ over the sector at each node (midpoints in azimuth).
        let mut ring = vec![0.0; m * 3 * n];
        for k in 0..HORIZON_AZIMUTHS {
            ring.iter_mut().for_each(|v| *v = 0.0);
            for s in 0..SUBSECTORS {
                let theta = width * (k as f64 + (s as f64 + 0.5) / SUBSECTORS as f64 - 0.5);
                let (sin_t, cos_t) = theta.sin_cos();
                for (j, &e) in nodes.iter().enumerate() {
                    let (sin_e, cos_e) = e.sin_cos();
                    let dir = Vec3::new(cos_e * cos_t, cos_e * sin_t, sin_e);
                    view.sky_radiance(dir, Shadow::None, &mut l[..n], &mut []);
                    let axes = [cos_e * cos_t, cos_e * sin_t, sin_e];
                    for (a, w) in axes.iter().enumerate() {
                        for c in 0..n {
                            ring[(j * 3 + a) * n + c] +=
                                l[c] * w * cos_e * width / SUBSECTORS as f64;
                        }
                    }
                }
            }
            // Cumulative from the zenith down (trapezoids in e).
            let base = k * m * 3 * n;
            for j in (0..m - 1).rev() {
                let de = nodes[j + 1] - nodes[j];
                for i in 0..3 * n {
                    moments[base + j * 3 * n + i] = moments[base + (j + 1) * 3 * n + i]
                        + 0.5 * de * (ring[j * 3 * n + i] + ring[(j + 1) * 3 * n + i]);
                }
            }
        }
        let mut open = [0.0; MAX_CHANNELS];
        for k in 0..HORIZON_AZIMUTHS {
            for c in 0..n {
                open[c] += moments[(k * m * 3 + 2) * n + c];
            }
        }
        SkyDome {
            channels,
            nodes,
            moments,
            open,
            centres: std::array::from_fn(|k| {
                let (s, c) = (width * k as f64).sin_cos();
                (c, s)
            }),
        }
    }

    /// Elevation nodes per sector.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// M_k(b) at each node (module doc): `((k·nodes + j)·3 + axis)·channels + c`, axis 0
    /// east, 1 north, 2 up (W·m⁻²·nm⁻¹).
    pub fn moments(&self) -> &[f64] {
        &self.moments
    }

    /// Σ_k M_k,up(0), the open horizontal plane's irradiance, per channel.
    pub fn open(&self) -> &[f64] {
        &self.open[..self.channels]
    }

    /// The sky's irradiance on a surface at a point whose local vertical is `up` (unit),
    /// with unit `normal`, under horizons `horizon` ([`crate::scene::Surface::horizon`]),
    /// as a share of the open horizontal plane's, per channel into `out`.
    pub fn share(
        &self,
        up: Vec3,
        normal: Vec3,
        horizon: &[f64; HORIZON_AZIMUTHS],
        out: &mut [f64],
    ) {
        let n = self.channels;
        let m = self.nodes.len();
        // The normal in the local frame: east and north as the world's x and y, made
        // perpendicular to `up`.
        let east = (Vec3::X - up * up.x).normalize_or_zero();
        let north = up.cross(east);
        let (ne, nn, nu) = (normal.dot(east), normal.dot(north), normal.dot(up));
        let mut sum = [0.0; MAX_CHANNELS];
        for (k, (&beta, &(cos_t, sin_t))) in horizon.iter().zip(&self.centres).enumerate() {
            // Where the surface's plane cuts the sky at the sector's centre: n·ω = 0, at
            // e₀ = atan(−a/n_up) (below the horizon when a ≥ 0).
            let a = ne * cos_t + nn * sin_t;
            let b = if a < 0.0 {
                beta.max((-a).atan2(nu))
            } else {
                beta
            };
            if b >= std::f64::consts::FRAC_PI_2 {
                continue;
            }
            let (j, f) = node_of(b);
            let lo = &self.moments[(k * m + j) * 3 * n..][..3 * n];
            let hi = &self.moments[(k * m + j + 1) * 3 * n..][..3 * n];
            for c in 0..n {
                let v = ne * (lo[c] + f * (hi[c] - lo[c]))
                    + nn * (lo[n + c] + f * (hi[n + c] - lo[n + c]))
                    + nu * (lo[2 * n + c] + f * (hi[2 * n + c] - lo[2 * n + c]));
                sum[c] += v.max(0.0);
            }
        }
        for c in 0..n {
            out[c] = if self.open[c] > 0.0 {
                sum[c] / self.open[c]
            } else {
                0.0
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Light;

    /// A sky of radiance `l(dir)` in every channel.
    struct Sky<F: Fn(Vec3) -> f64 + Send + Sync> {
        light: Light,
        l: F,
    }

    impl<F: Fn(Vec3) -> f64 + Send + Sync> SkyView for Sky<F> {
        fn light(&self) -> &Light {
            &self.light
        }
        fn sky_radiance(&self, dir: Vec3, _: Shadow, radiance: &mut [f64], _: &mut [f64]) {
            radiance.iter_mut().for_each(|v| *v = (self.l)(dir));
        }
        fn sky_radiance_to_point(&self, _: Vec3, _: Shadow, _: &mut [f64], _: &mut [f64]) {
            unreachable!()
        }
        fn transmittance_to_point(&self, _: Vec3, _: &mut [f64]) {
            unreachable!()
        }
        fn transmittance_to_light(&self, _: Vec3, _: &mut [f64]) {
            unreachable!()
        }
        fn sun_and_sky_irradiance(&self, _: Vec3, _: Vec3, _: &mut [f64], _: &mut [f64]) {
            unreachable!()
        }
    }

    fn dome(l: impl Fn(Vec3) -> f64 + Send + Sync) -> SkyDome {
        let model = crate::atmosphere::Atmosphere::earth()
            .resolve(&crate::spectrum::Wavelengths::rgb())
            .unwrap();
        let light = Light::sun(&model, Vec3::Z, false);
        SkyDome::new(&Sky { light, l }, 1)
    }

    #[test]
    fn a_uniform_sky_gives_the_sky_view_factors() {
        let d = dome(|_| 1.0);
        let mut s = [0.0];
        // Open and horizontal: the whole sky.
        d.share(Vec3::Z, Vec3::Z, &[0.0; HORIZON_AZIMUTHS], &mut s);
        assert!((s[0] - 1.0).abs() < 1e-9, "{}", s[0]);
        // Under a horizon at 30° all round: ∫ sin e cos e de from 30° to 90° = cos² 30°.
        d.share(
            Vec3::Z,
            Vec3::Z,
            &[30f64.to_radians(); HORIZON_AZIMUTHS],
            &mut s,
        );
        assert!((s[0] - 0.75).abs() < 2e-3, "{}", s[0]);
        // A plane tilted 60° towards the east, no horizon: the sky above the horizon
        // seen by it, ∫ max(0, n·ω) dω = π(1 + cos 60°)/2 (the isotropic sky's view
        // factor), to the sectors' width (within 2 %).
        let tilt = 60f64.to_radians();
        let n = Vec3::new(tilt.sin(), 0.0, tilt.cos());
        d.share(Vec3::Z, n, &[0.0; HORIZON_AZIMUTHS], &mut s);
        assert!(
            (s[0] / (0.5 * (1.0 + tilt.cos())) - 1.0).abs() < 0.02,
            "{}",
            s[0]
        );
    }

    /// ∫ L(ω) max(0, n·ω) dω over the sky above `horizon` (constant over each sector), by
    /// the midpoint rule on a fine grid of elevations and azimuths.
    fn brute(l: &dyn Fn(Vec3) -> f64, n: Vec3, horizon: &[f64; HORIZON_AZIMUTHS]) -> f64 {
        let (ne, na) = (600, 1440);
        let (de, da) = (
            std::f64::consts::FRAC_PI_2 / ne as f64,
            std::f64::consts::TAU / na as f64,
        );
        let width = std::f64::consts::TAU / HORIZON_AZIMUTHS as f64;
        let mut sum = 0.0;
        for i in 0..na {
            let theta = (i as f64 + 0.5) * da;
            let k = ((theta / width + 0.5) as usize) % HORIZON_AZIMUTHS;
            for j in 0..ne {
                let e = (j as f64 + 0.5) * de;
                if e < horizon[k] {
                    continue;
                }
                let w = Vec3::new(e.cos() * theta.cos(), e.cos() * theta.sin(), e.sin());
                sum += l(w) * n.dot(w).max(0.0) * e.cos() * de * da;
            }
        }
        sum
    }

    #[test]
    fn a_bright_sector_weighs_more() {
        // Three times as bright within 30° of the east.
        let l = |d: Vec3| {
            if d.y.atan2(d.x).abs() < 30f64.to_radians() {
                3.0
            } else {
                1.0
            }
        };
        let d = dome(l);
        let open = brute(&l, Vec3::Z, &[0.0; HORIZON_AZIMUTHS]);
        let tilt = 40f64.to_radians();
        let east = Vec3::new(tilt.sin(), 0.0, tilt.cos());
        let west = Vec3::new(-tilt.sin(), 0.0, tilt.cos());
        let mut ridge = [0.0; HORIZON_AZIMUTHS];
        ridge[0] = 20f64.to_radians();
        ridge[7] = 10f64.to_radians();
        let mut s = [0.0];
        for (n, h) in [
            (Vec3::Z, ridge),
            (east, [0.0; HORIZON_AZIMUTHS]),
            (west, [0.0; HORIZON_AZIMUTHS]),
            (east, ridge),
        ] {
            d.share(Vec3::Z, n, &h, &mut s);
            let expected = brute(&l, n, &h) / open;
            // The sectors' width: the surface's plane is cut at each sector's centre.
            assert!(
                (s[0] / expected - 1.0).abs() < 0.02,
                "{n:?}: {} vs {expected}",
                s[0]
            );
        }
        // The east-facing slope gets more than the uniform sky's (1 + cos 40°)/2, the
        // west-facing less.
        d.share(Vec3::Z, east, &[0.0; HORIZON_AZIMUTHS], &mut s);
        assert!(s[0] > 1.1 * 0.5 * (1.0 + tilt.cos()), "{}", s[0]);
    }
}
