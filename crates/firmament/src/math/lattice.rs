//! Evenly spread directions: the Fibonacci lattice on the sphere (González 2010,
//! "Measurement of areas on a sphere using Fibonacci and latitude–longitude lattices",
//! Math. Geosci. 42) and on a band of it.

use super::Vec3;

/// `n` directions spread evenly over the sphere, each standing for 4π/n sr.
pub fn sphere_directions(n: usize) -> Vec<Vec3> {
    band_directions(Vec3::Z, -1.0, 1.0, n)
}

/// `n` directions spread evenly over the band of directions d with `z0` < d·`axis` < `z1`
/// (the lattice on the band of z; a cap round `axis` when `z1` = 1), each standing for
/// 2π(z1 − z0)/n sr.
pub fn band_directions(axis: Vec3, z0: f64, z1: f64, n: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let (e1, e2) = axis.any_orthonormal_pair();
    (0..n)
        .map(|i| {
            let z = z1 - (z1 - z0) * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            s * phi.cos() * e1 + s * phi.sin() * e2 + z * axis
        })
        .collect()
}
