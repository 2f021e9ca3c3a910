//! The iterative "soft step" solver for big islands, after the design of Box2D v3:
//! substeps with soft contact constraints (a stiffness in Hz with damping), a relax pass
//! without bias, restitution once at the end above a speed threshold, warm starting from
//! the last step's impulses, speculative contacts, and contact anchors fixed for the step.
//!
//! Each substep: integrate velocities, warm start / solve with bias, integrate positions,
//! relax without bias. Contacts are found once per step; separations follow the bodies
//! through the substeps by their anchors.
//!
//! This module holds the solver and its stage list (`SoftStepSolver::step`); each stage
//! is in the module named for it, and the types the stages share in the module named
//! for each: the bodies (`bodies`), the contact points and pins (`constraints`),
//! the tuning (`settings`).

use super::SolverBody;
use super::contact::{Contact, ContactMemory};
use super::island::IslandGrouping;
use super::joint::JointConstraint;
use super::report::{IslandReport, StepStats};
use crate::math::Vec2;
use crate::stage_clock::{self, Stage, StepProfile};
use batch::{LanePath, PassPlan, PlanInput};
use bodies::LoadedBodies;
use constraints::PointConstraint;
use settings::{MAX_HERTZ_PER_SUBSTEP_RATE, SoftSettings, Softness, contact_pass};

/// `$entry`, running `$inline` compiled with FMA where the processor has it (the copy
/// `$fma`, with the feature enabled) and as built otherwise: `f64::mul_add` is then one
/// instruction instead of a library call, with the same bits either way. (The feature must
/// be on the function itself: a closure handed to a helper is compiled without it.)
macro_rules! with_fma_where_present {
    (
        $(#[$doc:meta])*
        $vis:vis fn $entry:ident, $fma:ident => $inline:ident(
            &mut self $(, $arg:ident: $ty:ty)* $(,)?
        ) $(-> $ret:ty)?;
    ) => {
        $(#[$doc])*
        $vis fn $entry(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $crate::solver::soft::batch::LanePath::has_fma() {
                // SAFETY: the processor has FMA, checked just above.
                return unsafe { self.$fma($($arg),*) };
            }
            self.$inline($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "fma")]
        unsafe fn $fma(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            self.$inline($($arg),*)
        }
    };
}

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod batch;
mod bodies;
mod constraints;
mod contact_lcp;
mod contacts;
mod joints;
mod lanes;
mod passes;
mod pins;
mod points;
mod prepare;
mod restitution;
pub(crate) mod settings;
mod store;

use contact_lcp::ContactLcp;
use joints::{JointMemory, SoftPins};
use passes::{integrate_position, integrate_velocity};

/// The SIMD instructions this processor solves the soft step's batches with: "AVX-512"
/// (eight f64 lanes a register), "AVX2" (four, a row of eight in two) or "portable"
/// (plain arrays). The results are the same bits on each; the speed is not, so
/// benchmarks name it beside the machine.
pub fn lane_path_name() -> &'static str {
    match LanePath::best() {
        LanePath::Portable => "portable",
        #[cfg(target_arch = "x86_64")]
        LanePath::Avx2 => "AVX2",
        #[cfg(target_arch = "x86_64")]
        LanePath::Avx512 => "AVX-512",
    }
}

/// Warm-start memory and buffers, kept between steps.
#[derive(Debug, Clone, Default)]
pub(crate) struct SoftStepSolver {
    /// The bodies as the step reads them, and which of them move.
    loaded: LoadedBodies,
    /// The pins and their motors as the step solves them.
    pins: SoftPins,
    points: Vec<PointConstraint>,
    /// Last step's contact impulses, recalled as this step's points are built.
    memory: ContactMemory,
    /// Each contact's impulses from the last step (`ContactMemory::recall`).
    recalled: Vec<(f64, f64)>,
    /// Each contact's impulses from this step, gathered from the lanes and the points
    /// before they go into the contacts in one sweep (`store`).
    impulses: Vec<(f64, f64)>,
    /// `points` index ranges, one per island of contacts.
    contact_islands: Vec<(usize, usize)>,
    /// The contacts' islands, kept while the contacts stay between the same bodies.
    contact_grouping: IslandGrouping,
    contact_lcp: ContactLcp,
    /// The passes' order over the manifolds outside the LCP islands, and what it is made
    /// from: each manifold's entry, noted as its points are built.
    plan: PassPlan,
    plan_inputs: Vec<PlanInput>,
    /// The entries a plan made before the points were built was made from
    /// (`plan_from_contacts`).
    planned_inputs: Vec<PlanInput>,
    /// Whether any point has restitution: a pile has none, and skips the pass over its
    /// points that looks for bounces.
    may_bounce: bool,
    /// Substeps taken since the solver was made: they choose each substep's
    /// `SweepOrder`.
    substeps_taken: u64,
    /// The warm-start memories and the substep count as they were before this step's
    /// first try, for a step taken again: a try thrown away must not warm-start the next
    /// (its impulses, put back on velocities the impact pass has since bounced, add
    /// energy).
    before_try: Option<(ContactMemory, JointMemory, u64)>,
    /// How each island was solved in the last step.
    pub reports: Vec<IslandReport>,
    /// A crate-private check, off in use: every point written, as if no manifold went
    /// straight into its lane, so that a test can show the lanes give the same bits.
    pub(crate) write_every_point: bool,
    /// The soft step's part of the world's `StepStats`.
    pub(crate) stats: StepStats,
    /// The soft step's stages of this world step, handed to the world's profile.
    pub(crate) profile: StepProfile,
}

impl SoftStepSolver {
    /// Keeps what the next `step` starts from, for `take_again`.
    pub(crate) fn keep_for_another_try(&mut self) {
        let memories = (self.memory.clone(), self.pins.joint_memory.clone());
        self.before_try = Some((memories.0, memories.1, self.substeps_taken));
    }

    /// Back to what the step kept by `keep_for_another_try` started from.
    pub(crate) fn take_again(&mut self) {
        if let Some((memory, joint_memory, substeps)) = &self.before_try {
            self.memory.clone_from(memory);
            self.pins.joint_memory.clone_from(joint_memory);
            self.substeps_taken = *substeps;
        }
    }
}

/// The direction of a substep's two sweeps (biased, then relaxed) over the colours of the
/// big islands (the small ones keep the points' order: a stack's bottom first, which
/// holds the sweep's stacks a little closer to their rest).
///
/// Gauss–Seidel leaves the constraints it solved last best satisfied: swept always
/// first to last, the colours favour some constraints over others at every step. Two
/// substeps forwards, then two backwards, cancel that to first order (symmetric
/// Gauss–Seidel), better than flipping every substep or only the relax pass; with the
/// colours scattered (`batch::PassPlan::colour_in_scattered_order`) a tall pyramid's top
/// sways less than Box2D v3's (docs/bench/profile.md, "Sweeping the colours both ways").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SweepOrder {
    Forwards,
    Backwards,
}

impl SweepOrder {
    /// Counted across steps, so that a step of one or two substeps alternates too.
    fn of_substep(substep: u64) -> Self {
        // Bit 1 of the count: two substeps one way, two the other.
        if substep & 2 == 0 {
            Self::Forwards
        } else {
            Self::Backwards
        }
    }
}

impl SoftStepSolver {
    /// For the next step only: of the bodies it is handed, only those in `slots`
    /// (increasing) may differ from those the last step was handed, and every body that
    /// moves is among them; the rest are fixed, and at rest or as they were. The step
    /// then loads only those, and the fixed bodies with a velocity.
    pub(crate) fn bodies_changed_only(&mut self, slots: &[u32]) {
        self.loaded.changed_only(slots);
    }

    /// How many times the pin islands' matrices were factored (`StepStats`).
    pub(crate) fn pin_factorisations(&self) -> u64 {
        self.pins.block.factored
    }

    /// Advances `bodies` by `dt`: velocities from `accelerations` (linear, angular per
    /// body), constraints from `contacts` and `joints`, positions and angles integrated.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn step(
        &mut self,
        settings: &SoftSettings,
        bodies: &mut [SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
        dt: f64,
        bounce_below: f64,
    ) {
        let h = dt / settings.substeps as f64;
        let contact_soft = Softness::new(
            settings.contact_hertz.min(MAX_HERTZ_PER_SUBSTEP_RATE / h),
            settings.contact_damping_ratio,
            h,
        );
        let joint_soft = Softness::new(
            settings.joint_hertz.min(MAX_HERTZ_PER_SUBSTEP_RATE / h),
            settings.joint_damping_ratio,
            h,
        );
        let started = stage_clock::mark();
        self.prepare(bodies, accelerations, contacts, joints, dt);
        self.profile.record(Stage::Preparing, started);
        let sweep_order = |substep: u64| {
            if settings.alternating_sweeps {
                SweepOrder::of_substep(substep)
            } else {
                SweepOrder::Forwards
            }
        };
        // Chunks of islands first, each through every substep while its batches stay in
        // the cache (`PassPlan::assign_chunks`), then the rest substep by substep.
        let pass = |use_bias| contact_pass(h, &contact_soft, settings, use_bias);
        for k in 0..self.chunks_apart() {
            let items = self.plan.chunk(k).0;
            for substep in 0..settings.substeps {
                let order = sweep_order(self.substeps_taken.wrapping_add(substep as u64));
                for &i in self.plan.chunk(k).1 {
                    let i = i as usize;
                    integrate_velocity(&mut self.loaded.bodies[i], accelerations[i], h);
                }
                let started = stage_clock::mark();
                // The first substep's passes read the chunk's batches from farther out and
                // ask for each next one (`BatchesAhead`); the later ones find them in the
                // level-2 cache, where asking only costs.
                let ask = substep == 0;
                self.warm_start_items(items.clone(), ask);
                self.profile.record(Stage::WarmStart, started);
                let started = stage_clock::mark();
                self.sweep_items(items.clone(), &pass(true), order, ask);
                for &i in self.plan.chunk(k).1 {
                    integrate_position(&mut self.loaded.bodies[i as usize], h);
                }
                self.sweep_items(items.clone(), &pass(false), order, false);
                self.profile.record(Stage::Solve, started);
            }
        }
        for _ in 0..settings.substeps {
            let order = sweep_order(self.substeps_taken);
            self.substeps_taken = self.substeps_taken.wrapping_add(1);
            self.integrate_velocities(accelerations, h);
            let started = stage_clock::mark();
            self.warm_start();
            self.profile.record(Stage::WarmStart, started);
            let started = stage_clock::mark();
            self.solve(h, &contact_soft, &joint_soft, settings, true, order);
            self.integrate_positions(h);
            self.solve(h, &contact_soft, &joint_soft, settings, false, order);
            self.profile.record(Stage::Solve, started);
            // Warm starting re-applies the accumulated impulse in every substep, so the
            // step's total is the sum of the substeps' accumulated values.
            for &k in &self.pins.motor_joints {
                let j = &mut self.pins.joints[k as usize];
                j.motor_step_total += j.motor_impulse;
            }
        }
        if self.may_bounce {
            // Restitution works on the points: they take the batches' impulses first.
            self.plan.scatter(&mut self.points);
            self.restitution(bounce_below);
        }
        self.pins.pin_plan.scatter(&mut self.pins.joints);
        let started = stage_clock::mark();
        self.store(bodies, contacts, joints, settings.substeps);
        self.profile.record(Stage::Storing, started);
        self.report();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::BodyHandle;
    use crate::collide::FeatureId;

    /// Boxes in columns on a fixed floor (the last body), and each box's two points on
    /// the body below it: the columns' heights, their boxes numbered from the first
    /// column's bottom up.
    fn columns(heights: &[usize]) -> (Vec<SolverBody>, Vec<Contact>) {
        let count: usize = heights.iter().sum();
        let floor = count as u32;
        let (mut bodies, mut contacts) = (vec![], vec![]);
        for (column, &height) in heights.iter().enumerate() {
            let x = 3.0 * column as f64;
            for row in 0..height {
                let below = if row == 0 {
                    floor
                } else {
                    bodies.len() as u32 - 1
                };
                let y = -(row as f64);
                for (dx, id) in [(-0.5, 1), (0.5, 2)] {
                    contacts.push(Contact {
                        body_a: BodyHandle(bodies.len() as u32),
                        body_b: BodyHandle(below),
                        point: Vec2::new(x + dx, y),
                        normal: Vec2::new(0.0, -1.0),
                        depth: 0.004,
                        id: FeatureId(id),
                        restitution: 0.0,
                        friction: 0.6,
                        approach_velocity: 0.0,
                        normal_velocity: 0.0,
                        normal_impulse: 0.0,
                        tangent_impulse: 0.0,
                    });
                }
                bodies.push(SolverBody {
                    position: Vec2::new(x, y - 0.5),
                    inv_mass: 1.0,
                    inv_inertia: 6.0,
                    ..SolverBody::default()
                });
            }
        }
        bodies.push(SolverBody::default());
        (bodies, contacts)
    }

    /// One step of 1/60 s of `bodies` under gravity (10 m/s² down every body) with a copy
    /// of `contacts`, which it returns with the step's impulses.
    fn step_falling(
        solver: &mut SoftStepSolver,
        bodies: &mut [SolverBody],
        contacts: &[Contact],
    ) -> Vec<Contact> {
        let accelerations = vec![(Vec2::new(0.0, 10.0), 0.0); bodies.len()];
        let settings = SoftSettings::for_length_scale(1.0);
        let mut contacts = contacts.to_vec();
        let mut joints = [];
        let h = 1.0 / 60.0;
        solver.step(
            &settings,
            bodies,
            &accelerations,
            &mut contacts,
            &mut joints,
            h,
            1.0,
        );
        contacts
    }

    /// Every body's velocity and pose and every contact's impulses, bit for bit.
    pub(super) fn state_bits(bodies: &[SolverBody], contacts: &[Contact]) -> Vec<u64> {
        let states = bodies.iter().flat_map(|b| {
            let (v, p) = (b.velocity, b.position);
            [v.x, v.y, b.angular_velocity, p.x, p.y, b.angle]
        });
        let impulses = contacts
            .iter()
            .flat_map(|c| [c.normal_impulse, c.tangent_impulse]);
        states.chain(impulses).map(f64::to_bits).collect()
    }

    /// A solver stepped `steps` times (`step_falling`) beside one that writes every point
    /// and plans from them, with the two contact lists in turn; both must leave the
    /// bodies and the impulses the same, bit for bit, after every step. Returns the two.
    fn step_beside_one_writing_every_point(
        bodies: Vec<SolverBody>,
        contacts_in_turn: [&[Contact]; 2],
        steps: usize,
    ) -> (SoftStepSolver, SoftStepSolver) {
        let mut solver = SoftStepSolver::default();
        let mut writing = SoftStepSolver {
            write_every_point: true,
            ..SoftStepSolver::default()
        };
        let (mut bodies_solver, mut bodies_writing) = (bodies.clone(), bodies);
        for k in 0..steps {
            let contacts = contacts_in_turn[k % 2];
            let contacts_solver = step_falling(&mut solver, &mut bodies_solver, contacts);
            let contacts_writing = step_falling(&mut writing, &mut bodies_writing, contacts);
            assert_eq!(
                state_bits(&bodies_solver, &contacts_solver),
                state_bits(&bodies_writing, &contacts_writing),
                "step {k}"
            );
        }
        (solver, writing)
    }

    /// After a step whose plan changed, the next plan is made from the contacts before the
    /// points are built, and each manifold goes straight into its lane. That must solve
    /// exactly as a solver that writes every point first and plans from them, through
    /// steps whose coloured island changes every time, with a manifold whose two points
    /// lie on one spot (its 2 × 2 block singular: two one-point manifolds) in it.
    #[test]
    fn a_plan_made_before_the_points_solves_as_one_made_after() {
        let (bodies, mut whole) = columns(&[30, 10, 1]);
        // Box 12's two points (contacts 24 and 25) on one spot.
        whole[25].point = whole[24].point;
        // Without the tall column's top box's contacts: the coloured island's plan
        // changes at every step.
        let mut topless = whole.clone();
        topless.drain(58..60);
        let (first, after) = step_beside_one_writing_every_point(bodies, [&whole, &topless], 8);
        // Every step: each changes the plan (the first makes one).
        assert_eq!(first.stats.soft_steps_planned_first, 8);
        assert_eq!(after.stats.soft_steps_planned_first, 0);
        // The singular manifold went as two one-point manifolds.
        let around = first.plan_inputs.iter().map(|p| p.first_and_count());
        let around: Vec<_> = around.filter(|&(k, _)| (22..28).contains(&k)).collect();
        assert_eq!(around, [(22, 2), (24, 1), (25, 1), (26, 2)]);
    }

    /// A step told which bodies changed (`bodies_changed_only`) loads only those and the
    /// fixed bodies with a velocity, and must move every body exactly as a step that loads
    /// every one: three columns on a floor, through steps where only the boxes change,
    /// then with the floor given a velocity up and along (every body loaded that step,
    /// and after it the floor again every step, as a fixed body in motion).
    #[test]
    fn a_step_loading_only_the_changed_bodies_moves_them_as_one_loading_all() {
        let (bodies, contacts) = columns(&[5, 3, 1]);
        let floor = bodies.len() - 1;
        let boxes: Vec<u32> = (0..floor as u32).collect();
        let accelerations = vec![(Vec2::new(0.0, 10.0), 0.0); bodies.len()];
        let settings = SoftSettings::for_length_scale(1.0);
        let (mut all, mut some) = (SoftStepSolver::default(), SoftStepSolver::default());
        let (mut bodies_all, mut bodies_some) = (bodies.clone(), bodies);
        let mut steps_loading_some = 0;
        for k in 0..16 {
            if k == 8 {
                bodies_all[floor].velocity = Vec2::new(0.3, -0.1);
                bodies_some[floor].velocity = Vec2::new(0.3, -0.1);
            } else if k > 0 {
                some.bodies_changed_only(&boxes);
                steps_loading_some += 1;
            }
            let step = |solver: &mut SoftStepSolver, bodies: &mut [SolverBody]| {
                let mut contacts = contacts.clone();
                let a = &accelerations;
                solver.step(
                    &settings,
                    bodies,
                    a,
                    &mut contacts,
                    &mut [],
                    1.0 / 60.0,
                    1.0,
                );
                contacts
            };
            let contacts_all = step(&mut all, &mut bodies_all);
            let contacts_some = step(&mut some, &mut bodies_some);
            assert_eq!(
                state_bits(&bodies_all, &contacts_all),
                state_bits(&bodies_some, &contacts_some),
                "step {k}"
            );
            assert_eq!(some.loaded.a_fixed_body_moves, k >= 8, "step {k}");
        }
        assert_eq!(steps_loading_some, 14);
    }

    /// Coloured islands solved in chunks, each through every substep before the next
    /// (`PassPlan::assign_chunks`), must move every body exactly as the whole step solved
    /// substep by substep: the islands share no moving body. Four coloured columns, one
    /// of them with two boxes pinned together (its island stays with the rest, whose pins
    /// are solved with their contacts), a taller one (too big for a chunk: with the rest
    /// too), a column of two boxes and a box alone (6 points together: solved one
    /// manifold at a time), through steps whose plan changes and steps that keep it; then
    /// with the floor moving (a fixed body with a velocity, whose motion each island must
    /// see substep by substep: the chunks are then solved with the rest).
    #[test]
    fn islands_solved_in_chunks_move_as_when_solved_together() {
        let (bodies, whole) = columns(&[30, 30, 30, 30, 40, 2, 1]);
        // Without the first column's top box's contacts: the plan changes every other step.
        let mut topless = whole.clone();
        topless.drain(58..60);
        // Boxes 95 and 96, in the fourth column, pinned at the corner they share.
        let mut joints = [JointConstraint {
            joint: 0,
            body_a: 95,
            body_b: 96,
            local_anchor_a: Vec2::new(0.5, -0.5),
            local_anchor_b: Vec2::new(0.5, 0.5),
            motor: None,
            limits: None,
            reference_angle: 0.0,
            limit_impulse: (0.0, 0.0),
            gap_target: Vec2::zeros(),
            impulse: Vec2::zeros(),
        }];
        let accelerations = vec![(Vec2::new(0.0, 10.0), 0.0); bodies.len()];
        let settings = SoftSettings::for_length_scale(1.0);
        let mut chunked = SoftStepSolver::default();
        // Every coloured island in a chunk of its own: a chunk holds one column's batches.
        let column = 30 * std::mem::size_of::<batch::ManifoldBatch<2>>() / lanes::LANES;
        chunked.plan.chunk_limits = Some((0, column));
        let mut together = SoftStepSolver::default();
        together.plan.chunk_limits = Some((usize::MAX, 0));
        let floor = bodies.len() - 1;
        let (mut bodies_chunked, mut bodies_together) = (bodies.clone(), bodies);
        for k in 0..12 {
            let contacts = [&whole, &topless][k / 2 % 2];
            let floor_moves = k >= 8;
            if floor_moves {
                bodies_chunked[floor].velocity = Vec2::new(0.3, 0.2);
                bodies_together[floor].velocity = Vec2::new(0.3, 0.2);
            }
            let mut step = |solver: &mut SoftStepSolver, bodies: &mut [SolverBody]| {
                let mut contacts = contacts.to_vec();
                let h = 1.0 / 60.0;
                let a = &accelerations;
                solver.step(&settings, bodies, a, &mut contacts, &mut joints, h, 1.0);
                contacts
            };
            let contacts_chunked = step(&mut chunked, &mut bodies_chunked);
            let contacts_together = step(&mut together, &mut bodies_together);
            assert_eq!(
                state_bits(&bodies_chunked, &contacts_chunked),
                state_bits(&bodies_together, &contacts_together),
                "step {k}"
            );
            // The three columns without a pin, a chunk each, solved apart while the floor
            // stands; none for the other solver.
            assert_eq!(
                (chunked.plan.chunk_count(), together.plan.chunk_count()),
                (3, 0)
            );
            let apart = if floor_moves { 0 } else { 3 };
            assert_eq!(
                (chunked.chunks_apart(), together.chunks_apart()),
                (apart, 0)
            );
        }
        // The pinned island's boxes, the tall column's, the small column's and the box
        // alone (the last box before the floor) were moved by the rest's passes, the other
        // columns' by the chunks'.
        let in_chunk = |boxes: [usize; 2]| boxes.map(|i| chunked.plan.in_chunk(i));
        assert_eq!(in_chunk([0, 31]), [true, true]);
        assert_eq!(in_chunk([95, 96]), [false, false]);
        assert_eq!(in_chunk([120, 159]), [false, false]);
        assert_eq!(in_chunk([160, floor - 1]), [false, false]);
    }

    /// A step with a point that may bounce reads every point for its restitution, so it
    /// plans after building them all, as before, even where only a manifold's second
    /// point may bounce.
    #[test]
    fn a_point_that_may_bounce_keeps_the_plan_after_the_points() {
        let (bodies, mut whole) = columns(&[30]);
        // Box 20's second point (contact 41) bouncy, its first not.
        whole[41].restitution = 0.5;
        whole[41].approach_velocity = -2.0;
        let mut topless = whole.clone();
        topless.drain(58..60);
        let (solver, _) = step_beside_one_writing_every_point(bodies, [&whole, &topless], 6);
        assert_eq!(solver.stats.soft_steps_planned_first, 0);
    }

    /// A step whose contacts join other bodies than the last step's, as many of them and
    /// with every body as free as before, takes the last grouping unchecked and must find
    /// that out as it builds the points (some of them into the kept plan's lanes): it must
    /// move the bodies exactly as a solver that grouped them afresh, and end with their
    /// grouping.
    #[test]
    fn contacts_on_other_bodies_are_grouped_again() {
        // A column of 30 boxes (60 points), one of 10 (20 points), both coloured into
        // batches, and a box alone (2 points, solved one manifold at a time).
        let (bodies, standing) = columns(&[30, 10, 1]);
        // Box 35 on box 20 instead of box 34: the two columns' islands change.
        let mut moved = standing.clone();
        for c in &mut moved[70..72] {
            c.body_b = BodyHandle(20);
        }
        // The box alone on box 39 instead of the floor: the last island (in the grouping
        // taken unchecked) joins another.
        let mut last_moved = standing.clone();
        for c in &mut last_moved[80..82] {
            c.body_b = BodyHandle(39);
        }
        // Only a manifold's second point on another body (box 8 instead of box 9), in
        // the same island.
        let mut second_moved = standing.clone();
        second_moved[21].body_b = BodyHandle(8);
        // The first steps' contacts and the last step's, whether the last step's grouping
        // is the first steps' kept unchecked, and whether it is another.
        let cases = [
            (&standing, &standing, true, false),
            (&standing, &moved, false, true),
            (&standing, &last_moved, false, true),
            (&standing, &second_moved, false, false), // the same islands
            (&second_moved, &standing, false, false), // the second point joins the first
        ];
        for (first, last, kept, changes) in cases {
            let (mut unchecked, mut fresh) = (SoftStepSolver::default(), SoftStepSolver::default());
            let (mut bodies_unchecked, mut bodies_fresh) = (bodies.clone(), bodies.clone());
            // Steps enough for the plan to be kept, and its lanes filled as the points
            // are built.
            for _ in 0..4 {
                step_falling(&mut unchecked, &mut bodies_unchecked, first);
                step_falling(&mut fresh, &mut bodies_fresh, first);
            }
            assert!(
                unchecked.stats.soft_steps_skipping_points > 0,
                "no lane was filled unwritten"
            );
            let first_grouping = unchecked.contact_grouping.grouped().to_vec();
            fresh.contact_grouping = IslandGrouping::default();
            let contacts_unchecked = step_falling(&mut unchecked, &mut bodies_unchecked, last);
            let contacts_fresh = step_falling(&mut fresh, &mut bodies_fresh, last);
            assert_eq!(
                state_bits(&bodies_unchecked, &contacts_unchecked),
                state_bits(&bodies_fresh, &contacts_fresh)
            );
            let grouping = unchecked.contact_grouping.grouped();
            assert_eq!(grouping, fresh.contact_grouping.grouped());
            assert_eq!(grouping != first_grouping, changes);
            assert_eq!(unchecked.contact_grouping.kept(), kept);
            // The tall column's every box pushed: the step solved what it was given.
            let pushes = contacts_unchecked[..60]
                .chunks(2)
                .map(|m| m[0].normal_impulse + m[1].normal_impulse);
            assert!(
                pushes.clone().all(|p| p > 0.0),
                "{:?}",
                pushes.collect::<Vec<_>>()
            );
        }
    }
}
