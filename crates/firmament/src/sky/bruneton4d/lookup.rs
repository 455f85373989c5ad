//! Lookups shared by the precomputation passes and the evaluation API: transmittance
//! between points and to the sun from the transmittance table (Bruneton 2017
//! `GetTransmittance`, `GetTransmittanceToSun`) and irradiance lookups.
//!
//! Arguments as in [`crate::math::sphere`]: r the distance from the planet's centre (m), μ
//! the cosine of the view ray's zenith angle there, μ_s the sun's; outputs per channel,
//! transmittances in [0, 1], irradiance in W·m⁻²·nm⁻¹.

use super::mu_s_blend::{irradiance_twilight_cells, twilight_cells};
use super::params::{self, Radii, TableSizes};
use super::table::{LookupBlend, Table2, MAX_OPTICAL_DEPTH};
use crate::atmosphere::Model;
use crate::math::smoothstep;
use crate::math::sphere::{advance, distance_to_enter_sphere, safe_sqrt};
use crate::math::Vec3;
use crate::spectrum::with_channel_buffers;

/// What a lookup needs: the model's radii, the sizes and the transmittance table (as
/// optical depth: lookups interpolate τ = −ln T bilinearly, then take e^{−τ}).
#[derive(Clone, Copy)]
pub struct Lookup<'a> {
    /// Radii and μ_s,min.
    pub radii: Radii,
    /// Table sizes.
    pub sizes: TableSizes,
    /// Optical depth to the top of the atmosphere, τ(r, μ) = −ln T(r, μ)
    /// ([`super::Tables::optical_depth`]).
    pub optical_depth: &'a Table2,
    /// Angular radius of the light (rad): the sun's in the precomputation, the lit
    /// view's light when rendering.
    pub sun_angular_radius: f64,
    /// The μ_s cells of the scattering tables that take the twilight blend
    /// ([`super::mu_s_blend::twilight_cells`]).
    pub twilight_cells: usize,
    /// The same for the irradiance table ([`super::mu_s_blend::irradiance_twilight_cells`]).
    pub irradiance_twilight_cells: usize,
}

impl<'a> Lookup<'a> {
    /// Lookup context for a model.
    pub fn new(model: &Model, sizes: TableSizes, optical_depth: &'a Table2) -> Self {
        let radii = Radii::of(model);
        Lookup {
            radii,
            twilight_cells: twilight_cells(&radii, sizes.scattering_mu_s),
            irradiance_twilight_cells: irradiance_twilight_cells(sizes.irradiance_mu_s),
            sizes,
            optical_depth,
            sun_angular_radius: model.sun_angular_radius_rad,
        }
    }

    /// The blends of the 4D lookups ([`super::Table4::sample_into`]).
    #[inline]
    pub fn blend(&self) -> LookupBlend {
        LookupBlend {
            twilight_cells: self.twilight_cells,
            bottom_over_h: self.radii.bottom / self.radii.h(),
        }
    }

    /// T(r, μ) to the top of the atmosphere (ray assumed not to hit the ground): e^{−τ} of
    /// the bilinearly interpolated optical depth.
    #[inline]
    pub fn transmittance_to_top(&self, r: f64, mu: f64, out: &mut [f64]) {
        self.optical_depth_to_top(r, mu, out);
        for t in out.iter_mut() {
            *t = (-*t).exp();
        }
    }

    /// τ(r, μ) to the top of the atmosphere, bilinear in the optical-depth table.
    #[inline]
    pub fn optical_depth_to_top(&self, r: f64, mu: f64, out: &mut [f64]) {
        let (u, v) = params::transmittance_uv(
            &self.radii,
            r,
            mu,
            self.sizes.transmittance_mu,
            self.sizes.transmittance_r,
        );
        self.optical_depth.sample_into(u, v, out);
    }

    /// Transmittance over `d` metres from (r, μ), from differences of table optical depths
    /// (Bruneton 2017 `GetTransmittance` takes ratios of transmittances); uses the reversed
    /// ray when it hits the ground. 0 where either end's optical depth is the table's
    /// stand-in for T = 0: a difference of two capped depths means nothing (with 10¹² DU
    /// of ozone the near end's τ of 3.6·10⁶, capped, less the far end's true 100 inside the
    /// layer gave T = e⁻⁴ through the layer, and a sky brighter than the sun above it).
    #[inline]
    pub fn transmittance(&self, r: f64, mu: f64, d: f64, ground: bool, out: &mut [f64]) {
        let (r_d, mu_d) = advance(r, mu, d, self.radii.bottom, self.radii.top);
        // T = e^{−(τ_a − τ_b)}: τ_a into `out`, τ_b into `b`.
        with_channel_buffers(out.len(), |[b]| {
            if ground {
                self.optical_depth_to_top(r_d, -mu_d, out);
                self.optical_depth_to_top(r, -mu, b);
            } else {
                self.optical_depth_to_top(r, mu, out);
                self.optical_depth_to_top(r_d, mu_d, b);
            }
            for (o, &b) in out.iter_mut().zip(b.iter()) {
                *o = transmittance_between(*o, b);
            }
        });
    }

    /// [`Lookup::transmittance`] to each of `distances` (m) along one ray, into `out`
    /// (channels per distance): the ray's own end of the optical depth looked up once.
    pub fn transmittances_along(
        &self,
        r: f64,
        mu: f64,
        distances: &[f64],
        ground: bool,
        out: &mut [f64],
    ) {
        let n = out.len() / distances.len().max(1);
        with_channel_buffers(n, |[start, end]| {
            // From the ground the ray is reversed: τ(r_d, −μ_d) − τ(r, −μ).
            if ground {
                self.optical_depth_to_top(r, -mu, start);
            } else {
                self.optical_depth_to_top(r, mu, start);
            }
            for (&d, o) in distances.iter().zip(out.chunks_mut(n)) {
                let (r_d, mu_d) = advance(r, mu, d, self.radii.bottom, self.radii.top);
                let (a, b) = if ground {
                    self.optical_depth_to_top(r_d, -mu_d, end);
                    (&*end, &*start)
                } else {
                    self.optical_depth_to_top(r_d, mu_d, end);
                    (&*start, &*end)
                };
                for ((o, &a), &b) in o.iter_mut().zip(a).zip(b) {
                    *o = transmittance_between(a, b);
                }
            }
        });
    }

    /// Transmittance to the sun times the visible fraction of the solar disk above the
    /// planet's horizon (Bruneton 2017 `GetTransmittanceToSun`, smoothstep approximation).
    #[inline]
    pub fn transmittance_to_sun(&self, r: f64, mu_s: f64, out: &mut [f64]) {
        let fraction = self.sun_visible_fraction(r, mu_s);
        if fraction <= 0.0 {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        self.transmittance_to_top(r, mu_s, out);
        out.iter_mut().for_each(|o| *o *= fraction);
    }

    /// Transmittance from `point` (planet-centred, m; above the atmosphere too) to a light
    /// in unit direction `light`, with the planet's occlusion of its disk: above the top,
    /// along the light's ray from where it enters the atmosphere (1 when it misses it).
    pub fn transmittance_to_light(&self, point: Vec3, light: Vec3, out: &mut [f64]) {
        let r = point.length();
        let top = self.radii.top;
        if r > top {
            let rmu = point.dot(light);
            match distance_to_enter_sphere(r, rmu, top) {
                Some(d) => self.transmittance_to_sun(top, ((rmu + d) / top).clamp(-1.0, 1.0), out),
                None => out.iter_mut().for_each(|v| *v = 1.0),
            }
            return;
        }
        self.transmittance_to_sun(r, (point.dot(light) / r).clamp(-1.0, 1.0), out);
    }

    /// Visible fraction of the sun's disk above the planet at (r, μ_s), smoothstep in μ_s
    /// around the horizon over ± the sun's angular radius.
    #[inline]
    pub fn sun_visible_fraction(&self, r: f64, mu_s: f64) -> f64 {
        let sin_theta_h = self.radii.bottom / r;
        let cos_theta_h = -safe_sqrt(1.0 - sin_theta_h * sin_theta_h);
        let e = sin_theta_h * self.sun_angular_radius;
        smoothstep(-e, e, mu_s - cos_theta_h)
    }

    /// Irradiance-table lookup at (r, μ_s): for [`super::Tables::irradiance`], the sky's
    /// irradiance (W·m⁻²·nm⁻¹) on a horizontal surface at radius r; the twilight blend of
    /// [`super::mu_s_blend`] for a sun below the horizon, [`super::r_blend`]'s along r.
    #[inline]
    pub fn irradiance(&self, table: &Table2, r: f64, mu_s: f64, out: &mut [f64]) {
        let (u, v) = params::irradiance_uv(
            &self.radii,
            r,
            mu_s,
            self.sizes.irradiance_mu_s,
            self.sizes.irradiance_r,
        );
        table.sample_irradiance_into(u, v, self.irradiance_twilight_cells, out);
    }
}

/// e^{−(τ_a − τ_b)} between a ray's near end (optical depth `a` to the top) and its far end
/// (`b`), 0 where either is the table's stand-in for T = 0 (see [`Lookup::transmittance`]).
#[inline]
fn transmittance_between(a: f64, b: f64) -> f64 {
    if a < MAX_OPTICAL_DEPTH as f64 && b < MAX_OPTICAL_DEPTH as f64 {
        (-(a - b).max(0.0)).exp()
    } else {
        0.0
    }
}
