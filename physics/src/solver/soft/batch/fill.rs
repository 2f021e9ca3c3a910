//! A batch filled from its manifolds' points, lane by lane (unused lanes on the null
//! body), and its impulses read back into the points and contacts.

use super::super::bodies::SoftBody;
use super::super::constraints::{NormalBlock, PointConstraint, PointLevers};
use super::super::lanes::LANES;
use super::{ManifoldBatch, PAD};
use crate::math::Vec2;

impl<const N: usize> ManifoldBatch<N> {
    /// Fills the batch with the manifolds whose first points are `first_point` (`PAD`:
    /// an unused lane, on the null body, the last of `bodies`).
    /// Without `points`, only the unused lanes are filled: the others are filled as
    /// their points are built (`PassPlan::plan_before_points`).
    pub(super) fn fill(
        &mut self,
        first_point: [u32; LANES],
        points: Option<&[PointConstraint]>,
        bodies: &[SoftBody],
    ) {
        self.first_point = first_point;
        let unused = first_point
            .contains(&PAD)
            .then(|| unused_lane(bodies.len() as u32 - 1));
        for (k, &first) in first_point.iter().enumerate() {
            let lane_points = match (&unused, points) {
                (Some(unused), _) if first == PAD => &unused[..],
                (_, Some(points)) => &points[first as usize..],
                (_, None) => continue,
            };
            self.fill_lane(k, first, &lane_points[..N], bodies);
        }
    }

    /// Lane `k`: the manifold whose points are `lane_points` (its first point `first`).
    #[inline(always)]
    pub(super) fn fill_lane(
        &mut self,
        k: usize,
        first: u32,
        lane_points: &[PointConstraint],
        bodies: &[SoftBody],
    ) {
        self.first_point[k] = first;
        let p = &lane_points[0];
        let (a, b) = (&bodies[p.a as usize], &bodies[p.b as usize]);
        self.a[k] = p.a;
        self.b[k] = p.b;
        self.inv_inertia_a.0[k] = a.inv_inertia;
        self.inv_inertia_b.0[k] = b.inv_inertia;
        self.normal_x.0[k] = p.normal.x;
        self.normal_y.0[k] = p.normal.y;
        self.friction.0[k] = p.friction;
        self.fixed.0[k] = if a.moves() && b.moves() { 0.0 } else { 1.0 };
        if N == 2 {
            let block = p.pair_coupling.expect("batched pairs are coupled");
            self.k11.0[k] = block.k11;
            self.k12.0[k] = block.k12;
            self.k22.0[k] = block.k22;
            self.inverse[0].0[k] = block.inverse.0;
            self.inverse[1].0[k] = block.inverse.1;
            self.inverse[2].0[k] = block.inverse.2;
        }
        let lanes = self.points.iter_mut().zip(&mut self.normal_impulses);
        for (((lane, impulse), contacts), p) in lanes.zip(&mut self.contacts).zip(lane_points) {
            contacts[k] = p.contact;
            impulse.0[k] = p.normal_impulse;
            lane.normal_lever_a.0[k] = p.levers.normal.0;
            lane.normal_lever_b.0[k] = p.levers.normal.1;
            lane.reach_a.0[k] = p.levers.reach.0;
            lane.reach_b.0[k] = p.levers.reach.1;
            lane.base_separation.0[k] = p.base_separation;
            lane.normal_mass.0[k] = p.normal_mass;
            lane.tangent_mass.0[k] = p.tangent_mass;
            lane.tangent_impulse.0[k] = p.tangent_impulse;
        }
        let bounces = lane_points[..N].iter().any(|p| p.restitution != 0.0);
        let bit = 1 << k;
        if bounces {
            for (lane, p) in self.bounce.iter_mut().zip(lane_points) {
                lane.restitution.0[k] = p.restitution;
                lane.relative_velocity.0[k] = p.relative_velocity;
                lane.max_normal_impulse.0[k] = p.max_normal_impulse;
                lane.closing_acceleration.0[k] = p.closing_acceleration;
                lane.fastest_impact.0[k] = p.fastest_impact;
            }
        }
        self.bouncing_lanes = if bounces {
            self.bouncing_lanes | bit
        } else {
            self.bouncing_lanes & !bit
        };
    }

    /// The accumulated impulses, into `impulses` at the lanes' contacts.
    pub(super) fn store_impulses(&self, impulses: &mut [(f64, f64)]) {
        let points = self.points.iter().zip(&self.normal_impulses);
        for ((lanes, normal), indices) in points.zip(&self.contacts) {
            for (k, &index) in indices.iter().enumerate().filter(|&(_, &i)| i != PAD) {
                impulses[index as usize] = (normal.0[k], lanes.tangent_impulse.0[k]);
            }
        }
    }

    /// Writes what the passes changed back to the batch's points.
    pub(super) fn scatter(&self, points: &mut [PointConstraint]) {
        for (which, (lp, lb)) in self.points.iter().zip(&self.bounce).enumerate() {
            let normal = self.normal_impulses[which].0;
            let tangent = lp.tangent_impulse.0;
            let max_normal = lb.max_normal_impulse.0;
            let relative = lb.relative_velocity.0;
            for k in (0..LANES).filter(|&k| self.first_point[k] != PAD) {
                let p = &mut points[self.first_point[k] as usize + which];
                p.normal_impulse = normal[k];
                p.tangent_impulse = tangent[k];
                // A point that cannot bounce keeps its own, as the passes leave them.
                if self.bouncing_lanes & (1 << k) != 0 {
                    p.max_normal_impulse = max_normal[k];
                    p.relative_velocity = relative[k];
                }
            }
        }
    }
}

/// The points of an unused lane (`PAD`): all zero, between the null body and itself, so
/// that every pass leaves them and the body as they are.
fn unused_lane(null_body: u32) -> [PointConstraint; 2] {
    let point = PointConstraint {
        contact: PAD,
        a: null_body,
        b: null_body,
        normal: Vec2::zeros(),
        levers: PointLevers::default(),
        base_separation: 0.0,
        normal_mass: 0.0,
        tangent_mass: 0.0,
        friction: 0.0,
        restitution: 0.0,
        relative_velocity: 0.0,
        normal_impulse: 0.0,
        tangent_impulse: 0.0,
        max_normal_impulse: 0.0,
        closing_acceleration: 0.0,
        fastest_impact: 0.0,
        pair_coupling: Some(NormalBlock {
            k11: 0.0,
            k12: 0.0,
            k22: 0.0,
            inverse: (0.0, 0.0, 0.0),
        }),
    };
    [point; 2]
}
