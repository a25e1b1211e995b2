//! A chunk's rolls, packed: what a roll ended with, in a few bytes, its throw left out (a
//! pure function of the run's specification and its index, recomputed on reading).
//!
//! Format `rolls-v2` (the chunk file's `format`): the rolls in index order, each
//!
//! - a tag, a LEB128 varint: bits 0-1 the fate (0 settled, 1 unconverged, 2 failed); bit 2,
//!   settled or unconverged, on a face (else on none), and for a failure bits 2-3 why (0
//!   non_finite, 1 tunnelled, 2 engine_error); bit 4 certified; bit 5 the energy-gain flag;
//!   bit 6 a non-zero dip depth;
//! - on a face, its index (`faces::Outcome::Face`: a cuboid's direction up, a die of any
//!   shape's outcome), a varint;
//! - `steps`, `engine_steps`, varints; if certified, its step and its face plus one (0: none),
//!   varints;
//! - the dip's `steps` and `longest`, varints; if bit 6, its depth `penetration`, the 8
//!   bytes of the f64, little-endian (exact).
//!
//! and the whole in standard base64 (RFC 4648, padded) in the chunk's JSON, under its
//! checksum ([`crate::run::seal`]). A 2D roll of the paper's scene takes about 20 bytes, 27
//! in base64 (the JSON records took 285).
//!
//! Format `rolls-v1`, which dicephys wrote before every outcome was a face, is still read
//! ([`unpack`]): it kept a cuboid's side, and its face only at rest.

use crate::model::faces::Outcome;
use crate::model::throws::Throws;
use crate::sim::roll::{Dip, Failure, Fate, RollRecord};

/// The format's name, as the chunk file gives it.
pub const FORMAT: &str = "rolls-v2";

/// The format dicephys wrote before this one, still read.
pub const FORMAT_V1: &str = "rolls-v1";

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
            Fate::Settled(o) => (0, o.face().is_some() as u64),
            Fate::Unconverged(o) => (1, o.face().is_some() as u64),
            Fate::Failed(Failure::NonFinite) => (2, 0),
            Fate::Failed(Failure::Tunnelled) => (2, 1),
            Fate::Failed(Failure::Engine) => (2, 2),
        };
        let deep = r.dip.penetration.to_bits() != 0;
        let tag = fate
            | what << 2
            | (r.certified.is_some() as u64) << 4
            | (r.energy_gain as u64) << 5
            | (deep as u64) << 6;
        varint(&mut out, tag);
        if let Fate::Settled(Outcome::Face(k)) | Fate::Unconverged(Outcome::Face(k)) = r.fate {
            varint(&mut out, u64::from(k));
        }
        varint(&mut out, r.steps);
        varint(&mut out, r.engine_steps);
        if let Some((step, o)) = r.certified {
            varint(&mut out, step);
            varint(&mut out, o.face().map_or(0, |k| u64::from(k) + 1));
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

/// A face's index as packed: at most 255.
fn face(i: u64, k: u64) -> Result<u8, String> {
    u8::try_from(k).map_err(|_| format!("roll {i}: face {k} past 255"))
}

/// The rolls of throws `indices`, unpacked from `bytes` of format `format` (`FORMAT`, or
/// `FORMAT_V1`), each with its throw from `throws`.
pub fn unpack(
    bytes: &[u8],
    indices: &[u64],
    throws: &Throws,
    format: &str,
) -> Result<Vec<RollRecord>, String> {
    let v1 = format == FORMAT_V1;
    let mut r = Reader(bytes);
    let mut out = Vec::with_capacity(indices.len());
    for &i in indices {
        let tag = r.varint()?;
        if tag >> (if v1 { 13 } else { 7 }) != 0 {
            return Err(format!("roll {i}: unknown tag bits"));
        }
        let what = tag >> 2 & 3;
        let fate = match tag & 3 {
            0 | 1 => {
                let o = if v1 {
                    outcome_v1(&mut r, i, tag)?
                } else {
                    match what {
                        0 => Outcome::Unknown,
                        1 => Outcome::Face(face(i, r.varint()?)?),
                        _ => return Err(format!("roll {i}: unknown outcome")),
                    }
                };
                if tag & 3 == 0 {
                    Fate::Settled(o)
                } else {
                    Fate::Unconverged(o)
                }
            }
            2 => Fate::Failed(match what {
                0 => Failure::NonFinite,
                1 => Failure::Tunnelled,
                2 => Failure::Engine,
                _ => return Err(format!("roll {i}: unknown failure")),
            }),
            _ => return Err(format!("roll {i}: unknown fate")),
        };
        let steps = r.varint()?;
        let engine_steps = r.varint()?;
        let certified = if tag >> 4 & 1 == 1 {
            let step = r.varint()?;
            let o = if v1 {
                certified_v1(&mut r, i, tag, fate)?
            } else {
                match r.varint()? {
                    0 => Outcome::Unknown,
                    k => Outcome::Face(face(i, k - 1)?),
                }
            };
            Some((step, o))
        } else {
            None
        };
        let (dip_steps, longest) = (r.varint()?, r.varint()?);
        let penetration = if tag >> 6 & 1 == 1 { r.f64()? } else { 0.0 };
        out.push(RollRecord {
            throw: throws.get(i),
            fate,
            steps,
            engine_steps,
            certified,
            energy_gain: tag >> 5 & 1 == 1,
            dip: Dip::of(dip_steps, longest, penetration),
        });
    }
    if !r.0.is_empty() {
        return Err(format!("{} bytes after the last roll", r.0.len()));
    }
    Ok(out)
}

// Format `rolls-v1`: what it had in place of this format's faces. Its tag: bits 0-1 the fate;
// bits 2-3 a cuboid's side (0 breadth, 1 width, 2 length, 3 unknown) or the failure; bit 4
// certified; bit 5 the energy gain; bit 6 a dip depth; bits 7-8 the certified side; bit 9 a
// face kept at rest, bit 10 its end of the axis (the face up is direction 2 × side + bit 10);
// bit 11 a die of any shape's face, its index a varint after the tag when bit 9 is set; bit 12
// a die of any shape's certified face, a varint after the certified step. The rest is laid out
// as in `rolls-v2`.

/// A settled or unconverged roll's outcome in `rolls-v1`. It kept no face at the step cap
/// (read as none), and a roll at rest from a chunk written before faces were kept (no bit 9)
/// is refused: its face is not known.
fn outcome_v1(r: &mut Reader, i: u64, tag: u64) -> Result<Outcome, String> {
    let (side, shaped, kept) = (tag >> 2 & 3, tag >> 11 & 1 == 1, tag >> 9 & 1 == 1);
    Ok(match tag & 3 {
        0 if side == 3 && !shaped => Outcome::Unknown,
        0 if !kept => {
            return Err(format!(
                "roll {i}: written before faces were kept (roll the run afresh)"
            ))
        }
        0 if shaped => Outcome::Face(face(i, r.varint()?)?),
        0 => Outcome::Face((2 * side + (tag >> 10 & 1)) as u8),
        _ => Outcome::Unknown,
    })
}

/// The certified face in `rolls-v1`: a die of any shape's (bit 12); for a cuboid, which kept
/// only its side, the face it came to rest on where that is on the certified side, else none
/// (so the audit's wrong and unknown counts are the ones it had, but for a certified roll left
/// unconverged, now unknown).
fn certified_v1(r: &mut Reader, i: u64, tag: u64, fate: Fate) -> Result<Outcome, String> {
    if tag >> 12 & 1 == 1 {
        return Ok(Outcome::Face(face(i, r.varint()?)?));
    }
    Ok(match fate {
        Fate::Settled(o @ Outcome::Face(d)) if u64::from(d / 2) == tag >> 7 & 3 => o,
        _ => Outcome::Unknown,
    })
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

    fn throws() -> Throws {
        use crate::model::throws::{ThrowKind, ThrowRanges, ThrowStyle};
        Throws::styled(
            ThrowKind::Keyed,
            ThrowStyle::Paper,
            None,
            7,
            ThrowRanges::default(),
            0,
        )
    }

    fn record(i: u64, fate: Fate, certified: Option<(u64, Outcome)>) -> RollRecord {
        RollRecord {
            throw: throws().get(i),
            fate,
            steps: 1000 + i,
            engine_steps: 900 + i,
            certified,
            energy_gain: i % 2 == 1,
            dip: Dip::of(
                i,
                i / 2,
                if i.is_multiple_of(3) {
                    0.0
                } else {
                    1e-6 * i as f64
                },
            ),
        }
    }

    #[test]
    fn every_fate_and_face_round_trips() {
        let face = Outcome::Face;
        let recs = [
            record(0, Fate::Settled(face(3)), Some((700, face(3)))),
            record(1, Fate::Settled(Outcome::Unknown), None),
            record(2, Fate::Unconverged(face(200)), Some((9, face(1)))),
            record(3, Fate::Unconverged(Outcome::Unknown), None),
            record(4, Fate::Failed(Failure::Tunnelled), Some((5, face(0)))),
            record(5, Fate::Settled(face(255)), Some((6, Outcome::Unknown))),
            record(6, Fate::Failed(Failure::Engine), None),
        ];
        let bytes = pack(&recs);
        let back = unpack(&bytes, &[0, 1, 2, 3, 4, 5, 6], &throws(), FORMAT).unwrap();
        assert_eq!(back, recs);
        // A byte short, or one too many, is an error.
        assert!(unpack(
            &bytes[..bytes.len() - 1],
            &[0, 1, 2, 3, 4, 5, 6],
            &throws(),
            FORMAT
        )
        .is_err());
        let mut more = bytes.clone();
        more.push(0);
        assert!(unpack(&more, &[0, 1, 2, 3, 4, 5, 6], &throws(), FORMAT).is_err());
    }

    /// One roll in `rolls-v1`: its tag, then what follows it (no dip).
    fn v1(tag: u64, after_tag: &[u64], steps: &[u64]) -> Vec<u8> {
        let mut b = Vec::new();
        varint(&mut b, tag);
        for &v in after_tag.iter().chain(steps).chain(&[0, 0]) {
            varint(&mut b, v);
        }
        b
    }

    #[test]
    fn a_v1_chunk_reads_as_faces() {
        let read = |b: &[u8]| unpack(b, &[0], &throws(), FORMAT_V1).map(|r| r[0]);
        // A cuboid at rest, width vertical (bits 2-3: 1), its face kept (bit 9) at the
        // negative end (bit 10): direction 3, −y up.
        let r = read(&v1(1 << 2 | 1 << 9 | 1 << 10, &[], &[50, 40])).unwrap();
        assert_eq!(r.fate, Fate::Settled(Outcome::Face(3)));
        assert_eq!((r.steps, r.engine_steps, r.certified), (50, 40, None));
        // Certified width (bits 7-8) at step 30, at rest on −y: the certificate named that
        // face; certified length, a side it did not rest on: wrong, so no face.
        let tag = 1 << 2 | 1 << 4 | 1 << 9 | 1 << 10;
        let r = read(&v1(tag | 1 << 7, &[], &[50, 40, 30])).unwrap();
        assert_eq!(r.certified, Some((30, Outcome::Face(3))));
        let r = read(&v1(tag | 2 << 7, &[], &[50, 40, 30])).unwrap();
        assert_eq!(r.certified, Some((30, Outcome::Unknown)));
        // Unknown at rest, and a cuboid moving at the cap (its side only): no face.
        let r = read(&v1(3 << 2, &[], &[50, 40])).unwrap();
        assert_eq!(r.fate, Fate::Settled(Outcome::Unknown));
        let r = read(&v1(1 | 2 << 2, &[], &[50, 40])).unwrap();
        assert_eq!(r.fate, Fate::Unconverged(Outcome::Unknown));
        // A die of any shape at rest on its face 7 (bit 11, the index after the tag), and
        // certified on face 7 (bit 12, after the certified step).
        let tag = 1 << 4 | 1 << 9 | 1 << 11 | 1 << 12;
        let r = read(&v1(tag, &[7], &[50, 40, 30, 7])).unwrap();
        assert_eq!(r.fate, Fate::Settled(Outcome::Face(7)));
        assert_eq!(r.certified, Some((30, Outcome::Face(7))));
        // A failure.
        let r = read(&v1(2 | 1 << 2, &[], &[50, 40])).unwrap();
        assert_eq!(r.fate, Fate::Failed(Failure::Tunnelled));
        // A cuboid at rest from a chunk written before faces were kept: refused.
        let e = read(&v1(1 << 2, &[], &[50, 40])).unwrap_err();
        assert!(e.contains("before faces were kept"), "{e}");
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
