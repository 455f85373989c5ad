//! Cloud types: how the density and the erosion of a layer vary with the normalised height
//! h ∈ [0, 1] inside it (0 at the base, 1 at the top). Hillaire (2016, seed "Cloud
//! distribution and density") keeps them in a cloud-type texture (red: density along the
//! height, green: erosion) indexed by the weather map's type; Schneider (2015) draws the
//! same three gradients for stratus, stratocumulus and cumulus. Here they are analytic
//! curves (products of smoothsteps), blended by the weather's type t ∈ [0, 1] (0 stratus,
//! ½ stratocumulus, 1 cumulus) in the cumuliform kinds.

use serde::{Deserialize, Serialize};

use crate::math::smoothstep;

/// The kind of a cloud layer: its profile, its noise and its defaults.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum CloudKind {
    /// Convective clouds, type blended from stratus to cumulus by the weather's type.
    Cumulus,
    /// A mid-level sheet with weak structure.
    Altostratus,
    /// High, thin ice clouds, stretched horizontally.
    Cirrus,
    /// Coverage 1, constant density, no noise: the homogeneous slab with closed forms.
    Uniform,
}

/// A bump rising over [a, b] and falling over [c, d].
#[inline(always)]
fn bump(h: f64, a: f64, b: f64, c: f64, d: f64) -> f64 {
    smoothstep(a, b, h) * (1.0 - smoothstep(c, d, h))
}

/// The three cumuliform gradients (Schneider 2015, fig. "height gradients").
fn stratus(h: f64) -> f64 {
    bump(h, 0.0, 0.08, 0.15, 0.3)
}
fn stratocumulus(h: f64) -> f64 {
    bump(h, 0.0, 0.12, 0.35, 0.6)
}
fn cumulus(h: f64) -> f64 {
    bump(h, 0.0, 0.1, 0.6, 0.95)
}

impl CloudKind {
    /// The density profile at normalised height `h` for the weather's type `t` (both in
    /// [0, 1]); in [0, 1].
    pub fn density(self, h: f64, t: f64) -> f64 {
        if !(0.0..=1.0).contains(&h) {
            return 0.0;
        }
        match self {
            CloudKind::Cumulus => {
                let t = t.clamp(0.0, 1.0);
                if t < 0.5 {
                    let w = 2.0 * t;
                    stratus(h) * (1.0 - w) + stratocumulus(h) * w
                } else {
                    let w = 2.0 * t - 1.0;
                    stratocumulus(h) * (1.0 - w) + cumulus(h) * w
                }
            }
            CloudKind::Altostratus => bump(h, 0.0, 0.25, 0.65, 1.0),
            CloudKind::Cirrus => bump(h, 0.0, 0.35, 0.55, 1.0),
            CloudKind::Uniform => 1.0,
        }
    }

    /// How strongly the erosion noise eats the shape at `h` (0: smooth, 1: fully eroded):
    /// billowy, firm bases and wispy tops for cumulus (Schneider 2015), little for the
    /// sheets, none for the uniform slab.
    pub fn erosion(self, h: f64) -> f64 {
        match self {
            CloudKind::Cumulus => 0.25 + 0.35 * h,
            CloudKind::Altostratus => 0.3,
            CloudKind::Cirrus => 0.5,
            CloudKind::Uniform => 0.0,
        }
    }

    /// The weather's type where the weather does not say (procedural maps), its mean and
    /// its spread around the mean.
    pub fn default_type(self) -> (f64, f64) {
        match self {
            CloudKind::Cumulus => (0.8, 0.2),
            _ => (0.5, 0.0),
        }
    }

    /// Horizontal stretch of the noise (horizontal scale over vertical): cirrus are long
    /// streaks, the others roughly isotropic.
    pub fn horizontal_stretch(self) -> f64 {
        match self {
            CloudKind::Cirrus => 6.0,
            CloudKind::Altostratus => 3.0,
            _ => 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_vanish_outside_the_layer_and_peak_inside() {
        for kind in [
            CloudKind::Cumulus,
            CloudKind::Altostratus,
            CloudKind::Cirrus,
        ] {
            for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
                assert_eq!(kind.density(0.0, t), 0.0);
                assert!(kind.density(1.0, t) < 1e-12);
                assert_eq!(kind.density(-0.1, t), 0.0);
                assert_eq!(kind.density(1.1, t), 0.0);
                let peak = (1..100)
                    .map(|i| kind.density(i as f64 / 100.0, t))
                    .fold(0.0, f64::max);
                assert!(peak > 0.9 && peak <= 1.0, "{kind:?} t {t}: {peak}");
            }
        }
        // Cumulus towers: taller for type 1 than for type 0.
        let top = |t: f64| {
            (0..=100)
                .rev()
                .find(|&i| CloudKind::Cumulus.density(i as f64 / 100.0, t) > 0.5)
                .unwrap()
        };
        assert!(top(1.0) > 2 * top(0.0));
        assert_eq!(CloudKind::Uniform.density(0.3, 0.0), 1.0);
    }
}
