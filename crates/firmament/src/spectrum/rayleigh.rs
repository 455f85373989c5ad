//! Rayleigh scattering cross-section of dry air and the air column, after
//! Bodhaine, B. A., Wood, N. B., Dutton, E. G. & Slusser, J. R. (1999),
//! "On Rayleigh optical depth calculations", J. Atmos. Oceanic Technol. 16, 1854–1861.
//!
//! σ(λ) is computed from first principles as in the paper (its eq. 2 with the Peck & Reeder
//! 1972 refractive index scaled for CO2 and the King factor of Bates 1984), not from the
//! paper's fitted closed form. Each formula is written out below, since equation numbers
//! differ between the paper's quotations.

use std::f64::consts::PI;

/// CO2 volume mixing ratio of Bodhaine et al.'s standard air (360 ppm = 3.6·10⁻⁴, the paper's standard air).
pub const BODHAINE_CO2_PPM: f64 = 360.0;

/// Molecular number density of standard air at 288.15 K and 1013.25 hPa, m⁻³: the N_s used
/// in Bodhaine et al.'s eq. 2 (2.546899·10¹⁹ cm⁻³ in the paper).
pub const LOSCHMIDT_288_15K_M3: f64 = 2.546_899e25;

/// Standard sea-level pressure, Pa (1013.25 hPa; Bodhaine et al. 1999, Table 3 conditions).
pub const BODHAINE_PRESSURE_PA: f64 = 101_325.0;

/// Avogadro constant, mol⁻¹ (SI 2019 exact value; Bodhaine et al. used 6.0221367·10²³,
/// 2·10⁻⁸ relative difference).
pub const AVOGADRO_PER_MOL: f64 = 6.022_140_76e23;

/// Mean molar mass of dry air with 360 ppm CO2, kg/mol: Bodhaine et al.,
/// m_a = 15.0556·C + 28.9595 g/mol with C = 3.6·10⁻⁴ → 28.96492 g/mol.
pub const BODHAINE_MOLAR_MASS_360PPM_KG_MOL: f64 = (15.0556 * 3.6e-4 + 28.9595) * 1e-3;

/// Sea-level gravity at 45° latitude, m/s²: Bodhaine et al. (after the Smithsonian tables),
/// g₀ = 980.6160·(1 − 0.0026373 cos 2φ + 0.0000059 cos² 2φ) cm/s², cos 90° = 0.
pub const BODHAINE_G_45DEG_SEA_LEVEL_M_S2: f64 = 9.806_16;

/// Gravity at the mass-weighted column height above a 45° sea-level site, m/s²: Bodhaine et
/// al.'s altitude formula at the column height z_c = 0.73737·0 + 5517.56 m. This is the g their Table 3
/// optical depths use; [`bodhaine_gravity_m_s2`] reproduces it.
pub const BODHAINE_G_COLUMN_45DEG_SEA_LEVEL_M_S2: f64 = 9.789_158;

/// Gravity at latitude `latitude_deg` and altitude `altitude_m`, m/s² (Bodhaine et al. 1999
/// §3, from the Smithsonian Meteorological Tables; z in metres, g in cm/s² there).
pub fn bodhaine_gravity_m_s2(latitude_deg: f64, altitude_m: f64) -> f64 {
    let c2 = (2.0 * latitude_deg.to_radians()).cos();
    let z = altitude_m;
    // sea-level gravity, cm/s²
    let g0 = 980.6160 * (1.0 - 0.002_637_3 * c2 + 0.000_005_9 * c2 * c2);
    // altitude correction, cm/s²
    let g = g0 - (3.085_462e-4 + 2.27e-7 * c2) * z + (7.254e-11 + 1.0e-13 * c2) * z * z
        - (1.517e-17 + 6e-20 * c2) * z * z * z;
    g * 1e-2
}

/// Mass-weighted column height above a site at `altitude_m`, m: Bodhaine et al. §3,
/// z_c = 0.73737·z + 5517.56 (used as the altitude of g in their eq. 3).
pub fn bodhaine_column_height_m(altitude_m: f64) -> f64 {
    0.737_37 * altitude_m + 5517.56
}

/// Refractive index of dry air with `co2_ppm` CO2 at 288.15 K, 1013.25 hPa, as (n − 1):
/// Peck & Reeder (1972) for 300 ppm (as quoted by Bodhaine et al., λ in µm),
/// 10⁸(n₃₀₀ − 1) = 8060.51 + 2480990/(132.274 − λ⁻²) + 17455.7/(39.32957 − λ⁻²),
/// scaled for CO2 as in Bodhaine et al.: (n − 1) = (n₃₀₀ − 1)·[1 + 0.54·(C − 0.0003)], C in parts per volume.
pub fn air_refractivity(lambda_nm: f64, co2_ppm: f64) -> f64 {
    let inv_l2 = 1.0 / (lambda_nm * 1e-3).powi(2); // µm⁻²
    let n300 =
        (8060.51 + 2_480_990.0 / (132.274 - inv_l2) + 17_455.7 / (39.329_57 - inv_l2)) * 1e-8;
    n300 * (1.0 + 0.54 * (co2_ppm * 1e-6 - 0.0003))
}

/// King correction factor F_air = (6 + 3ρ)/(6 − 7ρ) of dry air with `co2_ppm` CO2:
/// Bates (1984) per gas (as quoted by Bodhaine et al., λ in µm):
/// F(N2) = 1.034 + 3.17·10⁻⁴ λ⁻², F(O2) = 1.096 + 1.385·10⁻³ λ⁻² + 1.448·10⁻⁴ λ⁻⁴,
/// F(Ar) = 1.00, F(CO2) = 1.15, weighted by the volume percentages 78.084 N2, 20.946 O2,
/// 0.934 Ar and C(CO2) in percent.
pub fn air_king_factor(lambda_nm: f64, co2_ppm: f64) -> f64 {
    let inv_l2 = 1.0 / (lambda_nm * 1e-3).powi(2);
    let f_n2 = 1.034 + 3.17e-4 * inv_l2;
    let f_o2 = 1.096 + 1.385e-3 * inv_l2 + 1.448e-4 * inv_l2 * inv_l2;
    let (f_ar, f_co2) = (1.00, 1.15);
    let c = co2_ppm * 1e-4; // percent by volume
    (78.084 * f_n2 + 20.946 * f_o2 + 0.934 * f_ar + c * f_co2) / (78.084 + 20.946 + 0.934 + c)
}

/// Rayleigh scattering cross-section per molecule of dry air with 360 ppm CO2, m², at
/// `lambda_nm` (nm): Bodhaine et al. 1999 eq. 2,
/// σ = 24π³ (n² − 1)² / (λ⁴ N_s² (n² + 2)²) · F_air, with n and N_s at 288.15 K, 1013.25 hPa
/// (the ratio is independent of the state). About 4.51·10⁻³¹ m² at 550 nm.
pub fn rayleigh_cross_section_m2(lambda_nm: f64) -> f64 {
    rayleigh_cross_section_co2_m2(lambda_nm, BODHAINE_CO2_PPM)
}

/// As [`rayleigh_cross_section_m2`] for another CO2 mixing ratio `co2_ppm` (ppm by volume).
pub fn rayleigh_cross_section_co2_m2(lambda_nm: f64, co2_ppm: f64) -> f64 {
    let n = 1.0 + air_refractivity(lambda_nm, co2_ppm);
    let n2 = n * n;
    let lambda_m = lambda_nm * 1e-9;
    let ns = LOSCHMIDT_288_15K_M3;
    24.0 * PI.powi(3) * (n2 - 1.0).powi(2) / (lambda_m.powi(4) * ns * ns * (n2 + 2.0).powi(2))
        * air_king_factor(lambda_nm, co2_ppm)
}

/// Number of air molecules per m² in a vertical column above a surface at pressure
/// `pressure_pa` (Pa), N = P·N_A/(m_a·g) (Bodhaine et al. 1999 eq. 3 without σ), with
/// `gravity_m_s2` (m/s²) and `mean_molar_mass` in kg/mol. The zenith Rayleigh optical depth is
/// `rayleigh_cross_section_m2(λ) * rayleigh_column_m2(..)`. For Bodhaine's Table 3 use
/// [`BODHAINE_PRESSURE_PA`], [`BODHAINE_G_COLUMN_45DEG_SEA_LEVEL_M_S2`] and
/// [`BODHAINE_MOLAR_MASS_360PPM_KG_MOL`] (≈ 2.152·10²⁹ m⁻²).
pub fn rayleigh_column_m2(pressure_pa: f64, gravity_m_s2: f64, mean_molar_mass: f64) -> f64 {
    pressure_pa * AVOGADRO_PER_MOL / (mean_molar_mass * gravity_m_s2)
}
