//! The ray's walk through a grid's max-mip pyramid (Tevs, Ihrke & Seidel 2008): the cells
//! a ray crosses, nearest first, skipping the nodes it passes above. The WGSL twin is
//! `shaders/terrain/walk.wgsl`; the grid, its pyramid and the ray's geometry are in
//! [`super::grid`].

use super::grid::{CellSpan, Grid, GridRay, MaxPyramid};

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
        let top = self.pyramid.level_count() - 1;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

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
