//! The viewer's sky as the panel changes it: built afresh when the method, the
//! wavelengths or the terrain change; its tables re-run for a new atmosphere with the
//! compiled passes kept (`RenderSky::retable`), or, for the 4D tables on a software
//! rasteriser, computed over frames by `AmortisedTables` while the previous ones are drawn.

use std::sync::Arc;

use anyhow::{Context, Result};
use firmament::atmosphere::Adjustments;
use firmament::sky::bruneton4d::amortised::AmortisedTables;
use firmament::sky::bruneton4d::Bruneton4d;

use super::FramePath;
use crate::backend::RenderSky;
use crate::commands::render::terrain_and_atmosphere;
use crate::commands::view::state::ViewState;
use crate::method::Method;

/// What the sky's passes and buffers depend on: the sky is built afresh when it changes.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct SkyKey {
    pub(super) method: Method,
    pub(super) wavelengths: Option<String>,
    /// The terrain's configuration (its tables take its albedo and floor), as TOML.
    pub(super) terrain: Option<String>,
}

impl SkyKey {
    pub(super) fn of(state: &ViewState) -> SkyKey {
        SkyKey {
            method: state.method,
            wavelengths: state.scene.atmosphere.wavelengths.clone(),
            terrain: state
                .scene
                .terrain
                .as_ref()
                .map(|t| toml::to_string(t).unwrap_or_default()),
        }
    }
}

/// What only the tables depend on: a change re-runs the tables with the sky's passes kept
/// (`RenderSky::retable`), or, for the 4D tables on a software rasteriser, spreads their
/// precomputation over frames (`AmortisedTables`) while the previous ones are drawn.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct AirKey {
    preset: String,
    file: Option<std::path::PathBuf>,
    adjust: Adjustments,
}

impl AirKey {
    pub(super) fn of(state: &ViewState) -> AirKey {
        let a = &state.scene.atmosphere;
        AirKey {
            preset: a.preset.clone(),
            file: a.file.clone(),
            adjust: a.adjust.clone(),
        }
    }
}

impl FramePath {
    /// Build the sky when the method, the wavelengths or the terrain changed; re-run its
    /// tables when only the atmosphere did (amortised over frames for the 4D tables on a
    /// software rasteriser); run this frame's share of an amortised update. Returns whether
    /// the tables drawn changed (the exposure adapts afresh).
    pub fn ensure_sky(&mut self, state: &ViewState) -> Result<bool> {
        let (key, air) = (SkyKey::of(state), AirKey::of(state));
        let retable = match &self.sky {
            Some((k, a, _)) if *k == key => {
                // A new planet radius moves the terrain: built afresh.
                let moved = state.scene.terrain.is_some()
                    && a.adjust.planet_radius_m != air.adjust.planet_radius_m;
                (*a != air).then_some(!moved)
            }
            _ => Some(false),
        };
        match retable {
            Some(true) => self.retable(state, air)?,
            Some(false) => {
                self.build(state, key, air)?;
                return Ok(true);
            }
            None => {}
        }
        let Some(amortised) = self.amortised.as_mut() else {
            return Ok(false);
        };
        let report = amortised.frame();
        self.update = report.running;
        if !report.swapped {
            return Ok(false);
        }
        let front = amortised.front();
        let tables = Bruneton4d::new(front.model.clone(), front.tables.clone())?;
        let (_, _, sky) = self.sky.as_mut().expect("an update runs for a sky");
        sky.set_tables(tables)?;
        self.gpu_terrain = None;
        self.gpu_clouds = None;
        self.sky_generation += 1;
        Ok(true)
    }

    /// A fresh sky for `state`.
    fn build(&mut self, state: &ViewState, key: SkyKey, air: AirKey) -> Result<()> {
        let started = std::time::Instant::now();
        // The baked tables while the atmosphere is theirs (any method reads them as 4D).
        let tables = self.tables.as_ref().and_then(|(k, a, path)| {
            let same = k.wavelengths == key.wavelengths && k.terrain == key.terrain && *a == air;
            (same && key.method == Method::Bruneton4d).then(|| path.clone())
        });
        // With a terrain the tables take its mean albedo and its floor, as `render`'s do.
        let (terrain, mut atmosphere) =
            terrain_and_atmosphere(&state.scene, tables, &self.table_size, false, true)?;
        if atmosphere.tables.is_some() {
            // The file's wavelengths.
            atmosphere.wavelengths = None;
        }
        let software = self.ctx().is_software();
        let sky =
            RenderSky::with_tables_from(self.backend, &atmosphere, key.method, true, software)
                .with_context(|| format!("building the {} sky", key.method.name()))?;
        self.last_build_s = started.elapsed().as_secs_f64();
        // Later atmospheres keep these wavelengths and the terrain's ground.
        atmosphere.tables = None;
        atmosphere.wavelengths = Some(
            sky.model()
                .wavelengths
                .nm()
                .iter()
                .map(|w| w.to_string())
                .collect::<Vec<_>>()
                .join(","),
        );
        self.args = Some(atmosphere);
        self.sky = Some((key, air, sky));
        self.terrain = terrain.map(Arc::new);
        self.gpu_terrain = None;
        self.gpu_clouds = None;
        self.sky_generation += 1;
        self.amortised = None;
        self.update = None;
        Ok(())
    }

    /// The tables of a new atmosphere for the sky in use: the 4D tables on a software
    /// rasteriser through the amortised update (requested here, run by frames), any other
    /// at once with the sky's passes kept.
    fn retable(&mut self, state: &ViewState, air: AirKey) -> Result<()> {
        let mut args = self.args.clone().context("no sky yet")?;
        let a = &state.scene.atmosphere;
        (args.preset, args.atmosphere) = match &a.file {
            Some(f) => (None, Some(f.clone())),
            None => (Some(a.preset.clone()), None),
        };
        args.adjust = crate::common::AdjustArgs::of(&a.adjust);
        let software = self.ctx().is_software();
        let (key, held, sky) = self.sky.as_mut().context("no sky yet")?;
        if key.method == Method::Bruneton4d && software {
            let model = args.model()?;
            if self.amortised.is_none() {
                let RenderSky::Gpu { cpu_sky, .. } = sky else {
                    anyhow::bail!("the 4D sky on a software rasteriser holds its CPU tables");
                };
                let now = cpu_sky.get().context("the 4D sky's CPU tables")?;
                let front = Bruneton4d::new(now.model.clone(), now.tables.clone())?;
                self.amortised = Some(AmortisedTables::new(front, state.update_frames)?);
            }
            let amortised = self.amortised.as_mut().expect("just made");
            amortised.set_frames(state.update_frames)?;
            amortised.request(model)?;
        } else {
            let started = std::time::Instant::now();
            sky.retable(&args, true)
                .with_context(|| format!("the {} tables", key.method.name()))?;
            self.last_build_s = started.elapsed().as_secs_f64();
            self.gpu_terrain = None;
            self.gpu_clouds = None;
            self.sky_generation += 1;
        }
        *held = air;
        self.args = Some(args);
        Ok(())
    }

    /// A line for the panel while the 4D tables of a new atmosphere are computed over
    /// frames (the previous ones drawn meanwhile).
    pub fn update_line(&self) -> Option<String> {
        let u = self.update?;
        Some(format!(
            "new atmosphere's 4D tables: {:.0} % ({} frames left); drawing the previous ones",
            100.0 * u.fraction,
            u.frames_left
        ))
    }
}
