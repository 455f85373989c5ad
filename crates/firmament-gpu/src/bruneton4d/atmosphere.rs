//! The atmosphere as the shaders read it: the `Atmosphere` uniform of
//! `shaders/common/types.wgsl` (same field order) and a storage buffer of vec4 with
//! per-wavelength data (channel groups of 4), constituents, density layers and tabulated
//! phase functions (`shaders/common/bindings.wgsl`). Lengths in km, coefficients in km⁻¹,
//! computed in f64 and rounded once.

use firmament::atmosphere::groups::{AEROSOLS, MOLECULES};
use firmament::atmosphere::{Model, ScatteringGroups};
use firmament::math::sphere::distance_to_top_atmosphere_boundary;
use firmament::medium::PhaseFunction;
use firmament::sky::bruneton4d::precompute::ray_grading::{RayGrading, RAY_PAIRS};
use firmament::sky::bruneton4d::{mu_s_blend, params, TableSizes};

/// Wavelengths per channel group (one vec4).
pub const GROUP: usize = 4;

/// Channel groups for `channels` wavelengths.
pub fn groups(channels: usize) -> usize {
    channels.div_ceil(GROUP)
}

/// The index of `ray_fractions_offset` in the `Atmosphere` uniform (its last field).
const RAY_FRACTIONS_OFFSET_FIELD: usize = 40;

/// The packed atmosphere.
pub struct Packed {
    /// The `Atmosphere` uniform, one 32-bit word per field (padded to 16 bytes).
    pub uniform: Vec<u32>,
    /// The data storage buffer, 4 floats per vec4.
    pub data: Vec<f32>,
}

/// A phase function as (kind, offset, count, a, b, c) of `phase_eval` in common/phase.wgsl;
/// tabulated knots are appended to `data`.
fn pack_phase(p: &PhaseFunction, data: &mut Vec<f32>) -> [u32; 6] {
    let f = |x: f64| (x as f32).to_bits();
    match p {
        PhaseFunction::Isotropic => [0, 0, 0, 0, 0, 0],
        PhaseFunction::Rayleigh { depolarization } => {
            let gamma = depolarization / (2.0 - depolarization);
            [1, 0, 0, f(1.0 + 3.0 * gamma), f(1.0 - gamma), 0]
        }
        PhaseFunction::HenyeyGreenstein { g } => [2, 0, 0, f(*g), 0, 0],
        PhaseFunction::CornetteShanks { g } => [3, 0, 0, f(*g), 0, 0],
        PhaseFunction::Schlick { g } => [4, 0, 0, f(1.55 * g - 0.55 * g * g * g), 0, 0],
        PhaseFunction::DualLobeHg { g1, g2, weight } => [5, 0, 0, f(*g1), f(*g2), f(*weight)],
        PhaseFunction::Tabulated(t) => {
            let offset = (data.len() / 4) as u32;
            for (theta, value) in t.angles().iter().zip(t.values()) {
                data.extend_from_slice(&[*theta as f32, *value as f32, 0.0, 0.0]);
            }
            [6, offset, t.angles().len() as u32, 0, 0, 0]
        }
    }
}

/// Pack `model` for tables of `sizes`.
pub fn pack(model: &Model, sizes: &TableSizes) -> Packed {
    let groups_info = &model.groups;
    let n = model.channels();
    let n_groups = groups(n);
    let km = 1e-3;
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let h = (top * top - bottom * bottom).sqrt();
    // The A of the μ_s mapping (mu_s_map::x_mu_s) for μ_s,min.
    let d_min = top - bottom;
    let big_d = distance_to_top_atmosphere_boundary(bottom, model.mu_s_min, top);
    let big_a = (big_d - d_min) / (h - d_min);
    let mu_s_map = params::MuSMap::new(&params::Radii::of(model));
    let theta_joint = mu_s_map.theta_joint();

    let mut data: Vec<f32> = Vec::new();
    let per_wavelength = |data: &mut Vec<f32>, values: &[f64], scale: f64| {
        for k in 0..n_groups * GROUP {
            data.push(if k < n {
                (values[k] * scale) as f32
            } else {
                0.0
            });
        }
    };
    let solar_offset = data.len() / 4;
    per_wavelength(&mut data, &model.solar_irradiance, 1.0);
    let albedo_offset = data.len() / 4;
    per_wavelength(&mut data, &model.ground_albedo, 1.0);
    // Per constituent: info (first layer, layer count, group or −1), scattering, extinction.
    let constituent_offset = data.len() / 4;
    let mut first_layer = 0usize;
    for c in &model.constituents {
        let group = ScatteringGroups::group_of(c).map_or(-1.0, |x| x as f32);
        data.extend_from_slice(&[
            first_layer as f32,
            c.density.layers.len() as f32,
            group,
            0.0,
        ]);
        per_wavelength(&mut data, &c.scattering, 1.0 / km);
        per_wavelength(&mut data, &c.extinction, 1.0 / km);
        first_layer += c.density.layers.len();
    }
    // Layers: (width km, exp term, 1/H km⁻¹, linear term km⁻¹), (constant, 0, 0, 0).
    let layer_offset = data.len() / 4;
    for c in &model.constituents {
        for l in &c.density.layers {
            let inv_h = if l.scale_height_m.is_finite() && l.scale_height_m != 0.0 {
                1.0 / (l.scale_height_m * km)
            } else {
                0.0
            };
            data.extend_from_slice(&[
                (l.width_m * km) as f32,
                l.exp_term as f32,
                inv_h as f32,
                (l.linear_term_per_m / km) as f32,
                l.constant_term as f32,
                0.0,
                0.0,
                0.0,
            ]);
        }
    }
    let phase0 = pack_phase(&groups_info.phase[MOLECULES], &mut data);
    let phase1 = pack_phase(&groups_info.phase[AEROSOLS], &mut data);

    let f = |x: f64| (x as f32).to_bits();
    let u = |x: usize| x as u32;
    let mut uniform = vec![
        f(bottom * km),
        f(top * km),
        f(h * km),
        f(h * km * h * km),
        f(model.mu_s_min),
        f(big_a),
        f(theta_joint),
        f(model.sun_angular_radius_rad),
        u(n),
        u(n_groups),
        u(model.constituents.len()),
        u(sizes.transmittance_mu),
        u(sizes.transmittance_r),
        u(sizes.scattering_r),
        u(sizes.scattering_mu),
        u(sizes.scattering_mu_s),
        u(sizes.scattering_nu),
        u(sizes.irradiance_mu_s),
        u(sizes.irradiance_r),
        u(solar_offset),
        u(albedo_offset),
        u(constituent_offset),
        u(layer_offset),
    ];
    uniform.extend_from_slice(&phase0);
    uniform.extend_from_slice(&phase1);
    uniform.push(groups_info.present(MOLECULES) as u32);
    uniform.push(groups_info.present(AEROSOLS) as u32);
    // The μ_s cells of the scattering and irradiance tables that take the twilight blend
    // (mu_s_blend.wgsl), counted in f64 as on the CPU.
    let radii = params::Radii::of(model);
    uniform.push(u(mu_s_blend::twilight_cells(&radii, sizes.scattering_mu_s)));
    uniform.push(u(mu_s_blend::irradiance_twilight_cells(
        sizes.irradiance_mu_s,
    )));
    uniform.push(f(mu_s_map.joint_bruneton_x()));
    // No ray placement outside the precomputation (pack_for_precompute).
    debug_assert_eq!(uniform.len(), RAY_FRACTIONS_OFFSET_FIELD);
    uniform.push(0);
    while !uniform.len().is_multiple_of(4) {
        uniform.push(0);
    }
    Packed { uniform, data }
}

/// [`pack`] with what only the precomputation reads: the placement of every (r, μ) row's
/// view-ray samples (`ray.wgsl`, `ray_pair_end_km`), the interior ends of its pairs as
/// fractions of the ray's length, `RAY_PAIRS − 1` per row padded to whole vec4s, computed
/// by the CPU's own [`RayGrading`] so that both place the samples alike.
pub fn pack_for_precompute(model: &Model, sizes: &TableSizes) -> Packed {
    let mut packed = pack(model, sizes);
    let grading = RayGrading::for_tables(model, sizes);
    let per_row = (RAY_PAIRS - 1).div_ceil(GROUP) * GROUP;
    let offset = packed.data.len() / 4;
    let interior: Vec<f64> = grading.interior().collect();
    for row in interior.chunks_exact(RAY_PAIRS - 1) {
        packed.data.extend(row.iter().map(|&f| f as f32));
        packed
            .data
            .extend(std::iter::repeat_n(0.0, per_row - row.len()));
    }
    packed.uniform[RAY_FRACTIONS_OFFSET_FIELD] = offset as u32;
    packed
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::atmosphere::Atmosphere;
    use firmament::spectrum::Wavelengths;

    #[test]
    fn uniform_has_the_shader_struct_size() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let p = pack(&model, &TableSizes::small());
        // 41 fields of the WGSL `Atmosphere` struct, padded to 16 bytes.
        assert_eq!(p.uniform.len(), 44);
        assert_eq!(p.uniform[RAY_FRACTIONS_OFFSET_FIELD], 0);
        assert_eq!(p.data.len() % 4, 0);
        assert!(model.groups.present(MOLECULES));
    }

    #[test]
    fn the_precomputation_gets_each_rows_ray_placement() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let s = TableSizes::small();
        let p = pack_for_precompute(&model, &s);
        let offset = p.uniform[RAY_FRACTIONS_OFFSET_FIELD] as usize * 4;
        let per_row = (RAY_PAIRS - 1).div_ceil(GROUP) * GROUP;
        assert_eq!(
            p.data.len(),
            offset + s.scattering_r * s.scattering_mu * per_row
        );
        for row in p.data[offset..].chunks_exact(per_row) {
            let ends = &row[..RAY_PAIRS - 1];
            assert!(ends[0] > 0.0 && ends[RAY_PAIRS - 2] < 1.0);
            assert!(ends.windows(2).all(|w| w[1] > w[0]), "{ends:?}");
        }
    }

    #[test]
    fn channel_groups_round_up() {
        assert_eq!(groups(1), 1);
        assert_eq!(groups(3), 1);
        assert_eq!(groups(4), 1);
        assert_eq!(groups(5), 2);
        assert_eq!(groups(16), 4);
    }
}
