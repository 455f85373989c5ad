//! The benchmark frames: cameras, image sizes and the sun, the same on the CPU and the GPU.

use firmament::math::Vec3;
use firmament::render::RenderSettings;
use firmament::scene::{sun_direction, Camera, Projection};

/// One benchmark frame: a camera, an image size and how many runs it is worth at most.
pub struct BenchFrame {
    pub camera: Camera,
    pub width: usize,
    pub height: usize,
    /// Runs at most (a large frame is timed fewer times than `--runs`).
    pub max_runs: usize,
}

impl BenchFrame {
    /// A frame from a benchmark camera: heading 200°, 60° field of view.
    fn new(projection: Projection, altitude_m: f64, pitch_deg: f64, size: (usize, usize)) -> Self {
        BenchFrame {
            camera: Camera {
                projection,
                altitude_m,
                heading_deg: 200.0,
                pitch_deg,
                roll_deg: 0.0,
                fov_deg: 60.0,
            },
            width: size.0,
            height: size.1,
            max_runs: usize::MAX,
        }
    }

    /// The render settings of the frame (no white balance).
    pub fn settings(&self) -> RenderSettings<'_> {
        RenderSettings {
            camera: &self.camera,
            width: self.width,
            height: self.height,
            white_balance: false,
        }
    }

    /// The runs to time for `--runs runs`.
    pub fn runs(&self, runs: usize) -> usize {
        runs.min(self.max_runs)
    }
}

/// 1920×1080 from 1.5 km: half sky, half ground with aerial perspective, the sun in view
/// (the CPU and GPU frame benchmarks).
pub fn perspective_1080p() -> BenchFrame {
    BenchFrame::new(Projection::Perspective, 1500.0, 20.0, (1920, 1080))
}

/// The 1024×1024 all-sky fisheye from the ground.
pub fn fisheye_1024() -> BenchFrame {
    BenchFrame::new(Projection::Fisheye, 2.0, 0.0, (1024, 1024))
}

/// The 4096×2048 equirectangular map from the ground, at most 3 runs.
pub fn equirect_4096x2048() -> BenchFrame {
    BenchFrame {
        max_runs: 3,
        ..BenchFrame::new(Projection::Equirect, 2.0, 0.0, (4096, 2048))
    }
}

/// The sun of every benchmark frame: 60° from the zenith at azimuth 200°, disk drawn.
pub fn sun() -> Vec3 {
    sun_direction(60.0, 200.0)
}

/// The night of the night benchmark frame: a full moon 38° high in the east over the Alps,
/// 2026-01-03 20:00 UTC, 46.5° N, 8° E.
pub fn night() -> firmament::Result<firmament::astro::Sky> {
    use firmament::astro::{Instant, Place, Sky, Weather};
    let instant = Instant::parse("2026-01-03T20:00:00Z", "time")?;
    Sky::at(instant, Place::new(46.5, 8.0, 0.0)?, &Weather::default())
}
