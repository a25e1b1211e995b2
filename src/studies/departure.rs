//! A method's departure from its reference, r_m/r_ref − 1, on the same keyed throws, with its
//! paired error: the statistics of two [`Stream`]s that share their first throws.

use super::stream::Stream;
use super::sweep::ONE_PERCENT;
use crate::run::runner::CHUNK_ROLLS;
use crate::theory::stats;

/// A ratio's relative departure from a reference, r/ref − 1, with its error (the two taken as
/// independent: at another dt or engine the same throws soon follow other paths).
pub fn unpaired_departure(r: stats::Ratio, reference: stats::Ratio) -> (f64, f64) {
    let q = r.value / reference.value;
    let err = q * ((r.err / r.value).powi(2) + (reference.err / reference.value).powi(2)).sqrt();
    (q - 1.0, err)
}

/// Rolls per cell needed for a departure's error to resolve 1 % at 2σ (σ ≤ 0.5 %), from one
/// measured at `rolls` per cell: the error falls as 1/√rolls.
pub fn rolls_for_one_percent(err: f64, rolls: u64) -> Option<u64> {
    (err.is_finite() && err > 0.0)
        .then(|| (rolls as f64 * (err / (0.5 * ONE_PERCENT)).powi(2)).ceil() as u64)
}

/// A departure r_m/r_ref − 1 of one stream from another, with the ingredients of its error
/// so that the error at other roll counts can be predicted.
///
/// The two streams share their first throws, and where one has rolled further, its extra
/// throws are used through a control variate: with the method at n throws and the reference
/// at N > n, ln q = ln r_m(n) − ln r_ref(N) − β (ln r_ref(n) − ln r_ref(N)), with β the
/// regression of the method's per-throw influence on the reference's over the shared throws,
/// cov/V_r there: the least-variance weight (the bracket has mean 0 whatever β). β = 0 is
/// the plain comparison of each stream's whole ratio; β = 1 compares the shared throws alone.
/// Two methods that end alike throw for throw (β ≈ 1) then differ by what their shared
/// throws say, not by how far the reference's first n throws happen to sit from its N (the
/// plain comparison measured mostly that). Symmetrically when the method has rolled further.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Departure {
    /// r_m/r_ref − 1.
    pub value: f64,
    /// Its standard error, paired: the two share their first throws, and where they end alike
    /// the noise cancels (with the control variate above).
    pub err: f64,
    /// The error as if the two were independent (`departure`), for comparison.
    pub err_unpaired: f64,
    /// Fraction of the shared throws with the same outcome class (breadth, width, other).
    pub agreement: f64,
    /// Per-throw variance of ln r_m's influence, 1/p_b + 1/p_w.
    var_m: f64,
    /// The same for the reference.
    var_r: f64,
    /// Covariance of the two influences over the shared throws.
    cov: f64,
    /// The method's influence's variance over the shared throws.
    var_m_shared: f64,
    /// The reference's, over the shared throws.
    var_r_shared: f64,
}

impl Departure {
    /// The standard error of the departure with `nm` rolls of the method and `nr` of the
    /// reference (the first n = min(nm, nr) shared), times q for the relative departure.
    /// With the reference the longer (N = nr), the estimate is ā_n − γ c̄_n − (1 − β) c̄_rest
    /// (N − n)/N, γ = β + (1 − β) n/N, so var = V(a − γc)/n + (1 − β)² (N − n) V_r/N², V(a − γc)
    /// over the shared throws (never negative); the mirror image when the method is the longer.
    /// At nm = nr this is the plain paired (V_m + V_r − 2cov)/n. Without a variance to
    /// regress on, the plain comparison: V_m/nm + V_r/nr − 2·cov·n/(nm·nr).
    pub fn err_at(&self, nm: u64, nr: u64) -> f64 {
        let (m, r) = (nm as f64, nr as f64);
        let n = m.min(r);
        let cov = self.cov;
        // (shared variance of the shorter, of the longer, whole variance of the longer, its rolls)
        let (short, long, long_whole, big) = if m <= r {
            (self.var_m_shared, self.var_r_shared, self.var_r, r)
        } else {
            (self.var_r_shared, self.var_m_shared, self.var_m, m)
        };
        let var = if long > 0.0 {
            let beta = cov / long;
            let g = beta + (1.0 - beta) * n / big;
            (short - 2.0 * g * cov + g * g * long) / n
                + (1.0 - beta).powi(2) * (big - n) * long_whole / (big * big)
        } else {
            self.var_m / m + self.var_r / r - 2.0 * cov * n / (m * r)
        };
        (1.0 + self.value) * var.max(0.0).sqrt()
    }

    /// The reference's departure from itself.
    pub fn zero() -> Departure {
        Departure {
            value: 0.0,
            err: 0.0,
            err_unpaired: 0.0,
            agreement: 1.0,
            var_m: 0.0,
            var_r: 0.0,
            cov: 0.0,
            var_m_shared: 0.0,
            var_r_shared: 0.0,
        }
    }

    /// Rolls of both streams (the same number, sharing their throws) for 2σ of the departure
    /// to be at most `precision`, at the variances measured; `None` if not measured.
    pub fn rolls_both(&self, precision: f64) -> Option<u64> {
        let var = (1.0 + self.value).powi(2) * (self.var_m + self.var_r - 2.0 * self.cov);
        (var.is_finite() && var >= 0.0)
            .then(|| ((var / (0.5 * precision).powi(2)).ceil() as u64).max(1))
    }
}

/// The departure of `m` from `reference` on the same keyed throws, with its paired error
/// (delta method on ln of each ratio; the covariance from the throws both rolled).
pub fn paired_departure(m: &Stream, reference: &Stream) -> Departure {
    let nan = Departure {
        value: f64::NAN,
        err: f64::NAN,
        err_unpaired: f64::NAN,
        agreement: f64::NAN,
        var_m: f64::NAN,
        var_r: f64::NAN,
        cov: f64::NAN,
        var_m_shared: f64::NAN,
        var_r_shared: f64::NAN,
    };
    let (Some(a), Some(c)) = (m.influence(), reference.influence()) else {
        return nan;
    };
    let n = m.outcomes.len().min(reference.outcomes.len());
    if n == 0 {
        return nan;
    }
    // The covariance and the shared variances take each influence at its shared throws' own
    // proportions, so two streams that end alike there regress with β = 1 exactly (at the
    // whole streams' proportions ln r would be linearised about two points).
    let (ms, rs) = (&m.outcomes[..n], &reference.outcomes[..n]);
    let (a_s, c_s) = match (influence_of(ms), influence_of(rs)) {
        (Some(x), Some(y)) => (x, y),
        _ => (a, c),
    };
    let (mut sa, mut sc, mut saa, mut scc, mut sac, mut same) = (0.0, 0.0, 0.0, 0.0, 0.0, 0u64);
    for (&x, &y) in ms.iter().zip(rs) {
        let (ai, ci) = (a_s[x as usize], c_s[y as usize]);
        sa += ai;
        sc += ci;
        saa += ai * ai;
        scc += ci * ci;
        sac += ai * ci;
        same += (x == y) as u64;
    }
    let nf = n as f64;
    let (ma, mc) = (sa / nf, sc / nf);
    let (rm, rr) = (m.measured().ratio(), reference.measured().ratio());
    let (plain, err_unpaired) = unpaired_departure(rm, rr);
    let mut d = Departure {
        value: plain,
        err: f64::NAN,
        err_unpaired,
        agreement: same as f64 / nf,
        var_m: a[1] * a[1] * m.tally.counts.breadth as f64 / m.rolls() as f64
            + a[2] * a[2] * m.tally.counts.width as f64 / m.rolls() as f64,
        var_r: c[1] * c[1] * reference.tally.counts.breadth as f64 / reference.rolls() as f64
            + c[2] * c[2] * reference.tally.counts.width as f64 / reference.rolls() as f64,
        cov: sac / nf - ma * mc,
        var_m_shared: saa / nf - ma * ma,
        var_r_shared: scc / nf - mc * mc,
    };
    // The control variate: the longer stream's ratio on the shared throws against its whole
    // (a factor (r(n)/r(N))^−β on q). Left out if the shared throws lack an outcome.
    // The reference's drift divides q, the method's multiplies it.
    let (longer, v, sign) = if m.rolls() <= reference.rolls() {
        (reference, d.var_r_shared, -1.0)
    } else {
        (m, d.var_m_shared, 1.0)
    };
    if let (Some(shared), true) = (ratio_of(&longer.outcomes[..n]), v > 0.0) {
        let beta = d.cov / v;
        let whole = longer.tally.counts.breadth as f64 / longer.tally.counts.width as f64;
        d.value = (1.0 + plain) * (shared / whole).powf(sign * beta) - 1.0;
    }
    d.err = d.err_at(m.rolls(), reference.rolls());
    d
}

/// N(breadth)/N(width) over some throws' outcome classes; `None` if either is missing.
fn ratio_of(outcomes: &[u8]) -> Option<f64> {
    let (b, w) = breadth_width(outcomes);
    (b > 0.0 && w > 0.0).then(|| b / w)
}

/// `Stream::influence` over some throws' outcome classes, at their own proportions.
fn influence_of(outcomes: &[u8]) -> Option<[f64; 3]> {
    let (b, w) = breadth_width(outcomes);
    let n = outcomes.len() as f64;
    (b > 0.0 && w > 0.0).then(|| [0.0, n / b, -n / w])
}

fn breadth_width(outcomes: &[u8]) -> (f64, f64) {
    let b = outcomes.iter().filter(|&&x| x == 1).count();
    let w = outcomes.iter().filter(|&&x| x == 2).count();
    (b as f64, w as f64)
}

/// The chunks a method needs for 2σ of its departure to be at most `precision`, with the
/// reference at `nr` rolls; `None` if none up to `max_chunks` would do.
pub fn chunks_to_resolve(d: &Departure, nr: u64, precision: f64, max_chunks: u64) -> Option<u64> {
    if !d.err.is_finite() {
        return None;
    }
    // err_at falls as nm grows, so the first chunk count that resolves is found by bisection.
    let ok = |k: u64| 2.0 * d.err_at(k * CHUNK_ROLLS, nr) <= precision;
    if !ok(max_chunks.max(1)) {
        return None;
    }
    let (mut lo, mut hi) = (0u64, max_chunks.max(1));
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// Rolls for 2σ of a ratio's own relative error to be at most `precision` (its influence
/// variance from the rolls so far); `None` before both outcomes are seen.
pub fn rolls_for_ratio(s: &Stream, precision: f64) -> Option<u64> {
    let c = s.influence()?;
    let n = s.rolls() as f64;
    let var = c[1] * c[1] * s.tally.counts.breadth as f64 / n
        + c[2] * c[2] * s.tally.counts.width as f64 / n;
    Some((var / (0.5 * precision).powi(2)).ceil() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::EngineKind;
    use crate::model::block::Block;
    use crate::model::scene::{Mode, Scene};
    use crate::sim::roll::RollConfig;

    /// A stream that has rolled these outcome classes (1 breadth, 2 width, 0 other).
    fn stream(outcomes: Vec<u8>) -> Stream {
        let scene = Scene::paper(Block::from_mm(140.0, 24.0, 20.0).unwrap(), Mode::ThreeD);
        let mut s = Stream::new(EngineKind::Bullet, scene, RollConfig::default(), 1);
        let (b, w) = breadth_width(&outcomes);
        (s.tally.counts.breadth, s.tally.counts.width) = (b as u64, w as u64);
        s.tally.rolls = outcomes.len() as u64;
        s.outcomes = outcomes;
        s
    }

    /// splitmix64, as a uniform in [0, 1): the tests' own fixed-seed throws.
    struct Uniform(u64);
    impl Uniform {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            (z ^ (z >> 31)) as f64 / 2f64.powi(64)
        }
        fn class(&mut self, p_breadth: f64) -> u8 {
            if self.next() < p_breadth {
                1
            } else {
                2
            }
        }
    }

    /// The plain paired error (β = 0): each stream's whole ratio, the shared throws only
    /// correlating them.
    fn plain_err(d: &Departure, nm: u64, nr: u64) -> f64 {
        let (m, r) = (nm as f64, nr as f64);
        let var = d.var_m / m + d.var_r / r - 2.0 * d.cov * m.min(r) / (m * r);
        (1.0 + d.value) * var.sqrt()
    }

    #[test]
    fn a_method_that_ends_as_the_reference_departs_by_what_the_shared_throws_say() {
        // A reference of 20,000 throws; a method that ends as its first 4,000 but for 2 %,
        // redrawn. The plain paired comparison of the whole ratios also measures how far the
        // reference's first 4,000 sit from its 20,000; the control variate takes that out
        // (all but (1 − β) of it), so its departure is the shared throws' within its error,
        // and that error is a fraction of the plain one.
        let mut u = Uniform(7);
        let reference: Vec<u8> = (0..20_000).map(|_| u.class(0.36)).collect();
        let method: Vec<u8> = reference[..4_000]
            .iter()
            .map(|&x| if u.next() < 0.02 { u.class(0.36) } else { x })
            .collect();
        let shared = ratio_of(&method).unwrap() / ratio_of(&reference[..4_000]).unwrap() - 1.0;
        let d = paired_departure(&stream(method), &stream(reference));
        assert!(
            (d.value - shared).abs() < d.err,
            "departure {} ± {} against the shared throws' {shared}",
            d.value,
            d.err
        );
        assert!(
            d.err < 0.3 * plain_err(&d, 4_000, 20_000),
            "{d:?}: its error should be a fraction of the plain paired one"
        );
    }

    #[test]
    fn the_control_variate_departure_is_unbiased_and_its_error_is_its_spread() {
        // 400 pairs of streams with the same physics (true departure 0): one of 8,000 throws
        // at p = 0.36, the other of 2,000 ending as its first 2,000 but for 5 %, redrawn;
        // the longer one the reference, then the method. Over the pairs the departures average
        // 0 within 3 standard errors of their mean, and their standard deviation is the
        // predicted error within 15 %.
        let mut u = Uniform(2385);
        for method_longer in [false, true] {
            let (mut values, mut errs) = (Vec::new(), Vec::new());
            for _ in 0..400 {
                let long: Vec<u8> = (0..8_000).map(|_| u.class(0.36)).collect();
                let short: Vec<u8> = long[..2_000]
                    .iter()
                    .map(|&x| if u.next() < 0.05 { u.class(0.36) } else { x })
                    .collect();
                let (long, short) = (stream(long), stream(short));
                let d = if method_longer {
                    paired_departure(&long, &short)
                } else {
                    paired_departure(&short, &long)
                };
                values.push(d.value);
                errs.push(d.err);
            }
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let err = errs.iter().sum::<f64>() / n;
            let case = if method_longer { "method" } else { "reference" };
            assert!(
                mean.abs() < 3.0 * sd / n.sqrt(),
                "{case} longer: mean {mean}, sd {sd}"
            );
            assert!(
                (sd / err - 1.0).abs() < 0.15,
                "{case} longer: spread {sd} against predicted {err}"
            );
        }
    }
}
