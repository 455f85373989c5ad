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

    #[inline]
    fn node(&self, level: usize, i: usize, j: usize) -> Option<f64> {
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

/// The cells of `grid` that `ray` crosses within [t0, t1], nearest first, skipping the nodes
/// of `pyramid` whose maximum is below the ray's lowest height over them, and the nodes
/// whose maximum in `nonzero` (a pyramid over the same grid, when given) is 0 or less; a
/// node the ray crosses below its lowest value (`floors`: the pyramid of the negated
/// values, when given) comes whole (`CellSpan::below`).
///
/// Stackless (the WGSL twin `walk_next` has no recursion): the walk holds one node and the
/// ray's parameter where it entered it. A node the ray may touch is entered at its child
/// containing that point; a node done with (skipped or visited) is left through its exit
/// face to the neighbour, and the walk climbs to the highest ancestor of the neighbour that
/// is not an ancestor of the node left, so every node is tested once, as in a recursive
/// descent. The ray's grid coordinates move monotonically (a straight line in the gnomonic
/// plane), so the exit face is the one ahead on each axis.
pub struct Walk<'a> {
    pyramid: &'a MaxPyramid,
    nonzero: Option<&'a MaxPyramid>,
    floors: Option<&'a MaxPyramid>,
    ray: &'a GridRay,
    /// The side of grid line g (cells) along x′ and y′ as a + b·t, a = a0 + g·a1,
    /// b = b0 + g·b1 ([`GridRay::line`]): [a0, a1, b0, b1] per axis.
    lines: [[f64; 4]; 2],
    /// The current node: level, indices (may step off the grid at the end).
    level: usize,
    i: i64,
    j: i64,
    /// Where the ray entered the current node, where it leaves it through the face ahead
    /// on each axis (infinite when it does not), and where the walk ends.
    t: f64,
    exits: [f64; 2],
    end: f64,
    /// Direction of travel along x′ and y′ (−1, 0 or 1).
    step: [i64; 2],
    done: bool,
}

impl<'a> Walk<'a> {
    /// Within this many metres (relative to 1 + t) of the walk's parameter, a grid line's
    /// crossing counts as at it (rounding), and further behind as no crossing at all.
    const TOLERANCE: f64 = 1e-7;

    /// The walk of `ray` through `grid` within [t0, t1] (see [`Walk`]).
    pub fn new(
        grid: &'a Grid,
        pyramid: &'a MaxPyramid,
        nonzero: Option<&'a MaxPyramid>,
        floors: Option<&'a MaxPyramid>,
        ray: &'a GridRay,
        (t0, t1): (f64, f64),
    ) -> Walk<'a> {
        let clipped = ray.clip(grid, t0, t1, pyramid.max());
        let (a, b) = clipped.unwrap_or((0.0, 0.0));
        // The sign of travel on each axis, from the clipped segment's ends.
        let (x0, y0) = ray.grid_xy(grid, a);
        let (x1, y1) = ray.grid_xy(grid, b);
        let sign = |d: f64| {
            if d > 1e-12 {
                1
            } else if d < -1e-12 {
                -1
            } else {
                0
            }
        };
        let line = |along_y| {
            let (a0, b0) = ray.line(grid, 0.0, along_y);
            let (a1, b1) = ray.line(grid, 1.0, along_y);
            [a0, a1 - a0, b0, b1 - b0]
        };
        let step = [sign(x1 - x0), sign(y1 - y0)];
        // Start in the cell holding the clipped start (on a line, the one ahead): the
        // ancestors of that cell are where a walk from the top would descend first.
        let leaf = |g: f64, step: i64, cells: usize| {
            let mut i = g.floor();
            if step < 0 && g == i {
                i -= 1.0;
            }
            i.clamp(0.0, (cells - 1) as f64) as i64
        };
        let mut walk = Walk {
            pyramid,
            nonzero,
            floors,
            ray,
            lines: [line(false), line(true)],
            level: 0,
            i: leaf(x0, step[0], grid.nx - 1),
            j: leaf(y0, step[1], grid.ny - 1),
            t: a,
            exits: [f64::INFINITY; 2],
            end: b,
            step,
            done: clipped.is_none(),
        };
        walk.exits = [walk.face(walk.i, 0), walk.face(walk.j, 1)];
        walk
    }

    /// a + b·t for grid line `g` (cells) along `axis` (0: x′, 1: y′): [a, b].
    #[inline]
    fn line(&self, g: f64, axis: usize) -> [f64; 2] {
        let [a0, a1, b0, b1] = self.lines[axis];
        [a0 + g * a1, b0 + g * b1]
    }

    /// Where the ray crosses grid line `g` (cells) ahead of the walk's parameter along
    /// `axis`: the root of a linear function of t that changes sign where the line is
    /// crossed, or where the ray leaves the hemisphere p_z > 0 (a root behind the walk's
    /// parameter: the ray's image in the plane runs to its vanishing point before reaching
    /// the line, and never crosses it; infinite then).
    #[inline]
    fn crossing_ahead(&self, g: i64, axis: usize) -> f64 {
        let [a, b] = self.line(g as f64, axis);
        let t = if b == 0.0 { f64::INFINITY } else { -a / b };
        if t < self.t - Self::TOLERANCE * (1.0 + self.t.abs()) {
            f64::INFINITY
        } else {
            t.max(self.t)
        }
    }

    /// The crossing of the current node's face ahead along `axis` (infinite when the ray
    /// does not move along it). `idx` is the node's index on that axis.
    #[inline]
    fn face(&self, idx: i64, axis: usize) -> f64 {
        let size = 1i64 << self.level;
        match self.step[axis] {
            0 => f64::INFINITY,
            s if s > 0 => self.crossing_ahead((idx + 1) * size, axis),
            _ => self.crossing_ahead(idx * size, axis),
        }
    }

    /// Descend into the child of the current node that holds the point at the walk's
    /// parameter, along one axis: whether it is the upper half (beyond the midline `mid`,
    /// in cells) and the child's exit on that axis. At the midline (entered through it) the
    /// child is the one the ray moves into.
    #[inline]
    fn half(&self, mid: i64, axis: usize) -> (bool, f64) {
        let step = self.step[axis];
        let [a, b] = self.line(mid as f64, axis);
        let tol = Self::TOLERANCE * (1.0 + self.t.abs());
        let upper = if step != 0 && b != 0.0 && (self.t + a / b).abs() <= tol {
            step > 0
        } else {
            a + b * self.t >= 0.0
        };
        // The near half (the midline ahead) leaves through the midline.
        let near = (step > 0 && !upper) || (step < 0 && upper);
        let exit = if near {
            self.crossing_ahead(mid, axis)
        } else {
            self.exits[axis]
        };
        (upper, exit)
    }

    /// Leave the current node through the nearer face ahead and climb to the highest new
    /// ancestor of the neighbour; false when the walk is over.
    fn advance(&mut self) -> bool {
        let t_exit = self.exits[0].min(self.exits[1]);
        if t_exit >= self.end {
            return false;
        }
        self.t = t_exit;
        let (i0, j0) = (self.i, self.j);
        let (mut i1, mut j1) = (i0, j0);
        if self.exits[0] <= t_exit {
            i1 += self.step[0];
        }
        if self.exits[1] <= t_exit {
            j1 += self.step[1];
        }
        let top = self.pyramid.levels.len() - 1;
        let mut k = 1;
        while self.level + k <= top && ((i0 >> k) != (i1 >> k) || (j0 >> k) != (j1 >> k)) {
            k += 1;
        }
        self.level += k - 1;
        self.i = i1 >> (k - 1);
        self.j = j1 >> (k - 1);
        // A neighbour at the same level keeps the exit of the axis not stepped along.
        if k > 1 || i1 != i0 {
            self.exits[0] = self.face(self.i, 0);
        }
        if k > 1 || j1 != j0 {
            self.exits[1] = self.face(self.j, 1);
        }
        true
    }
}

impl Iterator for Walk<'_> {
    type Item = CellSpan;

    fn next(&mut self) -> Option<CellSpan> {
        while !self.done {
            let (level, i, j) = (self.level, self.i, self.j);
            let node = (i >= 0 && j >= 0)
                .then(|| self.pyramid.node(level, i as usize, j as usize))
                .flatten();
            let Some(max) = node else {
                self.done = true;
                break;
            };
            let (iu, ju) = (i as usize, j as usize);
            let t0 = self.t;
            let t1 = self.exits[0].min(self.exits[1]).min(self.end);
            let mut span = None;
            let skip = t1 <= t0
                || self.ray.above(t0, t1, max)
                || self
                    .nonzero
                    .is_some_and(|z| z.node(level, iu, ju).unwrap_or(0.0) <= 0.0);
            if !skip {
                // The height along a line is convex: its highest over [t0, t1] is at an end.
                let below = (self.floors.and_then(|f| f.node(level, iu, ju)))
                    .is_some_and(|floor| self.ray.below_at_ends(t0, t1, -floor));
                if below || level == 0 {
                    span = Some(CellSpan {
                        below,
                        i: iu,
                        j: ju,
                        t0,
                        t1,
                    });
                } else {
                    let half = 1i64 << (level - 1);
                    let (ux, ex) = self.half((2 * i + 1) * half, 0);
                    let (uy, ey) = self.half((2 * j + 1) * half, 1);
                    self.level -= 1;
                    self.i = 2 * i + i64::from(ux);
                    self.j = 2 * j + i64::from(uy);
                    self.exits = [ex, ey];
                    continue;
                }
            }
            if !self.advance() {
                self.done = true;
            }
            if span.is_some() {
                return span;
            }
        }
        None
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// With every node too high to skip, the walk must visit every cell the ray crosses, in
    /// order, the spans tiling the clipped ray, each span inside the cell it names; on a
    /// grid whose pyramid has partial nodes (80 cells a side), rotated, for rays up, down,
    /// along the axes and from off-centre points (whose images in the plane run towards a
    /// vanishing point).
    #[test]
    fn the_walk_tiles_the_ray_with_the_cells_it_crosses() {
        let r = 6_360_000.0;
        let n = 81;
        let (s, c) = 0.3f64.sin_cos();
        let grid = Grid {
            nx: n,
            ny: n,
            origin: [-4000.0, -3000.0],
            spacing_m: 100.0,
            axis: [c, s],
            values: vec![1.0e5; n * n],
        };
        let pyramid = MaxPyramid::new(&grid);
        let mut rays = Vec::new();
        for k in 0..400 {
            let f = |m: u64| ((k as u64 * m) % 1000) as f64 / 1000.0;
            let origin = Vec3::new(6000.0 * f(37) - 3000.0, 6000.0 * f(91) - 3000.0, r).normalize()
                * (r + 3000.0 * f(53));
            let elevation = (f(17) - 0.5) * 1.2;
            let azimuth = std::f64::consts::TAU * f(71);
            // Every tenth ray along a grid axis or its diagonal.
            let azimuth = if k % 10 == 0 {
                0.3 + (k / 10 % 4) as f64 * 0.25 * std::f64::consts::PI
            } else {
                azimuth
            };
            let dir = Vec3::new(
                elevation.cos() * azimuth.cos(),
                elevation.cos() * azimuth.sin(),
                elevation.sin(),
            );
            rays.push(GridRay {
                origin,
                dir,
                radius_m: r,
            });
        }
        let mut cells = 0;
        for ray in &rays {
            let Some((a, b)) = ray.clip(&grid, 0.0, 50_000.0, pyramid.max()) else {
                continue;
            };
            let mut t = a;
            for span in Walk::new(&grid, &pyramid, None, None, ray, (0.0, 50_000.0)) {
                assert!(!span.below);
                assert!((span.t0 - t).abs() < 1e-6, "gap: {t} then {span:?}");
                assert!(span.t1 > span.t0, "{span:?}");
                let (gx, gy) = ray.grid_xy(&grid, 0.5 * (span.t0 + span.t1));
                assert!(
                    gx >= span.i as f64 - 1e-6
                        && gx <= (span.i + 1) as f64 + 1e-6
                        && gy >= span.j as f64 - 1e-6
                        && gy <= (span.j + 1) as f64 + 1e-6,
                    "{span:?} holds ({gx}, {gy})"
                );
                t = span.t1;
                cells += 1;
            }
            assert!((t - b).abs() < 1e-6, "the walk ends at {t}, the ray at {b}");
        }
        assert!(cells > 5000, "{cells} cells");
    }
}
