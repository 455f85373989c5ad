//! Surfaces: what a ray can hit (distance, position, normal) and how it reflects (a Lambertian
//! albedo per wavelength), and the shadows it casts. The planet's ground sphere is the first;
//! the terrain's heightfield (`scene/terrain/`) the second.

use crate::atmosphere::Model;
use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::scene::camera::Ray;

/// Where a ray meets a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the ray (m).
    pub distance_m: f64,
    /// The point (planet-centred, m).
    pub position: Vec3,
    /// Unit normal, on the side the ray came from.
    pub normal: Vec3,
}

/// Azimuths of [`Surface::horizon`] (the terrain's, `scene::terrain::occlusion`).
pub const HORIZON_AZIMUTHS: usize = crate::scene::terrain::occlusion::AZIMUTHS;

/// A surface in the scene.
pub trait Surface: Send + Sync {
    /// The nearest hit of `ray` at a distance in (0, `max_distance_m`).
    fn intersect(&self, ray: &Ray, max_distance_m: f64) -> Option<SurfaceHit>;

    /// The Lambertian albedo per channel at `hit`, into `out`.
    fn albedo(&self, hit: &SurfaceHit, out: &mut [f64]);

    /// The distance intervals (m) along `ray`, within [0, `max_distance_m`], whose points
    /// this surface hides from a light in direction `light` (unit): the shafts of shadow in
    /// the air and its shadow on other surfaces. Appended to `out`. None by default (a
    /// surface that casts no shadow of its own, as the planet's ground, whose shadow the sky
    /// method holds).
    fn shadowed_intervals(
        &self,
        ray: &Ray,
        light: Vec3,
        max_distance_m: f64,
        out: &mut Vec<(f64, f64)>,
    ) {
        let _ = (ray, light, max_distance_m, out);
    }

    /// The fraction of the sky light that reaches `hit` past the rest of this surface,
    /// relative to an open plane of the same tilt (ambient occlusion; the plane's own
    /// (1 + n·up)/2 is the sky method's). 1 by default.
    fn sky_visibility(&self, hit: &SurfaceHit) -> f64 {
        let _ = hit;
        1.0
    }

    /// The horizon's elevation (rad, ≥ 0) that the rest of this surface makes around `hit`
    /// towards azimuth k, the direction (cos 2πk/K, sin 2πk/K) in (east, north), K =
    /// [`HORIZON_AZIMUTHS`], into `out`: the sky below it is hidden (a renderer weights it
    /// by the sky's radiance, `render::sky_dome`). False by default: no horizon but the
    /// surface's own plane, or [`Surface::sky_visibility`] alone.
    fn horizon(&self, hit: &SurfaceHit, out: &mut [f64; HORIZON_AZIMUTHS]) -> bool {
        let _ = (hit, out);
        false
    }

    /// The relief this surface gives the planet, when it reshapes it enough to change the
    /// light of the air around it (`render::terrain_air`); None by default.
    fn relief(&self) -> Option<&dyn Relief> {
        None
    }

    /// A specular BRDF (sr⁻¹) at `hit` for the light from `to_light` seen from `to_viewer`
    /// (unit vectors), added to the Lambertian albedo for the lights' direct beams (the
    /// sea's glint); 0 by default.
    fn specular(&self, hit: &SurfaceHit, to_viewer: Vec3, to_light: Vec3) -> f64 {
        let _ = (hit, to_viewer, to_light);
        0.0
    }
}

/// A surface that reshapes the planet over a region: heights above the planet's sphere over
/// a rectangle of the gnomonic plane tangent at the observer's foot (plane coordinates
/// (u, v) = R·(p_x, p_y)/p_z, m; `scene::terrain::grid`).
pub trait Relief: Send + Sync {
    /// The planet's radius R (m) the heights stand on.
    fn planet_radius_m(&self) -> f64;
    /// The region: [u_min, v_min, u_max, v_max] (m).
    fn bounds_m(&self) -> [f64; 4];
    /// The highest point (m above the sphere).
    fn top_m(&self) -> f64;
    /// The height (m above the sphere) at plane coordinates (u, v).
    fn height_m(&self, u: f64, v: f64) -> f64;
    /// The lowest height (m above the sphere) over (u, v) at which a light in direction
    /// `light` (unit) is seen past the relief, as its shafts in the air are drawn: the
    /// height of the relief itself where it is lit (and where its shadows in the air are
    /// not drawn, as the air there is lit).
    fn shadow_height_m(&self, light: Vec3, u: f64, v: f64) -> f64 {
        let _ = light;
        self.height_m(u, v)
    }
}

/// A borrowed surface is a surface (a scene can hold a terrain built once for many frames).
impl<T: Surface + ?Sized> Surface for &T {
    fn intersect(&self, ray: &Ray, max_distance_m: f64) -> Option<SurfaceHit> {
        (**self).intersect(ray, max_distance_m)
    }
    fn albedo(&self, hit: &SurfaceHit, out: &mut [f64]) {
        (**self).albedo(hit, out)
    }
    fn shadowed_intervals(
        &self,
        ray: &Ray,
        light: Vec3,
        max_distance_m: f64,
        out: &mut Vec<(f64, f64)>,
    ) {
        (**self).shadowed_intervals(ray, light, max_distance_m, out)
    }
    fn sky_visibility(&self, hit: &SurfaceHit) -> f64 {
        (**self).sky_visibility(hit)
    }
    fn horizon(&self, hit: &SurfaceHit, out: &mut [f64; HORIZON_AZIMUTHS]) -> bool {
        (**self).horizon(hit, out)
    }
    fn relief(&self) -> Option<&dyn Relief> {
        (**self).relief()
    }
    fn specular(&self, hit: &SurfaceHit, to_viewer: Vec3, to_light: Vec3) -> f64 {
        (**self).specular(hit, to_viewer, to_light)
    }
}

/// A sphere seen from outside: the planet's ground, or any ball in the scene.
#[derive(Clone, Debug)]
pub struct Sphere {
    /// Centre (planet-centred, m).
    pub centre: Vec3,
    /// Radius (m).
    pub radius_m: f64,
    /// Lambertian albedo per channel.
    pub albedo: Vec<f64>,
    /// Whether it casts shadows into the scene ([`Surface::shadowed_intervals`]); false for
    /// the planet's ground.
    pub casts_shadows: bool,
}

impl Sphere {
    /// The planet's ground: the model's bottom sphere with its albedo. Its shadow (night,
    /// the Earth's shadow at twilight) is in the sky method's transmittance to the light.
    pub fn ground(model: &Model) -> Sphere {
        Sphere {
            centre: Vec3::ZERO,
            radius_m: model.bottom_radius_m,
            albedo: model.ground_albedo.clone(),
            casts_shadows: false,
        }
    }
}

impl Surface for Sphere {
    fn intersect(&self, ray: &Ray, max_distance_m: f64) -> Option<SurfaceHit> {
        // Seen from outside only: the near root, when in front of the origin. An origin
        // outside that looks away (o·d ≥ 0) cannot hit it: no square root for the sky.
        let o = ray.origin - self.centre;
        if o.dot(ray.dir) >= 0.0 {
            return None;
        }
        let (near, _) = ray_sphere(o, ray.dir, self.radius_m)?;
        if !(near > 0.0 && near < max_distance_m) {
            return None;
        }
        let position = ray.origin + near * ray.dir;
        Some(SurfaceHit {
            distance_m: near,
            position,
            // On the sphere: |position − centre| = radius.
            normal: (position - self.centre) / self.radius_m,
        })
    }

    fn albedo(&self, _hit: &SurfaceHit, out: &mut [f64]) {
        out.copy_from_slice(&self.albedo[..out.len()]);
    }

    fn shadowed_intervals(
        &self,
        ray: &Ray,
        light: Vec3,
        max_distance_m: f64,
        out: &mut Vec<(f64, f64)>,
    ) {
        if !self.casts_shadows {
            return;
        }
        // The shadow is the half-cylinder of radius R behind the centre along −light:
        // |P⊥(x − c)| < R and (x − c)·light < 0, with P⊥ the projection across `light`
        // (points between that plane and the back of the sphere are inside it, unseen).
        let o = ray.origin - self.centre;
        let (o_perp, d_perp) = (
            o - o.dot(light) * light,
            ray.dir - ray.dir.dot(light) * light,
        );
        let (a, b, c) = (
            d_perp.length_squared(),
            o_perp.dot(d_perp),
            o_perp.length_squared() - self.radius_m * self.radius_m,
        );
        let (mut t0, mut t1) = if a > 0.0 {
            let disc = b * b - a * c;
            if disc <= 0.0 {
                return;
            }
            let s = disc.sqrt();
            ((-b - s) / a, (-b + s) / a)
        } else if c < 0.0 {
            // Along the light: inside the cylinder everywhere or nowhere.
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return;
        };
        // Behind the centre: o·L + t·d·L < 0.
        let (ol, dl) = (o.dot(light), ray.dir.dot(light));
        if dl > 0.0 {
            t1 = t1.min(-ol / dl);
        } else if dl < 0.0 {
            t0 = t0.max(-ol / dl);
        } else if ol >= 0.0 {
            return;
        }
        let (t0, t1) = (t0.max(0.0), t1.min(max_distance_m));
        if t1 > t0 {
            out.push((t0, t1));
        }
    }
}

/// The complement of the union of `shadowed` within [0, `end`]: the lit intervals, in order.
/// `shadowed` is sorted in place.
pub fn lit_intervals(shadowed: &mut [(f64, f64)], end: f64, out: &mut Vec<(f64, f64)>) {
    shadowed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut lit_from = 0.0;
    for &(a, b) in shadowed.iter() {
        if a > lit_from {
            out.push((lit_from, a.min(end)));
        }
        lit_from = f64::max(lit_from, b);
        if lit_from >= end {
            return;
        }
    }
    if end > lit_from {
        out.push((lit_from, end));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball() -> Sphere {
        Sphere {
            centre: Vec3::new(0.0, 1000.0, 0.0),
            radius_m: 100.0,
            albedo: vec![0.5; 3],
            casts_shadows: true,
        }
    }

    #[test]
    fn sphere_hits_from_outside_only() {
        let s = ball();
        let ray = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::Y,
        };
        let hit = s.intersect(&ray, f64::INFINITY).unwrap();
        assert!((hit.distance_m - 900.0).abs() < 1e-9);
        assert!((hit.normal - Vec3::NEG_Y).length() < 1e-12);
        assert!(s.intersect(&ray, 800.0).is_none());
        let inside = Ray {
            origin: Vec3::new(0.0, 1000.0, 0.0),
            dir: Vec3::Y,
        };
        assert!(s.intersect(&inside, f64::INFINITY).is_none());
    }

    #[test]
    fn shadow_cylinder_behind_a_sphere() {
        // Light from +y: the shadow runs from the centre towards −y. A ray along x at
        // y = 500 crosses it for |x| < 100.
        let s = ball();
        let ray = Ray {
            origin: Vec3::new(-1000.0, 500.0, 0.0),
            dir: Vec3::X,
        };
        let mut out = Vec::new();
        s.shadowed_intervals(&ray, Vec3::Y, f64::INFINITY, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].0 - 900.0).abs() < 1e-9 && (out[0].1 - 1100.0).abs() < 1e-9);
        // On the light's side of the centre: no shadow.
        let front = Ray {
            origin: Vec3::new(-1000.0, 1500.0, 0.0),
            dir: Vec3::X,
        };
        out.clear();
        s.shadowed_intervals(&front, Vec3::Y, f64::INFINITY, &mut out);
        assert!(out.is_empty());
        // The planet's ground casts none of its own.
        let mut g = ball();
        g.casts_shadows = false;
        g.shadowed_intervals(&ray, Vec3::Y, f64::INFINITY, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn lit_intervals_complement_the_shadows() {
        let mut out = Vec::new();
        lit_intervals(&mut [(5.0, 7.0), (2.0, 3.0), (2.5, 4.0)], 10.0, &mut out);
        assert_eq!(out, vec![(0.0, 2.0), (4.0, 5.0), (7.0, 10.0)]);
        out.clear();
        lit_intervals(&mut [(0.0, 20.0)], 10.0, &mut out);
        assert!(out.is_empty());
        out.clear();
        lit_intervals(&mut [], 10.0, &mut out);
        assert_eq!(out, vec![(0.0, 10.0)]);
    }
}
