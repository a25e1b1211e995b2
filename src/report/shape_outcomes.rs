//! A die of any shape's outcomes in a run's summary: its settled rolls by label, each share
//! against a fair die's and the quasi-static theory's, and when its shares are refused a
//! verdict.

use crate::run::tally::Tally;
use serde::{Deserialize, Serialize};

/// A die of any shape's settled rolls by the label it shows (faces that show the same label
/// counted together), in the order of its faces; `None` for the cuboid.
pub fn shape_faces(
    tally: &Tally,
    scene: &crate::model::scene::Scene,
) -> Option<Vec<(String, u64)>> {
    let shape = scene.die.as_shape()?;
    let counts = (0..shape.faces.len()).map(|k| tally.faces.get(k).copied().unwrap_or(0));
    Some(shape.by_label(counts))
}

/// One outcome of a die of any shape: its label, count, probability ± its binomial error, and
/// its departure from 1/N in σ (N its distinct outcomes).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShapeFace {
    /// What the die shows.
    pub label: String,
    /// Settled rolls showing it.
    pub count: u64,
    /// Its probability among the settled rolls.
    pub p: f64,
    /// The binomial error of `p`.
    pub p_err: f64,
    /// Its departure from a fair die's share q (its facets' share of all) over that share's
    /// own error, (p − q)/√(q(1 − q)/n).
    pub z_fair: f64,
    /// The quasi-static theory's probability (`theory::quasi_static::shape`), of the rolls
    /// that end on an outcome; absent where it is not built (a coin loaded off its axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quasi_static: Option<f64>,
    /// The outward normal (body axes, unit) of the facet the die rests on to show it, the one
    /// the die map draws it on; absent for a coin's edge and a label several facets show
    /// (`Shape::outcome_geometry`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// That facet's (those facets') share of the die's surface area.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area_share: Option<f64>,
}

/// A die of any shape's outcomes against a fair die's (each label its facets' share).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShapeOutcomes {
    /// The die (`Shape::name`).
    pub shape: String,
    /// Each outcome, in the die's order.
    pub faces: Vec<ShapeFace>,
    /// Pearson's χ² against a fair die's shares.
    pub chi2: f64,
    /// Its degrees of freedom, N − 1.
    pub dof: usize,
    /// Its p-value.
    pub p_value: f64,
    /// Why a fair die's shares are not what this die was made for (its faces are not
    /// alike: `theory::null::unlike`); absent where they are.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fair_note: Option<String>,
    /// Pearson's χ² against the quasi-static theory (over the outcomes it gives a share;
    /// degrees of freedom one fewer), its degrees of freedom and p-value: how far the bounce
    /// takes the die from rolling down at rest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub against_quasi_static: Option<(f64, usize, f64)>,
    /// Why the quasi-static theory is not beside the counts, where it is not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quasi_static_missing: Option<String>,
    /// Rolls that did not come to rest on a face (still moving at the step cap, leaning,
    /// failed): none of the shares above counts them.
    #[serde(default)]
    pub unsettled: u64,
    /// Why no verdict is drawn from these shares ([`check_settled`]: too many rolls off a
    /// face); absent where one is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_verdict: Option<String>,
}

/// The share of a run's rolls that may end off a face before its faces' shares, which count
/// only the rolls at rest on one, are refused a verdict: 1 %. Past it the missing rolls could
/// move a share by more than a percentage point, and a coin on its rim or a prism still
/// rolling at the cap is not a random roll to leave out (on its edge, a coin is on its way
/// to the edge outcome).
pub const MAX_UNSETTLED_SHARE: f64 = 0.01;

/// Refused, saying why and what to change, when more than [`MAX_UNSETTLED_SHARE`] of the
/// rolls of `tally` did not come to rest on a face, or none did: a verdict over the settled
/// rolls alone would be biased.
pub fn check_settled(tally: &Tally) -> crate::Result<()> {
    let faced: u64 = tally.faces.iter().sum();
    let off = tally.rolls.saturating_sub(faced);
    let lean = tally.counts.unknown;
    let why = format!(
        "{} of {} rolls did not come to rest on a face ({} still moving at the step cap, {lean} \
         leaning, {} failed)",
        off,
        tally.rolls,
        tally.unconverged,
        tally.failed_total()
    );
    let advice = "raise --max-steps, or give --rolling-resistance (0.05 mm: a hard table) so that \
                  a die rolling on an edge or a rim stops";
    if tally.rolls > 0 && faced == 0 {
        return Err(crate::Error::failed(format!(
            "{why}: nothing to count; {advice}"
        )));
    }
    if off as f64 > MAX_UNSETTLED_SHARE * tally.rolls as f64 {
        return Err(crate::Error::failed(format!(
            "{why}, more than {:.0} %: the faces' shares over the others would be biased; \
             {advice}",
            100.0 * MAX_UNSETTLED_SHARE
        )));
    }
    Ok(())
}

impl ShapeOutcomes {
    /// The outcomes of a die of any shape from its tally; `None` for the cuboid.
    pub fn of(tally: &Tally, scene: &crate::model::scene::Scene) -> Option<ShapeOutcomes> {
        let shape = scene.die.as_shape()?;
        let counts = shape_faces(tally, scene)?;
        let n: u64 = counts.iter().map(|(_, c)| c).sum();
        let k = counts.len();
        let shares = crate::theory::null::uniform_shares(shape);
        let fair: Vec<f64> = counts
            .iter()
            .map(|(l, _)| shares.iter().find(|(m, _)| m == l).map_or(0.0, |s| s.1))
            .collect();
        let nf = n.max(1) as f64;
        let chi2 = counts
            .iter()
            .zip(&fair)
            .map(|((_, c), q)| (*c as f64 - nf * q).powi(2) / (nf * q))
            .sum();
        let shares = crate::theory::quasi_static::label_shares(scene, scene.features.layout);
        let (theory, quasi_static_missing) = match shares {
            Ok(q) => (
                Some(q.into_iter().map(|(_, q)| q).collect::<Vec<f64>>()),
                None,
            ),
            Err(e) => (None, Some(e)),
        };
        let against_quasi_static = theory.as_ref().map(|q| {
            let (mut chi2, mut k) = (0.0, 0usize);
            for ((_, c), q) in counts.iter().zip(q) {
                if *q > 0.0 {
                    chi2 += (*c as f64 - n as f64 * q).powi(2) / (n as f64 * q);
                    k += 1;
                }
            }
            let dof = k.saturating_sub(1);
            (
                chi2,
                dof,
                crate::theory::stats::chi_square_p_value(chi2, dof),
            )
        });
        let places = shape.outcome_geometry();
        let faces = counts
            .into_iter()
            .enumerate()
            .map(|(i, (label, count))| {
                let p = count as f64 / nf;
                let q = fair[i];
                let place = places.iter().find(|(l, _, _)| *l == label);
                ShapeFace {
                    normal: place.and_then(|p| p.1),
                    area_share: place.map(|p| p.2),
                    label,
                    count,
                    p,
                    // The face's own binomial error (fair's too).
                    p_err: crate::theory::stats::binomial_err(p, n.max(1)),
                    // The departure over the fair share's own error, which a face never seen
                    // also has.
                    z_fair: (p - q) / crate::theory::stats::binomial_err(q, n.max(1)),
                    quasi_static: theory.as_ref().map(|t| t[i]),
                }
            })
            .collect();
        let faced: u64 = tally.faces.iter().sum();
        Some(ShapeOutcomes {
            shape: shape.name.clone(),
            faces,
            chi2,
            dof: k.saturating_sub(1),
            p_value: crate::theory::stats::chi_square_p_value(chi2, k.saturating_sub(1)),
            fair_note: crate::theory::null::alike(shape),
            against_quasi_static,
            quasi_static_missing,
            unsettled: tally.rolls.saturating_sub(faced),
            no_verdict: check_settled(tally).err().map(|e| e.to_string()),
        })
    }

    /// Its lines in `roll`'s summary.
    pub fn lines(&self) -> String {
        let mut s = String::new();
        let per_line = 5;
        for chunk in self.faces.chunks(per_line) {
            let each: Vec<String> = chunk
                .iter()
                .map(|f| {
                    format!(
                        "{:>5} {:>7} {:.4}±{:.4} ({:+.1}σ)",
                        f.label, f.count, f.p, f.p_err, f.z_fair
                    )
                })
                .collect();
            s += &format!("  {}\n", each.join("  "));
        }
        // The faces told apart without the die map (issue 74.3).
        if self.faces.iter().any(|f| f.area_share.is_some()) {
            s += "  each face rests on the facet of outward normal (x, y, z), body axes; its \
                  share of the surface:\n";
            let c = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
            for chunk in self.faces.chunks(3) {
                let each: Vec<String> = chunk
                    .iter()
                    .map(|f| {
                        let normal = f.normal.map_or("-".to_string(), |[x, y, z]| {
                            format!("({:+.3}, {:+.3}, {:+.3})", c(x), c(y), c(z))
                        });
                        let area = f
                            .area_share
                            .map_or("-".to_string(), |a| format!("{:.2} %", 100.0 * a));
                        format!("{:>5} {normal:<24} {area:>7}", f.label)
                    })
                    .collect();
                s += &format!("  {}\n", each.join("   "));
            }
        }
        if self.unsettled > 0 {
            s += &format!(
                "  {} rolls not at rest on a face: none of these shares counts them\n",
                self.unsettled
            );
        }
        if let Some(why) = &self.no_verdict {
            s += &format!("  no verdict: {why}\n");
            return s;
        }
        s += &format!(
            "  against a fair die (each face's share of its facets): χ² {:.1} on {} degrees of \
             freedom, p {:.3}\n",
            self.chi2, self.dof, self.p_value
        );
        if let Some(note) = &self.fair_note {
            s += &format!("  note: {note}\n");
        }
        if let Some(why) = &self.quasi_static_missing {
            s += &format!("  the quasi-static theory is not beside these counts: {why}\n");
        }
        if let Some((chi2, dof, p)) = self.against_quasi_static {
            let worst = self
                .faces
                .iter()
                .filter_map(|f| {
                    let q = f.quasi_static?;
                    let z =
                        (f.p - q) / crate::theory::stats::binomial_err(q, self.rolls()).max(1e-300);
                    Some((f, q, z))
                })
                .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()));
            s += &format!(
                "  against the quasi-static theory (released at rest, no bounce): χ² {chi2:.1} on \
                 {dof}, p {p:.3}"
            );
            if let Some((f, q, z)) = worst {
                s += &format!(
                    "; farthest {} {:.4} against {q:.4} ({z:+.1}σ)",
                    f.label, f.p
                );
            }
            s += "\n";
        }
        s
    }

    /// The rolls that ended on an outcome.
    fn rolls(&self) -> u64 {
        self.faces.iter().map(|f| f.count).sum::<u64>().max(1)
    }
}
