// The 3D tables (firmament::sky::elek3d::table::Table3): trilinear filtering with GPU texture
// semantics (texel i's centre at (i + 0.5)/n, clamp to edge; table.wgsl's lerp_weights), by
// hand on storage buffers of vec4<f32>: texel t = (z·N_μ + y)·N_μs + x (altitude z, view
// zenith y, sun zenith x; the CPU's order), channel group k at t·groups + k.
//
// The tables are bound at the 4D tables' slots (lookup.wgsl declares 5 and 6):
//   5 scattering_a   single Rayleigh without its phase function (Elek3d::single_rayleigh)
//   6 scattering_b   single Mie without its phase function (Elek3d::single_mie)
//   7 multiple_table orders ≥ 2 as radiance (Elek3d::multiple)

@group(0) @binding(7) var<storage, read> multiple_table: array<vec4<f32>>;

// Table3::taps: the eight texels (indices without the group) and weights of a trilinear
// lookup, computed once for the three tables. Lanes (y0 x0, y0 x1, y1 x0, y1 x1) at the lower
// altitude texel in `index0`/`weight0`, at the upper one in `index1`/`weight1`. Vectors, not
// arrays: no dynamically indexed private memory.
struct Taps3 {
    index0: vec4<u32>,
    index1: vec4<u32>,
    weight0: vec4<f32>,
    weight1: vec4<f32>,
}

// Table3::taps at texture coordinates u = (u_h, u_μ, u_μs).
fn table3_taps(u: vec3<f32>) -> Taps3 {
    let lz = lerp_weights(u.x, elek3d.nh);
    let ly = lerp_weights(u.y, elek3d.nmu);
    let lx = lerp_weights(u.z, elek3d.nmu_s);
    let y = vec4<u32>(ly.i0, ly.i0, ly.i1, ly.i1);
    let x = vec4<u32>(lx.i0, lx.i1, lx.i0, lx.i1);
    let wyx = vec4<f32>(1.0 - ly.t, 1.0 - ly.t, ly.t, ly.t) * vec4<f32>(1.0 - lx.t, lx.t, 1.0 - lx.t, lx.t);
    var t: Taps3;
    t.index0 = (lz.i0 * elek3d.nmu + y) * elek3d.nmu_s + x;
    t.index1 = (lz.i1 * elek3d.nmu + y) * elek3d.nmu_s + x;
    t.weight0 = (1.0 - lz.t) * wyx;
    t.weight1 = lz.t * wyx;
    return t;
}

// The three tables at one lookup, channel group k: phase-free single Rayleigh and Mie, and
// the multiple scattering (radiance).
struct Scattering3 {
    rayleigh: vec4<f32>,
    mie: vec4<f32>,
    multiple: vec4<f32>,
}

fn sample_rayleigh3(i0: vec4<u32>, i1: vec4<u32>, w0: vec4<f32>, w1: vec4<f32>) -> vec4<f32> {
    return w0.x * scattering_a[i0.x] + w0.y * scattering_a[i0.y] + w0.z * scattering_a[i0.z] + w0.w * scattering_a[i0.w]
        + w1.x * scattering_a[i1.x] + w1.y * scattering_a[i1.y] + w1.z * scattering_a[i1.z] + w1.w * scattering_a[i1.w];
}

fn sample_mie3(i0: vec4<u32>, i1: vec4<u32>, w0: vec4<f32>, w1: vec4<f32>) -> vec4<f32> {
    return w0.x * scattering_b[i0.x] + w0.y * scattering_b[i0.y] + w0.z * scattering_b[i0.z] + w0.w * scattering_b[i0.w]
        + w1.x * scattering_b[i1.x] + w1.y * scattering_b[i1.y] + w1.z * scattering_b[i1.z] + w1.w * scattering_b[i1.w];
}

fn sample_multiple3(i0: vec4<u32>, i1: vec4<u32>, w0: vec4<f32>, w1: vec4<f32>) -> vec4<f32> {
    return w0.x * multiple_table[i0.x] + w0.y * multiple_table[i0.y] + w0.z * multiple_table[i0.z] + w0.w * multiple_table[i0.w]
        + w1.x * multiple_table[i1.x] + w1.y * multiple_table[i1.y] + w1.z * multiple_table[i1.z] + w1.w * multiple_table[i1.w];
}

// Table3::sample_taps_into on the three tables, channel group k.
fn table3_sample(t: Taps3, k: u32) -> Scattering3 {
    let g = atm.groups;
    let i0 = t.index0 * g + k;
    let i1 = t.index1 * g + k;
    var s: Scattering3;
    s.rayleigh = sample_rayleigh3(i0, i1, t.weight0, t.weight1);
    s.mie = sample_mie3(i0, i1, t.weight0, t.weight1);
    s.multiple = sample_multiple3(i0, i1, t.weight0, t.weight1);
    return s;
}

// Table3::slice for one view-zenith texel y: the three tables filtered at fixed (u_h, u_μs),
// channel group k (the per-view cache, view.wgsl's `camera_slice`).
fn table3_slice(u_h: f32, u_mu_s: f32, y: u32, k: u32) -> Scattering3 {
    let lz = lerp_weights(u_h, elek3d.nh);
    let lx = lerp_weights(u_mu_s, elek3d.nmu_s);
    let z = vec4<u32>(lz.i0, lz.i0, lz.i1, lz.i1);
    let x = vec4<u32>(lx.i0, lx.i1, lx.i0, lx.i1);
    let w = vec4<f32>(1.0 - lz.t, 1.0 - lz.t, lz.t, lz.t) * vec4<f32>(1.0 - lx.t, lx.t, 1.0 - lx.t, lx.t);
    let i = ((z * elek3d.nmu + y) * elek3d.nmu_s + x) * atm.groups + k;
    let none = vec4<f32>(0.0);
    let zero = vec4<u32>(0u);
    var s: Scattering3;
    s.rayleigh = sample_rayleigh3(i, zero, w, none);
    s.mie = sample_mie3(i, zero, w, none);
    s.multiple = sample_multiple3(i, zero, w, none);
    return s;
}
