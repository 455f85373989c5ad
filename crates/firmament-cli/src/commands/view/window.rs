//! The viewer's window: winit for the window and its events, a wgpu surface on the adapter
//! that presents to it (the same device draws the sky: `GpuContext::from_device`), egui
//! through egui-winit and egui-wgpu for the panel. Each frame: the clock and the keys move
//! the state, the sky is rebuilt if the atmosphere or the method changed, the frame path
//! draws into the swap chain's texture and egui on top.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use firmament::scene::sky_lights::SkySources;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use super::capture::{self, CaptureKind};
use super::controls::{self, Keys};
use super::frame_path::{display_settings, render_size, FramePath};
use super::panel::{panel, PanelInfo};
use super::state::ViewState;
use super::ViewArgs;
use crate::backend::{Backend, Gpu};

/// Width of the side panel (logical pixels).
const PANEL_WIDTH: f32 = 330.0;

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    path: FramePath,
    backend: &'static Backend,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
}

struct App {
    args: ViewArgs,
    state: ViewState,
    info: PanelInfo,
    gfx: Option<Gfx>,
    keys: Keys,
    /// The pointer's last position and which button drags (left: look, right: the sun).
    cursor: Option<(f64, f64)>,
    dragging: Option<MouseButton>,
    frames: u32,
    /// Tab hides the panel.
    show_panel: bool,
    last: Instant,
    reset_exposure: bool,
    /// Captures asked for (written after the next frame).
    pending: Vec<PathBuf>,
    result: Result<()>,
}

/// Open the window and run until it closes (or `--frames` are drawn).
pub fn run(args: ViewArgs, state: ViewState, not_drawn: Vec<String>) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow::anyhow!(
            "`firmament view` could not open a window: {e} (no display? `--offscreen --frames N --screenshot OUT.png` draws without one)"
        )
    })?;
    let pending = args.screenshot.clone();
    let mut app = App {
        args,
        state,
        info: PanelInfo {
            not_drawn,
            ..PanelInfo::default()
        },
        gfx: None,
        keys: Keys::default(),
        cursor: None,
        dragging: None,
        frames: 0,
        show_panel: true,
        last: Instant::now(),
        reset_exposure: true,
        pending: Vec::new(),
        result: Ok(()),
    };
    // `--screenshot` is taken after the last of `--frames`.
    let final_captures = pending;
    event_loop
        .run_app(&mut app)
        .context("the window's event loop")?;
    app.result?;
    if app.args.frames.is_some() && !final_captures.is_empty() && app.frames == 0 {
        anyhow::bail!("the window closed before a frame was drawn");
    }
    Ok(())
}

impl App {
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<Gfx> {
        let attributes = Window::default_attributes()
            .with_title("firmament view")
            .with_inner_size(winit::dpi::PhysicalSize::new(
                self.args.width,
                self.args.height,
            ));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        ));
        let instance = wgpu::Instance::new(desc);
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            apply_limit_buckets: false,
        }))
        .map_err(|e| {
            anyhow::anyhow!("`firmament view` needs a GPU adapter that can draw to the window: {e}")
        })?;
        let info = adapter.get_info();
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("firmament view"),
            required_features: features,
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::default(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .with_context(|| format!("opening {}", info.name))?;
        let ctx = firmament_gpu::GpuContext::from_device(device, queue, info);
        let gpu = Gpu { ctx };
        if !self.args.quiet {
            eprintln!("backend: gpu ({})", gpu.describe());
        }
        if self.args.render_scale.is_none() {
            self.state.render_scale = if gpu.ctx.is_software() { 0.5 } else { 1.0 };
        }
        self.info.adapter = gpu.describe();
        // The viewer's device lives as long as the program.
        let backend: &'static Backend = Box::leak(Box::new(Backend::Gpu(Box::new(gpu))));
        let Backend::Gpu(gpu) = backend else {
            unreachable!()
        };
        let caps = surface.get_capabilities(&adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or(caps.formats.first().copied())
            .context("the window's surface offers no format")?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: Default::default(),
        };
        surface.configure(gpu.ctx.device(), &config);
        let path = FramePath::new(
            backend,
            &self.state,
            self.args.tables.clone(),
            &self.args.table_size,
        )?;
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let egui_renderer = egui_wgpu::Renderer::new(
            gpu.ctx.device(),
            format,
            egui_wgpu::RendererOptions::default(),
        );
        Ok(Gfx {
            window,
            surface,
            config,
            path,
            backend,
            egui_ctx,
            egui_state,
            egui_renderer,
        })
    }

    fn key(&mut self, code: KeyCode, pressed: bool, event_loop: &ActiveEventLoop) {
        match code {
            KeyCode::KeyW => self.keys.forward = pressed,
            KeyCode::KeyS if self.keys_ctrl() && pressed => self.save_scene(),
            KeyCode::KeyS => self.keys.back = pressed,
            KeyCode::KeyE => self.keys.up = pressed,
            KeyCode::KeyQ => self.keys.down = pressed,
            KeyCode::ShiftLeft | KeyCode::ShiftRight => self.keys.fast = pressed,
            KeyCode::Space if pressed => self.state.playing = !self.state.playing,
            KeyCode::Tab if pressed => self.show_panel = !self.show_panel,
            KeyCode::F12 if pressed => self.ask_screenshot(),
            KeyCode::Escape if pressed => event_loop.exit(),
            _ => {}
        }
    }

    fn keys_ctrl(&self) -> bool {
        self.gfx.as_ref().is_some_and(|g| {
            g.egui_ctx
                .input(|i| i.modifiers.ctrl || i.modifiers.command)
        })
    }

    fn ask_screenshot(&mut self) {
        let dir = &self.args.capture_dir;
        self.pending.push(capture::next_name(dir, "png"));
        self.pending.push(capture::next_name(dir, "exr"));
    }

    fn save_scene(&mut self) {
        let path = capture::next_name(&self.args.capture_dir, "toml");
        let size = self
            .gfx
            .as_ref()
            .map_or((self.args.width, self.args.height), |g| {
                (g.config.width, g.config.height)
            });
        self.info.message = match capture::write_scene(&path, &self.state, size) {
            Ok(()) => format!(
                "saved {}: {}",
                path.display(),
                self.state.render_command(&path.display().to_string())
            ),
            Err(e) => format!("error: {e:#}"),
        };
        if !self.args.quiet {
            eprintln!("{}", self.info.message);
        }
    }

    /// Move the sun to where the pointer is in the sky.
    fn drag_sun(&mut self, x: f64, y: f64) {
        let Some(g) = &self.gfx else { return };
        let Some(sky) = g.path.sky() else { return };
        let (w, h) = (g.config.width as usize, g.config.height as usize);
        let prepared = self
            .state
            .scene
            .camera
            .prepare(sky.model().bottom_radius_m, w, h);
        if let Some(ray) = prepared.ray(x, y) {
            let d = ray.dir;
            let elevation = d.z.clamp(-1.0, 1.0).asin().to_degrees();
            let azimuth = d.x.atan2(d.y).to_degrees();
            self.state.set_sun(elevation, azimuth);
        }
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let now = Instant::now();
        let dt = now.duration_since(self.last).as_secs_f64();
        self.last = now;
        self.info.frame_ms = dt * 1e3;
        controls::fly(&mut self.state.scene.camera, self.keys, dt);
        if let Err(e) = self.state.tick(dt) {
            self.state.playing = false;
            self.info.message = format!("the clock stopped: {e:#}");
        }
        if self.gfx.is_none() {
            return Ok(());
        }
        let device = self.backend_device();
        let Some(g) = self.gfx.as_mut() else {
            return Ok(());
        };
        self.info.timestamps = g.path.has_timer();
        self.info.render_size = render_size(&self.state, (g.config.width, g.config.height));
        // The panel first: what it changes is drawn in this frame.
        let raw = g.egui_state.take_egui_input(&g.window);
        let mut actions = Default::default();
        let state = &mut self.state;
        let info = &self.info;
        let show_panel = self.show_panel;
        let output = g.egui_ctx.run_ui(raw, |ui| {
            if !show_panel {
                return;
            }
            egui::Panel::left("firmament panel")
                .default_size(PANEL_WIDTH)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        actions = panel(ui, state, info);
                    });
                });
        });
        g.egui_state
            .handle_platform_output(&g.window, output.platform_output.clone());
        if g.path.ensure_sky(&self.state)? {
            self.info.build_s = g.path.last_build_s;
            self.reset_exposure = true;
        }
        self.info.update = g.path.update_line();
        let sources: SkySources = g.path.sources(&self.state)?;
        let frame = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            other => {
                g.surface.configure(&device, &g.config);
                anyhow::bail!("the window's surface: {other:?}");
            }
        };
        let size = (g.config.width, g.config.height);
        let view = frame.texture.create_view(&Default::default());
        let Backend::Gpu(gpu) = g.backend else {
            unreachable!()
        };
        let ctx = &gpu.ctx;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("viewer frame"),
        });
        let display = display_settings(&self.state, dt, self.reset_exposure);
        self.reset_exposure = false;
        g.path.encode(
            &mut encoder,
            &self.state,
            &sources,
            &view,
            g.config.format,
            size,
            display,
        )?;
        self.info.render_size = render_size(&self.state, size);
        // egui over the frame.
        let ppp = g.egui_ctx.pixels_per_point();
        let jobs = g.egui_ctx.tessellate(output.shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: ppp,
        };
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                g.egui_renderer
                    .update_texture(ctx.device(), ctx.queue(), *id, delta);
            }
        }
        let extra =
            g.egui_renderer
                .update_buffers(ctx.device(), ctx.queue(), &mut encoder, &jobs, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            g.egui_renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in &output.textures_delta.free {
            g.egui_renderer.free_texture(id);
        }
        // A capture copies the swap chain's texture before it is presented.
        let capture_now = !self.pending.is_empty()
            || (self.args.frames.is_some_and(|n| self.frames + 1 >= n)
                && !self.args.screenshot.is_empty());
        let copy = capture_now.then(|| copy_out(ctx.device(), &mut encoder, &frame.texture));
        ctx.queue()
            .submit(extra.into_iter().chain([encoder.finish()]));
        g.path.submitted();
        self.info.reference = g.path.reference_line();
        self.info.march = g.path.march_line(&self.state);
        self.info.gpu_ms = g.path.pass_times().map(|t| (t.sky_ms, t.display_ms));
        if let Some(staging) = &copy {
            let shown = read_copy(ctx, staging, &frame.texture)?;
            let ev100 = g.path.shown_ev100()?;
            self.info.shown_ev100 = Some(ev100);
            let mut paths = std::mem::take(&mut self.pending);
            if self.args.frames.is_some_and(|n| self.frames + 1 >= n) {
                paths.extend(self.args.screenshot.iter().cloned());
            }
            for p in paths {
                match CaptureKind::of(&p)? {
                    CaptureKind::Png => capture::write_png(&p, size, &shown)?,
                    CaptureKind::Exr => {
                        capture::write_exr(&p, &g.path.hdr_frame()?, &self.state, ev100)?
                    }
                }
                self.info.message = format!("wrote {}", p.display());
                if !self.args.quiet {
                    eprintln!("{}", self.info.message);
                }
            }
        } else if self.frames.is_multiple_of(30) {
            self.info.shown_ev100 = g.path.shown_ev100().ok();
        }
        ctx.queue().present(frame);
        self.frames += 1;
        if actions.screenshot {
            self.ask_screenshot();
        }
        if actions.save_scene {
            self.save_scene();
        }
        if self.args.frames.is_some_and(|n| self.frames >= n) {
            if let Some(p) = &self.args.save_scene {
                capture::write_scene(p, &self.state, size)?;
            }
            event_loop.exit();
        } else if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
        Ok(())
    }

    fn backend_device(&self) -> wgpu::Device {
        match self.gfx.as_ref().map(|g| g.backend) {
            Some(Backend::Gpu(gpu)) => gpu.ctx.device().clone(),
            _ => unreachable!("a window has a GPU"),
        }
    }
}

/// Copy a swap-chain texture into a staging buffer (rows padded to 256 bytes).
fn copy_out(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> wgpu::Buffer {
    let (w, h) = (texture.width(), texture.height());
    let padded =
        (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("window capture"),
        size: padded as u64 * h as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    staging
}

/// The RGBA codes of a copied swap-chain texture (BGRA swizzled to RGBA).
fn read_copy(
    ctx: &firmament_gpu::GpuContext,
    staging: &wgpu::Buffer,
    texture: &wgpu::Texture,
) -> Result<Vec<[u8; 4]>> {
    let (w, h) = (texture.width() as usize, texture.height() as usize);
    let padded = staging.size() as usize / h;
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.device()
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| anyhow::anyhow!("waiting for the capture: {e}"))?;
    rx.recv()?
        .map_err(|e| anyhow::anyhow!("mapping the capture: {e}"))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| anyhow::anyhow!("reading the capture: {e:?}"))?;
    let bgra = matches!(
        texture.format(),
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    );
    let mut out = Vec::with_capacity(w * h);
    for r in 0..h {
        for p in data[r * padded..r * padded + w * 4].chunks_exact(4) {
            out.push(if bgra {
                [p[2], p[1], p[0], p[3]]
            } else {
                [p[0], p[1], p[2], p[3]]
            });
        }
    }
    drop(data);
    staging.unmap();
    Ok(out)
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(g) => {
                g.window.request_redraw();
                self.gfx = Some(g);
            }
            Err(e) => {
                self.result = Err(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let consumed = match &mut self.gfx {
            Some(g) => g.egui_state.on_window_event(&g.window, &event).consumed,
            None => false,
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(g) = &mut self.gfx {
                    g.config.width = size.width.max(1);
                    g.config.height = size.height.max(1);
                    let Backend::Gpu(gpu) = g.backend else {
                        unreachable!()
                    };
                    g.surface.configure(gpu.ctx.device(), &g.config);
                    g.window.request_redraw();
                }
            }
            WindowEvent::KeyboardInput { event, .. } if !consumed => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    self.key(code, event.state == ElementState::Pressed, event_loop);
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.dragging = match state {
                    ElementState::Pressed if !consumed => Some(button),
                    _ => None,
                };
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x, position.y);
                if let (Some((px, py)), Some(button)) = (self.cursor, self.dragging) {
                    let height = self.gfx.as_ref().map_or(1.0, |g| g.config.height as f64);
                    match button {
                        MouseButton::Left => {
                            controls::look(&mut self.state.scene.camera, x - px, y - py, height)
                        }
                        MouseButton::Right => self.drag_sun(x, y),
                        _ => {}
                    }
                }
                self.cursor = Some((x, y));
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                controls::zoom(&mut self.state.scene.camera, steps);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.result = Err(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }
}
