//! Radiance RGBE (`.hdr`) files: Greg Ward's shared-exponent encoding, run-length
//! compressed scanlines.

use std::io::Write;
use std::path::Path;

use super::atomic::write_atomic;
use super::{file_error, io_error, ImageRgbF32};
use crate::Result;

/// 2^k as f64, exactly (k within the normal range).
fn pow2(k: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&k));
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// Greg Ward's RGBE encoding (frexp-based, mantissas truncated): the largest channel
/// `v = m * 2^e` with `m` in [0.5, 1) sets the shared exponent `e + 128`, and each
/// channel stores `floor(c * 256 / 2^e)`. Negative and NaN channels become 0; values
/// above 1e38 are clamped; a maximum below 1e-32 gives (0, 0, 0, 0).
pub fn rgbe_encode(rgb: [f32; 3]) -> [u8; 4] {
    let c = rgb.map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1e38) });
    let v = c[0].max(c[1]).max(c[2]);
    if v < 1e-32 {
        return [0; 4];
    }
    // frexp: v is a normal f32 here, v = m * 2^e with m in [0.5, 1).
    let e = ((v.to_bits() >> 23) & 0xff) as i32 - 126;
    let scale = pow2(8 - e); // exact
    let q = |x: f32| ((x as f64 * scale).floor() as i64).clamp(0, 255) as u8;
    [q(c[0]), q(c[1]), q(c[2]), (e + 128) as u8]
}

/// Ward's RGBE decoding (Radiance `colr_color`): `(byte + 0.5) * 2^(exp - 136)`;
/// an exponent byte of 0 is black.
pub fn rgbe_decode(rgbe: [u8; 4]) -> [f32; 3] {
    if rgbe[3] == 0 {
        return [0.0; 3];
    }
    let f = pow2(rgbe[3] as i32 - (128 + 8));
    [0, 1, 2].map(|i| ((rgbe[i] as f64 + 0.5) * f) as f32)
}

/// Adaptive run-length encoding of one channel of a new-style RLE scanline.
fn rle_channel(data: &[u8], out: &mut Vec<u8>) {
    let n = data.len();
    let run_at = |i: usize, cap: usize| {
        let mut r = 1;
        while i + r < n && r < cap && data[i + r] == data[i] {
            r += 1;
        }
        r
    };
    let mut i = 0;
    while i < n {
        let run = run_at(i, 127);
        if run >= 4 {
            out.push(128 + run as u8);
            out.push(data[i]);
            i += run;
            continue;
        }
        let mut j = i;
        while j < n && j - i < 128 && (j == i || run_at(j, 4) < 4) {
            j += 1;
        }
        out.push((j - i) as u8);
        out.extend_from_slice(&data[i..j]);
        i = j;
    }
}

/// Writes a Radiance RGBE (`.hdr`) file: `#?RADIANCE`, `FORMAT=32-bit_rle_rgbe`,
/// `-Y h +X w`, with new-style run-length encoded scanlines (flat scanlines when the
/// width is outside 8..=32767, where RLE is not defined).
pub fn write_hdr(path: impl AsRef<Path>, image: &ImageRgbF32) -> Result<()> {
    let path = path.as_ref();
    image.check(path)?;
    let (w, h) = (image.width, image.height);
    let rle = (8..=0x7fff).contains(&w);
    let mut body = Vec::with_capacity(w * h * 4 + 64);
    body.extend_from_slice(b"#?RADIANCE\nSOFTWARE=firmament\nFORMAT=32-bit_rle_rgbe\n\n");
    body.extend_from_slice(format!("-Y {h} +X {w}\n").as_bytes());
    let mut channels = vec![[0u8; 4]; w];
    let mut plane = vec![0u8; w];
    for row in image.data.chunks_exact(w) {
        for (dst, &px) in channels.iter_mut().zip(row) {
            *dst = rgbe_encode(px);
        }
        if rle {
            body.extend_from_slice(&[2, 2, (w >> 8) as u8, (w & 0xff) as u8]);
            for c in 0..4 {
                for (p, px) in plane.iter_mut().zip(&channels) {
                    *p = px[c];
                }
                rle_channel(&plane, &mut body);
            }
        } else {
            body.extend(channels.iter().flatten());
        }
    }
    write_atomic(path, |out| {
        out.write_all(&body).map_err(|e| io_error(path, &e, true))
    })
}

/// Writes a Radiance RGBE file with flat (uncompressed) scanlines.
pub fn write_hdr_uncompressed(path: impl AsRef<Path>, image: &ImageRgbF32) -> Result<()> {
    let path = path.as_ref();
    image.check(path)?;
    let (w, h) = (image.width, image.height);
    let mut body = Vec::with_capacity(w * h * 4 + 64);
    body.extend_from_slice(b"#?RADIANCE\nSOFTWARE=firmament\nFORMAT=32-bit_rle_rgbe\n\n");
    body.extend_from_slice(format!("-Y {h} +X {w}\n").as_bytes());
    for &px in &image.data {
        body.extend_from_slice(&rgbe_encode(px));
    }
    write_atomic(path, |out| {
        out.write_all(&body).map_err(|e| io_error(path, &e, true))
    })
}

struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn byte(&mut self) -> Option<u8> {
        let b = *self.data.get(self.pos)?;
        self.pos += 1;
        Some(b)
    }
    fn bytes(&mut self, n: usize) -> Option<&'a [u8]> {
        let s = self.data.get(self.pos..self.pos.checked_add(n)?)?;
        self.pos += n;
        Some(s)
    }
    fn line(&mut self) -> Option<&'a [u8]> {
        let rest = self.data.get(self.pos..)?;
        let end = rest.iter().position(|&b| b == b'\n')?;
        self.pos += end + 1;
        Some(&rest[..end])
    }
}

/// Reads a Radiance RGBE (`.hdr`) file: flat, old-style RLE and new-style RLE
/// scanlines; resolution strings `-Y h +X w` (standard) and `+Y h +X w` (bottom-up).
/// Pixel values are divided by the product of any `EXPOSURE=` header lines, giving
/// the original values. `32-bit_rle_xyze` files are refused.
pub fn read_hdr(path: impl AsRef<Path>) -> Result<ImageRgbF32> {
    let path = path.as_ref();
    let data = std::fs::read(path).map_err(|e| io_error(path, &e, false))?;
    parse_hdr(&data)
        .map_err(|reason| file_error(path, format!("cannot read Radiance HDR: {reason}")))
}

fn parse_hdr(data: &[u8]) -> std::result::Result<ImageRgbF32, String> {
    let eof = || "file is truncated".to_string();
    let mut cur = Cursor { data, pos: 0 };
    let first = cur.line().ok_or_else(eof)?;
    if !first.starts_with(b"#?") {
        return Err("not a Radiance file (no #? signature)".into());
    }
    let mut exposure = 1.0f64;
    loop {
        let line = cur.line().ok_or_else(eof)?;
        let line = std::str::from_utf8(line)
            .unwrap_or("")
            .trim_end_matches('\r');
        if line.trim().is_empty() {
            break;
        }
        if let Some(f) = line.strip_prefix("FORMAT=") {
            if f.trim() != "32-bit_rle_rgbe" {
                return Err(format!(
                    "unsupported FORMAT={} (only 32-bit_rle_rgbe)",
                    f.trim()
                ));
            }
        } else if let Some(x) = line.strip_prefix("EXPOSURE=") {
            let x: f64 = x
                .trim()
                .parse()
                .map_err(|_| format!("bad header line `{line}`"))?;
            if x > 0.0 && x.is_finite() {
                exposure *= x;
            }
        }
    }
    let res = cur.line().ok_or_else(eof)?;
    let res = std::str::from_utf8(res).map_err(|_| "bad resolution line".to_string())?;
    let parts: Vec<&str> = res.split_whitespace().collect();
    let bad_res = || {
        format!(
            "unsupported resolution line `{}` (expected `-Y h +X w`)",
            res.trim()
        )
    };
    if parts.len() != 4 || parts[2] != "+X" || (parts[0] != "-Y" && parts[0] != "+Y") {
        return Err(bad_res());
    }
    let bottom_up = parts[0] == "+Y";
    let h: usize = parts[1].parse().map_err(|_| bad_res())?;
    let w: usize = parts[3].parse().map_err(|_| bad_res())?;
    if w == 0 || h == 0 || w.checked_mul(h).is_none_or(|n| n > (1 << 31)) {
        return Err(format!("unsupported image size {w}x{h}"));
    }
    let mut img = ImageRgbF32::new(w, h);
    let mut scan = vec![[0u8; 4]; w];
    for row in 0..h {
        read_scanline(&mut cur, &mut scan)?;
        let y = if bottom_up { h - 1 - row } else { row };
        for (dst, &px) in img.data[y * w..(y + 1) * w].iter_mut().zip(&scan) {
            let v = rgbe_decode(px);
            *dst = if exposure == 1.0 {
                v
            } else {
                v.map(|c| (c as f64 / exposure) as f32)
            };
        }
    }
    Ok(img)
}

fn read_scanline(cur: &mut Cursor<'_>, scan: &mut [[u8; 4]]) -> std::result::Result<(), String> {
    let eof = || "file is truncated".to_string();
    let w = scan.len();
    let head = cur.bytes(4).ok_or_else(eof)?;
    let new_rle = (8..=0x7fff).contains(&w) && head[0] == 2 && head[1] == 2 && head[2] & 0x80 == 0;
    if new_rle {
        let len = ((head[2] as usize) << 8) | head[3] as usize;
        if len != w {
            return Err(format!(
                "RLE scanline length {len} does not match width {w}"
            ));
        }
        for c in 0..4 {
            let mut x = 0;
            while x < w {
                let count = cur.byte().ok_or_else(eof)? as usize;
                if count > 128 {
                    let n = count - 128;
                    let v = cur.byte().ok_or_else(eof)?;
                    if x + n > w {
                        return Err("RLE run overruns the scanline".into());
                    }
                    scan[x..x + n].iter_mut().for_each(|p| p[c] = v);
                    x += n;
                } else {
                    if count == 0 || x + count > w {
                        return Err("bad RLE literal count".into());
                    }
                    let src = cur.bytes(count).ok_or_else(eof)?;
                    for (p, &v) in scan[x..x + count].iter_mut().zip(src) {
                        p[c] = v;
                    }
                    x += count;
                }
            }
        }
        return Ok(());
    }
    // Flat pixels, possibly with old-style runs (1, 1, 1, n): repeat the previous pixel.
    let mut x = 0;
    let mut shift = 0u32;
    let mut px = [head[0], head[1], head[2], head[3]];
    loop {
        if px[0] == 1 && px[1] == 1 && px[2] == 1 {
            if x == 0 || shift > 24 {
                return Err("bad old-style RLE run".into());
            }
            let n = (px[3] as usize) << shift;
            if x + n > w {
                return Err("RLE run overruns the scanline".into());
            }
            let prev = scan[x - 1];
            scan[x..x + n].iter_mut().for_each(|p| *p = prev);
            x += n;
            shift += 8;
        } else {
            scan[x] = px;
            x += 1;
            shift = 0;
        }
        if x >= w {
            return Ok(());
        }
        let b = cur.bytes(4).ok_or_else(eof)?;
        px = [b[0], b[1], b[2], b[3]];
    }
}
