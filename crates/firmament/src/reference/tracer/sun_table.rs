//! A coarse table of the optical depth towards the sun, τ(r, μ_s), for one wavelength:
//! only the shape of the distance pdf of twilight sampling (`lit`) reads it, never an
//! estimate, so its interpolation error costs variance, not bias.
//!
//! Grid: altitude h = H·u² (dense near the ground, where τ changes fastest) and, at each
//! altitude, μ_s from the horizon's μ_h(r) = −√(r² − R_g²)/r up: μ_s = μ_h + (1 − μ_h)·v²
//! (dense at grazing rays, whose τ climbs steeply). Bilinear in (u, v). Below the horizon
//! the sun is behind the planet (no transmittance), judged for the disk's upper limb so
//! that a partly set sun still counts as lit.

use super::Channel;

/// Altitudes and sun directions of the table.
const N_H: usize = 32;
const N_MU: usize = 64;

/// τ towards the sun on the (u, v) grid of the module documentation.
pub(crate) struct SunTable {
    tau: Vec<f64>,
    bottom: f64,
    height: f64,
    sin_alpha: f64,
    cos_alpha: f64,
}

impl SunTable {
    /// The table of `ch`'s constituents (the scene's volumes are not in it).
    pub(crate) fn new(ch: &Channel) -> SunTable {
        let (r_g, height) = (ch.bottom, ch.height);
        let mut tau = Vec::with_capacity(N_H * N_MU);
        for i in 0..N_H {
            let u = i as f64 / (N_H - 1) as f64;
            let h = height * u * u;
            let x = h * (2.0 * r_g + h);
            let r = r_g + h;
            let mu_h = -x.sqrt() / r;
            for j in 0..N_MU {
                let v = j as f64 / (N_MU - 1) as f64;
                let mu = mu_h + (1.0 - mu_h) * v * v;
                let b = r * mu;
                // To the top, past the tangent point when the ray grazes the ground.
                let c = x - ch.x_top;
                let t_top = -b + (b * b - c).max(0.0).sqrt();
                tau.push(ch.optical_depth(x, b, t_top));
            }
        }
        let one_minus_cos = ch.one_minus_cos_alpha;
        SunTable {
            tau,
            bottom: r_g,
            height,
            sin_alpha: ch.sin_alpha,
            cos_alpha: 1.0 - one_minus_cos,
        }
    }

    /// Transmittance towards the sun at a point with x = r² − R_g² and b_s = r μ_s (μ_s
    /// the cosine of the sun's zenith angle there); 0 when even the disk's upper limb is
    /// below the horizon.
    pub(crate) fn transmittance(&self, x: f64, b_s: f64) -> f64 {
        let x = x.max(0.0);
        let r = (self.bottom * self.bottom + x).sqrt();
        let h = (x / (r + self.bottom)).min(self.height);
        let mu = (b_s / r).clamp(-1.0, 1.0);
        // The upper limb: cos(θ − α), or the zenith when the sun is within α of it.
        let sin_t = ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt();
        let mu = if sin_t <= self.sin_alpha && mu > 0.0 {
            1.0
        } else {
            (mu * self.cos_alpha + sin_t * self.sin_alpha).min(1.0)
        };
        let mu_h = -x.sqrt() / r;
        if mu < mu_h {
            return 0.0;
        }
        let u = (h / self.height).max(0.0).sqrt() * (N_H - 1) as f64;
        let v = ((mu - mu_h) / (1.0 - mu_h)).max(0.0).sqrt() * (N_MU - 1) as f64;
        let (i, j) = ((u as usize).min(N_H - 2), (v as usize).min(N_MU - 2));
        let (fu, fv) = (u - i as f64, v - j as f64);
        let at = |i: usize, j: usize| self.tau[i * N_MU + j];
        let tau = (1.0 - fu) * ((1.0 - fv) * at(i, j) + fv * at(i, j + 1))
            + fu * ((1.0 - fv) * at(i + 1, j) + fv * at(i + 1, j + 1));
        (-tau).exp()
    }
}
