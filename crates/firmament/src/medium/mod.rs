//! Participating media: density profiles, constituents and phase functions.

pub mod constituent;
pub mod phase;
pub mod profile;

pub use constituent::{Coefficient, Constituent, ConstituentKind, ResolvedConstituent};
pub use phase::PhaseFunction;
pub use profile::{DensityLayer, DensityProfile};
