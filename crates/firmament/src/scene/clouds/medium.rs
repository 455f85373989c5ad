//! A cloud layer as a [`Volume`]: where a ray crosses its shell, its coefficients (grey:
//! the same in every channel), its dual-lobe phase function, its majorant for delta
//! tracking, its optical depth by quadrature, and the cheaper estimates the renderer's
//! marcher lights it with (the progressive march towards the light of Hillaire 2016, seed
//! "Sun shadow sampling", and the vertical depths of the ambient light).

use super::config::MultipleScattering;
use super::layer::CloudLayer;
use super::two_stream::TwoStream;
use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::medium::PhaseFunction;
use crate::scene::volume::{DiffuseLight, Octaves, Volume};
use crate::scene::Ray;

/// The quadrature step of [`Volume::optical_depth`] (m): the finest texel of the default
/// erosion texture is 23 m (750 m / 32), so a 10 m midpoint rule follows the trilinear
/// field to well under 1 % of τ.
const QUADRATURE_STEP_M: f64 = 10.0;
/// Optical depth beyond which a quadrature stops (transmittance below e⁻⁴⁰ ≈ 4·10⁻¹⁸).
const OPAQUE_DEPTH: f64 = 40.0;
/// Samples of the march towards the light, at distances growing geometrically.
pub const LIGHT_SAMPLES: usize = 6;
/// The first samples of the march towards the light see the erosion detail (the cloud's
/// self-shadowing at its surface); the farther ones skip it.
pub const DETAILED_LIGHT_SAMPLES: usize = 2;
/// The ratio of successive light-march steps.
pub const LIGHT_STEP_GROWTH: f64 = 1.8;
/// The farthest the march towards the light looks (m): beyond, a cumulus layer's cells
/// rarely line up.
pub const LIGHT_MARCH_MAX_M: f64 = 6000.0;
/// The most grazing light the equivalent slab of the two-stream is lit by (a cloud's sides
/// face a low sun; a uniform slab's sun is never that low in the tests).
pub const MIN_LIGHT_COSINE: f64 = 0.2;
/// Samples of each vertical march of the ambient light.
pub const AMBIENT_SAMPLES: usize = 2;

/// A cloud layer's medium with its phase function.
pub struct CloudMedium {
    /// The layer.
    pub layer: CloudLayer,
    /// Its phase function.
    pub phase: PhaseFunction,
    /// The two-stream tables of its multiple scattering (None: octaves).
    pub two_stream: Option<TwoStream>,
}

impl CloudMedium {
    /// The medium of `layer`.
    pub fn new(layer: CloudLayer) -> CloudMedium {
        let [g1, g2, weight] = layer.params.phase;
        let phase = PhaseFunction::DualLobeHg { g1, g2, weight };
        let two_stream = (layer.params.multiple_scattering == MultipleScattering::TwoStream)
            .then(|| TwoStream::new(layer.params.albedo, &phase));
        CloudMedium {
            phase,
            layer,
            two_stream,
        }
    }

    /// The stretches (up to two) of `ray` inside the layer's shell, t ≥ 0.
    pub fn segments(&self, ray: &Ray) -> ([(f64, f64); 2], usize) {
        let [rb, rt] = self.layer.radii_m;
        let mut out = [(0.0, 0.0); 2];
        let mut n = 0;
        let Some((a1, b1)) = ray_sphere(ray.origin, ray.dir, rt) else {
            return (out, 0);
        };
        if b1 <= 0.0 {
            return (out, 0);
        }
        let start = a1.max(0.0);
        let mut push = |a: f64, b: f64| {
            if b > a {
                out[n] = (a, b);
                n += 1;
            }
        };
        match ray_sphere(ray.origin, ray.dir, rb) {
            Some((a0, b0)) if b0 > start && a0 < b1 => {
                push(start, a0.max(start));
                push(b0.max(start), b1);
            }
            _ => push(start, b1),
        }
        (out, n)
    }

    /// σ_t (m⁻¹) at `point`.
    #[inline]
    pub fn extinction(&self, point: Vec3) -> f64 {
        self.layer.params.extinction_per_m * self.layer.density(point)
    }

    /// Optical depth along `ray` over [t0, t1] by the midpoint rule (closed form for the
    /// uniform layer), stopping once opaque.
    fn quadrature(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        let (segs, n) = self.segments(ray);
        let mut tau = 0.0;
        for &(a, b) in &segs[..n] {
            let (a, b) = (a.max(t0), b.min(t1));
            if b <= a {
                continue;
            }
            if self.layer.noise.is_none() {
                tau += self.layer.params.extinction_per_m * (b - a);
                continue;
            }
            let steps = ((b - a) / QUADRATURE_STEP_M).ceil().max(1.0) as usize;
            let dt = (b - a) / steps as f64;
            for i in 0..steps {
                tau += self.extinction(ray.origin + (a + (i as f64 + 0.5) * dt) * ray.dir) * dt;
                if tau > OPAQUE_DEPTH {
                    return tau;
                }
            }
        }
        tau
    }
}

impl Volume for CloudMedium {
    fn bounds(&self, ray: &Ray) -> Option<(f64, f64)> {
        let (segs, n) = self.segments(ray);
        (n > 0).then(|| (segs[0].0, segs[n - 1].1))
    }

    fn coefficients(&self, point: Vec3, extinction: &mut [f64], scattering: &mut [f64]) {
        let st = self.extinction(point);
        extinction.iter_mut().for_each(|e| *e = st);
        let ss = st * self.layer.params.albedo;
        scattering.iter_mut().for_each(|s| *s = ss);
    }

    fn phase(&self, _point: Vec3) -> &PhaseFunction {
        &self.phase
    }

    fn majorant(&self, ray: &Ray, t0: f64, t1: f64, _channel: usize) -> f64 {
        let (segs, n) = self.segments(ray);
        if segs[..n].iter().any(|&(a, b)| a < t1 && b > t0) {
            self.layer.params.extinction_per_m * self.layer.max_density()
        } else {
            0.0
        }
    }

    fn optical_depth(&self, ray: &Ray, t0: f64, t1: f64, _channel: usize) -> f64 {
        self.quadrature(ray, t0, t1)
    }

    fn is_grey(&self) -> bool {
        true
    }

    fn radii_m(&self) -> Option<[f64; 2]> {
        Some(self.layer.radii_m)
    }

    fn alike_everywhere(&self) -> bool {
        self.layer.planetary.is_none()
    }

    /// Outside the shell, or where the weather's coverage and the type's profile leave no
    /// room for cloud whatever the noise.
    fn surely_empty(&self, point: Vec3) -> bool {
        self.layer.surely_empty(point)
    }

    /// The erosion texture's texel: the finest detail the density has (the uniform slab: a
    /// 64th of its thickness).
    fn feature_size_m(&self) -> Option<f64> {
        Some(match &self.layer.noise {
            Some([_, detail]) => self.layer.params.tiles_m[2] / detail.size as f64,
            // The uniform slab: the light within it changes over its thickness.
            None => (self.layer.radii_m[1] - self.layer.radii_m[0]) / 64.0,
        })
    }

    fn diffuse_radiance(
        &self,
        point: Vec3,
        mu_light: f64,
        tau_light: f64,
        _channel: usize,
    ) -> Option<DiffuseLight> {
        let ts = self.two_stream.as_ref()?;
        let r = point.length();
        let [rb, rt] = self.layer.radii_m;
        let [above, below] = if r < rb {
            // Under the layer: its whole column above.
            let up = Ray {
                origin: point,
                dir: point / r,
            };
            [self.light_optical_depth(&up, 0, 0.5), 0.0]
        } else if r > rt {
            return Some(DiffuseLight {
                base_direct: 1.0,
                scattering_scale: ts.scattering_scale,
                extinction_scale: ts.extinction_scale,
                forward_phase_cap: ts.forward_phase_cap,
                ..DiffuseLight::default()
            });
        } else {
            self.vertical_optical_depths(point, 0)
        };
        let thickness = above + below;
        // A cloud's sides face a low light: the equivalent slab is never lit more grazingly
        // than MIN_LIGHT_COSINE (a light at or just below the local horizon, which the air
        // still lets through at altitude, lights the clouds from the side).
        let mu_slab = if tau_light.is_finite() && mu_light > -0.1 {
            mu_light.max(MIN_LIGHT_COSINE)
        } else {
            mu_light
        };
        // The light's depth into the equivalent slab: where its beam is as dimmed as the
        // march towards it says (the vertical depth in a uniform slab).
        let sun_depth = if mu_slab > 0.0 {
            (tau_light * mu_slab).min(thickness)
        } else {
            thickness
        };
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut f = DiffuseLight {
            from_light: ts.sun(thickness, sun_depth, mu_slab),
            from_above: ts.diffuse(thickness, above, true),
            from_below: ts.diffuse(thickness, above, false),
            base_direct: if mu_light > 0.0 {
                (-thickness / mu_light).exp()
            } else {
                0.0
            },
            // At a black base F↑ = 0, so F↓ = 2π·I₀.
            base_from_light: two_pi * ts.sun(thickness, thickness, mu_light)[0],
            base_from_above: two_pi * ts.diffuse(thickness, thickness, true)[0],
            // Diffuse light from above: F↓(0) = 1, F↑(0) = 2π·I₀(0) − 1; the slab
            // reflects light from below alike.
            base_reflectance: (two_pi * ts.diffuse(thickness, 0.0, true)[0] - 1.0).clamp(0.0, 1.0),
            asymmetry: ts.asymmetry,
            scattering_scale: ts.scattering_scale,
            extinction_scale: ts.extinction_scale,
            forward_phase_cap: ts.forward_phase_cap,
        };
        // The beam's light scattered into the phase's forward peak (the two streams see the
        // beam dimmed by the δ-scaled depth, what crosses unscattered by the true one)
        // reaches the base as a beam too.
        if mu_light > 0.0 {
            f.base_from_light += mu_light * f.forward_peak(thickness / mu_light);
        }
        Some(f)
    }

    fn octaves(&self) -> Octaves {
        if let Some(ts) = &self.two_stream {
            // Octave 0: single scattering; octave 1: the two-stream's diffuse light, seen
            // through the δ-scaled extinction, no single scattering of its own.
            return Octaves {
                count: 2,
                scattering: 0.0,
                extinction: ts.extinction_scale,
                eccentricity: 1.0,
            };
        }
        let [a, b, c] = self.layer.params.octave_gains;
        Octaves {
            count: self.layer.params.octaves,
            scattering: a,
            extinction: b,
            eccentricity: c,
        }
    }

    /// The progressive march (Hillaire 2016): [`LIGHT_SAMPLES`] steps growing by
    /// [`LIGHT_STEP_GROWTH`] to the layer's exit (at most [`LIGHT_MARCH_MAX_M`]), each
    /// sampled at its midpoint (a jittered point makes neighbouring pixels see different
    /// shadows: visible grain); the uniform layer's depth in closed form.
    fn light_optical_depth(&self, ray: &Ray, _channel: usize, _jitter: f64) -> f64 {
        let (segs, n) = self.segments(ray);
        if n == 0 {
            return 0.0;
        }
        if self.layer.noise.is_none() {
            return self.quadrature(ray, 0.0, f64::INFINITY);
        }
        // The first stretch starting at the sample (the ray starts inside or below).
        let (a, b) = segs[0];
        let end = b.min(a + LIGHT_MARCH_MAX_M);
        let total: f64 = (0..LIGHT_SAMPLES)
            .map(|i| LIGHT_STEP_GROWTH.powi(i as i32))
            .sum();
        let mut step = (end - a) / total;
        let (mut t, mut tau) = (a, 0.0);
        let sigma = self.layer.params.extinction_per_m;
        for i in 0..LIGHT_SAMPLES {
            let x = ray.origin + (t + 0.5 * step) * ray.dir;
            tau += sigma * self.layer.density_with(x, i < DETAILED_LIGHT_SAMPLES) * step;
            t += step;
            step *= LIGHT_STEP_GROWTH;
        }
        tau
    }

    /// The optical depths straight up to the layer's top and straight down to its base,
    /// by [`AMBIENT_SAMPLES`] midpoint samples each, without the erosion detail.
    fn vertical_optical_depths(&self, point: Vec3, _channel: usize) -> [f64; 2] {
        let r = point.length();
        let [rb, rt] = self.layer.radii_m;
        if !(rb..=rt).contains(&r) {
            return [0.0; 2];
        }
        let up = point / r;
        let uniform = self.layer.noise.is_none();
        let depth = |from: f64, to: f64| {
            if uniform {
                return self.layer.params.extinction_per_m * (to - from).abs();
            }
            let dt = (to - from) / AMBIENT_SAMPLES as f64;
            (0..AMBIENT_SAMPLES)
                .map(|i| {
                    let x = up * (from + (i as f64 + 0.5) * dt);
                    self.layer.params.extinction_per_m
                        * self.layer.density_with(x, false)
                        * dt.abs()
                })
                .sum()
        };
        [depth(r, rt), depth(r, rb)]
    }
}
