//! What `firmament bench` reports: one object whose fields are the keys of `--json` (and of
//! the `key: value` lines of the text output). Every key is always there, `null` when it was
//! not measured; the groups measured together are flattened into the one object. Printed
//! through [`serde_json::Value`], whose map keeps the keys in alphabetical order.

use std::collections::BTreeMap;

use serde::Serialize;

/// The whole report.
#[derive(Serialize, Debug)]
pub struct BenchReport {
    /// The machine the figures were taken on.
    pub machine: Machine,
    /// `--runs`: repetitions per CPU measurement.
    pub runs: usize,
    #[serde(flatten)]
    pub cpu_precompute: CpuPrecompute,
    #[serde(flatten)]
    pub cpu_frames: CpuFrames,
    #[serde(flatten)]
    pub cpu_reference: CpuReference,
    #[serde(flatten)]
    pub cpu_methods: CpuMethods,
    /// Why the GPU was not measured; `null` when it was.
    pub gpu_skipped: Option<String>,
    #[serde(flatten)]
    pub gpu: GpuTimings,
    #[serde(flatten)]
    pub gpu_methods: GpuMethods,
}

/// The CPU's model name and the threads the CPU work ran on.
#[derive(Serialize, Debug)]
pub struct Machine {
    pub cpu: String,
    pub threads: usize,
}

/// The CPU precomputation of the tables: seconds (medians) and what was computed.
#[derive(Serialize, Debug, Default)]
pub struct CpuPrecompute {
    pub cpu_precompute_s: Option<f64>,
    pub cpu_precompute_wavelengths: Option<usize>,
    pub cpu_precompute_orders: Option<usize>,
    /// Seconds of one run per stage (transmittance, single scattering, …).
    pub cpu_precompute_stages_s: Option<BTreeMap<String, f64>>,
    /// With `--spectral`.
    pub cpu_precompute_spectral_s: Option<f64>,
    pub cpu_precompute_spectral_wavelengths: Option<usize>,
}

/// The CPU renderer's frames, seconds (medians; tone mapping to 8 bits included).
#[derive(Serialize, Debug, Default)]
pub struct CpuFrames {
    pub cpu_frame_1080p_perspective_s: Option<f64>,
    pub cpu_frame_1024_fisheye_s: Option<f64>,
    pub cpu_frame_4096x2048_equirect_s: Option<f64>,
    /// The 1080p view at night (full moon as a second light, the stars and the glow), the
    /// astronomy of the date included.
    pub cpu_frame_1080p_night_s: Option<f64>,
    /// The default scene (the valley at golden hour, light shafts), 1920×1080: the shadow
    /// field of the sun and the frame; the terrain built once beforehand.
    pub cpu_frame_1080p_terrain_s: Option<f64>,
    /// With `--clouds`: the cumulus scene (`scenes/clouds-cumulus-noon.toml`: fair-weather
    /// cumulus, the sun 55° high) at 1920×1080, converged, its shadow maps included (the
    /// noise volumes made or read from the cache once before); at most 3 runs.
    pub cpu_frame_1080p_clouds_s: Option<f64>,
}

/// The fast methods on the CPU (seconds, medians): Hillaire 2020's tables (all of them, and
/// each pass of one build), one sky-view table, the aerial-perspective volume (32³ froxels
/// for the 1080p benchmark camera) of Hillaire's march and of the 4D tables, "the four
/// LUTs" (transmittance, multiple scattering, sky view, aerial perspective: what a frame
/// whose atmosphere changed pays), and the 1080p benchmark frame with Hillaire's method,
/// per pixel and through the volume.
#[derive(Serialize, Debug, Default)]
pub struct CpuMethods {
    pub cpu_hillaire_tables_s: Option<f64>,
    pub cpu_hillaire_transmittance_s: Option<f64>,
    pub cpu_hillaire_multiple_scattering_s: Option<f64>,
    pub cpu_hillaire_irradiance_s: Option<f64>,
    pub cpu_hillaire_sky_view_s: Option<f64>,
    pub cpu_hillaire_aerial_volume_s: Option<f64>,
    pub cpu_hillaire_four_luts_s: Option<f64>,
    pub cpu_hillaire_frame_1080p_perspective_s: Option<f64>,
    pub cpu_hillaire_frame_1080p_perspective_aerial_volume_s: Option<f64>,
    pub cpu_bruneton4d_aerial_volume_s: Option<f64>,
    /// The 3D table (Elek 2009 / Yusov 2013): its precomputation and the 1080p frame.
    pub cpu_elek3d_tables_s: Option<f64>,
    pub cpu_elek3d_frame_1080p_perspective_s: Option<f64>,
}

/// The reference path tracer's throughput: one earth RGB pixel (the zenith from 1 m, the
/// sun 30° high), 8192 paths per wavelength on every thread (median of the runs).
#[derive(Serialize, Debug, Default)]
pub struct CpuReference {
    pub cpu_reference_zenith_pixel_s: Option<f64>,
    pub cpu_reference_paths_per_s: Option<f64>,
}

/// The GPU: the adapter, the precomputation and the 1080p frame.
#[derive(Serialize, Debug, Default)]
pub struct GpuTimings {
    pub gpu_adapter: Option<String>,
    pub gpu_backend: Option<String>,
    pub gpu_adapter_software: Option<bool>,
    /// `--gpu-runs`: repetitions per GPU measurement.
    pub gpu_runs: Option<usize>,
    pub gpu_pipeline_creation_s: Option<f64>,
    pub gpu_precompute_s: Option<f64>,
    pub gpu_precompute_timing_method: Option<String>,
    pub gpu_precompute_spectral_s: Option<f64>,
    pub gpu_precompute_wavelengths: Option<usize>,
    pub gpu_precompute_orders: Option<usize>,
    pub gpu_frame_1080p_perspective_s: Option<f64>,
    pub gpu_frame_timing_method: Option<String>,
    pub gpu_frame_1080p_perspective_with_readback_s: Option<f64>,
    /// The default scene (the valley at golden hour, light shafts) at 1920×1080: the render
    /// dispatch alone, as `gpu_frame_timing_method` says.
    pub gpu_frame_1080p_terrain_s: Option<f64>,
    /// The same frame whole: the sun's shadow field and the terrain's change of the air's
    /// light on the CPU, the upload, the dispatch, the readback and the tone mapping (the
    /// terrain built and the tables read back once beforehand).
    pub gpu_frame_1080p_terrain_with_cpu_parts_s: Option<f64>,
    /// With `--clouds`: the cumulus scene (`scenes/clouds-cumulus-noon.toml`) at 1920×1080,
    /// the render dispatch alone.
    pub gpu_frame_1080p_clouds_s: Option<f64>,
    /// The same frame whole: each light's cloud-shadow map on the CPU, the upload, the
    /// dispatch, the readback and the tone mapping (the noise volumes made once before).
    pub gpu_frame_1080p_clouds_with_cpu_parts_s: Option<f64>,
}

/// The fast methods on the GPU (seconds, medians, `--method`): Hillaire 2020's passes
/// (timestamp queries on a hardware adapter, the wall clock per pass on a software one), its
/// sky-view pass and pixels' pass of the 1080p benchmark frame; the 3D table's frame (its
/// tables are the CPU's, uploaded: `cpu_elek3d_tables_s`), the compute pass alone.
#[derive(Serialize, Debug, Default)]
pub struct GpuMethods {
    pub gpu_hillaire_transmittance_s: Option<f64>,
    pub gpu_hillaire_multiple_scattering_s: Option<f64>,
    pub gpu_hillaire_irradiance_s: Option<f64>,
    pub gpu_hillaire_sky_view_s: Option<f64>,
    pub gpu_hillaire_frame_1080p_perspective_s: Option<f64>,
    pub gpu_hillaire_timing_method: Option<String>,
    pub gpu_elek3d_frame_1080p_perspective_s: Option<f64>,
}

impl Machine {
    /// This machine: the CPU model from /proc/cpuinfo (Linux; "unknown" elsewhere) and
    /// rayon's threads.
    pub fn this() -> Machine {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
            })
            .unwrap_or_else(|| "unknown".into());
        Machine {
            cpu,
            threads: rayon::current_num_threads(),
        }
    }
}

impl BenchReport {
    /// The report as one JSON object (keys in alphabetical order).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("a report serialises")
    }

    /// The text output: a `key: value` line per key, the value as compact JSON.
    pub fn lines(&self) -> Vec<String> {
        match self.to_json() {
            serde_json::Value::Object(map) => map
                .iter()
                .map(|(key, value)| format!("{key}: {value}"))
                .collect(),
            _ => unreachable!("a report is an object"),
        }
    }
}
