//! The impulse stage list's passes over the pins (`sequential`, `thesis`, `exact`): the
//! joints grouped into islands, each solved by one direct solve per Newton step
//! (`PinIsland`) or, when large, by Gauss–Seidel sweeps as the thesis iterates
//! (thesis §3.3); motors driven as bounded velocity constraints; broken joints repaired by
//! positions.

use super::pin_island::{PinIsland, displace_island};
use super::system::{DenseRowsLcp, Row, RowKind, VelocityTargets, velocity_rows};
use crate::math::{Vec2, clamp};
use crate::solver::island::{IslandGrouping, island_ranges};
use crate::solver::joint::{JointConstraint, JointIterations, gap_target, own_block, solve_2x2};
use crate::solver::lcp::{LcpMethod, REGULARISATION};
use crate::solver::{BodiesAndMoving, SolverBody};

/// Islands with at most this many joints are solved by one direct (Cholesky) solve per
/// Newton step; larger ones by Gauss–Seidel sweeps, as the thesis iterates (thesis §3.3).
pub(crate) const DIRECT_JOINT_LIMIT: usize = 256;

/// Start of step: every joint's anchors stop drifting apart (thesis §3.3 eq. 40), iterated.
pub(crate) fn correct_velocities(
    joints: &mut [JointConstraint],
    bodies: &mut [SolverBody],
    it: &JointIterations,
) -> usize {
    for sweep in 0..it.max_sweeps {
        let mut worst: f64 = 0.0;
        for j in joints.iter_mut() {
            worst = worst.max(j.correct_velocity(bodies));
        }
        if worst < it.velocity_tolerance {
            return sweep;
        }
    }
    it.max_sweeps
}

/// After contacts: impulses that make every joint's anchors meet at the end of the step
/// (thesis §3.3), Gauss–Seidel until all predicted gaps are within tolerance.
pub(crate) fn correct_positions(
    joints: &mut [JointConstraint],
    bodies: &mut [SolverBody],
    dt: f64,
    it: &JointIterations,
) -> usize {
    for sweep in 0..it.max_sweeps {
        let mut worst: f64 = 0.0;
        for j in joints.iter_mut() {
            worst = worst.max(j.correct_position(bodies, dt));
        }
        if worst < it.position_tolerance {
            return sweep;
        }
    }
    it.max_sweeps
}

/// Joint motors as bounded velocity constraints, and joints' stops as one-sided ones,
/// solved by projected Gauss–Seidel on the accumulated impulse so the bound ±max_torque·h
/// holds over the whole step; unless `fresh`, keeping the impulses already applied this
/// step so the bound holds over several rounds.
fn drive_motors_continue(
    joints: &mut [JointConstraint],
    bodies: &mut [SolverBody],
    dt: f64,
    sweeps: usize,
    fresh: bool,
) {
    if fresh {
        for j in joints.iter_mut() {
            if let Some(m) = j.motor.as_mut() {
                m.last_impulse = 0.0;
            }
            j.limit_impulse = (0.0, 0.0);
        }
    }
    for _ in 0..sweeps {
        for j in joints.iter_mut() {
            let (ia, ib) = (j.body_a as usize, j.body_b as usize);
            let k = bodies[ia].inv_inertia + bodies[ib].inv_inertia;
            if k == 0.0 {
                continue;
            }
            let push = |bodies: &mut [SolverBody], delta: f64| {
                bodies[ia].angular_velocity += delta * bodies[ia].inv_inertia;
                bodies[ib].angular_velocity -= delta * bodies[ib].inv_inertia;
            };
            let relative =
                |bodies: &[SolverBody]| bodies[ia].angular_velocity - bodies[ib].angular_velocity;
            if let Some(motor) = j.motor.as_mut().filter(|m| m.enabled) {
                let limit = motor.max_torque * dt;
                let total = clamp(
                    motor.last_impulse - (relative(bodies) - motor.drive_speed()) / k,
                    -limit,
                    limit,
                );
                let delta = total - motor.last_impulse;
                motor.last_impulse = total;
                push(bodies, delta);
            }
            if j.limits.is_some() {
                hold_stops(j, bodies, dt);
            }
        }
    }
}

/// A joint's stops (`JointLimits`) as one-sided constraints on s = ω_A − ω_B (a weld's
/// two-sided), on the impulses they have already applied this step: s ≤ the lower stop's
/// bound with an impulse ≤ 0, s ≥ the upper's with one ≥ 0. Gauss–Seidel, not rows of
/// the LCPs: a motor on the same joint has the same row, and the two together make the
/// LCP's matrix singular.
fn hold_stops(j: &mut JointConstraint, bodies: &mut [SolverBody], dt: f64) {
    let Some(limits) = j.limits else {
        return;
    };
    let (ia, ib) = (j.body_a as usize, j.body_b as usize);
    let k = bodies[ia].inv_inertia + bodies[ib].inv_inertia;
    if k == 0.0 {
        return;
    }
    let theta = bodies[ib].angle - bodies[ia].angle - j.reference_angle;
    let (at_most, at_least) = limits.spin_bounds(theta, dt);
    let relative =
        |bodies: &[SolverBody]| bodies[ia].angular_velocity - bodies[ib].angular_velocity;
    let push = |bodies: &mut [SolverBody], delta: f64| {
        bodies[ia].angular_velocity += delta * bodies[ia].inv_inertia;
        bodies[ib].angular_velocity -= delta * bodies[ib].inv_inertia;
    };
    let (lower, upper) = j.limit_impulse;
    let mut lower_total = lower - (relative(bodies) - at_most) / k;
    if !limits.is_weld() {
        lower_total = lower_total.min(0.0);
    }
    push(bodies, lower_total - lower);
    let mut upper_total = upper;
    if !limits.is_weld() {
        upper_total = (upper - (relative(bodies) - at_least) / k).max(0.0);
        push(bodies, upper_total - upper);
    }
    j.limit_impulse = (lower_total, upper_total);
}

/// The stops' last word on an island, after the motors' hold: sweeps of `hold_stops`
/// (two stops coupled through a body, a double pendulum's, take a dozen to settle).
fn hold_island_stops(island: &mut [JointConstraint], bodies: &mut [SolverBody], dt: f64) {
    if island.iter().all(|j| j.limits.is_none()) {
        return;
    }
    for _ in 0..16 {
        for j in island.iter_mut() {
            hold_stops(j, bodies, dt);
        }
    }
}

/// Buffers for solving joints island by island, reused across steps.
#[derive(Debug, Clone, Default)]
pub(crate) struct JointBlockSolver {
    islands: JointIslands,
    pin_island: PinIsland,
    motor_speeds: MotorSpeeds,
}

/// The joints grouped into islands, one island's copied out at a time.
#[derive(Debug, Clone, Default)]
struct JointIslands {
    /// The joints' islands, kept while the joints and the moving bodies are the same (a
    /// chain's are found once, not at every pass of every substep).
    grouping: IslandGrouping,
    /// Each island's range in the grouping.
    ranges: Vec<(usize, usize)>,
    island: Vec<JointConstraint>,
}

/// The repair moves bodies by the smallest mass-weighted displacement, with rotations
/// made this much costlier than physics would weigh them. A thin link's small inertia
/// would otherwise let the first-order solve turn links by whole turns to save a little
/// translation, and the Newton steps stall; translations enter the gaps linearly, so a
/// chain or tree closes in one step, and rotation is still used where a closed loop
/// needs it.
const REPAIR_ROTATION_WEIGHT: f64 = 1e-4;

/// Each joint with its repair target: broken joints `max_closing` narrower (or closed),
/// the others held as they are.
fn with_repair_targets(
    joints: &[JointConstraint],
    bodies: &[SolverBody],
    it: &JointIterations,
) -> Vec<JointConstraint> {
    joints
        .iter()
        .map(|j| {
            let now = j.predicted_gap(bodies, 0.0);
            let target = if now.norm() > it.broken_gap {
                gap_target(now, it.max_closing)
            } else {
                now
            };
            JointConstraint {
                gap_target: target,
                ..*j
            }
        })
        .collect()
}

fn repair_residual(j: &JointConstraint, bodies: &[SolverBody]) -> Vec2 {
    j.predicted_gap(bodies, 0.0) - j.gap_target
}

/// The same repair one joint at a time, by Gauss–Seidel sweeps (large islands).
fn repair_positions_sequential(
    joints: &[JointConstraint],
    bodies: &mut [SolverBody],
    it: &JointIterations,
) {
    let joints = with_repair_targets(joints, bodies, it);
    for _ in 0..it.max_sweeps {
        let mut worst: f64 = 0.0;
        for j in &joints {
            let d = repair_residual(j, bodies);
            worst = worst.max(d.norm());
            let Some(push) = solve_2x2(own_block(j, bodies, 0.0), -d) else {
                continue;
            };
            displace_island(std::slice::from_ref(j), bodies, &[push.x, push.y], 1.0);
        }
        if worst < it.position_tolerance {
            break;
        }
    }
}

/// Body slots an island's joints touch (with repeats).
fn island_bodies(joints: &[JointConstraint]) -> impl Iterator<Item = usize> + '_ {
    joints
        .iter()
        .flat_map(|j| [j.body_a as usize, j.body_b as usize])
}

impl JointIslands {
    /// Calls `solve` once per island with that island's joints, copied contiguously;
    /// `moving`: the slots of the bodies that move, increasing.
    fn for_each(
        &mut self,
        joints: &mut [JointConstraint],
        (bodies, moving): BodiesAndMoving<'_>,
        mut solve: impl FnMut(&mut [JointConstraint], &mut [SolverBody]),
    ) {
        let grouped = self.grouping.group(
            joints.len(),
            bodies.len(),
            |i| (joints[i].body_a, joints[i].body_b),
            moving,
        );
        island_ranges(grouped, &mut self.ranges);
        for &(start, end) in &self.ranges {
            self.island.clear();
            self.island
                .extend(grouped[start..end].iter().map(|&(_, i)| joints[i as usize]));
            solve(&mut self.island, bodies);
            for (k, &(_, i)) in grouped[start..end].iter().enumerate() {
                joints[i as usize] = self.island[k];
            }
        }
    }
}

impl JointBlockSolver {
    /// Before a step: every broken joint (wider than [`JointIterations::broken_gap`]) is
    /// pulled up to `max_closing` closer by moving the bodies of its island, which adds no
    /// kinetic energy — a stretched chain snaps together instead of whipping. Does
    /// nothing (and costs one pass over the joints) when no joint is broken.
    pub(crate) fn repair_positions(
        &mut self,
        joints: &mut [JointConstraint],
        (bodies, moving): BodiesAndMoving<'_>,
        it: &JointIterations,
    ) {
        if joints
            .iter()
            .all(|j| j.predicted_gap(bodies, 0.0).norm() <= it.broken_gap)
        {
            return;
        }
        let pin_island = &mut self.pin_island;
        self.islands
            .for_each(joints, (bodies, moving), |island, bodies| {
                let mut slots: Vec<usize> = island_bodies(island).collect();
                slots.sort_unstable();
                slots.dedup();
                for &i in &slots {
                    bodies[i].inv_inertia *= REPAIR_ROTATION_WEIGHT;
                }
                let direct = island.len() <= DIRECT_JOINT_LIMIT;
                let targets = || with_repair_targets(island, bodies, it);
                if !(direct && pin_island.repair(&targets(), bodies, it)) {
                    repair_positions_sequential(island, bodies, it);
                }
                for &i in &slots {
                    bodies[i].inv_inertia /= REPAIR_ROTATION_WEIGHT;
                }
            });
    }

    /// Stage 1 (thesis eq. 40) for every island: the relative anchor velocities vanish.
    pub(crate) fn correct_velocities(
        &mut self,
        joints: &mut [JointConstraint],
        bodies: BodiesAndMoving<'_>,
        it: &JointIterations,
    ) {
        let pin_island = &mut self.pin_island;
        self.islands.for_each(joints, bodies, |island, bodies| {
            let direct = island.len() <= DIRECT_JOINT_LIMIT;
            let solved = direct && pin_island.stop_drift(island, bodies);
            if !solved {
                correct_velocities(island, bodies, it);
            }
        });
    }

    /// Stage 6 (thesis §3.3): motors, then Newton steps on the predicted gaps until every
    /// joint closes. Motors and joints alternate so that both hold at the end;
    /// `motors_started` says the motors' impulses of this step so far are in place.
    pub(crate) fn correct_positions(
        &mut self,
        joints: &mut [JointConstraint],
        bodies: BodiesAndMoving<'_>,
        dt: f64,
        it: &JointIterations,
        motors_started: bool,
    ) {
        let (pin_island, motor_speeds) = (&mut self.pin_island, &mut self.motor_speeds);
        self.islands.for_each(joints, bodies, |island, bodies| {
            // Motors and stops: the rows on the joints' relative spins.
            let has_motor = island
                .iter()
                .any(|j| j.motor.is_some_and(|m| m.enabled) || j.limits.is_some());
            let direct = island.len() <= DIRECT_JOINT_LIMIT;
            if !direct {
                if has_motor {
                    drive_motors_continue(island, bodies, dt, 10, !motors_started);
                }
                correct_positions(island, bodies, dt, it);
                hold_island_stops(island, bodies, dt);
                return;
            }
            let outer = if has_motor { 8 } else { 1 };
            for round in 0..outer {
                if has_motor {
                    // Keep what the contact solve already pushed so the bound holds overall.
                    drive_motors_continue(island, bodies, dt, 4, round == 0 && !motors_started);
                }
                if !pin_island.close_gaps(island, bodies, dt, it) {
                    correct_positions(island, bodies, dt, it);
                    break;
                }
            }
            if has_motor {
                // Holding the speeds moves the anchors' predicted gaps at second order;
                // one more Newton pass closes them, and holding again undoes what that
                // did to the speeds, to second order of a second order.
                motor_speeds.hold(island, bodies, dt);
                if pin_island.close_gaps(island, bodies, dt, it) {
                    motor_speeds.hold(island, bodies, dt);
                }
                hold_island_stops(island, bodies, dt);
            }
        });
    }
}

/// The last word on an island's motors: the pins' Newton steps close the gaps by changing
/// velocities, and in a closed loop (a four-bar's crank) that changes the speed a motor
/// drove its joint to. One LCP of the motors' rows and the pins' rows
/// puts each motor at its speed (within what its torque has left this step) while every
/// pin's anchors keep the relative velocity the Newton steps gave them.
#[derive(Debug, Clone, Default)]
struct MotorSpeeds {
    rows: Vec<Row>,
    dense: DenseRowsLcp,
    x: Vec<f64>,
}

impl MotorSpeeds {
    fn hold(&mut self, island: &mut [JointConstraint], bodies: &mut [SolverBody], dt: f64) {
        let targets = VelocityTargets {
            dt,
            bounce_below: f64::INFINITY,
            friction: false,
        };
        velocity_rows(&[], island, bodies, &targets, &mut self.rows);
        for row in self.rows.iter_mut() {
            match row.kind {
                // As they are: the closing the Newton steps gave them stays.
                RowKind::JointX(_) | RowKind::JointY(_) => row.b = 0.0,
                RowKind::JointMotor(k) => {
                    let applied = island[k as usize].motor.map_or(0.0, |m| m.last_impulse);
                    (row.lo, row.hi) = (row.lo - applied, row.hi - applied);
                }
                _ => {}
            }
        }
        for row in self.rows.iter_mut() {
            // Bounds that hold zero: a motor whose torque is spent is held where it is.
            (row.lo, row.hi) = (row.lo.min(0.0), row.hi.max(0.0));
        }
        let stats = (self.dense).solve(&self.rows, bodies, REGULARISATION, &[], &mut self.x);
        if stats.method == LcpMethod::Rejected || !self.x.iter().all(|x| x.is_finite()) {
            return;
        }
        for (row, &x) in self.rows.iter().zip(&self.x) {
            row.apply(bodies, x);
            match row.kind {
                RowKind::JointX(k) => island[k as usize].impulse.x += x,
                RowKind::JointY(k) => island[k as usize].impulse.y += x,
                RowKind::JointMotor(k) => {
                    if let Some(m) = island[k as usize].motor.as_mut() {
                        m.last_impulse += x;
                    }
                }
                _ => {}
            }
        }
    }
}
