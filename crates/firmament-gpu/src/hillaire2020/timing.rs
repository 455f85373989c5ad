//! GPU timings of Hillaire 2020 for `firmament bench` and the `hillaire2020_timing`
//! example: each pass of a build (transmittance, multiple scattering, irradiance) and of a
//! frame (the sky-view tables, the pixels), medians over runs after one untimed warm-up, from
//! timestamp queries at the ends of each compute pass where the device has them (as
//! `render/timing.rs`), else the wall clock of each pass submitted alone and waited for.
//! Software adapters get the wall clock too: lavapipe (Mesa 22.3 here) writes a pass's end
//! timestamp before the work of its dispatches over several channel groups is done (a
//! spectral transmittance pass of 0.86 s read as 0.08 ms, the time landing before the next
//! pass's start). Buffers and bind groups are made once beforehand; nothing is read back
//! but the timestamps.

use std::time::Instant;

use firmament::atmosphere::Model;
use firmament::render::RenderSettings;
use firmament::scene::Light;
use firmament::sky::hillaire2020::HillaireConfig;

use super::precompute::{HillairePrecomputer, STAGES};
use super::render::{check_frame_buffer, GpuHillaireRenderer};
use super::sky::GpuHillaire;
use crate::device::{read_back, scoped, staging_buffer};
use crate::render::{RenderInputs, RenderTarget};
use crate::{GpuContext, GpuError};

/// How the passes were timed.
const TIMESTAMPS: &str = "timestamp queries";
const WALL_CLOCK: &str = "wall clock (each pass submitted alone, until the device is idle)";

/// Whether the passes are timed by timestamp queries on `ctx` (see the module's notes).
fn use_timestamps(ctx: &GpuContext) -> bool {
    ctx.supports_timestamps() && !ctx.is_software()
}

/// Median seconds of each pass of a build of the atmosphere-wide tables.
#[derive(Clone, Copy, Debug)]
pub struct HillairePassTiming {
    /// The optical-depth table.
    pub transmittance_s: f64,
    /// The multiple-scattering field (every order's gather and projection, and the tail).
    pub multiple_scattering_s: f64,
    /// The sky irradiance.
    pub irradiance_s: f64,
    /// Builds timed (after one warm-up).
    pub runs: usize,
    /// "timestamp queries" (GPU clock, each compute pass alone) or the wall clock.
    pub method: &'static str,
}

/// Median seconds of each pass of a frame.
#[derive(Clone, Copy, Debug)]
pub struct HillaireFrameTiming {
    /// The sky-view table of every light (0 for an observer in space).
    pub sky_view_s: f64,
    /// The pixels.
    pub frame_s: f64,
    /// Frames timed (after one warm-up).
    pub frames: usize,
    /// "timestamp queries" or the wall clock.
    pub method: &'static str,
}

/// Record `stages` passes with `record(encoder, stage, query set)` (stage s writing queries
/// 2s and 2s + 1) `runs` + 1 times; the medians per stage of the timed runs and the method.
fn time_stages(
    ctx: &GpuContext,
    stages: usize,
    runs: usize,
    record: &dyn Fn(&mut wgpu::CommandEncoder, usize, Option<&wgpu::QuerySet>),
) -> Result<(Vec<f64>, &'static str), GpuError> {
    let device = ctx.device();
    let timestamps = use_timestamps(ctx);
    let wait = || {
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Execution {
                during: "timing passes".into(),
                reason: e.to_string(),
            })
    };
    let mut times = vec![Vec::with_capacity(runs); stages];
    scoped(ctx, "timing passes", || {
        let bytes = 16 * stages as u64;
        let queries = timestamps.then(|| {
            let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * stages as u32,
            });
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (set, resolve)
        });
        for run in 0..=runs {
            match &queries {
                Some((set, resolve)) => {
                    let mut encoder = device.create_command_encoder(&Default::default());
                    for stage in 0..stages {
                        record(&mut encoder, stage, Some(set));
                    }
                    encoder.resolve_query_set(set, 0..2 * stages as u32, resolve, 0);
                    let b = staging_buffer(device, "timestamp readback", bytes);
                    encoder.copy_buffer_to_buffer(resolve, 0, &b, 0, bytes);
                    ctx.queue().submit([encoder.finish()]);
                    let raw = read_back(ctx, &[&b], "reading timestamps")?;
                    let tick = |i: usize| {
                        let b = &raw[0][8 * i..8 * i + 8];
                        u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
                    };
                    let period = ctx.queue().get_timestamp_period() as f64 * 1e-9;
                    for (stage, t) in times.iter_mut().enumerate() {
                        let ticks = tick(2 * stage + 1).saturating_sub(tick(2 * stage));
                        if run > 0 {
                            t.push(ticks as f64 * period);
                        }
                    }
                }
                None => {
                    for (stage, t) in times.iter_mut().enumerate() {
                        let mut encoder = device.create_command_encoder(&Default::default());
                        record(&mut encoder, stage, None);
                        let start = Instant::now();
                        ctx.queue().submit([encoder.finish()]);
                        wait()?;
                        if run > 0 {
                            t.push(start.elapsed().as_secs_f64());
                        }
                    }
                }
            }
        }
        Ok(())
    })?;
    let medians = times
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        })
        .collect();
    Ok((medians, if timestamps { TIMESTAMPS } else { WALL_CLOCK }))
}

impl HillairePrecomputer {
    /// Build the tables for `model` `runs` + 1 times into the same buffers and return the
    /// median time of each pass (no allocation, upload or readback in the times).
    pub fn time_passes(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
        runs: usize,
    ) -> Result<HillairePassTiming, GpuError> {
        let runs = runs.max(1);
        let build = self.prepare(ctx, model, config)?;
        let (t, method) = time_stages(ctx, STAGES.len(), runs, &|encoder, stage, set| {
            self.record(encoder, &build, stage, set)
        })?;
        Ok(HillairePassTiming {
            transmittance_s: t[0],
            multiple_scattering_s: t[1],
            irradiance_s: t[2],
            runs,
            method,
        })
    }
}

impl GpuHillaireRenderer {
    /// Render `frames` frames into a buffer (after one warm-up) and return the median time
    /// of the sky-view pass and of the pixels' pass (no upload or readback).
    pub fn time_render(
        &self,
        ctx: &GpuContext,
        sky: &GpuHillaire,
        lights: &[Light],
        settings: &RenderSettings,
        frames: usize,
    ) -> Result<HillaireFrameTiming, GpuError> {
        let frames = frames.max(1);
        check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let target = RenderTarget::Buffer(&output);
        let job = self.prepare(ctx, sky, lights, settings, target, RenderInputs::default())?;
        let with_sky_view = job.has_sky_view();
        let (t, method) = time_stages(ctx, 2, frames, &|encoder, stage, set| {
            if stage == 0 {
                if with_sky_view {
                    self.record_sky_view(encoder, &job, set);
                } else if let Some(set) = set {
                    // No tables from space: an empty pass keeps the queries written.
                    let _ = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("no sky view"),
                        timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                            query_set: set,
                            beginning_of_pass_write_index: Some(0),
                            end_of_pass_write_index: Some(1),
                        }),
                    });
                }
            } else {
                self.record_pixels(encoder, &job, set);
            }
        })?;
        Ok(HillaireFrameTiming {
            sky_view_s: if with_sky_view { t[0] } else { 0.0 },
            frame_s: t[1],
            frames,
            method,
        })
    }
}
