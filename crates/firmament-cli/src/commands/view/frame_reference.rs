//! The reference path tracer beside the viewer's frame ([`FramePath`]'s part of it): what
//! it traces for the view drawn (the same model unlifted, terrain, map and clouds), or why
//! it cannot, and what the panel and `--reference-passes` read of it.

use std::sync::Arc;

use anyhow::Result;
use firmament::scene::sky_lights::SkySources;

use super::super::progressive::{Compare, Job};
use super::super::state::ViewState;
use super::sky::{AirKey, SkyKey};
use super::FramePath;

impl FramePath {
    /// What the reference traces for this frame, or why it cannot.
    pub(super) fn reference_job(
        &mut self,
        state: &ViewState,
        sources: &SkySources,
        camera: &firmament::scene::Camera,
        size: (u32, u32),
    ) -> std::result::Result<Job, String> {
        if state.compare == Compare::Off {
            return Err(String::new());
        }
        if sources.lights.len() != 1 || sources.background.is_some() {
            return Err(
                "traces the sun's light only so far (not with the moon up or the sun below the horizon)"
                    .into(),
            );
        }
        let key = (SkyKey::of(state), AirKey::of(state));
        if self.ref_model.as_ref().is_none_or(|(k, _)| *k != key) {
            // The planet's own ground: the tracer meets the terrain itself.
            let args = self.args.as_ref().ok_or("no sky yet")?.unlifted();
            let model = args.model().map_err(|e| format!("{e:#}"))?;
            self.ref_model = Some((key, Arc::new(model)));
        }
        if state.scene.surface.as_ref().is_some_and(|s| s.glint) {
            return Err("traces Lambertian surfaces only: not the sun's glint on the sea (the map's `glint = false` lets it trace the map)".into());
        }
        let (_, model) = self.ref_model.as_ref().expect("just made");
        // The clouds the method draws, the tracer meets too.
        let volumes = match &self.clouds {
            Some((_, _, media)) if self.clouds_drawn(state) => Some(media.clone()),
            _ => None,
        };
        Ok(Job {
            model: model.clone(),
            terrain: self.terrain.clone(),
            planet: self.planet.as_ref().map(|m| m.cpu.clone()),
            volumes,
            camera: camera.clone(),
            sun: sources.lights[0].clone(),
            size,
            white_balance: state.scene.output.white_balance,
        })
    }

    /// What the panel says of the reference, when shown.
    pub fn reference_line(&self) -> Option<String> {
        self.reference.line.clone()
    }

    /// Why the reference is not traced for the view last drawn, when it is not.
    pub fn reference_refused(&self) -> Option<&str> {
        self.reference.refused.as_deref()
    }

    /// The method against the reference when its last pass arrived: the relative
    /// difference of the mean luminances and the mean |ΔL|/L (the reference's noise in it).
    pub fn reference_difference(&self) -> Option<(f64, f64)> {
        self.reference.difference()
    }

    /// Passes the reference has averaged for the view last drawn (0 before the first).
    pub fn reference_passes(&self) -> usize {
        self.reference.tracer.passes()
    }

    /// Waits until the reference, which traces beside the frames, has averaged `passes`
    /// passes for the view last drawn: an error when it refused that view or the user
    /// interrupted.
    pub fn wait_for_reference(&self, passes: usize) -> Result<()> {
        while self.reference_passes() < passes {
            if let Some(why) = self.reference_refused() {
                anyhow::bail!("`--reference`: the reference {why}");
            }
            if crate::common::cancel_flag().load(std::sync::atomic::Ordering::Relaxed) {
                anyhow::bail!("interrupted");
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        Ok(())
    }
}
