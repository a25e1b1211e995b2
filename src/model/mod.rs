//! What is thrown and where: the die (the paper's block, a shape, a mesh) and its labelled
//! faces, what the engines collide, the die as a rigid body, its state, the scene (floor,
//! surface, time step), and the throws' initial conditions.

pub mod block;
pub mod collider;
pub mod compliance;
pub mod die;
pub mod faces;
pub mod form;
pub mod glibc;
pub mod mass;
pub mod mesh_file;
pub mod polytope;
pub mod scene;
pub mod shape;
pub mod state;
pub mod throws;
pub mod turns;
