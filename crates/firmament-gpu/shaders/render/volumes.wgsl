// The clouds in front of what a ray sees (firmament::render::volumes): a ray march with the
// energy-conserving step of Hillaire 2016 (§5.6.3: ∫₀^d S·e^{−σ_t s} ds = (S − S·e^{−σ_t d})/σ_t),
// every sample lit by each light through the air (the sky method's transmittance) and the
// layers (the march towards the light), multiple scattering by the layer's two-stream (the
// δ-scaled diffuse light in octave slot 1) or by Wrenninge's octaves with the ambient light
// from above and below; steps at the layers' feature size growing with distance (crossing
// the thinnest layer in at least VERTICAL_STEPS), leaps
// where the weather leaves no room for cloud, and the composition at the transmittance-
// weighted mean depth d̄: L = S_air(0 → d̄) + T_air(d̄)·L_vol + T_vol·(L_behind − S_air(0 → d̄)).
// The layers are grey, so the composition holds in linear sRGB. Unlike the CPU, the air's
// light at a sample is looked up at every sample (the CPU reuses it within 250 m).

// The most steps of one march (a guard: a grazing ray across 300 km takes ~1 000).
const MAX_MARCH_STEPS: u32 = 8192u;

// ∫₀^dt S·e^{−σs} ds (volumes::step_integral), `step_t` being e^{−σ·dt}.
fn step_integral(source: vec4<f32>, sigma: f32, dt: f32, step_t: f32) -> vec4<f32> {
    if (sigma > 0.0) {
        return (source - source * step_t) / sigma;
    }
    return source * dt;
}

// A jitter in [0, 1) from the ray's direction (volumes::ray_jitter, over f32 bits).
fn ray_jitter(dir: vec3<f32>) -> f32 {
    let h = lowbias32(bitcast<u32>(dir.x) ^ lowbias32(bitcast<u32>(dir.y) ^ lowbias32(bitcast<u32>(dir.z))));
    return f32(h >> 8u) / 16777216.0;
}

// The clouds' extinction (m⁻¹) at a point and the layer holding it (layers never overlap).
struct CloudSample {
    sigma_t: f32,
    layer: u32,
}

fn cloud_sample(p: CloudPoint) -> CloudSample {
    var s: CloudSample;
    s.sigma_t = 0.0;
    for (var i = 0u; i < clouds.layers; i++) {
        let d = cloud_layer_density(i, p, true);
        if (d > 0.0) {
            s.sigma_t = clouds.layer[i].extinction_per_m * d;
            s.layer = i;
            return s;
        }
    }
    return s;
}

fn clouds_surely_empty(p: CloudPoint) -> bool {
    for (var i = 0u; i < clouds.layers; i++) {
        if (!layer_surely_empty(i, p)) {
            return false;
        }
    }
    return true;
}

// The layers' stretch along the ray: (first entry, last exit), x > y when none.
fn clouds_bounds(q: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    var out = vec2<f32>(3.4e38, -1.0);
    for (var i = 0u; i < clouds.layers; i++) {
        let s = layer_segments(i, q, dir);
        if (s.n > 0u) {
            out.x = min(out.x, s.s[0].x);
            out.y = max(out.y, s.s[s.n - 1u].y);
        }
    }
    return out;
}

// Per light, the grey part of a sample's lighting: the layers' optical depth towards it,
// the cosine of its zenith angle, and the air's light at the sample and at the ground below.
struct SampleLight {
    tau: f32,
    mu: f32,
    at: PointLight,
    ground: PointLight,
    diffuse: DiffuseLight,
}

// The in-scattered source of octave m at a sample of layer i for channel group k
// (volumes::light_sources), summed over the lights; octave slot 1 of a two-stream layer is
// its diffuse light. `depths`: the sample's vertical optical depths in the layer.
fn light_sources(i: u32, sigma_t: f32, dir: vec3<f32>, p: CloudPoint, depths: vec2<f32>, sl: ptr<function, array<SampleLight, MAX_LIGHTS>>, k: u32, src: ptr<function, array<vec4<f32>, MAX_OCTAVES>>) {
    let l = clouds.layer[i];
    for (var m = 0u; m < MAX_OCTAVES; m++) {
        (*src)[m] = vec4<f32>(0.0);
    }
    let ss = sigma_t * l.albedo;
    let albedo = ground_albedo(k);
    for (var j = 0u; j < frame.lights; j++) {
        let vl = view_light(j);
        let s = (*sl)[j];
        let e_light = light_irradiance(j, k);
        let scale = light_scale(j, k);
        let t_light = sample_transmittance(s.at.to_light, k) * s.at.fraction;
        let sky = point_irradiance(s.at, k).sky * scale;
        let ge = point_irradiance(s.ground, k);
        let ground_direct = ge.direct * e_light;
        let ground_sky = ge.sky * scale;
        let cos = dot(dir, vl.direction);
        var gain_s = 1.0;
        var gain_t = 1.0;
        var gain_g = 1.0;
        for (var m = 0u; m < min(l.octaves, MAX_OCTAVES); m++) {
            let p = phase_eval(5u, 0u, 0u, l.g1 * gain_g, l.g2 * gain_g, l.weight, cos);
            (*src)[m] += gain_s * ss * p * e_light * t_light * exp(-gain_t * s.tau);
            gain_s *= l.octave_scattering;
            gain_t *= l.octave_extinction;
            gain_g *= l.octave_eccentricity;
        }
        if (l.two_stream_at != NONE) {
            let f = s.diffuse;
            let beam = e_light * t_light;
            let ground = (ground_direct * f.base_direct + beam * f.base_from_light + ground_sky * f.base_from_above)
                / (1.0 - albedo * f.base_reflectance);
            let i0 = f.from_light.x * beam + f.from_above.x * sky + f.from_below.x * albedo * ground;
            let i1 = f.from_light.y * beam + f.from_above.y * sky + f.from_below.y * albedo * ground;
            let towards_eye = -dot(dir, p.up);
            let radiance = max(i0 + f.asymmetry * i1 * towards_eye, vec4<f32>(0.0));
            // The beam's light in the forward peak (δ-scaled minus unscattered), scattered
            // towards the eye with the phase the δ-scaling keeps.
            let peak = forward_peak(l.ts_extinction_scale, s.tau);
            let p_kept = min(phase_eval(5u, 0u, 0u, l.g1, l.g2, l.weight, cos), l.ts_forward_cap);
            (*src)[1] += ss * (f.scattering_scale * radiance + p_kept * beam * peak);
        } else {
            let one_minus_g = 1.0 - l.mean_cosine;
            let w_sky = 1.0 / (1.0 + one_minus_g * depths.x);
            let w_ground = 1.0 / (1.0 + one_minus_g * depths.y);
            let ground = albedo * (ground_direct + ground_sky);
            (*src)[0] += ss * (w_sky * sky + w_ground * ground) / (2.0 * PI);
        }
    }
}

// The result of a march: the clouds' light per channel group (before the air in front),
// their transmittance (octave 0) and mean depth (m; < 0 when the ray met no cloud).
struct CloudMarch {
    t_vol: f32,
    depth_m: f32,
}

// volumes::composite's march along the ray from local `q` in `dir` before `end_m`; the
// clouds' light per group into `l_vol`.
fn march_clouds(q: vec3<f32>, dir: vec3<f32>, end_m: f32, l_vol: ptr<function, array<vec4<f32>, MAX_CHANNEL_GROUPS>>) -> CloudMarch {
    var out: CloudMarch;
    out.t_vol = 1.0;
    out.depth_m = -1.0;
    for (var k = 0u; k < atm.groups; k++) {
        (*l_vol)[k] = vec4<f32>(0.0);
    }
    let bounds = clouds_bounds(q, dir);
    let a = bounds.x;
    let b = min(bounds.y, end_m);
    if (!(b > a)) {
        return out;
    }
    let jitter = ray_jitter(dir);
    let count = min(clouds.octave_count, MAX_OCTAVES);
    var t_m: array<f32, MAX_OCTAVES>;
    for (var m = 0u; m < MAX_OCTAVES; m++) {
        t_m[m] = 1.0;
    }
    var depth_sum = 0.0;
    var weight_sum = 0.0;
    var t = a;
    var empty_run = 0u;
    var sl: array<SampleLight, MAX_LIGHTS>;
    var src: array<vec4<f32>, MAX_OCTAVES>;
    // Where each light's air light (the sky method's transmittance to it and irradiances,
    // which vary over kilometres) was last looked up, reused within AIR_LIGHT_REUSE_M of
    // it for the first CACHED_LIGHTS lights, as the CPU's march does.
    var air_at: array<vec3<f32>, MAX_LIGHTS>;
    var air_kept = 0u;
    for (var guard = 0u; guard < MAX_MARCH_STEPS && t < b; guard++) {
        // The feature's step growing with distance, but crossing the thinnest layer in at
        // least VERTICAL_STEPS however far (volumes::composite's step_at, at t).
        let at_t = q + t * dir;
        let mu = dot(dir, normalize(vec3<f32>(at_t.xy, clouds.planet_radius_m + at_t.z)));
        let vertical = max(clouds.thinnest_m / (VERTICAL_STEPS * max(abs(mu), 1e-3)), clouds.feature_m);
        let dt = min(min(max(FEATURE_STEPS * clouds.feature_m, STEP_DISTANCE_FRACTION * t), vertical), b - t);
        let x = q + (t + jitter * dt) * dir;
        let p = cloud_point(x);
        let c = cloud_sample(p);
        if (c.sigma_t == 0.0) {
            empty_run += 1u;
            if (empty_run >= EMPTY_BEFORE_LEAP) {
                // Leap where no layer can have cloud at either end (a bound that ignores the
                // fine noise, so the leaps do not depend on the jitter).
                let leap = LEAP_STEPS * dt;
                // (Both ends through one call site: each site inlines the layers' weather.)
                let probe = cloud_point(q + (t + leap + jitter * dt) * dir);
                var empty = t + leap < b;
                for (var end = 0u; end < 2u && empty; end++) {
                    var at = p;
                    if (end == 1u) {
                        at = probe;
                    }
                    empty = clouds_surely_empty(at);
                }
                if (empty) {
                    t += leap;
                    continue;
                }
            }
            t += dt;
            continue;
        }
        empty_run = 0u;
        let i = c.layer;
        // The sample's altitude above the tables' ground.
        let alt_km = (p.alt_m - clouds.lift_m) * 1e-3;
        // The sample's vertical optical depths in its layer (the ambient light's and the
        // two-stream's slab), once for every light and channel group.
        let depths = vertical_optical_depths(i, p);
        for (var j = 0u; j < frame.lights; j++) {
            let vl = view_light(j);
            sl[j].tau = light_optical_depth(x, vl.direction);
            sl[j].mu = dot(vl.direction, p.up);
            let d = x - air_at[j];
            let kept = j < CACHED_LIGHTS && (air_kept & (1u << j)) != 0u;
            if (!(kept && dot(d, d) < AIR_LIGHT_REUSE_M * AIR_LIGHT_REUSE_M)) {
                sl[j].at = point_light(vl, alt_km, p.up, p.up);
                sl[j].ground = point_light(vl, 0.0, p.up, p.up);
                air_at[j] = x;
                air_kept |= 1u << min(j, 31u);
            }
            if (clouds.layer[i].two_stream_at != NONE) {
                sl[j].diffuse = diffuse_radiance(i, depths, sl[j].mu, sl[j].tau);
            }
        }
        // Each octave's step transmittance (grey).
        var step_t: array<f32, MAX_OCTAVES>;
        var sigma: array<f32, MAX_OCTAVES>;
        var gain_t = 1.0;
        for (var m = 0u; m < count; m++) {
            sigma[m] = gain_t * c.sigma_t;
            step_t[m] = exp(-sigma[m] * dt);
            gain_t *= clouds.octave_extinction;
        }
        for (var k = 0u; k < atm.groups; k++) {
            light_sources(i, c.sigma_t, dir, p, depths, &sl, k, &src);
            for (var m = 0u; m < count; m++) {
                (*l_vol)[k] += t_m[m] * step_integral(src[m], sigma[m], dt, step_t[m]);
            }
        }
        let opacity = t_m[0] * (1.0 - step_t[0]);
        var opaque = true;
        for (var m = 0u; m < count; m++) {
            t_m[m] *= step_t[m];
            opaque = opaque && t_m[m] < OPAQUE_TRANSMITTANCE;
        }
        depth_sum += opacity * (t + 0.5 * dt);
        weight_sum += opacity;
        if (opaque) {
            break;
        }
        t += dt;
    }
    if (weight_sum > 0.0) {
        out.depth_m = depth_sum / weight_sum;
        out.t_vol = t_m[0];
    }
    return out;
}

// volumes::dim_surface_light for a ground point at local `x` with vertical `up` and unit
// `normal` under light j: the direct beam dimmed by the layers' transmittance towards the
// light (from the shadow map where it covers the point, else the march), the beam they
// scatter forward added to the sky's light as diffuse (on a tilted surface by
// (1 + n·up)/2, like the sky's), the sky's light dimmed by them, and the ground–cloud
// interreflection. `t_air` is the air's transmittance to the light.
struct SurfaceLight {
    direct: vec4<f32>,
    sky: vec4<f32>,
}

fn dim_surface_light(j: u32, x: vec3<f32>, up: vec3<f32>, normal: vec3<f32>, light_dir: vec3<f32>, k: u32, t_air: vec4<f32>, e_in: SurfaceLight) -> SurfaceLight {
    let mu = dot(light_dir, up);
    let mapped = map_disk_optical_depth(j, x, light_dir, lights.direction[j].w);
    let p = cloud_point(x);
    let albedo = ground_albedo(k);
    var beam = 1.0;
    var sky_factor = 1.0;
    var diffuse = 0.0;
    var bounce = vec4<f32>(1.0);
    for (var i = 0u; i < clouds.layers; i++) {
        let crosses = layer_segments(i, x, light_dir).n > 0u;
        let over = layer_segments(i, x, up).n > 0u;
        if (!crosses && !over) {
            continue;
        }
        let l = clouds.layer[i];
        let two_stream = l.two_stream_at != NONE;
        let under = p.alt_m < l.bottom_m;
        // The layer's depth towards the light (unless the map covers the point) and up its
        // column (for octaves; for the two-stream under the layer, up the radial vertical):
        // both marches through one call site (each site inlines the layer's density).
        var taus = vec2<f32>(0.0);
        for (var s = 0u; s < 2u; s++) {
            let needed = select(crosses && mapped < 0.0, select(over, under, two_stream), s == 1u);
            if (needed) {
                let vertical = select(up, p.up, two_stream);
                taus[s] = layer_light_optical_depth(i, x, select(light_dir, vertical, s == 1u));
            }
        }
        var tau_l = taus.x;
        if (mapped >= 0.0) {
            tau_l = mapped / f32(clouds.layers);
        }
        let unscattered = exp(-tau_l);
        var through: f32;
        var from_beam: f32;
        if (two_stream) {
            // The point's vertical depths in the layer: under it, its whole column above.
            let above = p.alt_m > l.top_m;
            var depths = vec2<f32>(taus.y, 0.0);
            if (!under && !above) {
                depths = vertical_optical_depths(i, p);
            }
            var f = diffuse_above(i);
            if (!above) {
                f = diffuse_radiance(i, depths, mu, tau_l);
            }
            bounce /= 1.0 - albedo * f.base_reflectance;
            through = f.base_from_above;
            from_beam = f.base_from_light;
        } else {
            let total = 1.0 / (1.0 + (1.0 - l.mean_cosine) * taus.y);
            through = total;
            from_beam = max(mu, 0.0) * max(total - unscattered, 0.0);
        }
        diffuse = diffuse * through + beam * from_beam;
        sky_factor *= through;
        beam *= unscattered;
    }
    var out: SurfaceLight;
    out.direct = e_in.direct * beam;
    let open = 0.5 * (1.0 + dot(normal, up));
    out.sky = e_in.sky * sky_factor + light_irradiance(j, k) * t_air * (diffuse * open);
    out.sky += (bounce - 1.0) * (out.direct + out.sky);
    return out;
}
