//! The graph's normal equations H δ = −g as a block-sparse symmetric matrix, its sparse
//! Cholesky factor H = P ᵀ L Lᵀ P from faer (supernodal, with an approximate-minimum-degree
//! ordering of the pose blocks), and the solves. No dense matrix of the problem's size is
//! ever formed: H holds one N×N block per pose and per edge, L what the ordering fills in.

use faer::dyn_stack::{MemBuffer, MemStack};
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

/// The block pattern of H and where each block's entries live, in the factor's order: H is
/// stored as its lower triangle, by columns, its pose blocks already placed in an
/// approximate-minimum-degree order, so that faer factors it as given (no permutation of H at
/// each factorisation; the solves permute the right-hand side).
pub struct BlockSystem<const N: usize> {
    blocks: usize,
    /// `position[b]`: where pose block b stands in the factor's order.
    position: Vec<usize>,
    /// For block column c (factor's order): the block rows r ≥ c that are non-zero,
    /// ascending (starts with c).
    lower: Vec<Vec<usize>>,
    /// Scalar CSC of the lower triangle (factor's order; each column's diagonal entry first).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values of H (same layout as `row_idx`).
    pub values: Vec<f64>,
    /// `forward[new]` = original scalar index; `inverse[original]` = new.
    forward: Vec<usize>,
    inverse: Vec<usize>,
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
        let position = block_ordering(blocks, &upper)?;
        let mut lower: Vec<Vec<usize>> = (0..blocks).map(|c| vec![c]).collect();
        for (c, list) in upper.iter().enumerate() {
            for &b in &list[..list.len() - 1] {
                let (nb, nc) = (position[b], position[c]);
                lower[nb.min(nc)].push(nb.max(nc));
            }
        }
        for list in &mut lower {
            list.sort_unstable();
        }
        let mut col_ptr = Vec::with_capacity(blocks * N + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (c, list) in lower.iter().enumerate() {
            for q in 0..N {
                for &r in list {
                    let first = if r == c { q } else { 0 };
                    row_idx.extend((first..N).map(|p| r * N + p));
                }
                col_ptr.push(row_idx.len());
            }
        }
        let values = vec![0.0; row_idx.len()];
        let n = blocks * N;
        let mut forward = vec![0; n];
        let mut inverse = vec![0; n];
        for (b, &nb) in position.iter().enumerate() {
            for p in 0..N {
                forward[nb * N + p] = b * N + p;
                inverse[b * N + p] = nb * N + p;
            }
        }
        // faer's symbolic analysis reads the upper triangle when given no ordering: the same
        // pattern, transposed, for it alone.
        let (upper_col_ptr, upper_row_idx) = transposed_pattern(n, &col_ptr, &row_idx);
        let pattern =
            SymbolicSparseColMatRef::new_checked(n, n, &upper_col_ptr, None, &upper_row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Upper,
            SymmetricOrdering::Identity,
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
            position,
            lower,
            col_ptr,
            row_idx,
            values,
            forward,
            inverse,
            symbolic,
            factor: Vec::new(),
        })
    }

    /// Scalar unknowns.
    pub fn unknowns(&self) -> usize {
        self.blocks * N
    }

    /// Non-zeros of H's lower (equally, upper) triangle.
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

    /// H[b, c] += block (pose blocks b, c in the original numbering). H is symmetric and
    /// stored once: an edge adds its H[i, j] only. A diagonal block is taken from its upper
    /// triangle (blockᵀ's lower one: JᵀΛJ need not be symmetric to the last bit).
    pub fn add(&mut self, b: usize, c: usize, block: &SMatrix<f64, N, N>) {
        let (nb, nc) = (self.position[b], self.position[c]);
        // Stored at (rows of block `row`, columns of block `column`), row ≥ column; the
        // value at (p, q) of that block is block[(p, q)], or block[(q, p)] when transposed.
        let (row, column, transposed) = if nb > nc {
            (nb, nc, false)
        } else {
            (nc, nb, true)
        };
        let list = &self.lower[column];
        let Ok(k) = list.binary_search(&row) else {
            return;
        };
        for q in 0..N {
            let start = self.col_ptr[column * N + q];
            if k == 0 {
                // The diagonal block: rows q … N − 1 of column q.
                for p in q..N {
                    self.values[start + p - q] += block[(q, p)];
                }
                continue;
            }
            // After the diagonal block's N − q rows, N rows for each block before this one.
            let at = start + (N - q) + (k - 1) * N;
            for p in 0..N {
                self.values[at + p] += if transposed {
                    block[(q, p)]
                } else {
                    block[(p, q)]
                };
            }
        }
    }

    /// Adds λ to every diagonal entry (Levenberg–Marquardt damping).
    pub fn add_to_diagonal(&mut self, lambda: f64) {
        for col in 0..self.unknowns() {
            // The diagonal entry is the first of its column.
            let start = self.col_ptr[col];
            self.values[start] += lambda;
        }
    }

    /// Factors H = Pᵀ L Lᵀ P (numeric; the symbolic part is reused).
    pub fn factorize(&mut self) -> Result<(), SparseError> {
        let n = self.unknowns();
        // faer zeroes L's values itself: the buffer only needs its length (kept between
        // factorisations, not written twice).
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
                Side::Lower,
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
    /// column-major, in the original order.
    pub fn solve_in_place(&self, rhs: &mut [f64], columns: usize) {
        let n = self.unknowns();
        let llt = LltRef::new(&self.symbolic, &self.factor);
        let mut memory = MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(columns, Par::Seq),
        );
        // P rhs, solved, then Pᵀ: the copies faer makes itself for an ordering it holds.
        let mut permuted = vec![0.0; n * columns];
        for c in 0..columns {
            for (new, &old) in self.forward.iter().enumerate() {
                permuted[c * n + new] = rhs[c * n + old];
            }
        }
        let x = MatMut::from_column_major_slice_mut(&mut permuted, n, columns);
        llt.solve_in_place_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut memory));
        for c in 0..columns {
            for (new, &old) in self.forward.iter().enumerate() {
                rhs[c * n + old] = permuted[c * n + new];
            }
        }
    }

    /// The factor, column by column, in the permuted order (for selected inversion).
    pub fn factor(&self) -> Factor<'_> {
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
            forward: &self.forward,
            inverse: &self.inverse,
        }
    }
}

/// The scalar CSC pattern (col_ptr, row_idx) of the transpose of the n × n pattern given,
/// rows ascending in each column.
fn transposed_pattern(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut counts = vec![0usize; n + 1];
    for &i in row_idx {
        counts[i + 1] += 1;
    }
    for i in 0..n {
        counts[i + 1] += counts[i];
    }
    let mut next = counts.clone();
    let mut rows = vec![0; row_idx.len()];
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            rows[next[i]] = j;
            next[i] += 1;
        }
    }
    (counts, rows)
}

/// An approximate-minimum-degree ordering of the pose blocks (faer's AMD on the block graph
/// `upper`: for each block, the blocks ≤ it it is joined to): `position[b]`, where block b
/// stands. A block's N unknowns stay together, so the supernodes follow the poses.
fn block_ordering(blocks: usize, upper: &[Vec<usize>]) -> Result<Vec<usize>, SparseError> {
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
    Ok(inv)
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
        self.run(i, j, 1)
    }

    /// The value-storage offset of entry (i, j) when rows i … i + len − 1 of column j (i ≥ j)
    /// are all in L's pattern and stored one after another (then entry (i + p, j) is at the
    /// offset + p); None otherwise (some row outside the pattern, or the run crosses from the
    /// supernode's own rows into the rows below it).
    ///
    /// ```
    /// use posecov::eval::graph::sparse::BlockSystem;
    /// use nalgebra::Matrix3;
    /// // Two SE(2) poses joined by one edge: H = [[2I, −I], [−I, 2I]].
    /// let mut h = BlockSystem::<3>::new(2, &[(0, 1)]).unwrap();
    /// h.add(0, 0, &(Matrix3::identity() * 2.0));
    /// h.add(1, 1, &(Matrix3::identity() * 2.0));
    /// h.add(0, 1, &-Matrix3::identity());
    /// h.factorize().unwrap();
    /// let l = h.factor();
    /// let at = l.run(0, 0, 6).unwrap(); // column 0, rows 0 … 5
    /// assert_eq!((1..6).map(|p| l.run(p, 0, 1)).collect::<Vec<_>>(), (1..6).map(|p| Some(at + p)).collect::<Vec<_>>());
    /// assert_eq!(l.run(0, 1, 1), None); // above the diagonal
    /// ```
    pub fn run(&self, i: usize, j: usize, len: usize) -> Option<usize> {
        let Supernode {
            columns,
            pattern,
            at,
        } = self.supernode(self.supernode_of[j]);
        let column = at + (j - columns.start) * (columns.len() + pattern.len());
        let last = i + len.max(1) - 1;
        if last < columns.end {
            (i >= j).then(|| column + (i - columns.start))
        } else if i >= columns.end {
            // The pattern is ascending without repeats: rows i … last are consecutive in it
            // when the one len − 1 places after i is last.
            let k = pattern.binary_search(&i).ok()?;
            (pattern.get(k + len.max(1) - 1) == Some(&last)).then(|| column + columns.len() + k)
        } else {
            None
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
