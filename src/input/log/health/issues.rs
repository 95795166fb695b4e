//! The issues of one message: a set with one bit per kind of [`Issue`], so nothing can ever be
//! dropped, and four bytes to copy.

use std::fmt;

use crate::plan::log::Issue;

/// The issues of one message, each kind at most once, listed in the order the checks find
/// them ([`Issues::ORDER`]: the orientation, then the covariance's checks in the order
/// [`classify`](super::classify) makes them, then the trend's). Compares equal to a `Vec` or
/// slice of the same issues in that order.
///
/// It is one bit per kind in a `u32`: [`Issues::ORDER`] holds every kind of [`Issue`] once,
/// which a compile-time check proves (a kind's bit is an exhaustive `match`, and the bits are
/// checked to be distinct and below 32), so no message can have an issue it cannot hold.
///
/// ```
/// use posecov::input::log::health::Issues;
/// use posecov::plan::log::Issue;
/// let mut issues = Issues::default();
/// issues.push(Issue::Placeholder);
/// issues.push(Issue::Drop);
/// assert_eq!(issues, vec![Issue::Placeholder, Issue::Drop]);
/// assert!(issues.contains(Issue::Drop) && !issues.is_empty());
/// issues.push(Issue::Placeholder); // the same kind again: held once
/// assert_eq!(issues.len(), 2);
/// ```
#[derive(Clone, Copy, Default, PartialEq, Eq)]
pub struct Issues(u32);

impl Issues {
    /// No issue.
    pub const EMPTY: Issues = Issues(0);

    /// Every kind of issue, in the order a message lists them: the order the checks find them
    /// (the orientation; the covariance: not finite, ROS's −1, all zero, placeholders,
    /// asymmetric, not PSD; the position trace's trend), then the kinds found per topic or
    /// per log (never in a message's list today), in [`Issue::ALL`]'s order.
    pub const ORDER: [Issue; 25] = [
        Issue::BadOrientation,
        Issue::NonFinite,
        Issue::UnknownMarker,
        Issue::AllZero,
        Issue::PlaceholderUsedAxis,
        Issue::Placeholder,
        Issue::Asymmetric,
        Issue::NotPsd,
        Issue::Drop,
        Issue::Growth,
        Issue::Undecodable,
        Issue::Constant,
        Issue::FrozenStamp,
        Issue::TypeChange,
        Issue::TfCycle,
        Issue::TfSeveralParents,
        Issue::StampFallback,
        Issue::StampOrder,
        Issue::TfMissingLink,
        Issue::TfNoTransform,
        Issue::TfTiltsPlane,
        // A NavSatFix's declared covariance type (`input::log::navsat`).
        Issue::CovarianceTypeUnknown,
        Issue::CovarianceApproximated,
        Issue::DiagonalKnownOffDiagonal,
        Issue::NoFix,
    ];

    /// The bit of `issue`: its place in [`Self::ORDER`]. An exhaustive `match`: a new kind of
    /// issue does not compile until it has a bit.
    const fn bit(issue: Issue) -> u32 {
        match issue {
            Issue::BadOrientation => 0,
            Issue::NonFinite => 1,
            Issue::UnknownMarker => 2,
            Issue::AllZero => 3,
            Issue::PlaceholderUsedAxis => 4,
            Issue::Placeholder => 5,
            Issue::Asymmetric => 6,
            Issue::NotPsd => 7,
            Issue::Drop => 8,
            Issue::Growth => 9,
            Issue::Undecodable => 10,
            Issue::Constant => 11,
            Issue::FrozenStamp => 12,
            Issue::TypeChange => 13,
            Issue::TfCycle => 14,
            Issue::TfSeveralParents => 15,
            Issue::StampFallback => 16,
            Issue::StampOrder => 17,
            Issue::TfMissingLink => 18,
            Issue::TfNoTransform => 19,
            Issue::TfTiltsPlane => 20,
            Issue::CovarianceTypeUnknown => 21,
            Issue::CovarianceApproximated => 22,
            Issue::DiagonalKnownOffDiagonal => 23,
            Issue::NoFix => 24,
        }
    }

    /// Adds `issue` (a kind already held stays held once: one finding per message).
    pub fn push(&mut self, issue: Issue) {
        self.0 |= 1 << Self::bit(issue);
    }

    /// Whether `issue` is among them.
    pub fn contains(&self, issue: Issue) -> bool {
        self.0 & (1 << Self::bit(issue)) != 0
    }

    /// The bits of the kinds that make a message unusable ([`Issue::unusable`]).
    const UNUSABLE: u32 = {
        let mut bits = 0;
        let mut k = 0;
        while k < Self::ORDER.len() {
            if Self::ORDER[k].unusable() {
                bits |= 1 << k;
            }
            k += 1;
        }
        bits
    };

    /// Whether one of them makes the message unusable ([`Issue::unusable`]): one test of
    /// the bits.
    pub fn any_unusable(&self) -> bool {
        self.0 & Self::UNUSABLE != 0
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.0 == 0
    }

    /// How many kinds.
    pub fn len(&self) -> usize {
        self.0.count_ones() as usize
    }

    /// The issues with their places in [`Self::ORDER`], in that order.
    pub fn iter_placed(&self) -> impl Iterator<Item = (usize, Issue)> + use<> {
        let mut bits = self.0;
        std::iter::from_fn(move || {
            let b = bits.trailing_zeros() as usize;
            bits &= bits.wrapping_sub(1);
            Self::ORDER.get(b).map(|issue| (b, *issue))
        })
    }

    /// The issues, in [`Self::ORDER`].
    pub fn iter(&self) -> impl Iterator<Item = Issue> + use<> {
        self.iter_placed().map(|(_, issue)| issue)
    }
}

/// Proves at compile time that every kind has its own bit below 32 and is where
/// [`Issues::ORDER`] lists it (so [`Issues::iter`] gives back what was pushed).
const _: () = {
    assert!(Issues::ORDER.len() == Issue::ALL.len() && Issues::ORDER.len() <= 32);
    let mut k = 0;
    while k < Issues::ORDER.len() {
        assert!(Issues::bit(Issues::ORDER[k]) == k as u32);
        k += 1;
    }
};

impl fmt::Debug for Issues {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl Extend<Issue> for Issues {
    fn extend<I: IntoIterator<Item = Issue>>(&mut self, issues: I) {
        for issue in issues {
            self.push(issue);
        }
    }
}

impl PartialEq<[Issue]> for Issues {
    fn eq(&self, other: &[Issue]) -> bool {
        self.iter().eq(other.iter().copied())
    }
}

impl PartialEq<Vec<Issue>> for Issues {
    fn eq(&self, other: &Vec<Issue>) -> bool {
        self == other.as_slice()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_is_held_in_order() {
        // Every kind at once, each pushed twice in the reverse order: all kept, in ORDER.
        let mut issues = Issues::default();
        for issue in Issue::ALL.iter().rev().chain(Issue::ALL.iter()) {
            issues.push(*issue);
        }
        assert_eq!(issues.len(), Issue::ALL.len());
        assert_eq!(issues, Issues::ORDER.to_vec());
        assert!(Issue::ALL.iter().all(|i| issues.contains(*i)));
        // Each kind alone: unusable exactly when `Issue::unusable` says so.
        for issue in Issue::ALL {
            let mut one = Issues::default();
            one.push(issue);
            assert_eq!(one.any_unusable(), issue.unusable(), "{issue:?}");
        }
        // The order a message's checks push them in is the order listed.
        let mut found = Issues::default();
        found.extend([
            Issue::BadOrientation,
            Issue::AllZero,
            Issue::Placeholder,
            Issue::Drop,
        ]);
        assert_eq!(
            found,
            vec![
                Issue::BadOrientation,
                Issue::AllZero,
                Issue::Placeholder,
                Issue::Drop
            ]
        );
        assert_eq!(
            format!("{found:?}"),
            "[BadOrientation, AllZero, Placeholder, Drop]"
        );
    }
}
