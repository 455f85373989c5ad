//! Elek 2009 / Yusov 2013's 3D tables on the GPU (the twin of
//! [`firmament::sky::elek3d`]): the tables the CPU precomputes (well under a second)
//! uploaded in its texel order ([`GpuElek3d::from_sky`]: the optical depth, the phase-free
//! single Rayleigh and Mie, the multiple scattering and the sky irradiance, f32), and frames
//! ([`GpuElek3dRenderer`]) through `render/render.wgsl` with `shaders/elek3d/view.wgsl` in
//! place of the 4D view: the clear sky over the ground sphere, the sky from each light's
//! slice of the tables at the observer (the CPU view's per-view cache, one compute pass),
//! the aerial perspective to the ground from the tables at both ends, views from space, the
//! lights' disks, lunar lights, the background glow, an optional per-pixel shadowed length,
//! and the 4D tables' twilight below the tables' lowest sun.
//!
//! WGSL twins in `shaders/elek3d/`: `params`, `table`, `view` (the CPU files of the same
//! names; `params` and `table` functions carry an `elek3d_`/`table3_` prefix where the 4D
//! tables' have the name) and `scene` (the clear sky: no terrain on the GPU). The
//! transmittance, irradiance and twilight lookups are the 4D tables' WGSL
//! (`bruneton4d/params`, `table`, `lookup`, `twilight`), as the CPU method reuses
//! `bruneton4d::Lookup` and `bruneton4d::twilight`.
//!
//! Not on the GPU: the precomputation (the CPU's, uploaded), terrains and other surfaces
//! (a frame is the clear sky over the ground sphere), light shafts from lit intervals
//! (one shadowed length per pixel only), the aerial-perspective froxel volume
//! (`render::aerial_volume`), volumes.

pub mod render;
pub mod sky;

pub use render::GpuElek3dRenderer;
pub use sky::{GpuElek3d, GpuElek3dTables};
