//! Cycles spent in each stage of a world's last step (`World::profile`), for profiling.
//! With the feature `stage-clock` each stage is timed by the processor's time-stamp
//! counter (`rdtsc` on x86-64, nanoseconds elsewhere); without it every function here is
//! empty and compiles away, and every profile reads zero.
//!
//! Why not wall-clock medians: on a shared machine those drift by tens of percent, while
//! the fewest cycles a stage took over many steps of one run move by 1–2%, which is what a
//! change of a few percent needs (docs/bench/profile.md, "Cycles per stage").

/// The stages a step is timed in. The soft step's (preparing and its parts, warm start,
/// solve, storing) are timed under `ContactSolver::Soft` and `Auto` only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// A whole `World::step`.
    Step,
    /// Bounds and candidate pairs (`World::find_candidate_pairs`).
    BroadPhase,
    /// A manifold for each candidate pair, reused or by SAT.
    NarrowPhase,
    /// Idle manifolds dropped, and the contacts built from the rest.
    Contacts,
    /// The soft step's islands, points, plan and lanes.
    Preparing,
    /// The soft step's warm starts, all substeps.
    WarmStart,
    /// The soft step's passes with and without bias, positions integrated between them.
    Solve,
    /// The soft step's results written back: velocities and poses to the bodies, impulses
    /// to the contacts and the warm-start memory.
    Storing,
    /// Within `Preparing`: the bodies copied in and the contacts grouped into islands (on
    /// a pile at rest, only the bodies' freedom checked: the last grouping is taken, and
    /// the contacts' bodies are checked as their points are built).
    PreparingIslands,
    /// Within `Preparing`: the contacts' points built, and the lanes of the kept plan, or
    /// of a plan made before them, filled from them (`SoftStepSolver::build_points`,
    /// twice if the plan changed after all or the contacts' grouping taken unchecked was
    /// not theirs).
    PreparingPoints,
    /// Within `Preparing`: the small islands' LCPs set up, and the plan read and, if it
    /// changed, made again (colours and batches); after a step whose plan changed, read
    /// off the contacts and made before the points (`plan_from_contacts`).
    PreparingPlan,
    /// Continuous collision after the step: fast bodies that passed into a static one
    /// moved back to the impact (`World::stop_at_impact`), under every solver.
    Continuous,
}

impl Stage {
    pub const ALL: [Stage; 12] = [
        Stage::Step,
        Stage::BroadPhase,
        Stage::NarrowPhase,
        Stage::Contacts,
        Stage::Preparing,
        Stage::WarmStart,
        Stage::Solve,
        Stage::Storing,
        Stage::PreparingIslands,
        Stage::PreparingPoints,
        Stage::PreparingPlan,
        Stage::Continuous,
    ];

    /// The stage this one is a part of, if any (its cycles are counted in both). Only the
    /// test of the counts below reads it.
    #[cfg(all(test, feature = "stage-clock"))]
    fn within(self) -> Option<Stage> {
        match self {
            Stage::PreparingIslands | Stage::PreparingPoints | Stage::PreparingPlan => {
                Some(Stage::Preparing)
            }
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Stage::Step => "whole step",
            Stage::BroadPhase => "broad phase",
            Stage::NarrowPhase => "narrow phase",
            Stage::Contacts => "contacts",
            Stage::Preparing => "preparing",
            Stage::WarmStart => "warm start",
            Stage::Solve => "solve",
            Stage::Storing => "storing",
            Stage::PreparingIslands => "preparing: bodies, islands",
            Stage::PreparingPoints => "preparing: points",
            Stage::PreparingPlan => "preparing: LCPs, plan",
            Stage::Continuous => "continuous collision",
        }
    }
}

/// When a stage began (`mark`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mark(#[cfg(feature = "stage-clock")] u64);

#[cfg(feature = "stage-clock")]
mod counting {
    #[inline(always)]
    pub(super) fn now() -> u64 {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: `rdtsc` has no preconditions on x86-64.
            unsafe { std::arch::x86_64::_rdtsc() }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            use std::sync::OnceLock;
            use std::time::Instant;
            static START: OnceLock<Instant> = OnceLock::new();
            START.get_or_init(Instant::now).elapsed().as_nanos() as u64
        }
    }
}

/// Now, as the start of a stage.
#[inline(always)]
pub(crate) fn mark() -> Mark {
    #[cfg(feature = "stage-clock")]
    {
        Mark(counting::now())
    }
    #[cfg(not(feature = "stage-clock"))]
    {
        Mark()
    }
}

/// The clock's ticks each stage of a step took, by `Stage::ALL`'s order: read the last
/// step's with `World::profile`, turned into time by `ticks_per_microsecond`. All zero
/// without the feature `stage-clock`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepProfile {
    pub ticks: [u64; Stage::ALL.len()],
}

impl StepProfile {
    /// Adds the time since `since` to `stage`'s count.
    #[inline(always)]
    pub(crate) fn record(&mut self, stage: Stage, since: Mark) {
        #[cfg(feature = "stage-clock")]
        {
            self.ticks[stage as usize] += counting::now().wrapping_sub(since.0);
        }
        #[cfg(not(feature = "stage-clock"))]
        let _ = (stage, since);
    }

    /// `other`'s counts added to these, and `other` set to zero: a solver's own profile
    /// handed to its world's.
    #[inline(always)]
    pub(crate) fn take_from(&mut self, other: &mut StepProfile) {
        #[cfg(feature = "stage-clock")]
        {
            for (mine, theirs) in self.ticks.iter_mut().zip(&mut other.ticks) {
                *mine += std::mem::take(theirs);
            }
        }
        #[cfg(not(feature = "stage-clock"))]
        let _ = other;
    }
}

/// How many of the clock's ticks pass in a microsecond (the time-stamp counter's rate on
/// x86-64; about 1,000 elsewhere, where it counts nanoseconds), measured against the wall
/// clock over a tenth of a second: to turn a `StepProfile`'s ticks into time. `None` without
/// the feature.
pub fn ticks_per_microsecond() -> Option<f64> {
    #[cfg(feature = "stage-clock")]
    {
        use std::time::{Duration, Instant};
        let (started, first) = (Instant::now(), counting::now());
        while started.elapsed() < Duration::from_millis(100) {}
        let ticks = counting::now().wrapping_sub(first);
        Some(ticks as f64 / started.elapsed().as_secs_f64() / 1e6)
    }
    #[cfg(not(feature = "stage-clock"))]
    {
        None
    }
}

/// Run by CI with the feature (`cargo test -p pe --features stage-clock --lib stage_clock`).
#[cfg(all(test, feature = "stage-clock"))]
mod tests {
    use super::*;
    use crate::{BodyDef, ContactSolver, ConvexPolygon, Vec2, World};

    /// A box resting on a floor under the soft step, three steps: every stage of each
    /// step took time, the stages, which lie inside the step, add up to less, and the
    /// parts of a stage to no more than it; a world's profile is its own.
    #[test]
    fn each_step_counts_its_stages() {
        let mut w = World::new(Vec2::new(0.0, 10.0));
        w.settings.contact_solver = ContactSolver::Soft;
        let floor = ConvexPolygon::rectangle(10.0, 1.0).unwrap();
        w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 1.0), 0.0))
            .unwrap();
        let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        w.add_body(BodyDef::new(square, 1.0).at(Vec2::new(0.0, 0.0), 0.0))
            .unwrap();
        assert_eq!(*w.profile(), StepProfile::default(), "no step yet");
        let mut other = w.clone();
        other.settings.contact_solver = ContactSolver::Exact;
        for _ in 0..3 {
            w.step(1.0 / 60.0);
            other.step(1.0 / 60.0);
            let counts = w.profile().ticks;
            assert!(counts.iter().all(|&c| c > 0), "{counts:?}");
            let parts_of = |whole: Option<Stage>| -> u64 {
                let parts = Stage::ALL[1..].iter().filter(|s| s.within() == whole);
                parts.map(|&s| counts[s as usize]).sum()
            };
            assert!(parts_of(None) < counts[Stage::Step as usize], "{counts:?}");
            let preparing = counts[Stage::Preparing as usize];
            assert!(parts_of(Some(Stage::Preparing)) <= preparing, "{counts:?}");
            // The exact step has no soft stages: none of the soft world's reached it.
            let exact = other.profile().ticks;
            assert_eq!(exact[Stage::Preparing as usize], 0, "{exact:?}");
            assert!(exact[Stage::Step as usize] > 0, "{exact:?}");
        }
    }

    /// The clock's rate is a processor's: between 0.1 and 10 GHz of time-stamp ticks (or
    /// nanoseconds, 1 GHz).
    #[test]
    fn ticks_per_microsecond_is_a_clock_rate() {
        let rate = ticks_per_microsecond().expect("the feature is on");
        assert!((100.0..10_000.0).contains(&rate), "{rate}");
    }
}
