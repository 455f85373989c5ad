// Filtering with GPU texture semantics (firmament::sky::bruneton4d::table), done by hand on
// storage buffers so the weights are exact f32 (hardware samplers quantise them). Tables are
// storage buffers of vec4<f32>: channel group k (wavelengths 4k..4k+3) of texel i at index
// i·groups + k, texels in the CPU order (the host drops the padding lanes).

// (i0, i1, t) of linear filtering at texture coordinate u over n texels (clamp to edge).
struct Lerp {
    i0: u32,
    i1: u32,
    t: f32,
}

fn lerp_weights(u: f32, n: u32) -> Lerp {
    let x = clamp(u * f32(n) - 0.5, 0.0, f32(n - 1u));
    var l: Lerp;
    l.i0 = min(u32(floor(x)), n - 1u);
    l.i1 = min(l.i0 + 1u, n - 1u);
    l.t = x - f32(l.i0);
    return l;
}

// The 16 texels and weights of a 4D scattering lookup (Table4::sample_rows_into). Texel
// (i, j) is row[i] + col[j]: rows are the (r, μ) pairs (z0 y0, z0 y1, z1 y0, z1 y1), columns
// the (ν, μ_s) pairs (ν0 s0, ν0 s1, ν1 s0, ν1 s1). A lookup blends each row's ν columns along
// μ_s (linearly by mu_s.t, or in a twilight cell by mu_s_blend.wgsl with their outer
// neighbours colb (ν0, ν1 at the sample below s0) and cola (above s1)), then each (μ, ν)
// texel along r (r_blend.wgsl, filter r), then bilinearly by wy and wnu. wrow·wcol are the
// plain trilinear weights (Bruneton's), which the precomputation's ΔJ lookups keep. Vectors,
// not arrays: no dynamically indexed private memory (slow on software rasterisers).
struct Filter4 {
    row: vec4<u32>,
    col: vec4<u32>,
    wrow: vec4<f32>,
    wcol: vec4<f32>,
    mu_s: MuSFilter,
    colb: vec2<u32>,
    cola: vec2<u32>,
    wnu: vec2<f32>,
    wy: vec2<f32>,
    r: RFilter,
}

fn scattering_filter_rows(u_nu: f32, u_mu_s: f32, ly: Lerp, r: RFilter) -> Filter4 {
    let nnu = atm.scattering_nu;
    let nmu_s = atm.scattering_mu_s;
    let tex_x = u_nu * f32(nnu - 1u);
    let nu0 = min(u32(floor(tex_x)), nnu - 1u);
    let nu1 = min(nu0 + 1u, nnu - 1u);
    let tnu = tex_x - f32(nu0);
    let m = mu_s_filter(u_mu_s, nmu_s, atm.mu_s_twilight_cells);
    var ls: Lerp;
    ls.i0 = m.s0;
    ls.i1 = m.s1;
    ls.t = m.t;
    let width = scattering_width();
    let z = vec4<u32>(r.z0, r.z0, r.z1, r.z1);
    let y = vec4<u32>(ly.i0, ly.i1, ly.i0, ly.i1);
    let n = vec4<u32>(nu0, nu0, nu1, nu1);
    let ms = vec4<u32>(ls.i0, ls.i1, ls.i0, ls.i1);
    var f: Filter4;
    f.row = (z * atm.scattering_mu + y) * width;
    f.col = n * nmu_s + ms;
    f.wrow = vec4<f32>(1.0 - r.t, 1.0 - r.t, r.t, r.t) * vec4<f32>(1.0 - ly.t, ly.t, 1.0 - ly.t, ly.t);
    f.wcol = vec4<f32>(1.0 - tnu, 1.0 - tnu, tnu, tnu) * vec4<f32>(1.0 - ls.t, ls.t, 1.0 - ls.t, ls.t);
    f.mu_s = m;
    f.colb = vec2<u32>(nu0, nu1) * nmu_s + m.below;
    f.cola = vec2<u32>(nu0, nu1) * nmu_s + m.above;
    f.wnu = vec2<f32>(1.0 - tnu, tnu);
    f.wy = vec2<f32>(1.0 - ly.t, ly.t);
    f.r = r;
    return f;
}

fn scattering_filter(uvwz: vec4<f32>) -> Filter4 {
    return scattering_filter_rows(uvwz.x, uvwz.y, lerp_weights(uvwz.z, atm.scattering_mu), r_filter(uvwz.w, atm.scattering_r));
}

// Bilinear filter of a 2D table: the four texels (vec4 indices without the group) and weights.
struct Filter2 {
    index: vec4<u32>,
    weight: vec4<f32>,
}

fn table2_filter(uv: vec2<f32>, width: u32, height: u32) -> Filter2 {
    let lx = lerp_weights(uv.x, width);
    let ly = lerp_weights(uv.y, height);
    var f: Filter2;
    f.index = vec4<u32>(ly.i0 * width + lx.i0, ly.i0 * width + lx.i1, ly.i1 * width + lx.i0, ly.i1 * width + lx.i1) * atm.groups;
    f.weight = vec4<f32>((1.0 - lx.t) * (1.0 - ly.t), lx.t * (1.0 - ly.t), (1.0 - lx.t) * ly.t, lx.t * ly.t);
    return f;
}
