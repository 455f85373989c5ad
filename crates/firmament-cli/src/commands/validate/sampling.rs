//! The reference's sample counts: fixed, or adaptive (a pilot, then enough paths for a
//! target relative standard error of luminance, capped); and the tracing of one
//! configuration's views in parallel.

use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::math::Vec3;
use firmament::reference::{self, RadianceEstimate, ReferenceSettings};
use firmament::spectrum::ColourMatrix;
use indicatif::ProgressBar;
use rayon::prelude::*;

use super::views::View;
use crate::common::cancel_flag;

/// Pilot paths per wavelength for the adaptive sample count.
pub const PILOT_SAMPLES: usize = 1024;

/// How many paths per wavelength the reference traces for a view.
#[derive(Clone, Copy, Debug)]
pub enum SamplePlan {
    Fixed(usize),
    /// Enough for a relative standard error of luminance `target` (a fraction), at most
    /// `max`.
    Adaptive {
        target: f64,
        max: usize,
    },
}

/// Reference estimates of every view seen from `camera` with the sun in `sun`, in
/// parallel; view `i` uses the random streams of `(stream_base << 16) | i`. Each finished
/// view advances `bar`; Ctrl-C stops it ("interrupted").
pub fn trace_views(
    model: &Model,
    colour: &ColourMatrix,
    camera: Vec3,
    sun: Vec3,
    views: &[View],
    plan: &SamplePlan,
    seed: u64,
    stream_base: u64,
    bar: &ProgressBar,
) -> Result<Vec<RadianceEstimate>> {
    let cancel = cancel_flag();
    let interrupted = AtomicBool::new(false);
    let estimates: Vec<Option<RadianceEstimate>> = views
        .par_iter()
        .enumerate()
        .map(|(i, v)| {
            if cancel.load(Ordering::Relaxed) {
                interrupted.store(true, Ordering::Relaxed);
                return None;
            }
            let key = (stream_base << 16) | i as u64;
            let estimate = trace_view(model, colour, camera, v.dir, sun, plan, seed, key);
            bar.inc(1);
            Some(estimate)
        })
        .collect();
    if interrupted.load(Ordering::Relaxed) {
        bar.finish_and_clear();
        anyhow::bail!("interrupted");
    }
    Ok(estimates.into_iter().flatten().collect())
}

/// Reference estimate for one view: a pilot, then enough paths for the target (or a fixed
/// count). The same key keeps the pilot's paths in the final estimate.
fn trace_view(
    model: &Model,
    colour: &ColourMatrix,
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    plan: &SamplePlan,
    seed: u64,
    key: u64,
) -> RadianceEstimate {
    let trace = |samples| {
        let settings = ReferenceSettings {
            samples,
            seed,
            ..Default::default()
        };
        reference::sky_radiance_keyed(model, camera, view, sun, &settings, key)
    };
    let (target, max) = match *plan {
        SamplePlan::Fixed(n) => return trace(n),
        SamplePlan::Adaptive { target, max } => (target, max),
    };
    let pilot = trace(PILOT_SAMPLES);
    let relative_stderr = relative_luminance_stderr(colour, &pilot);
    if !relative_stderr.is_finite() || relative_stderr <= target {
        return pilot;
    }
    let wanted = (PILOT_SAMPLES as f64 * (relative_stderr / target).powi(2) * 1.1).ceil() as usize;
    let n = wanted.div_ceil(256) * 256;
    let n = n.clamp(PILOT_SAMPLES, max.max(PILOT_SAMPLES));
    if n == PILOT_SAMPLES {
        return pilot;
    }
    trace(n)
}

/// The estimate's relative standard error of luminance (infinite when it is dark).
fn relative_luminance_stderr(colour: &ColourMatrix, e: &RadianceEstimate) -> f64 {
    let (y, stderr) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
    if y > 0.0 {
        stderr / y
    } else {
        f64::INFINITY
    }
}
