//! firmament's wgpu backend, two sky methods computed by compute shaders in the same sizes
//! and texel layout as their CPU paths, so that the two compare texel by texel: the
//! precomputed tables of Bruneton & Neyret 2008 (as refined in Bruneton 2017;
//! [`firmament::sky::bruneton4d`], sharing its table file format) and the small tables of
//! Hillaire 2020 with their per-frame sky view ([`firmament::sky::hillaire2020`];
//! [`hillaire2020`]); a third, Elek 2009 / Yusov 2013's 3D tables
//! ([`firmament::sky::elek3d`]; [`elek3d`]), uploaded from the CPU's precomputation; and
//! frames of the clear sky rendered from any of them (over a terrain from the 4D tables
//! only).
//!
//! ```no_run
//! use firmament::atmosphere::Atmosphere;
//! use firmament::sky::bruneton4d::TableConfig;
//! use firmament::spectrum::Wavelengths;
//!
//! let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
//! let ctx = firmament_gpu::GpuContext::new().unwrap();
//! println!("adapter: {}", ctx.adapter_name());
//! let tables = firmament_gpu::precompute(&ctx, &model, &TableConfig::default()).unwrap();
//! assert_eq!(tables.channels(), 3);
//! ```
//!
//! An engine hands in its own device ([`GpuContext::from_device`]), keeps the tables on it
//! ([`GpuSky::precompute`], [`GpuSky::tables`]: buffers with documented bindings), renders
//! into its own buffer or texture ([`GpuRenderer::encode`]) or samples the tables in its
//! own shaders with the sky method's WGSL module ([`shader::sky_module`]); readback is a
//! separate step ([`GpuTables::read_back`], [`GpuRenderer::read_frame`]). Hillaire 2020
//! goes the same way: [`GpuHillaire::compute`] (refusing what `Hillaire2020::compute`
//! refuses), [`GpuHillaire::tables`], [`GpuHillaireRenderer::encode`],
//! [`shader::hillaire2020_sky_module`], [`GpuHillaireTables::read_back`], with per-pass GPU
//! times ([`HillairePrecomputer::time_passes`], [`GpuHillaireRenderer::time_render`]). The
//! 3D tables: [`GpuElek3d::from_sky`], [`GpuElek3d::tables`], [`GpuElek3dRenderer::encode`],
//! [`shader::elek3d_sky_module`], [`GpuElek3dRenderer::time_render`].
//!
//! Shaders are WGSL under `shaders/`: `common/` (types, bindings, profiles, phase functions,
//! geometry), `bruneton4d/` (parameterisations, filters, lookups, `view.wgsl` for rendering,
//! and `precompute/` one file per pass), `hillaire2020/` (its parameterisations, harmonics,
//! ray march, passes and `view.wgsl`), `elek3d/` (its parameterisation, filter and
//! `view.wgsl`) and `render/` (lights, cameras, the frame), each named
//! like the Rust file it mirrors, composed with a prelude of the Rust constants
//! ([`shader`]). The atmosphere travels in uniform and storage buffers; changing it compiles
//! nothing.

pub mod bruneton4d;
pub mod clouds;
mod device;
pub mod display;
pub mod elek3d;
mod error;
pub mod hillaire2020;
pub mod pass_timer;
pub mod passes;
pub mod planet;
pub mod render;
pub mod shader;
pub mod terrain;
mod wgsl_prelude;

pub use bruneton4d::{GpuSky, GpuTables, Precomputer};
pub use clouds::GpuClouds;
pub use device::{driver_crash, test_context, GpuContext};
pub use elek3d::{GpuElek3d, GpuElek3dRenderer, GpuElek3dTables};
pub use error::GpuError;
pub use hillaire2020::{
    GpuHillaire, GpuHillaireRenderer, GpuHillaireTables, HillaireFrameTiming, HillairePassTiming,
    HillairePrecomputer, HillaireTables,
};
pub use planet::GpuPlanet;
pub use render::{
    GpuRenderer, Interleave, RenderInputs, RenderTarget, RenderTiming, TemporalFrames, PIXEL_BYTES,
};
pub use terrain::GpuTerrain;

use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::{TableConfig, Tables};

/// Precompute every table for `model` on the GPU and read them back: the CPU's layout
/// ([`Tables::compute`]).
pub fn precompute(
    ctx: &GpuContext,
    model: &Model,
    config: &TableConfig,
) -> Result<Tables, GpuError> {
    Precomputer::new(ctx)?.run(ctx, model, config)
}
