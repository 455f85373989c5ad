//! The terrain as a surface: heights above the planet's sphere on a grid ([`super::grid`]),
//! hit exactly by rays (a max-mip walk, then the exact root of the ray against each cell's
//! bilinear patch), shaded with a smooth normal, coloured by its materials, and casting
//! shadows into the air and onto itself through the shadow-height field of each light
//! ([`super::shadow`]).

use std::sync::{Arc, RwLock};

use super::grid::{bilinear, first_descent, fractions, CellSpan, Grid, GridRay, MaxPyramid};
use super::materials::Materials;
use super::occlusion::Occlusion;
use super::shadow::ShadowField;
use super::walk::Walk;
use crate::math::Vec3;
use crate::scene::camera::Ray;
use crate::scene::surface::{Relief, Surface, SurfaceHit, HORIZON_AZIMUTHS};

/// The radius (m, one standard deviation) of the terrain around the observer whose albedo
/// the tables take for the planet's ground ([`Heightfield::mean_albedo`]).
pub const ALBEDO_RADIUS_M: f64 = 5000.0;

/// Shadow fields kept per light direction (a frame has at most a few lights).
const SHADOW_CACHE: usize = 4;

/// A heightfield on the planet.
pub struct Heightfield {
    /// Heights above the sphere (m) at the grid's vertices (axis-aligned: x′ = east).
    pub heights: Grid,
    pyramid: MaxPyramid,
    /// The planet's radius (m).
    pub radius_m: f64,
    /// The surface's reflectance.
    pub materials: Materials,
    /// Whether the terrain casts shadows (on itself, and into the air when `shafts`).
    pub casts_shadows: bool,
    /// Whether its shadows in the air (the light shafts) are computed; off, only the
    /// surface's shadows are (exact shadow rays at the view rays' ends).
    pub shafts: bool,
    /// The fraction of the sky the terrain leaves visible, relative to an open plane of the
    /// same tilt, and its horizons ([`super::occlusion`]); none: the whole sky everywhere.
    pub occlusion: Option<Occlusion>,
    /// Whether it changes the air's light around it ([`Surface::relief`] is None without).
    pub air_light: bool,
    shadows: RwLock<Vec<(Vec3, Arc<ShadowField>)>>,
}

impl Heightfield {
    /// A heightfield of `heights` (grid in the plane tangent at the observer's foot) on a
    /// planet of radius `radius_m`.
    pub fn new(heights: Grid, radius_m: f64, materials: Materials) -> Heightfield {
        let pyramid = MaxPyramid::new(&heights);
        Heightfield {
            heights,
            pyramid,
            radius_m,
            materials,
            casts_shadows: true,
            shafts: true,
            occlusion: None,
            air_light: true,
            shadows: RwLock::new(Vec::new()),
        }
    }

    /// A copy with no shadow fields cached (each light's is computed again on first use).
    pub fn clone_without_shadows(&self) -> Heightfield {
        Heightfield {
            heights: self.heights.clone(),
            pyramid: self.pyramid.clone(),
            radius_m: self.radius_m,
            materials: self.materials.clone(),
            casts_shadows: self.casts_shadows,
            shafts: self.shafts,
            occlusion: self.occlusion.clone(),
            air_light: self.air_light,
            shadows: RwLock::new(Vec::new()),
        }
    }

    /// The mean albedo per channel (`channels` of them) of the terrain around the observer,
    /// weighted by a Gaussian of [`ALBEDO_RADIUS_M`] around its foot (a 64 × 64 subgrid of
    /// the terrain, the sphere beyond it counted at the same mean): the ground whose
    /// reflection lights the air and the sky the observer sees.
    pub fn mean_albedo(&self, channels: usize) -> Vec<f64> {
        let g = &self.heights;
        let (mut sum, mut a) = (vec![0.0; channels], vec![0.0; channels]);
        let mut weights = 0.0;
        let steps = 64usize;
        for j in 0..steps {
            for i in 0..steps {
                let gx = (i as f64 + 0.5) / steps as f64 * (g.nx - 1) as f64;
                let gy = (j as f64 + 0.5) / steps as f64 * (g.ny - 1) as f64;
                let (u, v) = g.plane_coords(gx, gy);
                let w = (-(u * u + v * v) / (2.0 * ALBEDO_RADIUS_M * ALBEDO_RADIUS_M)).exp();
                let h = g.bilinear(gx, gy);
                let position = Vec3::new(u, v, self.radius_m).normalize() * (self.radius_m + h);
                let hit = SurfaceHit {
                    distance_m: 0.0,
                    position,
                    normal: self.normal_at(position),
                };
                self.albedo(&hit, &mut a);
                sum.iter_mut().zip(&a).for_each(|(s, v)| *s += w * v);
                weights += w;
            }
        }
        sum.iter().map(|s| s / weights).collect()
    }

    /// The floor under the observer: the lowest vertex within 2·[`ALBEDO_RADIUS_M`] of
    /// its foot, and no higher than the ground beneath it (m above the sphere). A sky
    /// method's ground lifted there ([`crate::atmosphere::Atmosphere::lifted`]) holds only
    /// the air the terrain leaves around the observer.
    pub fn floor_m(&self) -> f64 {
        let g = &self.heights;
        let reach = 2.0 * ALBEDO_RADIUS_M;
        let mut floor = self.height_at(0.0, 0.0);
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (u, v) = g.plane_coords(i as f64, j as f64);
                if u * u + v * v <= reach * reach {
                    floor = floor.min(g.at(i, j));
                }
            }
        }
        floor.max(0.0)
    }

    /// The max-mip pyramid of the heights (for a GPU copy of the walk).
    pub fn pyramid(&self) -> &MaxPyramid {
        &self.pyramid
    }

    /// The highest point (m above the sphere).
    pub fn max_height_m(&self) -> f64 {
        self.pyramid.max()
    }

    /// The height (m) at plane coordinates (u, v) (0 off the grid: the sphere).
    pub fn height_at(&self, u: f64, v: f64) -> f64 {
        self.heights.value_at(u, v).unwrap_or(0.0)
    }

    /// The plane coordinates (u, v) of a planet-centred point (None on the far hemisphere).
    pub fn plane_of(&self, p: Vec3) -> Option<(f64, f64)> {
        let r = self.radius_m;
        (p.z > 0.0).then(|| (r * p.x / p.z, r * p.y / p.z))
    }

    /// The height (m) below a planet-centred point.
    pub fn height_below(&self, p: Vec3) -> f64 {
        self.plane_of(p).map_or(0.0, |(u, v)| self.height_at(u, v))
    }

    fn grid_ray(&self, ray: &Ray) -> GridRay {
        GridRay {
            origin: ray.origin,
            dir: ray.dir,
            radius_m: self.radius_m,
        }
    }

    /// The smooth (shading) normal at a planet-centred point on the surface: the surface
    /// S(u, v) = (R + H(u, v))·n̂(u, v), n̂ = (u, v, R)/|(u, v, R)|, with H's gradient from
    /// central differences interpolated bilinearly.
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        let r = self.radius_m;
        let (u, v) = (r * p.x / p.z, r * p.y / p.z);
        let (gx, gy) = self.heights.cell_coords(u, v);
        let (hu, hv) = self.heights.gradient(gx, gy);
        let h = self.heights.bilinear(gx, gy);
        let q = Vec3::new(u, v, r);
        let len = q.length();
        let n = q / len;
        // ∂n̂/∂u = (e_x − n̂ n̂_x)/|q|, likewise for v.
        let dn_du = (Vec3::X - n * n.x) / len;
        let dn_dv = (Vec3::Y - n * n.y) / len;
        let su = hu * n + (r + h) * dn_du;
        let sv = hv * n + (r + h) * dn_dv;
        su.cross(sv).normalize()
    }

    /// The shadow-height field for light direction `light` (computed once per direction).
    pub fn shadow_field(&self, light: Vec3) -> Arc<ShadowField> {
        if let Some((_, f)) = (self.shadows.read().unwrap().iter()).find(|(d, _)| *d == light) {
            return f.clone();
        }
        let mut cache = self.shadows.write().unwrap();
        if let Some((_, f)) = cache.iter().find(|(d, _)| *d == light) {
            return f.clone();
        }
        let field = Arc::new(ShadowField::new(self, light));
        if cache.len() >= SHADOW_CACHE {
            cache.remove(0);
        }
        cache.push((light, field.clone()));
        field
    }

    /// Whether the terrain hides direction `light` from point `p` (planet-centred, on or
    /// above the surface): an exact shadow ray.
    pub fn occludes(&self, p: Vec3, light: Vec3) -> bool {
        let ray = Ray {
            origin: p,
            dir: light,
        };
        self.intersect(&ray, f64::INFINITY).is_some()
    }
}

/// Newton steps on the exact ray height minus the patch from the root `s` of the cell's
/// quadratic `f` (which takes the ray as straight in the cell: to 1e-3 m at grazing
/// incidence), so a hit on a flat terrain is the sphere's to 1e-9 m.
fn refine(gr: &GridRay, grid: &Grid, cell: CellSpan, s: f64, f: [f64; 3]) -> f64 {
    let span = cell.t1 - cell.t0;
    let mut t = cell.t0 + s * span;
    if s <= 0.0 {
        return t;
    }
    let slope = (f[1] + 2.0 * f[2] * s) / span;
    if slope >= 0.0 {
        return t;
    }
    for _ in 0..2 {
        let (x, y, h) = gr.grid_point(grid, t);
        let (a, b) = fractions(x, y, cell.i, cell.j);
        let g = h - bilinear(grid.corners(cell.i, cell.j), a, b);
        t = (t - g / slope).clamp(cell.t0, cell.t1);
    }
    t
}

impl Heightfield {
    /// When `ray` ends at `max_distance_m` on a surface (the terrain or the sphere under it,
    /// within 0.5 m), whether `light` is hidden from that end: an exact shadow ray from 5 cm
    /// above it. None when the ray does not end on a surface.
    pub fn end_in_shadow(&self, ray: &GridRay, light: Vec3, max_distance_m: f64) -> Option<bool> {
        if !max_distance_m.is_finite() {
            return None;
        }
        let end = ray.at(max_distance_m);
        if end.length() - self.radius_m > self.height_below(end) + 0.5 {
            return None;
        }
        Some(self.occludes(end + 0.05 * end.normalize(), light))
    }
}

impl Surface for Heightfield {
    fn intersect(&self, ray: &Ray, max_distance_m: f64) -> Option<SurfaceHit> {
        let gr = self.grid_ray(ray);
        let grid = &self.heights;
        let mut hit_t = None;
        // Rays leaving the surface start a hair above it (no self-hit at t ≈ 0).
        let t_min = 1e-6 * (1.0 + ray.origin.length() * 1e-9);
        for cell in Walk::new(
            grid,
            &self.pyramid,
            None,
            None,
            &gr,
            (t_min, max_distance_m),
        ) {
            let f = gr.gap_in_cell(grid, cell);
            if let Some(s) = first_descent(f) {
                hit_t = Some(refine(&gr, grid, cell, s, f));
                break;
            }
        }
        let t = hit_t.filter(|&t| t > t_min && t < max_distance_m)?;
        let position = ray.origin + t * ray.dir;
        let mut normal = self.normal_at(position);
        if normal.dot(ray.dir) > 0.0 {
            normal = -normal;
        }
        Some(SurfaceHit {
            distance_m: t,
            position,
            normal,
        })
    }

    fn albedo(&self, hit: &SurfaceHit, out: &mut [f64]) {
        let p = hit.position;
        let h = p.length() - self.radius_m;
        let up = p / p.length();
        let slope = hit.normal.dot(up).clamp(-1.0, 1.0).acos();
        self.materials.albedo(p, h, slope, out);
    }

    fn shadowed_intervals(
        &self,
        ray: &Ray,
        light: Vec3,
        max_distance_m: f64,
        out: &mut Vec<(f64, f64)>,
    ) {
        if !self.casts_shadows {
            return;
        }
        let ray = self.grid_ray(ray);
        if self.shafts {
            self.shadow_field(light)
                .shadowed_intervals(self, &ray, max_distance_m, out);
        } else if self.end_in_shadow(&ray, light, max_distance_m) == Some(true) {
            out.push((max_distance_m * (1.0 - 1e-12), max_distance_m));
        }
    }

    fn sky_visibility(&self, hit: &SurfaceHit) -> f64 {
        match (&self.occlusion, self.plane_of(hit.position)) {
            (Some(ao), Some((u, v))) => ao.visibility.value_at(u, v).unwrap_or(1.0),
            _ => 1.0,
        }
    }

    fn horizon(&self, hit: &SurfaceHit, out: &mut [f64; HORIZON_AZIMUTHS]) -> bool {
        match (&self.occlusion, self.plane_of(hit.position)) {
            (Some(ao), Some((u, v))) => ao.horizons_at(u, v, out),
            _ => false,
        }
    }

    fn relief(&self) -> Option<&dyn Relief> {
        self.air_light.then_some(self as &dyn Relief)
    }
}

impl Relief for Heightfield {
    fn planet_radius_m(&self) -> f64 {
        self.radius_m
    }

    fn bounds_m(&self) -> [f64; 4] {
        let g = &self.heights;
        let (w, h) = ((g.nx - 1) as f64, (g.ny - 1) as f64);
        let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)].map(|(x, y)| g.plane_coords(x, y));
        let (us, vs) = (corners.map(|c| c.0), corners.map(|c| c.1));
        let (min, max) = (
            |a: [f64; 4]| a.iter().copied().fold(f64::INFINITY, f64::min),
            |a: [f64; 4]| a.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        [min(us), min(vs), max(us), max(vs)]
    }

    fn top_m(&self) -> f64 {
        self.max_height_m()
    }

    fn height_m(&self, u: f64, v: f64) -> f64 {
        self.height_at(u, v)
    }

    fn shadow_height_m(&self, light: Vec3, u: f64, v: f64) -> f64 {
        let ground = self.height_at(u, v);
        if !(self.casts_shadows && self.shafts) {
            return ground;
        }
        (self.shadow_field(light).heights.value_at(u, v)).map_or(ground, |s| s.max(ground))
    }
}
