// Cameras (firmament::scene::camera): the ray through a pixel for every projection.

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

// The heading (rad) of the level all-round projections (fisheye, equirect), from the
// prepared basis: forward = (sin h, cos h, 0). Exactly 0 facing north.
fn heading() -> f32 {
    return atan2(frame.forward.x, frame.forward.y);
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
                d = direction_from_zenith_azimuth(rho * PI / 2.0, atan2(-x, y) + heading());
            }
        }
        case 2u: {
            // Equirect: azimuth u·π from the heading, elevation v·π/2 (zenith angle
            // π/2 − elevation).
            let azimuth = u * PI + heading();
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
