//! The world and its step: a list of named stages (SPEC §3.4).

use crate::body::{Body, BodyDef, BodyError, BodyHandle};
use crate::collide::reuse::{ManifoldCache, Pose};
use crate::collide::toi::{Sweep, place, separation, time_of_impact, time_of_sinking};
use crate::collide::{Aabb, BroadPhase, Manifold, PairSet, WorldPolygon, collide_polygons_into};
use crate::math::Vec2;
use crate::solver::contact::{Contact, mixed_friction, restitution_threshold, solve_sequential};
use crate::solver::island::UnionFind;
use crate::solver::joint::{
    Joint, JointBlockSolver, JointConstraint, JointHandle, JointIterations, JointMotor,
    JointSolver, velocity_gap_target,
};
use crate::solver::motor::{BodyMotor, MotorError};
use crate::solver::simultaneous::{FrictionModel, IslandReport, SimultaneousSolver};
use crate::solver::soft::{SoftSettings, SoftStepSolver};
use crate::solver::system::VelocityTargets;
use crate::solver::{ContactSolver, SolverBody};
use crate::stage_clock::{self, Stage};

/// How velocities and positions advance over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Position from the velocity at the start of the step (SPEC §2.1).
    ExplicitEuler,
    /// Velocity first, then position with the new velocity: the thesis's order (SPEC §2.2).
    #[default]
    SemiImplicitEuler,
}

/// Tuning of a world. Lengths scale with `length_scale`, the size of a typical body, so that
/// a scene in pixels behaves like the same scene in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSettings {
    pub integrator: Integrator,
    pub contact_solver: ContactSolver,
    /// A typical body size in the world's length unit (1 for metre-sized bodies).
    pub length_scale: f64,
    pub joint_solver: JointSolver,
    /// Islands with more LCP rows than this are solved iteratively rather than by pivoting.
    pub dense_row_limit: usize,
    /// Whether islands at rest go to sleep (see `World::step`).
    pub sleeping: bool,
    /// Whether a body that ends a step through or deep in a static body is put back to its
    /// time of impact (see `World::step`).
    pub continuous: bool,
    /// Substeps per step of the soft step (`ContactSolver::Soft`); Box2D v3's default, 4.
    pub soft_substeps: usize,
    /// Whether a pair that has barely moved relative to itself keeps its last manifold's
    /// features instead of a new separating-axis test (see `collide::reuse`).
    pub reuse_manifolds: bool,
    /// Whether the soft step sweeps a big island's colours backwards every other pair of
    /// substeps, against the sway that one fixed order builds in a pile (see
    /// `solver::soft::SweepOrder`).
    pub soft_alternating_sweeps: bool,
}

impl Default for StepSettings {
    fn default() -> Self {
        Self {
            integrator: Integrator::default(),
            contact_solver: ContactSolver::default(),
            length_scale: 1.0,
            joint_solver: JointSolver::default(),
            dense_row_limit: crate::solver::simultaneous::DENSE_ROW_LIMIT,
            sleeping: false,
            continuous: true,
            soft_substeps: 4,
            reuse_manifolds: true,
            soft_alternating_sweeps: true,
        }
    }
}

impl StepSettings {
    /// Bodies closer than this count as touching, so resting contacts persist (SPEC §3.1).
    pub(crate) fn contact_margin(&self) -> f64 {
        0.02 * self.length_scale
    }

    /// The broad phase pairs bodies by their bounds grown by this much, and keeps those
    /// pairs while every body's bounds stay inside its grown ones (Box2D's fat bounds,
    /// 0.1 m for its 1 m boxes): a pile at rest is not paired again every step.
    pub(crate) fn broad_phase_margin(&self) -> f64 {
        0.1 * self.length_scale
    }

    /// A body slower than this (at its farthest point) counts as still, for sleeping.
    pub(crate) fn sleep_speed(&self) -> f64 {
        0.05 * self.length_scale
    }

    /// Penetration up to this depth is left alone, so resting contacts stay in touch.
    pub fn slop(&self) -> f64 {
        0.005 * self.length_scale
    }

    /// A pair keeps its manifold while no point of either body has moved relative to the
    /// other by more than this since the manifold was found: a tenth of the slop.
    pub(crate) fn manifold_reuse_tolerance(&self) -> f64 {
        0.1 * self.slop()
    }

    /// A reference face is swapped for the other body's only when better by this much.
    pub(crate) fn tie_tolerance(&self) -> f64 {
        0.001 * self.length_scale
    }

    /// Joint passes stop at a gap of a millionth of a body; the cap bounds the work when a
    /// badly broken joint cannot close in one step.
    pub(crate) fn joint_iterations(&self, dt: f64) -> JointIterations {
        JointIterations {
            position_tolerance: 1e-6 * self.length_scale,
            velocity_tolerance: 1e-6 * self.length_scale / dt,
            max_sweeps: 50,
            max_closing: 0.2 * self.length_scale,
            broken_gap: 0.01 * self.length_scale,
        }
    }
}

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
        }
    }
}

/// Why a joint cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointError {
    #[error("the joint refers to a body that does not exist")]
    MissingBody,
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
    #[error(
        "gravity carries a body {fall:e} from rest in one step, more than {limit:e} ({FALL_PER_STEP} length scales): bodies would fall through each other; take a smaller step"
    )]
    FallsTooFar { fall: f64, limit: f64 },
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

/// Fraction of the excess penetration the split-impulse pass removes per step: all of it
/// at once overshoots in stacks, where pushes add up along the column.
const SPLIT_IMPULSE_RATE: f64 = 0.4;

/// At most this many substeps per step (see `World::substeps_for`).
const MAX_SUBSTEPS: usize = 8;

/// While the broad phase pairs the bodies again every time, every this many pairings use
/// grown bounds, to see whether they hold again (`find_candidate_pairs`).
const RETRY_GROWN_BOUNDS: u32 = 8;

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
    /// The joints or ignored pairs changed since `non_colliding` and `jointed` were built:
    /// they are rebuilt once at the next step, not at every change (a scene of 20,000 pins
    /// took 12 s to build with a sort per `add_joint`).
    collision_filter_stale: bool,
    /// Pairs kept apart by [`World::ignore_collisions`], besides the jointed ones.
    ignored_pairs: Vec<(u32, u32)>,
    body_motors: Vec<(BodyHandle, BodyMotor)>,
    manifolds: Vec<Manifold>,
    /// Each pipeline's manifolds kept for reuse (see `Pipeline`).
    manifold_caches: [ManifoldCache; 2],
    contacts: Vec<Contact>,
    /// Per body: the island it fell asleep with (woken together).
    sleep_labels: Vec<u32>,
    /// Per body: under `auto`, the step until which its island stays on the soft step
    /// (`keep_over_budget_on_soft`).
    soft_until: Vec<u64>,
    scratch: Scratch,
}

/// Whether gathering the joints works out the gap each is to close (`gap_target`): the
/// exact and thesis solvers repair a broken joint over several steps; the soft step
/// pulls every pin closed its own way and never reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GapTargets {
    ForBrokenJoints,
    None,
}

/// The two stage lists of a step: impulses (`sequential`, `thesis`, `exact`) and the soft
/// step. Under `auto` both run in one step on different islands, each finding its own
/// contacts, so each keeps its own manifolds for reuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pipeline {
    Impulses = 0,
    Soft = 1,
}

/// Seconds an island must stay still before it sleeps.
const SLEEP_AFTER: f64 = 0.5;

/// Seconds an island that went over the exact solver's pivot budget stays on the soft
/// step under `auto`.
const SOFT_AFTER_OVER_BUDGET: f64 = 1.0;

/// Buffers reused from step to step so that stepping does not allocate.
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// Islands of bodies, for sleeping and for `auto`'s choice of solver.
    island_union: UnionFind,
    wake_labels: Vec<u32>,
    wake_broad_phase: BroadPhase,
    island_ready: Vec<bool>,
    polygons: Vec<WorldPolygon>,
    poses: Vec<Pose>,
    boxes: Vec<Option<Aabb>>,
    broad_phase: BroadPhase,
    pairs: Vec<(u32, u32)>,
    /// The broad phase's own pairs, by the bounds grown by `broad_phase_margin` (or bare,
    /// while grown ones do not hold), and which bodies were static or asleep then (see
    /// `find_candidate_pairs`; emptied when they no longer stand).
    fat_boxes: Vec<Option<Aabb>>,
    fat_pairs: Vec<(u32, u32)>,
    fat_fixed: Vec<bool>,
    /// How many times in a row the broad phase has paired the bodies again (0: it kept its
    /// pairs the last time).
    paired_in_a_row: u32,
    /// Whether some moving body has more than `MAX_NEIGHBOURS` moving neighbours among the
    /// broad phase's pairs, each body's bounding radius, and scratch for finding out.
    crowded: bool,
    radii: Vec<f64>,
    grown_by: Vec<f64>,
    neighbours: NeighbourScratch,
    /// Which bodies are fixed in this pass, held ones among them (`find_candidate_pairs`).
    fixed_now: Vec<bool>,
    solver_bodies: Vec<SolverBody>,
    /// How far each body can move this step, and the two parts of it: its centroid's
    /// displacement at its current velocity, and how far its spin can carry its
    /// farthest point.
    reach: Vec<f64>,
    motion: Vec<(Vec2, f64)>,
    /// This step's manifolds' gaps less what their bodies can close of them, and how far
    /// a collision may turn each body off its course (`drop_idle_manifolds`).
    gaps: Vec<f64>,
    turn_off: Vec<f64>,
    /// Velocities before this step's forces, for restitution.
    start_velocities: Vec<(Vec2, f64)>,
    /// Poses and velocities at the start of the step, to redo it with finer substeps.
    saved_state: Vec<(Vec2, f64, Vec2, f64)>,
    joint_constraints: Vec<JointConstraint>,
    joint_solver: JointBlockSolver,
    simultaneous: SimultaneousSolver,
    soft: SoftStepSolver,
    accelerations: Vec<(Vec2, f64)>,
    /// Every body's centroid and angle when the step began, for continuous collision.
    step_start: Vec<(Vec2, f64)>,
    /// Continuous collision: the moving body's outline where its step ends and starts,
    /// and the time-of-impact search's own.
    mover_at_end: WorldPolygon,
    mover_at_start: WorldPolygon,
    toi_scratch: WorldPolygon,
    /// Continuous collision: static bodies' slots, outlines and bounds; the bodies
    /// stopped and their times of impact; joint islands and each island's earliest impact.
    obstacles: Vec<(u32, WorldPolygon, Aabb)>,
    impacts: Vec<(u32, f64)>,
    impact_union: UnionFind,
    island_impact: Vec<f64>,
    /// `auto`: the islands' links and row counts, which bodies are in big islands, the
    /// bodies held in the current pass, the exact pass's contacts while the soft pass
    /// runs, and both passes' island reports.
    auto_links: Vec<(u32, u32, usize)>,
    island_rows: Vec<usize>,
    island_needs: Vec<IslandNeeds>,
    /// Per body: whether it is kept on the soft step this step (`World::soft_until`).
    prefer_soft: Vec<bool>,
    in_soft_island: Vec<bool>,
    last_marking: LastMarking,
    #[cfg(test)]
    marks_kept: usize,
    held: Vec<(u32, (Vec2, f64))>,
    exact_contacts: Vec<Contact>,
    exact_manifolds: Vec<Manifold>,
    auto_reports: Vec<IslandReport>,
    /// `pairs` (and outlines, reaches, poses) are those of the bodies as they are now, for
    /// the next contact detection at the same step length: set by `auto` only.
    candidates_current: bool,
}

/// What `auto`'s last marking of soft islands was made from, and what it found: a pile
/// at rest gives the same step after step (`World::mark_soft_islands`).
#[derive(Debug, Clone, Default)]
struct LastMarking {
    links: Vec<(u32, u32, usize)>,
    candidates: Vec<(u32, u32)>,
    fixed: Vec<bool>,
    row_limit: usize,
    prefer_soft: Vec<bool>,
    /// `(exact, soft)`: whether some moving body is in an exact island, some in a soft
    /// one.
    found: Option<(bool, bool)>,
}

/// What an island holds that decides whether `auto` solves it exactly.
#[derive(Debug, Clone, Copy)]
struct IslandNeeds {
    /// A pin or a motor.
    jointed: bool,
    /// The heaviest and the lightest moving body's inverse mass (the smallest and the
    /// largest).
    inverse_masses: (f64, f64),
    /// A body that went over the exact solver's pivot budget lately.
    prefers_soft: bool,
}

impl Default for IslandNeeds {
    fn default() -> Self {
        Self {
            jointed: false,
            inverse_masses: (f64::INFINITY, 0.0),
            prefers_soft: false,
        }
    }
}

/// Moving bodies whose masses differ this much make an island `auto` solves exactly: the
/// soft step's Gauss–Seidel passes carry a heavy body's weight down a light one slowly.
const EXACT_MASS_RATIO: f64 = 10.0;

impl IslandNeeds {
    /// A robot stays exact whatever its pivots cost: the budget bounds each step's, and
    /// the soft step would let its pins give.
    fn kept_on_soft(&self) -> bool {
        self.prefers_soft && !self.jointed
    }

    fn exact_needed(&self) -> bool {
        let (heaviest, lightest) = self.inverse_masses;
        self.jointed || (heaviest > 0.0 && lightest >= EXACT_MASS_RATIO * heaviest)
    }
}

/// The most moving bodies of its own size a moving body collides with at once, the
/// nearest first; a smaller one counts as the fraction of one that its bounding radius is
/// of the body's, so a large body meets as many small ones as fit along it. Bodies
/// dropped onto one spot (2,000 boxes placed at one point: two million pairs, 2.5 GB of
/// contacts) collide with their nearest so many and pass through the rest until they
/// have parted. No scene of bodies that merely touch comes near it (a box in a pyramid
/// has eight neighbours); where bodies move fast among many, as the benchmark's smash's
/// block of 0.5 m boxes struck at 40 m/s, the pairs dropped are those farthest off, which
/// nearer ones stand between.
const MAX_NEIGHBOURS: f64 = 32.0;

/// How much of body `i`'s room for neighbours body `j` takes: 1 for a body at least its
/// size, by bounding radius, and less for a smaller one.
fn neighbour_share(radii: &[f64], i: usize, j: usize) -> f64 {
    if radii[j] >= radii[i] {
        1.0
    } else {
        radii[j] / radii[i]
    }
}

/// Whether some moving body has more than `MAX_NEIGHBOURS` moving neighbours among
/// `pairs`, counted by `neighbour_share` into `room_taken`.
fn crowded(pairs: &[(u32, u32)], fixed: &[bool], radii: &[f64], room_taken: &mut Vec<f64>) -> bool {
    room_taken.clear();
    room_taken.resize(fixed.len(), 0.0);
    let mut crowded = false;
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        if !fixed[i] && !fixed[j] {
            for (k, other) in [(i, j), (j, i)] {
                room_taken[k] += neighbour_share(radii, k, other);
                crowded |= room_taken[k] > MAX_NEIGHBOURS;
            }
        }
    }
    crowded
}

/// Scratch for `keep_nearest_neighbours`.
#[derive(Debug, Clone, Default)]
struct NeighbourScratch {
    room_taken: Vec<f64>,
    dropped: Vec<bool>,
    /// (gap, pair) for the pairs found only by how far their bodies can move.
    within_reach: Vec<(f64, u32)>,
}

/// Keeps each pair with a fixed body, and pairs of moving bodies while both have room
/// (`MAX_NEIGHBOURS`): first those whose own bounds overlap, in the pairs' order (in a
/// pile-up they are all alike and all there is), then those found only by how far the
/// bodies can move in the step, nearest first. `boxes` are the bounds grown by `grown_by`
/// each.
fn keep_nearest_neighbours(
    pairs: &mut Vec<(u32, u32)>,
    fixed: &[bool],
    (boxes, grown_by, radii): (&[Option<Aabb>], &[f64], &[f64]),
    scratch: &mut NeighbourScratch,
) {
    let NeighbourScratch {
        room_taken,
        dropped,
        within_reach,
    } = scratch;
    room_taken.clear();
    room_taken.resize(fixed.len(), 0.0);
    dropped.clear();
    dropped.resize(pairs.len(), false);
    within_reach.clear();
    let mut keep_if_room = |p: usize, (i, j): (usize, usize), dropped: &mut [bool]| {
        let (share_i, share_j) = (neighbour_share(radii, i, j), neighbour_share(radii, j, i));
        if room_taken[i] + share_i <= MAX_NEIGHBOURS && room_taken[j] + share_j <= MAX_NEIGHBOURS {
            room_taken[i] += share_i;
            room_taken[j] += share_j;
        } else {
            dropped[p] = true;
        }
    };
    for (p, &(i, j)) in pairs.iter().enumerate() {
        let (i, j) = (i as usize, j as usize);
        if fixed[i] || fixed[j] {
            continue;
        }
        let (Some(a), Some(b)) = (&boxes[i], &boxes[j]) else {
            continue;
        };
        let apart = (b.min - a.max).sup(&(a.min - b.max));
        // The gap between their own bounds, without the growth.
        let gap = apart.x.max(apart.y) + grown_by[i] + grown_by[j];
        if gap < 0.0 {
            keep_if_room(p, (i, j), dropped);
        } else {
            within_reach.push((gap, p as u32));
        }
    }
    within_reach.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    for &(_, p) in within_reach.iter() {
        let (i, j) = pairs[p as usize];
        keep_if_room(p as usize, (i as usize, j as usize), dropped);
    }
    let mut p = 0;
    pairs.retain(|_| {
        p += 1;
        !dropped[p - 1]
    });
}

/// How far two bodies can close on each other in a step, from each one's `motion`: their
/// centroids' relative displacement and how far each one's spin carries its farthest point.
/// No more than the sum of their reaches, and nothing for bodies moving together.
fn relative_reach((shift_a, turn_a): (Vec2, f64), (shift_b, turn_b): (Vec2, f64)) -> f64 {
    (shift_a - shift_b).norm() + turn_a + turn_b
}

/// Whether two bodies may move relative to each other by more than `distance` in a step:
/// `relative_reach(a, b) > distance`, without its square root (it is asked of every
/// manifold).
fn relative_reach_exceeds(
    (shift_a, turn_a): (Vec2, f64),
    (shift_b, turn_b): (Vec2, f64),
    distance: f64,
) -> bool {
    let left = distance - turn_a - turn_b;
    left < 0.0 || (shift_a - shift_b).norm_squared() > left * left
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
        Ok(BodyHandle((self.bodies.len() - 1) as u32))
    }

    /// Removes a body; its handle then finds nothing. Returns the body if it existed.
    pub fn remove_body(&mut self, handle: BodyHandle) -> Option<Body> {
        self.bodies.get_mut(handle.index())?.take()
    }

    pub fn body(&self, handle: BodyHandle) -> Option<&Body> {
        self.bodies.get(handle.index())?.as_ref()
    }

    pub fn body_mut(&mut self, handle: BodyHandle) -> Option<&mut Body> {
        self.bodies.get_mut(handle.index())?.as_mut()
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
        let a = self.body(def.body_a).ok_or(JointError::MissingBody)?;
        let local_anchor_a = a.to_local(def.anchor);
        let local_anchor_b = match def.body_b {
            Some(h) => self
                .body(h)
                .ok_or(JointError::MissingBody)?
                .to_local(def.anchor),
            None => def.anchor,
        };
        self.joints.push(Some(Joint {
            body_a: def.body_a,
            body_b: def.body_b,
            local_anchor_a,
            local_anchor_b,
            collide_connected: def.collide_connected,
            motor: def.motor,
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

    /// A joint to change; its bodies and `collide_connected` are read again at the next
    /// step.
    pub fn joint_mut(&mut self, handle: JointHandle) -> Option<&mut Joint> {
        let joint = self.joints.get_mut(handle.index())?.as_mut()?;
        self.collision_filter_stale = true;
        Some(joint)
    }

    /// A joint's motor to change (switching it on and off, say) without the joint's
    /// collision filter being rebuilt, as `joint_mut` has it.
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

    /// Adds a thesis body motor (SPEC §4.4) driving `body`. Returns its index.
    pub fn add_body_motor(
        &mut self,
        body: BodyHandle,
        motor: BodyMotor,
    ) -> Result<usize, MotorError> {
        motor.validate()?;
        self.body_motors.push((body, motor));
        Ok(self.body_motors.len() - 1)
    }

    pub fn body_motors(&self) -> &[(BodyHandle, BodyMotor)] {
        &self.body_motors
    }

    fn refresh_collision_filter(&mut self) {
        if !std::mem::take(&mut self.collision_filter_stale) {
            return;
        }
        self.scratch.fat_boxes.clear();
        self.scratch.fat_fixed.clear();
        self.scratch.fat_pairs.clear();
        self.jointed.clear();
        self.jointed.extend(
            self.joints
                .iter()
                .flatten()
                .flat_map(|j| [Some(j.body_a.0), j.body_b.map(|b| b.0)])
                .flatten(),
        );
        self.jointed.sort_unstable();
        self.jointed.dedup();
        self.non_colliding.rebuild(
            self.joints
                .iter()
                .flatten()
                .filter(|j| !j.collide_connected)
                .filter_map(|j| {
                    let (a, b) = (j.body_a.0, j.body_b?.0);
                    Some((a.min(b), a.max(b)))
                })
                .chain(self.ignored_pairs.iter().copied()),
        );
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

    /// Potential energy in the uniform gravity field, zero at the world origin.
    pub fn potential_energy(&self) -> f64 {
        self.bodies()
            .map(|(_, b)| -b.mass() * self.gravity.dot(&b.position))
            .sum()
    }

    pub fn linear_momentum(&self) -> Vec2 {
        self.bodies().map(|(_, b)| b.velocity * b.mass()).sum()
    }

    pub fn angular_momentum(&self) -> f64 {
        self.bodies().map(|(_, b)| b.angular_momentum()).sum()
    }

    /// Advances the world by `dt`: SPEC §3.4's stages, in order.
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
        let fall = self.gravity.norm() * dt * dt;
        let limit = FALL_PER_STEP * self.settings.length_scale;
        if fall > limit {
            return Err(StepError::FallsTooFar { fall, limit });
        }
        let started = stage_clock::mark();
        self.advance(dt);
        stage_clock::record(Stage::Step, started);
        self.check_state()
    }

    /// Every moving body's state finite and within `crate::limits`.
    fn check_state(&self) -> Result<(), StepError> {
        use crate::limits::{COORDINATE, SPEED, SPIN};
        for (i, body) in self.bodies.iter().enumerate() {
            let Some(b) = body.as_ref().filter(|b| !b.is_fixed()) else {
                continue;
            };
            let numbers = [
                ("x", b.position.x, COORDINATE),
                ("y", b.position.y, COORDINATE),
                ("speed", b.velocity.norm(), SPEED),
                ("spin", b.angular_velocity, SPIN),
            ];
            if let Some((what, value, limit)) = crate::limits::first_beyond(numbers) {
                return Err(StepError::StateBeyond {
                    body: i as u32,
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
        if self.settings.continuous {
            let start = &mut self.scratch.step_start;
            start.clear();
            start.extend(self.bodies.iter().map(|b| {
                b.as_ref()
                    .map_or((Vec2::zeros(), 0.0), |b| (b.position, b.angle))
            }));
        }
        self.apply_motor_torques(dt);
        match self.settings.contact_solver {
            ContactSolver::Soft => self.step_soft(dt),
            ContactSolver::Auto => self.step_auto(dt),
            _ => self.step_impulses(dt),
        }
        self.clear_forces();
        self.step_count += 1;
        if self.settings.continuous {
            let started = stage_clock::mark();
            self.stop_at_impact();
            stage_clock::record(Stage::Continuous, started);
        }
        if self.settings.sleeping {
            self.sleep_where_still(dt);
        } else if !self.sleep_labels.is_empty() {
            // Sleeping was switched off: wake everyone, once.
            self.bodies.iter_mut().flatten().for_each(Body::wake);
            self.sleep_labels.clear();
        }
    }

    /// Continuous collision: see `step`.
    fn stop_at_impact(&mut self) {
        let slop = self.settings.slop();
        let margin = self.settings.contact_margin();
        let s = &mut self.scratch;
        // The static bodies' slots, outlines and bounds, built once per step when the
        // first body needs them (most steps, none does).
        let mut obstacles = std::mem::take(&mut s.obstacles);
        let mut count: Option<usize> = None;
        s.impacts.clear();
        for i in 0..self.bodies.len() {
            let Some(body) = self.bodies[i].as_ref() else {
                continue;
            };
            if body.is_fixed() {
                continue;
            }
            let sweep = Sweep {
                start: s.step_start[i],
                end: (body.position, body.angle),
            };
            let radius = body.bounding_radius();
            let motion =
                (sweep.end.0 - sweep.start.0).norm() + (sweep.end.1 - sweep.start.1).abs() * radius;
            // Fast bodies, and bodies an impact sent further than the contact margin (their
            // contacts were found before the solve, for the motion they had then). A
            // jointed body only when fast enough to pass through something: its whole
            // mechanism goes back with it (below), and a robot's feet pressed a little deep
            // into the ground are the contacts' job. (Measured with the margin rule for
            // jointed bodies too: the walker under `thesis` got 57% less far in 1,000
            // steps, and the car's pins under `exact` opened 2.8e-3 px instead of 2e-5.)
            let fast = 0.5 * body.inner_radius();
            // Slow enough for any body, and then for a jointed one: most bodies are
            // the first, and need no search among the jointed.
            if motion <= fast.min(margin)
                || motion <= fast && self.jointed.binary_search(&(i as u32)).is_ok()
            {
                continue;
            }
            let count = *count.get_or_insert_with(|| {
                let mut n = 0;
                for (slot, obstacle) in self.bodies.iter().enumerate() {
                    let Some(obstacle) = obstacle.as_ref().filter(|o| o.is_static()) else {
                        continue;
                    };
                    if obstacles.len() == n {
                        obstacles.push((0, WorldPolygon::default(), Aabb::default()));
                    }
                    let (index, polygon, bounds) = &mut obstacles[n];
                    *index = slot as u32;
                    polygon.update(obstacle);
                    *bounds = polygon.aabb();
                    n += 1;
                }
                n
            });
            let swept = Aabb {
                min: sweep.start.0.inf(&sweep.end.0),
                max: sweep.start.0.sup(&sweep.end.0),
            }
            .grown(radius + slop);
            let local = body.local_vertices();
            // The body's outlines at either end of its sweep, placed when an obstacle
            // first needs them: most fast bodies have none near (the smash's debris has
            // none at all), and placing both cost 7% of the smash's step.
            let (mut placed_at_end, mut placed_at_start) = (false, false);
            let mut first: Option<f64> = None;
            for (obstacle, polygon, bounds) in &obstacles[..count] {
                if !swept.overlaps(bounds) {
                    continue;
                }
                // A static body this one never collides with (a robot's pivot that its
                // own links pass over) is no obstacle.
                let pair = ((i as u32).min(*obstacle), (i as u32).max(*obstacle));
                if self.non_colliding.contains(pair) {
                    continue;
                }
                if !placed_at_end {
                    place(&mut s.mover_at_end, local, sweep.end);
                    placed_at_end = true;
                }
                // Ending in contact (within the solver's slop either way) is the contact
                // solver's business: a landing, a body sliding along a floor.
                let end_gap = separation(&s.mover_at_end, polygon);
                if (-2.0 * slop..=slop).contains(&end_gap) {
                    continue;
                }
                // Apart at both ends, and too far apart for the motion to have touched in
                // between (the gap shrinks no faster than `motion` per step).
                if end_gap > slop {
                    if !placed_at_start {
                        place(&mut s.mover_at_start, local, sweep.start);
                        placed_at_start = true;
                    }
                    let start_gap = separation(&s.mover_at_start, polygon);
                    if start_gap + end_gap > motion + 2.0 * slop {
                        continue;
                    }
                }
                // In contact at the start and far deeper at the end: the contact solver
                // did not hold it (under `thesis`, the joint pass after the contacts drags
                // a stopped link on into a wall); it goes back to where it was 2 × slop deep.
                let hit = time_of_impact(
                    local,
                    radius,
                    &sweep,
                    polygon,
                    slop,
                    0.25 * slop,
                    &mut s.toi_scratch,
                )
                .or_else(|| {
                    if end_gap >= -2.0 * slop {
                        return None;
                    }
                    time_of_sinking(
                        local,
                        radius,
                        &sweep,
                        polygon,
                        2.0 * slop,
                        0.25 * slop,
                        &mut s.toi_scratch,
                    )
                });
                if let Some(t) = hit {
                    first = Some(first.map_or(t, |f: f64| f.min(t)));
                }
            }
            if let Some(t) = first {
                s.impacts.push((i as u32, t));
            }
        }
        s.obstacles = obstacles;
        self.move_back_to_impacts();
    }

    /// Moves each body that continuous collision stopped back along its sweep to its time
    /// of impact. A jointed body takes its joint island with it, every moving body to the
    /// same fraction of its own sweep: moving one link alone would open its pins by the
    /// rest of the step's motion. (Turning bodies' pins then stay together to second order
    /// in the step's rotation; the joint passes close the rest next step.)
    fn move_back_to_impacts(&mut self) {
        let s = &mut self.scratch;
        if s.impacts.is_empty() {
            return;
        }
        let bodies = &mut self.bodies;
        let moving = |i: usize| bodies[i].as_ref().is_some_and(|b| !b.is_fixed());
        let jointed_hit = s
            .impacts
            .iter()
            .any(|(i, _)| self.jointed.binary_search(i).is_ok());
        if jointed_hit {
            s.impact_union.reset(bodies.len());
            for j in self.joints.iter().flatten() {
                if let Some(b) = j.body_b {
                    let (ia, ib) = (j.body_a.index(), b.index());
                    if moving(ia) && moving(ib) {
                        s.impact_union.union(ia as u32, ib as u32);
                    }
                }
            }
            s.island_impact.clear();
            s.island_impact.resize(bodies.len(), f64::INFINITY);
            for &(i, t) in &s.impacts {
                let root = s.impact_union.find(i) as usize;
                s.island_impact[root] = s.island_impact[root].min(t);
            }
            s.impacts.clear();
            for i in 0..bodies.len() {
                if moving(i) {
                    let t = s.island_impact[s.impact_union.find(i as u32) as usize];
                    if t.is_finite() {
                        s.impacts.push((i as u32, t));
                    }
                }
            }
        }
        for &(i, t) in &s.impacts {
            let body = bodies[i as usize].as_mut().expect("a moving body");
            let sweep = Sweep {
                start: s.step_start[i as usize],
                end: (body.position, body.angle),
            };
            (body.position, body.angle) = sweep.at(t);
        }
    }

    /// Wakes `handle` and everything asleep in its island.
    pub fn wake_body(&mut self, handle: BodyHandle) {
        let Some(label) = self.sleep_labels.get(handle.index()).copied() else {
            return;
        };
        if self.body(handle).is_some_and(|b| b.asleep) {
            self.wake_island(label);
        }
    }

    fn wake_island(&mut self, label: u32) {
        for (body, &l) in self.bodies.iter_mut().zip(&self.sleep_labels) {
            if let Some(b) = body
                && b.asleep
                && l == label
            {
                b.wake();
            }
        }
    }

    /// Wakes sleeping islands that an awake body can reach this step, and those with a
    /// motor switching on. Candidates come from the broad phase over the bodies' bounding
    /// circles (each awake one grown by its reach), so the cost follows the bodies near
    /// each other, not awake × asleep.
    fn wake_where_needed(&mut self, dt: f64) {
        let margin = self.settings.contact_margin();
        let mut wake = std::mem::take(&mut self.scratch.wake_labels);
        wake.clear();
        let some_asleep = self.bodies.iter().flatten().any(|b| b.asleep);
        let some_awake = self.bodies.iter().flatten().any(|b| !b.is_fixed());
        if some_asleep && some_awake {
            let reach = |b: &Body| {
                (b.velocity.norm()
                    + b.angular_velocity.abs() * b.bounding_radius()
                    + self.gravity.norm() * dt)
                    * dt
            };
            let s = &mut self.scratch;
            s.boxes.clear();
            s.reach.clear();
            for body in &self.bodies {
                let r = body
                    .as_ref()
                    .map_or(0.0, |b| if b.asleep { 0.0 } else { reach(b) });
                s.reach.push(r);
                s.boxes
                    .push(body.as_ref().filter(|b| !b.is_static()).map(|b| {
                        let half = b.bounding_radius() + r + 0.5 * margin;
                        Aabb {
                            min: b.position - Vec2::new(half, half),
                            max: b.position + Vec2::new(half, half),
                        }
                    }));
            }
            let bodies = &self.bodies;
            let asleep = |i: usize| bodies[i].as_ref().is_some_and(|b| b.asleep);
            s.wake_broad_phase
                .pairs(&s.boxes, |i, j| asleep(i) != asleep(j), &mut s.pairs);
            for &(i, j) in &s.pairs {
                let (sleeper, awake) = if asleep(i as usize) { (i, j) } else { (j, i) };
                let (b, a) = (
                    bodies[sleeper as usize].as_ref().expect("boxed"),
                    bodies[awake as usize].as_ref().expect("boxed"),
                );
                let apart =
                    (b.position - a.position).norm() - b.bounding_radius() - a.bounding_radius();
                if apart <= margin + s.reach[awake as usize] {
                    wake.push(self.sleep_labels[sleeper as usize]);
                }
            }
        }
        let step = self.step_count;
        for (h, m) in &self.body_motors {
            if m.is_on(step) && self.body(*h).is_some_and(|b| b.asleep) {
                wake.push(self.sleep_labels[h.index()]);
            }
        }
        for j in self.joints.iter().flatten() {
            if j.motor.is_some_and(|m| m.enabled) {
                for h in [Some(j.body_a), j.body_b].into_iter().flatten() {
                    if self.body(h).is_some_and(|b| b.asleep) {
                        wake.push(self.sleep_labels[h.index()]);
                    }
                }
            }
        }
        wake.sort_unstable();
        wake.dedup();
        for &label in &wake {
            self.wake_island(label);
        }
        self.scratch.wake_labels = wake;
    }

    /// Times how long each awake body has been still, and puts to sleep the islands whose
    /// bodies have all been still long enough.
    fn sleep_where_still(&mut self, dt: f64) {
        let tolerance = self.settings.sleep_speed();
        for b in self.bodies.iter_mut().flatten() {
            if b.is_fixed() {
                continue;
            }
            let speed = b.velocity.norm() + b.angular_velocity.abs() * b.bounding_radius();
            b.still_time = if speed < tolerance {
                b.still_time + dt
            } else {
                0.0
            };
        }
        let n = self.bodies.len();
        let moving = |bodies: &[Option<Body>], i: u32| {
            bodies[i as usize].as_ref().is_some_and(|b| !b.is_fixed())
        };
        let uf = &mut self.scratch.island_union;
        uf.reset(n);
        for c in &self.contacts {
            if moving(&self.bodies, c.body_a) && moving(&self.bodies, c.body_b) {
                uf.union(c.body_a, c.body_b);
            }
        }
        for j in self.joints.iter().flatten() {
            if let Some(b) = j.body_b
                && moving(&self.bodies, j.body_a.0)
                && moving(&self.bodies, b.0)
            {
                uf.union(j.body_a.0, b.0);
            }
        }
        // An island may sleep when its stillest-to-be body has waited long enough and no
        // motor in it runs.
        let mut ready = std::mem::take(&mut self.scratch.island_ready);
        ready.clear();
        ready.resize(n, true);
        for i in 0..n as u32 {
            if let Some(b) = self.bodies[i as usize].as_ref()
                && !b.is_fixed()
                && b.still_time < SLEEP_AFTER
            {
                ready[uf.find(i) as usize] = false;
            }
        }
        let step = self.step_count;
        for (h, m) in &self.body_motors {
            if m.is_on(step) {
                ready[uf.find(h.0) as usize] = false;
            }
        }
        for j in self.joints.iter().flatten() {
            if j.motor.is_some_and(|m| m.enabled) {
                ready[uf.find(j.body_a.0) as usize] = false;
                if let Some(b) = j.body_b {
                    ready[uf.find(b.0) as usize] = false;
                }
            }
        }
        self.sleep_labels.resize(n, u32::MAX);
        for i in 0..n as u32 {
            let root = uf.find(i);
            if let Some(b) = self.bodies[i as usize].as_mut()
                && !b.is_fixed()
                && ready[root as usize]
            {
                b.fall_asleep();
                self.sleep_labels[i as usize] = root;
            }
        }
        self.scratch.island_ready = ready;
    }

    fn step_impulses(&mut self, dt: f64) {
        self.repair_broken_joints(dt);
        let mut substeps = self.substeps_for(dt);
        // A joint still broken is being repaired on purpose over several steps; only
        // joints that should have closed ask for finer substeps.
        let repairing = self.max_joint_gap() > self.settings.joint_iterations(dt).broken_gap;
        loop {
            self.save_state();
            let h = dt / substeps as f64;
            self.for_each_motor(|m| m.step_impulse = 0.0);
            for _ in 0..substeps {
                self.correct_joint_velocities(h);
                self.integrate_velocities(h);
                self.detect_contacts(h, Pipeline::Impulses);
                self.push_apart();
                self.solve_constraints(h);
                self.place_bounces_at_impact(h);
                self.integrate_positions(h);
                self.for_each_motor(|m| {
                    if m.enabled {
                        m.step_impulse += m.last_impulse;
                    }
                });
            }
            // A whip can spin links up within the step; if they now turn too far per
            // substep, this step's joint prediction was not trustworthy: redo it finer.
            let mut needed = self.substeps_for(dt);
            if !repairing && self.max_joint_gap() > 1e-3 * self.settings.length_scale {
                needed = needed.max(2 * substeps);
            }
            if needed <= substeps || substeps >= MAX_SUBSTEPS {
                break;
            }
            self.restore_state();
            substeps = needed.max(2 * substeps).min(MAX_SUBSTEPS);
        }
    }

    fn for_each_motor(&mut self, f: impl Fn(&mut JointMotor)) {
        self.joints
            .iter_mut()
            .flatten()
            .filter_map(|j| j.motor.as_mut())
            .for_each(f);
    }

    fn save_state(&mut self) {
        let saved = &mut self.scratch.saved_state;
        saved.clear();
        saved.extend(self.bodies.iter().map(|b| {
            b.as_ref().map_or(Default::default(), |b| {
                (b.position, b.angle, b.velocity, b.angular_velocity)
            })
        }));
    }

    fn restore_state(&mut self) {
        for (body, &(p, a, v, w)) in self.bodies.iter_mut().zip(&self.scratch.saved_state) {
            if let Some(b) = body {
                (b.position, b.angle, b.velocity, b.angular_velocity) = (p, a, v, w);
            }
        }
    }

    /// How many substeps this step needs: the joint prediction (SPEC §3.3) follows each
    /// jointed body's rotation by ω·h, and past a quarter radian per step that is too far
    /// from linear for the Newton steps to be trusted (a whipping chain tip turns a radian
    /// per 1/60 s). Usually 1.
    fn substeps_for(&self, dt: f64) -> usize {
        const MAX_TURN: f64 = 0.25;
        let fastest = self
            .joints
            .iter()
            .flatten()
            .flat_map(|j| [Some(j.body_a), j.body_b])
            .flatten()
            .filter_map(|h| self.body(h))
            .map(|b| b.angular_velocity.abs())
            .fold(0.0, f64::max);
        ((fastest * dt / MAX_TURN).ceil() as usize).clamp(1, MAX_SUBSTEPS)
    }

    /// A speculative contact that bounces this step reverses while the bodies are still a
    /// gap g apart, where they have not yet fallen the last g: the rebound keeps
    /// (1 − e²)·g too much height. Moving the body down by that much (positions only) puts
    /// the bounce's energy where an impact at the surface would. Only against static
    /// bodies: between two free bodies the shift would change angular momentum about the
    /// origin, and exact conservation is worth more there than this O(v·h) height error.
    fn place_bounces_at_impact(&mut self, dt: f64) {
        let bounce_below = restitution_threshold(self.gravity, dt);
        for k in 0..self.contacts.len() {
            let c = self.contacts[k];
            let first_of_pair = k == 0 || {
                let p = &self.contacts[k - 1];
                (p.body_a, p.body_b) != (c.body_a, c.body_b)
            };
            if !first_of_pair {
                continue;
            }
            let pair = self.contacts[k..]
                .iter()
                .take_while(|p| (p.body_a, p.body_b) == (c.body_a, c.body_b));
            let (mut gap, mut room) = (0.0, f64::INFINITY);
            for p in pair {
                if p.depth < 0.0 && p.normal_impulse > 0.0 && p.bounces(dt, bounce_below) {
                    gap = f64::max(gap, (1.0 - p.restitution * p.restitution) * -p.depth);
                }
                // The shift may not push any of the pair's other points in: a body
                // pivoting on one corner that bounces on the other must stay out at both.
                room = room.min(-p.depth);
            }
            let gap = gap.min(room);
            if gap <= 0.0 {
                continue;
            }
            let is_fixed = |i: u32| self.bodies[i as usize].as_ref().is_none_or(Body::is_fixed);
            let (moving, direction) = match (is_fixed(c.body_a), is_fixed(c.body_b)) {
                (false, true) => (c.body_a, -c.normal),
                (true, false) => (c.body_b, c.normal),
                _ => continue,
            };
            // Moving one part of a jointed mechanism would open its joints.
            if self.jointed.binary_search(&moving).is_ok() {
                continue;
            }
            if let Some(body) = self.bodies[moving as usize].as_mut() {
                body.position += direction * gap;
            }
        }
    }

    /// The solver the impulse stage list runs as: `auto` runs it as `exact`.
    fn impulse_solver(&self) -> ContactSolver {
        match self.settings.contact_solver {
            ContactSolver::Auto => ContactSolver::Exact,
            solver => solver,
        }
    }

    /// `auto`: each island goes to `exact` or to the soft step (`mark_soft_islands`).
    /// Each solver's pass holds the other's bodies still. Islands are joined by the broad
    /// phase's candidate pairs of this step, not only by last step's contacts, so bodies
    /// that can touch during the step are in one pass: a box falling onto a pile joins
    /// the pile's pass before it lands. (Joined by last step's contacts only, the landing
    /// step acted one way, and the smash scene lost 0.7% of its momentum.) Contacts and
    /// island reports of both passes are kept.
    fn step_auto(&mut self, dt: f64) {
        let (exact, soft) = self.mark_soft_islands(dt);
        if !soft {
            self.step_impulses(dt);
            self.keep_over_budget_on_soft(dt);
            self.scratch
                .auto_reports
                .clone_from(&self.scratch.simultaneous.reports);
            return;
        }
        if !exact {
            // No body is held and none has moved: the soft step's broad phase would find
            // the candidate pairs just found.
            self.scratch.candidates_current = true;
            self.step_soft(dt);
            self.scratch
                .auto_reports
                .clone_from(&self.scratch.soft.reports);
            return;
        }
        self.hold_where(true);
        self.step_impulses(dt);
        self.release_held();
        self.keep_over_budget_on_soft(dt);
        let s = &mut self.scratch;
        std::mem::swap(&mut s.exact_contacts, &mut self.contacts);
        std::mem::swap(&mut s.exact_manifolds, &mut self.manifolds);
        self.hold_where(false);
        self.step_soft(dt);
        self.release_held();
        let s = &mut self.scratch;
        s.auto_reports.clone_from(&s.simultaneous.reports);
        s.auto_reports.extend_from_slice(&s.soft.reports);
        // A pair across the two passes (bodies that moved beyond their reach, as gravity
        // adds to the speed the reach was measured with) was found by both: keep the exact
        // pass's.
        let exact_pairs = &s.exact_manifolds;
        let seen = |a: u32, b: u32| {
            exact_pairs
                .binary_search_by(|m| (m.body_a.0, m.body_b.0).cmp(&(a, b)))
                .is_ok()
        };
        self.contacts.retain(|c| !seen(c.body_a, c.body_b));
        self.manifolds.retain(|m| !seen(m.body_a.0, m.body_b.0));
        self.contacts.splice(0..0, s.exact_contacts.drain(..));
        self.manifolds.splice(0..0, s.exact_manifolds.drain(..));
    }

    /// Marks each moving body whose island the soft step takes (`auto`). An island goes to
    /// `exact` where exact pivoting is both needed and fast: it holds a pin or a motor, or
    /// moving bodies whose masses differ tenfold (a robot, a heavy box on light ones),
    /// it has at most `dense_row_limit` LCP rows, and (unless it is a robot) none of its
    /// bodies went over the pivot budget within the last second. A pile of like bodies
    /// goes to the soft step, as accurate there at a fraction of the cost.
    ///
    /// Islands are joined by the last step's contacts, the joints and this step's candidate
    /// pairs. Rows: two per pin, one per motor, and the larger of two per contact point of
    /// the last step and two per candidate pair (one point each), so that a pile is big
    /// from its first step, before any contact is known. Returns whether some moving body
    /// is in an exact island and whether some is in a soft one.
    fn mark_soft_islands(&mut self, dt: f64) -> (bool, bool) {
        self.find_candidate_pairs(dt);
        let n = self.bodies.len();
        let bodies = &self.bodies;
        let moving = |i: u32| bodies[i as usize].as_ref().is_some_and(|b| !b.is_fixed());
        let s = &mut self.scratch;
        let mut links: Vec<(u32, u32, usize)> = std::mem::take(&mut s.auto_links);
        links.clear();
        links.extend(self.contacts.iter().map(|c| (c.body_a, c.body_b, 2)));
        let contact_links = links.len();
        for j in self.joints.iter().flatten() {
            let rows = 2 + usize::from(j.motor.is_some_and(|m| m.enabled));
            let b = j.body_b.map_or(j.body_a.0, |h| h.0);
            links.push((j.body_a.0, b, rows));
        }
        // A body motor is a link of the body to itself: no rows, but its island is a
        // robot's.
        links.extend(self.body_motors.iter().map(|(h, _)| (h.0, h.0, 0)));
        let soft_until = &self.soft_until;
        let step = self.step_count;
        s.prefer_soft.clear();
        s.prefer_soft
            .extend((0..n).map(|i| soft_until.get(i).is_some_and(|&until| until > step)));
        // The marking is a function of its links, candidates, fixed bodies, limit and the
        // bodies kept on the soft step alone (the fixed ones are `fat_fixed`: no body is
        // held between passes): the same inputs, the same marks, without the union-find.
        let limit = self.settings.dense_row_limit;
        let last = &s.last_marking;
        if let Some(marked) = last.found
            && (&last.links, &last.candidates, &last.fixed, last.row_limit)
                == (&links, &s.pairs, &s.fat_fixed, limit)
            && last.prefer_soft == s.prefer_soft
        {
            s.auto_links = links;
            #[cfg(test)]
            {
                s.marks_kept += 1;
            }
            return marked;
        }
        s.island_union.reset(n);
        let candidates = s.pairs.iter().map(|&(a, b)| (a, b, 0));
        for (a, b, _) in links.iter().copied().chain(candidates) {
            if moving(a) && moving(b) {
                s.island_union.union(a, b);
            }
        }
        // Per root, two counts: pins, motors and last step's contacts; pins, motors and
        // candidate pairs. (`links` lists the contacts first, then the joints and motors.)
        s.island_rows.clear();
        s.island_rows.resize(2 * n, 0);
        let counted = links.iter().enumerate().map(|(k, &(a, b, rows))| {
            let columns = if k < contact_links { 0..1 } else { 0..2 };
            (a, b, rows, columns)
        });
        let candidates = s.pairs.iter().map(|&(a, b)| (a, b, 2, 1..2));
        for (a, b, rows, columns) in counted.chain(candidates) {
            let end = if moving(a) { a } else { b };
            if moving(end) {
                let root = s.island_union.find(end) as usize;
                for column in columns {
                    s.island_rows[column * n + root] += rows;
                }
            }
        }
        // Per root: whether a pin or motor is in it, and its moving bodies' lightest and
        // heaviest inverse masses.
        s.island_needs.clear();
        s.island_needs.resize(n, IslandNeeds::default());
        for &(a, b, _) in &links[contact_links..] {
            let end = if moving(a) { a } else { b };
            if moving(end) {
                let root = s.island_union.find(end) as usize;
                s.island_needs[root].jointed = true;
            }
        }
        for i in 0..n as u32 {
            if let Some(body) = bodies[i as usize].as_ref().filter(|b| !b.is_fixed()) {
                let root = s.island_union.find(i) as usize;
                let needs = &mut s.island_needs[root];
                needs.inverse_masses.0 = needs.inverse_masses.0.min(body.inv_mass);
                needs.inverse_masses.1 = needs.inverse_masses.1.max(body.inv_mass);
                needs.prefers_soft |= s.prefer_soft[i as usize];
            }
        }
        s.auto_links = links;
        s.in_soft_island.clear();
        let (mut exact, mut soft) = (false, false);
        for i in 0..n as u32 {
            let root = s.island_union.find(i) as usize;
            let rows = s.island_rows[root].max(s.island_rows[n + root]);
            let needs = &s.island_needs[root];
            let goes_exact = needs.exact_needed() && rows <= limit && !needs.kept_on_soft();
            let in_soft = moving(i) && !goes_exact;
            s.in_soft_island.push(in_soft);
            soft |= in_soft;
            exact |= moving(i) && goes_exact;
        }
        let last = &mut s.last_marking;
        // The last links go back to be the buffer for the next marking's.
        std::mem::swap(&mut last.links, &mut s.auto_links);
        last.candidates.clone_from(&s.pairs);
        last.fixed.clone_from(&s.fat_fixed);
        last.row_limit = limit;
        last.prefer_soft.clone_from(&s.prefer_soft);
        last.found = Some((exact, soft));
        (exact, soft)
    }

    /// The bodies of islands whose exact solve went over its pivot budget this step stay
    /// on the soft step for the next second (`mark_soft_islands`): no island costs more
    /// than the budget for longer than a step.
    fn keep_over_budget_on_soft(&mut self, dt: f64) {
        let over = &self.scratch.simultaneous.over_budget_bodies;
        if over.is_empty() {
            return;
        }
        // This step's count is `step_count` until it ends: the next second of steps.
        let until = self.step_count + 1 + (SOFT_AFTER_OVER_BUDGET / dt).ceil() as u64;
        self.soft_until.resize(self.bodies.len(), 0);
        // The static world's slot comes after the bodies'.
        for &i in over.iter().filter(|&&i| (i as usize) < self.bodies.len()) {
            self.soft_until[i as usize] = until;
        }
    }

    /// Holds every moving body whose island is (`soft`) or is not (`!soft`) the soft
    /// step's.
    fn hold_where(&mut self, soft: bool) {
        let s = &mut self.scratch;
        s.held.clear();
        for (i, body) in self.bodies.iter_mut().enumerate() {
            if let Some(b) = body
                && !b.is_fixed()
                && s.in_soft_island[i] == soft
            {
                s.held.push((i as u32, b.hold()));
            }
        }
    }

    fn release_held(&mut self) {
        for &(i, velocity) in &self.scratch.held {
            if let Some(b) = self.bodies[i as usize].as_mut() {
                b.release(velocity);
            }
        }
        self.scratch.held.clear();
    }

    /// The soft step has its own stage list: forces, contacts found once, then substeps
    /// that integrate and solve together (see `solver::soft`).
    fn step_soft(&mut self, dt: f64) {
        self.scratch.start_velocities.clear(); // forces act inside the substeps
        self.detect_contacts(dt, Pipeline::Soft);
        // The soft step pulls every pin closed its own way: no repair targets.
        self.gather_solver_bodies_with(GapTargets::None);
        let s = &mut self.scratch;
        s.accelerations.clear();
        s.accelerations.extend(self.bodies.iter().map(|b| match b {
            Some(b) if !b.is_fixed() => (
                self.gravity + b.force * b.inv_mass,
                b.torque * b.inv_inertia,
            ),
            _ => (Vec2::zeros(), 0.0),
        }));
        s.accelerations.push((Vec2::zeros(), 0.0));
        s.soft.step(
            &SoftSettings {
                substeps: self.settings.soft_substeps.max(1),
                alternating_sweeps: self.settings.soft_alternating_sweeps,
                ..SoftSettings::for_length_scale(self.settings.length_scale)
            },
            &mut s.solver_bodies,
            &s.accelerations,
            &mut self.contacts,
            &mut s.joint_constraints,
            dt,
            restitution_threshold(self.gravity, dt),
        );
        self.scatter_solver_bodies();
    }

    /// Copies the bodies into the solver array, the static world last, and resolves the
    /// joints to slots in it, each with the gap it is to close this step.
    fn gather_solver_bodies(&mut self) {
        self.gather_solver_bodies_with(GapTargets::ForBrokenJoints);
    }

    fn gather_solver_bodies_with(&mut self, targets: GapTargets) {
        let s = &mut self.scratch;
        s.solver_bodies.clear();
        s.solver_bodies.extend(
            self.bodies
                .iter()
                .map(|b| b.as_ref().map(SolverBody::from_body).unwrap_or_default()),
        );
        let ground = self.bodies.len() as u32;
        s.solver_bodies.push(SolverBody::default());
        s.joint_constraints.clear();
        for (i, j) in self.joints.iter().enumerate() {
            let Some(j) = j else { continue };
            let live = |h: BodyHandle| self.bodies.get(h.index()).is_some_and(Option::is_some);
            if !live(j.body_a) || !j.body_b.is_none_or(live) {
                continue;
            }
            let mut c = JointConstraint {
                joint: i as u32,
                body_a: j.body_a.0,
                body_b: j.body_b.map_or(ground, |h| h.0),
                local_anchor_a: j.local_anchor_a,
                local_anchor_b: j.local_anchor_b,
                motor: j.motor,
                gap_target: Vec2::zeros(),
            };
            if targets == GapTargets::ForBrokenJoints {
                let gap_now = c.predicted_gap(&s.solver_bodies, 0.0);
                let broken_gap = self.settings.joint_iterations(1.0).broken_gap;
                c.gap_target = velocity_gap_target(gap_now, broken_gap);
            }
            s.joint_constraints.push(c);
        }
    }

    /// Copies solved velocities (and motor impulses) back.
    fn scatter_solver_bodies(&mut self) {
        for (body, solved) in self.bodies.iter_mut().zip(&self.scratch.solver_bodies) {
            if let Some(b) = body {
                b.velocity = solved.velocity;
                b.angular_velocity = solved.angular_velocity;
                b.position = solved.position;
                b.angle = solved.angle;
            }
        }
        for c in &self.scratch.joint_constraints {
            if let Some(Some(j)) = self.joints.get_mut(c.joint as usize) {
                j.motor = c.motor;
            }
        }
    }

    /// Broken joints move towards closing, by positions only.
    fn repair_broken_joints(&mut self, dt: f64) {
        if self.joints.is_empty() {
            return;
        }
        self.gather_solver_bodies();
        let it = self.settings.joint_iterations(dt);
        let s = &mut self.scratch;
        s.joint_solver.repair_positions(
            self.settings.joint_solver,
            &mut s.joint_constraints,
            &mut s.solver_bodies,
            &it,
        );
        self.scatter_solver_bodies();
    }

    /// Stage 1: joints whose anchors drift apart stop drifting (SPEC eq. 40).
    fn correct_joint_velocities(&mut self, dt: f64) {
        if self.joints.is_empty() {
            return;
        }
        self.gather_solver_bodies();
        let it = self.settings.joint_iterations(dt);
        let s = &mut self.scratch;
        s.joint_solver.correct_velocities(
            self.settings.joint_solver,
            &mut s.joint_constraints,
            &mut s.solver_bodies,
            &it,
        );
        self.scatter_solver_bodies();
    }

    /// Stage 2: body motors add their torque (SPEC §4.4).
    fn apply_motor_torques(&mut self, dt: f64) {
        for (handle, motor) in self.body_motors.iter_mut() {
            let Some(Some(b)) = self.bodies.get_mut(handle.index()) else {
                continue;
            };
            b.torque += motor.torque(self.step_count, b.angular_velocity, dt);
        }
    }

    /// Gravity and accumulated forces change velocities (SPEC §3.4 steps 2–3).
    fn integrate_velocities(&mut self, dt: f64) {
        self.scratch.start_velocities.clear();
        self.scratch
            .start_velocities
            .extend(self.bodies.iter().map(|b| {
                b.as_ref()
                    .map_or((Vec2::zeros(), 0.0), |b| (b.velocity, b.angular_velocity))
            }));
        for b in self.bodies.iter_mut().flatten() {
            if b.is_fixed() {
                continue;
            }
            b.velocity += (self.gravity + b.force * b.inv_mass) * dt;
            b.angular_velocity += b.torque * b.inv_inertia * dt;
        }
    }

    /// World outlines, each body's reach this step and poses, and the broad phase's
    /// candidate pairs: bodies whose bounds, grown by the margin and by how far each can
    /// move in `dt`, overlap (pairs of fixed bodies and pairs kept apart left out).
    fn find_candidate_pairs(&mut self, dt: f64) {
        let s = &mut self.scratch;
        s.polygons
            .resize_with(self.bodies.len(), WorldPolygon::default);
        s.boxes.clear();
        s.reach.clear();
        s.motion.clear();
        s.poses.clear();
        let margin = self.settings.contact_margin();
        let is_fixed =
            |body: &Option<Body>| body.as_ref().is_none_or(|b| b.is_static() || b.is_asleep());
        // The grown bounds' pairs still hold every pair whose bounds overlap now if every
        // body's bounds lie inside its grown ones, and the same bodies are fixed: checked
        // as the bounds are made, in the one pass over the bodies.
        let mut still_inside = s.fat_boxes.len() == self.bodies.len();
        let mut same_fixed = s.fat_fixed.len() == self.bodies.len();
        let bodies = self.bodies.iter().zip(s.polygons.iter_mut()).enumerate();
        for (i, (body, polygon)) in bodies {
            // The speed of its farthest point from the spin alone.
            let spin = body
                .as_ref()
                .map_or(0.0, |b| b.angular_velocity.abs() * b.bounding_radius());
            let velocity = body.as_ref().map_or(Vec2::zeros(), |b| b.velocity);
            let reach = (velocity.norm() + spin) * dt;
            s.reach.push(reach);
            s.motion.push((velocity * dt, spin * dt));
            let pose = body.as_ref().map_or(Pose::default(), Pose::of);
            s.poses.push(pose);
            let bounds = body.as_ref().map(|b| {
                // The outline from the pose (one rotation per body, shared with reuse).
                polygon.set_outline(b.local_vertices().iter().map(|&v| pose.to_world(v)));
                polygon.aabb().grown(0.5 * margin + reach)
            });
            if still_inside {
                still_inside = match (&bounds, &s.fat_boxes[i]) {
                    (Some(now), Some(fat)) => fat.contains(now),
                    (None, None) => true,
                    _ => false,
                };
            }
            same_fixed = same_fixed && s.fat_fixed[i] == is_fixed(body);
            s.boxes.push(bounds);
        }
        let bodies = &self.bodies;
        // Pairs of static or sleeping bodies are never tested: a pile at rest costs nothing.
        // The broad phase leaves out such pairs only, not those of bodies held for one pass
        // of `auto` (whose two passes hold different bodies); those are dropped from its
        // pairs below, so that its pairs serve both passes.
        if still_inside && same_fixed {
            s.paired_in_a_row = 0;
        } else {
            s.paired_in_a_row = s.paired_in_a_row.wrapping_add(1);
            // Grown bounds pay while their pairs hold for a few steps. Where every step pairs
            // again anyway (the smash's flying debris) they only add pairs to compare and
            // sort: pair the bounds as they are, and try grown ones again now and then in
            // case the scene has settled. The candidates are the same either way.
            let grow_pays =
                s.paired_in_a_row < 2 || s.paired_in_a_row.is_multiple_of(RETRY_GROWN_BOUNDS);
            let grow = if grow_pays {
                self.settings.broad_phase_margin()
            } else {
                0.0
            };
            s.fat_boxes.clear();
            s.fat_boxes
                .extend(s.boxes.iter().map(|b| b.map(|b| b.grown(grow))));
            s.fat_fixed.clear();
            s.fat_fixed.extend(bodies.iter().map(is_fixed));
            let (non_colliding, fixed) = (&self.non_colliding, &s.fat_fixed);
            let wanted = |i: usize, j: usize| {
                let both_fixed = fixed[i] & fixed[j];
                !both_fixed && !non_colliding.contains((i as u32, j as u32))
            };
            s.broad_phase.pairs(&s.fat_boxes, wanted, &mut s.fat_pairs);
            s.radii.clear();
            s.radii.extend(
                bodies
                    .iter()
                    .map(|b| b.as_ref().map_or(0.0, Body::bounding_radius)),
            );
            let room_taken = &mut s.neighbours.room_taken;
            s.crowded = crowded(&s.fat_pairs, fixed, &s.radii, room_taken);
        }
        // The candidates: the pairs whose bounds overlap now, in the broad phase's order.
        let boxes = &s.boxes;
        let overlap = |&(i, j): &(u32, u32)| match (&boxes[i as usize], &boxes[j as usize]) {
            (Some(a), Some(b)) => a.overlaps(b),
            _ => false,
        };
        s.pairs.clear();
        if s.held.is_empty() {
            s.pairs.extend(s.fat_pairs.iter().copied().filter(overlap));
        } else {
            s.fixed_now.clear();
            s.fixed_now
                .extend(bodies.iter().map(|b| b.as_ref().is_none_or(Body::is_fixed)));
            let fixed_now = &s.fixed_now;
            let one_moves = |&(i, j): &(u32, u32)| !(fixed_now[i as usize] & fixed_now[j as usize]);
            s.pairs.extend(
                s.fat_pairs
                    .iter()
                    .copied()
                    .filter(|p| one_moves(p) && overlap(p)),
            );
        }
        if s.crowded {
            s.grown_by.clear();
            s.grown_by
                .extend(s.reach.iter().map(|reach| 0.5 * margin + reach));
            let sizes = (&s.boxes[..], &s.grown_by[..], &s.radii[..]);
            keep_nearest_neighbours(&mut s.pairs, &s.fat_fixed, sizes, &mut s.neighbours);
        }
    }

    /// Broad phase, then SAT on each candidate pair (SPEC §3.1), or the pair's last
    /// manifold where it has barely moved (`collide::reuse`).
    ///
    /// Each body's bounds and contact margin grow by how far it can move this step, so a
    /// contact is found (as a speculative one) before the bodies meet, however fast; those
    /// that cannot act this step are then dropped (`drop_idle_manifolds`).
    fn detect_contacts(&mut self, dt: f64, pipeline: Pipeline) {
        let started = stage_clock::mark();
        if !std::mem::take(&mut self.scratch.candidates_current) {
            self.find_candidate_pairs(dt);
        }
        stage_clock::record(Stage::BroadPhase, started);
        let started = stage_clock::mark();
        let s = &mut self.scratch;
        let margin = self.settings.contact_margin();
        self.manifolds.clear();
        self.contacts.clear();
        let tie = self.settings.tie_tolerance();
        let reuse_tolerance = self.settings.manifold_reuse_tolerance();
        let cache = &mut self.manifold_caches[pipeline as usize];
        if self.settings.reuse_manifolds {
            cache.begin_step();
        } else {
            cache.clear();
        }
        for &(i, j) in &s.pairs {
            let (a, b) = (BodyHandle(i), BodyHandle(j));
            let (pose_a, pose_b) = (&s.poses[i as usize], &s.poses[j as usize]);
            let pair_margin = margin + s.reach[i as usize] + s.reach[j as usize];
            // A reused manifold is made in its place in the list (`reuse_into`).
            let limits = (pair_margin, reuse_tolerance);
            if self.settings.reuse_manifolds
                && cache.reuse_into((a, pose_a), (b, pose_b), limits, &mut self.manifolds)
            {
                continue;
            }
            s.polygons[i as usize].ensure_normals();
            s.polygons[j as usize].ensure_normals();
            let found = collide_polygons_into(
                (a, &s.polygons[i as usize]),
                (b, &s.polygons[j as usize]),
                (pair_margin, tie),
                &mut self.manifolds,
            );
            // A pair that may move past the reuse tolerance in this step will not be reused
            // at the next one: the smash's debris found ~50,000 manifolds a step and reused
            // ~1,300.
            let (motion_a, motion_b) = (s.motion[i as usize], s.motion[j as usize]);
            if found
                && self.settings.reuse_manifolds
                && !relative_reach_exceeds(motion_a, motion_b, reuse_tolerance)
                && let Some(m) = self.manifolds.last()
            {
                cache.store(m, (pose_a, pose_b), pair_margin);
            }
        }
        stage_clock::record(Stage::NarrowPhase, started);
        let started = stage_clock::mark();
        self.drop_idle_manifolds(margin);
        for m in &self.manifolds {
            let body = |h: BodyHandle| self.bodies.get(h.index()).and_then(Option::as_ref);
            let (Some(a), Some(b)) = (body(m.body_a), body(m.body_b)) else {
                continue;
            };
            let friction = mixed_friction(
                a.friction.unwrap_or(self.friction),
                b.friction.unwrap_or(self.friction),
            );
            let start = &self.scratch.start_velocities;
            let approach = |h: BodyHandle, body: &Body, point: Vec2| {
                let (v, w) = start
                    .get(h.index())
                    .copied()
                    .unwrap_or((body.velocity, body.angular_velocity));
                (v + crate::math::cross_scalar(w, point - body.position)).dot(&m.normal)
            };
            for p in m.points() {
                let approach_velocity =
                    approach(m.body_a, a, p.position) - approach(m.body_b, b, p.position);
                // Without velocities kept from the step's start (the soft step's forces
                // act inside its substeps), the approach is the velocity now.
                let normal_velocity = if start.is_empty() {
                    approach_velocity
                } else {
                    (a.velocity_at(p.position) - b.velocity_at(p.position)).dot(&m.normal)
                };
                self.contacts.push(Contact {
                    body_a: m.body_a.0,
                    body_b: m.body_b.0,
                    point: p.position,
                    normal: m.normal,
                    depth: p.depth,
                    id: p.id,
                    restitution: a.restitution.min(b.restitution),
                    friction,
                    approach_velocity,
                    normal_velocity,
                    normal_impulse: 0.0,
                    tangent_impulse: 0.0,
                });
            }
        }
        stage_clock::record(Stage::Contacts, started);
    }

    /// Drops the speculative manifolds that cannot act this step: every point farther off
    /// than the two bodies can close on each other (`relative_reach`), allowing for how
    /// far a collision within the step may turn either one off its course.
    ///
    /// Each body's reach finds the manifolds whatever way a collision may send it; of
    /// those, the smash's debris flying off together kept ~35,000 a step that could not
    /// act, of ~51,000. The allowance is the guard for the turn: a body closing on others
    /// at speed v along their normals may change velocity by up to 2v (a bounce), and a
    /// pinned or motor-driven body by anything. Dropped on the relative reach alone, a
    /// random throw's pentagon bounced off a wall into a triangle it had no points with,
    /// 0.12 m deep.
    fn drop_idle_manifolds(&mut self, margin: f64) {
        let s = &mut self.scratch;
        let motion = &s.motion;
        let gap_after = |m: &Manifold| {
            let (a, b) = (motion[m.body_a.index()], motion[m.body_b.index()]);
            -m.depth() - relative_reach(a, b)
        };
        // A manifold within the margin can close whatever the bodies do: a pile's, and
        // anything at rest, found without a square root.
        let within = |m: &Manifold| -m.depth() <= margin;
        if self.manifolds.iter().all(within) {
            return;
        }
        s.gaps.clear();
        s.gaps.extend(self.manifolds.iter().map(gap_after));
        // How far each body may be turned off its course this step.
        s.turn_off.clear();
        s.turn_off.resize(self.bodies.len(), 0.0);
        for &i in &self.jointed {
            s.turn_off[i as usize] = f64::INFINITY;
        }
        for (h, _) in &self.body_motors {
            s.turn_off[h.index()] = f64::INFINITY;
        }
        for (m, _) in self
            .manifolds
            .iter()
            .zip(&s.gaps)
            .filter(|(_, g)| **g <= margin)
        {
            let ((shift_a, turn_a), (shift_b, turn_b)) =
                (motion[m.body_a.index()], motion[m.body_b.index()]);
            let closing = (-(shift_a - shift_b).dot(&m.normal)).max(0.0) + turn_a + turn_b;
            s.turn_off[m.body_a.index()] += 2.0 * closing;
            s.turn_off[m.body_b.index()] += 2.0 * closing;
        }
        let mut k = 0;
        self.manifolds.retain(|m| {
            let allowance = s.turn_off[m.body_a.index()] + s.turn_off[m.body_b.index()];
            let keep = s.gaps[k] <= margin + allowance;
            k += 1;
            keep
        });
    }

    /// The thesis removes overlap directly: each pair is pushed apart along its normal by
    /// its depth, shared by inverse mass (SPEC §3.1). Positions only.
    fn push_apart(&mut self) {
        if self.impulse_solver() == ContactSolver::Exact {
            return; // the exact solver removes depth by split impulses instead
        }
        for m in &self.manifolds {
            let depth = m.depth();
            if depth <= 0.0 {
                continue;
            }
            let (ia, ib) = (m.body_a.index(), m.body_b.index());
            let inv_a = self.bodies[ia].as_ref().map_or(0.0, |b| b.inv_mass);
            let inv_b = self.bodies[ib].as_ref().map_or(0.0, |b| b.inv_mass);
            let total = inv_a + inv_b;
            if total == 0.0 {
                continue;
            }
            if let Some(a) = self.bodies[ia].as_mut() {
                a.position += m.normal * (depth * inv_a / total);
            }
            if let Some(b) = self.bodies[ib].as_mut() {
                b.position -= m.normal * (depth * inv_b / total);
            }
        }
    }

    /// Stages 5–6: contact impulses (with pins and motors in the exact solver), then joint
    /// position prediction, then (exact solver) the split-impulse depth correction.
    fn solve_constraints(&mut self, dt: f64) {
        let solver = self.impulse_solver();
        self.gather_solver_bodies();
        let s = &mut self.scratch;
        let targets = VelocityTargets {
            dt,
            bounce_below: restitution_threshold(self.gravity, dt),
            friction: true,
            close_joint_gaps: true,
        };
        match solver {
            ContactSolver::Sequential | ContactSolver::Soft | ContactSolver::Auto => {
                s.simultaneous.reports.clear();
                solve_sequential(
                    &mut self.contacts,
                    &mut s.solver_bodies,
                    dt,
                    targets.bounce_below,
                )
            }
            ContactSolver::Thesis | ContactSolver::Exact => {
                let model = if solver == ContactSolver::Thesis {
                    FrictionModel::TwoStage
                } else {
                    FrictionModel::Coupled
                };
                s.simultaneous.dense_row_limit = self.settings.dense_row_limit;
                s.simultaneous.solve(
                    model,
                    &mut self.contacts,
                    &mut s.joint_constraints,
                    &mut s.solver_bodies,
                    &targets,
                );
            }
        }
        if !s.joint_constraints.is_empty() {
            let it = self.settings.joint_iterations(dt);
            s.joint_solver.correct_positions(
                self.settings.joint_solver,
                &mut s.joint_constraints,
                &mut s.solver_bodies,
                dt,
                &it,
                solver == ContactSolver::Exact,
            );
        }
        if solver == ContactSolver::Exact {
            s.simultaneous.dense_row_limit = self.settings.dense_row_limit;
            s.simultaneous.separate(
                &self.contacts,
                &s.joint_constraints,
                &mut s.solver_bodies,
                dt,
                self.settings.slop(),
                SPLIT_IMPULSE_RATE,
            );
        }
        self.scatter_solver_bodies();
    }

    /// How each island was solved in the last step: by which method (see
    /// `IslandMethod`), with how many contacts, joints and rows. Under `exact` and
    /// `thesis` the last substep's islands; under `soft` the step's; under `auto` both passes'.
    pub fn island_reports(&self) -> &[IslandReport] {
        match self.settings.contact_solver {
            ContactSolver::Soft => &self.scratch.soft.reports,
            ContactSolver::Auto => &self.scratch.auto_reports,
            _ => &self.scratch.simultaneous.reports,
        }
    }

    /// Positions follow velocities (SPEC §3.4 step 7).
    fn integrate_positions(&mut self, dt: f64) {
        let gravity = self.gravity;
        let explicit = self.settings.integrator == Integrator::ExplicitEuler;
        for b in self.bodies.iter_mut().flatten() {
            if b.is_fixed() {
                continue;
            }
            let (v, w) = if explicit {
                // Undo this step's force contribution: the position uses the old velocity,
                // plus whatever impulses (contacts, joints) changed since.
                let force_dv = (gravity + b.force * b.inv_mass) * dt;
                let force_dw = b.torque * b.inv_inertia * dt;
                (b.velocity - force_dv, b.angular_velocity - force_dw)
            } else {
                (b.velocity, b.angular_velocity)
            };
            b.position += v * dt;
            b.angle += w * dt;
        }
    }

    fn clear_forces(&mut self) {
        for b in self.bodies.iter_mut().flatten() {
            b.force = Vec2::zeros();
            b.torque = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::ConvexPolygon;

    /// A manifold that goes into the kept plan's lanes is not written to the soft step's
    /// points; when the plan changes after all, or something bounces, they are built
    /// again. A pile stepped so must move exactly as one whose every point is written,
    /// through a box landing on it (the plan changes) and one bouncing on its top box
    /// (restitution is the smaller of the two bodies': only the top box has any).
    #[test]
    fn points_left_unwritten_change_no_step() {
        let (h, rows) = (1.0 / 60.0, 8);
        let pile = |write_every_point| {
            let mut world = World::new(Vec2::new(0.0, 10.0));
            world.settings.contact_solver = ContactSolver::Soft;
            world.friction = 0.6;
            let floor = ConvexPolygon::rectangle(40.0, 1.0).unwrap();
            world
                .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
                .unwrap();
            let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
            for row in 0..rows {
                for i in 0..rows - row {
                    let x = i as f64 - 0.5 * (rows - 1 - row) as f64;
                    let centre = Vec2::new(x, -0.5 - row as f64);
                    let def = BodyDef::new(unit.clone(), 1.0).at(centre, 0.0);
                    let top = row == rows - 1;
                    world
                        .add_body(if top { def.restitution(0.5) } else { def })
                        .unwrap();
                }
            }
            world.scratch.soft.write_every_point = write_every_point;
            world
        };
        let (mut skipping, mut writing) = (pile(false), pile(true));
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for step in 0..300 {
            let dropped = match step {
                90 => Some((BodyDef::new(unit.clone(), 1.0), -3.0)),
                180 => Some((BodyDef::new(unit.clone(), 1.0).restitution(0.5), 0.1)),
                _ => None,
            };
            if let Some((def, x)) = dropped {
                let def = def.at(Vec2::new(x, -(rows as f64) - 3.0), 0.1);
                skipping.add_body(def.clone()).unwrap();
                writing.add_body(def).unwrap();
            }
            skipping.step(h);
            writing.step(h);
            let bits = |w: &World| -> Vec<u64> {
                w.bodies()
                    .flat_map(|(_, b)| b.state())
                    .map(f64::to_bits)
                    .collect()
            };
            assert_eq!(bits(&skipping), bits(&writing), "step {step}");
        }
        let (skipped, rebuilt) = skipping.scratch.soft.steps_skipping;
        assert!(skipped > 200, "{skipped} steps left points unwritten");
        // The landing's step or two, and every step from the bouncing box's first
        // contact on.
        assert!(
            (50..150).contains(&rebuilt),
            "{rebuilt} built their points again"
        );
        assert_eq!(writing.scratch.soft.steps_skipping, (0, 0));
    }

    /// The broad phase keeps its pairs while bodies stay inside their grown bounds; the
    /// candidates must still be exactly the pairs whose bounds overlap now.
    #[test]
    fn candidates_are_the_overlapping_pairs_while_the_broad_phase_keeps_its_pairs() {
        let mut world = World::new(Vec2::zeros());
        world.settings.contact_solver = ContactSolver::Soft;
        let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        // A grid of boxes drifting slowly, each its own way: a few hundredths of a box
        // per step, so that the grown bounds hold for some steps and not for others.
        for i in 0..8 {
            for j in 0..8 {
                let (x, y) = (1.3 * i as f64, 1.3 * j as f64);
                let v = Vec2::new(
                    ((3 * i + j) % 5) as f64 - 2.0,
                    ((i + 2 * j) % 5) as f64 - 2.0,
                );
                let def = BodyDef::new(square.clone(), 1.0).at(Vec2::new(x, y), 0.0);
                world.add_body(def.velocity(v * 0.9, 0.3)).unwrap();
            }
        }
        world
            .add_body(
                BodyDef::new(ConvexPolygon::rectangle(30.0, 1.0).unwrap(), 0.0)
                    .at(Vec2::new(4.5, 11.0), 0.0),
            )
            .unwrap();
        let dt = 1.0 / 60.0;
        let (mut kept, mut found) = (0, 0);
        for _ in 0..300 {
            world.step(dt);
            let before = world.scratch.fat_boxes.clone();
            world.find_candidate_pairs(dt);
            if world.scratch.fat_boxes == before {
                kept += 1;
            } else {
                found += 1;
            }
            assert_eq!(world.scratch.pairs, overlapping_pairs(&world));
        }
        assert!(
            kept > 20 && found > 20,
            "pairs kept {kept} times, found {found} times"
        );
    }

    /// Every pair of bodies, not both fixed, whose bounds overlap now: what the broad
    /// phase must find, by comparing every pair.
    fn overlapping_pairs(world: &World) -> Vec<(u32, u32)> {
        let boxes = &world.scratch.boxes;
        let n = boxes.len();
        let fixed = |i: usize| world.bodies[i].as_ref().is_none_or(Body::is_fixed);
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
    fn pyramid_under_auto() -> World {
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

    /// `auto` holds the soft islands' bodies for its exact pass and the exact ones' for
    /// its soft pass: the broad phase keeps its pairs across the holds, and each pass's
    /// candidates are exactly the overlapping pairs of which a body moves in that pass.
    #[test]
    fn candidates_leave_out_the_pairs_held_still_in_each_pass_of_auto() {
        let mut world = pyramid_under_auto();
        // Apart from the pyramid (a soft island), two stacks of two, each topped by a
        // box twenty times as heavy (exact ones).
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for x in [20.0, 25.0] {
            for (y, density) in [(-0.5, 1.0), (-1.5, 20.0)] {
                let def = BodyDef::new(unit.clone(), density).at(Vec2::new(x, y), 0.1);
                world.add_body(def).unwrap();
            }
        }
        let dt = 1.0 / 60.0;
        for _ in 0..5 {
            world.step(dt);
        }
        assert_eq!(world.mark_soft_islands(dt), (true, true));
        let unheld = world.scratch.pairs.clone();
        assert_eq!(unheld, overlapping_pairs(&world));
        let mut moving_in_pass = vec![];
        for soft in [true, false] {
            let fat_boxes = world.scratch.fat_boxes.clone();
            world.hold_where(soft);
            world.find_candidate_pairs(dt);
            assert_eq!(world.scratch.fat_boxes, fat_boxes, "pairs kept");
            assert_eq!(world.scratch.pairs, overlapping_pairs(&world));
            assert!(world.scratch.pairs.len() < unheld.len());
            moving_in_pass.push(world.scratch.pairs.len());
            world.release_held();
        }
        // Each pass has pairs of its own: the pyramid's, and the stacks' and floor's.
        assert!(moving_in_pass.iter().all(|&n| n > 2), "{moving_in_pass:?}");
    }

    /// `auto` marks the soft islands again only when what the marks are made from changes:
    /// at every step, the kept marks are the ones a fresh marking gives, through row
    /// limits that the arm's island passes as its motor is switched off and on, and the
    /// pyramid falling asleep.
    #[test]
    fn soft_islands_are_marked_again_whenever_what_they_are_made_from_changes() {
        let mut world = pyramid_under_auto();
        world.settings.sleeping = true;
        // A bar on a motor, which never falls asleep.
        let bar = ConvexPolygon::rectangle(2.0, 0.2).unwrap();
        let arm = world
            .add_body(BodyDef::new(bar, 1.0).at(Vec2::new(40.0, -5.0), 0.0))
            .unwrap();
        let mut pin = JointDef::new(arm, None, Vec2::new(40.0, -5.0));
        pin.motor = Some(JointMotor::new(1.0, 10.0));
        let shoulder = world.add_joint(pin).unwrap();
        let dt = 1.0 / 60.0;
        for step in 0..120 {
            let default_limit = StepSettings::default().dense_row_limit;
            match step {
                10 => world.settings.dense_row_limit = 100_000,
                15 | 26 => world.settings.dense_row_limit = default_limit,
                // The arm's island: two rows for its pin, a third for its motor.
                20 => world.settings.dense_row_limit = 2,
                22 | 24 => {
                    let motor = world.joint_mut(shoulder).unwrap().motor.as_mut().unwrap();
                    motor.enabled = step == 24;
                }
                _ => {}
            }
            let kept = world.mark_soft_islands(dt);
            let kept_marks = world.scratch.in_soft_island.clone();
            world.scratch.last_marking.found = None;
            let fresh = world.mark_soft_islands(dt);
            assert_eq!(kept, fresh, "step {step}");
            assert_eq!(kept_marks, world.scratch.in_soft_island, "step {step}");
            world.step(dt);
        }
        let asleep = world.bodies().filter(|(_, b)| b.is_asleep()).count();
        assert_eq!(asleep, 55, "the pyramid fell asleep");
        // Each step marks three times: the check's, the fresh one, the step's own. The
        // first and the last are kept unless something changed: at most 240 times.
        let kept = world.scratch.marks_kept;
        assert!((220..=240).contains(&kept), "marks kept {kept} times");
    }

    /// Debris flying apart leaves its grown bounds every step, so the broad phase pairs
    /// the bare bounds, trying grown ones every `RETRY_GROWN_BOUNDS` pairings; then the
    /// debris is stopped, the grown bounds hold again and their pairs are kept. The
    /// candidates are exactly the overlapping pairs throughout.
    #[test]
    fn candidates_are_the_overlapping_pairs_while_debris_outruns_its_grown_bounds() {
        let mut world = World::new(Vec2::zeros());
        world.settings.contact_solver = ContactSolver::Soft;
        let square = ConvexPolygon::rectangle(0.5, 0.5).unwrap();
        let mut handles = vec![];
        for i in 0..10 {
            for j in 0..10 {
                let at = Vec2::new(0.6 * i as f64, 0.6 * j as f64);
                // Outwards from the middle at up to 23 m/s: 0.4 m a step, four margins.
                let velocity = (at - Vec2::new(2.7, 2.7)) * 6.0;
                let def = BodyDef::new(square.clone(), 1.0).at(at, 0.2);
                handles.push(world.add_body(def.velocity(velocity, 2.0)).unwrap());
            }
        }
        let dt = 1.0 / 60.0;
        let (mut bare, mut grown, mut kept) = (0, 0, 0);
        for step in 0..60 {
            if step == 40 {
                for &h in &handles {
                    let body = world.body_mut(h).unwrap();
                    body.velocity = Vec2::zeros();
                    body.angular_velocity = 0.0;
                }
            }
            // The step's own broad phase, at the poses the step began with.
            let before = world.scratch.fat_boxes.clone();
            world.step(dt);
            let s = &world.scratch;
            if s.fat_boxes == before {
                kept += 1;
            } else if s.fat_boxes == s.boxes {
                bare += 1;
            } else {
                grown += 1;
            }
            assert_eq!(s.pairs, overlapping_pairs(&world), "step {step}");
        }
        assert!(
            bare > 30 && grown >= 5 && kept > 15,
            "bare bounds paired {bare} times, grown {grown}, pairs kept {kept} times"
        );
    }
}
