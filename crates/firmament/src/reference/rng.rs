//! A small counter-based random number generator: every path gets its own stream, keyed by
//! (seed, pixel, channel, sample), so results do not depend on thread scheduling.
//!
//! SplitMix64 (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number
//! generators", OOPSLA; the finaliser is Stafford's "Mix13"), used both as the key hash
//! and as the stream generator.

/// SplitMix64's output function (a bijective 64-bit mixer).
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// A SplitMix64 stream.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// The stream for a key (seed, pixel, channel, sample): the key words are hashed in
    /// sequence so that nearby keys give unrelated streams.
    pub fn for_key(seed: u64, pixel: u64, channel: u64, sample: u64) -> Rng {
        let mut h = mix64(seed ^ 0x5151_7a7a_0f0f_3c3c);
        h = mix64(h ^ pixel.wrapping_mul(GOLDEN));
        h = mix64(h ^ channel.wrapping_add(1).wrapping_mul(0xd6e8_feb8_6659_fd93));
        h = mix64(h ^ sample.wrapping_mul(0xa076_1d64_78bd_642f));
        Rng { state: h }
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN);
        mix64(self.state)
    }

    /// Uniform in [0, 1) with 53 random bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Exponential variate with rate 1 (−ln(1 − u), u in [0, 1): finite).
    #[inline]
    pub fn exponential(&mut self) -> f64 {
        -(1.0 - self.next_f64()).ln()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_mean_and_variance() {
        let mut rng = Rng::for_key(1, 2, 3, 4);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let u = rng.next_f64();
            assert!((0.0..1.0).contains(&u));
            s += u;
            s2 += u * u;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!((mean - 0.5).abs() < 0.003, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 0.002, "{var}");
    }

    #[test]
    fn keys_give_different_streams() {
        let a = Rng::for_key(0, 0, 0, 0).next_u64();
        let b = Rng::for_key(0, 0, 0, 1).next_u64();
        let c = Rng::for_key(0, 1, 0, 0).next_u64();
        let d = Rng::for_key(0, 0, 1, 0).next_u64();
        assert!(a != b && a != c && a != d && b != c && c != d);
    }
}
