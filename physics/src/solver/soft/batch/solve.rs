//! A batch's warm start and solve, lane by lane: the same arithmetic as one manifold
//! solved alone (`contacts`), eight manifolds side by side.

use super::super::bodies::{BodyRow, SoftBody};
use super::super::lanes::{LANES, LaneMask, Lanes};
use super::super::settings::Softness;
use super::dispatch::{BatchLanes, LaneBatch};
use super::{LaneBounce, LanePoints, ManifoldBatch, PAD};

/// A body's velocity, lane by lane.
#[derive(Debug, Clone, Copy)]
pub(in crate::solver::soft) struct LaneVelocity<L> {
    pub x: L,
    pub y: L,
    pub w: L,
    /// The inverse masses read with the velocities (`BodyRow::Velocity`), which
    /// `scatter_velocities` may write back beside them.
    pub inv_mass: L,
}

impl<L: Lanes> LaneVelocity<L> {
    /// # Safety
    /// Every index must be below `bodies.len()` (`Lanes::gather`).
    #[inline(always)]
    pub(crate) unsafe fn load(bodies: &[SoftBody], index: &[u32; LANES]) -> Self {
        // SAFETY: the caller's precondition.
        let [x, y, w, inv_mass] = unsafe { L::gather(bodies, index, BodyRow::Velocity) };
        Self { x, y, w, inv_mass }
    }

    /// # Safety
    /// As `load`.
    #[inline(always)]
    pub(crate) unsafe fn store(&self, bodies: &mut [SoftBody], index: &[u32; LANES]) {
        let columns = [self.x, self.y, self.w, self.inv_mass];
        // SAFETY: the caller's precondition.
        unsafe { L::scatter_velocities(columns, bodies, index) };
    }
}

/// The two bodies' velocities and inverse masses of every lane, as `BodyPair`.
#[derive(Debug, Clone, Copy)]
struct LanePair<L> {
    a: LaneVelocity<L>,
    b: LaneVelocity<L>,
    inv_inertia: (L, L),
}

impl<L: Lanes> LanePair<L> {
    /// `if_true`'s velocities where `mask` holds, `if_false`'s elsewhere.
    #[inline(always)]
    fn select(mask: L::Mask, if_true: Self, if_false: Self) -> Self {
        let pick = |t: LaneVelocity<L>, f: LaneVelocity<L>| LaneVelocity {
            x: mask.select(t.x, f.x),
            y: mask.select(t.y, f.y),
            w: mask.select(t.w, f.w),
            inv_mass: f.inv_mass,
        };
        Self {
            a: pick(if_true.a, if_false.a),
            b: pick(if_true.b, if_false.b),
            ..if_false
        }
    }

    /// `BodyPair::velocity_along`, lane by lane.
    #[inline(always)]
    fn velocity_along(&self, (dx, dy): (L, L), lever_a: L, lever_b: L) -> L {
        let (rx, ry) = (self.a.x - self.b.x, self.a.y - self.b.y);
        let linear = ry.mul_add(dy, rx * dx);
        let angular = self.b.w.neg_mul_add(lever_b, self.a.w * lever_a);
        linear + angular
    }

    /// `BodyPair::apply_along`, lane by lane.
    #[inline(always)]
    fn apply_along(&mut self, (dx, dy): (L, L), lever_a: L, lever_b: L, impulse: L) {
        let (sa, sb) = (impulse * self.a.inv_mass, impulse * self.b.inv_mass);
        self.a.x = dx.mul_add(sa, self.a.x);
        self.a.y = dy.mul_add(sa, self.a.y);
        self.a.w = (self.inv_inertia.0 * lever_a).mul_add(impulse, self.a.w);
        self.b.x = dx.neg_mul_add(sb, self.b.x);
        self.b.y = dy.neg_mul_add(sb, self.b.y);
        self.b.w = (self.inv_inertia.1 * lever_b).neg_mul_add(impulse, self.b.w);
    }
}

/// What one pass needs to find each point's target and softness (see `normal_target`).
#[derive(Debug, Clone, Copy)]
pub(in crate::solver::soft) struct PassSettings {
    pub(in crate::solver::soft) inv_h: f64,
    pub(in crate::solver::soft) soft: Softness,
    /// The softness of contacts with a fixed body.
    pub(in crate::solver::soft) static_soft: Softness,
    pub(in crate::solver::soft) max_push: f64,
    /// `SoftSettings::max_soft_depth`.
    pub(in crate::solver::soft) max_depth: f64,
    pub(in crate::solver::soft) use_bias: bool,
}

impl<const N: usize, L: Lanes> ManifoldBatch<N, L> {
    /// Whether any lane's points may bounce: only then are `bounce`'s lanes read or
    /// written during the passes (they change nothing where restitution is 0).
    #[inline(always)]
    fn may_bounce(&self) -> bool {
        self.bouncing_lanes != 0
    }

    /// Whether every lane's bodies are in `bodies`: checked once a pass, so that the
    /// gathers need not check each index.
    #[inline(always)]
    fn indices_fit(&self, bodies: &[SoftBody]) -> bool {
        let highest = self.a.iter().chain(&self.b).fold(0, |m, &i| m.max(i));
        (highest as usize) < bodies.len()
    }

    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn load(&self, bodies: &[SoftBody]) -> LanePair<L> {
        // SAFETY: the caller's precondition.
        unsafe {
            LanePair {
                a: LaneVelocity::load(bodies, &self.a),
                b: LaneVelocity::load(bodies, &self.b),
                inv_inertia: (self.inv_inertia_a, self.inv_inertia_b),
            }
        }
    }

    /// A's lanes, then B's, as `BodyPair::store` writes them.
    ///
    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn store(&self, pair: &LanePair<L>, bodies: &mut [SoftBody]) {
        // SAFETY: the caller's precondition.
        unsafe {
            pair.a.store(bodies, &self.a);
            pair.b.store(bodies, &self.b);
        }
    }

    /// `separation` for each lane's point `which`.
    ///
    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn separations(&self, bodies: &[SoftBody]) -> [L; N] {
        // SAFETY (both): the caller's precondition.
        let [dpx_a, dpy_a, cos_a, sin_a] = unsafe { L::gather(bodies, &self.a, BodyRow::Motion) };
        let [dpx_b, dpy_b, cos_b, sin_b] = unsafe { L::gather(bodies, &self.b, BodyRow::Motion) };
        let (dx, dy) = (dpx_a - dpx_b, dpy_a - dpy_b);
        let one = L::splat(1.0);
        let moved = dy.mul_add(self.normal_y, dx * self.normal_x);
        // Written out in the loop: a closure here was left out of line.
        let mut separations = [L::splat(0.0); N];
        for (s, p) in separations.iter_mut().zip(&self.points) {
            let turned_a = sin_a.mul_add(p.normal_lever_a, (cos_a - one) * p.reach_a);
            let turned_b = sin_b.mul_add(p.normal_lever_b, (cos_b - one) * p.reach_b);
            *s = moved + turned_a - turned_b + p.base_separation;
        }
        separations
    }

    /// A two-point manifold's normals, as `solve_pair` solves them: together where both
    /// rows are rigid (the relax pass, or both points speculative), point by point where
    /// a row is a soft spring; in a batch with lanes of both kinds, both are computed and
    /// each lane's chosen.
    #[inline(always)]
    fn solve_normals_together<const BIAS: bool, const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        separations: &[L],
        targets: &[Target<L>],
    ) {
        let zero = L::splat(0.0);
        let normal = (self.normal_x, self.normal_y);
        let rigid = separations[0].gt(zero) & separations[1].gt(zero);
        let soft = rigid ^ zero.eq(zero);
        if !BIAS || !soft.any() {
            self.solve_normals_as_block::<BOUNCE>(pair, separations, targets);
            return;
        }
        if !rigid.any() {
            let bounce = BOUNCE.then_some(&mut self.bounce[..]);
            let points = (&self.points[..], &mut self.normal_impulses[..], bounce);
            solve_normals_alone::<L, BIAS>(pair, points, normal, separations, targets);
            self.push_to_floors::<BOUNCE>(pair, targets);
            return;
        }
        // Copied before the block changes them: the velocities and impulses, and the
        // bounce lanes of a batch that may bounce.
        let (mut alone, mut impulses) = (*pair, self.normal_impulses);
        let mut bounce = BOUNCE.then_some(self.bounce);
        self.solve_normals_as_block::<BOUNCE>(pair, separations, targets);
        let alone_bounce = bounce.as_mut().map(|b| &mut b[..]);
        let alone_points = (&self.points[..], &mut impulses[..], alone_bounce);
        solve_normals_alone::<L, BIAS>(&mut alone, alone_points, normal, separations, targets);
        *pair = LanePair::select(rigid, *pair, alone);
        for (p, q) in self.normal_impulses.iter_mut().zip(impulses) {
            p.set(rigid.select(*p, q));
        }
        if let Some(bounce) = bounce {
            for (p, q) in self.bounce.iter_mut().zip(bounce) {
                let largest = rigid.select(p.max_normal_impulse, q.max_normal_impulse);
                p.max_normal_impulse.set(largest);
                let fastest = rigid.select(p.relative_velocity, q.relative_velocity);
                p.relative_velocity.set(fastest);
            }
        }
        self.push_to_floors::<BOUNCE>(pair, targets);
    }

    /// `push_to_floors` on every lane where a point sank below its floor (a lane that
    /// did not gets nothing: its rows' LCP is solved by no push).
    #[inline(always)]
    fn push_to_floors<const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        targets: &[Target<L>],
    ) {
        let zero = L::splat(0.0);
        let normal = (self.normal_x, self.normal_y);
        let points = &self.points[..];
        let v1 = pair.velocity_along(normal, points[0].normal_lever_a, points[0].normal_lever_b);
        let v2 = pair.velocity_along(normal, points[1].normal_lever_a, points[1].normal_lever_b);
        let (r1, r2) = (v1 - targets[0].3, v2 - targets[1].3);
        let (below1, below2) = (r1.lt(zero), r2.lt(zero));
        // a | b as (a ^ b) ^ (a & b): the masks have no "or".
        if !((below1 ^ below2) ^ (below1 & below2)).any() {
            return;
        }
        let [push1, push2] = self.two_row_lcp([r1, r2]);
        let points = self.points.iter().zip(&mut self.normal_impulses);
        for (((p, impulse), bounce), push) in points.zip(&mut self.bounce).zip([push1, push2]) {
            let total = *impulse + push;
            apply_normal(pair, (p, impulse), BOUNCE.then_some(bounce), normal, total);
        }
    }

    /// `two_row_lcp` (contacts.rs) on every lane: x ≥ 0 with w = K x + r ≥ 0 and
    /// x·w = 0 for the manifold's two rows, the active set of each lane chosen by masks.
    #[inline(always)]
    fn two_row_lcp(&self, [r1, r2]: [L; 2]) -> [L; 2] {
        let zero = L::splat(0.0);
        let points = &self.points[..];
        let [i11, i12, i22] = self.inverse;
        let k12 = self.k12;
        let both = (-(i12.mul_add(r2, i11 * r1)), -(i22.mul_add(r2, i12 * r1)));
        let first = -r1 * points[0].normal_mass;
        let second = -r2 * points[1].normal_mass;
        let take_both = both.0.ge(zero) & both.1.ge(zero);
        let take_first = first.ge(zero) & k12.mul_add(first, r2).ge(zero);
        let take_second = second.ge(zero) & k12.mul_add(second, r1).ge(zero);
        [
            take_both.select(both.0, take_first.select(first, zero)),
            take_both.select(
                both.1,
                take_first.select(zero, take_second.select(second, zero)),
            ),
        ]
    }

    /// Both points' normal velocities, their approach where they may bounce, and the
    /// 2 × 2 block (`solve_block`).
    #[inline(always)]
    fn solve_normals_as_block<const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        separations: &[L],
        targets: &[Target<L>],
    ) {
        let normal = (self.normal_x, self.normal_y);
        let points = &self.points[..];
        let v1 = pair.velocity_along(normal, points[0].normal_lever_a, points[0].normal_lever_b);
        let v2 = pair.velocity_along(normal, points[1].normal_lever_a, points[1].normal_lever_b);
        if BOUNCE {
            approach(&mut self.bounce[0], v1, separations[0]);
            approach(&mut self.bounce[1], v2, separations[1]);
        }
        self.solve_block::<BOUNCE>(pair, [v1, v2], [targets[0].0, targets[1].0]);
    }

    /// `solve_normal_pair` on every lane: the active set of each lane's 2 × 2 LCP chosen
    /// by masks. Rigid rows (the relax pass): targets `t1`, `t2`.
    #[inline(always)]
    fn solve_block<const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        [v1, v2]: [L; 2],
        [t1, t2]: [L; 2],
    ) {
        let [x1, x2] = [self.normal_impulses[0], self.normal_impulses[1]];
        let (k11, k12, k22) = (self.k11, self.k12, self.k22);
        let (kx1, kx2) = (k12.mul_add(x2, k11 * x1), k22.mul_add(x2, k12 * x1));
        let [total1, total2] = self.two_row_lcp([(v1 - t1) - kx1, (v2 - t2) - kx2]);
        let normal = (self.normal_x, self.normal_y);
        let points = self.points.iter().zip(&mut self.normal_impulses);
        for (((p, impulse), bounce), total) in points.zip(&mut self.bounce).zip([total1, total2]) {
            apply_normal(pair, (p, impulse), BOUNCE.then_some(bounce), normal, total);
        }
    }
}

// SAFETY: `ManifoldBatch<N, L>` is `repr(C)` with lanes of `F64x8`'s size and alignment
// (asserted with the struct), any bits valid in each.
unsafe impl<const N: usize> LaneBatch for ManifoldBatch<N> {
    type Pass = PassSettings;
    type With<L: Lanes> = ManifoldBatch<N, L>;

    #[inline(always)]
    fn upper_half_used(&self) -> bool {
        self.first_point[LANES / 2..].iter().any(|&f| f != PAD)
    }
}

impl<const N: usize, L: Lanes> BatchLanes<PassSettings> for ManifoldBatch<N, L> {
    /// `warm_start` for the batch's points.
    #[inline(always)]
    fn warm_start_lanes(&self, bodies: &mut [SoftBody]) {
        assert!(
            self.indices_fit(bodies),
            "a batch's bodies are the solver's"
        );
        // SAFETY: just checked.
        let mut pair = unsafe { self.load(bodies) };
        let normal = (self.normal_x, self.normal_y);
        let tangent = (-self.normal_y, self.normal_x);
        for (p, &impulse) in self.points.iter().zip(&self.normal_impulses) {
            pair.apply_along(normal, p.normal_lever_a, p.normal_lever_b, impulse);
            // The tangent row's levers are the reaches (`PointLevers::tangent`).
            pair.apply_along(tangent, p.reach_a, p.reach_b, p.tangent_impulse);
        }
        // SAFETY: checked above.
        unsafe { self.store(&pair, bodies) };
    }

    /// `solve_pair` on every lane.
    #[inline(always)]
    fn solve_lanes(&mut self, bodies: &mut [SoftBody], pass: &PassSettings) {
        // The relax pass (no bias) has mass scale 1 and impulse scale 0 in every lane;
        // compiled apart, it leaves out the terms they multiply. The same bits: x · 1 is
        // x, and leaving out a term of 0 · y can only turn a zero's sign, which the
        // clamp at 0 (`apply_normal`) then drops. And a batch with no lane that may
        // bounce (every batch of a pile) is compiled without the bounce lanes' code,
        // which otherwise took registers the passes spilled for.
        match (pass.use_bias, self.may_bounce()) {
            (true, false) => self.solve_pass::<true, false>(bodies, pass),
            (false, false) => self.solve_pass::<false, false>(bodies, pass),
            (true, true) => self.solve_pass::<true, true>(bodies, pass),
            (false, true) => self.solve_pass::<false, true>(bodies, pass),
        }
    }
}

impl<const N: usize, L: Lanes> ManifoldBatch<N, L> {
    /// `solve_pair` on every lane, `BIAS` being `pass.use_bias` and `BOUNCE`
    /// `self.may_bounce()`.
    #[inline(always)]
    fn solve_pass<const BIAS: bool, const BOUNCE: bool>(
        &mut self,
        bodies: &mut [SoftBody],
        pass: &PassSettings,
    ) {
        assert!(
            self.indices_fit(bodies),
            "a batch's bodies are the solver's"
        );
        // SAFETY: just checked.
        let (separations, mut pair) = unsafe { (self.separations(bodies), self.load(bodies)) };
        let normal = (self.normal_x, self.normal_y);
        let zero = L::splat(0.0);
        let one = L::splat(1.0);
        // `normal_target`: speculative points close their gap, touching ones are soft
        // with bias (or rigid in the relax pass).
        let fixed = self.fixed.gt(zero);
        let soft = |f: fn(&Softness) -> f64| {
            fixed.select(L::splat(f(&pass.static_soft)), L::splat(f(&pass.soft)))
        };
        let target = |s: L| {
            let speculative = s.gt(zero);
            let (target, mass_scale, impulse_scale) = if BIAS {
                let bias = -(soft(|t| t.bias_rate) * s).max(L::splat(-pass.max_push));
                (bias, soft(|t| t.mass_scale), soft(|t| t.impulse_scale))
            } else {
                (zero, one, zero)
            };
            let floor = if BIAS {
                (-(L::splat(pass.max_depth) + s) * L::splat(pass.inv_h)).min(zero)
            } else {
                L::splat(f64::NEG_INFINITY)
            };
            (
                speculative.select(-s * L::splat(pass.inv_h), target),
                speculative.select(one, mass_scale),
                speculative.select(zero, impulse_scale),
                floor,
            )
        };
        let mut targets = [(zero, zero, zero, zero); N];
        for (t, &s) in targets.iter_mut().zip(&separations) {
            *t = target(s);
        }
        if N == 2 {
            self.solve_normals_together::<BIAS, BOUNCE>(&mut pair, &separations, &targets);
        } else {
            let bounce = BOUNCE.then_some(&mut self.bounce[..]);
            let points = (&self.points[..], &mut self.normal_impulses[..], bounce);
            solve_normals_alone::<L, BIAS>(&mut pair, points, normal, &separations, &targets);
        }
        let tangent = (-self.normal_y, self.normal_x);
        for (p, &normal_impulse) in self.points.iter_mut().zip(&self.normal_impulses) {
            let vt = pair.velocity_along(tangent, p.reach_a, p.reach_b);
            let limit = self.friction * normal_impulse;
            let total = p
                .tangent_mass
                .neg_mul_add(vt, p.tangent_impulse)
                .clamp(-limit, limit);
            let delta = total - p.tangent_impulse;
            p.tangent_impulse.set(total);
            pair.apply_along(tangent, p.reach_a, p.reach_b, delta);
        }
        // SAFETY: checked above.
        unsafe { self.store(&pair, bodies) };
    }
}

/// A point's normal target, mass scale and impulse scale (see `normal_target`), lane by
/// lane.
/// A point's normal target, mass scale, impulse scale and, in a biased pass, the least
/// velocity it may keep (`sinking_floor`; −∞ in the relax pass).
type Target<L> = (L, L, L, L);

/// A batch's points, their normal impulses, and their bounce lanes where some lane may
/// bounce.
type PointsOf<'a, L> = (
    &'a [LanePoints<L>],
    &'a mut [L],
    Option<&'a mut [LaneBounce<L>]>,
);

/// `solve_normal` on every lane, point after point.
#[inline(always)]
fn solve_normals_alone<L: Lanes, const BIAS: bool>(
    pair: &mut LanePair<L>,
    (points, impulses, mut bounce): PointsOf<L>,
    normal: (L, L),
    separations: &[L],
    targets: &[Target<L>],
) {
    for (k, (p, impulse)) in points.iter().zip(impulses).enumerate() {
        let (target, mass_scale, impulse_scale, floor) = targets[k];
        let vn = pair.velocity_along(normal, p.normal_lever_a, p.normal_lever_b);
        let mut bounce = bounce.as_deref_mut().map(|b| &mut b[k]);
        if let Some(b) = bounce.as_deref_mut() {
            approach(b, vn, separations[k]);
        }
        let accumulated = *impulse;
        let change = if BIAS {
            let soft =
                impulse_scale.neg_mul_add(accumulated, -p.normal_mass * mass_scale * (vn - target));
            soft.max(-p.normal_mass * (vn - floor))
        } else {
            -p.normal_mass * (vn - target)
        };
        apply_normal(pair, (p, impulse), bounce, normal, accumulated + change);
    }
}

/// `apply_normal` on every lane: the accumulated normal impulse set to `total` (clamped
/// at 0), the difference applied; the largest push kept for points that may bounce.
#[inline(always)]
fn apply_normal<L: Lanes>(
    pair: &mut LanePair<L>,
    (p, impulse): (&LanePoints<L>, &mut L),
    bounce: Option<&mut LaneBounce<L>>,
    normal: (L, L),
    total: L,
) {
    let total = total.max(L::splat(0.0));
    let delta = total - *impulse;
    impulse.set(total);
    if let Some(b) = bounce {
        let elastic = b.restitution.ne(L::splat(0.0));
        let largest = elastic.select(b.max_normal_impulse.max(delta), b.max_normal_impulse);
        b.max_normal_impulse.set(largest);
    }
    pair.apply_along(normal, p.normal_lever_a, p.normal_lever_b, delta);
}

/// `approach` on every lane: the fastest approach of points that may bounce.
#[inline(always)]
fn approach<L: Lanes>(b: &mut LaneBounce<L>, vn: L, separation: L) {
    let zero = L::splat(0.0);
    let may_bounce = b.restitution.ne(zero) & b.max_normal_impulse.eq(zero) & vn.lt(zero);
    if may_bounce.any() {
        let gained = L::splat(2.0) * b.closing_acceleration * separation.max(zero);
        let impact = (-(vn * vn + gained.max(zero)).sqrt()).max(b.fastest_impact);
        let fastest = may_bounce.select(b.relative_velocity.min(impact), b.relative_velocity);
        b.relative_velocity.set(fastest);
    }
}
