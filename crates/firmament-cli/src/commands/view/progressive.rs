//! The reference path tracer in the viewer: the view traced progressively on a worker
//! thread (passes of a few paths per wavelength per pixel, each with its own random streams,
//! averaged), restarted whenever the camera, the light, the atmosphere or the size changes,
//! and shown beside the sky method's frame (the right half) or instead of it, so the fast
//! methods are compared with ground truth in place. The window never waits for it: each
//! frame shows the passes done so far.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use firmament::atmosphere::Model;
use firmament::reference::{self, ReferenceSettings};
use firmament::render::RenderSettings;
use firmament::scene::clouds::CloudMedium;
use firmament::scene::planet::PlanetSurface;
use firmament::scene::terrain::Heightfield;
use firmament::scene::{Camera, Light, Surface, Volume};

use super::difference::{difference, false_colour, FULL_SCALE};

/// Paths per wavelength per pixel in one pass (the tracer's smallest: two give a standard
/// error).
pub const PATHS_PER_PASS: usize = 2;

/// How the reference is shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compare {
    /// Not traced.
    #[default]
    Off,
    /// The right half of the view is the reference's.
    Split,
    /// The whole view is the reference's.
    Whole,
    /// The whole view is the method against the reference in false colour
    /// ([`super::difference::false_colour`]).
    Difference,
}

/// What a trace depends on: a change restarts it.
#[derive(Clone)]
pub struct Job {
    /// The atmosphere as the tracer sees it (the planet's own ground, not the tables'
    /// lifted one).
    pub model: Arc<Model>,
    /// The terrain the paths meet, if any.
    pub terrain: Option<Arc<Heightfield>>,
    /// The planet's surface map the paths meet (Lambertian), if any.
    pub planet: Option<Arc<PlanetSurface>>,
    /// The cloud layers the paths meet (delta tracking), if any.
    pub volumes: Option<Arc<Vec<CloudMedium>>>,
    /// The camera (its altitude already above the terrain).
    pub camera: Camera,
    /// The sun.
    pub sun: Light,
    /// The frame's size.
    pub size: (u32, u32),
    /// Whether the frame is white-balanced to the sun.
    pub white_balance: bool,
}

impl Job {
    fn same(&self, o: &Job) -> bool {
        self.model.hash == o.model.hash
            && self.camera == o.camera
            && self.sun.direction == o.sun.direction
            && self.sun.visible_disk == o.sun.visible_disk
            && self.size == o.size
            && self.white_balance == o.white_balance
            && self.terrain.as_ref().map(Arc::as_ptr) == o.terrain.as_ref().map(Arc::as_ptr)
            && self.volumes.as_ref().map(Arc::as_ptr) == o.volumes.as_ref().map(Arc::as_ptr)
            && self.planet.as_ref().map(Arc::as_ptr) == o.planet.as_ref().map(Arc::as_ptr)
    }
}

/// The average of the passes done for the current job.
#[derive(Clone, Debug, Default)]
pub struct Accumulated {
    /// The job's number (increases with every restart).
    pub generation: u64,
    /// Passes averaged.
    pub passes: usize,
    /// Per pixel, rows from the top: linear sRGB with Y in cd/m² and the mask (1 or 0), as
    /// the GPU's HDR frame holds them.
    pub pixels: Vec<f32>,
    /// Mean relative standard error of the pixels' luminance over the passes so far.
    pub noise: f64,
    /// Why the trace stopped, if it failed.
    pub error: Option<String>,
}

#[derive(Default)]
struct Shared {
    job: Mutex<Option<(u64, Job)>>,
    result: Mutex<Accumulated>,
    /// Set when the job changes (stops the pass in flight) or the viewer closes.
    cancel: AtomicBool,
    quit: AtomicBool,
}

/// The worker and what it shares with the viewer.
pub struct Progressive {
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
    generation: u64,
    current: Option<Job>,
}

impl Default for Progressive {
    fn default() -> Self {
        Progressive::new()
    }
}

impl Progressive {
    /// An idle tracer (its thread starts with the first job).
    pub fn new() -> Progressive {
        Progressive {
            shared: Arc::new(Shared::default()),
            worker: None,
            generation: 0,
            current: None,
        }
    }

    /// Trace `job` (restarting when it differs from the one in flight), or nothing.
    pub fn set(&mut self, job: Option<Job>) {
        let same = match (&self.current, &job) {
            (Some(a), Some(b)) => a.same(b),
            (None, None) => true,
            _ => false,
        };
        if same {
            return;
        }
        self.generation += 1;
        self.shared.cancel.store(true, Ordering::Relaxed);
        *self.shared.job.lock().expect("job lock") = job.clone().map(|j| (self.generation, j));
        self.current = job;
        if self.current.is_some() && self.worker.is_none() {
            let shared = self.shared.clone();
            self.worker = Some(std::thread::spawn(move || work(&shared)));
        }
    }

    /// The passes done for the current job (None before the first ends), their pixels
    /// left empty when they are those of `have` (a (generation, passes) mark already taken):
    /// a frame loop copies the image once a pass.
    pub fn latest(&self, have: Option<(u64, usize)>) -> Option<Accumulated> {
        let r = self.shared.result.lock().expect("result lock");
        if self.current.is_none()
            || r.generation != self.generation
            || (r.passes == 0 && r.error.is_none())
        {
            return None;
        }
        let pixels = if have == Some((r.generation, r.passes)) {
            Vec::new()
        } else {
            r.pixels.clone()
        };
        Some(Accumulated {
            generation: r.generation,
            passes: r.passes,
            pixels,
            noise: r.noise,
            error: r.error.clone(),
        })
    }

    /// Passes averaged for the current job (0 before the first).
    pub fn passes(&self) -> usize {
        let r = self.shared.result.lock().expect("result lock");
        if self.current.is_some() && r.generation == self.generation {
            r.passes
        } else {
            0
        }
    }
}

impl Drop for Progressive {
    fn drop(&mut self) {
        self.shared.quit.store(true, Ordering::Relaxed);
        self.shared.cancel.store(true, Ordering::Relaxed);
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}

/// The worker: passes of the current job until it changes; idle without one.
fn work(shared: &Shared) {
    let mut sums: Vec<f64> = Vec::new();
    let mut noise_sum = 0.0;
    let mut running: Option<(u64, Job)> = None;
    let mut pass = 0usize;
    while !shared.quit.load(Ordering::Relaxed) {
        let asked = shared.job.lock().expect("job lock").clone();
        if asked.as_ref().map(|(g, _)| *g) != running.as_ref().map(|(g, _)| *g) {
            shared.cancel.store(false, Ordering::Relaxed);
            running = asked;
            pass = 0;
            sums.clear();
            noise_sum = 0.0;
        }
        let Some((generation, job)) = &running else {
            std::thread::sleep(std::time::Duration::from_millis(20));
            continue;
        };
        match trace_pass(job, pass as u64, &shared.cancel) {
            Ok((pixels, noise)) => {
                if sums.is_empty() {
                    sums = vec![0.0; pixels.len()];
                }
                for (s, p) in sums.iter_mut().zip(&pixels) {
                    *s += *p as f64;
                }
                pass += 1;
                noise_sum += noise;
                let n = pass as f64;
                let mut r = shared.result.lock().expect("result lock");
                *r = Accumulated {
                    generation: *generation,
                    passes: pass,
                    pixels: sums.iter().map(|s| (s / n) as f32).collect(),
                    // Independent passes: the mean's error falls as 1/√passes.
                    noise: noise_sum / n / n.sqrt(),
                    error: None,
                };
            }
            Err(firmament::Error::Interrupted) => {}
            Err(e) => {
                *shared.result.lock().expect("result lock") = Accumulated {
                    generation: *generation,
                    error: Some(e.to_string()),
                    ..Default::default()
                };
                // Wait for another job.
                while shared
                    .job
                    .lock()
                    .expect("job lock")
                    .as_ref()
                    .map(|(g, _)| *g)
                    == Some(*generation)
                    && !shared.quit.load(Ordering::Relaxed)
                {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
            }
        }
    }
}

/// One pass: the frame at [`PATHS_PER_PASS`] paths per wavelength with the pass's random
/// streams; its pixels (RGBA as the HDR frame) and its mean relative noise.
fn trace_pass(job: &Job, pass: u64, cancel: &AtomicBool) -> firmament::Result<(Vec<f32>, f64)> {
    // The map's sphere lies on the ground sphere and wins the tie (after the terrain).
    let surfaces: Vec<Box<dyn Surface + '_>> = (job.terrain.iter())
        .map(|t| Box::new(t.as_ref()) as Box<dyn Surface + '_>)
        .chain(job.planet.iter().map(|p| Box::new(p.as_ref()) as _))
        .collect();
    let volumes: Vec<Box<dyn Volume + '_>> = job
        .volumes
        .iter()
        .flat_map(|v| v.iter())
        .map(|c| Box::new(c) as _)
        .collect();
    let settings = RenderSettings {
        camera: &job.camera,
        width: job.size.0 as usize,
        height: job.size.1 as usize,
        white_balance: job.white_balance,
    };
    let reference = ReferenceSettings {
        seed: 0x5eed_0000 + pass,
        ..ReferenceSettings::with_samples(PATHS_PER_PASS)
    };
    let (frame, noise) = reference::render_frame(
        &job.model,
        &volumes,
        &surfaces,
        &settings,
        &job.sun,
        &reference,
        &|_| {},
        Some(cancel),
    )?;
    let pixels = frame
        .image
        .data
        .iter()
        .zip(&frame.mask)
        .flat_map(|(p, &m)| [p[0], p[1], p[2], if m { 1.0 } else { 0.0 }])
        .collect();
    Ok((pixels, noise))
}

/// The reference's passes on the device: uploaded when a pass ends, copied over the sky
/// method's HDR frame (its right half, or all of it) before the display pass.
#[derive(Default)]
pub struct Overlay {
    /// The tracer.
    pub tracer: Progressive,
    /// The latest average on the device, its size, and which (generation, passes) it is.
    buffer: Option<(wgpu::Buffer, (u32, u32))>,
    uploaded: Option<(u64, usize)>,
    /// What the panel says about it.
    pub line: Option<String>,
    /// Why it is not traced (refused for this view, or failed), when so.
    pub refused: Option<String>,
    /// The method's frame copied when a pass was uploaded (read after the submission),
    /// and the pass's pixels it is compared with.
    method_copy: Option<wgpu::Buffer>,
    compare_with: Option<Vec<f32>>,
    /// The method against the reference over the frame when the last pass arrived: the
    /// mean luminance's relative difference and the mean relative |ΔL| per pixel.
    difference: Option<(f64, f64)>,
    /// What [`Overlay::cover`] copies over the frame this time (None: nothing).
    cover: Option<Compare>,
    /// How the reference was shown last frame, and what the device buffer holds: the
    /// reference's average (split, whole) or the false colour (difference).
    mode: Compare,
    holds: Option<Compare>,
    /// A false-colour image made after the last submission, to upload.
    false_colour: Option<Vec<f32>>,
}

impl Overlay {
    /// Trace `job` when `compare` asks for the reference (else stop) and upload a newly
    /// ended pass, recording a copy of the method's frame `hdr` (of `size`) as it is now for
    /// the comparison (call it right after the sky's dispatch, before the points are added:
    /// the tracer draws disks its own way); [`Overlay::cover`] then records the overwrite.
    pub fn encode(
        &mut self,
        ctx: &firmament_gpu::GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        hdr: &wgpu::Buffer,
        size: (u32, u32),
        compare: Compare,
        job: Result<Job, String>,
    ) {
        self.refused = None;
        self.cover = None;
        let job = match (compare, job) {
            (Compare::Off, _) => {
                self.difference = None;
                self.tracer.set(None);
                self.line = None;
                return;
            }
            (_, Err(why)) => {
                self.tracer.set(None);
                self.line = Some(format!("reference: {why}"));
                self.refused = Some(why);
                return;
            }
            (_, Ok(job)) => job,
        };
        self.tracer.set(Some(job));
        if compare != self.mode {
            // The buffer holds the other kind of image: the pass is taken again.
            self.mode = compare;
            self.uploaded = None;
            self.holds = None;
            self.false_colour = None;
        }
        let Some(latest) = self.tracer.latest(self.uploaded) else {
            self.line =
                Some("reference: tracing its first pass (the method's frame meanwhile)".into());
            return;
        };
        if let Some(e) = &latest.error {
            self.line = Some(format!("reference: {e}"));
            self.refused = Some(e.clone());
            return;
        }
        let bytes = size.0 as u64 * size.1 as u64 * firmament_gpu::PIXEL_BYTES;
        if self.buffer.as_ref().is_none_or(|(_, s)| *s != size) {
            let buffer = ctx.device().create_buffer(&wgpu::BufferDescriptor {
                label: Some("reference frame"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.buffer = Some((buffer, size));
            self.uploaded = None;
            self.holds = None;
            self.false_colour = None;
        }
        let (buffer, _) = self.buffer.as_ref().expect("just made");
        if let Some(image) = self.false_colour.take() {
            if image.len() as u64 * 4 == bytes {
                ctx.queue()
                    .write_buffer(buffer, 0, bytemuck::cast_slice(&image));
                self.holds = Some(Compare::Difference);
            }
        }
        let mark = (latest.generation, latest.passes);
        if self.uploaded != Some(mark) && latest.pixels.len() as u64 * 4 == bytes {
            if compare != Compare::Difference {
                ctx.queue()
                    .write_buffer(buffer, 0, bytemuck::cast_slice(&latest.pixels));
                self.holds = Some(compare);
            }
            self.uploaded = Some(mark);
            // The method's frame of the same view, before the reference covers it: compared
            // once the frame is submitted (`Overlay::submitted`).
            let copy = ctx.device().create_buffer(&wgpu::BufferDescriptor {
                label: Some("method frame for the reference"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            encoder.copy_buffer_to_buffer(hdr, 0, &copy, 0, bytes);
            self.method_copy = Some(copy);
            self.compare_with = Some(latest.pixels);
        }
        self.line = Some(format!(
            "reference{}: {} passes, {} paths/λ a pixel, noise {:.1} %{}",
            match compare {
                Compare::Split => " (right half)".to_string(),
                Compare::Difference => format!(
                    " (the method against it: red brighter, blue darker, full at ±{:.0} %)",
                    100.0 * FULL_SCALE
                ),
                _ => String::new(),
            },
            latest.passes,
            latest.passes * PATHS_PER_PASS,
            100.0 * latest.noise,
            match self.difference {
                Some((bias, mean_abs)) => format!(
                    "; the method against it over the frame (the disks apart): mean luminance {:+.2} %, mean |ΔL|/L {:.2} % (its noise included)",
                    100.0 * bias,
                    100.0 * mean_abs
                ),
                None => String::new(),
            }
        ));
        self.cover = self.holds.filter(|&h| h == compare);
    }

    /// Record the reference's average over the frame (its right half, or all of it), after
    /// [`Overlay::encode`] and the passes that add to the method's frame (the points).
    pub fn cover(&self, encoder: &mut wgpu::CommandEncoder, hdr: &wgpu::Buffer, size: (u32, u32)) {
        let (Some(compare), Some((buffer, _))) = (self.cover, &self.buffer) else {
            return;
        };
        let px = firmament_gpu::PIXEL_BYTES;
        let (w, h) = (size.0 as u64, size.1 as u64);
        match compare {
            Compare::Whole | Compare::Difference => {
                encoder.copy_buffer_to_buffer(buffer, 0, hdr, 0, w * h * px)
            }
            Compare::Split => {
                // Row by row, the columns from the middle on.
                let from = w / 2;
                for y in 0..h {
                    let offset = (y * w + from) * px;
                    encoder.copy_buffer_to_buffer(buffer, offset, hdr, offset, (w - from) * px);
                }
            }
            Compare::Off => {}
        }
    }
}

impl Overlay {
    /// [`FramePath::reference_difference`](super::frame_path::FramePath::reference_difference).
    pub fn difference(&self) -> Option<(f64, f64)> {
        self.difference
    }

    /// After the frame [`Overlay::encode`] recorded is submitted: when it copied the
    /// method's frame for a new pass, read it (waiting for the device, once a pass) and
    /// compare it with the pass's average over the pixels inside the projection.
    pub fn submitted(&mut self, ctx: &firmament_gpu::GpuContext) {
        let (Some(copy), Some(reference)) = (self.method_copy.take(), self.compare_with.take())
        else {
            return;
        };
        let slice = copy.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        if ctx
            .device()
            .poll(wgpu::PollType::wait_indefinitely())
            .is_err()
        {
            return;
        }
        let Ok(view) = slice.get_mapped_range() else {
            return;
        };
        let method: Vec<f32> = view
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        drop(view);
        copy.unmap();
        self.difference = difference(&method, &reference);
        if self.mode == Compare::Difference {
            self.false_colour = Some(false_colour(&method, &reference));
        }
    }
}
