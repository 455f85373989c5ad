//! The path tracer proper: one wavelength at a time through a [`Model`]: the channel's
//! coefficients (`Channel`), positions relative to an anchor (`geometry`), free paths by
//! delta tracking (`free_path`), deterministic optical depths (`optical_depth`), the
//! scene's volumes (`volumes`) and surfaces (`surfaces`), and the paths themselves
//! (`paths`).
//!
//! Geometry. Positions are kept as an offset `o` from an *anchor* `A` on the ground sphere
//! (|A| = R_g, below the ray's start), so that the quantity that matters, the altitude, is
//! computed without cancellation even for R_g = 1e12 m (the plane-parallel limit):
//! `x = r² − R_g² = (|A|² − R_g²) + 2A·o + |o|²` and `h = x / (r + R_g)`. Along a straight
//! ray from `o` with direction `d`, `x(t) = x₀ + 2bt + t²` with `b = (A + o)·d = rμ`.
//!
//! Free paths. Delta (Woodcock) tracking with a piecewise-constant majorant: the ray is cut
//! into chunks over which the altitude changes by at most Δh; on each chunk the majorant is
//! an upper bound of every constituent's layered density over the chunk's exact altitude
//! range (min at the closest approach to the planet centre, max at an end; each layer's
//! exponential and linear terms are monotone, so bounding them separately at the range
//! ends is safe). Δh is reduced (÷4, down to half the smallest scale height) while the
//! majorant would waste more than 0.5 null collisions on the chunk.
//!
//! Next-event estimation. At every real collision and ground bounce a direction is drawn
//! uniformly in the cone of the sun disk (angular radius from the model; radiance
//! E/Ω, times the limb-darkening law normalised to E); the transmittance towards it is
//! integrated deterministically (composite 4-point Gauss–Legendre, split at the closest
//! approach), and is 0 if the ray meets the ground (so the partial disk at sunset and the
//! planet's shadow at twilight come out right). Light that reaches the sun by phase
//! sampling is not counted (no double counting; the sun disk itself is never seen).
//!
//! Twilight sampling (`lit`, on by default without volumes): the NEE of each flight's
//! collision is replaced by one along the whole flight, its point drawn ∝ an estimate of
//! the sunlit single scattering there (a coarse table of the sun's optical depth,
//! `sun_table`, gives the shape), so the air in the planet's shadow costs nothing.
//!
//! Surfaces. Besides the analytic ground sphere (the model's albedo), a flight ends at the
//! nearest of the scene's surfaces inside the atmosphere, where the path is reflected as
//! at the ground: Lambertian with the surface's albedo about the hit's normal, NEE with
//! cos = n·l, a shadow ray that any surface blocks. See `surfaces`.

mod free_path;
pub(crate) mod geometry;
mod guide;
mod lit;
mod optical_depth;
mod paths;
mod sun_table;
mod surfaces;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod twilight_tests;
mod volumes;

use std::f64::consts::PI;
use std::sync::OnceLock;

use super::rng::Rng;
use super::ReferenceSettings;
use crate::atmosphere::{LimbDarkening, Model};
use crate::math::Vec3;
use crate::medium::{DensityProfile, PhaseFunction};
use crate::scene::light::{disk_solid_angle_weighted, limb_darkening};
use crate::scene::{Surface, SurfaceHit, Volume};
use geometry::rotate;
pub(crate) use geometry::{cosine_direction, Frame};
use lit::LitLine;
use sun_table::SunTable;

/// One constituent at one wavelength.
struct Part<'a> {
    density: &'a DensityProfile,
    phase: &'a PhaseFunction,
    extinction: f64,
    scattering: f64,
}

/// Photon-budget tallies (fractions of the incident power).
pub(crate) const BUDGET_TALLIES: usize = 6;
pub(crate) const T_REFLECTED: usize = 0;
pub(crate) const T_GROUND_ABSORBED: usize = 1;
pub(crate) const T_MEDIUM_ABSORBED: usize = 2;
pub(crate) const T_GROUND_DIRECT: usize = 3;
pub(crate) const T_GROUND_DIFFUSE: usize = 4;
pub(crate) const T_TRUNCATED: usize = 5;

/// Everything the tracer needs for one wavelength.
pub(crate) struct Channel<'a> {
    index: usize,
    bottom: f64,
    /// H (2R_g + H): x at the top of the atmosphere.
    x_top: f64,
    parts: Vec<Part<'a>>,
    ground_albedo: f64,
    solar: f64,
    one_minus_cos_alpha: f64,
    sin_alpha: f64,
    limb: LimbDarkening,
    lambda_nm: f64,
    limb_norm: f64,
    min_dh: f64,
    height: f64,
    /// r² − R_g² at the altitudes where a density profile has a kink, ascending.
    kinks_x: Vec<f64>,
    segments: usize,
    max_bounces: usize,
    roulette_after: usize,
    /// The scene's volumes (non-atmospheric media), sampled in world coordinates.
    volumes: &'a [Box<dyn Volume + 'a>],
    /// The scene's surfaces besides the planet's ground sphere (terrain, balls), met by
    /// world-space rays.
    surfaces: &'a [Box<dyn Surface + 'a>],
    /// Wavelengths of the model (the volumes' coefficients come for all at once).
    channels: usize,
    /// [`ReferenceSettings::lit_sampling`].
    lit_sampling: bool,
    /// The sun's optical depth for twilight sampling's pdfs, built on first use.
    sun_table: OnceLock<SunTable>,
}

/// Graded intervals per monotone piece of a camera ray in [`Primary`].
pub(crate) const PRIMARY_INTERVALS: usize = 128;

/// A camera ray with its cumulative optical depth at graded nodes (for one wavelength), up
/// to where it ends (`t_end` m, at `end`).
pub(crate) struct Primary {
    o: Vec3,
    d: Vec3,
    t: Vec<f64>,
    tau: Vec<f64>,
    t_end: f64,
    end: End,
    /// The distance pdf of twilight sampling along the ray (see `lit`), when built.
    lit: Option<LitLine>,
}

/// Where a flight leaves the air.
#[derive(Clone, Copy, Debug)]
pub(crate) enum End {
    /// Through the top of the atmosphere.
    Space,
    /// On the planet's ground sphere.
    Ground,
    /// On the scene's surface of this index.
    Surface(usize, SurfaceHit),
}

/// Scratch space for one path: what a collision leaves for the phase function and the
/// choice of scatterer.
pub(crate) struct Scratch {
    /// Density of each constituent at the current collision.
    pub(crate) dens: Vec<f64>,
    /// Each volume's scattering coefficient of this channel at the current collision.
    pub(crate) volume_scattering: Vec<f64>,
    /// The current collision (planet-centred), where the volumes' phase functions are read.
    pub(crate) point: Vec3,
    /// Per-channel buffers for `Volume::coefficients`.
    pub(crate) extinction: Vec<f64>,
    pub(crate) scattering: Vec<f64>,
    /// Per-channel buffer for `Surface::albedo`.
    pub(crate) albedo: Vec<f64>,
    /// A flight's distance pdf under twilight sampling.
    pub(crate) line: LitLine,
}

impl<'a> Channel<'a> {
    pub(crate) fn new(
        model: &'a Model,
        volumes: &'a [Box<dyn Volume + 'a>],
        surfaces: &'a [Box<dyn Surface + 'a>],
        k: usize,
        settings: &ReferenceSettings,
    ) -> Channel<'a> {
        let parts: Vec<Part> = model
            .constituents
            .iter()
            .filter(|c| c.extinction[k] > 0.0)
            .map(|c| Part {
                density: &c.density,
                phase: &c.phase,
                extinction: c.extinction[k],
                scattering: c.scattering[k],
            })
            .collect();
        let height = model.top_radius_m - model.bottom_radius_m;
        let mut min_scale = f64::INFINITY;
        for p in &parts {
            for l in &p.density.layers {
                if l.exp_term != 0.0 && l.scale_height_m.is_finite() {
                    min_scale = min_scale.min(l.scale_height_m);
                }
            }
        }
        let min_dh = if min_scale.is_finite() {
            0.5 * min_scale
        } else {
            height / 64.0
        }
        .clamp(height * 1e-4, height);
        let mut kinks: Vec<f64> = parts
            .iter()
            .flat_map(|p| p.density.breakpoints(height))
            .collect();
        kinks.sort_by(f64::total_cmp);
        kinks.dedup();
        let r_g = model.bottom_radius_m;
        let kinks_x = kinks.iter().map(|h| h * (2.0 * r_g + h)).collect();
        let alpha = model.sun_angular_radius_rad;
        let half = (0.5 * alpha).sin();
        let one_minus_cos_alpha = 2.0 * half * half;
        let lambda_nm = model.wavelengths.nm()[k];
        let limb = model.limb_darkening;
        // L(θ) = E·ld(μ(θ))/Ω_w; drawing uniformly in the cone (pdf 1/Ω_cone) weights a
        // sample by E·ld·Ω_cone/Ω_w.
        let limb_norm = match limb {
            LimbDarkening::None => 1.0,
            _ => 2.0 * PI * one_minus_cos_alpha / disk_solid_angle_weighted(alpha, limb, lambda_nm),
        };
        Channel {
            index: k,
            bottom: model.bottom_radius_m,
            x_top: height * (2.0 * model.bottom_radius_m + height),
            parts,
            ground_albedo: model.ground_albedo[k],
            solar: model.solar_irradiance[k],
            one_minus_cos_alpha,
            sin_alpha: alpha.sin(),
            limb,
            lambda_nm,
            limb_norm,
            min_dh,
            height,
            kinks_x,
            segments: settings.transmittance_segments.max(1),
            max_bounces: settings.max_bounces,
            roulette_after: settings.roulette_after,
            volumes,
            surfaces,
            channels: model.channels(),
            lit_sampling: settings.lit_sampling,
            sun_table: OnceLock::new(),
        }
    }

    /// The sun's optical-depth table (built on first use, shared by the threads).
    pub(super) fn sun_table(&self) -> &SunTable {
        self.sun_table.get_or_init(|| SunTable::new(self))
    }

    /// Wavelength index.
    pub(crate) fn index(&self) -> usize {
        self.index
    }

    pub(crate) fn scratch(&self) -> Scratch {
        Scratch {
            dens: vec![0.0; self.parts.len()],
            volume_scattering: vec![0.0; self.volumes.len()],
            point: Vec3::ZERO,
            extinction: vec![0.0; self.channels],
            scattering: vec![0.0; self.channels],
            albedo: vec![0.0; self.channels],
            line: LitLine::default(),
        }
    }

    /// A direction in the sun disk and its weight E·ld·Ω_cone/Ω_w (W·m⁻²·nm⁻¹).
    #[inline]
    pub(super) fn sample_sun(&self, sun: Vec3, rng: &mut Rng) -> (Vec3, f64) {
        let u1 = rng.next_f64();
        let u2 = rng.next_f64();
        let one_minus_cos = u1 * self.one_minus_cos_alpha;
        let dir = rotate(sun, 1.0 - one_minus_cos, 2.0 * PI * u2);
        let weight = match self.limb {
            LimbDarkening::None => self.solar,
            law => {
                let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
                let x = (sin_t / self.sin_alpha).min(1.0);
                let mu = (1.0 - x * x).max(0.0).sqrt();
                self.solar * limb_darkening(law, mu, self.lambda_nm) * self.limb_norm
            }
        };
        (dir, weight)
    }

    /// The coefficients at a collision at altitude `h` and offset `o`, the constituents'
    /// densities and the volumes' scattering left in `scratch`; returns (σ_t, σ_s).
    #[inline]
    pub(super) fn coefficients(
        &self,
        frame: &Frame,
        o: Vec3,
        h: f64,
        scratch: &mut Scratch,
    ) -> (f64, f64) {
        let (mut st, mut ss) = (0.0, 0.0);
        for (p, d) in self.parts.iter().zip(scratch.dens.iter_mut()) {
            *d = p.density.density(h);
            st += *d * p.extinction;
            ss += *d * p.scattering;
        }
        if !self.volumes.is_empty() {
            let (vt, vs) = self.volume_coefficients(frame.point(o), scratch);
            st += vt;
            ss += vs;
        }
        (st, ss)
    }

    /// Mixed phase function at a collision.
    #[inline]
    pub(super) fn phase(&self, scratch: &Scratch, sigma_s: f64, cos: f64) -> f64 {
        let mut p = 0.0;
        for (part, d) in self.parts.iter().zip(&scratch.dens) {
            let s = d * part.scattering;
            if s > 0.0 {
                p += s * part.phase.eval(cos);
            }
        }
        for (volume, &s) in self.volumes.iter().zip(&scratch.volume_scattering) {
            if s > 0.0 {
                p += s * volume.phase(scratch.point).eval(cos);
            }
        }
        p / sigma_s
    }

    /// New direction after scattering: constituent or volume chosen ∝ its scattering
    /// coefficient, then its phase function importance-sampled.
    #[inline]
    pub(super) fn scatter(&self, d: Vec3, scratch: &Scratch, sigma_s: f64, rng: &mut Rng) -> Vec3 {
        let mut u = rng.next_f64() * sigma_s;
        let mut chosen = None;
        let parts = self
            .parts
            .iter()
            .zip(&scratch.dens)
            .map(|(part, dd)| (part.phase, dd * part.scattering));
        let volumes = self
            .volumes
            .iter()
            .zip(&scratch.volume_scattering)
            .map(|(v, &s)| (v.phase(scratch.point), s));
        for (phase, s) in parts.chain(volumes) {
            if s > 0.0 {
                chosen = Some(phase);
                if u < s {
                    break;
                }
                u -= s;
            }
        }
        let phase = chosen.expect("a collision with σ_s > 0 has a scatterer");
        let (cos, phi) = phase.sample(rng.next_f64(), rng.next_f64());
        rotate(d, cos, phi)
    }

    /// Russian roulette: false if the path is terminated; else the weight is rescaled.
    #[inline]
    pub(super) fn roulette(&self, events: usize, w: &mut f64, rng: &mut Rng) -> bool {
        if events < self.roulette_after {
            return true;
        }
        let p = w.min(1.0);
        if p >= 1.0 {
            return true;
        }
        if p <= 0.0 || rng.next_f64() >= p {
            return false;
        }
        *w /= p;
        true
    }
}
