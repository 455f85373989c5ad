//! Amortised table updates (Hillaire 2016 §2 "Our approach": once the tables are computed
//! the sun moves freely, but a change of the atmosphere's parameters (a time of day with a
//! changing turbidity, a weather transition) triggers an update too costly for one frame, so
//! its cost is spread over several frames).
//!
//! [`AmortisedTables`] is a double buffer: the front [`Bruneton4d`] (a model and its complete
//! tables) is what every view reads, and at most one [`PrecomputeJob`] for a new model runs
//! behind it, 1/N of its cost per [`AmortisedTables::frame`]; when it completes, the front is
//! replaced whole. The job's tables are private to it until then, and a view borrows the
//! front (or holds its `Arc`, [`AmortisedTables::shared`]), so no frame reads a half-built
//! table or a mix of two sets. The tables swapped in are those of [`Tables::compute`] bit for
//! bit: every unit computes its texels as the direct precomputation does.
//!
//! [`Tables::compute`]: super::Tables::compute

use std::sync::Arc;

use super::precompute::PrecomputeJob;
use super::{Bruneton4d, TableConfig};
use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::sky::{SkyMethod, SkyView};
use crate::{Error, Result};

/// The most frames an update may be spread over.
pub const MAX_FRAMES: usize = 100_000;

/// What [`AmortisedTables::request`] does while an update is running.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RequestPolicy {
    /// The running update finishes (and is swapped in); the newest request then starts
    /// (earlier waiting ones are dropped). A change requested every frame (a slow drift of
    /// the turbidity) still updates the front every N frames, at most 2N frames behind.
    #[default]
    Queue,
    /// The running update is dropped and the newest request starts over: the front
    /// reaches the newest model sooner once requests stop, but a change requested more
    /// often than every N frames never reaches the front.
    Restart,
}

/// An update in flight: the job and the frames it has had.
struct Update {
    job: PrecomputeJob,
    frames: usize,
    frames_done: usize,
}

impl Update {
    fn progress(&self, queued: bool) -> UpdateProgress {
        UpdateProgress {
            atmosphere_hash: self.job.model().hash,
            fraction: self.job.fraction(),
            frames_left: self.frames.saturating_sub(self.frames_done),
            queued,
        }
    }
}

/// Where an update stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateProgress {
    /// [`Model::hash`] of the model being computed.
    pub atmosphere_hash: u64,
    /// Share of its cost done, in [0, 1].
    pub fraction: f64,
    /// Frames until it is swapped in (for a running update; its whole N when queued).
    pub frames_left: usize,
    /// Whether it waits for the running one ([`RequestPolicy::Queue`]).
    pub queued: bool,
}

/// What one [`AmortisedTables::frame`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameReport {
    /// Units of the update run this frame.
    pub units: usize,
    /// Their estimated cost ([`crate::sky::bruneton4d::precompute::Unit::weight`]).
    pub weight: f64,
    /// Whether this frame replaced the front by the completed update.
    pub swapped: bool,
    /// [`AmortisedTables::generation`] of the front after this frame.
    pub generation: u64,
    /// [`Model::hash`] of the front after this frame.
    pub atmosphere_hash: u64,
    /// The update still in flight after this frame, if any.
    pub running: Option<UpdateProgress>,
}

/// A sky method whose tables follow a changing atmosphere, each update spread over
/// [`AmortisedTables::frames`] frames (see the [module](self) notes).
pub struct AmortisedTables {
    front: Arc<Bruneton4d>,
    config: TableConfig,
    frames: usize,
    policy: RequestPolicy,
    generation: u64,
    running: Option<Update>,
    queued: Option<PrecomputeJob>,
}

impl AmortisedTables {
    /// Start from a complete set (its configuration is used for every update), updates
    /// spread over `frames` frames (1 = the whole update in the next frame).
    pub fn new(front: Bruneton4d, frames: usize) -> Result<AmortisedTables> {
        check_frames(frames)?;
        Ok(AmortisedTables {
            config: front.tables.config,
            front: Arc::new(front),
            frames,
            policy: RequestPolicy::default(),
            generation: 0,
            running: None,
            queued: None,
        })
    }

    /// Precompute the first set directly (not amortised) and start from it.
    pub fn compute(model: Model, config: &TableConfig, frames: usize) -> Result<AmortisedTables> {
        check_frames(frames)?;
        AmortisedTables::new(Bruneton4d::compute(model, config)?, frames)
    }

    /// The same with this [`RequestPolicy`].
    pub fn with_policy(mut self, policy: RequestPolicy) -> AmortisedTables {
        self.policy = policy;
        self
    }

    /// The set in use: a complete, consistent model and tables.
    pub fn front(&self) -> &Bruneton4d {
        &self.front
    }

    /// The set in use, to hold across frames (a render thread): it stays whole and
    /// unchanged after a swap replaces it here.
    pub fn shared(&self) -> Arc<Bruneton4d> {
        Arc::clone(&self.front)
    }

    /// The number of swaps so far (0 for the first set): which set is in use.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Frames an update is spread over.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Spread the updates that start from now on over `frames` frames (a running one keeps
    /// its own count).
    pub fn set_frames(&mut self, frames: usize) -> Result<()> {
        check_frames(frames)?;
        self.frames = frames;
        Ok(())
    }

    /// The table configuration of every set.
    pub fn config(&self) -> &TableConfig {
        &self.config
    }

    /// Ask for the tables of `model`, computed over the next [`AmortisedTables::frames`]
    /// frames (after the running update under [`RequestPolicy::Queue`]). The model is
    /// checked at once (as [`Tables::compute`](super::Tables::compute) would check it) and
    /// must keep the front's wavelengths, so that a swap never changes the channels a
    /// renderer holds buffers for. Asking for the model already in use, or already being
    /// computed, starts nothing.
    pub fn request(&mut self, model: Model) -> Result<()> {
        if model.wavelengths.nm() != self.front.model.wavelengths.nm() {
            return Err(Error::invalid(
                "wavelengths",
                format!("{:?} nm", model.wavelengths.nm()),
                format!(
                    "the wavelengths of the tables in use, {:?} nm",
                    self.front.model.wavelengths.nm()
                ),
            ));
        }
        let hash = model.hash;
        let running_hash = self.running.as_ref().map(|u| u.job.model().hash);
        // The model the front will hold once nothing else is asked for.
        if running_hash.unwrap_or(self.front.model.hash) == hash {
            self.queued = None;
            return Ok(());
        }
        if self.queued.as_ref().map(|job| job.model().hash) == Some(hash) {
            return Ok(());
        }
        if running_hash.is_some()
            && self.policy == RequestPolicy::Restart
            && hash == self.front.model.hash
        {
            // Back to the set in use: nothing to compute.
            self.running = None;
            self.queued = None;
            return Ok(());
        }
        let job = PrecomputeJob::new(model, &self.config)?;
        match (&self.running, self.policy) {
            (Some(_), RequestPolicy::Queue) => self.queued = Some(job),
            _ => {
                self.queued = None;
                self.start(job);
            }
        }
        Ok(())
    }

    /// Drop the running and queued updates; the front stays.
    pub fn cancel(&mut self) {
        self.running = None;
        self.queued = None;
    }

    /// The running update, if any (the queued one is [`AmortisedTables::queued`]).
    pub fn progress(&self) -> Option<UpdateProgress> {
        self.running.as_ref().map(|u| u.progress(false))
    }

    /// The update waiting for the running one, if any.
    pub fn queued(&self) -> Option<UpdateProgress> {
        self.queued.as_ref().map(|job| UpdateProgress {
            atmosphere_hash: job.model().hash,
            fraction: 0.0,
            frames_left: self.frames,
            queued: true,
        })
    }

    /// Call once per frame, before the frame's views: runs the running update's share for
    /// this frame (frame k of N brings it to k/N of its cost; the N-th completes it) and
    /// swaps the completed tables in. Idle when nothing was asked for.
    pub fn frame(&mut self) -> FrameReport {
        let (mut units, mut weight, mut swapped) = (0, 0.0, false);
        if let Some(update) = self.running.as_mut() {
            update.frames_done += 1;
            let before = update.job.done_weight();
            let target = update.frames_done as f64 / update.frames as f64;
            units = update.job.step_to(target);
            weight = update.job.done_weight() - before;
            if update.job.is_done() {
                self.swap();
                swapped = true;
            }
        }
        FrameReport {
            units,
            weight,
            swapped,
            generation: self.generation,
            atmosphere_hash: self.front.model.hash,
            running: self.progress(),
        }
    }

    /// Complete the running update now (a loading screen, a cut) and swap it in; the
    /// queued one then starts. False when none was running.
    pub fn complete_now(&mut self) -> bool {
        if self.running.is_none() {
            return false;
        }
        self.swap();
        true
    }

    fn start(&mut self, job: PrecomputeJob) {
        self.running = Some(Update {
            job,
            frames: self.frames,
            frames_done: 0,
        });
    }

    /// Replace the front by the running update's tables (computing what is left) and start
    /// the queued update.
    fn swap(&mut self) {
        let Some(update) = self.running.take() else {
            return;
        };
        let (model, tables) = update.job.finish();
        self.front = Arc::new(Bruneton4d::pair(model, tables));
        self.generation += 1;
        if let Some(job) = self.queued.take() {
            self.start(job);
        }
    }
}

fn check_frames(frames: usize) -> Result<()> {
    if (1..=MAX_FRAMES).contains(&frames) {
        Ok(())
    } else {
        Err(Error::invalid(
            "frames",
            frames,
            format!("an integer in [1, {MAX_FRAMES}]"),
        ))
    }
}

impl SkyMethod for AmortisedTables {
    fn model(&self) -> &Model {
        &self.front.model
    }

    fn view<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        self.front.view(observer, light)
    }

    fn probe<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        self.front.probe(observer, light)
    }
}
