//! A contact point or a manifold solved alone (small islands, lone manifolds, restitution):
//! the same arithmetic the batches run lane by lane.

use super::batch::PassSettings;
use super::bodies::SoftBody;
use super::constraints::{NormalBlock, PointConstraint};
use crate::math::{Rot, Vec2, clamp, cross, greater, lesser, perp};

/// Re-applies a point's accumulated impulses at the start of a substep.
#[inline(always)]
pub(super) fn warm_start_point(bodies: &mut [SoftBody], p: &PointConstraint) {
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
pub(super) fn approach(pair: &BodyPair, p: &mut PointConstraint, separation: f64) -> f64 {
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
pub(super) struct BodyPair {
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
    pub(super) fn load(bodies: &[SoftBody], a: u32, b: u32) -> Self {
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
    pub(super) fn store(&self, bodies: &mut [SoftBody]) {
        let ba = &mut bodies[self.a as usize];
        (ba.v, ba.w) = (self.va, self.wa);
        let bb = &mut bodies[self.b as usize];
        (bb.v, bb.w) = (self.vb, self.wb);
    }

    /// The velocity of a point's anchors (A relative to B, at the anchors fixed for the
    /// step) along `direction`, with the anchors' `levers` about it.
    #[inline(always)]
    pub(super) fn velocity_along(&self, direction: Vec2, (lever_a, lever_b): (f64, f64)) -> f64 {
        let r = self.va - self.vb;
        let linear = r.y.mul_add(direction.y, r.x * direction.x);
        let angular = (-self.wb).mul_add(lever_b, self.wa * lever_a);
        linear + angular
    }

    /// A point's normal velocity.
    #[inline(always)]
    pub(super) fn normal_velocity(&self, p: &PointConstraint) -> f64 {
        self.velocity_along(p.normal, p.levers.normal)
    }

    /// `impulse` along `direction` on A and its opposite on B, with the anchors' levers.
    #[inline(always)]
    pub(super) fn apply_along(
        &mut self,
        direction: Vec2,
        (lever_a, lever_b): (f64, f64),
        impulse: f64,
    ) {
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
    pub(super) fn apply(&mut self, r_a: Vec2, r_b: Vec2, impulse: Vec2) {
        self.va += impulse * self.inv_mass.0;
        self.wa += self.inv_inertia.0 * cross(r_a, impulse);
        self.vb -= impulse * self.inv_mass.1;
        self.wb -= self.inv_inertia.1 * cross(r_b, impulse);
    }
}

/// Sets a point's accumulated normal impulse to `total` (clamped at 0), applying the
/// difference.
#[inline(always)]
pub(super) fn apply_normal(pair: &mut BodyPair, p: &mut PointConstraint, total: f64) {
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
pub(super) fn separation(a: &SoftBody, b: &SoftBody, p: &PointConstraint) -> f64 {
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
pub(super) fn normal_target(
    separation: f64,
    pass: &PassSettings,
    fixed: bool,
) -> (f64, (f64, f64), f64) {
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
pub(super) fn point_target(
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
/// never come near it; under gravity that carries a body many times its size in a step,
/// the spring alone would let it through the floor in the first step.
#[inline(always)]
pub(super) fn sinking_floor(separation: f64, pass: &PassSettings) -> f64 {
    lesser(-(pass.max_depth + separation) * pass.inv_h, 0.0)
}

#[inline(always)]
pub(super) fn solve_point(bodies: &mut [SoftBody], p: &mut PointConstraint, pass: &PassSettings) {
    let (target, softness, separation) = point_target(bodies, p, pass);
    let mut pair = BodyPair::load(bodies, p.a, p.b);
    solve_normal(&mut pair, p, target, softness, separation, pass);
    solve_friction(&mut pair, p);
    pair.store(bodies);
}

/// One point's normal row alone: soft towards `target` with the softness scales (in a
/// biased pass, no softer than `sinking_floor`).
#[inline(always)]
pub(super) fn solve_normal(
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
pub(super) fn solve_friction(pair: &mut BodyPair, p: &mut PointConstraint) {
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
#[inline(always)]
pub(super) fn solve_pair(
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
/// the first's, and two boxes meeting face to face fast sink into each other.
///
/// Soft rows are not: there each point is a spring scaled by its own effective mass, as
/// in Box2D v3. A face's two springs solved together are coupled through the
/// bodies' rotation, and resting structures crept: over 8 s at rest, Box2D's arch 4.8 mm
/// and its card house 16.6 mm, against 0.01 and 0.000 mm point by point (Box2D v3 0.05
/// and 0.0009).
#[inline(always)]
pub(super) fn solve_normal_pair(
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
    let r = ((v1 - tp) - kx1, (v2 - tq) - kx2);
    let totals = two_row_lcp(&block, r, (p.normal_mass, q.normal_mass));
    apply_normal(pair, p, totals.0);
    apply_normal(pair, q, totals.1);
}

/// The least further pushes x ≥ 0 on a manifold's two points that lift their normal
/// velocities to their floors: w = K x + r ≥ 0, x·w = 0, with `r` the velocities less
/// the floors (`solve_normal_pair`'s four active sets).
#[inline(always)]
pub(super) fn push_to_floors(
    pair: &mut BodyPair,
    (p, q): (&mut PointConstraint, &mut PointConstraint),
    (r1, r2): (f64, f64),
) {
    let block = p.pair_coupling.expect("paired points");
    let pushes = two_row_lcp(&block, (r1, r2), (p.normal_mass, q.normal_mass));
    apply_normal(pair, p, p.normal_impulse + pushes.0);
    apply_normal(pair, q, q.normal_impulse + pushes.1);
}

/// x ≥ 0 with w = K x + r ≥ 0 and x·w = 0 for a manifold's two rows, K its normal
/// `block` (`normal_masses` = 1 / k₁₁, 1 / k₂₂), by trying the four active sets: both
/// rows pushed, the first alone, the second alone, neither (r ≥ 0 is the only case left
/// for a positive definite K).
#[inline(always)]
fn two_row_lcp(block: &NormalBlock, (r1, r2): (f64, f64), normal_masses: (f64, f64)) -> (f64, f64) {
    let (i11, i12, i22) = block.inverse;
    let k12 = block.k12;
    let both = (-(i12.mul_add(r2, i11 * r1)), -(i22.mul_add(r2, i12 * r1)));
    let (first, second) = (-r1 * normal_masses.0, -r2 * normal_masses.1);
    if both.0 >= 0.0 && both.1 >= 0.0 {
        both
    } else if first >= 0.0 && k12.mul_add(first, r2) >= 0.0 {
        (first, 0.0)
    } else if second >= 0.0 && k12.mul_add(second, r1) >= 0.0 {
        (0.0, second)
    } else {
        (0.0, 0.0)
    }
}
