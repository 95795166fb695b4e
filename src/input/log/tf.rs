//! A log's `/tf` and `/tf_static` while it streams by: every transform decoded with the
//! reference decoder ([`reference::decode_reference`](super::reference)) — the one TF decoder —
//! and kept per edge, bounded, into a [`TfTree`] (what is kept: its docs).

use std::collections::HashMap;

use super::reference::{self, ReferenceType};
use super::{Codec, Stream};
use crate::plan::log::{
    Decimator, MAX_TF_EDGES, MAX_TF_SAMPLES, ReferenceSample, TfEdge, TfTree, UndecodableTf,
};

/// The topics whose transforms join frames.
pub(super) const TF_TOPICS: [&str; 2] = ["/tf", "/tf_static"];

/// The transforms read so far.
#[derive(Clone, Default)]
pub(super) struct TfCollector {
    /// Per edge: the edge, its kept `/tf` samples and its `/tf` transforms read.
    edges: Vec<(TfEdge, Decimator<ReferenceSample>, u64)>,
    /// Parent → child → index in `edges`: looked up by `&str`, so a transform of a known edge
    /// (every `/tf` message after the first) allocates nothing.
    by_name: HashMap<String, HashMap<String, usize>>,
    undecodable: Vec<UndecodableTf>,
}

impl TfCollector {
    /// One message on `stream` (ignored unless `/tf` or `/tf_static` of a TF type).
    pub(super) fn message(
        &mut self,
        stream: &Stream,
        log_time_ns: i64,
        bytes: &[u8],
        codec: Codec,
    ) {
        let (topic, kind) = (stream.topic.as_str(), stream.reference.as_ref());
        let Some(i) = TF_TOPICS.iter().position(|t| *t == topic) else {
            return;
        };
        let is_static = i == 1;
        let Some(Ok(kind @ (ReferenceType::TfMessage | ReferenceType::TransformStamped))) = kind
        else {
            return;
        };
        let poses = match reference::decode_reference(*kind, codec, bytes) {
            Ok(poses) => poses,
            Err(_) => {
                match self.undecodable.iter_mut().find(|u| u.topic == topic) {
                    Some(u) => u.count += 1,
                    None => self.undecodable.push(UndecodableTf {
                        topic: topic.to_owned(),
                        count: 1,
                        first_log_time_ns: log_time_ns,
                    }),
                }
                return;
            }
        };
        for pose in poses {
            let parent = pose.frame_id.trim_start_matches('/');
            let child = pose.child_frame_id.trim_start_matches('/');
            let sample = pose.sample(log_time_ns);
            let at = match self
                .by_name
                .get(parent)
                .and_then(|children| children.get(child))
            {
                Some(at) => *at,
                None => {
                    let mut edge = TfEdge::new(parent, child, topic, sample.stamp_ns);
                    edge.dropped = self.edges.len() >= MAX_TF_EDGES;
                    self.edges
                        .push((edge, Decimator::new(1, MAX_TF_SAMPLES), 0));
                    self.by_name
                        .entry(parent.to_owned())
                        .or_default()
                        .insert(child.to_owned(), self.edges.len() - 1);
                    self.edges.len() - 1
                }
            };
            let (edge, kept, dynamic) = &mut self.edges[at];
            edge.messages += 1;
            if edge.dropped {
                continue;
            }
            if is_static {
                edge.static_value = Some(sample);
            } else {
                kept.push(*dynamic, sample);
                *dynamic += 1;
            }
        }
    }

    /// The tree read.
    pub(super) fn finish(self) -> TfTree {
        TfTree {
            edges: self
                .edges
                .into_iter()
                .map(|(mut edge, kept, _)| {
                    edge.stride = kept.stride();
                    edge.samples = kept.into_items();
                    edge
                })
                .collect(),
            undecodable: self.undecodable,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::log::decode::{Header, Time};
    use crate::input::log::reference::{TfMessage, Transform, TransformStamped};

    fn bytes(sec: i32, nanosec: u32, parent: &str, child: &str) -> Vec<u8> {
        let tf = TfMessage {
            transforms: vec![TransformStamped {
                header: Header {
                    stamp: Time { sec, nanosec },
                    frame_id: parent.into(),
                },
                child_frame_id: child.into(),
                transform: Transform {
                    translation: [1.0, 0.0, 0.0],
                    rotation: [0.0, 0.0, 0.0, 1.0],
                },
            }],
        };
        let mut b = vec![0, 1, 0, 0];
        b.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&tf).unwrap());
        b
    }

    fn stream(topic: &str) -> Stream {
        Stream {
            topic: topic.into(),
            type_name: "tf2_msgs/msg/TFMessage".into(),
            kind: None,
            reference: Some(Ok(ReferenceType::TfMessage)),
            sensor: None,
        }
    }

    #[test]
    fn an_hour_of_tf_at_100_hz_is_kept_bounded_and_even() {
        let mut tf = TfCollector::default();
        let (dynamic, fixed, other) = (stream("/tf"), stream("/tf_static"), stream("/other"));
        for k in 0..360_000u32 {
            let b = bytes((k / 100) as i32, (k % 100) * 10_000_000, "/map", "odom");
            tf.message(&dynamic, 0, &b, Codec::Cdr);
        }
        tf.message(&fixed, 0, &bytes(0, 0, "base_link", "laser"), Codec::Cdr);
        tf.message(&other, 0, &bytes(0, 0, "a", "b"), Codec::Cdr);
        tf.message(&dynamic, 7, &[0, 1, 0, 0, 9], Codec::Cdr);
        let tree = tf.finish();
        assert_eq!(tree.edges.len(), 2);
        let edge = &tree.edges[0];
        assert_eq!((edge.parent.as_str(), edge.messages), ("map", 360_000));
        assert!(edge.samples.len() <= MAX_TF_SAMPLES && edge.samples.len() > MAX_TF_SAMPLES / 2);
        assert_eq!(edge.stride, 64);
        let step = edge.samples[1].stamp_ns - edge.samples[0].stamp_ns;
        assert_eq!(step, 640_000_000);
        assert!(
            edge.samples
                .windows(2)
                .all(|w| w[1].stamp_ns - w[0].stamp_ns == step)
        );
        assert!(tree.edges[1].static_value.is_some() && tree.edges[1].samples.is_empty());
        assert_eq!(
            tree.undecodable,
            [UndecodableTf {
                topic: "/tf".to_owned(),
                count: 1,
                first_log_time_ns: 7
            }]
        );
    }
}
