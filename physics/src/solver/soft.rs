//! The iterative "soft step" solver for big islands, after the design of Box2D v3:
//! substeps with soft contact constraints (a stiffness in Hz with damping), a relax pass
//! without bias, restitution once at the end above a speed threshold, warm starting from
//! the last step's impulses, speculative contacts, and contact anchors fixed for the step.
//!
//! Each substep: integrate velocities, warm start / solve with bias, integrate positions,
//! relax without bias. Contacts are found once per step; separations follow the bodies
//! through the substeps by their anchors.

use super::SolverBody;
use super::contact::{Contact, ContactMemory};
use super::envelope::EnvelopeCholesky;
use super::island::IslandGrouping;
use super::joint::JointConstraint;
use super::lcp::{FrictionBound, LcpMethod, LcpProblem, LcpSolver, REGULARISATION};
use super::simultaneous::{IslandMethod, IslandReport};
use crate::math::{Rot, Vec2, clamp, cross, cross_scalar, greater, lesser, perp};
use crate::stage_clock::{self, Stage};
use batch::{AskedFor, LaneBatch, LanePath, PassItem, PassPlan, PassSettings, PlanInput};
use pins::{PinPass, PinPlan};
use std::ops::Range;

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod batch;
mod lanes;
mod pins;

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

/// Joint islands up to this many pins are solved as one linear system per pass (a dense
/// Cholesky of 2m × 2m); larger ones pin by pin, in coloured batches (`pins`). One pass of
/// pin-by-pin Gauss–Seidel cannot hold a light chain under a heavy load: the error
/// travels one link per pass.
const DIRECT_JOINT_LIMIT: usize = 64;

/// Tuning of the soft step; defaults after Box2D v3, scaled by the world's length scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SoftSettings {
    pub substeps: usize,
    /// Contact stiffness (Hz), capped at a quarter of the substep rate for stability;
    /// twice as stiff against a fixed body (as Box2D v3), which holds a pile up from
    /// below: the 625 jammed discs of Box2D's Confined sample crept 138 mm over 8 s at
    /// one stiffness, 6.7 mm at two.
    pub contact_hertz: f64,
    pub contact_damping_ratio: f64,
    pub joint_hertz: f64,
    pub joint_damping_ratio: f64,
    /// The fastest a soft contact pushes overlapping bodies apart (length units / s).
    pub max_push_speed: f64,
    /// The deepest a soft contact lets its bodies sink in one substep's biased pass
    /// (length units): see `sinking_floor`.
    pub max_soft_depth: f64,
    /// The fastest a soft pin pulls its anchors together (length units / s).
    pub joint_push_speed: f64,
    /// Whether every other pair of substeps sweeps the colours backwards (`SweepOrder`).
    pub alternating_sweeps: bool,
}

impl SoftSettings {
    pub(crate) fn for_length_scale(length_scale: f64) -> Self {
        Self {
            substeps: 4,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
            max_push_speed: 3.0 * length_scale,
            max_soft_depth: 0.1 * length_scale,
            // Far faster than contacts: a loaded net of pins (100 × 100, hanging from
            // seven) opened to 16 m with pins capped at 3 length scales per second, and
            // to 0.49 m (as Box2D v3's, which has no cap) at 100.
            joint_push_speed: 100.0 * length_scale,
            alternating_sweeps: true,
        }
    }
}

/// Mass and impulse scaling of a soft constraint (Box2D's b2Softness): a spring–damper of
/// the given frequency and damping ratio, made implicit over the substep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Softness {
    bias_rate: f64,
    mass_scale: f64,
    impulse_scale: f64,
}

impl Softness {
    fn new(hertz: f64, zeta: f64, h: f64) -> Self {
        if hertz == 0.0 {
            return Self {
                bias_rate: 0.0,
                mass_scale: 1.0,
                impulse_scale: 0.0,
            };
        }
        let omega = std::f64::consts::TAU * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// A body during the soft step: velocity, inverse mass, and how far it moved this step.
///
/// Laid out for the batches' SIMD paths (`avx2::Avx2Lanes::gather`, `avx512`), which read
/// each body's `v, w, inv_mass` as one 32-byte row and `dp, dq` as another, and
/// transpose them into lanes: the two rows start at 0 and 32 bytes. A body is 64-byte
/// aligned, so that both rows lie in one cache line: at 96 bytes a body, every other one
/// straddled two, and on the Zen 1, where a big pile's bodies do not stay in the level-2
/// cache, large_pyramid's passes took 8–10% longer (docs/bench/profile.md).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(64))]
struct SoftBody {
    v: Vec2,
    w: f64,
    inv_mass: f64,
    /// Displacement and rotation since the start of the step.
    dp: Vec2,
    dq: Rot,
    inv_inertia: f64,
    dangle: f64,
}

/// Which four numbers of a body a batch reads together (`SoftBody::row`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum BodyRow {
    /// `v.x, v.y, w, inv_mass`.
    Velocity,
    /// `dp.x, dp.y, dq.cos, dq.sin`.
    Motion,
}

// The rows `SoftBody::row_offset` names.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<Vec2>() == 16 && size_of::<Rot>() == 16);
    assert!(offset_of!(SoftBody, v) == 0 && offset_of!(SoftBody, w) == 16);
    assert!(offset_of!(SoftBody, inv_mass) == 24);
    assert!(offset_of!(SoftBody, dp) == 32 && offset_of!(SoftBody, dq) == 48);
    assert!(offset_of!(Rot, cos) == 0 && offset_of!(Rot, sin) == 8);
    assert!(std::mem::align_of::<SoftBody>() == 64 && size_of::<SoftBody>() == 128);
};

impl SoftBody {
    /// The four numbers of `row`, in its order.
    fn row(&self, row: BodyRow) -> [f64; 4] {
        match row {
            BodyRow::Velocity => [self.v.x, self.v.y, self.w, self.inv_mass],
            BodyRow::Motion => [self.dp.x, self.dp.y, self.dq.cos, self.dq.sin],
        }
    }

    /// Where `row` starts, in f64s from the start of the body (the layout asserted below
    /// the struct).
    #[cfg(target_arch = "x86_64")]
    const fn row_offset(row: BodyRow) -> usize {
        match row {
            BodyRow::Velocity => 0,
            BodyRow::Motion => 4,
        }
    }

    /// The body a batch's unused lanes point at: fixed and at rest.
    fn null() -> Self {
        Self {
            dq: Rot { cos: 1.0, sin: 0.0 },
            ..Self::default()
        }
    }

    /// Whether impulses move it (a fixed body, static, asleep or held, has no inverse mass).
    fn moves(&self) -> bool {
        self.inv_mass > 0.0 || self.inv_inertia > 0.0
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct PointConstraint {
    contact: u32,
    a: u32,
    b: u32,
    normal: Vec2,
    /// The anchors' levers about the normal and the tangent (`r × n`, `r × t` on A and
    /// on B), fixed for the step like the anchors: a row's velocity and impulse use them
    /// instead of crossing the arms again at every pass.
    levers: PointLevers,
    /// Separation at the start, minus the anchors' part, so that the current separation is
    /// `n·(Δ(p_a + r_a) − Δ(p_b + r_b)) + base_separation`.
    base_separation: f64,
    normal_mass: f64,
    tangent_mass: f64,
    friction: f64,
    restitution: f64,
    relative_velocity: f64,
    normal_impulse: f64,
    tangent_impulse: f64,
    max_normal_impulse: f64,
    /// How fast gravity and forces close the gap (along −normal), for the impact speed.
    closing_acceleration: f64,
    /// The fastest impact `approach` may record: the approach at the step's start plus
    /// what the closing acceleration adds over the step. Any faster is speed the step's
    /// other contacts gave the bodies, which a bounce must not return: a small body
    /// wedged between a wall and another body gained half its speed again each step,
    /// bounced off the one and the other in turn.
    fastest_impact: f64,
    /// With the next point: their 2 × 2 normal mass matrix, when the two are one
    /// manifold's and the block is well conditioned (solved together).
    pair_coupling: Option<NormalBlock>,
}

/// The 2 × 2 normal mass matrix K of a manifold's two points and its inverse, computed
/// once per step so that the passes do not divide.
#[derive(Debug, Clone, Copy, PartialEq)]
struct NormalBlock {
    k11: f64,
    k12: f64,
    k22: f64,
    inverse: (f64, f64, f64),
}

impl NormalBlock {
    /// The block of two points `p`, `q` of one manifold between bodies `a` and `b`, if it
    /// is well conditioned.
    fn of(
        pair: (&SoftBody, &SoftBody),
        (p, q): (&PointConstraint, &PointConstraint),
    ) -> Option<Self> {
        Self::of_levers(pair, (p.levers.normal, q.levers.normal))
    }

    /// `of` for two points whose normal levers (`PointLevers::normal`) are `l1` and `l2`.
    #[inline(always)]
    fn of_levers(
        (a, b): (&SoftBody, &SoftBody),
        (l1, l2): ((f64, f64), (f64, f64)),
    ) -> Option<Self> {
        // Multiplied out again rather than taken as 1 / normal_mass, and the inverse
        // from one reciprocal: divisions were the slowest part of building the points.
        let m = a.inv_mass + b.inv_mass;
        let inertias = (a.inv_inertia, b.inv_inertia);
        let k11 = row_coupling(m, inertias, l1, l1);
        let k12 = row_coupling(m, inertias, l1, l2);
        let k22 = row_coupling(m, inertias, l2, l2);
        let det = k11.mul_add(k22, -(k12 * k12));
        (k11 > 0.0 && k22 > 0.0 && k11 * k11 < MAX_BLOCK_CONDITION * det).then(|| {
            let inv_det = 1.0 / det;
            Self {
                k11,
                k12,
                k22,
                inverse: (k22 * inv_det, -k12 * inv_det, k11 * inv_det),
            }
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct PointLevers {
    normal: (f64, f64),
    /// `r · n` on A and on B: how far each anchor reaches along the normal. Also the
    /// tangent row's levers: r × perp(n) = r · n.
    reach: (f64, f64),
}

impl PointLevers {
    /// The levers of contact `c` about its bodies' centroids at the step's start.
    #[inline(always)]
    fn of(bodies: &[SolverBody], c: &Contact) -> Self {
        let (a, b) = (&bodies[c.body_a as usize], &bodies[c.body_b as usize]);
        let n = c.normal;
        let (r_a, r_b) = (c.point - a.position, c.point - b.position);
        // r × n and r · n, each product added with one rounding (see `BodyPair`).
        let lever = |r: Vec2| r.x.mul_add(n.y, -(r.y * n.x));
        let reach = |r: Vec2| r.y.mul_add(n.y, r.x * n.x);
        Self {
            normal: (lever(r_a), lever(r_b)),
            reach: (reach(r_a), reach(r_b)),
        }
    }

    /// The tangent row's lever arms, r × t with t = perp(n): the reach, r · n.
    fn tangent(&self) -> (f64, f64) {
        self.reach
    }
}

/// J M⁻¹ Jᵀ of two rows along one direction between the same two bodies: `inv_masses` the
/// bodies' summed inverse masses, `inertias` their inverse inertias, and each row's levers
/// (`r × n` on A and on B). With one row twice, the inverse of its effective mass.
#[inline(always)]
fn row_coupling(
    inv_masses: f64,
    (ia, ib): (f64, f64),
    (a1, b1): (f64, f64),
    (a2, b2): (f64, f64),
) -> f64 {
    (ib * b1).mul_add(b2, (ia * a1).mul_add(a2, inv_masses))
}

/// Two points of one manifold are solved as a block only when their 2 × 2 matrix has a
/// condition number below this (Box2D v2's bound); nearly parallel rows go one by one.
const MAX_BLOCK_CONDITION: f64 = 1000.0;

#[derive(Debug, Clone, Copy, PartialEq)]
struct SoftJoint {
    a: u32,
    b: u32,
    r_a: Vec2,
    r_b: Vec2,
    /// Anchor separation at the start of the step (A − B).
    base_gap: Vec2,
    impulse: Vec2,
    motor_impulse: f64,
    /// The motor's angular impulse summed over this step's substeps.
    motor_step_total: f64,
    motor: Option<(f64, f64)>,
    slot: u32,
    /// Its index in the step's input joints (the solver reorders them by island).
    input: u32,
}

/// Last step's pin impulses (linear, and the motor's angular one) by joint slot.
#[derive(Debug, Clone, Default)]
struct JointMemory {
    /// `(slot, impulse, motor impulse)`, sorted by slot.
    entries: Vec<(u32, Vec2, f64)>,
    /// This step's, by the pin's index among the step's input joints (`Self::NONE`'s slot
    /// where it keeps none), until `finish` makes them the entries.
    by_input: Vec<(u32, Vec2, f64)>,
}

impl JointMemory {
    const NONE: (u32, Vec2, f64) = (u32::MAX, Vec2::new(0.0, 0.0), 0.0);

    /// Starts a step of `inputs` joints; `recall` still reads the last step's.
    fn begin(&mut self, inputs: usize) {
        self.by_input.clear();
        self.by_input.resize(inputs, Self::NONE);
    }

    /// The pin `slot`'s impulses of the last step. The step's joints come in slot order,
    /// so `cursor` walks the entries once; a pin found behind it is searched for.
    fn recall(&self, slot: u32, cursor: &mut usize) -> Option<(u32, Vec2, f64)> {
        while self.entries.get(*cursor).is_some_and(|m| m.0 < slot) {
            *cursor += 1;
        }
        match self.entries.get(*cursor) {
            Some(&m) if m.0 == slot => Some(m),
            _ => self
                .entries
                .binary_search_by_key(&slot, |m| m.0)
                .ok()
                .map(|k| self.entries[k]),
        }
    }

    /// Keeps the impulses of the step's input joint `input` for the next step.
    fn keep(&mut self, input: u32, entry: (u32, Vec2, f64)) {
        self.by_input[input as usize] = entry;
    }

    /// The kept impulses become the ones to recall.
    fn finish(&mut self) {
        self.entries.clear();
        let kept = self.by_input.iter().filter(|e| e.0 != Self::NONE.0);
        self.entries.extend(kept);
        // Input order is slot order, unless a caller gave the joints otherwise.
        if !self.entries.is_sorted_by_key(|e| e.0) {
            self.entries.sort_unstable_by_key(|e| e.0);
        }
    }
}

/// Warm-start memory and buffers, kept between steps.
#[derive(Debug, Clone, Default)]
pub(crate) struct SoftStepSolver {
    bodies: Vec<SoftBody>,
    points: Vec<PointConstraint>,
    joints: Vec<SoftJoint>,
    spare_joints: Vec<SoftJoint>,
    /// Last step's contact impulses, recalled as this step's points are built.
    memory: ContactMemory,
    /// Each contact's impulses from the last step (`ContactMemory::recall`).
    recalled: Vec<(f64, f64)>,
    /// Each contact's impulses from this step, gathered from the lanes and the points
    /// before they go into the contacts in one sweep (`store`).
    impulses: Vec<(f64, f64)>,
    joint_memory: JointMemory,
    /// The pinned bodies' rotations at the step's start, found as the pins need them.
    rotations: Vec<Option<Rot>>,
    /// `joints` indices of the pins with a motor, in `joints`' order.
    motor_joints: Vec<u32>,
    /// By body, whether a pin joins it (empty if there are no pins): such a body's
    /// island is solved with the rest, not in a chunk (`PassPlan::assign_chunks`).
    pinned: Vec<bool>,
    /// Whether a fixed body has a velocity this step (a static body the caller set moving):
    /// its motion counts in every substep of the islands it touches, which a chunk solved
    /// apart would not see, so the chunks are then solved with the rest.
    a_fixed_body_moves: bool,
    /// `points` index ranges, one per island of contacts.
    contact_islands: Vec<(usize, usize)>,
    /// `joints` index ranges, one per island of pins, and the buffers of their solve.
    joint_islands: Vec<(usize, usize)>,
    /// The big pin islands' batches (`pins`).
    pin_plan: PinPlan,
    /// The contacts' islands, kept while the contacts stay between the same bodies.
    contact_grouping: IslandGrouping,
    /// The pins' islands, kept while the pins join the same bodies.
    joint_grouping: IslandGrouping,
    block: JointBlock,
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
    /// How each island was solved in the last step.
    pub reports: Vec<IslandReport>,
    /// Tests only: every point written, as if no manifold went straight into its lane.
    #[cfg(test)]
    pub(crate) write_every_point: bool,
    /// Tests only: steps that left points unwritten, and steps that built them again.
    #[cfg(test)]
    pub(crate) steps_skipping: (usize, usize),
    /// Tests only: steps that made their plan before their points.
    #[cfg(test)]
    pub(crate) steps_planned_first: usize,
}

/// The direction of a substep's two sweeps (biased, then relaxed) over the colours of the
/// big islands (the small ones keep the points' order: a stack's bottom first, which
/// holds the sweep's stacks a little closer to their rest).
///
/// Gauss–Seidel leaves the constraints it solved last best satisfied: swept always
/// first to last, the colours favour some constraints over others at every step. Two
/// substeps forwards, then two backwards, cancel that to first order (symmetric
/// Gauss–Seidel). With the colours given in the points' order, it took the 100-row
/// pyramid's largest top sway from 0.23 of a box to 0.022; flipping every substep helped
/// less (0.086), flipping only the relax pass less still (0.15). With the colours
/// scattered (`batch::PassPlan::colour_in_scattered_order`) the sway is 0.0065 swept one
/// way and 0.0025 alternating (Box2D v3: 0.0094): see docs/bench/profile.md.
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

/// The system of one island of pins, its buffers reused between passes.
#[derive(Debug, Clone, Default)]
struct JointBlock {
    arms: Vec<(Vec2, Vec2)>,
    /// K, row-major, its lower triangle filled.
    k: Vec<f64>,
    rhs: Vec<f64>,
    /// This step's factor of each island's K, by island (`SoftStepSolver::joint_islands`).
    factors: Vec<IslandFactor>,
    /// Tests only: K factored in every pass, and how many times it was.
    #[cfg(test)]
    factor_every_pass: bool,
    #[cfg(test)]
    factored: usize,
}

/// An island's factor of K and the bits of the arms it was made from. K depends on the
/// arms and on the bodies' masses, which a step does not change, and the arms only on the
/// bodies' rotations: the relax pass of one substep and the biased pass of the next see
/// the same rotations (velocities change between them, positions do not), so the second
/// takes the first's factor, the same to the bit.
#[derive(Debug, Clone, Default)]
struct IslandFactor {
    /// Empty if no factor was made this step.
    arm_bits: Vec<[u64; 4]>,
    factor: EnvelopeCholesky,
}

fn arm_bits(arms: &[(Vec2, Vec2)]) -> impl Iterator<Item = [u64; 4]> + '_ {
    arms.iter()
        .map(|(a, b)| [a.x, a.y, b.x, b.y].map(f64::to_bits))
}

/// The contacts' islands as `build_points` takes them: `(island, contact)` pairs
/// (`IslandGrouping::grouped`), and, where they were taken unchecked, the bodies of the
/// contacts they grouped, by contact (`IslandGrouping::ends`).
type ContactGrouping<'a> = (&'a [(u32, u32)], Option<&'a [(u32, u32)]>);

/// The contact after the `k`-th of `grouped`, if it is the same manifold's second point:
/// it joins the same bodies along the same normal. (A manifold's points share their
/// bodies, so their island.)
fn second_point_of(contacts: &[Contact], grouped: &[(u32, u32)], k: usize) -> Option<u32> {
    let c = &contacts[grouped[k].1 as usize];
    grouped.get(k + 1).map(|&(_, j)| j).filter(|&j| {
        let d = &contacts[j as usize];
        (d.body_a, d.body_b, d.normal) == (c.body_a, c.body_b, c.normal)
    })
}

/// `build_points`' answer when a contact joins other bodies than the grouping it was
/// given says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct ContactsRegrouped;

/// What `build_points` carries from point to point as it reads the contacts.
struct Reading<'a> {
    recall: Recall,
    /// The bodies of the contacts that the grouping taken unchecked grouped, by contact.
    unchecked_ends: Option<&'a [(u32, u32)]>,
    /// Whether a contact joins other bodies than those.
    regrouped: bool,
}

/// How `build_points` finds the last step's impulses: guessing each contact's entry at
/// (or beside) its own index until a guess misses, then from all of them recalled at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Recall {
    Guessing,
    AllRecalled,
}

/// The most a body may turn in one substep (radians).
const MAX_TURN_PER_SUBSTEP: f64 = 0.25 * std::f64::consts::PI;

/// Soft constraints are capped at a quarter of the substep rate for stability.
const MAX_HERTZ_PER_SUBSTEP_RATE: f64 = 0.25;

fn rotate_delta(q: Rot, r: Vec2) -> Vec2 {
    q.apply(r)
}

/// A contact pass's settings for substeps of `h`.
fn contact_pass(h: f64, soft: &Softness, settings: &SoftSettings, use_bias: bool) -> PassSettings {
    PassSettings {
        inv_h: 1.0 / h,
        soft: *soft,
        static_soft: Softness::new(
            (2.0 * settings.contact_hertz).min(MAX_HERTZ_PER_SUBSTEP_RATE / h),
            settings.contact_damping_ratio,
            h,
        ),
        max_push: settings.max_push_speed,
        max_depth: settings.max_soft_depth,
        use_bias,
    }
}

/// A moving body's velocity over a substep of `h`.
fn integrate_velocity(b: &mut SoftBody, (linear, angular): (Vec2, f64), h: f64) {
    b.v += linear * h;
    b.w += angular * h;
    // A body turning more than a quarter turn per substep is beyond what the linearised
    // rotation below (and any contact found at the step's start) can follow; like Box2D,
    // cap the spin there rather than let it overflow to NaN.
    let max_w = MAX_TURN_PER_SUBSTEP / h;
    b.w = clamp(b.w, -max_w, max_w);
}

/// A body's motion since the step's start, over a substep of `h`.
fn integrate_position(b: &mut SoftBody, h: f64) {
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
        stage_clock::record(Stage::Preparing, started);
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
                    integrate_velocity(&mut self.bodies[i], accelerations[i], h);
                }
                let started = stage_clock::mark();
                // The first substep's passes read the chunk's batches from farther out and
                // ask for each next one (`BatchesAhead`); the later ones find them in the
                // level-2 cache, where asking only costs (many_pyramids' solve 7% slower).
                let ask = substep == 0;
                self.warm_start_items(items.clone(), ask);
                stage_clock::record(Stage::WarmStart, started);
                let started = stage_clock::mark();
                self.sweep_items(items.clone(), &pass(true), order, ask);
                for &i in self.plan.chunk(k).1 {
                    integrate_position(&mut self.bodies[i as usize], h);
                }
                self.sweep_items(items.clone(), &pass(false), order, false);
                stage_clock::record(Stage::Solve, started);
            }
        }
        for _ in 0..settings.substeps {
            let order = sweep_order(self.substeps_taken);
            self.substeps_taken = self.substeps_taken.wrapping_add(1);
            self.integrate_velocities(accelerations, h);
            let started = stage_clock::mark();
            self.warm_start();
            stage_clock::record(Stage::WarmStart, started);
            let started = stage_clock::mark();
            self.solve(h, &contact_soft, &joint_soft, settings, true, order);
            self.integrate_positions(h);
            self.solve(h, &contact_soft, &joint_soft, settings, false, order);
            stage_clock::record(Stage::Solve, started);
            // Warm starting re-applies the accumulated impulse in every substep, so the
            // step's total is the sum of the substeps' accumulated values.
            for &k in &self.motor_joints {
                let j = &mut self.joints[k as usize];
                j.motor_step_total += j.motor_impulse;
            }
        }
        if self.may_bounce {
            // Restitution works on the points: they take the batches' impulses first.
            self.plan.scatter(&mut self.points);
            self.restitution(bounce_below);
        }
        self.pin_plan.scatter(&mut self.joints);
        let started = stage_clock::mark();
        self.store(bodies, contacts, joints);
        stage_clock::record(Stage::Storing, started);
        self.report();
    }

    fn prepare(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        joints: &[JointConstraint],
        dt: f64,
    ) {
        let started = stage_clock::mark();
        self.bodies.clear();
        let mut a_fixed_body_moves = false;
        self.bodies.extend(bodies.iter().map(|b| {
            let body = SoftBody {
                v: b.velocity,
                w: b.angular_velocity,
                inv_mass: b.inv_mass,
                inv_inertia: b.inv_inertia,
                dp: Vec2::zeros(),
                dq: Rot { cos: 1.0, sin: 0.0 },
                dangle: 0.0,
            };
            a_fixed_body_moves |= !body.moves() && (body.v != Vec2::zeros() || body.w != 0.0);
            body
        }));
        self.a_fixed_body_moves = a_fixed_body_moves;
        // The null body, last: where a batch's unused lanes point (`batch::PAD`). Fixed
        // and at rest, and past the bodies `store` writes back.
        self.bodies.push(SoftBody::null());
        self.pinned.clear();
        if !joints.is_empty() {
            self.pinned.resize(bodies.len(), false);
            for j in joints {
                self.pinned[j.body_a as usize] = true;
                self.pinned[j.body_b as usize] = true;
            }
        }
        // The points are built island by island (each island's in the contacts' order):
        // grouping the contacts is cheaper than reordering the larger points afterwards.
        // A pile at rest has the same contacts between the same bodies step after step:
        // its last grouping is taken unchecked, and the points, which read every contact,
        // check each one's bodies against it as they are built.
        let mut grouping = std::mem::take(&mut self.contact_grouping);
        let reused = grouping.bodies_kept(contacts.len(), bodies.len(), |i| {
            self.bodies[i as usize].moves()
        });
        if !reused {
            self.group_contacts(&mut grouping, contacts);
        }
        stage_clock::record(Stage::PreparingIslands, started);
        // After a step whose plan changed (debris in flight: every step of the smash), the
        // plan is made from the contacts before the points are built, so that each
        // manifold goes straight into its lane, rather than into the points and from
        // there, read in colour order, into its lane (docs/bench/profile.md, "The plan
        // made before the points").
        let started = stage_clock::mark();
        let may_plan_first = !reused && !self.plan.kept_last_step();
        #[cfg(test)]
        let may_plan_first = may_plan_first && !self.write_every_point;
        let planned_first =
            may_plan_first && self.plan_from_contacts(bodies, contacts, grouping.grouped());
        if planned_first {
            stage_clock::record(Stage::PreparingPlan, started);
        }
        let started = stage_clock::mark();
        // Each manifold goes into the kept plan's lanes as soon as it is complete, and
        // then its points are not written: on a big pile at rest, writing them was a
        // tenth of the step (docs/bench/profile.md, "Points not written").
        if !planned_first {
            self.plan.begin_filling();
        }
        let unchecked = reused.then(|| grouping.ends());
        let built = self.build_points(
            bodies,
            accelerations,
            contacts,
            (grouping.grouped(), unchecked),
            dt,
        );
        let skipped = match built {
            Ok(skipped) => skipped,
            Err(ContactsRegrouped) => {
                // A contact joins other bodies than last step's: grouped afresh, and
                // every point built again.
                self.group_contacts(&mut grouping, contacts);
                let grouped = (grouping.grouped(), None);
                self.build_points(bodies, accelerations, contacts, grouped, dt)
                    .expect("the contacts' own grouping")
            }
        };
        stage_clock::record(Stage::PreparingPoints, started);
        let started = stage_clock::mark();
        self.contact_lcp
            .prepare(&self.bodies, &self.points, &self.contact_islands);
        // The plan was made from the manifolds the points make (the same pairing, from
        // the same levers), and nothing bounces: it stands, its lanes filled.
        debug_assert!(
            !planned_first || (self.plan_inputs == self.planned_inputs && !self.may_bounce)
        );
        let kept = planned_first
            || self.plan.read(
                &self.contact_lcp.all_islands,
                &self.plan_inputs,
                &self.pinned,
            );
        stage_clock::record(Stage::PreparingPlan, started);
        let rebuild = skipped && (!kept || self.may_bounce);
        #[cfg(test)]
        {
            self.steps_skipping.0 += usize::from(skipped);
            self.steps_skipping.1 += usize::from(rebuild);
            self.steps_planned_first += usize::from(planned_first);
        }
        if rebuild {
            // The plan changed after all, or something bounces (restitution reads every
            // point): every point is built again, and written. The LCP islands' points
            // were written already, and the plan's entries come out the same, so the LCP
            // and the plan's reading stand.
            let rebuilt = stage_clock::mark();
            self.plan.stop_filling();
            let grouped = (grouping.grouped(), None);
            self.build_points(bodies, accelerations, contacts, grouped, dt)
                .expect("the contacts' own grouping");
            stage_clock::record(Stage::PreparingPoints, rebuilt);
        }
        self.contact_grouping = grouping;
        if !planned_first {
            let started = stage_clock::mark();
            self.plan.plan(&self.points, &self.bodies);
            stage_clock::record(Stage::PreparingPlan, started);
        }
        // Each pinned body's rotation once: a body of a net carries four pins.
        self.rotations.clear();
        if !joints.is_empty() {
            self.rotations.resize(bodies.len(), None);
        }
        self.joints.clear();
        self.joint_memory.begin(joints.len());
        let mut cursor = 0;
        for (input, j) in joints.iter().enumerate() {
            let (a, b) = (&bodies[j.body_a as usize], &bodies[j.body_b as usize]);
            // A pin between two fixed bodies (asleep, or held for the other solver's pass
            // under `auto`) can do nothing: it is left out, so neither its island nor its
            // motor's reading (the other pass's) is touched.
            let fixed = |b: &SolverBody| b.inv_mass == 0.0 && b.inv_inertia == 0.0;
            let remembered = self.joint_memory.recall(j.joint, &mut cursor);
            if fixed(a) && fixed(b) {
                // Kept, so that the pin warm-starts again when its bodies move.
                if let Some(entry) = remembered {
                    self.joint_memory.keep(input as u32, entry);
                }
                continue;
            }
            let mut turned = |i: u32| {
                *self.rotations[i as usize]
                    .get_or_insert_with(|| Rot::new(bodies[i as usize].angle))
            };
            let (r_a, r_b) = j.arms_turned((turned(j.body_a), turned(j.body_b)));
            let (_, impulse, motor_impulse) = remembered.unwrap_or(JointMemory::NONE);
            let motor = j
                .motor
                .filter(|m| m.enabled)
                .map(|m| (m.target_speed, m.max_torque));
            self.joints.push(SoftJoint {
                a: j.body_a,
                b: j.body_b,
                r_a,
                r_b,
                // The soft step always pulls towards a closed pin (a broken joint too),
                // no faster than `max_push_speed`; the target the other solvers use to
                // repair broken joints over several steps does not apply here.
                base_gap: (a.position + r_a) - (b.position + r_b),
                impulse,
                // Warm starting applies the remembered motor impulse in every substep: a
                // motor switched off or removed must not keep driving its joint with it.
                motor_impulse: if motor.is_some() { motor_impulse } else { 0.0 },
                motor_step_total: 0.0,
                motor,
                slot: j.joint,
                input: input as u32,
            });
        }
        self.group_joints();
        self.block.begin_step(self.joint_islands.len());
        self.motor_joints.clear();
        let motors = self
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.motor.is_some());
        self.motor_joints.extend(motors.map(|(k, _)| k as u32));
        let unchanged = self.joint_grouping.kept();
        self.pin_plan
            .plan(&self.joints, &self.joint_islands, &self.bodies, unchanged);
    }

    /// Plans the passes before the points are built (`PassPlan::plan_before_points`),
    /// from the manifolds' entries read off the contacts in the order of `grouped`, as
    /// `build_points` notes them: a contact and the next are one manifold if they join
    /// the same bodies along the same normal and their 2 × 2 block is well conditioned
    /// (found from their levers alone). Kept in `planned_inputs`, which the points'
    /// entries must equal. Not if a contact may bounce (restitution reads every point, so
    /// they are written anyway): then false, and nothing is planned.
    fn plan_from_contacts(
        &mut self,
        bodies: &[SolverBody],
        contacts: &[Contact],
        grouped: &[(u32, u32)],
    ) -> bool {
        self.planned_inputs.clear();
        let mut k = 0;
        while k < grouped.len() {
            let c = &contacts[grouped[k].1 as usize];
            if c.restitution != 0.0 {
                return false;
            }
            let moves = |i: u32| self.bodies[i as usize].moves();
            let mut input = PlanInput::new(
                (c.body_a, c.body_b),
                k,
                (moves(c.body_a), moves(c.body_b)),
                c.normal,
            );
            let second = second_point_of(contacts, grouped, k);
            if second.is_some_and(|j| contacts[j as usize].restitution != 0.0) {
                return false;
            }
            let coupled = second.is_some_and(|j| {
                let pair = (
                    &self.bodies[c.body_a as usize],
                    &self.bodies[c.body_b as usize],
                );
                let (p, q) = (
                    PointLevers::of(bodies, c),
                    PointLevers::of(bodies, &contacts[j as usize]),
                );
                NormalBlock::of_levers(pair, (p.normal, q.normal)).is_some()
            });
            if coupled {
                input.add_second_point();
                k += 2;
            } else {
                k += 1;
            }
            self.planned_inputs.push(input);
        }
        let ends = |k: usize| {
            let c = &contacts[grouped[k].1 as usize];
            (c.body_a, c.body_b)
        };
        self.contact_lcp
            .classify(&self.bodies, &self.contact_islands, ends);
        self.plan.read(
            &self.contact_lcp.all_islands,
            &self.planned_inputs,
            &self.pinned,
        );
        self.plan.plan_before_points(contacts.len(), &self.bodies);
        true
    }

    /// Groups the contacts by island afresh (`grouping`), and notes each island's range.
    fn group_contacts(&mut self, grouping: &mut IslandGrouping, contacts: &[Contact]) {
        let grouped = grouping.group(
            contacts.len(),
            self.bodies.len() - 1, // not the null body
            |i| (contacts[i].body_a, contacts[i].body_b),
            |i| self.bodies[i as usize].moves(),
        );
        island_ranges(grouped, &mut self.contact_islands);
    }

    /// The contacts' points, in the order of `grouped` (island by island), their
    /// manifolds' entries for the plan (`plan_inputs`), and `may_bounce`. A manifold
    /// that goes into the kept plan's lanes (`PassPlan::fill_manifold`) is not written to
    /// `points`, unless its island is small enough to be solved as an LCP (which reads
    /// its points): its entries there are left from an earlier step. Returns whether any
    /// was left so. Such entries are read only by a changed plan and where something may
    /// bounce (restitution, and the impulses stored from the points), and `prepare` then
    /// builds the points again, with the filling stopped.
    ///
    /// With `unchecked_ends` (the ends of the contacts that `grouped` grouped, by contact),
    /// each contact's bodies are checked against them as its point is built, and one that
    /// differs stops the building at its island's end: the grouping is not this step's.
    fn build_points(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        (grouped, unchecked_ends): ContactGrouping,
        dt: f64,
    ) -> Result<bool, ContactsRegrouped> {
        if self.points.len() < contacts.len() {
            self.points
                .resize(contacts.len(), PointConstraint::default());
        }
        self.points.truncate(contacts.len());
        self.plan_inputs.clear();
        self.may_bounce = false;
        let mut reading = Reading {
            recall: Recall::Guessing,
            unchecked_ends,
            regrouped: false,
        };
        let mut skipped = false;
        // A point built already that begins the next manifold: the second of two
        // whose block was not well conditioned.
        let mut carried: Option<PointConstraint> = None;
        // The island of the current point: where it ends, and whether it may be an LCP
        // island (`ContactLcp::prepare`), which reads its points.
        let (mut island, mut island_end, mut small_island) = (0, 0, true);
        let mut k = 0;
        while k < grouped.len() {
            if k == island_end {
                if reading.regrouped {
                    return Err(ContactsRegrouped);
                }
                let (start, end) = self.contact_islands[island];
                (island, island_end, small_island) =
                    (island + 1, end, end - start <= LCP_POINT_LIMIT);
            }
            let c = &contacts[grouped[k].1 as usize];
            let mut first = match carried.take() {
                Some(p) => p,
                None => self.build_point(
                    bodies,
                    accelerations,
                    contacts,
                    grouped[k].1,
                    dt,
                    &mut reading,
                ),
            };
            // The two are coupled if their block is well conditioned.
            let second = second_point_of(contacts, grouped, k)
                .map(|j| self.build_point(bodies, accelerations, contacts, j, dt, &mut reading));
            let block = second.as_ref().and_then(|q| {
                let pair = (
                    &self.bodies[c.body_a as usize],
                    &self.bodies[c.body_b as usize],
                );
                NormalBlock::of(pair, (&first, q))
            });
            let moves = |i: u32| self.bodies[i as usize].moves();
            let mut input = PlanInput::new(
                (c.body_a, c.body_b),
                k,
                (moves(c.body_a), moves(c.body_b)),
                c.normal,
            );
            if let (Some(block), Some(q)) = (block, second) {
                first.pair_coupling = Some(block);
                input.add_second_point();
                self.plan_inputs.push(input);
                skipped |= self.place_manifold(k, [first, q], small_island);
                k += 2;
            } else {
                self.plan_inputs.push(input);
                skipped |= self.place_manifold(k, [first], small_island);
                carried = second;
                k += 1;
            }
        }
        if reading.regrouped {
            return Err(ContactsRegrouped);
        }
        Ok(skipped)
    }

    /// The point of contact `i` (this step's contacts' index), its impulses recalled from
    /// the last step.
    #[inline(always)]
    fn build_point(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        i: u32,
        dt: f64,
        reading: &mut Reading,
    ) -> PointConstraint {
        let c = &contacts[i as usize];
        if let Some(ends) = reading.unchecked_ends {
            // Noted, not branched on: the building stops at the island's end.
            reading.regrouped |= ends[i as usize] != (c.body_a, c.body_b);
        }
        let recall = &mut reading.recall;
        let (a, b) = (&bodies[c.body_a as usize], &bodies[c.body_b as usize]);
        let levers = PointLevers::of(bodies, c);
        // A row's effective mass, 1 / (m_a⁻¹ + m_b⁻¹ + I_a⁻¹ l_a² + I_b⁻¹ l_b²).
        let mass = |levers: (f64, f64)| {
            let inertias = (a.inv_inertia, b.inv_inertia);
            let k = row_coupling(a.inv_mass + b.inv_mass, inertias, levers, levers);
            if k > 0.0 { 1.0 / k } else { 0.0 }
        };
        // A pile at rest has the same contacts in the same order, each its entry at its
        // own index or beside it (`ContactMemory::guess`); at the first that is not,
        // every contact's impulses are recalled at once, in the contacts' order, which
        // the memory's follows (the points are built in the islands').
        let guessed = match recall {
            Recall::Guessing => self.memory.guess(i as usize, c),
            Recall::AllRecalled => None,
        };
        let (normal_impulse, tangent_impulse) = guessed.unwrap_or_else(|| {
            if *recall == Recall::Guessing {
                self.memory.recall(contacts, &mut self.recalled);
                *recall = Recall::AllRecalled;
            }
            self.recalled[i as usize]
        });
        self.may_bounce |= c.restitution != 0.0;
        // Read only for points that may bounce (`approach`).
        let closing_acceleration = if c.restitution == 0.0 {
            0.0
        } else {
            -(accelerations[c.body_a as usize].0 - accelerations[c.body_b as usize].0)
                .dot(&c.normal)
        };
        PointConstraint {
            contact: i,
            a: c.body_a,
            b: c.body_b,
            normal: c.normal,
            levers,
            base_separation: -c.depth,
            normal_mass: mass(levers.normal),
            tangent_mass: mass(levers.tangent()),
            friction: c.friction,
            restitution: c.restitution,
            relative_velocity: c.approach_velocity,
            normal_impulse,
            tangent_impulse,
            max_normal_impulse: 0.0,
            closing_acceleration,
            fastest_impact: c.approach_velocity - closing_acceleration.max(0.0) * dt,
            pair_coupling: None,
        }
    }

    /// A complete manifold whose first point is `first`: into its lane in the kept plan,
    /// or else written to the points. Returns whether it was left unwritten (see
    /// `build_points`); a small island's always is written, for the LCP.
    #[inline(always)]
    fn place_manifold<const N: usize>(
        &mut self,
        first: usize,
        manifold: [PointConstraint; N],
        small: bool,
    ) -> bool {
        let in_lane = self.plan.fill_manifold(first, &manifold, &self.bodies);
        #[cfg(test)]
        let small = small || self.write_every_point;
        if in_lane && !small {
            return true;
        }
        for (j, p) in manifold.into_iter().enumerate() {
            self.points[first + j] = p;
        }
        false
    }

    /// Records how each island of contacts and of pins was solved.
    fn report(&mut self) {
        self.reports.clear();
        for &(start, end) in &self.joint_islands {
            let pins = end - start;
            self.reports.push(IslandReport {
                contacts: 0,
                joints: pins,
                rows: 2 * pins,
                method: if (2..=DIRECT_JOINT_LIMIT).contains(&pins) {
                    IslandMethod::SoftPinBlock
                } else {
                    IslandMethod::SoftPinByPin
                },
                pivots: 0,
                over_budget: false,
                residual: f64::NAN,
            });
        }
        for &(start, end, lcp) in &self.contact_lcp.all_islands {
            let points = end - start;
            self.reports.push(IslandReport {
                contacts: points,
                joints: 0,
                rows: 2 * points,
                method: if lcp {
                    IslandMethod::SoftLcp
                } else {
                    IslandMethod::SoftPointByPoint
                },
                pivots: 0,
                over_budget: false,
                residual: f64::NAN,
            });
        }
    }

    /// Orders `joints` island by island (pins linked through moving bodies; each island
    /// keeps the joints' order) and records each island's range.
    fn group_joints(&mut self) {
        let (joints, bodies) = (&self.joints, &self.bodies);
        let grouped = self.joint_grouping.group(
            joints.len(),
            bodies.len(),
            |i| (joints[i].a, joints[i].b),
            |i| bodies[i as usize].moves(),
        );
        // A net's pins are one island, in the joints' own order: nothing to move (copying
        // its 19,800 joints cost the joint grid 2% of its step).
        if grouped
            .iter()
            .enumerate()
            .any(|(k, &(_, i))| i as usize != k)
        {
            self.spare_joints.clear();
            self.spare_joints
                .extend(grouped.iter().map(|&(_, i)| joints[i as usize]));
            std::mem::swap(&mut self.joints, &mut self.spare_joints);
        }
        island_ranges(grouped, &mut self.joint_islands);
    }

    /// How many chunks this step solves apart, before the rest (`PassPlan::assign_chunks`).
    /// None if a fixed body moves: then the rest's passes take the chunks' items too, in
    /// their order, which solves every island as the chunks would.
    fn chunks_apart(&self) -> usize {
        if self.a_fixed_body_moves {
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
    fn integrate_velocities(&mut self, accelerations: &[(Vec2, f64)], h: f64) {
        let chunked = self.chunks_apart() > 0;
        let bodies = self.bodies.iter_mut().zip(accelerations).enumerate();
        for (i, (b, &acceleration)) in bodies {
            if b.moves() && !(chunked && self.plan.in_chunk(i)) {
                integrate_velocity(b, acceleration, h);
            }
        }
    }

    /// The rest's bodies' positions (those no chunk moves).
    fn integrate_positions(&mut self, h: f64) {
        let chunked = self.chunks_apart() > 0;
        for (i, b) in self.bodies.iter_mut().enumerate() {
            if !(chunked && self.plan.in_chunk(i)) {
                integrate_position(b, h);
            }
        }
    }

    fn apply(bodies: &mut [SoftBody], a: u32, b: u32, r_a: Vec2, r_b: Vec2, impulse: Vec2) {
        let mut pair = BodyPair::load(bodies, a, b);
        pair.apply(r_a, r_b, impulse);
        pair.store(bodies);
    }

    fn warm_start(&mut self) {
        for &(start, end, ..) in &self.contact_lcp.islands {
            for p in &self.points[start..end] {
                warm_start_point(&mut self.bodies, p);
            }
        }
        self.warm_start_items(self.rest_items(), true);
        // Each pin's impulse and its motor's, pin by pin; the batched islands' pins, then
        // their motors'.
        for &(start, end) in &self.joint_islands {
            if !PinPlan::batches_island(end - start) {
                for j in &self.joints[start..end] {
                    warm_start_pin(&mut self.bodies, j);
                    warm_start_motor(&mut self.bodies, j);
                }
            }
        }
        self.pin_plan.warm_start(&mut self.bodies);
        for &k in self.pin_plan.alone() {
            warm_start_pin(&mut self.bodies, &self.joints[k as usize]);
        }
        for &(start, end) in &self.joint_islands {
            if PinPlan::batches_island(end - start) {
                // `motor_joints` is in the joints' order.
                let from = self.motor_joints.partition_point(|&k| (k as usize) < start);
                let motors = self.motor_joints[from..].iter();
                for &k in motors.take_while(|&&k| (k as usize) < end) {
                    warm_start_motor(&mut self.bodies, &self.joints[k as usize]);
                }
            }
        }
    }

    /// Warm-starts the plan's `items`, in their order.
    fn warm_start_items(&mut self, items: Range<usize>, ask: bool) {
        let (batches, point_batches) = (self.plan.batches(), self.plan.point_batches());
        let lanes = LanePath::best();
        let ahead = self.plan.batches_ahead().only_if(ask);
        ahead.visit(
            self.plan.items[items].iter(),
            AskedFor::WarmStart,
            |item| match *item {
                PassItem::Batch(k) => batches[k as usize].warm_start_on(lanes, &mut self.bodies),
                PassItem::PointBatch(k) => {
                    point_batches[k as usize].warm_start_on(lanes, &mut self.bodies)
                }
                PassItem::Manifold(first, count) => {
                    let (first, count) = (first as usize, count as usize);
                    for p in &self.points[first..first + count] {
                        warm_start_point(&mut self.bodies, p);
                    }
                }
            },
        );
    }

    /// One pass over the plan's `items`, in their order or backwards: eight manifolds at
    /// a time where they are batched (see `batch`).
    fn sweep_items(
        &mut self,
        items: Range<usize>,
        pass: &PassSettings,
        order: SweepOrder,
        ask: bool,
    ) {
        let ahead = self.plan.batches_ahead().only_if(ask);
        let (all_items, batches, point_batches) = self.plan.work();
        let items = &all_items[items];
        let lanes = LanePath::best();
        let solve_item = |item: &PassItem| match *item {
            PassItem::Batch(k) => batches[k as usize].solve_on(lanes, &mut self.bodies, pass),
            PassItem::PointBatch(k) => {
                point_batches[k as usize].solve_on(lanes, &mut self.bodies, pass)
            }
            PassItem::Manifold(first, 2) => {
                let i = first as usize;
                let (first, second) = self.points.split_at_mut(i + 1);
                solve_pair(&mut self.bodies, (&mut first[i], &mut second[0]), pass);
            }
            PassItem::Manifold(first, _) => {
                solve_point(&mut self.bodies, &mut self.points[first as usize], pass)
            }
        };
        match order {
            SweepOrder::Forwards => ahead.visit(items.iter(), AskedFor::Pass, solve_item),
            SweepOrder::Backwards => ahead.visit(items.iter().rev(), AskedFor::Pass, solve_item),
        }
    }

    fn solve(
        &mut self,
        h: f64,
        contact_soft: &Softness,
        joint_soft: &Softness,
        settings: &SoftSettings,
        use_bias: bool,
        order: SweepOrder,
    ) {
        let joint_push = settings.joint_push_speed;
        for &k in &self.motor_joints {
            solve_motor(&mut self.bodies, &mut self.joints[k as usize], h);
        }
        for (index, &(start, end)) in self.joint_islands.iter().enumerate() {
            let island = &mut self.joints[start..end];
            if PinPlan::batches_island(island.len()) {
                continue;
            }
            // A lone pin's 2 × 2 is solved in closed form below.
            let solved = island.len() >= 2
                && self.block.solve(
                    &mut self.bodies,
                    (index, island),
                    joint_soft,
                    joint_push,
                    use_bias,
                );
            if !solved {
                for j in island.iter_mut() {
                    solve_joint(&mut self.bodies, j, joint_soft, joint_push, use_bias);
                }
            }
        }
        let pin_pass = PinPass {
            soft: *joint_soft,
            max_push: joint_push,
            use_bias,
        };
        self.pin_plan.solve(&mut self.bodies, &pin_pass);
        for &k in self.pin_plan.alone() {
            let j = &mut self.joints[k as usize];
            solve_joint(&mut self.bodies, j, joint_soft, joint_push, use_bias);
        }
        let pass = contact_pass(h, contact_soft, settings, use_bias);
        self.contact_lcp
            .solve(&mut self.bodies, &mut self.points, &pass);
        // In the plan's order: small islands in the points' order, then big ones colour
        // by colour (or their colours backwards), eight manifolds at a time (see `batch`).
        let (rest, coloured_from) = (self.rest_items(), self.plan.coloured_from);
        self.sweep_items(0..coloured_from, &pass, SweepOrder::Forwards, true);
        self.sweep_items(coloured_from..rest.end, &pass, order, true);
    }

    /// Restitution once, after the substeps, for contacts that were approaching faster
    /// than the threshold and did push.
    ///
    /// A flat face landing bounces on both corners at once: solved one corner at a time,
    /// the first would tip the body and the second bounce less.
    fn restitution(&mut self, bounce_below: f64) {
        let bounces = |p: &PointConstraint| {
            p.restitution != 0.0
                && p.relative_velocity <= -bounce_below
                && p.max_normal_impulse != 0.0
        };
        let mut i = 0;
        while i < self.points.len() {
            let paired = self.points[i].pair_coupling.is_some();
            if paired && bounces(&self.points[i]) && bounces(&self.points[i + 1]) {
                let (first, second) = self.points.split_at_mut(i + 1);
                let (p, q) = (&mut first[i], &mut second[0]);
                let target = |p: &PointConstraint| -p.restitution * p.relative_velocity;
                let targets = (target(p), target(q));
                let mut pair = BodyPair::load(&self.bodies, p.a, p.b);
                let velocities = (pair.normal_velocity(p), pair.normal_velocity(q));
                solve_normal_pair(&mut pair, (p, q), velocities, targets);
                pair.store(&mut self.bodies);
                i += 2;
                continue;
            }
            let stride = if paired { 2 } else { 1 };
            for p in &mut self.points[i..i + stride] {
                if bounces(p) {
                    let mut pair = BodyPair::load(&self.bodies, p.a, p.b);
                    let vn = pair.normal_velocity(p);
                    let impulse = -p.normal_mass * (vn + p.restitution * p.relative_velocity);
                    apply_normal(&mut pair, p, p.normal_impulse + impulse);
                    pair.store(&mut self.bodies);
                }
            }
            i += stride;
        }
    }

    fn store(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
    ) {
        for (b, s) in bodies.iter_mut().zip(&self.bodies) {
            if !s.moves() {
                continue;
            }
            b.velocity = s.v;
            b.angular_velocity = s.w;
            b.position += s.dp;
            b.angle += s.dangle;
        }
        // Gathered by contact first, then written into the contacts in their order: the
        // lanes come in colour order, and writing each straight into its contact touched
        // the contacts' lines (3 MB on large_pyramid) at random.
        let mut impulses = std::mem::take(&mut self.impulses);
        impulses.clear();
        // Every contact belongs to a batch, an LCP island or a manifold solved alone, so
        // every entry is written below.
        impulses.resize(contacts.len(), (0.0, 0.0));
        let store_points = |points: &[PointConstraint], impulses: &mut [(f64, f64)]| {
            for p in points {
                impulses[p.contact as usize] = (p.normal_impulse, p.tangent_impulse);
            }
        };
        if self.may_bounce {
            store_points(&self.points, &mut impulses);
        } else {
            // The batched points' impulses are still in their lanes: from there, and
            // the rest (LCP islands, manifolds solved alone) from the points.
            self.plan.store_impulses(&mut impulses);
            for &(start, end, lcp) in &self.contact_lcp.all_islands {
                if lcp {
                    store_points(&self.points[start..end], &mut impulses);
                }
            }
            for item in &self.plan.items {
                if let PassItem::Manifold(first, count) = *item {
                    let (first, count) = (first as usize, count as usize);
                    store_points(&self.points[first..first + count], &mut impulses);
                }
            }
        }
        self.memory.store_from(contacts, &impulses);
        self.impulses = impulses;
        for j in &self.joints {
            self.joint_memory
                .keep(j.input, (j.slot, j.impulse, j.motor_impulse));
            if let Some(m) = joints[j.input as usize].motor.as_mut() {
                m.last_impulse = j.motor_impulse;
                m.step_impulse = j.motor_step_total;
            }
        }
        self.joint_memory.finish();
    }
}

/// Re-applies a pin's motor's accumulated angular impulse (zero without one).
fn warm_start_motor(bodies: &mut [SoftBody], j: &SoftJoint) {
    let (a, b) = (j.a as usize, j.b as usize);
    let ia = bodies[a].inv_inertia;
    bodies[a].w += ia * j.motor_impulse;
    let ib = bodies[b].inv_inertia;
    bodies[b].w -= ib * j.motor_impulse;
}

/// Re-applies a pin's accumulated impulse (not its motor's) at the start of a substep,
/// at its anchors where they are now: at the step's first arms, a tiny-inertia body far
/// from its pin would be spun by the stale lever.
fn warm_start_pin(bodies: &mut [SoftBody], j: &SoftJoint) {
    let ra = rotate_delta(bodies[j.a as usize].dq, j.r_a);
    let rb = rotate_delta(bodies[j.b as usize].dq, j.r_b);
    SoftStepSolver::apply(bodies, j.a, j.b, ra, rb, j.impulse);
}

/// Re-applies a point's accumulated impulses at the start of a substep.
fn warm_start_point(bodies: &mut [SoftBody], p: &PointConstraint) {
    let mut pair = BodyPair::load(bodies, p.a, p.b);
    pair.apply_along(p.normal, p.levers.normal, p.normal_impulse);
    pair.apply_along(perp(p.normal), p.levers.tangent(), p.tangent_impulse);
    pair.store(bodies);
}

/// A contact point's normal velocity at its fixed anchors (A relative to B).
///
/// Until the point first pushes, this also records the fastest approach: the bounce at the
/// end of the step reverses the speed of the impact, which gravity may have raised since
/// the step began (and nothing else has: no faster than `fastest_impact`).
/// A speculative point closes its remaining gap within the substep without speeding up
/// over it; the impact speed adds what the closing acceleration would have given there.
/// Only a point that may bounce needs it.
#[inline(always)]
fn approach(pair: &BodyPair, p: &mut PointConstraint, separation: f64) -> f64 {
    let vn = pair.normal_velocity(p);
    if p.restitution != 0.0 && p.max_normal_impulse == 0.0 && vn < 0.0 {
        let gained = 2.0 * p.closing_acceleration * separation.max(0.0);
        let impact = -(vn * vn + gained.max(0.0)).sqrt();
        p.relative_velocity = p.relative_velocity.min(impact.max(p.fastest_impact));
    }
    vn
}

/// The velocities and inverse masses of a constraint's two bodies: a manifold's solve
/// reads them once and writes them back once, instead of at every row.
///
/// A contact's rows add each product into the sum it feeds with one rounding
/// (`f64::mul_add`), as the batches' lanes do (`Lanes::mul_add`): there a fused
/// multiply–add is one instruction, and the passes' chains of dependent updates shorter.
#[derive(Debug, Clone, Copy)]
struct BodyPair {
    a: u32,
    b: u32,
    va: Vec2,
    wa: f64,
    vb: Vec2,
    wb: f64,
    inv_mass: (f64, f64),
    inv_inertia: (f64, f64),
}

impl BodyPair {
    #[inline(always)]
    fn load(bodies: &[SoftBody], a: u32, b: u32) -> Self {
        let (ba, bb) = (&bodies[a as usize], &bodies[b as usize]);
        Self {
            a,
            b,
            va: ba.v,
            wa: ba.w,
            vb: bb.v,
            wb: bb.w,
            inv_mass: (ba.inv_mass, bb.inv_mass),
            inv_inertia: (ba.inv_inertia, bb.inv_inertia),
        }
    }

    #[inline(always)]
    fn store(&self, bodies: &mut [SoftBody]) {
        let ba = &mut bodies[self.a as usize];
        (ba.v, ba.w) = (self.va, self.wa);
        let bb = &mut bodies[self.b as usize];
        (bb.v, bb.w) = (self.vb, self.wb);
    }

    /// The velocity of a point's anchors (A relative to B, at the anchors fixed for the
    /// step) along `direction`, with the anchors' `levers` about it.
    #[inline(always)]
    fn velocity_along(&self, direction: Vec2, (lever_a, lever_b): (f64, f64)) -> f64 {
        let r = self.va - self.vb;
        let linear = r.y.mul_add(direction.y, r.x * direction.x);
        let angular = (-self.wb).mul_add(lever_b, self.wa * lever_a);
        linear + angular
    }

    /// A point's normal velocity.
    #[inline(always)]
    fn normal_velocity(&self, p: &PointConstraint) -> f64 {
        self.velocity_along(p.normal, p.levers.normal)
    }

    /// `impulse` along `direction` on A and its opposite on B, with the anchors' levers.
    #[inline(always)]
    fn apply_along(&mut self, direction: Vec2, (lever_a, lever_b): (f64, f64), impulse: f64) {
        let (sa, sb) = (impulse * self.inv_mass.0, impulse * self.inv_mass.1);
        self.va = Vec2::new(
            direction.x.mul_add(sa, self.va.x),
            direction.y.mul_add(sa, self.va.y),
        );
        self.wa = (self.inv_inertia.0 * lever_a).mul_add(impulse, self.wa);
        let (nx, ny) = (-direction.x, -direction.y);
        self.vb = Vec2::new(nx.mul_add(sb, self.vb.x), ny.mul_add(sb, self.vb.y));
        self.wb = (-(self.inv_inertia.1 * lever_b)).mul_add(impulse, self.wb);
    }

    /// `impulse` on A at `r_a`, its opposite on B at `r_b`.
    #[inline(always)]
    fn apply(&mut self, r_a: Vec2, r_b: Vec2, impulse: Vec2) {
        self.va += impulse * self.inv_mass.0;
        self.wa += self.inv_inertia.0 * cross(r_a, impulse);
        self.vb -= impulse * self.inv_mass.1;
        self.wb -= self.inv_inertia.1 * cross(r_b, impulse);
    }
}

/// Sets a point's accumulated normal impulse to `total` (clamped at 0), applying the
/// difference.
#[inline(always)]
fn apply_normal(pair: &mut BodyPair, p: &mut PointConstraint, total: f64) {
    let total = total.max(0.0);
    let delta = total - p.normal_impulse;
    p.normal_impulse = total;
    // Only read where the point may bounce (`approach`, `restitution`).
    if p.restitution != 0.0 {
        p.max_normal_impulse = p.max_normal_impulse.max(delta);
    }
    pair.apply_along(p.normal, p.levers.normal, delta);
}

/// A point's current separation: how its anchors moved along the normal since the start,
/// with `a` and `b` its bodies. The impulse acts at the anchors fixed for the step (as
/// warm starting applies it), so that every substep pushes through the same lever.
#[inline(always)]
fn separation(a: &SoftBody, b: &SoftBody, p: &PointConstraint) -> f64 {
    // A body turned by q moves its anchor r by q·r − r, whose part along n is
    // (cos − 1)(r·n) + sin (r × n): the anchor's reach along the normal and its lever.
    let turned = |q: Rot, reach: f64, lever: f64| q.sin.mul_add(lever, (q.cos - 1.0) * reach);
    let (reach, lever) = (p.levers.reach, p.levers.normal);
    let d = a.dp - b.dp;
    let moved = d.y.mul_add(p.normal.y, d.x * p.normal.x);
    moved + turned(a.dq, reach.0, lever.0) - turned(b.dq, reach.1, lever.1) + p.base_separation
}

/// The velocity a point's normal row aims at (minus bias) and its softness, at
/// `separation`: speculative (closing the gap and no more), soft with bias (stiffer
/// against a `fixed` body), or rigid in the relax pass.
#[inline(always)]
fn normal_target(separation: f64, pass: &PassSettings, fixed: bool) -> (f64, (f64, f64), f64) {
    let soft = if fixed { &pass.static_soft } else { &pass.soft };
    if separation > 0.0 {
        (-separation * pass.inv_h, (1.0, 0.0), separation)
    } else if pass.use_bias {
        (
            -(soft.bias_rate * separation).max(-pass.max_push),
            (soft.mass_scale, soft.impulse_scale),
            separation,
        )
    } else {
        (0.0, (1.0, 0.0), separation)
    }
}

/// A point's normal target (see `normal_target`) from its bodies' motion.
#[inline(always)]
fn point_target(
    bodies: &[SoftBody],
    p: &PointConstraint,
    pass: &PassSettings,
) -> (f64, (f64, f64), f64) {
    let (a, b) = (&bodies[p.a as usize], &bodies[p.b as usize]);
    normal_target(separation(a, b, p), pass, !(a.moves() && b.moves()))
}

/// The least normal velocity a point may keep in a biased pass: a soft spring lets a part
/// of the approach through (1 − its mass scale), and where that would carry the point
/// deeper than `max_depth` within the substep, it is held there rigidly. Ordinary scenes
/// never come near it; a box on the floor at a gravity of 1e5 and h = 1 (a hundred
/// thousand times its size each step) fell through in the first step without it.
#[inline(always)]
fn sinking_floor(separation: f64, pass: &PassSettings) -> f64 {
    lesser(-(pass.max_depth + separation) * pass.inv_h, 0.0)
}

fn solve_point(bodies: &mut [SoftBody], p: &mut PointConstraint, pass: &PassSettings) {
    let (target, softness, separation) = point_target(bodies, p, pass);
    let mut pair = BodyPair::load(bodies, p.a, p.b);
    solve_normal(&mut pair, p, target, softness, separation, pass);
    solve_friction(&mut pair, p);
    pair.store(bodies);
}

/// One point's normal row alone: soft towards `target` with the softness scales (in a
/// biased pass, no softer than `sinking_floor`).
#[inline(always)]
fn solve_normal(
    pair: &mut BodyPair,
    p: &mut PointConstraint,
    target: f64,
    (mass_scale, impulse_scale): (f64, f64),
    separation: f64,
    pass: &PassSettings,
) {
    let vn = approach(pair, p, separation);
    let pushed = -p.normal_mass * mass_scale * (vn - target);
    let mut impulse = (-impulse_scale).mul_add(p.normal_impulse, pushed);
    if pass.use_bias {
        impulse = greater(
            impulse,
            -p.normal_mass * (vn - sinking_floor(separation, pass)),
        );
    }
    apply_normal(pair, p, p.normal_impulse + impulse);
}

#[inline(always)]
fn solve_friction(pair: &mut BodyPair, p: &mut PointConstraint) {
    let t = perp(p.normal);
    let vt = pair.velocity_along(t, p.levers.tangent());
    let limit = p.friction * p.normal_impulse;
    let total = clamp(
        (-p.tangent_mass).mul_add(vt, p.tangent_impulse),
        -limit,
        limit,
    );
    let delta = total - p.tangent_impulse;
    p.tangent_impulse = total;
    pair.apply_along(t, p.levers.tangent(), delta);
}

/// Two points of one manifold: normals together where both rows are rigid (the relax
/// pass, or both points speculative: `solve_normal_pair`), point by point where a row is
/// a soft spring; then friction point by point.
fn solve_pair(
    bodies: &mut [SoftBody],
    (p, q): (&mut PointConstraint, &mut PointConstraint),
    pass: &PassSettings,
) {
    // One manifold's two points share their bodies.
    let (a, b) = (&bodies[p.a as usize], &bodies[p.b as usize]);
    let fixed = !(a.moves() && b.moves());
    let (tp, sp, dp) = normal_target(separation(a, b, p), pass, fixed);
    let (tq, sq, dq) = normal_target(separation(a, b, q), pass, fixed);
    let mut pair = BodyPair::load(bodies, p.a, p.b);
    let rigid = !pass.use_bias || (dp > 0.0 && dq > 0.0);
    if rigid {
        let (v1, v2) = (approach(&pair, p, dp), approach(&pair, q, dq));
        solve_normal_pair(&mut pair, (p, q), (v1, v2), (tp, tq));
    } else {
        solve_normal(&mut pair, p, tp, sp, dp, pass);
        solve_normal(&mut pair, q, tq, sq, dq, pass);
        // One point after the other, the second's push can undo the first's: where that
        // leaves either below its floor, both are pushed up to their floors together.
        let below = (
            pair.normal_velocity(p) - sinking_floor(dp, pass),
            pair.normal_velocity(q) - sinking_floor(dq, pass),
        );
        if below.0 < 0.0 || below.1 < 0.0 {
            push_to_floors(&mut pair, (p, q), below);
        }
    }
    solve_friction(&mut pair, p);
    solve_friction(&mut pair, q);
    pair.store(bodies);
}

/// The 2 × 2 normal block of rigid rows as a small LCP, solved by trying its four active
/// sets: totals x ≥ 0 with w = (v_n − target) + K (x − x₀) ≥ 0 and x·w = 0, x₀ the
/// accumulated impulses. Rigid rows (the relax pass, restitution, two speculative points)
/// are solved so, exactly: one point after the other, the second's push undoes part of
/// the first's, and two boxes meeting face to face at 12 m/s sank 1.7 mm into each other.
///
/// Soft rows are not: there each point is a spring scaled by its own effective mass, as
/// in Box2D v3. A face's two springs solved together are coupled through the
/// bodies' rotation, and resting structures crept: over 8 s at rest, Box2D's arch 4.8 mm
/// and its card house 16.6 mm, against 0.01 and 0.000 mm point by point (Box2D v3 0.05
/// and 0.0009).
#[inline(always)]
fn solve_normal_pair(
    pair: &mut BodyPair,
    (p, q): (&mut PointConstraint, &mut PointConstraint),
    (v1, v2): (f64, f64),
    (tp, tq): (f64, f64),
) {
    let block = p.pair_coupling.expect("paired points");
    let (x1, x2) = (p.normal_impulse, q.normal_impulse);
    // w = K x + r with r = (v − target) − K x₀; the one-row cases are x₁ = −r₁ / k₁₁
    // (with normal_mass = 1 / k₁₁).
    let (k11, k12, k22) = (block.k11, block.k12, block.k22);
    // Each product added to another rounded once (`f64::mul_add`), as the lanes do.
    let (kx1, kx2) = (k12.mul_add(x2, k11 * x1), k22.mul_add(x2, k12 * x1));
    let (r1, r2) = ((v1 - tp) - kx1, (v2 - tq) - kx2);
    let (i11, i12, i22) = block.inverse;
    let both = (-(i12.mul_add(r2, i11 * r1)), -(i22.mul_add(r2, i12 * r1)));
    let (first, second) = (-r1 * p.normal_mass, -r2 * q.normal_mass);
    let totals = if both.0 >= 0.0 && both.1 >= 0.0 {
        both
    } else if first >= 0.0 && k12.mul_add(first, r2) >= 0.0 {
        (first, 0.0)
    } else if second >= 0.0 && k12.mul_add(second, r1) >= 0.0 {
        (0.0, second)
    } else {
        (0.0, 0.0) // r ≥ 0 is the only case left for a positive definite K
    };
    apply_normal(pair, p, totals.0);
    apply_normal(pair, q, totals.1);
}

/// The least further pushes x ≥ 0 on a manifold's two points that lift their normal
/// velocities to their floors: w = K x + r ≥ 0, x·w = 0, with `r` the velocities less
/// the floors (`solve_normal_pair`'s four active sets).
#[inline(always)]
fn push_to_floors(
    pair: &mut BodyPair,
    (p, q): (&mut PointConstraint, &mut PointConstraint),
    (r1, r2): (f64, f64),
) {
    let block = p.pair_coupling.expect("paired points");
    let (i11, i12, i22) = block.inverse;
    let k12 = block.k12;
    let both = (-(i12.mul_add(r2, i11 * r1)), -(i22.mul_add(r2, i12 * r1)));
    let (first, second) = (-r1 * p.normal_mass, -r2 * q.normal_mass);
    let pushes = if both.0 >= 0.0 && both.1 >= 0.0 {
        both
    } else if first >= 0.0 && k12.mul_add(first, r2) >= 0.0 {
        (first, 0.0)
    } else if second >= 0.0 && k12.mul_add(second, r1) >= 0.0 {
        (0.0, second)
    } else {
        (0.0, 0.0)
    };
    apply_normal(pair, p, p.normal_impulse + pushes.0);
    apply_normal(pair, q, q.normal_impulse + pushes.1);
}

/// A joint motor: the relative spin driven towards its target, within ±max torque·h.
fn solve_motor(bodies: &mut [SoftBody], j: &mut SoftJoint, h: f64) {
    if let Some((target, max_torque)) = j.motor {
        let (a, b) = (bodies[j.a as usize], bodies[j.b as usize]);
        let k = a.inv_inertia + b.inv_inertia;
        if k > 0.0 {
            let limit = max_torque * h;
            let total = clamp(j.motor_impulse - (a.w - b.w - target) / k, -limit, limit);
            let delta = total - j.motor_impulse;
            j.motor_impulse = total;
            bodies[j.a as usize].w += a.inv_inertia * delta;
            bodies[j.b as usize].w -= b.inv_inertia * delta;
        }
    }
}

/// The index range of each island in `grouped` (sorted by island).
fn island_ranges(grouped: &[(u32, u32)], ranges: &mut Vec<(usize, usize)>) {
    ranges.clear();
    let mut start = 0;
    while start < grouped.len() {
        let root = grouped[start].0;
        let len = grouped[start..].iter().take_while(|g| g.0 == root).count();
        ranges.push((start, start + len));
        start += len;
    }
}

/// A pin's current arms, its anchors' relative velocity plus the soft bias towards a
/// closed gap, and the softness scales for this pass.
fn pin_target(
    bodies: &[SoftBody],
    j: &SoftJoint,
    soft: &Softness,
    max_push: f64,
    use_bias: bool,
) -> ((Vec2, Vec2), Vec2, f64, f64) {
    let (a, b) = (bodies[j.a as usize], bodies[j.b as usize]);
    let ra = rotate_delta(a.dq, j.r_a);
    let rb = rotate_delta(b.dq, j.r_b);
    let dv = (a.v + cross_scalar(a.w, ra)) - (b.v + cross_scalar(b.w, rb));
    if !use_bias {
        return ((ra, rb), dv, 1.0, 0.0);
    }
    let gap = (a.dp + ra - j.r_a) - (b.dp + rb - j.r_b) + j.base_gap;
    let bias = gap * soft.bias_rate;
    let speed = (bias.x * bias.x + bias.y * bias.y).sqrt();
    let bias = if speed > max_push {
        bias * (max_push / speed)
    } else {
        bias
    };
    ((ra, rb), dv + bias, soft.mass_scale, soft.impulse_scale)
}

impl JointBlock {
    /// Starts a step of `islands` islands of pins: no factor made yet.
    fn begin_step(&mut self, islands: usize) {
        self.factors.resize_with(islands, IslandFactor::default);
        for cached in &mut self.factors {
            cached.arm_bits.clear();
        }
    }

    /// Solves the pins of island `index` (`island`) together: K ψ = −(Δv + bias) over all
    /// of them, then each impulse softened as a lone pin's would be. False if K is not
    /// positive definite (redundant pins), leaving the bodies untouched.
    fn solve(
        &mut self,
        bodies: &mut [SoftBody],
        (index, island): (usize, &mut [SoftJoint]),
        soft: &Softness,
        max_push: f64,
        use_bias: bool,
    ) -> bool {
        let n = 2 * island.len();
        self.arms.clear();
        self.rhs.clear();
        self.rhs.resize(n, 0.0);
        let (mut mass_scale, mut impulse_scale) = (1.0, 0.0);
        for (p, j) in island.iter().enumerate() {
            let (arms, target, ms, is) = pin_target(bodies, j, soft, max_push, use_bias);
            self.arms.push(arms);
            (mass_scale, impulse_scale) = (ms, is);
            self.rhs[2 * p] = -target.x;
            self.rhs[2 * p + 1] = -target.y;
        }
        let cached = &self.factors[index];
        let same_arms = cached.arm_bits.iter().copied().eq(arm_bits(&self.arms));
        #[cfg(test)]
        let same_arms = same_arms && !self.factor_every_pass;
        if !same_arms {
            #[cfg(test)]
            {
                self.factored += 1;
            }
            let cached = &mut self.factors[index];
            let factored =
                Self::factor(bodies, island, &self.arms, &mut self.k, &mut cached.factor);
            cached.arm_bits.clear();
            if !factored {
                return false;
            }
            cached.arm_bits.extend(arm_bits(&self.arms));
        }
        self.factors[index].factor.solve(&mut self.rhs);
        let psi = &self.rhs;
        for (p, j) in island.iter_mut().enumerate() {
            let impulse =
                Vec2::new(psi[2 * p], psi[2 * p + 1]) * mass_scale - j.impulse * impulse_scale;
            j.impulse += impulse;
            let (ra, rb) = self.arms[p];
            SoftStepSolver::apply(bodies, j.a, j.b, ra, rb, impulse);
        }
        true
    }

    /// Builds K for `island`'s pins at `arms` (into `k`) and factors it into `factor`:
    /// false if it is not positive definite.
    fn factor(
        bodies: &[SoftBody],
        island: &[SoftJoint],
        arms: &[(Vec2, Vec2)],
        k: &mut Vec<f64>,
        factor: &mut EnvelopeCholesky,
    ) -> bool {
        let m = island.len();
        let n = 2 * m;
        k.clear();
        k.resize(n * n, 0.0);
        for p in 0..m {
            for q in p..m {
                // Pins with no body in common do not couple: their block stays zero (a
                // chain's K is block-tridiagonal, which the factorization exploits).
                let (jp, jq) = (&island[p], &island[q]);
                if jp.a != jq.a && jp.a != jq.b && jp.b != jq.a && jp.b != jq.b {
                    continue;
                }
                let block = coupling(bodies, jp, arms[p], jq, arms[q]);
                // The lower triangle: row 2q + c, column 2p + r (a pin's own block: row r,
                // column c).
                for (r, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    let (row, column) = if p == q { (r, c) } else { (c, r) };
                    k[(2 * q + row) * n + 2 * p + column] = block[r][c];
                }
            }
        }
        // Redundant pins (a body pinned to the world twice, a closed loop) make K singular:
        // its factor then has a pivot at round-off level and the impulses blow up. Only
        // then is K regularised (by 1e-9 of its largest diagonal, which keeps the impulses
        // bounded): a heavy chain's K is ill-conditioned but regular, and even that much
        // regularisation doubled its gap.
        let largest = (0..n).map(|i| k[i * n + i]).fold(0.0, f64::max);
        if !factor.factor(k, n, 1e-12 * largest) {
            for i in 0..n {
                k[i * n + i] += 1e-9 * largest;
            }
            return factor.factor(k, n, 0.0);
        }
        true
    }
}

/// The velocity change at pin `p`'s anchors per unit impulse at pin `q`'s: one 2×2 block
/// of J M⁻¹ Jᵀ, summed over the bodies they share (+ on A, − on B).
fn coupling(
    bodies: &[SoftBody],
    p: &SoftJoint,
    (pa, pb): (Vec2, Vec2),
    q: &SoftJoint,
    (qa, qb): (Vec2, Vec2),
) -> [[f64; 2]; 2] {
    let mut k = [[0.0; 2]; 2];
    for (bp, sp, rp) in [(p.a, 1.0, pa), (p.b, -1.0, pb)] {
        for (bq, sq, rq) in [(q.a, 1.0, qa), (q.b, -1.0, qb)] {
            let body = &bodies[bp as usize];
            if bp != bq || !body.moves() {
                continue;
            }
            let (m, i) = (body.inv_mass, body.inv_inertia);
            let s = sp * sq;
            // Δv at rp = m·P + i·(rq × P)·perp(rp), P a unit impulse along x, then y.
            k[0][0] += s * (m + i * rp.y * rq.y);
            k[0][1] += s * (-i * rp.y * rq.x);
            k[1][0] += s * (-i * rp.x * rq.y);
            k[1][1] += s * (m + i * rp.x * rq.x);
        }
    }
    k
}

/// One pin alone (islands too big for the block solve).
fn solve_joint(
    bodies: &mut [SoftBody],
    j: &mut SoftJoint,
    soft: &Softness,
    max_push: f64,
    use_bias: bool,
) {
    let ((ra, rb), target, mass_scale, impulse_scale) =
        pin_target(bodies, j, soft, max_push, use_bias);
    let (a, b) = (bodies[j.a as usize], bodies[j.b as usize]);
    let m = a.inv_mass + b.inv_mass;
    let (ia, ib) = (a.inv_inertia, b.inv_inertia);
    let k11 = m + ia * ra.y * ra.y + ib * rb.y * rb.y;
    let k12 = -ia * ra.x * ra.y - ib * rb.x * rb.y;
    let k22 = m + ia * ra.x * ra.x + ib * rb.x * rb.x;
    let det = k11 * k22 - k12 * k12;
    if det <= 0.0 {
        return;
    }
    let rhs = target;
    let solved = Vec2::new(
        (k22 * rhs.x - k12 * rhs.y) / det,
        (k11 * rhs.y - k12 * rhs.x) / det,
    );
    let impulse = -solved * mass_scale - j.impulse * impulse_scale;
    j.impulse += impulse;
    SoftStepSolver::apply(bodies, j.a, j.b, ra, rb, impulse);
}

/// Contact islands of at most `LCP_POINT_LIMIT` points whose masses differ by at least
/// `LCP_NORMALS_MASS_RATIO` solve their normals as one LCP per pass, rigid with the soft
/// bias as target, and their friction point by point after it; from `LCP_MASS_RATIO` on,
/// friction is in the LCP too (friction-index bounds). Soft rows take their stiffness from
/// their own effective mass, so a heavy body on a light one squeezes it by the mass ratio
/// (a 1e6:1 pair sank a third of the light box), and Gauss–Seidel passes carry a heavy
/// load down through light bodies slowly: a body rolling at 4 m/s over one 13 times
/// lighter on the floor went 1.4 smallest radii into it. The coupled solve does both at
/// once. Each pass after the step's first starts from the last pass's sets: where they
/// still hold, it solves one triangular system instead of pivoting. Measured with
/// `physics/examples/throw_survey.rs` (1,600 random throws, then at the length scale of
/// the smallest radius; the share with a contact deeper than a fifth of that radius after
/// 2 s): point by point 12.9%; normals in an LCP from 10-fold masses 9.9%, in a quarter
/// more time; from 4-fold or 2-fold 10.7%, in half as much again; islands of up to 32
/// points 10.6%, in twice the time. With friction in every small island's LCP too,
/// 1,000 steps of the random piles of the hard-case tests (17–21 polygons) took 0.14–6.3 s
/// instead of 0.03–0.05 s.
const LCP_POINT_LIMIT: usize = 16;
const LCP_MASS_RATIO: f64 = 100.0;
const LCP_NORMALS_MASS_RATIO: f64 = 10.0;

/// The small contact islands of a step and their LCPs.
#[derive(Debug, Clone, Default)]
struct ContactLcp {
    /// Point ranges `[start, end)`, where each island's matrix starts in `k`, and whether
    /// its friction rows are in it (else only its normals).
    islands: Vec<(usize, usize, usize, bool)>,
    /// Every contact island's point range, and whether it is solved as an LCP.
    all_islands: Vec<(usize, usize, bool)>,
    /// Row-major J M⁻¹ Jᵀ of each island: rows 2k (normal) and 2k + 1 (tangent) of point k,
    /// or row k (its normal) in an island without friction rows. The anchors are fixed for
    /// the step, so it is built once per step.
    k: Vec<f64>,
    b: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    friction_index: Vec<Option<FrictionBound>>,
    x: Vec<f64>,
    /// A solver per island: the passes after the step's first solve the same matrix
    /// again, and start from the last pass's sets (`LcpSolver::solve_again`).
    solvers: Vec<LcpSolver>,
    /// Whether each island was solved in this step already.
    solved: Vec<bool>,
    /// The rows of the island being built: bodies, and direction and levers.
    rows: Vec<(u32, u32, (Vec2, f64, f64))>,
}

/// A point's two rows: direction, and lever arms on A and B.
fn rows(p: &PointConstraint) -> [(Vec2, f64, f64); 2] {
    let (n, t) = (p.levers.normal, p.levers.tangent());
    [(p.normal, n.0, n.1), (perp(p.normal), t.0, t.1)]
}

impl ContactLcp {
    /// Builds the matrices of the small islands; `islands` are the points' index ranges.
    fn prepare(
        &mut self,
        bodies: &[SoftBody],
        points: &[PointConstraint],
        islands: &[(usize, usize)],
    ) {
        self.islands.clear();
        self.all_islands.clear();
        self.k.clear();
        for &(start, end) in islands {
            let ends = points[start..end].iter().map(|p| (p.a, p.b));
            let (lightest, heaviest) = Self::inverse_mass_range(bodies, end - start, ends);
            let lcp = lightest >= LCP_NORMALS_MASS_RATIO * heaviest;
            self.all_islands.push((start, end, lcp));
            if lcp {
                let with_friction = lightest >= LCP_MASS_RATIO * heaviest;
                let offset = self.k.len();
                let rows_per_point = if with_friction { 2 } else { 1 };
                self.rows.clear();
                self.rows.extend(points[start..end].iter().flat_map(|p| {
                    rows(p)
                        .into_iter()
                        .take(rows_per_point)
                        .map(|row| (p.a, p.b, row))
                }));
                let n = self.rows.len();
                self.k.resize(offset + n * n, 0.0);
                for (i, &(pa, pb, (di, ai, bi))) in self.rows.iter().enumerate() {
                    for (j, &(qa, qb, (dj, aj, bj))) in self.rows.iter().enumerate() {
                        let mut value = 0.0;
                        for (bp, sp, lp) in [(pa, 1.0, ai), (pb, -1.0, bi)] {
                            for (bq, sq, lq) in [(qa, 1.0, aj), (qb, -1.0, bj)] {
                                let body = &bodies[bp as usize];
                                if bp == bq {
                                    value += sp
                                        * sq
                                        * (body.inv_mass * di.dot(&dj)
                                            + body.inv_inertia * lp * lq);
                                }
                            }
                        }
                        self.k[offset + i * n + j] = value;
                    }
                }
                self.islands.push((start, end, offset, with_friction));
            }
        }
        self.solved.clear();
        self.solved.resize(self.islands.len(), false);
        if self.solvers.len() < self.islands.len() {
            self.solvers
                .resize_with(self.islands.len(), LcpSolver::default);
        }
    }

    /// Which of `islands` `prepare` makes an LCP of, into `all_islands`, from the bodies
    /// of each point (`ends`, by index) before the points are built.
    fn classify(
        &mut self,
        bodies: &[SoftBody],
        islands: &[(usize, usize)],
        ends: impl Fn(usize) -> (u32, u32),
    ) {
        self.all_islands.clear();
        for &(start, end) in islands {
            let island_ends = (start..end).map(&ends);
            let (lightest, heaviest) = Self::inverse_mass_range(bodies, end - start, island_ends);
            let lcp = lightest >= LCP_NORMALS_MASS_RATIO * heaviest;
            self.all_islands.push((start, end, lcp));
        }
    }

    /// The largest and the smallest inverse mass of the moving bodies of an island of
    /// `len` points (their bodies `ends`), if it is small enough to be an LCP; else a
    /// range no LCP is made of.
    fn inverse_mass_range(
        bodies: &[SoftBody],
        len: usize,
        ends: impl Iterator<Item = (u32, u32)>,
    ) -> (f64, f64) {
        if len > LCP_POINT_LIMIT {
            return (0.0, f64::INFINITY);
        }
        ends.flat_map(|(a, b)| [a, b])
            .map(|i| bodies[i as usize].inv_mass)
            .filter(|&m| m > 0.0)
            .fold((0.0, f64::INFINITY), |(most, least), m| {
                (f64::max(most, m), f64::min(least, m))
            })
    }

    /// One pass over the small islands: totals x with w = K (x − x₀) + v − target, normals
    /// x ≥ 0 ⟂ w ≥ 0, friction |x_t| ≤ μ x_n (in the LCP, or point by point after the
    /// normals). An island whose LCP is rejected (non-finite input) goes point by point.
    fn solve(
        &mut self,
        bodies: &mut [SoftBody],
        points: &mut [PointConstraint],
        pass: &PassSettings,
    ) {
        for (index, &(start, end, offset, with_friction)) in self.islands.iter().enumerate() {
            let island = &mut points[start..end];
            let rows_per_point = if with_friction { 2 } else { 1 };
            let n = rows_per_point * island.len();
            let k = &self.k[offset..offset + n * n];
            self.b.clear();
            self.x.clear();
            self.lo.clear();
            self.hi.clear();
            self.friction_index.clear();
            for (i, p) in island.iter_mut().enumerate() {
                let (target, _, separation) = point_target(bodies, p, pass);
                let pair = BodyPair::load(bodies, p.a, p.b);
                let vn = approach(&pair, p, separation);
                self.b.push(vn - target);
                self.x.push(p.normal_impulse);
                self.lo.push(0.0);
                self.hi.push(f64::INFINITY);
                if with_friction {
                    let vt = pair.velocity_along(perp(p.normal), p.levers.tangent());
                    self.b.push(vt);
                    self.x.push(p.tangent_impulse);
                    self.lo.push(0.0);
                    self.hi.push(0.0);
                    self.friction_index
                        .extend([None, Some(FrictionBound::single(2 * i, p.friction))]);
                }
            }
            for r in 0..n {
                let kx: f64 = (0..n).map(|c| k[r * n + c] * self.x[c]).sum();
                self.b[r] -= kx;
            }
            let problem = LcpProblem {
                n,
                a: k,
                b: &self.b,
                lo: &self.lo,
                hi: &self.hi,
                friction_index: with_friction.then_some(&self.friction_index[..]),
                regularisation: REGULARISATION,
            };
            // The starting impulses are in `b` already; the solve overwrites `x`.
            let solver = &mut self.solvers[index];
            let stats = if std::mem::replace(&mut self.solved[index], true) {
                solver.solve_again(&problem, &mut self.x)
            } else {
                solver.solve(&problem, &mut self.x)
            };
            if stats.method == LcpMethod::Rejected {
                for p in island.iter_mut() {
                    solve_point(bodies, p, pass);
                }
                continue;
            }
            for (i, p) in island.iter_mut().enumerate() {
                let mut pair = BodyPair::load(bodies, p.a, p.b);
                apply_normal(&mut pair, p, self.x[rows_per_point * i]);
                if with_friction {
                    let delta = self.x[2 * i + 1] - p.tangent_impulse;
                    p.tangent_impulse = self.x[2 * i + 1];
                    pair.apply_along(perp(p.normal), p.levers.tangent(), delta);
                }
                pair.store(bodies);
            }
            if !with_friction {
                for p in island.iter_mut() {
                    let mut pair = BodyPair::load(bodies, p.a, p.b);
                    solve_friction(&mut pair, p);
                    pair.store(bodies);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
                        body_a: bodies.len() as u32,
                        body_b: below,
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
    fn state_bits(bodies: &[SolverBody], contacts: &[Contact]) -> Vec<u64> {
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
        assert_eq!(first.steps_planned_first, 8);
        assert_eq!(after.steps_planned_first, 0);
        // The singular manifold went as two one-point manifolds.
        let around = first.plan_inputs.iter().map(|p| p.first_and_count());
        let around: Vec<_> = around.filter(|&(k, _)| (22..28).contains(&k)).collect();
        assert_eq!(around, [(22, 2), (24, 1), (25, 1), (26, 2)]);
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
            gap_target: Vec2::zeros(),
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
        assert_eq!(solver.steps_planned_first, 0);
    }

    /// A chain of `links` rods of 1 m along +x, pinned end to end and the first to a
    /// fixed body at the origin.
    fn rods(links: usize) -> (Vec<SolverBody>, Vec<JointConstraint>) {
        let anchor = links as u32;
        let mut bodies: Vec<SolverBody> = (0..links)
            .map(|i| SolverBody {
                position: Vec2::new(i as f64 + 0.5, 0.0),
                inv_mass: 1.0,
                inv_inertia: 12.0,
                ..SolverBody::default()
            })
            .collect();
        bodies.push(SolverBody::default());
        let joints = (0..links)
            .map(|i| JointConstraint {
                joint: i as u32,
                body_a: i as u32,
                body_b: if i == 0 { anchor } else { i as u32 - 1 },
                local_anchor_a: Vec2::new(-0.5, 0.0),
                local_anchor_b: if i == 0 {
                    Vec2::zeros()
                } else {
                    Vec2::new(0.5, 0.0)
                },
                motor: None,
                gap_target: Vec2::zeros(),
            })
            .collect();
        (bodies, joints)
    }

    /// An island of pins solved as one system factors its K only where its arms changed
    /// (`IslandFactor`): the relax pass of one substep and the biased pass of the next
    /// share a factor. The bodies must move as with K factored in every pass. A step
    /// starts afresh: a chain hanging still has the same arms from step to step, to the
    /// bit, and a mass changed between two steps must still reach its K.
    #[test]
    fn pins_factored_again_only_where_their_arms_changed_move_the_bodies_the_same() {
        let settings = SoftSettings::for_length_scale(1.0);
        let substeps = settings.substeps;
        let steps = |gravity: Vec2, count: usize, every_pass: bool| {
            let (mut bodies, mut joints) = rods(6);
            let mut solver = SoftStepSolver::default();
            solver.block.factor_every_pass = every_pass;
            let gravity = vec![(gravity, 0.0); bodies.len()];
            let mut bits = Vec::new();
            for k in 0..count {
                if k == count / 2 {
                    bodies[3].inv_mass = 0.25;
                }
                let (mut contacts, h) = (Vec::new(), 1.0 / 60.0);
                let (b, j) = (&mut bodies, &mut joints);
                solver.step(&settings, b, &gravity, &mut contacts, j, h, 1.0);
                bits.push(state_bits(&bodies, &[]));
            }
            (bits, solver.block.factored)
        };
        // Swinging down from level: every pass's arms are new but those after a relax pass.
        let down = Vec2::new(0.0, 10.0);
        let (shared, factored) = steps(down, 10, false);
        let (every, factored_every) = steps(down, 10, true);
        assert_eq!(shared, every);
        assert_eq!(factored_every, 10 * 2 * substeps);
        assert_eq!(factored, 10 * (substeps + 1));
        // Pulled along its length, the chain hangs still: one factor a step, made afresh
        // each step.
        let along = Vec2::new(10.0, 0.0);
        let (shared, factored) = steps(along, 4, false);
        let (every, _) = steps(along, 4, true);
        assert_eq!(shared, every);
        assert_eq!(factored, 4);
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
            c.body_b = 20;
        }
        // The box alone on box 39 instead of the floor: the last island (in the grouping
        // taken unchecked) joins another.
        let mut last_moved = standing.clone();
        for c in &mut last_moved[80..82] {
            c.body_b = 39;
        }
        // Only a manifold's second point on another body (box 8 instead of box 9), in
        // the same island.
        let mut second_moved = standing.clone();
        second_moved[21].body_b = 8;
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
                unchecked.steps_skipping.0 > 0,
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
