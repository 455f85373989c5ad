//! firmament's wgpu backend: the precomputed tables of Bruneton & Neyret 2008 (as refined in
//! Bruneton 2017) computed by compute shaders, in the same sizes and texel layout as the CPU
//! path ([`firmament::sky::bruneton4d`]), so the two compare texel by texel and share the
//! table file format; and frames of the clear sky rendered from them.
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
//! separate step ([`GpuTables::read_back`], [`GpuRenderer::read_frame`]).
//!
//! Shaders are WGSL under `shaders/`: `common/` (types, bindings, profiles, phase functions,
//! geometry), `bruneton4d/` (parameterisations, filters, lookups, `view.wgsl` for rendering,
//! and `precompute/` one file per pass) and `render/` (lights, cameras, the frame), each named
//! like the Rust file it mirrors, composed with a prelude of the Rust constants
//! ([`shader`]). The atmosphere travels in uniform and storage buffers; changing it compiles
//! nothing.

pub mod bruneton4d;
mod device;
mod error;
pub mod passes;
pub mod render;
pub mod shader;
pub mod terrain;

pub use bruneton4d::{GpuSky, GpuTables, Precomputer};
pub use device::{test_context, GpuContext};
pub use error::GpuError;
pub use render::{GpuRenderer, RenderInputs, RenderTarget, RenderTiming, PIXEL_BYTES};
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
