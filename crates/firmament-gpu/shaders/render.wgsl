// A frame, one invocation per pixel: firmament::render::render with shade_sliced (Bruneton &
// Neyret 2008 eq. 16; Bruneton 2017 `GetSkyRadiance`, `GetSkyRadianceToPoint`,
// `GetSunAndSkyIrradiance`). Every function names the Rust function it mirrors.
//
// The tables are bound at the slots functions.wgsl declares for the precomputation passes:
//   3 transmittance_table     τ(r, μ) = −ln T to the top (Tables::optical_depth)
//   4 delta_irradiance_table  the final indirect irradiance E(r, μ_s) (Tables::irradiance)
//   5 scattering_a            single molecular scattering (Tables::scattering)
//   6 scattering_b            single Mie (Tables::single_mie; see Frame.mie_layout)
//   7 multiple_table          multiple scattering, radiance (Tables::multiple; declared
//                             here, the precomputation's output slot)
//
// Geometry is in km relative to the planet centre, but never through planet-scale
// differences: the camera's ρ = sqrt(r² − R_g²) and its height above the top of the
// atmosphere come from the host in f64, a camera in space enters the atmosphere through the
// impact parameter p (discriminants (R − p)(R + p), no cancellation), and the ground point of
// a ray is (r = R_g, ρ = 0) with its zenith cosine from the ray's discriminant.

// Per-frame constants (firmament_gpu::render writes them in this field order).
struct Frame {
    width: u32,
    height: u32,
    // This dispatch covers rows first_row .. first_row + rows (frames too large for one
    // storage binding are drawn in bands).
    first_row: u32,
    rows: u32,
    // 0 perspective, 1 fisheye, 2 equirect, 3 cubemap, 4 orbit (camera::Projection).
    projection: u32,
    // Whether the camera is inside the atmosphere (r ≤ R_t).
    inside: u32,
    sun_disk: u32,
    // Single Mie storage: 0 all channels, 1 channel 0 only with one vec4 per texel (red-only
    // tables from the CPU), 2 channel 0 read from the full layout (red-only, GPU tables).
    mie_layout: u32,
    // View basis of the pinhole projections (PreparedCamera), local frame x east, y north, z up.
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // Unit vector towards the sun; w: sin of the sun's angular radius.
    sun: vec4<f32>,
    // White-balance factors per linear sRGB channel (1 when off).
    balance: vec4<f32>,
    // Camera radius (km).
    camera_r: f32,
    // Camera ρ = sqrt(r² − R_g²) (km), inside the atmosphere.
    camera_rho: f32,
    // r − R_t (km), for a camera in space.
    camera_above_top: f32,
    tan_half_fov: f32,
    // (u_μs, u_r) of the camera slice (render::camera_slice, Sky::slice), computed in f64.
    slice_u_mu_s: f32,
    slice_u_r: f32,
    pad0: f32,
    pad1: f32,
}

@group(0) @binding(7) var<storage, read> multiple_table: array<vec4<f32>>;
@group(0) @binding(10) var<uniform> frame: Frame;
// Per channel group k, at k·CHANNEL_STRIDE: the linear sRGB rows of the colour matrix
// (render::ColourMatrix::to_srgb, 3 vec4), the sun's centre radiance times the six
// limb-darkening polynomial coefficients (Sky::solar_radiance_centre × limb_darkening, 6
// vec4), and the red-only Mie ratio factors (Tables::mie_ratio, 1 vec4). A uniform, room
// for 64 wavelengths (16 groups; CHANNEL_DATA_VEC4 in render.rs), so that the pass binds no
// more than 8 storage buffers.
@group(0) @binding(11) var<uniform> channel_data: array<vec4<f32>, 160>;
// Linear sRGB (Y in cd/m²) and 1 in w for pixels inside the projection; zeros outside.
@group(0) @binding(12) var<storage, read_write> frame_out: array<vec4<f32>>;

// The camera slice (render::camera_slice, Sky::slice): the single, multiple and single Mie
// scattering tables filtered at the camera's (u_μs, u_r), written by `camera_slice` each
// frame; entry e = y·N_ν + ν at e·3·groups + k for single scattering, + groups for
// multiple scattering ([single; multiple] interleaved as in Sky::slice), + 2·groups for
// Mie (channel 0 in x when red-only).
@group(0) @binding(13) var<storage, read_write> slice_table: array<vec4<f32>>;

const CHANNEL_STRIDE: u32 = 10u;

// ---------------------------------------------------------------------------------------
// Cameras (render/camera.rs).

// geometry::direction_from_zenith_azimuth: x east, y north, z up, azimuth clockwise from north.
fn direction_from_zenith_azimuth(zenith: f32, azimuth: f32) -> vec3<f32> {
    let s = sin(zenith);
    return vec3<f32>(s * sin(azimuth), s * cos(azimuth), cos(zenith));
}

// camera::cube_direction: faces +X, −X, +Y, −Y, +Z, −Z seen from the inside.
fn cube_direction(face: u32, u: f32, v: f32) -> vec3<f32> {
    switch face {
        case 0u: {
            return vec3<f32>(1.0, -u, v);
        }
        case 1u: {
            return vec3<f32>(-1.0, u, v);
        }
        case 2u: {
            return vec3<f32>(u, 1.0, v);
        }
        case 3u: {
            return vec3<f32>(-u, -1.0, v);
        }
        case 4u: {
            return vec3<f32>(-u, v, 1.0);
        }
        default: {
            return vec3<f32>(u, v, -1.0);
        }
    }
}

struct CameraRay {
    dir: vec3<f32>,
    valid: bool,
}

// PreparedCamera::ray (and Camera::ray_all_round) at pixel position (px, py), centres at
// +0.5; not valid outside the projection (the corners of a fisheye).
fn camera_ray(px: f32, py: f32) -> CameraRay {
    let w = f32(frame.width);
    let h = f32(frame.height);
    let u = 2.0 * px / w - 1.0;
    let v = 1.0 - 2.0 * py / h;
    var ray: CameraRay;
    ray.valid = true;
    var d: vec3<f32>;
    switch frame.projection {
        case 1u: {
            // Equidistant fisheye in the inscribed circle, (u·aspect, v) or (u, v/aspect)
            // written with exact numerators.
            var x = u;
            var y = v;
            if (w >= h) {
                x = (2.0 * px - w) / h;
            } else {
                y = (h - 2.0 * py) / w;
            }
            let rho = sqrt(x * x + y * y);
            if (rho > 1.0) {
                ray.valid = false;
                return ray;
            }
            if (rho == 0.0) {
                // atan2(0, 0) is 0 on the CPU; the zenith.
                d = vec3<f32>(0.0, 0.0, 1.0);
            } else {
                d = direction_from_zenith_azimuth(rho * PI / 2.0, atan2(-x, y));
            }
        }
        case 2u: {
            // Equirect: azimuth u·π, elevation v·π/2 (zenith angle π/2 − elevation).
            let azimuth = u * PI;
            let elevation = v * PI / 2.0;
            let c = cos(elevation);
            d = vec3<f32>(c * sin(azimuth), c * cos(azimuth), sin(elevation));
        }
        case 3u: {
            let face_w = w / 6.0;
            let face = min(u32(px / face_w), 5u);
            let fu = 2.0 * (px - f32(face) * face_w) / face_w - 1.0;
            d = cube_direction(face, fu, v);
        }
        default: {
            // Perspective and orbit: pinhole through the prepared basis.
            let t = frame.tan_half_fov;
            d = frame.forward.xyz + (u * t * w / h) * frame.right.xyz + (v * t) * frame.up.xyz;
        }
    }
    ray.dir = normalize(d);
    return ray;
}

// ---------------------------------------------------------------------------------------
// Where a view ray starts in the atmosphere (Sky::enter_atmosphere): the camera itself, or
// for a camera in space the point where the ray enters the top.

struct ViewStart {
    // False when the ray misses the atmosphere.
    in_atmosphere: bool,
    r: f32,
    rho: f32,
    mu: f32,
    mu_s: f32,
    // r²μ² − ρ², the discriminant of the ground sphere along the ray (≥ 0: the line meets it).
    disc_ground: f32,
    // Whether the camera slice's (u_μs, u_r) apply at this point.
    sliced: bool,
}

fn view_start(dir: vec3<f32>, nu: f32) -> ViewStart {
    var s: ViewStart;
    let sun = frame.sun.xyz;
    if (frame.inside != 0u) {
        // The camera is on the +z axis: μ = dir.z, μ_s = sun.z.
        s.in_atmosphere = true;
        s.r = frame.camera_r;
        s.rho = frame.camera_rho;
        s.mu = clamp_cosine(dir.z);
        s.mu_s = clamp_cosine(sun.z);
        s.disc_ground = s.r * s.r * s.mu * s.mu - s.rho * s.rho;
        s.sliced = true;
        return s;
    }
    // The nearer root of d² + 2 r_c μ d + r_c² − R_t² = 0, positive iff μ < 0; with the
    // impact parameter p = r_c sin θ the discriminant is (R_t − p)(R_t + p), and the nearer
    // root is the product of the roots (r_c − R_t)(r_c + R_t) over the farther one.
    let rc = frame.camera_r;
    let rmu = rc * dir.z;
    let p = rc * length(dir.xy);
    let disc = (atm.top_radius - p) * (atm.top_radius + p);
    if (disc < 0.0 || rmu >= 0.0) {
        s.in_atmosphere = false;
        return s;
    }
    let root = sqrt(disc);
    let d = frame.camera_above_top * (rc + atm.top_radius) / (-rmu + root);
    s.in_atmosphere = true;
    s.r = atm.top_radius;
    s.rho = atm.h;
    // (r_c μ + d)/R_t = −sqrt(disc)/R_t.
    s.mu = clamp_cosine(-root / atm.top_radius);
    s.mu_s = clamp_cosine((rc * sun.z + d * nu) / atm.top_radius);
    s.disc_ground = (atm.bottom_radius - p) * (atm.bottom_radius + p);
    s.sliced = false;
    return s;
}

// Distance from the start to the ground (geometry::distance_to_bottom_atmosphere_boundary,
// in the cancellation-free form of distance_to_bottom with the discriminant given).
fn distance_to_ground(s: ViewStart) -> f32 {
    let root = safe_sqrt(s.disc_ground);
    let far = -s.r * s.mu + root;
    if (far > 0.0) {
        return max(s.rho * s.rho / far, 0.0);
    }
    return max(-s.r * s.mu - root, 0.0);
}

// ---------------------------------------------------------------------------------------
// Table lookups with their filters computed once per pixel and applied per channel group.

// τ to the top at a filter (Lookup::optical_depth_to_top).
fn sample_optical_depth(f: Filter2, k: u32) -> vec4<f32> {
    return f.weight.x * transmittance_table[f.index.x + k] + f.weight.y * transmittance_table[f.index.y + k]
        + f.weight.z * transmittance_table[f.index.z + k] + f.weight.w * transmittance_table[f.index.w + k];
}

fn sample_transmittance(f: Filter2, k: u32) -> vec4<f32> {
    return exp(-sample_optical_depth(f, k));
}

// Lookup::transmittance_to_top's filter.
fn transmittance_filter(r: f32, rho: f32, mu: f32) -> Filter2 {
    return table2_filter(transmittance_uv(r, rho, mu), atm.transmittance_mu, atm.transmittance_r);
}

// Lookup::irradiance on the final irradiance table (bound at slot 4).
fn sample_irradiance(f: Filter2, k: u32) -> vec4<f32> {
    return f.weight.x * delta_irradiance_table[f.index.x + k] + f.weight.y * delta_irradiance_table[f.index.y + k]
        + f.weight.z * delta_irradiance_table[f.index.z + k] + f.weight.w * delta_irradiance_table[f.index.w + k];
}

// Channel 0 of a red-only single Mie table: texel t at t (one vec4 per texel, from the CPU)
// or at t·groups (the full layout of the GPU precomputation).
fn mie_red_row(f: Filter4, row: u32) -> f32 {
    var g = atm.groups;
    if (frame.mie_layout == 1u) {
        g = 1u;
    }
    return f.wcol.x * scattering_b[(row + f.col.x) * g].x + f.wcol.y * scattering_b[(row + f.col.y) * g].x
        + f.wcol.z * scattering_b[(row + f.col.z) * g].x + f.wcol.w * scattering_b[(row + f.col.w) * g].x;
}

fn sample_mie_red(f: Filter4) -> f32 {
    return f.wrow.x * mie_red_row(f, f.row.x) + f.wrow.y * mie_red_row(f, f.row.y)
        + f.wrow.z * mie_red_row(f, f.row.z) + f.wrow.w * mie_red_row(f, f.row.w);
}

// Multiple scattering of channel group k at a 4D filter (Table4::sample_into on
// Tables::multiple), as sample_scattering_a does for slot a.
fn multiple_row(f: Filter4, row: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    return f.wcol.x * multiple_table[(row + f.col.x) * g + k] + f.wcol.y * multiple_table[(row + f.col.y) * g + k]
        + f.wcol.z * multiple_table[(row + f.col.z) * g + k] + f.wcol.w * multiple_table[(row + f.col.w) * g + k];
}

fn sample_multiple(f: Filter4, k: u32) -> vec4<f32> {
    return f.wrow.x * multiple_row(f, f.row.x, k) + f.wrow.y * multiple_row(f, f.row.y, k)
        + f.wrow.z * multiple_row(f, f.row.z, k) + f.wrow.w * multiple_row(f, f.row.w, k);
}

// Single molecular scattering plus multiple scattering divided by the molecular phase
// function (callers multiply by it), and single Mie, of channel group k (Sky::
// combined_scattering_sliced). `p_r` is max(P_molecules(ν), 1e-30). With red-only Mie, `red`
// is the channel-0 Mie sample and `scat0` the channel-0 combined scattering (multiple
// included, as the CPU's ratio rule takes it), known once group 0 has been read.
struct Combined {
    scattering: vec4<f32>,
    mie: vec4<f32>,
}

// The ratio rule of MieStorage::RedOnly: scat[k]·red/scat[0]·ratio[k].
fn mie_from_red(scattering: vec4<f32>, k: u32, red: f32, scat0: f32) -> vec4<f32> {
    var s0 = scat0;
    if (k == 0u) {
        s0 = scattering.x;
    }
    if (s0 > 0.0) {
        return scattering * red / s0 * channel_data[k * CHANNEL_STRIDE + 9u];
    }
    return vec4<f32>(0.0);
}

// From the 4D tables (Table4::sample_into).
fn combined_scattering(f: Filter4, k: u32, red: f32, scat0: f32, p_r: f32) -> Combined {
    var c: Combined;
    c.scattering = sample_scattering_a(f, k) + sample_multiple(f, k) / p_r;
    if (frame.mie_layout == 0u) {
        c.mie = sample_scattering_b(f, k);
    } else {
        c.mie = mie_from_red(c.scattering, k, red, scat0);
    }
    return c;
}

// The bilinear (ν, μ) filter of the camera slice (Table4::sample_slice_channels_into);
// indices are slice entries (y·N_ν + ν).
fn slice_filter(u_nu: f32, u_mu: f32) -> Filter2 {
    let nnu = atm.scattering_nu;
    let tex_x = u_nu * f32(nnu - 1u);
    let nu0 = min(u32(floor(max(tex_x, 0.0))), nnu - 1u);
    let nu1 = min(nu0 + 1u, nnu - 1u);
    let tnu = tex_x - f32(nu0);
    let ly = lerp_weights(u_mu, atm.scattering_mu);
    var f: Filter2;
    f.index = vec4<u32>(ly.i0 * nnu + nu0, ly.i0 * nnu + nu1, ly.i1 * nnu + nu0, ly.i1 * nnu + nu1);
    f.weight = vec4<f32>((1.0 - ly.t) * (1.0 - tnu), (1.0 - ly.t) * tnu, ly.t * (1.0 - tnu), ly.t * tnu);
    return f;
}

fn sample_slice(f: Filter2, offset: u32) -> vec4<f32> {
    let stride = 3u * atm.groups;
    return f.weight.x * slice_table[f.index.x * stride + offset] + f.weight.y * slice_table[f.index.y * stride + offset]
        + f.weight.z * slice_table[f.index.z * stride + offset] + f.weight.w * slice_table[f.index.w * stride + offset];
}

// From the camera slice.
fn combined_scattering_slice(f: Filter2, k: u32, red: f32, scat0: f32, p_r: f32) -> Combined {
    var c: Combined;
    c.scattering = sample_slice(f, k) + sample_slice(f, atm.groups + k) / p_r;
    if (frame.mie_layout == 0u) {
        c.mie = sample_slice(f, 2u * atm.groups + k);
    } else {
        c.mie = mie_from_red(c.scattering, k, red, scat0);
    }
    return c;
}

// The lookup at the ray's start: the camera slice when the camera is inside the atmosphere
// (every ray shares its (r, μ_s); Sky::slice gives the 4D lookup's values), the 4D tables
// otherwise.
struct StartLookup {
    sliced: bool,
    slice: Filter2,
    table: Filter4,
}

fn start_lookup(s: ViewStart, nu: f32, ground: bool) -> StartLookup {
    var l: StartLookup;
    l.sliced = s.sliced;
    if (s.sliced) {
        l.slice = slice_filter(u_nu_from_nu(s.mu, s.mu_s, nu), start_u_mu(s, ground));
    } else {
        let u_mu_s = texcoord_from_unit(x_mu_s(s.mu_s), atm.scattering_mu_s);
        let u_r = texcoord_from_unit(s.rho / atm.h, atm.scattering_r);
        l.table = scattering_filter(vec4<f32>(u_nu_from_nu(s.mu, s.mu_s, nu), u_mu_s, start_u_mu(s, ground), u_r));
    }
    return l;
}

fn start_combined(l: StartLookup, k: u32, red: f32, scat0: f32, p_r: f32) -> Combined {
    if (l.sliced) {
        return combined_scattering_slice(l.slice, k, red, scat0, p_r);
    }
    return combined_scattering(l.table, k, red, scat0, p_r);
}

fn start_mie_red(l: StartLookup) -> f32 {
    if (l.sliced) {
        return sample_slice(l.slice, 2u * atm.groups).x;
    }
    return sample_mie_red(l.table);
}

// params::scattering_u_mu at the start, the distance to the ground from its discriminant.
fn start_u_mu(s: ViewStart, ground: bool) -> f32 {
    if (!ground) {
        return scattering_u_mu(s.r, s.rho, s.mu, false);
    }
    let d = distance_to_ground(s);
    let d_min = s.rho * s.rho / (s.r + atm.bottom_radius);
    let d_max = s.rho;
    var x = 0.0;
    if (d_max != d_min) {
        x = sqrt(clamp((d - d_min) / (d_max - d_min), 0.0, 1.0));
    }
    return 0.5 - 0.5 * texcoord_from_unit(x, atm.scattering_mu / 2u);
}

// ---------------------------------------------------------------------------------------
// The sun's disk (render::add_sun_disk, sky::limb_darkening): x = sin(angle)/sin(α) from the
// cross product (accurate near the centre, where acos of a cosine near 1 is not in f32).

struct Disk {
    inside: bool,
    mu: f32,
}

fn sun_disk(dir: vec3<f32>) -> Disk {
    var disk: Disk;
    let sun = frame.sun.xyz;
    let sin_angle = length(cross(dir, sun));
    disk.inside = frame.sun_disk != 0u && dot(dir, sun) > 0.0 && sin_angle < frame.sun.w;
    let x = sin_angle / frame.sun.w;
    disk.mu = safe_sqrt(1.0 - x * x);
    return disk;
}

// Centre radiance × max(Σ a_j μ^j, 0) for channel group k.
fn sun_disk_radiance(mu: f32, k: u32) -> vec4<f32> {
    let base = k * CHANNEL_STRIDE + 3u;
    var s = vec4<f32>(0.0);
    var p = 1.0;
    for (var j = 0u; j < 6u; j++) {
        s += channel_data[base + j] * p;
        p *= mu;
    }
    return max(s, vec4<f32>(0.0));
}

// ColourMatrix::to_srgb of channel group k.
fn to_srgb(l: vec4<f32>, k: u32) -> vec3<f32> {
    let base = k * CHANNEL_STRIDE;
    return vec3<f32>(dot(channel_data[base], l), dot(channel_data[base + 1u], l), dot(channel_data[base + 2u], l));
}

// ---------------------------------------------------------------------------------------
// render::shade_sliced, summed to linear sRGB over the channel groups.

fn shade(dir: vec3<f32>) -> vec3<f32> {
    let sun = frame.sun.xyz;
    let nu = clamp_cosine(dot(dir, sun));
    let s = view_start(dir, nu);
    let disk = sun_disk(dir);
    var rgb = vec3<f32>(0.0);
    if (!s.in_atmosphere) {
        // Sky::sky_radiance of a ray that misses the atmosphere: no radiance, transmittance 1.
        if (disk.inside) {
            for (var k = 0u; k < atm.groups; k++) {
                rgb += to_srgb(sun_disk_radiance(disk.mu, k), k);
            }
        }
        return rgb;
    }
    let pr = group_phase(0u, nu);
    let pm = group_phase(1u, nu);
    // What multiple scattering is divided by (Sky::combined_scattering_sliced).
    let p_r = max(pr, 1e-30);
    // geometry::ray_intersects_ground with the start's discriminant.
    let ground = s.mu < 0.0 && s.disc_ground >= 0.0;
    let f = start_lookup(s, nu, ground);
    var red = 0.0;
    if (frame.mie_layout != 0u) {
        red = start_mie_red(f);
    }
    // ray_sphere(..).filter(near > 0): a camera on the ground (ρ = 0) sees no ground point.
    if (ground && s.rho > 0.0) {
        // The ground point: r = R_g, ρ = 0, zenith cosine −sqrt(r²μ² − ρ²)/R_g, and the sun's
        // zenith cosine there by the law of cosines.
        let d = distance_to_ground(s);
        let mu_p = clamp_cosine(-safe_sqrt(s.disc_ground) / atm.bottom_radius);
        let mu_s_p = clamp_cosine((s.r * s.mu_s + d * nu) / atm.bottom_radius);
        let f_p = scattering_filter(scattering_uvwz(atm.bottom_radius, 0.0, mu_p, mu_s_p, nu, true));
        var red_p = 0.0;
        if (frame.mie_layout != 0u) {
            red_p = sample_mie_red(f_p);
        }
        // Lookup::transmittance for a ground ray: e^{−(τ(R_g, −μ_p) − τ(r, −μ))}.
        let f_t_ground = transmittance_filter(atm.bottom_radius, 0.0, -mu_p);
        let f_t_camera = transmittance_filter(s.r, s.rho, -s.mu);
        // Sky::sun_and_sky_irradiance with the normal p/|p| (sky occlusion factor 1).
        let f_irradiance = table2_filter(irradiance_uv(0.0, mu_s_p), atm.irradiance_mu_s, atm.irradiance_r);
        let sun_fraction = sun_visible_fraction(atm.bottom_radius, 0.0, mu_s_p);
        let f_sun = transmittance_filter(atm.bottom_radius, 0.0, mu_s_p);
        let cos_sun = max(mu_s_p, 0.0);
        // Sky::sky_radiance_to_point: single Mie faded out below the horizon (Bruneton 2017).
        let fade = smoothstep_safe(0.0, 0.01, s.mu_s);
        var scat0 = 0.0;
        var scat0_p = 0.0;
        for (var k = 0u; k < atm.groups; k++) {
            let t = transmittance_between(sample_optical_depth(f_t_ground, k), sample_optical_depth(f_t_camera, k));
            let c = start_combined(f, k, red, scat0, p_r);
            let c_p = combined_scattering(f_p, k, red_p, scat0_p, p_r);
            if (k == 0u) {
                scat0 = c.scattering.x;
                scat0_p = c_p.scattering.x;
            }
            let in_scattered = max(c.scattering - t * c_p.scattering, vec4<f32>(0.0)) * pr
                + max(c.mie - t * c_p.mie, vec4<f32>(0.0)) * fade * pm;
            let e_sky = sample_irradiance(f_irradiance, k);
            var e_sun = vec4<f32>(0.0);
            if (sun_fraction > 0.0) {
                e_sun = sample_transmittance(f_sun, k) * sun_fraction * solar_irradiance(k) * cos_sun;
            }
            let l = in_scattered + ground_albedo(k) / PI * (e_sun + e_sky) * t;
            rgb += to_srgb(l, k);
        }
        return rgb;
    }
    // Sky::sky_radiance, with the transmittance to the top only for the sun's disk (0 for a
    // ray towards the ground).
    var f_t: Filter2;
    if (disk.inside) {
        f_t = transmittance_filter(s.r, s.rho, s.mu);
    }
    var scat0 = 0.0;
    for (var k = 0u; k < atm.groups; k++) {
        let c = start_combined(f, k, red, scat0, p_r);
        if (k == 0u) {
            scat0 = c.scattering.x;
        }
        var l = c.scattering * pr + c.mie * pm;
        if (disk.inside && !ground) {
            l += sun_disk_radiance(disk.mu, k) * sample_transmittance(f_t, k);
        }
        rgb += to_srgb(l, k);
    }
    return rgb;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= frame.rows * frame.width) {
        return;
    }
    let x = i % frame.width;
    let y = frame.first_row + i / frame.width;
    let ray = camera_ray(f32(x) + 0.5, f32(y) + 0.5);
    var out = vec4<f32>(0.0);
    if (ray.valid) {
        out = vec4<f32>(shade(ray.dir) * frame.balance.xyz, 1.0);
    }
    frame_out[i] = out;
}

// The camera slice for this frame (Sky::slice: Table4::slice of the single, multiple and
// single Mie tables at (u_μs, u_r) of the camera): one invocation per (μ, ν) entry and
// channel group.
@compute @workgroup_size(64)
fn camera_slice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= atm.scattering_mu * atm.scattering_nu) {
        return;
    }
    let k = gid.z;
    let g = atm.groups;
    let y = i / atm.scattering_nu;
    let nu = i % atm.scattering_nu;
    let ls = lerp_weights(frame.slice_u_mu_s, atm.scattering_mu_s);
    let lz = lerp_weights(frame.slice_u_r, atm.scattering_r);
    let width = scattering_width();
    // Texels (z_a, s_b) with weights wz·ws, as Table4::slice sums them.
    let rows = (vec4<u32>(lz.i0, lz.i0, lz.i1, lz.i1) * atm.scattering_mu + y) * width;
    let texels = rows + nu * atm.scattering_mu_s + vec4<u32>(ls.i0, ls.i1, ls.i0, ls.i1);
    let w = vec4<f32>(1.0 - lz.t, 1.0 - lz.t, lz.t, lz.t) * vec4<f32>(1.0 - ls.t, ls.t, 1.0 - ls.t, ls.t);
    let scattering = w.x * scattering_a[texels.x * g + k] + w.y * scattering_a[texels.y * g + k]
        + w.z * scattering_a[texels.z * g + k] + w.w * scattering_a[texels.w * g + k];
    let multiple = w.x * multiple_table[texels.x * g + k] + w.y * multiple_table[texels.y * g + k]
        + w.z * multiple_table[texels.z * g + k] + w.w * multiple_table[texels.w * g + k];
    var mie = vec4<f32>(0.0);
    if (frame.mie_layout == 0u) {
        mie = w.x * scattering_b[texels.x * g + k] + w.y * scattering_b[texels.y * g + k]
            + w.z * scattering_b[texels.z * g + k] + w.w * scattering_b[texels.w * g + k];
    } else if (k == 0u) {
        var gm = g;
        if (frame.mie_layout == 1u) {
            gm = 1u;
        }
        mie.x = w.x * scattering_b[texels.x * gm].x + w.y * scattering_b[texels.y * gm].x
            + w.z * scattering_b[texels.z * gm].x + w.w * scattering_b[texels.w * gm].x;
    }
    slice_table[i * 3u * g + k] = scattering;
    slice_table[i * 3u * g + g + k] = multiple;
    slice_table[i * 3u * g + 2u * g + k] = mie;
}
