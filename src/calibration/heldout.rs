//! Many blocks predicted at once (`predict --blocks`), and, where the file counts their throws,
//! a held-out test: each row's measured ratio against its prediction (z), and Pearson's χ² of
//! every count against the predicted probabilities, widened by the prediction's own error.
//!
//! ```text
//! label,block,mode[,surface][,thrower][,length_vertical,breadth_vertical,width_vertical]
//! new-1,140x26x12,2d,MDF,,0,120,380
//! ```
//!
//! A counts file (`fit --data`'s format) is read as well: its rows are predicted and tested.

use crate::calibration::data::{self, shown, DataRow};
use crate::calibration::predict::{BlockPrediction, Predicted};
use crate::calibration::proper::{self, Score, Scores};
use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::model::scene::Mode;
use crate::theory::stats;
use serde::{Deserialize, Serialize};

/// One block to predict, with its measured counts if the file has them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockRow {
    /// The row's name.
    pub label: String,
    /// The block.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// The fit's surface to use (empty: the fit's only one).
    pub surface: Option<String>,
    /// The fit's thrower to use (empty: the fit's only one).
    pub thrower: Option<String>,
    /// Counts of length, breadth and width vertical, if measured.
    pub counts: Option<[u64; 3]>,
    /// The outcomes a counts file's row counts apart (indices into `counts`; a `-` merges an
    /// outcome into a congruent one); `None`: every outcome the mode has, apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub groups: Option<Vec<Vec<usize>>>,
}

/// Reliability round 5, class J: a column a blocks file does not know (face counts among
/// them) used to be dropped, leaving the row unmeasured in silence; now it is refused.
fn known_columns(header: &[String]) -> std::result::Result<(), String> {
    const KNOWN: [&str; 8] = [
        "label",
        "block",
        "mode",
        "surface",
        "thrower",
        "length_vertical",
        "breadth_vertical",
        "width_vertical",
    ];
    match header.iter().find(|h| !KNOWN.contains(&h.as_str())) {
        Some(h) => Err(format!(
            "unknown column '{}' (a blocks file has {}; face counts belong in a counts file, \
             `fit --data`)",
            shown(h),
            KNOWN.join(", ")
        )),
        None => Ok(()),
    }
}

/// Reads a blocks file (or a counts file); `name` names it in messages.
pub fn parse(text: &str, name: &str) -> Result<Vec<BlockRow>> {
    if text
        .lines()
        .find(|l| !l.starts_with('#'))
        .is_some_and(|h| h.contains("length_mm"))
    {
        return data::parse(text, name)?
            .into_iter()
            .map(|r| from_counts(r, name))
            .collect();
    }
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let bad = |line: u64, m: String| Error::Invalid(format!("{name}: line {line}: {m}"));
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| bad(1, shown(&e.to_string())))?
        .iter()
        .map(str::to_string)
        .collect();
    let col = |c: &str| header.iter().position(|h| h == c);
    known_columns(&header).map_err(|m| bad(1, m))?;
    let (Some(label), Some(block), Some(mode)) = (col("label"), col("block"), col("mode")) else {
        return Err(bad(
            1,
            "the header needs label, block and mode (and may have surface, thrower, \
             length_vertical, breadth_vertical, width_vertical), or is a counts file's"
                .into(),
        ));
    };
    let count_cols: Vec<Option<usize>> = data::OUTCOMES
        .iter()
        .map(|o| col(&format!("{o}_vertical")))
        .collect();
    if count_cols.iter().any(Option::is_some) && count_cols.iter().any(Option::is_none) {
        return Err(bad(1, "give all three count columns or none".into()));
    }
    let mut rows: Vec<BlockRow> = Vec::new();
    for rec in reader.records() {
        let rec = rec.map_err(|e| Error::Invalid(shown(&format!("{name}: {e}"))))?;
        let line = rec.position().map_or(0, |p| p.line());
        let field = |c: usize| rec.get(c).unwrap_or("").to_string();
        let optional = |c: &str| col(c).map(field).filter(|v| !v.is_empty());
        let block: Block = field(block)
            .parse()
            .map_err(|e: Error| bad(line, format!("block: {e}")))?;
        let mode: Mode = field(mode).parse().map_err(|_| {
            bad(
                line,
                format!("mode '{}' is not 2d or 3d", shown(&field(mode))),
            )
        })?;
        let counts = match count_cols.as_slice() {
            // A row may leave all three empty: a block not measured.
            [Some(l), Some(b), Some(w)] if [l, b, w].iter().all(|&&i| field(i).is_empty()) => None,
            [Some(l), Some(b), Some(w)] => {
                let mut c = [0u64; 3];
                for (k, &i) in [l, b, w].into_iter().enumerate() {
                    c[k] = super::data::count(&field(i)).map_err(|m| bad(line, m))?;
                }
                Some(c)
            }
            _ => None,
        };
        let row = BlockRow {
            label: field(label),
            block,
            mode,
            surface: optional("surface"),
            thrower: optional("thrower"),
            counts,
            groups: None,
        };
        if row.label.is_empty() || rows.iter().any(|r| r.label == row.label) {
            return Err(bad(
                line,
                format!("label '{}' empty or used twice", shown(&row.label)),
            ));
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(Error::Invalid(format!("{name}: no blocks")));
    }
    Ok(rows)
}

/// A counts file's row as a block to predict and test.
fn from_counts(r: DataRow, name: &str) -> Result<BlockRow> {
    let counts = match r.outcomes {
        data::Outcomes::Sides => [r.counts[0], r.counts[1], r.counts[2]],
        data::Outcomes::Faces => {
            return Err(Error::Invalid(format!(
                "{name}: face counts: the blocks a prediction tests are counted by side \
                 (length_vertical, breadth_vertical, width_vertical)"
            )))
        }
    };
    Ok(BlockRow {
        label: r.label,
        block: r.block,
        mode: r.mode,
        surface: Some(r.surface),
        thrower: (r.thrower != "all").then_some(r.thrower),
        counts: Some(counts),
        groups: Some(r.groups),
    })
}

/// A value and its standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub err: f64,
}

/// One block's prediction, and its test where it was measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PredictedRow {
    /// The row's name.
    pub label: String,
    /// The prediction.
    pub prediction: BlockPrediction,
    /// The measured counts (length, breadth, width), if any.
    pub counts: Option<[u64; 3]>,
    /// The measured ratio N(breadth)/N(width) with its binomial error (the paper's).
    pub measured_ratio: Option<Measured>,
    /// (measured − predicted)/√(σ_measured² + σ_predicted²) of the ratio.
    pub z: Option<f64>,
    /// The row's Pearson χ² over its outcomes (a 2D row: its sides), each count's variance
    /// N p (1 − p)-like widened by the prediction's: (c − N p)²/(N p + N² σ_p²).
    pub chi2: Option<f64>,
    /// Its degrees of freedom: the outcomes counted less one.
    pub dof: Option<usize>,
    /// The proper scores of the prediction against the counts, beside its baselines'
    /// ([`crate::calibration::proper`]); left out where the row was not measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scores: Option<Scores>,
}

/// Every block's prediction, with the held-out test over the measured ones.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Predictions {
    /// Each block, in the file's order.
    pub rows: Vec<PredictedRow>,
    /// Σ χ² over the measured rows.
    pub chi2: Option<f64>,
    /// Σ dof over them.
    pub dof: Option<usize>,
    /// P(χ²_dof ≥ χ²).
    pub p_value: Option<f64>,
    /// The measured rows' proper scores summed (the dice's included), beside the baselines'.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scores: Option<Scores>,
    /// Each die of any shape a `die` column named, in the file's order: its prediction (its
    /// `tests` the row's scores).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dice: Vec<PredictedDie>,
    /// The fit predicted from.
    pub fit: String,
    /// The command line that made it.
    pub command_line: String,
}

/// A die of any shape's row of a counts file, predicted.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PredictedDie {
    /// The row's name.
    pub label: String,
    /// Its die, as the `die` column names it.
    pub die: String,
    /// The prediction, scored against the row's counts (its `tests`).
    pub prediction: BlockPrediction,
}

/// `row`'s prediction `p`, tested against its counts if it has them.
pub fn test(row: &BlockRow, p: BlockPrediction) -> PredictedRow {
    let Some(c) = row.counts else {
        return PredictedRow {
            label: row.label.clone(),
            prediction: p,
            counts: None,
            measured_ratio: None,
            z: None,
            chi2: None,
            dof: None,
            scores: None,
        };
    };
    let (b, w) = (c[1] as f64, c[2] as f64);
    // A misfitting fit's counts scatter φ times the binomial's (its overdispersion).
    let phi = p.overdispersion.max(1.0);
    let measured_ratio = (b > 0.0 && w > 0.0).then(|| {
        // Binomial: q = b/(b + w), r = q/(1 − q), Var r = q(1 − q)/(n (1 − q)⁴).
        let n = b + w;
        let q = b / n;
        Measured {
            value: b / w,
            err: (phi * q * (1.0 - q) / n).sqrt() / (1.0 - q).powi(2),
        }
    });
    let z = measured_ratio
        .zip(p.ratio)
        .map(|(m, r)| stats::z_score(m.value, m.err, r.value, r.err));
    let scores = Some(Scores {
        prediction: score_against(row, &p.p, phi),
        ..Scores::default()
    });
    let (counts, values, sigma) = cells(row, &p.p).unwrap_or_default();
    let n: f64 = counts.iter().map(|&k| k as f64).sum();
    let norm: f64 = values.iter().sum();
    let chi2 = (n > 0.0 && norm > 0.0).then(|| {
        counts
            .iter()
            .zip(values.iter().zip(&sigma))
            .map(|(&k, (&v, &e))| {
                let (q, s) = (v / norm, e / norm);
                let var = phi * n * q + n * n * s * s;
                if var > 0.0 {
                    (k as f64 - n * q).powi(2) / var
                } else {
                    0.0
                }
            })
            .sum()
    });
    PredictedRow {
        label: row.label.clone(),
        prediction: p,
        counts: Some(c),
        measured_ratio,
        z,
        chi2,
        dof: chi2.map(|_| counts.len() - 1),
        scores,
    }
}

/// The outcomes a block's row counts: a 2D block cannot stand on its end.
fn live(mode: Mode) -> Vec<usize> {
    match mode {
        Mode::ThreeD => vec![0, 1, 2],
        Mode::TwoD => vec![1, 2],
    }
}

/// The cells a measured row counts apart: its counts, and `p`'s values and errors (length,
/// breadth, width vertical) summed over each (errors in quadrature): a counts file's groups (a
/// `-` merges two congruent outcomes), else the mode's outcomes (a 2D block cannot stand on
/// its end). `None` unmeasured.
fn cells(row: &BlockRow, p: &[Predicted]) -> Option<Cells> {
    let c = row.counts?;
    let groups: Vec<Vec<usize>> = row
        .groups
        .clone()
        .unwrap_or_else(|| live(row.mode).into_iter().map(|k| vec![k]).collect());
    let of = |g: &Vec<usize>, f: &dyn Fn(&Predicted) -> f64| {
        g.iter().map(|&k| p.get(k).map_or(f64::NAN, f)).sum::<f64>()
    };
    Some((
        groups
            .iter()
            .map(|g| g.iter().map(|&k| c[k]).sum())
            .collect(),
        groups.iter().map(|g| of(g, &|q| q.value)).collect(),
        groups
            .iter()
            .map(|g| of(g, &|q| q.err * q.err).sqrt())
            .collect(),
    ))
}

/// A row's cells: counts, predicted values, their errors.
type Cells = (Vec<u64>, Vec<f64>, Vec<f64>);

/// The proper scores of `p` (length, breadth, width vertical) against `row`'s counts, from a
/// fit of overdispersion `phi`; `None` where the row was not measured or `p` lacks an outcome.
pub fn score_against(row: &BlockRow, p: &[Predicted], phi: f64) -> Option<Score> {
    let (counts, values, sigma) = cells(row, p)?;
    let usable = counts.iter().sum::<u64>() > 0
        && values.iter().all(|v| v.is_finite())
        && values.iter().sum::<f64>() > 0.0;
    usable.then(|| proper::score(&counts, &values, &sigma, phi))
}

/// The rows' predictions, with the χ² of the measured ones.
pub fn collect(
    rows: Vec<PredictedRow>,
    dice: Vec<PredictedDie>,
    fit: String,
    command_line: String,
) -> Predictions {
    let tested: Vec<&PredictedRow> = rows.iter().filter(|r| r.chi2.is_some()).collect();
    let chi2 = (!tested.is_empty()).then(|| tested.iter().filter_map(|r| r.chi2).sum::<f64>());
    let dof = (!tested.is_empty()).then(|| tested.iter().filter_map(|r| r.dof).sum::<usize>());
    let p_value = chi2
        .zip(dof)
        .filter(|(_, d)| *d > 0)
        .map(|(c, d)| stats::chi_square_p_value(c, d));
    let scored: Vec<&Scores> = tested
        .iter()
        .filter_map(|r| r.scores.as_ref())
        .chain(
            dice.iter()
                .flat_map(|d| &d.prediction.tests)
                .map(|t| &t.scores),
        )
        .collect();
    let scores = (!scored.is_empty()).then(|| Scores::total(&scored));
    Predictions {
        rows,
        chi2,
        dof,
        p_value,
        scores,
        dice,
        fit,
        command_line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_it_does_not_know_is_refused_not_dropped() {
        let e = parse("label,block,mode,face_1\nA,140x24x20,3d,5\n", "b.csv").unwrap_err();
        assert!(e.to_string().contains("unknown column 'face_1'"), "{e}");
        let e = parse(
            "label,block,mode,lenght_vertical\nA,140x24x20,3d,5\n",
            "b.csv",
        );
        assert!(e.is_err());
    }

    #[test]
    fn blocks_files_and_counts_files_both_read() {
        let rows = parse(
            "label,block,mode,surface,length_vertical,breadth_vertical,width_vertical\n\
             a,140x26x12,2d,MDF,0,120,380\nb,140x24x20,3d,,1,2,3\n",
            "b.csv",
        )
        .unwrap();
        assert_eq!(rows[0].counts, Some([0, 120, 380]));
        assert_eq!(rows[0].surface.as_deref(), Some("MDF"));
        assert_eq!(rows[1].surface, None);
        let some = parse(
            "label,block,mode,length_vertical,breadth_vertical,width_vertical\n\
             a,140x26x12,2d,,,\n",
            "b.csv",
        )
        .unwrap();
        assert_eq!(some[0].counts, None);
        let bare = parse("label,block,mode\nx,140x24x20,3d\n", "b.csv").unwrap();
        assert_eq!(bare[0].counts, None);
        let counts = parse(
            "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\n\
             a,MDF,140,24,20,2d,0,361,639\n",
            "c.csv",
        )
        .unwrap();
        assert_eq!(counts[0].counts, Some([0, 361, 639]));
        for (text, says) in [
            ("label,mode\n", "needs label, block and mode"),
            ("label,block,mode,length_vertical\n", "all three"),
            ("label,block,mode\na,14x,3d\n", "line 2: block"),
            (
                "label,block,mode\na,140x24x20,3d\na,140x24x20,3d\n",
                "used twice",
            ),
        ] {
            let e = parse(text, "b.csv").unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn a_prediction_equal_to_the_counts_has_no_chi2_and_a_far_one_has_much() {
        use crate::calibration::predict::Predicted;
        let pred = |pb: f64| BlockPrediction {
            block: Block::from_mm(140.0, 24.0, 20.0).unwrap(),
            mode: Mode::TwoD,
            surface: "all".into(),
            thrower: "all".into(),
            p: [0.0, pb, 1.0 - pb]
                .iter()
                .map(|&v| Predicted {
                    value: v,
                    err: 0.0,
                    err_params: 0.0,
                    err_sim: 0.0,
                    err_model: 0.0,
                    fit_value: None,
                })
                .collect(),
            ratio: Some(Predicted {
                value: pb / (1.0 - pb),
                err: 0.0,
                err_params: 0.0,
                err_sim: 0.0,
                err_model: 0.0,
                fit_value: None,
            }),
            faces: None,
            labels: Vec::new(),
            shape: None,
            theory_ratio: Some(0.5),
            draws: 2,
            rolls: 10,
            unsettled: 0,
            extrapolation: None,
            overdispersion: 1.0,
            discrepancy: None,
            other_die: None,
            tests: Vec::new(),
        };
        let row = BlockRow {
            label: "a".into(),
            block: Block::from_mm(140.0, 24.0, 20.0).unwrap(),
            mode: Mode::TwoD,
            surface: None,
            thrower: None,
            counts: Some([0, 250, 750]),
            groups: None,
        };
        let same = test(&row, pred(0.25));
        assert!(same.chi2.unwrap() < 1e-12 && same.z.unwrap().abs() < 1e-12);
        assert_eq!(same.dof, Some(1));
        // 0.35 against 250 of 1000: z of the share is 0.10/√(0.35·0.65/1000) ≈ 6.6, χ² its
        // square over the two sides' Pearson terms.
        let far = test(&row, pred(0.35));
        let want = 100.0f64.powi(2) / 350.0 + 100.0f64.powi(2) / 650.0;
        assert!((far.chi2.unwrap() - want).abs() < 1e-9, "{:?}", far.chi2);
        // From a fit that misfits with overdispersion 4, the counts scatter 4 times the
        // binomial's: the same departure is a quarter of the χ², the ratio's z half.
        let widened = test(
            &row,
            BlockPrediction {
                overdispersion: 4.0,
                ..pred(0.35)
            },
        );
        assert!((widened.chi2.unwrap() - want / 4.0).abs() < 1e-9);
        assert!((widened.z.unwrap() - far.z.unwrap() / 2.0).abs() < 1e-9);
        let all = collect(vec![same, far], Vec::new(), "f".into(), "c".into());
        assert_eq!(all.dof, Some(2));
        assert!(all.p_value.unwrap() < 1e-6);
    }
}
