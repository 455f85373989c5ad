//! firmament's wgpu backend: the precomputed tables of Bruneton & Neyret 2008 (as refined in
//! Bruneton 2017) computed by compute shaders, in the same sizes and texel layout as the CPU
//! path ([`firmament::sky::bruneton4d`]), so the two compare texel by texel and share the table file
//! format.
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
//! Frames render on the GPU too ([`render`]): [`GpuSky`] holds the tables (uploaded from a
//! CPU [`firmament::sky::Bruneton4d`], or precomputed and kept on the device with
//! [`GpuSky::precompute`]), [`GpuRenderer::render`] returns the CPU renderer's
//! [`firmament::render::Frame`] for the same settings, and [`GpuRenderer::time_render`]
//! times the dispatch alone.
//!
//! Shaders are WGSL under `shaders/`, one file per pass plus `functions.wgsl` shared by all
//! (it mirrors the CPU's parameterisations and lookups). The atmosphere travels in uniform
//! and storage buffers; changing it compiles nothing.

mod context;
mod error;
pub mod lut;
pub mod render;

pub use context::{test_context, GpuContext};
pub use error::GpuError;
pub use lut::precompute;
pub use render::{GpuRenderer, GpuSky, RenderTiming};
