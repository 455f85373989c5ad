//! Ambient occlusion of the sky by the terrain: at every vertex the horizon's elevation
//! β(φ) in [`AZIMUTHS`] directions (the highest terrain seen within [`HORIZON_RANGE_M`],
//! lowered by the planet's curvature d²/2R), and the cosine-weighted share of the sky above
//! it seen by the surface, relative to an open plane of the same tilt (whose share,
//! (1 + n·up)/2, the sky method already applies: Bruneton & Neyret 2008 eq. 16). The share
//! per azimuth is the closed form of ∫ max(0, n·ω) cos e de from max(β, e₀) to π/2, with e₀
//! where the surface's own plane cuts the sky (Dozier & Frew 1990, "Rapid calculation of
//! terrain parameters for radiation modeling from digital elevation data", IEEE TGRS 28,
//! the sky-view factor). The sky is taken as uniform in azimuth for this share; the
//! horizons themselves are kept too, so a renderer can weight the sky they hide by its
//! radiance (`render::sky_dome`: at golden hour the hidden sky is the bright part round
//! the sun). Light reflected by the surrounding slopes is not added.

use rayon::prelude::*;

use super::grid::{split, Grid};

/// Azimuths searched for the horizon.
pub const AZIMUTHS: usize = 8;
/// The occlusion is computed at every STRIDE-th vertex each way (it varies over the
/// horizon's scale, hundreds of metres, not a cell's) and interpolated between.
pub const STRIDE: usize = 2;
/// How far the horizon is searched (m): the peaks that hide a low sun from the default
/// valley stand up to 25 km away (searched to 4 km, the valley's shadowed floor near the
/// observer kept the sun's aureole and read +7 % against the reference at golden hour,
/// +5 % to 25 km, as the brute-force irradiance; docs/accuracy.md).
pub const HORIZON_RANGE_M: f64 = 25_000.0;

/// The sky's visibility and the horizons of a terrain, on a grid `stride` times coarser
/// than its heights (the horizons searched on the full one), read by bilinear
/// interpolation.
#[derive(Clone, Debug)]
pub struct Occlusion {
    /// The visibility of the sky (0 to 1) relative to an open plane of the same tilt.
    pub visibility: Grid,
    /// The horizon's elevation (rad, ≥ 0) towards azimuth k, the direction
    /// (cos 2πk/K, sin 2πk/K) in (east, north), K = [`AZIMUTHS`], at each of the
    /// visibility grid's vertices (`(j·nx + i)·K + k`: one vertex's together).
    pub horizons: Vec<f32>,
}

impl Occlusion {
    /// The horizons at plane coordinates (u, v), interpolated bilinearly, into `out`; false
    /// off the grid.
    pub fn horizons_at(&self, u: f64, v: f64, out: &mut [f64; AZIMUTHS]) -> bool {
        let g = &self.visibility;
        let (gx, gy) = g.cell_coords(u, v);
        if !g.contains(gx, gy) {
            return false;
        }
        let (i, a) = split(gx, g.nx);
        let (j, b) = split(gy, g.ny);
        let at = |i: usize, j: usize| &self.horizons[(j * g.nx + i) * AZIMUTHS..][..AZIMUTHS];
        let (c00, c10, c01, c11) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
        for k in 0..AZIMUTHS {
            let low = c00[k] as f64 + (c10[k] - c00[k]) as f64 * a;
            let high = c01[k] as f64 + (c11[k] - c01[k]) as f64 * a;
            out[k] = low + (high - low) * b;
        }
        true
    }
}

/// The [`Occlusion`] at every `stride`-th vertex of `heights` (both ways) on a planet of
/// radius `radius_m`.
pub fn occlusion(heights: &Grid, radius_m: f64, stride: usize) -> Occlusion {
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
    let coarse = |value: f32| Grid {
        nx,
        ny,
        origin: heights.origin,
        spacing_m: dx * stride as f64,
        axis: heights.axis,
        values: vec![value; nx * ny],
    };
    let mut out = coarse(1.0);
    // The horizons vertex-major while they are searched ([vertex][azimuth]).
    let mut betas = vec![0.0f32; nx * ny * AZIMUTHS];
    let (last_x, last_y) = ((heights.nx - 1) as f64, (heights.ny - 1) as f64);
    out.values
        .par_chunks_mut(nx)
        .zip(betas.par_chunks_mut(nx * AZIMUTHS))
        .enumerate()
        .for_each(|(j, (row, row_betas))| {
            for (i, (v, beta)) in row
                .iter_mut()
                .zip(row_betas.chunks_mut(AZIMUTHS))
                .enumerate()
            {
                // The coarse vertex on the fine grid (the last row and column clamped: the
                // coarse grid may reach a little beyond the fine one's edge).
                let gx = ((i * stride) as f64).min(last_x);
                let gy = ((j * stride) as f64).min(last_y);
                let h0 = heights.bilinear(gx, gy);
                let (hu, hv) = heights.gradient(gx, gy);
                let norm = (1.0 + hu * hu + hv * hv).sqrt();
                let (nx, ny, nz) = (-hu / norm, -hv / norm, 1.0 / norm);
                let (mut seen, mut open) = (0.0, 0.0);
                for (&(c, s), beta) in dirs.iter().zip(beta.iter_mut()) {
                    let mut tan_b: f64 = 0.0;
                    for &d in &steps {
                        let (x, y) = (gx + c * d / dx, gy + s * d / dx);
                        if !heights.contains(x, y) {
                            break;
                        }
                        let rise = heights.bilinear(x, y) - h0 - d * d / (2.0 * radius_m);
                        tan_b = tan_b.max(rise / d);
                    }
                    *beta = tan_b.atan() as f32;
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
    Occlusion {
        visibility: out,
        horizons: betas,
    }
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
        let flat = occlusion(&g, 6.36e6, 1).visibility;
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
        let pit = occlusion(&g, 1e12, 1);
        let v = pit.visibility.at(20, 20);
        assert!((0.49..0.67).contains(&v), "{v}");
        // The horizons: the wall's top seen from the centre, 35.5° to 45° every way.
        let mut h = [0.0; AZIMUTHS];
        let (u, v) = pit.visibility.plane_coords(20.0, 20.0);
        assert!(pit.horizons_at(u, v, &mut h));
        for b in h {
            let b = b.to_degrees();
            assert!((35.0..45.1).contains(&b), "{b}");
        }
    }
}
