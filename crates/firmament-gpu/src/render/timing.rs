//! Timing GPU frames: the render dispatch alone, from timestamp queries where the device has
//! them.

use std::time::Instant;

use firmament::render::RenderSettings;
use firmament::scene::Light;

use super::{GpuRenderer, RenderInputs, RenderTarget};
use crate::device::{read_back, scoped, staging_buffer};
use crate::{GpuContext, GpuError, GpuSky};

/// The median time of the render dispatch alone (no upload, no readback) over some frames.
#[derive(Clone, Copy, Debug)]
pub struct RenderTiming {
    /// Median seconds per frame.
    pub seconds: f64,
    /// Frames timed (after one untimed warm-up frame).
    pub frames: usize,
    /// How it was measured: "timestamp queries" (GPU clock, the compute pass alone) or
    /// "wall clock (submit + wait)" where the device has no timestamp queries.
    pub method: &'static str,
}

impl GpuRenderer {
    /// Render `frames` frames into a buffer (after one warm-up) and return the median time of
    /// the render dispatch alone, without upload or readback: from timestamp queries around
    /// the compute pass where the device has them, else the wall time of submit + wait.
    pub fn time_render(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
        frames: usize,
    ) -> Result<RenderTiming, GpuError> {
        self.time_render_with(ctx, sky, lights, settings, RenderInputs::default(), frames)
    }

    /// [`GpuRenderer::time_render`] with extra inputs (a terrain, shadowed lengths).
    pub fn time_render_with(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
        inputs: RenderInputs,
        frames: usize,
    ) -> Result<RenderTiming, GpuError> {
        let frames = frames.max(1);
        self.check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let target = RenderTarget::Buffer(&output);
        let job = self.prepare(ctx, sky, lights, settings, target, inputs)?;
        let device = ctx.device();
        let timestamps = ctx.supports_timestamps();
        let wait = |during: &str| {
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map(|_| ())
                .map_err(|e| GpuError::Execution {
                    during: during.to_string(),
                    reason: e.to_string(),
                })
        };
        let mut times = Vec::with_capacity(frames);
        scoped(ctx, "timing frames", || {
            let queries = timestamps.then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("frame timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                });
                let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: 16,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                (set, resolve)
            });
            for i in 0..=frames {
                let mut encoder = device.create_command_encoder(&Default::default());
                self.record(&mut encoder, &job, queries.as_ref().map(|q| &q.0));
                let readback = queries.as_ref().map(|(set, resolve)| {
                    encoder.resolve_query_set(set, 0..2, resolve, 0);
                    let b = staging_buffer(device, "timestamp readback", 16);
                    encoder.copy_buffer_to_buffer(resolve, 0, &b, 0, 16);
                    b
                });
                let start = Instant::now();
                ctx.queue().submit([encoder.finish()]);
                wait("timing frames")?;
                let wall = start.elapsed().as_secs_f64();
                let seconds = match readback {
                    Some(b) => {
                        let raw = read_back(ctx, &[&b], "reading timestamps")?;
                        let tick = |b: &[u8]| {
                            u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
                        };
                        tick(&raw[0][8..16]).saturating_sub(tick(&raw[0][0..8])) as f64
                            * ctx.queue().get_timestamp_period() as f64
                            * 1e-9
                    }
                    None => wall,
                };
                if i > 0 {
                    times.push(seconds);
                }
            }
            Ok(())
        })?;
        times.sort_by(f64::total_cmp);
        Ok(RenderTiming {
            seconds: times[times.len() / 2],
            frames,
            method: if timestamps {
                "timestamp queries"
            } else {
                "wall clock (submit + wait)"
            },
        })
    }
}
