//! An island's constraints as rows of one linear complementarity problem (thesis §3.2):
//! contact normals and friction, pin joints (equality rows) and joint motors (boxed rows).
//!
//! Each row is a velocity `J·v` along one direction; `A = J M⁻¹ Jᵀ` (the thesis's `A_il` with
//! signs, eq. 17/27) couples rows that share a body.

use crate::math::{Vec2, cross};
use crate::solver::SolverBody;
use crate::solver::contact::Contact;
use crate::solver::joint::JointConstraint;
use crate::solver::lcp::{FrictionBound, LcpProblem, LcpSolver, LcpStats};

/// One body's part of a row: the row's velocity is `linear·v + angular·ω` summed over both.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct RowEnd {
    pub body: u32,
    pub linear: Vec2,
    pub angular: f64,
}

/// What a row stands for, to put its impulse back where it belongs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowKind {
    ContactNormal(u32),
    ContactTangent(u32),
    /// The one friction row of a face contact's two points (see `velocity_rows`).
    SharedTangent(u32, u32),
    JointX(u32),
    JointY(u32),
    JointMotor(u32),
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Row {
    pub kind: RowKind,
    pub ends: [RowEnd; 2],
    pub b: f64,
    pub lo: f64,
    pub hi: f64,
    /// For a friction row: the normal rows whose impulses bound it, and μ.
    pub friction_of: Option<FrictionBound>,
}

impl Row {
    pub(crate) fn velocity(&self, bodies: &[SolverBody]) -> f64 {
        self.ends
            .iter()
            .map(|e| {
                let t = &bodies[e.body as usize];
                e.linear.dot(&t.velocity) + e.angular * t.angular_velocity
            })
            .sum()
    }

    /// How much a unit impulse along the row changes the row's own velocity: `A_ii`.
    pub(crate) fn diagonal(&self, bodies: &[SolverBody]) -> f64 {
        self.ends
            .iter()
            .map(|e| {
                let t = &bodies[e.body as usize];
                t.inv_mass * e.linear.norm_squared() + t.inv_inertia * e.angular * e.angular
            })
            .sum()
    }

    /// Applies impulse `x` along the row (its Jacobian transposed, scaled by M⁻¹).
    pub(crate) fn apply(&self, bodies: &mut [SolverBody], x: f64) {
        for e in &self.ends {
            let t = &mut bodies[e.body as usize];
            t.velocity += e.linear * (x * t.inv_mass);
            t.angular_velocity += e.angular * x * t.inv_inertia;
        }
    }
}

/// A row along `dir` at world point `p` between A (+) and B (−): a contact or pin row.
fn point_row(
    a: u32,
    b: u32,
    p_a: Vec2,
    p_b: Vec2,
    dir: Vec2,
    bodies: &[SolverBody],
) -> [RowEnd; 2] {
    let r_a = p_a - bodies[a as usize].position;
    let r_b = p_b - bodies[b as usize].position;
    [
        RowEnd {
            body: a,
            linear: dir,
            angular: cross(r_a, dir),
        },
        RowEnd {
            body: b,
            linear: -dir,
            angular: -cross(r_b, dir),
        },
    ]
}

/// What the velocity rows aim for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VelocityTargets {
    pub dt: f64,
    /// Approach speeds below this do not bounce.
    pub bounce_below: f64,
    /// Whether friction rows are included (the thesis's first stage solves normals alone).
    pub friction: bool,
}

impl VelocityTargets {
    /// The same targets with no contact bouncing: the inelastic answer a bounce is held
    /// against (`solver::bounce`).
    pub(crate) fn without_bounce(&self) -> Self {
        Self {
            bounce_below: f64::INFINITY,
            ..*self
        }
    }
}

/// Builds the velocity-level rows of one island.
pub(crate) fn velocity_rows(
    contacts: &[(u32, Contact)],
    joints: &[JointConstraint],
    bodies: &[SolverBody],
    targets: &VelocityTargets,
    rows: &mut Vec<Row>,
) {
    rows.clear();
    let mut k = 0;
    while k < contacts.len() {
        // A manifold's points come one after another, on one normal.
        let (index, c) = contacts[k];
        let shares_face = contacts.get(k + 1).is_some_and(|&(_, d)| {
            (d.body_a, d.body_b) == (c.body_a, c.body_b) && d.normal == c.normal
        });
        let points = if shares_face { 2 } else { 1 };
        let first_normal = rows.len();
        for &(index, c) in &contacts[k..k + points] {
            let ends = point_row(c.body_a.0, c.body_b.0, c.point, c.point, c.normal, bodies);
            let mut row = Row {
                kind: RowKind::ContactNormal(index),
                ends,
                b: 0.0,
                lo: 0.0,
                hi: f64::INFINITY,
                friction_of: None,
            };
            row.b = row.velocity(bodies) - c.min_normal_velocity(targets.dt, targets.bounce_below);
            rows.push(row);
        }
        if targets.friction {
            // Two points on one face have the same tangent row but for the lever, which
            // differs only by the points' offset along the normal (their depths): one row
            // at their midpoint, bounded by μ times both normals, is the same friction
            // without a redundant row (redundant rows make the pivoting degenerate).
            let (kind, point, bound) = if shares_face {
                let (second, d) = contacts[k + 1];
                let bound = FrictionBound::shared(first_normal, first_normal + 1, c.friction);
                (
                    RowKind::SharedTangent(index, second),
                    (c.point + d.point) * 0.5,
                    bound,
                )
            } else {
                let bound = FrictionBound::single(first_normal, c.friction);
                (RowKind::ContactTangent(index), c.point, bound)
            };
            let ends = point_row(c.body_a.0, c.body_b.0, point, point, c.tangent(), bodies);
            let mut t_row = Row {
                kind,
                ends,
                b: 0.0,
                lo: 0.0,
                hi: 0.0,
                friction_of: Some(bound),
            };
            t_row.b = t_row.velocity(bodies);
            rows.push(t_row);
        }
        k += points;
    }
    for (k, j) in joints.iter().enumerate() {
        let (a, b) = (&bodies[j.body_a as usize], &bodies[j.body_b as usize]);
        let (r_a, r_b) = j.arms((a.angle, b.angle));
        let (p_a, p_b) = (a.position + r_a, b.position + r_b);
        // A pin's rows ask only that its anchors stop drifting apart: the velocity solve
        // asks nothing of the bodies that they did not bring, so it adds no energy. Its
        // gap is closed by the pins' own position pass after it (`joint_block`), apart
        // from the contacts: asked of the same solve, a gap that a contact forbids closing
        // (two pinned bodies overlapping) makes the rows contradict each other, and the
        // solve's answer to that is energy from nothing.
        for (kind, dir) in [
            (RowKind::JointX(k as u32), Vec2::new(1.0, 0.0)),
            (RowKind::JointY(k as u32), Vec2::new(0.0, 1.0)),
        ] {
            let ends = point_row(j.body_a, j.body_b, p_a, p_b, dir, bodies);
            let mut row = Row {
                kind,
                ends,
                b: 0.0,
                lo: f64::NEG_INFINITY,
                hi: f64::INFINITY,
                friction_of: None,
            };
            row.b = row.velocity(bodies);
            rows.push(row);
        }
        if let Some(m) = j.motor.filter(|m| m.enabled) {
            let limit = m.max_torque.abs() * targets.dt;
            let ends = [
                RowEnd {
                    body: j.body_a,
                    linear: Vec2::zeros(),
                    angular: 1.0,
                },
                RowEnd {
                    body: j.body_b,
                    linear: Vec2::zeros(),
                    angular: -1.0,
                },
            ];
            let mut row = Row {
                kind: RowKind::JointMotor(k as u32),
                ends,
                b: 0.0,
                lo: -limit,
                hi: limit,
                friction_of: None,
            };
            row.b = row.velocity(bodies) - m.drive_speed();
            rows.push(row);
        }
    }
}

/// A boxed LCP assembled densely from rows (`assemble`), with its buffers and solver
/// kept from solve to solve: the islands' LCPs, the impact pass and the motors' hold
/// each solve their rows through one.
#[derive(Debug, Clone, Default)]
pub(crate) struct DenseRowsLcp {
    a: Vec<f64>,
    b: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    friction_index: Vec<Option<FrictionBound>>,
    lcp: LcpSolver,
}

impl DenseRowsLcp {
    /// The impulses of `rows` at `bodies` into `x`, the friction rows' first bounds taken
    /// from `guess` (empty: from zero).
    pub(crate) fn solve(
        &mut self,
        rows: &[Row],
        bodies: &[SolverBody],
        regularisation: f64,
        guess: &[f64],
        x: &mut Vec<f64>,
    ) -> LcpStats {
        assemble(rows, bodies, &mut self.a);
        self.b.clear();
        self.lo.clear();
        self.hi.clear();
        self.friction_index.clear();
        for r in rows {
            self.b.push(r.b);
            self.lo.push(r.lo);
            self.hi.push(r.hi);
            self.friction_index.push(r.friction_of);
        }
        let problem = LcpProblem {
            n: rows.len(),
            a: &self.a,
            b: &self.b,
            lo: &self.lo,
            hi: &self.hi,
            friction_index: Some(&self.friction_index),
            regularisation,
        };
        self.lcp.solve_guessing(&problem, guess, x)
    }
}

/// Fills the dense symmetric `A = J M⁻¹ Jᵀ` (row-major, n×n) of `rows`.
pub(crate) fn assemble(rows: &[Row], bodies: &[SolverBody], a: &mut Vec<f64>) {
    let n = rows.len();
    // Every entry is written below: the old ones need no zeroing first.
    a.resize(n * n, 0.0);
    for p in 0..n {
        for q in p..n {
            let mut sum = 0.0;
            for ep in &rows[p].ends {
                for eq in &rows[q].ends {
                    if ep.body == eq.body {
                        let t = &bodies[ep.body as usize];
                        sum += t.inv_mass * ep.linear.dot(&eq.linear)
                            + t.inv_inertia * ep.angular * eq.angular;
                    }
                }
            }
            a[p * n + q] = sum;
            a[q * n + p] = sum;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::BodyHandle;
    use crate::collide::FeatureId;

    /// The assembled A must equal the measured velocity response to unit impulses — the
    /// check thesis §3.2.2 says was made for the matrix.
    #[test]
    fn matrix_matches_the_response_to_unit_impulses() {
        let bodies = vec![
            SolverBody {
                inv_mass: 0.5,
                inv_inertia: 0.3,
                position: Vec2::new(0.0, 0.0),
                angle: 0.2,
                ..Default::default()
            },
            SolverBody {
                inv_mass: 0.25,
                inv_inertia: 0.1,
                position: Vec2::new(1.5, 0.5),
                angle: -0.4,
                ..Default::default()
            },
            SolverBody::default(),
        ];
        let contact = |a: u32, b: u32, p: Vec2, n: Vec2| Contact {
            body_a: BodyHandle(a),
            body_b: BodyHandle(b),
            point: p,
            normal: n.normalize(),
            depth: 0.01,
            id: FeatureId(0),
            restitution: 0.0,
            friction: 0.5,
            approach_velocity: 0.0,
            normal_velocity: 0.0,
            normal_impulse: 0.0,
            tangent_impulse: 0.0,
        };
        let contacts = [
            (0, contact(0, 1, Vec2::new(0.8, 0.3), Vec2::new(-1.0, -0.2))),
            (1, contact(1, 2, Vec2::new(1.7, 1.0), Vec2::new(0.0, -1.0))),
            (2, contact(0, 2, Vec2::new(-0.5, 0.5), Vec2::new(0.1, -1.0))),
        ];
        let joints = [JointConstraint {
            joint: 0,
            body_a: 0,
            body_b: 1,
            local_anchor_a: Vec2::new(0.7, 0.1),
            local_anchor_b: Vec2::new(-0.6, -0.3),
            motor: None,
            limits: None,
            reference_angle: 0.0,
            limit_impulse: (0.0, 0.0),
            gap_target: Vec2::zeros(),
            impulse: Vec2::zeros(),
        }];
        let targets = VelocityTargets {
            dt: 0.01,
            bounce_below: 0.0,
            friction: true,
        };
        let mut rows = vec![];
        velocity_rows(&contacts, &joints, &bodies, &targets, &mut rows);
        let mut a = vec![];
        assemble(&rows, &bodies, &mut a);
        let n = rows.len();
        for q in 0..n {
            let mut probe = bodies.clone();
            rows[q].apply(&mut probe, 1.0);
            for p in 0..n {
                let response = rows[p].velocity(&probe);
                assert!((response - a[p * n + q]).abs() < 1e-14, "A[{p}][{q}]");
            }
        }
    }
}
