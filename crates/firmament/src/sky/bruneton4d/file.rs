//! The table file format, version 7 (little-endian):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `FIRMLUT\0` |
//! | 4 | format version (u32, = 7; older versions are refused: 6 mapped the sky rays' distance to the top linearly (`params::sky_x_from_distance_fraction`), 5 held the μ_s mapping's joint at Bruneton's coordinate over any shell, 3 and 4 sampled the sun's elevation by Bruneton's μ_s mapping alone (`params::x_mu_s`), version 2 stored the transmittance instead of the optical depth, version 1 folded multiple scattering into `scattering`) |
//! | 4 | header length L (u32) |
//! | L | header, UTF-8 JSON: `config` (sizes, orders, mie storage), `wavelengths_nm`, `atmosphere_hash` (hex), `channels`, `order_means`, `mie_ratio`, `encoding` (`f32` or `half`) |
//! | … | f32 arrays: optical depth to the top (τ = −ln T), irradiance; then single Rayleigh (molecular), single Mie, multiple scattering, as f32 arrays (`f32`) or each as per-texel exponents and half floats ([`compact`], `half`); sizes from the header |
//! | 8 | checksum of everything before it: FNV-1a 64 over its 8-byte little-endian words, the last one zero-padded, then its length in bytes |
//!
//! A truncated, corrupt, wrong-version or mismatched file is refused, never used.

use std::io::{Read, Write};
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::compact;
use super::table::{Table2, Table4};
use super::{MieStorage, TableConfig, Tables};
use crate::{Error, Result};

const MAGIC: &[u8; 8] = b"FIRMLUT\0";
/// Current format version (6: the μ_s mapping's joint held at 15° sun elevation or above,
/// which moves the sun samples of shells thinner than about 5.5·10⁻³ of their planet’s radius;
/// 5: samples added above 18°; an older file's texels would be read at the wrong sun
/// elevations).
pub const VERSION: u32 = 7;

/// How the 4D scattering tables' values are stored (the 2D tables are always f32).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Encoding {
    /// 4 bytes a value, exact.
    #[default]
    F32,
    /// Half floats with a power-of-two scale per texel ([`compact`]): about 2 bytes a
    /// value, each within 4.9·10⁻⁴ relative of its f32 (`docs/accuracy.md`).
    Half,
}

impl Encoding {
    /// `f32` or `half`.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::F32 => "f32",
            Encoding::Half => "half",
        }
    }
}

/// What a file's header says: enough to tell which tables it holds without reading them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Header {
    /// What was computed.
    pub config: TableConfig,
    /// Wavelengths (nm), one channel each.
    pub wavelengths_nm: Vec<f64>,
    /// [`crate::atmosphere::Model::hash`] in hexadecimal.
    pub atmosphere_hash: String,
    /// Number of channels (= `wavelengths_nm.len()`).
    pub channels: usize,
    /// Mean radiance of each order per channel ([`Tables::order_means`]).
    pub order_means: Vec<Vec<f64>>,
    /// Ratio rule factors ([`Tables::mie_ratio`]).
    pub mie_ratio: Vec<f64>,
    /// The 4D tables' encoding (absent in version 3: f32).
    #[serde(default)]
    pub encoding: Encoding,
}

/// Serialise tables to bytes, the 4D tables as f32.
pub fn to_bytes(t: &Tables) -> Vec<u8> {
    to_bytes_encoded(t, Encoding::F32)
}

/// Serialise tables to bytes, the 4D tables in `encoding`.
pub fn to_bytes_encoded(t: &Tables, encoding: Encoding) -> Vec<u8> {
    let header = Header {
        config: t.config,
        wavelengths_nm: t.wavelengths_nm.clone(),
        atmosphere_hash: format!("{:016x}", t.atmosphere_hash),
        channels: t.channels(),
        order_means: t.order_means.clone(),
        mie_ratio: t.mie_ratio.clone(),
        encoding,
    };
    let json = serde_json::to_vec(&header).expect("header serialises");
    let flat = [&t.optical_depth.data, &t.irradiance.data];
    let scattering = [&t.single_rayleigh, &t.single_mie, &t.multiple];
    let bytes: usize = flat.iter().map(|d| d.len() * 4).sum::<usize>()
        + scattering
            .iter()
            .map(|s| match encoding {
                Encoding::F32 => s.data.len() * 4,
                Encoding::Half => compact::encoded_len(s.data.len() / s.channels, s.channels),
            })
            .sum::<usize>();
    let mut out = Vec::with_capacity(16 + json.len() + bytes + 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    let put_f32 = |out: &mut Vec<u8>, data: &[f32]| {
        for v in data {
            out.extend_from_slice(&v.to_le_bytes());
        }
    };
    for data in flat {
        put_f32(&mut out, data);
    }
    for table in scattering {
        match encoding {
            Encoding::F32 => put_f32(&mut out, &table.data),
            Encoding::Half => compact::encode(&table.data, table.channels, &mut out),
        }
    }
    let sum = checksum(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// The checksum of `bytes`: FNV-1a 64 over 8-byte little-endian words (the last
/// zero-padded), then the byte count (so that trailing zeros count).
fn checksum(bytes: &[u8]) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut words = bytes.chunks_exact(8);
    for w in &mut words {
        h = (h ^ u64::from_le_bytes(w.try_into().unwrap())).wrapping_mul(PRIME);
    }
    let mut last = [0u8; 8];
    last[..words.remainder().len()].copy_from_slice(words.remainder());
    h = (h ^ u64::from_le_bytes(last)).wrapping_mul(PRIME);
    (h ^ bytes.len() as u64).wrapping_mul(PRIME)
}

/// The version and header length at the start of a file, after checking its magic number
/// and version.
fn prefix(bytes: &[u8], path: &str) -> Result<(u32, usize)> {
    let bad = |reason: String| Error::TableFile {
        path: path.to_string(),
        reason,
    };
    if bytes.len() < 16 || &bytes[..8] != MAGIC {
        return Err(bad(
            "not a firmament table file (bad magic number or too short)".into(),
        ));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version != VERSION {
        return Err(bad(format!(
            "format version {version}, this program reads version {VERSION} (older files sample the sky's directions or the sun's elevation differently); bake the tables again"
        )));
    }
    let hlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    if hlen > MAX_HEADER_BYTES {
        return Err(bad(format!(
            "header length {hlen} bytes (at most {MAX_HEADER_BYTES}): the file is corrupt"
        )));
    }
    Ok((version, hlen))
}

/// The largest header accepted (a real one is a few kB).
const MAX_HEADER_BYTES: usize = 1 << 20;

/// The header of a file's bytes (magic, version and header checks only; the checksum
/// needs the whole file). Returns it with the offset of the data after it.
fn parse_header(bytes: &[u8], path: &str) -> Result<(Header, usize)> {
    let bad = |reason: String| Error::TableFile {
        path: path.to_string(),
        reason,
    };
    let (_, hlen) = prefix(bytes, path)?;
    if 16 + hlen > bytes.len() {
        return Err(bad(
            "header length beyond the end of the file: the file is truncated or corrupt".into(),
        ));
    }
    let header: Header = serde_json::from_slice(&bytes[16..16 + hlen])
        .map_err(|e| bad(format!("unreadable header: {e}")))?;
    header
        .config
        .validate()
        .map_err(|e| bad(format!("invalid sizes in header: {e}")))?;
    let n = header.channels;
    if n == 0 || n != header.wavelengths_nm.len() {
        return Err(bad("channel count does not match the wavelengths".into()));
    }
    Ok((header, 16 + hlen))
}

/// Parse tables from bytes; `path` names the file in messages.
pub fn from_bytes(bytes: &[u8], path: &str) -> Result<Tables> {
    let bad = |reason: String| Error::TableFile {
        path: path.to_string(),
        reason,
    };
    if bytes.len() < 16 + 8 || &bytes[..8] != MAGIC {
        return Err(bad(
            "not a firmament table file (bad magic number or too short)".into(),
        ));
    }
    let (body, tail) = bytes.split_at(bytes.len() - 8);
    let stored = u64::from_le_bytes(tail.try_into().unwrap());
    prefix(body, path)?;
    if checksum(body) != stored {
        return Err(bad(
            "checksum mismatch: the file is truncated or corrupt".into()
        ));
    }
    let (header, start) = parse_header(body, path)?;
    let n = header.channels;
    let s = header.config.sizes;
    let mie_channels = match header.config.mie {
        MieStorage::Separate => n,
        MieStorage::RedOnly => 1,
    };
    let scat = s.scattering_r * s.scattering_mu * s.scattering_mu_s * s.scattering_nu;
    let flat_counts = [
        s.transmittance_mu * s.transmittance_r * n,
        s.irradiance_mu_s * s.irradiance_r * n,
    ];
    let scattering_channels = [n, mie_channels, n];
    let stored_len = |channels: usize| match header.encoding {
        Encoding::F32 => scat * channels * 4,
        Encoding::Half => compact::encoded_len(scat, channels),
    };
    let expected = flat_counts.iter().sum::<usize>() * 4
        + scattering_channels
            .iter()
            .map(|&c| stored_len(c))
            .sum::<usize>();
    let data = &body[start..];
    if data.len() != expected {
        return Err(bad(format!(
            "{} bytes of table data, the header announces {expected}",
            data.len(),
        )));
    }
    let mut offset = 0;
    let mut take_f32 = |count: usize| -> Vec<f32> {
        let v = data[offset..offset + count * 4]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        offset += count * 4;
        v
    };
    let optical_depth = Table2 {
        width: s.transmittance_mu,
        height: s.transmittance_r,
        channels: n,
        data: take_f32(flat_counts[0]),
    };
    let irradiance = Table2 {
        width: s.irradiance_mu_s,
        height: s.irradiance_r,
        channels: n,
        data: take_f32(flat_counts[1]),
    };
    let mut scattering = scattering_channels.iter().map(|&channels| {
        let mut table = Table4::for_sizes(&s, channels);
        let len = stored_len(channels);
        let bytes = &data[offset..offset + len];
        table.data = match header.encoding {
            Encoding::F32 => bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            Encoding::Half => compact::decode(bytes, scat, channels),
        };
        offset += len;
        table
    });
    let (single_rayleigh, single_mie, multiple) = (
        scattering.next().unwrap(),
        scattering.next().unwrap(),
        scattering.next().unwrap(),
    );
    let hash = u64::from_str_radix(&header.atmosphere_hash, 16)
        .map_err(|_| bad("bad atmosphere hash".into()))?;
    Ok(Tables {
        config: header.config,
        wavelengths_nm: header.wavelengths_nm,
        atmosphere_hash: hash,
        transmittance: optical_depth.transmittance_of_optical_depth(),
        optical_depth,
        irradiance,
        single_rayleigh,
        single_mie,
        order_means: header.order_means,
        mie_ratio: header.mie_ratio,
        multiple,
    })
}

/// Write tables atomically (temporary file, then rename), the 4D tables as f32.
pub fn write(t: &Tables, path: &Path) -> Result<()> {
    write_encoded(t, path, Encoding::F32)
}

/// Write tables atomically (temporary file, then rename), the 4D tables in `encoding`.
pub fn write_encoded(t: &Tables, path: &Path, encoding: Encoding) -> Result<()> {
    let bytes = to_bytes_encoded(t, encoding);
    crate::io::write_atomic(path, |out| {
        out.write_all(&bytes)
            .map_err(|e| crate::io::io_error(path, &e, true))
    })
}

/// Read tables from a file (format checks only; see [`Tables::check_matches`]).
pub fn read(path: &Path) -> Result<Tables> {
    let bytes = std::fs::read(path).map_err(|e| file_error(path, &e))?;
    from_bytes(&bytes, &path.display().to_string())
}

/// Read only a file's header (which tables it holds: wavelengths, sizes, encoding), without
/// its data or checksum: [`read`] checks those.
pub fn read_header(path: &Path) -> Result<Header> {
    let mut file = std::fs::File::open(path).map_err(|e| file_error(path, &e))?;
    let mut start = [0u8; 16];
    file.read_exact(&mut start)
        .map_err(|e| file_error(path, &e))?;
    let shown = path.display().to_string();
    let (_, hlen) = prefix(&start, &shown)?;
    let mut bytes = start.to_vec();
    bytes.resize(16 + hlen, 0);
    file.read_exact(&mut bytes[16..])
        .map_err(|e| file_error(path, &e))?;
    Ok(parse_header(&bytes, &shown)?.0)
}

fn file_error(path: &Path, e: &std::io::Error) -> Error {
    Error::File {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}
