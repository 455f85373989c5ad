// The terrain's bindings (firmament_gpu::terrain packs them): its uniform and one storage
// buffer of f32 holding every field on its grid (heights, their max-mip pyramid, the sky
// visibility, each light's shadow heights and pyramids) and the observer's air volume.

struct Terrain {
    // Vertices along x′ and y′, pyramid levels, TERRAIN_* flags.
    nx: u32,
    ny: u32,
    level_count: u32,
    flags: u32,
    // Plane coordinates (m) of vertex (0, 0) and the grid's x′ axis (cos θ, sin θ) from east.
    origin_u: f32,
    origin_v: f32,
    axis: vec2<f32>,
    // Vertex spacing, the planet's sphere under the terrain (its radius), the highest
    // height, and the observer's height above that sphere (m).
    spacing_m: f32,
    radius_m: f32,
    max_height_m: f32,
    observer_height_m: f32,
    // Offsets in terrain_data of the heights, their pyramid and the sky visibility; lights
    // with a shadow field.
    heights: u32,
    pyramid: u32,
    visibility: u32,
    lights: u32,
    // The visibility's grid (same origin and axis): vertices per side, spacing (m); the air
    // volume's offset (NONE without).
    visibility_nx: u32,
    visibility_ny: u32,
    visibility_spacing_m: f32,
    air: u32,
    // Materials: snow line, tree line (m); the tables' ground above the sphere (m); the
    // shadow fields' edge margin (in cells' spacing, shadow::EDGE_MARGIN).
    zones: vec4<f32>,
    // The horizons' offset (HORIZON_AZIMUTHS per visibility vertex, rad; NONE without) and
    // the sky domes' elevation nodes.
    horizons: u32,
    dome_nodes: u32,
    pad0: u32,
    pad1: u32,
    // Per light: offsets of its shadow heights S, their pyramid, the pyramid of the raise
    // S − H and of −S (NONE where the light has no field).
    shadow: array<vec4<u32>, MAX_LIGHTS>,
    // Per light: the offsets of its signed clearance (ShadowField::clearance) and of its sky
    // dome (render::sky_dome::SkyDome: the moments, then the open plane's irradiance).
    per_light: array<vec4<u32>, MAX_LIGHTS>,
    // Per pyramid level: cells along x′, along y′, offset from a pyramid's start.
    levels: array<vec4<u32>, MAX_PYRAMID_LEVELS>,
    // Per channel group: the albedo of snow, rock, grass, forest (the uniform albedo in the
    // snow row with TERRAIN_UNIFORM_ALBEDO).
    albedo: array<vec4<f32>, TERRAIN_ALBEDO_VEC4>,
}

@group(0) @binding(17) var<storage, read> terrain_data: array<f32>;
@group(0) @binding(18) var<uniform> terrain: Terrain;

// No field at this offset.
const NONE: u32 = 0xffffffffu;
