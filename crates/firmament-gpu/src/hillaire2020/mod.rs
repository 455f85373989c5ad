//! Hillaire 2020 on the GPU (the twin of [`firmament::sky::hillaire2020`]): the
//! atmosphere-wide tables built by compute passes in the CPU's sizes and texel layout
//! ([`precompute`]: the optical depth by the 4D tables' transmittance pass with Hillaire's
//! segment count, Ψ_ms for the isotropic and the harmonics models, the sky irradiance),
//! kept on the device ([`GpuHillaire`]) and read back for parity
//! ([`GpuHillaireTables::read_back`]), and frames ([`GpuHillaireRenderer`]) with the
//! sky-view table of each light computed per frame and the per-pixel march for the aerial
//! perspective to the ground and for views from space, through `render/render.wgsl` with
//! `shaders/hillaire2020/view.wgsl` in place of the 4D view. Per-pass GPU times in
//! [`timing`].
//!
//! WGSL twins in `shaders/hillaire2020/`: `config` (this module's [`config`]), `params`,
//! `harmonics`, `march`, `multiple_scattering`, `irradiance`, `sky_view`, `view` (the CPU
//! files of the same names) and `scene` (the clear sky: no terrain on the GPU).
//!
//! Not on the GPU: terrains and other surfaces (a frame is the clear sky over the ground
//! sphere), light shafts from lit intervals (one shadowed length per pixel only), the
//! aerial-perspective froxel volume (`render::aerial_volume`), volumes.

pub mod config;
pub mod precompute;
mod readback;
pub mod render;
pub mod sky;
pub mod timing;

pub use precompute::{GpuHillaireTables, HillairePrecomputer, HillaireTables};
pub use render::GpuHillaireRenderer;
pub use sky::GpuHillaire;
pub use timing::{HillaireFrameTiming, HillairePassTiming};

/// The guard on f_ms in the series 1/(1 − f_ms) of the multiple-scattering pass, the CPU's.
pub use firmament::sky::hillaire2020::multiple_scattering::F_MS_GUARD;
