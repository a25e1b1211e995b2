//! A stored JSON document's checksum, so that a damaged one is refused rather than counted.
//!
//! A checkpoint's chunks and a shard's `roll --json` carry a field `checksum`:
//! `"fnv1a128:"` and 32 hex digits, the 128-bit FNV-1a hash of the document's other fields
//! written canonically (object keys sorted, no spaces, numbers and strings as `serde_json`
//! writes them). Every such document holds its run's key or specification, so the checksum
//! covers the run as well as the content: a changed count, a renamed field, a flipped bit
//! or a chunk of one run relabelled as another's all fail it. It guards against damage, not
//! forgery (anyone can compute it). Layout and spacing are not covered: a document may be
//! re-indented freely.

use serde::{de::DeserializeOwned, Serialize};
use serde_json::Value;

/// The field that holds the checksum.
pub const FIELD: &str = "checksum";

const PREFIX: &str = "fnv1a128:";

/// The checksum of `v` (an object), its `checksum` field left out.
pub fn checksum(v: &Value) -> String {
    let mut h = Fnv(0x6c62_272e_07bb_0142_62b8_2175_6295_c58d);
    match v {
        Value::Object(m) => {
            let mut m = m.clone();
            m.remove(FIELD);
            canonical(&Value::Object(m), &mut h);
        }
        v => canonical(v, &mut h),
    }
    format!("{PREFIX}{:032x}", h.0)
}

/// `value` as a JSON object with its checksum added.
pub fn sealed<T: Serialize>(value: &T) -> crate::Result<Value> {
    let mut v = serde_json::to_value(value).map_err(|e| crate::Error::failed(e.to_string()))?;
    let sum = checksum(&v);
    match &mut v {
        Value::Object(m) => {
            m.insert(FIELD.into(), Value::String(sum));
            Ok(v)
        }
        _ => Err(crate::Error::failed("only an object can be sealed")),
    }
}

/// `value`, sealed, as compact JSON (chunks) or pretty (what a user reads).
pub fn to_string<T: Serialize>(value: &T, pretty: bool) -> crate::Result<String> {
    let v = sealed(value)?;
    if pretty {
        serde_json::to_string_pretty(&v)
    } else {
        serde_json::to_string(&v)
    }
    .map_err(|e| crate::Error::failed(e.to_string()))
}

/// What is wrong with a stored document.
#[derive(Debug, Clone, PartialEq)]
pub enum Broken {
    /// Not JSON, or no checksum (written by a dicephys before checksums), or a checksum that
    /// does not match: damaged, to be rolled again.
    Damaged(String),
    /// Sealed and whole, but not of the expected shape.
    Shape(String),
}

impl std::fmt::Display for Broken {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Broken::Damaged(s) | Broken::Shape(s) => f.write_str(s),
        }
    }
}

/// Reads a sealed document: its checksum checked, then its fields.
pub fn open<T: DeserializeOwned>(text: &str) -> std::result::Result<T, Broken> {
    let v: Value = serde_json::from_str(text)
        .map_err(|e| Broken::Damaged(format!("damaged: not whole JSON ({e})")))?;
    let stored = v.get(FIELD).and_then(Value::as_str).ok_or_else(|| {
        Broken::Damaged("no checksum (damaged, or written by an older dicephys)".into())
    })?;
    let want = checksum(&v);
    if stored != want {
        return Err(Broken::Damaged(format!(
            "damaged: its checksum is {stored}, its content's {want}"
        )));
    }
    serde_json::from_value(v).map_err(|e| Broken::Shape(format!("not the expected document ({e})")))
}

struct Fnv(u128);

impl Fnv {
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= x as u128;
            self.0 = self
                .0
                .wrapping_mul(0x0000_0000_0100_0000_0000_0000_0000_013b);
        }
    }
}

/// Hashes `v` written canonically: keys sorted, no whitespace.
fn canonical(v: &Value, h: &mut Fnv) {
    match v {
        Value::Object(m) => {
            let mut keys: Vec<&String> = m.keys().collect();
            keys.sort();
            h.bytes(b"{");
            for (i, k) in keys.into_iter().enumerate() {
                if i > 0 {
                    h.bytes(b",");
                }
                canonical(&Value::String(k.clone()), h);
                h.bytes(b":");
                canonical(&m[k], h);
            }
            h.bytes(b"}");
        }
        Value::Array(a) => {
            h.bytes(b"[");
            for (i, x) in a.iter().enumerate() {
                if i > 0 {
                    h.bytes(b",");
                }
                canonical(x, h);
            }
            h.bytes(b"]");
        }
        leaf => h.bytes(serde_json::to_string(leaf).unwrap_or_default().as_bytes()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn any_change_but_layout_breaks_the_seal() {
        let v = serde_json::json!({"key": "ab", "n": [1, 2.5, "x"], "o": {"b": 1, "a": null}});
        let text = to_string(&v, true).unwrap();
        assert_eq!(
            open::<Value>(&text).unwrap(),
            v.as_object()
                .map(|m| {
                    let mut m = m.clone();
                    m.insert(FIELD.into(), sealed(&v).unwrap()[FIELD].clone());
                    Value::Object(m)
                })
                .unwrap()
        );
        let compact: Value = serde_json::from_str(&text).unwrap();
        assert!(open::<Value>(&serde_json::to_string(&compact).unwrap()).is_ok());
        for (from, to) in [("2.5", "2.4"), ("\"ab\"", "\"ac\""), ("\"a\"", "\"c\"")] {
            let bad = text.replacen(from, to, 1);
            assert!(
                matches!(open::<Value>(&bad), Err(Broken::Damaged(_))),
                "{bad}"
            );
        }
        assert!(matches!(
            open::<Value>(&serde_json::to_string(&v).unwrap()),
            Err(Broken::Damaged(_))
        ));
    }
}
