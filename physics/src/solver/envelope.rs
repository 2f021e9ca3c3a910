//! Factorizations within a matrix's envelope (its profile): row i of the factor L is
//! nonzero only from the first nonzero of row i of K, so a matrix whose nonzeros hug the
//! diagonal costs O(n · width²) instead of the dense O(n³). An island of pins numbered
//! along its chain has a block-tridiagonal K; any other pattern still factors, at up to
//! the dense cost. Only the envelope is stored. Cholesky for symmetric positive definite
//! K; LU without pivoting for K whose pattern is symmetric and whose values nearly are.

/// The factor L of K = L Lᵀ, row by row within the envelope: row i holds columns
/// `first[i]..=i`, from `l[start[i]]` on.
#[derive(Debug, Clone, Default)]
pub(crate) struct EnvelopeCholesky {
    n: usize,
    first: Vec<usize>,
    start: Vec<usize>,
    l: Vec<f64>,
    /// 1 / L_ii: the substitutions multiply by these rather than divide, since each row's
    /// division waits on the row before.
    inverse_diagonal: Vec<f64>,
}

impl EnvelopeCholesky {
    /// Factors the symmetric `k` (row-major n × n; only its lower triangle is read).
    /// False if a pivot (L_ii²) is not above `min_pivot`: K is not positive definite, or
    /// too near singular to trust.
    pub(crate) fn factor(&mut self, k: &[f64], n: usize, min_pivot: f64) -> bool {
        debug_assert_eq!(k.len(), n * n);
        self.n = n;
        self.first.clear();
        self.first
            .extend((0..n).map(|i| (0..i).find(|&j| k[i * n + j] != 0.0).unwrap_or(i)));
        self.start.clear();
        let mut stored = 0;
        for (i, &first) in self.first.iter().enumerate() {
            self.start.push(stored);
            stored += i + 1 - first;
        }
        self.l.clear();
        self.l.resize(stored, 0.0);
        self.inverse_diagonal.clear();
        self.inverse_diagonal.resize(n, 0.0);
        for i in 0..n {
            let (first_i, start_i) = (self.first[i], self.start[i]);
            for j in first_i..=i {
                // Entries of rows i and j left of both rows' envelopes are zero.
                let (first_j, start_j) = (self.first[j], self.start[j]);
                let from = first_i.max(first_j);
                let row_i = &self.l[start_i + from - first_i..start_i + j - first_i];
                let row_j = &self.l[start_j + from - first_j..start_j + j - first_j];
                let mut sum = k[i * n + j];
                for (a, b) in row_i.iter().zip(row_j) {
                    sum -= a * b;
                }
                let at = start_i + j - first_i;
                if i == j {
                    if sum <= min_pivot || sum.is_nan() {
                        return false;
                    }
                    self.l[at] = sum.sqrt();
                    self.inverse_diagonal[i] = 1.0 / self.l[at];
                } else {
                    self.l[at] = sum * self.inverse_diagonal[j];
                }
            }
        }
        true
    }

    /// Row i of L left of its diagonal, and the column it starts at.
    fn left_of_diagonal(&self, i: usize) -> (&[f64], usize) {
        let (first, start) = (self.first[i], self.start[i]);
        (&self.l[start..start + i - first], first)
    }

    /// Solves K x = b in place with the last successful `factor`.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        debug_assert_eq!(b.len(), n);
        // L y = b, row by row.
        for i in 0..n {
            let (row, first) = self.left_of_diagonal(i);
            let (solved, rest) = b.split_at_mut(i);
            let mut sum = rest[0];
            for (l, y) in row.iter().zip(&solved[first..]) {
                sum -= l * y;
            }
            rest[0] = sum * self.inverse_diagonal[i];
        }
        // Lᵀ x = y, from the last row up: x_i found, its column of Lᵀ (row i of L) is
        // taken out of the rows above.
        for i in (0..n).rev() {
            b[i] *= self.inverse_diagonal[i];
            let x = b[i];
            let (row, first) = self.left_of_diagonal(i);
            for (y, l) in b[first..i].iter_mut().zip(row) {
                *y -= l * x;
            }
        }
    }
}

/// K = L U within the envelope of a matrix whose nonzero pattern is symmetric, without
/// pivoting: L unit lower, row i from column `first[i]`; U upper, column i from row
/// `first[i]`. For the joints' Newton steps, whose K is J M⁻¹ Jᵀ with one side's arms
/// turned a step ahead: nearly symmetric and positive definite, so pivoting is not needed,
/// and a pivot that comes out small says so (`factor` is false; solve densely then).
#[derive(Debug, Clone, Default)]
pub(crate) struct EnvelopeLu {
    n: usize,
    first: Vec<usize>,
    start: Vec<usize>,
    /// Row i of L left of its diagonal, then column i of U down to its diagonal, from
    /// `start[i]`: `i - first[i]` and then `i + 1 - first[i]` values.
    lu: Vec<f64>,
}

impl EnvelopeLu {
    /// Factors `k` (row-major n × n) within the envelope `first`: `first[i]` is at or left
    /// of the first nonzero of row i and of column i (a caller that knows K's pattern says
    /// so, rather than having all n² entries scanned). False if a pivot's magnitude is not
    /// above `min_pivot`.
    pub(crate) fn factor(&mut self, k: &[f64], n: usize, first: &[usize], min_pivot: f64) -> bool {
        debug_assert_eq!(k.len(), n * n);
        debug_assert_eq!(first.len(), n);
        self.n = n;
        self.first.clear();
        self.first.extend_from_slice(first);
        self.start.clear();
        let mut stored = 0;
        for (i, &first) in self.first.iter().enumerate() {
            debug_assert!(first <= i);
            debug_assert!((0..first).all(|j| k[i * n + j] == 0.0 && k[j * n + i] == 0.0));
            self.start.push(stored);
            stored += 2 * (i - first) + 1;
        }
        self.lu.clear();
        self.lu.resize(stored, 0.0);
        let (first, lu) = (&self.first, &mut self.lu);
        // Row r of L at column m is `lu[l_base(r) + m]`, column c of U at row m is
        // `lu[u_base(c) + m]`: the inner sums index by m alone.
        let l_base = |r: usize| self.start[r] - first[r];
        let u_base = |c: usize| self.start[c] + c - 2 * first[c];
        for i in 0..n {
            let first_i = first[i];
            let (l_i, u_i) = (l_base(i), u_base(i));
            // Column i of U above the diagonal, then row i of L, then U_ii.
            for j in first_i..i {
                let (from, l_j) = (first_i.max(first[j]), l_base(j));
                let sum: f64 = (from..j).map(|m| lu[l_j + m] * lu[u_i + m]).sum();
                lu[u_i + j] = k[j * n + i] - sum;
            }
            for j in first_i..i {
                let (from, u_j) = (first_i.max(first[j]), u_base(j));
                let sum: f64 = (from..j).map(|m| lu[l_i + m] * lu[u_j + m]).sum();
                lu[l_i + j] = (k[i * n + j] - sum) / lu[u_j + j];
            }
            let sum: f64 = (first_i..i).map(|m| lu[l_i + m] * lu[u_i + m]).sum();
            let pivot = k[i * n + i] - sum;
            if pivot.abs() <= min_pivot || !pivot.is_finite() {
                return false;
            }
            lu[u_i + i] = pivot;
        }
        true
    }

    /// L_ij, for `first[i] <= j < i`.
    fn l(&self, i: usize, j: usize) -> f64 {
        self.lu[self.start[i] + j - self.first[i]]
    }

    /// U_ji (row j of column i), for `first[i] <= j <= i`.
    fn u(&self, j: usize, i: usize) -> f64 {
        let first = self.first[i];
        self.lu[self.start[i] + (i - first) + (j - first)]
    }

    /// Solves K x = b in place with the last successful `factor`.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        debug_assert_eq!(b.len(), n);
        for i in 0..n {
            let sum: f64 = (self.first[i]..i).map(|m| self.l(i, m) * b[m]).sum();
            b[i] -= sum;
        }
        for i in (0..n).rev() {
            b[i] /= self.u(i, i);
            let (x, first) = (b[i], self.first[i]);
            for (j, y) in b[first..i].iter_mut().enumerate() {
                *y -= self.u(first + j, i) * x;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Each row's first column where row or column i is nonzero: K's envelope, found by
    /// scanning.
    fn envelope_of(k: &[f64], n: usize) -> Vec<usize> {
        (0..n)
            .map(|i| {
                (0..i)
                    .find(|&j| k[i * n + j] != 0.0 || k[j * n + i] != 0.0)
                    .unwrap_or(i)
            })
            .collect()
    }

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// Random symmetric positive definite matrices with banded, arrow-shaped and full
    /// patterns: the solution matches nalgebra's dense Cholesky to round-off.
    #[test]
    fn solves_like_a_dense_cholesky() {
        let mut seed = 7;
        for (n, pattern) in [(1, 0), (6, 0), (20, 1), (20, 2), (30, 3), (40, 1)] {
            // pattern 0 full, 1 band of 3, 2 arrow (last rows full), 3 two blocks
            let in_pattern = |i: usize, j: usize| match pattern {
                0 => true,
                1 => i.abs_diff(j) <= 3,
                2 => i.abs_diff(j) <= 1 || i.max(j) >= n - 2,
                _ => (i < n / 2) == (j < n / 2),
            };
            let mut a = DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                for j in 0..=i {
                    if in_pattern(i, j) {
                        let v = lcg(&mut seed);
                        a[(i, j)] = v;
                        a[(j, i)] = v;
                    }
                }
                a[(i, i)] = n as f64; // diagonally dominant: positive definite
            }
            let k: Vec<f64> = (0..n * n).map(|x| a[(x / n, x % n)]).collect();
            let b = DVector::from_fn(n, |_, _| lcg(&mut seed));
            let mut envelope = EnvelopeCholesky::default();
            assert!(envelope.factor(&k, n, 0.0));
            if pattern == 1 {
                // Only the band is stored: row i from column i − 3 (or 0) to i.
                let band: usize = (0..n).map(|i| i - i.saturating_sub(3) + 1).sum();
                assert_eq!(envelope.l.len(), band, "n {n}");
            }
            let mut x: Vec<f64> = b.iter().copied().collect();
            envelope.solve(&mut x);
            let dense = a.clone().cholesky().unwrap().solve(&b);
            for i in 0..n {
                assert!((x[i] - dense[i]).abs() < 1e-13, "n {n}, pattern {pattern}");
            }
            let residual = &a * DVector::from_vec(x) - &b;
            assert!(residual.amax() < 1e-12, "n {n}, pattern {pattern}");
        }
    }

    #[test]
    fn refuses_a_matrix_that_is_not_positive_definite() {
        // Two pins holding one body to the world at the same point: K = [[1, 1], [1, 1]].
        let mut envelope = EnvelopeCholesky::default();
        assert!(!envelope.factor(&[1.0, 1.0, 1.0, 1.0], 2, 1e-12));
        assert!(!envelope.factor(&[-1.0], 1, 0.0));
        assert!(!envelope.factor(&[f64::NAN], 1, 0.0));
        assert!(envelope.factor(&[4.0, 2.0, 2.0, 3.0], 2, 1e-12));
        let mut x = [2.0, 1.0];
        envelope.solve(&mut x);
        assert!((x[0] - 0.5).abs() < 1e-15 && x[1].abs() < 1e-15);
    }

    /// Random matrices with a symmetric pattern (banded, arrow-shaped, full, two blocks)
    /// and unsymmetric values, diagonally dominant: the envelope LU solves them as
    /// nalgebra's dense LU does, to round-off; a zero pivot is refused.
    #[test]
    fn envelope_lu_solves_like_a_dense_lu() {
        let mut seed = 11;
        for (n, pattern) in [(1, 0), (6, 0), (20, 1), (20, 2), (30, 3), (40, 1)] {
            let in_pattern = |i: usize, j: usize| match pattern {
                0 => true,
                1 => i.abs_diff(j) <= 3,
                2 => i.abs_diff(j) <= 1 || i.max(j) >= n - 2,
                _ => (i < n / 2) == (j < n / 2),
            };
            let mut a = DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                for j in 0..n {
                    if in_pattern(i, j) {
                        a[(i, j)] = lcg(&mut seed);
                    }
                }
                a[(i, i)] = n as f64;
            }
            let k: Vec<f64> = (0..n * n).map(|x| a[(x / n, x % n)]).collect();
            let b = DVector::from_fn(n, |_, _| lcg(&mut seed));
            let mut envelope = EnvelopeLu::default();
            assert!(envelope.factor(&k, n, &envelope_of(&k, n), 0.0));
            let mut x: Vec<f64> = b.iter().copied().collect();
            envelope.solve(&mut x);
            let expected = a.clone().lu().solve(&b).unwrap();
            for (got, want) in x.iter().zip(expected.iter()) {
                assert!(
                    (got - want).abs() < 1e-13,
                    "n {n}, pattern {pattern}: {got} vs {want}"
                );
            }
        }
        let singular = [1.0, 2.0, 2.0, 4.0];
        assert!(!EnvelopeLu::default().factor(&singular, 2, &[0, 0], 1e-12));
    }
}
