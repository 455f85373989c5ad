//! firmament: a physically based sky, atmosphere and cloud renderer.
//!
//! Data flows one way: an [`atmosphere::Atmosphere`] (parameters, TOML, presets) is resolved
//! for a wavelength grid into an [`atmosphere::Model`]; a sky method ([`sky::SkyMethod`],
//! e.g. the precomputed tables of [`sky::bruneton4d`]) evaluates its light transport; a
//! [`scene::Scene`] composes it with surfaces, volumes and lights; [`render`] turns the
//! scene into a [`render::Frame`] seen by a camera; [`io`] writes the files. The
//! [`reference`] path tracer computes the same quantities by Monte Carlo, to measure every
//! approximation against.

pub mod astro;
pub mod atmosphere;
pub mod error;
pub mod io;
pub mod math;
pub mod medium;
pub mod reference;
pub mod render;
pub mod scene;
pub mod sky;
pub mod spectrum;

pub use error::{Error, Result};
