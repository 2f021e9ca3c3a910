//! Pin (revolute) joints by impulses with position prediction (SPEC §2.5, §3.3).

use super::island::IslandGrouping;
use super::pin_island::{PinIsland, displace_island};
use super::{BodiesAndMoving, SolverBody};
use crate::body::BodyHandle;
use crate::math::{Rot, Vec2, clamp};

/// Islands with at most this many joints are solved by one direct (Cholesky) solve per
/// Newton step; larger ones by Gauss–Seidel sweeps, as the thesis iterates (SPEC §3.3).
pub(crate) const DIRECT_JOINT_LIMIT: usize = 256;

/// A joint's handle in its world. Handles are never reused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct JointHandle(pub u32);

impl JointHandle {
    pub(crate) fn index(self) -> usize {
        self.0 as usize
    }
}

/// A pin joint between two bodies, or a body and the static world (`body_b: None`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint {
    pub body_a: BodyHandle,
    pub body_b: Option<BodyHandle>,
    /// The anchor in each body's space (relative to its centroid, unrotated); for the world,
    /// a world point.
    pub local_anchor_a: Vec2,
    pub local_anchor_b: Vec2,
    /// Whether the two bodies still collide with each other (off by default: jointed robot
    /// parts overlap around their pins, SPEC §3.1).
    pub collide_connected: bool,
    pub motor: Option<JointMotor>,
}

/// A joint as the solver sees it: body slots in the step's solver array (the static world
/// is the slot past the last body) and the anchors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointConstraint {
    pub joint: u32,
    pub body_a: u32,
    pub body_b: u32,
    pub local_anchor_a: Vec2,
    pub local_anchor_b: Vec2,
    pub motor: Option<JointMotor>,
    /// The predicted gap this step's position pass aims for: zero, unless the joint is
    /// broken wider than one step may close (see [`JointIterations::max_closing`]).
    pub gap_target: Vec2,
}

/// Drives the relative angular velocity ω_A − ω_B to `target_speed` with a torque of at
/// most `max_torque`, reacting on both bodies (issue 4b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointMotor {
    pub target_speed: f64,
    pub max_torque: f64,
    pub enabled: bool,
    /// Angular impulse of the motor's last solve (one substep's worth).
    pub last_impulse: f64,
    /// Angular impulse the motor applied over the whole last step, all substeps summed:
    /// the mean torque of the step is `step_impulse / h`.
    pub step_impulse: f64,
}

impl JointMotor {
    /// Both numbers finite and within `crate::limits`, the torque bound non-negative.
    pub(crate) fn validate(&self) -> Result<(), super::motor::MotorError> {
        use super::motor::MotorError;
        if !self.target_speed.is_finite() {
            return Err(MotorError::NonFinite("target speed", self.target_speed));
        }
        if !self.max_torque.is_finite() {
            return Err(MotorError::NonFinite("max torque", self.max_torque));
        }
        if self.max_torque < 0.0 {
            return Err(MotorError::Negative("max torque", self.max_torque));
        }
        let numbers = [
            ("target speed", self.target_speed, crate::limits::SPIN),
            ("max torque", self.max_torque, crate::limits::TORQUE),
        ];
        if let Some((what, value, limit)) = crate::limits::first_beyond(numbers) {
            return Err(MotorError::Beyond(what, value, limit));
        }
        Ok(())
    }

    pub fn new(target_speed: f64, max_torque: f64) -> Self {
        Self {
            target_speed,
            max_torque,
            enabled: true,
            last_impulse: 0.0,
            step_impulse: 0.0,
        }
    }
}

/// How hard the joint passes iterate (SPEC §3.3 Rec: Gauss–Seidel with a tolerance and a cap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointIterations {
    /// Stop once every predicted gap is below this (length units).
    pub position_tolerance: f64,
    /// Stop once every relative anchor speed is below this (length units per second).
    pub velocity_tolerance: f64,
    pub max_sweeps: usize,
    /// The most a broken joint's gap may close in one step (so that repair is visible
    /// rather than a teleport).
    pub max_closing: f64,
    /// A joint wider than this is broken: it is repaired by moving the bodies (see
    /// [`JointBlockSolver::repair_positions`]), not by the velocity passes, which would
    /// turn the whole gap into speed (gap/h) and, along a chain, add it up.
    pub broken_gap: f64,
}

/// The 2×2 matrix K of SPEC eq. 39: the anchors' relative velocity change per unit impulse.
fn effective_mass_matrix(a: &SolverBody, r_a: Vec2, b: &SolverBody, r_b: Vec2) -> [[f64; 2]; 2] {
    let m = a.inv_mass + b.inv_mass;
    let (ia, ib) = (a.inv_inertia, b.inv_inertia);
    [
        [
            m + ia * r_a.y * r_a.y + ib * r_b.y * r_b.y,
            -ia * r_a.x * r_a.y - ib * r_b.x * r_b.y,
        ],
        [
            -ia * r_a.x * r_a.y - ib * r_b.x * r_b.y,
            m + ia * r_a.x * r_a.x + ib * r_b.x * r_b.x,
        ],
    ]
}

/// Solves `K ψ = rhs` in closed form; `None` if K is singular (both bodies static).
fn solve_2x2(k: [[f64; 2]; 2], rhs: Vec2) -> Option<Vec2> {
    let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    if det.abs() <= f64::EPSILON * (k[0][0] * k[1][1]).abs() || det == 0.0 {
        return None;
    }
    Some(Vec2::new(
        (k[1][1] * rhs.x - k[0][1] * rhs.y) / det,
        (k[0][0] * rhs.y - k[1][0] * rhs.x) / det,
    ))
}

impl JointConstraint {
    /// World anchor offsets from each centroid, `r_A` and `r_B`.
    pub(crate) fn arms(&self, angles: (f64, f64)) -> (Vec2, Vec2) {
        self.arms_turned((Rot::new(angles.0), Rot::new(angles.1)))
    }

    /// `arms` for bodies turned by the given rotations (found once per body, where the
    /// bodies carry many pins).
    pub(crate) fn arms_turned(&self, (a, b): (Rot, Rot)) -> (Vec2, Vec2) {
        (a.apply(self.local_anchor_a), b.apply(self.local_anchor_b))
    }

    /// Removes the anchors' relative velocity (SPEC eq. 40). Returns |d_v| before.
    fn correct_velocity(&self, bodies: &mut [SolverBody]) -> f64 {
        let (ia, ib) = (self.body_a as usize, self.body_b as usize);
        let (r_a, r_b) = self.arms((bodies[ia].angle, bodies[ib].angle));
        let (a, b) = (&bodies[ia], &bodies[ib]);
        let d_v = a.velocity_at(a.position + r_a) - b.velocity_at(b.position + r_b);
        let k = effective_mass_matrix(a, r_a, b, r_b);
        if let Some(psi) = solve_2x2(k, -d_v) {
            let (pa, pb) = (bodies[ia].position + r_a, bodies[ib].position + r_b);
            bodies[ia].apply_impulse(psi, pa);
            bodies[ib].apply_impulse(-psi, pb);
        }
        d_v.norm()
    }

    /// Where the anchors would be after integrating the current velocities for `dt`.
    pub(crate) fn predicted_gap(&self, bodies: &[SolverBody], dt: f64) -> Vec2 {
        let end = |i: usize, local: Vec2| {
            let b = &bodies[i];
            b.position + b.velocity * dt + Rot::new(b.angle + b.angular_velocity * dt).apply(local)
        };
        end(self.body_a as usize, self.local_anchor_a)
            - end(self.body_b as usize, self.local_anchor_b)
    }

    /// One Newton step on the predicted gap (SPEC eq. 34–39). Returns |d| before.
    fn correct_position(&self, bodies: &mut [SolverBody], dt: f64) -> f64 {
        let (ia, ib) = (self.body_a as usize, self.body_b as usize);
        let d = self.predicted_gap(bodies, dt) - self.gap_target;
        // The impulse acts at the anchors now, where the pin force really acts (at the
        // predicted arms it would do work and drain energy); the gap is observed at the
        // predicted pose, so K is the exact derivative and Newton converges.
        let k = own_block(self, bodies, dt);
        let (r_a, r_b) = self.arms((bodies[ia].angle, bodies[ib].angle));
        if let Some(psi) = solve_2x2(k, -d / dt) {
            let (pa, pb) = (bodies[ia].position + r_a, bodies[ib].position + r_b);
            bodies[ia].apply_impulse(psi, pa);
            bodies[ib].apply_impulse(-psi, pb);
        }
        d.norm()
    }
}

/// Start of step: every joint's anchors stop drifting apart (SPEC §3.3 eq. 40), iterated.
pub(crate) fn correct_velocities(
    joints: &[JointConstraint],
    bodies: &mut [SolverBody],
    it: &JointIterations,
) -> usize {
    for sweep in 0..it.max_sweeps {
        let mut worst: f64 = 0.0;
        for j in joints {
            worst = worst.max(j.correct_velocity(bodies));
        }
        if worst < it.velocity_tolerance {
            return sweep;
        }
    }
    it.max_sweeps
}

/// After contacts: impulses that make every joint's anchors meet at the end of the step
/// (SPEC §3.3), Gauss–Seidel until all predicted gaps are within tolerance.
pub(crate) fn correct_positions(
    joints: &[JointConstraint],
    bodies: &mut [SolverBody],
    dt: f64,
    it: &JointIterations,
) -> usize {
    for sweep in 0..it.max_sweeps {
        let mut worst: f64 = 0.0;
        for j in joints.iter() {
            worst = worst.max(j.correct_position(bodies, dt));
        }
        if worst < it.position_tolerance {
            return sweep;
        }
    }
    it.max_sweeps
}

/// What a joint's gap should be at the end of this step: closed, or `max_closing` narrower
/// if it is wider than that now.
pub(crate) fn gap_target(gap_now: Vec2, max_closing: f64) -> Vec2 {
    let len = gap_now.norm();
    if len > max_closing {
        gap_now * (1.0 - max_closing / len)
    } else {
        Vec2::zeros()
    }
}

/// What the velocity passes aim a joint's predicted gap at: closed for a healthy joint
/// (the thesis method, SPEC §3.3), held where it is for a broken one, which only the
/// position repair closes.
pub(crate) fn velocity_gap_target(gap_now: Vec2, broken_gap: f64) -> Vec2 {
    if gap_now.norm() > broken_gap {
        gap_now
    } else {
        Vec2::zeros()
    }
}

/// Joint motors as bounded velocity constraints, solved by projected Gauss–Seidel on the
/// accumulated impulse so the bound ±max_torque·h holds over the whole step; unless
/// `fresh`, keeping the impulses already applied this step so the bound holds over several
/// rounds.
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
        }
    }
    for _ in 0..sweeps {
        for j in joints.iter_mut() {
            let Some(motor) = j.motor.as_mut().filter(|m| m.enabled) else {
                continue;
            };
            let (ia, ib) = (j.body_a as usize, j.body_b as usize);
            let k = bodies[ia].inv_inertia + bodies[ib].inv_inertia;
            if k == 0.0 {
                continue;
            }
            let relative = bodies[ia].angular_velocity - bodies[ib].angular_velocity;
            let limit = motor.max_torque * dt;
            let total = clamp(
                motor.last_impulse - (relative - motor.target_speed) / k,
                -limit,
                limit,
            );
            let delta = total - motor.last_impulse;
            motor.last_impulse = total;
            bodies[ia].angular_velocity += delta * bodies[ia].inv_inertia;
            bodies[ib].angular_velocity -= delta * bodies[ib].inv_inertia;
        }
    }
}

/// Buffers for solving joints island by island, reused across steps.
#[derive(Debug, Clone, Default)]
pub(crate) struct JointBlockSolver {
    islands: JointIslands,
    pin_island: PinIsland,
}

/// The joints grouped into islands, one island's copied out at a time.
#[derive(Debug, Clone, Default)]
struct JointIslands {
    /// The joints' islands, kept while the joints and the moving bodies are the same (a
    /// chain's are found once, not at every pass of every substep).
    grouping: IslandGrouping,
    island: Vec<JointConstraint>,
}

/// The velocity change at joint `p`'s anchors per unit impulse at joint `q`: one 2×2 block
/// of K = J M⁻¹ Jᵀ, summed over the bodies the two joints share (signs: + on A, − on B).
/// The impulse acts at `q`'s anchors now (`q_arms`); `p`'s are observed `ahead` seconds
/// on, turned by ω·ahead (`p_arms_ahead`): for the position pass that is the exact
/// derivative of the predicted gap, so the Newton steps converge quadratically even for
/// fast-spinning links.
pub(super) fn coupling_block(
    (p, p_arms_ahead): (&JointConstraint, (Vec2, Vec2)),
    (q, q_arms): (&JointConstraint, (Vec2, Vec2)),
    bodies: &[SolverBody],
) -> [[f64; 2]; 2] {
    let mut k = [[0.0; 2]; 2];
    let (pa, pb) = p_arms_ahead;
    let (qa, qb) = q_arms;
    for (bp, sp, rp) in [(p.body_a, 1.0, pa), (p.body_b, -1.0, pb)] {
        for (bq, sq, rq) in [(q.body_a, 1.0, qa), (q.body_b, -1.0, qb)] {
            if bp != bq {
                continue;
            }
            let t = &bodies[bp as usize];
            let s = sp * sq;
            k[0][0] += s * (t.inv_mass + t.inv_inertia * rp.y * rq.y);
            k[0][1] += s * (-t.inv_inertia * rp.y * rq.x);
            k[1][0] += s * (-t.inv_inertia * rp.x * rq.y);
            k[1][1] += s * (t.inv_mass + t.inv_inertia * rp.x * rq.x);
        }
    }
    k
}

/// `coupling_block` of one joint with itself: its own 2×2 K.
fn own_block(j: &JointConstraint, bodies: &[SolverBody], ahead: f64) -> [[f64; 2]; 2] {
    let angle = |i: u32| bodies[i as usize].angle;
    let angle_ahead = |i: u32| angle(i) + ahead * bodies[i as usize].angular_velocity;
    let arms_ahead = j.arms((angle_ahead(j.body_a), angle_ahead(j.body_b)));
    let arms_now = j.arms((angle(j.body_a), angle(j.body_b)));
    coupling_block((j, arms_ahead), (j, arms_now), bodies)
}

/// The repair moves bodies by the smallest mass-weighted displacement, with rotations
/// made this much costlier than physics would weigh them. A thin link's small inertia
/// would otherwise let the first-order solve turn links by whole turns to save a little
/// translation, and the Newton steps stall; translations enter the gaps linearly, so a
/// chain or tree closes
/// in one step, and rotation is still used where a closed loop needs it.
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
        let mut start = 0;
        while start < grouped.len() {
            let root = grouped[start].0;
            let end = start
                + grouped[start..]
                    .iter()
                    .take_while(|(r, _)| *r == root)
                    .count();
            self.island.clear();
            self.island
                .extend(grouped[start..end].iter().map(|&(_, i)| joints[i as usize]));
            solve(&mut self.island, bodies);
            for (k, &(_, i)) in grouped[start..end].iter().enumerate() {
                joints[i as usize] = self.island[k];
            }
            start = end;
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

    /// Stage 1 (SPEC eq. 40) for every island: the relative anchor velocities vanish.
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

    /// Stage 6 (SPEC §3.3): motors, then Newton steps on the predicted gaps until every
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
        let pin_island = &mut self.pin_island;
        self.islands.for_each(joints, bodies, |island, bodies| {
            let has_motor = island.iter().any(|j| j.motor.is_some_and(|m| m.enabled));
            let direct = island.len() <= DIRECT_JOINT_LIMIT;
            if !direct {
                if has_motor {
                    drive_motors_continue(island, bodies, dt, 10, !motors_started);
                }
                correct_positions(island, bodies, dt, it);
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
        });
    }
}
