//! The table coordinates the precomputation passes tabulate once for their hot loops: the
//! (r, μ, μ_s, ν) of every scattering texel from its separable parts, and the μ_s mapping as
//! texel positions. Both give the values of the mappings in [`params`].

use super::ray_grading::RayGrading;
use crate::atmosphere::Model;
use crate::sky::bruneton4d::params::{self, Radii, TableSizes};

/// [`params::scattering_texel`] for every texel of the tables, from its separable parts computed
/// once: r per z, (μ, ground) per (z, y), μ_s per μ_s index (each a function of its own
/// texture coordinate only) and ν from them and u_ν, so the values are the same.
pub struct ScatteringGrid {
    nmu: usize,
    nmu_s: usize,
    r: Vec<f64>,
    mu: Vec<(f64, bool)>,
    mu_s: Vec<f64>,
    u_nu: Vec<f64>,
    /// Where each (r, μ) row's view ray is sampled (even steps until
    /// [`ScatteringGrid::with_graded_rays`]).
    pub rays: RayGrading,
}

impl ScatteringGrid {
    /// The grid of these sizes.
    pub fn new(radii: &Radii, s: &TableSizes) -> ScatteringGrid {
        let at = |i_nu, i_mu_s, y, z| {
            params::scattering_r_mu_mu_s_nu(radii, s, params::texel_uvwz(s, i_nu, i_mu_s, y, z))
        };
        let (nr, nmu) = (s.scattering_r, s.scattering_mu);
        ScatteringGrid {
            nmu,
            nmu_s: s.scattering_mu_s,
            r: (0..nr).map(|z| at(0, 0, 0, z).0).collect(),
            mu: (0..nr * nmu)
                .map(|i| {
                    let (_, mu, _, _, ground) = at(0, 0, i % nmu, i / nmu);
                    (mu, ground)
                })
                .collect(),
            mu_s: (0..s.scattering_mu_s).map(|i| at(0, i, 0, 0).2).collect(),
            u_nu: (0..s.scattering_nu)
                .map(|i| params::texel_uvwz(s, i, 0, 0, 0)[0])
                .collect(),
            rays: RayGrading::even(),
        }
    }

    /// The same grid with its view rays' samples graded through `model`
    /// ([`RayGrading::new`]).
    pub fn with_graded_rays(mut self, model: &Model, s: &TableSizes) -> ScatteringGrid {
        self.rays = RayGrading::new(model, &self, s);
        self
    }

    /// Same as [`params::scattering_texel`].
    #[inline]
    pub fn texel(&self, x: usize, y: usize, z: usize) -> (f64, f64, f64, f64, bool) {
        let (mu, ground) = self.mu[z * self.nmu + y];
        let mu_s = self.mu_s[x % self.nmu_s];
        let nu = params::nu_from_u_nu(mu, mu_s, self.u_nu[x / self.nmu_s]);
        let nu = params::clamp_nu(mu, mu_s, nu);
        (self.r[z], mu, mu_s, nu, ground)
    }
}

/// [`params::x_mu_s`] tabulated as texel positions for fast filtering (multiple-scattering hot loop):
/// `position(μ_s)` = u·n − 0.5 clamped to [0, n − 1], linear in a 4097-entry table over
/// s = sin(θ_s/2) = √((1 − μ_s)/2) ∈ [0, 1]: the mapping is linear in the sun's zenith angle
/// θ_s above its joint, smooth in s but not in μ_s at the zenith (a table over μ_s was 0.08
/// texel off there); the table error is below 2·10⁻⁵ texel but in the cells that hold the
/// mapping's kinks, at μ_s,min and at the joint (≈ 10⁻³).
pub struct MuSPositions {
    n: usize,
    table: Vec<f64>,
}

impl MuSPositions {
    /// For `n` μ_s texels.
    pub fn new(radii: &Radii, n: usize) -> MuSPositions {
        let map = params::MuSMap::new(radii);
        let k = 4096;
        let table = (0..=k)
            .map(|j| {
                let s = j as f64 / k as f64;
                let mu_s = 1.0 - 2.0 * s * s;
                (params::texcoord_from_unit(map.x(mu_s), n) * n as f64 - 0.5)
                    .clamp(0.0, (n - 1) as f64)
            })
            .collect();
        MuSPositions { n, table }
    }

    /// (s0, s1, t): the two texels and the weight of s1.
    #[inline]
    pub fn filter(&self, mu_s: f64) -> (usize, usize, f64) {
        let k = self.table.len() - 1;
        let f = ((1.0 - mu_s.clamp(-1.0, 1.0)) * 0.5).sqrt() * k as f64;
        // 0 ≤ f ≤ k and 0 ≤ p ≤ n − 1, far below 2³¹: truncating through i32 gives the same
        // index as through usize, with a cheaper conversion on x86-64.
        let j = (f as i32 as usize).min(k - 1);
        let t = f - j as f64;
        let (p0, p1) = (self.table[j], self.table[j + 1]);
        let p = p0 + t * (p1 - p0);
        let s0 = (p as i32 as usize).min(self.n - 1);
        (s0, (s0 + 1).min(self.n - 1), p - s0 as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: Radii = crate::sky::bruneton4d::params::EARTH_RADII;

    #[test]
    fn scattering_grid_is_scattering_texel() {
        for s in [TableSizes::default(), TableSizes::small()] {
            let grid = ScatteringGrid::new(&G, &s);
            for z in 0..s.scattering_r {
                for y in 0..s.scattering_mu {
                    for x in 0..s.scattering_nu * s.scattering_mu_s {
                        assert_eq!(
                            grid.texel(x, y, z),
                            params::scattering_texel(&G, &s, x, y, z)
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn mu_s_positions_follow_the_mapping() {
        let n = 40;
        let table = MuSPositions::new(&G, n);
        let map = params::MuSMap::new(&G);
        let near_zenith = [0.999, 0.99999, 1.0];
        for mu_s in (0..=200)
            .map(|i| -1.0 + 2.0 * i as f64 / 200.0)
            .chain(near_zenith)
        {
            let want = (params::texcoord_from_unit(map.x(mu_s), n) * n as f64 - 0.5)
                .clamp(0.0, (n - 1) as f64);
            let (s0, _, t) = table.filter(mu_s);
            let got = s0 as f64 + t;
            assert!((got - want).abs() < 2e-5, "μ_s {mu_s}: {got} vs {want}");
        }
    }
}
