//! Topics in different frames joined by the log's own transforms (`/tf`, `/tf_static`): where
//! a chain of transforms leads from a topic's `frame_id` to a frame another topic is drawn in
//! (map → odom, as AMCL publishes it), the topic is drawn in that common frame; else each frame
//! keeps its own view, and why is said ([`FrameProblem`]).
//!
//! - The tree: every child frame has one parent (tf's rule). A child with several parents, or
//!   a chain of parents that comes back to itself (a cycle), is a broken tree: nothing is
//!   joined through it.
//! - The common frame of topics whose frames are in one tree is their lowest common ancestor:
//!   the first frame on the way up from one topic's frame that every other's way up reaches
//!   (`map` for topics in `map` and `odom`; a frame above it is never needed).
//! - A message at stamp t is moved by common_from_frame(t), the product of the chain's edges,
//!   each looked up at t ([`StampedPoses::at`]: interpolated on SE(3), never extrapolated; a
//!   `/tf_static` edge is its latest value). A message outside the chain's span is left out of
//!   the joined view, counted and said ([`FrameJoin::left_out`]).
//! - The covariance moves with the pose in the ROS reading used: Σ' = B_T Σ B_Tᵀ,
//!   B_T = blkdiag(R_T, R_T) in tf2's reading ([`ros_cov_moved`], CONVENTIONS §6); the
//!   right-form Gaussian posecov draws is unchanged, its mean moved to T · X̂. `/tf` carries no
//!   covariance: the transform is taken as exact.
//! - A planar topic is joined only by transforms that keep its plane (roll and pitch below
//!   [`PLANE_TOLERANCE`]).
//!
//! ```
//! use posecov::eval::log::frames::{FrameProblemKind, TopicFrame, join_plan};
//! use posecov::plan::log::{ReferenceSample, TfEdge, TfTree};
//! let s = ReferenceSample { stamp_ns: 0, position: [1.0, 0.0, 0.0], orientation_xyzw: [0.0, 0.0, 0.0, 1.0] };
//! let edge = |p: &str, c: &str| TfEdge { samples: vec![s, ReferenceSample { stamp_ns: 10, ..s }], messages: 2, ..TfEdge::new(p, c, "/tf", 0) };
//! let tf = TfTree { edges: vec![edge("map", "odom"), edge("odom", "base_link")], ..Default::default() };
//! let topic = |topic, frame_id, first_stamp_ns| TopicFrame { topic, frame_id, first_stamp_ns };
//! let plan = join_plan(&tf, &[topic("/odom", "odom", Some(0)), topic("/amcl_pose", "map", Some(0)), topic("/gps", "utm", Some(3))]);
//! assert_eq!(plan.chains[0].as_deref(), Some(&["odom".to_owned(), "map".to_owned()][..]));
//! assert!(plan.chains[1].is_none() && plan.chains[2].is_none());
//! assert_eq!(plan.problems[0].kind, FrameProblemKind::NoTransform);
//! let x = plan.lookup(&tf, plan.chains[0].as_deref().unwrap(), 5).unwrap();
//! assert_eq!(x.translation().x, 1.0);
//! assert!(plan.lookup(&tf, plan.chains[0].as_deref().unwrap(), 11).is_none()); // never extrapolated
//! ```
//!
//! [`ros_cov_moved`]: crate::interop::ros_cov_moved

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::{Matrix6, Vector3};
use serde::Serialize;

use super::TopicMessages;
use super::stamped::{Lookup, StampedPoses, pose_of_sample};
use crate::interop::{RosReading, ros_cov_moved};
use crate::lie::{GroupKind, LieGroup, Se3};
use crate::plan::log::{Class, Issue, TfTree, TrackPoint};

/// A transform keeps a planar topic's plane when its roll and pitch are below this (rad).
pub const PLANE_TOLERANCE: f64 = 1e-6;

/// A topic drawn in another frame than its own.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameJoin {
    /// Its own frame (`header.frame_id`).
    pub from: String,
    /// The common frame it is drawn in.
    pub to: String,
    /// The frames from its own up to the common one (both included).
    pub chain: Vec<String>,
    /// Drawn messages moved.
    pub moved: u64,
    /// Drawn messages left out: stamped outside the chain's transforms.
    pub left_out: u64,
    /// The first left-out message's stamp, ns.
    pub first_left_out_ns: Option<i64>,
    /// Trajectory points left out likewise.
    pub trajectory_left_out: u64,
}

/// Why frames could not be joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameProblemKind {
    /// A chain of parents that comes back to itself (a defect of the log's `/tf`).
    Cycle,
    /// A child frame with several parents, where tf allows one (a defect of the log's `/tf`).
    SeveralParents,
    /// Topics' frames are in `/tf`, but in trees no transform joins (a note: drawn apart).
    MissingLink,
    /// A topic's frame never gets a transform in `/tf` or `/tf_static` (a note: drawn apart).
    NoTransform,
    /// A planar topic whose transform tilts its plane (a note: drawn apart).
    TiltsPlane,
}

impl FrameProblemKind {
    /// Its finding in the one table of findings ([`Issue`]): the word (`tf_cycle`) in the
    /// panel, `report --json` and `check --allow`, and its class (a broken tree is a defect,
    /// `posecov check` fails on it; a frame the log does not join is a note).
    ///
    /// ```
    /// use posecov::eval::log::frames::FrameProblemKind;
    /// use posecov::plan::log::{Class, Issue};
    /// assert_eq!(FrameProblemKind::MissingLink.issue().name(), "tf_missing_link");
    /// assert_eq!(FrameProblemKind::Cycle.issue(), Issue::TfCycle);
    /// assert_eq!(FrameProblemKind::Cycle.class(), Class::Defect);
    /// assert_eq!(FrameProblemKind::NoTransform.class(), Class::Note);
    /// ```
    pub fn issue(self) -> Issue {
        match self {
            FrameProblemKind::Cycle => Issue::TfCycle,
            FrameProblemKind::SeveralParents => Issue::TfSeveralParents,
            FrameProblemKind::MissingLink => Issue::TfMissingLink,
            FrameProblemKind::NoTransform => Issue::TfNoTransform,
            FrameProblemKind::TiltsPlane => Issue::TfTiltsPlane,
        }
    }

    /// Defect or note, by [`Issue::class`] (see [`issue`](Self::issue) for an example).
    pub fn class(self) -> Class {
        // Whether the topic is dead-reckoned matters only to `constant`.
        self.issue().class(false)
    }
}

/// One reason frames were not joined, located: the frames, the topics concerned, where it was
/// read and when.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameProblem {
    /// What is wrong.
    pub kind: FrameProblemKind,
    /// The frames: the cycle in order (its first again at the end); the child then its
    /// parents; for a missing link, one frame per tree; the frame never transformed.
    pub frames: Vec<String>,
    /// A missing link only: the root of each tree in `frames`' order.
    pub roots: Vec<String>,
    /// The pose topics drawn apart because of it.
    pub topics: Vec<String>,
    /// Where it was read: `/tf`, `/tf_static`, or the pose topic.
    pub source: String,
    /// When it was first seen (ns): the transform that closed the cycle or gave the second
    /// parent, or the topic's first message.
    pub stamp_ns: Option<i64>,
}

/// A topic as [`join_plan`] reads it: its name, the `frame_id` its messages are in, and its
/// first stamp (ns; where a frame problem is located).
///
/// ```
/// use posecov::eval::log::frames::TopicFrame;
/// let t = TopicFrame { topic: "/odom", frame_id: "odom", first_stamp_ns: Some(0) };
/// assert_eq!(t.frame_id, "odom");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopicFrame<'a> {
    /// The topic's name.
    pub topic: &'a str,
    /// The `frame_id` of its messages.
    pub frame_id: &'a str,
    /// Its first stamp, ns, if any message.
    pub first_stamp_ns: Option<i64>,
}

/// Which topics join which frame: per topic its chain of frames up to the common one
/// (`None`: drawn in its own frame), and the problems found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameJoins {
    /// Per topic, in the order given.
    pub chains: Vec<Option<Vec<String>>>,
    /// What kept frames apart.
    pub problems: Vec<FrameProblem>,
}

/// What joining frames found: the log had transforms, and what kept frames apart.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct FrameFindings {
    /// The log has `/tf` or `/tf_static` transforms.
    pub has_tf: bool,
    /// What kept frames apart.
    pub problems: Vec<FrameProblem>,
}

/// The chain of frames from `frame` up to its root; `Err(cycle)` when it comes back.
fn chain_up(parents: &BTreeMap<&str, &str>, frame: &str) -> Result<Vec<String>, Vec<String>> {
    let mut out = vec![frame.to_owned()];
    while let Some(p) = parents.get(out[out.len() - 1].as_str()) {
        if let Some(i) = out.iter().position(|f| f == p) {
            let mut cycle = out[i..].to_vec();
            cycle.push((*p).to_owned());
            return Err(cycle);
        }
        out.push((*p).to_owned());
    }
    Ok(out)
}

/// Decides which topics join (see the [module docs](self)): `topics` gives each topic's name,
/// `frame_id` and first stamp.
///
/// See the [module docs](self) for an example.
pub fn join_plan(tf: &TfTree, topics: &[TopicFrame<'_>]) -> FrameJoins {
    let mut plan = FrameJoins {
        chains: vec![None; topics.len()],
        problems: Vec::new(),
    };
    if tf.edges.is_empty() {
        return plan;
    }
    let (parents, broken) = one_parent_each(tf, &mut plan.problems);
    // One frame among the topics: nothing to join, nothing to say of frames /tf lacks.
    let distinct: BTreeSet<String> = topics
        .iter()
        .map(|t| bare_frame(t.frame_id))
        .filter(|f| !f.is_empty())
        .collect();
    if distinct.len() < 2 {
        return plan;
    }
    let mut trees = chains_to_roots(tf, topics, &parents, &broken, &mut plan.problems);
    // Per tree: each topic's chain up to the lowest common ancestor of its topics' frames.
    for members in trees.roots.values() {
        if let Some(common) = common_frame(&trees.chains, members) {
            for &i in members {
                if let Some(c) = &trees.chains[i]
                    && let Some(end) = c.iter().position(|f| *f == common)
                    && end > 0
                {
                    plan.chains[i] = Some(c[..=end].to_vec());
                }
            }
        }
    }
    // Frames in /tf but in trees apart (not apart by a broken link, said above): a missing
    // link.
    trees.roots.retain(|root, _| !broken.contains(root));
    if trees.roots.len() > 1 {
        plan.problems.push(missing_link(&trees, topics));
    }
    plan
}

/// A frame id without its leading `/` (tf2 drops it).
fn bare_frame(f: &str) -> String {
    f.trim_start_matches('/').to_owned()
}

/// tf's one-parent rule: each child's one parent; a child with several parents keeps none
/// (returned apart, its problem noted with the transform that gave the second parent).
fn one_parent_each<'t>(
    tf: &'t TfTree,
    problems: &mut Vec<FrameProblem>,
) -> (BTreeMap<&'t str, &'t str>, BTreeSet<String>) {
    let mut seen: BTreeMap<&str, Vec<&crate::plan::log::TfEdge>> = BTreeMap::new();
    for e in &tf.edges {
        seen.entry(e.child.as_str()).or_default().push(e);
    }
    let mut parents = BTreeMap::new();
    let mut broken = BTreeSet::new();
    for (child, edges) in &seen {
        if let [one] = edges.as_slice() {
            parents.insert(*child, one.parent.as_str());
        } else {
            broken.insert((*child).to_owned());
            let second = edges.iter().max_by_key(|e| e.first_stamp_ns);
            let mut frames = vec![(*child).to_owned()];
            frames.extend(edges.iter().map(|e| e.parent.clone()));
            problems.push(FrameProblem {
                kind: FrameProblemKind::SeveralParents,
                frames,
                roots: Vec::new(),
                topics: Vec::new(),
                source: second.map(|e| e.topic.clone()).unwrap_or_default(),
                stamp_ns: second.map(|e| e.first_stamp_ns),
            });
        }
    }
    (parents, broken)
}

/// The topics' frames in /tf's trees.
struct Trees {
    /// Per topic, its chain of frames up to its tree's root (`None`: no frame, not in /tf, or
    /// in a cycle).
    chains: Vec<Option<Vec<String>>>,
    /// Per root, the topics (indices) under it.
    roots: BTreeMap<String, Vec<usize>>,
}

/// Each topic's chain up to its root, grouped by root; a frame /tf lacks and a cycle are
/// noted (a cycle once, with every topic it keeps apart), and a topic below a frame with
/// several parents is added to that problem.
fn chains_to_roots(
    tf: &TfTree,
    topics: &[TopicFrame<'_>],
    parents: &BTreeMap<&str, &str>,
    broken: &BTreeSet<String>,
    problems: &mut Vec<FrameProblem>,
) -> Trees {
    let known: BTreeSet<&str> = tf
        .edges
        .iter()
        .flat_map(|e| [e.parent.as_str(), e.child.as_str()])
        .collect();
    let mut chains: Vec<Option<Vec<String>>> = vec![None; topics.len()];
    let mut roots: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (i, t) in topics.iter().enumerate() {
        let (name, f) = (t.topic, bare_frame(t.frame_id));
        if f.is_empty() {
            continue;
        }
        if !known.contains(f.as_str()) {
            note_topic(
                problems,
                FrameProblemKind::NoTransform,
                &f,
                name,
                t.first_stamp_ns,
            );
            continue;
        }
        match chain_up(parents, &f) {
            Ok(c) => {
                if c.iter().any(|g| broken.contains(g)) {
                    for p in problems.iter_mut() {
                        if p.kind == FrameProblemKind::SeveralParents && c.contains(&p.frames[0]) {
                            p.topics.push(name.to_owned());
                        }
                    }
                }
                roots.entry(c[c.len() - 1].clone()).or_default().push(i);
                chains[i] = Some(c);
            }
            Err(cycle) => note_cycle(tf, problems, cycle, name),
        }
    }
    Trees { chains, roots }
}

/// Notes topic `name` kept apart by `cycle` (its frames, the first repeated at the end): added
/// to the problem of the same cycle, or a new problem with the transform that closed it.
fn note_cycle(tf: &TfTree, problems: &mut Vec<FrameProblem>, cycle: Vec<String>, name: &str) {
    let mut sorted = cycle[..cycle.len() - 1].to_vec();
    sorted.sort();
    let same = |p: &FrameProblem| {
        let mut s = p.frames[..p.frames.len() - 1].to_vec();
        s.sort();
        p.kind == FrameProblemKind::Cycle && s == sorted
    };
    match problems.iter_mut().find(|p| same(p)) {
        Some(p) => p.topics.push(name.to_owned()),
        None => {
            let closing = cycle
                .windows(2)
                .filter_map(|w| tf.edge(&w[1], &w[0]))
                .max_by_key(|e| e.first_stamp_ns);
            problems.push(FrameProblem {
                kind: FrameProblemKind::Cycle,
                frames: cycle.into_iter().rev().collect(),
                roots: Vec::new(),
                topics: vec![name.to_owned()],
                source: closing.map(|e| e.topic.clone()).unwrap_or_default(),
                stamp_ns: closing.map(|e| e.first_stamp_ns),
            });
        }
    }
}

/// The lowest frame of a tree common to the chains of its topics `members`; `None` when they
/// are all in one frame (nothing to join).
fn common_frame(chains: &[Option<Vec<String>>], members: &[usize]) -> Option<String> {
    let firsts: BTreeSet<&str> = members
        .iter()
        .filter_map(|&i| chains[i].as_ref().map(|c| c[0].as_str()))
        .collect();
    if firsts.len() < 2 {
        return None;
    }
    let first = chains[members[0]].as_ref()?;
    first
        .iter()
        .find(|f| {
            members
                .iter()
                .all(|&i| chains[i].as_ref().is_some_and(|c| c.contains(f)))
        })
        .cloned()
}

/// The problem of topics in /tf trees apart: per tree one topic's frame and the tree's root,
/// and every topic under them.
fn missing_link(trees: &Trees, topics: &[TopicFrame<'_>]) -> FrameProblem {
    let (frames, roots): (Vec<String>, Vec<String>) = trees
        .roots
        .iter()
        .filter_map(|(root, members)| {
            let c = trees.chains[members[0]].as_ref()?;
            Some((c[0].clone(), root.clone()))
        })
        .unzip();
    FrameProblem {
        kind: FrameProblemKind::MissingLink,
        frames,
        roots,
        topics: trees
            .roots
            .values()
            .flatten()
            .map(|&i| topics[i].topic.to_owned())
            .collect(),
        source: "/tf".to_owned(),
        stamp_ns: None,
    }
}

/// Notes a topic's frame problem, one per frame (further topics added to it).
fn note_topic(
    problems: &mut Vec<FrameProblem>,
    kind: FrameProblemKind,
    frame: &str,
    topic: &str,
    stamp_ns: Option<i64>,
) {
    match problems
        .iter_mut()
        .find(|p| p.kind == kind && p.frames[0] == frame)
    {
        Some(p) => p.topics.push(topic.to_owned()),
        None => problems.push(FrameProblem {
            kind,
            frames: vec![frame.to_owned()],
            roots: Vec::new(),
            topics: vec![topic.to_owned()],
            source: topic.to_owned(),
            stamp_ns,
        }),
    }
}

impl FrameJoins {
    /// common_from_frame at `stamp_ns` along `chain` (a topic's frame first): the product of
    /// the chain's edges, each looked up at the stamp; `None` outside an edge's span (never
    /// extrapolated) or where an edge has no transform kept.
    ///
    /// See the [module docs](self) for an example.
    pub fn lookup(&self, tf: &TfTree, chain: &[String], stamp_ns: i64) -> Option<Se3> {
        EdgeLookup::new(tf, chain).at(stamp_ns)
    }
}

/// A chain's edges, ready to be looked up at stamps.
struct EdgeLookup {
    /// Per edge from the topic's frame up: its `/tf` samples, or its `/tf_static` value.
    edges: Vec<Result<StampedPoses, Option<Se3>>>,
}

impl EdgeLookup {
    fn new(tf: &TfTree, chain: &[String]) -> Self {
        let edges = chain
            .windows(2)
            .map(|w| match tf.edge(&w[1], &w[0]) {
                Some(e) if !e.samples.is_empty() => {
                    let mut poses = StampedPoses::default();
                    for s in &e.samples {
                        if let Some(x) = pose_of_sample(s) {
                            poses.insert(s.stamp_ns, x);
                        }
                    }
                    Ok(poses)
                }
                Some(e) => Err(e.static_value.as_ref().and_then(pose_of_sample)),
                None => Err(None),
            })
            .collect();
        Self { edges }
    }

    fn at(&self, stamp_ns: i64) -> Option<Se3> {
        let mut x = Se3::identity();
        for edge in &self.edges {
            let e = match edge {
                Ok(poses) => match poses.at(stamp_ns) {
                    Lookup::At(e) => e,
                    Lookup::Before | Lookup::After => return None,
                },
                Err(value) => (*value)?,
            };
            x = e.compose(&x);
        }
        Some(x)
    }
}

/// Whether a transform keeps the plane z = 0's orientation (roll, pitch ≤ [`PLANE_TOLERANCE`]).
fn keeps_plane(t: &Se3) -> bool {
    let [roll, pitch, _] = t.rotation().to_rpy();
    roll.abs() <= PLANE_TOLERANCE && pitch.abs() <= PLANE_TOLERANCE
}

/// A topic's messages moved into its chain's common frame, in place: every drawn message and
/// trajectory point moved by common_from_frame at its stamp (the covariance by
/// [`ros_cov_moved`] in `reading`), those outside the transforms' span left out; `frame_id`
/// becomes the common frame. `Err(stamp)`: an SE(2) topic whose transform at `stamp` tilts its
/// plane; nothing is moved then.
///
/// ```
/// use posecov::eval::log::{TopicMessages, frames::move_topic};
/// use posecov::input::{locate, log::{LogOptions, read_located}};
/// use posecov::interop::RosReading;
/// use posecov::plan::log::{ReferenceSample, TfEdge, TfTree};
/// let s = ReferenceSample { stamp_ns: 0, position: [1.0, 0.0, 0.0], orientation_xyzw: [0.0, 0.0, 0.0, 1.0] };
/// let edge = TfEdge { samples: vec![s, ReferenceSample { stamp_ns: 47_700_000_000, ..s }], messages: 2, ..TfEdge::new("map", "odom", "/tf", 0) };
/// let tf = TfTree { edges: vec![edge], ..Default::default() };
/// let mut log = read_located(&locate("jackal_odometry").unwrap(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
/// let topic = &mut log.topics[0]; // in `odom`, 47.584 s to 108.764 s
/// let (group, x0) = (topic.group, topic.trajectory[0].position[0]);
/// let mut messages = TopicMessages::take(topic);
/// let chain = ["odom".to_owned(), "map".to_owned()];
/// let join = move_topic(&tf, &chain, group, &mut messages, RosReading::Tf2).unwrap();
/// assert_eq!(messages.frame_id, "map");
/// assert_eq!(messages.trajectory[0].position[0], x0 + 1.0);
/// assert!(join.moved >= 1 && join.left_out > 0); // after 47.7 s: never extrapolated
/// ```
pub fn move_topic(
    tf: &TfTree,
    chain: &[String],
    group: GroupKind,
    messages: &mut TopicMessages,
    reading: RosReading,
) -> Result<FrameJoin, i64> {
    let lookup = EdgeLookup::new(tf, chain);
    let planar = group.is_planar();
    // First every transform, so that a tilted plane leaves the messages as they were.
    let at = |stamp: i64| -> Result<Option<Se3>, i64> {
        match lookup.at(stamp) {
            Some(t) if planar && !keeps_plane(&t) => Err(stamp),
            t => Ok(t),
        }
    };
    let drawn_at: Vec<Option<Se3>> = messages
        .drawn
        .iter()
        .map(|d| at(d.message.stamp_ns))
        .collect::<Result<_, _>>()?;
    let trajectory_at: Vec<Option<Se3>> = messages
        .trajectory
        .iter()
        .map(|p| at(p.stamp_ns))
        .collect::<Result<_, _>>()?;
    let to = chain.last().cloned().unwrap_or_default();
    let mut join = FrameJoin {
        from: std::mem::replace(&mut messages.frame_id, to.clone()),
        to,
        chain: chain.to_vec(),
        moved: 0,
        left_out: 0,
        first_left_out_ns: None,
        trajectory_left_out: 0,
    };
    let drawn = std::mem::take(&mut messages.drawn);
    for (mut d, t) in drawn.into_iter().zip(drawn_at) {
        let Some(t) = t else {
            join.left_out += 1;
            join.first_left_out_ns.get_or_insert(d.message.stamp_ns);
            continue;
        };
        let m = &mut d.message;
        if let Ok(r) = crate::lie::So3::try_from_quaternion_xyzw(m.orientation_xyzw) {
            let x = t.compose(&Se3::from_parts(m.position.into(), r));
            m.position = (*x.translation()).into();
            m.orientation_xyzw = x.rotation().to_quaternion_xyzw();
        }
        let cov = Matrix6::from_row_slice(&m.covariance);
        if cov.iter().all(|v| v.is_finite()) {
            let moved = ros_cov_moved(&cov, t.rotation(), reading);
            for (i, v) in m.covariance.iter_mut().enumerate() {
                *v = moved[(i / 6, i % 6)];
            }
        }
        join.moved += 1;
        messages.drawn.push(d);
    }
    let trajectory = std::mem::take(&mut messages.trajectory);
    for (p, t) in trajectory.into_iter().zip(trajectory_at) {
        match t {
            Some(t) => messages.trajectory.push(TrackPoint {
                stamp_ns: p.stamp_ns,
                position: t.act(&Vector3::from(p.position)).into(),
            }),
            None => join.trajectory_left_out += 1,
        }
    }
    Ok(join)
}
