//! Time slicing: each UI frame gets a slice of path-tracing work that fits a frame budget, so the
//! window stays responsive where the GPU is the CPU (lavapipe). The renderer sizes each dispatch
//! to half the budget from its measured throughput (`sizing::dispatch_shape`); the slice clock then
//! runs dispatches while the next, predicted to take as long as the last, still fits.

use std::time::Duration;

/// A slice's default budget: 25 ms leaves a UI at 60 Hz about a frame in two, and keeps each
/// dispatch far from the ~100 ms at which operating systems suspect a hung GPU.
pub const DEFAULT_BUDGET: Duration = Duration::from_millis(25);

/// What each dispatch is sized to: half the budget, so a slice holds at least one whole one.
pub fn dispatch_target(budget: Duration) -> Duration {
    budget / 2
}

/// Counts a slice's dispatches against its budget.
#[derive(Clone, Copy, Debug)]
pub struct SliceClock {
    budget: Duration,
    spent: Duration,
}

impl SliceClock {
    pub fn new(budget: Duration) -> Self {
        SliceClock {
            budget,
            spent: Duration::ZERO,
        }
    }

    /// After a dispatch that took `last`: whether another as long still fits.
    pub fn another(&mut self, last: Duration) -> bool {
        self.spent += last;
        self.spent + last <= self.budget
    }

    pub fn spent(&self) -> Duration {
        self.spent
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sizing::dispatch_shape;

    /// A synthetic GPU: a dispatch of `rows × samples` costs `rate` seconds per sample-row, with a
    /// deterministic ±`jitter` wobble; the renderer's sizing and the slice clock run against it.
    fn slice(rate: f64, jitter: f64, budget: Duration, width: u32, rows: u32) -> (Duration, f64) {
        let (rows_per, samples) =
            dispatch_shape(rate, dispatch_target(budget), width, rows, 1 << 16, None)
                .unwrap_or((1, 1));
        let nominal = rate * f64::from(rows_per) * f64::from(samples);
        let mut clock = SliceClock::new(budget);
        let mut k = 0u32;
        loop {
            k += 1;
            let wobble = if k.is_multiple_of(2) {
                1.0 + jitter
            } else {
                1.0 - jitter
            };
            if !clock.another(Duration::from_secs_f64(nominal * wobble)) || k > 10_000 {
                break;
            }
        }
        (clock.spent(), nominal)
    }

    #[test]
    fn slices_stay_within_the_budget_on_a_synthetic_throughput_model() {
        let budget = DEFAULT_BUDGET;
        // From a fast GPU (1 µs a sample-row) to a slow CPU on a big scene (5 ms a sample-row).
        for rate in [1e-6, 1e-5, 1e-4, 5e-4, 1e-3, 5e-3] {
            let (spent, dispatch) = slice(rate, 0.0, budget, 1280, 720);
            assert!(
                dispatch <= dispatch_target(budget).as_secs_f64() * 1.001,
                "rate {rate}: one dispatch is sized to half the budget ({dispatch} s)"
            );
            assert!(
                spent <= budget,
                "rate {rate}: {spent:?} spent of a {budget:?} budget"
            );
            assert!(
                spent.as_secs_f64() >= budget.as_secs_f64() / 2.0 - 1e-9,
                "rate {rate}: a slice uses at least half its budget ({spent:?})"
            );
        }
        // With ±20% wobble the overshoot is at most the wobble of one dispatch.
        for rate in [1e-5, 1e-4, 1e-3] {
            let (spent, dispatch) = slice(rate, 0.2, budget, 1280, 720);
            assert!(
                spent.as_secs_f64() <= budget.as_secs_f64() + 0.2 * dispatch * 1.001,
                "rate {rate}: {spent:?}"
            );
        }
    }

    #[test]
    fn a_dispatch_longer_than_the_budget_ends_the_slice() {
        let mut clock = SliceClock::new(DEFAULT_BUDGET);
        assert!(!clock.another(Duration::from_millis(30)));
    }
}
