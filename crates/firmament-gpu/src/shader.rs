//! WGSL composition. Every constant the shaders share with the CPU code is defined once, in
//! Rust, and handed to WGSL in a generated prelude; every pipeline's source is the prelude
//! followed by the modules it needs, in the order of [`Module`]s given (Hillaire 2020's
//! shaders add their own constants after it). Each WGSL file has a
//! Rust twin with the same name and function names (see `docs/architecture.md`).

pub use crate::wgsl_prelude::prelude;
use firmament::sky::bruneton4d::precompute::TRANSMITTANCE_SEGMENTS;

/// A WGSL source file and its path under `shaders/` (for messages).
#[derive(Clone, Copy, Debug)]
pub struct Module {
    /// Path under `shaders/`.
    pub path: &'static str,
    /// The source.
    pub source: &'static str,
}

impl Module {
    /// The file's name without its folder and extension (the pipeline's label).
    pub fn name(&self) -> &'static str {
        let file = self.path.rsplit('/').next().unwrap_or(self.path);
        file.strip_suffix(".wgsl").unwrap_or(file)
    }
}

macro_rules! module {
    ($path:literal) => {
        Module {
            path: $path,
            source: include_str!(concat!("../shaders/", $path)),
        }
    };
}

/// The modules every shader has: types, bindings, profiles, phase functions, geometry.
pub const COMMON: [Module; 5] = [
    module!("common/types.wgsl"),
    module!("common/bindings.wgsl"),
    module!("common/profile.wgsl"),
    module!("common/phase.wgsl"),
    module!("common/geometry.wgsl"),
];

/// The 4D tables' parameterisations, filters and lookups.
pub const BRUNETON4D: [Module; 6] = [
    module!("bruneton4d/params.wgsl"),
    module!("bruneton4d/mu_s_map.wgsl"),
    module!("bruneton4d/table.wgsl"),
    module!("bruneton4d/mu_s_blend.wgsl"),
    module!("bruneton4d/r_blend.wgsl"),
    module!("bruneton4d/lookup.wgsl"),
];

/// What the precomputation passes share besides [`COMMON`] and [`BRUNETON4D`].
pub const PRECOMPUTE: [Module; 2] = [
    module!("bruneton4d/precompute/ray.wgsl"),
    module!("bruneton4d/precompute/previous.wgsl"),
];

/// The precomputation passes, one file each.
pub mod passes {
    use super::Module;
    /// transmittance.wgsl
    pub const TRANSMITTANCE: Module = module!("bruneton4d/precompute/transmittance.wgsl");
    /// direct_irradiance.wgsl
    pub const DIRECT_IRRADIANCE: Module = module!("bruneton4d/precompute/direct_irradiance.wgsl");
    /// single_scattering.wgsl
    pub const SINGLE_SCATTERING: Module = module!("bruneton4d/precompute/single_scattering.wgsl");
    /// phase_kernels.wgsl
    pub const PHASE_KERNELS: Module = module!("bruneton4d/precompute/phase_kernels.wgsl");
    /// scattering_density_field.wgsl
    pub const SCATTERING_DENSITY_FIELD: Module =
        module!("bruneton4d/precompute/scattering_density_field.wgsl");
    /// scattering_density.wgsl
    pub const SCATTERING_DENSITY: Module = module!("bruneton4d/precompute/scattering_density.wgsl");
    /// indirect_irradiance.wgsl
    pub const INDIRECT_IRRADIANCE: Module =
        module!("bruneton4d/precompute/indirect_irradiance.wgsl");
    /// multiple_scattering.wgsl
    pub const MULTIPLE_SCATTERING: Module =
        module!("bruneton4d/precompute/multiple_scattering.wgsl");
    /// order_sums.wgsl
    pub const ORDER_SUMS: Module = module!("bruneton4d/precompute/order_sums.wgsl");
    /// order_tail_factors.wgsl
    pub const ORDER_TAIL_FACTORS: Module = module!("bruneton4d/precompute/order_tail_factors.wgsl");
    /// order_tail.wgsl
    pub const ORDER_TAIL: Module = module!("bruneton4d/precompute/order_tail.wgsl");
}

/// The sky method's render-time modules (the view of one observer and one light; its
/// questions towards any point and over lit intervals).
pub const BRUNETON4D_VIEW: [Module; 3] = [
    module!("bruneton4d/view.wgsl"),
    module!("bruneton4d/view_point.wgsl"),
    module!("bruneton4d/twilight.wgsl"),
];

/// The terrain: its bindings, the grid and its walk, the surface, the materials, the
/// horizons, the shadow fields.
pub const TERRAIN: [Module; 7] = [
    module!("terrain/terrain.wgsl"),
    module!("terrain/grid.wgsl"),
    module!("terrain/walk.wgsl"),
    module!("terrain/heightfield.wgsl"),
    module!("terrain/materials.wgsl"),
    module!("terrain/occlusion.wgsl"),
    module!("terrain/shadow.wgsl"),
];

/// The renderer's modules: lights, cameras, the air volume, the scene over the terrain, the
/// frame.
pub const RENDER: [Module; 9] = [
    module!("render/frame.wgsl"),
    module!("render/light.wgsl"),
    module!("render/planet.wgsl"),
    module!("render/camera.wgsl"),
    module!("render/disk_edges.wgsl"),
    module!("render/air_volume.wgsl"),
    module!("render/sky_dome.wgsl"),
    module!("render/scene.wgsl"),
    module!("render/render.wgsl"),
];

/// The clouds' modules (after [`RENDER`]): their types, noise, weather (tiled and the
/// planet's), the filtered density, layers, two-stream tables and medium, the shadow map, the
/// march and the frame under them.
pub const CLOUDS: [Module; 12] = [
    module!("clouds/profile.wgsl"),
    module!("clouds/noise_volume.wgsl"),
    module!("clouds/weather.wgsl"),
    module!("clouds/planetary.wgsl"),
    module!("clouds/lod.wgsl"),
    module!("clouds/layer.wgsl"),
    module!("clouds/two_stream.wgsl"),
    module!("clouds/medium.wgsl"),
    module!("render/cloud_shadow.wgsl"),
    module!("render/shadowed_air.wgsl"),
    module!("render/volumes.wgsl"),
    module!("render/cloud_frame.wgsl"),
];

/// Hillaire 2020's shared modules (after [`COMMON`] and [`BRUNETON4D`], whose lookups read
/// its optical depth): its sizes and data, parameterisations, harmonics and the ray march.
pub const HILLAIRE2020: [Module; 4] = [
    module!("hillaire2020/config.wgsl"),
    module!("hillaire2020/params.wgsl"),
    module!("hillaire2020/harmonics.wgsl"),
    module!("hillaire2020/march.wgsl"),
];

/// Hillaire 2020's atmosphere-wide passes besides the transmittance (the 4D tables' pass,
/// [`hillaire2020_transmittance_source`]), one file each.
pub mod hillaire2020_passes {
    use super::Module;
    /// multiple_scattering.wgsl (entry points `gather`, `main`, `gather_next`,
    /// `project_next` and `tail`)
    pub const MULTIPLE_SCATTERING: Module = module!("hillaire2020/multiple_scattering.wgsl");
    /// irradiance.wgsl (entry points `gather` and `main`)
    pub const IRRADIANCE: Module = module!("hillaire2020/irradiance.wgsl");
}

/// Hillaire 2020's render-time modules: the per-frame sky-view tables (entry point
/// `sky_view`) and the view.
pub const HILLAIRE2020_VIEW: [Module; 2] = [
    module!("hillaire2020/sky_view.wgsl"),
    module!("hillaire2020/view.wgsl"),
];

/// What a Hillaire 2020 frame takes of the renderer's modules (no terrain: its scene is the
/// clear sky, `hillaire2020/scene.wgsl`): lights, cameras, the disks' edges, the frame.
pub const HILLAIRE2020_RENDER: [Module; 7] = [
    module!("hillaire2020/scene.wgsl"),
    module!("render/frame.wgsl"),
    module!("render/light.wgsl"),
    module!("render/planet.wgsl"),
    module!("render/camera.wgsl"),
    module!("render/disk_edges.wgsl"),
    module!("render/render.wgsl"),
];

/// Elek 2009 / Yusov 2013's 3D tables (after [`COMMON`] and [`BRUNETON4D`], whose lookups
/// read its optical depth and irradiance): its parameterisation and trilinear filter.
pub const ELEK3D: [Module; 2] = [module!("elek3d/params.wgsl"), module!("elek3d/table.wgsl")];

/// The 3D tables' render-time modules: the view (with its `camera_slice` entry point) and
/// the 4D tables' twilight below the tables' lowest sun.
pub const ELEK3D_VIEW: [Module; 2] = [
    module!("elek3d/view.wgsl"),
    module!("bruneton4d/twilight.wgsl"),
];

/// What a 3D-table frame takes of the renderer's modules (no terrain: its scene is the
/// clear sky, `elek3d/scene.wgsl`): lights, cameras, the disks' edges, the frame.
pub const ELEK3D_RENDER: [Module; 7] = [
    module!("elek3d/scene.wgsl"),
    module!("render/frame.wgsl"),
    module!("render/light.wgsl"),
    module!("render/planet.wgsl"),
    module!("render/camera.wgsl"),
    module!("render/disk_edges.wgsl"),
    module!("render/render.wgsl"),
];

/// The temporal resolve of interleaved frames (`render::temporal`): the frame's constants,
/// the cameras and the resolve.
pub const TEMPORAL: [Module; 3] = [
    module!("render/frame.wgsl"),
    module!("render/camera.wgsl"),
    module!("render/temporal.wgsl"),
];

/// The frame's output into a storage buffer.
pub const OUTPUT_BUFFER: Module = module!("render/output_buffer.wgsl");
/// The frame's output into a storage texture (`OUTPUT_FORMAT` substituted).
pub const OUTPUT_TEXTURE: Module = module!("render/output_texture.wgsl");

/// The prelude followed by `modules`, with `OUTPUT_FORMAT` replaced by `output_format` when
/// given.
pub fn compose(modules: &[Module], output_format: Option<&str>) -> String {
    let mut s = prelude();
    for m in modules {
        s += &format!("\n// ---- {} ----\n", m.path);
        match output_format {
            Some(f) => s += &m.source.replace("OUTPUT_FORMAT", f),
            None => s += m.source,
        }
    }
    s
}

/// The source of precomputation pass `pass`.
pub fn precompute_source(pass: Module) -> String {
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&PRECOMPUTE)
        .copied()
        .chain([pass])
        .collect();
    compose(&modules, None)
}

/// The sky method's WGSL for an engine's own shader: the prelude, the common modules, the 4D
/// tables' lookups and the view functions (`sky_ray`/`sky_radiance`, `ground_ray`/
/// `sky_radiance_to_point`, `ground_light`/`sun_and_sky_irradiance`, `camera_slice`; towards
/// any point and over lit intervals: `point_ray`, `piece_at`, `lit_single`,
/// `whole_multiple`, `point_light`/`point_irradiance`). The
/// bindings it declares are documented in `shaders/bruneton4d/view.wgsl` and on
/// [`crate::GpuSky`].
pub fn sky_module() -> String {
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&BRUNETON4D_VIEW)
        .copied()
        .collect();
    compose(&modules, None)
}

/// The render shader's source, writing to a buffer (`output_format` None) or to a storage
/// texture of that WGSL format (`rgba32float`, `rgba16float`).
pub fn render_source(output_format: Option<&str>) -> String {
    let output = if output_format.is_some() {
        OUTPUT_TEXTURE
    } else {
        OUTPUT_BUFFER
    };
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&BRUNETON4D_VIEW)
        .chain(&TERRAIN)
        .chain(&RENDER)
        .chain(&CLOUDS)
        .copied()
        .chain([output])
        .collect();
    compose(&modules, output_format)
}

/// The temporal resolve's source (`render::temporal`).
pub fn temporal_source() -> String {
    compose(&TEMPORAL, None)
}

/// The constants Hillaire 2020's shaders add to the prelude.
fn hillaire2020_prelude() -> String {
    let norms = firmament::sky::hillaire2020::harmonics::normalisations();
    let list: Vec<String> = norms.iter().map(|&n| format!("{:?}", n as f32)).collect();
    format!(
        "// Hillaire 2020 (firmament_gpu::hillaire2020).\nconst F_MS_GUARD: f32 = {:?};\nconst MU_S_HORIZON_STRETCH: f32 = {:?};\n\
         // N_ℓm of the harmonics at harmonic_index(ℓ, m) (harmonics::normalisations).\n\
         var<private> HARMONIC_NORMALISATIONS: array<f32, {}> = array<f32, {}>({});\n",
        crate::hillaire2020::F_MS_GUARD as f32,
        firmament::sky::hillaire2020::params::MU_S_HORIZON_STRETCH as f32,
        norms.len(),
        norms.len(),
        list.join(", ")
    )
}

/// [`compose`] with Hillaire 2020's constants after the prelude.
fn compose_hillaire2020(modules: &[Module], output_format: Option<&str>) -> String {
    let mut s = compose(modules, output_format);
    s.insert_str(prelude().len(), &hillaire2020_prelude());
    s
}

/// The 4D tables' transmittance pass with `segments` Gauss–Legendre segments per ray in
/// place of [`TRANSMITTANCE_SEGMENTS`] (Hillaire 2020's `transmittance_segments`).
pub fn hillaire2020_transmittance_source(segments: usize) -> String {
    let line = |n: usize| format!("const TRANSMITTANCE_SEGMENTS: u32 = {n}u;\n");
    let source = precompute_source(passes::TRANSMITTANCE);
    assert!(source.contains(&line(TRANSMITTANCE_SEGMENTS)));
    source.replacen(&line(TRANSMITTANCE_SEGMENTS), &line(segments), 1)
}

/// The source of Hillaire 2020's pass `pass` ([`hillaire2020_passes`]).
pub fn hillaire2020_pass_source(pass: Module) -> String {
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&HILLAIRE2020)
        .copied()
        .chain([pass])
        .collect();
    compose_hillaire2020(&modules, None)
}

/// Hillaire 2020's WGSL for an engine's own shader: the prelude, the common modules, the
/// optical-depth lookups, the march, the sky-view tables and the view functions (the names
/// of [`sky_module`]'s `sky_ray`/`sky_radiance`, `ground_ray`/`sky_radiance_to_point`,
/// `ground_light`/`sun_and_sky_irradiance`, and the `sky_view` entry point that fills the
/// per-frame tables). The bindings are listed in `shaders/hillaire2020/view.wgsl` and on
/// [`crate::GpuHillaire`]. One sky method per shader: it defines the same names as
/// [`sky_module`].
pub fn hillaire2020_sky_module() -> String {
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&HILLAIRE2020)
        .chain(&HILLAIRE2020_VIEW)
        .copied()
        .collect();
    compose_hillaire2020(&modules, None)
}

/// The render shader of a Hillaire 2020 frame ([`render_source`] with Hillaire's view in
/// place of the 4D tables' and no terrain), to a buffer or a storage texture.
pub fn hillaire2020_render_source(output_format: Option<&str>) -> String {
    let output = if output_format.is_some() {
        OUTPUT_TEXTURE
    } else {
        OUTPUT_BUFFER
    };
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&HILLAIRE2020)
        .chain(&HILLAIRE2020_VIEW)
        .chain(&HILLAIRE2020_RENDER)
        .copied()
        .chain([output])
        .collect();
    compose_hillaire2020(&modules, output_format)
}

/// The 3D tables' WGSL for an engine's own shader: the prelude, the common modules, the 4D
/// tables' lookups (transmittance, irradiance, twilight), the 3D tables' mappings and filter
/// and the view functions (the names of [`sky_module`]'s `sky_ray`/`sky_radiance`,
/// `ground_ray`/`sky_radiance_to_point`, `ground_light`/`sun_and_sky_irradiance`, and the
/// `camera_slice` entry point that fills the per-view slices). The bindings are listed in
/// `shaders/elek3d/view.wgsl` and on [`crate::GpuElek3d`]. One sky method per shader: it
/// defines the same names as [`sky_module`].
pub fn elek3d_sky_module() -> String {
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&ELEK3D)
        .chain(&ELEK3D_VIEW)
        .copied()
        .collect();
    compose(&modules, None)
}

/// The render shader of a 3D-table frame ([`render_source`] with the 3D tables' view in
/// place of the 4D tables' and no terrain), to a buffer or a storage texture.
pub fn elek3d_render_source(output_format: Option<&str>) -> String {
    let output = if output_format.is_some() {
        OUTPUT_TEXTURE
    } else {
        OUTPUT_BUFFER
    };
    let modules: Vec<Module> = COMMON
        .iter()
        .chain(&BRUNETON4D)
        .chain(&ELEK3D)
        .chain(&ELEK3D_VIEW)
        .chain(&ELEK3D_RENDER)
        .copied()
        .chain([output])
        .collect();
    compose(&modules, output_format)
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::math::quadrature::GL4;
    use firmament::sky::bruneton4d::precompute::RAY_INTERVALS;

    #[test]
    fn prelude_holds_the_rust_constants() {
        let p = prelude() + &hillaire2020_prelude();
        assert!(p.contains(&format!("const RAY_INTERVALS: u32 = {RAY_INTERVALS}u;")));
        assert!(p.contains("const MAX_CHANNEL_GROUPS: u32 = 16u;"));
        let node = format!("{:?}", GL4.nodes[0] as f32);
        assert!(p.contains(&format!("const GL4_NODES = array<f32, 2>({node}, ")));
        // No module defines a constant the prelude defines.
        for m in COMMON
            .iter()
            .chain(&BRUNETON4D)
            .chain(&PRECOMPUTE)
            .chain(&RENDER)
            .chain(&BRUNETON4D_VIEW)
            .chain(&TERRAIN)
            .chain(&CLOUDS)
            .chain(&HILLAIRE2020)
            .chain(&HILLAIRE2020_VIEW)
            .chain(&HILLAIRE2020_RENDER)
            .chain(&ELEK3D)
            .chain(&ELEK3D_VIEW)
            .chain(&ELEK3D_RENDER)
            .chain(&[
                hillaire2020_passes::MULTIPLE_SCATTERING,
                hillaire2020_passes::IRRADIANCE,
            ])
            .chain(&TEMPORAL)
            .chain(&[OUTPUT_BUFFER, OUTPUT_TEXTURE])
        {
            for line in p.lines().filter(|l| l.starts_with("const ")) {
                let name = line.split([':', ' ']).nth(1).unwrap();
                assert!(
                    !m.source.contains(&format!("const {name}:"))
                        && !m.source.contains(&format!("const {name} ")),
                    "{} redefines {name}",
                    m.path
                );
            }
        }
    }

    /// Every composed source parses and validates as WGSL (naga, the front end wgpu uses),
    /// so a shader error fails without a GPU adapter.
    #[test]
    fn every_composed_source_validates() {
        use crate::shader::passes::*;
        let mut sources = vec![
            ("render (buffer)".to_string(), render_source(None)),
            (
                "render (rgba16float)".to_string(),
                render_source(Some("rgba16float")),
            ),
            ("sky module".to_string(), sky_module()),
            (
                "hillaire2020 render (buffer)".to_string(),
                hillaire2020_render_source(None),
            ),
            (
                "hillaire2020 render (rgba32float)".to_string(),
                hillaire2020_render_source(Some("rgba32float")),
            ),
            (
                "hillaire2020 sky module".to_string(),
                hillaire2020_sky_module(),
            ),
            (
                "elek3d render (buffer)".to_string(),
                elek3d_render_source(None),
            ),
            (
                "elek3d render (rgba16float)".to_string(),
                elek3d_render_source(Some("rgba16float")),
            ),
            ("elek3d sky module".to_string(), elek3d_sky_module()),
            ("temporal resolve".to_string(), temporal_source()),
            (
                "hillaire2020 transmittance (16 segments)".to_string(),
                hillaire2020_transmittance_source(16),
            ),
        ];
        for pass in [
            hillaire2020_passes::MULTIPLE_SCATTERING,
            hillaire2020_passes::IRRADIANCE,
        ] {
            sources.push((pass.path.to_string(), hillaire2020_pass_source(pass)));
        }
        for pass in [
            TRANSMITTANCE,
            DIRECT_IRRADIANCE,
            SINGLE_SCATTERING,
            PHASE_KERNELS,
            SCATTERING_DENSITY_FIELD,
            SCATTERING_DENSITY,
            INDIRECT_IRRADIANCE,
            MULTIPLE_SCATTERING,
            ORDER_SUMS,
            ORDER_TAIL_FACTORS,
            ORDER_TAIL,
        ] {
            sources.push((pass.path.to_string(), precompute_source(pass)));
        }
        for (name, source) in sources {
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
            let mut validator = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            );
            if let Err(e) = validator.validate(&module) {
                panic!("{name}: {}", e.emit_to_string(&source));
            }
        }
    }
}
