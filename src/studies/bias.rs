//! `fair --vary`: how a feature of the die biases it. The die rolled at N values of one feature
//! (its centre of mass along an axis, its pips' depth, its edges' radius, a coin's thickness, a
//! block's or prism's length), the same keyed throws at each, each value's faces judged against
//! a fair die's (`studies::fair`); the table, `bias.json` and the bias figure. A study
//! ([`BiasStudy`]) as `roll` and `fair` are; `design` steps the same features ([`Varied`]).

use super::fair::{assess, Fairness, Null};
use super::kind::Kind;
use super::place::{Done, Hooks, Place};
use crate::error::{Error, Field, Result};
use crate::model::faces::{Layout, DIRECTIONS};
use crate::model::mass::Features;
use crate::model::scene::Form;
use crate::report::progress::Unit;
use crate::run::runner::Runner;
use crate::run::spec::RunSpec;
use serde::{Deserialize, Serialize};

/// `fair --vary`: the die of `spec` at each value `vary` names, judged against `null`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BiasStudy {
    /// The die, the scene, the throws and the rolls at each value.
    pub spec: RunSpec,
    /// What a fair die would show.
    pub null: Null,
    /// The feature and its values, as given: "NAME=LO:HI:N" ([`parse_vary`]).
    pub vary: String,
}

impl BiasStudy {
    /// Rolls it with `runner` (its progress the rolls over every value): each value's verdict,
    /// or `None` if a stop request ended it.
    pub fn points(&self, runner: &Runner) -> Result<Option<Vec<BiasPoint>>> {
        let (what, values) = parse_vary(&self.vary)?;
        let layout = self.spec.scene.features.layout;
        vary(&self.spec, layout, what, &values, &self.null, runner)
    }

    /// The rolls over every value.
    pub fn rolls(&self) -> Result<u64> {
        Ok(self.spec.rolls * parse_vary(&self.vary)?.1.len() as u64)
    }

    /// `fair --vary --json`'s document (bias.json) and the table printed without it: the one
    /// rendering, here and in Python.
    pub fn render(&self, points: &[BiasPoint]) -> Result<(String, String)> {
        let (what, _) = parse_vary(&self.vary)?;
        let doc = bias_document(&self.spec, what, &self.null, points);
        Ok((
            crate::run::seal::to_string(&doc, true)?,
            bias_table(what, points),
        ))
    }

    /// What makes two runs of it one, for `--out`'s directory (as `fair --vary` has always
    /// claimed it).
    pub fn identity(&self) -> serde_json::Value {
        serde_json::json!({ "spec": self.spec, "null": (self.null.spec()), "vary": self.vary })
    }
}

impl Kind for BiasStudy {
    fn name(&self) -> &'static str {
        "fair"
    }

    /// The null and every value checked before the directory is claimed: a refused one
    /// writes nothing.
    fn validate(&self) -> Result<()> {
        super::fair::check_null(&self.spec, &self.null)?;
        let (what, values) = parse_vary(&self.vary)?;
        varied_specs(&self.spec, what, &values).map(drop)
    }

    fn unit(&self) -> Unit {
        Unit::Rolls { per_cell: 0 }
    }

    /// `--out`'s directory, if one is named.
    fn owns<'a>(&self, place: &'a Place) -> Option<&'a std::path::Path> {
        (!place.out.as_os_str().is_empty()).then_some(place.out.as_path())
    }

    fn check_splittable(&self) -> Result<()> {
        Err(Error::Invalid(
            "fair --vary runs on one machine: give each value its own `fair`".into(),
        ))
    }

    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        let what = parse_vary(&self.vary)?.0;
        let total = self.rolls()? as f64;
        let progress = |n: u64| (hooks.progress)(n as f64, total);
        let runner = Runner::new(place.threads, hooks.stop.clone()).with_progress(&progress);
        let Some(points) = self.points(&runner)? else {
            return Ok(Done {
                interrupted: Some(crate::run::stop::interrupted(
                    &crate::run::stop::Kept::Nothing(Some("a --vary run does not resume")),
                )),
                ..Done::default()
            });
        };
        let (json, table) = self.render(&points)?;
        let mut note = None;
        let out = &place.out;
        if !out.as_os_str().is_empty() {
            let spec = &self.spec;
            let die = spec.scene.die.title();
            let title = format!(
                "{die}, {}, {}: {} rolls a value; lines: {}",
                spec.engine.name(),
                spec.throws.style,
                spec.rolls,
                self.null
            );
            write_bias(out, what, &title, &points)?;
            crate::run::io::write_atomic(&out.join("bias.json"), json.as_bytes())?;
            if !place.json {
                note = Some(format!("wrote {}/bias.json and bias.svg, .png", out.display()).into());
            }
        }
        Ok(Done {
            stdout: match place.json {
                true => format!("{json}\n"),
                false => table,
            },
            note,
            ..Done::default()
        })
    }
}

/// A feature of the die that `fair --vary` steps through.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Varied {
    /// The centre of mass along x (breadth), mm: given outright, its other components the
    /// die's (`--com`) or 0.
    ComX,
    /// … along y (width), mm.
    ComY,
    /// … along z (length), mm.
    ComZ,
    /// The pips' depth, mm (the die must have pips).
    PipDepth,
    /// The edges' and corners' radius, mm.
    EdgeRadius,
    /// A coin's (a cylinder's) thickness, mm, its diameter kept (`--shape coin:D,H`).
    Thickness,
    /// A block's length, mm, its breadth and width kept (`--block`); or a prism's length, its
    /// sides and breadth kept (`--shape prism:N,D,L`).
    Length,
    /// A block's breadth, mm, its length and width kept.
    Breadth,
    /// A block's width, mm, its length and breadth kept.
    Width,
}

impl Varied {
    /// `scene` with this feature at `mm`: the die's shape or block for a coin's thickness or
    /// a block's length, else its features.
    pub fn apply(
        self,
        scene: &crate::model::scene::Scene,
        mm: f64,
    ) -> Result<crate::model::scene::Scene> {
        use crate::model::shape::Solid;
        let at = |why: &str| Error::field(Field::Vary, format!("{self}={mm}"), why.to_string());
        let mut s = scene.clone();
        match self {
            Varied::Thickness => {
                let Some(Solid::Cylinder { diameter, .. }) = scene.die.as_shape().map(|x| &x.solid)
                else {
                    return Err(at("the die is not a coin: give --shape coin:D,H"));
                };
                let coin =
                    crate::model::shape::named(&format!("coin:{},{mm}", diameter * 1e3), None)
                        .map_err(|e| at(&e.to_string()))?;
                s.die = Form::shape(coin);
            }
            Varied::Length | Varied::Breadth | Varied::Width => match scene.die.as_shape() {
                None => {
                    let b = scene.die.block();
                    let mut sides = [b.length, b.breadth, b.width].map(|v| v * 1e3);
                    sides[self as usize - Varied::Length as usize] = mm;
                    s.die = Form::Cuboid(
                        crate::model::block::Block::from_mm(sides[0], sides[1], sides[2])
                            .map_err(|e| at(&e.to_string()))?,
                    );
                }
                Some(shape) if self == Varied::Length && shape.name.starts_with("prism:") => {
                    // prism:N,D,L: its sides and breadth kept, its length this.
                    let args: Vec<&str> = shape.name["prism:".len()..].split(',').collect();
                    let prism = crate::model::shape::named(
                        &format!("prism:{},{},{mm}", args[0], args[1]),
                        None,
                    )
                    .map_err(|e| at(&e.to_string()))?;
                    s.die = Form::shape(prism);
                }
                Some(_) if self == Varied::Length => {
                    return Err(at(
                        "the die is not a block or a prism: give --block LxBxW or --shape \
                         prism:N,D,L",
                    ))
                }
                Some(_) => return Err(at("the die is not a block: give --block LxBxW")),
            },
            _ => {
                s.features = self.set(&scene.features, mm)?;
                // A die of any shape but a box is rounded in its hull (`mass::take_rounding`).
                crate::model::mass::take_rounding(s.die.shape_mut(), &mut s.features)
                    .map_err(|e| at(&e))?;
            }
        }
        Ok(s)
    }

    /// `features` with this feature at `mm` (the features alone: not a coin's thickness or a
    /// block's length, which are the die's shape, [`Varied::apply`]).
    pub fn set(self, features: &Features, mm: f64) -> Result<Features> {
        let m = mm / 1000.0;
        match self {
            Varied::Thickness | Varied::Length | Varied::Breadth | Varied::Width => {
                Err(Error::field(
                    Field::Vary,
                    self.to_string(),
                    "is the die's shape, not a feature",
                ))
            }
            Varied::ComX | Varied::ComY | Varied::ComZ => {
                Ok(features.with_com_on(self as usize, m))
            }
            Varied::PipDepth => features.with_pip_depth(m).ok_or_else(|| {
                Error::field(
                    Field::Vary,
                    "pip_depth",
                    "the die has no pips to vary: give them (--pips D,H or a die file)",
                )
            }),
            Varied::EdgeRadius => Ok(Features {
                edge_radius: m,
                ..*features
            }),
        }
    }
}

/// `fair --vary`'s values: `N` evenly spaced from `LO` to `HI`, from "NAME=LO:HI:N".
pub fn parse_vary(s: &str) -> Result<(Varied, Vec<f64>)> {
    let bad = |why: &str| Error::field(Field::Vary, s, why.to_string());
    let (name, range) = s
        .split_once('=')
        .ok_or_else(|| bad("write NAME=LO:HI:N, e.g. com_z=0:2:9"))?;
    let what: Varied = crate::error::parse_name("feature", name.trim())?;
    let parts: Vec<&str> = range.split(':').map(str::trim).collect();
    let [lo, hi, n] = parts[..] else {
        return Err(bad("write NAME=LO:HI:N, e.g. com_z=0:2:9"));
    };
    let (lo, hi): (f64, f64) = match (lo.parse(), hi.parse()) {
        (Ok(a), Ok(b)) if f64::is_finite(a) && f64::is_finite(b) && a <= b => (a, b),
        _ => return Err(bad("LO and HI must be numbers of mm, LO <= HI")),
    };
    let n: usize = n
        .parse()
        .ok()
        .filter(|n| (1..=1000).contains(n))
        .ok_or_else(|| bad("N must be a whole number from 1 to 1000"))?;
    let values = (0..n)
        .map(|i| {
            if n == 1 {
                lo
            } else {
                lo + (hi - lo) * i as f64 / (n - 1) as f64
            }
        })
        .collect();
    Ok((what, values))
}

/// One value of a varied feature: the die there, judged.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BiasPoint {
    /// The feature's value, mm.
    pub value: f64,
    /// The die's faces against the null.
    pub fairness: Fairness,
}

/// The die of `spec` at each of `values` of `what`, the same keyed throws at every value (so
/// that the curve's steps are the feature's, not the throws'), each judged against `null`.
/// `None` if a stop request ended it.
pub fn vary(
    spec: &RunSpec,
    layout: Layout,
    what: Varied,
    values: &[f64],
    null: &Null,
    runner: &Runner,
) -> Result<Option<Vec<BiasPoint>>> {
    let specs = varied_specs(spec, what, values)?;
    let mut out = Vec::new();
    for (i, (s, &value)) in specs.iter().zip(values).enumerate() {
        let base = i as u64 * spec.rolls;
        let progress = |n| (runner.progress)(base + n);
        let summary =
            crate::studies::roll::roll(s, None, None, None, &runner.with_progress(&progress))?
                .with_layout(layout);
        if summary.partial {
            return Ok(None);
        }
        out.push(BiasPoint {
            value,
            fairness: assess(&summary, null)?,
        });
    }
    Ok(Some(out))
}

/// The run of `spec` at each of `values` of `what`, each checked: what [`vary`] rolls, and
/// what a front end checks before it claims an output directory, so that a value the die
/// cannot take is refused with nothing written.
pub fn varied_specs(spec: &RunSpec, what: Varied, values: &[f64]) -> Result<Vec<RunSpec>> {
    if let (Varied::PipDepth, Some(shape)) = (what, spec.scene.die.hull()) {
        return Err(Error::field(
            Field::Vary,
            "pip_depth",
            format!(
                "{} has no pips (they are drilled in a cuboid's faces, --block): vary com_x, \
                 com_y or com_z",
                shape.name
            ),
        ));
    }
    values
        .iter()
        .map(|&v| {
            // The pips already sit by the run's layout (`roll --layout` placed them).
            let mut s = spec.clone();
            s.scene = what.apply(&spec.scene, v)?;
            // A value the die cannot take is named as the user wrote it, `--vary NAME=V`, not
            // as the feature's own flag, which they did not give (reliability round 5, G).
            s.validate(false).map_err(|e| match e {
                Error::Field { field, why, .. }
                    if matches!(
                        (field, what),
                        (Field::Com, Varied::ComX | Varied::ComY | Varied::ComZ)
                            | (Field::PipsDepth, Varied::PipDepth)
                            | (Field::EdgeRadius, Varied::EdgeRadius)
                    ) =>
                {
                    Error::field(Field::Vary, format!("{what}={v}"), why)
                }
                e => e,
            })?;
            // A die of any shape rests on the facets it rests on at this centre of mass.
            s.scene = s
                .scene
                .resting_at_com()
                .map_err(|e| Error::field(Field::Vary, format!("{what}={v}"), e))?;
            Ok(s)
        })
        .collect()
}

/// `fair --vary --json`'s document (bias.json): the feature, the null, the run and each
/// value's verdict.
pub fn bias_document(
    spec: &RunSpec,
    what: Varied,
    null: &Null,
    points: &[BiasPoint],
) -> serde_json::Value {
    serde_json::json!({ "vary": what, "null": (null.spec()), "spec": spec, "points": points })
}

/// `fair --vary`'s table, as the terminal shows it: a row a value of `what`, each face's
/// probability with its error, χ²'s p and the throws to see the bias.
pub fn bias_table(what: Varied, points: &[BiasPoint]) -> String {
    // Each face in the order the rows give them (a cube's 1 … 6, a shape's labels).
    let names: Vec<String> = points.first().map_or_else(Vec::new, |b| {
        b.fairness
            .faces
            .iter()
            .map(|f| f.number.to_string())
            .collect()
    });
    let mut t = format!(
        "{what} (mm) | P({}), each ± its error | χ² p | throws to see it at 2σ\n",
        match names.len() {
            0..=6 => names.join(", "),
            n => format!("{} … {}, {n} faces", names[0], names[n - 1]),
        }
    );
    for b in points {
        let f = &b.fairness;
        let ps: Vec<String> = f
            .faces
            .iter()
            .map(|x| format!("{:.4}±{:.4}", x.p, x.err))
            .collect();
        t += &format!(
            "{:>8.3} | {} | {:.2e} | {}\n",
            b.value,
            ps.join(" "),
            f.p_value,
            f.throws_2sigma.map_or("-".into(), |n| format!("{n:.0}"))
        );
    }
    t
}

/// Writes the bias figure (`bias.svg`, `.png`: each face's probability against the varied
/// feature, with its error and the null) into `dir`.
pub fn write_bias(
    dir: &std::path::Path,
    what: Varied,
    title: &str,
    points: &[BiasPoint],
) -> Result<()> {
    use crate::report::figures::{die::FaceCurve, Point};
    // Every face the die has (a cube's six, a d20's twenty), by the label it shows.
    let faces = points.first().map_or(0, |b| b.fairness.faces.len());
    let series: Vec<FaceCurve> = (0..faces)
        .map(|k| {
            let pts = points
                .iter()
                .filter_map(|b| {
                    b.fairness.faces.get(k).map(|f| Point {
                        x: b.value,
                        y: f.p,
                        y_err: f.err,
                    })
                })
                .collect();
            let null = points
                .iter()
                .filter_map(|b| b.fairness.faces.get(k).map(|f| (b.value, f.null)))
                .collect();
            FaceCurve {
                number: k as u8 + 1,
                label: {
                    let f = &points[0].fairness.faces[k];
                    // A cube's face by its number; a shape's by its label.
                    if DIRECTIONS.iter().any(|d| f.direction == *d) {
                        f.number.to_string()
                    } else {
                        f.direction.clone()
                    }
                },
                points: pts,
                null,
            }
        })
        .collect();
    crate::report::figures::die::bias(dir, "bias", title, &format!("{what}, mm"), &series)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_varied_feature_reads_its_values_and_refuses_bad_ones() {
        let (what, v) = parse_vary("com_z=0:2:5").unwrap();
        assert_eq!(what, Varied::ComZ);
        assert_eq!(v, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(parse_vary("edge_radius=1:1:1").unwrap().1, vec![1.0]);
        for bad in [
            "com_z",
            "weight=0:1:3",
            "com_z=1:0:3",
            "com_z=0:1",
            "com_z=0:1:0",
        ] {
            assert!(parse_vary(bad).is_err(), "{bad}");
        }
        let f = Varied::ComY.set(&Features::default(), 1.5).unwrap();
        assert_eq!(f.com, Some([0.0, 0.0015, 0.0]));
        assert!(Varied::PipDepth.set(&Features::default(), 1.0).is_err());
    }
}
