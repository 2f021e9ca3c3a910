//! The soft step's constraints as its passes take them: a contact point (`PointConstraint`)
//! with its levers, a manifold's two points as one 2 × 2 block (`NormalBlock`), and a pin
//! (`SoftJoint`). The stages that build, batch and solve them are in the modules named
//! for each stage.

use super::bodies::SoftBody;
use crate::math::Vec2;
use crate::solver::SolverBody;
use crate::solver::contact::Contact;
use crate::solver::joint::JointLimits;

#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct PointConstraint {
    pub(super) contact: u32,
    pub(super) a: u32,
    pub(super) b: u32,
    pub(super) normal: Vec2,
    /// The anchors' levers about the normal and the tangent (`r × n`, `r × t` on A and
    /// on B), fixed for the step like the anchors: a row's velocity and impulse use them
    /// instead of crossing the arms again at every pass.
    pub(super) levers: PointLevers,
    /// Separation at the start, minus the anchors' part, so that the current separation is
    /// `n·(Δ(p_a + r_a) − Δ(p_b + r_b)) + base_separation`.
    pub(super) base_separation: f64,
    pub(super) normal_mass: f64,
    pub(super) tangent_mass: f64,
    pub(super) friction: f64,
    pub(super) restitution: f64,
    pub(super) relative_velocity: f64,
    pub(super) normal_impulse: f64,
    pub(super) tangent_impulse: f64,
    pub(super) max_normal_impulse: f64,
    /// How fast gravity and forces close the gap (along −normal), for the impact speed.
    pub(super) closing_acceleration: f64,
    /// The fastest impact `approach` may record: the approach at the step's start plus
    /// what the closing acceleration adds over the step. Any faster is speed the step's
    /// other contacts gave the bodies, which a bounce must not return: a small body
    /// wedged between a wall and another body gained half its speed again each step,
    /// bounced off the one and the other in turn.
    pub(super) fastest_impact: f64,
    /// With the next point: their 2 × 2 normal mass matrix, when the two are one
    /// manifold's and the block is well conditioned (solved together).
    pub(super) pair_coupling: Option<NormalBlock>,
}

/// The 2 × 2 normal mass matrix K of a manifold's two points and its inverse, computed
/// once per step so that the passes do not divide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct NormalBlock {
    pub(super) k11: f64,
    pub(super) k12: f64,
    pub(super) k22: f64,
    pub(super) inverse: (f64, f64, f64),
}

impl NormalBlock {
    /// The block of two points `p`, `q` of one manifold between bodies `a` and `b`, if it
    /// is well conditioned.
    pub(super) fn of(
        pair: (&SoftBody, &SoftBody),
        (p, q): (&PointConstraint, &PointConstraint),
    ) -> Option<Self> {
        Self::of_levers(pair, (p.levers.normal, q.levers.normal))
    }

    /// `of` for two points whose normal levers (`PointLevers::normal`) are `l1` and `l2`.
    #[inline(always)]
    pub(super) fn of_levers(
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
pub(super) struct PointLevers {
    pub(super) normal: (f64, f64),
    /// `r · n` on A and on B: how far each anchor reaches along the normal. Also the
    /// tangent row's levers: r × perp(n) = r · n.
    pub(super) reach: (f64, f64),
}

impl PointLevers {
    /// The levers of contact `c` about its bodies' centroids at the step's start.
    #[inline(always)]
    pub(super) fn of(bodies: &[SolverBody], c: &Contact) -> Self {
        let (a, b) = (&bodies[c.body_a.index()], &bodies[c.body_b.index()]);
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
    pub(super) fn tangent(&self) -> (f64, f64) {
        self.reach
    }
}

/// J M⁻¹ Jᵀ of two rows along one direction between the same two bodies: `inv_masses` the
/// bodies' summed inverse masses, `inertias` their inverse inertias, and each row's levers
/// (`r × n` on A and on B). With one row twice, the inverse of its effective mass.
#[inline(always)]
pub(super) fn row_coupling(
    inv_masses: f64,
    (ia, ib): (f64, f64),
    (a1, b1): (f64, f64),
    (a2, b2): (f64, f64),
) -> f64 {
    (ib * b1).mul_add(b2, (ia * a1).mul_add(a2, inv_masses))
}

/// Two points of one manifold are solved as a block only when their 2 × 2 matrix has a
/// condition number below this (Box2D v2's bound); nearly parallel rows go one by one.
pub(super) const MAX_BLOCK_CONDITION: f64 = 1000.0;

/// Joint islands up to this many pins are solved as one linear system per pass (a dense
/// Cholesky of 2m × 2m); larger ones pin by pin, in coloured batches (`pins`). One pass of
/// pin-by-pin Gauss–Seidel cannot hold a light chain under a heavy load: the error
/// travels one link per pass.
pub(super) const DIRECT_JOINT_LIMIT: usize = 64;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SoftJoint {
    pub(super) a: u32,
    pub(super) b: u32,
    pub(super) r_a: Vec2,
    pub(super) r_b: Vec2,
    /// Anchor separation at the start of the step (A − B).
    pub(super) base_gap: Vec2,
    pub(super) impulse: Vec2,
    pub(super) motor_impulse: f64,
    /// The motor's angular impulse summed over this step's substeps.
    pub(super) motor_step_total: f64,
    pub(super) motor: Option<(f64, f64)>,
    /// The joint's stops and its angle θ at the step's start (θ now: that plus body B's
    /// turn since less body A's), with the stops' accumulated impulses on ω_A − ω_B.
    pub(super) limits: Option<(JointLimits, f64)>,
    pub(super) limit_impulse: (f64, f64),
    pub(super) slot: u32,
    /// Its index in the step's input joints (the solver reorders them by island).
    pub(super) input: u32,
}
