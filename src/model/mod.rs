//! What is thrown and where: the block and its sides, the die as a rigid body and its six
//! faces, its state, the
//! scene (floor, surface, time step), and the throws' initial conditions.

pub mod block;
pub mod die;
pub mod faces;
pub mod glibc;
pub mod mass;
pub mod scene;
pub mod state;
pub mod throws;
pub mod turns;
