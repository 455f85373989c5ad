// Lights (firmament::scene::light): direction, angular radius, irradiance at the top of the
// atmosphere and the radiance across the disk, per channel group. Filled by
// firmament_gpu::render (the field order of LightConstants).

struct Lights {
    // Per light: the unit direction towards it (xyz) and its angular radius (w, rad).
    direction: array<vec4<f32>, MAX_LIGHTS>,
    // Per light: (whether the disk is drawn, sin of the angular radius as bits, 0, 0).
    disk: array<vec4<u32>, MAX_LIGHTS>,
    // Per light and channel group, LIGHT_STRIDE vec4 at (light·MAX_CHANNEL_GROUPS + k)·
    // LIGHT_STRIDE: the centre radiance times the disk law's six coefficients
    // (DiskProfile, LIGHT_DISK..), the light's irradiance over the tables' solar irradiance
    // (LIGHT_SCALE) and its irradiance (LIGHT_IRRADIANCE, W·m⁻²·nm⁻¹).
    data: array<vec4<f32>, LIGHTS_DATA_VEC4>,
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

fn light_scale(light: u32, k: u32) -> vec4<f32> {
    return light_data(light, k, LIGHT_SCALE);
}

fn light_irradiance(light: u32, k: u32) -> vec4<f32> {
    return light_data(light, k, LIGHT_IRRADIANCE);
}
