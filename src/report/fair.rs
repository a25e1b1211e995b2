//! `fair`'s results and their text: each face against a fair die's, the χ² over the faces,
//! the throws a tester needs (computed in `studies::fair`).

use crate::report::summary::RunSummary;
use serde::{Deserialize, Serialize};

pub use crate::theory::null::Null;

/// One face's verdict.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FaceVerdict {
    /// Its number, under the run's layout.
    pub number: u8,
    /// Its outward direction in body axes (`+x` … `-z`); a die of any shape's: the label
    /// it shows.
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
    /// The outward normal (body axes, unit) of the facet the die rests on when it shows this
    /// face, the one the die map draws it on (a cube's: opposite `direction`); absent where
    /// there is none (a coin's edge, a label several facets show, 2D, counts by labels that
    /// are not the die's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// That facet's share of the die's surface area (a label several facets show: theirs);
    /// absent where the die is not known (2D, counts by labels that are not the die's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area_share: Option<f64>,
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
    /// Why the null is not what the die was made for (a uniform null on a die whose faces are
    /// not alike: `theory::null::unlike`); absent where it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
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

impl Fairness {
    /// The verdict in a few words, for a figure's title: biased or not, with χ²'s p.
    pub fn short_verdict(&self) -> String {
        if self.resolved {
            format!("biased (χ² p = {:.1e})", self.p_value)
        } else {
            format!("no bias resolved (χ² p = {:.2})", self.p_value)
        }
    }

    /// The faces' table and the verdict, as the terminal shows them.
    pub fn table(&self) -> String {
        let mut out = String::from(
            "  face  up  count      p        ± 1σ     null     departure      z   throws to see \
             it (2σ / 5σ)\n",
        );
        let shaped = self.faces.iter().any(|f| f.area_share.is_some());
        if shaped {
            // The faces told apart without the picture: where each lies, and how large it is.
            let head = format!("   {:<26}  {:>7}", "rests on (normal x, y, z)", "area");
            out.insert_str(out.len() - 1, &head);
        }
        for f in &self.faces {
            let see = match (f.throws_2sigma, f.throws_5sigma) {
                (Some(a), Some(b)) => format!("{a:.0} / {b:.0}"),
                _ => "unresolved".into(),
            };
            out += &format!(
                "  {:>4}  {:<2} {:>7}  {:.5}  {:.5}  {:.5}  {:+.5}  {:+6.2}   {see}",
                f.number, f.direction, f.count, f.p, f.err, f.null, f.departure, f.z
            );
            if shaped {
                // Rounded first, so that no -0.000 shows.
                let c = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
                let normal = f.normal.map_or("-".to_string(), |[x, y, z]| {
                    format!("({:+.3}, {:+.3}, {:+.3})", c(x), c(y), c(z))
                });
                let area = f
                    .area_share
                    .map_or("-".to_string(), |a| format!("{:.2} %", 100.0 * a));
                // Under the header's columns: "throws to see it (2σ / 5σ)" is 26 wide.
                let pad = 26usize.saturating_sub(see.chars().count());
                out += &format!("{:pad$}   {normal:<26}  {area:>7}", "");
            }
            out += "\n";
        }
        out += &format!("  {}\n", self.verdict);
        if let Some(n) = &self.note {
            out += &format!("  note: {n}\n");
        }
        out
    }

    /// Measured counts' verdict (`studies::fair::assess_counts`), as `fair --counts` prints
    /// it after "Is this die fair? ": the throws, the null and the table.
    pub fn counted_text(&self) -> String {
        format!(
            "{} throws counted, against {}\n{}",
            self.n,
            self.null,
            self.table()
        )
    }

    /// The faces' table as CSV: one row a face (`face` its number, `label` its direction on a
    /// cube or what a die of any shape shows), the throws to see it empty where unresolved.
    pub fn csv(&self) -> String {
        // Through the CSV writer: a label that holds a comma, a quote or a line end is quoted.
        let mut w = csv::Writer::from_writer(Vec::new());
        let opt = |v: Option<f64>| v.map_or(String::new(), |t| format!("{t:.0}"));
        let mut rows = vec![[
            "face",
            "label",
            "count",
            "p",
            "err",
            "null",
            "departure",
            "z",
            "throws_2sigma",
            "throws_5sigma",
        ]
        .map(String::from)];
        for f in &self.faces {
            rows.push([
                f.number.to_string(),
                f.direction.clone(),
                f.count.to_string(),
                f.p.to_string(),
                f.err.to_string(),
                f.null.to_string(),
                f.departure.to_string(),
                f.z.to_string(),
                opt(f.throws_2sigma),
                opt(f.throws_5sigma),
            ]);
        }
        for r in &rows {
            w.write_record(r).expect("a CSV row into memory");
        }
        String::from_utf8(w.into_inner().expect("CSV into memory")).expect("UTF-8 fields")
    }

    /// The human report.
    pub fn text(&self, s: &RunSummary) -> String {
        let mut die = s.spec.scene.die.title();
        if s.spec.scene.die.counts_sides() {
            die += &format!(", {} layout", s.layout);
        }
        let mut out = format!(
            "Is this die fair? {die}, {} {}, throw {}, {} rolls ({} at rest on a face), \
             against {}\n",
            s.engine, s.mode, s.spec.throws.style, s.rolls, self.n, self.null
        );
        out += &self.table();
        if let Some(r) = &s.precision {
            out += &format!("  {}\n", r.line());
        }
        // What `roll` says of the same run: rolls that failed, and physics that broke.
        if s.failed_total > 0 {
            let each: Vec<String> = s
                .failed
                .iter()
                .map(|(f, n)| format!("{} {n}", f.name()))
                .collect();
            out += &format!(
                "  {} rolls failed and are not counted ({})\n",
                s.failed_total,
                each.join(", ")
            );
        }
        for w in &s.warnings {
            out += &format!("  warning: {w}\n");
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_label_with_a_comma_or_a_quote_is_quoted_in_the_csv() {
        let face = |number: u8, label: &str| FaceVerdict {
            number,
            direction: label.into(),
            count: 5,
            p: 0.5,
            err: 0.1,
            null: 0.5,
            departure: 0.0,
            z: 0.0,
            normal: None,
            area_share: None,
            throws_2sigma: None,
            throws_5sigma: None,
        };
        let fair = Fairness {
            null: Null::Uniform,
            note: None,
            n: 10,
            faces: vec![face(1, "a,b"), face(2, "say \"c\"")],
            chi2: 0.0,
            dof: 1,
            p_value: 1.0,
            lambda: 0.0,
            throws_2sigma: None,
            throws_5sigma: None,
            resolved: false,
            verdict: String::new(),
        };
        let text = fair.csv();
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let rows: Vec<csv::StringRecord> = r.records().map(|r| r.unwrap()).collect();
        assert_eq!(rows.len(), 2, "{text}");
        for (row, label) in rows.iter().zip(["a,b", "say \"c\""]) {
            assert_eq!(row.len(), 10, "{text}");
            assert_eq!(&row[1], label, "{text}");
        }
        // A plain table is written as before.
        assert!(text.starts_with("face,label,count,p,err,null,departure,z,throws_2sigma,"));
        assert!(text.contains("\n1,\"a,b\",5,0.5,0.1,0.5,0,0,,\n"), "{text}");
    }
}
