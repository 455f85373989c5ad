//! An atmosphere resolved for a wavelength grid: plain per-wavelength arrays that the
//! tables, the renderer and the reference path tracer read in their hot loops.

use super::{
    interpolate_linear, Albedo, Atmosphere, LimbDarkening, ScatteringGroups, SolarSpectrum,
};
use crate::math::quadrature::GL4;
use crate::math::sphere;
use crate::medium::{ConstituentKind, ResolvedConstituent};
use crate::spectrum::{self, Wavelengths};

/// Resolved atmosphere. Per-wavelength vectors all have `wavelengths.len()` entries.
#[derive(Clone, Debug)]
pub struct Model {
    /// The parameters this was resolved from.
    pub atmosphere: Atmosphere,
    /// The wavelength grid.
    pub wavelengths: Wavelengths,
    /// Ground radius (m).
    pub bottom_radius_m: f64,
    /// Top-of-atmosphere radius (m).
    pub top_radius_m: f64,
    /// Ground albedo per wavelength.
    pub ground_albedo: Vec<f64>,
    /// Solar spectral irradiance at the top of the atmosphere (W·m⁻²·nm⁻¹) per wavelength.
    pub solar_irradiance: Vec<f64>,
    /// Solar angular radius (rad).
    pub sun_angular_radius_rad: f64,
    /// Limb darkening law.
    pub limb_darkening: LimbDarkening,
    /// cos of the largest sun zenith angle the tables cover.
    pub mu_s_min: f64,
    /// Constituents with per-wavelength coefficients at density 1.
    pub constituents: Vec<ResolvedConstituent>,
    /// The constituents grouped as the tables store them (molecules, aerosols).
    pub groups: ScatteringGroups,
    /// 64-bit FNV-1a hash of the parameters and the wavelengths (identifies table files).
    pub hash: u64,
}

/// Vertical optical depths per wavelength, grouped as in `firmament query`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OpticalDepths {
    /// Molecules (Rayleigh) extinction.
    pub rayleigh: Vec<f64>,
    /// Aerosol (Mie) extinction.
    pub mie: Vec<f64>,
    /// Absorbers (ozone).
    pub ozone: Vec<f64>,
    /// Sum.
    pub total: Vec<f64>,
}

impl Model {
    pub(crate) fn new(atmosphere: &Atmosphere, wavelengths: &Wavelengths) -> Model {
        let nm = wavelengths.nm();
        let height = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
        let constituents: Vec<ResolvedConstituent> = atmosphere
            .constituents
            .iter()
            .map(|c| {
                let column = c.density.column_m(0.0, height);
                let scattering = c.scattering.resolve(nm, column);
                let absorption = c.absorption.resolve(nm, column);
                let extinction = scattering
                    .iter()
                    .zip(&absorption)
                    .map(|(s, a)| s + a)
                    .collect();
                ResolvedConstituent {
                    name: c.name.clone(),
                    kind: c.kind,
                    density: c.density.clone(),
                    scattering,
                    absorption,
                    extinction,
                    phase: c.phase.clone(),
                }
            })
            .collect();
        let ground_albedo = nm
            .iter()
            .map(|&l| match &atmosphere.ground_albedo {
                Albedo::Grey(a) => *a,
                Albedo::Table {
                    wavelengths_nm,
                    values,
                } => interpolate_linear(wavelengths_nm, values, l),
            })
            .collect();
        let mut model = Model {
            atmosphere: atmosphere.clone(),
            wavelengths: wavelengths.clone(),
            bottom_radius_m: atmosphere.bottom_radius_m,
            top_radius_m: atmosphere.top_radius_m,
            ground_albedo,
            solar_irradiance: Vec::new(),
            sun_angular_radius_rad: atmosphere.sun.angular_radius_deg.to_radians(),
            limb_darkening: atmosphere.sun.limb_darkening,
            mu_s_min: (90.0 - atmosphere.min_sun_elevation_deg).to_radians().cos(),
            groups: ScatteringGroups::new(&constituents, nm.len()),
            constituents,
            hash: 0,
        };
        model.solar_irradiance = match &atmosphere.sun.spectrum {
            SolarSpectrum::AstmG173 => nm
                .iter()
                .map(|&l| spectrum::solar_irradiance_band_mean(l, 10.0))
                .collect(),
            SolarSpectrum::Table {
                wavelengths_nm,
                values,
            } => nm
                .iter()
                .map(|&l| interpolate_linear(wavelengths_nm, values, l))
                .collect(),
            SolarSpectrum::ZenithIlluminance { lux } => {
                // Scale the standard shape so that E_toa·T_zenith integrates to `lux`.
                let shape: Vec<f64> = nm
                    .iter()
                    .map(|&l| spectrum::solar_irradiance_band_mean(l, 10.0))
                    .collect();
                let t = model.optical_depths_vertical(0.0).total;
                let ground: Vec<f64> = shape
                    .iter()
                    .zip(&t)
                    .map(|(e, tau)| e * (-tau).exp())
                    .collect();
                let y = spectrum::luminance_from_spectrum(nm, &ground);
                let scale = if y > 0.0 { lux / y } else { 0.0 };
                shape.iter().map(|e| e * scale).collect()
            }
        };
        model.hash = fnv1a(format!("{}|{:?}", atmosphere.to_toml(), nm).as_bytes());
        model
    }

    /// Number of wavelengths.
    #[inline]
    pub fn channels(&self) -> usize {
        self.wavelengths.len()
    }

    /// Height of the atmosphere (m).
    #[inline]
    pub fn height_m(&self) -> f64 {
        self.top_radius_m - self.bottom_radius_m
    }

    /// Densities of every constituent at `altitude_m`, written into `out`.
    #[inline]
    pub fn densities_into(&self, altitude_m: f64, out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(&self.constituents) {
            *o = c.density.density(altitude_m);
        }
    }

    /// Extinction coefficient (m⁻¹) per wavelength at `altitude_m`, into `out`.
    pub fn extinction_into(&self, altitude_m: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for c in &self.constituents {
            let rho = c.density.density(altitude_m);
            if rho > 0.0 {
                for (o, e) in out.iter_mut().zip(&c.extinction) {
                    *o += rho * e;
                }
            }
        }
    }

    /// Scattering coefficient (m⁻¹) per wavelength at `altitude_m`, into `out`.
    pub fn scattering_into(&self, altitude_m: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for c in &self.constituents {
            let rho = c.density.density(altitude_m);
            if rho > 0.0 {
                for (o, s) in out.iter_mut().zip(&c.scattering) {
                    *o += rho * s;
                }
            }
        }
    }

    /// Column (m) of each constituent's density along the ray from radius `r` in direction
    /// `mu` over `length_m` metres, into `out` (one entry per constituent). Composite
    /// 4-point Gauss–Legendre with `segments` sub-intervals (Bruneton 2017 uses 500
    /// trapezoids; 128 Gauss segments are more accurate for the same cost).
    pub fn columns_along_ray(
        &self,
        r: f64,
        mu: f64,
        length_m: f64,
        segments: usize,
        out: &mut [f64],
    ) {
        out.iter_mut().for_each(|o| *o = 0.0);
        gauss_radii_along_ray(r, mu, length_m, segments, |radius, w| {
            let alt = (radius - self.bottom_radius_m).max(0.0);
            for (o, con) in out.iter_mut().zip(&self.constituents) {
                *o += w * con.density.density(alt);
            }
        });
    }

    /// Optical depth per wavelength from constituent columns (m), into `out`.
    #[inline]
    pub fn optical_depth_from_columns(&self, columns: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for (col, c) in columns.iter().zip(&self.constituents) {
            if *col != 0.0 {
                for (o, e) in out.iter_mut().zip(&c.extinction) {
                    *o += col * e;
                }
            }
        }
    }

    /// Optical depth per wavelength along a ray segment (see [`Model::columns_along_ray`]).
    pub fn optical_depth_along_ray(&self, r: f64, mu: f64, length_m: f64) -> Vec<f64> {
        let mut columns = vec![0.0; self.constituents.len()];
        self.columns_along_ray(r, mu, length_m, 256, &mut columns);
        let mut tau = vec![0.0; self.channels()];
        self.optical_depth_from_columns(&columns, &mut tau);
        tau
    }

    /// Vertical optical depths from `altitude_m` to the top, per group, per wavelength
    /// (exact columns of the layered profiles).
    pub fn optical_depths_vertical(&self, altitude_m: f64) -> OpticalDepths {
        let n = self.channels();
        let mut d = OpticalDepths {
            rayleigh: vec![0.0; n],
            mie: vec![0.0; n],
            ozone: vec![0.0; n],
            total: vec![0.0; n],
        };
        let top = self.height_m();
        for c in &self.constituents {
            let column = c.density.column_m(altitude_m.clamp(0.0, top), top);
            let target = match c.kind {
                ConstituentKind::Molecules => &mut d.rayleigh,
                ConstituentKind::Aerosols => &mut d.mie,
                ConstituentKind::Absorber => &mut d.ozone,
            };
            for (i, e) in c.extinction.iter().enumerate() {
                target[i] += column * e;
                d.total[i] += column * e;
            }
        }
        d
    }
}

/// 64-bit FNV-1a.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// `f(radius, weight)` at the nodes of the composite 4-point Gauss–Legendre rule with
/// `segments` sub-intervals over `length_m` metres of the ray from radius `r` (m) in
/// direction `mu` (nothing when the length is not positive): the columns along a ray, from
/// the exact profiles ([`Model::columns_along_ray`]) or a table of them
/// (`DensityTable::columns_along_ray`).
#[inline]
pub fn gauss_radii_along_ray(
    r: f64,
    mu: f64,
    length_m: f64,
    segments: usize,
    mut f: impl FnMut(f64, f64),
) {
    GL4.for_each_node(0.0, length_m, segments, |d, w| {
        f(sphere::safe_sqrt(d * d + 2.0 * r * mu * d + r * r), w)
    });
}
