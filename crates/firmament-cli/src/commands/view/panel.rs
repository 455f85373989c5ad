//! The viewer's panel (egui): the method, the sun or the date, the camera and its presets,
//! the atmosphere, the exposure, the capture buttons and the timings. It edits a
//! [`ViewState`] and reports what was asked; it draws nothing itself, so it is tested
//! headlessly (`egui_kittest`, below).

use firmament::render::tonemap::ToneCurve;

#[path = "panel_sky.rs"]
mod sky;

use super::presets::PRESETS as VIEW_PRESETS;
use super::progressive::Compare;
use super::state::{ViewState, MAX_ALTITUDE_M, PRESETS, VIEW_METHODS};
use sky::{air_section, clouds_section, date_section};

/// What the panel asked for this frame, besides editing the state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PanelActions {
    pub screenshot: bool,
    pub save_scene: bool,
}

/// What the panel shows besides the state.
#[derive(Clone, Debug, Default)]
pub struct PanelInfo {
    /// The adapter in words.
    pub adapter: String,
    /// The last frame's time on the CPU clock, submission to submission (ms).
    pub frame_ms: f64,
    /// The GPU's time for the sky's dispatch and the display (ms), when measured.
    pub gpu_ms: Option<(f64, f64)>,
    /// Whether the adapter has timestamp queries (the times may not be read back yet).
    pub timestamps: bool,
    /// The size the sky is drawn at.
    pub render_size: (u32, u32),
    /// The EV100 the frame was shown at.
    pub shown_ev100: Option<f64>,
    /// Seconds the sky's tables took to build last.
    pub build_s: f64,
    /// The amortised update of the 4D tables in flight, in words.
    pub update: Option<String>,
    /// The reference's progress, in words.
    pub reference: Option<String>,
    /// The temporal frames' progress (under clouds or over a terrain), in words.
    pub march: Option<String>,
    /// A line about the last capture or save, or an error.
    pub message: String,
    /// What the scene has that the viewer does not draw yet.
    pub not_drawn: Vec<String>,
}

/// Draw the panel into `ui`, editing `state`.
pub fn panel(ui: &mut egui::Ui, state: &mut ViewState, info: &PanelInfo) -> PanelActions {
    let mut actions = PanelActions::default();
    ui.heading("firmament");
    ui.label(format!(
        "drawing: {} on {}",
        state.method.name(),
        if info.adapter.is_empty() {
            "the GPU"
        } else {
            &info.adapter
        }
    ));
    ui.horizontal(|ui| {
        for m in VIEW_METHODS {
            ui.radio_value(&mut state.method, m, m.name());
        }
    });
    for line in [&info.update, &info.march].into_iter().flatten() {
        ui.small(line);
    }
    ui.horizontal(|ui| {
        ui.label("reference");
        for (label, c) in [
            ("off", Compare::Off),
            ("split", Compare::Split),
            ("whole", Compare::Whole),
            ("difference", Compare::Difference),
        ] {
            ui.radio_value(&mut state.compare, c, label);
        }
    })
    .response
    .on_hover_text("the Monte Carlo path tracer, traced progressively on the CPU and restarted when anything moves");
    if let Some(line) = &info.reference {
        ui.small(line);
    }
    ui.separator();
    sun_section(ui, state);
    ui.separator();
    camera_section(ui, state);
    ui.separator();
    ui.label("Atmosphere");
    ui.horizontal_wrapped(|ui| {
        for p in PRESETS {
            let on = state.scene.atmosphere.file.is_none() && state.scene.atmosphere.preset == p;
            if ui.selectable_label(on, p).clicked() {
                state.scene.atmosphere.preset = p.to_string();
                state.scene.atmosphere.file = None;
            }
        }
    });
    ui.horizontal(|ui| {
        ui.label("wavelengths");
        let w = &mut state.scene.atmosphere.wavelengths;
        for (label, value) in [("spectral (16)", "spectral"), ("rgb (3)", "rgb")] {
            let on = w.as_deref().unwrap_or("spectral") == value;
            if ui.selectable_label(on, label).clicked() {
                *w = Some(value.to_string());
            }
        }
    });
    air_section(ui, state);
    clouds_section(ui, state);
    ui.separator();
    exposure_section(ui, state, info);
    ui.separator();
    ui.horizontal(|ui| {
        if ui.button("Screenshot (F12)").clicked() {
            actions.screenshot = true;
        }
        if ui.button("Save scene (Ctrl+S)").clicked() {
            actions.save_scene = true;
        }
    });
    if !info.message.is_empty() {
        ui.label(&info.message);
    }
    ui.separator();
    ui.label(format!(
        "frame {:.1} ms · sky {}×{}{}",
        info.frame_ms,
        info.render_size.0,
        info.render_size.1,
        match info.gpu_ms {
            Some((sky, display)) => format!(" · GPU: sky {sky:.2} ms, display {display:.2} ms"),
            None if info.timestamps => " · GPU times: reading back".into(),
            None => " · no GPU timestamps on this adapter".into(),
        }
    ));
    if info.build_s > 0.0 {
        ui.label(format!("tables built in {:.2} s", info.build_s));
    }
    for line in &info.not_drawn {
        ui.small(line);
    }
    actions
}

fn sun_section(ui: &mut egui::Ui, state: &mut ViewState) {
    let mut dated = state.dated();
    if ui.checkbox(&mut dated, "date and place").changed() {
        // Off keeps the sun where the date put it; on starts from now.
        let now = chrono::DateTime::<chrono::Utc>::from(std::time::SystemTime::now());
        let _ = state.set_dated(dated, now);
    }
    if state.dated() {
        date_section(ui, state);
    } else {
        ui.label("Sun (drag with the right mouse button)");
        let mut elevation = state.sun_elevation_deg();
        let mut azimuth = state.scene.sun.azimuth_deg;
        let e = ui.add(egui::Slider::new(&mut elevation, -18.0..=90.0).text("elevation °"));
        let a = ui.add(egui::Slider::new(&mut azimuth, 0.0..=360.0).text("azimuth °"));
        if e.changed() || a.changed() {
            state.set_sun(elevation, azimuth);
        }
    }
    ui.horizontal(|ui| {
        let label = if state.playing { "Pause" } else { "Play" };
        if ui.button(label).clicked() {
            state.playing = !state.playing;
        }
        ui.add(
            egui::Slider::new(&mut state.hours_per_second, 0.01..=2.0)
                .logarithmic(true)
                .text("h/s"),
        );
    });
    ui.checkbox(&mut state.scene.sun.disk, "sun disk");
}

fn camera_section(ui: &mut egui::Ui, state: &mut ViewState) {
    ui.label("Camera (drag: look · W/S E/Q: fly · Shift: faster · wheel: zoom)");
    let c = &mut state.scene.camera;
    let mut altitude = c.altitude_m;
    if ui
        .add(
            egui::Slider::new(&mut altitude, 2.0..=MAX_ALTITUDE_M)
                .logarithmic(true)
                .text("altitude m"),
        )
        .changed()
    {
        state.set_altitude(altitude);
    }
    let c = &mut state.scene.camera;
    ui.add(egui::Slider::new(&mut c.heading_deg, 0.0..=360.0).text("heading °"));
    ui.add(egui::Slider::new(&mut c.pitch_deg, -89.0..=89.0).text("pitch °"));
    ui.add(egui::Slider::new(&mut c.fov_deg, 5.0..=120.0).text("field of view °"));
    ui.horizontal_wrapped(|ui| {
        for p in VIEW_PRESETS {
            if ui.button(p.name).clicked() {
                p.apply(state);
            }
        }
    });
}

fn exposure_section(ui: &mut egui::Ui, state: &mut ViewState, info: &PanelInfo) {
    let mut automatic = state.scene.output.ev100.is_none();
    if ui.checkbox(&mut automatic, "automatic exposure").changed() {
        state.scene.output.ev100 = if automatic {
            None
        } else {
            Some(info.shown_ev100.unwrap_or(12.0))
        };
    }
    match &mut state.scene.output.ev100 {
        Some(ev) => {
            ui.add(egui::Slider::new(ev, -8.0..=20.0).text("EV100"));
        }
        None => {
            ui.add(egui::Slider::new(&mut state.adapt_tau_s, 0.0..=5.0).text("adaptation s"));
            if let Some(ev) = info.shown_ev100 {
                ui.label(format!("EV100 {ev:.2}"));
            }
        }
    }
    ui.horizontal(|ui| {
        ui.label("tone curve");
        for (label, curve) in [
            ("ACES", ToneCurve::Aces),
            ("filmic", ToneCurve::Filmic),
            ("clamp", ToneCurve::Clamp),
        ] {
            if ui
                .selectable_label(state.scene.output.tonemap == curve, label)
                .clicked()
            {
                state.set_curve(curve);
            }
        }
    });
    ui.add(egui::Slider::new(&mut state.render_scale, 0.1..=1.0).text("render scale"));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::Method;
    use egui::accesskit::Role;
    use egui_kittest::kittest::Queryable;
    use egui_kittest::Harness;

    fn state() -> ViewState {
        ViewState::new(super::super::state::clear_scene(), Method::Bruneton4d, true)
    }

    fn harness(state: ViewState) -> Harness<'static, ViewState> {
        // Tall enough for the whole panel: clicks land on what is shown.
        Harness::builder()
            .with_size((420.0, 1400.0))
            .build_ui_state(
                |ui, s: &mut ViewState| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        panel(ui, s, &PanelInfo::default());
                    });
                },
                state,
            )
    }

    #[test]
    fn the_method_the_atmosphere_and_the_curve_follow_the_clicks() {
        let mut h = harness(state());
        h.get_by_label("hillaire2020").click();
        h.run();
        assert_eq!(h.state().method, Method::Hillaire2020);
        h.get_by_label("hazy").click();
        h.get_by_label("rgb (3)").click();
        h.run();
        assert_eq!(h.state().scene.atmosphere.preset, "hazy");
        assert_eq!(
            h.state().scene.atmosphere.wavelengths.as_deref(),
            Some("rgb")
        );
        h.get_by_label("filmic").click();
        h.run();
        assert_eq!(h.state().scene.output.tonemap, ToneCurve::Filmic);
    }

    #[test]
    fn play_presets_and_exposure_change_the_scene() {
        let mut h = harness(state());
        h.get_by_label("Play").click();
        h.run();
        assert!(h.state().playing);
        h.get_by_label("orbit").click();
        h.run();
        assert!(h.state().scene.camera.altitude_m > 1.0e6);
        assert!(h.state().scene.camera.pitch_deg < -80.0);
        // Manual exposure starts where the automatic one was shown (12 without a frame).
        h.get_by_label("automatic exposure").click();
        h.run();
        assert_eq!(h.state().scene.output.ev100, Some(12.0));
        h.get_by_label("automatic exposure").click();
        h.run();
        assert_eq!(h.state().scene.output.ev100, None);
    }

    #[test]
    fn the_buttons_report_captures_and_dates_move_by_the_hour() {
        let mut s = state();
        s.scene.location = Some(firmament::scene::file::SceneLocation {
            lat_deg: 48.0,
            lon_deg: 2.0,
            elevation_m: 0.0,
            pressure_hpa: 1013.25,
            temperature_c: 10.0,
        });
        s.scene.time = Some(firmament::scene::file::SceneTime {
            at: "2026-03-20T18:00:00Z".into(),
            moon_disk: true,
        });
        let asked = std::rc::Rc::new(std::cell::Cell::new(PanelActions::default()));
        let seen = asked.clone();
        let mut h = Harness::builder()
            .with_size((420.0, 1400.0))
            .build_ui_state(
                move |ui, s: &mut ViewState| {
                    let a = panel(ui, s, &PanelInfo::default());
                    let mut all = seen.get();
                    all.screenshot |= a.screenshot;
                    all.save_scene |= a.save_scene;
                    seen.set(all);
                },
                s,
            );
        h.get_by_label("+1 h").click();
        h.run();
        assert!(h
            .state()
            .scene
            .time
            .as_ref()
            .unwrap()
            .at
            .starts_with("2026-03-20T19:00:00"));
        h.get_by_label("Screenshot (F12)").click();
        h.get_by_label("Save scene (Ctrl+S)").click();
        h.run();
        assert_eq!(
            asked.get(),
            PanelActions {
                screenshot: true,
                save_scene: true
            }
        );
    }

    #[test]
    fn the_air_sliders_write_the_scenes_adjustments_and_reset() {
        let mut h = harness(state());
        h.get_by_role_and_label(Role::Slider, "aerosol optical depth (550 nm)")
            .set_value_accesskit(0.5);
        h.get_by_role_and_label(Role::Slider, "ozone DU")
            .set_value_accesskit(420.0);
        h.get_by_role_and_label(Role::Slider, "Rayleigh scale")
            .set_value_accesskit(2.0);
        h.get_by_role_and_label(Role::Slider, "ground albedo")
            .set_value_accesskit(0.3);
        h.get_by_role_and_label(Role::Slider, "planet radius km")
            .set_value_accesskit(3389.5);
        h.run();
        let a = h.state().scene.atmosphere.adjust.clone();
        assert_eq!(a.aerosol_optical_depth, Some(0.5));
        assert_eq!(a.ozone_du, Some(420.0));
        assert_eq!(a.rayleigh_scale, Some(2.0));
        assert_eq!(a.ground_albedo, Some(0.3));
        assert!((a.planet_radius_m.unwrap() - 3.3895e6).abs() < 1e-3);
        // Whatever the panel writes, the library takes.
        firmament::atmosphere::Atmosphere::earth()
            .adjusted(&a)
            .unwrap();
        h.get_by_label("the atmosphere's own values").click();
        h.run();
        assert!(h.state().scene.atmosphere.adjust.is_empty());
        h.get_by_label("4D update frames").set_value_accesskit(20.0);
        h.get_by_label("split").click();
        h.run();
        assert_eq!(h.state().update_frames, 20);
        assert_eq!(h.state().compare, Compare::Split);
    }

    #[test]
    fn the_date_panel_turns_on_and_moves_the_day_the_hour_and_the_place() {
        let mut h = harness(state());
        h.get_by_label("date and place").click();
        h.run();
        assert!(h.state().dated());
        h.get_by_label("year").set_value_accesskit(2027.0);
        h.get_by_label("month").set_value_accesskit(2.0);
        h.get_by_label("day").set_value_accesskit(31.0);
        h.run();
        // February 31st is the last day of February.
        let at = h.state().scene.time.as_ref().unwrap().at.clone();
        assert!(at.starts_with("2027-02-28T"), "{at}");
        h.get_by_role_and_label(Role::Slider, "local solar time h")
            .set_value_accesskit(18.5);
        h.get_by_role_and_label(Role::Slider, "latitude °")
            .set_value_accesskit(-33.9);
        h.run();
        assert!((h.state().solar_hours().unwrap() - 18.5).abs() < 1e-3);
        assert_eq!(h.state().scene.location.as_ref().unwrap().lat_deg, -33.9);
        // Off again: the angles of the sun the date put there.
        h.get_by_label("date and place").click();
        h.run();
        assert!(!h.state().dated());
    }

    #[test]
    fn the_cloud_sliders_move_the_layer() {
        let mut s = state();
        s.scene.clouds = vec![toml::from_str("kind = \"cumulus\"").unwrap()];
        let mut h = harness(s);
        h.get_by_role_and_label(Role::Slider, "cumulus 0: coverage")
            .set_value_accesskit(0.7);
        h.get_by_role_and_label(Role::Slider, "cumulus 0: base km")
            .set_value_accesskit(2.0);
        h.run();
        let layer = &h.state().scene.clouds[0];
        assert_eq!(layer.coverage, Some(0.7));
        // The layer keeps its 2 km thickness.
        assert_eq!((layer.bottom_m, layer.top_m), (Some(2000.0), Some(4000.0)));
        // Another kind takes its own defaults (cirrus: 8–9.5 km).
        h.get_by_label("cirrus 0").click();
        h.run();
        let p = h.state().scene.clouds[0].resolved();
        assert_eq!((p.bottom_m, p.top_m), (8000.0, 9500.0));
        // A sixteenth of the pixels marched a frame, then every pixel.
        assert_eq!(
            h.state().march_step,
            super::super::state::DEFAULT_MARCH_STEP
        );
        h.get_by_label("1/16").click();
        h.run();
        assert_eq!(h.state().march_step, 4);
        h.get_by_label("all").click();
        h.run();
        assert_eq!(h.state().march_step, 1);
        h.get_by_label("add a layer").click();
        h.run();
        assert_eq!(h.state().scene.clouds.len(), 2);
        h.get_by_label("remove 0").click();
        h.run();
        assert_eq!(h.state().scene.clouds.len(), 1);
        assert_eq!(
            h.state().scene.clouds[0].kind,
            firmament::scene::clouds::CloudKind::Cumulus
        );
    }
}
