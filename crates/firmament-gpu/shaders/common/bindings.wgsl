// The bindings every shader has (slots 0–2): the atmosphere, the pass parameters and the
// per-wavelength data, and the accessors of that data (packed by
// firmament_gpu::bruneton4d::atmosphere).

@group(0) @binding(0) var<uniform> atm: Atmosphere;
@group(0) @binding(1) var<uniform> pass_params: PassParams;
// Per-wavelength data (vec4 per channel group), constituents, layers, tabulated phases.
@group(0) @binding(2) var<storage, read> data: array<vec4<f32>>;

// Flat invocation index of a 2D dispatch over 64-wide workgroups.
fn invocation_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WORKGROUP;
}

fn solar_irradiance(k: u32) -> vec4<f32> {
    return data[atm.solar_offset + k];
}

fn ground_albedo(k: u32) -> vec4<f32> {
    return data[atm.albedo_offset + k];
}

// Per constituent: (first layer, layer count, group or −1, 0), then its scattering and
// extinction coefficients (km⁻¹) per channel group.
fn constituent_base(c: u32) -> u32 {
    return atm.constituent_offset + c * (1u + 2u * atm.groups);
}

fn constituent_scattering(c: u32, k: u32) -> vec4<f32> {
    return data[constituent_base(c) + 1u + k];
}

fn constituent_extinction(c: u32, k: u32) -> vec4<f32> {
    return data[constituent_base(c) + 1u + atm.groups + k];
}
