//! Minimising −2 ln L over a box, and its profile: Nelder–Mead in unit coordinates (every
//! parameter scaled to [0, 1]), points outside the box pulled back to its faces.
//!
//! The likelihood surfaces here are cheap (a surrogate per row) but not convex: a simplex
//! search restarted from its own best point until it stops improving is robust, needs no
//! derivatives, and is deterministic.

/// A minimum found.
#[derive(Clone, Debug, PartialEq)]
pub struct Minimum {
    /// Where, in unit coordinates.
    pub x: Vec<f64>,
    /// The function's value there.
    pub f: f64,
    /// Function evaluations spent.
    pub evals: usize,
    /// The simplex closed to the tolerance (rather than running out of evaluations).
    pub converged: bool,
}

fn clamp(x: &mut [f64]) {
    x.iter_mut().for_each(|v| *v = v.clamp(0.0, 1.0));
}

/// Nelder–Mead from `x0` with initial steps `step` (unit coordinates), to a spread of values
/// below `tol` or `max_evals` evaluations; restarted from its best point until a restart gains
/// less than `tol`.
pub fn minimize(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: f64, tol: f64) -> Minimum {
    minimize_until(f, x0, step, tol, &|| false)
}

/// [`minimize`], abandoned as soon as `stop()` says so (the caller then sees a stop request,
/// not a minimum): checked before every simplex step, so that a stop costs at most one step
/// however many evaluations the search had left (a fit's profiles of 24 parameters ran on for
/// minutes after Ctrl-C, each search spending its budget on a likelihood that had become +∞).
pub fn minimize_until(
    f: &dyn Fn(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    tol: f64,
    stop: &dyn Fn() -> bool,
) -> Minimum {
    let mut best = nelder_mead(f, x0, step, tol, 4000 * (x0.len() + 1), stop);
    for _ in 0..8 {
        if stop() {
            break;
        }
        let again = nelder_mead(f, &best.x, step / 2.0, tol, 4000 * (x0.len() + 1), stop);
        let gain = best.f - again.f;
        let evals = best.evals + again.evals;
        if again.f < best.f {
            best = Minimum { evals, ..again };
        } else {
            best.evals = evals;
            best.converged |= again.converged;
        }
        if gain < tol {
            break;
        }
    }
    best
}

fn nelder_mead(
    f: &dyn Fn(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    tol: f64,
    max_evals: usize,
    stop: &dyn Fn() -> bool,
) -> Minimum {
    let n = x0.len();
    if n == 0 {
        return Minimum {
            x: vec![],
            f: f(&[]),
            evals: 1,
            converged: true,
        };
    }
    let evals = std::cell::Cell::new(0usize);
    let eval = |x: &[f64]| {
        evals.set(evals.get() + 1);
        let v = f(x);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    };
    let mut start = x0.to_vec();
    clamp(&mut start);
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    let v0 = eval(&start);
    simplex.push((start.clone(), v0));
    for i in 0..n {
        let mut x = start.clone();
        // Step inwards from a face, so that no vertex starts on top of another.
        x[i] = if x[i] + step <= 1.0 {
            x[i] + step
        } else {
            x[i] - step
        };
        let v = eval(&x);
        simplex.push((x, v));
    }
    let mut converged = false;
    loop {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let spread = simplex[n].1 - simplex[0].1;
        if spread.abs() < tol {
            converged = true;
            break;
        }
        if evals.get() >= max_evals || stop() {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|(x, _)| x[j]).sum::<f64>() / n as f64)
            .collect();
        let towards = |t: f64| -> Vec<f64> {
            let mut x: Vec<f64> = (0..n)
                .map(|j| centroid[j] + t * (simplex[n].0[j] - centroid[j]))
                .collect();
            clamp(&mut x);
            x
        };
        let xr = towards(-1.0);
        let fr = eval(&xr);
        if fr < simplex[0].1 {
            let xe = towards(-2.0);
            let fe = eval(&xe);
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let (xc, fc) = if fr < simplex[n].1 {
                let x = towards(-0.5);
                let v = eval(&x);
                (x, v)
            } else {
                let x = towards(0.5);
                let v = eval(&x);
                (x, v)
            };
            if fc < simplex[n].1.min(fr) {
                simplex[n] = (xc, fc);
            } else {
                // Shrink towards the best vertex.
                let best = simplex[0].0.clone();
                for v in simplex.iter_mut().skip(1) {
                    let x: Vec<f64> = (0..n).map(|j| best[j] + 0.5 * (v.0[j] - best[j])).collect();
                    let fx = eval(&x);
                    *v = (x, fx);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, fx) = simplex.swap_remove(0);
    Minimum {
        x,
        f: fx,
        evals: evals.get(),
        converged,
    }
}

/// The minimum of `f` with coordinate `j` held at `v`, from `start` (the other coordinates).
pub fn minimize_with(
    f: &dyn Fn(&[f64]) -> f64,
    start: &[f64],
    j: usize,
    v: f64,
    tol: f64,
    stop: &dyn Fn() -> bool,
) -> Minimum {
    let others: Vec<f64> = start
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != j)
        .map(|(_, x)| *x)
        .collect();
    let full = |y: &[f64]| -> Vec<f64> {
        let mut x = y.to_vec();
        x.insert(j, v);
        x
    };
    let g = |y: &[f64]| f(&full(y));
    let m = minimize_until(&g, &others, 0.1, tol, stop);
    Minimum { x: full(&m.x), ..m }
}

/// A profile-likelihood interval of one coordinate, in unit coordinates: where the profile of
/// −2 ln L rises by `delta` above its minimum. `lo_open`/`hi_open`: the profile stays below the
/// level up to the box's face on that side (the data do not bound the parameter there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// The lower end.
    pub lo: f64,
    /// The upper end.
    pub hi: f64,
    /// The level reaches the lower face of the box without crossing.
    pub lo_open: bool,
    /// The level reaches the upper face without crossing.
    pub hi_open: bool,
}

/// The profile of coordinate `j` on a grid of `points` values across [0, 1], each minimised
/// over the other coordinates from the nearest solved neighbour (warm start, outwards from the
/// minimum `at`). Ends early when `stop()` says so (the rest of the grid left at +∞).
pub fn profile(
    f: &dyn Fn(&[f64]) -> f64,
    at: &Minimum,
    j: usize,
    points: usize,
    tol: f64,
    stop: &dyn Fn() -> bool,
) -> Vec<(f64, f64)> {
    let points = points.max(3);
    let grid: Vec<f64> = (0..points)
        .map(|i| i as f64 / (points - 1) as f64)
        .collect();
    let mut out = vec![(0.0, f64::INFINITY); points];
    let centre = grid
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - at.x[j]).abs().total_cmp(&(b.1 - at.x[j]).abs()))
        .map(|(i, _)| i)
        .unwrap_or(0);
    for dir in [-1i64, 1] {
        let mut from = at.x.clone();
        let mut i = centre as i64 + if dir < 0 { 0 } else { 1 };
        while i >= 0 && i < points as i64 && !stop() {
            let v = grid[i as usize];
            let m = minimize_with(f, &from, j, v, tol, stop);
            out[i as usize] = (v, m.f.min(f64::MAX));
            from = m.x;
            i += dir;
        }
    }
    out
}

/// The interval where the profile (as [`profile`] gives it) is within `delta` of `fmin`,
/// its ends interpolated linearly between grid points.
pub fn interval(profile: &[(f64, f64)], fmin: f64, delta: f64) -> Interval {
    let level = fmin + delta;
    let inside: Vec<bool> = profile.iter().map(|(_, v)| *v <= level).collect();
    let Some(first) = inside.iter().position(|b| *b) else {
        // The grid missed the minimum's neighbourhood: the whole grid is above the level.
        let best = profile
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0.5, |p| p.0);
        return Interval {
            lo: best,
            hi: best,
            lo_open: false,
            hi_open: false,
        };
    };
    let last = inside.iter().rposition(|b| *b).unwrap_or(first);
    let cross = |a: (f64, f64), b: (f64, f64)| -> f64 {
        if (b.1 - a.1).abs() < 1e-300 || !b.1.is_finite() || !a.1.is_finite() {
            return (a.0 + b.0) / 2.0;
        }
        a.0 + (level - a.1) / (b.1 - a.1) * (b.0 - a.0)
    };
    let lo = if first == 0 {
        profile[0].0
    } else {
        cross(profile[first - 1], profile[first])
    };
    let hi = if last == profile.len() - 1 {
        profile[last].0
    } else {
        cross(profile[last], profile[last + 1])
    };
    Interval {
        lo,
        hi,
        lo_open: first == 0,
        hi_open: last == profile.len() - 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_finds_a_quadratic_minimum_and_its_profile_interval() {
        // −2 ln L of a Gaussian with σ = (0.05, 0.1), correlated 0.6, centred at (0.4, 0.7):
        // the profile interval at Δ = 1 is the marginal ±σ.
        let (m0, m1, s0, s1, r) = (0.4, 0.7, 0.05, 0.1, 0.6);
        let f = |x: &[f64]| {
            let (a, b) = ((x[0] - m0) / s0, (x[1] - m1) / s1);
            (a * a - 2.0 * r * a * b + b * b) / (1.0 - r * r)
        };
        let m = minimize(&f, &[0.5, 0.5], 0.1, 1e-12);
        assert!(
            (m.x[0] - m0).abs() < 1e-4 && (m.x[1] - m1).abs() < 1e-4,
            "{m:?}"
        );
        let p = profile(&f, &m, 0, 81, 1e-10, &|| false);
        let i = interval(&p, m.f, 1.0);
        assert!(
            (i.lo - (m0 - s0)).abs() < 2e-3 && (i.hi - (m0 + s0)).abs() < 2e-3,
            "{i:?}"
        );
        assert!(!i.lo_open && !i.hi_open);
    }

    #[test]
    fn a_flat_direction_is_open_on_both_sides() {
        let f = |x: &[f64]| ((x[0] - 0.3) / 0.05).powi(2) + 1e-6 * x[1];
        let m = minimize(&f, &[0.5, 0.5], 0.1, 1e-12);
        let i = interval(&profile(&f, &m, 1, 11, 1e-10, &|| false), m.f, 4.0);
        assert!(i.lo_open && i.hi_open, "{i:?}");
        // A minimum on a face: open on that side only.
        let g = |x: &[f64]| ((x[0] - 1.2) / 0.5).powi(2);
        let m = minimize(&g, &[0.5], 0.1, 1e-12);
        assert!((m.x[0] - 1.0).abs() < 1e-9);
        let i = interval(&profile(&g, &m, 0, 41, 1e-10, &|| false), m.f, 1.0);
        // ((x − 1.2)/0.5)² ≤ 0.16 + 1 from x = 1.2 − 0.5·√1.16 = 0.6615.
        assert!(
            i.hi_open && !i.lo_open && (i.lo - 0.6615).abs() < 0.01,
            "{i:?}"
        );
    }

    /// A stop ends a search within one simplex step, however many evaluations it had left:
    /// counted in evaluations, not seconds, so the test holds on any machine. A 24-parameter
    /// bowl whose search and profile are asked to stop after 200 evaluations spend at most a
    /// step's more (a shrink: n + 1), where they would otherwise spend tens of thousands.
    #[test]
    fn a_stop_ends_the_search_and_the_profile_within_one_step() {
        use std::cell::Cell;
        let n = 24;
        let counter = Cell::new(0usize);
        let calls = &counter;
        let f = |x: &[f64]| {
            calls.set(calls.get() + 1);
            x.iter()
                .enumerate()
                .map(|(i, v)| (i as f64 + 1.0) * (v - 0.3).powi(2))
                .sum::<f64>()
        };
        let after = |k: usize| move || calls.get() >= k;
        let start = vec![0.5; n];
        let m = minimize_until(&f, &start, 0.15, 1e-12, &after(200));
        assert!(calls.get() <= 200 + n + 1, "{} evaluations", calls.get());
        assert!(!m.converged);
        calls.set(0);
        let unstopped = minimize(&f, &start, 0.15, 1e-12);
        assert!(unstopped.evals > 10 * (200 + n + 1), "{}", unstopped.evals);
        calls.set(0);
        let p = profile(&f, &unstopped, 3, 21, 1e-12, &after(200));
        assert!(calls.get() <= 200 + n + 1, "{} evaluations", calls.get());
        assert_eq!(p.len(), 21);
    }
}
