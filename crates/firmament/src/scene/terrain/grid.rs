//! A field of values on a regular grid over the planet, and the ray's walk through it.
//!
//! Coordinates. A point p (planet-centred, m) of a planet of radius R is placed on the plane
//! tangent at the observer's foot (0, 0, R) by the gnomonic (central) projection
//! (u, v) = R·(p_x, p_y)/p_z, and its height is |p| − R. The gnomonic projection maps every
//! straight line in space to a straight line in the plane (Snyder 1987, *Map projections: a
//! working manual*, USGS PP 1395, §22), so a grid line u = c is the plane R·p_x − c·p_z = 0
//! through the planet's centre, a ray crosses it once at a parameter found by one division,
//! and a grid DDA in the plane visits exactly the cells a ray crosses in space: the grid
//! follows the planet's curvature with no approximation. Near the foot the projection is
//! metric (scale 1/cos²θ at angle θ from the foot: 1.00002 at 20 km on Earth).
//!
//! A grid may be rotated in the plane (the shadow-height field is aligned with the light's
//! azimuth); its lines are still planes through the centre.
//!
//! Traversal. A max-mip pyramid (Tevs, Ihrke & Seidel 2008, "Maximum mipmaps for fast,
//! accurate, and scalable dynamic height field rendering", I3D) bounds the field over each
//! node; a node is skipped when the ray's lowest height over the part of it inside the node
//! (the height along a line is convex: its minimum is at the closest approach to the centre
//! or at an end) is above the node's maximum, so no cell whose values the ray could reach is
//! missed, however thin a ridge.

use crate::math::Vec3;

/// Values at the vertices of a regular grid in the tangent plane (possibly rotated).
#[derive(Clone, Debug)]
pub struct Grid {
    /// Vertices along x′ and y′.
    pub nx: usize,
    /// Vertices along y′.
    pub ny: usize,
    /// Plane coordinates (x′, y′) of vertex (0, 0) (m).
    pub origin: [f64; 2],
    /// Vertex spacing (m).
    pub spacing_m: f64,
    /// (cos θ, sin θ) of the grid's x′ axis from east: x′ = cos θ·u + sin θ·v,
    /// y′ = −sin θ·u + cos θ·v.
    pub axis: [f64; 2],
    /// Values, row-major (index `j·nx + i`).
    pub values: Vec<f32>,
}

impl Grid {
    /// Plane coordinates (u, v) → grid coordinates (x′, y′) in cells from vertex (0, 0).
    #[inline]
    pub fn cell_coords(&self, u: f64, v: f64) -> (f64, f64) {
        let [c, s] = self.axis;
        (
            ((c * u + s * v) - self.origin[0]) / self.spacing_m,
            ((-s * u + c * v) - self.origin[1]) / self.spacing_m,
        )
    }

    /// Grid coordinates (in cells) → plane coordinates (u, v).
    #[inline]
    pub fn plane_coords(&self, gx: f64, gy: f64) -> (f64, f64) {
        let [c, s] = self.axis;
        let (x, y) = (
            self.origin[0] + gx * self.spacing_m,
            self.origin[1] + gy * self.spacing_m,
        );
        (c * x - s * y, s * x + c * y)
    }

    /// The value at vertex (i, j).
    #[inline]
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.values[j * self.nx + i] as f64
    }

    /// Whether grid coordinates lie on the grid.
    #[inline]
    pub fn contains(&self, gx: f64, gy: f64) -> bool {
        gx >= 0.0 && gy >= 0.0 && gx <= (self.nx - 1) as f64 && gy <= (self.ny - 1) as f64
    }

    /// The four corner values of cell (i, j) as [v00, v10, v01, v11].
    #[inline]
    pub fn corners(&self, i: usize, j: usize) -> [f64; 4] {
        let k = j * self.nx + i;
        [
            self.values[k] as f64,
            self.values[k + 1] as f64,
            self.values[k + self.nx] as f64,
            self.values[k + self.nx + 1] as f64,
        ]
    }

    /// The interpolated value at plane coordinates (u, v), None off the grid.
    pub fn value_at(&self, u: f64, v: f64) -> Option<f64> {
        let (gx, gy) = self.cell_coords(u, v);
        self.contains(gx, gy).then(|| self.bilinear(gx, gy))
    }

    /// Bilinear interpolation at grid coordinates (clamped to the grid).
    pub fn bilinear(&self, gx: f64, gy: f64) -> f64 {
        let (i, a) = split(gx, self.nx);
        let (j, b) = split(gy, self.ny);
        bilinear(self.corners(i, j), a, b)
    }

    /// Bilinear interpolation at grid coordinates (clamped) of `f` of the corner values.
    pub fn bilinear_of(&self, gx: f64, gy: f64, f: impl Fn(f64) -> f64) -> f64 {
        let (i, a) = split(gx, self.nx);
        let (j, b) = split(gy, self.ny);
        bilinear(self.corners(i, j).map(f), a, b)
    }

    /// The gradient (∂/∂x′, ∂/∂y′ per metre) at grid coordinates: central differences at the
    /// vertices, interpolated bilinearly (a smooth normal for shading).
    pub fn gradient(&self, gx: f64, gy: f64) -> (f64, f64) {
        let (i, a) = split(gx, self.nx);
        let (j, b) = split(gy, self.ny);
        let mut gxs = [0.0; 4];
        let mut gys = [0.0; 4];
        for (k, (di, dj)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
            let (x, y) = (i + di, j + dj);
            let (x0, x1) = (x.saturating_sub(1), (x + 1).min(self.nx - 1));
            let (y0, y1) = (y.saturating_sub(1), (y + 1).min(self.ny - 1));
            gxs[k] = (self.at(x1, y) - self.at(x0, y)) / ((x1 - x0) as f64 * self.spacing_m);
            gys[k] = (self.at(x, y1) - self.at(x, y0)) / ((y1 - y0) as f64 * self.spacing_m);
        }
        (bilinear(gxs, a, b), bilinear(gys, a, b))
    }
}

/// Cell index and fraction of a grid coordinate along an axis of `n` vertices (clamped).
/// (A cast truncates, which is the floor of the clamped, non-negative coordinate: without
/// SSE4.1 in the baseline target, `floor` is a libm call in the walk's inner loops.)
#[inline]
pub(crate) fn split(g: f64, n: usize) -> (usize, f64) {
    let g = g.clamp(0.0, (n - 1) as f64);
    let i = (g as usize).min(n - 2);
    (i, g - i as f64)
}

/// Bilinear interpolation of corners [v00, v10, v01, v11] at fractions (a, b).
#[inline]
pub fn bilinear(c: [f64; 4], a: f64, b: f64) -> f64 {
    let low = c[0] + (c[1] - c[0]) * a;
    let high = c[2] + (c[3] - c[2]) * a;
    low + (high - low) * b
}

/// The coefficients of a bilinear patch along a straight segment of the cell, from grid
/// fractions (a0, b0) at s = 0 to (a1, b1) at s = 1: value(s) = q0 + q1·s + q2·s².
#[inline]
pub fn along_segment(c: [f64; 4], a0: f64, b0: f64, a1: f64, b1: f64) -> [f64; 3] {
    let (k0, k1, k2, k3) = (c[0], c[1] - c[0], c[2] - c[0], c[3] - c[1] - c[2] + c[0]);
    let (da, db) = (a1 - a0, b1 - b0);
    [
        k0 + k1 * a0 + k2 * b0 + k3 * a0 * b0,
        k1 * da + k2 * db + k3 * (a0 * db + b0 * da),
        k3 * da * db,
    ]
}

/// A max-mip pyramid over a grid's cells: level 0 holds each cell's maximum corner value,
/// level k the maximum over blocks of 2^k × 2^k cells.
#[derive(Clone, Debug)]
pub struct MaxPyramid {
    /// (cells along x′, cells along y′, maxima) per level, level 0 first.
    levels: Vec<(usize, usize, Vec<f32>)>,
}

impl MaxPyramid {
    /// The pyramid of `grid`.
    pub fn new(grid: &Grid) -> MaxPyramid {
        let (cx, cy) = (grid.nx - 1, grid.ny - 1);
        let mut base = vec![0.0f32; cx * cy];
        for j in 0..cy {
            for i in 0..cx {
                let c = grid.corners(i, j);
                base[j * cx + i] = c.iter().copied().fold(f64::NEG_INFINITY, f64::max) as f32;
            }
        }
        let mut levels = vec![(cx, cy, base)];
        while let Some((w, h, prev)) = levels.last().filter(|(w, h, _)| *w > 1 || *h > 1) {
            let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
            let mut next = vec![f32::NEG_INFINITY; nw * nh];
            for j in 0..*h {
                for i in 0..*w {
                    let m = &mut next[(j / 2) * nw + i / 2];
                    *m = m.max(prev[j * w + i]);
                }
            }
            levels.push((nw, nh, next));
        }
        MaxPyramid { levels }
    }

    /// The maximum over the whole grid.
    pub fn max(&self) -> f64 {
        self.levels
            .last()
            .map_or(f64::NEG_INFINITY, |l| l.2[0] as f64)
    }

    /// The levels, finest first: (nodes along x′, nodes along y′, values row-major).
    pub fn levels(&self) -> impl Iterator<Item = (usize, usize, &[f32])> {
        self.levels.iter().map(|(w, h, v)| (*w, *h, v.as_slice()))
    }

    /// The number of levels (the top one is a single node).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Node (i, j)'s maximum at `level`, None off the level's nodes.
    #[inline]
    pub(crate) fn node(&self, level: usize, i: usize, j: usize) -> Option<f64> {
        let (w, h, v) = &self.levels[level];
        (i < *w && j < *h).then(|| v[j * w + i] as f64)
    }
}

/// A ray's geometry against a grid on a planet of radius `radius_m`: where it crosses grid
/// lines and how high it is.
#[derive(Clone, Copy, Debug)]
pub struct GridRay {
    /// Origin (planet-centred, m).
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// The planet's radius (m).
    pub radius_m: f64,
}

impl GridRay {
    /// The point at `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + t * self.dir
    }

    /// Height above the sphere at `t` (m).
    #[inline]
    pub fn height(&self, t: f64) -> f64 {
        self.at(t).length() - self.radius_m
    }

    /// Whether the ray is higher than `height` (m above the sphere) everywhere over
    /// [t0, t1] (its lowest point is the closest approach to the centre, or an end),
    /// compared as squared radii (no square root).
    #[inline]
    pub fn above(&self, t0: f64, t1: f64, height: f64) -> bool {
        let closest = (-self.origin.dot(self.dir)).clamp(t0, t1);
        let top = self.radius_m + height;
        self.at(closest).length_squared() > top * top
    }

    /// Whether both ends of [t0, t1] (so the whole of it: the height along a line is
    /// convex) are lower than `height` (m above the sphere, which must be > −R).
    #[inline]
    pub fn below_at_ends(&self, t0: f64, t1: f64, height: f64) -> bool {
        let top = self.radius_m + height;
        let r2 = self
            .at(t0)
            .length_squared()
            .max(self.at(t1).length_squared());
        r2 < top * top
    }

    /// Plane coordinates (u, v) of the point at `t` (gnomonic; the point must have p_z > 0).
    #[inline]
    pub fn plane(&self, t: f64) -> (f64, f64) {
        let p = self.at(t);
        (self.radius_m * p.x / p.z, self.radius_m * p.y / p.z)
    }

    /// Grid coordinates at `t`.
    #[inline]
    pub fn grid_xy(&self, grid: &Grid, t: f64) -> (f64, f64) {
        let (u, v) = self.plane(t);
        grid.cell_coords(u, v)
    }

    /// Grid coordinates and height at `t`.
    #[inline]
    pub fn grid_point(&self, grid: &Grid, t: f64) -> (f64, f64, f64) {
        let (u, v) = self.plane(t);
        let (gx, gy) = grid.cell_coords(u, v);
        (gx, gy, self.height(t))
    }

    /// The ray's height minus the grid's bilinear patch across `cell`, as q0 + q1·s + q2·s²
    /// from where it enters the cell (s = 0) to where it leaves (s = 1). The ray is taken as
    /// straight in the cell: its height's curvature over 100 m is L²/8R, 2·10⁻⁴ m.
    pub fn gap_in_cell(&self, grid: &Grid, cell: CellSpan) -> [f64; 3] {
        let (x0, y0, h0) = self.grid_point(grid, cell.t0);
        let (x1, y1, h1) = self.grid_point(grid, cell.t1);
        let (a0, b0) = fractions(x0, y0, cell.i, cell.j);
        let (a1, b1) = fractions(x1, y1, cell.i, cell.j);
        let q = along_segment(grid.corners(cell.i, cell.j), a0, b0, a1, b1);
        [h0 - q[0], (h1 - h0) - q[1], -q[2]]
    }

    /// The linear function a + b·t whose sign tells the side of grid line x′ = `gx` (cells)
    /// (or y′ = `gx` when `along_y`) the point at t is on: positive beyond it.
    #[inline]
    pub fn line(&self, grid: &Grid, g: f64, along_y: bool) -> (f64, f64) {
        let [c, s] = grid.axis;
        let (cu, cv) = if along_y { (-s, c) } else { (c, s) };
        let offset = if along_y {
            grid.origin[1]
        } else {
            grid.origin[0]
        } + g * grid.spacing_m;
        // Beyond the line: R·(cu·p_x + cv·p_y) − offset·p_z > 0 (for p_z > 0).
        let n = Vec3::new(self.radius_m * cu, self.radius_m * cv, -offset);
        (self.origin.dot(n), self.dir.dot(n))
    }

    /// The part of [t0, t1] inside the grid's rectangle, on the near hemisphere (p_z > 0)
    /// and below `max_height` (m).
    pub fn clip(&self, grid: &Grid, t0: f64, t1: f64, max_height: f64) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (t0, t1);
        let mut keep = |a: f64, b: f64| {
            // a + b·t ≥ 0.
            if b > 0.0 {
                lo = lo.max(-a / b);
            } else if b < 0.0 {
                hi = hi.min(-a / b);
            } else if a < 0.0 {
                hi = f64::NEG_INFINITY;
            }
        };
        keep(self.origin.z, self.dir.z);
        let (lx, ly) = self.line(grid, 0.0, false);
        keep(lx, ly);
        let (lx, ly) = self.line(grid, (grid.nx - 1) as f64, false);
        keep(-lx, -ly);
        let (lx, ly) = self.line(grid, 0.0, true);
        keep(lx, ly);
        let (lx, ly) = self.line(grid, (grid.ny - 1) as f64, true);
        keep(-lx, -ly);
        // Below the shell |p| = R + max_height.
        let top = self.radius_m + max_height;
        let b = self.origin.dot(self.dir);
        let c = self.origin.length_squared() - top * top;
        let disc = b * b - c;
        if disc <= 0.0 {
            return None;
        }
        let s = disc.sqrt();
        lo = lo.max(-b - s);
        hi = hi.min(-b + s);
        (hi > lo).then_some((lo, hi))
    }
}

/// A cell the walk reaches: its indices and the ray's parameters where it enters and leaves
/// (or, with `below`, a whole node the ray crosses below the lowest value in it).
#[derive(Clone, Copy, Debug)]
pub struct CellSpan {
    /// The span is a whole node the ray crosses below its lowest value ([`Walk`]'s
    /// `floors`); `i` and `j` are then the node's, not a cell's.
    pub below: bool,
    /// Cell index along x′.
    pub i: usize,
    /// Cell index along y′.
    pub j: usize,
    /// Entry parameter (m).
    pub t0: f64,
    /// Exit parameter (m).
    pub t1: f64,
}

/// The fractions (a, b) within cell (i, j) of grid coordinates, clamped to [0, 1].
#[inline]
pub fn fractions(gx: f64, gy: f64, i: usize, j: usize) -> (f64, f64) {
    (
        (gx - i as f64).clamp(0.0, 1.0),
        (gy - j as f64).clamp(0.0, 1.0),
    )
}

/// The smallest root of q0 + q1·s + q2·s² in [0, 1] where the function goes from positive
/// to non-positive (or 0 when it starts non-positive), or None.
pub fn first_descent(q: [f64; 3]) -> Option<f64> {
    let [c, b, a] = q;
    if c <= 0.0 {
        return Some(0.0);
    }
    roots(q)
        .into_iter()
        .flatten()
        .filter(|s| (0.0..=1.0).contains(s))
        .find(|&s| {
            // Descending (or touching) there.
            b + 2.0 * a * s <= 0.0
        })
}

/// The real roots of q0 + q1·s + q2·s², ascending (numerically stable form).
pub fn roots(q: [f64; 3]) -> [Option<f64>; 2] {
    let [c, b, a] = q;
    let scale = a.abs().max(b.abs()).max(c.abs());
    if a.abs() <= 1e-12 * scale {
        return if b != 0.0 {
            [Some(-c / b), None]
        } else {
            [None, None]
        };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let sq = disc.sqrt();
    let k = -0.5 * (b + b.signum() * sq);
    let (r1, r2) = if k != 0.0 {
        (k / a, c / k)
    } else {
        (-0.5 * b / a, -0.5 * b / a)
    };
    let (lo, hi) = if r1 <= r2 { (r1, r2) } else { (r2, r1) };
    [Some(lo), Some(hi)]
}
