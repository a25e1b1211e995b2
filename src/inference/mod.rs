//! The mathematics a fit stands on, with no dice in it: a smooth surrogate of a simulator's
//! outcome probabilities, the likelihood of counts under it, the optimiser and the posterior
//! sampler. What is fitted to what (the counts, the parameters, the designs) is
//! [`crate::calibration`]'s; the rolling, [`crate::studies::fit`]'s.
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
