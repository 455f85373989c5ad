//! Cube maps in the layouts engines read. firmament renders a cube map as six faces of its
//! own frame (x east, y north, z up; `Projection::Cubemap`); a layout is an exact
//! rearrangement of those pixels (every layout's axes are a signed permutation of ours, so
//! no pixel is resampled) into the standard faces of the graphics APIs:
//!
//! - face order +X, −X, +Y, −Y, +Z, −Z, and each face oriented as the OpenGL/Vulkan face
//!   selection table has it (OpenGL 4.6 §8.13 "Cube Map Texture Selection", Vulkan
//!   "Cube Map Face and Coordinate Selection"; KTX2 and DDS store the same faces): for a face
//!   pixel at (a, b) ∈ [−1, 1]², a to the right and b down the image, the cube direction is
//!   +X (1, −b, −a), −X (−1, −b, a), +Y (a, 1, b), −Y (a, −1, −b), +Z (a, −b, 1),
//!   −Z (−a, −b, −1);
//! - a cube frame c that is left-handed with +Y up (KTX2 spec, "Cubemap Orientation").
//!
//! How the world's directions land in that frame is what the layouts choose (see
//! docs/conventions.md, which names each engine's reading):
//!
//! | layout | cube axes (c) from east, north, up | arrangement |
//! |---|---|---|
//! | `firmament` | firmament's own faces (+X east … +Z up, side faces zenith-up) | 6 × 1 |
//! | `y-up` | c = (east, up, north): north on +Z (forward in Unity, Bevy, Godot) | 6 × 1 |
//! | `cross` | as `y-up` | 4 × 3 horizontal cross: +Y above +Z; −X +Z +X −Z; −Y below |
//! | `unreal` | c = (north, east, up): Unreal's world with north on +X, up on +Z | 6 × 1 |

use crate::io::ImageRgbF32;
use crate::math::Vec3;
use crate::scene::{Camera, Projection};

/// How a cube map's faces are oriented and arranged in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeLayout {
    /// firmament's own 6 × 1 strip: +X east, −X west, +Y north, −Y south, +Z up, −Z down,
    /// side faces with the zenith at the top, the up and down faces with north at the top.
    Firmament,
    /// Standard faces in a 6 × 1 strip, +Y up, north on +Z.
    YUp,
    /// Standard faces of [`CubeLayout::YUp`] in a 4 × 3 horizontal cross.
    Cross,
    /// Standard faces in a 6 × 1 strip with Unreal's axes: +X north, +Y east, +Z up.
    Unreal,
}

/// Cells (column, row) of the faces +X, −X, +Y, −Y, +Z, −Z in the 4 × 3 horizontal cross.
const CROSS_CELLS: [(usize, usize); 6] = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];

impl CubeLayout {
    /// Every layout with its name.
    pub const ALL: [(CubeLayout, &'static str); 4] = [
        (CubeLayout::Firmament, "firmament"),
        (CubeLayout::YUp, "y-up"),
        (CubeLayout::Cross, "cross"),
        (CubeLayout::Unreal, "unreal"),
    ];

    /// Parse a name of [`CubeLayout::ALL`].
    pub fn parse(s: &str) -> Option<CubeLayout> {
        Self::ALL.iter().find(|(_, n)| *n == s).map(|(l, _)| *l)
    }

    /// The layout's name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(l, _)| *l == self)
            .map_or("", |(_, n)| n)
    }

    /// The file's size for faces of `face` pixels.
    pub fn size(self, face: usize) -> (usize, usize) {
        match self {
            CubeLayout::Cross => (4 * face, 3 * face),
            _ => (6 * face, face),
        }
    }

    /// The cube-frame direction of world direction `d` (x east, y north, z up): every
    /// layout's axes swap is its own inverse.
    pub fn cube_axes(self, d: Vec3) -> Vec3 {
        self.world_of(d)
    }

    /// The world direction (x east, y north, z up) of cube-frame direction `c`.
    fn world_of(self, c: Vec3) -> Vec3 {
        match self {
            CubeLayout::Firmament => c,
            CubeLayout::YUp | CubeLayout::Cross => Vec3::new(c.x, c.z, c.y),
            CubeLayout::Unreal => Vec3::new(c.y, c.x, c.z),
        }
    }

    /// The world direction seen by pixel (x, y) of a file of `face`-pixel faces (pixel
    /// centres at +0.5), with the face it lies on; None in a cross's empty cells.
    pub fn direction(self, face: usize, px: f64, py: f64) -> Option<(usize, Vec3)> {
        let n = face as f64;
        let (f, fx, fy) = match self {
            CubeLayout::Cross => {
                let cell = ((px / n) as usize, (py / n) as usize);
                let f = CROSS_CELLS.iter().position(|&c| c == cell)?;
                (f, px - (cell.0 * face) as f64, py - (cell.1 * face) as f64)
            }
            _ => {
                let f = ((px / n) as usize).min(5);
                (f, px - (f * face) as f64, py)
            }
        };
        if self == CubeLayout::Firmament {
            let camera = firmament_cube_camera();
            let d = camera.prepare(0.0, 6 * face, face).ray(px, py)?.dir;
            return Some((f, d));
        }
        let (a, b) = (2.0 * fx / n - 1.0, 2.0 * fy / n - 1.0);
        let c = match f {
            0 => Vec3::new(1.0, -b, -a),
            1 => Vec3::new(-1.0, -b, a),
            2 => Vec3::new(a, 1.0, b),
            3 => Vec3::new(a, -1.0, -b),
            4 => Vec3::new(a, -b, 1.0),
            _ => Vec3::new(-a, -b, -1.0),
        };
        Some((f, self.world_of(c).normalize_or_zero()))
    }

    /// Rearrange firmament's own cube map (`Projection::Cubemap`, 6·N × N) into this
    /// layout; the cross's empty cells are black.
    pub fn arrange(self, strip: &ImageRgbF32) -> ImageRgbF32 {
        let face = strip.height;
        assert_eq!(strip.width, 6 * face, "a 6:1 cube map");
        if self == CubeLayout::Firmament {
            return strip.clone();
        }
        let (w, h) = self.size(face);
        let mut out = ImageRgbF32::new(w, h);
        let source = firmament_cube_camera().prepare(0.0, 6 * face, face);
        for y in 0..h {
            for x in 0..w {
                let Some((_, d)) = self.direction(face, x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                // Pixel centres map to pixel centres: the axes are a signed permutation.
                let (sx, sy) = source.pixel_of(d).expect("every direction is on a face");
                let (sx, sy) = ((sx as usize).min(6 * face - 1), (sy as usize).min(face - 1));
                out.data[y * w + x] = strip.data[sy * strip.width + sx];
            }
        }
        out
    }

    /// The six faces +X, −X, +Y, −Y, +Z, −Z of this layout's cube frame, each N × N (for
    /// cube files, DDS and KTX2, which store the faces one after another).
    pub fn faces(self, strip: &ImageRgbF32) -> Vec<ImageRgbF32> {
        let strip_layout = match self {
            CubeLayout::Cross => CubeLayout::YUp,
            other => other,
        };
        let all = strip_layout.arrange(strip);
        let n = strip.height;
        (0..6)
            .map(|f| {
                let mut face = ImageRgbF32::new(n, n);
                for y in 0..n {
                    let row = &all.data[y * all.width + f * n..y * all.width + (f + 1) * n];
                    face.data[y * n..(y + 1) * n].copy_from_slice(row);
                }
                face
            })
            .collect()
    }
}

/// The camera of firmament's own cube map (its faces' directions do not depend on the
/// altitude).
fn firmament_cube_camera() -> Camera {
    Camera {
        projection: Projection::Cubemap,
        altitude_m: 0.0,
        heading_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        fov_deg: 90.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_layout_sees_every_direction_once() {
        // Each layout's pixel directions are the firmament strip's, permuted.
        let n = 8;
        let mut strip = ImageRgbF32::new(6 * n, n);
        for (i, p) in strip.data.iter_mut().enumerate() {
            *p = [i as f32, 0.0, 0.0];
        }
        for (layout, name) in CubeLayout::ALL {
            assert_eq!(CubeLayout::parse(name), Some(layout));
            let out = layout.arrange(&strip);
            let mut seen: Vec<usize> = (out.data.iter())
                .enumerate()
                .filter(|(i, _)| {
                    layout
                        .direction(
                            n,
                            (i % out.width) as f64 + 0.5,
                            (i / out.width) as f64 + 0.5,
                        )
                        .is_some()
                })
                .map(|(_, p)| p[0] as usize)
                .collect();
            seen.sort_unstable();
            assert_eq!(seen, (0..6 * n * n).collect::<Vec<_>>(), "{name}");
        }
    }

    #[test]
    fn the_standard_faces_face_their_axes() {
        // The centre of face f looks along its axis in the cube frame: y-up puts north on
        // +Z and up on +Y, Unreal north on +X and up on +Z.
        let (east, north, up) = (Vec3::X, Vec3::Y, Vec3::Z);
        for (layout, want) in [
            (CubeLayout::YUp, [east, -east, up, -up, north, -north]),
            (CubeLayout::Cross, [east, -east, up, -up, north, -north]),
            (CubeLayout::Unreal, [north, -north, east, -east, up, -up]),
            (CubeLayout::Firmament, [east, -east, north, -north, up, -up]),
        ] {
            let n = 4;
            for (f, w) in want.iter().enumerate() {
                let (x, y) = match layout {
                    CubeLayout::Cross => (CROSS_CELLS[f].0 * n + 2, CROSS_CELLS[f].1 * n + 2),
                    _ => (f * n + 2, 2),
                };
                let (face, d) = layout.direction(n, x as f64, y as f64).unwrap();
                assert_eq!(face, f);
                assert!((d - *w).length() < 1e-12, "{layout:?} face {f}: {d:?}");
            }
        }
    }
}
