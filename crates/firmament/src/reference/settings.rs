//! The reference path tracer's settings.

use serde::Serialize;

use crate::{Error, Result};

/// Settings of the reference path tracer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReferenceSettings {
    /// Paths per wavelength (per pixel). ≥ 2 (the standard error needs two).
    pub samples: usize,
    /// Seed of the random streams.
    pub seed: u64,
    /// Largest number of scattering and ground-reflection events on a path (1 = single
    /// scattering only). Paths longer than this are cut, which biases the result low; with
    /// Russian roulette only conservative, very thick media get near the default 100.
    pub max_bounces: usize,
    /// Events before Russian roulette starts (survival probability = the path weight).
    pub roulette_after: usize,
    /// Whether the ground seen directly by a camera ray adds its reflected radiance
    /// (false: like `SkyView::sky_radiance`; true: whole-scene images).
    pub include_ground: bool,
    /// Gauss–Legendre segments (4 nodes each) per smooth piece of a sun ray (between the
    /// closest approach and the altitudes where a profile has a kink; half as many on the
    /// pieces away from the lowest point) for the next-event transmittance.
    pub transmittance_segments: usize,
    /// Next-event estimation along each flight rather than at its collision: the point
    /// that receives sunlight is drawn along the whole flight in proportion to an estimate
    /// of its sunlit single scattering (see `reference::tracer::lit`), so the parts of the
    /// air in the planet's shadow cost nothing. Unbiased either way; it is what makes
    /// twilight affordable. Without volumes only (with volumes the collisions' NEE is used).
    pub lit_sampling: bool,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        ReferenceSettings {
            samples: 4096,
            seed: 0,
            max_bounces: 100,
            roulette_after: 5,
            include_ground: false,
            transmittance_segments: 6,
            lit_sampling: true,
        }
    }
}

impl ReferenceSettings {
    /// Defaults with `samples` paths per wavelength.
    pub fn with_samples(samples: usize) -> Self {
        ReferenceSettings {
            samples,
            ..Default::default()
        }
    }

    /// Check the numbers (the error names the field).
    pub fn validate(&self) -> Result<()> {
        if self.samples < 2 {
            return Err(Error::invalid("samples", self.samples, "an integer ≥ 2"));
        }
        if self.max_bounces < 1 {
            return Err(Error::invalid(
                "max_bounces",
                self.max_bounces,
                "an integer ≥ 1",
            ));
        }
        if self.transmittance_segments < 1 {
            return Err(Error::invalid(
                "transmittance_segments",
                self.transmittance_segments,
                "an integer ≥ 1",
            ));
        }
        Ok(())
    }
}
