// Lights (firmament::scene::light): direction, angular radius, irradiance at the top of the
// atmosphere and the radiance across the disk, per channel group. Filled by
// firmament_gpu::render (the field order of LightConstants).

struct Lights {
    // Per light: the unit direction towards it (xyz) and its angular radius (w, rad).
    direction: array<vec4<f32>, MAX_LIGHTS>,
    // Per light: (whether the disk is drawn, sin of the angular radius as bits, 1 for a
    // lunar disk, 0).
    disk: array<vec4<u32>, MAX_LIGHTS>,
    // Per light and channel group, LIGHT_STRIDE vec4 at (light·MAX_CHANNEL_GROUPS + k)·
    // LIGHT_STRIDE: the disk's six rows from LIGHT_DISK (DiskProfile::Emitting: the centre
    // radiance times the law's coefficients; DiskProfile::Lunar: the lit factor, the
    // earthshine, the unit vector from the moon to the sun in xyz), the light's irradiance
    // over the tables' solar irradiance (LIGHT_SCALE) and its irradiance (LIGHT_IRRADIANCE,
    // W·m⁻²·nm⁻¹).
    data: array<vec4<f32>, LIGHTS_DATA_VEC4>,
    // The glow from beyond the air (scene::sky_lights::Background): (on, the emitting
    // layer's share, its radius in km, 0), then the zenith radiance per channel group.
    background: vec4<f32>,
    background_radiance: array<vec4<f32>, MAX_CHANNEL_GROUPS>,
}

@group(0) @binding(14) var<uniform> lights: Lights;

fn light_data(light: u32, k: u32, row: u32) -> vec4<f32> {
    return lights.data[(light * MAX_CHANNEL_GROUPS + k) * LIGHT_STRIDE + row];
}

// The light as the sky method's view needs it (ViewLight); light l owns slice l.
fn view_light(light: u32) -> ViewLight {
    var l: ViewLight;
    l.direction = lights.direction[light].xyz;
    l.angular_radius = lights.direction[light].w;
    l.sin_angular_radius = bitcast<f32>(lights.disk[light].y);
    l.slice = light;
    return l;
}

// Light::add_disk_radiance: whether `dir` falls in the drawn disk, and μ on the emitting
// sphere there, x = sin(angle)/sin(α) from the cross product (accurate near the centre,
// where acos of a cosine near 1 is not in f32).
struct Disk {
    inside: bool,
    mu: f32,
}

fn light_disk(light: u32, dir: vec3<f32>) -> Disk {
    var disk: Disk;
    let l = lights.direction[light].xyz;
    let sin_alpha = bitcast<f32>(lights.disk[light].y);
    let sin_angle = length(cross(dir, l));
    disk.inside = lights.disk[light].x != 0u && dot(dir, l) > 0.0 && sin_angle < sin_alpha;
    let x = sin_angle / sin_alpha;
    disk.mu = safe_sqrt(1.0 - x * x);
    return disk;
}

// Centre radiance × max(Σ a_j μ^j, 0) for channel group k.
fn disk_radiance(light: u32, mu: f32, k: u32) -> vec4<f32> {
    var s = vec4<f32>(0.0);
    var p = 1.0;
    for (var j = 0u; j < 6u; j++) {
        s += light_data(light, k, LIGHT_DISK + j) * p;
        p *= mu;
    }
    return max(s, vec4<f32>(0.0));
}

// LunarDisk::add_radiance (scene/lunar.rs) before the transmittance: the surface normal where `dir` meets a
// unit-distance sphere of radius sin α, then lit × μ₀/(μ₀ + μ) + earthshine on the lit
// part, earthshine on the dark part.
fn lunar_disk_radiance(light: u32, dir: vec3<f32>, k: u32) -> vec4<f32> {
    let c = lights.direction[light].xyz;
    let r = bitcast<f32>(lights.disk[light].y);
    let off = cross(dir, c);
    let disc = r * r - dot(off, off);
    if (disc < 0.0) {
        return vec4<f32>(0.0);
    }
    let t = dot(dir, c) - sqrt(disc);
    let normal = normalize((dir * t - c) / r);
    let to_sun = light_data(light, 0u, LIGHT_DISK + 2u).xyz;
    let mu0 = dot(normal, to_sun);
    let mu = max(dot(normal, -dir), 0.0);
    let earthshine = light_data(light, k, LIGHT_DISK + 1u);
    if (mu0 > 0.0) {
        return light_data(light, k, LIGHT_DISK) * (mu0 / (mu0 + mu)) + earthshine;
    }
    return earthshine;
}

// The disk's radiance along `dir` for channel group k (inside the disk).
fn light_disk_radiance(light: u32, disk: Disk, dir: vec3<f32>, k: u32) -> vec4<f32> {
    if (lights.disk[light].z != 0u) {
        return lunar_disk_radiance(light, dir, k);
    }
    return disk_radiance(light, disk.mu, k);
}

fn light_scale(light: u32, k: u32) -> vec4<f32> {
    return light_data(light, k, LIGHT_SCALE);
}

fn light_irradiance(light: u32, k: u32) -> vec4<f32> {
    return light_data(light, k, LIGHT_IRRADIANCE);
}

// Background::factor (scene/sky_lights.rs): the van Rhijn factor for the layer's share, 1
// for the rest, seen from radius r_km with the cosine of the zenith angle cos_z.
fn background_factor(r_km: f32, cos_z: f32) -> f32 {
    let x = min(r_km / lights.background.z, 1.0);
    let van_rhijn = 1.0 / sqrt(max(1.0 - x * x * (1.0 - cos_z * cos_z), 1e-6));
    return lights.background.y * van_rhijn + (1.0 - lights.background.y);
}
