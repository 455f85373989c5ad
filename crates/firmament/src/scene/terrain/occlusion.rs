//! Ambient occlusion of the sky by the terrain: at every vertex the horizon's elevation
//! β(φ) in [`AZIMUTHS`] directions (the highest terrain seen within [`HORIZON_RANGE_M`],
//! lowered by the planet's curvature d²/2R), and the cosine-weighted share of the sky above
//! it seen by the surface, relative to an open plane of the same tilt (whose share,
//! (1 + n·up)/2, the sky method already applies: Bruneton & Neyret 2008 eq. 16). The share
//! per azimuth is the closed form of ∫ max(0, n·ω) cos e de from max(β, e₀) to π/2, with e₀
//! where the surface's own plane cuts the sky (Dozier & Frew 1990, "Rapid calculation of
//! terrain parameters for radiation modeling from digital elevation data", IEEE TGRS 28,
//! the sky-view factor). The sky is taken as uniform in azimuth for this ratio; light
//! reflected by the surrounding slopes is not added.

use rayon::prelude::*;

use super::grid::Grid;

/// Azimuths searched for the horizon.
pub const AZIMUTHS: usize = 8;
/// The occlusion is computed at every STRIDE-th vertex each way (it varies over the
/// horizon's scale, hundreds of metres, not a cell's) and interpolated between.
pub const STRIDE: usize = 2;
/// How far the horizon is searched (m).
pub const HORIZON_RANGE_M: f64 = 4000.0;

/// The visibility of the sky (0 to 1) at every `stride`-th vertex of `heights` (both ways)
/// on a planet of radius `radius_m`: a grid `stride` times coarser over the same rectangle
/// (the horizons searched on the full one), read by bilinear interpolation.
pub fn sky_visibility(heights: &Grid, radius_m: f64, stride: usize) -> Grid {
    let stride = stride.max(1);
    let dx = heights.spacing_m;
    let mut steps = Vec::new();
    let mut d = dx;
    while d <= HORIZON_RANGE_M {
        steps.push(d);
        d *= 1.3;
    }
    let dirs: Vec<(f64, f64)> = (0..AZIMUTHS)
        .map(|k| (std::f64::consts::TAU * k as f64 / AZIMUTHS as f64).sin_cos())
        .map(|(s, c)| (c, s))
        .collect();
    let (nx, ny) = (
        (heights.nx - 1).div_ceil(stride) + 1,
        (heights.ny - 1).div_ceil(stride) + 1,
    );
    let mut out = Grid {
        nx,
        ny,
        origin: heights.origin,
        spacing_m: dx * stride as f64,
        axis: heights.axis,
        values: vec![1.0; nx * ny],
    };
    let (last_x, last_y) = ((heights.nx - 1) as f64, (heights.ny - 1) as f64);
    out.values
        .par_chunks_mut(nx)
        .enumerate()
        .for_each(|(j, row)| {
            for (i, v) in row.iter_mut().enumerate() {
                // The coarse vertex on the fine grid (the last row and column clamped: the
                // coarse grid may reach a little beyond the fine one's edge).
                let gx = ((i * stride) as f64).min(last_x);
                let gy = ((j * stride) as f64).min(last_y);
                let h0 = heights.bilinear(gx, gy);
                let (hu, hv) = heights.gradient(gx, gy);
                let norm = (1.0 + hu * hu + hv * hv).sqrt();
                let (nx, ny, nz) = (-hu / norm, -hv / norm, 1.0 / norm);
                let (mut seen, mut open) = (0.0, 0.0);
                for &(c, s) in &dirs {
                    let mut tan_b: f64 = 0.0;
                    for &d in &steps {
                        let (x, y) = (gx + c * d / dx, gy + s * d / dx);
                        if !heights.contains(x, y) {
                            break;
                        }
                        let rise = heights.bilinear(x, y) - h0 - d * d / (2.0 * radius_m);
                        tan_b = tan_b.max(rise / d);
                    }
                    let a = nx * c + ny * s;
                    let e0 = (-a).atan2(nz);
                    seen += share(a, nz, tan_b.atan().max(e0));
                    open += share(a, nz, e0.max(0.0));
                }
                *v = if open > 0.0 {
                    (seen / open).clamp(0.0, 1.0) as f32
                } else {
                    1.0
                };
            }
        });
    out
}

/// ∫ from `low` to π/2 of (a cos e + c sin e) cos e de.
fn share(a: f64, c: f64, low: f64) -> f64 {
    use std::f64::consts::FRAC_PI_2;
    if low >= FRAC_PI_2 {
        return 0.0;
    }
    let s = low.sin();
    a * (FRAC_PI_2 / 2.0 - low / 2.0 - (2.0 * low).sin() / 4.0) + c * 0.5 * (1.0 - s * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_plain_sees_the_whole_sky_and_a_pit_less() {
        let mut g = Grid {
            nx: 41,
            ny: 41,
            origin: [0.0, 0.0],
            spacing_m: 50.0,
            axis: [1.0, 0.0],
            values: vec![0.0; 41 * 41],
        };
        let flat = sky_visibility(&g, 6.36e6, 1);
        assert!((flat.at(20, 20) - 1.0).abs() < 1e-6);
        // A ring wall 500 m high from 500 m: a horizon at 45° seen from the centre, so the
        // open share ∫ sin e cos e de from β to 90° is cos²β of the plain's: 1/2. The
        // horizon search steps by 30 %, so it finds the wall between 500 and 700 m: β
        // between 35.5° and 45°, a share between 0.50 and 0.66.
        for j in 0..41 {
            for i in 0..41 {
                let r = (((i as f64 - 20.0).powi(2) + (j as f64 - 20.0).powi(2)).sqrt()) * 50.0;
                if r >= 500.0 {
                    g.values[j * 41 + i] = 500.0;
                }
            }
        }
        let pit = sky_visibility(&g, 1e12, 1);
        let v = pit.at(20, 20);
        assert!((0.49..0.67).contains(&v), "{v}");
    }
}
