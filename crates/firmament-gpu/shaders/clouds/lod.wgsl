// The clouds' density filtered over a pixel's footprint (firmament::scene::clouds::lod): the
// noise's mean density given the weather (MeanDensity: a table [type MEAN_TYPES][coverage
// MEAN_COVERAGES][height MEAN_HEIGHTS] then χ [type][coverage], in cloud_data from a layer's
// `mean_at`), blended with the noise's density by the footprint's size in noise cells.

// lod::filter_weight: how much of the mean replaces the noise at a footprint of
// `footprint_m` over cells of `cell_m`: 0 below FILTER_START_CELLS, 1 from FILTER_END_CELLS.
fn filter_weight(footprint_m: f32, cell_m: f32) -> f32 {
    return smoothstep(FILTER_START_CELLS * cell_m, FILTER_END_CELLS * cell_m, footprint_m);
}

// A table axis of `n` nodes over [0, 1] at `v`: the lower node and the fraction beyond it.
fn mean_axis(v: f32, n: u32) -> vec2<f32> {
    let f = clamp(v, 0.0, 1.0) * f32(n - 1u);
    let i = min(floor(f), f32(n - 2u));
    return vec2<f32>(i, f - i);
}

// MeanDensity::effective of the table at `at`: the mean density at (h, c, t), trilinear
// (MeanDensity::sample), times χ(c, t), bilinear.
fn mean_effective(at: u32, h: f32, c: f32, t: f32) -> f32 {
    let ah = mean_axis(h, MEAN_HEIGHTS);
    let ac = mean_axis(c, MEAN_COVERAGES);
    let ak = mean_axis(t, MEAN_TYPES);
    let ih = u32(ah.x);
    let ic = u32(ac.x);
    let it = u32(ak.x);
    var mean = 0.0;
    var chi = 0.0;
    for (var dt = 0u; dt < 2u; dt++) {
        let wt = select(1.0 - ak.y, ak.y, dt == 1u);
        for (var dc = 0u; dc < 2u; dc++) {
            let wc = select(1.0 - ac.y, ac.y, dc == 1u);
            let row = (it + dt) * MEAN_COVERAGES + ic + dc;
            let cell = at + row * MEAN_HEIGHTS + ih;
            mean += wt * wc * mix(cloud_data[cell], cloud_data[cell + 1u], ah.y);
            chi += wt * wc * cloud_data[at + MEAN_TYPES * MEAN_COVERAGES * MEAN_HEIGHTS + row];
        }
    }
    return mean * chi;
}
