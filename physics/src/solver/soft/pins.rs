//! The pins of a big island (more than `DIRECT_JOINT_LIMIT`, too many for the block
//! solve) eight at a time, one a SIMD lane, as `batch` solves the contacts' manifolds: the
//! island's pins are coloured (no two in a colour share a moving body), and each colour
//! goes in batches of eight. Every lane runs `solve_joint`'s arithmetic in its order, so a
//! batch gives the same bits as its pins solved one after another, on any lane path.
//!
//! Solved one after another in the island's order, each pin would wait for the one
//! before: a net's neighbouring pins share a body, so each update could start only once
//! the last one's velocities are stored. In batches they do not wait
//! (docs/bench/profile.md, "Pins in batches").

use super::batch::{BatchLanes, LaneBatch, LanePath, LaneVelocity, PAD};
use super::bodies::{BodyRow, SoftBody};
use super::constraints::{DIRECT_JOINT_LIMIT, SoftJoint};
use super::lanes::{F64x8, LANES, LaneMask, Lanes};
use super::settings::Softness;
#[cfg(target_arch = "x86_64")]
use super::{avx2::BothHalves, avx512::F64x8Avx512};
use crate::math::Vec2;
use crate::solver::island::counting_sort;

/// Colours of the pins' graph, as many as a body's `u32` of colour bits holds; a pin that
/// finds none free is solved alone, after the batches. A net needs four.
const COLOURS: u32 = 32;

/// Pins coloured together, in the island's order: each tile's colours are solved before
/// the next tile's, so that a pass goes over the bodies of a few hundred pins a colour at
/// a time while they are in the cache (coloured whole, a big net's rows outgrow the L2
/// cache; docs/bench/profile.md, "Pins in batches").
const TILE: usize = 512;

/// The batches of the step's big pin islands, and the buffers that plan them.
#[derive(Debug, Clone, Default)]
pub(super) struct PinPlan {
    batches: Vec<PinBatch>,
    filled: usize,
    /// Pins of the batched islands (indices into the step's joints) that found no free
    /// colour: solved one at a time, after the batches.
    alone: Vec<u32>,
    /// Per body, a bit for each colour it has a pin in.
    colours_of: Vec<u32>,
    /// The island's pins as `(colour, pin)`, and sorted by colour.
    coloured: Vec<(u32, u32)>,
    by_colour: Vec<(u32, u32)>,
    starts: Vec<u32>,
}

impl PinPlan {
    /// Whether an island of `pins` pins is solved in batches (else as one block, or a lone
    /// pin in closed form).
    pub(crate) fn batches_island(pins: usize) -> bool {
        pins > DIRECT_JOINT_LIMIT
    }

    /// Colours the pins of every island that `batches_island` and fills their batches,
    /// colour by colour (each colour's pins in the island's order); `bodies` ends with the
    /// null body, where unused lanes point. `unchanged`: the joints join the same bodies,
    /// each moving or not, as at the last call (`IslandGrouping::kept`), so the colours
    /// stand and only the batches' numbers are filled again.
    pub(crate) fn plan(
        &mut self,
        joints: &[SoftJoint],
        islands: &[(usize, usize)],
        bodies: &[SoftBody],
        unchanged: bool,
    ) {
        let null_body = bodies.len() as u32 - 1;
        if unchanged {
            for batch in &mut self.batches[..self.filled] {
                batch.fill(batch.pin, joints, bodies, null_body);
            }
            return;
        }
        self.filled = 0;
        self.alone.clear();
        let mut batched = islands
            .iter()
            .filter(|&&(start, end)| Self::batches_island(end - start))
            .peekable();
        if batched.peek().is_none() {
            return;
        }
        self.colours_of.clear();
        self.colours_of.resize(bodies.len(), 0);
        let moves = |i: &&u32| bodies[**i as usize].moves();
        let tiles = batched.flat_map(|&(start, end)| {
            (start..end)
                .step_by(TILE)
                .map(move |s| (s, end.min(s + TILE)))
        });
        for (start, end) in tiles {
            self.coloured.clear();
            for (k, j) in joints[start..end].iter().enumerate() {
                let pin = (start + k) as u32;
                let moving = [j.a, j.b];
                let moving = moving.iter().filter(moves);
                let used = moving
                    .clone()
                    .fold(0, |u, &i| u | self.colours_of[i as usize]);
                let colour = (!used).trailing_zeros();
                if colour == COLOURS {
                    self.alone.push(pin);
                    continue;
                }
                for &i in moving {
                    self.colours_of[i as usize] |= 1 << colour;
                }
                self.coloured.push((colour, pin));
            }
            counting_sort(
                &self.coloured,
                COLOURS as usize,
                |&(colour, _)| colour as usize,
                &mut self.starts,
                &mut self.by_colour,
            );
            for colour in self.by_colour.chunk_by(|p, q| p.0 == q.0) {
                for lanes in colour.chunks(LANES) {
                    let pins = std::array::from_fn(|k| lanes.get(k).map_or(PAD, |&(_, pin)| pin));
                    if self.filled == self.batches.len() {
                        self.batches.push(PinBatch::default());
                    }
                    self.batches[self.filled].fill(pins, joints, bodies, null_body);
                    self.filled += 1;
                }
            }
            // The next tile's colours start afresh.
            for j in &joints[start..end] {
                self.colours_of[j.a as usize] = 0;
                self.colours_of[j.b as usize] = 0;
            }
        }
    }

    /// The pins of the batched islands that are solved alone, after the batches.
    pub(crate) fn alone(&self) -> &[u32] {
        &self.alone
    }

    /// Applies the batched pins' accumulated impulses at their anchors where they are now.
    pub(crate) fn warm_start(&self, bodies: &mut [SoftBody]) {
        let path = LanePath::best();
        for batch in &self.batches[..self.filled] {
            batch.warm_start_on(path, bodies);
        }
    }

    /// One pass over the batches, as `solve_joint` over their pins.
    pub(crate) fn solve(&mut self, bodies: &mut [SoftBody], pass: &PinPass) {
        let path = LanePath::best();
        for batch in &mut self.batches[..self.filled] {
            batch.solve_on(path, bodies, pass);
        }
    }

    /// The batched pins' accumulated impulses, into their joints.
    pub(crate) fn scatter(&self, joints: &mut [SoftJoint]) {
        for batch in &self.batches[..self.filled] {
            let [x, y] = batch.impulse.map(|c| c.0);
            for (k, &pin) in batch.pin.iter().enumerate().filter(|&(_, &p)| p != PAD) {
                joints[pin as usize].impulse = Vec2::new(x[k], y[k]);
            }
        }
    }
}

/// What a pass of the pins needs: their softness, the fastest they pull their anchors
/// together, and whether they do (the relax pass does not).
#[derive(Debug, Clone, Copy)]
pub(super) struct PinPass {
    pub(super) soft: Softness,
    pub(super) max_push: f64,
    pub(super) use_bias: bool,
}

/// Eight pins with no moving body in common, lane by lane. Stored with `F64x8` lanes;
/// `repr(C)`, so that the AVX2 and AVX-512 paths read the same bytes as `PinBatch<L>`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C)]
pub(super) struct PinBatch<L = F64x8> {
    /// Each lane's pin, its index among the step's joints (`PAD`: an unused lane, on the
    /// null body).
    pin: [u32; LANES],
    a: [u32; LANES],
    b: [u32; LANES],
    inv_inertia_a: L,
    inv_inertia_b: L,
    /// The arms on A and on B, `(x, y)`, turned to the bodies' angles at the step's start.
    arm_a: [L; 2],
    arm_b: [L; 2],
    /// Anchor separation at the step's start (A − B).
    base_gap: [L; 2],
    /// The accumulated impulse, on A (its opposite on B).
    impulse: [L; 2],
}

#[cfg(target_arch = "x86_64")]
const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<PinBatch>() == size_of::<PinBatch<BothHalves>>());
    assert!(align_of::<PinBatch>() == align_of::<PinBatch<BothHalves>>());
    assert!(size_of::<PinBatch>() == size_of::<PinBatch<F64x8Avx512>>());
    assert!(align_of::<PinBatch>() == align_of::<PinBatch<F64x8Avx512>>());
};

impl PinBatch {
    /// The pins `pins` (indices into `joints`; `PAD`: an unused lane, on `null_body`).
    fn fill(
        &mut self,
        pins: [u32; LANES],
        joints: &[SoftJoint],
        bodies: &[SoftBody],
        null_body: u32,
    ) {
        *self = Self::default();
        self.pin = pins;
        for (k, &pin) in pins.iter().enumerate() {
            if pin == PAD {
                (self.a[k], self.b[k]) = (null_body, null_body);
                continue;
            }
            let j = &joints[pin as usize];
            (self.a[k], self.b[k]) = (j.a, j.b);
            self.inv_inertia_a.0[k] = bodies[j.a as usize].inv_inertia;
            self.inv_inertia_b.0[k] = bodies[j.b as usize].inv_inertia;
            for (c, (r_a, r_b, gap, impulse)) in [
                (j.r_a.x, j.r_b.x, j.base_gap.x, j.impulse.x),
                (j.r_a.y, j.r_b.y, j.base_gap.y, j.impulse.y),
            ]
            .into_iter()
            .enumerate()
            {
                self.arm_a[c].0[k] = r_a;
                self.arm_b[c].0[k] = r_b;
                self.base_gap[c].0[k] = gap;
                self.impulse[c].0[k] = impulse;
            }
        }
    }
}

// SAFETY: `PinBatch<L>` is `repr(C)` with lanes of `F64x8`'s size and alignment
// (asserted above), any bits valid in each.
unsafe impl LaneBatch for PinBatch {
    type Pass = PinPass;
    type With<L: Lanes> = PinBatch<L>;

    #[inline(always)]
    fn upper_half_used(&self) -> bool {
        self.pin[LANES / 2..].iter().any(|&p| p != PAD)
    }
}

/// A body's velocity change from `impulse` at the arm `r` (`BodyPair::apply`, one side):
/// added on A (`on_a`), taken off B, as the scalar `+=` and `-=`.
#[inline(always)]
fn push<L: Lanes>(
    body: &mut LaneVelocity<L>,
    inv_inertia: L,
    r: [L; 2],
    impulse: [L; 2],
    on_a: bool,
) {
    let linear = [impulse[0] * body.inv_mass, impulse[1] * body.inv_mass];
    // `cross(r, impulse)`.
    let angular = inv_inertia * (r[0] * impulse[1] - r[1] * impulse[0]);
    if on_a {
        body.x += linear[0];
        body.y += linear[1];
        body.w += angular;
    } else {
        body.x -= linear[0];
        body.y -= linear[1];
        body.w -= angular;
    }
}

/// `Rot::apply`: `arm` turned by the rotation `(cos, sin)`.
#[inline(always)]
fn turn<L: Lanes>((cos, sin): (L, L), arm: [L; 2]) -> [L; 2] {
    [cos * arm[0] - sin * arm[1], sin * arm[0] + cos * arm[1]]
}

/// `pushed`'s velocities where `solvable` holds, `before`'s elsewhere.
#[inline(always)]
fn where_solvable<L: Lanes>(
    solvable: L::Mask,
    pushed: LaneVelocity<L>,
    before: LaneVelocity<L>,
) -> LaneVelocity<L> {
    LaneVelocity {
        x: solvable.select(pushed.x, before.x),
        y: solvable.select(pushed.y, before.y),
        w: solvable.select(pushed.w, before.w),
        inv_mass: before.inv_mass,
    }
}

impl<L: Lanes> PinBatch<L> {
    /// Whether every lane's bodies are in `bodies`: checked once a pass, so that the
    /// gathers need not check each index.
    #[inline(always)]
    fn indices_fit(&self, bodies: &[SoftBody]) -> bool {
        let highest = self.a.iter().chain(&self.b).fold(0, |m, &i| m.max(i));
        (highest as usize) < bodies.len()
    }

    /// The bodies' moves since the step's start (`BodyRow::Motion`) and their
    /// velocities, A's and B's.
    ///
    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn load(&self, bodies: &[SoftBody]) -> ([[L; 4]; 2], [LaneVelocity<L>; 2]) {
        // SAFETY: the caller's precondition.
        unsafe {
            (
                [
                    L::gather(bodies, &self.a, BodyRow::Motion),
                    L::gather(bodies, &self.b, BodyRow::Motion),
                ],
                [
                    LaneVelocity::load(bodies, &self.a),
                    LaneVelocity::load(bodies, &self.b),
                ],
            )
        }
    }

    /// A's lanes, then B's, as `BodyPair::store` writes them.
    ///
    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn store(&self, [a, b]: &[LaneVelocity<L>; 2], bodies: &mut [SoftBody]) {
        // SAFETY: the caller's precondition.
        unsafe {
            a.store(bodies, &self.a);
            b.store(bodies, &self.b);
        }
    }
}

impl<L: Lanes> BatchLanes<PinPass> for PinBatch<L> {
    /// `warm_start_pin` on every lane.
    #[inline(always)]
    fn warm_start_lanes(&self, bodies: &mut [SoftBody]) {
        assert!(
            self.indices_fit(bodies),
            "a batch's bodies are the solver's"
        );
        // SAFETY: just checked.
        let ([[.., cos_a, sin_a], [.., cos_b, sin_b]], [mut a, mut b]) =
            unsafe { self.load(bodies) };
        let ra = turn((cos_a, sin_a), self.arm_a);
        let rb = turn((cos_b, sin_b), self.arm_b);
        push(&mut a, self.inv_inertia_a, ra, self.impulse, true);
        push(&mut b, self.inv_inertia_b, rb, self.impulse, false);
        // SAFETY: checked above.
        unsafe { self.store(&[a, b], bodies) };
    }

    /// `solve_joint` on every lane: a lane whose 2 × 2 is singular (only the null body's,
    /// in an unused lane) keeps its velocities and impulse, as `solve_joint` returns.
    #[inline(always)]
    fn solve_lanes(&mut self, bodies: &mut [SoftBody], pass: &PinPass) {
        assert!(
            self.indices_fit(bodies),
            "a batch's bodies are the solver's"
        );
        // SAFETY: just checked.
        let ([motion_a, motion_b], [a, b]) = unsafe { self.load(bodies) };
        let [dpx_a, dpy_a, cos_a, sin_a] = motion_a;
        let [dpx_b, dpy_b, cos_b, sin_b] = motion_b;
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        // `pin_target`: the anchors' relative velocity, plus the bias towards a closed gap.
        let ra = turn((cos_a, sin_a), self.arm_a);
        let rb = turn((cos_b, sin_b), self.arm_b);
        let dv = [
            (a.x + -a.w * ra[1]) - (b.x + -b.w * rb[1]),
            (a.y + a.w * ra[0]) - (b.y + b.w * rb[0]),
        ];
        let (target, mass_scale, impulse_scale) = if pass.use_bias {
            // Written out, as below: a closure here was left out of line, and with it
            // the intrinsics it called.
            let (arm_a, arm_b, base_gap) = (self.arm_a, self.arm_b, self.base_gap);
            let gap = [
                ((dpx_a + ra[0]) - arm_a[0]) - ((dpx_b + rb[0]) - arm_b[0]) + base_gap[0],
                ((dpy_a + ra[1]) - arm_a[1]) - ((dpy_b + rb[1]) - arm_b[1]) + base_gap[1],
            ];
            let rate = L::splat(pass.soft.bias_rate);
            let bias = [gap[0] * rate, gap[1] * rate];
            let speed = (bias[0] * bias[0] + bias[1] * bias[1]).sqrt();
            let max_push = L::splat(pass.max_push);
            let too_fast = speed.gt(max_push);
            // The cap divides in every lane, which is slow; it is computed only when some
            // lane pulls too fast, and a net held together has none.
            let bias = if too_fast.any() {
                let cap = max_push / speed;
                [
                    too_fast.select(bias[0] * cap, bias[0]),
                    too_fast.select(bias[1] * cap, bias[1]),
                ]
            } else {
                bias
            };
            (
                [dv[0] + bias[0], dv[1] + bias[1]],
                L::splat(pass.soft.mass_scale),
                L::splat(pass.soft.impulse_scale),
            )
        } else {
            (dv, one, zero)
        };
        // The 2 × 2 effective mass, solved in closed form.
        let m = a.inv_mass + b.inv_mass;
        let (ia, ib) = (self.inv_inertia_a, self.inv_inertia_b);
        let k11 = m + ia * ra[1] * ra[1] + ib * rb[1] * rb[1];
        let k12 = -ia * ra[0] * ra[1] - ib * rb[0] * rb[1];
        let k22 = m + ia * ra[0] * ra[0] + ib * rb[0] * rb[0];
        let det = k11 * k22 - k12 * k12;
        let solvable = det.gt(zero);
        let [tx, ty] = target;
        let solved = [(k22 * tx - k12 * ty) / det, (k11 * ty - k12 * tx) / det];
        let impulse = [
            -solved[0] * mass_scale - self.impulse[0] * impulse_scale,
            -solved[1] * mass_scale - self.impulse[1] * impulse_scale,
        ];
        for (total, delta) in self.impulse.iter_mut().zip(impulse) {
            total.set(solvable.select(*total + delta, *total));
        }
        let (mut pushed_a, mut pushed_b) = (a, b);
        push(&mut pushed_a, ia, ra, impulse, true);
        push(&mut pushed_b, ib, rb, impulse, false);
        let pushed = [
            where_solvable(solvable, pushed_a, a),
            where_solvable(solvable, pushed_b, b),
        ];
        // SAFETY: checked above.
        unsafe { self.store(&pushed, bodies) };
    }
}

#[cfg(test)]
mod tests {
    use super::super::batch::tests::{Numbers, body};
    use super::super::joints::{solve_joint, warm_start_pin};
    use super::*;

    /// The step's pin `k` between `a` and `b`, without a motor.
    fn pin(
        k: usize,
        (a, b): (u32, u32),
        (r_a, r_b): (Vec2, Vec2),
        base_gap: Vec2,
        impulse: Vec2,
    ) -> SoftJoint {
        SoftJoint {
            a,
            b,
            r_a,
            r_b,
            base_gap,
            impulse,
            motor_impulse: 0.0,
            motor_step_total: 0.0,
            motor: None,
            limits: None,
            limit_impulse: (0.0, 0.0),
            slot: k as u32,
            input: k as u32,
        }
    }

    /// Eight pins: lanes 0–5 between moving bodies, lanes 6 and 7 each on the same fixed
    /// body (which lanes may share), in both halves of the AVX2 path. With `far_open`,
    /// every third is far open, its pull capped at the pass's `max_push`.
    fn eight_pins(seed: u64, far_open: bool) -> (Vec<SoftBody>, Vec<SoftJoint>) {
        let mut n = Numbers(seed);
        let mut bodies: Vec<SoftBody> = (0..14).map(|_| body(&mut n, true)).collect();
        bodies.push(body(&mut n, false));
        bodies.push(SoftBody::null());
        let pairs = [
            (0, 1),
            (2, 3),
            (4, 14),
            (5, 6),
            (14, 7),
            (8, 9),
            (10, 11),
            (12, 13),
        ];
        let mut arm = || Vec2::new(n.next(-0.6, 0.6), n.next(-0.6, 0.6));
        let joints = pairs
            .iter()
            .enumerate()
            .map(|(k, &ends)| {
                let arms = (arm(), arm());
                let gap = arm() * if far_open && k % 3 == 0 { 10.0 } else { 0.01 };
                pin(k, ends, arms, gap, arm())
            })
            .collect();
        (bodies, joints)
    }

    fn pass(use_bias: bool) -> PinPass {
        PinPass {
            soft: Softness::new(60.0, 2.0, 1.0 / 240.0),
            max_push: 3.0,
            use_bias,
        }
    }

    /// Velocities, inverse masses (written back beside them) and impulses, as bits, so
    /// that even the sign of a zero counts.
    fn state(bodies: &[SoftBody], joints: &[SoftJoint]) -> Vec<u64> {
        let v = bodies.iter().flat_map(|b| [b.v.x, b.v.y, b.w, b.inv_mass]);
        let j = joints.iter().flat_map(|j| [j.impulse.x, j.impulse.y]);
        v.chain(j).map(f64::to_bits).collect()
    }

    fn batch_of(pins: [u32; LANES], joints: &[SoftJoint], bodies: &[SoftBody]) -> PinBatch {
        let mut batch = PinBatch::default();
        batch.fill(pins, joints, bodies, bodies.len() as u32 - 1);
        batch
    }

    fn scatter(batch: &PinBatch, joints: &mut [SoftJoint]) {
        let plan = PinPlan {
            batches: vec![*batch],
            filled: 1,
            ..PinPlan::default()
        };
        plan.scatter(joints);
    }

    #[test]
    fn a_batch_solves_as_its_pins_one_after_another() {
        // Without a pin far open, the batch caps no lane's pull.
        for (seed, far_open) in (1..=20).flat_map(|seed| [(seed, true), (seed, false)]) {
            for use_bias in [true, false] {
                let (bodies, joints) = eight_pins(seed, far_open);
                let pass = pass(use_bias);
                let (mut expected_bodies, mut expected_joints) = (bodies.clone(), joints.clone());
                for j in &mut expected_joints {
                    solve_joint(&mut expected_bodies, j, &pass.soft, pass.max_push, use_bias);
                }
                let expected = state(&expected_bodies, &expected_joints);
                assert_ne!(
                    expected,
                    state(&bodies, &joints),
                    "the pass changes something"
                );
                for path in LanePath::available() {
                    let mut batch = batch_of(std::array::from_fn(|k| k as u32), &joints, &bodies);
                    let (mut lanes, mut lane_joints) = (bodies.clone(), joints.clone());
                    batch.solve_on(path, &mut lanes, &pass);
                    scatter(&batch, &mut lane_joints);
                    let label =
                        format!("seed {seed}, far open {far_open}, bias {use_bias}, {path:?}");
                    assert_eq!(state(&lanes, &lane_joints), expected, "{label}");
                }
            }
        }
    }

    #[test]
    fn a_batch_warm_starts_as_its_pins_one_after_another() {
        for seed in 1..=20 {
            let (bodies, joints) = eight_pins(seed, true);
            let mut expected = bodies.clone();
            for j in &joints {
                warm_start_pin(&mut expected, j);
            }
            for path in LanePath::available() {
                let batch = batch_of(std::array::from_fn(|k| k as u32), &joints, &bodies);
                let mut lanes = bodies.clone();
                batch.warm_start_on(path, &mut lanes);
                assert_eq!(
                    state(&lanes, &[]),
                    state(&expected, &[]),
                    "seed {seed}, {path:?}"
                );
            }
        }
    }

    /// Unused lanes, in the upper half alone and in both: the pins in use solve as alone,
    /// the null body stays at rest, and no joint but the lanes' is written.
    #[test]
    fn a_batch_with_unused_lanes_solves_its_pins_and_leaves_the_rest() {
        let (bodies, joints) = eight_pins(7, true);
        let pass = pass(true);
        for used in [
            [0, 1, 2, PAD, PAD, PAD, PAD, PAD],
            [0, PAD, 2, 3, PAD, 5, PAD, PAD],
        ] {
            let (mut expected_bodies, mut expected_joints) = (bodies.clone(), joints.clone());
            for &k in used.iter().filter(|&&k| k != PAD) {
                let j = &mut expected_joints[k as usize];
                solve_joint(&mut expected_bodies, j, &pass.soft, pass.max_push, true);
            }
            for path in LanePath::available() {
                let mut batch = batch_of(used, &joints, &bodies);
                let (mut lanes, mut lane_joints) = (bodies.clone(), joints.clone());
                batch.solve_on(path, &mut lanes, &pass);
                scatter(&batch, &mut lane_joints);
                let expected = state(&expected_bodies, &expected_joints);
                assert_eq!(state(&lanes, &lane_joints), expected, "{used:?}, {path:?}");
            }
        }
    }

    /// A net of `side` × `side` bodies pinned to their neighbours, every 17th fixed, and a
    /// hub: body 1 (moving) pinned to 40 more, more pins than there are colours.
    fn net(side: usize) -> (Vec<SoftBody>, Vec<SoftJoint>) {
        let mut n = Numbers(3);
        let mut bodies: Vec<SoftBody> = (0..side * side + 40)
            .map(|i| body(&mut n, i % 17 != 0))
            .collect();
        bodies.push(SoftBody::null());
        let mut ends = Vec::new();
        for r in 0..side {
            for c in 0..side {
                let i = r * side + c;
                if c + 1 < side {
                    ends.push((i, i + 1));
                }
                if r + 1 < side {
                    ends.push((i, i + side));
                }
            }
        }
        ends.extend((0..40).map(|k| (1, side * side + k)));
        let joints = ends
            .iter()
            .enumerate()
            .map(|(k, &(a, b))| {
                let arms = (Vec2::new(0.5, 0.0), Vec2::new(-0.5, 0.0));
                let impulse = Vec2::new(k as f64, 0.0);
                pin(k, (a as u32, b as u32), arms, Vec2::zeros(), impulse)
            })
            .collect();
        (bodies, joints)
    }

    /// `plan` over one island of all the joints, made afresh.
    fn planned(joints: &[SoftJoint], bodies: &[SoftBody], plan: &mut PinPlan) {
        plan.plan(joints, &[(0, joints.len())], bodies, false);
    }

    /// Every pin is batched once or solved alone, and no two pins of a batch share a
    /// moving body.
    #[test]
    fn the_plan_takes_every_pin_once_and_batches_none_sharing_a_moving_body() {
        let (bodies, joints) = net(12);
        assert!(PinPlan::batches_island(joints.len()));
        let mut plan = PinPlan::default();
        planned(&joints, &bodies, &mut plan);
        let mut seen = vec![0; joints.len()];
        for batch in &plan.batches[..plan.filled] {
            let mut moving = Vec::new();
            for &pin in batch.pin.iter().filter(|&&p| p != PAD) {
                seen[pin as usize] += 1;
                let j = &joints[pin as usize];
                moving.extend(
                    [j.a, j.b]
                        .into_iter()
                        .filter(|&i| bodies[i as usize].moves()),
                );
            }
            let count = moving.len();
            moving.sort_unstable();
            moving.dedup();
            assert_eq!(moving.len(), count, "a moving body twice in a batch");
        }
        for &pin in plan.alone() {
            seen[pin as usize] += 1;
        }
        assert!(seen.iter().all(|&s| s == 1), "every pin once: {seen:?}");
        assert!(
            !plan.alone().is_empty(),
            "the hub's last pins find no colour"
        );
        assert!(plan.filled * LANES < joints.len() + 8 * COLOURS as usize);
    }

    /// A plan kept from the last step (the same pins between the same bodies) fills its
    /// batches with this step's numbers, as a fresh one. (Whether they are the same is
    /// `IslandGrouping::kept`'s to tell: `a_kept_grouping_follows_every_change`.)
    #[test]
    fn a_kept_plan_is_the_fresh_plan() {
        let (bodies, mut joints) = net(12);
        let mut kept = PinPlan::default();
        planned(&joints, &bodies, &mut kept);
        let batches = |plan: &PinPlan| plan.batches[..plan.filled].to_vec();
        let before = batches(&kept);
        for j in &mut joints {
            j.impulse.y += 1.0;
            j.r_a.x += 0.25;
            j.base_gap.x -= 0.5;
        }
        kept.plan(&joints, &[(0, joints.len())], &bodies, true);
        let mut fresh = PinPlan::default();
        planned(&joints, &bodies, &mut fresh);
        assert_eq!(batches(&kept), batches(&fresh));
        assert_eq!(kept.alone(), fresh.alone());
        assert_ne!(batches(&kept), before, "the numbers were filled again");
    }
}
