//! What an engine collides: the die's solid described once, from the scene, and built into
//! each engine's own shape by one function there (`engine::bullet`, `engine::rapier3d`,
//! `engine::moreau`). A new kind of solid is a variant here and an arm in each of those.

use crate::model::scene::Scene;
use crate::model::shape::Solid;
use nalgebra::Vector3;

/// The die's solid, in body axes, centred on its geometric centre (its centroid).
#[derive(Clone, Debug, PartialEq)]
pub enum Collider {
    /// A box: half its sides along body x, y, z, m, its edges and corners rounded by
    /// `radius` (0: sharp). The paper's cuboid, a d6, a box-shaped mesh (`Shape::as_box`).
    Box {
        /// m.
        half: Vector3<f64>,
        /// m.
        radius: f64,
    },
    /// A convex polyhedron: its vertices, m, and the margin Bullet keeps its surface out
    /// from them (`Shape::margin`); rounded by `radius` (0: sharp), the vertices' hull swept
    /// by a ball of it (`Shape::rounded`: the inner body's vertices, the margin the radius).
    Hull {
        /// The vertices.
        points: Vec<Vector3<f64>>,
        /// m.
        margin: f64,
        /// m.
        radius: f64,
    },
    /// A cylinder along body z (a coin).
    Cylinder {
        /// m.
        radius: f64,
        /// m.
        half_height: f64,
    },
}

impl Collider {
    /// The scene's die's.
    pub fn of(scene: &Scene) -> Collider {
        match scene.die.hull().map(|s| (s, &s.solid)) {
            None => {
                let [a, b, c] = scene.body_sides();
                Collider::Box {
                    half: Vector3::new(a, b, c) / 2.0,
                    radius: scene.features.edge_radius,
                }
            }
            Some((s, Solid::Hull { .. })) => Collider::Hull {
                points: s.points(),
                margin: s.margin(),
                radius: s.radius,
            },
            Some((_, Solid::Cylinder { diameter, height })) => Collider::Cylinder {
                radius: 0.5 * diameter,
                half_height: 0.5 * height,
            },
        }
    }

    /// The sharp, centred-on-its-frame box the engines build straight from its sides (with
    /// the inertia they compute themselves) where the die is also the uniform, centred block:
    /// the paper's. Any other die is "made" (`model::mass`): its body is its principal frame
    /// at its centre of mass, its mass properties computed here.
    pub fn made(scene: &Scene) -> bool {
        !scene.features.plain() || scene.die.hull().is_some()
    }
}
