//! Point lights outside the atmosphere (the stars, and lights' disks smaller than a few
//! pixels) drawn into a frame: each point's irradiance, extinguished along its line of
//! sight, spread over the four pixels around its position with bilinear weights that sum to
//! one, each share divided by its pixel's solid angle, so a point's energy in the image is
//! its irradiance whatever the resolution.

use crate::atmosphere::Model;
use crate::io::ImageRgbF32;
use crate::math::sphere::ray_intersects_ground;
use crate::math::Vec3;
use crate::scene::sky_lights::PointSource;
use crate::scene::{Light, PreparedCamera, Ray, Scene, Surface};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::ColourMatrix;

/// How the points are seen: the transmittance from the observer to space along a
/// direction (per channel, 0 where the direction is blocked), and the image's frame.
pub struct PointView<'a> {
    /// Transmittance to space along a unit direction (local frame), into the slice.
    pub transmittance: &'a dyn Fn(Vec3, &mut [f64]),
    /// The camera of the image.
    pub camera: &'a PreparedCamera,
    /// The image's colour conversion and white balance.
    pub colour: &'a ColourMatrix,
    /// Factors per linear sRGB channel.
    pub balance: [f64; 3],
}

/// Adds `points` to `image` (linear sRGB, Y in cd/m², times `balance`) as `view` sees them;
/// `channels` is the points' number of channels.
pub fn draw_points<'p>(
    points: impl IntoIterator<Item = &'p PointSource>,
    channels: usize,
    view: &PointView,
    image: &mut ImageRgbF32,
    mask: &[bool],
) {
    let (w, h) = (image.width, image.height);
    splat_points(points, channels, view, (w, h), &mut |i, c| {
        if mask[i] {
            let p = &mut image.data[i];
            for k in 0..3 {
                p[k] += c[k];
            }
        }
    });
}

/// Each point's share of each pixel of a `size` image as `view` sees it: `add(pixel index,
/// linear sRGB radiance in cd/m² terms)` for the four pixels around the point, bilinear
/// weights summing to one, each share over its pixel's solid angle.
pub fn splat_points<'p>(
    points: impl IntoIterator<Item = &'p PointSource>,
    channels: usize,
    view: &PointView,
    (w, h): (usize, usize),
    add: &mut dyn FnMut(usize, [f32; 3]),
) {
    let (camera, colour, balance) = (view.camera, view.colour, view.balance);
    let n = channels;
    let (mut t, mut e) = (vec![0.0; n], vec![0.0; n]);
    for star in points {
        let Some((px, py)) = camera.pixel_of(star.direction) else {
            continue;
        };
        (view.transmittance)(star.direction, &mut t);
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
            if omega <= 0.0 {
                continue;
            }
            let share = |i: usize| (c[i] * balance[i] * weight / omega) as f32;
            add(y * w + x, [share(0), share(1), share(2)]);
        }
    }
}

/// The lights whose drawn disks would cover fewer than four pixels where they stand: their
/// index and their light as a point (a disk that small, sampled at pixel centres, would
/// flicker in and out of the image; as a point its energy is kept).
pub fn small_disks(
    lights: &[Light],
    camera: &PreparedCamera,
    width: usize,
    height: usize,
) -> Vec<(usize, PointSource)> {
    let mut out = Vec::new();
    for (i, light) in lights.iter().enumerate() {
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

/// In `scene` through `sky_view`: the sky method's transmittance to space, zero where a
/// surface blocks the direction.
pub(super) fn scene_transmittance(
    scene: &Scene,
    sky_view: &dyn SkyView,
    observer: Vec3,
    dir: Vec3,
    out: &mut [f64],
) {
    let ray = Ray {
        origin: observer,
        dir,
    };
    if scene.nearest_hit(&ray, f64::INFINITY).is_some() {
        out.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    crate::spectrum::with_channel_buffers(out.len(), |[radiance]| {
        sky_view.sky_radiance(dir, Shadow::None, radiance, out)
    });
}

/// Transmittance from `observer` (planet-centred, m) to space along `dir`, from `model`'s
/// columns (no tables; 0 when the planet's ground is in the way): for frames drawn where
/// no CPU tables are at hand (the GPU's).
pub fn transmittance_to_space(model: &Model, observer: Vec3, dir: Vec3, out: &mut [f64]) {
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let mut r = observer.length();
    let mut rmu = observer.dot(dir);
    if r > top {
        match crate::math::sphere::distance_to_enter_sphere(r, rmu, top) {
            Some(d) => {
                rmu += d;
                r = top;
            }
            None => {
                out.iter_mut().for_each(|v| *v = 1.0);
                return;
            }
        }
    }
    let mu = (rmu / r).clamp(-1.0, 1.0);
    if ray_intersects_ground(r, mu, bottom) {
        out.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    let length = crate::math::sphere::distance_to_top_atmosphere_boundary(r, mu, top);
    let tau = model.optical_depth_along_ray(r, mu, length);
    for (o, t) in out.iter_mut().zip(tau) {
        *o = (-t).exp();
    }
}

/// Adds `points` to `frame`, rendered elsewhere (the GPU) with `settings` for `model`, seen
/// through the model's own transmittance ([`transmittance_to_space`]), hidden where one of
/// `occluders` (the terrain) is in the way.
pub fn draw_points_into(
    frame: &mut super::Frame,
    points: &[PointSource],
    model: &Model,
    settings: &super::RenderSettings,
    occluders: &[&dyn Surface],
) {
    let super::Frame { image, mask } = frame;
    with_point_view(model, settings, occluders, &mut |view| {
        draw_points(points, model.channels(), view, image, mask)
    });
}

/// [`draw_points_into`]'s additions without a frame: per pixel touched (once each, in
/// increasing index), the linear sRGB to add, for a frame that stays on the device (the
/// viewer's: `firmament_gpu::render::stars` adds them there). Pixels outside the
/// projection are the caller's to skip (the GPU frame's mask).
pub fn point_splats(
    points: &[PointSource],
    model: &Model,
    settings: &super::RenderSettings,
    occluders: &[&dyn Surface],
) -> Vec<(u32, [f32; 3])> {
    let mut adds: Vec<(u32, [f32; 3])> = Vec::new();
    let size = (settings.width, settings.height);
    with_point_view(model, settings, occluders, &mut |view| {
        splat_points(points, model.channels(), view, size, &mut |i, c| {
            adds.push((i as u32, c))
        })
    });
    // One entry per pixel: the GPU adds them without two threads on one pixel.
    adds.sort_by_key(|(i, _)| *i);
    let mut merged: Vec<(u32, [f32; 3])> = Vec::with_capacity(adds.len());
    for (i, c) in adds {
        match merged.last_mut() {
            Some((j, m)) if *j == i => (0..3).for_each(|k| m[k] += c[k]),
            _ => merged.push((i, c)),
        }
    }
    merged
}

/// The [`PointView`] of a frame drawn elsewhere: the model's transmittance to space from the
/// camera, zero behind `occluders`.
fn with_point_view(
    model: &Model,
    settings: &super::RenderSettings,
    occluders: &[&dyn Surface],
    then: &mut dyn FnMut(&PointView),
) {
    let (w, h) = (settings.width, settings.height);
    let camera = settings.camera.prepare(model.bottom_radius_m, w, h);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + settings.camera.altitude_m);
    let colour = model.colour_matrix();
    let transmittance = |dir: Vec3, out: &mut [f64]| {
        let ray = Ray {
            origin: observer,
            dir,
        };
        if occluders
            .iter()
            .any(|s| s.intersect(&ray, f64::INFINITY).is_some())
        {
            out.iter_mut().for_each(|v| *v = 0.0);
            return;
        }
        transmittance_to_space(model, observer, dir, out)
    };
    let view = PointView {
        transmittance: &transmittance,
        camera: &camera,
        colour: &colour,
        balance: colour.white_balance(&model.solar_irradiance, settings.white_balance),
    };
    then(&view);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Frame, RenderSettings};
    use crate::scene::camera::{Camera, Projection};
    use crate::spectrum::Wavelengths;

    #[test]
    fn the_sparse_splats_are_the_frames_additions_once_per_pixel() {
        let model = crate::atmosphere::Atmosphere::earth()
            .resolve(&Wavelengths::parse("rgb").unwrap())
            .unwrap();
        let camera = Camera {
            projection: Projection::Perspective,
            altitude_m: 10.0,
            heading_deg: 0.0,
            pitch_deg: 30.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
        };
        let settings = RenderSettings {
            camera: &camera,
            width: 40,
            height: 30,
            white_balance: false,
        };
        // Points on a grid of directions, some sharing pixels, some out of view.
        let mut points = Vec::new();
        for i in 0..200 {
            let (az, el) = (i as f64 * 0.071, 0.05 + (i % 17) as f64 * 0.06);
            let d = Vec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin());
            points.push(PointSource {
                direction: d,
                irradiance: vec![1e-6 * (1 + i % 5) as f64; 3],
            });
            points.push(PointSource {
                direction: d,
                irradiance: vec![2e-7; 3],
            });
        }
        let mut frame = Frame {
            image: ImageRgbF32::new(40, 30),
            mask: vec![true; 1200],
        };
        draw_points_into(&mut frame, &points, &model, &settings, &[]);
        let splats = point_splats(&points, &model, &settings, &[]);
        assert!(
            splats.windows(2).all(|p| p[0].0 < p[1].0),
            "one entry per pixel, in order"
        );
        let mut sparse = ImageRgbF32::new(40, 30);
        for (i, c) in &splats {
            sparse.data[*i as usize] = *c;
        }
        let mut touched = 0;
        for (a, b) in frame.image.data.iter().zip(&sparse.data) {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-6 * a[k].abs().max(1e-30),
                    "{a:?} {b:?}"
                );
            }
            touched += (a[1] > 0.0) as usize;
        }
        assert_eq!(touched, splats.len());
        assert!(touched > 20, "{touched}");
    }
}
