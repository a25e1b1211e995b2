//! The die as it is made: a centre of mass moved off the centre, drilled pips, rounded edges,
//! a printed shell and infill (`Features`), and the mass properties of the solid that results
//! (`MassProps`): its mass, centre of mass and inertia tensor, computed exactly.
//!
//! Every part is a box, a slab, a quarter cylinder, an eighth of a sphere, a spherical cap or a
//! cylinder, whose mass and first and second moments are closed forms (the cavities' are
//! polynomials of degree 4 along their axis, integrated exactly by 3-point Gauss–Legendre,
//! which avoids the cancellation of the antiderivatives for shallow pips). The parts add up
//! as moments about the geometric centre; the tensor about the centre of mass follows from
//! the parallel-axis theorem, and its eigenvectors are the body's principal frame.
//!
//! By concern: the description (`features`), its checks (`validate`), the die file
//! (`die_file`), the pips' geometry (`pips`), a printed die's inner solid (`shell`), a part's
//! moments (`moments`), the mass integration (`integrate`), a convex die's rounded edges
//! (`rounded`) and the frame an engine's body is turned by (`turn`).

mod die_file;
mod features;
mod integrate;
mod moments;
mod pips;
mod rounded;
#[cfg(test)]
mod rounded_tests;
mod shell;
#[cfg(test)]
mod shell_tests;
#[cfg(test)]
mod tests;
mod turn;
mod validate;

pub use die_file::{
    described_shape, is_mesh, DieFile, LabelDef, ReadFile, MAX_DIE_FILE, MAX_MESH_FILE,
};
pub use features::{pattern, Features, Insert, PipShape, Pips, Shell, DEFAULT_WALL};
pub use integrate::{Composition, MassProps};
pub use moments::rounded_box;
pub use pips::{cavity, pip_places};
pub use rounded::{rounded_shared, take_rounding};
pub use turn::BodyTurn;
