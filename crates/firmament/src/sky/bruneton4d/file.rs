//! The table file format, version 3 (little-endian):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `FIRMLUT\0` |
//! | 4 | format version (u32, = 3; version 1 folded multiple scattering into `scattering`, version 2 stored the transmittance instead of the optical depth; both are refused) |
//! | 4 | header length L (u32) |
//! | L | header, UTF-8 JSON: `config` (sizes, orders, mie storage), `wavelengths_nm`, `atmosphere_hash` (hex), `channels`, `order_means`, `mie_ratio` |
//! | … | f32 arrays: optical depth to the top (τ = −ln T), irradiance, single Rayleigh (molecular), single Mie, multiple scattering, in that order, sizes from the header |
//! | 8 | FNV-1a 64 checksum of everything before it |
//!
//! A truncated, corrupt, wrong-version or mismatched file is refused, never used.

use std::io::Write;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::table::{Table2, Table4};
use super::{MieStorage, TableConfig, Tables};
use crate::atmosphere::model::fnv1a;
use crate::{Error, Result};

const MAGIC: &[u8; 8] = b"FIRMLUT\0";
/// Current format version.
pub const VERSION: u32 = 3;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    config: TableConfig,
    wavelengths_nm: Vec<f64>,
    atmosphere_hash: String,
    channels: usize,
    order_means: Vec<Vec<f64>>,
    mie_ratio: Vec<f64>,
}

/// Serialise tables to bytes.
pub fn to_bytes(t: &Tables) -> Vec<u8> {
    let header = Header {
        config: t.config,
        wavelengths_nm: t.wavelengths_nm.clone(),
        atmosphere_hash: format!("{:016x}", t.atmosphere_hash),
        channels: t.channels(),
        order_means: t.order_means.clone(),
        mie_ratio: t.mie_ratio.clone(),
    };
    let json = serde_json::to_vec(&header).expect("header serialises");
    let floats = t.optical_depth.data.len()
        + t.irradiance.data.len()
        + t.single_rayleigh.data.len()
        + t.single_mie.data.len()
        + t.multiple.data.len();
    let mut out = Vec::with_capacity(16 + json.len() + floats * 4 + 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    for data in [
        &t.optical_depth.data,
        &t.irradiance.data,
        &t.single_rayleigh.data,
        &t.single_mie.data,
        &t.multiple.data,
    ] {
        for v in data.iter() {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    let sum = fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
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
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version != VERSION {
        return Err(bad(format!(
            "format version {version}, this program reads version {VERSION}; bake the tables again"
        )));
    }
    let (body, tail) = bytes.split_at(bytes.len() - 8);
    let stored = u64::from_le_bytes(tail.try_into().unwrap());
    if fnv1a(body) != stored {
        return Err(bad(
            "checksum mismatch: the file is truncated or corrupt".into()
        ));
    }
    let hlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    if 16 + hlen > body.len() {
        return Err(bad("header length beyond the end of the file".into()));
    }
    let header: Header = serde_json::from_slice(&body[16..16 + hlen])
        .map_err(|e| bad(format!("unreadable header: {e}")))?;
    header
        .config
        .validate()
        .map_err(|e| bad(format!("invalid sizes in header: {e}")))?;
    let n = header.channels;
    if n == 0 || n != header.wavelengths_nm.len() {
        return Err(bad("channel count does not match the wavelengths".into()));
    }
    let s = header.config.sizes;
    let mie_channels = match header.config.mie {
        MieStorage::Separate => n,
        MieStorage::RedOnly => 1,
    };
    let scat = s.scattering_r * s.scattering_mu * s.scattering_mu_s * s.scattering_nu;
    let counts = [
        s.transmittance_mu * s.transmittance_r * n,
        s.irradiance_mu_s * s.irradiance_r * n,
        scat * n,
        scat * mie_channels,
        scat * n,
    ];
    let data = &body[16 + hlen..];
    if data.len() != counts.iter().sum::<usize>() * 4 {
        return Err(bad(format!(
            "{} bytes of table data, the header announces {}",
            data.len(),
            counts.iter().sum::<usize>() * 4
        )));
    }
    let mut offset = 0;
    let mut take = |count: usize| -> Vec<f32> {
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
        data: take(counts[0]),
    };
    let irradiance = Table2 {
        width: s.irradiance_mu_s,
        height: s.irradiance_r,
        channels: n,
        data: take(counts[1]),
    };
    let mut single_rayleigh = Table4::for_sizes(&s, n);
    single_rayleigh.data = take(counts[2]);
    let mut single_mie = Table4::for_sizes(&s, mie_channels);
    single_mie.data = take(counts[3]);
    let mut multiple = single_rayleigh.clone();
    multiple.data = take(counts[4]);
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

/// Write tables atomically (temporary file, then rename).
pub fn write(t: &Tables, path: &Path) -> Result<()> {
    let bytes = to_bytes(t);
    crate::io::write_atomic(path, |out| {
        out.write_all(&bytes)
            .map_err(|e| crate::io::io_error(path, &e, true))
    })
}

/// Read tables from a file (format checks only; see [`Tables::check_matches`]).
pub fn read(path: &Path) -> Result<Tables> {
    let bytes = std::fs::read(path).map_err(|e| Error::File {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    from_bytes(&bytes, &path.display().to_string())
}
