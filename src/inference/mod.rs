//! Inference from counts: what parameters make the simulator match measured counts, how sure
//! that is, and what it then predicts. Pure statistics, no simulation (the study that rolls the
//! dice is [`crate::studies::fit`]).
//!
//! * [`surrogate`]: the simulator's outcome probabilities as a smooth function of the
//!   parameters, fitted to simulated counts at many points (a multinomial logit in Legendre
//!   polynomials), with the covariance its simulation noise leaves;
//! * [`likelihood`]: measured counts given probabilities that carry that noise
//!   (Dirichlet-multinomial), outcomes counted together, Pearson's χ²;
//! * [`optimize`]: the maximum-likelihood point and profile-likelihood intervals (Nelder–Mead
//!   in the unit box);
//! * [`posterior`]: draws from the flat-prior posterior (Metropolis), for predictions.

pub mod likelihood;
pub mod optimize;
pub mod posterior;
pub mod surrogate;
