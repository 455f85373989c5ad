//! Integer hashes for deterministic noise (the terrain's patches, the image's dither), 32-bit
//! so that WGSL computes the same values (`shaders/terrain/materials.wgsl`).

/// Wellons's "lowbias32" finaliser (C. Wellons 2018, "Prospecting for hash functions",
/// bias 0.17).
#[inline]
pub fn lowbias32(mut v: u32) -> u32 {
    v ^= v >> 16;
    v = v.wrapping_mul(0x7feb_352d);
    v ^= v >> 15;
    v = v.wrapping_mul(0x846c_a68b);
    v ^ (v >> 16)
}

/// A hash of a lattice point with a salt: [`lowbias32`] chained over the salt and the two
/// coordinates.
#[inline]
pub fn hash32(salt: u32, x: i32, y: i32) -> u32 {
    lowbias32(x as u32 ^ lowbias32(y as u32 ^ lowbias32(salt)))
}

/// A uniform value in [0, 1) from a hash (its top 24 bits).
#[inline]
pub fn unit(h: u32) -> f64 {
    (h >> 8) as f64 / (1u32 << 24) as f64
}
