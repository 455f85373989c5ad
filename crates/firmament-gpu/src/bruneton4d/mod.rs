//! The 4D-table sky method on the GPU: the atmosphere packed for the shaders
//! ([`atmosphere`]), the precomputation pass for pass as on the CPU ([`precompute`]), and
//! the tables ready to render ([`sky`]), whose WGSL twin is
//! `shaders/bruneton4d/view.wgsl`.

pub mod atmosphere;
pub mod precompute;
pub mod sky;

pub use precompute::{GpuTables, Precomputer};
pub use sky::GpuSky;
