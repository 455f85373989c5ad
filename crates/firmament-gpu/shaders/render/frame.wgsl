// The render shader's per-frame constants (firmament_gpu::render::frame's FrameConstants),
// shared by every sky method's frame and the temporal resolve (render/temporal.wgsl).

// Per-frame constants (firmament_gpu::render::FrameConstants writes them in this order).
struct Frame {
    width: u32,
    height: u32,
    // This dispatch covers rows first_row .. first_row + rows (frames too large for one
    // storage binding are drawn in bands).
    first_row: u32,
    rows: u32,
    // 0 perspective, 1 fisheye, 2 equirect, 3 cubemap, 4 orbit (camera::Projection).
    projection: u32,
    lights: u32,
    // Whether a per-pixel shadowed length is bound (shadow_lengths, metres).
    shadow_input: u32,
    // Single Mie storage (View.mie_layout).
    mie_layout: u32,
    // View basis of the pinhole projections (PreparedCamera), local frame x east, y north, z up.
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // White-balance factors per linear sRGB channel (1 when off).
    balance: vec4<f32>,
    // The observer: radius, ρ = sqrt(r² − R_g²) (inside the atmosphere) and r − R_t (km), and
    // whether it is inside the atmosphere.
    camera_r_km: f32,
    camera_rho_km: f32,
    camera_above_top_km: f32,
    inside: u32,
    tan_half_fov: f32,
    // An upper bound on the pixels' footprints (rad; disk_edges.wgsl).
    max_footprint_rad: f32,
    // Interleaved frames (render/temporal.wgsl): the step k in bits 0–7 (0 or 1: every
    // pixel), the pixel (x, y) of each k×k block drawn in bits 8–15 and 16–23, and
    // DEPTH_IN_ALPHA: the output's alpha holds each pixel's depth (m) in place of the mask.
    interleave: u32,
    // The columns an interleaved frame draws: from bits 0–15 to before bits 16–31 (0: the
    // frame's width). A window of the frame drawn whole (around a light's disk) is a band's
    // rows and these columns.
    interleave_columns: u32,
}

@group(0) @binding(10) var<uniform> frame: Frame;

// The step k of an interleaved frame (1: every pixel).
fn interleave_step() -> u32 {
    return max(frame.interleave & 0xffu, 1u);
}

// The pixel (x, y) of each k×k block an interleaved frame draws.
fn interleave_phase() -> vec2<u32> {
    return vec2<u32>((frame.interleave >> 8u) & 0xffu, (frame.interleave >> 16u) & 0xffu);
}

// Whether the output's alpha holds each pixel's depth (m; SKY_DEPTH_M towards the sky, 0
// outside the projection) in place of the mask.
fn depth_in_alpha() -> bool {
    return (frame.interleave & DEPTH_IN_ALPHA) != 0u;
}
