//! The backend's error type.

use thiserror::Error;

/// Everything the GPU backend can refuse or fail at.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No usable adapter (no GPU, no software rasteriser such as lavapipe).
    #[error("no GPU adapter with compute shaders found ({0}); on Linux, install a Vulkan driver (e.g. `apt-get install mesa-vulkan-drivers libvulkan1` for the lavapipe software rasteriser)")]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not open the GPU device on adapter `{adapter}`: {reason}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// Why.
        reason: String,
    },
    /// Parameters the CPU path refuses too.
    #[error(transparent)]
    Invalid(#[from] firmament::Error),
    /// Tables or frames that do not fit the device's limits.
    #[error("{what} needs {needed} but the GPU adapter `{adapter}` allows at most {limit} ({limit_name}); use smaller tables, fewer wavelengths or a smaller frame")]
    Limit {
        /// What needed too much.
        what: String,
        /// The amount needed, in words.
        needed: String,
        /// The device's limit.
        limit: String,
        /// The wgpu limit's name.
        limit_name: &'static str,
        /// The adapter's name.
        adapter: String,
    },
    /// A failure reported by the device while computing (validation, out of memory, loss).
    #[error("GPU failure during {during}: {reason}")]
    Execution {
        /// The stage.
        during: String,
        /// The device's message.
        reason: String,
    },
}
