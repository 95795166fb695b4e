//! Bounded, even thinning of a log's per-message series.

/// Keeps items at indices that are multiples of `stride`; when more than `cap` are kept, the
/// stride doubles and every other one is dropped. Memory stays bounded by `cap`.
pub(super) struct Decimator<T> {
    items: Vec<(u64, T)>,
    stride: u64,
    cap: usize,
}

impl<T> Decimator<T> {
    pub(super) fn new(stride: u64, cap: usize) -> Self {
        Self {
            items: Vec::new(),
            stride: stride.max(1),
            cap: cap.max(1),
        }
    }
    /// The current stride: every `stride`-th index is kept.
    pub(super) fn stride(&self) -> u64 {
        self.stride
    }
    pub(super) fn wants(&self, index: u64) -> bool {
        index.is_multiple_of(self.stride)
    }
    pub(super) fn push(&mut self, index: u64, item: T) {
        if !self.wants(index) {
            return;
        }
        self.items.push((index, item));
        while self.items.len() > self.cap {
            self.stride *= 2;
            let stride = self.stride;
            self.items.retain(|(i, _)| i.is_multiple_of(stride));
        }
    }
    pub(super) fn into_items(self) -> Vec<T> {
        self.items.into_iter().map(|(_, t)| t).collect()
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
        let kept = d.into_items();
        assert!(kept.len() <= 200 && kept.len() > 100, "{}", kept.len());
        let stride = kept[1] - kept[0];
        assert!(kept.windows(2).all(|w| w[1] - w[0] == stride));
        assert_eq!(kept[0], 0);
    }
}
