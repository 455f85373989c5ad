//! The panel's sections that change the sky itself: the date and place, the atmosphere's
//! adjustments and the cloud layers (each edits the scene file, so "save scene" keeps it).

use super::ViewState;
use firmament::atmosphere::adjust;
use firmament::sky::bruneton4d::shell;

/// The date, the time of day and the place of a dated scene.
pub(super) fn date_section(ui: &mut egui::Ui, state: &mut ViewState) {
    let at = state
        .scene
        .time
        .as_ref()
        .map(|t| t.at.clone())
        .unwrap_or_default();
    ui.label(format!("Time: {at}"));
    if let Ok(instant) = firmament::astro::Instant::parse(&at, "time.at") {
        use chrono::Datelike;
        let d = instant.utc.date_naive();
        let (mut y, mut m, mut day) = (d.year(), d.month(), d.day());
        let changed = ui
            .horizontal(|ui| {
                let field = |ui: &mut egui::Ui, name: &str, v: &mut u32, hi: u32| {
                    let label = ui.label(name);
                    ui.add(egui::DragValue::new(v).range(1..=hi))
                        .labelled_by(label.id)
                        .changed()
                };
                let mut year = y as u32;
                let a = field(ui, "year", &mut year, 2200);
                y = year.max(1800) as i32;
                let b = field(ui, "month", &mut m, 12);
                let c = field(ui, "day", &mut day, 31);
                a || b || c
            })
            .inner;
        if changed {
            // The last day of a shorter month when the day is past it.
            for last in (28..=day.max(28)).rev() {
                if state
                    .set_date(&format!("{y:04}-{m:02}-{:02}", day.min(last)))
                    .is_ok()
                {
                    break;
                }
            }
        }
    }
    if let Some(mut h) = state.solar_hours() {
        if ui
            .add(egui::Slider::new(&mut h, 0.0..=24.0).text("local solar time h"))
            .changed()
        {
            let _ = state.set_solar_hours(h);
        }
    }
    ui.horizontal(|ui| {
        for (label, hours) in [
            ("−1 h", -1.0),
            ("−10 min", -1.0 / 6.0),
            ("+10 min", 1.0 / 6.0),
            ("+1 h", 1.0),
        ] {
            if ui.button(label).clicked() {
                // A date the ephemerides refuse stays where it was.
                let _ = state.shift_time(hours);
            }
        }
    });
    if let Some(l) = state.scene.location.as_mut() {
        ui.add(egui::Slider::new(&mut l.lat_deg, -90.0..=90.0).text("latitude °"));
        ui.add(egui::Slider::new(&mut l.lon_deg, -180.0..=180.0).text("longitude °"));
    }
    if let Some(t) = state.scene.time.as_mut() {
        ui.checkbox(&mut t.moon_disk, "moon disk");
    }
}

/// The atmosphere's adjustments (`[atmosphere.adjust]`), each slider starting from the
/// atmosphere's own value.
pub(super) fn air_section(ui: &mut egui::Ui, state: &mut ViewState) {
    let Some(own) = state.air_values() else {
        return;
    };
    let terrain = state.scene.terrain.is_some();
    let a = &mut state.scene.atmosphere.adjust;
    adjust_slider(
        ui,
        &mut a.aerosol_optical_depth,
        own.aerosol_optical_depth,
        (0.0, 3.0),
        "aerosol optical depth (550 nm)",
        (true, own.aerosol_optical_depth > 0.0),
    );
    adjust_slider(
        ui,
        &mut a.ozone_du,
        own.ozone_du,
        (0.0, 1000.0),
        "ozone DU",
        (false, own.ozone_du > 0.0),
    );
    adjust_slider(
        ui,
        &mut a.rayleigh_scale,
        1.0,
        (0.0, 10.0),
        "Rayleigh scale",
        (true, true),
    );
    adjust_slider(
        ui,
        &mut a.ground_albedo,
        own.ground_albedo,
        (0.0, 1.0),
        "ground albedo",
        (false, !terrain),
    );
    if terrain {
        ui.small("(the terrain's materials light the tables' ground)");
    }
    let mut km = a.planet_radius_m.unwrap_or(own.planet_radius_m) / 1e3;
    // Up to the largest planet the tables take under this shell (bruneton4d::shell).
    let (lo, hi) = adjust::PLANET_RADIUS_RANGE_M;
    let hi = hi.min(own.shell_m / shell::MIN_RELATIVE_THICKNESS).max(lo);
    if ui
        .add(
            egui::Slider::new(&mut km, lo / 1e3..=hi / 1e3)
                .logarithmic(true)
                .text("planet radius km"),
        )
        .changed()
    {
        a.planet_radius_m = Some(km * 1e3);
    }
    ui.horizontal(|ui| {
        if ui.button("the atmosphere's own values").clicked() {
            state.scene.atmosphere.adjust = Default::default();
        }
        let label = ui.label("4D update frames");
        ui.add(egui::DragValue::new(&mut state.update_frames).range(1..=120))
            .labelled_by(label.id)
            .on_hover_text(
                "a new atmosphere's 4D tables are spread over this many frames on a software rasteriser",
            );
    });
}

/// The scene's cloud layers: coverage, base (the thickness kept) and the wind's offset.
pub(super) fn clouds_section(ui: &mut egui::Ui, state: &mut ViewState) {
    use firmament::scene::clouds::{CloudKind, CloudLayerConfig};
    ui.horizontal(|ui| {
        ui.label("Clouds (bruneton4d)");
        if ui.button("add a layer").clicked() {
            let layer = CloudLayerConfig::of_kind(CloudKind::Cumulus);
            state.scene.clouds.push(layer);
        }
    });
    if !state.scene.clouds.is_empty() || state.scene.terrain.is_some() {
        ui.horizontal(|ui| {
            ui.label("pixels marched a frame:");
            for (step, label) in [(1, "all"), (2, "1/4"), (4, "1/16")] {
                if ui
                    .selectable_label(state.march_step == step, label)
                    .clicked()
                {
                    state.march_step = step;
                }
            }
        });
    }
    let mut remove = None;
    for (i, layer) in state.scene.clouds.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            for kind in [
                CloudKind::Cumulus,
                CloudKind::Altostratus,
                CloudKind::Cirrus,
                CloudKind::Uniform,
            ] {
                let label = format!("{:?}", kind).to_lowercase();
                if ui
                    .selectable_label(layer.kind == kind, format!("{label} {i}"))
                    .clicked()
                    && layer.kind != kind
                {
                    // The new kind's own heights, coverage and extinction.
                    let (seed, wind) = (layer.seed, layer.wind_offset_m);
                    *layer = CloudLayerConfig::of_kind(kind);
                    (layer.seed, layer.wind_offset_m) = (seed, wind);
                }
            }
            if ui.button(format!("remove {i}")).clicked() {
                remove = Some(i);
            }
        });
        let p = layer.resolved();
        let name = format!("{:?}", p.kind).to_lowercase();
        let mut coverage = p.coverage;
        if ui
            .add(egui::Slider::new(&mut coverage, 0.0..=1.0).text(format!("{name} {i}: coverage")))
            .changed()
        {
            layer.coverage = Some(coverage);
        }
        let mut base_km = p.bottom_m / 1e3;
        if ui
            .add(egui::Slider::new(&mut base_km, 0.1..=15.0).text(format!("{name} {i}: base km")))
            .changed()
        {
            let thickness = p.top_m - p.bottom_m;
            layer.bottom_m = Some(base_km * 1e3);
            layer.top_m = Some(base_km * 1e3 + thickness);
        }
        ui.horizontal(|ui| {
            let label = ui.label(format!("{name} {i}: wind offset km (east, north)"));
            for k in 0..2 {
                let mut km = layer.wind_offset_m[k] / 1e3;
                if ui
                    .add(egui::DragValue::new(&mut km).speed(0.1))
                    .labelled_by(label.id)
                    .changed()
                {
                    layer.wind_offset_m[k] = km * 1e3;
                }
            }
        });
    }
    if let Some(i) = remove {
        state.scene.clouds.remove(i);
    }
}

/// A slider for an adjustment: shows `own` until moved, then holds the value moved to.
fn adjust_slider(
    ui: &mut egui::Ui,
    value: &mut Option<f64>,
    own: f64,
    (lo, hi): (f64, f64),
    label: &str,
    (logarithmic, enabled): (bool, bool),
) {
    let mut v = value.unwrap_or(own);
    let slider = egui::Slider::new(&mut v, lo..=hi)
        .logarithmic(logarithmic)
        .text(label);
    if ui.add_enabled(enabled, slider).changed() {
        *value = Some(v);
    }
}
