//! Frames under clouds or over a terrain a quarter (or a sixteenth) of the pixels at a time
//! (`firmament_gpu::TemporalFrames`, the viewer's): against the full frame of the same
//! camera, drawn by `GpuRenderer` marching every pixel. With the camera still the k² phases
//! rebuild the full frame exactly; a turned camera reuses the previous frame reprojected,
//! a turned and raised one is closer to the full frame than this frame's pixels
//! interpolated alone; a reset forgets the history; a visible sun's disk is drawn whole
//! every frame. Cumulus from the ground and the valley's terrain, 96×56, RGB small tables.

mod common;

use firmament::math::Vec3;
use firmament::render::{Frame, RenderSettings, Shader};
use firmament::scene::clouds::{cloud_media, CloudKind, CloudLayerConfig, CloudNoise};
use firmament::scene::terrain::TerrainConfig;
use firmament::scene::{sun_direction, Camera, Light, Projection, Scene};
use firmament_gpu::{GpuClouds, GpuSky, GpuTerrain, RenderInputs, TemporalFrames};

use common::*;

const SIZE: (usize, usize) = (96, 56);

/// Mean relative luminance difference of two frames.
fn mean_rel(a: &Frame, b: &Frame) -> f64 {
    let n = a.image.data.len();
    (0..n)
        .map(|i| {
            let (x, y) = (luminance(&a.image.data[i]), luminance(&b.image.data[i]));
            (x - y).abs() / y.max(1e-9)
        })
        .sum::<f64>()
        / n as f64
}

/// The largest relative luminance difference of two frames.
fn max_rel(a: &Frame, b: &Frame) -> f64 {
    (0..a.image.data.len())
        .map(|i| {
            let (x, y) = (luminance(&a.image.data[i]), luminance(&b.image.data[i]));
            (x - y).abs() / y.max(1e-9)
        })
        .fold(0.0, f64::max)
}

/// Write `frame` as `DIR/name.png` when FIRMAMENT_TEST_PICTURES=DIR is set (to look at).
fn picture(name: &str, frame: &Frame) {
    if let Ok(dir) = std::env::var("FIRMAMENT_TEST_PICTURES") {
        let exposure = 0.18 / frame.log_average_luminance();
        let rgb = frame.to_srgb8(exposure, firmament::render::ToneCurve::Aces);
        let (w, h) = (frame.image.width, frame.image.height);
        firmament::io::write_png_srgb8(format!("{dir}/{name}.png"), w, h, &rgb).unwrap();
    }
}

/// What a frame takes besides the sky, for its lights (the clouds' or the terrain's uploads
/// are per light).
type Inputs<'a> = Box<dyn Fn(&[Light]) -> RenderInputs<'a> + 'a>;

struct Setup<'a> {
    gpu: &'static Gpu,
    sky: &'a GpuSky,
    inputs: Inputs<'a>,
}

impl Setup<'_> {
    fn settings(camera: &Camera) -> RenderSettings<'_> {
        RenderSettings {
            camera,
            width: SIZE.0,
            height: SIZE.1,
            white_balance: false,
        }
    }

    /// Every pixel marched.
    fn full(&self, camera: &Camera, lights: &[Light]) -> Frame {
        let settings = Self::settings(camera);
        (self.gpu.renderer)
            .render_with(
                &self.gpu.ctx,
                self.sky,
                lights,
                &settings,
                (self.inputs)(lights),
            )
            .unwrap()
    }

    /// `frames` temporal frames of `camera` into one output; the last one read back.
    fn temporal(
        &self,
        t: &mut TemporalFrames,
        camera: &Camera,
        lights: &[Light],
        frames: usize,
    ) -> Frame {
        let (ctx, renderer) = (&self.gpu.ctx, &self.gpu.renderer);
        let settings = Self::settings(camera);
        let output = renderer.frame_buffer(ctx, &settings);
        for _ in 0..frames {
            let mut encoder = ctx.device().create_command_encoder(&Default::default());
            let inputs = (self.inputs)(lights);
            t.encode(
                ctx,
                &mut encoder,
                renderer,
                self.sky,
                lights,
                &settings,
                &output,
                inputs,
            )
            .unwrap();
            ctx.queue().submit([encoder.finish()]);
        }
        renderer.read_frame(ctx, &output, SIZE.0, SIZE.1).unwrap()
    }
}

/// The share of the pixels `turned` did not draw (its phase (0, 0) at step 2) that equal
/// `before_frame` of `before` reprojected: bilinear at the pixel's direction in the previous
/// camera, found through `PreparedCamera::ray` independently of the shader, within 10⁻⁴.
fn reprojected_share(
    before: &Camera,
    turned: &Camera,
    before_frame: &Frame,
    turned_frame: &Frame,
    radius: f64,
) -> f64 {
    let (b, now) = (
        before.prepare(radius, SIZE.0, SIZE.1),
        turned.prepare(radius, SIZE.0, SIZE.1),
    );
    let (mut matched, mut undrawn) = (0, 0);
    for y in 0..SIZE.1 {
        for x in 0..SIZE.0 {
            if x % 2 == 0 && y % 2 == 0 {
                continue;
            }
            let dir = now.ray(x as f64 + 0.5, y as f64 + 0.5).unwrap().dir;
            // Where the previous camera saw `dir`: Newton steps on its ray through (px, py).
            let (mut px, mut py) = (x as f64 + 0.5, y as f64 + 0.5);
            for _ in 0..20 {
                let at = |px: f64, py: f64| b.ray(px, py).unwrap().dir;
                let (d, e) = (1e-3, at(px, py));
                let (dx, dy) = ((at(px + d, py) - e) / d, (at(px, py + d) - e) / d);
                let r = dir - e;
                // Least squares in the two image directions.
                let (a, bb, c) = (dx.dot(dx), dx.dot(dy), dy.dot(dy));
                let (p, q) = (dx.dot(r), dy.dot(r));
                let det = a * c - bb * bb;
                px += (c * p - bb * q) / det;
                py += (a * q - bb * p) / det;
            }
            let (cx, cy) = (px - 0.5, py - 0.5);
            let (x0, y0) = (cx.floor(), cy.floor());
            if x0 < 0.0 || y0 < 0.0 || x0 + 1.0 >= SIZE.0 as f64 || y0 + 1.0 >= SIZE.1 as f64 {
                continue;
            }
            let (fx, fy) = (cx - x0, cy - y0);
            let l = |i: f64, j: f64| {
                luminance(&before_frame.image.data[j as usize * SIZE.0 + i as usize])
            };
            let expected = (1.0 - fy) * ((1.0 - fx) * l(x0, y0) + fx * l(x0 + 1.0, y0))
                + fy * ((1.0 - fx) * l(x0, y0 + 1.0) + fx * l(x0 + 1.0, y0 + 1.0));
            let got = luminance(&turned_frame.image.data[y * SIZE.0 + x]);
            undrawn += 1;
            if (got - expected).abs() <= 1e-4 * expected {
                matched += 1;
            }
        }
    }
    matched as f64 / undrawn as f64
}

#[test]
fn interleaved_cloud_frames_converge_reproject_and_reset() {
    let Some(gpu) = gpu("interleaved_cloud_frames_converge_reproject_and_reset") else {
        return;
    };
    let _guard = serial();
    let sky = earth_rgb();
    let radius = sky.model.bottom_radius_m;
    let layer = CloudLayerConfig::of_kind(CloudKind::Cumulus);
    let (noise, _) = CloudNoise::new([32, 16], None).unwrap();
    let media = cloud_media(std::slice::from_ref(&layer), radius, (0.0, 0.0), &noise).unwrap();
    let lights_at = |zenith: f64| {
        let scene = Scene::clear_sky(sky, sun_direction(zenith, 200.0), false);
        scene.lights
    };
    let lights = lights_at(40.0);
    let camera = common::camera(Projection::Perspective, 2.0, 30.0, 25.0, 70.0);
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let upload = |zenith: f64| {
        let mut scene = Scene::clear_sky(sky, sun_direction(zenith, 200.0), false);
        scene.volumes.push(Box::new(&media[0]));
        let observer = Vec3::new(0.0, 0.0, radius + camera.altitude_m);
        let shader = Shader::new(&scene, observer).unwrap();
        GpuClouds::new(&gpu.ctx, &gpu_sky, &media, &shader).unwrap()
    };
    let (clouds, clouds_later) = (upload(40.0), upload(70.0));
    let later_sun = sun_direction(70.0, 200.0);
    let setup = Setup {
        gpu,
        sky: &gpu_sky,
        inputs: Box::new(|lights: &[Light]| RenderInputs {
            clouds: Some(if lights[0].direction == later_sun {
                &clouds_later
            } else {
                &clouds
            }),
            ..RenderInputs::default()
        }),
    };
    let full = setup.full(&camera, &lights);
    picture("full", &full);

    // The camera still: the first frame is a quarter marched, the rest interpolated; after
    // k² frames every pixel is its own march, the full frame to the bit.
    for step in [2, 4] {
        let mut t = TemporalFrames::new(&gpu.ctx, step).unwrap();
        let first = setup.temporal(&mut t, &camera, &lights, 1);
        picture(&format!("first-step{step}"), &first);
        let first_err = mean_rel(&first, &full);
        let converged = setup.temporal(&mut t, &camera, &lights, (step * step - 1) as usize);
        let err = max_rel(&converged, &full);
        assert_eq!(t.still_frames(), step * step);
        eprintln!(
            "step {step}: first frame mean {first_err:.3e} from the full frame; after {} frames the largest difference {err:.1e}",
            step * step
        );
        assert!(
            first_err > 1e-4,
            "the first frame is the full one: {first_err}"
        );
        assert_eq!(err, 0.0, "step {step}: not converged to the full frame");
        assert!(converged.mask.iter().all(|&m| m));
    }

    // The camera turned by 2.5 and 1.5 pixels' angles after converging: where the resolve
    // takes the history whole, its value is the previous frame's, bilinear at the pixel's
    // direction in the previous camera (found here through `PreparedCamera::ray`,
    // independently of the shader): 78 % of the undrawn pixels. The others are at depth
    // edges (a cloud against the sky, or clouds 30 % apart in depth: the bilinear taps of
    // another surface left out) or fell back to this frame's pixels.
    let mut t = TemporalFrames::new(&gpu.ctx, 2).unwrap();
    setup.temporal(&mut t, &camera, &lights, 4);
    let mut turned = camera.clone();
    turned.heading_deg += 2.5 * camera.fov_deg / SIZE.1 as f64;
    turned.pitch_deg -= 1.5 * camera.fov_deg / SIZE.1 as f64;
    let turned_frame = setup.temporal(&mut t, &turned, &lights, 1);
    assert_eq!(t.still_frames(), 1, "the camera moved");
    picture("turned-reprojected", &turned_frame);
    let share = reprojected_share(&camera, &turned, &full, &turned_frame, radius);
    eprintln!(
        "turned: {:.1} % of the undrawn pixels are the previous frame's, reprojected",
        100.0 * share
    );
    assert!(
        share > 0.7,
        "only {share} of the undrawn pixels reprojected"
    );

    // Then raised by 40 m as well: the history reprojected at the drawn pixels' depths is
    // closer to the full frame than this frame's pixels interpolated alone.
    let mut moved = turned.clone();
    moved.altitude_m += 40.0;
    let moved_full = setup.full(&moved, &lights);
    let mut t = TemporalFrames::new(&gpu.ctx, 2).unwrap();
    setup.temporal(&mut t, &camera, &lights, 4);
    let reprojected = setup.temporal(&mut t, &moved, &lights, 1);
    // (The fifth frame's phase is the first's, (0, 0): a fresh start's first frame draws
    // the same pixels.)
    let mut alone = TemporalFrames::new(&gpu.ctx, 2).unwrap();
    let interpolated = setup.temporal(&mut alone, &moved, &lights, 1);
    picture("moved-full", &moved_full);
    picture("moved-reprojected", &reprojected);
    picture("moved-interpolated", &interpolated);
    let (e_reprojected, e_interpolated) = (
        mean_rel(&reprojected, &moved_full),
        mean_rel(&interpolated, &moved_full),
    );
    eprintln!(
        "turned and raised: reprojected history {e_reprojected:.3e}, this frame's pixels alone {e_interpolated:.3e} (mean relative luminance from the full frame)"
    );
    assert!(
        e_reprojected < 0.85 * e_interpolated,
        "the reprojection does not help: {e_reprojected} vs {e_interpolated}"
    );

    // A new sun and a reset: the first frame after it is a fresh start's, nothing of the
    // old sun's history in it.
    let new_lights = lights_at(70.0);
    t.reset();
    let after_reset = setup.temporal(&mut t, &moved, &new_lights, 1);
    let mut fresh = TemporalFrames::new(&gpu.ctx, 2).unwrap();
    let fresh_first = setup.temporal(&mut fresh, &moved, &new_lights, 1);
    assert_eq!(max_rel(&after_reset, &fresh_first), 0.0);
    // Without the reset the old sun's light would stay in three pixels of four.
    let mut stale = TemporalFrames::new(&gpu.ctx, 2).unwrap();
    setup.temporal(&mut stale, &moved, &lights, 4);
    let kept = setup.temporal(&mut stale, &moved, &new_lights, 1);
    let new_full = setup.full(&moved, &new_lights);
    eprintln!(
        "a new sun: after a reset {:.3e}, with the stale history {:.3e}",
        mean_rel(&after_reset, &new_full),
        mean_rel(&kept, &new_full)
    );
    assert!(mean_rel(&kept, &new_full) > mean_rel(&after_reset, &new_full));

    // The sun's disk in view (a 6° field towards it: the disk 5 pixels wide, its light in
    // a few dozen pixels): the window around it is drawn whole every frame, so a sixteenth
    // of the blocks' pixels marched still gives the full frame's disk.
    let with_disk = Scene::clear_sky(sky, sun_direction(40.0, 200.0), true).lights;
    let towards = common::camera(Projection::Perspective, 2.0, 200.0, 50.0, 6.0);
    let disk_full = setup.full(&towards, &with_disk);
    let mut t = TemporalFrames::new(&gpu.ctx, 4).unwrap();
    let disk_first = setup.temporal(&mut t, &towards, &with_disk, 1);
    picture("disk-full", &disk_full);
    picture("disk-first-step4", &disk_first);
    let prepared = towards.prepare(radius, SIZE.0, SIZE.1);
    let sun = with_disk[0].direction;
    let (mut on_disk, mut same) = (0, 0);
    let (mut total_full, mut total_first) = (0.0, 0.0);
    for y in 0..SIZE.1 {
        for x in 0..SIZE.0 {
            let dir = prepared.ray(x as f64 + 0.5, y as f64 + 0.5).unwrap().dir;
            if angle(dir, sun) <= 1.5 * with_disk[0].angular_radius_rad {
                let i = y * SIZE.0 + x;
                on_disk += 1;
                same += usize::from(disk_first.image.data[i] == disk_full.image.data[i]);
                total_full += luminance(&disk_full.image.data[i]);
                total_first += luminance(&disk_first.image.data[i]);
            }
        }
    }
    eprintln!(
        "the sun's disk in view: {same} of its {on_disk} pixels as the full frame's in the first frame at step 4 (its light {:+.2e} from the full frame's; the whole frame {:.3e} mean relative)",
        total_first / total_full - 1.0,
        mean_rel(&disk_first, &disk_full)
    );
    assert!(on_disk >= 9, "the disk covers {on_disk} pixels only");
    assert_eq!(same, on_disk);

    // A frame without clouds is not interleaved.
    let inputs = RenderInputs {
        interleave: Some(firmament_gpu::Interleave::nth(2, 0)),
        ..RenderInputs::default()
    };
    let settings = Setup::settings(&camera);
    let Err(e) = gpu
        .renderer
        .render_with(&gpu.ctx, setup.sky, &lights, &settings, inputs)
    else {
        panic!("an interleaved frame without clouds was drawn");
    };
    let e = e.to_string();
    assert!(e.contains("interleave"), "{e}");
}

#[test]
fn interleaved_terrain_frames_converge_and_reproject() {
    let Some(gpu) = gpu("interleaved_terrain_frames_converge_and_reproject") else {
        return;
    };
    let _guard = serial();
    // The valley from 25 m at golden hour, the sun behind the ridges ahead (its shafts).
    let (terrain, sky) = valley(TerrainConfig {
        resolution: 257,
        ..TerrainConfig::default()
    });
    let bottom = sky.model.bottom_radius_m;
    let altitude = 25.0 + terrain.height_at(0.0, 0.0) - (bottom - terrain.radius_m);
    let camera = common::camera(Projection::Perspective, altitude, 250.0, 4.0, 60.0);
    let mut scene = Scene::clear_sky(&sky, sun_direction(84.5, 237.0), false);
    scene.add_terrain(&terrain, terrain.radius_m);
    let lights = scene.lights.clone();
    let shader = Shader::new(&scene, Vec3::new(0.0, 0.0, bottom + altitude)).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, &sky).unwrap();
    let gpu_terrain = GpuTerrain::new(&gpu.ctx, &gpu_sky, &terrain, &shader).unwrap();
    let setup = Setup {
        gpu,
        sky: &gpu_sky,
        inputs: Box::new(|_: &[Light]| RenderInputs {
            terrain: Some(&gpu_terrain),
            ..RenderInputs::default()
        }),
    };
    let full = setup.full(&camera, &lights);
    picture("terrain-full", &full);
    let mut t = TemporalFrames::new(&gpu.ctx, 2).unwrap();
    let first = setup.temporal(&mut t, &camera, &lights, 1);
    picture("terrain-first-step2", &first);
    let converged = setup.temporal(&mut t, &camera, &lights, 3);
    let (first_err, err) = (mean_rel(&first, &full), max_rel(&converged, &full));
    eprintln!(
        "terrain: first frame {first_err:.3e} from the full frame, after 4 frames the largest difference {err:.1e}"
    );
    assert!(
        first_err > 1e-4,
        "the first frame is the full one: {first_err}"
    );
    assert_eq!(err, 0.0, "not converged to the full frame");
    // Turned: the ridges' and the sky's pixels reprojected (the depth edges of a ridge
    // against the sky or the slope behind it left to this frame's pixels).
    let mut turned = camera.clone();
    turned.heading_deg += 2.5 * camera.fov_deg / SIZE.1 as f64;
    turned.pitch_deg -= 1.5 * camera.fov_deg / SIZE.1 as f64;
    let turned_frame = setup.temporal(&mut t, &turned, &lights, 1);
    picture("terrain-turned", &turned_frame);
    let share = reprojected_share(&camera, &turned, &full, &turned_frame, bottom);
    let (e_turned, e_alone) = (
        mean_rel(&turned_frame, &setup.full(&turned, &lights)),
        mean_rel(
            &setup.temporal(
                &mut TemporalFrames::new(&gpu.ctx, 2).unwrap(),
                &turned,
                &lights,
                1,
            ),
            &setup.full(&turned, &lights),
        ),
    );
    eprintln!(
        "terrain turned: {:.1} % of the undrawn pixels are the previous frame's, reprojected; {e_turned:.3e} from the full frame (this frame's pixels alone {e_alone:.3e})",
        100.0 * share
    );
    assert!(
        share > 0.7,
        "only {share} of the undrawn pixels reprojected"
    );
    assert!(e_turned < e_alone, "{e_turned} vs {e_alone}");
}
