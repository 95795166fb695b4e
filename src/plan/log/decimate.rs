//! Bounded, even thinning of a log's per-message series: the drawn messages and series the
//! reader keeps (`input::log`), and the NEES series kept at the same messages (`eval::log::nees`).
//!
//! # In the plan
//!
//! `plan/log/decimate.rs` (the one bounded, even thinning: drawn messages, series and the NEES
//! series at the same messages).

/// Keeps items at indices that are multiples of `stride`; when more than `cap` are kept, the
/// stride doubles and every other one is dropped. Memory stays bounded by `cap`: once full it
/// holds one allocation of `cap + 1` items, the same after any length.
///
/// ```
/// use posecov::plan::log::Decimator;
/// let mut d = Decimator::new(1, 4);
/// for i in 0..10u64 {
///     if d.wants(i) {
///         d.push(i, i * 10);
///     }
/// }
/// assert_eq!(d.stride(), 4);
/// assert_eq!(d.into_items(), [0, 40, 80]);
/// ```
#[derive(Debug, Clone)]
pub struct Decimator<T> {
    items: Vec<(u64, T)>,
    stride: u64,
    cap: usize,
}

impl<T> Decimator<T> {
    /// Keeps every `stride`-th index, at most `cap` items (see the type's example).
    pub fn new(stride: u64, cap: usize) -> Self {
        Self {
            items: Vec::new(),
            stride: stride.max(1),
            cap: cap.max(1),
        }
    }
    /// The current stride: every `stride`-th index is kept.
    pub fn stride(&self) -> u64 {
        self.stride
    }
    /// Whether item `index` would be kept now.
    pub fn wants(&self, index: u64) -> bool {
        index.is_multiple_of(self.stride)
    }
    /// Keeps item `index` if [`wants`](Self::wants) it (indices in increasing order).
    pub fn push(&mut self, index: u64, item: T) {
        if !self.wants(index) {
            return;
        }
        if self.items.len() == self.items.capacity() {
            // Grown by doubling, but to `cap + 1` at most: a decimator that was ever full
            // holds one allocation of its bound, whatever the length after (flat memory).
            let wanted = (2 * self.items.len()).clamp(4, self.cap + 1);
            self.items
                .reserve_exact(wanted.saturating_sub(self.items.len()).max(1));
        }
        self.items.push((index, item));
        while self.items.len() > self.cap {
            self.stride *= 2;
            let stride = self.stride;
            self.items.retain(|(i, _)| i.is_multiple_of(stride));
        }
    }
    /// The kept items, in the order pushed.
    pub fn into_items(self) -> Vec<T> {
        self.items.into_iter().map(|(_, t)| t).collect()
    }

    /// `items` thinned as a decimator of `cap` keeps them: every stride-th from the first,
    /// the stride doubled until at most `cap` are left.
    ///
    /// ```
    /// use posecov::plan::log::Decimator;
    /// assert_eq!(Decimator::thinned((0..10).collect(), 4), [0, 4, 8]);
    /// assert_eq!(Decimator::thinned(vec![1, 2], 4), [1, 2]);
    /// ```
    pub fn thinned(items: Vec<T>, cap: usize) -> Vec<T> {
        if items.len() <= cap {
            return items;
        }
        let mut d = Self::new(1, cap);
        for (i, item) in (0u64..).zip(items) {
            d.push(i, item);
        }
        d.into_items()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_is_bounded_and_even() {
        let mut d = Decimator::new(1, 200);
        for i in 0..100_000u64 {
            d.push(i, i);
        }
        // Full once, its allocation is its bound: the same after a short and a long run.
        assert_eq!(d.items.capacity(), 201);
        let kept = d.into_items();
        assert!(kept.len() <= 200 && kept.len() > 100, "{}", kept.len());
        let stride = kept[1] - kept[0];
        assert!(kept.windows(2).all(|w| w[1] - w[0] == stride));
        assert_eq!(kept[0], 0);
    }
}
