// The planet's surface map (firmament::scene::planet, firmament_gpu::planet): the albedo of
// the ground sphere as weights of five spectra, baked into an equirectangular texture
// (row 0 at 90° N, column 0 at 180° W) and read bilinearly, and the sea's glint (Cox & Munk
// 1954) weighted by the sea's share.

struct Planet {
    // 1 when a map is bound; 1 when the fifth weight is 1 minus the others (a procedural
    // map: ocean, ice, rock, forest, grass, the first the sea's share); the texture's size.
    on: u32,
    rest_fifth: u32,
    width: u32,
    height: u32,
    // The sea's slope variance σ² (0: no glint) and refractive index.
    glint: vec4<f32>,
    // The observer's east, north and up in the map's planet-fixed frame (z to 90° N, x to
    // 0° E).
    east: vec4<f32>,
    north: vec4<f32>,
    up: vec4<f32>,
    // PLANET_BASIS spectra per channel group.
    basis: array<vec4<f32>, PLANET_BASIS_VEC4>,
}

@group(0) @binding(25) var planet_map: texture_2d<f32>;
@group(0) @binding(26) var<uniform> planet: Planet;

fn planet_on() -> bool {
    return planet.on != 0u;
}

// The ground sphere's point (km, the frame's local coordinates) on the ray from the observer
// at radius r_km on the +z axis along `dir` (a ray that meets the ground).
fn ground_point(r_km: f32, dir: vec3<f32>) -> vec3<f32> {
    let bottom = atm.bottom_radius_km;
    let b = r_km * dir.z;
    let c = (r_km - bottom) * (r_km + bottom);
    let t = -b - sqrt(max(b * b - c, 0.0));
    return vec3<f32>(0.0, 0.0, r_km) + max(t, 0.0) * dir;
}

// PlanetSurface::weights at a ground point `p` (local frame), bilinear between the texels'
// centres, wrapping in longitude: the first four weights and the fifth.
struct PlanetWeights {
    w: vec4<f32>,
    fifth: f32,
}

fn planet_weights(p: vec3<f32>) -> PlanetWeights {
    let d = normalize(p.x * planet.east.xyz + p.y * planet.north.xyz + p.z * planet.up.xyz);
    let lat = asin(clamp(d.z, -1.0, 1.0));
    let lon = atan2(d.y, d.x);
    let w = i32(planet.width);
    let h = i32(planet.height);
    let x = (lon / (2.0 * PI) + 0.5) * f32(w) - 0.5;
    let y = clamp((0.5 - lat / PI) * f32(h) - 0.5, 0.0, f32(h - 1));
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let xa = ((i32(x0) % w) + w) % w;
    let xb = (xa + 1) % w;
    let ya = i32(y0);
    let yb = min(ya + 1, h - 1);
    let top = mix(textureLoad(planet_map, vec2<i32>(xa, ya), 0), textureLoad(planet_map, vec2<i32>(xb, ya), 0), fx);
    let bottom = mix(textureLoad(planet_map, vec2<i32>(xa, yb), 0), textureLoad(planet_map, vec2<i32>(xb, yb), 0), fx);
    var out: PlanetWeights;
    out.w = mix(top, bottom, fy);
    out.fifth = select(0.0, 1.0 - (out.w.x + out.w.y + out.w.z + out.w.w), planet.rest_fifth != 0u);
    return out;
}

// Surface::albedo of the map, channel group k.
fn planet_albedo(t: PlanetWeights, k: u32) -> vec4<f32> {
    let b = PLANET_BASIS * k;
    return t.w.x * planet.basis[b] + t.w.y * planet.basis[b + 1u] + t.w.z * planet.basis[b + 2u]
        + t.w.w * planet.basis[b + 3u] + t.fifth * planet.basis[b + 4u];
}

// Unpolarised Fresnel reflectance at incidence cosine `cos_i` from air into index `n`.
fn fresnel(cos_i: f32, n: f32) -> f32 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (n * n);
    if (sin_t2 >= 1.0) {
        return 1.0;
    }
    let ct = sqrt(1.0 - sin_t2);
    let rs = (cos_i - n * ct) / (cos_i + n * ct);
    let rp = (n * cos_i - ct) / (n * cos_i + ct);
    return 0.5 * (rs * rs + rp * rp);
}

// PlanetSurface::glint_brdf: the Cox & Munk (1954) glint BRDF (sr⁻¹),
// F(β_i)·P(tan β)/(4 cos θ_i cos θ_v cos⁴ β).
fn glint_brdf(sigma2: f32, normal: vec3<f32>, to_viewer: vec3<f32>, to_light: vec3<f32>) -> f32 {
    let ci = dot(normal, to_light);
    let cv = dot(normal, to_viewer);
    if (ci <= 0.0 || cv <= 0.0) {
        return 0.0;
    }
    let h = normalize(to_light + to_viewer);
    let cb = clamp(dot(normal, h), 1e-6, 1.0);
    let tan2 = (1.0 - cb * cb) / (cb * cb);
    let p = exp(-tan2 / sigma2) / (PI * sigma2);
    let f = fresnel(clamp(dot(h, to_light), 0.0, 1.0), planet.glint.y);
    let cb2 = cb * cb;
    return f * p / (4.0 * ci * cv * cb2 * cb2);
}

// Surface::specular of the map: the glint weighted by the sea's share (sr⁻¹).
fn planet_specular(t: PlanetWeights, normal: vec3<f32>, to_viewer: vec3<f32>, to_light: vec3<f32>) -> f32 {
    if (planet.glint.x <= 0.0 || planet.rest_fifth == 0u || t.w.x <= 0.0) {
        return 0.0;
    }
    return t.w.x * glint_brdf(planet.glint.x, normal, to_viewer, to_light);
}
