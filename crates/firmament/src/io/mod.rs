//! Image input and output: PNG (8-bit sRGB), OpenEXR (half or single float) and
//! Radiance RGBE (`.hdr`).
//!
//! Every writer goes through a temporary file in the destination's directory
//! (`.<name>.tmp-<pid>`) that is renamed over the destination only once it has been
//! written completely and synced, and removed on any failure (including a panic), so
//! a failed or interrupted write never leaves a partial output file.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{Error, Result};

// ---------------------------------------------------------------------------------------
// Image type
// ---------------------------------------------------------------------------------------

/// A linear RGB image in physical units (radiance, or luminance-scaled; the caller
/// decides), row-major with the top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageRgbF32 {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width * height` pixels, row-major, top row first.
    pub data: Vec<[f32; 3]>,
}

impl ImageRgbF32 {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Self {
        ImageRgbF32 {
            width,
            height,
            data: vec![[0.0; 3]; width * height],
        }
    }

    /// The pixel at column `x`, row `y` (row 0 is the top). Panics when out of range.
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        self.data[y * self.width + x]
    }

    /// Sets the pixel at column `x`, row `y` (row 0 is the top). Panics when out of range.
    pub fn set(&mut self, x: usize, y: usize, rgb: [f32; 3]) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        self.data[y * self.width + x] = rgb;
    }

    fn check(&self, path: &Path) -> Result<()> {
        if self.width == 0 || self.height == 0 {
            return Err(file_error(
                path,
                format!(
                    "cannot write an empty image ({}x{})",
                    self.width, self.height
                ),
            ));
        }
        if self.data.len() != self.width * self.height {
            return Err(file_error(
                path,
                format!(
                    "image data holds {} pixels, but {}x{} needs {}",
                    self.data.len(),
                    self.width,
                    self.height,
                    self.width * self.height
                ),
            ));
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------
// Output format
// ---------------------------------------------------------------------------------------

/// An output file format, chosen by the file name's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// 8-bit sRGB PNG (tone-mapped).
    Png,
    /// OpenEXR, linear float RGB.
    Exr,
    /// Radiance RGBE, linear.
    Hdr,
}

impl OutputFormat {
    /// The format named by `path`'s extension (`.png`, `.exr`, `.hdr`, any case).
    pub fn from_path(path: impl AsRef<Path>) -> Result<OutputFormat> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(OutputFormat::Png),
            Some("exr") => Ok(OutputFormat::Exr),
            Some("hdr") => Ok(OutputFormat::Hdr),
            _ => Err(Error::invalid(
                "out",
                path.display(),
                "a file name ending in .png, .exr or .hdr",
            )),
        }
    }

    /// The canonical extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Png => "png",
            OutputFormat::Exr => "exr",
            OutputFormat::Hdr => "hdr",
        }
    }

    /// Whether the format stores linear high-dynamic-range values (EXR, HDR) rather
    /// than tone-mapped 8-bit sRGB (PNG).
    pub fn is_hdr(self) -> bool {
        !matches!(self, OutputFormat::Png)
    }
}

/// Sample precision of an EXR file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExrPrecision {
    /// 32-bit float samples (lossless for `f32` data).
    #[default]
    F32,
    /// 16-bit half float samples (11 significant bits, range about 6e-5 .. 65504).
    F16,
}

// ---------------------------------------------------------------------------------------
// Errors and atomic writes
// ---------------------------------------------------------------------------------------

fn file_error(path: &Path, reason: impl Into<String>) -> Error {
    Error::File {
        path: path.display().to_string(),
        reason: reason.into(),
    }
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A clear reason for an I/O failure on `path`; `writing` selects the wording.
fn io_reason(path: &Path, e: &std::io::Error, writing: bool) -> String {
    use std::io::ErrorKind;
    let dir = parent_dir(path);
    match e.kind() {
        ErrorKind::NotFound if writing && !dir.is_dir() => {
            format!("cannot write: directory {} does not exist", dir.display())
        }
        ErrorKind::NotFound if writing => format!("cannot write: {e}"),
        ErrorKind::NotFound => "cannot read: file does not exist".to_string(),
        ErrorKind::PermissionDenied if writing => {
            format!(
                "cannot write: permission denied (in directory {})",
                dir.display()
            )
        }
        ErrorKind::PermissionDenied => "cannot read: permission denied".to_string(),
        ErrorKind::UnexpectedEof => "cannot read: file is truncated".to_string(),
        _ if writing => format!("cannot write: {e}"),
        _ => format!("cannot read: {e}"),
    }
}

fn io_error(path: &Path, e: &std::io::Error, writing: bool) -> Error {
    file_error(path, io_reason(path, e, writing))
}

/// The temporary file's path: `.<name>.tmp-<pid>` next to `path`.
fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| file_error(path, "cannot write: the path does not name a file"))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    Ok(parent_dir(path).join(tmp_name))
}

/// Removes the temporary file on drop unless disarmed (covers errors and panics).
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Writes `path` through a temporary file: `write` fills it, then it is flushed,
/// synced and renamed over `path`. On any failure the temporary is removed and
/// `path` is left untouched.
fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let tmp = temp_path(path)?;
    if path.is_dir() {
        return Err(file_error(path, "cannot write: the path is a directory"));
    }
    let file = File::create(&tmp).map_err(|e| io_error(path, &e, true))?;
    let mut guard = TempGuard {
        path: tmp.clone(),
        armed: true,
    };
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|e| io_error(path, e.error(), true))?;
    file.sync_all().map_err(|e| io_error(path, &e, true))?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(|e| io_error(path, &e, true))?;
    guard.armed = false;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// sRGB and PNG
// ---------------------------------------------------------------------------------------

/// Linear [0, 1] to 8-bit sRGB with the IEC 61966-2-1 transfer function
/// (values outside [0, 1] are clamped, NaN gives 0; rounded to nearest).
pub fn encode_srgb(linear: f32) -> u8 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    } as f64;
    let v = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0).round().clamp(0.0, 255.0) as u8
}

/// 8-bit sRGB to linear [0, 1] (inverse of [`encode_srgb`] up to quantisation).
pub fn decode_srgb(srgb: u8) -> f32 {
    let v = srgb as f64 / 255.0;
    let c = if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    };
    c as f32
}

fn image_error(path: &Path, e: image::ImageError, writing: bool) -> Error {
    match e {
        image::ImageError::IoError(io) => io_error(path, &io, writing),
        other if writing => file_error(path, format!("cannot write PNG: {other}")),
        other => file_error(path, format!("cannot read PNG: {other}")),
    }
}

/// Writes an 8-bit sRGB PNG (`rgb8`: `width * height` pixels, row-major, top row
/// first, already tone-mapped and encoded by the caller).
pub fn write_png_srgb8(
    path: impl AsRef<Path>,
    width: usize,
    height: usize,
    rgb8: &[[u8; 3]],
) -> Result<()> {
    use image::ImageEncoder;
    let path = path.as_ref();
    if width == 0 || height == 0 || width > u32::MAX as usize || height > u32::MAX as usize {
        return Err(file_error(
            path,
            format!("cannot write a {width}x{height} PNG"),
        ));
    }
    if rgb8.len() != width * height {
        return Err(file_error(
            path,
            format!(
                "image data holds {} pixels, but {width}x{height} needs {}",
                rgb8.len(),
                width * height
            ),
        ));
    }
    let bytes: &[u8] = rgb8.as_flattened();
    write_atomic(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(
                bytes,
                width as u32,
                height as u32,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| image_error(path, e, true))
    })
}

/// Reads a PNG as 8-bit sRGB (converted to RGB8 if it is grey, has alpha or 16-bit
/// samples): `(width, height, pixels)`, row-major, top row first.
pub fn read_png_srgb8(path: impl AsRef<Path>) -> Result<(usize, usize, Vec<[u8; 3]>)> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| io_error(path, &e, false))?;
    let img = image::load(std::io::BufReader::new(file), image::ImageFormat::Png)
        .map_err(|e| image_error(path, e, false))?
        .into_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let data = img
        .into_raw()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    Ok((w, h, data))
}

// ---------------------------------------------------------------------------------------
// OpenEXR
// ---------------------------------------------------------------------------------------

fn exr_error(path: &Path, e: exr::error::Error, writing: bool) -> Error {
    use exr::error::Error as E;
    let verb = if writing {
        "cannot write EXR"
    } else {
        "cannot read EXR"
    };
    match e {
        E::Io(io) => io_error(path, &io, writing),
        E::NotSupported(s) => file_error(path, format!("{verb}: not supported: {s}")),
        E::Invalid(s) => file_error(path, format!("{verb}: invalid: {s}")),
        E::Aborted => file_error(path, format!("{verb}: aborted")),
    }
}

/// Writes an OpenEXR file with R, G, B channels at `precision` (ZIP-compressed
/// scanlines, lossless for the chosen precision).
pub fn write_exr(
    path: impl AsRef<Path>,
    image: &ImageRgbF32,
    precision: ExrPrecision,
) -> Result<()> {
    write_exr_with_attributes(path, image, precision, &[])
}

/// As [`write_exr`], also storing `attributes` as string (`text`) attributes of the
/// layer header (e.g. `("firmament:preset", "clear")`). Names and values must be
/// Latin-1 text.
pub fn write_exr_with_attributes(
    path: impl AsRef<Path>,
    image: &ImageRgbF32,
    precision: ExrPrecision,
    attributes: &[(&str, &str)],
) -> Result<()> {
    use exr::prelude::*;
    let path = path.as_ref();
    image.check(path)?;
    let mut layer_attributes = LayerAttributes::default();
    for &(name, value) in attributes {
        let (Some(n), Some(v)) = (Text::new_or_none(name), Text::new_or_none(value)) else {
            return Err(file_error(
                path,
                format!("cannot write EXR attribute `{name}`: not Latin-1 text"),
            ));
        };
        if name.is_empty() {
            return Err(file_error(
                path,
                "cannot write EXR attribute with an empty name",
            ));
        }
        layer_attributes.other.insert(n, AttributeValue::Text(v));
    }
    let size = (image.width, image.height);
    let w = image.width;
    let px = |p: Vec2<usize>| image.data[p.y() * w + p.x()];
    write_atomic(path, |out| {
        let result = match precision {
            ExrPrecision::F32 => {
                let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                    let [r, g, b] = px(p);
                    (r, g, b)
                });
                Image::from_layer(Layer::new(
                    size,
                    layer_attributes,
                    Encoding::SMALL_LOSSLESS,
                    channels,
                ))
                .write()
                .to_buffered(out)
            }
            ExrPrecision::F16 => {
                let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                    let [r, g, b] = px(p);
                    (f16::from_f32(r), f16::from_f32(g), f16::from_f32(b))
                });
                Image::from_layer(Layer::new(
                    size,
                    layer_attributes,
                    Encoding::SMALL_LOSSLESS,
                    channels,
                ))
                .write()
                .to_buffered(out)
            }
        };
        result.map_err(|e| exr_error(path, e, true))
    })
}

/// Reads the R, G, B channels of the first RGB(A) layer of an OpenEXR file (half,
/// float or uint samples, converted to `f32`; alpha is ignored).
pub fn read_exr(path: impl AsRef<Path>) -> Result<ImageRgbF32> {
    use exr::prelude::*;
    let path = path.as_ref();
    // Open ourselves first for a clear "does not exist" message.
    File::open(path).map_err(|e| io_error(path, &e, false))?;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution: Vec2<usize>, _| ImageRgbF32::new(resolution.width(), resolution.height()),
        |img: &mut ImageRgbF32, p: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = img.width;
            img.data[p.y() * w + p.x()] = [r, g, b];
        },
    )
    .map_err(|e| exr_error(path, e, false))?;
    Ok(image.layer_data.channel_data.pixels)
}

/// Reads the string (`text`) attributes of an OpenEXR file's first header (layer and
/// image attributes other than the standard ones), sorted by name.
pub fn read_exr_text_attributes(path: impl AsRef<Path>) -> Result<Vec<(String, String)>> {
    use exr::meta::attribute::AttributeValue;
    let path = path.as_ref();
    File::open(path).map_err(|e| io_error(path, &e, false))?;
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e, false))?;
    let mut out = Vec::new();
    if let Some(header) = meta.headers.first() {
        for (k, v) in header
            .own_attributes
            .other
            .iter()
            .chain(header.shared_attributes.other.iter())
        {
            if let AttributeValue::Text(t) = v {
                out.push((k.to_string(), t.to_string()));
            }
        }
    }
    out.sort();
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// Radiance RGBE
// ---------------------------------------------------------------------------------------

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

#[cfg(test)]
mod tests;
