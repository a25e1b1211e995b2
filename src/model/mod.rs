//! What is thrown and where: the block and its sides, the die as a rigid body and its six
//! faces, its state, the
//! scene (floor, surface, time step), and the throws' initial conditions.

pub mod block;
pub mod die;
pub mod faces;
pub mod glibc;
pub mod mass;
pub mod mesh_file;
pub mod polytope;
pub mod scene;
pub mod shape;
pub mod state;
pub mod throws;
pub mod turns;
