// Cloud types (firmament::scene::clouds::profile): the density and the erosion of a layer
// along the normalised height h ∈ [0, 1] (0 at the base, 1 at the top), analytic curves
// after Schneider 2015's height gradients, blended by the weather's type t (0 stratus,
// ½ stratocumulus, 1 cumulus) in the cumuliform kind. Kinds: CLOUD_CUMULUS,
// CLOUD_ALTOSTRATUS, CLOUD_CIRRUS, CLOUD_UNIFORM.

// Hermite smoothstep of x between e0 and e1 (math::smoothstep).
fn cloud_smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// A bump rising over [a, b] and falling over [c, d].
fn bump(h: f32, a: f32, b: f32, c: f32, d: f32) -> f32 {
    return cloud_smoothstep(a, b, h) * (1.0 - cloud_smoothstep(c, d, h));
}

// CloudKind::density.
fn profile_density(kind: u32, h: f32, t_in: f32) -> f32 {
    if (h < 0.0 || h > 1.0) {
        return 0.0;
    }
    switch kind {
        case CLOUD_CUMULUS: {
            let t = clamp(t_in, 0.0, 1.0);
            let stratus = bump(h, 0.0, 0.08, 0.15, 0.3);
            let stratocumulus = bump(h, 0.0, 0.12, 0.35, 0.6);
            let cumulus = bump(h, 0.0, 0.1, 0.6, 0.95);
            if (t < 0.5) {
                let w = 2.0 * t;
                return stratus * (1.0 - w) + stratocumulus * w;
            }
            let w = 2.0 * t - 1.0;
            return stratocumulus * (1.0 - w) + cumulus * w;
        }
        case CLOUD_ALTOSTRATUS: {
            return bump(h, 0.0, 0.25, 0.65, 1.0);
        }
        case CLOUD_CIRRUS: {
            return bump(h, 0.0, 0.35, 0.55, 1.0);
        }
        default: {
            return 1.0;
        }
    }
}

// CloudKind::erosion.
fn profile_erosion(kind: u32, h: f32) -> f32 {
    switch kind {
        case CLOUD_CUMULUS: {
            return 0.25 + 0.35 * h;
        }
        case CLOUD_ALTOSTRATUS: {
            return 0.3;
        }
        case CLOUD_CIRRUS: {
            return 0.5;
        }
        default: {
            return 0.0;
        }
    }
}
