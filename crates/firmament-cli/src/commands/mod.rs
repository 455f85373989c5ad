//! One module per subcommand: its arguments (clap) and its `run`. What several share lives
//! in [`crate::common`] (atmosphere and tables) and [`crate::backend`] (CPU or GPU).

pub mod astro;
pub mod atmosphere;
pub mod bake;
pub mod bench;
pub mod gallery;
pub mod lamps;
pub mod outputs;
pub mod provenance;
pub mod query;
pub mod query_scene;
pub mod render;
pub mod render_args;
pub mod render_reference;
pub mod timelapse;
pub mod validate;
pub mod view;
