//! The render shader's per-frame uniforms, computed in f64 and rounded once: the `Frame`
//! of `shaders/render/frame.wgsl`, the `Lights` of `shaders/render/light.wgsl` and the
//! `SliceCoordinates` of `shaders/bruneton4d/view.wgsl`, with the layout constants the
//! prelude hands to WGSL. The first two serve every sky method on the device
//! ([`FrameSky`]: the 4D tables' [`GpuSky`], Hillaire 2020's `GpuHillaire`).

use firmament::math::sphere::safe_sqrt;
use firmament::math::Vec3;
use firmament::render::RenderSettings;
use firmament::scene::sky_lights::Background;
use firmament::scene::{DiskProfile, Light, Projection};
use firmament::sky::bruneton4d::params::scattering_uvwz;
use firmament::spectrum::MAX_CHANNELS;

use crate::bruneton4d::atmosphere::GROUP;
use crate::GpuSky;

/// vec4 per channel group in the view constants: three sRGB rows, the red-only Mie ratio.
pub const CHANNEL_STRIDE: usize = 4;
/// Offset of the linear sRGB rows of the colour matrix in a group's view constants.
pub const CHANNEL_SRGB: usize = 0;
/// Offset of the red-only Mie ratio factors in a group's view constants.
pub const CHANNEL_MIE_RATIO: usize = 3;
/// vec4 in the view constants (room for [`MAX_CHANNELS`]).
pub const CHANNEL_DATA_VEC4: usize = MAX_CHANNELS / GROUP * CHANNEL_STRIDE;
/// The most lights a GPU frame takes (each has its slice of the tables).
pub const MAX_LIGHTS: usize = 4;
/// vec4 per light and channel group: the disk's six rows (an emitting disk: its law ×
/// centre radiance; a lunar disk: the lit factor, the earthshine and the direction from the
/// moon to the sun in xyz), the scale and the irradiance.
pub const LIGHT_STRIDE: usize = 8;
/// Offsets in a light's group data.
pub const LIGHT_DISK: usize = 0;
pub const LIGHT_SCALE: usize = 6;
pub const LIGHT_IRRADIANCE: usize = 7;
/// vec4 of per-light data.
pub const LIGHTS_DATA_VEC4: usize = MAX_LIGHTS * (MAX_CHANNELS / GROUP) * LIGHT_STRIDE;
/// Tables in a slice entry: single Rayleigh, multiple, single Mie.
pub const SLICE_TABLES: usize = 3;

/// What the `Frame` and `Lights` uniforms read of a sky method on the device.
pub(crate) trait FrameSky {
    /// The ground's and the top's radii (m).
    fn radii_m(&self) -> (f64, f64);
    /// `View.mie_layout` of the 4D tables (0 for a method without one).
    fn mie_layout(&self) -> u32;
    /// Number of wavelengths.
    fn channel_count(&self) -> usize;
    /// The solar irradiance the method's tables were computed with (each light scales
    /// against it).
    fn solar_irradiance(&self) -> &[f64];
    /// White-balance factors (ColourMatrix::white_balance with the option on).
    fn balance(&self) -> [f64; 3];
}

impl FrameSky for GpuSky {
    fn radii_m(&self) -> (f64, f64) {
        (self.radii.bottom, self.radii.top)
    }
    fn mie_layout(&self) -> u32 {
        self.mie_layout
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

fn bits(x: f64) -> u32 {
    (x as f32).to_bits()
}

fn v4(v: Vec3, w: f64) -> [u32; 4] {
    [bits(v.x), bits(v.y), bits(v.z), bits(w)]
}

/// The `Frame` uniform.
pub(crate) struct FrameConstants {
    width: u32,
    height: u32,
    projection: u32,
    lights: u32,
    shadow_input: u32,
    mie_layout: u32,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    balance: [f64; 3],
    camera_r_km: f64,
    camera_rho_km: f64,
    camera_above_top_km: f64,
    pub(crate) inside: bool,
    tan_half_fov: f64,
    /// An upper bound on the pixels' footprints (rad; render::disk_edges).
    max_footprint_rad: f64,
    /// An interleaved frame's step, phase and depth flag ([`super::temporal::Interleave`];
    /// 0: every pixel, the mask in alpha).
    pub(crate) interleave: u32,
    /// The columns it draws ([`super::temporal::Interleave::columns_word`]; 0: all).
    pub(crate) interleave_columns: u32,
}

impl FrameConstants {
    pub(crate) fn new(
        sky: &impl FrameSky,
        lights: usize,
        shadow_input: bool,
        settings: &RenderSettings,
    ) -> FrameConstants {
        let camera = settings.camera;
        let (bottom, top) = sky.radii_m();
        let r = bottom + camera.altitude_m;
        let prepared = camera.prepare(bottom, settings.width, settings.height);
        let (forward, right, up) = prepared.basis();
        FrameConstants {
            width: settings.width as u32,
            height: settings.height as u32,
            projection: match camera.projection {
                Projection::Perspective => 0,
                Projection::Fisheye => 1,
                Projection::Equirect => 2,
                Projection::Cubemap => 3,
                Projection::Orbit => 4,
            },
            lights: lights as u32,
            shadow_input: u32::from(shadow_input),
            mie_layout: sky.mie_layout(),
            forward,
            right,
            up,
            balance: if settings.white_balance {
                sky.balance()
            } else {
                [1.0; 3]
            },
            camera_r_km: r * 1e-3,
            camera_rho_km: safe_sqrt(r * r - bottom * bottom) * 1e-3,
            camera_above_top_km: (r - top) * 1e-3,
            inside: r <= top,
            tan_half_fov: prepared.tan_half_fov(),
            max_footprint_rad: firmament::render::disk_edges::max_footprint_rad(
                &prepared,
                settings.width,
                settings.height,
            ),
            interleave: 0,
            interleave_columns: 0,
        }
    }

    /// The uniform's words for the band of `rows` rows from `first_row`.
    pub(crate) fn words(&self, first_row: usize, rows: usize) -> Vec<u32> {
        let mut out = vec![
            self.width,
            self.height,
            first_row as u32,
            rows as u32,
            self.projection,
            self.lights,
            self.shadow_input,
            self.mie_layout,
        ];
        out.extend(v4(self.forward, 0.0));
        out.extend(v4(self.right, 0.0));
        out.extend(v4(self.up, 0.0));
        out.extend(v4(Vec3::from_array(self.balance), 1.0));
        out.extend([
            bits(self.camera_r_km),
            bits(self.camera_rho_km),
            bits(self.camera_above_top_km),
            u32::from(self.inside),
            bits(self.tan_half_fov),
            bits(self.max_footprint_rad),
            self.interleave,
            self.interleave_columns,
        ]);
        out
    }
}

/// The `Lights` uniform: directions, disks and per-group data of up to [`MAX_LIGHTS`]
/// lights, scaled against the tables' solar irradiance, and the background glow.
pub(crate) fn light_words(
    sky: &impl FrameSky,
    lights: &[Light],
    background: Option<&Background>,
) -> Vec<u32> {
    let groups = MAX_CHANNELS / GROUP;
    let mut direction = vec![0u32; MAX_LIGHTS * 4];
    let mut disk = vec![0u32; MAX_LIGHTS * 4];
    let mut data = vec![0.0f32; LIGHTS_DATA_VEC4 * 4];
    for (l, light) in lights.iter().enumerate() {
        direction[l * 4..l * 4 + 4].copy_from_slice(&v4(light.direction, light.angular_radius_rad));
        disk[l * 4] = u32::from(light.visible_disk);
        disk[l * 4 + 1] = bits(light.angular_radius_rad.sin());
        disk[l * 4 + 2] = u32::from(matches!(light.disk, DiskProfile::Lunar(_)));
        let scale = light.scale_against(sky.solar_irradiance());
        for k in 0..sky.channel_count() {
            let (group, lane) = (k / GROUP, k % GROUP);
            let mut set = |row: usize, v: f64| {
                data[((l * groups + group) * LIGHT_STRIDE + row) * 4 + lane] = v as f32;
            };
            match &light.disk {
                DiskProfile::Emitting {
                    centre_radiance,
                    law,
                } => {
                    for (j, a) in law[k].iter().enumerate() {
                        set(LIGHT_DISK + j, centre_radiance[k] * a);
                    }
                }
                DiskProfile::Lunar(moon) => {
                    set(LIGHT_DISK, moon.lit[k]);
                    set(LIGHT_DISK + 1, moon.earthshine[k]);
                }
            }
            set(LIGHT_SCALE, scale[k]);
            set(LIGHT_IRRADIANCE, light.irradiance[k]);
        }
        if let DiskProfile::Lunar(moon) = &light.disk {
            // The direction to the sun, in channel group 0's third disk row.
            let s = moon.sun_from_moon;
            let at = (l * groups * LIGHT_STRIDE + LIGHT_DISK + 2) * 4;
            data[at..at + 3].copy_from_slice(&[s.x as f32, s.y as f32, s.z as f32]);
        }
    }
    // The background: (on, the layer's share, the layer's radius in km, 0), then its
    // zenith radiance per channel group.
    let mut glow = vec![0.0f32; 4 + groups * 4];
    if let Some(b) = background {
        glow[0] = 1.0;
        glow[1] = b.layer_fraction as f32;
        glow[2] = (b.layer_radius_m * 1e-3) as f32;
        for (k, v) in b
            .zenith_radiance
            .iter()
            .enumerate()
            .take(sky.channel_count())
        {
            glow[4 + k] = *v as f32;
        }
    }
    direction
        .into_iter()
        .chain(disk)
        .chain(data.into_iter().map(f32::to_bits))
        .chain(glow.into_iter().map(f32::to_bits))
        .collect()
}

/// The `SliceCoordinates` uniform: each light's (u_μs, u_r) at the observer (the CPU view's
/// slice, `scattering_uvwz` at μ_s = light·up), the lights and the Mie layout.
pub(crate) fn slice_words(sky: &GpuSky, lights: &[Light], settings: &RenderSettings) -> Vec<u32> {
    let r = sky.radii.bottom + settings.camera.altitude_m;
    let mut at = vec![0u32; MAX_LIGHTS * 4];
    for (l, light) in lights.iter().enumerate() {
        let uvwz = scattering_uvwz(
            &sky.radii,
            &sky.sizes,
            r,
            0.0,
            light.direction.z.clamp(-1.0, 1.0),
            0.0,
            false,
        );
        at[l * 4] = bits(uvwz[1]);
        at[l * 4 + 1] = bits(uvwz[3]);
    }
    at.extend([lights.len() as u32, sky.mie_layout, 0, 0]);
    at
}
