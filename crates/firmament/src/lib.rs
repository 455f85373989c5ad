//! firmament: a physically based sky and atmosphere renderer.
//!
//! Data flows one way: [`atmosphere::Atmosphere`] (parameters, TOML, presets) is resolved
//! for a wavelength grid into a [`atmosphere::Model`], from which [`lut`] precomputes
//! Bruneton & Neyret (2008) tables, which [`sky`] evaluates.

pub mod atmosphere;
pub mod error;
pub mod geometry;
pub mod io;
pub mod lut;
pub mod medium;
pub mod reference;
pub mod render;
pub mod sky;
pub mod spectrum;

pub use error::{Error, Result};
