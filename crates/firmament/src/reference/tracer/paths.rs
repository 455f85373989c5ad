//! The paths: camera rays with a forced first collision, then delta tracking with
//! next-event estimation towards the sun at every collision (or, under twilight sampling,
//! along every flight: `lit`) and reflection (on the ground sphere or a surface); photons
//! from the sun for the flux budget.

use std::f64::consts::PI;

use super::geometry::{advance, cosine_direction, Frame};
use super::{
    Channel, Primary, Scratch, BUDGET_TALLIES, T_GROUND_ABSORBED, T_GROUND_DIFFUSE,
    T_GROUND_DIRECT, T_MEDIUM_ABSORBED, T_REFLECTED, T_TRUNCATED,
};
use crate::math::Vec3;
use crate::reference::rng::Rng;

impl Channel<'_> {
    /// One radiance sample (W·m⁻²·sr⁻¹·nm⁻¹) along a camera ray (the path runs from the
    /// eye towards the light). `primary_ground`: whether the ground or surface seen directly
    /// by this ray contributes its reflected light.
    ///
    /// The first collision is forced: its optical depth is drawn from the exponential
    /// distribution truncated to the ray's total τ_L (tabulated exactly at `intervals`
    /// graded nodes per monotone piece, linear in between; τ_L up to the ground, a surface
    /// or the top), with weight σ_s(t)·(1 − e^{−τ_L})/σ̄(interval); the uncollided part
    /// (probability e^{−τ_L}) is followed too when it reaches a ground or surface that
    /// counts. This removes the variance of "did the path collide at all", which dominates
    /// in thin air (zenith views, space).
    /// Through volumes the first flight is plain delta tracking.
    pub(crate) fn radiance_sample(
        &self,
        frame: &Frame,
        primary: &Primary,
        sun: Vec3,
        primary_ground: bool,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        if self.has_volumes() {
            return self.radiance_sample_with_volumes(
                frame,
                primary,
                sun,
                primary_ground,
                rng,
                scratch,
            );
        }
        let lit = self.lit();
        let mut radiance = 0.0;
        if lit {
            radiance += self.primary_estimate(frame, primary, sun, rng, scratch);
        }
        let tau_l = *primary.tau.last().unwrap();
        if tau_l > 0.0 {
            let escape = (-tau_l).exp();
            let target = -(1.0 - rng.next_f64() * (1.0 - escape)).ln();
            let i = primary
                .tau
                .partition_point(|&v| v <= target)
                .clamp(1, primary.tau.len() - 1)
                - 1;
            let dtau = primary.tau[i + 1] - primary.tau[i];
            let dt = primary.t[i + 1] - primary.t[i];
            if dtau > 0.0 && dt > 0.0 {
                let mean_sigma = dtau / dt;
                let t = (primary.t[i] + (target - primary.tau[i]) / mean_sigma)
                    .clamp(primary.t[i], primary.t[i + 1]);
                let o = advance(primary.o, t, primary.d);
                let x0 = frame.x(primary.o);
                let b = frame.b(primary.o, primary.d);
                let (_, ss) = self.coefficients(frame, o, self.alt(x0, b, t), scratch);
                if ss > 0.0 {
                    let w = ss * (1.0 - escape) / mean_sigma;
                    radiance += if lit {
                        self.after_lit_collision(frame, o, primary.d, w, ss, sun, rng, scratch)
                    } else {
                        self.after_collision(frame, o, primary.d, w, ss, sun, rng, scratch)
                    };
                }
            }
        }
        if primary_ground {
            radiance += self.primary_reflection(frame, primary, (-tau_l).exp(), sun, rng, scratch);
        }
        radiance
    }

    /// The reflection where a camera ray ends (none at the top of the atmosphere), reached
    /// uncollided with weight `w`.
    fn primary_reflection(
        &self,
        frame: &Frame,
        primary: &Primary,
        w: f64,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        let (o, d) = (primary.o, primary.d);
        match self.reflection(frame, o, d, primary.t_end, &primary.end, scratch) {
            Some((o, n, albedo)) if albedo > 0.0 => {
                self.after_reflection(frame, o, n, albedo, w, 0, sun, rng, scratch)
            }
            _ => 0.0,
        }
    }

    /// [`Channel::radiance_sample`] through the scene's volumes: the first flight by plain
    /// delta tracking (the primary ray's tabulated optical depth holds the air only).
    fn radiance_sample_with_volumes(
        &self,
        frame: &Frame,
        primary: &Primary,
        sun: Vec3,
        primary_ground: bool,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        let (o, d) = (primary.o, primary.d);
        match self.collide(frame, o, d, primary.t_end, rng, scratch) {
            Some(t) => {
                let x = advance(o, t, d);
                let h = self.alt(frame.x(o), frame.b(o, d), t);
                let (st, ss) = self.coefficients(frame, x, h, scratch);
                if st <= 0.0 || ss <= 0.0 {
                    return 0.0;
                }
                self.after_collision(frame, x, d, ss / st, ss, sun, rng, scratch)
            }
            None if primary_ground => {
                self.primary_reflection(frame, primary, 1.0, sun, rng, scratch)
            }
            None => 0.0,
        }
    }

    /// NEE at a real collision at `o` (densities in `dens`, weight `w` already including
    /// σ_s/σ_t), then the rest of the path.
    pub(super) fn after_collision(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        mut w: f64,
        ss: f64,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        let (ls, e) = self.sample_sun(sun, rng);
        let tr = self.transmittance(frame, o, ls);
        let mut radiance = if tr > 0.0 {
            w * self.phase(scratch, ss, d.dot(ls)) * tr * e
        } else {
            0.0
        };
        let events = 1;
        if events >= self.max_bounces || !self.roulette(events, &mut w, rng) {
            return radiance;
        }
        let d = self.scatter(d, scratch, ss, rng);
        radiance += self.trace(frame, o, d, w, events, sun, rng, scratch);
        radiance
    }

    /// A Lambertian reflection at `o` (on the ground or lifted off a surface) about unit
    /// normal `n` with `albedo`, incoming weight `w` after `events` events: NEE, then the
    /// rest of the path.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn after_reflection(
        &self,
        frame: &Frame,
        o: Vec3,
        n: Vec3,
        albedo: f64,
        mut w: f64,
        mut events: usize,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        events += 1;
        let (ls, e) = self.sample_sun(sun, rng);
        let cos = n.dot(ls);
        let mut radiance = 0.0;
        if cos > 0.0 {
            let tr = self.transmittance(frame, o, ls);
            radiance += w * albedo / PI * cos * tr * e;
        }
        w *= albedo;
        if events >= self.max_bounces || !self.roulette(events, &mut w, rng) {
            return radiance;
        }
        let d = cosine_direction(n, rng);
        radiance + self.trace(frame, o, d, w, events, sun, rng, scratch)
    }

    /// A real collision at `o` under twilight sampling (see `lit`): its light came with
    /// the flight's estimate, so no NEE; the rest of the path.
    #[allow(clippy::too_many_arguments)]
    fn after_lit_collision(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        mut w: f64,
        ss: f64,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        let events = 1;
        if events >= self.max_bounces || !self.roulette(events, &mut w, rng) {
            return 0.0;
        }
        let d = self.guided_scatter(frame, o, d, scratch, ss, sun, &mut w, rng);
        self.trace(frame, o, d, w, events, sun, rng, scratch)
    }

    /// The path from `o` along `d` with weight `w` after `events` events (delta tracking;
    /// under twilight sampling each flight's estimate replaces the NEE at its collision).
    pub(super) fn trace(
        &self,
        frame: &Frame,
        mut o: Vec3,
        mut d: Vec3,
        mut w: f64,
        mut events: usize,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        let lit = self.lit();
        let mut radiance = 0.0;
        loop {
            let x0 = frame.x(o);
            let b = frame.b(o, d);
            let (t_end, end) = self.flight(frame, o, d, x0, b);
            if lit {
                radiance += w * self.flight_estimate(frame, o, d, t_end, sun, rng, scratch);
            }
            if let Some(t) = self.collide(frame, o, d, t_end, rng, scratch) {
                o = advance(o, t, d);
                let h = self.alt(x0, b, t);
                let (st, ss) = self.coefficients(frame, o, h, scratch);
                if st <= 0.0 || ss <= 0.0 {
                    break;
                }
                w *= ss / st;
                events += 1;
                if !lit {
                    let (ls, e) = self.sample_sun(sun, rng);
                    let tr = self.transmittance(frame, o, ls);
                    if tr > 0.0 {
                        radiance += w * self.phase(scratch, ss, d.dot(ls)) * tr * e;
                    }
                }
                if events >= self.max_bounces || !self.roulette(events, &mut w, rng) {
                    break;
                }
                d = if lit {
                    self.guided_scatter(frame, o, d, scratch, ss, sun, &mut w, rng)
                } else {
                    self.scatter(d, scratch, ss, rng)
                };
            } else {
                let Some((p, n, albedo)) = self.reflection(frame, o, d, t_end, &end, scratch)
                else {
                    break;
                };
                if albedo <= 0.0 {
                    break;
                }
                o = p;
                events += 1;
                let (ls, e) = self.sample_sun(sun, rng);
                let cos = n.dot(ls);
                if cos > 0.0 {
                    let tr = self.transmittance(frame, o, ls);
                    radiance += w * albedo / PI * cos * tr * e;
                }
                w *= albedo;
                if events >= self.max_bounces || !self.roulette(events, &mut w, rng) {
                    break;
                }
                d = cosine_direction(n, rng);
            }
        }
        radiance
    }

    /// One photon from offset `o` (on the top of the atmosphere) along `d` (= −sun),
    /// tallied as fractions of its power: see the `T_*` indices. The planet alone: the flux
    /// budget traces no surfaces.
    pub(crate) fn budget_sample(
        &self,
        frame: &Frame,
        mut o: Vec3,
        mut d: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> [f64; BUDGET_TALLIES] {
        debug_assert!(!self.has_surfaces(), "the flux budget traces no surfaces");
        let mut tally = [0.0; BUDGET_TALLIES];
        let mut w = 1.0;
        let mut events = 0usize;
        let mut scattered = false;
        loop {
            let x0 = frame.x(o);
            let b = frame.b(o, d);
            let (t_end, ground) = self.boundary(x0, b);
            if let Some(t) = self.collide(frame, o, d, t_end, rng, scratch) {
                o = advance(o, t, d);
                let (st, ss) = self.coefficients(frame, o, self.alt(x0, b, t), scratch);
                let albedo = if st > 0.0 { ss / st } else { 0.0 };
                tally[T_MEDIUM_ABSORBED] += w * (1.0 - albedo);
                w *= albedo;
                events += 1;
                scattered = true;
                if !self.photon_goes_on(events, &mut w, &mut tally, rng) {
                    break;
                }
                d = self.scatter(d, scratch, ss, rng);
            } else {
                if !ground {
                    tally[T_REFLECTED] += w;
                    break;
                }
                o = advance(o, t_end, d);
                tally[if scattered {
                    T_GROUND_DIFFUSE
                } else {
                    T_GROUND_DIRECT
                }] += w;
                tally[T_GROUND_ABSORBED] += w * (1.0 - self.ground_albedo);
                w *= self.ground_albedo;
                events += 1;
                scattered = true;
                if !self.photon_goes_on(events, &mut w, &mut tally, rng) {
                    break;
                }
                d = cosine_direction(frame.up(o), rng);
            }
        }
        tally
    }

    /// After an event of a photon of weight `w`: false when it ends (absorbed, cut at
    /// `max_bounces` with its weight tallied as truncated, or stopped by Russian roulette).
    fn photon_goes_on(
        &self,
        events: usize,
        w: &mut f64,
        tally: &mut [f64; BUDGET_TALLIES],
        rng: &mut Rng,
    ) -> bool {
        if *w <= 0.0 {
            return false;
        }
        if events >= self.max_bounces {
            tally[T_TRUNCATED] += *w;
            return false;
        }
        self.roulette(events, w, rng)
    }
}
