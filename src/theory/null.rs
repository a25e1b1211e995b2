//! The null hypothesis a die's faces are judged against (`fair --null`): what a fair die of
//! its shape would show, what the quasi-static theory says it shows, or a target stated by
//! label (a design's probabilities).
//!
//! "Fair" is per facet, not per label: a cube with A on one face and B on five is fair when A
//! shows 1/6 of the time. And it has a meaning only for a die whose faces are all alike (a
//! Platonic die, a cube made slightly off): a prism, a coin or a designed die has faces of
//! several kinds, and the uniform null is then flagged ([`alike`]) for what it is, a design
//! target the die was not made for.

use crate::model::block::{Block, Mode};
use crate::model::faces::Layout;
use crate::model::scene::Scene;
use crate::model::shape::Shape;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// What a fair die's faces would show.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Null {
    /// Every facet it can rest on equally often: each label its facets' share (a d6 1/6 a
    /// face; in 2D, 1/4 for each side).
    #[default]
    Uniform,
    /// The quasi-static theory: what the die shows released at rest in a random orientation
    /// and rolling down without a bounce, the end of the gradient flow of its centre of mass's
    /// height. For a cuboid that is each face's solid angle from the centre of mass over 4π
    /// (Simpson's, eq. after (InElasK), for the paper's block; the inner box's for a made die;
    /// `theory::quasi_static`), hence its other name, `solid-angle`; for a die of any shape,
    /// the flow's exact basins (`theory::basins`). 3D only.
    QuasiStatic,
    /// A stated probability for each label (`LABEL=P,…`: a design's target), summing to 1.
    Target(Vec<(String, f64)>),
}

/// The names `--null` takes besides a target.
pub const NAMES: [&str; 3] = ["uniform", "quasi-static", "solid-angle"];

/// How far two target probabilities may miss summing to 1 (fractions written to six places).
const SUM_TOLERANCE: f64 = 1e-6;

impl std::fmt::Display for Null {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Null::Uniform => f.write_str("uniform"),
            Null::QuasiStatic => f.write_str("quasi-static"),
            Null::Target(t) => {
                let items: Vec<String> = t.iter().map(|(l, p)| format!("{l}={p}")).collect();
                write!(f, "the target {}", items.join(","))
            }
        }
    }
}

impl Null {
    /// The text `--null` parses back into this null.
    pub fn spec(&self) -> String {
        match self {
            Null::Target(t) => t
                .iter()
                .map(|(l, p)| format!("{l}={p}"))
                .collect::<Vec<_>>()
                .join(","),
            other => other.to_string(),
        }
    }
}

/// A probability written as a decimal (`0.25`) or a fraction (`1/4`).
fn probability(text: &str) -> Option<f64> {
    let v = match text.split_once('/') {
        Some((a, b)) => a.trim().parse::<f64>().ok()? / b.trim().parse::<f64>().ok()?,
        None => text.trim().parse::<f64>().ok()?,
    };
    (v.is_finite() && v > 0.0 && v <= 1.0).then_some(v)
}

impl std::str::FromStr for Null {
    type Err = String;

    /// `uniform`, `quasi-static` (or `solid-angle`), or a target `LABEL=P,…` (`edge=1/3,
    /// heads=1/3,tails=1/3`): each label once, each P above 0, summing to 1.
    fn from_str(s: &str) -> Result<Null, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "uniform" => return Ok(Null::Uniform),
            "quasi-static" | "solid-angle" => return Ok(Null::QuasiStatic),
            _ => {}
        }
        if !s.contains('=') {
            return Err(format!(
                "unknown null '{s}' (known: uniform, quasi-static, solid-angle, or a target \
                 LABEL=P,… such as heads=1/3,tails=1/3,edge=1/3)"
            ));
        }
        let mut out: Vec<(String, f64)> = Vec::new();
        for item in s.split(',').map(str::trim) {
            let (label, p) = item
                .split_once('=')
                .ok_or_else(|| format!("'{item}': write LABEL=P (e.g. 6=1/4)"))?;
            let label = label.trim();
            if label.is_empty() || out.iter().any(|(l, _)| l == label) {
                return Err(format!(
                    "the target's face '{label}' is empty or given twice"
                ));
            }
            let p = probability(p).ok_or_else(|| {
                format!(
                    "'{}' (face {label}) is not a probability above 0 and at most 1 (0.25 or \
                     1/4)",
                    p.trim()
                )
            })?;
            out.push((label.to_string(), p));
        }
        if out.len() < 2 {
            return Err("a target gives at least two faces".into());
        }
        let sum: f64 = out.iter().map(|(_, p)| p).sum();
        if (sum - 1.0).abs() > SUM_TOLERANCE {
            return Err(format!("the target's probabilities sum to {sum:.6}, not 1"));
        }
        Ok(Null::Target(out))
    }
}

impl Serialize for Null {
    /// As `--null` writes it: `"uniform"`, `"quasi-static"`, or the target `"1=0.25,…"`.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.spec())
    }
}

impl<'de> Deserialize<'de> for Null {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Null, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// The target's probability for each of `labels`, in their order: refused, naming them, when
/// the target's labels are not the die's.
pub fn target_for(target: &[(String, f64)], labels: &[String]) -> Result<Vec<f64>, String> {
    let missing: Vec<&str> = labels
        .iter()
        .filter(|l| !target.iter().any(|(t, _)| t == *l))
        .map(String::as_str)
        .collect();
    let extra: Vec<&str> = target
        .iter()
        .filter(|(t, _)| !labels.contains(t))
        .map(|(t, _)| t.as_str())
        .collect();
    if !missing.is_empty() || !extra.is_empty() {
        let mut sorted: Vec<&str> = labels.iter().map(String::as_str).collect();
        sorted.sort_by_key(|l| (l.parse::<u64>().unwrap_or(u64::MAX), l.to_string()));
        return Err(format!(
            "the target's faces are not the die's ({}): {}{}",
            sorted.join(", "),
            if extra.is_empty() {
                String::new()
            } else {
                format!("it has no face {}", extra.join(", "))
            },
            if missing.is_empty() {
                String::new()
            } else {
                format!(
                    "{}the target leaves out {}",
                    if extra.is_empty() { "" } else { "; " },
                    missing.join(", ")
                )
            }
        ));
    }
    Ok(labels
        .iter()
        .map(|l| target.iter().find(|(t, _)| t == l).map_or(0.0, |t| t.1))
        .collect())
}

/// Each of the die's labels (in the order of their first facet, `Shape::faces`) with the
/// share a fair die gives it: its resting facets over all of them.
pub fn uniform_shares(shape: &Shape) -> Vec<(String, f64)> {
    let n = shape.faces.len();
    shape.by_label(std::iter::repeat_n(1.0 / n as f64, n))
}

/// Each label a scene's die shows (`Scene::labels`, each once) with the share a fair die gives
/// it, and why "fair" is not what the die was made for where its faces are not alike: a die of
/// any shape's labels by their facets ([`uniform_shares`], [`alike`]), a block's numbers 1/N
/// each (four in 2D), alike when it is nearly a cube. What `fair --null uniform` sets a run's
/// counts and a tester's against, for every die.
pub fn uniform_label_shares(scene: &Scene, layout: Layout) -> (Vec<(String, f64)>, Option<String>) {
    match scene.die.as_shape() {
        Some(shape) => (uniform_shares(shape), alike(shape)),
        None => {
            let labels = scene.labels(layout);
            let q = 1.0 / labels.len() as f64;
            let shares = labels.into_iter().map(|l| (l, q)).collect();
            (shares, block_unlike(&scene.die.block(), scene.mode))
        }
    }
}

/// [`unlike`] for a block: each face's solid angle from its centre (Simpson's, the paper's
/// 3D theory); in 2D, its breadth against its width.
fn block_unlike(b: &Block, mode: Mode) -> Option<String> {
    match mode {
        Mode::ThreeD => {
            let (p, _) = crate::theory::simpson_3d(b);
            unlike(&[
                p.breadth_vertical / 2.0,
                p.width_vertical / 2.0,
                p.length_vertical / 2.0,
            ])
        }
        Mode::TwoD => unlike(&[b.breadth, b.width]),
    }
}

/// How far apart (relative) a die's facets' quasi-static shares may be for its faces to count
/// as alike, so that the die is one meant to be fair, made a little off: a cube 16 × 16 × 15
/// mm (6 % thin) spans 0.161–0.179 (11 %) and is a d6; a prism or a coin, whose faces are of
/// two kinds, spans factors of 3 and more.
pub const ALIKE_TOLERANCE: f64 = 0.25;

/// `None` when the faces of `shares` (each facet's quasi-static share of the uniform solid)
/// are alike, so that "fair" (each facet 1/N) means what it says; else why not, in words.
pub fn unlike(shares: &[f64]) -> Option<String> {
    let lo = shares.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = shares.iter().copied().fold(0.0, f64::max);
    (lo <= 0.0 || hi / lo - 1.0 > ALIKE_TOLERANCE).then(|| {
        format!(
            "its faces are not alike (as a uniform solid released at rest they come up \
             {lo:.3} to {hi:.3} of the time): a fair die's 1/N is a target it was not made \
             for; --null quasi-static sets it against its own shape, --null LABEL=P,… against \
             a design's"
        )
    })
}

/// [`unlike`] for a die of any shape as a uniform solid: its facets' quasi-static shares at
/// its centroid (the cylinder's caps and edge for a coin); `None` also where they cannot be
/// built.
pub fn alike(shape: &Shape) -> Option<String> {
    let centred = shape.resting_at(&nalgebra::Vector3::zeros()).ok()?;
    let shares = crate::theory::quasi_static::shape(&centred, &nalgebra::Vector3::zeros()).ok()?;
    unlike(&shares)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_null_parses_as_written_and_round_trips() {
        assert_eq!("uniform".parse::<Null>(), Ok(Null::Uniform));
        assert_eq!("solid-angle".parse::<Null>(), Ok(Null::QuasiStatic));
        let t: Null = "heads=1/3, tails=1/3,edge=0.333333333333".parse().unwrap();
        let Null::Target(ref v) = t else {
            panic!("{t:?}")
        };
        assert_eq!(v.len(), 3);
        assert!((v[0].1 - 1.0 / 3.0).abs() < 1e-15);
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(serde_json::from_str::<Null>(&json).unwrap(), t);
        assert_eq!(
            serde_json::to_string(&Null::QuasiStatic).unwrap(),
            "\"quasi-static\""
        );
        for bad in [
            "fair",
            "a=0.5,b=0.4",
            "a=0.5,a=0.5",
            "a=0,b=1",
            "a=1/0,b=1",
            "a=x,b=1",
            "a=1",
            "=0.5,b=0.5",
        ] {
            assert!(bad.parse::<Null>().is_err(), "{bad}");
        }
    }

    #[test]
    fn a_target_names_what_the_die_lacks() {
        let t = vec![("a".to_string(), 0.5), ("c".to_string(), 0.5)];
        let e = target_for(&t, &["a".into(), "b".into()]).unwrap_err();
        assert!(e.contains("no face c") && e.contains("leaves out b"), "{e}");
        let ok = target_for(&t, &["c".into(), "a".into()]).unwrap();
        assert_eq!(ok, [0.5, 0.5]);
    }

    #[test]
    fn fair_is_per_facet_and_only_for_faces_alike() {
        // A cube labelled A on one face and B on five: A 1/6, B 5/6.
        let mut cube = crate::model::shape::named("d6", None).unwrap();
        for (k, f) in cube.faces.iter_mut().enumerate() {
            f.label = if k == 0 { "A" } else { "B" }.into();
        }
        let q = uniform_shares(&cube);
        assert_eq!(q.len(), 2);
        assert!((q.iter().find(|l| l.0 == "A").unwrap().1 - 1.0 / 6.0).abs() < 1e-15);
        assert!((q.iter().find(|l| l.0 == "B").unwrap().1 - 5.0 / 6.0).abs() < 1e-15);
        // Platonic dice are alike; a prism, a coin and a long box are not.
        for name in ["d4", "d6", "d8", "d10", "d12", "d20"] {
            let s = crate::model::shape::named(name, None).unwrap();
            assert_eq!(alike(&s), None, "{name}");
        }
        for name in ["prism:3,10,10", "prism:6,16,30", "coin:24,2"] {
            let s = crate::model::shape::named(name, None).unwrap();
            assert!(alike(&s).is_some(), "{name}");
        }
    }
}
