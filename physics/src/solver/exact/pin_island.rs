//! An island of pins solved at once: K ψ = −residual over all its joints, by one direct
//! solve per Newton step (thesis §3.3 eq. 34–39 for the whole island), with its buffers kept
//! from island to island and step to step.

use crate::math::{Rot, Vec2};
use crate::solver::SolverBody;
use crate::solver::envelope::EnvelopeLu;
use crate::solver::joint::{JointConstraint, JointIterations, coupling_block};
use nalgebra::{DMatrix, DVector};

/// Where the joints' gaps are observed when K is built: at the bodies' present angles, or
/// turned on by ω·dt to where the predicted gaps look (`PinIsland::predicted_gaps`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Observed {
    Now,
    Ahead,
}

/// One island's direct pin solve: its layout (its bodies, each joint's two among them, the
/// arms at the present angles, which joints share a moving body) and the buffers of its
/// Newton steps.
#[derive(Debug, Clone, Default)]
pub(super) struct PinIsland {
    /// What the layout was made from: each joint's two bodies and whether each moves.
    layout_key: Vec<(u32, u32, bool, bool)>,
    /// The island's body slots, sorted, and each joint's two by their place among them.
    slots: Vec<u32>,
    ends: Vec<(usize, usize)>,
    /// Each body's rotation at its present angle, and each joint's arms there. Impulses
    /// change velocities, not angles: these hold while the island's impulses are found
    /// and applied.
    turned_now: Vec<Rot>,
    arms_now: Vec<(Vec2, Vec2)>,
    /// Joint p's coupled joints (those sharing a moving body with it, itself among them,
    /// increasing): `coupled[coupled_start[p]..coupled_start[p + 1]]`, the only blocks of
    /// K that are not zero. A chain's K is block tridiagonal: its m² blocks are nearly all
    /// zero, and filling them would cost a long chain more than solving it.
    coupled_start: Vec<usize>,
    coupled: Vec<usize>,
    /// Each moving body's joints, by body: `(body, joint)` sorted.
    on_body: Vec<(usize, usize)>,
    /// Each body's rotation where the predicted gaps look, each joint's arms there, and
    /// its gap (relative to its target).
    turned_ahead: Vec<Rot>,
    arms_ahead: Vec<(Vec2, Vec2)>,
    gaps: Vec<Vec2>,
    /// The bodies as they were before a trial step.
    saved: Vec<(usize, SolverBody)>,
    k: Vec<f64>,
    /// Each row of K's first column that may be nonzero: joint p's rows start at its
    /// first coupled joint's (part of the layout).
    k_first: Vec<usize>,
    /// The right-hand side, and then the impulses ψ.
    psi: Vec<f64>,
    envelope: EnvelopeLu,
}

impl PinIsland {
    /// The island's bodies, the joints' places among them, the arms at the present angles
    /// and the coupled joints. The structure depends only on which bodies each joint holds
    /// and which of them move: it is kept while those stay (an island is laid out several
    /// times a substep), and only the arms are turned afresh.
    fn lay_out(&mut self, joints: &[JointConstraint], bodies: &[SolverBody]) {
        let moves = |slot: u32| bodies[slot as usize].moves();
        let key = |j: &JointConstraint| (j.body_a, j.body_b, moves(j.body_a), moves(j.body_b));
        let same = self.layout_key.len() == joints.len()
            && self
                .layout_key
                .iter()
                .zip(joints)
                .all(|(k, j)| *k == key(j));
        if !same {
            self.layout_key.clear();
            self.layout_key.extend(joints.iter().map(key));
            self.lay_out_structure(joints, bodies);
        }
        self.turned_now.clear();
        self.turned_now.extend(
            self.slots
                .iter()
                .map(|&i| Rot::new(bodies[i as usize].angle)),
        );
        self.arms_now.clear();
        for (j, &(a, b)) in joints.iter().zip(&self.ends) {
            let arms = j.arms_turned((self.turned_now[a], self.turned_now[b]));
            self.arms_now.push(arms);
        }
    }

    /// `lay_out`'s structure: the bodies, the joints' ends among them and the coupled
    /// joints.
    fn lay_out_structure(&mut self, joints: &[JointConstraint], bodies: &[SolverBody]) {
        self.slots.clear();
        self.slots
            .extend(joints.iter().flat_map(|j| [j.body_a, j.body_b]));
        self.slots.sort_unstable();
        self.slots.dedup();
        let place = |slot: u32, slots: &[u32]| slots.binary_search(&slot).expect("listed");
        self.ends.clear();
        self.ends.extend(
            joints
                .iter()
                .map(|j| (place(j.body_a, &self.slots), place(j.body_b, &self.slots))),
        );
        let moves = |slot: u32| bodies[slot as usize].moves();
        self.on_body.clear();
        for (q, &(a, b)) in self.ends.iter().enumerate() {
            for end in [a, b] {
                if moves(self.slots[end]) {
                    self.on_body.push((end, q));
                }
            }
        }
        self.on_body.sort_unstable();
        self.coupled_start.clear();
        self.coupled.clear();
        for &(a, b) in &self.ends {
            self.coupled_start.push(self.coupled.len());
            let from = self.coupled.len();
            for end in [a, b] {
                let first = self.on_body.partition_point(|&(body, _)| body < end);
                let on_end = self.on_body[first..]
                    .iter()
                    .take_while(|&&(body, _)| body == end);
                self.coupled.extend(on_end.map(|&(_, q)| q));
            }
            self.coupled[from..].sort_unstable();
            let kept = dedup_in_place(&mut self.coupled[from..]);
            self.coupled.truncate(from + kept);
        }
        self.coupled_start.push(self.coupled.len());
        self.k_first.clear();
        for p in 0..joints.len() {
            let coupled = &self.coupled[self.coupled_start[p]..self.coupled_start[p + 1]];
            let first = 2 * coupled.first().map_or(p, |&q| q.min(p));
            self.k_first.extend([first, first]);
        }
    }

    /// The impulses that make `residual` zero for all joints of the island at once, to
    /// first order: K ψ = −residual, each joint's gap observed as `observed` says, into
    /// `self.psi`. False if K is singular beyond repair.
    fn find_impulses(
        &mut self,
        joints: &[JointConstraint],
        bodies: &[SolverBody],
        observed: Observed,
        residual: impl Fn(usize) -> Vec2,
    ) -> bool {
        let n = 2 * joints.len();
        // K is kept zero between solves (`clear_k`): only its coupled blocks are written.
        if self.k.len() != n * n {
            self.k.clear();
            self.k.resize(n * n, 0.0);
        }
        self.psi.clear();
        self.psi.resize(n, 0.0);
        let observed_arms = match observed {
            Observed::Now => &self.arms_now,
            Observed::Ahead => &self.arms_ahead,
        };
        for p in 0..joints.len() {
            for &q in &self.coupled[self.coupled_start[p]..self.coupled_start[p + 1]] {
                let block = coupling_block(
                    (&joints[p], observed_arms[p]),
                    (&joints[q], self.arms_now[q]),
                    bodies,
                );
                for (r, row) in block.iter().enumerate() {
                    for (c, value) in row.iter().enumerate() {
                        self.k[(2 * p + r) * n + 2 * q + c] = *value;
                    }
                }
            }
            let d = residual(p);
            self.psi[2 * p] = -d.x;
            self.psi[2 * p + 1] = -d.y;
        }
        // Redundant joints (closed loops at special poses) make K singular: a
        // regularisation far below the entries' rounding keeps the solve going without
        // changing answers.
        let scale = (0..n).map(|i| self.k[i * n + i]).fold(0.0, f64::max);
        for i in 0..n {
            self.k[i * n + i] += 1e-12 * scale;
        }
        // Within K's envelope where its pivots stay well away from zero (a chain's K is
        // block tridiagonal, and its envelope narrow), densely with pivoting otherwise.
        let solved = if self
            .envelope
            .factor(&self.k, n, &self.k_first, 1e-10 * scale)
        {
            self.envelope.solve(&mut self.psi);
            true
        } else {
            let rhs = DVector::from_column_slice(&self.psi);
            let dense = DMatrix::from_row_slice(n, n, &self.k).lu().solve(&rhs);
            dense.is_some_and(|psi| {
                self.psi.copy_from_slice(psi.as_slice());
                true
            })
        };
        self.clear_k(joints.len());
        solved && self.psi.iter().all(|v| v.is_finite())
    }

    /// Zeroes what `find_impulses` wrote into K: the coupled blocks and the diagonal.
    fn clear_k(&mut self, joint_count: usize) {
        let n = 2 * joint_count;
        for p in 0..joint_count {
            for &q in &self.coupled[self.coupled_start[p]..self.coupled_start[p + 1]] {
                for r in 2 * p..2 * p + 2 {
                    self.k[r * n + 2 * q..r * n + 2 * q + 2].fill(0.0);
                }
            }
        }
        for i in 0..n {
            self.k[i * n + i] = 0.0;
        }
    }

    /// Adds `fraction` of the impulses found to the joints' record of what they applied.
    fn record_impulses(&self, joints: &mut [JointConstraint], fraction: f64) {
        for (p, j) in joints.iter_mut().enumerate() {
            j.impulse += Vec2::new(self.psi[2 * p], self.psi[2 * p + 1]) * fraction;
        }
    }

    /// Applies `fraction` of the impulses found at the joints' present anchors.
    fn apply_impulses(&self, joints: &[JointConstraint], bodies: &mut [SolverBody], fraction: f64) {
        for (p, j) in joints.iter().enumerate() {
            let impulse = Vec2::new(self.psi[2 * p], self.psi[2 * p + 1]) * fraction;
            let (ia, ib) = (j.body_a as usize, j.body_b as usize);
            let (r_a, r_b) = self.arms_now[p];
            let (pa, pb) = (bodies[ia].position + r_a, bodies[ib].position + r_b);
            bodies[ia].apply_impulse(impulse, pa);
            bodies[ib].apply_impulse(-impulse, pb);
        }
    }

    /// Each joint's predicted gap `dt` on (relative to its target) and its arms turned to
    /// where that gap is measured, each body turned once; returns the largest gap.
    fn predicted_gaps(
        &mut self,
        joints: &[JointConstraint],
        bodies: &[SolverBody],
        dt: f64,
    ) -> f64 {
        self.turned_ahead.clear();
        self.turned_ahead.extend(self.slots.iter().map(|&i| {
            let b = &bodies[i as usize];
            Rot::new(b.angle + b.angular_velocity * dt)
        }));
        self.arms_ahead.clear();
        self.gaps.clear();
        let mut worst: f64 = 0.0;
        for (j, &(a, b)) in joints.iter().zip(&self.ends) {
            let arms = j.arms_turned((self.turned_ahead[a], self.turned_ahead[b]));
            let (a, b) = (&bodies[j.body_a as usize], &bodies[j.body_b as usize]);
            let end_a = a.position + a.velocity * dt + arms.0;
            let end_b = b.position + b.velocity * dt + arms.1;
            let gap = end_a - end_b - j.gap_target;
            worst = worst.max(gap.norm());
            self.arms_ahead.push(arms);
            self.gaps.push(gap);
        }
        worst
    }

    /// Stage 1 (thesis eq. 40) for the whole island at once: impulses that make every
    /// joint's anchors move together. False if the direct solve is impossible.
    pub(super) fn stop_drift(
        &mut self,
        joints: &mut [JointConstraint],
        bodies: &mut [SolverBody],
    ) -> bool {
        self.lay_out(joints, bodies);
        let mut drift = std::mem::take(&mut self.gaps);
        drift.clear();
        drift.extend(joints.iter().zip(&self.arms_now).map(|(j, &(r_a, r_b))| {
            let (a, b) = (&bodies[j.body_a as usize], &bodies[j.body_b as usize]);
            a.velocity_at(a.position + r_a) - b.velocity_at(b.position + r_b)
        }));
        let found = self.find_impulses(joints, bodies, Observed::Now, |p| drift[p]);
        self.gaps = drift;
        if found {
            self.apply_impulses(joints, bodies, 1.0);
            self.record_impulses(joints, 1.0);
        }
        found
    }

    /// Newton steps on the island's predicted gaps. Each step must shrink the worst gap; if
    /// a full step does not (far from the solution the rotation makes the gap very
    /// nonlinear, and a full step can leap to a wildly spinning solution), half steps are
    /// tried, and the pass stops if none helps. False if the direct solve is impossible.
    pub(super) fn close_gaps(
        &mut self,
        joints: &mut [JointConstraint],
        bodies: &mut [SolverBody],
        dt: f64,
        it: &JointIterations,
    ) -> bool {
        self.lay_out(joints, bodies);
        let mut worst = self.predicted_gaps(joints, bodies, dt);
        for _ in 0..it.max_sweeps.min(10) {
            if worst < it.position_tolerance {
                break;
            }
            let gaps = std::mem::take(&mut self.gaps);
            let found = self.find_impulses(joints, bodies, Observed::Ahead, |p| gaps[p] / dt);
            self.gaps = gaps;
            if !found {
                return false;
            }
            self.saved.clear();
            self.saved
                .extend(self.slots.iter().map(|&i| (i as usize, bodies[i as usize])));
            let mut fraction = 1.0;
            let mut improved = false;
            for _ in 0..5 {
                self.apply_impulses(joints, bodies, fraction);
                let now = self.predicted_gaps(joints, bodies, dt);
                if now < worst {
                    worst = now;
                    improved = true;
                    self.record_impulses(joints, fraction);
                    break;
                }
                for &(i, b) in &self.saved {
                    bodies[i] = b;
                }
                fraction *= 0.5;
            }
            if !improved {
                break; // the rest waits for the next step (see the note on heavy chains)
            }
        }
        true
    }

    /// Newton steps on the island's current gaps, moving bodies (not their velocities)
    /// until each joint is at its repair target. Backtracks like `close_gaps`. False if
    /// the direct solve is impossible.
    pub(super) fn repair(
        &mut self,
        joints: &[JointConstraint],
        bodies: &mut [SolverBody],
        it: &JointIterations,
    ) -> bool {
        let residual = |j: &JointConstraint, bodies: &[SolverBody]| {
            j.predicted_gap(bodies, 0.0) - j.gap_target
        };
        let worst_of = |bodies: &[SolverBody]| {
            joints
                .iter()
                .map(|j| residual(j, bodies).norm_squared())
                .sum::<f64>()
                .sqrt()
        };
        let mut worst = worst_of(bodies);
        for _ in 0..20 {
            if worst < it.position_tolerance {
                break;
            }
            // The repair turns bodies: the arms at their present angles change each step.
            self.lay_out(joints, bodies);
            if !self.find_impulses(joints, bodies, Observed::Now, |p| {
                residual(&joints[p], bodies)
            }) {
                return false;
            }
            self.saved.clear();
            self.saved
                .extend(self.slots.iter().map(|&i| (i as usize, bodies[i as usize])));
            let mut fraction = 1.0;
            let mut improved = false;
            for _ in 0..12 {
                displace_island(joints, bodies, &self.psi, fraction);
                let now = worst_of(bodies);
                if now < worst {
                    worst = now;
                    improved = true;
                    break;
                }
                for &(i, b) in &self.saved {
                    bodies[i] = b;
                }
                fraction *= 0.5;
            }
            if !improved {
                break;
            }
        }
        true
    }
}

/// Keeps the first of each run of equal values at the front; returns how many there are.
fn dedup_in_place(values: &mut [usize]) -> usize {
    let mut kept = 0;
    for k in 0..values.len() {
        if kept == 0 || values[k] != values[kept - 1] {
            values[kept] = values[k];
            kept += 1;
        }
    }
    kept
}

/// Moves `fraction` of the displacement that the island impulses `psi` would cause in one
/// second: Δx = M⁻¹ψ, Δθ = I⁻¹ r×ψ. Positions change, velocities do not.
pub(super) fn displace_island(
    joints: &[JointConstraint],
    bodies: &mut [SolverBody],
    psi: &[f64],
    fraction: f64,
) {
    for (p, j) in joints.iter().enumerate() {
        let push = Vec2::new(psi[2 * p], psi[2 * p + 1]) * fraction;
        let (ia, ib) = (j.body_a as usize, j.body_b as usize);
        let (r_a, r_b) = j.arms((bodies[ia].angle, bodies[ib].angle));
        for (i, r, sign) in [(ia, r_a, 1.0), (ib, r_b, -1.0)] {
            let b = &mut bodies[i];
            b.position += push * (sign * b.inv_mass);
            b.angle += sign * b.inv_inertia * crate::math::cross(r, push);
        }
    }
}
