//! An atmosphere's own colour weights: [`Model::colour_matrix`] fits the XYZ weights of the
//! model's wavelength samples (`spectrum::weights`) to the generic family of sky-like
//! spectra plus this atmosphere's single-scattering skies and the sun's beam through it, computed at the sample
//! wavelengths and on a 10-nm grid, so that three samples of a sky whose constituents are
//! known give its luminance and colour as a dense spectrum would (docs/accuracy.md,
//! "Luminance from a few wavelengths").

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use super::{Model, SolarSpectrum};
use crate::math::quadrature::GL4;
use crate::math::sphere;
use crate::spectrum::weights::{
    generic_family, grid_nm, SolarShape, TrainingSpectrum, TWILIGHT_SAMPLES,
};
use crate::spectrum::{ColourMatrix, Wavelengths};

/// The dense grid the training skies are computed on: 360, 370, …, 830 nm (48 samples, the
/// CIE 1931 table's range).
fn dense_wavelengths() -> Wavelengths {
    let nm: Vec<f64> = (0..48).map(|i| 360.0 + 10.0 * i as f64).collect();
    Wavelengths::from_list(&nm).expect("360–830 nm is a valid list")
}

/// Observer altitudes (m), sun elevations (°), view zenith angles (°) and view azimuths from
/// the sun (°) of the training skies: daylight and twilight (the suns below the horizon for
/// [`TWILIGHT_SAMPLES`] samples or more) from the ground and from a plane, with the ground
/// seen from above.
const ALTITUDES_M: [f64; 2] = [1.0, 8000.0];
const SUN_ELEVATIONS_DEG: [f64; 8] = [-4.0, -1.0, 3.0, 8.0, 15.0, 30.0, 50.0, 90.0];
const VIEW_ZENITHS_DEG: [f64; 8] = [0.0, 40.0, 70.0, 82.0, 88.0, 100.0, 130.0, 180.0];
const VIEW_AZIMUTHS_DEG: [f64; 3] = [0.0, 90.0, 180.0];
/// Gauss panels along a view ray, and along the ray to the sun from each of its points.
const VIEW_PANELS: usize = 12;
const SUN_PANELS: usize = 6;

impl Model {
    /// The colour weights of this model's wavelengths under its sun, fitted to the generic
    /// family and to the model's own single-scattering skies (module documentation). Fitted
    /// once per model (tens of ms) and kept; falls back to [`ColourMatrix::new`]'s generic weights if the dense grid
    /// cannot be resolved.
    pub fn colour_matrix(&self) -> ColourMatrix {
        // Kept per model (its hash and its sun's samples): a frame asks in several places.
        type Cache = Mutex<HashMap<(u64, Vec<u64>), ColourMatrix>>;
        static CACHE: OnceLock<Cache> = OnceLock::new();
        let key = (
            self.hash,
            self.solar_irradiance.iter().map(|e| e.to_bits()).collect(),
        );
        let cache = CACHE.get_or_init(Default::default);
        if let Some(m) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
            return m;
        }
        let m = self.fit_colour_matrix();
        if let Ok(mut c) = cache.lock() {
            if c.len() >= 64 {
                c.clear();
            }
            c.insert(key, m.clone());
        }
        m
    }

    /// The fit behind [`Model::colour_matrix`].
    fn fit_colour_matrix(&self) -> ColourMatrix {
        let nm = self.wavelengths.nm();
        let mut family = generic_family(nm);
        if let Ok(dense) = self.atmosphere.resolve(&dense_wavelengths()) {
            // Few samples cannot serve twilight and daylight at once: daylight's skies only.
            let elevations: Vec<f64> = SUN_ELEVATIONS_DEG
                .iter()
                .copied()
                .filter(|e| *e > 0.0 || self.channels() >= TWILIGHT_SAMPLES)
                .collect();
            family.extend(single_scattering_skies(self, &dense, &elevations));
            family.extend(direct_beams(self, &dense));
        }
        ColourMatrix::fitted(&self.solar_shape(), &family)
    }

    /// The sun's spectrum at the samples (the model's own values) and on the 1-nm grid
    /// (the full ASTM G173 spectrum, scaled as the samples are, or the atmosphere's table).
    pub fn solar_shape(&self) -> SolarShape {
        let nm = self.wavelengths.nm();
        let on_grid = match &self.atmosphere.sun.spectrum {
            SolarSpectrum::Table {
                wavelengths_nm,
                values,
            } => grid_nm()
                .map(|l| super::interpolate_linear(wavelengths_nm, values, l))
                .collect(),
            SolarSpectrum::AstmG173 | SolarSpectrum::ZenithIlluminance { .. } => {
                // The ASTM shape, scaled as the model scaled its samples.
                let astm = SolarShape::astm_g173(nm);
                let scale = astm
                    .at_samples
                    .iter()
                    .zip(&self.solar_irradiance)
                    .find(|(a, _)| **a > 0.0)
                    .map_or(1.0, |(a, m)| m / a);
                astm.on_grid.iter().map(|e| e * scale).collect()
            }
        };
        SolarShape {
            at_samples: self.solar_irradiance.clone(),
            on_grid,
        }
    }
}

/// Single-scattering skies (radiance per unit solar irradiance, so the sun's factor `f`) of
/// `model` at its samples and of `dense` (the same atmosphere on the 10-nm grid),
/// interpolated onto the 1-nm grid; with the sunlit ground, Lambertian, in views that reach
/// it.
fn single_scattering_skies(
    model: &Model,
    dense: &Model,
    elevations: &[f64],
) -> Vec<TrainingSpectrum> {
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let constituents = model.constituents.len();
    let mut out = Vec::new();
    let mut columns = vec![0.0; constituents];
    let mut to_sun = vec![0.0; constituents];
    let mut rho = vec![0.0; constituents];
    for &altitude in &ALTITUDES_M {
        let r0 = bottom + altitude.min(model.height_m() * 0.5);
        for &elevation in elevations {
            let mu_s = elevation.to_radians().sin();
            for &zenith in &VIEW_ZENITHS_DEG {
                let mu = zenith.to_radians().cos();
                for &azimuth in &VIEW_AZIMUTHS_DEG {
                    // ν: the cosine of the angle between the view and the sun.
                    let nu = mu * mu_s
                        + sphere::safe_sqrt(1.0 - mu * mu)
                            * sphere::safe_sqrt(1.0 - mu_s * mu_s)
                            * azimuth.to_radians().cos();
                    let ground = sphere::ray_intersects_ground(r0, mu, bottom);
                    let length = sphere::distance_to_nearest_atmosphere_boundary(
                        r0, mu, bottom, top, ground,
                    );
                    let mut sparse = vec![0.0; model.channels()];
                    let mut dense_f = vec![0.0; dense.channels()];
                    for (d, w) in GL4.composite(0.0, length, VIEW_PANELS) {
                        let (r, mu_s_here) = point_and_sun(r0, mu, mu_s, nu, d);
                        if sphere::ray_intersects_ground(r, mu_s_here, bottom) {
                            continue; // in the planet's shadow
                        }
                        model.columns_along_ray(r0, mu, d, 4, &mut columns);
                        let to_top = sphere::distance_to_top_atmosphere_boundary(r, mu_s_here, top);
                        model.columns_along_ray(r, mu_s_here, to_top, SUN_PANELS, &mut to_sun);
                        model.densities_into(r - bottom, &mut rho);
                        for (m, out) in [(model, &mut sparse), (dense, &mut dense_f)] {
                            add_scattering(m, &rho, &columns, &to_sun, nu, w, out);
                        }
                    }
                    if ground {
                        // The sunlit ground at the ray's end (Lambertian, direct sun only).
                        let (r, mu_s_here) = point_and_sun(r0, mu, mu_s, nu, length);
                        if mu_s_here > 0.0 {
                            model.columns_along_ray(r0, mu, length, 8, &mut columns);
                            let to_top =
                                sphere::distance_to_top_atmosphere_boundary(r, mu_s_here, top);
                            model.columns_along_ray(r, mu_s_here, to_top, SUN_PANELS, &mut to_sun);
                            for (m, out) in [(model, &mut sparse), (dense, &mut dense_f)] {
                                add_ground(m, &columns, &to_sun, mu_s_here, out);
                            }
                        }
                    }
                    out.extend(training(dense, sparse, &dense_f));
                }
            }
        }
    }
    out
}

/// Sun elevations (°) of the training beams: the sun's own disk, down to the horizon.
const BEAM_ELEVATIONS_DEG: [f64; 9] = [0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 15.0, 30.0, 90.0];

/// The sun's beam through the air, `exp(−τ(λ))` to the top, from each training altitude:
/// the disk's colour and the lights' colours (lamps) are read through the same weights.
fn direct_beams(model: &Model, dense: &Model) -> Vec<TrainingSpectrum> {
    let mut columns = vec![0.0; model.constituents.len()];
    let mut out = Vec::new();
    for &altitude in &ALTITUDES_M {
        let r = model.bottom_radius_m + altitude.min(model.height_m() * 0.5);
        // The low sun's deep red beam only where the samples can serve it (see elevations).
        let low = model.channels() >= TWILIGHT_SAMPLES;
        for &elevation in BEAM_ELEVATIONS_DEG.iter().filter(|e| low || **e >= 3.0) {
            let mu_s = elevation.to_radians().sin();
            let to_top = sphere::distance_to_top_atmosphere_boundary(r, mu_s, model.top_radius_m);
            model.columns_along_ray(r, mu_s, to_top, 16, &mut columns);
            let beam = |m: &Model| -> Vec<f64> {
                (0..m.channels())
                    .map(|k| (-optical_depth(m, k, &[&columns])).exp())
                    .collect()
            };
            out.extend(training(dense, beam(model), &beam(dense)));
        }
    }
    out
}

/// Radius and cosine of the sun's zenith angle at distance `d` along the ray (r0, μ), for a
/// sun at μ_s and ν from the ray (Bruneton 2017, eq. for r_d and μ_s,d).
fn point_and_sun(r0: f64, mu: f64, mu_s: f64, nu: f64, d: f64) -> (f64, f64) {
    let r = sphere::safe_sqrt(d * d + 2.0 * r0 * mu * d + r0 * r0);
    (r, ((r0 * mu_s + d * nu) / r).clamp(-1.0, 1.0))
}

/// Adds `w`·Σ_c ρ_c·σ_s,c·P_c(ν)·T(observer → point)·T(point → sun) per channel of `m`.
fn add_scattering(
    m: &Model,
    rho: &[f64],
    columns: &[f64],
    to_sun: &[f64],
    nu: f64,
    w: f64,
    out: &mut [f64],
) {
    for (k, o) in out.iter_mut().enumerate() {
        let tau = optical_depth(m, k, &[columns, to_sun]);
        let source: f64 = m
            .constituents
            .iter()
            .zip(rho)
            .map(|(c, r)| r * c.scattering[k] * c.phase.eval(nu))
            .sum();
        *o += w * source * (-tau).exp();
    }
}

/// Adds the Lambertian ground's reflection of the direct sun, `a·μ_s·T_sun·T_view/π`.
fn add_ground(m: &Model, columns: &[f64], to_sun: &[f64], mu_s: f64, out: &mut [f64]) {
    for (k, o) in out.iter_mut().enumerate() {
        let tau = optical_depth(m, k, &[columns, to_sun]);
        *o += m.ground_albedo[k] * mu_s * (-tau).exp() / std::f64::consts::PI;
    }
}

/// Optical depth of channel k of `m` along paths given by their constituent columns (m).
fn optical_depth(m: &Model, k: usize, paths: &[&[f64]]) -> f64 {
    (m.constituents.iter().enumerate())
        .map(|(i, c)| paths.iter().map(|p| p[i]).sum::<f64>() * c.extinction[k])
        .sum()
}

/// A training spectrum from its samples and its dense values (`dense`'s grid), if both are
/// positive everywhere (a relative fit needs a target).
fn training(dense: &Model, sparse: Vec<f64>, dense_f: &[f64]) -> Option<TrainingSpectrum> {
    (sparse.iter().all(|v| *v > 0.0) && dense_f.iter().all(|v| *v > 0.0)).then(|| {
        TrainingSpectrum {
            at_samples: sparse,
            on_grid: onto_grid(dense.wavelengths.nm(), dense_f),
            weight: 1.0,
        }
    })
}

/// A spectrum sampled on `nm` (increasing) linearly interpolated onto the 1-nm grid, ends
/// held.
fn onto_grid(nm: &[f64], values: &[f64]) -> Vec<f64> {
    grid_nm()
        .map(|l| super::interpolate_linear(nm, values, l))
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::atmosphere::Atmosphere;
    use crate::spectrum::{self, Wavelengths};

    /// The sun's own illuminance is the full 1-nm integral of the embedded ASTM G173
    /// spectrum (133 100 lx with the CIE 1931 ȳ), from three samples as from sixteen.
    #[test]
    fn solar_illuminance_is_the_full_spectrum_s() {
        let full: f64 = spectrum::weights::grid_nm()
            .map(|l| spectrum::solar_irradiance_astm_g173(l) * spectrum::cie_1931_2deg(l)[1])
            .sum::<f64>()
            * spectrum::LUMINOUS_EFFICACY_LM_W;
        for w in [Wavelengths::rgb(), Wavelengths::spectral()] {
            let model = Atmosphere::earth().resolve(&w).unwrap();
            let lux = model.colour_matrix().to_xyz(&model.solar_irradiance)[1];
            assert!((lux / full - 1.0).abs() < 1e-4, "{lux} vs {full}");
        }
        assert!((full / 133_100.0 - 1.0).abs() < 1e-3, "{full}");
    }
}
