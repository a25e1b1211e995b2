//! Turns: the random directions and rotations a throw other than the paper's draws, each from
//! uniform deviates, so that a keyed stream makes them a pure function of (seed, index): a
//! rotation uniform on SO(3) (Haar), a direction uniform on the sphere, and the hand's turn of
//! the paper's throw, whose von Mises–Fisher and wrapped-Cauchy angles a concentration κ
//! spreads (κ = 0 the tumble, κ → ∞ the paper's throw).

use crate::model::scene::Mode;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// The directions a tumble or a rest throw draws, beyond the paper's numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Turn {
    /// The starting orientation, body to world, as a unit quaternion [w, i, j, k]: uniform on
    /// the rotations (Haar measure), by Shoemake's method from three uniform deviates.
    pub rotation: [f64; 4],
    /// The spin axis in world axes, uniform on the unit sphere (zero at rest).
    pub spin_axis: [f64; 3],
    /// The horizontal velocity's direction, radians from +x towards +z, uniform (0 at rest).
    pub heading: f64,
}

impl Turn {
    /// The orientation in 3D, or in 2D its angle about z: the azimuth of the rotated body x
    /// axis in the x-y plane, uniform on [0, 2π) when the rotation is Haar-uniform (the rotated
    /// x axis is uniform on the sphere, and so its azimuth about z).
    pub fn orientation(&self, mode: Mode) -> UnitQuaternion<f64> {
        let [w, i, j, k] = self.rotation;
        let q = UnitQuaternion::new_normalize(Quaternion::new(w, i, j, k));
        match mode {
            Mode::ThreeD => q,
            Mode::TwoD => {
                let x = q * Vector3::x();
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), x.y.atan2(x.x))
            }
        }
    }
}

/// A unit quaternion [w, i, j, k] uniform on the rotations (Haar measure) from three
/// independent uniform deviates in [0, 1), by Shoemake's method ("Uniform random rotations",
/// Graphics Gems III, 1992): (√(1−u₁) sin 2πu₂, √(1−u₁) cos 2πu₂, √u₁ sin 2πu₃, √u₁ cos 2πu₃)
/// is uniform on the unit 3-sphere, and so its rotation on SO(3).
pub fn haar_quaternion(u1: f64, u2: f64, u3: f64) -> [f64; 4] {
    use std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (s2, c2) = (TAU * u2).sin_cos();
    let (s3, c3) = (TAU * u3).sin_cos();
    [b * c3, a * s2, a * c2, b * s3]
}

/// The mean cosine of a von Mises–Fisher direction on the sphere with concentration κ about
/// its mean: the Langevin function L(κ) = coth κ − 1/κ, from 0 (κ = 0, uniform) to 1 (κ → ∞).
/// A hand's throw's every angle has this mean cosine, so L(κ) is its "alignment" with the
/// paper's throw.
pub fn alignment(kappa: f64) -> f64 {
    if kappa < 1e-4 {
        kappa / 3.0
    } else if kappa > 40.0 {
        1.0 - 1.0 / kappa
    } else {
        1.0 / kappa.tanh() - 1.0 / kappa
    }
}

/// The concentration κ whose [`alignment`] is `a` in [0, 1) (Newton's method on L, which is
/// increasing and concave on κ ≥ 0).
pub fn kappa_of_alignment(a: f64) -> f64 {
    if a <= 0.0 {
        return 0.0;
    }
    if a >= 1.0 {
        return f64::INFINITY;
    }
    // Start from the larger of the two ends' inverses (3a near 0, 1/(1−a) near 1): above the
    // root, where Newton on a concave increasing function converges monotonically.
    let mut k = (3.0 * a).max(1.0 / (1.0 - a));
    for _ in 0..100 {
        let slope = if k < 1e-4 {
            1.0 / 3.0
        } else {
            1.0 / (k * k) - 1.0 / k.sinh().powi(2)
        };
        let next = (k - (alignment(k) - a) / slope.max(1e-300)).max(0.0);
        if (next - k).abs() <= 1e-13 * k.max(1.0) {
            return next;
        }
        k = next;
    }
    k
}

/// The cosine to its mean of a von Mises–Fisher direction on the sphere with concentration κ,
/// by the inverse of its distribution function from one uniform deviate u (Wood, 1994):
/// w = 1 + ln(u + (1 − u) e^(−2κ))/κ; uniform in [−1, 1] at κ = 0. A smooth function of κ for
/// a fixed u, so that throws keyed by one stream move smoothly as κ changes.
fn vmf_cosine(kappa: f64, u: f64) -> f64 {
    if kappa < 1e-9 {
        return 2.0 * u - 1.0;
    }
    let e = (-2.0 * kappa).exp();
    (1.0 + (e + u * (-(-2.0 * kappa).exp_m1())).ln() / kappa).clamp(-1.0, 1.0)
}

/// A von Mises–Fisher unit vector about +z with concentration κ, from two deviates.
fn vmf_about_z(kappa: f64, u1: f64, u2: f64) -> Vector3<f64> {
    let w = vmf_cosine(kappa, u1);
    let r = (1.0 - w * w).max(0.0).sqrt();
    let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
    Vector3::new(r * c, r * s, w)
}

/// An angle in (−π, π] from the wrapped Cauchy distribution about 0 with mean resultant ρ in
/// [0, 1), by the inverse of its distribution function: 2 atan(((1 − ρ)/(1 + ρ)) tan(π(u − ½))),
/// uniform at ρ = 0. Its mean cosine is ρ.
fn wrapped_cauchy(rho: f64, u: f64) -> f64 {
    use std::f64::consts::PI;
    2.0 * (((1.0 - rho) / (1.0 + rho)) * (PI * (u - 0.5)).tan()).atan()
}

/// A hand's turn of the paper's throw, with concentration κ, from six uniform deviates:
///
/// - the long axis (body z) points along a von Mises–Fisher direction about the world's z with
///   concentration κ (u₀, u₁), and the die is rolled about it by a wrapped Cauchy angle with
///   mean cosine L(κ) (u₂): the orientation is the shortest rotation taking z to that
///   direction, after the roll;
/// - the spin axis is a von Mises–Fisher direction about the body's long axis with
///   concentration κ (u₃, u₄), carried into the world by the orientation;
/// - the heading leaves +x by a wrapped Cauchy angle with mean cosine L(κ) (u₅).
///
/// At κ = 0 the long axis is uniform on the sphere and the roll uniform, so the orientation is
/// uniform on the rotations (Haar), and the spin axis, uniform in the body, is uniform in the
/// world: the tumble's distribution. As κ → ∞ every angle goes to 0: the paper's throw.
pub fn hand_turn(kappa: f64, u: [f64; 6]) -> Turn {
    let rho = alignment(kappa);
    let axis = vmf_about_z(kappa, u[0], u[1]);
    let tilt = UnitQuaternion::rotation_between(&Vector3::z(), &axis).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    });
    let roll = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), wrapped_cauchy(rho, u[2]));
    let q = tilt * roll;
    let spin = q * vmf_about_z(kappa, u[3], u[4]);
    let qq = q.quaternion();
    Turn {
        rotation: [qq.w, qq.i, qq.j, qq.k],
        spin_axis: [spin.x, spin.y, spin.z],
        heading: wrapped_cauchy(rho, u[5]),
    }
}

/// A unit vector uniform on the sphere from two uniform deviates in [0, 1) (Archimedes: z
/// uniform in [−1, 1], azimuth uniform).
pub fn unit_vector(u1: f64, u2: f64) -> [f64; 3] {
    let z = 2.0 * u1 - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
    [r * c, r * s, z]
}
