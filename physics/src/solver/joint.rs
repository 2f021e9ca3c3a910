//! Pin (revolute) joints (thesis §2.5, §3.3): the joint and its motor, and a joint as the
//! solvers take it: its anchors, its predicted gap, the impulses that close it one joint
//! at a time, and its blocks of K = J M⁻¹ Jᵀ. The passes over all of them are
//! `joint_block`'s.

use super::SolverBody;
use crate::body::BodyHandle;
use crate::math::{Rot, Vec2};

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
    /// parts overlap around their pins, thesis §3.1).
    pub collide_connected: bool,
    pub motor: Option<JointMotor>,
    /// The relative angle angle_B − angle_A (angle_B = 0 for the world) when the joint was
    /// made: the joint's angle θ counts from it, so that θ = 0 as placed.
    pub reference_angle: f64,
    pub spring: Option<JointSpring>,
    pub limits: Option<JointLimits>,
}

/// Stops on a joint's angle θ: lower ≤ θ ≤ upper; equal, a weld. Solved as inequality
/// rows on the relative spin (an equality row for a weld) in the exact solver's LCPs and
/// its joint passes, and as Box2D v3 solves them in the soft step: a stop ahead lets the
/// joint reach it exactly in the step (speculative); one passed is pushed back at a
/// fifth of the way a step, so that it does not bounce off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    pub lower: f64,
    pub upper: f64,
}

/// The share of a passed stop's overlap the exact solver takes back per step.
const LIMIT_PUSH_BACK: f64 = 0.2;

impl JointLimits {
    pub fn new(lower: f64, upper: f64) -> Self {
        Self { lower, upper }
    }

    pub fn is_weld(&self) -> bool {
        self.lower == self.upper
    }

    /// Both finite, within `crate::limits::ANGLE`, lower ≤ upper.
    pub(crate) fn validate(&self) -> Result<(), super::motor::MotorError> {
        use super::motor::MotorError;
        for (what, value) in [("lower angle", self.lower), ("upper angle", self.upper)] {
            if !value.is_finite() {
                return Err(MotorError::NonFinite(what, value));
            }
            if value.abs() > crate::limits::ANGLE {
                return Err(MotorError::Beyond(what, value, crate::limits::ANGLE));
            }
        }
        if self.lower > self.upper {
            return Err(MotorError::Negative(
                "upper − lower angle",
                self.upper - self.lower,
            ));
        }
        Ok(())
    }

    /// The bounds a step of `dt` puts on s = ω_A − ω_B (the motors' sign; θ grows with
    /// −s) at angle θ: s ≤ the first (the lower stop), s ≥ the second (the upper).
    pub(crate) fn spin_bounds(&self, theta: f64, dt: f64) -> (f64, f64) {
        let room = |c: f64| {
            if c >= 0.0 {
                c / dt
            } else {
                LIMIT_PUSH_BACK * c / dt
            }
        };
        (room(theta - self.lower), -room(self.upper - theta))
    }
}

/// A rotational spring-damper across a joint: torque on body B
/// −stiffness·(θ − rest_angle) − damping·(ω_B − ω_A), the opposite on A.
///
/// The step applies it as a torque pair before the constraints are solved: explicitly in
/// its stiffness where the step resolves the spring ((ω h)² ≤ 1 for the pair's ω² =
/// stiffness·(1/I_A + 1/I_B)): symplectic, so an undamped spring keeps its energy and its
/// period; implicitly beyond that, so that a spring however stiff stays stable (it then
/// loses energy it cannot show). Damping is always implicit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSpring {
    /// Torque per radian, ≥ 0.
    pub stiffness: f64,
    /// Torque per rad/s, ≥ 0.
    pub damping: f64,
    pub rest_angle: f64,
}

impl JointSpring {
    pub fn new(stiffness: f64, damping: f64, rest_angle: f64) -> Self {
        Self {
            stiffness,
            damping,
            rest_angle,
        }
    }

    /// The angular impulse the spring puts on body B over a step of `dt` (−it on A),
    /// given the joint's angle θ, the relative spin ω_B − ω_A and the pair's summed
    /// inverse inertia, as a kick before the drift: explicit in the stiffness where the
    /// step resolves the spring ((ω h)² ≤ 1), so symplectic; implicit beyond (β = 1).
    pub(crate) fn impulse(&self, theta: f64, relative_spin: f64, inv_inertia: f64, dt: f64) -> f64 {
        let (k, c, m) = (self.stiffness, self.damping, inv_inertia);
        if m <= 0.0 {
            return 0.0;
        }
        let share = if dt * dt * k * m <= 1.0 { 0.0 } else { 1.0 };
        // ω' = ω + m·J with J = −dt·(k·(θ − rest + β·h·ω') + c·ω'), solved for ω'.
        let spin_after = (relative_spin - m * dt * k * (theta - self.rest_angle))
            / (1.0 + m * dt * (c + share * dt * k));
        (spin_after - relative_spin) / m
    }

    /// Both numbers finite, non-negative and within `crate::limits`, the rest angle finite.
    pub(crate) fn validate(&self) -> Result<(), super::motor::MotorError> {
        use super::motor::MotorError;
        for (what, value) in [
            ("stiffness", self.stiffness),
            ("damping", self.damping),
            ("rest angle", self.rest_angle),
        ] {
            if !value.is_finite() {
                return Err(MotorError::NonFinite(what, value));
            }
        }
        for (what, value) in [("stiffness", self.stiffness), ("damping", self.damping)] {
            if value < 0.0 {
                return Err(MotorError::Negative(what, value));
            }
        }
        let numbers = [
            ("stiffness", self.stiffness, crate::limits::TORQUE),
            ("damping", self.damping, crate::limits::TORQUE),
            ("rest angle", self.rest_angle, crate::limits::ANGLE),
        ];
        if let Some((what, value, limit)) = crate::limits::first_beyond(numbers) {
            return Err(MotorError::Beyond(what, value, limit));
        }
        Ok(())
    }
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
    /// The joint's stops, and θ's offset: θ = angle_B − angle_A − reference_angle.
    pub limits: Option<JointLimits>,
    pub reference_angle: f64,
    /// The impulses the stops have put on s = ω_A − ω_B this step (lower, upper).
    pub limit_impulse: (f64, f64),
    /// The predicted gap this step's position pass aims for: zero, unless the joint is
    /// broken wider than one step may close (see [`JointIterations::max_closing`]).
    pub gap_target: Vec2,
    /// The impulse the pin has put on body A (−it on B) since the joint was gathered: the
    /// world sums it over a step's passes into the pin's reaction.
    pub impulse: Vec2,
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
    /// A servo: drives the joint's angle θ (see [`Joint::reference_angle`]) to this, at no
    /// more than |target_speed| and with at most `max_torque`, and holds it there. Each
    /// step the world asks for the relative spin that reaches the target by the step's
    /// end, (target − θ)/h, capped at |target_speed| (`drive_speed`).
    pub target_angle: Option<f64>,
    /// The servo's spin for this step (ω_A − ω_B, as `target_speed`): the world sets it
    /// at the start of every step; what is written here is overwritten.
    pub servo_speed: f64,
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
        if let Some(angle) = self.target_angle
            && !angle.is_finite()
        {
            return Err(MotorError::NonFinite("target angle", angle));
        }
        let numbers = [
            ("target speed", self.target_speed, crate::limits::SPIN),
            ("max torque", self.max_torque, crate::limits::TORQUE),
            (
                "target angle",
                self.target_angle.unwrap_or(0.0),
                crate::limits::ANGLE,
            ),
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
            target_angle: None,
            servo_speed: 0.0,
        }
    }

    /// A servo to `target_angle` (radians of θ) at no more than `max_speed` (rad/s).
    pub fn servo(target_angle: f64, max_speed: f64, max_torque: f64) -> Self {
        Self {
            target_angle: Some(target_angle),
            ..Self::new(max_speed.abs(), max_torque)
        }
    }

    /// The relative spin ω_A − ω_B the solvers drive this step: `target_speed`, or a
    /// servo's speed towards its angle.
    pub fn drive_speed(&self) -> f64 {
        match self.target_angle {
            Some(_) => self.servo_speed,
            None => self.target_speed,
        }
    }

    /// Sets a servo's speed for a step of `dt` at joint angle `theta`: the spin that
    /// reaches the target by the step's end, within ±|target_speed|. θ grows with
    /// ω_B − ω_A, the negative of what the motor drives.
    pub(crate) fn aim(&mut self, theta: f64, dt: f64) {
        if let Some(target) = self.target_angle {
            let cap = self.target_speed.abs();
            self.servo_speed = -((target - theta) / dt).clamp(-cap, cap);
        }
    }
}

/// How hard the joint passes iterate (thesis §3.3 Rec: Gauss–Seidel with a tolerance and a cap).
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

/// The 2×2 matrix K of thesis eq. 39: the anchors' relative velocity change per unit impulse.
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
pub(super) fn solve_2x2(k: [[f64; 2]; 2], rhs: Vec2) -> Option<Vec2> {
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

    /// Removes the anchors' relative velocity (thesis eq. 40). Returns |d_v| before.
    pub(super) fn correct_velocity(&mut self, bodies: &mut [SolverBody]) -> f64 {
        let (ia, ib) = (self.body_a as usize, self.body_b as usize);
        let (r_a, r_b) = self.arms((bodies[ia].angle, bodies[ib].angle));
        let (a, b) = (&bodies[ia], &bodies[ib]);
        let d_v = a.velocity_at(a.position + r_a) - b.velocity_at(b.position + r_b);
        let k = effective_mass_matrix(a, r_a, b, r_b);
        if let Some(psi) = solve_2x2(k, -d_v) {
            let (pa, pb) = (bodies[ia].position + r_a, bodies[ib].position + r_b);
            bodies[ia].apply_impulse(psi, pa);
            bodies[ib].apply_impulse(-psi, pb);
            self.impulse += psi;
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

    /// One Newton step on the predicted gap (thesis eq. 34–39). Returns |d| before.
    pub(super) fn correct_position(&mut self, bodies: &mut [SolverBody], dt: f64) -> f64 {
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
            self.impulse += psi;
        }
        d.norm()
    }
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
/// (the thesis method, thesis §3.3), held where it is for a broken one, which only the
/// position repair closes.
pub(crate) fn velocity_gap_target(gap_now: Vec2, broken_gap: f64) -> Vec2 {
    if gap_now.norm() > broken_gap {
        gap_now
    } else {
        Vec2::zeros()
    }
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
pub(super) fn own_block(j: &JointConstraint, bodies: &[SolverBody], ahead: f64) -> [[f64; 2]; 2] {
    let angle = |i: u32| bodies[i as usize].angle;
    let angle_ahead = |i: u32| angle(i) + ahead * bodies[i as usize].angular_velocity;
    let arms_ahead = j.arms((angle_ahead(j.body_a), angle_ahead(j.body_b)));
    let arms_now = j.arms((angle(j.body_a), angle(j.body_b)));
    coupling_block((j, arms_ahead), (j, arms_now), bodies)
}
