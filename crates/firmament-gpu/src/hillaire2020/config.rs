//! Hillaire 2020's sizes and counts as the shaders read them (the `Hillaire` uniform of
//! `shaders/hillaire2020/config.wgsl`, same field order) and its per-atmosphere data: the
//! multiple-scattering pass's gather rules, the irradiance pass's directions and the groups'
//! phase moments, computed in f64 as the CPU computes them and rounded once. Also the
//! atmosphere the shaders take: the 4D packing ([`crate::bruneton4d::atmosphere::pack`])
//! with Hillaire's transmittance size.

use firmament::atmosphere::groups::{AEROSOLS, MOLECULES};
use firmament::atmosphere::{Model, ScatteringGroups};
use firmament::math::lattice::band_directions;
use firmament::math::quadrature::GaussLegendreRule;
use firmament::math::Vec3;
use firmament::sky::bruneton4d::TableSizes;
use firmament::sky::hillaire2020::harmonics::{coefficient_count, phase_moments};
pub use firmament::sky::hillaire2020::multiple_scattering::higher_orders_directions;
use firmament::sky::hillaire2020::multiple_scattering::HIGHER_ORDERS_DEGREE;
use firmament::sky::hillaire2020::{HillaireConfig, MultipleScatteringModel};

use crate::bruneton4d::atmosphere::{self, Packed};
use crate::GpuError;

/// The `Hillaire` uniform (one 32-bit word per field) and the `hillaire_data` storage
/// buffer (4 floats per vec4).
pub struct PackedConfig {
    /// The uniform's words.
    pub uniform: Vec<u32>,
    /// The uniform of the gathers of the higher orders
    /// (`multiple_scattering::compute`'s loop): order 2's (through the first order's
    /// field), then that of orders ≥ 3 (through a higher order's field, of degree ≤
    /// [`HIGHER_ORDERS_DEGREE`]), each with the coarser gather rule
    /// ([`higher_orders_directions`]) and the field it writes of degree ≤
    /// [`HIGHER_ORDERS_DEGREE`].
    pub higher_orders: [Vec<u32>; 2],
    /// The data's floats.
    pub data: Vec<f32>,
}

/// The gather rules' node counts below and above the horizon for `n_mu` nodes in μ
/// (multiple_scattering::gather_directions: a third below).
pub fn gather_split(n_mu: usize) -> (usize, usize) {
    let below = (n_mu / 3).max(1);
    (below, n_mu.saturating_sub(below).max(1))
}

/// The 4D tables' sizes with this transmittance (what the lookups read; Hillaire's own
/// sizes are in the `Hillaire` uniform).
pub fn table_sizes(config: &HillaireConfig) -> TableSizes {
    TableSizes {
        transmittance_mu: config.transmittance.0,
        transmittance_r: config.transmittance.1,
        ..TableSizes::default()
    }
}

/// The atmosphere as every shader reads it, for `config`'s tables.
pub fn pack_atmosphere(model: &Model, config: &HillaireConfig) -> Packed {
    atmosphere::pack(model, &table_sizes(config))
}

/// Refuse what the shaders cannot take: a scattering constituent whose phase function is not
/// its group's (the GPU applies one phase function per scattering group, that of its first
/// member, where the CPU march applies each constituent's own).
pub fn check_phases(model: &Model) -> Result<(), GpuError> {
    for (i, c) in model.constituents.iter().enumerate() {
        let Some(group) = ScatteringGroups::group_of(c) else {
            continue;
        };
        if c.phase != model.groups.phase[group] {
            return Err(firmament::Error::invalid(
                format!("constituents[{i}].phase"),
                format!("{:?}", c.phase),
                format!(
                    "the phase function of the first {} constituent ({:?}) for Hillaire 2020 on the GPU, which applies one phase function per scattering group; the CPU method takes it",
                    if group == MOLECULES { "molecular" } else { "aerosol" },
                    model.groups.phase[group]
                ),
            )
            .into());
        }
    }
    Ok(())
}

/// Pack `config` for `model` (validated by the caller).
pub fn pack(model: &Model, config: &HillaireConfig) -> PackedConfig {
    let degree = config.multiple_scattering_model.degree();
    let next_degree = degree.min(HIGHER_ORDERS_DEGREE);
    let (n_mu, n_phi) = config.multiple_scattering_directions;
    let (next_mu, next_phi) = higher_orders_directions(config.multiple_scattering_directions);
    let mut data: Vec<f32> = Vec::new();
    // The gather rules on [−1, 1]: (node, weight), below the horizon then above; the first
    // order's, then the higher orders'.
    let mut gather_rule = |n_mu: usize| {
        let offset = data.len() / 4;
        let (below, above) = gather_split(n_mu);
        for rule in [GaussLegendreRule::new(below), GaussLegendreRule::new(above)] {
            for (x, w) in rule.nodes.iter().zip(&rule.weights) {
                data.extend_from_slice(&[*x as f32, *w as f32, 0.0, 0.0]);
            }
        }
        offset
    };
    let gather_offset = gather_rule(n_mu);
    let next_gather_offset = gather_rule(next_mu);
    // The irradiance pass's directions over the upper hemisphere.
    let directions_offset = data.len() / 4;
    for d in band_directions(Vec3::Z, 0.0, 1.0, config.irradiance_directions) {
        data.extend_from_slice(&[d.x as f32, d.y as f32, d.z as f32, 0.0]);
    }
    // Per group the moments k_ℓ, ℓ ≤ degree (the isotropic field is seen through an
    // isotropic phase: k₀ = 1, as MultipleScattering::moments).
    let moments_offset = data.len() / 4;
    for group in [MOLECULES, AEROSOLS] {
        let moments = match config.multiple_scattering_model {
            MultipleScatteringModel::Isotropic => vec![1.0],
            MultipleScatteringModel::Harmonics(_) => {
                phase_moments(&model.groups.phase[group], degree)
            }
        };
        for k in moments {
            data.extend_from_slice(&[k as f32, 0.0, 0.0, 0.0]);
        }
    }
    let u = |x: usize| x as u32;
    // The uniform of a pass whose march reads a field of `field_degree`, gathers on
    // (`n_mu`, `n_phi`) nodes whose rule is at `gather_offset` and writes a field of
    // `order_degree`.
    let uniform = |field_degree: usize,
                   (n_mu, n_phi): (usize, usize),
                   gather_offset: usize,
                   order_degree: usize| {
        let (below, above) = gather_split(n_mu);
        vec![
            u(config.multiple_scattering.0),
            u(config.multiple_scattering.1),
            u(field_degree),
            u(coefficient_count(field_degree)),
            u(below),
            u(above),
            u(n_phi),
            u(config.multiple_scattering_steps),
            u(config.sky_view.0),
            u(config.sky_view.1),
            u(config.sky_view_steps),
            u(config.march_steps),
            u(config.irradiance.0),
            u(config.irradiance.1),
            u(config.irradiance_directions),
            u(config.irradiance_steps),
            u(gather_offset),
            u(directions_offset),
            u(moments_offset),
            u(degree + 1),
            u(coefficient_count(degree)),
            u(coefficient_count(order_degree)),
            u(config.multiple_scattering_orders),
            0,
        ]
    };
    let next = (next_mu, next_phi);
    PackedConfig {
        uniform: uniform(degree, (n_mu, n_phi), gather_offset, degree),
        higher_orders: [
            uniform(degree, next, next_gather_offset, next_degree),
            uniform(next_degree, next, next_gather_offset, next_degree),
        ],
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::atmosphere::Atmosphere;
    use firmament::sky::hillaire2020::multiple_scattering::HIGHER_ORDERS_DIRECTIONS;
    use firmament::spectrum::Wavelengths;

    #[test]
    fn uniform_has_the_shader_struct_size_and_data_its_offsets() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let config = HillaireConfig {
            multiple_scattering_model: MultipleScatteringModel::Harmonics(2),
            ..HillaireConfig::default()
        };
        let p = pack(&model, &config);
        // 24 fields of the WGSL `Hillaire` struct (a multiple of 4 words).
        assert_eq!(p.uniform.len(), 24);
        assert_eq!(p.uniform[3], 6);
        let (below, above) = gather_split(config.multiple_scattering_directions.0);
        let next = higher_orders_directions(config.multiple_scattering_directions);
        let (next_below, next_above) = gather_split(next.0);
        let rules = below + above + next_below + next_above;
        assert_eq!(p.uniform[17] as usize, rules);
        assert_eq!(p.uniform[18] as usize, rules + config.irradiance_directions);
        assert_eq!(p.data.len() / 4, p.uniform[18] as usize + 2 * 3);
        // Rayleigh's k₀ = 1 and k₂ = 1/10 (depolarisation aside), stride degree + 1.
        let m = p.uniform[18] as usize * 4;
        assert_eq!(p.uniform[19], 3);
        assert!((p.data[m] - 1.0).abs() < 1e-5);
        assert!((p.data[m + 8] - 0.1).abs() < 0.01);
        // The higher orders' copies: the coarser rule after the first, the same moments.
        for h in &p.higher_orders {
            assert_eq!(h.len(), 24);
            assert_eq!(h[16] as usize, below + above);
            assert_eq!((h[4] + h[5]) as usize, next.0);
            assert_eq!(h[6] as usize, next.1);
            assert_eq!(&h[17..21], &p.uniform[17..21]);
        }
    }

    #[test]
    fn the_higher_orders_gather_on_the_coarser_rule_and_degree() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let config = HillaireConfig {
            multiple_scattering_model: MultipleScatteringModel::Harmonics(6),
            multiple_scattering_directions: (24, 12),
            multiple_scattering_orders: 5,
            ..HillaireConfig::default()
        };
        let p = pack(&model, &config);
        let count = |d: usize| coefficient_count(d) as u32;
        // The first order: degree 6 read and written, into a table of degree 6.
        assert_eq!(
            (p.uniform[2], p.uniform[3], p.uniform[20], p.uniform[21]),
            (6, count(6), count(6), count(6))
        );
        // Order 2 reads the degree-6 field and writes degree 4; orders ≥ 3 read degree 4.
        let [second, higher] = &p.higher_orders;
        assert_eq!((second[2], second[21]), (6, count(HIGHER_ORDERS_DEGREE)));
        assert_eq!((higher[2], higher[3]), (4, count(HIGHER_ORDERS_DEGREE)));
        assert_eq!((higher[6], higher[20], higher[22]), (6, count(6), 5));
        assert_eq!(higher_orders_directions((24, 12)), HIGHER_ORDERS_DIRECTIONS);
    }

    #[test]
    fn the_earth_presets_phases_are_their_groups() {
        for name in firmament::atmosphere::presets::NAMES {
            let model = Atmosphere::preset(name)
                .unwrap()
                .resolve(&Wavelengths::rgb())
                .unwrap();
            check_phases(&model).unwrap();
        }
    }
}
