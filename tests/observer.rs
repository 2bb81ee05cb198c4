//! The study's observer: events reach it as they are located, before the
//! equilibrium past them, the same events the study returns; a study stopped
//! by its observer keeps the events it passed.

use crate::common;
use knotrod::analysis::equilibrium::Equilibrium;
use knotrod::analysis::event::{Event, EventKind};
use knotrod::study::error::{Result, StudyError};
use knotrod::study::observer::Observer;
use knotrod::study::run::run_scene;

/// Keeps what it is told, in order; stops after `stop_after` equilibria.
#[derive(Default)]
struct Log {
    equilibria: usize,
    events: Vec<(usize, Event)>,
    stop_after: Option<usize>,
}

impl Observer for Log {
    fn equilibrium(&mut self, _: Equilibrium) -> Result<()> {
        self.equilibria += 1;
        if Some(self.equilibria) == self.stop_after {
            return Err(StudyError::Observer("stopped by the test".into()));
        }
        Ok(())
    }

    fn event(&mut self, e: &Event) -> Result<()> {
        self.events.push((self.equilibria, e.clone()));
        Ok(())
    }
}

#[test]
fn events_reach_the_observer_as_they_are_located() {
    let scene = common::scene_at("scenes/fig3_kirchhoff.toml", 60);
    let mut log = Log::default();
    let events = run_scene(&scene, None, &mut log).unwrap();
    // every event the study returns, told once, in the order found
    assert_eq!(log.events.len(), events.len());
    for ((_, told), e) in log.events.iter().zip(&events) {
        assert_eq!((told.kind, told.branch), (e.kind, e.branch));
        assert_eq!(told.phi_over_2pi, e.phi_over_2pi);
    }
    // as located: spread along the run, not all at its end
    let first = log.events.first().unwrap().0;
    assert!(
        first > 0 && first < log.equilibria / 2,
        "first event after {first} of {}",
        log.equilibria
    );
    // their provisional labels are the final ones here (one pass per leg)
    let kinds: Vec<EventKind> = events.iter().map(|e| e.kind).collect();
    assert!(kinds.contains(&EventKind::Wall) && kinds.contains(&EventKind::Crossing));
}

#[test]
fn a_run_stopped_by_its_observer_keeps_the_events_it_passed() {
    // Figure 3 from the Appendix D knot: up in φ past W2 and X first
    let scene = common::scene_at("scenes/fig3_kirchhoff.toml", 60);
    let mut full = Log::default();
    run_scene(&scene, None, &mut full).unwrap();
    let stop = full.equilibria / 3;
    let mut log = Log {
        stop_after: Some(stop),
        ..Log::default()
    };
    let err = run_scene(&scene, None, &mut log).unwrap_err();
    assert!(matches!(err, StudyError::Observer(_)));
    let passed: Vec<_> = full.events.iter().filter(|(k, _)| *k < stop).collect();
    assert!(!passed.is_empty(), "the first third passes events");
    assert_eq!(log.events.len(), passed.len());
}
