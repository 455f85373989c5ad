//! Output colour spaces: their primaries and white point (the chromaticities an OpenEXR
//! header carries), the matrix from the renderer's linear Rec. 709 into each, derived from
//! the chromaticities (SMPTE RP 177-1993, "Derivation of basic television color
//! equations") with Bradford chromatic adaptation between white points (Lam 1985; the
//! CIECAM97s matrix), and the gamut mapping that keeps every component non-negative at the
//! same luminance.
//!
//! A sky's spectra are inside the visible gamut but not always inside Rec. 709's: the sun's
//! disk at sunset, a saturated deep-blue twilight zenith. Their linear Rec. 709 values then
//! have a negative component, which image files and other programs do not expect. Mapped,
//! such a colour is desaturated towards the grey of its own luminance Y (the achromatic
//! axis, R = G = B = Y) just far enough that no component is negative: Y and the hue's
//! direction in the RGB cube are kept, the saturation lost is the gamut's limit. A wider
//! space (Rec. 2020, ACEScg) holds more of them unmapped.

/// An output RGB colour space (linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gamut {
    /// ITU-R BT.709-6 primaries, D65 (the renderer's own; sRGB's primaries).
    Rec709,
    /// ITU-R BT.2020-2 primaries, D65.
    Rec2020,
    /// ACEScg: the ACES AP1 primaries with the ACES white (SMPTE ST 2065-1; Academy
    /// S-2014-004).
    AcesCg,
}

/// CIE 1931 xy chromaticities of a space's primaries and white.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chromaticities {
    /// Red primary (x, y).
    pub red: [f64; 2],
    /// Green primary.
    pub green: [f64; 2],
    /// Blue primary.
    pub blue: [f64; 2],
    /// White point.
    pub white: [f64; 2],
}

/// D65 (CIE 15:2004), as BT.709 and BT.2020 give it.
const D65: [f64; 2] = [0.3127, 0.3290];

type Matrix = [[f64; 3]; 3];

/// Bradford's cone-response matrix (Lam 1985).
const BRADFORD: Matrix = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

impl Gamut {
    /// The accepted names (`--gamut`): `rec709`, `rec2020`, `acescg`.
    pub fn parse(name: &str) -> Option<Gamut> {
        match name {
            "rec709" => Some(Gamut::Rec709),
            "rec2020" => Some(Gamut::Rec2020),
            "acescg" => Some(Gamut::AcesCg),
            _ => None,
        }
    }

    /// The space's name as `parse` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Gamut::Rec709 => "rec709",
            Gamut::Rec2020 => "rec2020",
            Gamut::AcesCg => "acescg",
        }
    }

    /// Its primaries and white.
    pub fn chromaticities(self) -> Chromaticities {
        match self {
            Gamut::Rec709 => Chromaticities {
                red: [0.640, 0.330],
                green: [0.300, 0.600],
                blue: [0.150, 0.060],
                white: D65,
            },
            Gamut::Rec2020 => Chromaticities {
                red: [0.708, 0.292],
                green: [0.170, 0.797],
                blue: [0.131, 0.046],
                white: D65,
            },
            Gamut::AcesCg => Chromaticities {
                red: [0.713, 0.293],
                green: [0.165, 0.830],
                blue: [0.128, 0.044],
                white: [0.32168, 0.33767],
            },
        }
    }

    /// The matrix from linear Rec. 709 (D65) to this space: Rec. 709 → XYZ, Bradford
    /// adaptation from D65 to this space's white, XYZ → this space.
    pub fn from_rec709(self) -> Matrix {
        let source = Gamut::Rec709.chromaticities();
        let target = self.chromaticities();
        let to_xyz = rgb_to_xyz(&source);
        let from_xyz = invert(&rgb_to_xyz(&target));
        let adapt = bradford(source.white, target.white);
        multiply(&from_xyz, &multiply(&adapt, &to_xyz))
    }

    /// Relative luminance Y of this space's (R, G, B): the Y row of its RGB → XYZ matrix
    /// (the weights sum to 1: the white has Y = 1).
    pub fn luminance_weights(self) -> [f64; 3] {
        rgb_to_xyz(&self.chromaticities())[1]
    }
}

/// The RGB → XYZ matrix of primaries and white (SMPTE RP 177): the primaries' XYZ (Y = 1)
/// as columns, each scaled so that RGB (1, 1, 1) is the white with Y = 1.
fn rgb_to_xyz(c: &Chromaticities) -> Matrix {
    let xyz = |[x, y]: [f64; 2]| [x / y, 1.0, (1.0 - x - y) / y];
    let (r, g, b, w) = (xyz(c.red), xyz(c.green), xyz(c.blue), xyz(c.white));
    let p = [[r[0], g[0], b[0]], [r[1], g[1], b[1]], [r[2], g[2], b[2]]];
    let s = apply(&invert(&p), w);
    std::array::from_fn(|i| std::array::from_fn(|j| p[i][j] * s[j]))
}

/// The Bradford adaptation from white `from` to white `to` (xy).
fn bradford(from: [f64; 2], to: [f64; 2]) -> Matrix {
    let xyz = |[x, y]: [f64; 2]| [x / y, 1.0, (1.0 - x - y) / y];
    let (a, b) = (apply(&BRADFORD, xyz(from)), apply(&BRADFORD, xyz(to)));
    let scale: Matrix = [
        [b[0] / a[0], 0.0, 0.0],
        [0.0, b[1] / a[1], 0.0],
        [0.0, 0.0, b[2] / a[2]],
    ];
    multiply(&invert(&BRADFORD), &multiply(&scale, &BRADFORD))
}

/// m·v.
pub fn apply(m: &Matrix, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn invert(m: &Matrix) -> Matrix {
    let c = |i: usize, j: usize| {
        let (i0, i1) = ((i + 1) % 3, (i + 2) % 3);
        let (j0, j1) = ((j + 1) % 3, (j + 2) % 3);
        m[i0][j0] * m[i1][j1] - m[i0][j1] * m[i1][j0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    // The inverse is the transposed cofactors over the determinant.
    std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det))
}

/// `rgb` with no negative component at the same luminance (`weights`, the space's Y row):
/// moved along the line to the grey R = G = B = Y until its smallest component is 0;
/// black when Y ≤ 0. Colours already in the gamut are returned as they are.
pub fn map_into_gamut(rgb: [f64; 3], weights: [f64; 3]) -> [f64; 3] {
    let min = rgb[0].min(rgb[1]).min(rgb[2]);
    if min >= 0.0 {
        return rgb;
    }
    let y = weights[0] * rgb[0] + weights[1] * rgb[1] + weights[2] * rgb[2];
    if y <= 0.0 {
        return [0.0; 3];
    }
    // c' = Y + s (c − Y) with the smallest component at 0: s = Y / (Y − min).
    let s = y / (y - min);
    rgb.map(|c| (y + s * (c - y)).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Matrix, b: &Matrix, tol: f64) {
        for i in 0..3 {
            for j in 0..3 {
                assert!((a[i][j] - b[i][j]).abs() < tol, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn matrices_match_the_published_ones() {
        // Rec. 709 → XYZ: IEC 61966-2-1 (sRGB) to its four decimals.
        close(
            &rgb_to_xyz(&Gamut::Rec709.chromaticities()),
            &[
                [0.4124, 0.3576, 0.1805],
                [0.2126, 0.7152, 0.0722],
                [0.0193, 0.1192, 0.9505],
            ],
            1e-4,
        );
        // Rec. 709 → Rec. 2020: ITU-R BT.2087-0, eq. (4).
        close(
            &Gamut::Rec2020.from_rec709(),
            &[
                [0.6274, 0.3293, 0.0433],
                [0.0691, 0.9195, 0.0114],
                [0.0164, 0.0880, 0.8956],
            ],
            1e-4,
        );
        // Rec. 709 → ACEScg with Bradford (the matrix OpenColorIO's ACES configs use).
        close(
            &Gamut::AcesCg.from_rec709(),
            &[
                [0.6131, 0.3395, 0.0474],
                [0.0702, 0.9164, 0.0135],
                [0.0206, 0.1096, 0.8698],
            ],
            1e-4,
        );
        // White stays white (each space's white at Y = 1).
        for g in [Gamut::Rec709, Gamut::Rec2020, Gamut::AcesCg] {
            let w = apply(&g.from_rec709(), [1.0; 3]);
            assert!(w.iter().all(|v| (v - 1.0).abs() < 1e-9), "{g:?}: {w:?}");
            let sum: f64 = g.luminance_weights().iter().sum();
            assert!((sum - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn mapping_keeps_luminance_and_removes_negatives() {
        let w = Gamut::Rec709.luminance_weights();
        for rgb in [
            [3.0, 1.0, -0.5],
            [40.0, 12.0, -9.0],
            [-0.2, 0.5, 2.0],
            [0.1, 0.2, 0.3],
        ] {
            let m = map_into_gamut(rgb, w);
            assert!(m.iter().all(|&v| v >= 0.0), "{m:?}");
            let (y0, y1) = (apply(&[w, w, w], rgb)[0], apply(&[w, w, w], m)[0]);
            assert!((y0 - y1).abs() <= 1e-12 * y0.abs().max(1.0), "{y0} vs {y1}");
            if rgb.iter().all(|&v| v >= 0.0) {
                assert_eq!(m, rgb);
            } else {
                // On the grey line through the original: the smallest component at 0.
                assert!(m.iter().copied().fold(f64::INFINITY, f64::min) < 1e-12);
            }
        }
        assert_eq!(map_into_gamut([-1.0, -1.0, 0.5], w), [0.0; 3]);
    }
}
