//! Named targets (issue 73): a law over the numbers a die's labels show, given by its name
//! rather than label by label.
//!
//! - `2d6`: the sum of two fair six-sided dice, s = 2 … 12 with P(s) = (6 − |s − 7|)/36.
//! - `binomial:N`: heads in N fair coin tosses, k = 0 … N with P(k) = C(N, k)/2^N.
//!
//! A die fits a named target when its labels are the law's numbers, each once: a label is one
//! number (`7`) or several joined by `|` (`2|12`), the class a die file gives a mirror pair
//! whose members are not told apart (`docs/results/real-dice/v1.toml`); such a label's
//! probability is its numbers' together.

use serde::Serialize;

/// The largest N of `binomial:N`: 2^N stays exact in an f64 long past it, and a die has at
/// most 255 outcomes.
pub const MAX_BINOMIAL: u32 = 64;

/// A named target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum Named {
    /// The sum of two fair d6.
    TwoD6,
    /// Heads in N fair coin tosses.
    Binomial(u32),
}

impl From<Named> for String {
    fn from(n: Named) -> String {
        n.to_string()
    }
}

impl TryFrom<String> for Named {
    type Error = String;
    fn try_from(s: String) -> Result<Named, String> {
        Named::parse(&s)?.ok_or_else(|| format!("'{s}': not a named target (2d6, binomial:N)"))
    }
}

impl std::fmt::Display for Named {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Named::TwoD6 => f.write_str("2d6"),
            Named::Binomial(n) => write!(f, "binomial:{n}"),
        }
    }
}

impl Named {
    /// `2d6` or `binomial:N`; `Ok(None)` for any other text (a target given label by label),
    /// an error for a `binomial` whose N is not a whole number from 1 to [`MAX_BINOMIAL`].
    pub fn parse(s: &str) -> Result<Option<Named>, String> {
        let s = s.trim().to_ascii_lowercase();
        if s == "2d6" {
            return Ok(Some(Named::TwoD6));
        }
        let Some(rest) = s.strip_prefix("binomial") else {
            return Ok(None);
        };
        match rest.strip_prefix(':').map(|n| n.trim().parse::<u32>()) {
            Some(Ok(n)) if (1..=MAX_BINOMIAL).contains(&n) => Ok(Some(Named::Binomial(n))),
            _ => Err(format!(
                "'{s}': write binomial:N, N a whole number from 1 to {MAX_BINOMIAL} (heads in N \
                 fair tosses)"
            )),
        }
    }

    /// Each number the law gives and its probability, in order.
    pub fn law(self) -> Vec<(u32, f64)> {
        match self {
            Named::TwoD6 => (2..=12)
                .map(|s: u32| (s, (6.0 - (s as f64 - 7.0).abs()) / 36.0))
                .collect(),
            Named::Binomial(n) => {
                // C(N, k) by the running product C(N, k) = C(N, k − 1) (N − k + 1)/k: a few
                // roundings, each 1e-16 relative.
                let total = 2f64.powi(n as i32);
                let mut c = 1.0;
                (0..=n)
                    .map(|k| {
                        if k > 0 {
                            c = c * (n - k + 1) as f64 / k as f64;
                        }
                        (k, c / total)
                    })
                    .collect()
            }
        }
    }

    /// The target over `labels` (the die's, in its order): each label's probability, its
    /// numbers' together. Refused, in words, where the labels are not the law's numbers each
    /// once.
    pub fn over(self, labels: &[String]) -> Result<Vec<(String, f64)>, String> {
        let law = self.law();
        let (lo, hi) = (law[0].0, law[law.len() - 1].0);
        let refuse = |why: String| {
            // The labels as one reads them: numbers in order, then the rest.
            let mut shown: Vec<&str> = labels.iter().map(String::as_str).collect();
            shown.sort_by_key(|l| (l.parse::<u64>().unwrap_or(u64::MAX), l.to_string()));
            format!(
                "{self} is a law over the numbers {lo} to {hi}, each a label of the die once (or \
                 gathered, {lo}|{hi}); this die's labels are {}: {why}",
                shown.join(", ")
            )
        };
        let mut seen: Vec<u32> = Vec::new();
        let mut out = Vec::new();
        for label in labels {
            let mut p = 0.0;
            for part in label.split('|') {
                let n = part
                    .trim()
                    .parse::<u32>()
                    .ok()
                    .filter(|n| (lo..=hi).contains(n))
                    .ok_or_else(|| refuse(format!("'{label}' is not among them")))?;
                if seen.contains(&n) {
                    return Err(refuse(format!("{n} is on two labels")));
                }
                seen.push(n);
                p += law[(n - lo) as usize].1;
            }
            out.push((label.clone(), p));
        }
        let missing: Vec<String> = (lo..=hi)
            .filter(|n| !seen.contains(n))
            .map(|n| n.to_string())
            .collect();
        if !missing.is_empty() {
            return Err(refuse(format!("no label shows {}", missing.join(", "))));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A design's named target is written as its name and read back from it (a design's
    /// configuration is a study's, which a plan or Python hands over as JSON).
    #[test]
    fn a_named_target_is_read_back_from_the_name_it_is_written_as() {
        for n in [Named::TwoD6, Named::Binomial(5)] {
            let v = serde_json::to_value(n).unwrap();
            assert_eq!(v, serde_json::json!(n.to_string()));
            assert_eq!(serde_json::from_value::<Named>(v).unwrap(), n);
        }
        for bad in ["binomial:0", "3d6", "binomial:x"] {
            assert!(
                serde_json::from_value::<Named>(serde_json::json!(bad)).is_err(),
                "{bad}"
            );
        }
    }

    fn labels(s: &[&str]) -> Vec<String> {
        s.iter().map(|l| l.to_string()).collect()
    }

    #[test]
    fn two_d6_is_the_sum_of_two_fair_dice() {
        // By counting: the 36 ordered pairs of faces, each sum's share.
        let mut count = [0u32; 13];
        for a in 1..=6 {
            for b in 1..=6 {
                count[a + b] += 1;
            }
        }
        let law = Named::TwoD6.law();
        assert_eq!(law.len(), 11);
        for (s, p) in &law {
            assert!(
                (p - count[*s as usize] as f64 / 36.0).abs() < 1e-15,
                "{s}: {p}"
            );
        }
        assert!((law.iter().map(|x| x.1).sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn binomial_n_is_heads_in_n_fair_tosses() {
        let law = Named::Binomial(4).law();
        let want = [1.0, 4.0, 6.0, 4.0, 1.0].map(|c| c / 16.0);
        assert_eq!(law.iter().map(|x| x.0).collect::<Vec<_>>(), [0, 1, 2, 3, 4]);
        for ((_, p), w) in law.iter().zip(want) {
            assert!((p - w).abs() < 1e-15);
        }
        // By enumerating the 2^10 toss sequences.
        let law = Named::Binomial(10).law();
        for (k, p) in law {
            let n = (0u32..1024).filter(|s| s.count_ones() == k).count();
            assert!((p - n as f64 / 1024.0).abs() < 1e-15, "{k}");
        }
        let sum: f64 = Named::Binomial(MAX_BINOMIAL)
            .law()
            .iter()
            .map(|x| x.1)
            .sum();
        assert!((sum - 1.0).abs() < 1e-12, "{sum}");
    }

    #[test]
    fn names_parse_and_print_back() {
        assert_eq!(Named::parse("2d6"), Ok(Some(Named::TwoD6)));
        assert_eq!(Named::parse(" Binomial:3 "), Ok(Some(Named::Binomial(3))));
        assert_eq!(Named::parse("heads=1/2,tails=1/2"), Ok(None));
        for bad in ["binomial", "binomial:0", "binomial:x", "binomial:65"] {
            assert!(Named::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Named::Binomial(3).to_string(), "binomial:3");
    }

    #[test]
    fn a_label_gathers_its_numbers_and_the_labels_must_cover_the_law() {
        // V1's classes (docs/results/real-dice/v1.toml), in a die file's order.
        let v1 = labels(&["7", "6|8", "5|9", "4|10", "3|11", "2|12"]);
        let t = Named::TwoD6.over(&v1).unwrap();
        let want = [6.0, 10.0, 8.0, 6.0, 4.0, 2.0].map(|c| c / 36.0);
        for ((l, p), w) in t.iter().zip(want) {
            assert!((p - w).abs() < 1e-15, "{l}: {p}");
        }
        assert_eq!(t[1].0, "6|8");
        let binom3 = labels(&["0|3", "1|2"]);
        let t = Named::Binomial(3).over(&binom3).unwrap();
        assert!((t[0].1 - 0.25).abs() < 1e-15 && (t[1].1 - 0.75).abs() < 1e-15);
        // A d6's 1 … 6 are not 2 … 12; a number twice; a number left out.
        let e = Named::TwoD6
            .over(&labels(&["1", "2", "3", "4", "5", "6"]))
            .unwrap_err();
        assert!(e.contains("'1' is not among them"), "{e}");
        let e = Named::Binomial(2)
            .over(&labels(&["0", "1", "2|1"]))
            .unwrap_err();
        assert!(e.contains("1 is on two labels"), "{e}");
        let e = Named::Binomial(3)
            .over(&labels(&["0", "1", "2"]))
            .unwrap_err();
        assert!(e.contains("no label shows 3"), "{e}");
        let e = Named::Binomial(2)
            .over(&labels(&["heads", "tails", "edge"]))
            .unwrap_err();
        assert!(e.contains("'heads' is not among them"), "{e}");
    }
}
