//! The graph's normal equations H δ = −g as a block-sparse symmetric matrix, its sparse
//! Cholesky factor H = P ᵀ L Lᵀ P from faer (supernodal, with an approximate-minimum-degree
//! ordering of the pose blocks), and the solves. No dense matrix of the problem's size is
//! ever formed: H holds one N×N block per pose and per edge, L what the ordering fills in.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use nalgebra::SMatrix;

/// Largest number of non-zeros of the Cholesky factor L a solve takes on (≈ 0.5 GB of
/// values; the marginals need as much again): larger graphs are refused before any numeric
/// work, with the size.
pub const MAX_FACTOR_NONZEROS: usize = 60_000_000;

/// Why the linear algebra stopped.
#[derive(Debug, Clone, PartialEq)]
pub enum SparseError {
    /// The factor would be larger than [`MAX_FACTOR_NONZEROS`].
    TooLarge {
        /// Scalar unknowns.
        unknowns: usize,
        /// Non-zeros of L.
        factor_nonzeros: usize,
    },
    /// H is not positive definite (a direction no measurement constrains).
    NotPositiveDefinite,
    /// faer refused (out of memory, index overflow).
    Faer(String),
}

impl std::fmt::Display for SparseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::TooLarge {
                unknowns,
                factor_nonzeros,
            } => write!(
                f,
                "the sparse Cholesky factor of this graph has {factor_nonzeros} non-zeros ({unknowns} unknowns); posecov solves graphs up to {MAX_FACTOR_NONZEROS} (≈ {} MB of factor)",
                MAX_FACTOR_NONZEROS * 8 / 1_000_000
            ),
            Self::NotPositiveDefinite => write!(
                f,
                "the information matrix is not positive definite: some direction is constrained by no measurement"
            ),
            Self::Faer(e) => write!(f, "sparse Cholesky failed: {e}"),
        }
    }
}

impl std::error::Error for SparseError {}

/// The block pattern of H (upper triangle, by block column) and where each block's entries
/// live in the scalar CSC arrays.
pub struct BlockSystem<const N: usize> {
    blocks: usize,
    /// For block column c: the block rows b ≤ c that are non-zero, ascending (ends with c).
    upper: Vec<Vec<usize>>,
    /// Scalar CSC of the upper triangle.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values of H (same layout as `row_idx`).
    pub values: Vec<f64>,
    /// Offset of scalar column (c·N + q)'s first entry, per block column c (q = 0).
    symbolic: SymbolicCholesky<usize>,
    factor: Vec<f64>,
}

impl<const N: usize> BlockSystem<N> {
    /// The pattern of H for `blocks` pose blocks joined by `pairs` (block a, block b), the
    /// ordering and the symbolic factorisation; refused beyond [`MAX_FACTOR_NONZEROS`].
    pub fn new(blocks: usize, pairs: &[(usize, usize)]) -> Result<Self, SparseError> {
        let mut upper: Vec<Vec<usize>> = (0..blocks).map(|c| vec![c]).collect();
        for &(a, b) in pairs {
            if a != b {
                upper[a.max(b)].push(a.min(b));
            }
        }
        for list in &mut upper {
            list.sort_unstable();
            list.dedup();
        }
        let mut col_ptr = Vec::with_capacity(blocks * N + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (c, list) in upper.iter().enumerate() {
            for q in 0..N {
                for &b in list {
                    let rows = if b == c { q + 1 } else { N };
                    row_idx.extend((0..rows).map(|p| b * N + p));
                }
                col_ptr.push(row_idx.len());
            }
        }
        let values = vec![0.0; row_idx.len()];
        let ordering = block_ordering::<N>(blocks, &upper)?;
        let n = blocks * N;
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let (fwd, inv) = &ordering;
        let perm = PermRef::new_checked(fwd, inv, n);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(|e| SparseError::Faer(format!("{e:?}")))?;
        if symbolic.len_val() > MAX_FACTOR_NONZEROS {
            return Err(SparseError::TooLarge {
                unknowns: n,
                factor_nonzeros: symbolic.len_val(),
            });
        }
        Ok(Self {
            blocks,
            upper,
            col_ptr,
            row_idx,
            values,
            symbolic,
            factor: Vec::new(),
        })
    }

    /// Scalar unknowns.
    pub fn unknowns(&self) -> usize {
        self.blocks * N
    }

    /// Non-zeros of H's upper triangle.
    pub fn nonzeros(&self) -> usize {
        self.row_idx.len()
    }

    /// Non-zeros of the factor L.
    pub fn factor_nonzeros(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Sets every entry of H to zero.
    pub fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }

    /// H[b, c] += block (b ≤ c: the block as given; b > c: its transpose into H[c, b]).
    pub fn add(&mut self, b: usize, c: usize, block: &SMatrix<f64, N, N>) {
        let (row_block, col_block, transposed) = if b <= c { (b, c, false) } else { (c, b, true) };
        let list = &self.upper[col_block];
        let Ok(k) = list.binary_search(&row_block) else {
            return;
        };
        let base = self.col_ptr[col_block * N];
        let width = (list.len() - 1) * N;
        for q in 0..N {
            // Column c·N + q starts after the q earlier columns of this block column.
            let start = base + q * width + q * (q + 1) / 2;
            let rows = if row_block == col_block { q + 1 } else { N };
            for p in 0..rows {
                let v = if transposed {
                    block[(q, p)]
                } else {
                    block[(p, q)]
                };
                self.values[start + k * N + p] += v;
            }
        }
    }

    /// Adds λ to every diagonal entry (Levenberg–Marquardt damping).
    pub fn add_to_diagonal(&mut self, lambda: f64) {
        for col in 0..self.unknowns() {
            // The diagonal entry is the last of its column.
            let end = self.col_ptr[col + 1];
            self.values[end - 1] += lambda;
        }
    }

    /// Factors H = Pᵀ L Lᵀ P (numeric; the symbolic part is reused).
    pub fn factorize(&mut self) -> Result<(), SparseError> {
        let n = self.unknowns();
        self.factor.clear();
        self.factor.resize(self.symbolic.len_val(), 0.0);
        let pattern =
            SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let matrix = SparseColMatRef::new(pattern, &self.values);
        let mut memory = MemBuffer::try_new(
            self.symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        )
        .map_err(|_| SparseError::Faer("out of memory".to_owned()))?;
        self.symbolic
            .factorize_numeric_llt(
                &mut self.factor,
                matrix,
                Side::Upper,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut memory),
                Default::default(),
            )
            .map(|_| ())
            // The only numeric failure is a non-positive pivot.
            .map_err(|_| SparseError::NotPositiveDefinite)
    }

    /// Solves H x = rhs in place (after [`factorize`](Self::factorize)); `rhs` is n × k,
    /// column-major.
    pub fn solve_in_place(&self, rhs: &mut [f64], columns: usize) {
        let n = self.unknowns();
        let llt = LltRef::new(&self.symbolic, &self.factor);
        let mut memory = MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(columns, Par::Seq),
        );
        let x = MatMut::from_column_major_slice_mut(rhs, n, columns);
        llt.solve_in_place_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut memory));
    }

    /// The factor, column by column, in the permuted order (for selected inversion).
    pub fn factor(&self) -> Factor<'_> {
        let (fwd, inv) = self
            .symbolic
            .perm()
            .map(|p| p.arrays())
            .expect("a custom ordering is always set");
        let SymbolicCholeskyRaw::Supernodal(s) = self.symbolic.raw() else {
            unreachable!("the supernodal factorisation is forced")
        };
        let supernodes = s.n_supernodes();
        let (begin, end) = (s.supernode_begin(), s.supernode_end());
        let mut supernode_of = vec![0; self.unknowns()];
        for k in 0..supernodes {
            supernode_of[begin[k]..end[k]].fill(k);
        }
        Factor {
            n: self.unknowns(),
            begin,
            end,
            row_idx_ptr: s.col_ptr_for_row_idx(),
            val_ptr: s.col_ptr_for_val(),
            row_idx: s.row_idx(),
            values: &self.factor,
            supernode_of,
            forward: fwd,
            inverse: inv,
        }
    }
}

/// An approximate-minimum-degree ordering of the pose blocks (faer's AMD on the block
/// graph), expanded to the scalar unknowns: a block's N unknowns stay together, so the
/// supernodes follow the poses. Returns (forward, inverse) scalar permutations.
fn block_ordering<const N: usize>(
    blocks: usize,
    upper: &[Vec<usize>],
) -> Result<(Vec<usize>, Vec<usize>), SparseError> {
    let mut col_ptr = Vec::with_capacity(blocks + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    for list in upper {
        row_idx.extend_from_slice(list);
        col_ptr.push(row_idx.len());
    }
    let mut fwd = vec![0usize; blocks];
    let mut inv = vec![0usize; blocks];
    let pattern = SymbolicSparseColMatRef::new_checked(blocks, blocks, &col_ptr, None, &row_idx);
    let mut memory = MemBuffer::try_new(faer::sparse::linalg::amd::order_maybe_unsorted_scratch::<
        usize,
    >(blocks, row_idx.len()))
    .map_err(|_| SparseError::Faer("out of memory".to_owned()))?;
    faer::sparse::linalg::amd::order_maybe_unsorted(
        &mut fwd,
        &mut inv,
        pattern,
        Default::default(),
        MemStack::new(&mut memory),
    )
    .map_err(|e| SparseError::Faer(format!("{e:?}")))?;
    let scalar_fwd: Vec<usize> = fwd
        .iter()
        .flat_map(|&b| (0..N).map(move |p| b * N + p))
        .collect();
    let mut scalar_inv = vec![0; blocks * N];
    for (new, &old) in scalar_fwd.iter().enumerate() {
        scalar_inv[old] = new;
    }
    Ok((scalar_fwd, scalar_inv))
}

/// Read access to a supernodal factor L in the permuted order, supernode by supernode: the
/// columns of a supernode share one row pattern below them and are stored as one dense block.
pub struct Factor<'a> {
    /// Unknowns.
    pub n: usize,
    begin: &'a [usize],
    end: &'a [usize],
    row_idx_ptr: &'a [usize],
    val_ptr: &'a [usize],
    row_idx: &'a [usize],
    values: &'a [f64],
    supernode_of: Vec<usize>,
    /// `forward[new]` = old scalar index.
    pub forward: &'a [usize],
    /// `inverse[old]` = new scalar index.
    pub inverse: &'a [usize],
}

impl Factor<'_> {
    /// Length of the value storage (the same layout serves the selected inverse).
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether L has no entries.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Supernodes of L: runs of consecutive columns that share one row pattern below them.
    pub fn supernodes(&self) -> usize {
        self.begin.len()
    }

    /// The supernode that holds column j.
    pub fn supernode_of(&self, j: usize) -> usize {
        self.supernode_of[j]
    }

    /// Supernode s: its columns, the rows below them and where its values are. L's entries of
    /// these columns are one dense column-major matrix of `columns.len() + pattern.len()` rows
    /// (first the columns' own rows, lower triangle used, then `pattern`).
    pub fn supernode(&self, s: usize) -> Supernode<'_> {
        Supernode {
            columns: self.begin[s]..self.end[s],
            pattern: &self.row_idx[self.row_idx_ptr[s]..self.row_idx_ptr[s + 1]],
            at: self.val_ptr[s],
        }
    }

    /// The value-storage offset of entry (i, j), i ≥ j, if it is in L's pattern.
    pub fn offset(&self, i: usize, j: usize) -> Option<usize> {
        let Supernode {
            columns,
            pattern,
            at,
        } = self.supernode(self.supernode_of[j]);
        let column = at + (j - columns.start) * (columns.len() + pattern.len());
        if i < columns.end {
            (i >= j).then(|| column + (i - columns.start))
        } else {
            pattern
                .binary_search(&i)
                .ok()
                .map(|k| column + columns.len() + k)
        }
    }

    /// L's values (the layout of [`supernode`](Self::supernode)).
    pub fn values(&self) -> &[f64] {
        self.values
    }
}

/// One supernode of a [`Factor`] (see [`Factor::supernode`]).
pub struct Supernode<'a> {
    /// Its columns (consecutive, in the factor's order).
    pub columns: std::ops::Range<usize>,
    /// The rows below its columns, ascending.
    pub pattern: &'a [usize],
    /// Offset of its dense block in the value storage.
    pub at: usize,
}
