//! Solvers of the discrete rod: one minimiser (Newton, and SQP for
//! constrained laws and contact) behind [`minimizer::Minimizer`], the KKT
//! system of constrained laws, pseudo-arclength continuation, the secant
//! iteration and bisection that locate roots along a family
//! ([`root`]), and the vocabulary of events ([`event::Vanishing`]).

pub mod continuation;
pub mod continuum;
pub mod event;
pub mod kkt;
pub mod minimizer;
pub mod newton;
pub mod outcome;
pub mod root;
pub mod sqp;
pub mod step;
