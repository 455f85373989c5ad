//! The display pass (exposure and tone mapping on the GPU) against the CPU's
//! `Frame::log_average_luminance`, `tonemap::auto_ev100` and `Frame::to_srgb8`, on a
//! synthetic HDR frame spanning twelve decades (night sky to the sun's disk), with colours
//! outside Rec. 709's gamut and pixels outside the projection.

use firmament::io::ImageRgbF32;
use firmament::render::tonemap::{auto_ev100, exposure_from_ev100, ToneCurve};
use firmament::render::Frame;
use firmament_gpu::display::{
    hdr_buffer, read_hdr_frame, read_rgba8, Display, DisplaySettings, Exposure,
};
use firmament_gpu::test_context;

/// A frame with luminances from 10⁻³ to 10⁹ cd/m², some out-of-gamut colours, a masked
/// border (as a fisheye's corners).
fn synthetic_frame(w: usize, h: usize) -> Frame {
    let mut image = ImageRgbF32::new(w, h);
    let mut mask = vec![true; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let t = (x as f64 + 0.5) / w as f64;
            let s = (y as f64 + 0.5) / h as f64;
            // 10^-3 .. 10^5 across, a few sun-bright pixels.
            let l = 10f64.powf(-3.0 + 8.0 * t) as f32;
            let tint = [1.0 + s as f32, 1.0, 1.5 - s as f32];
            image.data[i] = tint.map(|c| c * l);
            if (x + y) % 37 == 0 {
                // Out of gamut: a negative red, as a saturated blue sky's spectrum gives.
                image.data[i][0] = -0.05 * l;
            }
            if x < 2 || y < 1 {
                mask[i] = false;
                image.data[i] = [0.0; 3];
            }
        }
    }
    image.data[w * (h / 2) + w / 2] = [1.6e9, 1.6e9, 1.5e9];
    Frame { image, mask }
}

fn upload(ctx: &firmament_gpu::GpuContext, frame: &Frame) -> (wgpu::Buffer, (u32, u32)) {
    let (w, h) = (frame.image.width as u32, frame.image.height as u32);
    let buffer = hdr_buffer(ctx, w, h);
    let texels: Vec<f32> = frame
        .image
        .data
        .iter()
        .zip(&frame.mask)
        .flat_map(|(p, &m)| [p[0], p[1], p[2], if m { 1.0 } else { 0.0 }])
        .collect();
    ctx.queue()
        .write_buffer(&buffer, 0, bytemuck::cast_slice(&texels));
    (buffer, (w, h))
}

fn target(
    ctx: &firmament_gpu::GpuContext,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    ctx.device().create_texture(&wgpu::TextureDescriptor {
        label: Some("display target"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

fn show(
    ctx: &firmament_gpu::GpuContext,
    display: &Display,
    hdr: &(wgpu::Buffer, (u32, u32)),
    out: &wgpu::Texture,
    settings: DisplaySettings,
) -> Vec<[u8; 4]> {
    let mut encoder = ctx
        .device()
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    display.encode(
        ctx,
        &mut encoder,
        &hdr.0,
        hdr.1,
        &out.create_view(&Default::default()),
        out.format(),
        (out.width(), out.height()),
        &settings,
        None,
    );
    ctx.queue().submit([encoder.finish()]);
    read_rgba8(ctx, out).unwrap()
}

#[test]
fn the_display_meters_and_tone_maps_as_the_cpu() {
    let Some(ctx) = test_context() else { return };
    let (w, h) = (96, 40);
    let frame = synthetic_frame(w, h);
    let hdr = upload(&ctx, &frame);
    // The buffer round trip is exact.
    let back = read_hdr_frame(&ctx, &hdr.0, hdr.1 .0, hdr.1 .1).unwrap();
    assert_eq!(back.image.data, frame.image.data);
    assert_eq!(back.mask, frame.mask);
    let display = Display::new(&ctx).unwrap();
    for (format, curve) in [
        (wgpu::TextureFormat::Rgba8Unorm, ToneCurve::Aces),
        (wgpu::TextureFormat::Rgba8UnormSrgb, ToneCurve::Filmic),
        (wgpu::TextureFormat::Bgra8UnormSrgb, ToneCurve::Clamp),
    ] {
        let out = target(&ctx, w as u32, h as u32, format);
        let settings = DisplaySettings {
            exposure: Exposure::Automatic { tau_s: 0.0 },
            curve,
            dt_s: 0.0,
            reset: true,
        };
        let codes = show(&ctx, &display, &hdr, &out, settings);
        let state = display.read_exposure(&ctx).unwrap();
        let metered = frame.log_average_luminance();
        let rel = state.metered_cd_m2 / metered - 1.0;
        assert!(
            rel.abs() < 1e-4,
            "metered {} vs CPU {metered}",
            state.metered_cd_m2
        );
        assert!((state.ev100 - auto_ev100(metered)).abs() < 1e-4);
        let cpu = frame.to_srgb8(exposure_from_ev100(auto_ev100(metered), curve), curve);
        let worst = cpu
            .iter()
            .zip(&codes)
            .flat_map(|(c, g)| (0..3).map(move |k| (c[k] as i32 - g[k] as i32).abs()))
            .max()
            .unwrap();
        // f32 on the GPU against f64 on the CPU: at most one code apart.
        assert!(worst <= 1, "{format:?} {curve:?}: codes differ by {worst}");
    }
}

#[test]
fn the_exposure_adapts_and_holds_a_manual_value() {
    let Some(ctx) = test_context() else { return };
    let (w, h) = (32, 16);
    let frame = synthetic_frame(w, h);
    let hdr = upload(&ctx, &frame);
    let display = Display::new(&ctx).unwrap();
    let out = target(&ctx, 64, 32, wgpu::TextureFormat::Rgba8Unorm);
    let target_ev = auto_ev100(frame.log_average_luminance());
    let manual = |ev100| DisplaySettings {
        exposure: Exposure::Manual { ev100 },
        curve: ToneCurve::Aces,
        dt_s: 0.1,
        reset: false,
    };
    show(&ctx, &display, &hdr, &out, manual(target_ev - 4.0));
    let state = display.read_exposure(&ctx).unwrap();
    assert!((state.ev100 - (target_ev - 4.0)).abs() < 1e-5);
    // One time constant later the gap has shrunk by 1/e.
    let adapt = DisplaySettings {
        exposure: Exposure::Automatic { tau_s: 0.5 },
        dt_s: 0.5,
        ..manual(0.0)
    };
    let codes = show(&ctx, &display, &hdr, &out, adapt);
    let state = display.read_exposure(&ctx).unwrap();
    let expected = target_ev - 4.0 * (-1f64).exp();
    assert!(
        (state.ev100 - expected).abs() < 1e-3,
        "{} vs {expected}",
        state.ev100
    );
    // Upscaled ×2: the display is not blank and keeps the gradient's order left to right.
    let row: Vec<u8> = (0..64).map(|x| codes[16 * 64 + x][1]).collect();
    assert!(row[63] > row[8] && row[8] <= row[32], "{row:?}");
}

#[test]
fn the_pass_timer_reads_the_display_passes_back_without_a_stall() {
    let Some(ctx) = test_context() else { return };
    let Some(mut timer) = firmament_gpu::pass_timer::PassTimer::new(&ctx) else {
        eprintln!(
            "no timestamp queries on {}: nothing to time",
            ctx.adapter_name()
        );
        return;
    };
    let frame = synthetic_frame(64, 32);
    let hdr = upload(&ctx, &frame);
    let display = Display::new(&ctx).unwrap();
    let out = target(&ctx, 64, 32, wgpu::TextureFormat::Rgba8Unorm);
    let settings = DisplaySettings {
        exposure: Exposure::Automatic { tau_s: 0.0 },
        curve: ToneCurve::Aces,
        dt_s: 0.0,
        reset: true,
    };
    // Nothing read back before a frame.
    assert_eq!(timer.times(&ctx), None);
    let mut encoder = ctx
        .device()
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    display.encode(
        &ctx,
        &mut encoder,
        &hdr.0,
        hdr.1,
        &out.create_view(&Default::default()),
        out.format(),
        (64, 32),
        &settings,
        Some(timer.query_set()),
    );
    assert!(timer.resolve(&mut encoder, firmament_gpu::pass_timer::SkySlots::One));
    ctx.queue().submit([encoder.finish()]);
    timer.after_submit();
    // While the copy is mapped, a second frame records no copy.
    let mut second = ctx
        .device()
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    assert!(!timer.resolve(&mut second, firmament_gpu::pass_timer::SkySlots::One));
    ctx.device()
        .poll(wgpu::PollType::wait_indefinitely())
        .unwrap();
    let t = timer.times(&ctx).expect("times after the device is idle");
    assert!(t.display_ms > 0.0 && t.display_ms < 60_000.0, "{t:?}");
}
