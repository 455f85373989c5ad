use super::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// ∫ f dΩ: composite 8-point Gauss–Legendre in θ (μ = cos θ), fine enough for g = 0.95.
fn sphere_integral(f: impl Fn(f64) -> f64) -> f64 {
    GL8.integrate(0.0, PI, 4096, |t| 2.0 * PI * f(t.cos()) * t.sin())
}

/// Probability that μ ∈ [a, b].
fn bin_probability(p: &PhaseFunction, a: f64, b: f64) -> f64 {
    GL8.integrate(b.acos(), a.acos(), 256, |t| {
        2.0 * PI * p.eval(t.cos()) * t.sin()
    })
}

fn analytic_cases() -> Vec<PhaseFunction> {
    let mut v = vec![
        PhaseFunction::Isotropic,
        PhaseFunction::Rayleigh {
            depolarization: 0.0,
        },
        PhaseFunction::Rayleigh {
            depolarization: 0.0279,
        },
        PhaseFunction::Rayleigh {
            depolarization: 0.45,
        },
    ];
    for g in [-0.95, -0.5, -0.01, 0.0, 1e-7, 0.03, 0.3, 0.76, 0.9, 0.95] {
        v.push(PhaseFunction::HenyeyGreenstein { g });
        v.push(PhaseFunction::CornetteShanks { g });
        v.push(PhaseFunction::Schlick {
            g: g.clamp(-0.93, 0.93),
        });
    }
    v.push(PhaseFunction::DualLobeHg {
        g1: 0.8,
        g2: -0.5,
        weight: 0.5,
    });
    v.push(PhaseFunction::DualLobeHg {
        g1: 0.95,
        g2: 0.2,
        weight: 0.9,
    });
    v.push(PhaseFunction::DualLobeHg {
        g1: 0.5,
        g2: -0.3,
        weight: 1.0,
    });
    v.push(PhaseFunction::DualLobeHg {
        g1: 0.5,
        g2: -0.3,
        weight: 0.0,
    });
    v
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

fn temp_file(name: &str, contents: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "firmament-phase-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

/// An HG(g) table every 0.5°, scaled by an arbitrary factor (normalised on load).
fn hg_table(g: f64) -> String {
    let mut s = String::from("# angle_deg value\n\n");
    for i in 0..=360 {
        let a = i as f64 * 0.5;
        s.push_str(&format!(
            "{a} {}  # comment\n",
            3.7 * hg(g, a.to_radians().cos())
        ));
    }
    s
}

fn all_cases() -> Vec<PhaseFunction> {
    let mut v = analytic_cases();
    v.push(PhaseFunction::load_tabulated(temp_file("hg.txt", &hg_table(0.7))).unwrap());
    // Coarse, partial table: flat extension to 0° and 180°, a zero-valued segment.
    v.push(
        PhaseFunction::load_tabulated(temp_file(
            "coarse.txt",
            "10, 5\n40 1\n90 0\n100 0\n150 2.5\n",
        ))
        .unwrap(),
    );
    v
}

#[test]
fn phase_every_variant_integrates_to_one() {
    for p in all_cases() {
        p.validate("phase").unwrap();
        let total = sphere_integral(|mu| p.eval(mu));
        assert!((total - 1.0).abs() < 1e-4, "{p:?}: ∫p dΩ = {total}");
    }
}

#[test]
fn phase_mean_cosine_matches_numeric() {
    for p in all_cases() {
        let numeric = sphere_integral(|mu| mu * p.eval(mu));
        assert!(
            (numeric - p.mean_cosine()).abs() < 1e-4,
            "{p:?}: numeric {numeric} vs {}",
            p.mean_cosine()
        );
    }
    for g in [-0.9, 0.0, 0.5, 0.95] {
        let p = PhaseFunction::HenyeyGreenstein { g };
        assert_eq!(p.mean_cosine(), g);
        assert!((sphere_integral(|mu| mu * p.eval(mu)) - g).abs() < 1e-5);
    }
}

#[test]
fn phase_legendre_coefficients() {
    for p in all_cases() {
        let chi = p.legendre_coefficients(4);
        assert!((chi[0] - 1.0).abs() < 1e-4, "{p:?}: {chi:?}");
        assert!((chi[1] - p.mean_cosine()).abs() < 1e-4, "{p:?}: {chi:?}");
    }
    // Rayleigh, ρ = 0: 1 + μ² = (4/3)P_0 + (2/3)P_2 → χ_2 = 1/10.
    let chi = PhaseFunction::Rayleigh {
        depolarization: 0.0,
    }
    .legendre_coefficients(3);
    assert!((chi[2] - 0.1).abs() < 1e-9, "{chi:?}");
}

#[test]
fn phase_rayleigh_and_cornette_shanks_limits() {
    let r = PhaseFunction::Rayleigh {
        depolarization: 0.0,
    };
    let cs = PhaseFunction::CornetteShanks { g: 0.0 };
    for i in 0..=100 {
        let mu = -1.0 + i as f64 * 0.02;
        let expected = 3.0 / (16.0 * PI) * (1.0 + mu * mu);
        assert!((r.eval(mu) - expected).abs() < 1e-15);
        assert!((cs.eval(mu) - expected).abs() < 1e-15);
    }
    // Depolarised Rayleigh: forward/side ratio (1+3γ+1−γ)/(1+3γ) = 2(1+γ)/(1+3γ).
    let rho: f64 = 0.0279;
    let gamma = rho / (2.0 - rho);
    let p = PhaseFunction::Rayleigh {
        depolarization: rho,
    };
    assert!((p.eval(1.0) / p.eval(0.0) - 2.0 * (1.0 + gamma) / (1.0 + 3.0 * gamma)).abs() < 1e-12);
    // HG at g = 0 is isotropic; CS and HG agree on the forward/backward symmetry.
    assert!((PhaseFunction::HenyeyGreenstein { g: 0.0 }.eval(0.3) - INV_4PI).abs() < 1e-16);
    let (a, b) = (
        PhaseFunction::CornetteShanks { g: 0.6 },
        PhaseFunction::CornetteShanks { g: -0.6 },
    );
    assert!((a.eval(0.4) - b.eval(-0.4)).abs() < 1e-15);
}

/// Radical inverse in base 2 (van der Corput) for the second random number.
fn van_der_corput(mut i: u32) -> f64 {
    i = i.reverse_bits();
    i as f64 / 4_294_967_296.0
}

#[test]
fn phase_sampling_histograms_match_eval() {
    const N: usize = 200_000;
    const BINS: usize = 20;
    for p in all_cases() {
        let mut hist = [0usize; BINS];
        for i in 0..N {
            // Stratified u1 (low discrepancy), van der Corput u2.
            let (mu, phi) = p.sample((i as f64 + 0.5) / N as f64, van_der_corput(i as u32));
            assert!(
                (-1.0..=1.0).contains(&mu) && (0.0..2.0 * PI).contains(&phi),
                "{p:?}: {mu} {phi}"
            );
            hist[(((mu + 1.0) * 0.5 * BINS as f64) as usize).min(BINS - 1)] += 1;
        }
        for (k, &count) in hist.iter().enumerate() {
            let a = -1.0 + 2.0 * k as f64 / BINS as f64;
            let expected = N as f64 * bin_probability(&p, a, a + 2.0 / BINS as f64);
            if expected < 1.0 {
                assert!(count <= 2, "{p:?} bin {k}: {count} vs {expected}");
                continue;
            }
            // Inverse-CDF with stratified u1 puts each bin within ±1 of its expectation.
            let tolerance = (0.02 * expected).max(1.5);
            assert!(
                (count as f64 - expected).abs() <= tolerance,
                "{p:?} bin {k}: {count} samples, expected {expected:.1}"
            );
        }
    }
}

#[test]
fn phase_sampling_is_exact_inverse_of_cdf() {
    // P(μ ≤ sample(u)) = u for each single-lobe sampler, to near rounding (the dual-lobe
    // sampler picks a lobe with u1, so it is not monotone in u1; the histograms cover it).
    for p in all_cases()
        .into_iter()
        .filter(|p| !matches!(p, PhaseFunction::DualLobeHg { .. }))
    {
        for i in 1..40 {
            let u = i as f64 / 40.0;
            let (mu, _) = p.sample(u, 0.5);
            let cdf = bin_probability(&p, -1.0, mu);
            assert!(
                (cdf - u).abs() < 2e-6,
                "{p:?}: u = {u}, cdf(sample) = {cdf}"
            );
        }
        assert_eq!(p.sample(0.0, 0.0).0.clamp(-1.0, 1.0), p.sample(0.0, 0.0).0);
    }
}

#[test]
fn phase_tabulated_reproduces_henyey_greenstein() {
    let g = 0.7;
    let p = PhaseFunction::load_tabulated(temp_file("hg.txt", &hg_table(g))).unwrap();
    let PhaseFunction::Tabulated(t) = &p else {
        unreachable!()
    };
    assert_eq!(t.angles().len(), 361);
    assert_eq!(*t.angles().last().unwrap(), PI);
    for i in 0..=1000 {
        let mu = -1.0 + i as f64 * 0.002;
        let (tab, exact) = (p.eval(mu), hg(g, mu));
        assert!(
            (tab / exact - 1.0).abs() < 0.01,
            "μ = {mu}: {tab} vs {exact}"
        );
    }
    assert!((p.mean_cosine() - g).abs() < 1e-3, "{}", p.mean_cosine());
}

#[test]
fn phase_tabulated_toml_prepare_relative_to_base_dir() {
    let path = temp_file("table.dat", &hg_table(0.5));
    let dir = path.parent().unwrap();
    #[derive(Deserialize, Serialize)]
    struct Doc {
        phase: PhaseFunction,
    }
    let mut doc: Doc =
        toml::from_str("phase = { type = \"tabulated\", file = \"table.dat\" }").unwrap();
    assert!(!doc.phase.is_prepared());
    doc.phase.validate("phase").unwrap();
    doc.phase.prepare(dir).unwrap();
    assert!(doc.phase.is_prepared());
    assert!((doc.phase.eval(0.2) - hg(0.5, 0.2)).abs() / hg(0.5, 0.2) < 0.01);
    // Serialises back to the path as written.
    let text = toml::to_string(&doc).unwrap();
    assert!(
        text.contains("type = \"tabulated\"") && text.contains("file = \"table.dat\""),
        "{text}"
    );
    // Unresolved relative to the wrong directory → File error naming the path.
    let mut bad: Doc =
        toml::from_str("phase = { type = \"tabulated\", file = \"table.dat\" }").unwrap();
    match bad.phase.prepare(Path::new("/nonexistent-firmament-dir")) {
        Err(Error::File { path, .. }) => assert!(path.contains("table.dat"), "{path}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn phase_toml_analytic_forms() {
    let p: PhaseFunction = toml::from_str("type = \"rayleigh\"").unwrap();
    assert_eq!(
        p,
        PhaseFunction::Rayleigh {
            depolarization: 0.0
        }
    );
    let p: PhaseFunction = toml::from_str("type = \"henyey-greenstein\"\ng = 0.76").unwrap();
    assert_eq!(p, PhaseFunction::HenyeyGreenstein { g: 0.76 });
    let p: PhaseFunction =
        toml::from_str("type = \"dual-lobe-hg\"\ng1 = 0.8\ng2 = -0.3\nweight = 0.6").unwrap();
    assert_eq!(
        p,
        PhaseFunction::DualLobeHg {
            g1: 0.8,
            g2: -0.3,
            weight: 0.6
        }
    );
    for p in analytic_cases() {
        let back: PhaseFunction = toml::from_str(&toml::to_string(&p).unwrap()).unwrap();
        assert_eq!(back, p);
    }
    assert!(toml::from_str::<PhaseFunction>("type = \"cornette-shanks\"\ng = 0.8\nk = 1").is_err());
    assert!(
        toml::from_str::<PhaseFunction>("type = \"tabulated\"\nfile = \"x\"\nextra = 1").is_err()
    );
    assert!(toml::from_str::<PhaseFunction>("type = \"mie\"").is_err());
}

fn invalid_field(r: Result<()>) -> String {
    match r {
        Err(e @ Error::InvalidParameter { .. }) => e.to_string(),
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn phase_validate_names_field_value_and_range() {
    let f = "constituents[1].phase";
    let msg = invalid_field(PhaseFunction::HenyeyGreenstein { g: 1.0 }.validate(f));
    assert!(
        msg.contains("constituents[1].phase.g") && msg.contains('1') && msg.contains("(-1, 1)"),
        "{msg}"
    );
    let msg = invalid_field(PhaseFunction::CornetteShanks { g: f64::NAN }.validate(f));
    assert!(msg.contains("phase.g") && msg.contains("NaN"), "{msg}");
    let msg = invalid_field(PhaseFunction::Schlick { g: -1.5 }.validate(f));
    assert!(msg.contains("phase.g") && msg.contains("-1.5"), "{msg}");
    let msg = invalid_field(PhaseFunction::Schlick { g: 0.95 }.validate(f));
    assert!(msg.contains("phase.g") && msg.contains("0.9381"), "{msg}");
    PhaseFunction::Schlick { g: 0.938 }.validate(f).unwrap();
    assert!((schlick_k(SCHLICK_G_MAX) - 1.0).abs() < 1e-15);
    let msg = invalid_field(
        PhaseFunction::DualLobeHg {
            g1: 0.5,
            g2: -1.0,
            weight: 0.5,
        }
        .validate(f),
    );
    assert!(msg.contains("phase.g2"), "{msg}");
    let msg = invalid_field(
        PhaseFunction::DualLobeHg {
            g1: 0.5,
            g2: 0.1,
            weight: 1.2,
        }
        .validate(f),
    );
    assert!(
        msg.contains("phase.weight") && msg.contains("1.2") && msg.contains("[0, 1]"),
        "{msg}"
    );
    let msg = invalid_field(
        PhaseFunction::Rayleigh {
            depolarization: 0.5,
        }
        .validate(f),
    );
    assert!(
        msg.contains("phase.depolarization") && msg.contains("[0, 0.5)"),
        "{msg}"
    );
    let msg = invalid_field(
        PhaseFunction::Rayleigh {
            depolarization: -0.01,
        }
        .validate(f),
    );
    assert!(msg.contains("-0.01"), "{msg}");
    let msg = invalid_field(PhaseFunction::Tabulated(TabulatedPhase::new("")).validate(f));
    assert!(msg.contains("phase.file"), "{msg}");
}

#[test]
fn phase_tabulated_refuses_bad_files() {
    let cases = [
        ("one.txt", "0 1\n", "at least 2"),
        ("empty.txt", "# nothing\n", "at least 2"),
        ("neg.txt", "0 1\n90 -0.5\n180 1\n", "negative"),
        ("nan.txt", "0 1\n90 NaN\n180 1\n", "not finite"),
        ("inf.txt", "0 1\n90 inf\n180 1\n", "not finite"),
        ("order.txt", "0 1\n90 1\n45 1\n", "not greater"),
        ("dup.txt", "0 1\n90 1\n90 1\n", "not greater"),
        ("range.txt", "0 1\n190 1\n", "outside [0, 180]"),
        ("negangle.txt", "-5 1\n90 1\n", "outside [0, 180]"),
        ("zero.txt", "0 0\n180 0\n", "all zero"),
        ("junk.txt", "0 1\n90 abc\n", "not a number"),
        ("three.txt", "0 1 2\n180 1\n", "expected `angle_deg value`"),
    ];
    for (name, text, reason_part) in cases {
        let path = temp_file(name, text);
        match PhaseFunction::load_tabulated(&path) {
            Err(Error::File { path: p, reason }) => {
                assert!(p.contains(name), "{p}");
                assert!(reason.contains(reason_part), "{name}: {reason}");
            }
            other => panic!("{name}: expected File error, got {other:?}"),
        }
    }
    match PhaseFunction::load_tabulated("/nonexistent-firmament-dir/phase.txt") {
        Err(Error::File { path, .. }) => assert!(path.contains("phase.txt")),
        other => panic!("{other:?}"),
    }
}

/// Potter's truncation keeps 1 − f of the phase: ∫ min(p, p(θ_c)) dΩ = 1 − f, for the
/// clouds' dual lobe with f = g² (the δ-Eddington's) and for single lobes; nothing cut
/// leaves p's forward value.
#[test]
fn truncated_forward_value_cuts_the_fraction_asked() {
    let cases = [
        PhaseFunction::DualLobeHg {
            g1: 0.8,
            g2: -0.5,
            weight: 0.8,
        },
        PhaseFunction::HenyeyGreenstein { g: 0.85 },
        PhaseFunction::HenyeyGreenstein { g: 0.3 },
    ];
    for p in cases {
        let f = p.mean_cosine().powi(2);
        let cap = p.truncated_forward_value(f);
        let kept = sphere_integral(|mu| p.eval(mu).min(cap));
        assert!(
            (kept - (1.0 - f)).abs() < 2e-4,
            "{p:?}: kept {kept}, 1 − f {}",
            1.0 - f
        );
        assert!(cap < p.eval(1.0) && cap > p.eval(-1.0), "{p:?}: cap {cap}");
    }
    let hg = PhaseFunction::HenyeyGreenstein { g: 0.5 };
    assert_eq!(hg.truncated_forward_value(0.0), hg.eval(1.0));
}
