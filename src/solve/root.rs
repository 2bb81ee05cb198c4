//! Where a scalar test vanishes along a one-parameter family of equilibria:
//! one secant iteration ([`Secant::find`]) and one bisection ([`bisect`]),
//! each calling back for the (expensive, warm-started) equilibrium at an
//! abscissa. The continuum's events, the boundary walk's corrector and
//! corners, the polish's corners and a loading path's jumps all narrow their
//! roots here, by the same rules.

/// An abscissa where the family was solved: the test's value there and the
/// caller's solution.
#[derive(Clone, Debug)]
pub struct Iterate<P> {
    /// The abscissa.
    pub at: f64,
    /// The test's value there.
    pub value: f64,
    /// The caller's solution there.
    pub point: P,
}

/// How a secant iteration starts.
#[derive(Clone, Debug)]
pub enum Start<P> {
    /// One solved abscissa and the test's slope there.
    Slope(Iterate<P>, f64),
    /// Two solved abscissae (the later one second).
    Chord(Iterate<P>, Iterate<P>),
}

/// How far a secant step may reach before it has left the root's
/// neighbourhood (another root's, or no root's).
#[derive(Clone, Copy, Debug)]
pub enum Reach {
    /// The root within `radius` of `centre`.
    Around {
        /// The neighbourhood's centre.
        centre: f64,
        /// Its radius.
        radius: f64,
    },
    /// A step of at most this.
    Step(f64),
    /// A step of at most `factor` times the larger of `floor` and the last
    /// chord.
    Chord {
        /// The factor.
        factor: f64,
        /// The smallest chord counted.
        floor: f64,
    },
}

impl Reach {
    fn reached(&self, root: f64, step: f64, chord: f64) -> bool {
        !root.is_finite()
            || match *self {
                Reach::Around { centre, radius } => (root - centre).abs() > radius,
                Reach::Step(m) => step.abs() > m,
                Reach::Chord { factor, floor } => step.abs() > factor * floor.max(chord.abs()),
            }
    }
}

/// The rules of a secant iteration.
#[derive(Clone, Copy, Debug)]
pub struct Secant {
    /// Most evaluations after the start.
    pub max_evaluations: usize,
    /// Converged once the predicted root moves by at most this (times
    /// 1 + |root| where `relative`).
    pub tolerance: f64,
    /// Whether `tolerance` is relative to 1 + |root|.
    pub relative: bool,
    /// How far a step may reach.
    pub reach: Reach,
    /// Solve a little past each predicted root, by this, and extrapolate the
    /// root: for a test too noisy at its root (the lowest eigenvalue, solved
    /// on its stable side).
    pub offset: f64,
    /// Solve at the converged root before returning it; otherwise the root
    /// is extrapolated from the last solution (one solve fewer).
    pub confirm: bool,
    /// A chord shorter than this keeps the previous slope (the test's noise
    /// would swamp it).
    pub shortest_chord: f64,
    /// An iteration that fails once its last `.0` abscissae lie within `.1`
    /// of each other has stalled at the test's noise: its last solution is
    /// the root, its error that spread.
    pub stall: Option<(usize, f64)>,
}

impl Default for Secant {
    fn default() -> Self {
        Secant {
            max_evaluations: 40,
            tolerance: 1e-10,
            relative: false,
            reach: Reach::Step(f64::INFINITY),
            offset: 0.0,
            confirm: true,
            shortest_chord: 0.0,
            stall: None,
        }
    }
}

/// A root found by the secant iteration.
#[derive(Clone, Debug)]
pub struct Root<P> {
    /// The root: where the test vanishes (extrapolated where not
    /// confirmed).
    pub at: f64,
    /// The last solution: at the root where confirmed, else the one it was
    /// extrapolated from.
    pub last: Iterate<P>,
    /// The solution before it.
    pub previous: Option<Iterate<P>>,
    /// The last secant step.
    pub step: f64,
    /// The root's error: its last move, or a stall's spread.
    pub error: f64,
    /// Secant steps taken.
    pub iterations: usize,
}

/// Why a secant iteration found no root.
#[derive(Debug, Clone, PartialEq)]
pub enum NoRoot<E> {
    /// It took its evaluations without converging (nor stalling).
    NotConverged,
    /// The test was flat or undefined along the last chord.
    Flat,
    /// A step left the root's neighbourhood (this step).
    Left(f64),
    /// The family could not be solved at a step.
    Failed(E),
}

/// A failed secant iteration: why, and the last two test values.
#[derive(Debug, Clone, PartialEq)]
pub struct SecantFailure<E> {
    /// Why.
    pub why: NoRoot<E>,
    /// The test's last two values (the later second).
    pub values: [f64; 2],
}

impl Secant {
    /// The root of the test from `start`: `evaluate(at, step, last,
    /// previous)` solves the family at `at` (a secant step `step` from the
    /// last solution, plus the offset) and returns the test there;
    /// `settled(last, next)` may declare a root before the step is small
    /// (a located quantity stationary there).
    pub fn find<P, E>(
        &self,
        start: Start<P>,
        mut evaluate: impl FnMut(f64, f64, &Iterate<P>, Option<&Iterate<P>>) -> Result<Iterate<P>, E>,
        settled: impl Fn(&Iterate<P>, &Iterate<P>) -> bool,
    ) -> Result<Root<P>, SecantFailure<E>> {
        // the chord (Δabscissa, Δtest) whose ratio is the slope
        let (mut previous, mut last, mut chord) = match start {
            Start::Slope(a, slope) => (None, a, (1.0, slope)),
            Start::Chord(a, b) => {
                let chord = (b.at - a.at, b.value - a.value);
                (Some(a), b, chord)
            }
        };
        // the abscissae solved at, for the stall rule alone
        let mut visited: Vec<f64> = match self.stall {
            Some(_) => previous.iter().chain([&last]).map(|p| p.at).collect(),
            None => Vec::new(),
        };
        let mut last_root = f64::NAN;
        let mut evaluations = 0;
        let why = 'iterate: {
            for k in 0..=self.max_evaluations {
                if last.value == 0.0 {
                    return Ok(Root {
                        at: last.at,
                        last,
                        previous,
                        step: 0.0,
                        error: 0.0,
                        iterations: k,
                    });
                }
                if k == self.max_evaluations {
                    break 'iterate NoRoot::NotConverged;
                }
                if chord.1 == 0.0 || !last.value.is_finite() || !chord.1.is_finite() {
                    break 'iterate NoRoot::Flat;
                }
                let step = -last.value * chord.0 / chord.1;
                let root = last.at + step;
                let last_chord = previous.as_ref().map_or(0.0, |p| last.at - p.at);
                if self.reach.reached(root, step, last_chord) {
                    break 'iterate NoRoot::Left(step);
                }
                // the predicted root's move: the step itself where each
                // root is solved at, else the change of the extrapolation
                let moved = if self.offset == 0.0 {
                    step.abs()
                } else {
                    (root - last_root).abs()
                };
                let tolerance = if self.relative {
                    self.tolerance * (1.0 + root.abs())
                } else {
                    self.tolerance
                };
                if !self.confirm && moved <= tolerance {
                    return Ok(Root {
                        at: root,
                        last,
                        previous,
                        step,
                        error: moved,
                        iterations: k + 1,
                    });
                }
                let next = match evaluate(root + self.offset, step, &last, previous.as_ref()) {
                    Ok(next) => next,
                    Err(e) => break 'iterate NoRoot::Failed(e),
                };
                let dx = next.at - last.at;
                if dx.abs() > self.shortest_chord {
                    chord = (dx, next.value - last.value);
                }
                evaluations += 1;
                if self.stall.is_some() {
                    visited.push(next.at);
                }
                let done = (self.confirm && moved <= tolerance) || settled(&last, &next);
                previous = Some(std::mem::replace(&mut last, next));
                last_root = root;
                if done {
                    return Ok(Root {
                        at: last.at,
                        last,
                        previous,
                        step,
                        error: moved,
                        iterations: k + 1,
                    });
                }
            }
            NoRoot::NotConverged
        };
        // steps stalled at the test's noise (a root where it is flat): the
        // last solution, its error the spread of the last abscissae (not
        // for a step that left the neighbourhood)
        if let Some((count, spread)) = self.stall
            && !matches!(why, NoRoot::Left(_))
            && visited.len() > count
        {
            let tail = &visited[visited.len() - count..];
            let (lo, hi) = tail
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                });
            if hi - lo < spread {
                let step = previous.as_ref().map_or(0.0, |p| last.at - p.at);
                return Ok(Root {
                    at: last.at,
                    last,
                    previous,
                    step,
                    error: hi - lo,
                    iterations: evaluations,
                });
            }
        }
        let values = [previous.map_or(f64::NAN, |p| p.value), last.value];
        Err(SecantFailure { why, values })
    }
}

/// What a bisection's probe found at an abscissa.
#[derive(Clone, Debug)]
pub enum Probe<H, F> {
    /// The property holds at this abscissa (the probe may have moved off
    /// the midpoint), with the solution there.
    Holds(f64, H),
    /// It fails at this abscissa, with the solution there.
    Fails(f64, F),
    /// No solution at the midpoint: counted as past the change.
    Unsolved,
    /// No solution near the midpoint: the bracket is as narrow as it gets.
    Stop,
}

/// The narrowed bracket: the last abscissa where the property held and the
/// first where it failed, with their solutions (None: the ends given).
#[derive(Clone, Debug)]
pub struct Bracket<H, F> {
    /// Where it last held.
    pub lo: f64,
    /// Where it first failed.
    pub hi: f64,
    /// The solution at `lo`, if probed.
    pub holds: Option<H>,
    /// The solution at `hi`, if probed.
    pub fails: Option<F>,
}

/// Bisect `[lo, hi]`, where a property holds at `lo` and fails at `hi`,
/// until `narrow(lo, hi)`: `probe(mid)` solves the family at the midpoint
/// (given the bracket so far) and says which side it lies on.
pub fn bisect<H, F, E>(
    lo: f64,
    hi: f64,
    narrow: impl Fn(f64, f64) -> bool,
    mut probe: impl FnMut(f64, &Bracket<H, F>) -> Result<Probe<H, F>, E>,
) -> Result<Bracket<H, F>, E> {
    let mut b = Bracket {
        lo,
        hi,
        holds: None,
        fails: None,
    };
    while !narrow(b.lo, b.hi) {
        let mid = 0.5 * (b.lo + b.hi);
        // adjacent floats: no narrower bracket exists
        if mid == b.lo || mid == b.hi {
            break;
        }
        match probe(mid, &b)? {
            Probe::Holds(at, h) => (b.lo, b.holds) = (at, Some(h)),
            Probe::Fails(at, f) => (b.hi, b.fails) = (at, Some(f)),
            Probe::Unsolved => b.hi = mid,
            Probe::Stop => break,
        }
    }
    Ok(b)
}

/// [`bisect`] for a predicate alone: the middle of the final bracket of
/// `[lo, hi]`, where `holds` is true at `lo` and false at `hi`.
pub fn bisect_predicate<E>(
    lo: f64,
    hi: f64,
    narrow: impl Fn(f64, f64) -> bool,
    mut holds: impl FnMut(f64) -> Result<bool, E>,
) -> Result<f64, E> {
    let b = bisect(lo, hi, narrow, |mid, _: &Bracket<(), ()>| {
        Ok(if holds(mid)? {
            Probe::Holds(mid, ())
        } else {
            Probe::Fails(mid, ())
        })
    })?;
    Ok(0.5 * (b.lo + b.hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic(x: f64) -> f64 {
        x * x * x - 2.0 * x - 5.0
    }

    #[test]
    fn the_secant_iteration_finds_a_cubics_root_superlinearly() {
        // Wallis' cubic, root 2.0945514815423265
        let eval = |at: f64, _: f64, _: &Iterate<()>, _: Option<&Iterate<()>>| {
            Ok::<_, ()>(Iterate {
                at,
                value: cubic(at),
                point: (),
            })
        };
        let it = |at: f64| Iterate {
            at,
            value: cubic(at),
            point: (),
        };
        let s = Secant {
            tolerance: 1e-13,
            ..Secant::default()
        };
        let root = s
            .find(Start::Chord(it(2.0), it(2.2)), eval, |_, _| false)
            .unwrap();
        assert!((root.at - 2.094_551_481_542_326_5).abs() < 1e-14);
        assert!(root.iterations <= 7, "{} iterations", root.iterations);
        // from a slope, confirmed or not: unconfirmed, the root is
        // extrapolated from the last solve, one solve fewer
        let solves = |s: &Secant| {
            let mut count = 0;
            let root = s
                .find(
                    Start::Slope(it(2.0), 10.0),
                    |at, _, _, _| {
                        count += 1;
                        Ok::<_, ()>(it(at))
                    },
                    |_, _| false,
                )
                .unwrap();
            assert!((root.at - 2.094_551_481_542_326_5).abs() < 1e-13);
            count
        };
        let unconfirmed = Secant {
            confirm: false,
            ..s
        };
        assert_eq!(solves(&unconfirmed) + 1, solves(&s));
    }

    #[test]
    fn an_offset_iteration_extrapolates_the_root_from_its_good_side() {
        let eval = |at: f64, _: f64, _: &Iterate<()>, _: Option<&Iterate<()>>| {
            Ok::<_, ()>(Iterate {
                at,
                value: at - 1.0,
                point: (),
            })
        };
        let s = Secant {
            offset: 1e-3,
            confirm: false,
            tolerance: 1e-12,
            ..Secant::default()
        };
        let start = Iterate {
            at: 3.0,
            value: 2.0,
            point: (),
        };
        let root = s
            .find(Start::Slope(start, 0.5), eval, |_, _| false)
            .unwrap();
        assert!((root.at - 1.0).abs() < 1e-12);
        // every solve lay on the side the offset points to
        assert!(root.last.at > 1.0);
    }

    #[test]
    fn the_secant_iteration_reports_why_it_failed() {
        let flat = |at: f64, _: f64, _: &Iterate<()>, _: Option<&Iterate<()>>| {
            Ok::<_, ()>(Iterate {
                at,
                value: 1.0,
                point: (),
            })
        };
        let it = |at: f64, value: f64| Iterate {
            at,
            value,
            point: (),
        };
        let s = Secant::default();
        let e = s
            .find(Start::Chord(it(0.0, 1.0), it(1.0, 1.0)), flat, |_, _| false)
            .unwrap_err();
        assert_eq!(e.why, NoRoot::Flat);
        let s = Secant {
            reach: Reach::Step(0.1),
            ..s
        };
        let e = s
            .find(Start::Chord(it(0.0, 2.0), it(1.0, 1.0)), flat, |_, _| false)
            .unwrap_err();
        assert_eq!(e.why, NoRoot::Left(1.0));
        let failing = |_: f64, _: f64, _: &Iterate<()>, _: Option<&Iterate<()>>| {
            Err::<Iterate<()>, _>("no equilibrium")
        };
        let e = Secant::default()
            .find(Start::Slope(it(0.0, 1.0), 1.0), failing, |_, _| false)
            .unwrap_err();
        assert_eq!(e.why, NoRoot::Failed("no equilibrium"));
        // x² has a double root: the secant crawls at linear speed and, with
        // few evaluations, stalls; the stall rule takes it when the last
        // abscissae lie close together
        let square = |at: f64, _: f64, _: &Iterate<()>, _: Option<&Iterate<()>>| {
            Ok::<_, ()>(Iterate {
                at,
                value: at * at,
                point: (),
            })
        };
        let s = Secant {
            max_evaluations: 30,
            tolerance: 1e-300,
            ..Secant::default()
        };
        let start = || Start::Chord(it(1.0, 1.0), it(0.9, 0.81));
        let e = s.find(start(), square, |_, _| false).unwrap_err();
        assert_eq!(e.why, NoRoot::NotConverged);
        let s = Secant {
            stall: Some((4, 1e-3)),
            ..s
        };
        let root = s.find(start(), square, |_, _| false).unwrap();
        assert!(root.at.abs() < 1e-3 && root.error < 1e-3 && root.error > 0.0);
    }

    #[test]
    fn bisection_narrows_to_the_change_and_counts_unsolved_as_past_it() {
        // holds below 0.3; unsolved in (0.6, 0.7)
        let b = bisect(
            0.0,
            1.0,
            |lo, hi| hi - lo < 1e-9,
            |mid, _| {
                Ok::<_, ()>(if (0.6..0.7).contains(&mid) {
                    Probe::Unsolved
                } else if mid < 0.3 {
                    Probe::Holds(mid, mid)
                } else {
                    Probe::Fails(mid, mid)
                })
            },
        )
        .unwrap();
        assert!(b.lo <= 0.3 && b.hi >= 0.3 && b.hi - b.lo < 1e-9);
        assert_eq!(b.holds, Some(b.lo));
        assert_eq!(b.fails, Some(b.hi));
        // a probe that stops leaves the bracket as it is
        let b = bisect(
            0.0,
            1.0,
            |lo, hi| hi - lo < 1e-9,
            |_, _| Ok::<Probe<(), ()>, ()>(Probe::Stop),
        )
        .unwrap();
        assert_eq!((b.lo, b.hi), (0.0, 1.0));
        // a bracket asked narrower than the floats allow ends at adjacent ones
        let x = bisect_predicate(1.0, 2.0, |_, _| false, |m| Ok::<_, ()>(m * m < 2.0)).unwrap();
        assert!((x - 2f64.sqrt()).abs() <= 2.0 * f64::EPSILON);
    }
}
