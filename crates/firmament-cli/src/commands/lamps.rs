//! The lights of an environment map as lamps (`NAME.lights.json` next to the map): a renderer
//! that lights a scene with the map and a sun lamp (Blender, engines) needs the sun's
//! direction, angular diameter, illuminance and colour at the camera, and must know
//! whether the map already holds the disk (then the lamp would count it twice).
//!
//! The illuminance is the light's irradiance outside the atmosphere times the direct
//! beam's transmittance from the camera (Beer–Lambert over the model's constituents along
//! the straight ray to the top of the atmosphere; zero when the planet is in the way),
//! integrated against CIE 1931 ȳ (683 lm/W): what `query` reports as the direct normal
//! illuminance, computed here from the model without the tables.

use firmament::atmosphere::Model;
use firmament::math::sphere::distance_to_top_atmosphere_boundary;
use firmament::math::Vec3;
use firmament::render::cube_layout::CubeLayout;
use firmament::scene::{Light, Projection};
use serde_json::{json, Value};

/// Lumens per watt that Blender assumes for its lamps' power and strength (the photopic
/// maximum, 683 lm/W; Blender manual, "Light Objects: Power").
const BLENDER_LM_PER_W: f64 = 683.0;

/// Where the map's pixels point, for the lamps' directions in its users' frames.
#[derive(Clone, Copy, Debug)]
pub struct MapFrame {
    /// Equirect (centre column at `heading_deg`) or cube map (in `layout`).
    pub projection: Projection,
    /// The equirect map's centre column (degrees clockwise from north).
    pub heading_deg: f64,
    /// The cube map's layout.
    pub layout: CubeLayout,
}

/// The direct beam's transmittance (per wavelength) from `radius_m` towards `dir` (local
/// frame, z up): 0 when the planet hides the light's centre.
fn beam_transmittance(model: &Model, radius_m: f64, dir: Vec3) -> Vec<f64> {
    let mu = dir.z;
    // The ray meets the planet when it descends and passes closer to the centre than R.
    let r = radius_m;
    if mu < 0.0 && r * r * (1.0 - mu * mu) < model.bottom_radius_m * model.bottom_radius_m {
        return vec![0.0; model.channels()];
    }
    let length = distance_to_top_atmosphere_boundary(radius_m, mu, model.top_radius_m);
    let tau = model.optical_depth_along_ray(radius_m, mu, length.max(0.0));
    tau.iter().map(|t| (-t).exp()).collect()
}

/// One lamp's JSON: direction (azimuth, elevation, the local unit vector and the map
/// users' frame), angular diameter, illuminance (lux, on a surface facing it), colour
/// (linear Rec. 709 with luminance 1) and Blender's sun settings.
fn lamp(
    name: &str,
    model: &Model,
    light: &Light,
    radius_m: f64,
    frame: MapFrame,
    disk_in_map: bool,
) -> Value {
    let d = light.direction;
    let t = beam_transmittance(model, radius_m, d);
    let irradiance: Vec<f64> = light
        .irradiance
        .iter()
        .zip(&t)
        .map(|(e, t)| e * t)
        .collect();
    let colour = model.colour_matrix();
    let lux = colour.to_xyz(&irradiance)[1];
    let rgb = colour.to_srgb(&irradiance);
    let y = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    let colour: Vec<f64> = if y > 0.0 {
        rgb.iter().map(|c| (c / y).max(0.0)).collect()
    } else {
        vec![1.0; 3]
    };
    let elevation = d.z.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = d.x.atan2(d.y).to_degrees().rem_euclid(360.0);
    let mut out = json!({
        "name": name,
        "azimuth_deg": azimuth,
        "elevation_deg": elevation,
        "direction_east_north_up": [d.x, d.y, d.z],
        "angular_diameter_deg": 2.0 * light.angular_radius_rad.to_degrees(),
        "illuminance_lux": lux,
        "colour_rec709_linear": colour,
        "disk_in_map": disk_in_map && light.visible_disk,
    });
    match frame.projection {
        Projection::Equirect => {
            // Blender's environment texture puts the centre column on +X and turns right
            // (towards −Y) as the column grows (docs/conventions.md).
            let rel = (azimuth - frame.heading_deg).to_radians();
            let c = d.z.clamp(-1.0, 1.0).acos();
            let v = [c.sin() * rel.cos(), -c.sin() * rel.sin(), d.z];
            // A sun lamp shines along its −Z: rotate +Z onto the light's direction, X by
            // the zenith angle then Z by atan2(vx, −vy) (Euler XYZ).
            let rz = v[0].atan2(-v[1]).to_degrees();
            out["blender"] = json!({
                "direction": v,
                "sun_rotation_euler_xyz_deg": [c.to_degrees(), 0.0, rz],
                "sun_strength_w_m2": lux / BLENDER_LM_PER_W,
                "sun_angle_deg": 2.0 * light.angular_radius_rad.to_degrees(),
                "note": "for the map in an Environment Texture without a Mapping rotation",
            });
        }
        Projection::Cubemap => {
            let c = frame.layout.cube_axes(d);
            out["cube_direction"] = json!({
                "layout": frame.layout.name(),
                "direction": [c.x, c.y, c.z],
            });
        }
        _ => {}
    }
    out
}

/// The lamps of `lights` (the sun first, then the moon when up) for a camera `radius_m`
/// from the planet's centre.
pub fn lamps(
    model: &Model,
    lights: &[Light],
    radius_m: f64,
    frame: MapFrame,
    disk_in_map: bool,
    provenance: Value,
) -> Value {
    let names = ["sun", "moon"];
    let list: Vec<Value> = (lights.iter().zip(names))
        .map(|(l, n)| lamp(n, model, l, radius_m, frame, disk_in_map))
        .collect();
    json!({
        "lamps": list,
        "frame": "azimuth clockwise from north, direction_east_north_up with x east, y north, z up",
        "provenance": provenance,
    })
}
