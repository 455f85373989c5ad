//! Hillaire 2020, *A Scalable and Production Ready Sky and Atmosphere Rendering Technique*
//! (EGSR 2020; Unreal Engine's SkyAtmosphere, Bevy's atmosphere): small tables cheap
//! enough to rebuild whenever the atmosphere changes.
//!
//! - Transmittance to the top (256×64, §5.1): the same table and mapping as the 4D method's
//!   (`bruneton4d::precompute::transmittance`), kept as optical depth.
//! - Multiple scattering Ψ_ms (32×32 over altitude and the light's zenith angle, §5.5):
//!   every order beyond the first from an isotropic second order and its geometric series
//!   ([`multiple_scattering`]); refused where the series breaks ([`F_MS_LIMIT`]).
//! - Sky view (192×108, §5.3): per observer and light, built with the view
//!   ([`sky_view`]).
//! - The sky's irradiance on surfaces (32×16): not in the paper (engines capture the sky
//!   into a sky light), from the method's own radiance ([`irradiance`]).
//! - Everything else (views from space, aerial perspective, shafts) is the ray march
//!   ([`march`]); the aerial-perspective froxel volume of §5.4 is the renderer's and serves
//!   every method (`render::aerial_volume`).
//!
//! Spectral as the rest of firmament: every table holds the model's channels.

pub mod harmonics;
pub mod irradiance;
pub(crate) mod lanes;
pub(crate) mod march;
pub mod multiple_scattering;
pub mod params;
pub mod sky_view;
pub(crate) mod step_lanes;
pub mod view;

pub use multiple_scattering::{MultipleScattering, MultipleScatteringModel, F_MS_LIMIT};
pub use view::Hillaire2020View;

use super::bruneton4d::precompute::compute_optical_depth_with;
use super::bruneton4d::{Lookup, Table2, TableSizes};
use super::{SkyMethod, SkyView};
use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::{Error, Result};
use march::{Marcher, Medium};
use params::altitude_mu_s_uv;

/// The most scattering orders the multiple-scattering pass gathers explicitly (each one
/// beyond the second costs about one more multiple-scattering pass).
pub const MAX_ORDERS: usize = 16;

/// Sizes and sample counts of the method's tables and marches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HillaireConfig {
    /// Transmittance (μ, r) texels (Hillaire: 256×64).
    pub transmittance: (usize, usize),
    /// 4-point Gauss–Legendre segments per transmittance ray (Hillaire: 40 midpoints; the
    /// 4D tables: 128 segments).
    pub transmittance_segments: usize,
    /// Multiple-scattering (μ_s, altitude) texels (Hillaire: 32×32).
    pub multiple_scattering: (usize, usize),
    /// The second order's field: Hillaire's isotropic one, or firmament's harmonics.
    pub multiple_scattering_model: MultipleScatteringModel,
    /// The highest scattering order computed explicitly (Hillaire: 2, the rest by the
    /// 1/(1 − f_ms) series; firmament's n > 2 gathers the fields of orders 2 … n − 1 too,
    /// and from 4 takes the rest as the 4D tables do, by the geometric tail of the last two
    /// orders: [`multiple_scattering::compute`]).
    pub multiple_scattering_orders: usize,
    /// Gather directions of the multiple-scattering pass: Gauss–Legendre nodes in μ and
    /// azimuths over [0, π] (the field is symmetric about the light's plane; Hillaire: 64
    /// directions over the sphere). The default (16, 2) gathers 64 directions too, but the
    /// integrand is sharp in μ (the horizon's long paths) and smooth in φ: against a
    /// (32, 32) gather Ψ_ms is within 0.26 % median, p95 3.7 % on earth, where (8, 8) was
    /// 3.6 % / 14 % at twice the marches (docs/accuracy.md).
    pub multiple_scattering_directions: (usize, usize),
    /// Steps per gather ray (Hillaire: 20).
    pub multiple_scattering_steps: usize,
    /// Sky-view (azimuth, zenith) texels (Hillaire: 192×108).
    pub sky_view: (usize, usize),
    /// Steps per sky-view ray (Hillaire's demo: up to 30).
    pub sky_view_steps: usize,
    /// Sky irradiance (μ_s, altitude) texels.
    pub irradiance: (usize, usize),
    /// Hemisphere directions of the irradiance pass.
    pub irradiance_directions: usize,
    /// Steps per direction of the irradiance pass.
    pub irradiance_steps: usize,
    /// Steps of a per-ray march (views from space, shafts, aerial perspective).
    pub march_steps: usize,
}

impl Default for HillaireConfig {
    fn default() -> Self {
        HillaireConfig {
            transmittance: (256, 64),
            transmittance_segments: 16,
            multiple_scattering: (32, 32),
            multiple_scattering_model: MultipleScatteringModel::Isotropic,
            multiple_scattering_orders: 2,
            multiple_scattering_directions: (16, 2),
            multiple_scattering_steps: 20,
            sky_view: (192, 108),
            sky_view_steps: 30,
            irradiance: (32, 16),
            irradiance_directions: 32,
            irradiance_steps: 16,
            march_steps: 30,
        }
    }
}

impl HillaireConfig {
    /// Refuse sizes or counts that cannot work (each at least 2, at most 4096).
    pub fn validate(&self) -> Result<()> {
        let checks = [
            ("hillaire.transmittance.mu", self.transmittance.0),
            ("hillaire.transmittance.r", self.transmittance.1),
            (
                "hillaire.transmittance_segments",
                self.transmittance_segments,
            ),
            (
                "hillaire.multiple_scattering.mu_s",
                self.multiple_scattering.0,
            ),
            (
                "hillaire.multiple_scattering.altitude",
                self.multiple_scattering.1,
            ),
            (
                "hillaire.multiple_scattering_directions.mu",
                self.multiple_scattering_directions.0,
            ),
            (
                "hillaire.multiple_scattering_directions.phi",
                self.multiple_scattering_directions.1,
            ),
            (
                "hillaire.multiple_scattering_steps",
                self.multiple_scattering_steps,
            ),
            ("hillaire.sky_view.azimuth", self.sky_view.0),
            ("hillaire.sky_view.zenith", self.sky_view.1),
            ("hillaire.sky_view_steps", self.sky_view_steps),
            ("hillaire.irradiance.mu_s", self.irradiance.0),
            ("hillaire.irradiance.altitude", self.irradiance.1),
            ("hillaire.irradiance_directions", self.irradiance_directions),
            ("hillaire.irradiance_steps", self.irradiance_steps),
            ("hillaire.march_steps", self.march_steps),
        ];
        for (field, v) in checks {
            if !(2..=4096).contains(&v) {
                return Err(Error::invalid(field, v, "an integer from 2 to 4096"));
            }
        }
        if !(2..=MAX_ORDERS).contains(&self.multiple_scattering_orders) {
            return Err(Error::invalid(
                "hillaire.multiple_scattering_orders",
                self.multiple_scattering_orders,
                format!("an integer from 2 to {MAX_ORDERS}"),
            ));
        }
        if let MultipleScatteringModel::Harmonics(d) = self.multiple_scattering_model {
            if !(1..=harmonics::MAX_DEGREE).contains(&d) {
                return Err(Error::invalid(
                    "hillaire.multiple_scattering_model.degree",
                    d,
                    format!("an integer from 1 to {}", harmonics::MAX_DEGREE),
                ));
            }
        }
        Ok(())
    }

    /// The 4D method's sizes with this transmittance (its lookups read only those).
    fn table_sizes(&self) -> TableSizes {
        TableSizes {
            transmittance_mu: self.transmittance.0,
            transmittance_r: self.transmittance.1,
            ..TableSizes::default()
        }
    }
}

/// The Hillaire 2020 sky method: a model with its atmosphere-wide tables (the sky view is
/// the view's).
pub struct Hillaire2020 {
    /// The resolved atmosphere.
    pub model: Model,
    /// Sizes and counts.
    pub config: HillaireConfig,
    /// Optical depth to the top, τ(r, μ).
    pub optical_depth: Table2,
    /// The multiple-scattering field per unit light irradiance.
    pub multiple_scattering: MultipleScattering,
    /// The sky's irradiance on a horizontal surface per unit light irradiance.
    pub irradiance: Table2,
    /// The largest f_ms of the multiple-scattering pass (over texels and channels).
    pub max_f_ms: f64,
}

impl Hillaire2020 {
    /// Build the tables for `model` (refused where f_ms passes [`F_MS_LIMIT`]).
    pub fn compute(model: Model, config: &HillaireConfig) -> Result<Hillaire2020> {
        Hillaire2020::compute_reporting(model, config, &|_| {})
    }

    /// [`Hillaire2020::compute`], calling `stage` with the name of each pass as it starts
    /// ("transmittance", "multiple scattering", "irradiance") and "done" at the end (for
    /// timings).
    pub fn compute_reporting(
        model: Model,
        config: &HillaireConfig,
        stage: &dyn Fn(&str),
    ) -> Result<Hillaire2020> {
        config.validate()?;
        crate::spectrum::check_channels(model.channels(), "Hillaire 2020")?;
        let sizes = config.table_sizes();
        stage("transmittance");
        // The densities tabulated (the columns within 2e-5 of the exact ones: density_table.rs).
        let medium = Medium::new(&model);
        let densities = medium.density_table();
        let optical_depth = compute_optical_depth_with(&model, &sizes, &|r, mu, d, columns| {
            densities.columns_along_ray(r, mu, d, config.transmittance_segments, columns)
        });
        stage("multiple scattering");
        let ms = {
            let marcher = Marcher::new(medium, Lookup::new(&model, sizes, &optical_depth), None);
            let (w, h) = config.multiple_scattering;
            multiple_scattering::compute(
                &marcher,
                config.multiple_scattering_model,
                w,
                h,
                config.multiple_scattering_directions,
                config.multiple_scattering_steps,
                config.multiple_scattering_orders,
            )
        };
        if ms.max_f_ms > F_MS_LIMIT {
            let (altitude, _, k) = ms.max_at;
            return Err(Error::invalid(
                "method",
                "hillaire2020",
                format!(
                    "this atmosphere scatters too much for Hillaire 2020's multiple-scattering series: \
                     f_ms = {:.3} at {:.0} nm, {:.0} m (accepted up to {F_MS_LIMIT}: beyond it the sky \
                     reads 10–50 % low, docs/accuracy.md); the 4D tables (bruneton4d) or the reference take it",
                    ms.max_f_ms,
                    model.wavelengths.nm()[k],
                    altitude,
                ),
            ));
        }
        let mut sky = Hillaire2020 {
            model,
            config: *config,
            optical_depth,
            max_f_ms: ms.max_f_ms,
            multiple_scattering: ms,
            irradiance: Table2::new(1, 1, 1),
        };
        stage("irradiance");
        let (w, h) = config.irradiance;
        sky.irradiance = irradiance::compute(
            &sky.marcher(),
            w,
            h,
            config.irradiance_directions,
            config.irradiance_steps,
        );
        stage("done");
        Ok(sky)
    }

    /// The march over this method's tables.
    pub(crate) fn marcher(&self) -> Marcher<'_> {
        Marcher::new(
            Medium::new(&self.model),
            Lookup::new(&self.model, self.config.table_sizes(), &self.optical_depth),
            Some(&self.multiple_scattering),
        )
    }

    /// The sky's irradiance (per unit light irradiance) on a horizontal surface at radius
    /// `r` (m) under a light at zenith cosine `mu_s`, into `out`.
    pub fn sky_irradiance(&self, r: f64, mu_s: f64, out: &mut [f64]) {
        let t = &self.irradiance;
        let m = &self.model;
        let (u, v) = altitude_mu_s_uv(
            r,
            m.bottom_radius_m,
            m.top_radius_m,
            mu_s,
            t.width,
            t.height,
        );
        t.sample_into(u, v, out);
    }
}

impl SkyMethod for Hillaire2020 {
    fn model(&self) -> &Model {
        &self.model
    }

    fn view<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        Box::new(Hillaire2020View::new(self, observer, light, true))
    }

    fn probe<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        Box::new(Hillaire2020View::new(self, observer, light, false))
    }
}
