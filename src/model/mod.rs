//! Rod and strip models: discretisation and state, clamps, constitutive laws,
//! energies and their exact derivatives, contact gaps, the trefoil start, and
//! the continuum (shooting) ODE.

pub mod contact;
pub mod contact_hessian;
pub mod energy;
pub mod frames;
pub mod hessian_form;
pub mod natural;
pub mod ode;
pub mod rod;
pub mod shooting;
pub mod strain_hessian;
pub mod strip_shooting;
pub mod trefoil;
