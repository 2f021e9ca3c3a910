//! The measurement shared by every scene and engine: step a world, time each step alone,
//! and let the scene look at the state between steps without being timed.
//!
//! Engines compared with each other run `interleaved`: each in its own thread, but one at a
//! time, taking turns of `TURN_STEPS` steps. This machine's speed drifts by tens of
//! percent over seconds to minutes (other tenants, clocks), so engines run one after the
//! other saw different machines, and their ratios moved by nearly 3× between runs of the
//! same code (0.53 to 1.50); taking turns, every engine sees the same stretches of the
//! machine, and the ratios hold within a few percent.

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// Steps at the start of every run that are simulated but not timed: the first steps
/// allocate the engines' scratch buffers and warm the caches, which says nothing about the
/// steady cost of a step.
pub const WARMUP_STEPS: usize = 10;

/// A warm-up step that ends later than this into the run is timed after all: one-time
/// costs are far below a second, and a run whose steps take seconds cannot spare ten.
pub const WARMUP_WALL: Duration = Duration::from_secs(1);

/// No new step starts once a run has had the machine this long (its own turns' wall
/// time), provided one step has been timed: pe's dense `exact` solver takes seconds per
/// step on the pyramids, and the whole benchmark must stay within a few minutes.
pub const RUN_BUDGET: Duration = Duration::from_secs(40);

/// `fixed_steps`' count, 0 when unset.
static FIXED_STEPS: AtomicUsize = AtomicUsize::new(0);

/// Makes every later run exactly `steps` steps long, whatever its scene plans and
/// whatever the time it takes: for counting instructions under a profiler (callgrind),
/// where the budget would cut runs of two builds at different steps.
pub fn fixed_steps(steps: usize) {
    FIXED_STEPS.store(steps, Ordering::Relaxed);
}

/// Steps an engine runs before handing the machine to the next one in an `interleaved`
/// run. The first step of each turn is not timed: the other engines' turns may have
/// evicted its data from the caches, which a run of its own would not have seen. (Turns
/// of 10, 30 and 100 steps gave every engine the same medians on pyramid20.)
pub const TURN_STEPS: usize = 10;

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
/// world after each step (with the number of steps done so far) to record the metric. It
/// gets the world mutably because boxdd reads a body only through a capability that
/// borrows its world mutably; it must not change the simulation. Inside an `interleaved`
/// run it hands the machine on every `TURN_STEPS` steps.
pub fn measure<W>(
    world: &mut W,
    steps: usize,
    mut step: impl FnMut(&mut W),
    mut observe: impl FnMut(&mut W, usize),
) -> Timing {
    let fixed = FIXED_STEPS.load(Ordering::Relaxed);
    let (steps, budget) = if fixed > 0 {
        (fixed, Duration::MAX)
    } else {
        (steps, RUN_BUDGET)
    };
    let mut clock = OwnClock::start();
    let mut samples = Vec::with_capacity(steps);
    let mut steps_run = 0;
    let mut first_of_turn = false;
    for n in 0..steps {
        if !samples.is_empty() && clock.elapsed() >= budget {
            break;
        }
        let start = Instant::now();
        step(world);
        let elapsed = start.elapsed();
        let warm = n >= WARMUP_STEPS || clock.elapsed() >= WARMUP_WALL;
        if warm && !first_of_turn {
            samples.push(elapsed);
        }
        observe(world, n + 1);
        steps_run = n + 1;
        first_of_turn = false;
        if steps_run % TURN_STEPS == 0 && steps_run < steps {
            clock.pause();
            first_of_turn = Turns::next_turn();
            clock.resume();
        }
    }
    Timing {
        median: median(&mut samples),
        timed_steps: samples.len(),
        steps_run,
        planned: steps,
    }
}

/// The wall time a run has had the machine: the other jobs' turns do not count.
struct OwnClock {
    before: Duration,
    since: Option<Instant>,
}

impl OwnClock {
    fn start() -> Self {
        Self {
            before: Duration::ZERO,
            since: Some(Instant::now()),
        }
    }

    fn pause(&mut self) {
        if let Some(since) = self.since.take() {
            self.before += since.elapsed();
        }
    }

    fn resume(&mut self) {
        self.since.get_or_insert_with(Instant::now);
    }

    fn elapsed(&self) -> Duration {
        self.before + self.since.map_or(Duration::ZERO, |s| s.elapsed())
    }
}

/// Runs `jobs` (each a whole run: build the world, `measure`, report) one at a time, in
/// turns of `TURN_STEPS` steps, and returns their results in order. Each job runs in a
/// thread of its own, which holds the machine from the start of its turn to the end, so
/// building a world never overlaps another's timed steps.
pub fn interleaved<'a, T: Send + 'a>(jobs: Vec<Box<dyn FnOnce() -> T + Send + 'a>>) -> Vec<T> {
    let turns = Arc::new(Turns::new(jobs.len()));
    std::thread::scope(|scope| {
        let handles: Vec<_> = jobs
            .into_iter()
            .enumerate()
            .map(|(me, job)| {
                let turns = Arc::clone(&turns);
                std::thread::Builder::new()
                    // A main thread's stack on Linux, which every run had before it took
                    // turns (a spawned thread gets 2 MB).
                    .stack_size(8 << 20)
                    .spawn_scoped(scope, move || {
                        pin_to_the_benchmark_core();
                        turns.wait_for(me);
                        // Hands the turn on however the job ends, a panic included.
                        let _done = TurnEnds(&turns, me);
                        CURRENT_TURN.with(|t| *t.borrow_mut() = Some((Arc::clone(&turns), me)));
                        job()
                    })
                    .expect("a benchmark thread starts")
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// Keeps the calling thread on one core, the same for every engine's thread: a thread
/// woken for its turn on the other core would find its data in that core's caches.
pub fn pin_to_the_benchmark_core() {
    if let Some(last) = core_affinity::get_core_ids().and_then(|ids| ids.last().copied()) {
        core_affinity::set_for_current(last);
    }
}

thread_local! {
    /// The turns this thread takes part in, and its place among them (`interleaved`).
    static CURRENT_TURN: RefCell<Option<(Arc<Turns>, usize)>> = const { RefCell::new(None) };
}

/// Whose turn it is among the jobs of one `interleaved` run.
struct Turns {
    state: Mutex<TurnState>,
    changed: Condvar,
}

struct TurnState {
    current: usize,
    finished: Vec<bool>,
}

impl Turns {
    fn new(jobs: usize) -> Self {
        Self {
            state: Mutex::new(TurnState {
                current: 0,
                finished: vec![false; jobs],
            }),
            changed: Condvar::new(),
        }
    }

    fn wait_for(&self, me: usize) {
        let state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        let _mine = self
            .changed
            .wait_while(state, |s| s.current != me)
            .unwrap_or_else(PoisonError::into_inner);
    }

    /// Gives the machine to the next job that has not finished, and says whether that is
    /// another job (not `me`).
    fn pass(&self, me: usize, finished: bool) -> bool {
        let mut state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        state.finished[me] |= finished;
        let n = state.finished.len();
        let next = (1..=n).map(|k| (me + k) % n).find(|&j| !state.finished[j]);
        if let Some(next) = next {
            state.current = next;
        }
        drop(state);
        self.changed.notify_all();
        next.is_some_and(|j| j != me)
    }

    /// Inside an `interleaved` run, lets the other jobs take their turns and returns once
    /// this thread has the machine again: true if another job ran meanwhile.
    fn next_turn() -> bool {
        CURRENT_TURN.with(|t| {
            let Some((turns, me)) = t.borrow().clone() else {
                return false;
            };
            let handed_on = turns.pass(me, false);
            turns.wait_for(me);
            handed_on
        })
    }
}

/// Marks its job finished when dropped, handing the machine on.
struct TurnEnds<'a>(&'a Turns, usize);

impl Drop for TurnEnds<'_> {
    fn drop(&mut self) {
        let _ = self.0.pass(self.1, true);
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

/// A peer's own timing of each of its steps (its profile), kept for `stages` to set beside
/// pe's stage clock: nothing is kept until `keep`, then every step's until `take`.
pub struct ProfileLog<T> {
    keeping: AtomicBool,
    profiles: Mutex<Vec<T>>,
}

impl<T> ProfileLog<T> {
    pub const fn new() -> Self {
        Self {
            keeping: AtomicBool::new(false),
            profiles: Mutex::new(Vec::new()),
        }
    }

    /// From now on, every step's profile is kept, until `take`.
    pub fn keep(&self) {
        self.keeping.store(true, Ordering::Relaxed);
    }

    /// Whether profiles are being kept: a step asks before it reads its own.
    pub fn keeping(&self) -> bool {
        self.keeping.load(Ordering::Relaxed)
    }

    pub fn push(&self, profile: T) {
        self.profiles
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(profile);
    }

    /// The profiles of the steps taken since `keep` or the last call, in order.
    pub fn take(&self) -> Vec<T> {
        std::mem::take(&mut self.profiles.lock().unwrap_or_else(PoisonError::into_inner))
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

    #[test]
    fn a_runs_own_clock_stops_while_it_waits() {
        let mut clock = OwnClock::start();
        std::thread::sleep(Duration::from_millis(20));
        clock.pause();
        std::thread::sleep(Duration::from_millis(100));
        let paused = clock.elapsed();
        clock.resume();
        std::thread::sleep(Duration::from_millis(20));
        let resumed = clock.elapsed();
        // Sleeps last at least as long as asked; 100 ms of slack for a busy machine.
        assert!(paused >= Duration::from_millis(20) && paused < Duration::from_millis(100));
        assert!(resumed >= Duration::from_millis(40) && resumed < Duration::from_millis(120));
    }

    /// Jobs take turns of `TURN_STEPS` steps: each step appends its job's number to a
    /// shared log, which must read in blocks of whole turns, round and round, with no two
    /// jobs' steps mixed, and every job's results come back in order.
    #[test]
    fn interleaved_jobs_take_turns_of_whole_blocks() {
        let log = Mutex::new(Vec::new());
        let steps = [25, 10, 32];
        let jobs: Vec<Box<dyn FnOnce() -> usize + Send + '_>> = steps
            .iter()
            .enumerate()
            .map(|(k, &n)| {
                let log = &log;
                Box::new(move || {
                    let mut count = 0_usize;
                    let timing = measure(
                        &mut count,
                        n,
                        |c| *c += 1,
                        |_, _| log.lock().unwrap().push(k),
                    );
                    assert_eq!(timing.steps_run, n);
                    count
                }) as Box<dyn FnOnce() -> usize + Send + '_>
            })
            .collect();
        assert_eq!(interleaved(jobs), vec![25, 10, 32]);
        let runs: Vec<(usize, usize)> = log
            .into_inner()
            .unwrap()
            .chunk_by(|a, b| a == b)
            .map(|c| (c[0], c.len()))
            .collect();
        let expected = vec![
            (0, 10),
            (1, 10),
            (2, 10), // the second job finishes with its first turn
            (0, 10),
            (2, 10),
            (0, 5),
            (2, 12), // the last turn of each: what is left
        ];
        assert_eq!(runs, expected);
    }
}
