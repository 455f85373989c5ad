//! Gauss–Legendre quadrature, the one rule every integral in firmament uses: density
//! columns, optical depths along rays, phase-function normalisation and sampling tables.

/// A Gauss–Legendre rule on [−1, 1], given by its positive nodes and their weights (the
/// rules are symmetric).
#[derive(Clone, Copy, Debug)]
pub struct GaussLegendre {
    /// Positive nodes, ascending.
    pub nodes: &'static [f64],
    /// Their weights (each node ±x carries the same weight).
    pub weights: &'static [f64],
}

/// 4 nodes (Abramowitz & Stegun 1964, Table 25.4).
pub const GL4: GaussLegendre = GaussLegendre {
    nodes: &[0.339_981_043_584_856_3, 0.861_136_311_594_052_6],
    weights: &[0.652_145_154_862_546_1, 0.347_854_845_137_453_9],
};

/// 8 nodes (Abramowitz & Stegun 1964, Table 25.4).
pub const GL8: GaussLegendre = GaussLegendre {
    nodes: &[
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ],
    weights: &[
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ],
};

impl GaussLegendre {
    /// The nodes and weights of the composite rule with `panels` equal panels over [a, b]:
    /// (x, w) pairs with ∫_a^b f ≈ Σ w·f(x). Empty when b ≤ a.
    pub fn composite(&self, a: f64, b: f64, panels: usize) -> impl Iterator<Item = (f64, f64)> {
        let panels = if b > a { panels } else { 0 };
        let h = (b - a) / panels.max(1) as f64;
        let rule = *self;
        (0..panels).flat_map(move |i| {
            let c = a + (i as f64 + 0.5) * h;
            rule.nodes
                .iter()
                .zip(rule.weights)
                .flat_map(move |(&x, &w)| {
                    let dx = 0.5 * h * x;
                    let w = 0.5 * h * w;
                    [(c - dx, w), (c + dx, w)]
                })
        })
    }

    /// `f(x, w)` at each node and weight of [`GaussLegendre::composite`], in its order,
    /// without an iterator's overhead (the inner loops of the transmittance passes).
    #[inline]
    pub fn for_each_node(&self, a: f64, b: f64, panels: usize, mut f: impl FnMut(f64, f64)) {
        let panels = if b > a { panels } else { 0 };
        let h = (b - a) / panels.max(1) as f64;
        for i in 0..panels {
            let c = a + (i as f64 + 0.5) * h;
            for (&x, &w) in self.nodes.iter().zip(self.weights) {
                let (dx, w) = (0.5 * h * x, 0.5 * h * w);
                f(c - dx, w);
                f(c + dx, w);
            }
        }
    }

    /// ∫_a^b f by the composite rule with `panels` panels (0 when b ≤ a).
    pub fn integrate(&self, a: f64, b: f64, panels: usize, f: impl Fn(f64) -> f64) -> f64 {
        self.composite(a, b, panels).map(|(x, w)| w * f(x)).sum()
    }
}

/// A Gauss–Legendre rule of any number of nodes on [−1, 1], its nodes found by Newton's
/// method on P_n from Tricomi's estimate (Abramowitz & Stegun 1964, 25.4.29 and 22.7.10).
#[derive(Clone, Debug)]
pub struct GaussLegendreRule {
    /// The nodes, descending.
    pub nodes: Vec<f64>,
    /// Their weights.
    pub weights: Vec<f64>,
}

impl GaussLegendreRule {
    /// The rule of `n` ≥ 1 nodes.
    pub fn new(n: usize) -> GaussLegendreRule {
        let n = n.max(1);
        let mut nodes = Vec::with_capacity(n);
        let mut weights = Vec::with_capacity(n);
        for i in 0..n {
            let mut x = ((i as f64 + 0.75) / (n as f64 + 0.5) * std::f64::consts::PI).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // P_n(x) and P_{n−1}(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    (p0, p1) = (
                        p1,
                        ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64,
                    );
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            nodes.push(x);
            weights.push(2.0 / ((1.0 - x * x) * dp * dp));
        }
        GaussLegendreRule { nodes, weights }
    }

    /// The (x, w) pairs of the rule mapped onto [a, b].
    pub fn on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        (self.nodes.iter().zip(&self.weights)).map(move |(x, w)| (c + h * x, h * w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_are_exact_for_polynomials_of_their_degree() {
        // n nodes integrate degree 2n − 1 exactly.
        for (rule, degree) in [(GL4, 7), (GL8, 15)] {
            let w: f64 = rule.weights.iter().sum::<f64>() * 2.0;
            assert!((w - 2.0).abs() < 1e-14);
            let got = rule.integrate(0.0, 2.0, 1, |x| x.powi(degree));
            let want = 2f64.powi(degree + 1) / (degree + 1) as f64;
            assert!((got / want - 1.0).abs() < 1e-13, "{got} {want}");
        }
    }

    #[test]
    fn rules_of_any_size_match_the_tabulated_ones_and_their_degree() {
        let eight = GaussLegendreRule::new(8);
        let mut nodes: Vec<f64> = eight.nodes.iter().filter(|x| **x > 0.0).copied().collect();
        nodes.reverse();
        for (a, b) in nodes.iter().zip(GL8.nodes) {
            assert!((a - b).abs() < 1e-14, "{a} {b}");
        }
        for n in [1, 2, 5, 13] {
            let rule = GaussLegendreRule::new(n);
            let degree = 2 * n as i32 - 1;
            let got: f64 = rule.on(0.0, 2.0).map(|(x, w)| w * x.powi(degree)).sum();
            let want = 2f64.powi(degree + 1) / (degree + 1) as f64;
            assert!((got / want - 1.0).abs() < 1e-12, "n {n}: {got} {want}");
        }
    }

    #[test]
    fn composite_rule_converges_on_an_exponential() {
        let got = GL4.integrate(0.0, 10.0, 8, |x| (-x).exp());
        assert!((got - (1.0 - (-10f64).exp())).abs() < 1e-7);
        assert_eq!(GL4.integrate(1.0, 1.0, 8, |x| x), 0.0);
    }
}
