//! Evaluation of the precomputed tables for one observer and one light (Bruneton & Neyret
//! 2008 §5, eq. 16 pieces, as in Bruneton 2017 `GetSkyRadiance`, `GetSkyRadianceToPoint`,
//! `GetSunAndSkyIrradiance`).
//!
//! The per-view cache: every ray from an observer inside the atmosphere starts at the same
//! radius r and sun zenith cosine μ_s, so the 4D scattering tables are filtered once into a
//! 2D (μ, ν) slice at that (r, μ_s) and the start of every ray from the observer is looked
//! up there (the same values: the filter is separable). Rays that start elsewhere (views
//! from space enter the atmosphere at a different point per ray) and the far ends of rays
//! use the 4D tables.

use super::lookup::Lookup;
use super::{params, twilight, Bruneton4d, MieStorage};
use crate::atmosphere::groups::{AEROSOLS, MOLECULES};
use crate::math::sphere::{advance, ray_intersects_ground};
use crate::math::{smoothstep, Vec3};
use crate::scene::light::Light;
use crate::sky::entry::{enter_atmosphere, Entry};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::with_channel_buffers;

/// [`Bruneton4d`] prepared for views from one observer under one light.
pub struct Bruneton4dView<'a> {
    sky: &'a Bruneton4d,
    light: &'a Light,
    lookup: Lookup<'a>,
    observer: Vec3,
    /// |observer| (m).
    observer_r: f64,
    /// The tables at the observer's (r, μ_s), when it is inside the atmosphere.
    slice: Option<Slice>,
    /// The light's irradiance over the solar irradiance the tables were computed with.
    scale: Vec<f64>,
}

/// The scattering tables filtered at one (r, μ_s) (`Table4::slice`): single Rayleigh and
/// multiple scattering interleaved per texel ([single; multiple], one filter serves both),
/// and single Mie.
struct Slice {
    scattering: Vec<f64>,
    mie: Vec<f64>,
}

/// Where a table lookup reads: the slice at (u_ν, u_μ), or the 4D tables at (u_ν, u_μs,
/// u_μ, u_r).
#[derive(Clone, Copy)]
enum At<'s> {
    Slice(&'s Slice, f64, f64),
    Table([f64; 4]),
}

/// Which orders of the tables a lookup sums: the single scattering, the multiple, or both.
#[derive(Clone, Copy, PartialEq)]
enum Orders {
    All,
    Single,
    Multiple,
}

/// A view ray at its start: (r, μ, μ_s, ν), whether it meets the ground, whether it starts
/// at the observer.
struct RayGeometry {
    r: f64,
    mu: f64,
    mu_s: f64,
    nu: f64,
    ground: bool,
    at_observer: bool,
}

impl<'a> Bruneton4dView<'a> {
    /// The view from `observer` under `light`.
    pub fn new(sky: &'a Bruneton4d, observer: Vec3, light: &'a Light) -> Bruneton4dView<'a> {
        let lookup = sky.lookup(light.angular_radius_rad);
        let r = observer.length();
        let slice = (r <= sky.model.top_radius_m).then(|| {
            let mu_s = (observer.dot(light.direction) / r).clamp(-1.0, 1.0);
            Slice::new(sky, &lookup, r, mu_s)
        });
        let scale = light.scale_against(&sky.model.solar_irradiance);
        Bruneton4dView {
            sky,
            light,
            lookup,
            observer,
            observer_r: r,
            slice,
            scale,
        }
    }

    fn channels(&self) -> usize {
        self.sky.channels()
    }

    /// Where the ray from the observer along `dir` enters the atmosphere: the observer
    /// itself when inside, else the entry point of the top; None when the ray misses it.
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
        let mu = (start.rmu / r).clamp(-1.0, 1.0);
        RayGeometry {
            r,
            mu,
            mu_s: (start.point.dot(self.light.direction) / r).clamp(-1.0, 1.0),
            nu: dir.dot(self.light.direction).clamp(-1.0, 1.0),
            ground: ray_intersects_ground(r, mu, self.sky.model.bottom_radius_m),
            at_observer: start.at_observer,
        }
    }

    /// Rayleigh + multiple scattering (divided by the molecular phase function) and single
    /// Mie scattering, without phase functions, at distance `d` (m) along the ray (Bruneton
    /// 2017 `GetCombinedScattering`; the ratio rule for red-only Mie). `at_start` (d = 0):
    /// the ray's start, from the slice when the ray starts at the observer. `rayleigh_phase`:
    /// the molecular phase function at the ray's ν. `orders`: the single scattering only
    /// (Rayleigh and Mie), the multiple only (into `scat`, `mie` zero), or both.
    #[allow(clippy::too_many_arguments)]
    fn combined_scattering(
        &self,
        ray: &RayGeometry,
        d: f64,
        at_start: bool,
        rayleigh_phase: f64,
        orders: Orders,
        scat: &mut [f64],
        mie: &mut [f64],
    ) {
        let sky = self.sky;
        let tables = &sky.tables;
        let lk = &self.lookup;
        let n = scat.len();
        let (r, mu, mu_s) = if at_start {
            (ray.r, ray.mu, ray.mu_s)
        } else {
            let (bottom, top) = (sky.model.bottom_radius_m, sky.model.top_radius_m);
            let (r_d, mu_d) = advance(ray.r, ray.mu, d, bottom, top);
            (
                r_d,
                mu_d,
                ((ray.r * ray.mu_s + d * ray.nu) / r_d).clamp(-1.0, 1.0),
            )
        };
        let at = with_channel_buffers(2 * n, |[both]| {
            let at = match self.slice.as_ref().filter(|_| at_start && ray.at_observer) {
                Some(s) => {
                    // The slice already filtered (μ_s, r): only u_ν and u_μ are needed.
                    let u_nu = params::u_nu(mu, mu_s, ray.nu);
                    let u_mu = params::scattering_u_mu(&lk.radii, &lk.sizes, r, mu, ray.ground);
                    tables.single_rayleigh.sample_slice_channels_into(
                        &s.scattering,
                        2 * n,
                        u_nu,
                        u_mu,
                        both,
                    );
                    scat.copy_from_slice(&both[..n]);
                    At::Slice(s, u_nu, u_mu)
                }
                None => {
                    let uvwz = params::scattering_uvwz(
                        &lk.radii, &lk.sizes, r, mu, mu_s, ray.nu, ray.ground,
                    );
                    // Only the tables of the orders asked for (the shafts ask for the
                    // single and the multiple scattering apart).
                    let [rayleigh, _, multiple] = sky.logs();
                    if orders != Orders::Multiple {
                        (tables.single_rayleigh).sample_logs_into(
                            uvwz,
                            &lk.blend(),
                            Some(rayleigh),
                            scat,
                        );
                    }
                    if orders != Orders::Single {
                        tables.multiple.sample_logs_into(
                            uvwz,
                            &lk.blend(),
                            Some(multiple),
                            &mut both[n..2 * n],
                        );
                    }
                    At::Table(uvwz)
                }
            };
            // Multiple scattering is stored as radiance; callers apply the molecular phase
            // function to `scat`, so it goes in divided by it.
            let p = rayleigh_phase.max(1e-30);
            for k in 0..n {
                scat[k] = match orders {
                    Orders::All => scat[k] + both[n + k] / p,
                    Orders::Single => scat[k],
                    Orders::Multiple => both[n + k] / p,
                };
            }
            at
        });
        let single_mie = &tables.single_mie;
        let sample = |out: &mut [f64]| match at {
            At::Slice(s, u_nu, u_mu) => single_mie.sample_slice_into(&s.mie, u_nu, u_mu, out),
            At::Table(uvwz) => {
                let logs = Some(&sky.logs()[1]);
                single_mie.sample_logs_into(uvwz, &self.lookup.blend(), logs, out)
            }
        };
        match (orders, tables.config.mie) {
            (Orders::Multiple, _) => mie.iter_mut().for_each(|v| *v = 0.0),
            (_, MieStorage::Separate) => sample(mie),
            (_, MieStorage::RedOnly) => {
                let mut red = [0.0];
                sample(&mut red);
                for k in 0..n {
                    mie[k] = if scat[0] > 0.0 {
                        scat[k] * red[0] / scat[0] * tables.mie_ratio[k]
                    } else {
                        0.0
                    };
                }
            }
        }
        // Below the tables' lowest sun (Bruneton 2017's μ_s,min) the lookups above read the
        // μ_s,min row; the sky there falls on from it (`twilight`: clamping gave every
        // deeper night the sky of the lowest tabulated sun, a cut to 0 a jump at μ_s,min).
        if mu_s < sky.model.mu_s_min {
            with_channel_buffers(n, |[fade]| {
                twilight::fade(lk, &tables.irradiance, r, mu_s, fade);
                for k in 0..n {
                    scat[k] *= fade[k];
                    mie[k] *= fade[k];
                }
            });
        }
    }

    /// Σ over the lit intervals [a, b] (m from the ray's start) of T(0, a)·S(a) − T(0, b)·S(b),
    /// with phase functions,
    /// into `radiance` (scaled to the light). `end` is the ray's length; an interval that
    /// reaches it subtracts nothing when `open_end` (a ray to the sky: nothing is scattered
    /// beyond the boundary). `t_end`: T(0, end) when the caller has it (else empty), saving
    /// a lookup for the interval that ends there. Single Mie is multiplied by `mie_fade`.
    /// `orders`: which of the tables' orders.
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
        let lk = &self.lookup;
        let phase = &self.sky.model.groups.phase;
        let (pr, pm) = (phase[MOLECULES].eval(ray.nu), phase[AEROSOLS].eval(ray.nu));
        radiance[..n].iter_mut().for_each(|v| *v = 0.0);
        with_channel_buffers(n, |[scat, mie, scat_b, mie_b, t]| {
            for (a, b) in intervals {
                let (a, b) = (a.max(0.0), b.min(end));
                if b <= a {
                    continue;
                }
                self.combined_scattering(ray, a, a == 0.0, pr, orders, scat, mie);
                if a > 0.0 {
                    lk.transmittance(ray.r, ray.mu, a, ray.ground, t);
                    for k in 0..n {
                        scat[k] *= t[k];
                        mie[k] *= t[k];
                    }
                }
                if b < end || !open_end {
                    self.combined_scattering(ray, b, false, pr, orders, scat_b, mie_b);
                    let t: &[f64] = if b == end && !t_end.is_empty() {
                        t_end
                    } else {
                        lk.transmittance(ray.r, ray.mu, b, ray.ground, t);
                        t
                    };
                    for k in 0..n {
                        scat[k] = (scat[k] - t[k] * scat_b[k]).max(0.0);
                        mie[k] = (mie[k] - t[k] * mie_b[k]).max(0.0);
                    }
                }
                for k in 0..n {
                    radiance[k] += scat[k] * pr + mie[k] * mie_fade * pm;
                }
            }
        });
        for (v, s) in radiance[..n].iter_mut().zip(&self.scale) {
            *v *= s;
        }
    }

    /// The radiance scattered towards the observer along `ray` up to `end` with the light
    /// reaching only the `lit` intervals: the single scattering over those, the multiple
    /// over the whole ray (the shadowed air is still lit by the sky; what the shadowing
    /// surfaces hide of the sky is `render::terrain_air`'s).
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

    /// Distance from the start along the ray to the nearest boundary (ground or top).
    fn boundary_distance(&self, ray: &RayGeometry) -> f64 {
        let m = &self.sky.model;
        crate::math::sphere::distance_to_nearest_atmosphere_boundary(
            ray.r,
            ray.mu,
            m.bottom_radius_m,
            m.top_radius_m,
            ray.ground,
        )
    }
}

impl SkyView for Bruneton4dView<'_> {
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
        // An empty `transmittance` asks for radiance only (saves a lookup per sky pixel).
        if transmittance.is_empty() {
        } else if ray.ground {
            transmittance[..n].iter_mut().for_each(|v| *v = 0.0);
        } else {
            self.lookup
                .transmittance_to_top(ray.r, ray.mu, transmittance);
        }
        let end = f64::INFINITY;
        match shadow {
            Shadow::Length(l) if l > 0.0 => {
                self.lit_radiance(&ray, [(l, end)], end, true, &[], 1.0, Orders::All, radiance)
            }
            Shadow::Lit(intervals) => {
                // A camera in space starts where the ray enters the top.
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
            .transmittance(ray.r, ray.mu, d_total, ray.ground, transmittance);
        let t = &transmittance[..n];
        // Bruneton 2017: fade single Mie when the light is below the horizon (table
        // artefacts).
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
        let irradiance = &self.sky.tables.irradiance;
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

impl Slice {
    fn new(sky: &Bruneton4d, lookup: &Lookup, r: f64, mu_s: f64) -> Slice {
        let tables = &sky.tables;
        let uvwz = params::scattering_uvwz(&lookup.radii, &lookup.sizes, r, 0.0, mu_s, 0.0, false);
        let n = sky.channels();
        let [rayleigh, mie, multiple] = sky.logs().each_ref().map(Some);
        let (u_mu_s, u_r, blend) = (uvwz[1], uvwz[3], &lookup.blend());
        let single = tables.single_rayleigh.slice(u_mu_s, u_r, blend, rayleigh);
        let multiple = tables.multiple.slice(u_mu_s, u_r, blend, multiple);
        let mut scattering = Vec::with_capacity(2 * single.len());
        for (a, b) in single.chunks(n).zip(multiple.chunks(n)) {
            scattering.extend_from_slice(a);
            scattering.extend_from_slice(b);
        }
        Slice {
            scattering,
            mie: tables.single_mie.slice(u_mu_s, u_r, blend, mie),
        }
    }
}
