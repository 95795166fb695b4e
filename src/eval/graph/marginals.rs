//! Marginal covariances by selected inversion of the sparse factor: the entries of
//! Σ = H⁻¹ on the pattern of the Cholesky factor L, and nothing else (Takahashi, Fagan &
//! Chen 1973; Erisman & Tinney 1975; g2o's `MarginalCovarianceCholesky` does the same one
//! entry at a time), here one supernode at a time on dense blocks (as in Amestoy et al.,
//! "On computing inverse entries of a sparse matrix in an out-of-core environment", SIAM J.
//! Sci. Comput. 2012, and Lin et al.'s SelInv, ACM TOMS 2011).
//!
//! With H = L Lᵀ (in the factor's permuted order), Lᵀ Σ = L⁻¹ is upper triangular with
//! diagonal block L_ss⁻¹. Take a supernode s (columns S, the rows R below them) and
//! L̂ = L_RS L_SS⁻¹. Block row S of Lᵀ Σ = L⁻¹ gives, from the last supernode to the first,
//!
//! - Σ_RS = −Σ_RR L̂,
//! - Σ_SS = L_SS⁻ᵀ L_SS⁻¹ − L̂ᵀ Σ_RS.
//!
//! R is a clique of the filled graph, so every entry of Σ_RR lies in the pattern of L in
//! later supernodes: Σ is computed exactly on that pattern, which holds every pose's
//! diagonal block and the block of every edge's two poses. Each step is a gather of Σ_RR
//! (|R|² entries, all in L's pattern), a triangular solve and two dense products (faer's
//! kernels): the cost is of the order of the factorisation's, and the memory is Σ in L's
//! layout plus one |R| × |R| block (≤ 2 nnz(L)), never a dense n×n. Any other pair of poses is
//! answered by two block solves with the factor ([`joint_by_solves`]).

use std::ops::Range;

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, MatMut, MatRef, Par};
use nalgebra::SMatrix;

use super::sparse::{BlockSystem, Factor, Supernode};

/// Σ = H⁻¹ on the pattern of L (same storage layout as L).
pub struct SelectedInverse<'a> {
    factor: Factor<'a>,
    sigma: Vec<f64>,
}

/// Computes Σ on L's pattern (see the [module docs](self)). `None` if a lookup falls outside
/// the pattern (it cannot for a Cholesky factor; checked rather than assumed).
pub fn selected_inverse<const N: usize>(system: &BlockSystem<N>) -> Option<SelectedInverse<'_>> {
    let factor = system.factor();
    let mut sigma = vec![0.0; factor.len()];
    let mut sigma_rr = Vec::new();
    let mut l_hat = Vec::new();
    let mut l_ss_inverse = Vec::new();
    for s in (0..factor.supernodes()).rev() {
        let Supernode {
            columns,
            pattern,
            at,
        } = factor.supernode(s);
        let (w, r) = (columns.len(), pattern.len());
        let rows = w + r;
        gather(&factor, &sigma, pattern, &mut sigma_rr)?;
        let sigma_rr = MatRef::from_column_major_slice(&sigma_rr, r, r);
        let l = MatRef::from_column_major_slice(&factor.values()[at..at + rows * w], rows, w);
        let (l_ss, l_rs) = l.split_at_row(w);
        // L̂ = L_RS L_SS⁻¹, i.e. L_SSᵀ L̂ᵀ = L_RSᵀ.
        l_hat.clear();
        l_hat.resize(r * w, 0.0);
        let mut l_hat_mut = MatMut::from_column_major_slice_mut(&mut l_hat, r, w);
        l_hat_mut.copy_from(l_rs);
        solve_upper_triangular_in_place(l_ss.transpose(), l_hat_mut.transpose_mut(), Par::Seq);
        let l_hat = MatRef::from_column_major_slice(&l_hat, r, w);
        // L_SS⁻¹ (lower triangular, w × w).
        l_ss_inverse.clear();
        l_ss_inverse.resize(w * w, 0.0);
        (0..w).for_each(|k| l_ss_inverse[k * w + k] = 1.0);
        let inverse = MatMut::from_column_major_slice_mut(&mut l_ss_inverse, w, w);
        solve_lower_triangular_in_place(l_ss, inverse, Par::Seq);
        let inverse = MatRef::from_column_major_slice(&l_ss_inverse, w, w);
        let out = MatMut::from_column_major_slice_mut(&mut sigma[at..at + rows * w], rows, w);
        let (mut sigma_ss, mut sigma_rs) = out.split_at_row_mut(w);
        matmul(
            sigma_rs.as_mut(),
            Accum::Replace,
            sigma_rr,
            l_hat,
            -1.0,
            Par::Seq,
        );
        matmul(
            sigma_ss.as_mut(),
            Accum::Replace,
            inverse.transpose(),
            inverse,
            1.0,
            Par::Seq,
        );
        matmul(
            sigma_ss.as_mut(),
            Accum::Add,
            l_hat.transpose(),
            sigma_rs.as_ref(),
            -1.0,
            Par::Seq,
        );
    }
    Some(SelectedInverse { factor, sigma })
}

/// Σ_RR as a dense |R| × |R| column-major matrix, from the entries of Σ already computed
/// (rows R all lie after the supernode being inverted). The rows of R that fall in one later
/// supernode t are found in t's row list by one merge, and serve every column of R in t.
/// `None` if an entry is outside L's pattern.
fn gather(factor: &Factor<'_>, sigma: &[f64], rows: &[usize], out: &mut Vec<f64>) -> Option<()> {
    let r = rows.len();
    out.clear();
    out.resize(r * r, 0.0);
    let mut positions = Vec::with_capacity(r);
    let mut b = 0;
    while b < r {
        let Supernode {
            columns,
            pattern,
            at,
        } = factor.supernode(factor.supernode_of(rows[b]));
        let leading = columns.len() + pattern.len();
        // Position of each row R[a], a ≥ b, in t's row list (its columns, then its pattern).
        positions.clear();
        let mut k = 0;
        for &row in &rows[b..] {
            if row < columns.end {
                positions.push(row - columns.start);
            } else {
                while k < pattern.len() && pattern[k] < row {
                    k += 1;
                }
                if pattern.get(k) != Some(&row) {
                    return None;
                }
                positions.push(columns.len() + k);
            }
        }
        let group_end = b + rows[b..].partition_point(|&row| row < columns.end);
        for c in b..group_end {
            let column = at + (rows[c] - columns.start) * leading;
            for a in c..r {
                let v = sigma[column + positions[a - b]];
                out[a + c * r] = v;
                out[c + a * r] = v;
            }
        }
        b = group_end;
    }
    Some(())
}

impl SelectedInverse<'_> {
    /// Σ[a, b] for scalar unknowns a, b in the original order, if in L's pattern.
    pub fn entry(&self, a: usize, b: usize) -> Option<f64> {
        self.entry_in_factor_order(self.factor.inverse[a], self.factor.inverse[b])
    }

    /// The N×N block Σ[block a, block b] (original block numbers), if in L's pattern: always
    /// for a = b and for two blocks an edge joins. A block's N unknowns are consecutive in the
    /// factor's order ([`BlockSystem`]'s block ordering), so each of its columns is one run of
    /// Σ's storage, found once ([`Factor::run`]); entry by entry where it is not.
    pub fn block<const N: usize>(&self, a: usize, b: usize) -> Option<SMatrix<f64, N, N>> {
        let (i, j) = (self.factor.inverse[a * N], self.factor.inverse[b * N]);
        let mut out = SMatrix::<f64, N, N>::zeros();
        let mut column = [0.0; N];
        if i == j {
            for q in 0..N {
                self.column_into(i, j + q, q..N, &mut column)?;
                for p in q..N {
                    out[(p, q)] = column[p];
                    out[(q, p)] = column[p];
                }
            }
        } else if i > j {
            for q in 0..N {
                self.column_into(i, j + q, 0..N, &mut column)?;
                out.column_mut(q).copy_from_slice(&column);
            }
        } else {
            // Σ[a, b] = Σ[b, a]ᵀ, stored with b's rows under a's columns.
            for p in 0..N {
                self.column_into(j, i + p, 0..N, &mut column)?;
                for q in 0..N {
                    out[(p, q)] = column[q];
                }
            }
        }
        Some(out)
    }

    /// Σ[i + p, j] for p in `rows` into `out[p]` (unknowns in the factor's order, i + p ≥ j):
    /// one run of the storage when the rows are stored as one, else entry by entry.
    fn column_into(&self, i: usize, j: usize, rows: Range<usize>, out: &mut [f64]) -> Option<()> {
        match self.factor.run(i + rows.start, j, rows.len()) {
            Some(at) => {
                for p in rows.clone() {
                    out[p] = self.sigma[at + p - rows.start];
                }
            }
            None => {
                for p in rows {
                    out[p] = self.entry_in_factor_order(i + p, j)?;
                }
            }
        }
        Some(())
    }

    /// Σ[i, j] for unknowns i, j in the factor's order, if in L's pattern.
    fn entry_in_factor_order(&self, i: usize, j: usize) -> Option<f64> {
        let (i, j) = (i.max(j), i.min(j));
        self.factor.offset(i, j).map(|at| self.sigma[at])
    }
}

/// Σ[block a, block b] for any two blocks, by solving H X = E_b (N columns of the identity)
/// with the factor: O(nnz(L)) per column, no dense n×n.
pub fn joint_by_solves<const N: usize>(
    system: &BlockSystem<N>,
    a: usize,
    b: usize,
) -> SMatrix<f64, N, N> {
    let n = system.unknowns();
    let mut rhs = vec![0.0; n * N];
    for q in 0..N {
        rhs[q * n + b * N + q] = 1.0;
    }
    system.solve_in_place(&mut rhs, N);
    SMatrix::<f64, N, N>::from_fn(|p, q| rhs[q * n + a * N + p])
}
