//! The planet's ground seen from afar: a sphere whose albedo varies over it, from a user's
//! equirectangular map or a procedural Earth (oceans, land, ice), with the sun's glint on the
//! sea (Cox & Munk 1954). It replaces the uniform ground sphere (`Sphere::ground`) so that
//! the planet from orbit is not a uniform grey ball.
//!
//! Placement: the observer stands at (`lat_deg`, `lon_deg`) of the map (the scene's
//! `[location]`, or 0, 0), the renderer's frame being x east, y north, z up there.
//!
//! Spectra (`data/ocean_albedo.csv`, `data/terrain_albedo.csv`, tools/gen_data.py): the
//! ocean's light from beneath the surface plus the surface's Fresnel reflectance of the
//! diffuse sky (Payne 1972: ≈ 0.066); land mixes the terrain's grass, forest and rock
//! (deserts) spectra; ice is the terrain's snow. A user map's linear sRGB is spread over the
//! wavelengths by interpolating its channels at 680, 550 and 440 nm (held beyond).

use super::surface::{Sphere, Surface, SurfaceHit};
use super::terrain::materials::material_spectra;
use super::terrain::relief::hash;
use super::Ray;
use crate::math::lattice::sphere_directions;
use crate::math::{smoothstep, Vec3};
use crate::spectrum::table::Table;

const OCEAN_ALBEDO_CSV: &str = include_str!("../../data/ocean_albedo.csv");

/// Spectra a map mixes ([`PlanetSurface::basis`]).
pub const BASIS: usize = 5;

/// Refractive index of sea water in the visible (Quan & Fry 1995: 1.339–1.345).
pub const SEA_WATER_INDEX: f64 = 1.34;

/// The ocean's Lambertian albedo per wavelength: the light from beneath the surface and
/// the surface's diffuse sky reflection (module doc), linearly interpolated in the table.
pub fn ocean_spectrum(wavelengths_nm: &[f64]) -> Vec<f64> {
    let table = Table::parse("ocean_albedo.csv", OCEAN_ALBEDO_CSV);
    let (lo, hi) = (table.x[0], table.x[table.x.len() - 1]);
    wavelengths_nm
        .iter()
        .map(|&nm| {
            let nm = nm.clamp(lo, hi);
            table.interp(0, nm) + table.interp(1, nm)
        })
        .collect()
}

/// What the planet's albedo comes from.
#[derive(Clone, Debug)]
pub enum SurfaceMap {
    /// Continents from 3D gradient noise over the sphere (`seed`), covering 1 −
    /// `ocean_fraction` of it; ice poleward of about 70°; deserts in the subtropics, forest
    /// in the tropics and mid-latitudes, grass between.
    Procedural {
        /// Seed of the continents' noise.
        seed: u64,
        /// The share of the sphere that is sea, in [0, 1] (Earth: 0.71).
        ocean_fraction: f64,
    },
    /// An equirectangular map (`width` × `height` linear sRGB pixels, row 0 at 90° N, column
    /// 0 at 180° W).
    Image {
        /// Width of the map (pixels, 360° of longitude).
        width: usize,
        /// Height of the map (pixels, 180° of latitude).
        height: usize,
        /// The albedo, linear sRGB read as reflectances at 680, 550 and 440 nm (linear
        /// between them); `width * height` pixels, row-major.
        rgb: Vec<[f32; 3]>,
    },
}

/// The planet's ground with a map.
#[derive(Clone, Debug)]
pub struct PlanetSurface {
    /// The sphere (its albedo unused: the map's).
    sphere: Sphere,
    /// The map.
    pub map: SurfaceMap,
    /// The observer's east, north and up in the map's planet-fixed frame (z to 90° N, x to
    /// 0° E).
    frame: [Vec3; 3],
    /// Spectra per channel: ocean, ice, rock, grass, forest.
    ocean: Vec<f64>,
    ice: Vec<f64>,
    rock: Vec<f64>,
    grass: Vec<f64>,
    forest: Vec<f64>,
    /// The wavelengths (nm), for a map's colours.
    wavelengths_nm: Vec<f64>,
    /// The sea's slope variance σ² for the glint (Cox & Munk 1954: 0.003 + 5.12·10⁻³·W for
    /// a wind W in m/s at 12.5 m); None: no glint.
    pub slope_variance: Option<f64>,
    /// The noise level under which a procedural point is sea.
    pub(crate) sea_level: f64,
}

impl PlanetSurface {
    /// The planet of radius `radius_m` with `map`, the observer at (`lat_deg`, `lon_deg`),
    /// the spectra at `wavelengths_nm`, the glint for a wind of `wind_m_s` (None: off).
    pub fn new(
        radius_m: f64,
        map: SurfaceMap,
        lat_deg: f64,
        lon_deg: f64,
        wavelengths_nm: &[f64],
        wind_m_s: Option<f64>,
    ) -> PlanetSurface {
        let frame = observer_frame(lat_deg, lon_deg);
        let [ice, rock, grass, forest] = material_spectra(wavelengths_nm);
        let mut planet = PlanetSurface {
            sphere: Sphere {
                centre: Vec3::ZERO,
                radius_m,
                albedo: Vec::new(),
                casts_shadows: false,
            },
            map,
            frame,
            ocean: ocean_spectrum(wavelengths_nm),
            ice,
            rock,
            grass,
            forest,
            wavelengths_nm: wavelengths_nm.to_vec(),
            slope_variance: wind_m_s.map(|w| 0.003 + 5.12e-3 * w),
            sea_level: 0.0,
        };
        if let SurfaceMap::Procedural {
            seed,
            ocean_fraction,
        } = planet.map
        {
            // The quantile of the continents' noise over 8192 evenly spread points.
            let mut v: Vec<f64> = sphere_directions(8192)
                .into_iter()
                .map(|d| continents(seed, d))
                .collect();
            v.sort_by(f64::total_cmp);
            let k = ((ocean_fraction.clamp(0.0, 1.0) * v.len() as f64) as usize).min(v.len() - 1);
            planet.sea_level = if ocean_fraction >= 1.0 {
                f64::INFINITY
            } else {
                v[k]
            };
        }
        planet
    }

    /// The planet-fixed unit direction of a renderer-frame point.
    fn fixed(&self, p: Vec3) -> Vec3 {
        let [e, n, u] = self.frame;
        (p.x * e + p.y * n + p.z * u).normalize()
    }

    /// Whether a planet-fixed direction is sea (procedural maps only).
    fn is_sea(&self, d: Vec3) -> bool {
        match self.map {
            SurfaceMap::Procedural { seed, .. } => continents(seed, d) < self.sea_level,
            SurfaceMap::Image { .. } => false,
        }
    }

    /// The sea's share of the sphere's area in this map, by 20 000 evenly spread points.
    pub fn sea_fraction(&self) -> f64 {
        let points = sphere_directions(20_000);
        let sea = points.iter().filter(|&&d| self.is_sea(d)).count();
        sea as f64 / points.len() as f64
    }

    /// The albedo at a planet-fixed unit direction as weights of the five spectra of
    /// [`PlanetSurface::basis`] (the albedo is their weighted sum; the GPU bakes these weights
    /// into a texture, `firmament_gpu::planet`): for a procedural map, the shares of ocean,
    /// ice, rock, forest and grass (summing to 1; the first is 1 at sea, 0 on land); for an
    /// image, its linear red, green and blue (then 0, 0).
    pub fn weights(&self, d: Vec3) -> [f64; BASIS] {
        match &self.map {
            SurfaceMap::Procedural { seed, .. } => {
                if self.is_sea(d) {
                    return [1.0, 0.0, 0.0, 0.0, 0.0];
                }
                let lat = d.z.clamp(-1.0, 1.0).asin().to_degrees().abs();
                let wiggle = 8.0 * noise3(*seed ^ 0x1ce, 4.0 * d);
                let ice = smoothstep(66.0, 72.0, lat + wiggle);
                // Moisture: wet tropics and mid-latitudes, dry subtropics (Hadley cells).
                let belt = (-(lat - 25.0).powi(2) / (2.0 * 9.0 * 9.0)).exp();
                let wet = 0.5 + 0.5 * noise3(*seed ^ 0xdee, 3.0 * d) - 0.9 * belt;
                let desert = smoothstep(0.15, 0.0, wet);
                let forest = smoothstep(0.35, 0.6, wet);
                // ice + (1 − ice)·(desert·rock + (1 − desert)·(forest·forest + (1 − forest)·grass)).
                let land = 1.0 - ice;
                let green = land * (1.0 - desert);
                [
                    0.0,
                    ice,
                    land * desert,
                    green * forest,
                    green * (1.0 - forest),
                ]
            }
            SurfaceMap::Image { width, height, rgb } => {
                let lat = d.z.clamp(-1.0, 1.0).asin();
                let lon = d.y.atan2(d.x);
                let x = (lon / std::f64::consts::TAU + 0.5) * *width as f64 - 0.5;
                let y = (0.5 - lat / std::f64::consts::PI) * *height as f64 - 0.5;
                let c = bilinear_wrap(rgb, *width, *height, x, y);
                [c[0], c[1], c[2], 0.0, 0.0]
            }
        }
    }

    /// The five spectra [`PlanetSurface::weights`] mix, at the surface's wavelengths: ocean,
    /// ice, rock, forest, grass for a procedural map; for an image the spectra of its pure
    /// red, green and blue (linear between 680, 550 and 440 nm, [`colour_basis`]), then two
    /// of zeros.
    pub fn basis(&self) -> [Vec<f64>; BASIS] {
        match self.map {
            SurfaceMap::Procedural { .. } => [
                self.ocean.clone(),
                self.ice.clone(),
                self.rock.clone(),
                self.forest.clone(),
                self.grass.clone(),
            ],
            SurfaceMap::Image { .. } => {
                let column = |i: usize| -> Vec<f64> {
                    self.wavelengths_nm
                        .iter()
                        .map(|&nm| colour_basis(nm)[i])
                        .collect()
                };
                let zeros = vec![0.0; self.wavelengths_nm.len()];
                [column(0), column(1), column(2), zeros.clone(), zeros]
            }
        }
    }

    /// Whether the first weight of [`PlanetSurface::weights`] is the sea's share (a
    /// procedural map with a glint): the glint's weight on the GPU.
    pub fn sea_is_first(&self) -> bool {
        matches!(self.map, SurfaceMap::Procedural { .. })
    }

    /// The observer's east, north and up in the map's planet-fixed frame (z to 90° N, x to
    /// 0° E).
    pub fn frame(&self) -> [Vec3; 3] {
        self.frame
    }

    /// The Cox & Munk (1954) glint BRDF (sr⁻¹) of the sea for light from `to_light` seen
    /// from `to_viewer` (units) over the local `normal`: F(β_i)·P(tan β)/(4 cos θ_i cos θ_v
    /// cos⁴ β), P the isotropic Gaussian of the facets' slopes with variance σ², β the
    /// facet's tilt (its normal the half vector), F Fresnel at the facet; no shadowing of
    /// facets by waves.
    pub fn glint_brdf(sigma2: f64, normal: Vec3, to_viewer: Vec3, to_light: Vec3) -> f64 {
        let (ci, cv) = (normal.dot(to_light), normal.dot(to_viewer));
        if ci <= 0.0 || cv <= 0.0 {
            return 0.0;
        }
        let h = (to_light + to_viewer).normalize();
        let cb = normal.dot(h).clamp(1e-6, 1.0);
        let tan2 = (1.0 - cb * cb) / (cb * cb);
        let p = (-tan2 / sigma2).exp() / (std::f64::consts::PI * sigma2);
        let f = fresnel(h.dot(to_light).clamp(0.0, 1.0), SEA_WATER_INDEX);
        f * p / (4.0 * ci * cv * cb.powi(4))
    }
}

impl Surface for PlanetSurface {
    fn intersect(&self, ray: &Ray, max_distance_m: f64) -> Option<SurfaceHit> {
        self.sphere.intersect(ray, max_distance_m)
    }

    fn albedo(&self, hit: &SurfaceHit, out: &mut [f64]) {
        let w = self.weights(self.fixed(hit.position));
        let basis = self.basis();
        for (k, o) in out.iter_mut().enumerate() {
            *o = (0..BASIS).map(|j| w[j] * basis[j][k]).sum();
        }
    }

    fn specular(&self, hit: &SurfaceHit, to_viewer: Vec3, to_light: Vec3) -> f64 {
        match self.slope_variance {
            Some(s2) if self.is_sea(self.fixed(hit.position)) => {
                Self::glint_brdf(s2, hit.normal, to_viewer, to_light)
            }
            _ => 0.0,
        }
    }
}

/// The observer's east, north and up at (`lat_deg`, `lon_deg`) in a planet-fixed frame (z to
/// 90° N, x to 0° E): the renderer's x, y and z there.
pub(crate) fn observer_frame(lat_deg: f64, lon_deg: f64) -> [Vec3; 3] {
    let (phi, lambda) = (lat_deg.to_radians(), lon_deg.to_radians());
    let up = Vec3::new(
        phi.cos() * lambda.cos(),
        phi.cos() * lambda.sin(),
        phi.sin(),
    );
    let east = Vec3::new(-lambda.sin(), lambda.cos(), 0.0);
    [east, up.cross(east), up]
}

/// The continents' noise at a planet-fixed unit direction: eight octaves of gradient noise
/// (coasts down to about 30 km), the finer ones a little stronger than fBm's halving so
/// that coasts are ragged.
fn continents(seed: u64, d: Vec3) -> f64 {
    let mut sum = 0.0;
    let (mut f, mut a) = (1.4, 1.0);
    for o in 0..8 {
        sum += a * noise3(seed.wrapping_add(o), f * d);
        f *= 2.03;
        a *= 0.55;
    }
    sum
}

/// 3D gradient noise in about [−1, 1] (Perlin 2002, "Improving noise", SIGGRAPH: quintic
/// fade, gradients from a hash of the lattice point).
pub(crate) fn noise3(seed: u64, p: Vec3) -> f64 {
    let (xi, yi, zi) = (p.x.floor(), p.y.floor(), p.z.floor());
    let (fx, fy, fz) = (p.x - xi, p.y - yi, p.z - zi);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v, w) = (fade(fx), fade(fy), fade(fz));
    let grad = |dx: i64, dy: i64, dz: i64| {
        let h = hash(
            seed ^ ((zi as i64 + dz) as u64).wrapping_mul(0x2545_f491_4f6c_dd1d),
            xi as i64 + dx,
            yi as i64 + dy,
        );
        // A direction from two uniform numbers.
        let z = ((h >> 11) & 0xfffff) as f64 / 1048575.0 * 2.0 - 1.0;
        let a = (h >> 32) as f64 / 4294967296.0 * std::f64::consts::TAU;
        let s = (1.0 - z * z).sqrt();
        Vec3::new(s * a.cos(), s * a.sin(), z).dot(Vec3::new(
            fx - dx as f64,
            fy - dy as f64,
            fz - dz as f64,
        ))
    };
    let lerp = |a: f64, b: f64, t: f64| a + t * (b - a);
    let x00 = lerp(grad(0, 0, 0), grad(1, 0, 0), u);
    let x10 = lerp(grad(0, 1, 0), grad(1, 1, 0), u);
    let x01 = lerp(grad(0, 0, 1), grad(1, 0, 1), u);
    let x11 = lerp(grad(0, 1, 1), grad(1, 1, 1), u);
    1.5 * lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

/// Unpolarised Fresnel reflectance at incidence cosine `cos_i` from air into index `n`.
pub fn fresnel(cos_i: f64, n: f64) -> f64 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (n * n);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - sin_t2).sqrt();
    let rs = ((cos_i - n * ct) / (cos_i + n * ct)).powi(2);
    let rp = ((n * cos_i - ct) / (n * cos_i + ct)).powi(2);
    0.5 * (rs + rp)
}

/// The map's colour at pixel coordinates (x, y), bilinear, wrapping in x, clamped in y.
pub(crate) fn bilinear_wrap(rgb: &[[f32; 3]], w: usize, h: usize, x: f64, y: f64) -> [f64; 3] {
    let y = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let xi = |dx: i64| ((x0 as i64 + dx).rem_euclid(w as i64)) as usize;
    let yi = |dy: usize| (y0 as usize + dy).min(h - 1);
    let mut c = [0.0; 3];
    for (dx, dy, wgt) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let p = rgb[yi(dy) * w + xi(dx)];
        for k in 0..3 {
            c[k] += wgt * p[k] as f64;
        }
    }
    c
}

/// The weights of a linear sRGB colour's channels in its value at `nm`: the channels stand
/// at 680 (R), 550 (G) and 440 nm (B), linear between them, held beyond.
pub fn colour_basis(nm: f64) -> [f64; 3] {
    if nm >= 680.0 {
        [1.0, 0.0, 0.0]
    } else if nm >= 550.0 {
        let f = (nm - 550.0) / 130.0;
        [f, 1.0 - f, 0.0]
    } else if nm >= 440.0 {
        let f = (nm - 440.0) / 110.0;
        [0.0, f, 1.0 - f]
    } else {
        [0.0, 0.0, 1.0]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The procedural Earth the tests use (seed 3, 71 % sea, RGB, the glint on).
    pub(crate) fn earth() -> PlanetSurface {
        let map = SurfaceMap::Procedural {
            seed: 3,
            ocean_fraction: 0.71,
        };
        PlanetSurface::new(
            6_360_000.0,
            map,
            0.0,
            0.0,
            &[680.0, 550.0, 440.0],
            Some(7.0),
        )
    }

    #[test]
    fn the_procedural_earth_has_its_sea_share_and_zones() {
        let p = earth();
        let sea = p.sea_fraction();
        assert!((sea - 0.71).abs() < 0.01, "sea {sea}");
        // Land by zone: ice near the poles, none at the equator.
        let (mut ice_polar, mut ice_tropic, mut n_polar, mut n_tropic) = (0, 0, 0, 0);
        let mut out = [0.0; 3];
        for d in sphere_directions(20_000) {
            let z = d.z;
            if p.is_sea(d) {
                continue;
            }
            // The renderer's frame at (0° N, 0° E): x east = fixed y, y north = fixed z,
            // z up = fixed x.
            let position = 6_360_000.0 * Vec3::new(d.y, d.z, d.x);
            let hit = SurfaceHit {
                distance_m: 0.0,
                position,
                normal: position.normalize(),
            };
            p.albedo(&hit, &mut out);
            let lat = z.asin().to_degrees().abs();
            let white = out[1] > 0.8;
            if lat > 80.0 {
                n_polar += 1;
                ice_polar += usize::from(white);
            } else if lat < 20.0 {
                n_tropic += 1;
                ice_tropic += usize::from(white);
            }
        }
        assert!(ice_polar * 10 > 8 * n_polar, "{ice_polar} of {n_polar}");
        assert_eq!(ice_tropic, 0, "of {n_tropic}");
    }

    #[test]
    fn the_glint_brdf_integrates_to_the_fresnel_reflectance() {
        // Cox–Munk facets with F = 1 conserve energy: ∫ f cos θ_v dω_v over the upper
        // hemisphere = the share of facets whose mirror image stays above the horizon
        // (≈ 1 for a high sun and calm sea). With Fresnel: ≈ F(θ_i) of a flat sea.
        let n = Vec3::Z;
        for (sun_zenith, wind) in [(30.0f64, 2.0), (30.0, 10.0), (60.0, 5.0)] {
            let s2 = 0.003 + 5.12e-3 * wind;
            let to_light = Vec3::new(
                sun_zenith.to_radians().sin(),
                0.0,
                sun_zenith.to_radians().cos(),
            );
            let (nt, np) = (600, 1200);
            let mut sum = 0.0;
            for i in 0..nt {
                let t = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
                for j in 0..np {
                    let f = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                    let v = Vec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos());
                    let dw = t.sin()
                        * (std::f64::consts::FRAC_PI_2 / nt as f64)
                        * (std::f64::consts::TAU / np as f64);
                    sum += PlanetSurface::glint_brdf(s2, n, v, to_light) * t.cos() * dw;
                }
            }
            let flat = fresnel(sun_zenith.to_radians().cos(), SEA_WATER_INDEX);
            eprintln!("glint, sun {sun_zenith}°, wind {wind} m/s: ∫ f cos dω = {sum:.5}, flat sea's Fresnel {flat:.5}");
            assert!(
                (sum / flat - 1.0).abs() < 0.08,
                "sun {sun_zenith}°, wind {wind}: ∫ = {sum}, flat-sea Fresnel {flat}"
            );
        }
    }

    #[test]
    fn a_map_pixel_lands_at_its_latitude_and_longitude() {
        // 4 × 2 map: the north-east quarter (row 0, columns 2–3: 0–180° E) red, the rest
        // black.
        let mut rgb = vec![[0.0f32; 3]; 8];
        rgb[2] = [1.0, 0.0, 0.0];
        rgb[3] = [1.0, 0.0, 0.0];
        let map = SurfaceMap::Image {
            width: 4,
            height: 2,
            rgb,
        };
        let p = PlanetSurface::new(1.0, map, 0.0, 0.0, &[680.0, 440.0], None);
        let mut out = [0.0; 2];
        // 45° N, 135° E in the observer's frame (x east, y north, z up at 0° N 0° E).
        let (lat, lon) = (45f64.to_radians(), 135f64.to_radians());
        let fixed = Vec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
        let hit = SurfaceHit {
            distance_m: 0.0,
            position: Vec3::new(fixed.y, fixed.z, fixed.x),
            normal: Vec3::Z,
        };
        p.albedo(&hit, &mut out);
        assert!(out[0] > 0.99 && out[1] < 1e-9, "{out:?}");
        let south = SurfaceHit {
            position: Vec3::new(fixed.y, -fixed.z, fixed.x),
            ..hit
        };
        p.albedo(&south, &mut out);
        assert!(out[0] < 1e-9, "{out:?}");
    }

    #[test]
    fn the_weights_sum_to_one_and_mix_the_spectra() {
        let p = earth();
        let basis = p.basis();
        let (mut sea, mut land) = (0, 0);
        for d in sphere_directions(4000) {
            let w = p.weights(d);
            assert!(w.iter().all(|&x| (0.0..=1.0).contains(&x)), "{w:?}");
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{w:?}");
            if p.is_sea(d) {
                sea += 1;
                assert_eq!(w, [1.0, 0.0, 0.0, 0.0, 0.0]);
            } else {
                land += 1;
                assert_eq!(w[0], 0.0);
            }
        }
        assert!(sea > 0 && land > 0);
        // The sea's albedo is the ocean spectrum.
        assert_eq!(basis[0], ocean_spectrum(&[680.0, 550.0, 440.0]));
    }

    #[test]
    fn the_weight_texture_of_an_image_holds_its_pixels() {
        let (w, h) = (6, 3);
        let rgb: Vec<[f32; 3]> = (0..w * h)
            .map(|i| [i as f32 / 20.0, 0.5, 1.0 - i as f32 / 20.0])
            .collect();
        let map = SurfaceMap::Image {
            width: w,
            height: h,
            rgb: rgb.clone(),
        };
        let p = PlanetSurface::new(1.0, map, 10.0, 20.0, &[700.0, 600.0, 500.0, 400.0], None);
        assert_eq!(p.texture_size(), (w, h));
        let texels = p.weight_texture(w, h);
        for (t, c) in texels.iter().zip(&rgb) {
            for k in 0..3 {
                assert!((t[k] - c[k]).abs() < 1e-6, "{t:?} {c:?}");
            }
            assert_eq!(t[3], 0.0);
        }
        // The basis reproduces colour_at's spread: 600 nm is 50/130 of the way from G to R.
        let b = p.basis();
        assert!((b[0][1] - 50.0 / 130.0).abs() < 1e-12 && (b[1][1] - 80.0 / 130.0).abs() < 1e-12);
        assert_eq!((b[2][0], b[2][3]), (0.0, 1.0));
    }
}
