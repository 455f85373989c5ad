//! Volumes: participating media that are not a function of altitude alone (clouds next),
//! which the renderer's ray marcher and the reference path tracer both sample through the
//! same questions: where along a ray the medium may be, its extinction and scattering
//! coefficients and phase function at a point, an upper bound of its extinction over a
//! stretch of ray (delta tracking's majorant), and its optical depth along a ray.

use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::medium::PhaseFunction;
use crate::scene::camera::Ray;

/// A participating medium in the scene, besides the atmosphere's layered constituents.
/// Coefficients are per channel of the model's wavelength grid, in m⁻¹.
pub trait Volume: Send + Sync {
    /// The distances [t0, t1] (m, t0 ≥ 0) along `ray` outside which the medium is empty, or
    /// None when the ray misses it.
    fn bounds(&self, ray: &Ray) -> Option<(f64, f64)>;

    /// Extinction and scattering coefficients (m⁻¹) at `point`, per channel.
    fn coefficients(&self, point: Vec3, extinction: &mut [f64], scattering: &mut [f64]);

    /// The phase function at `point`.
    fn phase(&self, point: Vec3) -> &PhaseFunction;

    /// An upper bound (m⁻¹) of the extinction of `channel` over the distances [t0, t1]
    /// along `ray`.
    fn majorant(&self, ray: &Ray, t0: f64, t1: f64, channel: usize) -> f64;

    /// The optical depth of `channel` along `ray` over [t0, t1].
    fn optical_depth(&self, ray: &Ray, t0: f64, t1: f64, channel: usize) -> f64;

    /// Whether the coefficients are the same in every channel (then the renderer asks the
    /// estimates below once, for channel 0).
    fn is_grey(&self) -> bool {
        false
    }

    /// The renderer's multiple scattering by octaves (Wrenninge 2015); by default one octave:
    /// single scattering.
    fn octaves(&self) -> Octaves {
        Octaves::SINGLE
    }

    /// The renderer's estimate of the optical depth of `channel` from `ray.origin` towards a
    /// light along `ray.dir` (to infinity), `jitter` ∈ [0, 1) placing the samples of a
    /// march; by default the exact [`Volume::optical_depth`].
    fn light_optical_depth(&self, ray: &Ray, channel: usize, _jitter: f64) -> f64 {
        self.optical_depth(ray, 0.0, f64::INFINITY, channel)
    }

    /// The optical depths of `channel` from `point` straight up and straight down through
    /// the volume, which dim the ambient light from the sky above and the ground below; by
    /// default none.
    fn vertical_optical_depths(&self, _point: Vec3, _channel: usize) -> [f64; 2] {
        [0.0; 2]
    }

    /// The renderer's estimate of the diffuse (multiply scattered) light at `point`, for a
    /// light whose zenith cosine there is `mu_light` and towards which the volume's optical
    /// depth is `tau_light` (of `channel`); the renderer then scatters it isotropically and
    /// takes octave 0 for its single scattering and octave 1 for this light (the volume's
    /// [`Volume::octaves`] says so, with no single scattering in octave 1). None (the
    /// default): octaves and the ambient term.
    fn diffuse_radiance(
        &self,
        _point: Vec3,
        _mu_light: f64,
        _tau_light: f64,
        _channel: usize,
    ) -> Option<DiffuseLight> {
        None
    }

    /// Whether no medium can be at `point` whatever the volume's fine detail (the renderer
    /// leaps over stretches empty at both ends); by default false (no leaps).
    fn surely_empty(&self, _point: Vec3) -> bool {
        false
    }

    /// The radii (m, planet-centred) of the spherical shell the volume lies in, when it is
    /// one (a cloud layer): the renderer then maps its shadow below it
    /// ([`crate::render::cloud_shadow`]); None: no such map.
    fn radii_m(&self) -> Option<[f64; 2]> {
        None
    }

    /// Whether the volume is alike everywhere around the planet (a tiled weather), so that
    /// its shadow mapped around the observer stands for it beyond the map; false for a
    /// planet's weather, whose shadow beyond the map the renderer leaves out of the air.
    fn alike_everywhere(&self) -> bool {
        true
    }

    /// The scale (m) of the volume's smallest features: the renderer's march steps at about
    /// this length (growing with distance) instead of by optical depth; None: by optical
    /// depth.
    fn feature_size_m(&self) -> Option<f64> {
        None
    }
}

/// A borrowed volume is a volume (a scene can hold volumes it does not own, such as the
/// clouds a program builds once for many frames).
impl<V: Volume + ?Sized> Volume for &V {
    fn bounds(&self, ray: &Ray) -> Option<(f64, f64)> {
        (**self).bounds(ray)
    }
    fn coefficients(&self, point: Vec3, extinction: &mut [f64], scattering: &mut [f64]) {
        (**self).coefficients(point, extinction, scattering)
    }
    fn phase(&self, point: Vec3) -> &PhaseFunction {
        (**self).phase(point)
    }
    fn majorant(&self, ray: &Ray, t0: f64, t1: f64, channel: usize) -> f64 {
        (**self).majorant(ray, t0, t1, channel)
    }
    fn optical_depth(&self, ray: &Ray, t0: f64, t1: f64, channel: usize) -> f64 {
        (**self).optical_depth(ray, t0, t1, channel)
    }
    fn is_grey(&self) -> bool {
        (**self).is_grey()
    }
    fn octaves(&self) -> Octaves {
        (**self).octaves()
    }
    fn light_optical_depth(&self, ray: &Ray, channel: usize, jitter: f64) -> f64 {
        (**self).light_optical_depth(ray, channel, jitter)
    }
    fn vertical_optical_depths(&self, point: Vec3, channel: usize) -> [f64; 2] {
        (**self).vertical_optical_depths(point, channel)
    }
    fn feature_size_m(&self) -> Option<f64> {
        (**self).feature_size_m()
    }
    fn radii_m(&self) -> Option<[f64; 2]> {
        (**self).radii_m()
    }
    fn alike_everywhere(&self) -> bool {
        (**self).alike_everywhere()
    }
    fn surely_empty(&self, point: Vec3) -> bool {
        (**self).surely_empty(point)
    }
    fn diffuse_radiance(
        &self,
        point: Vec3,
        mu_light: f64,
        tau_light: f64,
        channel: usize,
    ) -> Option<DiffuseLight> {
        (**self).diffuse_radiance(point, mu_light, tau_light, channel)
    }
}

/// A volume's estimate of its diffuse light at a point ([`Volume::diffuse_radiance`]), per
/// unit irradiance of what enters it: the light's beam (normal to it), diffuse light from
/// above (the sky), diffuse light from below (the ground).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DiffuseLight {
    /// The diffuse radiance's moments at the point (sr⁻¹): its mean over all directions
    /// I₀ and its first moment I₁ (the radiance I₀ + I₁μ, μ from the upward vertical), per
    /// unit beam irradiance,
    pub from_light: [f64; 2],
    /// per unit hemispheric irradiance entering from above,
    pub from_above: [f64; 2],
    /// and per unit hemispheric irradiance entering from below.
    pub from_below: [f64; 2],
    /// The asymmetry with which the diffuse field scatters: the in-scattered radiance
    /// towards μ is I₀ + asymmetry·I₁·μ.
    pub asymmetry: f64,
    /// Under the point's column through the volume: the fraction of the beam that crosses
    /// it unscattered,
    pub base_direct: f64,
    /// the diffuse flux leaving its base per unit beam irradiance (the light scattered
    /// into the forward peak included),
    pub base_from_light: f64,
    /// and per unit hemispheric irradiance entering its top;
    pub base_from_above: f64,
    /// the fraction of diffuse light from below that the column reflects back down (the
    /// ground and the cloud's base light each other: the ground's irradiance grows by
    /// 1/(1 − A·this), A the ground's albedo).
    pub base_reflectance: f64,
    /// The fraction of the scattering coefficient that scatters this diffuse light (the
    /// rest is the phase function's forward peak, counted as unscattered: δ-scaling). The
    /// renderer carries the diffuse light along the view in the octave slot 1, whose
    /// extinction gain the volume's [`Volume::octaves`] gives.
    pub scattering_scale: f64,
    /// The δ-scaled optical depth per true one, 1 − ωf: the light's beam as the two
    /// streams see it is e^{−(1 − ωf)τ}, of which e^{−τ} crosses unscattered and the rest
    /// was scattered into the forward peak and goes on with the beam (the renderer
    /// scatters it towards the eye with the phase that the δ-scaling keeps, min(p, cap),
    /// Nakajima & Tanaka 1988's split of single scattering).
    pub extinction_scale: f64,
    /// That phase's cap (sr⁻¹; [`crate::medium::PhaseFunction::truncated_forward_value`]).
    pub forward_phase_cap: f64,
}

impl DiffuseLight {
    /// The share of the light's beam, after optical depth `tau` towards it, that the
    /// δ-scaling moved into the forward peak: e^{−(1 − ωf)τ} − e^{−τ}.
    #[inline]
    pub fn forward_peak(&self, tau: f64) -> f64 {
        (-self.extinction_scale * tau).exp() - (-tau).exp()
    }
}

/// Multiple scattering by octaves (Wrenninge 2015, "Art-directable multiple scattering";
/// Hillaire 2016 §5.6): octave n scatters aⁿ·σ_s with the extinction towards the light
/// bⁿ·σ_t and the phase asymmetry cⁿ·g, and the octaves are summed. With a ≤ b no octave's
/// effective albedo aⁿσ_s/(bⁿσ_t) exceeds the medium's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Octaves {
    /// Number of octaves (1: single scattering).
    pub count: u32,
    /// a: the scattering gain per octave.
    pub scattering: f64,
    /// b: the extinction gain per octave.
    pub extinction: f64,
    /// c: the phase asymmetry gain per octave.
    pub eccentricity: f64,
}

impl Octaves {
    /// Single scattering.
    pub const SINGLE: Octaves = Octaves {
        count: 1,
        scattering: 1.0,
        extinction: 1.0,
        eccentricity: 1.0,
    };

    /// Octave n's effective single-scattering albedo for a medium of albedo `albedo`:
    /// aⁿ·albedo/bⁿ.
    pub fn effective_albedo(&self, n: u32, albedo: f64) -> f64 {
        albedo * (self.scattering / self.extinction).powi(n as i32)
    }
}

/// A ball of homogeneous medium (a cloud puff, a test case with closed forms: the
/// transmittance through it is e^{−σ_t·chord}).
#[derive(Clone, Debug)]
pub struct HomogeneousSphere {
    /// Centre (planet-centred, m).
    pub centre: Vec3,
    /// Radius (m).
    pub radius_m: f64,
    /// Extinction coefficient per channel (m⁻¹).
    pub extinction: Vec<f64>,
    /// Scattering coefficient per channel (m⁻¹), at most the extinction.
    pub scattering: Vec<f64>,
    /// Phase function.
    pub phase: PhaseFunction,
}

impl HomogeneousSphere {
    /// The chord [t0, t1] of `ray` inside the ball.
    fn chord(&self, ray: &Ray) -> Option<(f64, f64)> {
        let (near, far) = ray_sphere(ray.origin - self.centre, ray.dir, self.radius_m)?;
        (far > 0.0).then(|| (near.max(0.0), far))
    }
}

impl Volume for HomogeneousSphere {
    fn bounds(&self, ray: &Ray) -> Option<(f64, f64)> {
        self.chord(ray)
    }

    fn coefficients(&self, point: Vec3, extinction: &mut [f64], scattering: &mut [f64]) {
        let inside = (point - self.centre).length_squared() <= self.radius_m * self.radius_m;
        for k in 0..extinction.len() {
            (extinction[k], scattering[k]) = if inside {
                (self.extinction[k], self.scattering[k])
            } else {
                (0.0, 0.0)
            };
        }
    }

    fn phase(&self, _point: Vec3) -> &PhaseFunction {
        &self.phase
    }

    fn majorant(&self, ray: &Ray, t0: f64, t1: f64, channel: usize) -> f64 {
        match self.chord(ray) {
            Some((a, b)) if a < t1 && b > t0 => self.extinction[channel],
            _ => 0.0,
        }
    }

    fn optical_depth(&self, ray: &Ray, t0: f64, t1: f64, channel: usize) -> f64 {
        match self.chord(ray) {
            Some((a, b)) => self.extinction[channel] * (b.min(t1) - a.max(t0)).max(0.0),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn homogeneous_sphere_chord_optical_depth() {
        let v = HomogeneousSphere {
            centre: Vec3::new(0.0, 0.0, 1000.0),
            radius_m: 100.0,
            extinction: vec![0.05],
            scattering: vec![0.05],
            phase: PhaseFunction::Isotropic,
        };
        // A ray through the centre: chord 200 m, τ = 10; offset by 60 m: chord 160 m.
        let through = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::Z,
        };
        assert_eq!(v.bounds(&through), Some((900.0, 1100.0)));
        assert!((v.optical_depth(&through, 0.0, f64::INFINITY, 0) - 10.0).abs() < 1e-9);
        assert!((v.optical_depth(&through, 1000.0, 2000.0, 0) - 5.0).abs() < 1e-9);
        let offset = Ray {
            origin: Vec3::new(60.0, 0.0, 0.0),
            dir: Vec3::Z,
        };
        assert!((v.optical_depth(&offset, 0.0, f64::INFINITY, 0) - 8.0).abs() < 1e-9);
        assert_eq!(v.majorant(&offset, 0.0, 500.0, 0), 0.0);
        assert_eq!(v.majorant(&offset, 0.0, 1000.0, 0), 0.05);
        let (mut e, mut s) = ([0.0], [0.0]);
        v.coefficients(Vec3::new(0.0, 0.0, 1050.0), &mut e, &mut s);
        assert_eq!((e[0], s[0]), (0.05, 0.05));
        v.coefficients(Vec3::new(0.0, 0.0, 1150.0), &mut e, &mut s);
        assert_eq!((e[0], s[0]), (0.0, 0.0));
    }
}
