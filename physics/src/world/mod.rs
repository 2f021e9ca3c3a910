//! The world and its step: a list of named stages (thesis §3.4). This module holds the
//! world's storage and API and the step's outer stages (`advance`); the solver's stage
//! list runs in between, `impulses` or `soft_step` (both, under `auto`), and each
//! stage's work is in the module named for it.

mod auto;
mod body_sets;
mod bounds;
mod candidates;
mod contacts;
mod continuous;
mod impulses;
mod integrate;
pub(crate) mod settings;
mod sleeping;
mod soft_step;
mod solver_bodies;

use settings::{Integrator, StepSettings};

use auto::{AutoMemory, AutoScratch};
use body_sets::{BodySets, EpochSeen};
use bounds::BodyBounds;
use candidates::{CandidateScratch, KeptPairs};
use continuous::{ContinuousScratch, Obstacles};
use sleeping::SleepScratch;
use solver_bodies::{GapTargets, SolverInputs};

use crate::body::{Body, BodyDef, BodyError, BodyHandle};
use crate::collide::reuse::ManifoldCache;
use crate::collide::{Manifold, PairSet};
use crate::math::Vec2;
use crate::solver::StageList;
use crate::solver::contact::Contact;
use crate::solver::exact::SimultaneousSolver;
use crate::solver::exact::joint_block::JointBlockSolver;
use crate::solver::impacts::ImpactPass;
use crate::solver::joint::{
    Joint, JointConstraint, JointHandle, JointLimits, JointMotor, JointSpring,
};
use crate::solver::motor::{BodyMotor, MotorError};
use crate::solver::report::{IslandReport, StepStats};
use crate::solver::soft::SoftStepSolver;
use crate::stage_clock::{self, Stage, StepProfile};

/// A joint to be made: the bodies and the shared world point they pin together, given
/// to [`World::add_joint`]. The two bodies turn freely about the pin unless a
/// [`JointMotor`] drives them, and do not collide with each other unless
/// `collide_connected` (a robot's parts overlap around their pins).
///
/// A wheel pinned to the world at its centre and driven by a motor at 2 rad/s, with an arm
/// pinned to its rim:
///
/// ```
/// use pe::{BodyDef, ConvexPolygon, JointDef, JointMotor, Vec2, World};
///
/// let mut world = World::new(Vec2::new(0.0, 9.81));
/// let wheel = ConvexPolygon::regular(12, 0.5).unwrap();
/// let wheel = world.add_body(BodyDef::new(wheel, 1.0)).unwrap();
/// let arm = ConvexPolygon::rectangle(1.0, 0.2).unwrap();
/// let arm = world.add_body(BodyDef::new(arm, 1.0).at(Vec2::new(0.5, 0.0), 0.0)).unwrap();
///
/// let mut axle = JointDef::new(wheel, None, Vec2::zeros());
/// axle.motor = Some(JointMotor::new(2.0, 1000.0)); // target rad/s, most torque
/// world.add_joint(axle).unwrap();
/// let elbow = world.add_joint(JointDef::new(arm, Some(wheel), Vec2::new(0.5, 0.0))).unwrap();
/// for _ in 0..60 {
///     world.step(1.0 / 60.0);
/// }
/// let spin = world.body(wheel).unwrap().angular_velocity;
/// assert!((spin - 2.0).abs() < 1e-6, "the motor holds its speed: {spin}");
/// assert!(world.joint_gap(elbow).unwrap() < 1e-3, "the arm stays on the rim");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointDef {
    pub body_a: BodyHandle,
    /// `None` pins body A to the static world.
    pub body_b: Option<BodyHandle>,
    /// The pin, in world coordinates at the bodies' current placement.
    pub anchor: Vec2,
    pub collide_connected: bool,
    pub motor: Option<JointMotor>,
    pub spring: Option<JointSpring>,
    pub limits: Option<JointLimits>,
}

impl JointDef {
    /// Pins `body_a` to `body_b` (`None`: the static world) at the world point `anchor`,
    /// with no motor, the two not colliding.
    pub fn new(body_a: BodyHandle, body_b: Option<BodyHandle>, anchor: Vec2) -> Self {
        Self {
            body_a,
            body_b,
            anchor,
            collide_connected: false,
            motor: None,
            spring: None,
            limits: None,
        }
    }
}

/// Why a joint cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointError {
    #[error("the joint refers to a body that does not exist")]
    MissingBody,
    #[error("there is no such joint")]
    MissingJoint,
    #[error("a joint needs two different bodies")]
    SameBody,
    #[error("the joint anchor is not a finite point")]
    NonFiniteAnchor,
    #[error("the joint anchor coordinate {0:e} is beyond ±{1:e}")]
    AnchorBeyond(f64, f64),
    #[error("joint {0}")]
    BadMotor(MotorError),
}

/// Why a step was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    #[error("the time step must be a finite number > 0, got {0}")]
    BadTimeStep(f64),
    #[error("gravity must be finite and within ±{max:e} per axis, got ({0}, {1})", max = crate::limits::GRAVITY)]
    BadGravity(f64, f64),
    #[error("the world's friction must be a number in [0, 1e6], got {0}")]
    BadFriction(f64),
    /// A setting of `StepSettings` out of its range.
    #[error("the setting {what} must be {range}, got {value}")]
    BadSetting {
        what: &'static str,
        value: f64,
        range: &'static str,
    },
    /// A body given a number beyond `crate::limits` (or not a number) through
    /// `World::body_mut`: refused before stepping, the world untouched.
    #[error("body {body}'s {what} is {value:.3e}, beyond ±{limit:e} (or not a number)")]
    BadBody {
        body: u32,
        what: &'static str,
        value: f64,
        limit: f64,
    },
    /// A joint motor given numbers it cannot have through `World::joint_motor_mut`.
    #[error("joint {joint}'s {error}")]
    BadJointMotor { joint: u32, error: MotorError },
    #[error(
        "gravity carries a body {fall:e} from rest in one step, more than {limit:e} ({FALL_PER_STEP} length scales): bodies would fall through each other; take a smaller step"
    )]
    FallsTooFar { fall: f64, limit: f64 },
    /// A joint motor asks for more than half a turn a step (`limits::ANGULAR`), which no
    /// step can show nor any solver follow.
    #[error(
        "joint {joint}'s motor asks for {speed:e} rad/s, {turn:.3e} rad a step at this step: more than half a turn (π) a step"
    )]
    MotorTooFast { joint: u32, speed: f64, turn: f64 },
    /// The step tore a pin open wider than twice the length scale: a force, a motor or a
    /// collision the step cannot follow. The world's state is not to be trusted.
    #[error(
        "joint {joint} was torn {gap:.3e} apart in one step (more than {limit:.3e}, twice the length scale): a force or motor faster than the step can follow"
    )]
    PinTorn { joint: u32, gap: f64, limit: f64 },
    /// The step ended with a body's state non-finite or beyond `crate::limits` (an
    /// absurd force, a collapse no solver can hold): the world's state is not to be
    /// trusted, and further steps are pointless.
    #[error("body {body} left the limits: its {what} is {value:.3e} (at most ±{limit:e})")]
    StateBeyond {
        body: u32,
        what: &'static str,
        value: f64,
        limit: f64,
    },
}

/// The farthest gravity may carry a body from rest in one step (g·h²), in length scales:
/// beyond it bodies fall through each other between two contact searches (the sequential
/// solver let a box through a floor twice its size from 37 length scales a step; every
/// other solver holds at any gravity within `limits::GRAVITY`).
pub const FALL_PER_STEP: f64 = 10.0;

/// A 2D world of rigid convex bodies, pin joints and motors: bodies are added from a
/// [`BodyDef`], joints from a [`JointDef`], and [`World::step`] advances them all. The
/// world has no up: gravity is a vector, and with y pointing down (as on a screen) it is
/// `(0, 9.81)`. Handles index the world's bodies and joints and are never reused.
///
/// A pendulum: a 2 m bar pinned to the static world at one end swings down, its centre
/// kept 1 m from the pin.
///
/// ```
/// use pe::{BodyDef, ConvexPolygon, JointDef, Vec2, World};
///
/// let mut world = World::new(Vec2::new(0.0, 9.81));
/// let bar = ConvexPolygon::rectangle(2.0, 0.1).unwrap();
/// // The bar lies along +x from the pin at the origin.
/// let bar = world.add_body(BodyDef::new(bar, 1.0).at(Vec2::new(1.0, 0.0), 0.0)).unwrap();
/// let pin = world.add_joint(JointDef::new(bar, None, Vec2::zeros())).unwrap();
/// for _ in 0..30 {
///     world.step(1.0 / 60.0);
/// }
/// let centre = world.body(bar).unwrap().position;
/// assert!(centre.y > 0.5, "it swung down: {centre:?}");
/// assert!((centre.norm() - 1.0).abs() < 1e-3, "the pin holds: {centre:?}");
/// assert!(world.joint_gap(pin).unwrap() < 1e-3);
/// ```
#[derive(Debug, Clone, Default)]
pub struct World {
    bodies: Vec<Option<Body>>,
    /// The bodies' slots sorted into static, sleeping and awake.
    sets: BodySets,
    pub gravity: Vec2,
    /// Friction coefficient for contacts whose bodies set none (the scene's `friction`).
    pub friction: f64,
    pub settings: StepSettings,
    step_count: u64,
    joints: Vec<Option<Joint>>,
    /// Body pairs `(i, j)`, `i < j`, that a joint or `ignore_collisions` keeps from
    /// colliding.
    non_colliding: PairSet,
    /// Bodies with at least one joint, sorted.
    jointed: Vec<u32>,
    /// The joints with a motor, by slot, increasing (made with `jointed`).
    motor_joints: Vec<u32>,
    /// The joints with a spring, by slot, increasing (made with `jointed`).
    spring_joints: Vec<u32>,
    /// The joints or ignored pairs changed since `non_colliding` and `jointed` were built:
    /// they are rebuilt once at the next step, not at every change (a sort per
    /// `add_joint` makes building a scene of many pins quadratic).
    collision_filter_stale: bool,
    /// Pairs kept apart by [`World::ignore_collisions`], besides the jointed ones.
    ignored_pairs: Vec<(u32, u32)>,
    body_motors: Vec<(BodyHandle, BodyMotor)>,
    /// Some body was handed out by `body_mut` since the last step: every body's numbers
    /// are checked before the next one.
    bodies_handed_out: bool,
    manifolds: Vec<Manifold>,
    /// Each pipeline's manifolds kept for reuse (see `Pipeline`).
    manifold_caches: [ManifoldCache; 2],
    contacts: Vec<Contact>,
    /// Per body: the island it fell asleep with (woken together).
    sleep_labels: Vec<u32>,
    /// What `auto` keeps from step to step.
    auto: AutoMemory,
    /// The substeps the pins' pull asked for in the last step of the impulse stage list
    /// and of the soft step (`World::substeps_for_tension`): the next step starts there.
    tension_substeps: usize,
    soft_tension_substeps: usize,
    /// The soft step's substeps, held (`soft_step::HeldSubsteps`).
    soft_substeps_held: soft_step::HeldSubsteps,
    /// The world's own counts of `StepStats` (the soft step keeps its own).
    stats: StepStats,
    /// The ticks each stage of the last step took (`World::profile`).
    profile: StepProfile,
    /// Each body's outline, pose, reach and bounds for the step.
    bounds: BodyBounds,
    /// The bodies as the solvers take them, with their accelerations and the velocities
    /// the step started with.
    inputs: SolverInputs,
    /// The static bodies as continuous collision's obstacles.
    obstacles: Obstacles,
    /// When every body's forces were last cleared (`clear_forces`).
    forces_cleared: EpochSeen,
    /// The broad phase's pairs, kept while they hold.
    kept_pairs: KeptPairs,
    /// The solvers, with what they keep from step to step: warm starts, factors, plans and
    /// the islands' reports.
    solvers: Solvers,
    scratch: Scratch,
}

/// The two stage lists of a step: impulses (`sequential`, `thesis`, `exact`) and the soft
/// step. Under `auto` both run in one step on different islands, each finding its own
/// contacts, so each keeps its own manifolds for reuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pipeline {
    Impulses = 0,
    Soft = 1,
}

/// The solvers a world steps with, each keeping its memory between steps.
#[derive(Debug, Clone, Default)]
struct Solvers {
    /// The pins' passes of the impulse stage list (`sequential`, `thesis`, `exact`).
    joints: JointBlockSolver,
    /// The islands' LCPs of `thesis` and `exact`.
    exact: SimultaneousSolver,
    /// The impact pass, before `exact`'s islands' LCPs and before the soft step.
    impacts: ImpactPass,
    soft: SoftStepSolver,
    /// When the soft solver last loaded the static and sleeping bodies.
    soft_seen: EpochSeen,
}

/// Buffers reused from step to step so that stepping does not allocate: the step's
/// candidate pairs and the solvers' joint rows, which several stages read, and each
/// stage's own buffers.
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// The step's candidate pairs (`find_candidate_pairs`).
    pairs: Vec<(u32, u32)>,
    /// `pairs` (and outlines, reaches, poses) are those of the bodies as they are now, for
    /// the next contact detection at the same step length: set by `auto` only.
    candidates_current: bool,
    candidates: CandidateScratch,
    /// This step's manifolds' gaps less what their bodies can close of them, and how far
    /// a collision may turn each body off its course (`drop_idle_manifolds`).
    gaps: Vec<f64>,
    turn_off: Vec<f64>,
    /// Poses and velocities at the start of the step, to redo it with finer substeps.
    saved_state: Vec<(Vec2, f64, Vec2, f64)>,
    /// Each body's pose when the step began, by slot (`World::check_pins_held`).
    poses_before: Vec<(Vec2, f64)>,
    joint_constraints: Vec<JointConstraint>,
    /// Each joint's impulse on body A so far this step, by joint slot (what its
    /// `JointConstraint::impulse` gathered in each pass), and each body's stiffness from
    /// its pins' pull (`World::substeps_for_tension`).
    pin_impulses: Vec<Vec2>,
    pull_stiffness: Vec<(f64, u32)>,
    sleeping: SleepScratch,
    continuous: ContinuousScratch,
    auto: AutoScratch,
}

impl World {
    pub fn new(gravity: Vec2) -> Self {
        Self {
            gravity,
            ..Self::default()
        }
    }

    pub fn add_body(&mut self, def: BodyDef) -> Result<BodyHandle, BodyError> {
        let body = Body::new(def)?;
        self.bodies.push(Some(body));
        self.sets.mark_changed();
        Ok(BodyHandle((self.bodies.len() - 1) as u32))
    }

    /// Removes a body and the joints attached to it (a pin to nothing holds nothing);
    /// its handle, and theirs, then find nothing, and its body motors act on nothing.
    /// Returns the body if it existed.
    pub fn remove_body(&mut self, handle: BodyHandle) -> Option<Body> {
        let body = self.bodies.get_mut(handle.index())?.take()?;
        self.sets.mark_changed();
        for joint in &mut self.joints {
            if joint
                .as_ref()
                .is_some_and(|j| j.body_a == handle || j.body_b == Some(handle))
            {
                *joint = None;
                self.collision_filter_stale = true;
            }
        }
        Some(body)
    }

    pub fn body(&self, handle: BodyHandle) -> Option<&Body> {
        self.bodies.get(handle.index())?.as_ref()
    }

    pub fn body_mut(&mut self, handle: BodyHandle) -> Option<&mut Body> {
        let body = self.bodies.get_mut(handle.index())?.as_mut()?;
        // An awake body is looked at again every step; another may now be moved by hand.
        if body.is_static() || body.is_asleep() {
            self.sets.mark_changed();
        }
        // Whatever it is given is checked before the next step.
        self.bodies_handed_out = true;
        Some(body)
    }

    /// The median bounding radius of the bodies that can move (none: `None`): the size of
    /// a typical body, for `StepSettings::length_scale` in a scene not in metres.
    pub fn median_body_radius(&self) -> Option<f64> {
        let mut sizes: Vec<f64> = self
            .bodies()
            .filter(|(_, b)| !b.is_static())
            .map(|(_, b)| b.bounding_radius())
            .collect();
        sizes.sort_by(f64::total_cmp);
        sizes.get(sizes.len() / 2).copied()
    }

    /// Live bodies in handle order.
    pub fn bodies(&self) -> impl Iterator<Item = (BodyHandle, &Body)> {
        self.bodies
            .iter()
            .enumerate()
            .filter_map(|(i, b)| Some((BodyHandle(i as u32), b.as_ref()?)))
    }

    /// Pins two bodies (or one to the world) at `def.anchor`; both body-space anchors are
    /// derived from that point now.
    pub fn add_joint(&mut self, def: JointDef) -> Result<JointHandle, JointError> {
        if !(def.anchor.x.is_finite() && def.anchor.y.is_finite()) {
            return Err(JointError::NonFiniteAnchor);
        }
        let far = def.anchor.x.abs().max(def.anchor.y.abs());
        if far > crate::limits::COORDINATE {
            return Err(JointError::AnchorBeyond(far, crate::limits::COORDINATE));
        }
        if Some(def.body_a) == def.body_b {
            return Err(JointError::SameBody);
        }
        if let Some(m) = &def.motor {
            m.validate().map_err(JointError::BadMotor)?;
        }
        if let Some(s) = &def.spring {
            s.validate().map_err(JointError::BadMotor)?;
        }
        if let Some(l) = &def.limits {
            l.validate().map_err(JointError::BadMotor)?;
        }
        let a = self.body(def.body_a).ok_or(JointError::MissingBody)?;
        let local_anchor_a = a.to_local(def.anchor);
        let angle_a = a.angle;
        let (local_anchor_b, angle_b) = match def.body_b {
            Some(h) => {
                let b = self.body(h).ok_or(JointError::MissingBody)?;
                (b.to_local(def.anchor), b.angle)
            }
            None => (def.anchor, 0.0),
        };
        self.joints.push(Some(Joint {
            body_a: def.body_a,
            body_b: def.body_b,
            local_anchor_a,
            local_anchor_b,
            collide_connected: def.collide_connected,
            motor: def.motor,
            reference_angle: angle_b - angle_a,
            spring: def.spring,
            limits: def.limits,
        }));
        self.collision_filter_stale = true;
        Ok(JointHandle((self.joints.len() - 1) as u32))
    }

    pub fn remove_joint(&mut self, handle: JointHandle) -> Option<Joint> {
        let removed = self.joints.get_mut(handle.index())?.take();
        self.collision_filter_stale = true;
        removed
    }

    pub fn joint(&self, handle: JointHandle) -> Option<&Joint> {
        self.joints.get(handle.index())?.as_ref()
    }

    /// Whether a joint's two bodies collide with each other; `None` if there is no such
    /// joint. A joint's bodies and anchors are fixed when it is made (`add_joint` checks
    /// them): to join other bodies, remove it and add another.
    pub fn set_collide_connected(&mut self, handle: JointHandle, collide: bool) -> Option<()> {
        let joint = self.joints.get_mut(handle.index())?.as_mut()?;
        joint.collide_connected = collide;
        self.collision_filter_stale = true;
        Some(())
    }

    /// Gives a joint a motor, another one, or none (`None`); refused if there is no such
    /// joint or the motor's numbers are ones it may not have.
    pub fn set_joint_motor(
        &mut self,
        handle: JointHandle,
        motor: Option<JointMotor>,
    ) -> Result<(), JointError> {
        if let Some(m) = &motor {
            m.validate().map_err(JointError::BadMotor)?;
        }
        let joint = self
            .joints
            .get_mut(handle.index())
            .and_then(Option::as_mut)
            .ok_or(JointError::MissingJoint)?;
        joint.motor = motor;
        self.collision_filter_stale = true; // the list of motor joints
        Ok(())
    }

    /// A joint's motor to change (switching it on and off, say); its numbers are checked
    /// before the next step (`StepError::BadJointMotor`).
    pub fn joint_motor_mut(&mut self, handle: JointHandle) -> Option<&mut JointMotor> {
        self.joints
            .get_mut(handle.index())?
            .as_mut()?
            .motor
            .as_mut()
    }

    /// Live joints in handle order.
    pub fn joints(&self) -> impl Iterator<Item = (JointHandle, &Joint)> {
        self.joints
            .iter()
            .enumerate()
            .filter_map(|(i, j)| Some((JointHandle(i as u32), j.as_ref()?)))
    }

    /// World positions of a joint's two anchors (equal while the joint holds).
    pub fn joint_anchors(&self, handle: JointHandle) -> Option<(Vec2, Vec2)> {
        let j = self.joint(handle)?;
        let a = self.body(j.body_a)?.to_world(j.local_anchor_a);
        let b = match j.body_b {
            Some(h) => self.body(h)?.to_world(j.local_anchor_b),
            None => j.local_anchor_b,
        };
        Some((a, b))
    }

    /// Distance between a joint's anchors.
    pub fn joint_gap(&self, handle: JointHandle) -> Option<f64> {
        self.joint_anchors(handle).map(|(a, b)| (a - b).norm())
    }

    /// The widest gap of any joint.
    pub fn max_joint_gap(&self) -> f64 {
        self.joints()
            .filter_map(|(h, _)| self.joint_gap(h))
            .fold(0.0, f64::max)
    }

    /// Adds a thesis body motor (thesis §4.4) driving `body`. Returns its index.
    pub fn add_body_motor(
        &mut self,
        body: BodyHandle,
        motor: BodyMotor,
    ) -> Result<usize, MotorError> {
        if self.body(body).is_none() {
            return Err(MotorError::MissingBody);
        }
        motor.validate()?;
        self.body_motors.push((body, motor));
        Ok(self.body_motors.len() - 1)
    }

    pub fn body_motors(&self) -> &[(BodyHandle, BodyMotor)] {
        &self.body_motors
    }

    /// Bodies `a` and `b` never collide with each other (e.g. a mechanism's parts that
    /// would lie in different planes, like a linkage and its frame).
    pub fn ignore_collisions(&mut self, a: BodyHandle, b: BodyHandle) {
        if a != b {
            self.ignored_pairs.push((a.0.min(b.0), a.0.max(b.0)));
            self.collision_filter_stale = true;
        }
    }

    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// The manifolds found by the last step.
    pub fn manifolds(&self) -> &[Manifold] {
        &self.manifolds
    }

    /// The contact points of the last step with the impulses the solver gave them.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    pub fn kinetic_energy(&self) -> f64 {
        self.bodies().map(|(_, b)| b.kinetic_energy()).sum()
    }

    /// Potential energy: in the uniform gravity field (zero at the world origin), and in
    /// the joint springs (½·k·(θ − rest)² each).
    pub fn potential_energy(&self) -> f64 {
        let gravity: f64 = self
            .bodies()
            .map(|(_, b)| -b.mass() * self.gravity.dot(&b.position))
            .sum();
        let springs = (0..self.joints.len() as u32).filter_map(|k| {
            let spring = self.joints[k as usize]?.spring?;
            let stretch = self.joint_angle(JointHandle(k))? - spring.rest_angle;
            Some(0.5 * spring.stiffness * stretch * stretch)
        });
        springs.fold(gravity, |sum, e| sum + e)
    }

    pub fn linear_momentum(&self) -> Vec2 {
        self.bodies().map(|(_, b)| b.velocity * b.mass()).sum()
    }

    pub fn angular_momentum(&self) -> f64 {
        self.bodies().map(|(_, b)| b.angular_momentum()).sum()
    }

    /// Advances the world by `dt`: thesis §3.4's stages, in order.
    ///
    /// With `settings.sleeping`, an island (bodies linked by contacts and joints) whose
    /// bodies have all been slower than `sleep_speed` for `SLEEP_AFTER` seconds, with no
    /// motor running, goes to sleep: it is skipped until an awake body comes within reach
    /// of one of its bodies, a motor on it switches on, or `wake_body` is called.
    ///
    /// With `settings.continuous`, a body that moved more than half its inner radius (or,
    /// without joints, the contact margin) this step and ended up through a static body
    /// it collides with, or deeper than twice the slop in it, is put back along its path
    /// to where it first came within the slop of it (its time of impact) or, if it
    /// started in contact, to where it was twice the slop deep. It keeps its velocity for
    /// the next step's contacts to answer. A jointed body takes its joint island with it,
    /// each body to the same fraction of its path. Speculative contacts stop most fast
    /// bodies already; this catches what they miss (a spinning body, the soft step's
    /// contacts found only at the step's start, a link the thesis's joint pass drags on).
    ///
    /// A step refused by `try_step` does nothing; one that leaves a body's state beyond
    /// the limits is reported there, and here ignored.
    ///
    /// A box dropped onto a static floor comes to rest on it:
    ///
    /// ```
    /// use pe::{BodyDef, ConvexPolygon, Vec2, World};
    ///
    /// let mut world = World::new(Vec2::new(0.0, 9.81)); // y points down
    /// let floor = ConvexPolygon::rectangle(10.0, 1.0).unwrap(); // its top at y = 0
    /// world.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0)).unwrap();
    /// let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    /// let dropped = BodyDef::new(square, 1.0).at(Vec2::new(0.0, -2.0), 0.0);
    /// let square = world.add_body(dropped).unwrap();
    /// for _ in 0..120 {
    ///     world.step(1.0 / 60.0);
    /// }
    /// let body = world.body(square).unwrap();
    /// assert!((body.position.y + 0.5).abs() < 0.01, "on the floor: {:?}", body.position);
    /// assert!(body.velocity.norm() < 1e-3, "at rest: {:?}", body.velocity);
    /// assert_eq!(world.contacts().len(), 2, "touching along its bottom edge");
    /// ```
    pub fn step(&mut self, dt: f64) {
        let _refused = self.try_step(dt);
    }

    /// `step`, refusing a time step that is not finite and positive, gravity or a world
    /// friction (≥ 0) that is not finite or beyond its limit in `crate::limits`, or gravity
    /// that would carry a body more than `FALL_PER_STEP` length scales in the step, with
    /// the reason; and reporting a step that left a moving body's state non-finite or
    /// beyond the limits (then the state is not to be trusted). (Bodies, joints and motors
    /// are checked when they are added.)
    ///
    /// ```
    /// use pe::{StepError, Vec2, World};
    ///
    /// let mut world = World::new(Vec2::new(0.0, 9.81));
    /// assert_eq!(world.try_step(0.0), Err(StepError::BadTimeStep(0.0)));
    /// assert_eq!(world.step_count(), 0, "a refused step does nothing");
    /// assert_eq!(world.try_step(1.0 / 60.0), Ok(()));
    /// assert_eq!(world.step_count(), 1);
    /// ```
    pub fn try_step(&mut self, dt: f64) -> Result<(), StepError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(StepError::BadTimeStep(dt));
        }
        let g = crate::limits::GRAVITY;
        if !(self.gravity.x.abs() <= g && self.gravity.y.abs() <= g) {
            return Err(StepError::BadGravity(self.gravity.x, self.gravity.y));
        }
        if !(0.0..=crate::limits::FRICTION).contains(&self.friction) {
            return Err(StepError::BadFriction(self.friction));
        }
        self.settings.check()?;
        let fall = self.gravity.norm() * dt * dt;
        let limit = FALL_PER_STEP * self.settings.length_scale;
        if fall > limit {
            return Err(StepError::FallsTooFar { fall, limit });
        }
        self.check_motor_speeds(dt)?;
        // The joint lists (motors, springs) as the joints are now, before anything reads
        // them this step.
        self.refresh_collision_filter();
        self.aim_servos(dt);
        if self.bodies_handed_out {
            self.check_bodies_given()?;
            self.bodies_handed_out = false;
        }
        let has_joints = self.joints.iter().any(Option::is_some);
        if has_joints {
            let poses = &mut self.scratch.poses_before;
            poses.clear();
            poses.extend(self.bodies.iter().map(|b| {
                b.as_ref()
                    .map_or((Vec2::zeros(), 0.0), |b| (b.position, b.angle))
            }));
        }
        self.profile = StepProfile::default();
        let started = stage_clock::mark();
        self.advance(dt);
        self.profile.take_from(&mut self.solvers.soft.profile);
        self.profile.record(Stage::Step, started);
        if has_joints {
            self.check_pins_held()?;
        }
        self.check_state()
    }

    /// A joint's angle θ: (angle_B − angle_A) less the same difference as the joint was
    /// made (angle_B = 0 for the world), so θ = 0 as placed and grows with ω_B − ω_A.
    pub fn joint_angle(&self, handle: JointHandle) -> Option<f64> {
        let j = self.joint(handle)?;
        let angle_a = self.body(j.body_a)?.angle;
        let angle_b = match j.body_b {
            Some(h) => self.body(h)?.angle,
            None => 0.0,
        };
        Some(angle_b - angle_a - j.reference_angle)
    }

    /// Each servo's speed for this step, from its joint's angle now.
    fn aim_servos(&mut self, dt: f64) {
        for i in 0..self.motor_joints.len() {
            let k = self.motor_joints[i] as usize;
            let servo = self.joints[k]
                .as_ref()
                .is_some_and(|j| j.motor.as_ref().is_some_and(|m| m.target_angle.is_some()));
            if !servo {
                continue;
            }
            let theta = self.joint_angle(JointHandle(k as u32));
            if let (Some(theta), Some(Some(j))) = (theta, self.joints.get_mut(k))
                && let Some(m) = j.motor.as_mut()
            {
                m.aim(theta, dt);
            }
        }
    }

    /// Every joint motor's numbers are ones it may have, and every enabled one asks for
    /// at most half a turn a step.
    fn check_motor_speeds(&self, dt: f64) -> Result<(), StepError> {
        for (k, joint) in self.joints.iter().enumerate() {
            let Some(m) = joint.and_then(|j| j.motor) else {
                continue;
            };
            m.validate().map_err(|error| StepError::BadJointMotor {
                joint: k as u32,
                error,
            })?;
            if !m.enabled {
                continue;
            }
            let turn = m.target_speed * dt;
            if turn.abs() > crate::limits::ANGULAR {
                return Err(StepError::MotorTooFast {
                    joint: k as u32,
                    speed: m.target_speed,
                    turn,
                });
            }
        }
        Ok(())
    }

    /// No pin was torn wider than twice the length scale by the step (`StepError::PinTorn`);
    /// one that was that wide before it (a robot placed with its pins apart, being
    /// repaired) only may not widen. A pin's gap grows in a step by no more than its two
    /// bodies moved (their centroids' paths and their turns at their bounding radii): where
    /// no body moved half a length scale, no pin can have been torn, and none is measured
    /// (a net of 19,800 pins would otherwise turn 10,000 bodies' anchors every step).
    fn check_pins_held(&self) -> Result<(), StepError> {
        let limit = 2.0 * self.settings.length_scale;
        let poses = &self.scratch.poses_before;
        let moved = |slot: usize| -> f64 {
            match (
                self.bodies.get(slot).and_then(Option::as_ref),
                poses.get(slot),
            ) {
                (Some(b), Some(&(p, a))) => {
                    (b.position - p).norm() + (b.angle - a).abs() * b.bounding_radius()
                }
                _ => 0.0,
            }
        };
        let farthest = (0..self.bodies.len()).map(moved).fold(0.0, f64::max);
        if farthest <= 0.25 * limit && !farthest.is_nan() {
            return Ok(());
        }
        let anchor_before = |handle: BodyHandle, local: Vec2| -> Option<Vec2> {
            let &(p, a) = poses.get(handle.index())?;
            Some(p + crate::math::Rot::new(a).apply(local))
        };
        for (k, joint) in self.joints.iter().enumerate() {
            let Some(j) = joint else { continue };
            let Some(gap) = self.joint_gap(JointHandle(k as u32)) else {
                continue;
            };
            let before_a = anchor_before(j.body_a, j.local_anchor_a);
            let before_b = match j.body_b {
                Some(h) => anchor_before(h, j.local_anchor_b),
                None => Some(j.local_anchor_b),
            };
            let before = match (before_a, before_b) {
                (Some(a), Some(b)) => (a - b).norm(),
                _ => 0.0,
            };
            if gap > limit && gap > before || gap.is_nan() {
                return Err(StepError::PinTorn {
                    joint: k as u32,
                    gap,
                    limit,
                });
            }
        }
        Ok(())
    }

    /// Every body's numbers, as `body_mut` may have set them, within `crate::limits`: what
    /// `Body::new` checks of a new body, and the forces.
    fn check_bodies_given(&self) -> Result<(), StepError> {
        use crate::limits::{ANGLE, COORDINATE, FORCE, FRICTION, SPEED, SPIN};
        for (handle, b) in self.bodies() {
            let numbers = [
                ("x", b.position.x, COORDINATE),
                ("y", b.position.y, COORDINATE),
                ("angle", b.angle, ANGLE),
                ("speed", b.velocity.norm(), SPEED),
                ("spin", b.angular_velocity, SPIN),
                ("force", b.force.norm(), FORCE),
                ("torque", b.torque, FORCE),
                ("friction", b.friction.unwrap_or(0.0), FRICTION),
            ];
            let beyond = crate::limits::first_beyond(numbers).or_else(|| {
                let bad_restitution = !(0.0..=1.0).contains(&b.restitution);
                bad_restitution.then_some(("restitution", b.restitution, 1.0))
            });
            let negative_friction = b.friction.is_some_and(|mu| mu < 0.0);
            let beyond = beyond.or_else(|| {
                negative_friction.then_some(("friction", b.friction.unwrap_or(0.0), FRICTION))
            });
            if let Some((what, value, limit)) = beyond {
                return Err(StepError::BadBody {
                    body: handle.0,
                    what,
                    value,
                    limit,
                });
            }
        }
        Ok(())
    }

    /// Every moving body's state finite and within `crate::limits`.
    fn check_state(&self) -> Result<(), StepError> {
        use crate::limits::{COORDINATE, SPEED, SPIN};
        for &i in self.sets.awake() {
            let b = self.bodies[i as usize].as_ref().expect("an awake body");
            let numbers = [
                ("x", b.position.x, COORDINATE),
                ("y", b.position.y, COORDINATE),
                ("speed", b.velocity.norm(), SPEED),
                ("spin", b.angular_velocity, SPIN),
            ];
            if let Some((what, value, limit)) = crate::limits::first_beyond(numbers) {
                return Err(StepError::StateBeyond {
                    body: i,
                    what,
                    value,
                    limit,
                });
            }
        }
        Ok(())
    }

    fn advance(&mut self, dt: f64) {
        self.refresh_collision_filter();
        if self.settings.sleeping {
            self.wake_where_needed(dt);
        }
        self.sets.refresh(&self.bodies);
        if self.settings.continuous {
            // Read for the awake bodies only.
            let start = &mut self.scratch.continuous.step_start;
            start.resize(self.bodies.len(), (Vec2::zeros(), 0.0));
            for &i in self.sets.awake() {
                let b = self.bodies[i as usize].as_ref().expect("an awake body");
                start[i as usize] = (b.position, b.angle);
            }
        }
        self.apply_motor_torques(dt);
        match self.settings.contact_solver.stage_list() {
            StageList::Impulses(method) => self.step_impulses(method, dt),
            StageList::Soft => self.step_soft(dt),
            StageList::Auto => self.step_auto(dt),
        }
        self.clear_forces();
        self.step_count += 1;
        if self.settings.continuous {
            let started = stage_clock::mark();
            self.stop_at_impact(dt);
            self.profile.record(Stage::Continuous, started);
        }
        if self.settings.sleeping {
            self.sleep_where_still(dt);
        } else if !self.sleep_labels.is_empty() {
            // Sleeping was switched off: wake everyone, once.
            self.bodies.iter_mut().flatten().for_each(Body::wake);
            self.sleep_labels.clear();
            self.sets.mark_changed();
        }
        self.sets.refresh(&self.bodies);
    }

    /// The clock's ticks each stage of the last step took: see [`StepProfile`]. Counted
    /// with the feature `stage-clock` only; all zero without it.
    pub fn profile(&self) -> &StepProfile {
        &self.profile
    }

    /// What the steps so far did, counted: see [`StepStats`].
    pub fn stats(&self) -> StepStats {
        let soft = &self.solvers.soft;
        let pins = StepStats {
            soft_pin_factorisations: soft.pin_factorisations(),
            ..StepStats::default()
        };
        self.stats.merged(&soft.stats).merged(&pins)
    }

    /// How each island was solved in the last step: by which method (see
    /// `IslandMethod`), with how many contacts, joints and rows. Under `exact` and
    /// `thesis` the last substep's islands; under `soft` the step's; under `auto` both passes'.
    pub fn island_reports(&self) -> &[IslandReport] {
        match self.settings.contact_solver.stage_list() {
            StageList::Impulses(_) => &self.solvers.exact.reports,
            StageList::Soft => &self.solvers.soft.reports,
            StageList::Auto => &self.auto.reports,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collide::Aabb;
    use crate::shape::ConvexPolygon;
    use crate::solver::ContactSolver;

    /// Every pair of bodies, not both fixed, whose bounds overlap now: what the broad
    /// phase must find, by comparing every pair.
    pub(super) fn overlapping_pairs(world: &World) -> Vec<(u32, u32)> {
        pairs_overlapping(world, &world.bounds.boxes)
    }

    /// The pairs of `boxes` (by slot) that overlap, but for pairs of two bodies fixed in
    /// the pass.
    pub(super) fn pairs_overlapping(world: &World, boxes: &[Option<Aabb>]) -> Vec<(u32, u32)> {
        let n = boxes.len();
        let fixed_in_pass = |i: usize, b: &Body| world.sets.fixed_in_pass(i as u32, b);
        let fixed = |i: usize| world.bodies[i].as_ref().is_none_or(|b| fixed_in_pass(i, b));
        (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .filter(|&(i, j)| !(fixed(i) && fixed(j)))
            .filter(|&(i, j)| match (&boxes[i], &boxes[j]) {
                (Some(a), Some(b)) => a.overlaps(b),
                _ => false,
            })
            .map(|(i, j)| (i as u32, j as u32))
            .collect()
    }

    /// A 10-row pyramid of unit boxes (55, a soft island) on a floor, under `auto`, g = 10.
    pub(super) fn pyramid_under_auto() -> World {
        let mut world = World::new(Vec2::new(0.0, 10.0));
        world.settings.contact_solver = ContactSolver::Auto;
        let floor = ConvexPolygon::rectangle(100.0, 1.0).unwrap();
        world
            .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
            .unwrap();
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for row in 0..10 {
            for i in 0..10 - row {
                let at = Vec2::new(i as f64 - 0.5 * (9 - row) as f64, -0.5 - row as f64);
                world
                    .add_body(BodyDef::new(unit.clone(), 1.0).at(at, 0.0))
                    .unwrap();
            }
        }
        world
    }
}
