//! The terrain's shadow in the air: for one light direction, the shadow height S at every
//! vertex, the lowest height above the sphere at which a point over that vertex sees the
//! light past the terrain (Max 1986, "Atmospheric illumination and shadows", SIGGRAPH;
//! the horizon sweep of Stewart 1998 / Timonen & Westerholm 2010 "Scalable height field
//! self-shadowing" along the light's azimuth). A point at height h is lit iff h ≥ S, so the
//! lit parts of a view ray are where its height is above S interpolated between vertices,
//! found exactly per cell (a quadratic, as the ray against the terrain): the lit segments
//! of Bruneton & Neyret 2008 eq. 17–18 in the general form.
//!
//! The sweep. On a grid rotated so that x′ points towards the light's azimuth, each row is a
//! profile of the terrain along the light's path; walking it from the light's side,
//! S_i = max(H_i, (R + S_{i+1})·cos(e_i + φ)/cos e_i − R) with φ = Δ/R the step's central
//! angle and e_i the light's elevation at vertex i: the exact rise of a straight ray over a
//! sphere (law of sines in the plane of the great circle), so the planet's curvature is in.
//! The rows are parallel in the tangent plane while the light's paths converge on its
//! vanishing point R·(L_x, L_y)/L_z: at 20 km across the path an error of 1·10⁻⁴ to 1·10⁻³
//! rad in azimuth (≤ 11 m over a 20 km shadow at a 5° sun), below a cell. The raise
//! D = S − H is then interpolated back onto the terrain's grid, where the walk runs: where
//! a vertex is lit D = 0 and the air touching a lit surface is lit, exactly. Only the
//! shadow's edge inside a cell is interpolated; the shadow on the surface at a ray's end is
//! decided by an exact shadow ray.

use rayon::prelude::*;

use super::grid::{roots, Grid, GridRay, MaxPyramid};
use super::heightfield::Heightfield;
use super::walk::Walk;
use crate::math::Vec3;

/// Lights within this angle of the zenith (rad) cast no shadow but their own: the sweep has
/// no azimuth to follow.
const VERTICAL_LIGHT_RAD: f64 = 1e-4;

/// Sweep samples per terrain cell along and across the light's path.
const SWEEP_REFINE: f64 = 3.0;

/// The shadow heights of one light over the terrain's grid.
pub struct ShadowField {
    /// S (m above the sphere) on the terrain's grid.
    pub heights: Grid,
    pyramid: MaxPyramid,
    /// The maximum of the raise S − H per node: where it is 0 the air is lit down to the
    /// ground, and the walk skips the node (a view ray there is above S where it is above H).
    raised: MaxPyramid,
    /// The pyramid of −S: a node the ray crosses below its lowest S is in shadow whole.
    floors: MaxPyramid,
    /// The signed height (m) of the sweep's shadow line above the terrain at each vertex:
    /// positive in shadow (the raise), negative in light (how far below the terrain the
    /// shadow line passes), on the terrain's grid.
    pub clearance: Grid,
    light: Vec3,
}

impl ShadowField {
    /// The field of `light` (unit, towards the light) over `terrain`.
    pub fn new(terrain: &Heightfield, light: Vec3) -> ShadowField {
        let grid = &terrain.heights;
        let mut heights = grid.clone();
        // Far below any shadow: a vertex of a vertical light, or one the sweep leaves lit
        // with no terrain towards the light.
        let mut clearance = Grid {
            values: vec![-CLEARANCE_CAP_M as f32; grid.values.len()],
            ..grid.clone()
        };
        let horizontal = (light.x * light.x + light.y * light.y).sqrt();
        if horizontal > VERTICAL_LIGHT_RAD {
            let raise = sweep(terrain, [light.x / horizontal, light.y / horizontal], light);
            heights
                .values
                .par_chunks_mut(grid.nx)
                .zip(clearance.values.par_chunks_mut(grid.nx))
                .enumerate()
                .for_each(|(j, (row, clear))| {
                    for (i, (s, c)) in row.iter_mut().zip(clear.iter_mut()).enumerate() {
                        let (u, v) = grid.plane_coords(i as f64, j as f64);
                        let (gx, gy) = raise.cell_coords(u, v);
                        if raise.contains(gx, gy) {
                            // The raise interpolated from the sweep's non-negative values
                            // (S ≥ H exactly where the sweep found light), the signed
                            // clearance from its signed ones.
                            let d = raise.bilinear(gx, gy);
                            let up = raise.bilinear_of(gx, gy, |v| v.max(0.0));
                            *s += up as f32;
                            *c = d as f32;
                        }
                    }
                });
        }
        let pyramid = MaxPyramid::new(&heights);
        let mut raise = heights.clone();
        for (d, h) in raise.values.iter_mut().zip(&grid.values) {
            *d -= h;
        }
        let mut negated = heights.clone();
        negated.values.iter_mut().for_each(|v| *v = -*v);
        ShadowField {
            raised: MaxPyramid::new(&raise),
            floors: MaxPyramid::new(&negated),
            heights,
            clearance,
            pyramid,
            light,
        }
    }

    /// The pyramids the walk through the field uses (for a GPU copy of it): the maxima of
    /// S, of the raise S − H (0: lit down to the ground) and of −S (the floors).
    pub fn pyramids(&self) -> [&MaxPyramid; 3] {
        [&self.pyramid, &self.raised, &self.floors]
    }

    /// The shadowed intervals of `ray` within [0, `max_distance_m`] (see the module
    /// documentation), appended to `out`. When the ray ends on a surface (a finite
    /// `max_distance_m` at the terrain or the sphere), whether its end is in shadow comes
    /// from an exact shadow ray.
    pub fn shadowed_intervals(
        &self,
        terrain: &Heightfield,
        ray: &GridRay,
        max_distance_m: f64,
        out: &mut Vec<(f64, f64)>,
    ) {
        let first = out.len();
        let grid = &self.heights;
        // The last span walked, and whether it was a whole node in shadow.
        let mut last_piece = (0.0, 0.0);
        let mut last_whole = false;
        let cells = Walk::new(
            grid,
            &self.pyramid,
            Some(&self.raised),
            Some(&self.floors),
            ray,
            (0.0, max_distance_m),
        );
        for cell in cells {
            if cell.below {
                push_merged(out, first, cell.t0, cell.t1);
                last_piece = (cell.t0, cell.t1);
                last_whole = true;
                continue;
            }
            // g(s) = ray height − S: shadowed where negative.
            let g = ray.gap_in_cell(grid, cell);
            let mut cuts = [0.0, 1.0, 1.0, 1.0];
            let mut n = 1;
            for s in roots(g).into_iter().flatten() {
                if s > 0.0 && s < 1.0 {
                    cuts[n] = s;
                    n += 1;
                }
            }
            cuts[n] = 1.0;
            let span = cell.t1 - cell.t0;
            for k in 0..n {
                let (s0, s1) = (cuts[k], cuts[k + 1]);
                let m = 0.5 * (s0 + s1);
                if g[0] + m * (g[1] + m * g[2]) < 0.0 {
                    push_merged(out, first, cell.t0 + s0 * span, cell.t0 + s1 * span);
                }
            }
            last_piece = (cell.t0, cell.t1);
            last_whole = false;
        }
        let Some(shadowed) = self.end_in_shadow(terrain, ray, max_distance_m) else {
            return;
        };
        let touches = out.len() > first && out.last().unwrap().1 >= max_distance_m * (1.0 - 1e-9);
        match (shadowed, touches) {
            (false, true) => {
                // The interpolated edge reaches a lit surface: stop it at the end's cell
                // (a cell's length before the end when that was a whole node).
                let cut = if last_whole {
                    max_distance_m - grid.spacing_m
                } else {
                    last_piece.0
                };
                let last = out.last_mut().unwrap();
                last.1 = last.1.min(cut).max(last.0);
                if last.1 <= last.0 {
                    out.pop();
                }
            }
            (true, false) => {
                // The exact shadow ray hides the end the interpolated field lit: shadow from
                // the end's cell (or a sliver at the end when the walk skipped it).
                let from = if last_piece.1 >= max_distance_m * (1.0 - 1e-9) {
                    last_piece.0
                } else {
                    max_distance_m * (1.0 - 1e-12)
                };
                push_merged(out, first, from, max_distance_m);
            }
            _ => {}
        }
    }
}

impl ShadowField {
    /// When `ray` ends at `max_distance_m` on a surface, whether the light is hidden there:
    /// from the field where the four corners of the end's cell agree by a margin (the
    /// shadow line passes more than [`EDGE_MARGIN`] cells' spacing above the terrain at all
    /// of them: in shadow; as far below at all of them: lit), from an exact shadow ray
    /// ([`Heightfield::end_in_shadow`]) near the shadow's edge and off the grid. The margin
    /// covers the sweep's error on the shadow line (its samples at 1/`SWEEP_REFINE` of a
    /// cell); what it cannot see is a shadow (or a gap of light) narrower than a cell
    /// passing between all four vertices (`tests/terrain.rs` counts the disagreements
    /// with exact rays).
    pub fn end_in_shadow(
        &self,
        terrain: &Heightfield,
        ray: &GridRay,
        max_distance_m: f64,
    ) -> Option<bool> {
        if !max_distance_m.is_finite() {
            return None;
        }
        let grid = &self.clearance;
        let (gx, gy, h) = ray.grid_point(grid, max_distance_m);
        if grid.contains(gx, gy) {
            let (i, j) = (
                (gx as usize).min(grid.nx - 2),
                (gy as usize).min(grid.ny - 2),
            );
            let hc = terrain.heights.corners(i, j);
            let (a, b) = super::grid::fractions(gx, gy, i, j);
            if h <= super::grid::bilinear(hc, a, b) + 0.5 {
                let margin = EDGE_MARGIN * grid.spacing_m;
                let c = grid.corners(i, j);
                if c.iter().all(|&d| d < -margin) {
                    return Some(false);
                }
                if c.iter().all(|&d| d > margin) {
                    return Some(true);
                }
            }
        }
        terrain.end_in_shadow(ray, self.light, max_distance_m)
    }
}

/// The margin of [`ShadowField::end_in_shadow`], in cells' spacing (of height).
pub const EDGE_MARGIN: f64 = 0.2;

/// The sweep's signed raise stops this far (m) below the terrain.
const CLEARANCE_CAP_M: f64 = 1.0e4;

/// Append [a, b] to `out[first..]`, merging it with the last interval when they touch.
fn push_merged(out: &mut Vec<(f64, f64)>, first: usize, a: f64, b: f64) {
    if out.len() > first {
        let last = out.last_mut().unwrap();
        if a <= last.1 + 1e-6 * (1.0 + last.1.abs() * 1e-6) {
            last.1 = last.1.max(b);
            return;
        }
    }
    out.push((a, b));
}

/// The signed raise D = S − H on a grid rotated so that x′ points along `azimuth` (unit, in
/// the tangent plane) and covering the terrain's rectangle: where negative, how far below
/// the terrain the shadow line from the light's side passes (down to −[`CLEARANCE_CAP_M`]).
fn sweep(terrain: &Heightfield, azimuth: [f64; 2], light: Vec3) -> Grid {
    let grid = &terrain.heights;
    let r = terrain.radius_m;
    let dx = grid.spacing_m / SWEEP_REFINE;
    let [c, s] = azimuth;
    // The terrain's corners in the rotated frame.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (gi, gj) in [
        (0, 0),
        (grid.nx - 1, 0),
        (0, grid.ny - 1),
        (grid.nx - 1, grid.ny - 1),
    ] {
        let (u, v) = grid.plane_coords(gi as f64, gj as f64);
        let (x, y) = (c * u + s * v, -s * u + c * v);
        lo = [lo[0].min(x), lo[1].min(y)];
        hi = [hi[0].max(x), hi[1].max(y)];
    }
    let nx = ((hi[0] - lo[0]) / dx).ceil() as usize + 1;
    let ny = ((hi[1] - lo[1]) / dx).ceil() as usize + 1;
    let mut raise = Grid {
        nx,
        ny,
        origin: lo,
        spacing_m: dx,
        axis: azimuth,
        values: vec![0.0; nx * ny],
    };
    // cos(e + φ)/cos e = cos φ − tan e · sin φ.
    let (sin_phi, cos_phi) = (dx / r).sin_cos();
    let (origin, heights) = (raise.origin, &terrain.heights);
    raise
        .values
        .par_chunks_mut(nx)
        .enumerate()
        .for_each(|(j, row)| {
            // Along the row everything is linear in i: the plane coordinates, the terrain
            // grid's coordinates and L·(u, v, R).
            let y = origin[1] + j as f64 * dx;
            let (u0, v0) = (c * origin[0] - s * y, s * origin[0] + c * y);
            let (du, dv) = (c * dx, s * dx);
            let (gx0, gy0) = heights.cell_coords(u0, v0);
            let (gx1, gy1) = heights.cell_coords(u0 + du, v0 + dv);
            let (dgx, dgy) = (gx1 - gx0, gy1 - gy0);
            let dot0 = light.x * u0 + light.y * v0 + light.z * r;
            let ddot = light.x * du + light.y * dv;
            // From the light's side (high x′) towards the shadows.
            let mut s_next = f64::NEG_INFINITY;
            for i in (0..nx).rev() {
                let k = i as f64;
                let (u, v) = (u0 + k * du, v0 + k * dv);
                let (gx, gy) = (gx0 + k * dgx, gy0 + k * dgy);
                // Off the terrain: the sphere.
                let h = if heights.contains(gx, gy) {
                    heights.bilinear(gx, gy)
                } else {
                    0.0
                };
                // The light's elevation e at the point: sin e = L·p/|p|, so
                // tan e = L·p / sqrt(|p|² − (L·p)²).
                let dot = dot0 + k * ddot;
                let tan_e = dot / (u * u + v * v + r * r - dot * dot).max(1e-12).sqrt();
                let carried = if s_next.is_finite() {
                    (r + s_next) * (cos_phi - tan_e * sin_phi) - r
                } else {
                    f64::NEG_INFINITY
                };
                let s_here = h.max(carried);
                row[i] = (carried - h).max(-CLEARANCE_CAP_M) as f32;
                s_next = s_here;
            }
        });
    raise
}
