//! The soft step's pins and motors: each pin's last impulses kept for warm starting, a
//! small island of pins solved as one linear system, and a pin or motor solved alone.

use super::SoftStepSolver;
use super::bodies::LoadedBodies;
use super::bodies::SoftBody;
use super::constraints::SoftJoint;
use super::contacts::BodyPair;
use super::pins::PinPlan;
use super::settings::Softness;
use crate::math::{Rot, Vec2, clamp, cross_scalar};
use crate::solver::SolverBody;
use crate::solver::envelope::EnvelopeCholesky;
use crate::solver::island::{IslandGrouping, island_ranges};
use crate::solver::joint::JointConstraint;

/// The soft step's pins and motors for a step: each pin as the passes read it, grouped by
/// island, with its remembered impulses, and the plans of the small islands' block solve
/// and the big islands' batches.
#[derive(Debug, Clone, Default)]
pub(super) struct SoftPins {
    pub(super) joints: Vec<SoftJoint>,
    pub(super) spare_joints: Vec<SoftJoint>,
    pub(super) joint_memory: JointMemory,
    /// The pinned bodies' rotations at the step's start, found as the pins need them.
    pub(super) rotations: Vec<Option<Rot>>,
    /// `joints` indices of the pins with a motor, in `joints`' order.
    pub(super) motor_joints: Vec<u32>,
    /// `joints` index ranges, one per island of pins, and the buffers of their solve.
    pub(super) joint_islands: Vec<(usize, usize)>,
    /// The big pin islands' batches (`pins`).
    pub(super) pin_plan: PinPlan,
    /// The pins' islands, kept while the pins join the same bodies.
    pub(super) joint_grouping: IslandGrouping,
    pub(super) block: JointBlock,
}

impl SoftPins {
    /// The pins that can act this step, their last impulses recalled, grouped by island,
    /// and the big islands' batches planned.
    pub(super) fn prepare(
        &mut self,
        bodies: &[SolverBody],
        joints: &[JointConstraint],
        loaded: &LoadedBodies,
    ) {
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
                .map(|m| (m.drive_speed(), m.max_torque));
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
                limits: j.limits.map(|l| (l, b.angle - a.angle - j.reference_angle)),
                limit_impulse: (0.0, 0.0),
                slot: j.joint,
                input: input as u32,
            });
        }
        self.group(loaded);
        self.block.begin_step(self.joint_islands.len());
        self.motor_joints.clear();
        let motors = self
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.motor.is_some() || j.limits.is_some());
        self.motor_joints.extend(motors.map(|(k, _)| k as u32));
        let unchanged = self.joint_grouping.kept();
        self.pin_plan
            .plan(&self.joints, &self.joint_islands, &loaded.bodies, unchanged);
    }

    /// Orders `joints` island by island (pins linked through moving bodies; each island
    /// keeps the joints' order) and records each island's range.
    fn group(&mut self, loaded: &LoadedBodies) {
        let joints = &self.joints;
        let grouped = self.joint_grouping.group(
            joints.len(),
            loaded.bodies.len(),
            |i| (joints[i].a, joints[i].b),
            &loaded.moving,
        );
        // A net's pins are one island, in the joints' own order: nothing to move, and
        // copying every joint is skipped.
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
}

/// Last step's pin impulses (linear, and the motor's angular one) by joint slot.
#[derive(Debug, Clone, Default)]
pub(super) struct JointMemory {
    /// `(slot, impulse, motor impulse)`, sorted by slot.
    entries: Vec<(u32, Vec2, f64)>,
    /// This step's, by the pin's index among the step's input joints (`Self::NONE`'s slot
    /// where it keeps none), until `finish` makes them the entries.
    by_input: Vec<(u32, Vec2, f64)>,
}

impl JointMemory {
    pub(super) const NONE: (u32, Vec2, f64) = (u32::MAX, Vec2::new(0.0, 0.0), 0.0);

    /// Starts a step of `inputs` joints; `recall` still reads the last step's.
    pub(super) fn begin(&mut self, inputs: usize) {
        self.by_input.clear();
        self.by_input.resize(inputs, Self::NONE);
    }

    /// The pin `slot`'s impulses of the last step. The step's joints come in slot order,
    /// so `cursor` walks the entries once; a pin found behind it is searched for.
    pub(super) fn recall(&self, slot: u32, cursor: &mut usize) -> Option<(u32, Vec2, f64)> {
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
    pub(super) fn keep(&mut self, input: u32, entry: (u32, Vec2, f64)) {
        self.by_input[input as usize] = entry;
    }

    /// The kept impulses become the ones to recall.
    pub(super) fn finish(&mut self) {
        self.entries.clear();
        let kept = self.by_input.iter().filter(|e| e.0 != Self::NONE.0);
        self.entries.extend(kept);
        // Input order is slot order, unless a caller gave the joints otherwise.
        if !self.entries.is_sorted_by_key(|e| e.0) {
            self.entries.sort_unstable_by_key(|e| e.0);
        }
    }
}
/// The system of one island of pins, its buffers reused between passes.
#[derive(Debug, Clone, Default)]
pub(super) struct JointBlock {
    arms: Vec<(Vec2, Vec2)>,
    /// K, row-major, its lower triangle filled.
    k: Vec<f64>,
    rhs: Vec<f64>,
    /// This step's factor of each island's K, by island (`SoftStepSolver::joint_islands`).
    factors: Vec<IslandFactor>,
    /// A crate-private check, off in use: K factored in every pass, not only where the
    /// arms changed, so that a test can show the kept factors give the same bits.
    pub(super) factor_every_pass: bool,
    /// How many times K was factored (`StepStats::soft_pin_factorisations`).
    pub(super) factored: u64,
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

pub(super) fn rotate_delta(q: Rot, r: Vec2) -> Vec2 {
    q.apply(r)
}

impl SoftStepSolver {
    fn apply(bodies: &mut [SoftBody], a: u32, b: u32, r_a: Vec2, r_b: Vec2, impulse: Vec2) {
        let mut pair = BodyPair::load(bodies, a, b);
        pair.apply(r_a, r_b, impulse);
        pair.store(bodies);
    }
}

/// Re-applies a pin's motor's and stops' accumulated angular impulse (zero without).
pub(super) fn warm_start_motor(bodies: &mut [SoftBody], j: &SoftJoint) {
    let (a, b) = (j.a as usize, j.b as usize);
    let impulse = j.motor_impulse + j.limit_impulse.0 + j.limit_impulse.1;
    let ia = bodies[a].inv_inertia;
    bodies[a].w += ia * impulse;
    let ib = bodies[b].inv_inertia;
    bodies[b].w -= ib * impulse;
}

/// Re-applies a pin's accumulated impulse (not its motor's) at the start of a substep,
/// at its anchors where they are now: at the step's first arms, a tiny-inertia body far
/// from its pin would be spun by the stale lever.
pub(super) fn warm_start_pin(bodies: &mut [SoftBody], j: &SoftJoint) {
    let ra = rotate_delta(bodies[j.a as usize].dq, j.r_a);
    let rb = rotate_delta(bodies[j.b as usize].dq, j.r_b);
    SoftStepSolver::apply(bodies, j.a, j.b, ra, rb, j.impulse);
}

/// A joint motor: the relative spin driven towards its target, within ±max torque·h.
pub(super) fn solve_motor(bodies: &mut [SoftBody], j: &mut SoftJoint, h: f64) {
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

/// A joint's stops, as Box2D v3 solves a revolute joint's limits: a stop ahead lets the
/// joint reach it in the substep (speculative, rigid); one passed is pushed back softly
/// (the pins' softness) in the biased pass and only held in the relaxing one. Each
/// stop's accumulated impulse stays one-signed; a weld's is free. Solved after the pins,
/// so that theirs is not the last word: a pin between bodies 5,000:1 apart swings the
/// light one's spin by hundreds of rad/s within a pass, past a stop solved before it.
pub(super) fn solve_limits(
    bodies: &mut [SoftBody],
    j: &mut SoftJoint,
    h: f64,
    soft: &Softness,
    use_bias: bool,
) {
    let Some((limits, theta_start)) = j.limits else {
        return;
    };
    let (ia, ib) = (j.a as usize, j.b as usize);
    let k = bodies[ia].inv_inertia + bodies[ib].inv_inertia;
    if k <= 0.0 {
        return;
    }
    let theta = theta_start + bodies[ib].dangle - bodies[ia].dangle;
    // Each stop as a gap C ≥ 0 closing at the speed `closing` (along s = ω_A − ω_B for
    // the lower stop, −s for the upper), its impulse along that sign.
    let stops = [(theta - limits.lower, 1.0), (limits.upper - theta, -1.0)];
    let weld = limits.is_weld();
    for (index, (gap, sign)) in stops.into_iter().enumerate() {
        if weld && index == 1 {
            break;
        }
        let (bias, mass_scale, impulse_scale) = if gap > 0.0 {
            (gap / h, 1.0, 0.0)
        } else if use_bias {
            (soft.bias_rate * gap, soft.mass_scale, soft.impulse_scale)
        } else {
            (0.0, 1.0, 0.0)
        };
        let accumulated = if index == 0 {
            j.limit_impulse.0
        } else {
            j.limit_impulse.1
        };
        // The gap's rate: for the lower stop −s, for the upper s.
        let s = bodies[ia].w - bodies[ib].w;
        let rate = -sign * s;
        let along = -mass_scale * (rate + bias) / k - impulse_scale * (-sign * accumulated);
        // `along` is the impulse on the gap's rate; on s it is −sign times that.
        let mut total_along = -sign * accumulated + along;
        if !weld {
            total_along = total_along.max(0.0);
        }
        let total = -sign * total_along;
        let delta = total - accumulated;
        if index == 0 {
            j.limit_impulse.0 = total;
        } else {
            j.limit_impulse.1 = total;
        }
        bodies[ia].w += bodies[ia].inv_inertia * delta;
        bodies[ib].w -= bodies[ib].inv_inertia * delta;
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
    pub(super) fn begin_step(&mut self, islands: usize) {
        self.factors.resize_with(islands, IslandFactor::default);
        for cached in &mut self.factors {
            cached.arm_bits.clear();
        }
    }

    /// Solves the pins of island `index` (`island`) together: K ψ = −(Δv + bias) over all
    /// of them, then each impulse softened as a lone pin's would be. False if K is not
    /// positive definite (redundant pins), leaving the bodies untouched.
    pub(super) fn solve(
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
        let same_arms = same_arms && !self.factor_every_pass;
        if !same_arms {
            self.factored += 1;
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
pub(super) fn solve_joint(
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

#[cfg(test)]
mod tests {
    use super::super::settings::SoftSettings;
    use super::super::tests::state_bits;
    use super::*;
    use crate::solver::SolverBody;
    use crate::solver::joint::JointConstraint;

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
                limits: None,
                reference_angle: 0.0,
                limit_impulse: (0.0, 0.0),
                gap_target: Vec2::zeros(),
                impulse: Vec2::zeros(),
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
            solver.pins.block.factor_every_pass = every_pass;
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
            (bits, solver.pin_factorisations() as usize)
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
}
