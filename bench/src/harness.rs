//! The measurement shared by every scene and engine: step a world, time each step alone,
//! and let the scene look at the state between steps without being timed.

use std::time::{Duration, Instant};

/// Steps at the start of every run that are simulated but not timed: the first steps
/// allocate the engines' scratch buffers and warm the caches, which says nothing about the
/// steady cost of a step.
pub const WARMUP_STEPS: usize = 10;

/// A warm-up step that ends later than this into the run is timed after all: one-time
/// costs are far below a second, and a run whose steps take seconds cannot spare ten.
pub const WARMUP_WALL: Duration = Duration::from_secs(1);

/// No new step starts once a run has taken this long (wall time), provided one step has
/// been timed: pe's dense `exact` solver takes seconds per step on the pyramids, and the
/// whole benchmark must stay within a few minutes.
pub const RUN_BUDGET: Duration = Duration::from_secs(40);

/// The cost of one run's steps.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    /// Median wall time of one timed step.
    pub median: Duration,
    /// How many steps were timed (the steps run minus the warm-up).
    pub timed_steps: usize,
    /// How many steps were simulated; fewer than `planned` if the budget ran out.
    pub steps_run: usize,
    pub planned: usize,
}

impl Timing {
    pub fn cut_short(&self) -> bool {
        self.steps_run < self.planned
    }
}

/// Runs up to `steps` steps of `world`. Only `step` is inside the clock; `observe` sees the
/// world after each step (with the number of steps done so far) to record the metric.
pub fn measure<W>(
    world: &mut W,
    steps: usize,
    mut step: impl FnMut(&mut W),
    mut observe: impl FnMut(&W, usize),
) -> Timing {
    let run_start = Instant::now();
    let mut samples = Vec::with_capacity(steps);
    let mut steps_run = 0;
    for n in 0..steps {
        if !samples.is_empty() && run_start.elapsed() >= RUN_BUDGET {
            break;
        }
        let start = Instant::now();
        step(world);
        let elapsed = start.elapsed();
        if n >= WARMUP_STEPS || run_start.elapsed() >= WARMUP_WALL {
            samples.push(elapsed);
        }
        observe(world, n + 1);
        steps_run = n + 1;
    }
    Timing {
        median: median(&mut samples),
        timed_steps: samples.len(),
        steps_run,
        planned: steps,
    }
}

/// The median, rather than the mean, so that a step interrupted by the OS (the machine may
/// be busy with other builds) does not move the figure. With an even count it is the
/// mean of the two middle samples.
fn median(samples: &mut [Duration]) -> Duration {
    if samples.is_empty() {
        return Duration::ZERO;
    }
    samples.sort_unstable();
    let mid = samples.len() / 2;
    if samples.len() % 2 == 1 {
        samples[mid]
    } else {
        (samples[mid - 1] + samples[mid]) / 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        let ms = Duration::from_millis;
        assert_eq!(median(&mut [ms(5), ms(1), ms(3)]), ms(3));
        assert_eq!(median(&mut [ms(4), ms(1), ms(2), ms(100)]), ms(3));
        assert_eq!(median(&mut []), Duration::ZERO);
    }
}
