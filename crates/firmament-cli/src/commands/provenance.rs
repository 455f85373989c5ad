//! Where a number or a picture came from: the program, the atmosphere (name and hash), the
//! method and its tables, the wavelengths; for pictures also the camera, the lights and the
//! exposure. One JSON object for `query` and the lamps' files, and the same as `firmament:*`
//! text attributes in EXR headers.

use firmament::atmosphere::Model;
use serde_json::{json, Map, Value};

/// The program, the atmosphere, the method and its tables (their configuration as JSON),
/// the wavelengths.
pub fn provenance(model: &Model, method: &str, tables: Option<Value>) -> Value {
    let mut p = json!({
        "program": "firmament",
        "version": env!("CARGO_PKG_VERSION"),
        "atmosphere": {
            "name": model.atmosphere.name,
            "hash": format!("{:016x}", model.hash),
        },
        "method": method,
        "wavelengths_nm": model.wavelengths.nm(),
    });
    if let Some(c) = tables {
        p["tables"] = c;
    }
    p
}

/// A JSON object as EXR text attributes: `firmament:KEY` for each leaf, nested keys joined
/// by `.`, arrays and numbers written as JSON.
pub fn exr_attributes(provenance: &Value) -> Vec<(String, String)> {
    fn walk(prefix: &str, v: &Value, out: &mut Vec<(String, String)>) {
        match v {
            Value::Object(m) => {
                for (k, v) in m {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&key, v, out);
                }
            }
            Value::String(s) => out.push((format!("firmament:{prefix}"), s.clone())),
            other => out.push((format!("firmament:{prefix}"), other.to_string())),
        }
    }
    let mut out = Vec::new();
    walk("", provenance, &mut out);
    out
}

/// Merge `extra`'s keys into the object `into`.
pub fn merged(mut into: Value, extra: Map<String, Value>) -> Value {
    if let Value::Object(m) = &mut into {
        m.extend(extra);
    }
    into
}
