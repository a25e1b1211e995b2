//! A chunk's rolls, packed: what a roll ended with, in a few bytes, its throw left out (a
//! pure function of the run's specification and its index, recomputed on reading).
//!
//! Format `rolls-v1` (the chunk file's `format`): the rolls in index order, each
//!
//! - a tag, a LEB128 varint: bits 0-1 the fate (0 settled, 1 unconverged, 2 failed); bits
//!   2-3 its outcome (0 breadth, 1 width, 2 length, 3 unknown) or failure (0 non_finite,
//!   1 tunnelled, 2 engine_error); bit 4 certified; bit 5 the energy-gain flag; bit 6 a
//!   non-zero dip depth; bits 7-8 the certified outcome; bit 9 a face kept (a settled roll
//!   from this version on), bit 10 its end of the axis (0 positive, 1 negative), so that
//!   the face up is direction 2 × outcome + bit 10 of `faces::DIRECTIONS` (chunks written
//!   before faces were kept have neither bit, and their rolls no face); bit 11 a die of any
//!   shape's face (`Outcome::Face`, bits 2-3 then 0), its index a varint right after the
//!   tag when bit 9 is set; bit 12 a die of any shape's certified face, a varint after the
//!   certified step (a cuboid's rolls set neither, so their bytes are as before);
//! - `steps`, `engine_steps`, varints; if certified, its step, a varint;
//! - the dip's `steps` and `longest`, varints; if bit 6, its depth `penetration`, the 8
//!   bytes of the f64, little-endian (exact).
//!
//! and the whole in standard base64 (RFC 4648, padded) in the chunk's JSON, under its
//! checksum ([`crate::run::seal`]). A 2D roll of the paper's scene takes about 20 bytes, 27
//! in base64 (the JSON records took 285).

use crate::model::block::Outcome;
use crate::model::throws::Throws;
use crate::sim::roll::{Dip, Failure, Fate, RollRecord};

/// The format's name, as the chunk file gives it.
pub const FORMAT: &str = "rolls-v1";

fn outcome_bits(o: Outcome) -> u64 {
    match o {
        Outcome::Breadth => 0,
        Outcome::Width => 1,
        Outcome::Length => 2,
        Outcome::Unknown => 3,
        Outcome::Face => 0,
    }
}

fn outcome_of(b: u64) -> Outcome {
    match b & 3 {
        0 => Outcome::Breadth,
        1 => Outcome::Width,
        2 => Outcome::Length,
        _ => Outcome::Unknown,
    }
}

fn varint(out: &mut Vec<u8>, mut v: u64) {
    loop {
        let b = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            out.push(b);
            return;
        }
        out.push(b | 0x80);
    }
}

/// The rolls, packed.
pub fn pack(records: &[RollRecord]) -> Vec<u8> {
    let mut out = Vec::with_capacity(records.len() * 24);
    for r in records {
        let (fate, what) = match r.fate {
            Fate::Settled(o) => (0, outcome_bits(o)),
            Fate::Unconverged(o) => (1, outcome_bits(o)),
            Fate::Failed(Failure::NonFinite) => (2, 0),
            Fate::Failed(Failure::Tunnelled) => (2, 1),
            Fate::Failed(Failure::Engine) => (2, 2),
        };
        let deep = r.dip.penetration.to_bits() != 0;
        let mut tag = fate | what << 2 | (r.energy_gain as u64) << 5 | (deep as u64) << 6;
        if let Some((_, o)) = r.certified {
            tag |= 1 << 4 | outcome_bits(o) << 7;
        }
        let shaped = matches!(
            r.fate,
            Fate::Settled(Outcome::Face) | Fate::Unconverged(Outcome::Face)
        );
        if shaped {
            tag |= 1 << 11;
        }
        if r.certified.is_some() && r.certified_face.is_some() {
            tag |= 1 << 12;
        }
        match r.up {
            Some(_) if shaped => tag |= 1 << 9,
            Some(d) => tag |= 1 << 9 | u64::from(d & 1) << 10,
            None => {}
        }
        varint(&mut out, tag);
        if let (true, Some(d)) = (shaped, r.up) {
            varint(&mut out, u64::from(d));
        }
        varint(&mut out, r.steps);
        varint(&mut out, r.engine_steps);
        if let Some((step, _)) = r.certified {
            varint(&mut out, step);
            // A die of any shape's certified face (bit 12).
            if let Some(k) = r.certified_face {
                varint(&mut out, u64::from(k));
            }
        }
        varint(&mut out, r.dip.steps);
        varint(&mut out, r.dip.longest);
        if deep {
            out.extend_from_slice(&r.dip.penetration.to_bits().to_le_bytes());
        }
    }
    out
}

struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn varint(&mut self) -> Result<u64, String> {
        let mut v = 0u64;
        for i in 0..10 {
            let (&b, rest) = self.0.split_first().ok_or("the packed rolls end early")?;
            self.0 = rest;
            if i == 9 && b > 1 {
                return Err("a packed count past 2^64".into());
            }
            v |= ((b & 0x7f) as u64) << (7 * i);
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err("a packed count past 2^64".into())
    }

    fn f64(&mut self) -> Result<f64, String> {
        if self.0.len() < 8 {
            return Err("the packed rolls end early".into());
        }
        let (b, rest) = self.0.split_at(8);
        self.0 = rest;
        Ok(f64::from_bits(u64::from_le_bytes(
            b.try_into().unwrap_or([0; 8]),
        )))
    }
}

/// The rolls of throws `indices`, unpacked from `bytes`, each with its throw from `throws`.
pub fn unpack(bytes: &[u8], indices: &[u64], throws: &Throws) -> Result<Vec<RollRecord>, String> {
    let mut r = Reader(bytes);
    let mut out = Vec::with_capacity(indices.len());
    for &i in indices {
        let tag = r.varint()?;
        if tag >> 13 != 0 {
            return Err(format!("roll {i}: unknown tag bits"));
        }
        let what = tag >> 2 & 3;
        let shaped = tag >> 11 & 1 == 1;
        let side = |b| if shaped { Outcome::Face } else { outcome_of(b) };
        let fate = match tag & 3 {
            0 => Fate::Settled(side(what)),
            1 => Fate::Unconverged(side(what)),
            2 => Fate::Failed(match what {
                0 => Failure::NonFinite,
                1 => Failure::Tunnelled,
                2 => Failure::Engine,
                _ => return Err(format!("roll {i}: unknown failure")),
            }),
            _ => return Err(format!("roll {i}: unknown fate")),
        };
        let face = if shaped && tag >> 9 & 1 == 1 {
            let d = r.varint()?;
            Some(u8::try_from(d).map_err(|_| format!("roll {i}: face {d} past 255"))?)
        } else {
            None
        };
        let steps = r.varint()?;
        let engine_steps = r.varint()?;
        let (certified, certified_face) = if tag >> 4 & 1 == 1 {
            let step = r.varint()?;
            if tag >> 12 & 1 == 1 {
                let k = r.varint()?;
                let k = u8::try_from(k).map_err(|_| format!("roll {i}: face {k} past 255"))?;
                (Some((step, Outcome::Face)), Some(k))
            } else {
                (Some((step, outcome_of(tag >> 7))), None)
            }
        } else {
            (None, None)
        };
        let (dip_steps, longest) = (r.varint()?, r.varint()?);
        let penetration = if tag >> 6 & 1 == 1 { r.f64()? } else { 0.0 };
        let up = match (tag >> 9 & 1, fate) {
            (1, Fate::Settled(Outcome::Face)) => face,
            (1, Fate::Settled(o)) if o != crate::model::block::Outcome::Unknown => {
                Some(2 * outcome_bits(o) as u8 + (tag >> 10 & 1) as u8)
            }
            (1, _) => return Err(format!("roll {i}: a face on a roll not settled on a side")),
            _ => None,
        };
        out.push(RollRecord {
            throw: throws.get(i),
            fate,
            steps,
            engine_steps,
            certified,
            certified_face,
            energy_gain: tag >> 5 & 1 == 1,
            dip: Dip::of(dip_steps, longest, penetration),
            up,
        });
    }
    if !r.0.is_empty() {
        return Err(format!("{} bytes after the last roll", r.0.len()));
    }
    Ok(out)
}

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// `bytes` in standard base64, padded.
pub fn base64(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(B64[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// The bytes of standard base64 `s` (padded), or why not.
pub fn unbase64(s: &str) -> Result<Vec<u8>, String> {
    let b = s.as_bytes();
    if !b.len().is_multiple_of(4) {
        return Err("base64 of a length not a multiple of 4".into());
    }
    let val = |c: u8| -> Result<u32, String> {
        B64.iter()
            .position(|&x| x == c)
            .map(|p| p as u32)
            .ok_or_else(|| format!("not base64: {:?}", c as char))
    };
    let mut out = Vec::with_capacity(b.len() / 4 * 3);
    for (q, c) in b.chunks(4).enumerate() {
        let last = q == b.len() / 4 - 1;
        let pad = c.iter().rev().take_while(|&&x| x == b'=').count();
        if pad > 2 || (pad > 0 && !last) {
            return Err("base64 padding out of place".into());
        }
        let mut n = 0u32;
        for &x in &c[..4 - pad] {
            n = n << 6 | val(x)?;
        }
        n <<= 6 * pad as u32;
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips() {
        for n in 0..40u8 {
            let v: Vec<u8> = (0..n).map(|i| i.wrapping_mul(37).wrapping_add(n)).collect();
            assert_eq!(unbase64(&base64(&v)).unwrap(), v);
        }
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert!(unbase64("Zm8").is_err());
        assert!(unbase64("Z=8=").is_err());
    }

    #[test]
    fn varints_round_trip_to_u64_max() {
        for v in [0, 1, 127, 128, 1 << 35, u64::MAX - 1, u64::MAX] {
            let mut b = Vec::new();
            varint(&mut b, v);
            assert_eq!(Reader(&b).varint().unwrap(), v);
        }
    }
}
