//! Rod models: discretisation, state, energies, and the continuum (shooting) ODE.

pub mod energy;
pub mod frames;
pub mod jet;
pub mod rod;
pub mod shooting;
pub mod trefoil;
