//! The terrain's change of the air's multiply scattered light, to first order.
//!
//! A sky method's tables hold the light of an atmosphere over a smooth sphere: every air
//! point is lit by the whole sky and by a flat ground. Near a terrain that is wrong in the
//! directions where a point sees the terrain: the sky behind the mountains does not reach
//! it, the terrain's own reflected light (and the shadowed air in front of it) does.
//! Bruneton & Neyret 2008 §5 leave this out; docs/accuracy.md measures what it costs. The
//! change of the radiance arriving at a point x from direction ω is
//!
//!   ΔL(x, ω) = L_scene(x, ω) − L_smooth(x, ω),
//!
//! the renderer's radiance with the terrain (lit, shadowed, through its shafts; the lights'
//! disks left out) minus the sky method's over its own smooth ground; scattered once
//! towards the observer it adds
//!
//!   ΔJ(x, v) = Σ_g σ_g(x) ∫ p_g(v·ω) ΔL(x, ω) dω
//!
//! (W·m⁻³·sr⁻¹·nm⁻¹; g the molecules and the aerosols; v the view direction, from the
//! observer outwards), which a view integrates with the air's transmittance,
//! ΔS = ∫ T(0, s) ΔJ(x_s, v) ds ([`super::air_volume`]). Higher orders of the change (ΔL
//! scattered twice) are left out: they scale with the scattering optical depth of the
//! valley's air (≈ 0.1 over a few km).
//!
//! [`AirField`] holds ΔL on a grid of columns over the relief and levels above its ground,
//! in the directions of a quadrature that crowds where mountains hide the brightest sky
//! (a cap around each light, its aureole; a band about the horizon), so ΔJ for any v is
//! the quadrature's sum with the exact phase functions. (Spherical harmonics of degree 2
//! were tried first: they smear the aerosols' forward peak, and views towards a low sun
//! behind a ridge read 30–70 % high.) [`scattering_change`] is the same integral at one
//! point without the grid, the field's check.

use rayon::prelude::*;

use crate::atmosphere::groups::{AEROSOLS, MOLECULES};
use crate::math::lattice::band_directions;
use crate::math::Vec3;
use crate::scene::{Ray, Relief, Scene};
use crate::spectrum::MAX_CHANNELS;
use crate::Result;

use super::sky_dome::SkyDome;
use super::{ShadeScratch, Shader};
use std::sync::Arc;

/// Columns of the field along each side of the relief's rectangle.
pub const COLUMNS: usize = 13;

/// Levels of the field above the relief's ground (m): close together near the ground,
/// where the mountains hide most of the sky.
pub const LEVELS_M: [f64; 6] = [10.0, 150.0, 500.0, 1100.0, 2100.0, 3600.0];

/// Directions per field point in bands of elevation (degrees): below −20°, −20° to 25°
/// (where mountains stand against the brightest sky, near the horizon), above 25°.
pub const BANDS: [(f64, f64, usize); 3] =
    [(-90.0, -20.0, 24), (-20.0, 25.0, 144), (25.0, 90.0, 24)];

/// Directions in the cap around each light (the aureole: the brightest sky a mountain
/// can hide, too narrow for the sphere's directions).
pub const CAP_DIRECTIONS: usize = 32;

/// The cap's half-angle (degrees).
pub const CAP_HALF_ANGLE_DEG: f64 = 12.0;

/// The directions and their solid angles (sr) for lights in `lights` (unit): a cap around
/// each, the sphere's lattice outside the caps; the weights sum to 4π.
pub fn quadrature(lights: &[Vec3]) -> Vec<(Vec3, f64)> {
    let cos_cap = CAP_HALF_ANGLE_DEG.to_radians().cos();
    let in_cap = |d: Vec3| lights.iter().any(|l| d.dot(*l) > cos_cap);
    let mut out: Vec<(Vec3, f64)> = Vec::new();
    for (k, &l) in lights.iter().enumerate() {
        // A cap overlapping an earlier one keeps only its own part (rare: two lights
        // within 24° of each other).
        let earlier = |d: Vec3| lights[..k].iter().any(|e| d.dot(*e) > cos_cap);
        let w = 2.0 * std::f64::consts::PI * (1.0 - cos_cap) / CAP_DIRECTIONS as f64;
        for d in band_directions(l, cos_cap, 1.0, CAP_DIRECTIONS) {
            if !earlier(d) {
                out.push((d, w));
            }
        }
    }
    // Each band's directions share its solid angle less the caps' part in it (the caps'
    // area per band counted by its own lattice, 16 times finer).
    for (e0, e1, count) in BANDS {
        let (z0, z1) = (e0.to_radians().sin(), e1.to_radians().sin());
        let area = 2.0 * std::f64::consts::PI * (z1 - z0);
        let fine = band_directions(Vec3::Z, z0, z1, 16 * count);
        let open = fine.iter().filter(|&&d| !in_cap(d)).count() as f64 / fine.len() as f64;
        let rest: Vec<Vec3> = band_directions(Vec3::Z, z0, z1, count)
            .into_iter()
            .filter(|&d| !in_cap(d))
            .collect();
        let w = area * open / rest.len().max(1) as f64;
        out.extend(rest.into_iter().map(|d| (d, w)));
    }
    out
}

/// The scene without its relief: the same sky method and lights (disks off) over the sky
/// method's own ground.
fn smooth_scene<'a>(scene: &Scene<'a>) -> Scene<'a> {
    let mut smooth = Scene::clear_sky(scene.sky, Vec3::Z, false);
    smooth.lights = scene.lights.clone();
    smooth
        .lights
        .iter_mut()
        .for_each(|l| l.visible_disk = false);
    smooth
}

/// ΔL(x, ω) for each direction of `dirs`, per channel, into `out` (`dirs.len()` ×
/// channels): `with` shades the scene from x, `without` the smooth scene.
fn radiance_change(with: &Shader, without: &Shader, x: Vec3, dirs: &[Vec3], out: &mut [f64]) {
    let n = with.channels;
    let mut scratch = ShadeScratch::default();
    let mut b = [0.0; MAX_CHANNELS];
    for (&dir, o) in dirs.iter().zip(out.chunks_mut(n)) {
        let ray = Ray { origin: x, dir };
        with.shade(&ray, &mut scratch, o);
        without.shade(&ray, &mut scratch, &mut b[..n]);
        for k in 0..n {
            o[k] -= b[k];
        }
    }
}

/// ΔJ(x, v) of the module's doc into `out` (per channel) by brute force: `dirs` with their
/// solid angles ([`quadrature`]), the exact phase functions. `scene` holds the relief;
/// its lights' disks are left out.
pub fn scattering_change(
    scene: &Scene,
    x: Vec3,
    view: Vec3,
    dirs: &[(Vec3, f64)],
    out: &mut [f64],
) -> Result<()> {
    let model = scene.sky.model();
    let n = model.channels();
    let smooth = smooth_scene(scene);
    let with = Shader::probe(scene, x)?.without_disks().with_sky_domes();
    let without = with.probe_of(&smooth)?;
    let directions: Vec<Vec3> = dirs.iter().map(|d| d.0).collect();
    let mut dl = vec![0.0; directions.len() * n];
    radiance_change(&with, &without, x, &directions, &mut dl);
    let (mut sigma_m, mut sigma_a) = ([0.0; MAX_CHANNELS], [0.0; MAX_CHANNELS]);
    let altitude = (x.length() - model.bottom_radius_m).max(0.0);
    let groups = &model.groups;
    groups.scattering_into(model, MOLECULES, altitude, &mut sigma_m[..n]);
    groups.scattering_into(model, AEROSOLS, altitude, &mut sigma_a[..n]);
    out[..n].iter_mut().for_each(|v| *v = 0.0);
    for (&(dir, w), d) in dirs.iter().zip(dl.chunks(n)) {
        // The light arriving from `dir` travels along −dir; scattered into −view, the
        // scattering angle's cosine is view·dir.
        let nu = view.dot(dir);
        let (pm, pa) = (
            groups.phase[MOLECULES].eval(nu),
            groups.phase[AEROSOLS].eval(nu),
        );
        for k in 0..n {
            out[k] += w * (sigma_m[k] * pm + sigma_a[k] * pa) * d[k];
        }
    }
    Ok(())
}

/// ΔL on a grid over a relief (module doc): at each point, for each direction of
/// [`quadrature`], per channel.
pub struct AirField<'a> {
    relief: &'a dyn Relief,
    /// The first light's direction (unit), whose shadow the field's heights follow.
    light: Option<Vec3>,
    /// The planet's radius (m).
    radius_m: f64,
    /// The relief's rectangle [u_min, v_min, u_max, v_max] in the plane (m).
    bounds: [f64; 4],
    /// The ground's height (m) at each column, row-major.
    ground: Vec<f64>,
    /// The first light's shadow height (m, [`Relief::shadow_height_m`]) at each column.
    shadow: Vec<f64>,
    channels: usize,
    /// The directions and their solid angles (sr).
    dirs: Vec<(Vec3, f64)>,
    /// ΔL (W·m⁻²·sr⁻¹·nm⁻¹) per point (`(j·COLUMNS + i)·levels + level`), direction and
    /// channel.
    radiance: Vec<f32>,
}

impl<'a> AirField<'a> {
    /// The field of `scene`'s first surface with a relief, under its lights; None when no
    /// surface has one. `domes`: the sky's radiance per light for the terrain's shading
    /// ([`Shader::with_domes`]).
    pub fn new(scene: &'a Scene, domes: Option<Arc<Vec<SkyDome>>>) -> Result<Option<AirField<'a>>> {
        let Some(relief) = scene.surfaces.iter().find_map(|s| s.relief()) else {
            return Ok(None);
        };
        let model = scene.sky.model();
        let n = model.channels();
        let radius = relief.planet_radius_m();
        let bounds = relief.bounds_m();
        let ground: Vec<f64> = (0..COLUMNS * COLUMNS)
            .map(|c| {
                let (u, v) = column_plane(bounds, c % COLUMNS, c / COLUMNS);
                relief.height_m(u, v)
            })
            .collect();
        let lights: Vec<Vec3> = scene.lights.iter().map(|l| l.direction).collect();
        let dirs = quadrature(&lights);
        let directions: Vec<Vec3> = dirs.iter().map(|q| q.0).collect();
        let smooth = smooth_scene(scene);
        let points = COLUMNS * COLUMNS * LEVELS_M.len();
        let per_point = directions.len() * n;
        let mut radiance = vec![0.0f32; points * per_point];
        radiance
            .par_chunks_mut(per_point)
            .enumerate()
            .try_for_each(|(p, out)| -> Result<()> {
                let (column, level) = (p / LEVELS_M.len(), p % LEVELS_M.len());
                let (u, v) = column_plane(bounds, column % COLUMNS, column / COLUMNS);
                let x = plane_point(radius, u, v, ground[column] + LEVELS_M[level]);
                let with = Shader::probe(scene, x)?
                    .without_disks()
                    .with_domes(domes.clone());
                let without = with.probe_of(&smooth)?;
                let mut dl = vec![0.0; per_point];
                radiance_change(&with, &without, x, &directions, &mut dl);
                for (o, d) in out.iter_mut().zip(&dl) {
                    *o = *d as f32;
                }
                Ok(())
            })?;
        let light = lights.first().copied();
        let shadow = (0..COLUMNS * COLUMNS)
            .map(|c| {
                let (u, v) = column_plane(bounds, c % COLUMNS, c / COLUMNS);
                light.map_or(ground[c], |l| relief.shadow_height_m(l, u, v))
            })
            .collect();
        Ok(Some(AirField {
            relief,
            light,
            radius_m: radius,
            bounds,
            ground,
            shadow,
            channels: n,
            dirs,
            radiance,
        }))
    }

    /// The relief's top plus twice the field's highest level (m from the planet's centre):
    /// above it the field is zero.
    pub fn ceiling_radius_m(&self) -> f64 {
        let top = self.ground.iter().copied().fold(0.0, f64::max);
        self.radius_m + top + 2.0 * LEVELS_M[LEVELS_M.len() - 1]
    }

    /// For a view direction `view`: each direction's solid angle times the molecules' and
    /// the aerosols' phase functions at the scattering angle (`model`'s groups).
    pub fn phase_weights(&self, model: &crate::atmosphere::Model, view: Vec3) -> Vec<[f64; 2]> {
        let phase = &model.groups.phase;
        (self.dirs.iter())
            .map(|&(d, w)| {
                // The light arriving from d travels along −d; scattered into −view, the
                // scattering angle's cosine is view·d.
                let nu = view.dot(d);
                [w * phase[MOLECULES].eval(nu), w * phase[AEROSOLS].eval(nu)]
            })
            .collect()
    }

    /// ΔJ(x, v) into `out` (per channel): the field interpolated at x (zero off the
    /// relief's rectangle, fading to zero over as much again above the highest level),
    /// scattered with `weights` (from [`Self::phase_weights`] for v) and `sigma`, the
    /// molecules' and the aerosols' scattering coefficients at x (m⁻¹).
    ///
    /// Bilinear between the four columns around x; in each column, linear between the
    /// levels at the height over the column's shadow height S (the first light's,
    /// [`Relief::shadow_height_m`]; the ground where it is lit) that x has over its own.
    /// ΔL jumps at the shadow's edge, far more sharply than the columns resolve: a point in
    /// the shadow loses the aureole the ridge hides round the light, and its rays towards
    /// the light run through shadowed air before they reach the lit air; a point above the
    /// edge keeps both. So each column is read on the same side of its shadow's edge, as
    /// far from it, as x. Where the light reaches the ground, S is the ground and this is
    /// the height above it.
    pub fn scattering_change_at(
        &self,
        x: Vec3,
        weights: &[[f64; 2]],
        sigma: [&[f64]; 2],
        out: &mut [f64],
    ) {
        let n = self.channels;
        out[..n].iter_mut().for_each(|v| *v = 0.0);
        if x.z <= 0.0 {
            return;
        }
        let (u, v) = (self.radius_m * x.x / x.z, self.radius_m * x.y / x.z);
        let [u0, v0, u1, v1] = self.bounds;
        let last = (COLUMNS - 1) as f64;
        let (gx, gy) = ((u - u0) / (u1 - u0) * last, (v - v0) / (v1 - v0) * last);
        if !(0.0..=last).contains(&gx) || !(0.0..=last).contains(&gy) {
            return;
        }
        let (i, j) = (
            (gx as usize).min(COLUMNS - 2),
            (gy as usize).min(COLUMNS - 2),
        );
        let (fx, fy) = (gx - i as f64, gy - j as f64);
        let height = x.length() - self.radius_m;
        let above_shadow = height - self.shadow_height_m(u, v);
        let per_point = self.dirs.len() * n;
        // The phase-weighted sums Σ_q w_q p_g ΔL_q at the points, interpolated.
        let mut sums = [[0.0; MAX_CHANNELS]; 2];
        for (di, dj, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let column = (j + dj) * COLUMNS + i + di;
            let w = w * fade(height - self.ground[column]);
            if w == 0.0 {
                continue;
            }
            let h = self.shadow[column] + above_shadow - self.ground[column];
            for (level, wl) in level_of(h) {
                let w = w * wl;
                if w == 0.0 {
                    continue;
                }
                let base = (column * LEVELS_M.len() + level) * per_point;
                let point = &self.radiance[base..base + per_point];
                for (pw, dl) in weights.iter().zip(point.chunks_exact(n)) {
                    for k in 0..n {
                        let d = w * dl[k] as f64;
                        sums[0][k] += pw[0] * d;
                        sums[1][k] += pw[1] * d;
                    }
                }
            }
        }
        for k in 0..n {
            out[k] = sigma[0][k] * sums[0][k] + sigma[1][k] * sums[1][k];
        }
    }

    /// The first light's shadow height at (u, v) (m above the sphere).
    fn shadow_height_m(&self, u: f64, v: f64) -> f64 {
        match self.light {
            Some(l) => self.relief.shadow_height_m(l, u, v),
            None => self.relief.height_m(u, v),
        }
    }
}

/// The two levels that bracket a height `h` (m above the ground) and their weights: linear
/// between them, the nearest alone beyond the lowest or the highest.
fn level_of(h: f64) -> [(usize, f64); 2] {
    let top = LEVELS_M.len() - 1;
    if h <= LEVELS_M[0] {
        return [(0, 1.0), (0, 0.0)];
    }
    if h >= LEVELS_M[top] {
        return [(top, 1.0), (top, 0.0)];
    }
    let l = LEVELS_M.partition_point(|&a| a <= h) - 1;
    let f = (h - LEVELS_M[l]) / (LEVELS_M[l + 1] - LEVELS_M[l]);
    [(l, 1.0 - f), (l + 1, f)]
}

/// 1 up to the field's highest level (m above the ground), then down to 0 over as much
/// again.
fn fade(h: f64) -> f64 {
    let top = LEVELS_M[LEVELS_M.len() - 1];
    (2.0 - h / top).clamp(0.0, 1.0)
}

/// Plane coordinates of column (i, j) of a rectangle.
fn column_plane(bounds: [f64; 4], i: usize, j: usize) -> (f64, f64) {
    let [u0, v0, u1, v1] = bounds;
    let last = (COLUMNS - 1) as f64;
    (
        u0 + (u1 - u0) * i as f64 / last,
        v0 + (v1 - v0) * j as f64 / last,
    )
}

/// The planet-centred point at plane coordinates (u, v), `height_m` above a sphere of
/// radius `radius_m` (the gnomonic plane at (0, 0, R)).
fn plane_point(radius_m: f64, u: f64, v: f64, height_m: f64) -> Vec3 {
    Vec3::new(u, v, radius_m).normalize() * (radius_m + height_m)
}
