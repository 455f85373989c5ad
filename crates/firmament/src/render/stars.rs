//! Point lights outside the atmosphere (the stars, and lights' disks smaller than a few
//! pixels) drawn into a frame: each point's irradiance, extinguished along its line of
//! sight, spread over the four pixels around its position with bilinear weights that sum to
//! one, each share divided by its pixel's solid angle, so a point's energy in the image is
//! its irradiance whatever the resolution.

use crate::io::ImageRgbF32;
use crate::scene::sky_lights::PointSource;
use crate::scene::{PreparedCamera, Ray, Scene};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::ColourMatrix;

/// Adds `points` to `image` (linear sRGB, Y in cd/m², times `balance`), seen from
/// `observer` through `view`'s transmittance and hidden by `scene`'s surfaces.
pub(super) fn draw_points<'p>(
    points: impl IntoIterator<Item = &'p PointSource>,
    scene: &Scene,
    view: &dyn SkyView,
    camera: &PreparedCamera,
    observer: crate::math::Vec3,
    colour: &ColourMatrix,
    balance: [f64; 3],
    image: &mut ImageRgbF32,
    mask: &[bool],
) {
    let n = scene.sky.model().channels();
    let (w, h) = (image.width, image.height);
    let (mut radiance, mut t, mut e) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for star in points {
        let Some((px, py)) = camera.pixel_of(star.direction) else {
            continue;
        };
        let ray = Ray {
            origin: observer,
            dir: star.direction,
        };
        if scene.nearest_hit(&ray, f64::INFINITY).is_some() {
            continue;
        }
        view.sky_radiance(star.direction, Shadow::None, &mut radiance, &mut t);
        for k in 0..n {
            e[k] = star.irradiance[k] * t[k];
        }
        let c = colour.to_srgb(&e);
        let (fx, fy) = (px - 0.5, py - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (ax, ay) = (fx - x0, fy - y0);
        for (dx, dy, weight) in [
            (0, 0, (1.0 - ax) * (1.0 - ay)),
            (1, 0, ax * (1.0 - ay)),
            (0, 1, (1.0 - ax) * ay),
            (1, 1, ax * ay),
        ] {
            let (x, y) = (x0 as i64 + dx, y0 as i64 + dy);
            if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 || weight <= 0.0 {
                continue;
            }
            let (x, y) = (x as usize, y as usize);
            let omega = camera.pixel_solid_angle(x, y);
            if !mask[y * w + x] || omega <= 0.0 {
                continue;
            }
            let p = &mut image.data[y * w + x];
            for i in 0..3 {
                p[i] += (c[i] * balance[i] * weight / omega) as f32;
            }
        }
    }
}

/// The lights whose drawn disks would cover fewer than four pixels where they stand: their
/// index and their light as a point (a disk that small, sampled at pixel centres, would
/// flicker in and out of the image; as a point its energy is kept).
pub(super) fn small_disks(
    scene: &Scene,
    camera: &PreparedCamera,
    width: usize,
    height: usize,
) -> Vec<(usize, PointSource)> {
    let mut out = Vec::new();
    for (i, light) in scene.lights.iter().enumerate() {
        if !light.visible_disk {
            continue;
        }
        let Some((px, py)) = camera.pixel_of(light.direction) else {
            continue;
        };
        let (x, y) = ((px as usize).min(width - 1), (py as usize).min(height - 1));
        let disk = std::f64::consts::PI * light.angular_radius_rad.sin().powi(2);
        if disk < 4.0 * camera.pixel_solid_angle(x, y) {
            out.push((
                i,
                PointSource {
                    direction: light.direction,
                    irradiance: light.irradiance.clone(),
                },
            ));
        }
    }
    out
}
