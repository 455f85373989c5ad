//! Elek 2009, *Rendering Parametrizable Planetary Atmospheres with Multiple Scattering in
//! Real-Time* (CESCG 2009), with the parameterisation of Yusov 2013 (*Outdoor Light
//! Scattering Sample*), as Frostbite uses them (Hillaire 2016, §"Our approach"): the 4D
//! scattering table of Bruneton & Neyret 2008 without its view–sun azimuth, a 3D table over
//! altitude, view zenith and sun zenith, the phase functions applied at render time with
//! the real ν. The faster option next to the 4D tables (`earth`, rgb, default sizes: 0.6–0.7 s
//! on two cores against their ≈ 6 s).
//!
//! - Dropping the azimuth (`sun_cone`, `single`): the table holds the azimuthal mean of
//!   the 4D tables' phase-free quantities, S₃(r, μ, μ_s) = (1/π)∫₀^π S₄(r, μ, μ_s, ν(φ)) dφ,
//!   computed directly: the mean moves inside the ray integral onto the sun's
//!   transmittance. Single Rayleigh and Mie apart, phase-free; multiple scattering (orders
//!   ≥ 2) as radiance, phases included, also azimuth-averaged. The mean rather than one
//!   azimuth (the sun's vertical plane, say) because it is what the orders need (a
//!   horizontal surface and the next order's density see only the azimuthal mean of a
//!   field, `kernels`) and it errs least over the whole sky: no side is favoured.
//! - Orders (`density`, `multiple`, `irradiance`): exact for the azimuthal means
//!   through the phase functions' azimuthal integrals K(μ, μ′), with the ground's bounce
//!   through an irradiance table like Bruneton's ΔE and the 4D tables' geometric order tail.
//! - Parameterisation ([`params`]): u_h = (h/H)^0.5, the view zenith split at the horizon
//!   with a power 0.2 towards it, Bruneton & Neyret 2008's sun-zenith arctangent (or the 4D
//!   tables' mapping, [`SunZenithMapping`]), texel centres exact.
//! - Ray integrals (`ray`): the 4D tables' exponentially fitted Simpson rule, so that the
//!   two methods differ by the azimuth and not by their quadrature.
//! - Transmittance, transmittance to the light and the twilight below the tables' lowest
//!   sun are the 4D tables' ([`crate::sky::bruneton4d::Lookup`],
//!   [`crate::sky::bruneton4d::twilight`]).
//!
//! What the azimuth costs (`examples/elek3d_accuracy.rs`, against the 4D tables, which
//! the reference confirms within 1–4 % at the views quoted): the sky's mean over azimuth is
//! kept within 1–3 %, and so is the sky's irradiance, but not its shape. Earth's shadow is
//! gone (the anti-solar twilight sky ×2–3 too bright, the sunward ×0.4–0.5 too dark under a
//! sun 3° down). In daylight the larger loss is the multiple scattering's aureole: the
//! second order is brightest towards the sun (the aerosols forward-scatter the single
//! scattering's aureole; ×3.5 the azimuthal mean near the horizon under a 10° sun), and
//! the 3D table spreads it over every azimuth, so low skies away from the sun read too
//! bright (+80 % at the horizon 105° from a 10° sun from the ground in `earth`, +50 % 75°
//! from a 60° sun in `hazy`) and those towards it too dark. It grows with the aerosols and
//! shrinks above them: median errors under a 60° sun of 3.8 % on the ground, 0.2 % from
//! 10 km (`earth`); 0.9 % on the ground in `bruneton2008`, 19 % in `hazy`.
//!
//! Spectral like the rest of firmament: every table holds the model's channels.

pub mod config;
mod density;
mod irradiance;
mod kernels;
mod multiple;
pub mod params;
mod precompute;
mod ray;
mod single;
mod sun_cone;
pub mod table;
pub mod view;

pub use config::Elek3dConfig;
pub use params::{Params, SunZenithMapping};
pub use table::Table3;
pub use view::Elek3dView;

use super::bruneton4d::{Lookup, Table2};
use super::{SkyMethod, SkyView};
use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::Result;

/// The 3D-table sky method: a model with its precomputed tables.
pub struct Elek3d {
    /// The resolved atmosphere.
    pub model: Model,
    /// Sizes and counts.
    pub config: Elek3dConfig,
    /// τ(r, μ) = −ln T to the top of the atmosphere, the 4D tables' table and mapping.
    pub optical_depth: Table2,
    /// Single scattering by the molecular group without its phase function, averaged over
    /// the view–sun azimuth (W·m⁻²·sr⁻¹·nm⁻¹ per unit phase).
    pub single_rayleigh: Table3,
    /// The same for the aerosol group.
    pub single_mie: Table3,
    /// Orders 2 to N (and the tail) as radiance (W·m⁻²·sr⁻¹·nm⁻¹), averaged over azimuth.
    pub multiple: Table3,
    /// The sky's irradiance on a horizontal surface E(r, μ_s) (W·m⁻²·nm⁻¹), the 4D tables'
    /// grid.
    pub irradiance: Table2,
    /// Mean radiance of each order over the texels, per channel (order 1 first).
    pub order_means: Vec<Vec<f64>>,
}

impl Elek3d {
    /// Precompute the tables for `model` (refused: bad sizes, more than
    /// [`crate::spectrum::MAX_CHANNELS`] wavelengths, air too thick for summed orders).
    pub fn compute(model: Model, config: &Elek3dConfig) -> Result<Elek3d> {
        config.validate()?;
        crate::spectrum::check_channels(model.channels(), "the 3D-table method")?;
        super::bruneton4d::thickness::check(&model)?;
        super::bruneton4d::shell::check(&model)?;
        let p = precompute::precompute(&model, config);
        Ok(Elek3d {
            model,
            config: *config,
            optical_depth: p.optical_depth,
            single_rayleigh: p.single_rayleigh,
            single_mie: p.single_mie,
            multiple: p.multiple,
            irradiance: p.irradiance,
            order_means: p.order_means,
        })
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.model.channels()
    }

    /// The table mappings.
    pub fn params(&self) -> Params {
        Params::new(&self.model, &self.config)
    }

    /// Transmittance and irradiance lookups for a light of angular radius
    /// `light_angular_radius_rad`.
    pub fn lookup(&self, light_angular_radius_rad: f64) -> Lookup<'_> {
        Lookup {
            sun_angular_radius: light_angular_radius_rad,
            ..Lookup::new(&self.model, self.config.table_sizes(), &self.optical_depth)
        }
    }

    /// The tables at (r, μ, μ_s) on a ray that meets the ground or not, into `rayleigh`,
    /// `mie` (phase-free single scattering) and `multiple` (radiance), each overwritten;
    /// μ_s below the tables' lowest sun reads that sun.
    #[allow(clippy::too_many_arguments)]
    pub fn scattering(
        &self,
        r: f64,
        mu: f64,
        mu_s: f64,
        ground: bool,
        rayleigh: &mut [f64],
        mie: &mut [f64],
        multiple: &mut [f64],
    ) {
        let u = self.params().coords(r, mu, mu_s, ground);
        let taps = self.single_rayleigh.taps(u);
        self.single_rayleigh.sample_taps_into(&taps, rayleigh);
        self.single_mie.sample_taps_into(&taps, mie);
        self.multiple.sample_taps_into(&taps, multiple);
    }
}

impl SkyMethod for Elek3d {
    fn model(&self) -> &Model {
        &self.model
    }

    fn view<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        Box::new(Elek3dView::new(self, observer, light))
    }
}
