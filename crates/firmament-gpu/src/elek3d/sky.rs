//! The 3D tables ready to render on the GPU ([`GpuElek3d`]): the CPU's tables uploaded in
//! its texel order, the mappings' constants, the per-channel constants the frame reads, and
//! the per-view cache (one slice of the tables per light, rewritten by every frame). The
//! WGSL twin is `shaders/elek3d/view.wgsl`; an engine binds these buffers at its slots and
//! composes [`crate::shader::elek3d_sky_module`] into its own shader.

use firmament::render::RenderSettings;
use firmament::scene::Light;
use firmament::sky::elek3d::params::SUN_ZENITH_T_MAX;
use firmament::sky::elek3d::{Elek3d, Elek3dConfig, Params, SunZenithMapping};

use crate::bruneton4d::atmosphere::{self, groups, GROUP};
use crate::device::{check_buffers, scoped};
use crate::passes::{init, storage};
use crate::render::frame::{
    FrameSky, CHANNEL_DATA_VEC4, CHANNEL_SRGB, CHANNEL_STRIDE, MAX_LIGHTS, SLICE_TABLES,
};
use crate::{GpuContext, GpuError};

/// The 3D tables' buffers on the device, at the bindings of `shaders/elek3d/`.
pub struct GpuElek3dTables {
    /// 0: the `Atmosphere` uniform (its transmittance and irradiance sizes are the method's,
    /// its scattering sizes the 3D table's with one ν texel: `Elek3dConfig::table_sizes`).
    pub atmosphere: wgpu::Buffer,
    /// 2: the per-wavelength data.
    pub data: wgpu::Buffer,
    /// 3: τ(r, μ) to the top (`Elek3d::optical_depth`).
    pub optical_depth: wgpu::Buffer,
    /// 4: the sky's irradiance on a horizontal surface (`Elek3d::irradiance`).
    pub irradiance: wgpu::Buffer,
    /// 5: phase-free single Rayleigh (`Elek3d::single_rayleigh`).
    pub single_rayleigh: wgpu::Buffer,
    /// 6: phase-free single Mie (`Elek3d::single_mie`).
    pub single_mie: wgpu::Buffer,
    /// 7: the multiple scattering (`Elek3d::multiple`).
    pub multiple: wgpu::Buffer,
    /// 8: the `Elek3dParams` uniform (`shaders/elek3d/params.wgsl`).
    pub params: wgpu::Buffer,
}

/// The 3D tables on the device, ready to render ([`crate::GpuElek3dRenderer`]). Bindings
/// (`shaders/elek3d/`): 0 atmosphere, 2 data, 3 optical depth, 4 irradiance, 5 single
/// Rayleigh, 6 single Mie, 7 multiple, 8 the mappings, 11 view constants, 13 the slices,
/// 15 their coordinates ([`GpuElek3d::slice_coordinates`]). Tables are storage buffers of
/// `vec4<f32>`: channel group k of texel i at i·groups + k, texels in the CPU's order.
pub struct GpuElek3d {
    tables: GpuElek3dTables,
    /// Per channel group: the linear sRGB rows of the colour matrix (binding 11).
    view_constants: wgpu::Buffer,
    /// The slice of each light (binding 13), written before every frame.
    slice: wgpu::Buffer,
    params: Params,
    config: Elek3dConfig,
    channels: usize,
    radii_m: (f64, f64),
    solar_irradiance: Vec<f64>,
    balance: [f64; 3],
}

impl std::fmt::Debug for GpuElek3d {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuElek3d")
            .field("channels", &self.channels)
            .field("config", &self.config)
            .finish()
    }
}

/// Bytes of the slices: per light, the three tables per view-zenith texel and channel group.
fn slice_bytes(config: &Elek3dConfig, groups: usize) -> u64 {
    (MAX_LIGHTS * config.view_zenith * SLICE_TABLES * groups * GROUP * 4) as u64
}

/// Channels padded to groups of four per texel, as the shaders index them.
fn pad_channels(data: &[f32], channels: usize, groups: usize) -> Vec<f32> {
    let texels = data.len() / channels.max(1);
    let mut out = vec![0.0f32; texels * groups * GROUP];
    for (t, texel) in data.chunks_exact(channels).enumerate() {
        out[t * groups * GROUP..t * groups * GROUP + channels].copy_from_slice(texel);
    }
    out
}

/// The `Elek3dParams` uniform of `shaders/elek3d/params.wgsl` (field order), from the CPU's
/// mappings in f64 rounded once.
pub(crate) fn params_words(params: &Params, config: &Elek3dConfig) -> Vec<u32> {
    let f = |x: f64| (x as f32).to_bits();
    let tan_t_max = SUN_ZENITH_T_MAX.tan();
    let t_min = (params.mu_s_min * tan_t_max).atan();
    vec![
        params.nh as u32,
        params.nmu as u32,
        params.nmu_s as u32,
        match config.sun_zenith_mapping {
            SunZenithMapping::Yusov => 0,
            SunZenithMapping::Tables4d => 1,
        },
        f(params.height_m() * 1e-3),
        f(params.height_power),
        f(params.view_zenith_power),
        f(t_min),
        f(SUN_ZENITH_T_MAX),
        f(tan_t_max),
        0,
        0,
    ]
}

impl GpuElek3d {
    /// Upload `sky`'s tables (computed on the CPU) and mappings. Refuses more wavelengths
    /// than the renderers handle and tables larger than the device binds.
    pub fn from_sky(ctx: &GpuContext, sky: &Elek3d) -> Result<GpuElek3d, GpuError> {
        let model = &sky.model;
        let n = sky.channels();
        firmament::spectrum::check_channels(n, "rendering")?;
        let g = groups(n);
        let config = sky.config;
        let optical_depth = pad_channels(&sky.optical_depth.data, n, g);
        let irradiance = pad_channels(&sky.irradiance.data, n, g);
        let single_rayleigh = pad_channels(&sky.single_rayleigh.data, n, g);
        let single_mie = pad_channels(&sky.single_mie.data, n, g);
        let multiple = pad_channels(&sky.multiple.data, n, g);
        let bytes = |v: &[f32]| (v.len() * 4) as u64;
        check_buffers(
            ctx,
            &[
                ("single Rayleigh table", bytes(&single_rayleigh)),
                ("single Mie table", bytes(&single_mie)),
                ("multiple scattering table", bytes(&multiple)),
                ("camera slice", slice_bytes(&config, g)),
                ("transmittance table", bytes(&optical_depth)),
                ("irradiance table", bytes(&irradiance)),
            ],
        )?;
        let params = sky.params();
        let packed = atmosphere::pack(model, &config.table_sizes());
        let colour = model.colour_matrix();
        // The uniform's full size (the shader declares a fixed-size array); lanes of
        // channel k in group k/4.
        let mut constants = vec![0.0f32; CHANNEL_DATA_VEC4 * 4];
        for k in 0..n {
            let (group, lane) = (k / GROUP, k % GROUP);
            let mut unit = vec![0.0f64; n];
            unit[k] = 1.0;
            for (c, v) in colour.to_srgb(&unit).iter().enumerate() {
                constants[(group * CHANNEL_STRIDE + CHANNEL_SRGB + c) * 4 + lane] = *v as f32;
            }
        }
        let device = ctx.device();
        scoped(ctx, "uploading the 3D tables", || {
            let usage = wgpu::BufferUsages::STORAGE;
            let f = |label: &str, v: &[f32]| init(device, label, bytemuck::cast_slice(v), usage);
            let uniform = |label: &str, words: &[u32]| {
                init(
                    device,
                    label,
                    bytemuck::cast_slice(words),
                    crate::passes::UNIFORM_USAGE,
                )
            };
            let tables = GpuElek3dTables {
                atmosphere: uniform("atmosphere", &packed.uniform),
                data: f("atmosphere data", &packed.data),
                optical_depth: f("optical depth", &optical_depth),
                irradiance: f("sky irradiance", &irradiance),
                single_rayleigh: f("single rayleigh (3D)", &single_rayleigh),
                single_mie: f("single mie (3D)", &single_mie),
                multiple: f("multiple scattering (3D)", &multiple),
                params: uniform("3D table mappings", &params_words(&params, &config)),
            };
            Ok(GpuElek3d {
                tables,
                view_constants: init(
                    device,
                    "view constants",
                    bytemuck::cast_slice(&constants),
                    crate::passes::UNIFORM_USAGE,
                ),
                slice: storage(device, "camera slice (3D)", slice_bytes(&config, g)),
                params,
                config,
                channels: n,
                radii_m: (model.bottom_radius_m, model.top_radius_m),
                solar_irradiance: model.solar_irradiance.clone(),
                balance: colour.white_balance(&model.solar_irradiance, true),
            })
        })
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The sizes and counts the tables were built with.
    pub fn config(&self) -> &Elek3dConfig {
        &self.config
    }

    /// The tables on the device.
    pub fn tables(&self) -> &GpuElek3dTables {
        &self.tables
    }

    /// The per-channel constants (binding 11).
    pub fn view_constants(&self) -> &wgpu::Buffer {
        &self.view_constants
    }

    /// The slices (binding 13), written by the `camera_slice` entry point.
    pub fn slice(&self) -> &wgpu::Buffer {
        &self.slice
    }

    /// The `SliceCoordinates` uniform (binding 15) of an observer `altitude_m` above the
    /// ground under `lights` (at most `MAX_LIGHTS`): each light's (u_h, u_μs) at the
    /// observer, the CPU view's (`Params` in f64 at μ_s = light·up), and the count.
    pub fn slice_coordinates(&self, lights: &[Light], altitude_m: f64) -> Vec<u32> {
        let bits = |x: f64| (x as f32).to_bits();
        let r = self.radii_m.0 + altitude_m;
        let mut words = vec![0u32; MAX_LIGHTS * 4];
        for (l, light) in lights.iter().take(MAX_LIGHTS).enumerate() {
            // The observer is on the +z axis: μ_s = light·up = light.z.
            let mu_s = light.direction.z.clamp(-1.0, 1.0);
            words[l * 4] = bits(self.params.u_h(r));
            words[l * 4 + 1] = bits(self.params.u_mu_s(mu_s));
        }
        words.extend([lights.len().min(MAX_LIGHTS) as u32, 0, 0, 0]);
        words
    }

    /// [`GpuElek3d::slice_coordinates`] for a frame's camera.
    pub(crate) fn slice_words(&self, lights: &[Light], settings: &RenderSettings) -> Vec<u32> {
        self.slice_coordinates(lights, settings.camera.altitude_m)
    }
}

impl FrameSky for GpuElek3d {
    fn radii_m(&self) -> (f64, f64) {
        self.radii_m
    }
    fn mie_layout(&self) -> u32 {
        0
    }
    fn channel_count(&self) -> usize {
        self.channels
    }
    fn solar_irradiance(&self) -> &[f64] {
        &self.solar_irradiance
    }
    fn balance(&self) -> [f64; 3] {
        self.balance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::atmosphere::Atmosphere;
    use firmament::spectrum::Wavelengths;

    /// The size naga gives the WGSL struct `name` of the 3D tables' sky module.
    fn wgsl_struct_size(name: &str) -> u32 {
        let source = crate::shader::elek3d_sky_module();
        let module = naga::front::wgsl::parse_str(&source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (handle, _) = (module.types.iter())
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name}"));
        layouter[handle].size
    }

    #[test]
    fn uniforms_have_the_shader_struct_sizes() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let config = Elek3dConfig::small();
        let words = params_words(&Params::new(&model, &config), &config);
        assert_eq!(4 * words.len() as u32, wgsl_struct_size("Elek3dParams"));
        assert_eq!(
            (16 * MAX_LIGHTS + 16) as u32,
            wgsl_struct_size("SliceCoordinates")
        );
    }

    #[test]
    fn channels_are_padded_to_groups_of_four() {
        let data = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0];
        let padded = pad_channels(&data, 5, 2);
        assert_eq!(padded.len(), 16);
        assert_eq!(&padded[..8], &[1.0, 2.0, 3.0, 4.0, 5.0, 0.0, 0.0, 0.0]);
        assert_eq!(&padded[8..], &[6.0, 7.0, 8.0, 9.0, 10.0, 0.0, 0.0, 0.0]);
    }
}
