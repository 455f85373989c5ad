//! The adapter, device and queue (opened here, or handed in by an engine), how errors
//! reported by the device reach the caller (never as a panic: wgpu's default handler for
//! uncaptured errors panics), and the plumbing every GPU step shares: error scopes, limit
//! checks, reading buffers back.

use std::sync::{Arc, Mutex};

use crate::GpuError;

/// A wgpu device chosen for compute work: a hardware GPU when there is one, a software
/// rasteriser (Mesa's lavapipe, WARP, SwiftShader) otherwise.
pub struct GpuContext {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    /// Errors the device reported outside error scopes.
    uncaptured: Arc<Mutex<Vec<String>>>,
    /// Set when the device is lost.
    lost: Arc<Mutex<Option<String>>>,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("adapter", &self.info.name)
            .field("backend", &self.info.backend)
            .finish()
    }
}

/// Preference order of adapter kinds: hardware first, software last.
fn rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

impl GpuContext {
    /// Open the best adapter with compute shaders: a discrete GPU, then an integrated or
    /// virtual one, then a software rasteriser. Honours wgpu's environment variables
    /// (`WGPU_BACKEND`, …). Errors when there is none.
    pub fn new() -> Result<GpuContext, GpuError> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<GpuContext, GpuError> {
        let desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let backends = desc.backends;
        let instance = wgpu::Instance::new(desc);
        let mut adapters: Vec<wgpu::Adapter> = instance
            .enumerate_adapters(backends)
            .await
            .into_iter()
            .filter(|a| {
                a.get_downlevel_capabilities()
                    .flags
                    .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
            })
            .collect();
        if adapters.is_empty() {
            return Err(GpuError::NoAdapter(format!(
                "backends searched: {backends:?}"
            )));
        }
        adapters.sort_by_key(|a| rank(a.get_info().device_type));
        let adapter = adapters.swap_remove(0);
        let info = adapter.get_info();
        // The adapter's own limits: the tables are large storage buffers.
        let limits = adapter.limits();
        // Timestamp queries when offered: GPU-side timings of the render dispatch.
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("firmament"),
                required_features: features,
                required_limits: limits.clone(),
                experimental_features: wgpu::ExperimentalFeatures::default(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| GpuError::Device {
                adapter: info.name.clone(),
                reason: e.to_string(),
            })?;
        let uncaptured = Arc::new(Mutex::new(Vec::new()));
        let sink = uncaptured.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let lost = Arc::new(Mutex::new(None));
        let lost_sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut v) = lost_sink.lock() {
                *v = Some(format!("device lost ({reason:?}): {message}"));
            }
        });
        let limits = device.limits();
        Ok(GpuContext {
            device,
            queue,
            info,
            limits,
            uncaptured,
            lost,
        })
    }

    /// A context on a device the caller already holds (an engine's, or a viewer's egui-wgpu
    /// device): firmament records its work on `device` and `queue` and never replaces the
    /// caller's error handlers; failures still come back as [`GpuError`] from error scopes.
    /// `info` describes the adapter (for messages and [`GpuContext::is_software`]). The
    /// device needs the limits the tables and frames use (storage buffers of their size,
    /// 8 storage buffers per stage); they are checked before any work.
    pub fn from_device(
        device: wgpu::Device,
        queue: wgpu::Queue,
        info: wgpu::AdapterInfo,
    ) -> GpuContext {
        let limits = device.limits();
        GpuContext {
            device,
            queue,
            info,
            limits,
            uncaptured: Arc::new(Mutex::new(Vec::new())),
            lost: Arc::new(Mutex::new(None)),
        }
    }

    /// The adapter's name, e.g. "NVIDIA GeForce RTX 4090" or "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub fn adapter_name(&self) -> &str {
        &self.info.name
    }

    /// The graphics API in use (Vulkan, Metal, Dx12, …).
    pub fn backend(&self) -> String {
        format!("{:?}", self.info.backend)
    }

    /// Whether the adapter is a software rasteriser running on the CPU (lavapipe and the like).
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Whether the passes read their uniform blocks as read-only storage buffers: on
    /// software adapters. Mesa 22.3's lavapipe (Debian 12's, LLVM 15) writes into freed
    /// memory while it builds a compute pipeline whose shader reads uniform buffers
    /// (valgrind: 4-byte writes from a recursive walk inside `vkCreateComputePipelines`,
    /// into unallocated blocks, at every build of the render pipelines), and the process
    /// dies of it later, in its queue thread or in glibc's allocator: 9 of 25 `render
    /// --backend gpu` runs of a small cumulus scene, against 0 of 25 with storage buffers,
    /// interleaved (2026-12-06), the frames identical to the byte. Hardware keeps uniform
    /// buffers. `FIRMAMENT_GPU_UNIFORMS=uniform` (or `storage`) overrides the choice.
    pub fn uniforms_as_storage(&self) -> bool {
        match std::env::var("FIRMAMENT_GPU_UNIFORMS").as_deref() {
            Ok("uniform") => false,
            Ok("storage") => true,
            _ => self.is_software(),
        }
    }

    /// Whether the device writes timestamp queries (`wgpu::Features::TIMESTAMP_QUERY`).
    pub fn supports_timestamps(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// The wgpu device.
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The wgpu queue.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// The device's limits (the adapter's own, requested in full).
    pub fn limits(&self) -> &wgpu::Limits {
        &self.limits
    }

    /// Errors reported since the last call (uncaptured errors and device loss), as one
    /// message, clearing them.
    pub(crate) fn take_reported_errors(&self) -> Option<String> {
        let mut messages = Vec::new();
        if let Ok(mut v) = self.uncaptured.lock() {
            messages.append(&mut v);
        }
        if let Ok(v) = self.lost.lock() {
            if let Some(m) = v.as_ref() {
                messages.push(m.clone());
            }
        }
        if messages.is_empty() {
            None
        } else {
            Some(messages.join("; "))
        }
    }
}

/// Run `f` inside validation, out-of-memory and internal error scopes; the first error
/// reported (or reported to the uncaptured handler, or a device loss) becomes `Err`.
pub(crate) fn scoped<T>(
    ctx: &GpuContext,
    during: &str,
    f: impl FnOnce() -> Result<T, GpuError>,
) -> Result<T, GpuError> {
    let device = ctx.device();
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = f();
    let errors = [
        pollster::block_on(validation.pop()),
        pollster::block_on(oom.pop()),
        pollster::block_on(internal.pop()),
    ];
    let execution = |reason: String| GpuError::Execution {
        during: during.to_string(),
        reason,
    };
    if let Some(e) = errors.into_iter().flatten().next() {
        return Err(execution(e.to_string()));
    }
    if let Some(reason) = ctx.take_reported_errors() {
        return Err(execution(reason));
    }
    result
}

/// Refuse storage buffers larger than the device binds or allocates, before allocating
/// anything: (what, bytes) each.
pub(crate) fn check_buffers(ctx: &GpuContext, buffers: &[(&str, u64)]) -> Result<(), GpuError> {
    let limits = ctx.limits();
    for &(what, bytes) in buffers {
        for (limit, name) in [
            (
                limits.max_storage_buffer_binding_size,
                "max_storage_buffer_binding_size",
            ),
            (limits.max_buffer_size, "max_buffer_size"),
        ] {
            if bytes > limit {
                return Err(GpuError::Limit {
                    what: format!("the {what}"),
                    needed: format!("{bytes} bytes"),
                    limit: format!("{limit} bytes"),
                    limit_name: name,
                    adapter: ctx.adapter_name().to_string(),
                });
            }
        }
    }
    Ok(())
}

/// Map the staging buffers (MAP_READ), wait for the device, and copy their bytes out.
pub(crate) fn read_back(
    ctx: &GpuContext,
    staging: &[&wgpu::Buffer],
    during: &str,
) -> Result<Vec<Vec<u8>>, GpuError> {
    let failure = |reason: String| GpuError::Execution {
        during: during.to_string(),
        reason,
    };
    let (tx, rx) = std::sync::mpsc::channel();
    for (i, b) in staging.iter().enumerate() {
        let tx = tx.clone();
        b.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send((i, r));
        });
    }
    drop(tx);
    ctx.device()
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| failure(e.to_string()))?;
    for _ in 0..staging.len() {
        let (_, r) = rx
            .recv()
            .map_err(|_| failure("the device never finished mapping the buffers".into()))?;
        r.map_err(|e| failure(e.to_string()))?;
    }
    let mut out = Vec::with_capacity(staging.len());
    for b in staging {
        let view = b
            .slice(..)
            .get_mapped_range()
            .map_err(|e| failure(e.to_string()))?;
        out.push(view.to_vec());
        drop(view);
        b.unmap();
    }
    Ok(out)
}

/// Copy the storage buffers `sources` to the host as f32 (one submission, then waits for the
/// device); `what` names the work for the errors of the copy, `during` those of the wait.
pub(crate) fn read_buffers_f32(
    ctx: &GpuContext,
    sources: &[&wgpu::Buffer],
    what: &str,
    during: &str,
) -> Result<Vec<Vec<f32>>, GpuError> {
    let device = ctx.device();
    let staging = scoped(ctx, what, || {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("firmament readback"),
        });
        let staging: Vec<wgpu::Buffer> = sources
            .iter()
            .map(|src| {
                let b = staging_buffer(device, "readback", src.size());
                encoder.copy_buffer_to_buffer(src, 0, &b, 0, src.size());
                b
            })
            .collect();
        ctx.queue().submit([encoder.finish()]);
        Ok(staging)
    })?;
    let bytes = scoped(ctx, during, || {
        read_back(ctx, &staging.iter().collect::<Vec<_>>(), during)
    })?;
    Ok(bytes.iter().map(|b| f32s(b)).collect())
}

/// A MAP_READ | COPY_DST buffer of `size` bytes to copy GPU results into.
pub(crate) fn staging_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Little-endian f32 values of raw bytes.
pub(crate) fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// A context for test suites: `Some` when an adapter is found; when none is, `None` (the
/// caller skips, saying so on stderr) unless the environment variable `CI` is set, in which
/// case this panics so that a CI machine without a working driver fails instead of
/// silently skipping the GPU tests.
pub fn test_context() -> Option<GpuContext> {
    decide_test_context(GpuContext::new(), std::env::var_os("CI").is_some())
}

/// Why a child process that drew on the test adapter died of that driver's known heap
/// corruption, or None for any other outcome (success, or a failure of firmament's own),
/// for test harnesses that run such a process again. Mesa 22.3's lavapipe (Debian 12's,
/// LLVM 15) corrupts the process's heap when it builds compute pipelines that read uniform
/// buffers ([`GpuContext::uniforms_as_storage`], which avoids that since 2026-12-06: 0 of
/// 25 runs of a small cumulus scene died, against 8 of 25 with uniform buffers); the
/// harnesses keep running such a process again for whatever else the driver does. The
/// corruption shows as a signal (its queue thread jumping to a wild address, glibc aborting
/// on a corrupted free list) or as a panic inside a dependency (naga's compaction indexing
/// with a wild handle, gpu-allocator, bit-vec): a panic located in a crate of the registry
/// (firmament's own failures are errors with exit code 1, or panics in its own files).
pub fn driver_crash(status: &std::process::ExitStatus, output: &str) -> Option<&'static str> {
    if status.success() {
        return None;
    }
    if status.code().is_none() {
        return Some("was killed by a signal");
    }
    (output.contains("panicked at") && output.contains("/.cargo/registry/"))
        .then_some("panicked in a dependency")
}

fn decide_test_context(result: Result<GpuContext, GpuError>, ci: bool) -> Option<GpuContext> {
    match result {
        Ok(ctx) => Some(ctx),
        Err(e) if ci => panic!("CI is set but no GPU adapter could be opened: {e}"),
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn driver_crashes_are_signals_and_panics_inside_dependencies() {
        use std::os::unix::process::ExitStatusExt;
        let ok = std::process::ExitStatus::from_raw(0);
        let exit_1 = std::process::ExitStatus::from_raw(1 << 8);
        let exit_101 = std::process::ExitStatus::from_raw(101 << 8);
        let sigabrt = std::process::ExitStatus::from_raw(6);
        let naga = "thread 'main' panicked at /root/.cargo/registry/src/index/naga-30.0.1/src/compact/handle_set_map.rs:83:23";
        let ours = "thread 'main' panicked at crates/firmament/src/sky/mod.rs:10:5";
        assert_eq!(driver_crash(&ok, naga), None);
        assert_eq!(driver_crash(&exit_1, "error: `--width` must be ≥ 1"), None);
        assert_eq!(driver_crash(&exit_101, ours), None);
        assert_eq!(
            driver_crash(&exit_101, naga),
            Some("panicked in a dependency")
        );
        assert_eq!(
            driver_crash(&sigabrt, "corrupted double-linked list"),
            Some("was killed by a signal")
        );
    }

    #[test]
    #[should_panic(expected = "CI is set")]
    fn missing_adapter_fails_under_ci() {
        decide_test_context(Err(GpuError::NoAdapter("test".into())), true);
    }

    #[test]
    fn missing_adapter_skips_outside_ci() {
        assert!(decide_test_context(Err(GpuError::NoAdapter("test".into())), false).is_none());
    }

    #[test]
    fn hardware_ranks_before_software() {
        assert!(rank(wgpu::DeviceType::DiscreteGpu) < rank(wgpu::DeviceType::IntegratedGpu));
        assert!(rank(wgpu::DeviceType::IntegratedGpu) < rank(wgpu::DeviceType::Cpu));
        assert!(rank(wgpu::DeviceType::Other) < rank(wgpu::DeviceType::Cpu));
    }
}
