//! The small contact islands of masses far apart, their normals (and from a larger mass
//! ratio their friction) solved as one LCP per pass.

use super::batch::PassSettings;
use super::bodies::SoftBody;
use super::constraints::PointConstraint;
use super::contacts::{
    BodyPair, apply_normal, approach, point_target, solve_friction, solve_point,
};
use crate::math::{Vec2, perp};
use crate::solver::lcp::{FrictionBound, LcpMethod, LcpProblem, LcpSolver, REGULARISATION};

/// Contact islands of at most `LCP_POINT_LIMIT` points whose masses differ by at least
/// `LCP_NORMALS_MASS_RATIO` solve their normals as one LCP per pass, rigid with the soft
/// bias as target, and their friction point by point after it; from `LCP_MASS_RATIO` on,
/// friction is in the LCP too (friction-index bounds). Soft rows take their stiffness from
/// their own effective mass, so a heavy body on a light one squeezes it by the mass ratio
/// (a 1e6:1 pair sank a third of the light box), and Gauss–Seidel passes carry a heavy
/// load down through light bodies slowly: a body rolling at 4 m/s over one 13 times
/// lighter on the floor went 1.4 smallest radii into it. The coupled solve does both at
/// once. Each pass after the step's first starts from the last pass's sets: where they
/// still hold, it solves one triangular system instead of pivoting. The limits trade
/// the random throws' deep contacts against their time (docs/bench/profile.md, "The
/// small islands' LCP: its limits").
pub(super) const LCP_POINT_LIMIT: usize = 16;
const LCP_MASS_RATIO: f64 = 100.0;
const LCP_NORMALS_MASS_RATIO: f64 = 10.0;

/// The small contact islands of a step and their LCPs.
#[derive(Debug, Clone, Default)]
pub(super) struct ContactLcp {
    /// Point ranges `[start, end)`, where each island's matrix starts in `k`, and whether
    /// its friction rows are in it (else only its normals).
    pub(super) islands: Vec<(usize, usize, usize, bool)>,
    /// Every contact island's point range, and whether it is solved as an LCP.
    pub(super) all_islands: Vec<(usize, usize, bool)>,
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
    pub(super) fn prepare(
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
    pub(super) fn classify(
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
    pub(super) fn solve(
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
