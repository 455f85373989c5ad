//! Frames under clouds or over a terrain at a fraction of the cost, for the viewer: each
//! frame marches one pixel of every k×k block (an interleaved frame, [`Interleave`]: k = 2
//! draws a quarter of the pixels), and a resolve pass (`shaders/render/temporal.wgsl`)
//! fills the others from the previous frames, reprojected through the two pinhole cameras
//! at the depths of the pixels drawn around them, or, where nothing matches (the first
//! frame after a change, a disocclusion, the view's new edge), from the drawn pixels around
//! them (Schneider 2015, "The real-time volumetric cloudscapes of Horizon Zero Dawn";
//! Hillaire 2016 §4.4). The blocks' pixels are visited in ordered-dither (Bayer) order, so
//! that each frame's pixels lie between the previous ones'; a window around each visible
//! light disk is marched whole every frame. With the camera and the scene still, k² frames
//! give every pixel its own march: the converged frame, exactly. Anything but the camera
//! changing (the lights, the atmosphere, the clouds, the terrain) calls for
//! [`TemporalFrames::reset`]: the history is then not read. Offline frames (`render
//! --backend gpu`) march every pixel.

use firmament::math::Vec3;
use firmament::render::RenderSettings;
use firmament::scene::{Light, Projection};

use super::frame::{FrameConstants, FrameSky, MAX_LIGHTS};
use super::{GpuRenderer, RenderInputs, RenderTarget, PIXEL_BYTES};
use crate::device::scoped;
use crate::passes::{buffer_pipeline, init, uniform_binding, workgroups, UNIFORM_USAGE};
use crate::{GpuContext, GpuError, GpuSky};

/// The depth (m) an interleaved frame writes for rays to the sky (`SKY_DEPTH_M` in WGSL).
pub const SKY_DEPTH_M: f32 = 1e30;
/// The `Frame.interleave` bit that puts each pixel's depth in the output's alpha.
pub const DEPTH_IN_ALPHA: u32 = 1 << 24;
/// The steps an interleaved frame takes (1: every pixel).
pub const STEPS: [u32; 3] = [1, 2, 4];

/// Which pixels an interleaved frame draws: pixel `phase` of each `step`×`step` block, or
/// with `window` (step 1, phase (0, 0)) every pixel of columns x0..x1 and rows y0..y1 (y0 a
/// multiple of 16, where a band of rows may start).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interleave {
    pub step: u32,
    pub phase: (u32, u32),
    pub window: Option<[u32; 4]>,
}

impl Interleave {
    /// The `n`-th frame's of a sequence of `step`: the blocks' pixels in ordered-dither
    /// (Bayer) order, each level of the 2×2 pattern (0, 0), (1, 1), (1, 0), (0, 1) taking
    /// two bits of n; every step² frames visit each pixel of a block once.
    pub fn nth(step: u32, n: u32) -> Interleave {
        let n = n % (step * step);
        let (mut x, mut y) = (0, 0);
        for level in 0..step.trailing_zeros() {
            let (dx, dy) = [(0, 0), (1, 1), (1, 0), (0, 1)][((n >> (2 * level)) & 3) as usize];
            let scale = step >> (level + 1);
            x += dx * scale;
            y += dy * scale;
        }
        Interleave {
            step,
            phase: (x, y),
            window: None,
        }
    }

    /// A window of the frame drawn whole ([`Interleave::window`]).
    pub fn window(window: [u32; 4]) -> Interleave {
        Interleave {
            step: 1,
            phase: (0, 0),
            window: Some(window),
        }
    }

    /// Refuse a step, phase or window that a `width`×`height` frame cannot take.
    pub(crate) fn check(&self, width: usize, height: usize) -> Result<(), GpuError> {
        if let Some([x0, y0, x1, y1]) = self.window {
            let fits = self.step == 1
                && self.phase == (0, 0)
                && x0 < x1
                && y0 < y1
                && x1 as usize <= width.min(0xffff)
                && y1 as usize <= height
                && (y0 as usize).is_multiple_of(super::BAND_ROW_ALIGN);
            if !fits {
                return Err(firmament::Error::invalid(
                    "interleave window",
                    format!("{:?} at step {}", self.window, self.step),
                    format!("step 1, x0 < x1 ≤ {width}, y0 < y1 ≤ {height}, y0 a multiple of 16"),
                )
                .into());
            }
        }
        if !STEPS.contains(&self.step) {
            return Err(
                firmament::Error::invalid("interleave step", self.step, "1, 2 or 4").into(),
            );
        }
        if self.phase.0 >= self.step || self.phase.1 >= self.step {
            return Err(firmament::Error::invalid(
                "interleave phase",
                format!("{:?}", self.phase),
                format!("each below the step {}", self.step),
            )
            .into());
        }
        Ok(())
    }

    /// `Frame.interleave` (render/frame.wgsl).
    pub(crate) fn word(&self) -> u32 {
        self.step | (self.phase.0 << 8) | (self.phase.1 << 16) | DEPTH_IN_ALPHA
    }

    /// `Frame.interleave_columns` (render/frame.wgsl): the window's columns, or 0 (all).
    pub(crate) fn columns_word(&self) -> u32 {
        self.window.map_or(0, |[x0, _, x1, _]| x0 | (x1 << 16))
    }
}

/// What a frame's dispatches cover: its rows, its columns and its step (the whole frame at
/// step 1 unless it is interleaved).
pub(crate) struct Extent {
    pub rows: (usize, usize),
    pub columns: usize,
    pub step: usize,
}

impl Extent {
    /// The extent of a `w`×`h` frame drawn into `target` in bands of `band_rows` rows;
    /// refuses an interleaved frame neither under clouds nor over a terrain (the frames
    /// whose entry points write the depth that drives the resolve), in several bands or into
    /// a texture.
    pub(crate) fn of(
        inputs: &RenderInputs,
        target: &RenderTarget,
        (w, h): (usize, usize),
        band_rows: usize,
    ) -> Result<Extent, GpuError> {
        let Some(il) = inputs.interleave else {
            return Ok(Extent {
                rows: (0, h),
                columns: w,
                step: 1,
            });
        };
        il.check(w, h)?;
        if inputs.clouds.is_none() && inputs.terrain.is_none() {
            return Err(firmament::Error::invalid(
                "RenderInputs.interleave",
                "a frame without clouds or a terrain",
                "interleaved frames under clouds or over a terrain",
            )
            .into());
        }
        if band_rows < h || !matches!(target, RenderTarget::Buffer(_)) {
            return Err(firmament::Error::invalid(
                "RenderInputs.interleave",
                format!(
                    "a {w}×{h} frame into {} bands or a texture",
                    h.div_ceil(band_rows)
                ),
                "one band of a buffer",
            )
            .into());
        }
        Ok(match il.window {
            Some([x0, y0, x1, y1]) => Extent {
                rows: (y0 as usize, y1 as usize),
                columns: (x1 - x0) as usize,
                step: 1,
            },
            None => Extent {
                rows: (0, h),
                columns: w,
                step: il.step as usize,
            },
        })
    }
}

/// The camera a frame was drawn with, as the resolve reprojects it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Seen {
    pinhole: bool,
    basis: (Vec3, Vec3, Vec3),
    tan_half_fov: f64,
    altitude_m: f64,
    size: (usize, usize),
}

impl Seen {
    fn of(sky: &GpuSky, settings: &RenderSettings) -> Seen {
        let camera = settings.camera;
        let prepared = camera.prepare(sky.radii_m().0, settings.width, settings.height);
        Seen {
            pinhole: matches!(
                camera.projection,
                Projection::Perspective | Projection::Orbit
            ),
            basis: prepared.basis(),
            tan_half_fov: prepared.tan_half_fov(),
            altitude_m: camera.altitude_m,
            size: (settings.width, settings.height),
        }
    }
}

/// `Temporal.flags` (render/temporal.wgsl).
const HISTORY_VALID: u32 = 1;
const SAME_CAMERA: u32 = 2;
const PINHOLES: u32 = 4;

/// This frame's pixels and the two histories (each frame reads one, writes the other).
struct Buffers {
    size: (usize, usize),
    fresh: wgpu::Buffer,
    history: [wgpu::Buffer; 2],
    /// The history the next frame reads.
    read: usize,
}

/// Interleaved frames under clouds and their resolve, frame after frame.
pub struct TemporalFrames {
    step: u32,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    buffers: Option<Buffers>,
    /// The camera of the history to read (None: no history).
    seen: Option<Seen>,
    /// Frames since the last reset.
    frame: u32,
    /// Frames since the last reset or the last move of the camera.
    still: u32,
}

impl TemporalFrames {
    /// The resolve pass, for frames drawing one pixel of each `step`×`step` block (1, 2 or 4;
    /// 1 draws every pixel and resolves nothing).
    pub fn new(ctx: &GpuContext, step: u32) -> Result<TemporalFrames, GpuError> {
        Interleave::nth(step, 0).check(1, 1)?;
        scoped(ctx, "the temporal resolve's compilation", || {
            let read = wgpu::BufferBindingType::Storage { read_only: true };
            let write = wgpu::BufferBindingType::Storage { read_only: false };
            let (pipeline, layout) = buffer_pipeline(
                ctx,
                "temporal resolve",
                &crate::shader::temporal_source(),
                "resolve",
                &[
                    (0, uniform_binding(ctx)),
                    (1, read),
                    (2, read),
                    (3, write),
                    (4, write),
                    (10, uniform_binding(ctx)),
                ],
            );
            Ok(TemporalFrames {
                step,
                pipeline,
                layout,
                buffers: None,
                seen: None,
                frame: 0,
                still: 0,
            })
        })
    }

    /// The step (1, 2 or 4).
    pub fn step(&self) -> u32 {
        self.step
    }

    /// A new step (1, 2 or 4); the history is dropped when it changes.
    pub fn set_step(&mut self, step: u32) -> Result<(), GpuError> {
        Interleave::nth(step, 0).check(1, 1)?;
        if step != self.step {
            self.step = step;
            self.reset();
        }
        Ok(())
    }

    /// Forget the history (the scene changed other than by the camera): the next frame
    /// fills its undrawn pixels from its drawn ones, and the phases start again.
    pub fn reset(&mut self) {
        self.seen = None;
        self.frame = 0;
        self.still = 0;
    }

    /// Frames drawn since the last reset or the last move of the camera: step² of them are
    /// the converged frame (for a panel's line).
    pub fn still_frames(&self) -> u32 {
        self.still
    }

    /// Record the next frame into `output` (a frame buffer of `settings`' size, as
    /// [`GpuRenderer::frame_buffer`]): under clouds or over a terrain one pixel of each
    /// block marched, then the resolve, in one compute pass (within `inputs.timestamps`);
    /// the clear sky over the sphere (cheap), or any frame at step 1, as
    /// [`GpuRenderer::encode`] draws it.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        renderer: &GpuRenderer,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
        output: &wgpu::Buffer,
        inputs: RenderInputs,
    ) -> Result<(), GpuError> {
        if self.step == 1 || (inputs.clouds.is_none() && inputs.terrain.is_none()) {
            self.reset();
            let target = RenderTarget::Buffer(output);
            return renderer.encode(ctx, encoder, sky, lights, settings, target, inputs);
        }
        let size = (settings.width, settings.height);
        let bytes = (size.0 * size.1) as u64 * PIXEL_BYTES;
        if output.size() < bytes {
            return Err(firmament::Error::invalid(
                "temporal output",
                format!("{} bytes", output.size()),
                format!("a frame buffer of {bytes} bytes"),
            )
            .into());
        }
        let device = ctx.device();
        if self.buffers.as_ref().is_none_or(|b| b.size != size) {
            let buffer = |label| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                })
            };
            self.buffers = Some(Buffers {
                size,
                fresh: buffer("interleaved frame"),
                history: [buffer("temporal history"), buffer("temporal history")],
                read: 0,
            });
            self.reset();
        }
        let buffers = self.buffers.as_ref().expect("just made");
        let interleave = Interleave::nth(self.step, self.frame);
        let job = renderer.prepare(
            ctx,
            sky,
            lights,
            settings,
            RenderTarget::Buffer(&buffers.fresh),
            RenderInputs {
                interleave: Some(interleave),
                ..inputs
            },
        )?;
        // The windows around the lights' disks in view, drawn whole every frame: a disk a
        // few pixels wide holds much of the frame's light, and an interpolated one would
        // spread it (and move the exposure).
        let now = Seen::of(sky, settings);
        let windows = disk_windows(&now, lights);
        let window_jobs = windows
            .iter()
            .map(|&w| {
                let target = RenderTarget::Buffer(&buffers.fresh);
                let inputs = RenderInputs {
                    interleave: Some(Interleave::window(w)),
                    ..inputs
                };
                renderer.prepare(ctx, sky, lights, settings, target, inputs)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut flags = (windows.len() as u32) << 8;
        let mut before = now;
        if let Some(seen) = self.seen {
            flags |= HISTORY_VALID;
            before = seen;
            if seen == now {
                flags |= SAME_CAMERA;
            }
            if seen.pinhole && now.pinhole {
                flags |= PINHOLES;
            }
        }
        let f32s = |v: Vec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        let mut words: Vec<u32> = vec![
            interleave.step,
            interleave.phase.0,
            interleave.phase.1,
            flags,
        ];
        let (forward, right, up) = before.basis;
        let moved = Vec3::new(0.0, 0.0, now.altitude_m - before.altitude_m);
        for v in [
            f32s(forward, before.tan_half_fov),
            f32s(right, 0.0),
            f32s(up, 0.0),
            f32s(moved, 0.0),
        ] {
            words.extend(v.map(f32::to_bits));
        }
        for i in 0..MAX_LIGHTS {
            words.extend(windows.get(i).copied().unwrap_or([0; 4]));
        }
        let frame_words = FrameConstants::new(sky, lights.len(), false, settings).words(0, size.1);
        let bind = scoped(ctx, "preparing the temporal resolve", || {
            let temporal = init(
                device,
                "temporal",
                bytemuck::cast_slice(&words),
                UNIFORM_USAGE,
            );
            let frame = init(
                device,
                "temporal frame",
                bytemuck::cast_slice(&frame_words),
                UNIFORM_USAGE,
            );
            let (read, write) = (
                &buffers.history[buffers.read],
                &buffers.history[1 - buffers.read],
            );
            let out = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: output,
                offset: 0,
                size: wgpu::BufferSize::new(bytes),
            });
            let entries = [
                (0, temporal.as_entire_binding()),
                (1, buffers.fresh.as_entire_binding()),
                (2, read.as_entire_binding()),
                (3, out),
                (4, write.as_entire_binding()),
                (10, frame.as_entire_binding()),
            ];
            Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("temporal resolve"),
                layout: &self.layout,
                entries: &entries
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource }),
            }))
        })?;
        let (x, y) = workgroups(
            size.0 * size.1,
            ctx.limits().max_compute_workgroups_per_dimension,
        );
        let jobs: Vec<_> = std::iter::once(&job).chain(&window_jobs).collect();
        renderer.record_then(encoder, &jobs, inputs.timestamps, |cpass| {
            cpass.set_pipeline(&self.pipeline);
            cpass.set_bind_group(0, &bind, &[]);
            cpass.dispatch_workgroups(x, y, 1);
        });
        if let Some(b) = self.buffers.as_mut() {
            b.read = 1 - b.read;
        }
        self.still = if flags & SAME_CAMERA != 0 {
            self.still + 1
        } else {
            1
        };
        self.seen = Some(now);
        self.frame += 1;
        Ok(())
    }
}

/// The windows of the frame drawn whole around the visible disks of `lights` seen by the
/// camera `seen` (pinhole cameras; none otherwise): the disk's radius in pixels at the frame's centre, doubled (a
/// pixel off-centre subtends less), and the footprints its edge's subsamples take
/// (`disk_edges::EDGE_FOOTPRINTS`) and one pixel around; rows from a multiple of 16.
fn disk_windows(seen: &Seen, lights: &[Light]) -> Vec<[u32; 4]> {
    if !seen.pinhole {
        return Vec::new();
    }
    let (w, h) = (seen.size.0 as f64, seen.size.1 as f64);
    let (forward, right, up) = seen.basis;
    let t = seen.tan_half_fov;
    let pixel_angle = 2.0 * t / h;
    let align = super::BAND_ROW_ALIGN as f64;
    lights
        .iter()
        .filter(|l| l.visible_disk)
        .filter_map(|l| {
            let d = l.direction;
            let z = d.dot(forward);
            if z <= 0.0 {
                return None;
            }
            let cx = (d.dot(right) / (z * t * w / h) + 1.0) * 0.5 * w;
            let cy = (1.0 - d.dot(up) / (z * t)) * 0.5 * h;
            let radius = 2.0 * l.angular_radius_rad / pixel_angle
                + firmament::render::disk_edges::EDGE_FOOTPRINTS
                + 1.0;
            let x0 = (cx - radius).floor().max(0.0);
            let x1 = (cx + radius).ceil().min(w.min(65535.0));
            let y0 = ((cy - radius).floor().max(0.0) / align).floor() * align;
            let y1 = (cy + radius).ceil().min(h);
            (x0 < x1 && y0 < y1).then_some([x0 as u32, y0 as u32, x1 as u32, y1 as u32])
        })
        .take(MAX_LIGHTS)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_block_pixel_is_drawn_once_every_step_squared_frames() {
        for step in STEPS {
            let n = step * step;
            let mut seen: Vec<(u32, u32)> =
                (0..n).map(|i| Interleave::nth(step, i).phase).collect();
            // The sequence repeats.
            assert_eq!(Interleave::nth(step, n + 1), Interleave::nth(step, 1));
            seen.sort();
            seen.dedup();
            assert_eq!(seen.len() as u32, n, "step {step}");
            assert!(seen.iter().all(|&(x, y)| x < step && y < step));
        }
        // The 2×2 order: the diagonal second, so consecutive frames are far apart.
        let order: Vec<_> = (0..4).map(|i| Interleave::nth(2, i).phase).collect();
        assert_eq!(order, [(0, 0), (1, 1), (1, 0), (0, 1)]);
        // At step 4 the first four frames spread over the block's quadrants.
        let first: Vec<_> = (0..4).map(|i| Interleave::nth(4, i).phase).collect();
        assert_eq!(first, [(0, 0), (2, 2), (2, 0), (0, 2)]);
    }

    #[test]
    fn steps_and_phases_outside_the_range_are_refused() {
        let bad = [
            Interleave {
                step: 3,
                phase: (0, 0),
                window: None,
            },
            Interleave {
                step: 2,
                phase: (2, 0),
                window: None,
            },
            Interleave {
                step: 0,
                phase: (0, 0),
                window: None,
            },
            // A window must start its rows at a multiple of 16, lie in the frame, take
            // step 1.
            Interleave::window([0, 8, 10, 20]),
            Interleave::window([0, 0, 70, 20]),
            Interleave::window([5, 0, 5, 20]),
            Interleave {
                step: 2,
                ..Interleave::window([0, 0, 10, 20])
            },
        ];
        for il in bad {
            let e = il.check(64, 32).unwrap_err().to_string();
            assert!(e.contains("interleave"), "{e}");
        }
        assert!(Interleave::window([3, 16, 40, 30]).check(64, 32).is_ok());
        assert_eq!(
            Interleave::nth(4, 5).word() & 0xff_ffff,
            4 | (3 << 8) | (3 << 16)
        );
        assert_eq!(
            Interleave::window([3, 16, 40, 30]).columns_word(),
            3 | (40 << 16)
        );
        assert_eq!(Interleave::nth(2, 1).columns_word(), 0);
    }
}
