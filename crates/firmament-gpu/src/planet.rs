//! The planet's surface map on the device: [`firmament::scene::planet::PlanetSurface`]'s
//! twin for GPU frames (`shaders/render/planet.wgsl`). The map's albedo is a weighted sum
//! of five spectra ([`PlanetSurface::weights`], [`PlanetSurface::basis`]): the weights are
//! baked once on the CPU into an equirectangular `Rgba16Float` texture
//! ([`PlanetSurface::weight_texture`]: an image map at its own size, a procedural one at
//! 2048 × 1024, cached on disk by `PlanetSurface::cached_weight_texture`) and read
//! bilinearly per pixel; the spectra, the observer's frame on the
//! planet and the sea's glint (Cox & Munk 1954) travel in a uniform. What this
//! approximates: the procedural continents are evaluated at the texels' centres and
//! interpolated between them (coasts within a texel, 20 km on Earth, blend sea and land,
//! and the glint is weighted by the sea's share), measured in docs/accuracy.md.

use firmament::math::Vec3;
use firmament::scene::planet::{PlanetSurface, BASIS, SEA_WATER_INDEX};
use firmament::spectrum::MAX_CHANNELS;

use crate::bruneton4d::atmosphere::GROUP;
use crate::device::scoped;
use crate::{GpuContext, GpuError};

/// vec4 of basis spectra in the `Planet` uniform: [`BASIS`] per channel group.
pub const PLANET_BASIS_VEC4: usize = BASIS * MAX_CHANNELS / GROUP;
/// Words of the `Planet` uniform: a header, the glint, the frame (three vec4), the basis.
const UNIFORM_WORDS: usize = 4 * (5 + PLANET_BASIS_VEC4);

/// A planet's surface map on the device.
#[derive(Debug)]
pub struct GpuPlanet {
    view: wgpu::TextureView,
    words: Vec<u32>,
    /// The weight texture's size (texels).
    pub width: u32,
    pub height: u32,
}

fn bits(x: f64) -> u32 {
    (x as f32).to_bits()
}

fn v4(v: Vec3) -> [u32; 4] {
    [bits(v.x), bits(v.y), bits(v.z), 0]
}

impl GpuPlanet {
    /// Bake `planet`'s weights at its [`PlanetSurface::texture_size`] and upload them with
    /// its spectra (at the wavelengths it was made for: the sky's). Refuses a map larger
    /// than the device's 2D textures.
    pub fn new(ctx: &GpuContext, planet: &PlanetSurface) -> Result<GpuPlanet, GpuError> {
        let (w, h) = planet.texture_size();
        GpuPlanet::from_texels(ctx, planet, &planet.weight_texture(w, h))
    }

    /// [`GpuPlanet::new`] with the weights already baked (`texels`, as
    /// [`PlanetSurface::weight_texture`] at [`PlanetSurface::texture_size`] gives them, or
    /// [`PlanetSurface::cached_weight_texture`]).
    pub fn from_texels(
        ctx: &GpuContext,
        planet: &PlanetSurface,
        texels: &[[f32; 4]],
    ) -> Result<GpuPlanet, GpuError> {
        let (w, h) = planet.texture_size();
        assert_eq!(texels.len(), w * h, "a texel per grid point");
        let limit = ctx.limits().max_texture_dimension_2d as usize;
        if w > limit || h > limit {
            return Err(GpuError::Limit {
                what: "the planet's surface map".into(),
                needed: format!("a {w}×{h} texture"),
                limit: format!("{limit} texels a side"),
                limit_name: "max_texture_dimension_2d",
                adapter: ctx.adapter_name().to_string(),
            });
        }
        let halves: Vec<u16> = texels
            .iter()
            .flat_map(|t| t.map(|v| half::f16::from_f32(v).to_bits()))
            .collect();
        let device = ctx.device();
        let view = scoped(ctx, "uploading the planet's surface map", || {
            let size = wgpu::Extent3d {
                width: w as u32,
                height: h as u32,
                depth_or_array_layers: 1,
            };
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("planet surface weights"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            ctx.queue().write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(&halves),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(8 * w as u32),
                    rows_per_image: Some(h as u32),
                },
                size,
            );
            Ok(texture.create_view(&Default::default()))
        })?;
        // Header: on, the fifth weight is the rest (procedural), width, height.
        let mut words = vec![1, u32::from(planet.sea_is_first()), w as u32, h as u32];
        // The glint: σ² (0: none), the sea's refractive index.
        let sigma2 = match planet.slope_variance {
            Some(s2) if planet.sea_is_first() => s2,
            _ => 0.0,
        };
        words.extend([bits(sigma2), bits(SEA_WATER_INDEX), 0, 0]);
        for v in planet.frame() {
            words.extend(v4(v));
        }
        let mut basis = vec![0.0f32; 4 * PLANET_BASIS_VEC4];
        for (j, spectrum) in planet.basis().iter().enumerate() {
            for (c, &v) in spectrum.iter().enumerate().take(MAX_CHANNELS) {
                basis[(BASIS * (c / GROUP) + j) * 4 + c % GROUP] = v as f32;
            }
        }
        words.extend(basis.iter().map(|v| v.to_bits()));
        assert_eq!(words.len(), UNIFORM_WORDS, "the Planet uniform's layout");
        Ok(GpuPlanet {
            view,
            words,
            width: w as u32,
            height: h as u32,
        })
    }

    /// Put the observer elsewhere on the same map: `frame` as
    /// [`PlanetSurface::frame`] gives it (the texture is kept).
    pub fn set_frame(&mut self, frame: [Vec3; 3]) {
        for (i, v) in frame.into_iter().enumerate() {
            self.words[8 + 4 * i..12 + 4 * i].copy_from_slice(&v4(v));
        }
    }

    /// The `Planet` uniform's words.
    pub(crate) fn uniform_words(&self) -> &[u32] {
        &self.words
    }

    /// The weight texture (binding 25).
    pub(crate) fn view(&self) -> &wgpu::TextureView {
        &self.view
    }
}

/// The `Planet` uniform without a map (the uniform ground's albedo).
pub(crate) fn no_planet_words() -> Vec<u32> {
    vec![0; UNIFORM_WORDS]
}

/// What a render pass binds at 25 without a map: a 1×1 texture.
pub(crate) struct NoPlanet {
    view: wgpu::TextureView,
}

impl NoPlanet {
    pub(crate) fn new(device: &wgpu::Device) -> NoPlanet {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("no planet map"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        NoPlanet {
            view: texture.create_view(&Default::default()),
        }
    }

    /// The texture and a new `Planet` uniform buffer for bindings 25 and 26: `planet`'s, or
    /// this empty one's.
    pub(crate) fn or<'a>(
        &'a self,
        device: &wgpu::Device,
        planet: Option<&'a GpuPlanet>,
    ) -> (&'a wgpu::TextureView, wgpu::Buffer) {
        let words = match planet {
            Some(p) => p.uniform_words().to_vec(),
            None => no_planet_words(),
        };
        let buffer = crate::passes::init(
            device,
            "planet",
            bytemuck::cast_slice(&words),
            crate::passes::UNIFORM_USAGE,
        );
        (planet.map_or(&self.view, |p| p.view()), buffer)
    }
}
