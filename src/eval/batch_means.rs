//! The standard error of a Monte Carlo mean by batch means: the sample, in index order, is cut
//! into [`BATCHES`] consecutive batches of (nearly) equal size; the mean of f(X) over each
//! batch is one draw of a quantity whose spread shrinks as 1/√(batch size), so the standard
//! error of the mean over all n samples is
//!
//! SE = √( Σ_b (m_b − m̄)² / (B (B − 1)) ), m_b the batch means, m̄ their average, B = [`BATCHES`]
//!
//! (Flegal & Jones 2010, "Batch means and spectral variance estimators in Markov chain Monte
//! Carlo", Ann. Statist. 38(2), eq. 6; for independent samples it agrees with σ/√n and,
//! unlike σ/√n, needs no fourth moment of f). Sample i belongs to batch ⌊i B / n⌋, so a sample
//! simulated block by block (blocked Monte Carlo) falls into the same batches as a whole one.
//! Entry by entry for a matrix-valued f (the uncentred covariance ξξᵀ, a position).

use std::ops::Range;

use nalgebra::SMatrix;

/// The number of batches B.
pub const BATCHES: usize = 20;

/// Per batch, the sum of f(X) over its samples, for a sample of `total` samples.
#[derive(Clone, Debug)]
pub(super) struct BatchSums<const R: usize, const C: usize> {
    total: usize,
    sums: Vec<SMatrix<f64, R, C>>,
    counts: Vec<usize>,
}

impl<const R: usize, const C: usize> BatchSums<R, C> {
    /// Empty sums for a sample of `total` samples.
    pub(super) fn new(total: usize) -> Self {
        Self {
            total,
            sums: vec![SMatrix::zeros(); BATCHES],
            counts: vec![0; BATCHES],
        }
    }

    /// Adds the samples `offset .. offset + len` of the whole sample: `sum(range)` gives the
    /// sum of f over the samples of `range`, counted from `offset` (the block's own indices).
    pub(super) fn add(
        &mut self,
        offset: usize,
        len: usize,
        sum: impl Fn(Range<usize>) -> SMatrix<f64, R, C>,
    ) {
        for (batch, range) in batch_ranges(offset, len, self.total) {
            self.counts[batch] += range.len();
            self.sums[batch] += sum(range.start - offset..range.end - offset);
        }
    }

    /// The mean of f over every sample added, and its batch-means standard error (`None` with
    /// fewer than two samples per batch).
    pub(super) fn mean_and_stderr(&self) -> (SMatrix<f64, R, C>, Option<SMatrix<f64, R, C>>) {
        let n: usize = self.counts.iter().sum();
        let total: SMatrix<f64, R, C> = self.sums.iter().sum();
        let mean = total / n.max(1) as f64;
        if self.counts.iter().any(|&c| c < 2) {
            return (mean, None);
        }
        let batch_means: Vec<SMatrix<f64, R, C>> = self
            .sums
            .iter()
            .zip(&self.counts)
            .map(|(s, &c)| s / c as f64)
            .collect();
        let average: SMatrix<f64, R, C> =
            batch_means.iter().sum::<SMatrix<f64, R, C>>() / BATCHES as f64;
        let squares: SMatrix<f64, R, C> = batch_means
            .iter()
            .map(|m| (m - average).component_mul(&(m - average)))
            .sum();
        let b = BATCHES as f64;
        (mean, Some((squares / (b * (b - 1.0))).map(f64::sqrt)))
    }
}

/// The batches that the samples `offset .. offset + len` of a sample of `total` fall into, with
/// the part of each (whole-sample indices): batch b holds ⌈b n / B⌉ .. ⌈(b + 1) n / B⌉.
fn batch_ranges(offset: usize, len: usize, total: usize) -> Vec<(usize, Range<usize>)> {
    let end = (offset + len).min(total);
    let start_of = |b: usize| (b * total).div_ceil(BATCHES);
    (0..BATCHES)
        .filter_map(|b| {
            let range = start_of(b).max(offset)..start_of(b + 1).min(end);
            (!range.is_empty()).then_some((b, range))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector1;

    #[test]
    fn batches_cover_the_sample_once_whole_or_in_blocks() {
        let whole = batch_ranges(0, 1003, 1003);
        assert_eq!(whole.len(), BATCHES);
        assert_eq!(whole.iter().map(|(_, r)| r.len()).sum::<usize>(), 1003);
        let mut blocked = Vec::new();
        for start in (0..1003).step_by(256) {
            blocked.extend(batch_ranges(start, 256.min(1003 - start), 1003));
        }
        let per_batch = |parts: &[(usize, Range<usize>)]| {
            let mut n = [0; BATCHES];
            for (b, r) in parts {
                n[*b] += r.len();
            }
            n
        };
        assert_eq!(per_batch(&whole), per_batch(&blocked));
    }

    #[test]
    fn stderr_of_independent_draws_is_sigma_over_root_n() {
        // f = ±1 alternating inside every batch: every batch mean is 0 (SE 0) …
        let values: Vec<f64> = (0..2000)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let mut sums = BatchSums::<1, 1>::new(values.len());
        sums.add(0, values.len(), |r| Vector1::new(values[r].iter().sum()));
        let (mean, se) = sums.mean_and_stderr();
        assert_eq!(mean[0], 0.0);
        assert!(se.unwrap()[0] < 1e-12);
        // … and a pseudo-random ±1 sequence gives ≈ 1/√n.
        let mut state = 12345u64;
        let values: Vec<f64> = (0..20000)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                if state >> 63 == 0 { 1.0 } else { -1.0 }
            })
            .collect();
        let mut sums = BatchSums::<1, 1>::new(values.len());
        sums.add(0, values.len(), |r| Vector1::new(values[r].iter().sum()));
        let se = sums.mean_and_stderr().1.unwrap()[0];
        let expected = 1.0 / (values.len() as f64).sqrt();
        assert!((se / expected - 1.0).abs() < 0.5, "{se} vs {expected}");
    }

    #[test]
    fn too_few_samples_have_no_stderr() {
        let mut sums = BatchSums::<1, 1>::new(30);
        sums.add(0, 30, |r| Vector1::new(r.len() as f64));
        assert!(sums.mean_and_stderr().1.is_none());
    }
}
