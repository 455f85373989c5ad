// Density profiles and the coefficients of the atmosphere's constituents at an altitude
// (firmament::medium::profile, firmament::atmosphere::groups): per layer
// exp_term·exp(−h/H) + a·h + c, clamped to ≥ 0.

fn layer_density(l: u32, altitude_km: f32) -> f32 {
    let a = data[l];
    let b = data[l + 1u];
    var e = 0.0;
    if (a.y != 0.0) {
        e = a.y * exp(-altitude_km * a.z);
    }
    return max(e + a.w * altitude_km + b.x, 0.0);
}

// Dimensionless density of constituent c at `altitude` km above the ground.
fn constituent_density(c: u32, altitude_km: f32) -> f32 {
    let info = data[constituent_base(c)];
    let first = atm.layer_offset + 2u * u32(info.x);
    let count = u32(info.y);
    var base = 0.0;
    for (var i = 0u; i < count; i++) {
        let l = first + 2u * i;
        let width = data[l].x;
        if (i + 1u == count || altitude_km < base + width) {
            return layer_density(l, altitude_km);
        }
        base += width;
    }
    return 0.0;
}

// Scattering coefficient (km⁻¹) of group g (0 molecules, 1 aerosols) at `altitude` km.
fn group_scattering(g: u32, altitude_km: f32, k: u32) -> vec4<f32> {
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < atm.constituents; c++) {
        let info = data[constituent_base(c)];
        if (i32(info.z) == i32(g)) {
            let density = constituent_density(c, altitude_km);
            if (density > 0.0) {
                out += density * constituent_scattering(c, k);
            }
        }
    }
    return out;
}

// Extinction coefficient (km⁻¹) of the whole atmosphere at `altitude` km.
fn extinction(altitude_km: f32, k: u32) -> vec4<f32> {
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < atm.constituents; c++) {
        let density = constituent_density(c, altitude_km);
        if (density > 0.0) {
            out += density * constituent_extinction(c, k);
        }
    }
    return out;
}
