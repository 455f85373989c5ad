//! The multiple scattering of the air under the clouds. The sky methods' multiple
//! scattering is the clear sky's: the air scatters the light of a whole sunlit sky and of
//! the sunlit ground below it. Under a cloud deck that light is the clouds': what leaves
//! their base (the sky's light and the light's beam diffused through them) and what the
//! dimmed ground returns. Keeping the clear sky's multiple scattering there drew a thick
//! overcast at a low sun +50 % too bright at the cloud bases and +112 % over the ground,
//! and its horizon blue (docs/accuracy.md, "Clouds").
//!
//! So the air below the clouds' base keeps `w` of its multiple scattering, `w` the ratio
//! of the light that drives it, per channel: the scalar flux of the diffuse field, for an
//! isotropic field twice the hemispheric irradiances, from the sky above (E_sky) and from
//! the Lambertian ground below (A·(E_direct + E_sky)),
//!
//! ```text
//! w = (E_sky' + A·(E_direct' + E_sky')) / (E_sky + A·(E_direct + E_sky))
//! ```
//!
//! primed under the clouds ([`super::volumes::dim_surface_light`] on the ground below: the
//! clouds' two-stream transmission of the sky's light and of the light's beam, the bounces
//! between the ground and the clouds' base), unprimed clear (the sky method). Whether the
//! light's beam reaches the air parcel itself (its single scattering: the shafts) does not
//! enter: the diffuse light is the neighbourhood's. The air under a cloud base sees the
//! sky over a neighbourhood of about twice the base's height (half the cosine-weighted
//! hemisphere lies within 45° of the zenith, 90 % within 72°): the ratio is averaged over a
//! box of half-width twice the base's altitude, so that the air under one cumulus of a
//! broken field keeps most of the open sky's light and the air under an overcast takes the
//! overcast's. Tabulated per light over the clouds' shadow map's square
//! ([`super::cloud_shadow::HALF_EXTENT_M`]) at [`AIR_TEXELS`]², once per frame; beyond the
//! square, the edge's texels.
//!
//! The ground's own diffuse light is smoothed the same way. [`dim_surface_light`] treats
//! each column alone (the independent pixel approximation): the light a cloud diffuses
//! reaches the ground straight below it, so the ground in a cumulus' shadow took all of
//! that cloud's forward-scattered beam and the sunlit ground in the gap beside it none. In
//! a broken field the diffuse photons leave a cloud's base and sides over the whole
//! hemisphere and land over a neighbourhood of a few base heights; the nonlocal independent
//! pixel approximation (Marshak, Davis, Wiscombe & Cahalan 1995, "Radiative smoothing in
//! fractal clouds", JGR 100(D12) 26247; Marshak et al. 1998, IEEE TGRS 36(1) 192) smooths
//! the columns' field by such a kernel. So the ground below the base takes the clear sky's
//! irradiance times `g`, the ratio of the dimmed to the clear sky irradiance of the ground
//! (the diffuse from the beam and the ground–base bounces included), averaged over the
//! same box as `w`; the beam stays local. Against the path tracer (docs/accuracy.md,
//! "Clouds") the cumulus field's ground in shadow under a 30° sun went from +18.0 % bias
//! to a few %.

use rayon::prelude::*;

use super::cloud_shadow::{CloudShadow, HALF_EXTENT_M};
use super::volumes::dim_surface_light;
use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::scene::{Ray, Scene};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::{with_channel_buffers, MAX_CHANNELS};

/// Texels per side of the weight map (2.5 km each over the square of half side 80 km).
pub const AIR_TEXELS: usize = 64;
/// The half-width of the averaging box, in the cloud base's altitude above the ground.
pub const NEIGHBOURHOOD_IN_BASE_HEIGHTS: f64 = 2.0;

/// The share of the clear sky's multiple scattering that the air under the clouds keeps,
/// per channel, over the ground of the shadow map's square.
pub struct ShadowedAir {
    channels: usize,
    /// The clouds' lowest base (m, planet-centred): the air below it is dimmed.
    base_radius_m: f64,
    /// The planet's radius (m): planar coordinates are gnomonic at this radius.
    planet_radius_m: f64,
    /// w per texel and channel, row-major from (−HALF, −HALF), channels innermost.
    weights: Vec<f32>,
    /// g per texel and channel (as `weights`): the ground's sky irradiance under the
    /// clouds over the clear sky's, averaged over the neighbourhood.
    ground: Vec<f32>,
}

impl ShadowedAir {
    /// The weights under `scene`'s volumes for the light of `view`, whose shadow map is
    /// `map`.
    pub fn new(scene: &Scene, view: &dyn SkyView, map: &CloudShadow) -> ShadowedAir {
        let model = scene.sky.model();
        let n = model.channels();
        let planet = model.bottom_radius_m;
        let light = view.light();
        let step = 2.0 * HALF_EXTENT_M / AIR_TEXELS as f64;
        let local: Vec<[[f64; MAX_CHANNELS]; 2]> = (0..AIR_TEXELS * AIR_TEXELS)
            .into_par_iter()
            .map(|texel| {
                let (i, j) = (texel % AIR_TEXELS, texel / AIR_TEXELS);
                let x = -HALF_EXTENT_M + (i as f64 + 0.5) * step;
                let y = -HALF_EXTENT_M + (j as f64 + 0.5) * step;
                let up = Vec3::new(x, y, planet).normalize();
                let ground = up * planet;
                let [mut w, mut g] = [[1.0f64; MAX_CHANNELS]; 2];
                with_channel_buffers(n, |[direct, sky, t_air, direct_c, sky_c]| {
                    view.sun_and_sky_irradiance(ground, up, direct, sky);
                    direct_c.copy_from_slice(direct);
                    sky_c.copy_from_slice(sky);
                    view.transmittance_to_light(ground, t_air);
                    let e_light = &light.irradiance[..n];
                    let dir = light.direction;
                    dim_surface_light(
                        scene,
                        Some(map),
                        ground,
                        up,
                        dir,
                        e_light,
                        t_air,
                        direct,
                        sky,
                    );
                    for k in 0..n {
                        let a = model.ground_albedo[k];
                        let clear = sky_c[k] + a * (direct_c[k] + sky_c[k]);
                        let under = sky[k] + a * (direct[k] + sky[k]);
                        if clear > 0.0 {
                            w[k] = under / clear;
                        }
                        if sky_c[k] > 0.0 {
                            g[k] = sky[k] / sky_c[k];
                        }
                    }
                });
                [w, g]
            })
            .collect();
        // The means over the neighbourhood the air under the base sees.
        let base_m = (map.base_radius_m() - planet).max(0.0);
        let half = (NEIGHBOURHOOD_IN_BASE_HEIGHTS * base_m / step).round() as isize;
        ShadowedAir {
            channels: n,
            base_radius_m: map.base_radius_m(),
            planet_radius_m: planet,
            weights: box_mean(&local, 0, n, half),
            ground: box_mean(&local, 1, n, half),
        }
    }

    /// The channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// w per texel and channel ([`AIR_TEXELS`]² row-major from (−HALF, −HALF), channels
    /// innermost), what a GPU frame samples.
    pub fn texels(&self) -> &[f32] {
        &self.weights
    }

    /// g per texel and channel (as [`ShadowedAir::texels`]), what a GPU frame samples.
    pub fn ground_texels(&self) -> &[f32] {
        &self.ground
    }

    /// w over the ground below `x` (bilinear; the edge texels beyond the square), per
    /// channel into `out`.
    pub fn weight(&self, x: Vec3, out: &mut [f64]) {
        self.sample(&self.weights, x, out);
    }

    /// The sky's light on the ground (or terrain) at `x` under the clouds: `clear`, the sky
    /// method's sky irradiance there (on the surface's tilt, before the clouds), times the
    /// neighbourhood's g, into `sky` (per channel), in place of
    /// [`dim_surface_light`]'s column-local estimate. False, `sky` untouched, at or above
    /// the clouds' base.
    pub fn ground_sky(&self, x: Vec3, clear: &[f64], sky: &mut [f64]) -> bool {
        if x.length() >= self.base_radius_m {
            return false;
        }
        self.sample(&self.ground, x, sky);
        for (s, c) in sky.iter_mut().zip(clear) {
            *s *= c;
        }
        true
    }

    /// `table` (w or g) below `x`, bilinear, per channel into `out`.
    fn sample(&self, table: &[f32], x: Vec3, out: &mut [f64]) {
        let n = self.channels;
        if x.z <= 0.0 {
            out[..n].iter_mut().for_each(|w| *w = 1.0);
            return;
        }
        let s = self.planet_radius_m / x.z;
        let step = 2.0 * HALF_EXTENT_M / AIR_TEXELS as f64;
        let max = (AIR_TEXELS - 1) as f64;
        let fx = ((x.x * s + HALF_EXTENT_M) / step - 0.5).clamp(0.0, max);
        let fy = ((x.y * s + HALF_EXTENT_M) / step - 0.5).clamp(0.0, max);
        let (i, j) = (
            (fx as usize).min(AIR_TEXELS - 2),
            (fy as usize).min(AIR_TEXELS - 2),
        );
        let (tx, ty) = (fx - i as f64, fy - j as f64);
        let at = |i: usize, j: usize, k: usize| table[(j * AIR_TEXELS + i) * n + k] as f64;
        for (k, w) in out[..n].iter_mut().enumerate() {
            let lo = at(i, j, k) + (at(i + 1, j, k) - at(i, j, k)) * tx;
            let hi = at(i, j + 1, k) + (at(i + 1, j + 1, k) - at(i, j + 1, k)) * tx;
            *w = lo + (hi - lo) * ty;
        }
    }

    /// The stretches of `ray` below the clouds' base and before `end`, cut at the
    /// boundaries of the clouds' shadow along it (`clouded`: increasing, disjoint), with
    /// their weights (at each stretch's middle), into `out` for [`dim_multiple`]. The GPU
    /// walks the same boundaries (`clouded_air`), where the pieces of the single
    /// scattering's lit stretches are looked up anyway.
    pub fn weigh(&self, ray: &Ray, end: f64, clouded: &[(f64, f64)], out: &mut Dimmed) {
        let n = self.channels;
        out.clear();
        let Some((near, far)) = ray_sphere(ray.origin, ray.dir, self.base_radius_m) else {
            return;
        };
        let (a, b) = (near.max(0.0), far.min(end));
        let cuts = clouded.iter().flat_map(|&(x, y)| [x, y]);
        let mut t = a;
        for next in cuts.filter(|&c| c > a && c < b).chain([b]) {
            if next <= t {
                continue;
            }
            let start = out.weights.len();
            out.weights.resize(start + n, 1.0);
            self.weight(
                ray.origin + 0.5 * (t + next) * ray.dir,
                &mut out.weights[start..],
            );
            out.stretches.push((t, next));
            t = next;
        }
    }
}

/// The mean of entry `which` of `local`'s texels ([`AIR_TEXELS`]², n channels each) over a
/// box of `half` texels each side (clipped at the square's edge), row-major with channels
/// innermost.
fn box_mean(local: &[[[f64; MAX_CHANNELS]; 2]], which: usize, n: usize, half: isize) -> Vec<f32> {
    let last = AIR_TEXELS as isize - 1;
    let mut out = vec![0.0f32; AIR_TEXELS * AIR_TEXELS * n];
    out.par_chunks_mut(AIR_TEXELS * n)
        .enumerate()
        .for_each(|(j, row)| {
            let (j0, j1) = ((j as isize - half).max(0), (j as isize + half).min(last));
            for i in 0..AIR_TEXELS {
                let (i0, i1) = ((i as isize - half).max(0), (i as isize + half).min(last));
                let mut sum = [0.0f64; MAX_CHANNELS];
                for jj in j0..=j1 {
                    for ii in i0..=i1 {
                        let v = &local[jj as usize * AIR_TEXELS + ii as usize][which];
                        for k in 0..n {
                            sum[k] += v[k];
                        }
                    }
                }
                let count = ((i1 - i0 + 1) * (j1 - j0 + 1)) as f64;
                for k in 0..n {
                    row[i * n + k] = (sum[k] / count) as f32;
                }
            }
        });
    out
}

/// The stretches of a view ray under the clouds with the share of the multiple scattering
/// each keeps (n channels per stretch).
#[derive(Clone, Debug, Default)]
pub struct Dimmed {
    /// [start, end] (m from the observer along the ray).
    pub stretches: Vec<(f64, f64)>,
    /// w per stretch and channel.
    pub weights: Vec<f64>,
}

impl Dimmed {
    /// No stretch.
    pub fn clear(&mut self) {
        self.stretches.clear();
        self.weights.clear();
    }
}

/// Take out of `radiance` (the air's light along `ray`, from `view`'s observer, up to
/// `end`) the multiple scattering that the stretches of `dimmed` do not keep: (1 − w) of
/// each stretch's (clipped to `end`), that being the difference of the multiple scattering
/// to the stretch's two ends (each with its transmittance from the observer).
pub fn dim_multiple(
    view: &dyn SkyView,
    ray: &Ray,
    dimmed: &Dimmed,
    end: f64,
    radiance: &mut [f64],
) {
    let n = radiance.len();
    if dimmed.stretches.is_empty() {
        return;
    }
    with_channel_buffers(n, |[near, far, t]| {
        // The multiple scattering to the point at `d` (0 at the observer).
        let multiple_to = |d: f64, out: &mut [f64], t: &mut [f64]| {
            if d <= 0.0 {
                out.iter_mut().for_each(|v| *v = 0.0);
            } else {
                view.sky_radiance_to_point(ray.origin + d * ray.dir, Shadow::Lit(&[]), out, t);
            }
        };
        let mut reached = f64::NAN;
        for (s, &(a, b)) in dimmed.stretches.iter().enumerate() {
            let b = b.min(end);
            if b <= a {
                continue;
            }
            // Consecutive stretches share an end.
            if a == reached {
                near.copy_from_slice(far);
            } else {
                multiple_to(a, near, t);
            }
            multiple_to(b, far, t);
            reached = b;
            let w = &dimmed.weights[s * n..(s + 1) * n];
            for k in 0..n {
                let m = (far[k] - near[k]).max(0.0);
                radiance[k] = (radiance[k] - (1.0 - w[k]) * m).max(0.0);
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stretches cover the ray below the base exactly, cut at the shadow's boundaries
    /// inside it, each with its weight.
    #[test]
    fn the_stretches_tile_the_air_below_the_base() {
        let planet = 6_360_000.0;
        let air = ShadowedAir {
            channels: 2,
            base_radius_m: planet + 1000.0,
            planet_radius_m: planet,
            weights: (0..AIR_TEXELS * AIR_TEXELS)
                .flat_map(|_| [0.25, 0.5])
                .collect(),
            ground: vec![1.0; AIR_TEXELS * AIR_TEXELS * 2],
        };
        let dir = Vec3::new(0.6, 0.0, 0.8);
        let ray = Ray {
            origin: Vec3::new(0.0, 0.0, planet + 2.0),
            dir,
        };
        let (_, exit) = ray_sphere(ray.origin, dir, planet + 1000.0).unwrap();
        let mut out = Dimmed::default();
        // One shadow straddling the base, one inside, one beyond the end.
        let clouded = [
            (100.0, 300.0),
            (500.0, exit + 50.0),
            (exit + 100.0, exit + 200.0),
        ];
        air.weigh(&ray, f64::INFINITY, &clouded, &mut out);
        let want = [(0.0, 100.0), (100.0, 300.0), (300.0, 500.0), (500.0, exit)];
        assert_eq!(out.stretches, want);
        assert_eq!(out.weights.len(), 2 * want.len());
        for w in out.weights.chunks(2) {
            assert!(
                (w[0] - 0.25).abs() < 1e-6 && (w[1] - 0.5).abs() < 1e-6,
                "{w:?}"
            );
        }
        // Clipped at the end; none from above the base looking up.
        air.weigh(&ray, 400.0, &clouded, &mut out);
        assert_eq!(
            out.stretches,
            [(0.0, 100.0), (100.0, 300.0), (300.0, 400.0)]
        );
        let above = Ray {
            origin: Vec3::new(0.0, 0.0, planet + 1500.0),
            dir,
        };
        air.weigh(&above, f64::INFINITY, &[], &mut out);
        assert!(out.stretches.is_empty());
    }

    /// The neighbourhood's mean moves the light, it does not make any: a spike of g in one
    /// texel spreads evenly over the (2h + 1)² texels around it, and the sum over the
    /// square (away from its edge) is kept.
    #[test]
    fn the_smoothing_spreads_a_texel_over_its_neighbourhood() {
        let half = 2;
        let mut local = vec![[[0.0; MAX_CHANNELS]; 2]; AIR_TEXELS * AIR_TEXELS];
        let (ci, cj) = (20, 30);
        local[cj * AIR_TEXELS + ci][1][..2].copy_from_slice(&[25.0, 50.0]);
        let out = box_mean(&local, 1, 2, half);
        let mut sum = [0.0; 2];
        for j in 0..AIR_TEXELS {
            for i in 0..AIR_TEXELS {
                let inside = i.abs_diff(ci) <= 2 && j.abs_diff(cj) <= 2;
                let texel = &out[(j * AIR_TEXELS + i) * 2..][..2];
                let want = if inside { [1.0, 2.0] } else { [0.0, 0.0] };
                assert_eq!(texel, want, "texel ({i}, {j})");
                sum[0] += texel[0];
                sum[1] += texel[1];
            }
        }
        assert_eq!(sum, [25.0, 50.0]);
        // w is the other entry: untouched by g's spike.
        assert!(box_mean(&local, 0, 2, half).iter().all(|&w| w == 0.0));
    }

    /// The ground below the base takes the clear sky's light times g (bilinear between
    /// texels); at or above the base the column's own estimate stays.
    #[test]
    fn the_ground_below_the_base_takes_the_neighbourhoods_light() {
        let planet = 6_360_000.0;
        let step = 2.0 * HALF_EXTENT_M / AIR_TEXELS as f64;
        // g rises by 0.01 per texel eastwards.
        let ground = (0..AIR_TEXELS * AIR_TEXELS)
            .flat_map(|t| {
                let g = 0.5 + 0.01 * (t % AIR_TEXELS) as f32;
                [g, 2.0 * g]
            })
            .collect();
        let air = ShadowedAir {
            channels: 2,
            base_radius_m: planet + 1000.0,
            planet_radius_m: planet,
            weights: vec![1.0; AIR_TEXELS * AIR_TEXELS * 2],
            ground,
        };
        // Half-way between the centres of texels 32 and 33 (x = step), on the ground.
        let x = Vec3::new(step, 0.0, planet);
        let mut sky = [7.0, 7.0];
        assert!(air.ground_sky(x, &[2.0, 3.0], &mut sky));
        let g = 0.5 + 0.01 * 32.5;
        assert!((sky[0] - 2.0 * g).abs() < 1e-6 && (sky[1] - 3.0 * 2.0 * g).abs() < 1e-6);
        let mut sky = [7.0, 7.0];
        assert!(!air.ground_sky(Vec3::new(step, 0.0, planet + 1000.0), &[2.0, 3.0], &mut sky));
        assert_eq!(sky, [7.0, 7.0]);
    }
}
