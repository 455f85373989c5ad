//! The sky-method seam: what rendering asks of the atmosphere, and the methods that answer.
//!
//! A [`SkyMethod`] evaluates the light transport of one resolved atmosphere ([`Model`]). For
//! one observer and one light it prepares a [`SkyView`], the method's per-view cache
//! (Bruneton's tables filtered at the observer's radius and sun angle; Hillaire's sky-view
//! and aerial-perspective tables will be caches of the same kind), and every question a
//! renderer asks goes through that view: sky radiance and transmittance along a ray from the
//! observer, in-scattered radiance and transmittance to a point (aerial perspective) with
//! the parts of the ray in shadow left out ([`Shadow`]: light shafts), the transmittance
//! from any point to the light, and the light's direct and sky irradiance on a surface.
//!
//! Radiance is W·m⁻²·sr⁻¹·nm⁻¹ and irradiance W·m⁻²·nm⁻¹ per channel of the model's
//! wavelength grid; positions are planet-centred metres, directions unit vectors. A light
//! other than the one the method was built for (the moon lighting the sun's tables) scales
//! the results by its own irradiance.
//!
//! Methods: [`bruneton4d`] (Bruneton & Neyret 2008, the 4D precomputed tables),
//! [`hillaire2020`] (Hillaire 2020: transmittance, multiple-scattering and sky-view tables
//! and a ray march), [`elek3d`] (Elek 2009 with Yusov 2013's parameterisation: a 3D table
//! without the view–sun azimuth, as Frostbite 2016 uses it).

pub mod bruneton4d;
pub mod elek3d;
pub mod entry;
pub mod hillaire2020;
pub mod surface_irradiance;

pub use bruneton4d::Bruneton4d;
pub use elek3d::Elek3d;
pub use hillaire2020::Hillaire2020;

use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;

/// Which parts of a view ray the light reaches (Bruneton & Neyret 2008 §5, eq. 17–18).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Shadow<'a> {
    /// The whole ray is lit.
    #[default]
    None,
    /// The paper's shadowed length (m): in shadow over the first metres of a ray to the sky,
    /// over the last metres of a ray to a point (the shadow behind an occluder seen from the
    /// front).
    Length(f64),
    /// The lit intervals [start, end] (m from the observer along the ray), increasing and
    /// disjoint; the rest of the ray is in shadow. Exact light shafts from the CPU's lit
    /// segments (the terrain's and the clouds' shadows): the single scattering is taken
    /// over the lit intervals only, the multiple over the whole ray (the air in a shadow is
    /// still lit by the sky; what the shadowing surface hides of the sky is
    /// `render::terrain_air`'s). `Length` leaves both out, as the paper does.
    Lit(&'a [(f64, f64)]),
}

/// A way of evaluating an atmosphere's light transport (the 4D tables, Hillaire 2020, the
/// 3D table, the reference path tracer).
pub trait SkyMethod: Send + Sync {
    /// The atmosphere it evaluates.
    fn model(&self) -> &Model;

    /// The evaluation for views from `observer` (planet-centred, m; anywhere, in space too)
    /// lit by `light`: the method's per-view cache is built here, once per frame and light.
    /// A light other than the model's sun scales every answer by its irradiance over the
    /// model's [`Model::solar_irradiance`].
    fn view<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a>;

    /// A view for a few rays only (a few hundred: the terrain's air field at points of the
    /// air, a probe at a point): a method whose per-view cache costs more than marching
    /// that many rays (Hillaire's sky-view table) may leave it out. The answers are the
    /// method's either way; by default the same as [`SkyMethod::view`].
    fn probe<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        self.view(observer, light)
    }
}

/// A sky method prepared for one observer and one light. Outputs are per channel of the
/// model's wavelength grid, overwritten.
pub trait SkyView: Send + Sync {
    /// The light.
    fn light(&self) -> &Light;

    /// Radiance (W·m⁻²·sr⁻¹·nm⁻¹) scattered towards the observer along the ray in unit
    /// direction `dir` (world frame) up to the atmosphere boundary or the planet's ground
    /// (the ground's own radiance and the light's disk excluded), and the transmittance
    /// (0–1) along that ray (0 where it meets the ground). An empty `transmittance` asks for
    /// the radiance only.
    fn sky_radiance(
        &self,
        dir: Vec3,
        shadow: Shadow,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    );

    /// Radiance (W·m⁻²·sr⁻¹·nm⁻¹) scattered towards the observer between it and `point`
    /// (planet-centred, m; aerial perspective, paper eq. 16's S|x − T(x, x_s)·S|x_s) and the
    /// transmittance (0–1) between them.
    fn sky_radiance_to_point(
        &self,
        point: Vec3,
        shadow: Shadow,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    );

    /// [`SkyView::sky_radiance_to_point`] without shadows for each of `points`, which lie
    /// on one ray from the observer in increasing distance (an aerial-perspective froxel
    /// column), into `radiance` and `transmittance` (`points.len()` × channels values,
    /// point-major). By default one query per point; a method that marches (Hillaire 2020)
    /// marches the ray once through all of them.
    fn sky_radiance_along(&self, points: &[Vec3], radiance: &mut [f64], transmittance: &mut [f64]) {
        let n = radiance.len() / points.len().max(1);
        for (i, &point) in points.iter().enumerate() {
            let (l, t) = (
                &mut radiance[i * n..(i + 1) * n],
                &mut transmittance[i * n..(i + 1) * n],
            );
            self.sky_radiance_to_point(point, Shadow::None, l, t);
        }
    }

    /// Transmittance (0–1) of the air between the observer and `point` (planet-centred, m).
    fn transmittance_to_point(&self, point: Vec3, out: &mut [f64]);

    /// Transmittance (0–1) from `point` (planet-centred, m) to the light, with the planet's
    /// occlusion of its disk: times the light's irradiance, the direct beam's irradiance on
    /// a surface facing it.
    fn transmittance_to_light(&self, point: Vec3, out: &mut [f64]);

    /// The light's direct irradiance and the sky's irradiance (W·m⁻²·nm⁻¹) on a surface at
    /// `point` (planet-centred, m) with unit `normal` (the direct term with the cosine of
    /// the light's incidence, the sky term with the (1 + n·n̄)/2 occlusion factor of paper
    /// eq. 16; above the atmosphere the direct beam only).
    fn sun_and_sky_irradiance(
        &self,
        point: Vec3,
        normal: Vec3,
        direct: &mut [f64],
        sky: &mut [f64],
    );
}
