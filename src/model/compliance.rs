//! A soft contact (issue 72's compliance): the table gives under the die as a spring and a
//! dashpot side by side (Kelvin–Voigt), so that an impact lasts a time τ instead of an
//! instant, friction and the die's turning act through it, and the bounce is what the spring
//! gives back through the dashpot.
//!
//! The exact limit is the unilateral linear spring–dashpot (Schwager & Pöschel 2007): a mass
//! meeting the table at speed v sinks by x with m ẍ = −(k x + c ẋ) while that force pushes,
//! and leaves when it falls to 0, not when x returns to 0 (the table cannot pull). With
//! ω₀ = √(k/m) and the damping ratio ζ = c / (2 m ω₀), the restitution e and the duration
//! ω₀ τ depend on ζ alone ([`landing`]): e = 1 and ω₀ τ = π undamped, e = e⁻² and ω₀ τ = 2 at
//! ζ = 1, e → 0 overdamped. A scene gives e and τ (its restitution and its contact time);
//! [`solve`] turns them into ω₀ and ζ, and [`per_point`] into each of a flat face's four
//! contact points' stiffness and damping, so that a die landing flat at any speed leaves at
//! e v after τ.
//!
//! Bullet solves such a contact implicitly (its ERP = h k/(h k + c) and CFM = 1/(h k + c)): the
//! force on the step's end penetration, backward Euler, which loses energy of its own when the
//! step h is not small against τ (at h = τ/10 a flat landing keeps about 0.8 of its bounce);
//! the limit holds as h → 0 (tests/it/impact.rs).

/// Contact points a die's face holds on the table (Bullet's manifold keeps four): a flat
/// landing shares the spring and the dashpot among them.
pub const FACE_POINTS: f64 = 4.0;

/// The largest damping ratio solved for: e(1000) ≈ 3e-4, below any restitution a scene takes
/// with a soft contact.
const ZETA_MAX: f64 = 1e3;

/// The unilateral Kelvin–Voigt landing at damping ratio `zeta` (≥ 0): its restitution e and
/// its duration ω₀ τ. The force m (2β ẋ + ω₀² x), β = ζ ω₀, falls to 0 at the first t > 0 where
/// tan ω t = −2βω/(ω₀² − 2β²) (ω = ω₀√(1 − ζ²); its hyperbolic twin when overdamped).
pub fn landing(zeta: f64) -> (f64, f64) {
    let z = zeta.max(0.0);
    if (z - 1.0).abs() < 1e-6 {
        // Critical: x = v t e^(−t), the force 0 at t = 2, where ẋ = −v e⁻².
        return ((-2.0f64).exp(), 2.0);
    }
    if z < 1.0 {
        let w = (1.0 - z * z).sqrt();
        let t = (std::f64::consts::PI - (2.0 * z * w).atan2(1.0 - 2.0 * z * z)) / w;
        let e = -(-z * t).exp() * ((w * t).cos() - z / w * (w * t).sin());
        (e, t)
    } else {
        let w = (z * z - 1.0).sqrt();
        let t = (2.0 * z * w / (2.0 * z * z - 1.0)).atanh() / w;
        let e = -(-z * t).exp() * ((w * t).cosh() - z / w * (w * t).sinh());
        (e, t)
    }
}

/// ω₀ (rad/s) and ζ of the contact whose landing has restitution `e` in (0, 1] and lasts
/// `tau` > 0 s. e(ζ) falls from 1 to 0 as ζ grows, so ζ is found by bisection, to the last
/// bit (about 65 halvings; every roll's die asks it once: `DieBody::of`).
pub fn solve(e: f64, tau: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (0.0, ZETA_MAX);
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if landing(mid).0 > e {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let zeta = 0.5 * (lo + hi);
    (landing(zeta).1 / tau, zeta)
}

/// Each of a face's [`FACE_POINTS`] contact points' stiffness (N/m) and damping (N s/m) for a
/// die of `mass` kg whose flat landing has restitution `e` and lasts `tau` s.
pub fn per_point(mass: f64, e: f64, tau: f64) -> (f64, f64) {
    let (w0, zeta) = solve(e, tau);
    let k = mass * w0 * w0 / FACE_POINTS;
    let c = 2.0 * zeta * mass * w0 / FACE_POINTS;
    (k, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form against a direct integration of the unilateral contact (RK4, 10⁻⁵ of
    /// ω₀'s period): restitution and duration to 1e-6 at ζ across the three regimes.
    #[test]
    fn the_landing_is_the_spring_and_dashpot_integrated() {
        for zeta in [
            0.0, 0.05, 0.2, 0.5, 0.6, 0.7, 0.75, 0.9, 1.0, 1.3, 3.0, 10.0,
        ] {
            let (e, t) = landing(zeta);
            let f = |x: f64, v: f64| -(x + 2.0 * zeta * v);
            let (mut x, mut v, mut time) = (0.0f64, 1.0f64, 0.0f64);
            let h = 1e-5;
            loop {
                let (k1x, k1v) = (v, f(x, v));
                let (k2x, k2v) = (v + 0.5 * h * k1v, f(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
                let (k3x, k3v) = (v + 0.5 * h * k2v, f(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
                let (k4x, k4v) = (v + h * k3v, f(x + h * k3x, v + h * k3v));
                let (nx, nv) = (
                    x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
                    v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
                );
                // The table pushes while x + 2ζ v > 0; past its zero the contact has ended.
                if time > 0.0 && nx + 2.0 * zeta * nv <= 0.0 {
                    let (a, b) = (x + 2.0 * zeta * v, nx + 2.0 * zeta * nv);
                    let s = a / (a - b);
                    time += s * h;
                    v += s * (nv - v);
                    break;
                }
                (x, v, time) = (nx, nv, time + h);
            }
            assert!((-v - e).abs() < 1e-6, "ζ {zeta}: e {e}, integrated {}", -v);
            assert!(
                (time - t).abs() < 1e-6,
                "ζ {zeta}: ω₀τ {t}, integrated {time}"
            );
        }
    }

    /// The literature's values (Schwager & Pöschel 2007): e(0) = 1 with ω₀τ = π, e(1) = e⁻²,
    /// and e falls with ζ throughout, continuous at the critical ratio.
    #[test]
    fn the_restitution_falls_with_damping_from_one_to_zero() {
        assert_eq!(landing(0.0), (1.0, std::f64::consts::PI));
        assert!((landing(1.0).0 - (-2.0f64).exp()).abs() < 1e-15);
        let below = landing(1.0 - 2e-6);
        let above = landing(1.0 + 2e-6);
        assert!((below.0 - above.0).abs() < 1e-5 && (below.1 - above.1).abs() < 1e-5);
        let mut last = 1.0 + 1e-12;
        for n in 0..=400 {
            let zeta = 10f64.powf(-3.0 + n as f64 * 6.0 / 400.0);
            let (e, _) = landing(zeta);
            assert!(e < last && e > 0.0, "ζ {zeta}: e {e} after {last}");
            last = e;
        }
        assert!(landing(ZETA_MAX).0 < 1e-3);
    }

    /// `solve` inverts `landing`: the contact it gives has the asked e and τ.
    #[test]
    fn a_contact_solved_for_has_its_restitution_and_duration() {
        for e in [0.05, 0.135, 0.3, 0.5, 0.8, 0.99] {
            for tau in [0.002, 0.005, 0.01] {
                let (w0, zeta) = solve(e, tau);
                let (got, wt) = landing(zeta);
                assert!((got - e).abs() < 1e-9, "e {e}: {got}");
                assert!((wt / w0 - tau).abs() < 1e-12, "τ {tau}: {}", wt / w0);
            }
        }
        let (k, c) = per_point(0.004, 0.5, 0.005);
        let (w0, zeta) = solve(0.5, 0.005);
        assert!((FACE_POINTS * k / 0.004 - w0 * w0).abs() < 1e-6 * w0 * w0);
        assert!((FACE_POINTS * c / (2.0 * 0.004 * w0) - zeta).abs() < 1e-12);
    }
}
