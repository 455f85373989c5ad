//! The ray march of Hillaire 2020 (§4, eq. 1–5 and the released demo's
//! `IntegrateScatteredLuminance`): along a ray, at samples spread quadratically from its
//! start, the light scattered once from the sun (its transmittance from the transmittance
//! table, the planet's shadow included) and the multiple scattering σ_s·Ψ_ms (the
//! isotropic multiple-scattering table, eq. 10), each step integrated analytically over
//! its length with the sample's extinction, ∫₀^Δ S·e^{−σ_t t} dt = (S − S·e^{−σ_t Δ})/σ_t
//! (Hillaire 2015/2016's energy-conserving step), times the throughput so far.
//!
//! Everything is per unit irradiance of the light at the top of the atmosphere, per channel
//! of the model's wavelength grid: radiance W·m⁻²·sr⁻¹·nm⁻¹ per W·m⁻²·nm⁻¹.

use crate::atmosphere::density_table::{DensityTable, DENSITY_SAMPLES};
use crate::atmosphere::groups::ScatteringGroups;
use crate::atmosphere::Model;
use crate::medium::PhaseFunction;
use crate::sky::bruneton4d::Lookup;
use crate::spectrum::with_channel_buffers;

use super::harmonics;
use super::lanes::{Lane, LightLanes, LANES};
use super::multiple_scattering::MultipleScattering;
use super::params::altitude_mu_s_uv;
use super::step_lanes::StepLanes;

/// The extinction and scattering of the air at an altitude, per constituent: what the
/// march reads at each sample.
pub(crate) struct Medium<'a> {
    pub model: &'a Model,
    /// Whether each constituent scatters (absorbers do not).
    scatters: Vec<bool>,
    /// The constituents' densities by altitude (within 1.3e-5 of the profiles).
    densities: DensityTable,
}

impl<'a> Medium<'a> {
    pub fn new(model: &'a Model) -> Medium<'a> {
        let scatters = model
            .constituents
            .iter()
            .map(|c| ScatteringGroups::group_of(c).is_some())
            .collect();
        Medium {
            model,
            scatters,
            densities: DensityTable::new(model, DENSITY_SAMPLES),
        }
    }

    /// The constituents' densities tabulated by altitude.
    pub fn density_table(&self) -> &DensityTable {
        &self.densities
    }

    /// At `altitude_m`: the extinction σ_t (m⁻¹) into `sigma_t`, the scattering σ_s (m⁻¹)
    /// into `sigma_s`, each constituent's density into `densities`.
    #[inline]
    pub fn coefficients(
        &self,
        altitude_m: f64,
        sigma_t: &mut [f64],
        sigma_s: &mut [f64],
        densities: &mut [f64],
    ) {
        sigma_t.iter_mut().for_each(|v| *v = 0.0);
        sigma_s.iter_mut().for_each(|v| *v = 0.0);
        let n = sigma_t.len();
        self.densities.densities(altitude_m, densities);
        for (i, c) in self.model.constituents.iter().enumerate() {
            let rho = densities[i];
            if rho <= 0.0 {
                continue;
            }
            for k in 0..n {
                sigma_t[k] += rho * c.extinction[k];
            }
            if self.scatters[i] {
                for k in 0..n {
                    sigma_s[k] += rho * c.scattering[k];
                }
            }
        }
    }

    /// Σ_c ρ_c·β_c·p_c into `phased` (overwritten) for the constituents' `densities` where
    /// `phases[c]` is constituent c's phase function at the ray's scattering angle (0 when
    /// `phases` is empty: no single scattering).
    #[inline]
    pub fn phased(&self, densities: &[f64], phases: &[f64], phased: &mut [f64]) {
        phased.iter_mut().for_each(|v| *v = 0.0);
        if phases.is_empty() {
            return;
        }
        for (i, c) in self.model.constituents.iter().enumerate() {
            if densities[i] <= 0.0 || !self.scatters[i] {
                continue;
            }
            let w = densities[i] * phases[i];
            for (p, b) in phased.iter_mut().zip(&c.scattering) {
                *p += w * b;
            }
        }
    }

    /// Whether constituent `i` scatters.
    #[inline]
    pub fn scatters(&self, i: usize) -> bool {
        self.scatters[i]
    }

    /// Each constituent's phase function at the scattering angle cosine `nu`, into `out`.
    pub fn phases(&self, nu: f64, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.model.constituents.iter().map(|c| c.phase.eval(nu)));
    }

    /// The isotropic phase 1/(4π) for every constituent (Hillaire's multiple-scattering
    /// pass, eq. 6–7).
    pub fn isotropic_phases(&self, out: &mut Vec<f64>) {
        out.clear();
        let p = PhaseFunction::Isotropic.eval(1.0);
        out.extend(self.model.constituents.iter().map(|_| p));
    }
}

/// A ray in the atmosphere: its start's radius r (m), the zenith cosines μ of its direction
/// and μ_s of the light there, ν = cos(view, light), and its length (m) to the boundary it
/// ends on (or to the point it is marched to).
#[derive(Clone, Copy, Debug)]
pub(crate) struct MarchRay {
    pub r: f64,
    pub mu: f64,
    pub mu_s: f64,
    pub nu: f64,
    pub length: f64,
}

impl MarchRay {
    /// The radius and the light's zenith cosine `t` metres along the ray.
    #[inline]
    pub fn at(&self, t: f64) -> (f64, f64) {
        let r_t = (t * t + 2.0 * self.r * self.mu * t + self.r * self.r)
            .max(0.0)
            .sqrt();
        let mu_s_t = ((self.r * self.mu_s + t * self.nu) / r_t.max(1.0)).clamp(-1.0, 1.0);
        (r_t, mu_s_t)
    }
}

/// Which parts of a ray a term is lit over: all of it, or the given increasing, disjoint
/// intervals (m from the ray's start).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Lit<'a> {
    All,
    Intervals(&'a [(f64, f64)]),
}

impl Lit<'_> {
    /// The fraction of [a, b] that is lit.
    #[inline]
    fn fraction(&self, a: f64, b: f64) -> f64 {
        match self {
            Lit::All => 1.0,
            Lit::Intervals(list) => {
                if b <= a {
                    return 0.0;
                }
                let covered: f64 = list
                    .iter()
                    .map(|&(s, e)| (e.min(b) - s.max(a)).max(0.0))
                    .sum();
                (covered / (b - a)).min(1.0)
            }
        }
    }
}

/// What lights the march: the single scattering's and the multiple scattering's lit parts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lighting<'a> {
    pub single: Lit<'a>,
    pub multiple: Lit<'a>,
}

impl Lighting<'_> {
    pub const ALL: Lighting<'static> = Lighting {
        single: Lit::All,
        multiple: Lit::All,
    };
}

/// The tables a march reads: transmittance (through `lookup`) and the multiple-scattering
/// field (None: no multiple-scattering term, the multiple-scattering pass itself), and the
/// same in f32 lanes for the fully lit marches ([`LightLanes`]; None for a harmonic field).
pub(crate) struct Marcher<'a> {
    pub medium: Medium<'a>,
    pub lookup: Lookup<'a>,
    pub multiple: Option<&'a MultipleScattering>,
    pub(super) lanes: Option<LightLanes>,
}

impl<'a> Marcher<'a> {
    /// The march over `lookup`'s transmittance and `multiple`'s field.
    pub fn new(
        medium: Medium<'a>,
        lookup: Lookup<'a>,
        multiple: Option<&'a MultipleScattering>,
    ) -> Marcher<'a> {
        let lanes = LightLanes::new(&medium, &lookup, multiple);
        Marcher {
            medium,
            lookup,
            multiple,
            lanes,
        }
    }

    /// This march without its lanes: every march on the general path (for comparing them).
    #[cfg(test)]
    pub fn without_lanes(mut self) -> Marcher<'a> {
        self.lanes = None;
        self
    }
}

/// The distance (m) from the start to the far end of step `i` of `steps` over `length`:
/// quadratic, dense near the start where a view ray from the ground meets its densest air
/// (Hillaire 2020 §5.3 and the demo's non-linear sample distribution).
#[inline]
pub(crate) fn step_end(i: usize, steps: usize, length: f64) -> f64 {
    let f = i as f64 / steps as f64;
    length * f * f
}

/// The part of a march that depends only on the ray's geometry (its start's radius, its
/// zenith cosine and its step ends), not on the light: per step the radius at its middle,
/// the constituents' densities there, the throughput before it and its analytic length
/// (1 − e^{−σ_t Δ})/σ_t per channel. Rays that differ only in the light's direction (a row
/// of the sky-view table, one gather direction's μ at one altitude for every μ_s of the
/// multiple-scattering and irradiance tables) share one: the densities and exponentials
/// are paid once, and each light pays only its lookups.
#[derive(Default)]
pub(crate) struct RayProfile {
    /// Per step: its start and end (m from the ray's start), its middle and the radius
    /// there (m).
    pub(super) steps: Vec<[f64; 4]>,
    /// Per step, each constituent's density at its middle.
    pub(super) densities: Vec<f64>,
    /// Per step and channel: the throughput before the step.
    pub(super) throughput: Vec<f64>,
    /// Per step and channel: the step's analytic length (m).
    pub(super) lengths: Vec<f64>,
    /// The ray's throughput per channel.
    pub transmittance: Vec<f64>,
    /// ∫ T·σ_s dt along the ray per channel (Hillaire's eq. 8 integrand before its phase
    /// function: what f_ms sums).
    pub scattered: Vec<f64>,
    /// The steps for the lanes' march, when the marcher has lanes ([`LightLanes`]).
    pub(super) lanes: StepLanes,
}

impl RayProfile {
    /// The ray's transmittance into `transmittance`, and ∫T·σ_s into `scattered` unless it
    /// is empty.
    fn copy_totals(&self, transmittance: &mut [f64], scattered: &mut [f64]) {
        transmittance.copy_from_slice(&self.transmittance);
        if !scattered.is_empty() {
            scattered.copy_from_slice(&self.scattered);
        }
    }
}

thread_local! {
    /// The profile [`Marcher::march`] and [`Marcher::march_over`] reuse on each thread.
    static SCRATCH: std::cell::RefCell<RayProfile> = std::cell::RefCell::default();
}

impl Marcher<'_> {
    /// The geometry-only part of a march of `ray` (its `r`, `mu` and `length`; the light's
    /// fields are not read) over the steps ending at `ends` (m from the ray's start,
    /// increasing, up to `ray.length`; no steps when that is not positive), into `p`.
    pub fn profile_into(
        &self,
        ray: &MarchRay,
        ends: impl Iterator<Item = f64>,
        p: &mut RayProfile,
    ) {
        let model = self.medium.model;
        let n = model.channels();
        p.steps.clear();
        p.densities.clear();
        p.throughput.clear();
        p.lengths.clear();
        p.transmittance.clear();
        p.transmittance.resize(n, 1.0);
        p.scattered.clear();
        p.scattered.resize(n, 0.0);
        if ray.length <= 0.0 {
            if let Some(lanes) = &self.lanes {
                lanes.fill_steps(p, self.lookup.sun_angular_radius);
            }
            return;
        }
        // Each vector once to its size (a profile's dozen vectors grown step by step were a
        // tenth of a table build in the allocator).
        let steps = ends.size_hint().0;
        let constituents = model.constituents.len();
        p.steps.reserve(steps);
        p.densities.reserve(steps * constituents);
        p.throughput.reserve(steps * n);
        p.lengths.reserve(steps * n);
        let bottom = model.bottom_radius_m;
        let mut densities = [0.0; 8];
        let mut densities_vec;
        let densities: &mut [f64] = if model.constituents.len() <= densities.len() {
            &mut densities[..model.constituents.len()]
        } else {
            densities_vec = vec![0.0; model.constituents.len()];
            &mut densities_vec
        };
        with_channel_buffers(n, |[sigma_t, sigma_s]| {
            let mut t0 = 0.0;
            for t1 in ends {
                let dt = t1 - t0;
                let t_mid = 0.5 * (t0 + t1);
                let (r_t, _) = ray.at(t_mid);
                self.medium
                    .coefficients(r_t - bottom, sigma_t, sigma_s, densities);
                p.steps.push([t0, t1, t_mid, r_t]);
                p.densities.extend_from_slice(densities);
                for k in 0..n {
                    let tau = sigma_t[k] * dt;
                    let step_t = (-tau).exp();
                    // (S − S·e^{−σ_t Δ})/σ_t, → S·Δ as σ_t → 0.
                    let length = if tau > 1e-9 {
                        (1.0 - step_t) / sigma_t[k]
                    } else {
                        dt
                    };
                    let before = p.transmittance[k];
                    p.throughput.push(before);
                    p.lengths.push(length);
                    p.scattered[k] += before * sigma_s[k] * length;
                    p.transmittance[k] = before * step_t;
                }
                t0 = t1;
            }
        });
        if let Some(lanes) = &self.lanes {
            lanes.fill_steps(p, self.lookup.sun_angular_radius);
        }
    }

    /// [`Marcher::profile_into`] of the `steps` quadratic steps of [`step_end`].
    pub fn profile_steps_into(&self, ray: &MarchRay, steps: usize, p: &mut RayProfile) {
        self.profile_into(ray, (1..=steps).map(|i| step_end(i, steps, ray.length)), p);
    }

    /// Σ over the ray's steps of the throughput so far times the step's analytic integral,
    /// into `radiance` (per unit light irradiance), and the ray's throughput into
    /// `transmittance` (both per channel, overwritten). `phases` holds each constituent's
    /// phase function at the ray's ν (see [`Medium::phases`]). `scattered`, when not
    /// empty, receives ∫ T·σ_s dt along the ray (Hillaire's eq. 8 integrand before its
    /// phase function: what f_ms sums).
    #[allow(clippy::too_many_arguments)]
    pub fn march(
        &self,
        ray: &MarchRay,
        steps: usize,
        phases: &[f64],
        lighting: &Lighting,
        radiance: &mut [f64],
        transmittance: &mut [f64],
        scattered: &mut [f64],
    ) {
        SCRATCH.with(|cell| {
            let mut profile = cell.borrow_mut();
            self.profile_steps_into(ray, steps, &mut profile);
            self.march_profile(ray, &profile, phases, lighting, radiance);
            profile.copy_totals(transmittance, scattered);
        });
    }

    /// [`Marcher::march`] over the steps ending at `ends` (m from the ray's start,
    /// increasing, up to `ray.length`; nothing when that is not positive), calling
    /// `at_end(i, radiance)` after step i with the radiance so far (the aerial-perspective
    /// volume's slices along one ray).
    #[allow(clippy::too_many_arguments)]
    pub fn march_over(
        &self,
        ray: &MarchRay,
        ends: impl Iterator<Item = f64>,
        phases: &[f64],
        lighting: &Lighting,
        radiance: &mut [f64],
        transmittance: &mut [f64],
        scattered: &mut [f64],
        at_end: impl FnMut(usize, &[f64]),
    ) {
        SCRATCH.with(|cell| {
            let mut profile = cell.borrow_mut();
            self.profile_into(ray, ends, &mut profile);
            self.march_profile_each(ray, &profile, phases, lighting, radiance, at_end);
            profile.copy_totals(transmittance, scattered);
        });
    }

    /// The light's part of a march: Σ over `profile`'s steps (marched along `ray`, whose
    /// `mu_s` and `nu` give the light) of the throughput so far times the step's analytic
    /// integral of the light scattered once (`phases`: each constituent's phase function
    /// at ν, none for no single scattering) and the multiple scattering, into `radiance`
    /// (overwritten).
    pub fn march_profile(
        &self,
        ray: &MarchRay,
        profile: &RayProfile,
        phases: &[f64],
        lighting: &Lighting,
        radiance: &mut [f64],
    ) {
        self.march_profile_with::<false>(ray, profile, phases, lighting, radiance, |_, _| {});
    }

    /// [`Marcher::march_profile`], calling `at_end(i, radiance)` after step i with the
    /// radiance so far.
    pub fn march_profile_each(
        &self,
        ray: &MarchRay,
        profile: &RayProfile,
        phases: &[f64],
        lighting: &Lighting,
        radiance: &mut [f64],
        at_end: impl FnMut(usize, &[f64]),
    ) {
        self.march_profile_with::<true>(ray, profile, phases, lighting, radiance, at_end);
    }

    /// The march, `at_end` called after each step when `EACH`.
    fn march_profile_with<const EACH: bool>(
        &self,
        ray: &MarchRay,
        profile: &RayProfile,
        phases: &[f64],
        lighting: &Lighting,
        radiance: &mut [f64],
        mut at_end: impl FnMut(usize, &[f64]),
    ) {
        if let (Some(lanes), Lit::All, Lit::All) = (&self.lanes, lighting.single, lighting.multiple)
        {
            // Fully lit: the lanes' march (the same sums; lanes.rs).
            let mut p = [0.0f32; 16];
            let p = if phases.len() <= p.len() {
                for (q, v) in p.iter_mut().zip(phases) {
                    *q = *v as f32;
                }
                &p[..phases.len()]
            } else {
                return self
                    .march_profile_general(ray, profile, phases, lighting, radiance, at_end);
            };
            let mut acc = [[0.0f32; LANES]; crate::spectrum::MAX_CHANNELS / LANES];
            let acc = &mut acc[..lanes.groups()];
            let mut step_radiance = |i: usize, acc: &[Lane]| {
                if EACH {
                    lanes.unpack(acc, radiance);
                    at_end(i, radiance);
                }
            };
            lanes.march(
                &profile.lanes,
                ray.r * ray.mu_s,
                ray.nu,
                p,
                acc,
                &mut step_radiance,
            );
            lanes.unpack(acc, radiance);
            return;
        }
        self.march_profile_general(ray, profile, phases, lighting, radiance, at_end);
    }

    /// [`Marcher::march_profile`] step by step in f64, for any field and lighting.
    fn march_profile_general(
        &self,
        ray: &MarchRay,
        profile: &RayProfile,
        phases: &[f64],
        lighting: &Lighting,
        radiance: &mut [f64],
        mut at_end: impl FnMut(usize, &[f64]),
    ) {
        let n = radiance.len();
        let model = self.medium.model;
        let constituents = model.constituents.len();
        let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
        radiance.iter_mut().for_each(|v| *v = 0.0);
        // The multiple-scattering field's coefficients at a step, and its harmonics there.
        let (coefficients, degree) = match self.multiple {
            Some(ms) => (harmonics::coefficient_count(ms.degree), ms.degree),
            None => (0, 0),
        };
        let mut field = vec![0.0; coefficients * n];
        let mut y = vec![0.0; coefficients];
        with_channel_buffers(n, |[phased, t_sun, psi, by_degree]| {
            for (i, &[t0, t1, t_mid, r_t]) in profile.steps.iter().enumerate() {
                let densities = &profile.densities[i * constituents..(i + 1) * constituents];
                let mu_s_t = ((ray.r * ray.mu_s + t_mid * ray.nu) / r_t.max(1.0)).clamp(-1.0, 1.0);
                self.medium.phased(densities, phases, phased);
                let lit_single = lighting.single.fraction(t0, t1);
                let lit_multiple = lighting.multiple.fraction(t0, t1);
                if lit_single > 0.0 {
                    self.lookup.transmittance_to_sun(r_t, mu_s_t, t_sun);
                } else {
                    t_sun.iter_mut().for_each(|v| *v = 0.0);
                }
                psi.iter_mut().for_each(|v| *v = 0.0);
                if let Some(ms) = self.multiple.filter(|_| lit_multiple > 0.0) {
                    let table = &ms.table;
                    let (u, v) =
                        altitude_mu_s_uv(r_t, bottom, top, mu_s_t, table.width, table.height);
                    table.sample_into(u, v, &mut field);
                    if degree == 0 {
                        y[0] = harmonics::Y00;
                    } else {
                        // The ray's direction in the step's frame (its zenith, its azimuth
                        // from the light's), where the field's harmonics are expressed.
                        let mu_v = ((ray.r * ray.mu + t_mid) / r_t.max(1.0)).clamp(-1.0, 1.0);
                        let sines = ((1.0 - mu_v * mu_v) * (1.0 - mu_s_t * mu_s_t))
                            .max(0.0)
                            .sqrt();
                        let cos_phi = if sines > 1e-12 {
                            ((ray.nu - mu_v * mu_s_t) / sines).clamp(-1.0, 1.0)
                        } else {
                            1.0
                        };
                        harmonics::eval(degree, mu_v, cos_phi, &mut y);
                    }
                    // Σ_c ρ_c β_c Σ_ℓ k_ℓ^c Σ_m Y_ℓm c_ℓm: each constituent's phase function
                    // applied to the field degree by degree (Funk–Hecke).
                    for l in 0..=degree {
                        by_degree.iter_mut().for_each(|v| *v = 0.0);
                        for m in 0..=l {
                            let c = harmonics::index(l, m);
                            let (yc, row) = (y[c], &field[c * n..(c + 1) * n]);
                            for k in 0..n {
                                by_degree[k] += yc * row[k];
                            }
                        }
                        for (ci, con) in model.constituents.iter().enumerate() {
                            let Some(&k_l) = ms.moments[ci].get(l) else {
                                continue;
                            };
                            let w = densities[ci] * k_l;
                            if w == 0.0 || !self.medium.scatters(ci) {
                                continue;
                            }
                            for k in 0..n {
                                psi[k] += w * con.scattering[k] * by_degree[k];
                            }
                        }
                    }
                }
                let (throughput, lengths) = (
                    &profile.throughput[i * n..(i + 1) * n],
                    &profile.lengths[i * n..(i + 1) * n],
                );
                for k in 0..n {
                    let source = lit_single * phased[k] * t_sun[k] + lit_multiple * psi[k];
                    radiance[k] += throughput[k] * source * lengths[k];
                }
                at_end(i, radiance);
            }
        });
    }
}
