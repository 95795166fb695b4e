//! A recording's rows on their way to the Rerun stream: each scene item's rows (path, time,
//! components) serialized to Arrow on every core, a bounded slice of items at a time
//! ([`slices`]), then grouped by path, components and static-or-timed into chunks of up to
//! [`ROWS_PER_CHUNK`] rows ([`Rows`]) and sent in log order (`rerun.rs`'s `log_items`).

use ::rerun as rr;
use rr::AsComponents;
use rr::log::{Chunk, RowId};

use super::SinkError;
use crate::scene::{ItemKind, SceneItem};

/// Most scene items serialized at once, in parallel.
pub(super) const ITEMS_SERIALIZED_AT_ONCE: usize = 256;

/// Most points (positions, vertices, shapes) in the items serialized at once: a slice of large
/// clouds holds about what one [`BYTES_PER_CHUNK`] chunk does, not 256 clouds' arrays.
const POINTS_SERIALIZED_AT_ONCE: usize = 1 << 18;

/// `items` in consecutive slices of at most [`ITEMS_SERIALIZED_AT_ONCE`] items and, but for a
/// single larger item, [`POINTS_SERIALIZED_AT_ONCE`] points.
pub(super) fn slices<'a, 'i>(items: &'a [&'i SceneItem]) -> Vec<&'a [&'i SceneItem]> {
    let points = |item: &SceneItem| match &item.kind {
        ItemKind::Points(c) => c.positions.len(),
        ItemKind::Surface(m) => m.vertices.len() + m.triangles.len(),
        ItemKind::LineStrips(l) => l.strips.iter().map(Vec::len).sum(),
        ItemKind::Ellipsoids(e) => e.shapes.len(),
        ItemKind::Triads(t) => 6 * t.translations.len(),
        ItemKind::Arrows(a) => 2 * a.origins.len(),
        ItemKind::Frame(_) | ItemKind::Text(_) => 1,
    };
    let mut out = Vec::new();
    let (mut start, mut weight) = (0, 0);
    for (i, item) in items.iter().enumerate() {
        let w = points(item);
        if i > start
            && (i - start >= ITEMS_SERIALIZED_AT_ONCE || weight + w > POINTS_SERIALIZED_AT_ONCE)
        {
            out.push(&items[start..i]);
            (start, weight) = (i, 0);
        }
        weight += w;
    }
    if start < items.len() {
        out.push(&items[start..]);
    }
    out
}

/// One row not yet sent: its path, time and components.
pub(super) struct Row {
    path: rr::EntityPath,
    at: rr::TimePoint,
    batches: Vec<rr::SerializedComponentBatch>,
}

/// The rows of one scene item.
#[derive(Default)]
pub(super) struct ItemRows(pub Vec<Row>);

impl ItemRows {
    /// Adds one row with all `parts`.
    pub(super) fn add(&mut self, path: &str, at: rr::TimePoint, parts: &[&dyn AsComponents]) {
        self.0.push(Row {
            path: rr::EntityPath::from(path),
            at,
            batches: parts
                .iter()
                .flat_map(|p| p.as_serialized_batches())
                .collect(),
        });
    }
}

/// Most rows of one path sent in one chunk ([`Rows`]).
const ROWS_PER_CHUNK: usize = 256;

/// A group of rows this large (their arrays' bytes) is sent at once, however few its rows: a
/// large cloud does not wait for the scene's end (memory stays what one chunk needs).
const BYTES_PER_CHUNK: usize = 4 << 20;

/// Rows waiting to be sent, grouped by entity path, components and static-or-timed, in the
/// order their groups began. A propagation's per-step items (a frame and an ellipsoid at each
/// of a thousand steps) then go out as a few chunks rather than thousands: each chunk costs a
/// schema, a compression frame and allocations to encode, which for one-row chunks was most
/// of the time a recording took (`--save` of a pose graph; a live run's pictures). The
/// content — every row, its time and components, in order per path — is what one chunk per
/// row would say.
#[derive(Default)]
pub(super) struct Rows {
    groups: Vec<Group>,
    /// Group index by key ([`Rows::key`]).
    index: std::collections::HashMap<String, usize>,
}

/// One group's rows: (row id, time, components), and their arrays' bytes.
struct Group {
    path: rr::EntityPath,
    rows: Vec<(RowId, rr::TimePoint, Vec<rr::SerializedComponentBatch>)>,
    bytes: usize,
}

impl Rows {
    /// What a group is: the path, static or timed, and the components' descriptors.
    fn key(
        path: &rr::EntityPath,
        at: &rr::TimePoint,
        batches: &[rr::SerializedComponentBatch],
    ) -> String {
        let mut key = format!("{path}\u{0}{}", at.is_static());
        for b in batches {
            key.push_str(&format!("\u{0}{:?}", b.descriptor));
        }
        key
    }

    /// Adds one row (a new row id: rows keep the order they were added in).
    pub(super) fn push(&mut self, row: Row) {
        let Row { path, at, batches } = row;
        let key = Self::key(&path, &at, &batches);
        let next = self.groups.len();
        let group = *self.index.entry(key).or_insert(next);
        if group == next {
            self.groups.push(Group {
                path,
                rows: Vec::new(),
                bytes: 0,
            });
        }
        let group = &mut self.groups[group];
        group.bytes += batches
            .iter()
            .map(|b| rr::external::arrow::array::Array::get_array_memory_size(&b.array))
            .sum::<usize>();
        group.rows.push((RowId::new(), at, batches));
    }

    /// Sends the groups that reached [`ROWS_PER_CHUNK`] rows or [`BYTES_PER_CHUNK`] bytes.
    pub(super) fn send_full(&mut self, rec: &rr::RecordingStream) -> Result<(), SinkError> {
        for group in &mut self.groups {
            if group.rows.len() >= ROWS_PER_CHUNK || group.bytes >= BYTES_PER_CHUNK {
                group.send(rec)?;
            }
        }
        Ok(())
    }

    /// Sends every row waiting, group by group in the order they began.
    pub(super) fn send_all(&mut self, rec: &rr::RecordingStream) -> Result<(), SinkError> {
        for group in &mut self.groups {
            group.send(rec)?;
        }
        Ok(())
    }
}

impl Group {
    /// The rows as one chunk (none when there are none).
    fn send(&mut self, rec: &rr::RecordingStream) -> Result<(), SinkError> {
        if self.rows.is_empty() {
            return Ok(());
        }
        self.bytes = 0;
        let mut builder = Chunk::builder(self.path.clone());
        for (row_id, at, batches) in self.rows.drain(..) {
            builder = builder.with_serialized_batches(row_id, at, batches);
        }
        let chunk = builder.build().map_err(|err| SinkError::Chunk {
            path: self.path.to_string(),
            message: err.to_string(),
        })?;
        rec.send_chunk(chunk);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Color, PointCloud, SceneItem, Timing};

    #[test]
    fn items_are_serialized_in_bounded_slices_in_order() {
        let cloud = |n: usize| {
            SceneItem::new(
                "world/c",
                Timing::Static,
                ItemKind::Points(PointCloud {
                    positions: vec![[0.0; 3]; n],
                    color: Color::rgb(1, 2, 3),
                    radius: 0.1,
                }),
            )
        };
        let text =
            |i: usize| SceneItem::new("t", Timing::Step(i as i64), ItemKind::Text("x".into()));
        // 600 small items: slices of 256, 256, 88.
        let small: Vec<SceneItem> = (0..600).map(text).collect();
        let refs: Vec<&SceneItem> = small.iter().collect();
        let lens: Vec<usize> = slices(&refs).iter().map(|s| s.len()).collect();
        assert_eq!(lens, [256, 256, 88]);
        // Large clouds: at most POINTS_SERIALIZED_AT_ONCE points a slice, one larger alone.
        let big = [
            cloud(POINTS_SERIALIZED_AT_ONCE / 2),
            cloud(POINTS_SERIALIZED_AT_ONCE / 2),
            cloud(1),
            cloud(3 * POINTS_SERIALIZED_AT_ONCE),
            cloud(1),
        ];
        let refs: Vec<&SceneItem> = big.iter().collect();
        let lens: Vec<usize> = slices(&refs).iter().map(|s| s.len()).collect();
        assert_eq!(lens, [2, 1, 1, 1]);
        assert!(slices(&[]).is_empty());
    }
}
