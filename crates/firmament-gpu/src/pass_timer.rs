//! Per-pass GPU times of a frame loop from timestamp queries, read back without stalling:
//! each frame's timestamps are resolved into a buffer and copied to a staging buffer while
//! no earlier copy is in flight; the copy is mapped asynchronously and read on a later
//! frame. A device without `TIMESTAMP_QUERY` gives no times (the caller says so).
//!
//! Slots: 0–3 for the sky ([`crate::RenderInputs::timestamps`]: 0–1 the pass of the 4D and
//! 3D tables, Hillaire's sky view 0–1 and pixels 2–3), 4–7 for the display
//! ([`crate::display::Display::encode`]: exposure 4–5, tone mapping 6–7).

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

use crate::GpuContext;

/// Queries in a frame's set.
pub const PASS_QUERIES: u32 = 8;
const BYTES: u64 = PASS_QUERIES as u64 * 8;

/// One frame's GPU times (ms).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// The sky's passes (Hillaire's sky view and pixels together), first start to last end.
    pub sky_ms: f64,
    /// The exposure meter and the tone mapping.
    pub display_ms: f64,
}

/// Which of slots 0–3 the sky's passes wrote ([`crate::RenderInputs::timestamps`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkySlots {
    /// One pass at 0–1 (the 4D and 3D tables).
    One,
    /// Hillaire 2020's sky view at 0–1 and pixels at 2–3 (an observer in the atmosphere).
    Two,
    /// Hillaire 2020's pixels alone at 2–3 (an observer in space: no sky view).
    Pixels,
}

/// Staging states.
const IDLE: u8 = 0;
const MAPPING: u8 = 1;
const MAPPED: u8 = 2;
const FAILED: u8 = 3;

/// Timestamp queries of a frame loop.
pub struct PassTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    staging: wgpu::Buffer,
    state: Arc<AtomicU8>,
    /// The slots of the sky's first start and last end in the frame in flight.
    sky_slots: SkySlots,
    /// A copy was recorded and not yet mapped.
    copy_recorded: bool,
    period_ns: f64,
    last: Option<PassTimes>,
}

impl PassTimer {
    /// A timer, or None when the device has no timestamp queries.
    pub fn new(ctx: &GpuContext) -> Option<PassTimer> {
        if !ctx.supports_timestamps() {
            return None;
        }
        let device = ctx.device();
        Some(PassTimer {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: PASS_QUERIES,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timestamps"),
                size: BYTES,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            staging: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timestamps readback"),
                size: BYTES,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            state: Arc::new(AtomicU8::new(IDLE)),
            sky_slots: SkySlots::One,
            copy_recorded: false,
            period_ns: ctx.queue().get_timestamp_period() as f64,
            last: None,
        })
    }

    /// The query set the frame's passes write into.
    pub fn query_set(&self) -> &wgpu::QuerySet {
        &self.set
    }

    /// After the frame's passes: resolve the timestamps and, when no copy is in flight,
    /// copy them out. `sky_slots`: which of slots 0–3 the sky wrote.
    /// Returns whether a copy was recorded ([`PassTimer::after_submit`] then maps it).
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder, sky_slots: SkySlots) -> bool {
        if self.state.load(Ordering::Acquire) != IDLE {
            return false;
        }
        // The whole set (slots 2–3 unwritten without Hillaire read as 0 and are ignored):
        // a resolve's offset must be a multiple of 256 bytes.
        encoder.resolve_query_set(&self.set, 0..PASS_QUERIES, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.staging, 0, BYTES);
        self.sky_slots = sky_slots;
        self.copy_recorded = true;
        true
    }

    /// After the submission holding a recorded copy: start mapping it.
    pub fn after_submit(&mut self) {
        if !std::mem::take(&mut self.copy_recorded) {
            return;
        }
        self.state.store(MAPPING, Ordering::Release);
        let state = self.state.clone();
        self.staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                state.store(if r.is_ok() { MAPPED } else { FAILED }, Ordering::Release);
            });
    }

    /// The latest times read back (polls the device without waiting).
    pub fn times(&mut self, ctx: &GpuContext) -> Option<PassTimes> {
        let _ = ctx.device().poll(wgpu::PollType::Poll);
        match self.state.load(Ordering::Acquire) {
            MAPPED => {
                let ticks: Vec<u64> = match self.staging.slice(..).get_mapped_range() {
                    Ok(view) => bytemuck::pod_collect_to_vec(&view),
                    Err(_) => Vec::new(),
                };
                self.staging.unmap();
                self.state.store(IDLE, Ordering::Release);
                if ticks.len() == PASS_QUERIES as usize {
                    let ms = |a: u64, b: u64| b.saturating_sub(a) as f64 * self.period_ns * 1e-6;
                    let (start, end) = match self.sky_slots {
                        SkySlots::One => (0, 1),
                        SkySlots::Two => (0, 3),
                        SkySlots::Pixels => (2, 3),
                    };
                    self.last = Some(PassTimes {
                        sky_ms: ms(ticks[start], ticks[end]),
                        display_ms: ms(ticks[4], ticks[7]),
                    });
                }
            }
            FAILED => self.state.store(IDLE, Ordering::Release),
            _ => {}
        }
        self.last
    }
}
