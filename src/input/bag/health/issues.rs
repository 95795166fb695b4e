//! The issues of one message, without an allocation.

use crate::plan::bag::Issue;

/// The issues of one message, in the order found: a list on the stack (every message of a
/// log has one; a `Vec` was an allocation per message). Compares equal to a `Vec` or slice
/// of the same issues in the same order.
///
/// ```
/// use posecov::input::bag::health::Issues;
/// use posecov::plan::bag::Issue;
/// let mut issues = Issues::default();
/// issues.push(Issue::Placeholder);
/// issues.push(Issue::Drop);
/// assert_eq!(issues, vec![Issue::Placeholder, Issue::Drop]);
/// assert!(issues.contains(&Issue::Drop) && !issues.is_empty());
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Issues {
    items: [Issue; Issues::CAPACITY],
    len: usize,
}

impl Default for Issues {
    fn default() -> Self {
        Self {
            items: [Issue::NonFinite; Issues::CAPACITY],
            len: 0,
        }
    }
}

impl Issues {
    /// More than one message can have: one word per check of [`classify`](super::classify)
    /// and [`Trend`](super::Trend).
    pub const CAPACITY: usize = 8;

    /// Adds `issue` (beyond [`Self::CAPACITY`] it is not kept; no message has that many).
    pub fn push(&mut self, issue: Issue) {
        if let Some(slot) = self.items.get_mut(self.len) {
            *slot = issue;
            self.len += 1;
        }
    }

    /// The issues, in the order found.
    pub fn as_slice(&self) -> &[Issue] {
        &self.items[..self.len]
    }

    /// The issues, in the order found.
    pub fn iter(&self) -> std::slice::Iter<'_, Issue> {
        self.as_slice().iter()
    }

    /// Whether `issue` is among them.
    pub fn contains(&self, issue: &Issue) -> bool {
        self.as_slice().contains(issue)
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl Extend<Issue> for Issues {
    fn extend<I: IntoIterator<Item = Issue>>(&mut self, issues: I) {
        for issue in issues {
            self.push(issue);
        }
    }
}

impl<'a> IntoIterator for &'a Issues {
    type Item = &'a Issue;
    type IntoIter = std::slice::Iter<'a, Issue>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl PartialEq for Issues {
    fn eq(&self, other: &Issues) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl Eq for Issues {}

impl PartialEq<Vec<Issue>> for Issues {
    fn eq(&self, other: &Vec<Issue>) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl PartialEq<[Issue]> for Issues {
    fn eq(&self, other: &[Issue]) -> bool {
        self.as_slice() == other
    }
}
