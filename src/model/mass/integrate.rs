//! The mass integration: the solid's mass, centre of mass and inertia tensor from its parts'
//! moments, and its principal frame.

use super::features::{Features, Insert};
use super::moments::{rounded_box, Moments};
use super::pips::{cavity, pip_moments, pip_overlaps, pip_places};
use super::shell;
use super::turn::BodyTurn;
use crate::error::{Error, Field, Result};
use crate::model::block::Mode;
use nalgebra::{Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};

/// The solid's mass properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps {
    /// kg.
    pub mass: f64,
    /// The centre of mass in body axes from the geometric centre, m.
    pub com: Vector3<f64>,
    /// The inertia tensor about the centre of mass, body axes, kg m².
    pub inertia: Matrix3<f64>,
    /// The principal frame in body axes: a body vector is `principal` × its principal
    /// coordinates. The identity when the tensor is diagonal in body axes.
    pub principal: UnitQuaternion<f64>,
    /// The principal moments, in the principal frame's axes.
    pub moments: Vector3<f64>,
}

impl MassProps {
    /// True if the principal frame is the body's own axes (no rotation between them).
    pub fn aligned(&self) -> bool {
        self.principal == UnitQuaternion::identity()
    }

    /// How an engine's body (the principal frame) is turned from the die's axes.
    pub fn turn(&self) -> BodyTurn {
        BodyTurn((!self.aligned()).then_some(self.principal))
    }
}

impl Insert {
    /// Its moments at unit density about the die's geometric centre: a box of volume V at c
    /// has Σ m r = V c and Σ m r rᵀ = V (diag(sᵢ²)/12 + c cᵀ).
    fn moments(&self) -> Moments {
        let s = Vector3::from(self.size);
        let c = Vector3::from(self.centre);
        let v = s.x * s.y * s.z;
        Moments {
            mass: v,
            first: v * c,
            second: v * (Matrix3::from_diagonal(&(s.component_mul(&s) / 12.0)) + c * c.transpose()),
        }
    }
}

/// What a die's mass properties depend on: its body's sides (x, y, z; in 2D the 1 m depth),
/// its density, its plain mass as the engines multiply it, 2D or 3D, and its features
/// (`Scene::composition`).
#[derive(Clone, Copy, Debug)]
pub struct Composition<'a> {
    /// The body's sides along x, y, z, m.
    pub sides: [f64; 3],
    /// kg/m³.
    pub density: f64,
    /// The plain block's mass, as the engines compute it (`Scene::mass`).
    pub plain_mass: f64,
    /// 2D or 3D.
    pub mode: Mode,
    /// The die as made.
    pub features: &'a Features,
    /// A die of any shape (`model::shape`), in place of the block of `sides`.
    pub shape: Option<&'a crate::model::shape::Shape>,
}

impl MassProps {
    /// The mass properties of a die: a solid of its density, rounded with `edge_radius`, less
    /// its pips (plus their fill), printed as a wall and an infill if it has a shell, with its
    /// centre of mass where `com` puts it if given. The
    /// plain block's are the closed forms the engines use. Checked.
    pub fn of_composition(s: &Composition) -> Result<MassProps> {
        let [a, b, c] = s.sides;
        match s.shape {
            Some(shape) => s.features.validate_on(shape, s.mode)?,
            None => s
                .features
                .validate(&(Vector3::new(a, b, c) / 2.0), s.mode)?,
        }
        let m = MassProps::compute_composition(s);
        let ok = m.moments.iter().all(|&x| x > 0.0)
            && (0..3).all(|i| m.moments[i] <= m.moments[(i + 1) % 3] + m.moments[(i + 2) % 3]);
        if !ok {
            let c = m.com * 1e3;
            return Err(Error::field(
                Field::Com,
                format!("{},{},{}", c.x, c.y, c.z),
                "is too far from the centre for this die's inertia (no solid has these moments)",
            ));
        }
        if let Some(t) = s.features.inertia {
            // Reliability round 5, class E: any solid's moment about an axis through its
            // centre of mass is at most m r², r the farthest any of its points lies from that
            // centre; far below it (a millionth) no engine here integrates the die.
            let reach = match s.shape {
                Some(shape) => shape.circumradius() + m.com.norm(),
                None => (Vector3::new(a, b, c) / 2.0).norm() + m.com.norm(),
            };
            let most = m.mass * reach * reach;
            if m.moments
                .iter()
                .any(|&x| x > most * (1.0 + 1e-9) || x < 1e-6 * most)
            {
                return Err(Error::field(
                    Field::Inertia,
                    t.map(|x| format!("{}", x * 1e9)).join(","),
                    format!(
                        "no die of this mass and size turns so: its principal moments must lie \
                         between a millionth of m·r² and m·r² = {:.4} g mm² (r = {:.3} mm, the \
                         farthest point from its centre of mass)",
                        most * 1e9,
                        reach * 1e3
                    ),
                ));
            }
        }
        Ok(m)
    }

    /// `of_composition` for a die already checked.
    pub fn compute_composition(s: &Composition) -> MassProps {
        let f = s.features;
        let [a, b, c] = s.sides;
        let half = Vector3::new(a, b, c) / 2.0;
        let rho = s.density;
        if f.plain() && s.shape.is_none() {
            let m = s.plain_mass;
            let inertia = Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (m / 12.0);
            return MassProps {
                mass: m,
                com: Vector3::zeros(),
                inertia: Matrix3::from_diagonal(&inertia),
                principal: UnitQuaternion::identity(),
                moments: inertia,
            };
        }
        let mut total = match s.shape {
            // A die of any shape: its solid's moments about its centroid.
            Some(shape) => Moments {
                mass: rho * shape.volume,
                first: Vector3::zeros(),
                second: shape.second_matrix() * rho,
            },
            None => {
                let (volume, second) = rounded_box(&half, f.edge_radius);
                Moments {
                    mass: rho * volume,
                    first: Vector3::zeros(),
                    second: Matrix3::from_diagonal(&(second * rho)),
                }
            }
        };
        if let Some(p) = &f.pips {
            let cav = cavity(p);
            for place in pip_places(&half, p, f.layout) {
                total.add(p.fill_density - rho, &pip_moments(&half, &cav, place));
            }
            // Where two cavities meet, the die lost that region once, not twice.
            total.add(rho - p.fill_density, &pip_overlaps(&half, p, f.layout));
        }
        if let Some(i) = &f.insert {
            total.add(i.density - rho, &i.moments());
        }
        if let Some(sh) = &f.shell {
            // The wall at ρ, the inner solid at ρ·infill: the inner solid's (1 − infill)
            // taken back. A wall too thick for the die (refused by the checks) leaves none.
            let inner = match s.shape {
                Some(shape) => shell::inner_shape(shape, sh.wall),
                None => {
                    (sh.wall < half.min()).then(|| shell::inner_box(&half, f.edge_radius, sh.wall))
                }
            };
            if let Some(inner) = inner {
                total.add(-(1.0 - sh.infill) * rho, &inner);
            }
        }
        let m = total.mass;
        let com = match f.com {
            Some(c) => Vector3::from(c),
            None => total.first / m,
        };
        // About the centre: I = tr(S) 1 − S; about the centre of mass (parallel axes):
        // I − m (|c|² 1 − c cᵀ).
        let s = total.second;
        let about_centre = Matrix3::identity() * s.trace() - s;
        let inertia = match f.inertia {
            Some([xx, yy, zz, xy, xz, yz]) => Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz),
            None => {
                about_centre
                    - m * (Matrix3::identity() * com.norm_squared() - com * com.transpose())
            }
        };
        let (principal, moments) = principal_frame(&inertia);
        MassProps {
            mass: m,
            com,
            inertia,
            principal,
            moments,
        }
    }
}

/// The principal frame and moments of a symmetric tensor: the identity and its diagonal
/// when it is diagonal already (so that an aligned die keeps its body axes exactly), else its
/// eigenvectors made a right-handed rotation.
fn principal_frame(t: &Matrix3<f64>) -> (UnitQuaternion<f64>, Vector3<f64>) {
    let off = t[(0, 1)].abs() + t[(0, 2)].abs() + t[(1, 2)].abs();
    if off == 0.0 {
        return (UnitQuaternion::identity(), t.diagonal());
    }
    let e = SymmetricEigen::new(*t);
    let mut v = e.eigenvectors;
    if v.determinant() < 0.0 {
        v.column_mut(2).neg_mut();
    }
    let r = Rotation3::from_matrix_unchecked(v);
    (UnitQuaternion::from_rotation_matrix(&r), e.eigenvalues)
}
