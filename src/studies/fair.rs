//! `dicephys fair`: is this die fair, face by face? A run's face counts set against a null
//! (each face 1/6, or each face the solid angle it subtends from the centre of mass, the
//! quasi-static theory, `theory::quasi_static`): each face's probability with its error and its departure in σ,
//! Pearson's χ² over the faces, and the throws a tester would need to see the bias at 2σ and at
//! 5σ. The simulation is itself such a tester: a bias it cannot resolve at 2σ is reported as
//! unresolved, with the rolls that would resolve it.

use crate::error::{Error, Field, Result};
use crate::model::faces::{Layout, DIRECTIONS};
use crate::model::scene::Mode;
pub use crate::report::fair::{FaceVerdict, Fairness, Null};
use crate::report::summary::RunSummary;
use crate::run::spec::RunSpec;
use crate::theory::{self, stats};

/// Two-sided tail of the normal beyond `z` σ: the p-value a "zσ" result stands for.
fn two_sided(z: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    let n = Normal::new(0.0, 1.0).expect("the standard normal");
    2.0 * n.sf(z)
}

/// χ²_dof's value exceeded with probability `p`.
fn critical(p: f64, dof: usize) -> f64 {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    ChiSquared::new(dof as f64).map_or(f64::NAN, |d| d.inverse_cdf(1.0 - p))
}

/// The null's probability for each direction the die can show (a die of any shape: each
/// label, in `shape_faces`' order), and a note where the null is not what the die was made for
/// (a uniform null on a die whose faces are not alike).
fn null_probabilities(s: &RunSummary, null: &Null) -> Result<(Vec<f64>, Option<String>)> {
    let scene = &s.spec.scene;
    // The labels counted, in the order of the counts (`face_counts`'): a die of any shape's
    // by label, a block's numbers by direction.
    let labels: Vec<String> = match crate::report::shape_outcomes::shape_faces(&s.tally, scene) {
        Some(f) => f.into_iter().map(|(l, _)| l).collect(),
        None => scene.labels(s.layout),
    };
    match null {
        // Every die's outcomes by one theory, in the same order.
        Null::QuasiStatic => {
            let shares = theory::quasi_static::label_shares(scene, s.layout)
                .map_err(|e| Error::field(Field::Null, "quasi-static", e))?;
            Ok((shares.into_iter().map(|(_, q)| q).collect(), None))
        }
        Null::Target(t) => Ok((
            theory::null::target_for(t, &labels)
                .map_err(|e| Error::field(Field::Null, null.spec(), e))?,
            None,
        )),
        // Each label its facets' share; a block's faces each 1/N.
        Null::Uniform => {
            let (shares, note) = theory::null::uniform_label_shares(scene, s.layout);
            Ok((share_of(&shares, &labels), note))
        }
    }
}

/// Refused before anything rolls: a null the die of `spec` cannot be judged against (a target
/// whose labels are not the die's, the quasi-static theory in 2D).
pub fn check_null(spec: &RunSpec, null: &Null) -> Result<()> {
    let scene = &spec.scene;
    match null {
        Null::Target(t) => {
            let labels = scene.labels(scene.features.layout);
            theory::null::target_for(t, &labels)
                .map(|_| ())
                .map_err(|e| Error::field(Field::Null, null.spec(), e))
        }
        Null::QuasiStatic if scene.mode == Mode::TwoD => Err(Error::field(
            Field::Null,
            "quasi-static",
            "the quasi-static theory is 3D; in 2D give uniform",
        )),
        _ => Ok(()),
    }
}

/// Each face's number, name and count: a cube's under its layout, by direction (the first
/// `shown`); a die of any shape's by the label it shows (its number where the label is one,
/// else its place).
fn face_counts(
    s: &RunSummary,
    shape: Option<&[(String, u64)]>,
    shown: usize,
) -> (Vec<u8>, Vec<String>, Vec<u64>) {
    match shape {
        Some(f) => (
            f.iter()
                .enumerate()
                .map(|(k, (l, _))| l.parse().unwrap_or(k as u8 + 1))
                .collect(),
            f.iter().map(|(l, _)| l.clone()).collect(),
            f.iter().map(|(_, c)| *c).collect(),
        ),
        None => (
            s.layout.numbers().to_vec(),
            DIRECTIONS.iter().map(|d| d.to_string()).collect(),
            s.tally.by_direction()[..shown].to_vec(),
        ),
    }
}

/// The faces of the run `s` set against `null`.
pub fn assess(s: &RunSummary, null: &Null) -> Result<Fairness> {
    let (q, note) = null_probabilities(s, null)?;
    let shape = crate::report::shape_outcomes::shape_faces(&s.tally, &s.spec.scene);
    if shape.is_none() && !s.tally.faces_complete() {
        return Err(Error::Invalid(
            "some of these rolls were read from chunks written before faces were kept: roll \
             them again (a new --checkpoint)"
                .into(),
        ));
    }
    let (numbers, names, counts) = face_counts(s, shape.as_deref(), q.len());
    let mut fair = judge(&numbers, &names, &counts, &q, null, "rolls at rest")?;
    place_faces(&mut fair, &s.spec.scene, None);
    fair.note = note;
    Ok(fair)
}

/// Counts a tester measured, `LABEL=N,LABEL=N,…` (`1=170,2=160,…`; a label as the die shows it,
/// `heads`, `20`), each label once, at least two: (label, count) in the order given.
pub fn parse_counts(text: &str) -> Result<Vec<(String, u64)>> {
    let bad = |why: String| Error::field(Field::Counts, text, why);
    let mut out: Vec<(String, u64)> = Vec::new();
    for item in text.split(',').map(str::trim) {
        let (label, n) = item
            .split_once('=')
            .ok_or_else(|| bad(format!("'{item}': write LABEL=COUNT (e.g. 1=170,2=160,…)")))?;
        let n = crate::calibration::data::count(n.trim()).map_err(bad)?;
        out.push((label.trim().to_string(), n));
    }
    check_counts(out, text)
}

/// Counts a tester measured, (label, count) in the order given (`parse_counts`' or a front
/// end's own), checked: each label once and one a count can name, at least two, some throws
/// and not too many; `given` is how they were written, for the error.
pub fn check_counts(counts: Vec<(String, u64)>, given: &str) -> Result<Vec<(String, u64)>> {
    let bad = |why: String| Error::field(Field::Counts, given, why);
    for (k, (label, _)) in counts.iter().enumerate() {
        if label.is_empty() || counts[..k].iter().any(|(l, _)| l == label) {
            return Err(bad(format!("face '{label}' is empty or given twice")));
        }
        crate::model::shape::check_label(label).map_err(bad)?;
    }
    if counts.len() < 2 {
        return Err(bad("give at least two faces' counts".into()));
    }
    // Each count is at most a fit's row's; their sum is checked too, never wrapped.
    let max = crate::calibration::data::MAX_ROW_THROWS;
    match counts.iter().try_fold(0u64, |a, (_, n)| a.checked_add(*n)) {
        Some(0) => return Err(bad("no throws counted".into())),
        Some(t) if t <= max => {}
        _ => {
            return Err(bad(format!(
                "counts too large: at most {max} throws in all"
            )))
        }
    }
    Ok(counts)
}

/// Measured counts (`parse_counts`) set against `null`: uniform (each of the faces given 1/N),
/// or quasi-static for the die `scene` describes (its faces' labels, or a cube's numbers under
/// `layout`, must be the ones counted). No simulation: the same table, χ² and throws to see
/// the bias as a run's.
pub fn assess_counts(
    counted: &[(String, u64)],
    null: &Null,
    scene: &crate::model::scene::Scene,
    layout: Layout,
) -> Result<Fairness> {
    let given: Vec<String> = counted.iter().map(|(l, _)| l.clone()).collect();
    let mut note = None;
    let q = match null {
        // The die's own labels: each its facets' share (a die whose labels merge facets);
        // other labels: 1/N over the faces given.
        Null::Uniform => {
            let (shares, unlike) = theory::null::uniform_label_shares(scene, layout);
            let own: Vec<&str> = shares.iter().map(|(l, _)| l.as_str()).collect();
            if same_labels(&given, &own) {
                note = unlike;
                share_of(&shares, &given)
            } else {
                vec![1.0 / counted.len() as f64; counted.len()]
            }
        }
        Null::Target(t) => theory::null::target_for(t, &given)
            .map_err(|e| Error::field(Field::Null, null.spec(), e))?,
        Null::QuasiStatic => {
            // The die's labels, each once, and their shares: one theory for every die.
            let shares = theory::quasi_static::label_shares(scene, layout)
                .map_err(|e| Error::field(Field::Null, "quasi-static", e))?;
            let mut labels: Vec<&str> = shares.iter().map(|(l, _)| l.as_str()).collect();
            labels.sort_by_key(|l| (l.parse::<u32>().unwrap_or(u32::MAX), l.to_string()));
            if counted.len() != shares.len() {
                return Err(Error::field(
                    Field::Counts,
                    counted.len(),
                    format!(
                        "faces counted; the die has {} ({}): count them all against the \
                         quasi-static null",
                        shares.len(),
                        labels.join(", ")
                    ),
                ));
            }
            counted
                .iter()
                .map(|(l, _)| {
                    shares
                        .iter()
                        .find(|(m, _)| m == l)
                        .map(|s| s.1)
                        .ok_or_else(|| {
                            Error::field(
                                Field::Counts,
                                l,
                                format!(
                                    "is not a face of the die (its faces: {})",
                                    labels.join(", ")
                                ),
                            )
                        })
                })
                .collect::<Result<Vec<f64>>>()?
        }
    };
    let names: Vec<String> = counted.iter().map(|(l, _)| l.clone()).collect();
    let numbers: Vec<u8> = names
        .iter()
        .enumerate()
        .map(|(k, l)| l.parse().unwrap_or(k as u8 + 1))
        .collect();
    let counts: Vec<u64> = counted.iter().map(|(_, c)| *c).collect();
    let mut fair = judge(&numbers, &names, &counts, &q, null, "throws counted")?;
    fair.note = note;
    place_faces(&mut fair, scene, Some(layout));
    Ok(fair)
}

/// Each face of `fair` told apart without the die map (issue 74.3): the outward normal of the
/// facet the die rests on to show it and that facet's share of the die's surface, for a die of
/// any shape by its label (`Shape::outcome_geometry`), for a cuboid in 3D by its direction
/// (`counted` by its layout: counts give the numbers, not the directions); nothing in 2D or
/// for a label the die has not.
fn place_faces(fair: &mut Fairness, scene: &crate::model::scene::Scene, counted: Option<Layout>) {
    let places: Vec<(String, Option<[f64; 3]>, f64)> = match (scene.die.as_shape(), scene.mode) {
        (Some(shape), _) => shape.outcome_geometry(),
        (None, Mode::TwoD) => return,
        (None, Mode::ThreeD) => {
            let b = scene.die.block();
            // Body x is the breadth, y the width, z the length.
            let side = [
                b.width * b.length,
                b.breadth * b.length,
                b.breadth * b.width,
            ];
            let total = 2.0 * side.iter().sum::<f64>();
            DIRECTIONS
                .iter()
                .enumerate()
                .map(|(d, name)| {
                    let key = match counted {
                        Some(layout) => layout.numbers()[d].to_string(),
                        None => name.to_string(),
                    };
                    // The face up is `name`; the die rests on the one opposite.
                    let mut normal = [0.0; 3];
                    normal[d / 2] = if d % 2 == 0 { -1.0 } else { 1.0 };
                    (key, Some(normal), side[d / 2] / total)
                })
                .collect()
        }
    };
    for f in &mut fair.faces {
        if let Some((_, normal, share)) = places.iter().find(|(k, _, _)| *k == f.direction) {
            f.normal = *normal;
            f.area_share = Some(*share);
        }
    }
}

/// True if `a` and `b` hold the same labels (each once in `a`).
/// Each of `labels`' share in `shares` (0 for a label the die does not show).
fn share_of(shares: &[(String, f64)], labels: &[String]) -> Vec<f64> {
    labels
        .iter()
        .map(|l| shares.iter().find(|(m, _)| m == l).map_or(0.0, |s| s.1))
        .collect()
}

fn same_labels(a: &[String], b: &[&str]) -> bool {
    let mut b: Vec<&str> = b.to_vec();
    b.sort_unstable();
    b.dedup();
    a.len() == b.len() && a.iter().all(|l| b.contains(&l.as_str()))
}

/// Each face's count set against its null probability `q`: the verdict of [`assess`]; `what`
/// names the counts in it ("rolls at rest", "throws counted").
fn judge(
    numbers: &[u8],
    names: &[String],
    counts: &[u64],
    q: &[f64],
    null: &Null,
    what: &str,
) -> Result<Fairness> {
    let n: u64 = counts.iter().sum();
    if n == 0 {
        return Err(Error::failed(
            "no roll came to rest on a face: nothing to judge",
        ));
    }
    let nf = n as f64;
    let see = |z: f64, q: f64, d: f64| z * z * q * (1.0 - q) / (d * d);
    let mut faces: Vec<FaceVerdict> = counts
        .iter()
        .zip(q)
        .enumerate()
        .map(|(d, (&c, &q))| {
            let p = stats::proportion(c, n);
            let departure = p.value - q;
            let resolved = departure.abs() > 2.0 * p.err && departure != 0.0;
            FaceVerdict {
                number: numbers[d],
                direction: names[d].clone(),
                count: c,
                p: p.value,
                err: p.err,
                null: q,
                departure,
                z: departure / (q * (1.0 - q) / nf).sqrt(),
                normal: None,
                area_share: None,
                throws_2sigma: resolved.then(|| see(2.0, q, departure)),
                throws_5sigma: resolved.then(|| see(5.0, q, departure)),
            }
        })
        .collect();
    faces.sort_by_key(|f| f.number);
    let chi2: f64 = counts
        .iter()
        .zip(q)
        .map(|(&c, &q)| (c as f64 - nf * q).powi(2) / (nf * q))
        .sum();
    let dof = q.len() - 1;
    let p_value = stats::chi_square_p_value(chi2, dof);
    let lambda = faces
        .iter()
        .map(|f| (f.departure.powi(2) - f.p * (1.0 - f.p) / nf) / f.null)
        .sum::<f64>()
        .max(0.0);
    let throws =
        |z: f64| (lambda > 0.0).then(|| (critical(two_sided(z), dof) - dof as f64) / lambda);
    let (t2, t5) = (throws(2.0), throws(5.0));
    let resolved = p_value < two_sided(2.0);
    let verdict = if resolved {
        format!(
            "biased: the faces depart from {null} with χ² = {chi2:.1} on {dof} dof (p = \
             {p_value:.2e}); a tester would see it at 2σ after about {} throws and at 5σ after \
             about {}",
            t2.map_or("?".into(), |t| format!("{t:.0}")),
            t5.map_or("?".into(), |t| format!("{t:.0}"))
        )
    } else {
        let smallest = (critical(two_sided(2.0), dof) - dof as f64) / nf;
        let need = match t2 {
            Some(t) if t > nf => format!(
                "; were the bias as estimated (λ = {lambda:.2e} a throw), about {t:.0} rolls \
                 would resolve it at 2σ"
            ),
            _ => String::new(),
        };
        format!(
            "unresolved: no departure from {null} at 2σ in {n} {what} (χ² = {chi2:.1} on {dof} \
             dof, p = {p_value:.2}); these would resolve a bias of λ ≥ {smallest:.2e} a \
             throw{need}"
        )
    };
    Ok(Fairness {
        null: null.clone(),
        note: None,
        n,
        faces,
        chi2,
        dof,
        p_value,
        lambda,
        throws_2sigma: t2,
        throws_5sigma: t5,
        resolved,
        verdict,
    })
}

/// Claims `dir` for this `fair` run (`run::owner`) and holds it while the returned file lives:
/// refused if another command or another run owns it, or another process runs this one there.
pub fn claim(
    dir: &std::path::Path,
    identity: &serde_json::Value,
) -> Result<crate::run::lock::Held> {
    super::place::claim(dir, "fair", identity, super::place::Claimant::Here)?;
    crate::run::owner::hold(dir)
}

/// Writes `fairness.json` (the document `json`, as `--json` prints it) and the die map
/// (`die_map.svg`, `die_map.png`) into `dir`, each whole or not at all.
pub fn write(dir: &std::path::Path, json: &str, fair: &Fairness, s: &RunSummary) -> Result<()> {
    let die = s.spec.scene.die.title();
    let title = format!(
        "{die}, {} {}, throw {}: {} rolls at rest; {}",
        s.engine,
        s.mode,
        s.spec.throws.style,
        fair.n,
        fair.short_verdict()
    );
    let faces: Vec<crate::report::figures::die::MapFace> = fair
        .faces
        .iter()
        .map(|f| crate::report::figures::die::MapFace {
            number: f.number,
            // The face's place on the die, so that a mirror die is drawn as its mirror.
            direction: crate::model::faces::DIRECTIONS
                .iter()
                .position(|d| *d == f.direction)
                .unwrap_or(4),
            p: f.p,
            err: f.err,
            z: f.z,
        })
        .collect();
    // The die map: a cube's net, or a die of any shape seen from two sides.
    match s.spec.scene.die.as_shape() {
        None => crate::report::figures::die::die_map(dir, "die_map", &title, &faces)?,
        Some(shape) => {
            let by_label: Vec<crate::report::figures::die::ShapeFace> = shape
                .faces
                .iter()
                .map(|o| {
                    let v = fair.faces.iter().find(|f| f.direction == o.label);
                    crate::report::figures::die::ShapeFace {
                        label: o.label.clone(),
                        p: v.map_or(0.0, |f| f.p),
                        z: v.map_or(0.0, |f| f.z),
                    }
                })
                .collect();
            crate::report::figures::die::shape_map(dir, "die_map", &title, shape, &by_label)?;
        }
    }
    // A cube's faces by number; any other die's by the label it shows.
    let by_number = s.spec.scene.die.as_shape().is_none();
    write_faces(dir, json, fair, &title, by_number)
}

/// The faces figure (`faces.svg`, `.png`: each face by its number, or by its label), the
/// table as `fairness.csv` and the document `json` as `fairness.json`, into `dir`.
fn write_faces(
    dir: &std::path::Path,
    json: &str,
    fair: &Fairness,
    title: &str,
    by_number: bool,
) -> Result<()> {
    let bars: Vec<crate::report::figures::die::FaceBar> = fair
        .faces
        .iter()
        .map(|f| crate::report::figures::die::FaceBar {
            label: if by_number {
                f.number.to_string()
            } else {
                f.direction.clone()
            },
            p: f.p,
            err: f.err,
            null: f.null,
        })
        .collect();
    let null = format!("{} null", fair.null);
    crate::report::figures::die::faces(dir, "faces", title, &null, &bars)?;
    crate::run::io::write_atomic(&dir.join("fairness.csv"), fair.csv().as_bytes())?;
    crate::run::io::write_atomic(&dir.join("fairness.json"), json.as_bytes())
}

/// Writes measured counts' verdict (`assess_counts`) into `dir`: `fairness.json` (the document
/// `json`), `fairness.csv` and the faces figure (`faces.svg`, `.png`).
pub fn write_counted(dir: &std::path::Path, json: &str, fair: &Fairness) -> Result<()> {
    let title = format!("{} throws counted; {}", fair.n, fair.short_verdict());
    write_faces(dir, json, fair, &title, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_normal_tail_and_its_critical_value_are_those_of_the_tables() {
        assert!((two_sided(2.0) - 0.0455).abs() < 1e-4);
        assert!((two_sided(5.0) - 5.733e-7).abs() < 1e-9);
        // χ²₅ at p = 0.05: 11.07.
        assert!((critical(0.05, 5) - 11.0705).abs() < 1e-3);
    }
}
