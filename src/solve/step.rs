//! One step-size control for every path-following method (branches, the
//! continuation to a parameter value, the boundary walk): the step is halved
//! after a failed step and grown after an easy one, within [min, max].

/// The step length of a path-following method.
#[derive(Clone, Copy, Debug)]
pub struct StepControl {
    /// The current step.
    pub length: f64,
    first: f64,
    min: f64,
    max: f64,
    growth: f64,
    easy: usize,
}

impl StepControl {
    /// Start at `first`; never below `min` nor above `max`; grow by `growth`
    /// after a step whose corrector took at most `easy` iterations.
    pub fn new(first: f64, min: f64, max: f64, growth: f64, easy: usize) -> Self {
        StepControl {
            length: first,
            first,
            min,
            max,
            growth,
            easy,
        }
    }

    /// Halve the step after a failure; false once it falls below the smallest.
    fn shrink(&mut self) -> bool {
        self.length *= 0.5;
        self.length >= self.min
    }

    /// After a step accepted in `iterations` corrector iterations: grow it if
    /// that was easy.
    fn accepted(&mut self, iterations: usize) {
        if iterations <= self.easy {
            self.length = (self.length * self.growth).min(self.max);
        }
    }

    /// One step of a path-following method: try `attempt` at the current
    /// length, accept it by `rule`, else halve and try again. On acceptance
    /// the step grows (if the corrector was easy) and the point comes back
    /// with the length it was found at; once the step falls below the
    /// smallest, the last error (None: the rule refused it) comes back.
    pub fn advance<P, E>(
        &mut self,
        rule: &Acceptance,
        mut attempt: impl FnMut(f64) -> Result<Trial<P>, E>,
    ) -> Result<(P, f64), Option<E>> {
        loop {
            let sigma = self.length;
            let last = match attempt(sigma) {
                Ok(t) if rule.accepts(&t, sigma) => {
                    self.accepted(t.iterations);
                    return Ok((t.point, sigma));
                }
                Ok(_) => None,
                Err(e) => Some(e),
            };
            if !self.shrink() {
                return Err(last);
            }
        }
    }

    /// Back to the first step (a new curve begins).
    pub fn restart(&mut self) {
        self.length = self.first;
    }
}

/// A corrected point offered to the step rule.
#[derive(Clone, Debug)]
pub struct Trial<P> {
    /// The point.
    pub point: P,
    /// Corrector iterations it took.
    pub iterations: usize,
    /// Corrector move relative to the step (0 where not measured).
    pub correction: f64,
    /// Cosine of the tangent's turn over the step, in the path's metric.
    pub turn: f64,
}

/// The one acceptance rule of a step: few corrector iterations, a small
/// correction and a small turn of the tangent — the step stayed on this part
/// of the curve rather than jumping across a hairpin.
#[derive(Clone, Copy, Debug)]
pub struct Acceptance {
    /// Most corrector iterations.
    pub max_iterations: usize,
    /// Largest correction relative to the step.
    pub max_correction: f64,
    /// Smallest cosine of the tangent's turn.
    pub min_turn: f64,
    /// Below this step the turn is not checked (a curve turning sharply on a
    /// tiny step is a corner, not a jump).
    pub turn_free_below: f64,
}

impl Acceptance {
    /// Whether the trial found `sigma` along the curve is accepted.
    pub fn accepts<P>(&self, t: &Trial<P>, sigma: f64) -> bool {
        t.iterations <= self.max_iterations
            && t.correction < self.max_correction
            && (sigma.abs() < self.turn_free_below || t.turn > self.min_turn)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_on_failure_grows_after_easy_steps_within_bounds() {
        let mut s = StepControl::new(0.01, 0.004, 0.02, 1.5, 3);
        s.accepted(3);
        assert_eq!(s.length, 0.01 * 1.5);
        s.accepted(3);
        assert_eq!(s.length, 0.02);
        s.accepted(4);
        assert_eq!(s.length, 0.02);
        assert!(s.shrink() && s.shrink());
        assert_eq!(s.length, 0.005);
        assert!(!s.shrink());
        s.restart();
        assert_eq!(s.length, 0.01);
    }

    #[test]
    fn advance_halves_until_the_rule_accepts_then_grows() {
        let rule = Acceptance {
            max_iterations: 6,
            max_correction: 0.5,
            min_turn: 0.9,
            turn_free_below: 0.0,
        };
        let mut s = StepControl::new(0.016, 0.001, 0.02, 1.5, 3);
        // a sharp turn beyond a step of 0.005 (a hairpin): refused until then
        let r = s.advance(&rule, |sigma| {
            Ok::<_, ()>(Trial {
                point: sigma,
                iterations: 2,
                correction: 0.1,
                turn: if sigma > 0.005 { 0.5 } else { 0.99 },
            })
        });
        assert_eq!(r, Ok((0.004, 0.004)));
        assert_eq!(s.length, 0.004 * 1.5);
        // never accepted: the step runs out and the last error comes back
        let r: Result<(f64, f64), Option<&str>> = s.advance(&rule, |_| Err("lost"));
        assert_eq!(r, Err(Some("lost")));
    }
}
