// Phase functions (firmament::medium::phase), normalised to 1 over the sphere.

const INV_4PI: f32 = 1.0 / (4.0 * PI);

fn hg(g: f32, mu: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) * INV_4PI / (d * sqrt(d));
}

fn tabulated_phase(offset: u32, count: u32, mu: f32) -> f32 {
    let t = acos(mu);
    // partition_point(theta ≤ t)
    var lo = 0u;
    var hi = count;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (data[offset + mid].x <= t) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let i = clamp(lo, 1u, count - 1u) - 1u;
    let a = data[offset + i];
    let b = data[offset + i + 1u];
    let f = clamp((t - a.x) / (b.x - a.x), 0.0, 1.0);
    return a.y + f * (b.y - a.y);
}

fn phase_eval(kind: u32, offset: u32, count: u32, a: f32, b: f32, c: f32, cos_theta: f32) -> f32 {
    let mu = clamp(cos_theta, -1.0, 1.0);
    switch kind {
        case 0u: {
            return INV_4PI;
        }
        case 1u: {
            // Rayleigh with depolarisation: 3/(4π(3a+b))·(a + bμ²).
            return 3.0 / (4.0 * PI * (3.0 * a + b)) * (a + b * mu * mu);
        }
        case 2u: {
            return hg(a, mu);
        }
        case 3u: {
            // Cornette–Shanks (Bruneton & Neyret 2008 eq. 4).
            let g2 = a * a;
            let d = 1.0 + g2 - 2.0 * a * mu;
            return 3.0 / (8.0 * PI) * (1.0 - g2) / (2.0 + g2) * (1.0 + mu * mu) / (d * sqrt(d));
        }
        case 4u: {
            // Schlick, a = k.
            let d = 1.0 - a * mu;
            return (1.0 - a * a) * INV_4PI / (d * d);
        }
        case 5u: {
            return c * hg(a, mu) + (1.0 - c) * hg(b, mu);
        }
        default: {
            return tabulated_phase(offset, count, mu);
        }
    }
}

// Phase function of scattering group g (0 molecules, 1 aerosols).
fn group_phase(g: u32, nu: f32) -> f32 {
    if (g == 0u) {
        return phase_eval(atm.phase0_kind, atm.phase0_offset, atm.phase0_count, atm.phase0_a, atm.phase0_b, atm.phase0_c, nu);
    }
    return phase_eval(atm.phase1_kind, atm.phase1_offset, atm.phase1_count, atm.phase1_a, atm.phase1_b, atm.phase1_c, nu);
}
