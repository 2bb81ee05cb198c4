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
    pub fn shrink(&mut self) -> bool {
        self.length *= 0.5;
        self.length >= self.min
    }

    /// After a step accepted in `iterations` corrector iterations: grow it if
    /// that was easy.
    pub fn accepted(&mut self, iterations: usize) {
        if iterations <= self.easy {
            self.length = (self.length * self.growth).min(self.max);
        }
    }

    /// Back to the first step (a new curve begins).
    pub fn restart(&mut self) {
        self.length = self.first;
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
}
