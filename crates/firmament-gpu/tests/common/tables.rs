//! Hillaire 2020's tables compared texel by texel (`hillaire2020_parity.rs`).
//!
//! Tolerances: the same f64 computation rounded to f32 at the end (CPU) against f32
//! throughout (GPU). The largest sums are the multiple-scattering gather (64 rays of 20
//! steps) and the irradiance (32 rays of 16 steps, each reading Ψ_ms): each step's
//! exp/smoothstep/bilinear weights carry ~1e-7 relative, and the (r, μ) of a step ~1e-7 of
//! planet-scale lengths, which moves a lookup near the horizon (where τ and the light's
//! visible fraction change fastest) by up to ~1e-4; hence a median of 1e-3 and a largest of
//! 1e-2, relative to each value (values below 1e-6 of the table's largest compared
//! absolutely against that floor).

use firmament::sky::bruneton4d::Table2;

pub const TABLE_MEDIAN: f64 = 1e-3;
pub const TABLE_MAX: f64 = 1e-2;

/// The relative differences of `gpu` against `cpu` texel by texel and channel by channel:
/// median and largest, printed with the worst texel. Values under 1e-6 of the table's
/// largest are compared against that floor; with `channels` < the values per texel (Ψ_ms's
/// harmonics, `channels` per coefficient), those under 1e-4 of their texel's degree-0
/// coefficient against it (the coefficients a field symmetric about the zenith leaves
/// at 0 come out as f32 cancellation, ~1e-7 of the field).
pub fn compare_tables(name: &str, cpu: &Table2, gpu: &Table2, channels: usize) -> (f64, f64) {
    assert_eq!(
        (cpu.width, cpu.height, cpu.channels),
        (gpu.width, gpu.height, gpu.channels),
        "{name}: sizes"
    );
    let max = cpu.data.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let floor = (max * 1e-6).max(f64::MIN_POSITIVE);
    let per_texel = cpu.channels;
    let degree0 = |i: usize| cpu.data[i / per_texel * per_texel + i % channels].abs() as f64;
    let mut rel: Vec<(f64, usize)> = (cpu.data.iter().zip(&gpu.data).enumerate())
        .map(|(i, (&c, &g))| {
            assert!(g.is_finite(), "{name}: non-finite GPU value at {i}");
            let mut f = floor;
            if channels < per_texel {
                f = f.max(1e-4 * degree0(i));
            }
            ((g as f64 - c as f64).abs() / (c.abs() as f64).max(f), i)
        })
        .collect();
    rel.sort_by(|a, b| a.0.total_cmp(&b.0));
    let median = rel[rel.len() / 2].0;
    let (worst, at) = rel[rel.len() - 1];
    let texel = at / per_texel;
    eprintln!(
        "{name}: {}×{}×{per_texel}: median rel {median:.2e}, max rel {worst:.2e} at texel ({}, {}) value {} cpu {:e} gpu {:e}",
        cpu.width,
        cpu.height,
        texel % cpu.width,
        texel / cpu.width,
        at % per_texel,
        cpu.data[at],
        gpu.data[at],
    );
    (median, worst)
}

pub fn assert_tables(name: &str, cpu: &Table2, gpu: &Table2, channels: usize) {
    let (median, max) = compare_tables(name, cpu, gpu, channels);
    assert!(median <= TABLE_MEDIAN, "{name}: median {median:e}");
    assert!(max <= TABLE_MAX, "{name}: max {max:e}");
}
