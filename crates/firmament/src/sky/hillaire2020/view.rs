//! [`Hillaire2020`] seen from one observer under one light: the sky-view table when the
//! observer is inside the atmosphere and the view is for a frame ([`Hillaire2020View::new`]),
//! and the ray march for everything else (views from space, rays with shafts, aerial
//! perspective to a point, probe views at points of the air; Hillaire 2020 §5.3 marches per
//! pixel from space as well).

use super::march::{Lighting, Lit, MarchRay, Marcher};
use super::{sky_view, Hillaire2020};
use crate::math::sphere::{distance_to_nearest_atmosphere_boundary, ray_intersects_ground};
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::sky::bruneton4d::Table2;
use crate::sky::entry::{enter_atmosphere, Entry};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::with_channel_buffers;

/// Hillaire 2020 prepared for one observer and one light.
pub struct Hillaire2020View<'a> {
    sky: &'a Hillaire2020,
    light: &'a Light,
    marcher: Marcher<'a>,
    observer: Vec3,
    observer_r: f64,
    /// The observer's unit up.
    up: Vec3,
    /// The sky-view table at the observer (None from space and for probe views).
    table: Option<Table2>,
}

impl<'a> Hillaire2020View<'a> {
    /// The view from `observer` under `light`; `with_table`: build the sky-view table
    /// (a frame's view) or march every ray (a probe of a few rays).
    pub fn new(
        sky: &'a Hillaire2020,
        observer: Vec3,
        light: &'a Light,
        with_table: bool,
    ) -> Hillaire2020View<'a> {
        let mut marcher = sky.marcher();
        marcher.lookup.sun_angular_radius = light.angular_radius_rad;
        let model = &sky.model;
        let observer_r = observer.length().max(model.bottom_radius_m);
        let up = observer.normalize_or_zero();
        let up = if up == Vec3::ZERO { Vec3::Z } else { up };
        let table = (with_table && observer_r <= model.top_radius_m).then(|| {
            let mu_s = up.dot(light.direction).clamp(-1.0, 1.0);
            let (w, h) = sky.config.sky_view;
            sky_view::compute(&marcher, observer_r, mu_s, w, h, sky.config.sky_view_steps)
        });
        Hillaire2020View {
            sky,
            light,
            marcher,
            observer,
            observer_r,
            up,
            table,
        }
    }

    fn channels(&self) -> usize {
        self.sky.model.channels()
    }

    fn start(&self, dir: Vec3) -> Option<Entry> {
        enter_atmosphere(
            self.observer,
            self.observer_r,
            dir,
            self.sky.model.top_radius_m,
        )
    }

    /// The march of `dir` from `start` over `length` (m; to its boundary when None), lit as
    /// `lighting`, into `radiance` scaled to the light.
    fn march(
        &self,
        start: &Entry,
        dir: Vec3,
        length: Option<f64>,
        lighting: &Lighting,
        radiance: &mut [f64],
    ) {
        let model = &self.sky.model;
        let n = self.channels();
        let mu = start.mu();
        let length = length.unwrap_or_else(|| {
            let ground = ray_intersects_ground(start.r, mu, model.bottom_radius_m);
            distance_to_nearest_atmosphere_boundary(
                start.r,
                mu,
                model.bottom_radius_m,
                model.top_radius_m,
                ground,
            )
        });
        let ray = self.march_ray(start, dir, length);
        self.with_phases(ray.nu, |phases| {
            with_channel_buffers(n, |[t]| {
                let steps = self.sky.config.march_steps;
                self.marcher.march(
                    &ray,
                    steps,
                    phases,
                    lighting,
                    &mut radiance[..n],
                    t,
                    &mut [],
                );
            })
        });
        for (v, e) in radiance[..n].iter_mut().zip(&self.light.irradiance) {
            *v *= e;
        }
    }

    /// The march ray of `dir` from `start` over `length` (m).
    fn march_ray(&self, start: &Entry, dir: Vec3, length: f64) -> MarchRay {
        MarchRay {
            r: start.r,
            mu: start.mu(),
            mu_s: (start.point.dot(self.light.direction) / start.r).clamp(-1.0, 1.0),
            nu: dir.dot(self.light.direction).clamp(-1.0, 1.0),
            length,
        }
    }

    /// `f` of each constituent's phase function at the scattering angle cosine `nu`.
    fn with_phases<R>(&self, nu: f64, f: impl FnOnce(&[f64]) -> R) -> R {
        let constituents = &self.sky.model.constituents;
        let mut phases = [0.0; 16];
        if constituents.len() <= phases.len() {
            for (p, c) in phases.iter_mut().zip(constituents) {
                *p = c.phase.eval(nu);
            }
            f(&phases[..constituents.len()])
        } else {
            let mut spill = Vec::new();
            self.marcher.medium.phases(nu, &mut spill);
            f(&spill)
        }
    }
}

/// Steps per interval between consecutive points of [`SkyView::sky_radiance_along`]'s
/// column march (uniform within each; the aerial-perspective volume's quadratic slices
/// make the steps denser near the camera, as the per-point march's are). With one, the 32
/// steps of a 32-slice column are within a mean 0.014 %, worst 0.15 % of a 600-step march
/// to each point, where 30 steps per point are within 0.009 % / 0.23 %
/// (`tests/hillaire2020.rs`), for a 30th of the steps. Two steps per slice (0.006 % /
/// 0.09 %) cost the volume 40 % more time (5.9 against 4.2 ms, BENCHMARKS.md) for an error
/// far below the volume's own (0.4 % mean against per-pixel aerial perspective).
pub const COLUMN_STEPS_PER_POINT: usize = 1;

/// The longest step (m) of that column march: an interval longer than this takes more
/// steps (the volume's 32 slices over 32 km are at most 2 km wide and take one each; a
/// column's few points far apart are marched as finely as its slices).
pub const COLUMN_STEP_MAX_M: f64 = 2_000.0;

/// The lit intervals of `shadow` shifted by `offset` (m: from the observer to the ray's
/// start), into `buffer`.
fn shifted<'b>(
    intervals: &[(f64, f64)],
    offset: f64,
    buffer: &'b mut Vec<(f64, f64)>,
) -> &'b [(f64, f64)] {
    buffer.clear();
    buffer.extend(intervals.iter().map(|&(a, b)| (a - offset, b - offset)));
    buffer
}

impl SkyView for Hillaire2020View<'_> {
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
        let model = &self.sky.model;
        let Some(start) = self.start(dir) else {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance.iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        let mu = start.mu();
        let ground = ray_intersects_ground(start.r, mu, model.bottom_radius_m);
        if !transmittance.is_empty() {
            if ground {
                transmittance[..n].iter_mut().for_each(|v| *v = 0.0);
            } else {
                self.marcher
                    .lookup
                    .transmittance_to_top(start.r, mu, &mut transmittance[..n]);
            }
        }
        let mut buffer = Vec::new();
        match (shadow, &self.table) {
            (Shadow::None, Some(table)) => {
                // The azimuth from the light in the observer's horizontal plane.
                let light = self.light.direction;
                let (d, s) = (dir - self.up * mu, light - self.up * self.up.dot(light));
                let norm = (d.length_squared() * s.length_squared()).sqrt();
                let cos_phi = if norm > 1e-24 { d.dot(s) / norm } else { 1.0 };
                sky_view::sample(
                    table,
                    start.r,
                    model.bottom_radius_m,
                    mu,
                    cos_phi,
                    &mut radiance[..n],
                );
                for (v, e) in radiance[..n].iter_mut().zip(&self.light.irradiance) {
                    *v *= e;
                }
            }
            (Shadow::None, None) => self.march(&start, dir, None, &Lighting::ALL, radiance),
            (Shadow::Length(l), _) => {
                // The paper's shadow over the ray's first metres: nothing scattered there.
                let lit = [(l.max(0.0) - start.offset_m(self.observer), f64::INFINITY)];
                let lighting = Lighting {
                    single: Lit::Intervals(&lit),
                    multiple: Lit::Intervals(&lit),
                };
                self.march(&start, dir, None, &lighting, radiance)
            }
            (Shadow::Lit(intervals), _) => {
                let lit = shifted(intervals, start.offset_m(self.observer), &mut buffer);
                let lighting = Lighting {
                    single: Lit::Intervals(lit),
                    multiple: Lit::All,
                };
                self.march(&start, dir, None, &lighting, radiance)
            }
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
        let d = start.distance_to(self.observer, point);
        if d <= 0.0 {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance[..n].iter_mut().for_each(|v| *v = 1.0);
            return;
        }
        let mu = start.mu();
        let ground = ray_intersects_ground(start.r, mu, self.sky.model.bottom_radius_m);
        self.marcher
            .lookup
            .transmittance(start.r, mu, d, ground, &mut transmittance[..n]);
        let mut buffer = Vec::new();
        let lit_length;
        let lighting = match shadow {
            Shadow::None => Lighting::ALL,
            Shadow::Length(l) => {
                // The paper's shadow over the ray's last metres.
                lit_length = [(0.0, d - l.max(0.0))];
                Lighting {
                    single: Lit::Intervals(&lit_length),
                    multiple: Lit::Intervals(&lit_length),
                }
            }
            Shadow::Lit(intervals) => Lighting {
                single: Lit::Intervals(shifted(
                    intervals,
                    start.offset_m(self.observer),
                    &mut buffer,
                )),
                multiple: Lit::All,
            },
        };
        self.march(&start, dir, Some(d), &lighting, radiance);
    }

    fn sky_radiance_along(&self, points: &[Vec3], radiance: &mut [f64], transmittance: &mut [f64]) {
        let n = self.channels();
        let model = &self.sky.model;
        let clear = |radiance: &mut [f64], transmittance: &mut [f64]| {
            radiance.iter_mut().for_each(|v| *v = 0.0);
            transmittance.iter_mut().for_each(|v| *v = 1.0);
        };
        let Some(&last) = points.last() else {
            return;
        };
        let dir = (last - self.observer).normalize_or_zero();
        let start = (dir != Vec3::ZERO).then(|| self.start(dir)).flatten();
        let Some(start) = start else {
            return clear(radiance, transmittance);
        };
        // Each point's distance from the ray's start (0 before the atmosphere's entry).
        let mut distances = Vec::with_capacity(points.len());
        let mut previous = 0.0f64;
        for &p in points {
            previous = previous.max(start.distance_to(self.observer, p));
            distances.push(previous);
        }
        if previous <= 0.0 {
            return clear(radiance, transmittance);
        }
        let mu = start.mu();
        let ground = ray_intersects_ground(start.r, mu, model.bottom_radius_m);
        self.marcher.lookup.transmittances_along(
            start.r,
            mu,
            &distances,
            ground,
            &mut transmittance[..distances.len() * n],
        );
        let ray = self.march_ray(&start, dir, previous);
        // Each interval's steps: COLUMN_STEPS_PER_POINT, more where it is longer than
        // COLUMN_STEP_MAX_M; `last_step[i]` is the step that ends at point i.
        let mut ends = Vec::with_capacity(distances.len() * COLUMN_STEPS_PER_POINT);
        let mut last_step = Vec::with_capacity(distances.len());
        let mut from = 0.0;
        for &d in &distances {
            let k = COLUMN_STEPS_PER_POINT.max(((d - from) / COLUMN_STEP_MAX_M).ceil() as usize);
            ends.extend((1..=k).map(|j| from + (d - from) * j as f64 / k as f64));
            last_step.push(ends.len() - 1);
            from = d;
        }
        let mut next = 0;
        let irradiance = &self.light.irradiance;
        self.with_phases(ray.nu, |phases| {
            with_channel_buffers(n, |[l, t]| {
                self.marcher.march_over(
                    &ray,
                    ends.into_iter(),
                    phases,
                    &Lighting::ALL,
                    l,
                    t,
                    &mut [],
                    |step, so_far| {
                        // Points at one distance share their step.
                        while next < last_step.len() && last_step[next] == step {
                            let i = next;
                            for (c, o) in radiance[i * n..(i + 1) * n].iter_mut().enumerate() {
                                *o = so_far[c] * irradiance[c];
                            }
                            next += 1;
                        }
                    },
                );
            })
        });
    }

    fn transmittance_to_point(&self, point: Vec3, out: &mut [f64]) {
        let dir = (point - self.observer).normalize_or_zero();
        let Some(start) = self.start(dir) else {
            out.iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        let mu = start.mu();
        let ground = ray_intersects_ground(start.r, mu, self.sky.model.bottom_radius_m);
        let d = (start.distance_to(self.observer, point)).max(0.0);
        self.marcher
            .lookup
            .transmittance(start.r, mu, d, ground, out);
    }

    fn transmittance_to_light(&self, point: Vec3, out: &mut [f64]) {
        self.marcher
            .lookup
            .transmittance_to_light(point, self.light.direction, out);
    }

    fn sun_and_sky_irradiance(
        &self,
        point: Vec3,
        normal: Vec3,
        direct: &mut [f64],
        sky: &mut [f64],
    ) {
        crate::sky::surface_irradiance::sun_and_sky_irradiance(
            &self.marcher.lookup,
            self.light,
            point,
            normal,
            |r, mu_s, out| {
                self.sky.sky_irradiance(r, mu_s, out);
                for (v, e) in out.iter_mut().zip(&self.light.irradiance) {
                    *v *= e;
                }
            },
            direct,
            sky,
        );
    }
}
