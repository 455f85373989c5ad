//! [`Elek3d`] seen from one observer under one light: the paper's eq. 16 pieces (Bruneton &
//! Neyret 2008 §5) from the 3D tables, as the 4D tables' view does them
//! ([`crate::sky::bruneton4d::Bruneton4dView`]): sky radiance along a ray, S|x − T·S|x_s
//! towards a point, the shadowed length and the lit intervals of light shafts.
//!
//! The single scattering is S₃,R(r, μ, μ_s)·P_R(ν) + S₃,M·P_M(ν) with the real ν; the
//! multiple scattering is read as it is. The per-view cache: every ray from an observer
//! inside the atmosphere starts at its (r, μ_s), so the three tables are filtered there
//! once into 1D slices over μ.

use super::{Elek3d, Params};
use crate::atmosphere::groups::{AEROSOLS, MOLECULES};
use crate::math::sphere::{
    advance, distance_to_nearest_atmosphere_boundary, ray_intersects_ground,
};
use crate::math::{smoothstep, Vec3};
use crate::scene::light::Light;
use crate::sky::bruneton4d::{twilight, Lookup};
use crate::sky::entry::{enter_atmosphere, Entry};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::with_channel_buffers;

/// [`Elek3d`] prepared for views from one observer under one light.
pub struct Elek3dView<'a> {
    sky: &'a Elek3d,
    light: &'a Light,
    lookup: Lookup<'a>,
    params: Params,
    observer: Vec3,
    observer_r: f64,
    /// The tables at the observer's (r, μ_s), when it is inside the atmosphere:
    /// `[y·3n + c]`, single Rayleigh, single Mie and multiple per view-zenith texel.
    slice: Option<Vec<f64>>,
    /// The light's irradiance over the solar irradiance the tables were computed with.
    scale: Vec<f64>,
}

/// Which orders a lookup sums.
#[derive(Clone, Copy, PartialEq)]
enum Orders {
    All,
    Single,
    Multiple,
}

/// A view ray at its start.
struct RayGeometry {
    r: f64,
    mu: f64,
    mu_s: f64,
    nu: f64,
    ground: bool,
    at_observer: bool,
}

impl<'a> Elek3dView<'a> {
    /// The view from `observer` under `light`.
    pub fn new(sky: &'a Elek3d, observer: Vec3, light: &'a Light) -> Elek3dView<'a> {
        let lookup = sky.lookup(light.angular_radius_rad);
        let params = sky.params();
        let r = observer.length();
        let slice = (r <= sky.model.top_radius_m).then(|| {
            let mu_s = (observer.dot(light.direction) / r).clamp(-1.0, 1.0);
            let (u_h, u_mu_s) = (params.u_h(r), params.u_mu_s(mu_s));
            let n = sky.channels();
            let tables = [&sky.single_rayleigh, &sky.single_mie, &sky.multiple];
            let slices = tables.map(|t| t.slice(u_h, u_mu_s));
            let mut s = Vec::with_capacity(3 * slices[0].len());
            for y in 0..params.nmu {
                for one in &slices {
                    s.extend_from_slice(&one[y * n..(y + 1) * n]);
                }
            }
            s
        });
        Elek3dView {
            sky,
            light,
            lookup,
            params,
            observer,
            observer_r: r,
            slice,
            scale: light.scale_against(&sky.model.solar_irradiance),
        }
    }

    fn channels(&self) -> usize {
        self.sky.channels()
    }

    fn start(&self, dir: Vec3) -> Option<Entry> {
        enter_atmosphere(
            self.observer,
            self.observer_r,
            dir,
            self.sky.model.top_radius_m,
        )
    }

    fn geometry(&self, start: &Entry, dir: Vec3) -> RayGeometry {
        let r = start.r;
        let mu = start.mu();
        RayGeometry {
            r,
            mu,
            mu_s: (start.point.dot(self.light.direction) / r).clamp(-1.0, 1.0),
            nu: dir.dot(self.light.direction).clamp(-1.0, 1.0),
            ground: ray_intersects_ground(r, mu, self.sky.model.bottom_radius_m),
            at_observer: start.at_observer,
        }
    }

    /// The tables at distance `d` (m) along `ray` into `single` (`[Rayleigh | Mie]`,
    /// phase-free, 2n) and `multiple` (radiance), the orders not asked for zero; below the
    /// tables' lowest sun, faded as the 4D tables' sky is ([`twilight::fade`]).
    fn scattering_at(
        &self,
        ray: &RayGeometry,
        d: f64,
        orders: Orders,
        single: &mut [f64],
        multiple: &mut [f64],
    ) {
        let n = self.channels();
        let (r, mu, mu_s) = if d == 0.0 {
            (ray.r, ray.mu, ray.mu_s)
        } else {
            let m = &self.sky.model;
            let (r_d, mu_d) = advance(ray.r, ray.mu, d, m.bottom_radius_m, m.top_radius_m);
            let mu_s_d = ((ray.r * ray.mu_s + d * ray.nu) / r_d).clamp(-1.0, 1.0);
            (r_d, mu_d, mu_s_d)
        };
        let sky = self.sky;
        match self.slice.as_ref().filter(|_| d == 0.0 && ray.at_observer) {
            Some(slice) => {
                let u_mu = self.params.u_mu(r, mu, ray.ground);
                let (y0, y1, t) =
                    crate::sky::bruneton4d::table::lerp_weights(u_mu, self.params.nmu);
                let (a, b) = (&slice[y0 * 3 * n..][..3 * n], &slice[y1 * 3 * n..][..3 * n]);
                for k in 0..2 * n {
                    single[k] = (1.0 - t) * a[k] + t * b[k];
                }
                for k in 0..n {
                    multiple[k] = (1.0 - t) * a[2 * n + k] + t * b[2 * n + k];
                }
            }
            None => {
                let taps = sky
                    .single_rayleigh
                    .taps(self.params.coords(r, mu, mu_s, ray.ground));
                let (rayleigh, mie) = single.split_at_mut(n);
                sky.single_rayleigh.sample_taps_into(&taps, rayleigh);
                sky.single_mie.sample_taps_into(&taps, mie);
                sky.multiple.sample_taps_into(&taps, multiple);
            }
        }
        match orders {
            Orders::All => {}
            Orders::Single => multiple[..n].iter_mut().for_each(|v| *v = 0.0),
            Orders::Multiple => single[..2 * n].iter_mut().for_each(|v| *v = 0.0),
        }
        if mu_s < sky.model.mu_s_min {
            with_channel_buffers(n, |[fade]| {
                twilight::fade(&self.lookup, &sky.irradiance, r, mu_s, fade);
                for k in 0..n {
                    single[k] *= fade[k];
                    single[n + k] *= fade[k];
                    multiple[k] *= fade[k];
                }
            });
        }
    }

    /// Σ over the lit intervals [a, b] (m from the ray's start) of T(0, a)·S(a) − T(0, b)·S(b),
    /// with the phase functions at the ray's ν, into `radiance` (scaled to the light).
    /// `end`: the ray's length; an interval reaching it subtracts nothing when `open_end`
    /// (a ray to the sky). `t_end`: T(0, end) when the caller has it (else empty). Single
    /// Mie is multiplied by `mie_fade`.
    #[allow(clippy::too_many_arguments)]
    fn lit_radiance(
        &self,
        ray: &RayGeometry,
        intervals: impl IntoIterator<Item = (f64, f64)>,
        end: f64,
        open_end: bool,
        t_end: &[f64],
        mie_fade: f64,
        orders: Orders,
        radiance: &mut [f64],
    ) {
        let n = self.channels();
        let phase = &self.sky.model.groups.phase;
        let (pr, pm) = (phase[MOLECULES].eval(ray.nu), phase[AEROSOLS].eval(ray.nu));
        radiance[..n].iter_mut().for_each(|v| *v = 0.0);
        with_channel_buffers(2 * n, |[single, single_b, multiple, multiple_b, t]| {
            let (multiple, multiple_b, t) = (&mut multiple[..n], &mut multiple_b[..n], &mut t[..n]);
            for (a, b) in intervals {
                let (a, b) = (a.max(0.0), b.min(end));
                if b <= a {
                    continue;
                }
                self.scattering_at(ray, a, orders, single, multiple);
                if a > 0.0 {
                    self.lookup.transmittance(ray.r, ray.mu, a, ray.ground, t);
                    for k in 0..n {
                        single[k] *= t[k];
                        single[n + k] *= t[k];
                        multiple[k] *= t[k];
                    }
                }
                if b < end || !open_end {
                    self.scattering_at(ray, b, orders, single_b, multiple_b);
                    let t: &[f64] = if b == end && !t_end.is_empty() {
                        t_end
                    } else {
                        self.lookup.transmittance(ray.r, ray.mu, b, ray.ground, t);
                        t
                    };
                    for k in 0..n {
                        single[k] = (single[k] - t[k] * single_b[k]).max(0.0);
                        single[n + k] = (single[n + k] - t[k] * single_b[n + k]).max(0.0);
                        multiple[k] = (multiple[k] - t[k] * multiple_b[k]).max(0.0);
                    }
                }
                for k in 0..n {
                    radiance[k] += single[k] * pr + single[n + k] * pm * mie_fade + multiple[k];
                }
            }
        });
        for (v, s) in radiance[..n].iter_mut().zip(&self.scale) {
            *v *= s;
        }
    }

    /// The light reaching only the `lit` intervals: single scattering over those, multiple
    /// over the whole ray up to `end` (the air in a shadow is still lit by the sky).
    #[allow(clippy::too_many_arguments)]
    fn shafted_radiance(
        &self,
        ray: &RayGeometry,
        lit: impl IntoIterator<Item = (f64, f64)>,
        end: f64,
        open_end: bool,
        t_end: &[f64],
        mie_fade: f64,
        radiance: &mut [f64],
    ) {
        let n = self.channels();
        with_channel_buffers(n, |[multiple]| {
            self.lit_radiance(
                ray,
                [(0.0, end)],
                end,
                open_end,
                t_end,
                mie_fade,
                Orders::Multiple,
                multiple,
            );
            self.lit_radiance(
                ray,
                lit,
                end,
                open_end,
                t_end,
                mie_fade,
                Orders::Single,
                radiance,
            );
            for k in 0..n {
                radiance[k] += multiple[k];
            }
        });
    }

    /// Distance from the ray's start to the ground or the top.
    fn boundary_distance(&self, ray: &RayGeometry) -> f64 {
        let m = &self.sky.model;
        distance_to_nearest_atmosphere_boundary(
            ray.r,
            ray.mu,
            m.bottom_radius_m,
            m.top_radius_m,
            ray.ground,
        )
    }
}

impl SkyView for Elek3dView<'_> {
    fn light(&self) -> &Light {
        self.light
    }

    fn sky_radiance(
        &self,
        dir: Vec3,
        shadow: Shadow,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) {
        let n = self.channels();
        let Some(start) = self.start(dir) else {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance.iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        let ray = self.geometry(&start, dir);
        if transmittance.is_empty() {
        } else if ray.ground {
            transmittance[..n].iter_mut().for_each(|v| *v = 0.0);
        } else {
            self.lookup
                .transmittance_to_top(ray.r, ray.mu, &mut transmittance[..n]);
        }
        let end = f64::INFINITY;
        match shadow {
            Shadow::Length(l) if l > 0.0 => {
                self.lit_radiance(&ray, [(l, end)], end, true, &[], 1.0, Orders::All, radiance)
            }
            Shadow::Lit(intervals) => {
                let offset = start.offset_m(self.observer);
                let shifted = intervals.iter().map(|&(a, b)| (a - offset, b - offset));
                let length = self.boundary_distance(&ray);
                self.shafted_radiance(&ray, shifted, length, true, &[], 1.0, radiance)
            }
            _ => self.lit_radiance(
                &ray,
                [(0.0, end)],
                end,
                true,
                &[],
                1.0,
                Orders::All,
                radiance,
            ),
        }
    }

    fn sky_radiance_to_point(
        &self,
        point: Vec3,
        shadow: Shadow,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) {
        let n = self.channels();
        let dir = (point - self.observer).normalize_or_zero();
        let Some(start) = self.start(dir) else {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance[..n].iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        // A point before the ray enters the atmosphere sees no air.
        let d_total = start.distance_to(self.observer, point);
        if d_total <= 0.0 {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance[..n].iter_mut().for_each(|v| *v = 1.0);
            return;
        }
        let ray = self.geometry(&start, dir);
        self.lookup
            .transmittance(ray.r, ray.mu, d_total, ray.ground, &mut transmittance[..n]);
        let t = &transmittance[..n];
        // As the 4D tables (Bruneton 2017): single Mie faded out as the light sets.
        let fade = smoothstep(0.0, 0.01, ray.mu_s);
        match shadow {
            Shadow::None => self.lit_radiance(
                &ray,
                [(0.0, d_total)],
                d_total,
                false,
                t,
                fade,
                Orders::All,
                radiance,
            ),
            Shadow::Length(l) => {
                let d = (d_total - l.max(0.0)).max(0.0);
                self.lit_radiance(
                    &ray,
                    [(0.0, d)],
                    d_total,
                    false,
                    t,
                    fade,
                    Orders::All,
                    radiance,
                )
            }
            Shadow::Lit(intervals) => {
                let offset = start.offset_m(self.observer);
                let shifted = intervals.iter().map(|&(a, b)| (a - offset, b - offset));
                self.shafted_radiance(&ray, shifted, d_total, false, t, fade, radiance)
            }
        }
    }

    fn transmittance_to_point(&self, point: Vec3, out: &mut [f64]) {
        let dir = (point - self.observer).normalize_or_zero();
        let Some(start) = self.start(dir) else {
            out.iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        let ray = self.geometry(&start, dir);
        let d = (start.distance_to(self.observer, point)).max(0.0);
        self.lookup.transmittance(ray.r, ray.mu, d, ray.ground, out);
    }

    fn transmittance_to_light(&self, point: Vec3, out: &mut [f64]) {
        self.lookup
            .transmittance_to_light(point, self.light.direction, out);
    }

    fn sun_and_sky_irradiance(
        &self,
        point: Vec3,
        normal: Vec3,
        direct: &mut [f64],
        sky: &mut [f64],
    ) {
        let irradiance = &self.sky.irradiance;
        crate::sky::surface_irradiance::sun_and_sky_irradiance(
            &self.lookup,
            self.light,
            point,
            normal,
            |r, mu_s, out| {
                twilight::sky_irradiance(&self.lookup, irradiance, r, mu_s, out);
                for (v, s) in out.iter_mut().zip(&self.scale) {
                    *v *= s;
                }
            },
            direct,
            sky,
        );
    }
}
