// The lights' disks over each pixel's footprint (firmament::render::disk_edges): a pixel
// whose footprint straddles a drawn disk's edge is the mean of DISK_SUBSAMPLES² rays spread
// over it; elsewhere one ray through its centre.

// The footprint (rad) of pixel (x, y): the square root of its solid angle from the rays
// through the middles of its sides (PreparedCamera::pixel_solid_angle).
fn pixel_footprint(x: u32, y: u32) -> f32 {
    let cx = f32(x) + 0.5;
    let cy = f32(y) + 0.5;
    let l = camera_ray(cx - 0.5, cy);
    let r = camera_ray(cx + 0.5, cy);
    let t = camera_ray(cx, cy - 0.5);
    let b = camera_ray(cx, cy + 0.5);
    if (!(l.valid && r.valid && t.valid && b.valid)) {
        return 0.0;
    }
    return sqrt(length(cross(r.dir - l.dir, b.dir - t.dir)));
}

// DiskEdges::straddles: whether pixel (x, y), its centre ray `dir`, straddles the edge of a
// drawn disk (within DISK_EDGE_FOOTPRINTS footprints of it).
fn straddles_disk_edge(x: u32, y: u32, dir: vec3<f32>) -> bool {
    var footprint = -1.0;
    for (var l = 0u; l < frame.lights; l++) {
        if (lights.disk[l].x == 0u) {
            continue;
        }
        let light = lights.direction[l].xyz;
        let a = lights.direction[l].w;
        let c = dot(dir, light);
        if (c < cos(min(a + DISK_EDGE_FOOTPRINTS * frame.max_footprint_rad, PI))) {
            continue;
        }
        if (footprint < 0.0) {
            footprint = pixel_footprint(x, y);
        }
        let angle = atan2(length(cross(dir, light)), c);
        if (abs(angle - a) < DISK_EDGE_FOOTPRINTS * footprint) {
            return true;
        }
    }
    return false;
}

// disk_edges::subpixels: the offset of sub-pixel ray k from the pixel's top-left corner.
fn subpixel(k: u32) -> vec2<f32> {
    let n = DISK_SUBSAMPLES;
    return vec2<f32>((f32(k % n) + 0.5) / f32(n), (f32(k / n) + 0.5) / f32(n));
}

// How many rays pixel `p` is the mean of: DISK_SUBSAMPLES² where it straddles a disk's
// edge, else 1. Entry points loop over pixel_ray(p, k, n) for k < n with their shading
// called once in the loop: each call site of a shading function is inlined whole by the
// driver, and a second one doubles a compile that grows faster than the code (lavapipe).
fn pixel_rays(p: Pixel) -> u32 {
    return select(1u, DISK_SUBSAMPLES * DISK_SUBSAMPLES, straddles_disk_edge(p.x, p.y, p.ray.dir));
}

// Ray k of the n of pixel `p` (its centre ray when n is 1).
fn pixel_ray(p: Pixel, k: u32, n: u32) -> CameraRay {
    if (n == 1u) {
        return p.ray;
    }
    return camera_ray(f32(p.x) + subpixel(k).x, f32(p.y) + subpixel(k).y);
}
