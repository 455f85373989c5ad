//! Running the paths: blocks of samples per wavelength in parallel, each with its own
//! random stream, reduced in a fixed order (results independent of the thread count).

use rayon::prelude::*;

use super::rng::Rng;
use super::tracer::{self, Channel};
use super::ReferenceSettings;
use crate::atmosphere::Model;
use crate::scene::{Surface, Volume};

/// Samples per block: the unit of parallel work and of the fixed-order reduction.
const BLOCK: usize = 256;

/// Running mean and variance (Welford; merged with Chan et al.'s formula).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Stats {
    pub(super) n: f64,
    pub(super) mean: f64,
    m2: f64,
}

impl Stats {
    #[inline]
    pub(super) fn push(&mut self, x: f64) {
        self.n += 1.0;
        let delta = x - self.mean;
        self.mean += delta / self.n;
        self.m2 += delta * (x - self.mean);
    }

    pub(super) fn merge(self, o: Stats) -> Stats {
        if self.n == 0.0 {
            return o;
        }
        if o.n == 0.0 {
            return self;
        }
        let n = self.n + o.n;
        let delta = o.mean - self.mean;
        Stats {
            n,
            mean: self.mean + delta * o.n / n,
            m2: self.m2 + o.m2 + delta * delta * self.n * o.n / n,
        }
    }

    pub(super) fn stderr(&self) -> f64 {
        if self.n < 2.0 {
            f64::INFINITY
        } else {
            (self.m2 / (self.n - 1.0) / self.n).max(0.0).sqrt()
        }
    }
}

/// Runs `f` for `settings.samples` samples per wavelength; returns per-wavelength stats of
/// each of the M tallies. Blocks of samples are run in parallel when `parallel`, and always
/// reduced in the same order.
pub(super) fn estimate<const M: usize, F>(
    model: &Model,
    volumes: &[Box<dyn Volume + '_>],
    surfaces: &[Box<dyn Surface + '_>],
    settings: &ReferenceSettings,
    key: u64,
    parallel: bool,
    f: F,
) -> Vec<[Stats; M]>
where
    F: Fn(&Channel, &mut Rng, &mut tracer::Scratch) -> [f64; M] + Sync,
{
    let n_ch = model.channels();
    let samples = settings.samples;
    let blocks = samples.div_ceil(BLOCK).max(1);
    let channels: Vec<Channel> = (0..n_ch)
        .map(|k| Channel::new(model, volumes, surfaces, k, settings))
        .collect();
    let run = |job: usize| -> [Stats; M] {
        let (k, blk) = (job / blocks, job % blocks);
        let ch = &channels[k];
        let mut scratch = ch.scratch();
        let mut stats = [Stats::default(); M];
        for i in blk * BLOCK..((blk + 1) * BLOCK).min(samples) {
            let mut rng = Rng::for_key(settings.seed, key, k as u64, i as u64);
            let v = f(ch, &mut rng, &mut scratch);
            for m in 0..M {
                stats[m].push(v[m]);
            }
        }
        stats
    };
    let per_block: Vec<[Stats; M]> = if parallel {
        (0..n_ch * blocks).into_par_iter().map(run).collect()
    } else {
        (0..n_ch * blocks).map(run).collect()
    };
    (0..n_ch)
        .map(|k| {
            let mut acc = [Stats::default(); M];
            for blk in 0..blocks {
                for m in 0..M {
                    acc[m] = acc[m].merge(per_block[k * blocks + blk][m]);
                }
            }
            acc
        })
        .collect()
}
