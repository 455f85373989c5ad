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
    let (camera, colour, balance) = (view.camera, view.colour, view.balance);
    let n = channels;
    let (w, h) = (image.width, image.height);
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
    let super::Frame { image, mask } = frame;
    draw_points(points, model.channels(), &view, image, mask);
}
