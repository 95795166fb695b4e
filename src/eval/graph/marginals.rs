//! Marginal covariances by selected inversion of the sparse factor: the entries of
//! Σ = H⁻¹ on the pattern of the Cholesky factor L, and nothing else (Takahashi, Fagan &
//! Chen 1973; Erisman & Tinney 1975; g2o's `MarginalCovarianceCholesky` does the same).
//!
//! With H = L Lᵀ (in the factor's permuted order), Lᵀ Σ = L⁻¹ is upper triangular with
//! diagonal 1/L_jj, which gives, from the last column to the first,
//!
//! - Σ_ij = −(1/L_jj) Σ_{k > j, k ∈ struct(j)} L_kj Σ_ki  for i > j in struct(j),
//! - Σ_jj = (1/L_jj) (1/L_jj − Σ_{k > j} L_kj Σ_kj),
//!
//! where struct(j) is the pattern of L's column j. Every Σ_ki needed lies in the pattern of
//! L (struct(j) is a clique of the filled graph), so Σ is computed exactly on that pattern,
//! which holds every pose's diagonal block and the block of every edge's two poses. The
//! cost is of the order of the factorisation's. Any other pair of poses is answered by two
//! block solves with the factor ([`joint_by_solves`]).

use nalgebra::SMatrix;

use super::sparse::{BlockSystem, Factor};

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
    let mut rows = Vec::new();
    let mut sums = Vec::new();
    let mut offsets = Vec::new();
    for j in (0..factor.n).rev() {
        let diagonal_at = factor.column(j, &mut rows);
        let d = factor.value(diagonal_at);
        sums.clear();
        sums.resize(rows.len(), 0.0);
        let l = |k: usize| factor.value(diagonal_at + 1 + k);
        for a in 0..rows.len() {
            let i = rows[a];
            // Σ_ii, then Σ_ik for the later rows k of column j (in column i at row k).
            let ii = factor.offset(i, i)?;
            sums[a] += l(a) * sigma[ii];
            offsets.clear();
            for &k in &rows[a + 1..] {
                offsets.push(factor.offset(k, i)?);
            }
            for (b, &at) in (a + 1..rows.len()).zip(&offsets) {
                let s = sigma[at];
                sums[a] += l(b) * s;
                sums[b] += l(a) * s;
            }
        }
        let mut dot = 0.0;
        for (a, s) in sums.iter().enumerate() {
            let sigma_ij = -s / d;
            sigma[diagonal_at + 1 + a] = sigma_ij;
            dot += l(a) * sigma_ij;
        }
        sigma[diagonal_at] = (1.0 / d - dot) / d;
    }
    Some(SelectedInverse { factor, sigma })
}

impl SelectedInverse<'_> {
    /// Σ[a, b] for scalar unknowns a, b in the original order, if in L's pattern.
    pub fn entry(&self, a: usize, b: usize) -> Option<f64> {
        let (i, j) = (self.factor.inverse[a], self.factor.inverse[b]);
        let (i, j) = (i.max(j), i.min(j));
        self.factor.offset(i, j).map(|at| self.sigma[at])
    }

    /// The N×N block Σ[block a, block b] (original block numbers), if in L's pattern: always
    /// for a = b and for two blocks an edge joins.
    pub fn block<const N: usize>(&self, a: usize, b: usize) -> Option<SMatrix<f64, N, N>> {
        let mut out = SMatrix::<f64, N, N>::zeros();
        for p in 0..N {
            for q in 0..N {
                out[(p, q)] = self.entry(a * N + p, b * N + q)?;
            }
        }
        Some(out)
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
