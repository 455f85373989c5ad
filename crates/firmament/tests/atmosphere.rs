//! Presets, TOML and validation messages.

use firmament::atmosphere::{presets, Atmosphere};
use firmament::spectrum::Wavelengths;

#[test]
fn presets_parse_and_round_trip_through_toml() {
    for name in presets::NAMES {
        let a = Atmosphere::preset(name).unwrap();
        let back = Atmosphere::from_toml_str(&a.to_toml(), None).unwrap();
        assert_eq!(a, back, "{name}");
        assert!(
            presets::toml_text(name).unwrap().contains("# "),
            "{name} has comments"
        );
    }
}

#[test]
fn bruneton2008_and_frostbite2016_have_the_papers_values() {
    let m = Atmosphere::preset("bruneton2008")
        .unwrap()
        .resolve(&Wavelengths::rgb())
        .unwrap();
    let r = &m.constituents[0].scattering;
    for (got, want) in r.iter().zip([5.8e-6, 13.5e-6, 33.1e-6]) {
        assert!((got - want).abs() / want < 1e-9);
    }
    let mie = &m.constituents[1];
    assert!((mie.scattering[1] - 2e-5).abs() < 1e-12);
    assert!((mie.scattering[1] / mie.extinction[1] - 0.9).abs() < 1e-9);
    let f = Atmosphere::preset("frostbite2016")
        .unwrap()
        .resolve(&Wavelengths::rgb())
        .unwrap();
    let ozone = &f.constituents[2].absorption;
    for (got, want) in ozone.iter().zip([3.426, 8.298, 0.356]) {
        assert!(
            (got - want * 0.06e-5).abs() / (want * 0.06e-5) < 1e-3,
            "{got}"
        );
    }
    assert!((f.constituents[1].extinction[0] - 4.4e-6).abs() < 1e-12);
}

fn error_of(text: &str) -> String {
    Atmosphere::from_toml_str(text, None)
        .unwrap_err()
        .to_string()
}

fn earth_with(from: &str, to: &str) -> String {
    let text = presets::toml_text("earth").unwrap();
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

#[test]
fn bad_values_are_refused_with_the_field_the_value_and_the_range() {
    let cases = [
        (
            "bottom_radius_m = 6360000.0",
            "bottom_radius_m = -5.0",
            "bottom_radius_m",
            "-5",
        ),
        (
            "top_radius_m = 6420000.0",
            "top_radius_m = 6000000.0",
            "top_radius_m",
            "greater than bottom_radius_m",
        ),
        (
            "ground_albedo = 0.1",
            "ground_albedo = 1.5",
            "ground_albedo",
            "[0, 1]",
        ),
        (
            "ground_albedo = 0.1",
            "ground_albedo = nan",
            "ground_albedo",
            "NaN",
        ),
        ("g = 0.76 }", "g = 1.2 }", "constituents[1].phase.g", "1.2"),
        (
            "scale_height_m = 1200.0",
            "scale_height_m = -1.0",
            "constituents[1].density[0].scale_height_m",
            "> 0",
        ),
        (
            "column_du = 300.0",
            "column_du = -3.0",
            "constituents[2].absorption.column_du",
            "≥ 0",
        ),
        (
            "angular_radius_deg = 0.26656",
            "angular_radius_deg = 0.0",
            "sun.angular_radius_deg",
            "(0, 10)",
        ),
        (
            "min_sun_elevation_deg = -12.0",
            "min_sun_elevation_deg = 5.0",
            "min_sun_elevation_deg",
            "[-90, 0]",
        ),
    ];
    for (from, to, field, range) in cases {
        let err = error_of(&earth_with(from, to));
        assert!(err.contains(field) && err.contains(range), "{to}: {err}");
    }
}

#[test]
fn unknown_fields_malformed_toml_and_unknown_presets_are_refused() {
    let err = error_of(&earth_with(
        "ground_albedo = 0.1",
        "ground_albedo = 0.1\nground_albdo = 0.2",
    ));
    assert!(
        err.contains("unknown field") && err.contains("ground_albdo"),
        "{err}"
    );
    let err = error_of("name = \"x\"\nbottom_radius_m = [");
    assert!(err.contains("TOML"), "{err}");
    let err = Atmosphere::preset("venus").unwrap_err().to_string();
    assert!(err.contains("venus") && err.contains("earth"), "{err}");
    let err = Wavelengths::parse("").unwrap_err().to_string();
    assert!(err.contains("wavelengths"), "{err}");
}
