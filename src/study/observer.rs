//! What a study reports while it runs, to one observer: each equilibrium as
//! it is computed and each event as it is located (in the spirit of rapier's
//! `EventHandler`: one trait, a method per kind of news, `()` ignoring all).
//! The CLI's outputs (recording, JSON lines, progress, live view) and the
//! Python callbacks implement it; numerics never see what they do with it.

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::study::error::Result;

/// Receives a study's results as they come. An error from a method stops
/// the study, which returns it ([`crate::study::error::StudyError::Observer`]
/// for an interruption or a failed write).
pub trait Observer {
    /// An equilibrium, as soon as it is computed.
    fn equilibrium(&mut self, e: Equilibrium) -> Result<()>;

    /// An event, as soon as it is located, before the equilibrium past it.
    /// Its label is provisional: labels are counted along each whole branch
    /// (W1 is the wall event of least φ), so the study's result carries the
    /// final ones.
    fn event(&mut self, _e: &Event) -> Result<()> {
        Ok(())
    }
}

/// Ignores everything.
impl Observer for () {
    fn equilibrium(&mut self, _: Equilibrium) -> Result<()> {
        Ok(())
    }
}

/// An observer of equilibria only: a closure given each one.
pub struct Equilibria<F>(pub F);

impl<F: FnMut(Equilibrium) -> Result<()>> Observer for Equilibria<F> {
    fn equilibrium(&mut self, e: Equilibrium) -> Result<()> {
        (self.0)(e)
    }
}

/// An observer that hands each equilibrium to `f` and ignores events.
pub fn equilibria<F: FnMut(Equilibrium) -> Result<()>>(f: F) -> Equilibria<F> {
    Equilibria(f)
}

/// An observer of equilibria and events: a closure for each.
pub struct Both<E, V>(pub E, pub V);

impl<E, V> Observer for Both<E, V>
where
    E: FnMut(Equilibrium) -> Result<()>,
    V: FnMut(&Event) -> Result<()>,
{
    fn equilibrium(&mut self, e: Equilibrium) -> Result<()> {
        (self.0)(e)
    }

    fn event(&mut self, e: &Event) -> Result<()> {
        (self.1)(e)
    }
}

/// An observer that hands each equilibrium to `on_equilibrium` and each
/// event to `on_event`.
pub fn both<E, V>(on_equilibrium: E, on_event: V) -> Both<E, V>
where
    E: FnMut(Equilibrium) -> Result<()>,
    V: FnMut(&Event) -> Result<()>,
{
    Both(on_equilibrium, on_event)
}
