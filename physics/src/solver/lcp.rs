//! A boxed linear complementarity problem solver (thesis §3.2.4, eq. 32):
//! given symmetric PSD `A`, `b` and bounds `lo ≤ 0 ≤ hi`, find `x` and `w = A·x + b` with
//! `lo ≤ x ≤ hi` and, per index, `x = lo, w ≥ 0` or `x = hi, w ≤ 0` or `lo < x < hi, w = 0`.
//!
//! The method is Baraff's 1994 pivoting algorithm as the thesis extends it to bounds: drive
//! one index at a time to complementarity, moving the clamped set `C` (w = 0) along. `A_CC`
//! is kept as a Cholesky factor updated by one row when an index joins `C` and by Givens
//! rotations when one leaves, so a pivot costs O(|C|²), not O(|C|³).
//!
//! Rows may also be *friction rows* whose bounds are `±μ·x_j` of a normal row `j`
//! (ODE's "findex"): those are solved by re-solving with bounds from the last normals until
//! the bounds stop moving (a fixed point, in 2–10 rounds on stacks). A round after the
//! first keeps the last round's sets and solves for the clamped indices directly; only if
//! that is not a solution does it pivot from scratch.
//!
//! Everything is scaled symmetrically by `1/√A_ii` first, so mass ratios of 1:1000 and more
//! give well-conditioned pivots. A pivot cap and a projected Gauss–Seidel fallback make it
//! always terminate.

use crate::math::clamp;

/// One problem. `a` is row-major `n×n`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LcpProblem<'a> {
    pub n: usize,
    pub a: &'a [f64],
    pub b: &'a [f64],
    pub lo: &'a [f64],
    pub hi: &'a [f64],
    /// Per row: `Some(bound)` makes the bounds `±μ` times the normal rows' impulses (then
    /// `lo`/`hi` are ignored).
    pub friction_index: Option<&'a [Option<FrictionBound>]>,
    /// Added to the diagonal of the scaled `A` (where the diagonal is 1) of every row with
    /// a bound: a compliance that keeps redundant contacts from making `A_CC` singular.
    /// `REGULARISATION` for velocities; a position pass may take more.
    pub regularisation: f64,
}

/// A friction row's bounds: `±μ` times the impulse of one normal row, or of two summed
/// (one friction row for both points of a face contact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FrictionBound {
    pub mu: f64,
    pub normal: usize,
    pub second_normal: Option<usize>,
}

impl FrictionBound {
    pub(crate) fn single(normal: usize, mu: f64) -> Self {
        Self {
            mu,
            normal,
            second_normal: None,
        }
    }

    pub(crate) fn shared(normal: usize, second_normal: usize, mu: f64) -> Self {
        Self {
            mu,
            normal,
            second_normal: Some(second_normal),
        }
    }

    /// `μ` times the (non-negative part of the) normal impulses, given each row's impulse.
    pub(crate) fn bound(&self, impulse: impl Fn(usize) -> f64) -> f64 {
        let second = self.second_normal.map_or(0.0, |k| impulse(k).max(0.0));
        self.mu * (impulse(self.normal).max(0.0) + second)
    }
}

/// How a problem was solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum LcpMethod {
    #[default]
    Pivoting,
    ProjectedGaussSeidel,
    /// A or b held a non-finite number: x = 0 was returned.
    Rejected,
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct LcpStats {
    pub method: LcpMethod,
    pub pivots: usize,
    /// Friction-index rounds: all of them, and those solved by keeping the last round's
    /// sets, without pivoting.
    pub rounds: usize,
    pub reused_sets: usize,
    /// Whether the rounds stopped at the pivot budget (`PIVOT_BUDGET_PER_ROW`) before
    /// their bounds settled.
    pub over_budget: bool,
    /// Largest violation of bounds or complementarity, relative to the problem's scale; NaN
    /// from `solve_again`, whose callers (the soft step's passes) do not report it.
    pub residual: f64,
}

/// Where an index stands during pivoting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Set {
    Unprocessed,
    Lower,
    Upper,
    Clamped,
}

/// Reusable buffers: solving allocates only when a problem is bigger than any before.
#[derive(Debug, Clone, Default)]
pub(crate) struct LcpSolver {
    scale: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    x: Vec<f64>,
    w: Vec<f64>,
    set: Vec<Set>,
    /// Indices in `C`, in the order of the factor's rows.
    clamped: Vec<usize>,
    /// Cholesky factor of `A_CC` (row-major, `n` columns reserved per row).
    factor: Vec<f64>,
    /// Each factor row's first column that may be nonzero. A clamped index couples to few
    /// others (a chain's pins to their neighbours' only), and its factor row is zero left
    /// of the first it couples to: the factor and its solves skip those zeros.
    factor_first: Vec<usize>,
    dx: Vec<f64>,
    dw: Vec<f64>,
    rhs: Vec<f64>,
    /// The indices not in `C`, increasing (`solve_with_last_sets`).
    unclamped: Vec<usize>,
    previous: Vec<f64>,
    /// The round before `previous`'s solution (damped friction bounds).
    older: Vec<f64>,
    /// The regularisation added to each row's diagonal (0 for an equality row).
    regularised: Vec<f64>,
    /// Whether `set`, `clamped` and `factor` are the last solution's (`solve_again`).
    sets_valid: bool,
}

/// Regularisation added to the diagonal of the scaled `A` (where the diagonal is 1):
/// redundant contacts make `A_CC` singular, and this keeps it positive definite while
/// changing `w` by 1e-12·|x|. It is in `A` itself, so that the factor and `w` agree: added
/// to the factor alone, a solve with the last sets disagreed with the pivoting that found
/// them, and every friction round pivoted again.
pub(crate) const REGULARISATION: f64 = 1e-12;
/// Friction-index rounds before giving up on a fixed point, and the relative change of
/// the impulses at which they stop.
const FRICTION_ROUNDS: usize = 30;
const ROUND_TOLERANCE: f64 = 1e-10;
/// Rounds in a row that do not halve the smallest change so far, after which the rounds
/// stop: they have settled to the solve's own rounding.
const STALLED_ROUNDS: usize = 3;
/// A guessed impulse this close to a bound (relative to the largest) counts as at it: a
/// wrong guess costs only the check that rejects it (then the round pivots), and at rest
/// the loose test finds the sets where a tight one misses them, and a pile at rest is
/// solved in one factorisation more often (docs/bench/profile.md).
const GUESS_AT_BOUND: f64 = 1e-4;
/// Pivots per row that the friction rounds may spend together; once past, the last
/// round's solution stands. A solve from scratch takes about one pivot per clamped row;
/// the budget leaves room for the hardest scenes measured (docs/bench/profile.md).
const PIVOT_BUDGET_PER_ROW: usize = 8;
/// Projected Gauss–Seidel sweeps of the fallback, and the change (relative to the largest
/// impulse) below which it stops early.
const PGS_SWEEPS: usize = 200;
const PGS_TOLERANCE: f64 = 1e-10;
/// The LCP conditions are checked within this much of the problem's scale (its largest
/// `b`): tolerances relative to the problem, so that a problem of tiny numbers (a body of
/// density 1e-20, whose impulses are 1e-18) is held to them as one of ordinary numbers.
const CHECK_TOLERANCE: f64 = 1e-9;

impl LcpSolver {
    /// Solves by pivoting (falling back to Gauss–Seidel if pivoting fails) into `x`.
    pub(crate) fn solve(&mut self, p: &LcpProblem, x: &mut Vec<f64>) -> LcpStats {
        self.solve_guessing(p, &[], x)
    }

    /// `solve`, with the friction rows' first bounds taken from `guess` (say, the last
    /// step's impulses) instead of from zero, so that the rounds start near the fixed
    /// point. An empty `guess` is zero.
    pub(crate) fn solve_guessing(
        &mut self,
        p: &LcpProblem,
        guess: &[f64],
        x: &mut Vec<f64>,
    ) -> LcpStats {
        let mut stats = self.solve_from(p, x, false, guess);
        if stats.method != LcpMethod::Rejected {
            stats.residual = complementarity_residual(p, x);
        }
        stats
    }

    /// Solves a problem with the same `A` as the last one this solver solved and another
    /// `b` (the soft step's passes after its first): the first round starts from the last
    /// solution's sets and the factor of their `A_CC`, and pivots only if they do not
    /// solve it. The residual is not computed: in small worlds it is a few percent of the
    /// soft step's time, for a check the pivoting already makes.
    pub(crate) fn solve_again(&mut self, p: &LcpProblem, x: &mut Vec<f64>) -> LcpStats {
        let warm = self.sets_valid && self.b.len() == p.n;
        self.solve_from(p, x, warm, &[])
    }

    fn solve_from(
        &mut self,
        p: &LcpProblem,
        x: &mut Vec<f64>,
        warm: bool,
        guess: &[f64],
    ) -> LcpStats {
        let n = p.n;
        self.sets_valid = false;
        x.clear();
        x.resize(n, 0.0);
        let finite = |v: &[f64]| v.iter().all(|z| z.is_finite());
        if !finite(&p.a[..n * n]) || !finite(&p.b[..n]) {
            return LcpStats {
                method: LcpMethod::Rejected,
                residual: f64::INFINITY,
                ..LcpStats::default()
            };
        }
        if warm {
            self.load_vectors(p);
        } else {
            self.load_scaled(p);
        }
        let mut stats = LcpStats::default();
        // Gauss–Seidel updates friction bounds row by row already; pivoting needs rounds.
        let has_friction_rows = p
            .friction_index
            .is_some_and(|f| f.iter().any(Option::is_some));
        let rounds = if has_friction_rows {
            FRICTION_ROUNDS
        } else {
            1
        };
        if !warm {
            // Warm, `x` keeps the last solution (scaled): it bounds the friction rows.
            self.x.clear();
            self.x.resize(n, 0.0);
            if guess.len() == n && guess.iter().all(|v| v.is_finite()) {
                for ((x, g), scale) in self.x.iter_mut().zip(guess).zip(&self.scale) {
                    *x = g / scale;
                }
            }
        }
        let mut method = LcpMethod::Pivoting;
        // A guess gives the first round's sets too; `solve_again` keeps the last ones.
        // Where there is no guess, equality rows (pins) are clamped in every solution: a
        // chain of pins then costs one factorisation, not a pivot per row.
        let has_equality_rows =
            (0..n).any(|i| p.lo[i] == f64::NEG_INFINITY && p.hi[i] == f64::INFINITY);
        let guessed = guess.len() == n || (guess.is_empty() && has_equality_rows);
        let mut pivoted = warm
            || ((has_friction_rows || has_equality_rows) && guessed && self.take_sets_from_x(p));
        let budget = PIVOT_BUDGET_PER_ROW * n + 10;
        let (mut damped, mut last_change) = (false, f64::INFINITY);
        let (mut best_change, mut stalled) = (f64::INFINITY, 0);
        for _ in 0..rounds {
            stats.rounds += 1;
            self.previous.clone_from(&self.x);
            self.update_friction_bounds(p, damped);
            // A round after the first starts from the last round's sets: the bounds
            // moved a little, and usually the same indices stay clamped.
            if pivoted && self.solve_with_last_sets() {
                stats.reused_sets += 1;
            } else {
                let ok = self.pivot(&mut stats.pivots);
                pivoted = ok;
                if !ok {
                    method = LcpMethod::ProjectedGaussSeidel;
                    self.x.clone_from(&self.previous);
                    self.gauss_seidel(p);
                }
            }
            let change = self
                .x
                .iter()
                .zip(&self.previous)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let size = self.x.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if change <= ROUND_TOLERANCE * size.max(1e-300) {
                break;
            }
            // Redundant contacts leave A_CC nearly singular, and a solve's own rounding
            // then moves the impulses by 1e-5 of themselves from round to round (the
            // arch's at rest): rounds that no longer halve the best change stop.
            if change < 0.5 * best_change {
                (best_change, stalled) = (change, 0);
            } else {
                stalled += 1;
                if stalled == STALLED_ROUNDS {
                    break;
                }
            }
            // Each round's solution is exact for its bounds; past the budget, the last one
            // stands, its friction bounded by the round before's normals.
            if stats.pivots > budget && stats.rounds < rounds {
                stats.over_budget = true;
                break;
            }
            // A fixed point that does not contract (the clamped set alternating between
            // two, round after round) is damped from then on: the bounds
            // follow the mean of the last two rounds' normals.
            damped |= change > 0.5 * last_change;
            last_change = change;
            std::mem::swap(&mut self.older, &mut self.previous);
        }
        // The sets and the factor are a solution's (for `solve_again`) only if no round
        // fell back to Gauss–Seidel.
        self.sets_valid = pivoted && method == LcpMethod::Pivoting;
        if self.sets_valid {
            self.refine_clamped();
        }
        for ((out, scaled), scale) in x.iter_mut().zip(&self.x).zip(&self.scale).take(n) {
            *out = scaled * scale;
        }
        stats.method = method;
        stats.residual = f64::NAN;
        stats
    }

    /// Keeps every index in its last set (clamped, or at its lower or upper bound, now
    /// moved), solves `A_CC x_C = −b_C − A_CB x_B` for the clamped ones, and accepts the
    /// result if it is a solution: clamped values within their bounds, and `w` pointing
    /// the right way at each bound. False (nothing changed that matters) otherwise.
    fn solve_with_last_sets(&mut self) -> bool {
        // The last pivoting left the factor of A_CC (its rows in `clamped`'s order), and
        // A does not change between rounds: only the right-hand side does. A failure
        // leaves x and w to `pivot`, which starts them afresh.
        let n = self.b.len();
        for i in 0..n {
            match self.set[i] {
                Set::Lower => self.x[i] = self.lo[i],
                Set::Upper => self.x[i] = self.hi[i],
                _ => {}
            }
        }
        if !self.x.iter().all(|v| v.is_finite()) {
            return false;
        }
        self.unclamped.clear();
        self.unclamped
            .extend((0..n).filter(|&j| self.set[j] != Set::Clamped));
        self.rhs.clear();
        for &i in &self.clamped {
            let bounded: f64 = self
                .unclamped
                .iter()
                .map(|&j| self.a[i * n + j] * self.x[j])
                .sum();
            self.rhs.push(-self.b[i] - bounded);
        }
        self.solve_factor();
        for (k, &i) in self.clamped.iter().enumerate() {
            self.x[i] = self.rhs[k];
        }
        self.compute_w();
        let scale = self.b.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let tolerance = CHECK_TOLERANCE * scale;
        let valid = (0..n).all(|i| match self.set[i] {
            Set::Clamped => {
                self.x[i].is_finite()
                    && self.x[i] >= self.lo[i] - tolerance
                    && self.x[i] <= self.hi[i] + tolerance
                    && self.w[i].abs() <= tolerance
            }
            Set::Lower => self.w[i] >= -tolerance || self.lo[i] == self.hi[i],
            Set::Upper => self.w[i] <= tolerance || self.lo[i] == self.hi[i],
            Set::Unprocessed => false,
        });
        if !valid {
            return false;
        }
        for &i in &self.clamped {
            self.x[i] = clamp(self.x[i], self.lo[i], self.hi[i]);
        }
        true
    }

    /// Guesses the sets from `x` (a guess of the solution, scaled): each index at a bound
    /// where `x` is there, clamped between; and factors `A_CC` for them. The first round
    /// then tries them before it pivots (`solve_with_last_sets`): at rest, last step's
    /// impulses give this step's sets, and a solve costs one factorisation instead of a
    /// pivot per clamped index. False if the factor failed.
    fn take_sets_from_x(&mut self, p: &LcpProblem) -> bool {
        let n = self.b.len();
        self.update_friction_bounds(p, false);
        self.w.resize(n, 0.0);
        self.set.clear();
        self.clamped.clear();
        self.factor.clear();
        self.factor.resize(n * n, 0.0);
        self.factor_first.clear();
        // At a bound where the guess is within rounding of it: the guess is the last
        // step's final round, itself only as exact as its solve (see `STALLED_ROUNDS`).
        let size = self.x.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let tolerance = GUESS_AT_BOUND * size;
        for i in 0..n {
            let (lo, hi, x) = (self.lo[i], self.hi[i], self.x[i]);
            self.set.push(if lo == hi || x <= lo + tolerance {
                Set::Lower
            } else if x >= hi - tolerance {
                Set::Upper
            } else {
                Set::Unprocessed
            });
        }
        for i in 0..n {
            if self.set[i] == Set::Unprocessed && !self.join_clamped(i) {
                return false;
            }
        }
        true
    }

    /// Iterative refinement of the clamped impulses against the regularisation. The solve
    /// answers (A_CC + εI) x_C = −b_C, which leaves every clamped row the residual velocity
    /// −ε·x: nothing where impulses are of a size, but a box far heavier than the boxes
    /// under it makes A_CC's smallest eigenvalue as small as the mass ratio, its weight's
    /// impulse falls short by ε over that, and it sinks through them at a steady speed. Each step solves the residual again with the same factor, and is
    /// kept only if it halves the residual (a redundant row's rounding, which no step
    /// reduces, is left alone) and keeps the sets a solution's.
    fn refine_clamped(&mut self) {
        const STEPS: usize = 3;
        let n = self.b.len();
        if self.clamped.is_empty() {
            return;
        }
        self.compute_w();
        let residual = |lcp: &Self| -> f64 {
            lcp.clamped
                .iter()
                .map(|&i| lcp.w[i] - lcp.regularised[i] * lcp.x[i])
                .map(|r| r * r)
                .sum::<f64>()
                .sqrt()
        };
        let mut before = residual(self);
        for _ in 0..STEPS {
            if before == 0.0 || !before.is_finite() {
                return;
            }
            self.rhs.clear();
            for &i in &self.clamped {
                self.rhs
                    .push(-(self.w[i] - self.regularised[i] * self.x[i]));
            }
            self.solve_factor();
            self.previous.clone_from(&self.x);
            for (k, &i) in self.clamped.iter().enumerate() {
                self.x[i] += self.rhs[k];
            }
            self.compute_w();
            let after = residual(self);
            let scale = self.b.iter().map(|v| v.abs()).fold(0.0, f64::max);
            let tolerance = CHECK_TOLERANCE * scale;
            let still_a_solution = (0..n).all(|i| match self.set[i] {
                Set::Clamped => self.x[i] >= self.lo[i] && self.x[i] <= self.hi[i],
                Set::Lower => self.w[i] >= -tolerance || self.lo[i] == self.hi[i],
                Set::Upper => self.w[i] <= tolerance || self.lo[i] == self.hi[i],
                Set::Unprocessed => true,
            });
            if !(after <= 0.5 * before && still_a_solution) {
                self.x.clone_from(&self.previous);
                self.compute_w();
                return;
            }
            before = after;
        }
    }

    /// `w = A x + b`.
    fn compute_w(&mut self) {
        let n = self.b.len();
        for i in 0..n {
            let row = &self.a[i * n..(i + 1) * n];
            self.w[i] = self.b[i] + row.iter().zip(&self.x).map(|(a, x)| a * x).sum::<f64>();
        }
    }

    /// `b`, `lo` and `hi`, scaled as the last `load_scaled` scaled the matrix.
    fn load_vectors(&mut self, p: &LcpProblem) {
        let n = p.n;
        self.b.clear();
        self.b.extend((0..n).map(|i| self.scale[i] * p.b[i]));
        self.lo.clear();
        self.lo.extend((0..n).map(|i| p.lo[i] / self.scale[i]));
        self.hi.clear();
        self.hi.extend((0..n).map(|i| p.hi[i] / self.scale[i]));
    }

    /// Copies the problem scaled by `s_i = 1/√A_ii`: `A' = S A S`, `b' = S b`, `x = S x'`.
    fn load_scaled(&mut self, p: &LcpProblem) {
        let n = p.n;
        self.scale.clear();
        self.scale.extend((0..n).map(|i| {
            if p.a[i * n + i] > 0.0 {
                1.0 / p.a[i * n + i].sqrt()
            } else {
                1.0
            }
        }));
        self.a.clear();
        for (i, row) in p.a[..n * n].chunks_exact(n).enumerate() {
            let scale_i = self.scale[i];
            self.a
                .extend(row.iter().zip(&self.scale).map(|(a, s)| scale_i * a * s));
        }
        self.regularised.clear();
        for i in 0..n {
            let bounded = p.lo[i].is_finite() || p.hi[i].is_finite();
            let added = if bounded || p.friction_index.is_some_and(|f| f[i].is_some()) {
                p.regularisation.max(REGULARISATION)
            } else {
                0.0
            };
            self.a[i * n + i] += added;
            self.regularised.push(added);
        }
        self.load_vectors(p);
    }

    /// Friction rows take their bounds from the current normal impulses (in scaled units).
    /// Friction rows take their bounds from the normal impulses of `x`, or (`damped`) of
    /// the mean of `x` and the round before's (`older`).
    fn update_friction_bounds(&mut self, p: &LcpProblem, damped: bool) {
        let Some(index) = p.friction_index else {
            return;
        };
        let (x, older, scale) = (&self.x, &self.older, &self.scale);
        let impulse = |j: usize| {
            if damped {
                0.5 * (x[j] + older[j]) * scale[j]
            } else {
                x[j] * scale[j]
            }
        };
        for (i, f) in index.iter().enumerate().take(p.n) {
            if let Some(f) = f {
                let bound = f.bound(impulse) / self.scale[i];
                self.lo[i] = -bound;
                self.hi[i] = bound;
            }
        }
    }

    /// Baraff's pivoting on the scaled problem, from x = 0. False if it failed (pivot cap,
    /// unbounded direction, or a non-finite step).
    fn pivot(&mut self, pivots: &mut usize) -> bool {
        let n = self.b.len();
        self.x.clear();
        self.x.resize(n, 0.0);
        self.w.clone_from(&self.b);
        self.set.clear();
        self.set.resize(n, Set::Unprocessed);
        self.clamped.clear();
        self.factor.clear();
        self.factor.resize(n * n, 0.0);
        self.factor_first.clear();
        self.dx.resize(n, 0.0);
        self.dw.resize(n, 0.0);
        // The cap is per call: each friction round pivots afresh.
        let cap = *pivots + 10 * n + 10;
        for d in 0..n {
            if self.lo[d] == self.hi[d] {
                self.x[d] = self.lo[d];
                self.set[d] = Set::Lower;
                continue;
            }
            if self.w[d] == 0.0 {
                if !self.join_clamped(d) {
                    return false;
                }
                continue;
            }
            if self.x[d] == self.lo[d] && self.w[d] > 0.0 {
                self.set[d] = Set::Lower;
                continue;
            }
            if self.x[d] == self.hi[d] && self.w[d] < 0.0 {
                self.set[d] = Set::Upper;
                continue;
            }
            let sigma = if self.w[d] < 0.0 { 1.0 } else { -1.0 };
            loop {
                *pivots += 1;
                if *pivots > cap || !self.direction(d, sigma) {
                    return false;
                }
                match self.max_step(d, sigma) {
                    None => return false,
                    Some((s, event)) => {
                        for i in 0..n {
                            self.x[i] += s * self.dx[i];
                            self.w[i] += s * self.dw[i];
                        }
                        if !self.apply_event(event) {
                            return false;
                        }
                        if matches!(event, Event::DriveDone(_) | Event::DriveBound(_, _)) {
                            break;
                        }
                    }
                }
            }
        }
        true
    }

    /// Δx with Δx_d = σ and Δw_C = 0, and Δw = A·Δx.
    fn direction(&mut self, d: usize, sigma: f64) -> bool {
        let n = self.b.len();
        self.dx.iter_mut().for_each(|v| *v = 0.0);
        self.dx[d] = sigma;
        let m = self.clamped.len();
        self.rhs.clear();
        self.rhs
            .extend(self.clamped.iter().map(|&i| -sigma * self.a[i * n + d]));
        self.solve_factor();
        for k in 0..m {
            self.dx[self.clamped[k]] = self.rhs[k];
        }
        for i in 0..n {
            let row = &self.a[i * n..(i + 1) * n];
            let mut sum = row[d] * sigma;
            for &j in &self.clamped {
                sum += row[j] * self.dx[j];
            }
            self.dw[i] = sum;
        }
        self.dx.iter().all(|v| v.is_finite())
    }

    /// The largest step along (Δx, Δw) before some index changes set.
    fn max_step(&self, d: usize, sigma: f64) -> Option<(f64, Event)> {
        let mut best: Option<(f64, Event)> = None;
        let mut consider = |s: f64, e: Event| {
            let s = s.max(0.0);
            if best.is_none_or(|(b, _)| s < b) {
                best = Some((s, e));
            }
        };
        if sigma * self.dw[d] > 0.0 {
            consider(-self.w[d] / self.dw[d], Event::DriveDone(d));
        }
        let bound = if sigma > 0.0 { self.hi[d] } else { self.lo[d] };
        if bound.is_finite() {
            consider(
                (bound - self.x[d]) * sigma,
                Event::DriveBound(d, sigma > 0.0),
            );
        }
        for &i in &self.clamped {
            if self.dx[i] < 0.0 && self.lo[i].is_finite() {
                consider(
                    (self.lo[i] - self.x[i]) / self.dx[i],
                    Event::Unclamp(i, false),
                );
            } else if self.dx[i] > 0.0 && self.hi[i].is_finite() {
                consider(
                    (self.hi[i] - self.x[i]) / self.dx[i],
                    Event::Unclamp(i, true),
                );
            }
        }
        for i in 0..d {
            let joins = match self.set[i] {
                Set::Lower => self.dw[i] < 0.0,
                Set::Upper => self.dw[i] > 0.0,
                _ => false,
            };
            if joins {
                consider(-self.w[i] / self.dw[i], Event::Clamp(i));
            }
        }
        best.filter(|(s, _)| s.is_finite())
    }

    fn apply_event(&mut self, event: Event) -> bool {
        match event {
            Event::DriveDone(d) | Event::Clamp(d) => {
                self.w[d] = 0.0;
                self.join_clamped(d)
            }
            Event::DriveBound(d, upper) => {
                self.x[d] = if upper { self.hi[d] } else { self.lo[d] };
                self.set[d] = if upper { Set::Upper } else { Set::Lower };
                true
            }
            Event::Unclamp(i, upper) => {
                self.x[i] = if upper { self.hi[i] } else { self.lo[i] };
                self.leave_clamped(i);
                self.set[i] = if upper { Set::Upper } else { Set::Lower };
                true
            }
        }
    }

    /// Appends index `j` to `C`: one new row of the Cholesky factor.
    fn join_clamped(&mut self, j: usize) -> bool {
        let n = self.b.len();
        let m = self.clamped.len();
        // Left of the first clamped index that row j couples to, the new row is zero.
        let first = (0..m)
            .find(|&k| self.a[self.clamped[k] * n + j] != 0.0)
            .unwrap_or(m);
        self.factor[m * n..m * n + first].fill(0.0);
        for k in first..m {
            let mut sum = self.a[self.clamped[k] * n + j];
            for c in first.max(self.factor_first[k])..k {
                sum -= self.factor[m * n + c] * self.factor[k * n + c];
            }
            self.factor[m * n + k] = sum / self.factor[k * n + k];
        }
        let row_norm: f64 = (first..m).map(|c| self.factor[m * n + c].powi(2)).sum();
        // Equality rows (unbounded both ways: pins) are not regularised in `A`, where
        // 1e-12 of compliance would loosen a heavy chain; their factor still is, as a
        // floor for a singular set of them.
        let equality = self.lo[j] == f64::NEG_INFINITY && self.hi[j] == f64::INFINITY;
        let floor = if equality { REGULARISATION } else { 0.0 };
        let pivot = self.a[j * n + j] + floor - row_norm;
        self.factor[m * n + m] = pivot.max(REGULARISATION).sqrt();
        self.factor_first.push(first);
        self.clamped.push(j);
        self.set[j] = Set::Clamped;
        self.factor[m * n + m].is_finite()
    }

    /// Removes index `i` from `C`, restoring the triangular factor by Givens rotations.
    fn leave_clamped(&mut self, i: usize) {
        let n = self.b.len();
        let m = self.clamped.len();
        let Some(k) = self.clamped.iter().position(|&c| c == i) else {
            return;
        };
        for r in k..m - 1 {
            for c in 0..m {
                self.factor[r * n + c] = self.factor[(r + 1) * n + c];
            }
        }
        for c in 0..m {
            self.factor[(m - 1) * n + c] = 0.0;
        }
        self.clamped.remove(k);
        let m = m - 1;
        for j in k..m {
            let (a, b) = (self.factor[j * n + j], self.factor[j * n + j + 1]);
            let r = a.hypot(b);
            if r == 0.0 {
                continue;
            }
            let (c, s) = (a / r, b / r);
            for row in j..m {
                let (p, q) = (self.factor[row * n + j], self.factor[row * n + j + 1]);
                self.factor[row * n + j] = c * p + s * q;
                self.factor[row * n + j + 1] = -s * p + c * q;
            }
        }
        for row in 0..m {
            self.factor[row * n + m] = 0.0;
        }
        for j in 0..m {
            if self.factor[j * n + j] < 0.0 {
                for row in j..m {
                    self.factor[row * n + j] = -self.factor[row * n + j];
                }
            }
        }
        // The rotations mix neighbouring columns: each row's zeros are found afresh.
        self.factor_first.clear();
        for row in 0..m {
            let entries = &self.factor[row * n..row * n + row];
            let first = entries.iter().position(|&v| v != 0.0).unwrap_or(row);
            self.factor_first.push(first);
        }
    }

    /// Solves `A_CC z = rhs` in place with the factor.
    fn solve_factor(&mut self) {
        let n = self.b.len();
        let m = self.clamped.len();
        for r in 0..m {
            let mut sum = self.rhs[r];
            for c in self.factor_first[r]..r {
                sum -= self.factor[r * n + c] * self.rhs[c];
            }
            self.rhs[r] = sum / self.factor[r * n + r];
        }
        for r in (0..m).rev() {
            let mut sum = self.rhs[r];
            for c in r + 1..m {
                if self.factor_first[c] <= r {
                    sum -= self.factor[c * n + r] * self.rhs[c];
                }
            }
            self.rhs[r] = sum / self.factor[r * n + r];
        }
    }

    /// Projected Gauss–Seidel on the scaled problem, from the current `x`.
    fn gauss_seidel(&mut self, p: &LcpProblem) {
        let n = self.b.len();
        for _ in 0..PGS_SWEEPS {
            let mut change: f64 = 0.0;
            for i in 0..n {
                if let Some(Some(f)) = p.friction_index.map(|f| f[i]) {
                    let bound = f.bound(|j| self.x[j] * self.scale[j]) / self.scale[i];
                    self.lo[i] = -bound;
                    self.hi[i] = bound;
                }
                let row = &self.a[i * n..(i + 1) * n];
                let w: f64 = row.iter().zip(&self.x).map(|(a, x)| a * x).sum::<f64>() + self.b[i];
                let diagonal = row[i].max(REGULARISATION);
                let new = clamp(self.x[i] - w / diagonal, self.lo[i], self.hi[i]);
                change = change.max((new - self.x[i]).abs());
                self.x[i] = new;
            }
            let size = self.x.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if change <= PGS_TOLERANCE * size {
                break;
            }
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Event {
    /// The driven index reached w = 0.
    DriveDone(usize),
    /// The driven index reached a bound (true: upper).
    DriveBound(usize, bool),
    /// A clamped index reached a bound and leaves C.
    Unclamp(usize, bool),
    /// An index at a bound reached w = 0 and joins C.
    Clamp(usize),
}

/// The largest violation of `lo ≤ x ≤ hi` and of complementarity, relative to
/// `max|b| + max|A|·max|x|` (the size of the terms that make up `w`).
pub(crate) fn complementarity_residual(p: &LcpProblem, x: &[f64]) -> f64 {
    let n = p.n;
    let amax = p.a[..n * n].iter().map(|v| v.abs()).fold(0.0, f64::max);
    let xmax = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let bmax = p.b[..n].iter().map(|v| v.abs()).fold(0.0, f64::max);
    let scale = (bmax + amax * xmax).max(1e-300);
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let w: f64 = (0..n).map(|j| p.a[i * n + j] * x[j]).sum::<f64>() + p.b[i];
        let (lo, hi) = match p.friction_index.and_then(|f| f[i]) {
            Some(f) => (-f.bound(|j| x[j]), f.bound(|j| x[j])),
            None => (p.lo[i], p.hi[i]),
        };
        let tol = 1e-12 * scale;
        let bounds = (lo - x[i]).max(x[i] - hi).max(0.0) / scale;
        // Complementarity: at lo w ≥ 0, at hi w ≤ 0, inside w = 0.
        let at_lo = (x[i] - lo).abs() <= tol + 1e-12 * lo.abs();
        let at_hi = (hi - x[i]).abs() <= tol + 1e-12 * hi.abs();
        let violation = if at_lo && at_hi {
            0.0
        } else if at_lo {
            (-w).max(0.0)
        } else if at_hi {
            w.max(0.0)
        } else {
            w.abs()
        };
        worst = worst.max(bounds).max(violation / scale);
    }
    worst
}

#[cfg(test)]
mod tests;
