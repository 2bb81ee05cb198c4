//! Solvers of the discrete rod: the minimiser (Newton, and SQP for
//! constrained laws and contact) behind one entry point, the KKT system of
//! constrained laws, pseudo-arclength continuation.

pub mod continuation;
pub mod kkt;
pub mod newton;
pub mod sqp;
