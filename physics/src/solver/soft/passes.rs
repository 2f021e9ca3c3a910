//! The substeps' passes: velocities and positions integrated, constraints warm-started,
//! and the biased and relaxed solves swept over the plan's items, chunk by chunk and
//! then the rest.

use super::batch::{AskedFor, LaneBatch, LanePath, ManifoldBatch, PassItem, PassSettings};
use super::bodies::SoftBody;
use super::constraints::PointConstraint;
use super::contacts::{solve_pair, solve_point, warm_start_point};
use super::joints::{solve_joint, solve_limits, solve_motor, warm_start_motor, warm_start_pin};
use super::pins::{PinPass, PinPlan};
use super::settings::{MAX_TURN_PER_SUBSTEP, SoftSettings, Softness, contact_pass};
use super::{SoftStepSolver, SweepOrder};
use crate::math::{Rot, Vec2, clamp};
use std::ops::Range;

/// A moving body's velocity over a substep of `h`.
pub(super) fn integrate_velocity(b: &mut SoftBody, (linear, angular): (Vec2, f64), h: f64) {
    b.v += linear * h;
    b.w += angular * h;
    // A body turning more than a quarter turn per substep is beyond what the linearised
    // rotation below (and any contact found at the step's start) can follow; like Box2D,
    // cap the spin there rather than let it overflow to NaN.
    let max_w = MAX_TURN_PER_SUBSTEP / h;
    b.w = clamp(b.w, -max_w, max_w);
}

/// A body's motion since the step's start, over a substep of `h`.
pub(super) fn integrate_position(b: &mut SoftBody, h: f64) {
    b.dp += b.v * h;
    b.dangle += b.w * h;
    // Rotate the delta rotation by ω·h and renormalise: no trigonometry per substep.
    let (c, s) = (b.dq.cos - h * b.w * b.dq.sin, b.dq.sin + h * b.w * b.dq.cos);
    let len = (c * c + s * s).sqrt();
    b.dq = Rot {
        cos: c / len,
        sin: s / len,
    };
}
impl SoftStepSolver {
    /// How many chunks this step solves apart, before the rest (`PassPlan::assign_chunks`).
    /// None if a fixed body moves: then the rest's passes take the chunks' items too, in
    /// their order, which solves every island as the chunks would.
    pub(super) fn chunks_apart(&self) -> usize {
        if self.loaded.a_fixed_body_moves {
            0
        } else {
            self.plan.chunk_count()
        }
    }

    /// The rest's items: every item but those of the chunks solved apart.
    fn rest_items(&self) -> Range<usize> {
        if self.chunks_apart() > 0 {
            self.plan.rest_items()
        } else {
            0..self.plan.items.len()
        }
    }

    /// The rest's bodies' velocities (those no chunk moves).
    pub(super) fn integrate_velocities(&mut self, accelerations: &[(Vec2, f64)], h: f64) {
        let chunked = self.chunks_apart() > 0;
        for &i in &self.loaded.in_motion {
            let (i, b) = (i as usize, &mut self.loaded.bodies[i as usize]);
            if b.moves() && !(chunked && self.plan.in_chunk(i)) {
                integrate_velocity(b, accelerations[i], h);
            }
        }
    }

    /// The rest's bodies' positions (those no chunk moves). A body at rest and fixed
    /// would stay where it is to the last bit: only `in_motion` is walked.
    pub(super) fn integrate_positions(&mut self, h: f64) {
        let chunked = self.chunks_apart() > 0;
        for &i in &self.loaded.in_motion {
            let i = i as usize;
            if !(chunked && self.plan.in_chunk(i)) {
                integrate_position(&mut self.loaded.bodies[i], h);
            }
        }
    }

    pub(super) fn warm_start(&mut self) {
        for &(start, end, ..) in &self.contact_lcp.islands {
            for p in &self.points[start..end] {
                warm_start_point(&mut self.loaded.bodies, p);
            }
        }
        self.warm_start_items(self.rest_items(), true);
        // Each pin's impulse and its motor's, pin by pin; the batched islands' pins, then
        // their motors'.
        for &(start, end) in &self.pins.joint_islands {
            if !PinPlan::batches_island(end - start) {
                for j in &self.pins.joints[start..end] {
                    warm_start_pin(&mut self.loaded.bodies, j);
                    warm_start_motor(&mut self.loaded.bodies, j);
                }
            }
        }
        self.pins.pin_plan.warm_start(&mut self.loaded.bodies);
        for &k in self.pins.pin_plan.alone() {
            warm_start_pin(&mut self.loaded.bodies, &self.pins.joints[k as usize]);
        }
        for &(start, end) in &self.pins.joint_islands {
            if PinPlan::batches_island(end - start) {
                // `motor_joints` is in the joints' order.
                let from = self
                    .pins
                    .motor_joints
                    .partition_point(|&k| (k as usize) < start);
                let motors = self.pins.motor_joints[from..].iter();
                for &k in motors.take_while(|&&k| (k as usize) < end) {
                    warm_start_motor(&mut self.loaded.bodies, &self.pins.joints[k as usize]);
                }
            }
        }
    }

    with_fma_where_present! {
        /// Warm-starts the plan's `items`, in their order.
        pub(super) fn warm_start_items, warm_start_items_with_fma => warm_start_items_inline(
            &mut self,
            items: Range<usize>,
            ask: bool,
        );
    }

    #[inline(always)]
    fn warm_start_items_inline(&mut self, items: Range<usize>, ask: bool) {
        let (batches, point_batches) = (self.plan.batches(), self.plan.point_batches());
        let lanes = LanePath::best();
        let ahead = self.plan.batches_ahead().only_if(ask);
        for item in ahead.asking(self.plan.items[items].iter(), AskedFor::WarmStart) {
            match *item {
                PassItem::Batch(k) => {
                    batches[k as usize].warm_start_on(lanes, &mut self.loaded.bodies)
                }
                PassItem::PointBatch(k) => {
                    point_batches[k as usize].warm_start_on(lanes, &mut self.loaded.bodies)
                }
                PassItem::Manifold(first, count) => {
                    let (first, count) = (first as usize, count as usize);
                    for p in &self.points[first..first + count] {
                        warm_start_point(&mut self.loaded.bodies, p);
                    }
                }
            }
        }
    }

    with_fma_where_present! {
        /// One pass over the plan's `items`, in their order or backwards: eight manifolds
        /// at a time where they are batched (see `batch`), the rest with FMA where the
        /// processor has it.
        pub(super) fn sweep_items, sweep_items_with_fma => sweep_items_inline(
            &mut self,
            items: Range<usize>,
            pass: &PassSettings,
            order: SweepOrder,
            ask: bool,
        );
    }

    #[inline(always)]
    fn sweep_items_inline(
        &mut self,
        items: Range<usize>,
        pass: &PassSettings,
        order: SweepOrder,
        ask: bool,
    ) {
        let ahead = self.plan.batches_ahead().only_if(ask);
        let (all_items, batches, point_batches) = self.plan.work();
        let items = &all_items[items];
        let work = (
            batches,
            point_batches,
            &mut self.loaded.bodies[..],
            &mut self.points[..],
        );
        match order {
            SweepOrder::Forwards => {
                sweep_in_order(ahead.asking(items.iter(), AskedFor::Pass), work, pass)
            }
            SweepOrder::Backwards => {
                sweep_in_order(ahead.asking(items.iter().rev(), AskedFor::Pass), work, pass)
            }
        }
    }

    pub(super) fn solve(
        &mut self,
        h: f64,
        contact_soft: &Softness,
        joint_soft: &Softness,
        settings: &SoftSettings,
        use_bias: bool,
        order: SweepOrder,
    ) {
        let joint_push = settings.joint_push_speed;
        for &k in &self.pins.motor_joints {
            solve_motor(
                &mut self.loaded.bodies,
                &mut self.pins.joints[k as usize],
                h,
            );
        }
        for (index, &(start, end)) in self.pins.joint_islands.iter().enumerate() {
            let island = &mut self.pins.joints[start..end];
            if PinPlan::batches_island(island.len()) {
                continue;
            }
            // A lone pin's 2 × 2 is solved in closed form below.
            let solved = island.len() >= 2
                && self.pins.block.solve(
                    &mut self.loaded.bodies,
                    (index, island),
                    joint_soft,
                    joint_push,
                    use_bias,
                );
            if !solved {
                for j in island.iter_mut() {
                    solve_joint(&mut self.loaded.bodies, j, joint_soft, joint_push, use_bias);
                }
            }
        }
        let pin_pass = PinPass {
            soft: *joint_soft,
            max_push: joint_push,
            use_bias,
        };
        self.pins.pin_plan.solve(&mut self.loaded.bodies, &pin_pass);
        for &k in self.pins.pin_plan.alone() {
            let j = &mut self.pins.joints[k as usize];
            solve_joint(&mut self.loaded.bodies, j, joint_soft, joint_push, use_bias);
        }
        for &k in &self.pins.motor_joints {
            let j = &mut self.pins.joints[k as usize];
            if j.limits.is_some() {
                solve_limits(&mut self.loaded.bodies, j, h, joint_soft, use_bias);
            }
        }
        let pass = contact_pass(h, contact_soft, settings, use_bias);
        self.contact_lcp
            .solve(&mut self.loaded.bodies, &mut self.points, &pass);
        // In the plan's order: small islands in the points' order, then big ones colour
        // by colour (or their colours backwards), eight manifolds at a time (see `batch`).
        let (rest, coloured_from) = (self.rest_items(), self.plan.coloured_from);
        self.sweep_items(0..coloured_from, &pass, SweepOrder::Forwards, true);
        self.sweep_items(coloured_from..rest.end, &pass, order, true);
    }
}

/// What a pass works on: the batches of pairs and of single points, the bodies and the
/// points.
type PassWork<'w> = (
    &'w mut [ManifoldBatch<2>],
    &'w mut [ManifoldBatch<1>],
    &'w mut [SoftBody],
    &'w mut [PointConstraint],
);

/// Solves each of `items` once, in the order given.
#[inline(always)]
fn sweep_in_order<'a>(
    items: impl Iterator<Item = &'a PassItem>,
    (batches, point_batches, bodies, points): PassWork,
    pass: &PassSettings,
) {
    let lanes = LanePath::best();
    for item in items {
        match *item {
            PassItem::Batch(k) => batches[k as usize].solve_on(lanes, bodies, pass),
            PassItem::PointBatch(k) => point_batches[k as usize].solve_on(lanes, bodies, pass),
            PassItem::Manifold(first, 2) => {
                let i = first as usize;
                let (first, second) = points.split_at_mut(i + 1);
                solve_pair(bodies, (&mut first[i], &mut second[0]), pass);
            }
            PassItem::Manifold(first, _) => solve_point(bodies, &mut points[first as usize], pass),
        }
    }
}
