//! Multiple scattering in a cloud by the local plane-parallel approximation: the diffuse
//! light at a point is that of a homogeneous slab with the point's vertical optical depths
//! above and below, solved by the δ-Eddington two-stream method (Joseph, Wiscombe &
//! Weinman 1976, "The delta-Eddington approximation for radiative flux transfer", J. Atmos.
//! Sci. 33; the solution's form as in Meador & Weaver 1980 and Toon et al. 1989, J.
//! Geophys. Res. 94, eq. 1–2 and Table 1).
//!
//! With τ measured down from the slab's top, the diffuse fluxes obey
//! dF↑/dτ = γ₁F↑ − γ₂F↓ − ω′γ₃·E·e^{−τ/μ₀},  dF↓/dτ = γ₂F↑ − γ₁F↓ + ω′γ₄·E·e^{−τ/μ₀},
//! E the beam's irradiance normal to it (its flux on the horizontal μ₀E·e^{−τ/μ₀}; with
//! ω′ = 1, F↓ − F↑ + μ₀E·e^{−τ/μ₀} is constant),
//! with the Eddington coefficients γ₁ = (7 − ω′(4 + 3g′))/4, γ₂ = −(1 − ω′(4 − 3g′))/4,
//! γ₃ = (2 − 3g′μ₀)/4, γ₄ = 1 − γ₃, after δ-scaling (f = g²: τ′ = (1 − ωf)τ,
//! ω′ = (1 − f)ω/(1 − ωf), g′ = g/(1 + g)). In the Eddington approximation the radiance is
//! I₀ + I₁μ with F↑ + F↓ = 2πI₀: the mean diffuse radiance I₀ = (F↑ + F↓)/(2π) is what the
//! renderer scatters (isotropically) at the point, in place of octaves.
//!
//! Tabulated per layer (albedo and phase): for the sun, I₀ per unit irradiance E normal to
//! the beam at the slab's top, over the relative depth, the slab's thickness and μ₀; for
//! diffuse light entering the top (the sky), I₀ per unit hemispheric irradiance, over the
//! relative depth and the thickness (light from below is the same read upside down).

use crate::medium::PhaseFunction;

/// Relative depths (0 top … 1 base) in the tables.
pub const DEPTHS: usize = 33;
/// Slab optical thicknesses, τ* = MAX_THICKNESS·s², s uniform.
pub const THICKNESSES: usize = 48;
/// The thickest slab tabulated (thicker reads as this).
pub const MAX_THICKNESS: f64 = 400.0;
/// Cosines of the sun's zenith angle, μ₀ = (i + ½)/n... uniform in (0, 1].
pub const COSINES: usize = 24;

/// The two-stream tables of one medium.
#[derive(Clone, Debug)]
pub struct TwoStream {
    /// δ-scaling: the scattering's fraction outside the forward peak, 1 − f, and the
    /// extinction's, 1 − ωf (f = g²).
    pub scattering_scale: f64,
    /// 1 − ωf.
    pub extinction_scale: f64,
    /// The δ-scaled asymmetry g′ = g/(1 + g).
    pub asymmetry: f64,
    /// The phase of what the δ-scaling keeps, min(p, this) (sr⁻¹): p cut at the cone that
    /// holds the forward peak's fraction f (Potter 1970,
    /// [`PhaseFunction::truncated_forward_value`]).
    pub forward_phase_cap: f64,
    /// (I₀, I₁)/E of the sun's light: [cosine][thickness][depth].
    sun: Vec<[f64; 2]>,
    /// (I₀, I₁)/E↓ of diffuse light entering the top: [thickness][depth].
    diffuse: Vec<[f64; 2]>,
}

/// (I₀, I₁) from (F↑, F↓).
fn moments((up, down): (f64, f64)) -> [f64; 2] {
    let pi = std::f64::consts::PI;
    [(up + down) / (2.0 * pi), 3.0 * (up - down) / (4.0 * pi)]
}

/// The δ-scaled single-scattering albedo and asymmetry of a medium of albedo `omega`
/// and asymmetry `g`, and the optical-depth factor 1 − ωf.
fn delta_scaled(omega: f64, g: f64) -> (f64, f64, f64) {
    let f = g * g;
    let scale = 1.0 - omega * f;
    ((1.0 - f) * omega / scale, g / (1.0 + g), scale)
}

/// F↑ + F↓ at relative depths `depths` (0…1) of a slab of (δ-scaled) thickness `tau`,
/// ω′, g′, lit by a beam of unit irradiance at `mu0` (flux μ₀ on the top; `mu0` ≤ 0: no
/// beam) and by
/// diffuse flux `top` entering the top; no light from below (a black base).
#[cfg(test)]
fn fluxes(omega: f64, g: f64, tau: f64, mu0: f64, top: f64, depths: &[f64]) -> Vec<f64> {
    flux_pairs(omega, g, tau, mu0, top, depths)
        .into_iter()
        .map(|(up, down)| up + down)
        .collect()
}

/// (F↑, F↓) at the depths, as [`fluxes`].
fn flux_pairs(omega: f64, g: f64, tau: f64, mu0: f64, top: f64, depths: &[f64]) -> Vec<(f64, f64)> {
    let g1 = (7.0 - omega * (4.0 + 3.0 * g)) / 4.0;
    let g2 = -(1.0 - omega * (4.0 - 3.0 * g)) / 4.0;
    let k = (g1 * g1 - g2 * g2).max(1e-18).sqrt();
    // The beam's particular solution α·e^{−τ/μ₀}, β·e^{−τ/μ₀} (μ₀ nudged off the
    // resonance k = 1/μ₀).
    let (alpha, beta, inv_mu) = if mu0 > 0.0 {
        let mut m = mu0;
        if (k * m - 1.0).abs() < 1e-6 {
            m *= 1.0 + 1e-5;
        }
        let g3 = (2.0 - 3.0 * g * m) / 4.0;
        let g4 = 1.0 - g3;
        let s = 1.0; // the beam's irradiance normal to it (its flux on the horizontal: μ₀)
        let (inv, a11, a12, a21, a22) = (1.0 / m, g1 + 1.0 / m, -g2, g2, -(g1 - 1.0 / m));
        let (r1, r2) = (omega * g3 * s, -omega * g4 * s);
        let det = a11 * a22 - a12 * a21;
        (
            (r1 * a22 - a12 * r2) / det,
            (a11 * r2 - a21 * r1) / det,
            inv,
        )
    } else {
        (0.0, 0.0, 0.0)
    };
    // F↑ = a·e^{k(τ−τ*)} + b·e^{−kτ} + α·e^{−τ/μ₀} (the growing mode scaled to the base so
    // nothing overflows), F↓ = a·c₊·e^{k(τ−τ*)} + b·c₋·e^{−kτ} + β·e^{−τ/μ₀},
    // c± = (γ₁ ∓ k)/γ₂. Boundaries: F↓(0) = top, F↑(τ*) = 0.
    let (cp, cm) = ((g1 - k) / g2, (g1 + k) / g2);
    let e_tau = (-k * tau).exp();
    let beam_base = (-tau * inv_mu).exp();
    // F↓(0): a·cp·e_tau + b·cm + β = top;  F↑(τ*): a + b·e_tau + α·beam_base = 0.
    let (m11, m12, r1) = (cp * e_tau, cm, top - beta);
    let (m21, m22, r2) = (1.0, e_tau, -alpha * beam_base);
    let det = m11 * m22 - m12 * m21;
    let a = (r1 * m22 - m12 * r2) / det;
    let b = (m11 * r2 - m21 * r1) / det;
    depths
        .iter()
        .map(|&u| {
            let t = u * tau;
            let grow = (k * (t - tau)).exp();
            let decay = (-k * t).exp();
            let beam = (-t * inv_mu).exp();
            let up = a * grow + b * decay + alpha * beam;
            let down = a * cp * grow + b * cm * decay + beta * beam;
            (up.max(0.0), down.max(0.0))
        })
        .collect()
}

impl TwoStream {
    /// The tables of a medium of single-scattering albedo `albedo` and phase function
    /// `phase` (its asymmetry, the mean cosine g, is what the two streams see).
    pub fn new(albedo: f64, phase: &PhaseFunction) -> TwoStream {
        let g = phase.mean_cosine();
        // ω = 1 exactly makes k = 0; the tables' albedo is kept just below.
        let (omega, g_scaled, scale) = delta_scaled(albedo.min(1.0 - 1e-6), g);
        let depths: Vec<f64> = (0..DEPTHS)
            .map(|i| i as f64 / (DEPTHS - 1) as f64)
            .collect();
        let thickness = |j: usize| MAX_THICKNESS * (j as f64 / (THICKNESSES - 1) as f64).powi(2);
        let mut sun = Vec::with_capacity(COSINES * THICKNESSES * DEPTHS);
        for i in 0..COSINES {
            let mu0 = (i as f64 + 0.5) / COSINES as f64;
            for j in 0..THICKNESSES {
                let f = flux_pairs(omega, g_scaled, scale * thickness(j), mu0, 0.0, &depths);
                sun.extend(f.into_iter().map(moments));
            }
        }
        let mut diffuse = Vec::with_capacity(THICKNESSES * DEPTHS);
        for j in 0..THICKNESSES {
            let f = flux_pairs(omega, g_scaled, scale * thickness(j), 0.0, 1.0, &depths);
            diffuse.extend(f.into_iter().map(moments));
        }
        let f = g * g;
        TwoStream {
            asymmetry: g_scaled,
            forward_phase_cap: phase.truncated_forward_value(f),
            scattering_scale: 1.0 - f,
            extinction_scale: 1.0 - albedo * f,
            sun,
            diffuse,
        }
    }

    /// The sun's table, (I₀, I₁) per unit beam irradiance: [cosine][thickness][depth].
    pub fn sun_table(&self) -> &[[f64; 2]] {
        &self.sun
    }

    /// The table of diffuse light entering the top: [thickness][depth].
    pub fn diffuse_table(&self) -> &[[f64; 2]] {
        &self.diffuse
    }

    /// Fractional indices into the thickness and depth axes.
    #[inline]
    fn axes(thickness: f64, depth: f64) -> (f64, f64) {
        let tau = thickness.clamp(0.0, MAX_THICKNESS);
        let s = (tau / MAX_THICKNESS).sqrt() * (THICKNESSES - 1) as f64;
        let u = if tau > 0.0 {
            (depth / tau).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (s, u * (DEPTHS - 1) as f64)
    }

    /// Bilinear read of a [thickness][depth] plane starting at `base`.
    #[inline]
    fn plane(data: &[[f64; 2]], base: usize, s: f64, u: f64) -> [f64; 2] {
        let (j0, i0) = (s.floor() as usize, u.floor() as usize);
        let (j1, i1) = ((j0 + 1).min(THICKNESSES - 1), (i0 + 1).min(DEPTHS - 1));
        let (fs, fu) = (s - j0 as f64, u - i0 as f64);
        let at = |j: usize, i: usize, m: usize| data[base + j * DEPTHS + i][m];
        std::array::from_fn(|m| {
            let lo = at(j0, i0, m) + (at(j0, i1, m) - at(j0, i0, m)) * fu;
            let hi = at(j1, i0, m) + (at(j1, i1, m) - at(j1, i0, m)) * fu;
            lo + (hi - lo) * fs
        })
    }

    /// The diffuse radiance's moments (I₀, I₁; per unit irradiance normal to the sun's
    /// beam at the slab's top) at optical depth `depth` below the top of a slab of optical
    /// thickness `thickness` (both true, not δ-scaled) under a sun at `mu0`.
    pub fn sun(&self, thickness: f64, depth: f64, mu0: f64) -> [f64; 2] {
        if mu0 <= 0.0 {
            return [0.0; 2];
        }
        let (s, u) = Self::axes(thickness, depth);
        let c = (mu0 * COSINES as f64 - 0.5).clamp(0.0, (COSINES - 1) as f64);
        let (c0, fc) = (c.floor() as usize, c - c.floor());
        let c1 = (c0 + 1).min(COSINES - 1);
        let size = THICKNESSES * DEPTHS;
        let a = Self::plane(&self.sun, c0 * size, s, u);
        let b = Self::plane(&self.sun, c1 * size, s, u);
        [a[0] + (b[0] - a[0]) * fc, a[1] + (b[1] - a[1]) * fc]
    }

    /// The moments per unit hemispheric irradiance entering the top (`from_above`) or the
    /// base, at `depth` below the top of a slab of `thickness` (I₁ from the upward
    /// vertical either way).
    pub fn diffuse(&self, thickness: f64, depth: f64, from_above: bool) -> [f64; 2] {
        let depth = if from_above {
            depth
        } else {
            (thickness - depth).max(0.0)
        };
        let (s, u) = Self::axes(thickness, depth);
        let [i0, i1] = Self::plane(&self.diffuse, 0, s, u);
        [i0, if from_above { i1 } else { -i1 }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same equations integrated by a fine finite-difference scheme (the boundary
    /// value problem by shooting on the two linear solutions): F↑ + F↓ at the depths.
    fn fluxes_numerically(omega: f64, g: f64, tau: f64, mu0: f64, top: f64, u: f64) -> f64 {
        let g1 = (7.0 - omega * (4.0 + 3.0 * g)) / 4.0;
        let g2 = -(1.0 - omega * (4.0 - 3.0 * g)) / 4.0;
        let g3 = (2.0 - 3.0 * g * mu0) / 4.0;
        let g4 = 1.0 - g3;
        let n = 200_000;
        let h = tau / n as f64;
        // Integrate from the top with F↓(0) = top and F↑(0) = x; linear in x.
        let run = |x: f64| {
            let (mut up, mut down) = (x, top);
            let mut at_u = 0.0;
            for i in 0..n {
                if i == (u * n as f64) as usize {
                    at_u = up + down;
                }
                let t = (i as f64 + 0.5) * h;
                let beam = if mu0 > 0.0 { (-t / mu0).exp() } else { 0.0 };
                // Midpoint (RK2) step.
                let d_up = |u_: f64, d_: f64, b: f64| g1 * u_ - g2 * d_ - omega * g3 * b;
                let d_down = |u_: f64, d_: f64, b: f64| g2 * u_ - g1 * d_ + omega * g4 * b;
                let b0 = if mu0 > 0.0 {
                    (-(t - 0.5 * h) / mu0).exp()
                } else {
                    0.0
                };
                let um = up + 0.5 * h * d_up(up, down, b0);
                let dm = down + 0.5 * h * d_down(up, down, b0);
                up += h * d_up(um, dm, beam);
                down += h * d_down(um, dm, beam);
            }
            if u >= 1.0 {
                at_u = up + down;
            }
            (up, at_u)
        };
        let (u0, s0) = run(0.0);
        let (u1, s1) = run(1.0);
        // F↑(τ*) = 0.
        let x = -u0 / (u1 - u0);
        s0 + x * (s1 - s0)
    }

    #[test]
    fn two_stream_solution_satisfies_its_equations() {
        for &(omega, g, tau, mu0) in &[
            (0.99, 0.5, 3.0, 0.7),
            (0.9, 0.3, 8.0, 0.3),
            (0.999, 0.46, 10.0, 0.5),
        ] {
            for u in [0.0, 0.3, 0.8] {
                let analytic = fluxes(omega, g, tau, mu0, 0.0, &[u])[0];
                let numeric = fluxes_numerically(omega, g, tau, mu0, 0.0, u);
                assert!(
                    (analytic / numeric - 1.0).abs() < 1e-4,
                    "{omega} {g} {tau} {mu0} {u}: {analytic} vs {numeric}"
                );
                let analytic = fluxes(omega, g, tau, 0.0, 1.0, &[u])[0];
                let numeric = fluxes_numerically(omega, g, tau, 0.0, 1.0, u);
                assert!(
                    (analytic / numeric - 1.0).abs() < 1e-4,
                    "diffuse {u}: {analytic} vs {numeric}"
                );
            }
        }
    }

    #[test]
    fn a_conservative_slab_reflects_what_it_does_not_transmit() {
        // Energy: with ω → 1 and a black base, the flux leaving the top plus the flux
        // leaving the base (diffuse and direct) equals the flux entering.
        let (omega, g, scale) = delta_scaled(1.0 - 1e-9, 0.85);
        for &(tau, mu0) in &[(5.0, 0.8), (20.0, 0.5), (60.0, 0.2)] {
            let t = scale * tau;
            // F↑ at the top and F↓ at the base from F↑ + F↓ and the boundaries.
            let top_sum = fluxes(omega, g, t, mu0, 0.0, &[0.0])[0]; // F↑(0) (F↓(0) = 0)
            let base_sum = fluxes(omega, g, t, mu0, 0.0, &[1.0])[0]; // F↓(τ*) (F↑ = 0)
            let direct = mu0 * (-t / mu0).exp();
            let total = top_sum + base_sum + direct;
            assert!(
                (total - mu0).abs() < 1e-6 * mu0,
                "τ {tau} μ₀ {mu0}: {total} vs {mu0}"
            );
        }
        // The tables' diffuse light vanishes without light and grows into the slab from a
        // lit top: in a thick slab the light near the top exceeds that near the base.
        let ts = TwoStream::new(0.999, &PhaseFunction::HenyeyGreenstein { g: 0.54 });
        assert!(ts.sun(20.0, 1.0, 0.8)[0] > 3.0 * ts.sun(20.0, 19.0, 0.8)[0]);
        assert_eq!(ts.sun(20.0, 1.0, -0.1), [0.0; 2]);
        let (a, b) = (ts.diffuse(10.0, 3.0, true), ts.diffuse(10.0, 7.0, false));
        assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] + b[1]).abs() < 1e-12);
        // Near a lit top the light goes up on balance (F↑ > F↓: I₁ > 0), near the base down.
        assert!(ts.sun(20.0, 0.5, 0.8)[1] > 0.0 && ts.sun(20.0, 19.5, 0.8)[1] < 0.0);
    }
}
