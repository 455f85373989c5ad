//! The lights' disks over each pixel's footprint. A pixel is one ray through its centre,
//! which samples a disk of a few pixels badly: its irradiance comes out as the count of
//! centres that fall inside it (a sun 6 pixels wide in a 4096-wide map read 6 % low). A
//! pixel whose footprint straddles a disk's edge is therefore the mean of
//! [`SUBSAMPLES`]² rays spread over it (the limb-darkened disk weighed by the share of the
//! pixel it covers, and the sky or a silhouette around it); inside or outside a disk a pixel
//! stays one ray. Disks smaller than four pixels are points instead (`stars::small_disks`).
//! The WGSL twin is `shaders/render/disk_edges.wgsl`.

use crate::math::Vec3;
use crate::scene::{Light, PreparedCamera};

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
