//! Convex-die geometry and exact mass properties.
//!
//! A die is a closed triangle mesh ([`Mesh`], triangles counter-clockwise seen from outside).
//! From it this module computes
//!
//! * its volume, centroid and inertia tensor about the centroid per unit density
//!   ([`Mesh::mass_properties`]), exactly, by the polyhedral volume integrals: the solid is cut
//!   into signed tetrahedra from a reference point, and each tetrahedron's integrals have closed
//!   forms (below). Non-convex meshes are allowed;
//! * its convex hull ([`hull`], by parry3d-f64's quickhull), the faces of a convex mesh with
//!   their coplanar triangles merged ([`facets`]), and whether a die resting on a face is in
//!   equilibrium ([`stable`]);
//! * the named dice of a games table ([`named`]: d4, d6, d8, d10, d12, d20 and N-gon prisms),
//!   with the label of each face, and a coin ([`Cylinder`]).
//!
//! Where parry3d-f64 is used, and where not: parry computes the convex hull ([`hull`]) only.
//! The mass properties are ours, in closed form, so that they can be tested against closed forms
//! to 1e-12; the tests compare them with parry's `MassProperties::from_trimesh` as a second
//! opinion (parry returns principal moments and a rotation, not the tensor in the mesh's axes).
//!
//! The module is unit-free: lengths are in whatever unit the caller uses (mm or m,
//! consistently), and mass properties are per unit density (mass = volume). The one exception
//! is the default size of a named die (`size: None`), which is in millimetres.
//!
//! Errors are `Result<_, String>`: one line saying what is wrong and where.

// Four rooms, one re-exported surface: `mesh` (the mesh and its exact volume integrals, a
// cylinder's), `hull` (the convex hull, its facets, the resting test), `offset` (facets moved
// in, a hull swept by a ball), `catalogue` (the named dice and their labels).
mod catalogue;
mod hull;
mod mesh;
mod offset;
#[cfg(test)]
mod tests;

pub use catalogue::*;
pub use hull::*;
pub use mesh::*;
pub use offset::{inner_hull, rounded_hull, DIRECTIONS};
