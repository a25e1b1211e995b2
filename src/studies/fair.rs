//! `dicephys fair`: is this die fair, face by face? A run's face counts set against a null
//! (each face 1/6, or each face the solid angle it subtends from the centre, the quasi-static
//! theory of a centred cuboid): each face's probability with its error and its departure in σ,
//! Pearson's χ² over the faces, and the throws a tester would need to see the bias at 2σ and at
//! 5σ. The simulation is itself such a tester: a bias it cannot resolve at 2σ is reported as
//! unresolved, with the rolls that would resolve it.

use crate::error::{Error, Result};
use crate::model::faces::{side_of, DIRECTIONS};
use crate::model::scene::Mode;
use crate::report::summary::RunSummary;
use crate::theory::{self, stats};
use serde::{Deserialize, Serialize};

/// What a fair die's faces would show.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "kebab-case")]
#[strum(serialize_all = "kebab-case")]
pub enum Null {
    /// Every face it can show equally often: 1/6 (in 2D, 1/4 for each side).
    #[default]
    Uniform,
    /// Each face the solid angle it subtends from the centre over 4π (Simpson's quasi-static
    /// theory, eq. after (InElasK), split evenly between a side's two faces): what an ideal
    /// block of these sides would show were it released at rest. 3D only.
    SolidAngle,
}

/// One face's verdict.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FaceVerdict {
    /// Its number, under the run's layout.
    pub number: u8,
    /// Its outward direction in body axes (`+x` … `-z`).
    pub direction: String,
    /// Rolls that came to rest with it up.
    pub count: u64,
    /// Its probability, count / rolls at rest on a face.
    pub p: f64,
    /// Its binomial error, √(p(1 − p)/n).
    pub err: f64,
    /// The null's probability.
    pub null: f64,
    /// p − null.
    pub departure: f64,
    /// The departure over the null's own error √(q(1 − q)/n).
    pub z: f64,
    /// The throws at which a tester counting this face alone sees its departure at 2σ
    /// (z² q(1 − q)/departure²); `None` where the simulation does not resolve the departure
    /// itself (|departure| < 2 err).
    pub throws_2sigma: Option<f64>,
    /// The same at 5σ.
    pub throws_5sigma: Option<f64>,
}

/// Is the die fair?
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fairness {
    /// The null the faces are set against.
    pub null: Null,
    /// Rolls at rest on a face: the denominator.
    pub n: u64,
    /// Each face the die can show (six in 3D, four in 2D), in the order of their numbers.
    pub faces: Vec<FaceVerdict>,
    /// Pearson's χ² of the face counts against the null.
    pub chi2: f64,
    /// Its degrees of freedom: faces − 1.
    pub dof: usize,
    /// P(χ²_dof ≥ chi2).
    pub p_value: f64,
    /// The bias per throw, λ = Σ (p − q)²/q less its noise Σ p(1 − p)/(n q) (never below 0):
    /// after N throws a tester's χ² exceeds its degrees of freedom by about N λ.
    pub lambda: f64,
    /// The throws at which a tester's expected χ² reaches the 2σ critical value (p = 0.0455):
    /// about even odds of seeing the bias. `None` when no bias is resolved (λ = 0).
    pub throws_2sigma: Option<f64>,
    /// The same at 5σ (p = 5.7 × 10⁻⁷).
    pub throws_5sigma: Option<f64>,
    /// The simulation's own χ² rejects the null at 2σ.
    pub resolved: bool,
    /// The verdict, in a sentence.
    pub verdict: String,
}

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

/// The null's probability for each direction the die can show.
fn null_probabilities(s: &RunSummary, null: Null) -> Result<Vec<f64>> {
    let shown = if s.mode == Mode::ThreeD { 6 } else { 4 };
    match (null, s.mode) {
        (Null::Uniform, _) => Ok(vec![1.0 / shown as f64; shown]),
        (Null::SolidAngle, Mode::ThreeD) => {
            let (p, _) = theory::simpson_3d(&s.spec.scene.block);
            Ok((0..6)
                .map(|d| match side_of(d) {
                    crate::model::block::Outcome::Breadth => p.breadth_vertical / 2.0,
                    crate::model::block::Outcome::Width => p.width_vertical / 2.0,
                    _ => p.length_vertical / 2.0,
                })
                .collect())
        }
        (Null::SolidAngle, Mode::TwoD) => Err(Error::field(
            "null",
            "solid-angle",
            "the solid angle is the 3D theory; in 2D give uniform",
        )),
    }
}

/// The faces of the run `s` set against `null`.
pub fn assess(s: &RunSummary, null: Null) -> Result<Fairness> {
    let q = null_probabilities(s, null)?;
    if !s.tally.faces_complete() {
        return Err(Error::Invalid(
            "some of these rolls were read from chunks written before faces were kept: roll \
             them again (a new --checkpoint)"
                .into(),
        ));
    }
    let numbers = s.layout.numbers();
    let counts: Vec<u64> = s.tally.up[..q.len()].to_vec();
    let n: u64 = counts.iter().sum();
    if n == 0 {
        return Err(Error::Failed(
            "no roll came to rest on a face: nothing to judge".into(),
        ));
    }
    let nf = n as f64;
    let see = |z: f64, q: f64, d: f64| z * z * q * (1.0 - q) / (d * d);
    let mut faces: Vec<FaceVerdict> = counts
        .iter()
        .zip(&q)
        .enumerate()
        .map(|(d, (&c, &q))| {
            let p = stats::proportion(c, n);
            let departure = p.value - q;
            let resolved = departure.abs() > 2.0 * p.err && departure != 0.0;
            FaceVerdict {
                number: numbers[d],
                direction: DIRECTIONS[d].into(),
                count: c,
                p: p.value,
                err: p.err,
                null: q,
                departure,
                z: departure / (q * (1.0 - q) / nf).sqrt(),
                throws_2sigma: resolved.then(|| see(2.0, q, departure)),
                throws_5sigma: resolved.then(|| see(5.0, q, departure)),
            }
        })
        .collect();
    faces.sort_by_key(|f| f.number);
    let chi2: f64 = counts
        .iter()
        .zip(&q)
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
            "unresolved: no departure from {null} at 2σ in {n} rolls at rest (χ² = {chi2:.1} on \
             {dof} dof, p = {p_value:.2}); these rolls would resolve a bias of λ ≥ \
             {smallest:.2e} a throw{need}"
        )
    };
    Ok(Fairness {
        null,
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

impl Fairness {
    /// The human report.
    pub fn text(&self, s: &RunSummary) -> String {
        let mut out = format!(
            "Is this die fair? {} mm, {} {}, throw {}, {} rolls ({} at rest on a face), {} \
             layout, against {}\n",
            s.block_mm.map(|v| v.to_string()).join("x"),
            s.engine,
            s.mode,
            s.spec.throws.style,
            s.rolls,
            self.n,
            s.layout,
            self.null
        );
        out += "  face  up  count      p        ± 1σ     null     departure      z   throws to see it (2σ / 5σ)\n";
        for f in &self.faces {
            let see = match (f.throws_2sigma, f.throws_5sigma) {
                (Some(a), Some(b)) => format!("{a:.0} / {b:.0}"),
                _ => "unresolved".into(),
            };
            out += &format!(
                "  {:>4}  {:<2} {:>7}  {:.5}  {:.5}  {:.5}  {:+.5}  {:+6.2}   {see}\n",
                f.number, f.direction, f.count, f.p, f.err, f.null, f.departure, f.z
            );
        }
        out += &format!("  {}\n", self.verdict);
        out
    }
}

/// Claims `dir` for this `fair` run (`run::owner`): refused if another command or another run
/// owns it.
pub fn claim(dir: &std::path::Path, identity: &serde_json::Value) -> Result<()> {
    crate::run::owner::refuse_cluster_run(dir)?;
    crate::run::owner::claim(dir, "fair", identity)
}

/// Writes `fairness.json` (the document `json`, as `--json` prints it) and the die map
/// (`die_map.svg`, `die_map.png`) into `dir`, each whole or not at all.
pub fn write(dir: &std::path::Path, json: &str, fair: &Fairness, s: &RunSummary) -> Result<()> {
    let title = format!(
        "{} mm, {} {}, throw {}: {} rolls at rest; {}",
        s.block_mm.map(|v| v.to_string()).join("x"),
        s.engine,
        s.mode,
        s.spec.throws.style,
        fair.n,
        if fair.resolved {
            format!("biased (χ² p = {:.1e})", fair.p_value)
        } else {
            format!("no bias resolved (χ² p = {:.2})", fair.p_value)
        }
    );
    let faces: Vec<crate::report::figures::die::MapFace> = fair
        .faces
        .iter()
        .map(|f| crate::report::figures::die::MapFace {
            number: f.number,
            p: f.p,
            err: f.err,
            z: f.z,
        })
        .collect();
    crate::report::figures::die::die_map(dir, "die_map", &title, &faces)?;
    crate::run::io::write_atomic(&dir.join("fairness.json"), json.as_bytes())
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
