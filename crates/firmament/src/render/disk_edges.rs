//! The lights' disks over each pixel's footprint. A pixel is one ray through its centre,
//! which samples a disk of a few pixels badly: its irradiance comes out as the count of
//! centres that fall inside it (a sun 6 pixels wide in a 4096-wide map read 6 % low). A
//! pixel whose footprint straddles a disk's edge is therefore the mean of
//! [`SUBSAMPLES`]² rays spread over it (the limb-darkened disk weighed by the share of the
//! pixel it covers, and the sky or a silhouette around it); inside or outside a disk a pixel
//! stays one ray. Disks smaller than four pixels are points instead (`stars::small_disks`).
//! The WGSL twin is `shaders/render/disk_edges.wgsl`.

use crate::math::Vec3;
use crate::render::{Frame, RenderSettings, ShadeScratch, Shader};
use crate::scene::{Light, PreparedCamera, Ray, Scene};
use crate::Result;

/// Sub-pixel rays per side on a disk's edge.
pub const SUBSAMPLES: usize = 8;

/// A pixel straddles a disk's edge when its centre lies within this many footprints (the
/// square root of its solid angle) of the edge: its corners are 0.71 footprint away.
pub const EDGE_FOOTPRINTS: f64 = 1.0;

/// The drawn disks of a frame and where their edges may lie.
pub struct DiskEdges {
    /// Per disk: direction, angular radius (rad), and the cosine of its radius plus
    /// [`EDGE_FOOTPRINTS`] of the frame's largest footprint (no pixel centre farther than
    /// that straddles its edge).
    disks: Vec<(Vec3, f64, f64)>,
}

/// An upper bound on the frame's pixel footprints (rad): twice the largest over a 17 × 17
/// grid of pixels (footprints change slowly across every projection).
pub fn max_footprint_rad(camera: &PreparedCamera, width: usize, height: usize) -> f64 {
    let mut max: f64 = 0.0;
    for j in 0..17 {
        for i in 0..17 {
            let x = (i * (width - 1)) / 16;
            let y = (j * (height - 1)) / 16;
            max = max.max(camera.pixel_solid_angle(x, y).sqrt());
        }
    }
    2.0 * max
}

impl DiskEdges {
    /// The edges of `lights[i]` for each index in `drawn` on a frame of `camera`.
    pub fn new(
        lights: &[Light],
        drawn: impl Iterator<Item = usize>,
        camera: &PreparedCamera,
        width: usize,
        height: usize,
    ) -> DiskEdges {
        let f = max_footprint_rad(camera, width, height);
        let disks = drawn
            .map(|i| {
                let l = &lights[i];
                let a = l.angular_radius_rad;
                let outer = (a + EDGE_FOOTPRINTS * f).min(std::f64::consts::PI);
                (l.direction, a, outer.cos())
            })
            .collect();
        DiskEdges { disks }
    }

    /// Whether pixel (x, y), whose centre ray is `dir`, straddles a disk's edge.
    pub fn straddles(&self, camera: &PreparedCamera, x: usize, y: usize, dir: Vec3) -> bool {
        let mut footprint = None;
        for &(l, a, cos_outer) in &self.disks {
            let c = dir.dot(l);
            if c < cos_outer {
                continue;
            }
            let f = *footprint.get_or_insert_with(|| camera.pixel_solid_angle(x, y).sqrt());
            let angle = dir.cross(l).length().atan2(c);
            if (angle - a).abs() < EDGE_FOOTPRINTS * f {
                return true;
            }
        }
        false
    }
}

/// The sub-pixel offsets of a pixel's [`SUBSAMPLES`]² rays (from its top-left corner, in
/// pixels): the centres of a regular grid.
pub fn subpixels() -> impl Iterator<Item = (f64, f64)> {
    let n = SUBSAMPLES;
    (0..n * n).map(move |k| {
        (
            ((k % n) as f64 + 0.5) / n as f64,
            ((k / n) as f64 + 0.5) / n as f64,
        )
    })
}

/// What a frame carries of `scene.lights[light]`'s disk, and what it should: the frame's
/// luminance minus the sky's without disks along each pixel's centre ray, times the
/// pixel's solid angle, summed over the pixels within three footprints of the disk (lux);
/// and the light's direct normal illuminance at the observer (its irradiance times the
/// transmittance to it). The two agree when the disk is drawn with its whole light.
pub fn disk_illuminance(
    frame: &Frame,
    scene: &Scene,
    settings: &RenderSettings,
    light: usize,
) -> Result<(f64, f64)> {
    let model = scene.sky.model();
    let (width, height) = (settings.width, settings.height);
    let camera = settings.camera;
    let prepared = camera.prepare(model.bottom_radius_m, width, height);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + camera.altitude_m);
    let plain = Shader::plain(scene, observer)?.without_disks();
    let colour = model.colour_matrix();
    let mut scratch = ShadeScratch::default();
    let y = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let l = &scene.lights[light];
    let mut sum = 0.0;
    let mut sky = vec![0.0; model.channels()];
    for j in 0..height {
        for i in 0..width {
            let Some(ray) = prepared.ray(i as f64 + 0.5, j as f64 + 0.5) else {
                continue;
            };
            // Within a few footprints of the disk (a point's splat included).
            let footprint = prepared.pixel_solid_angle(i, j).sqrt();
            if ray.dir.dot(l.direction).clamp(-1.0, 1.0).acos()
                > l.angular_radius_rad + 3.0 * footprint
            {
                continue;
            }
            let centre = Ray {
                origin: observer,
                dir: ray.dir,
            };
            plain.shade(&centre, &mut scratch, &mut sky);
            let p = frame.image.data[j * width + i];
            let pixel = y([p[0] as f64, p[1] as f64, p[2] as f64]);
            sum += (pixel - y(colour.to_srgb(&sky))) * prepared.pixel_solid_angle(i, j);
        }
    }
    let view = scene.sky.view(observer, l);
    let mut t = vec![0.0; model.channels()];
    view.transmittance_to_light(observer, &mut t);
    let e: Vec<f64> = l.irradiance.iter().zip(&t).map(|(e, t)| e * t).collect();
    Ok((sum, colour.to_xyz(&e)[1]))
}
