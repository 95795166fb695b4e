//! Every entity path of a scene, built in one place: one function per kind of entity, so
//! draw never formats a path and no sink parses one (a sink that needs to know what an item
//! or a series belongs to reads its typed [`Origin`] or [`PlotId`]).
//!
//! The layout: 3-D geometry under [`WORLD`] — a pose `world/<pose>` ([`pose`]) with one
//! subtree per method (`world/<pose>/<method>`, [`method`]) and its Monte Carlo samples
//! ([`monte_carlo`]); a pose graph's optimised picture `world/optimized` ([`optimized`]); a
//! robot log's topic `world/<topic segments>` ([`topic`]) with its robot view ([`robot`]);
//! scalar series under [`PLOTS`] — `plots/<plot>/<series>` ([`series`]). A part of any of
//! these is [`child`].
//!
//! ```
//! use posecov::scene::paths;
//! assert_eq!(paths::child(&paths::method("T_MC", "first_order"), "ellipsoid"), "world/T_MC/first_order/ellipsoid");
//! assert_eq!(paths::topic("/amcl pose"), "world/amcl_pose");
//! ```

use super::{PLOTS, WORLD};
use crate::scene::PlotId;

/// A part `leaf` (one or more segments) of the entity at `base`: `base/leaf`.
///
/// ```
/// assert_eq!(posecov::scene::paths::child("world/a", "cloud"), "world/a/cloud");
/// ```
pub fn child(base: &str, leaf: &str) -> String {
    format!("{base}/{leaf}")
}

/// Whether `path` is `root` or lies under it (a whole segment: `world/ab` is not under
/// `world/a`) — the one subtree rule of views, hidden entities and the graph's states.
///
/// ```
/// use posecov::scene::paths::is_under;
/// assert!(is_under("world/a/x", "world/a") && is_under("world/a", "world/a"));
/// assert!(!is_under("world/ab", "world/a"));
/// ```
pub fn is_under(path: &str, root: &str) -> bool {
    path.strip_prefix(root)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with('/'))
}

/// A scenario's pose (or a graph's node): `world/<pose>`.
///
/// ```
/// assert_eq!(posecov::scene::paths::pose("T_MC"), "world/T_MC");
/// ```
pub fn pose(name: &str) -> String {
    format!("{WORLD}/{name}")
}

/// A pose's nominal frame: `world/<pose>/frame`.
///
/// ```
/// assert_eq!(posecov::scene::paths::pose_frame("T_MC"), "world/T_MC/frame");
/// ```
pub fn pose_frame(name: &str) -> String {
    child(&pose(name), "frame")
}

/// One method's (or one estimate's) subtree of a pose: `world/<pose>/<segment>` (the method's
/// slug, [`Method::slug`](crate::uncertain::Method::slug)).
///
/// ```
/// assert_eq!(posecov::scene::paths::method("T_MC", "first_order"), "world/T_MC/first_order");
/// ```
pub fn method(name: &str, segment: &str) -> String {
    child(&pose(name), segment)
}

/// A pose's Monte Carlo samples: `world/<pose>/monte_carlo`.
///
/// ```
/// assert_eq!(posecov::scene::paths::monte_carlo("T"), "world/T/monte_carlo");
/// ```
pub fn monte_carlo(name: &str) -> String {
    method(name, "monte_carlo")
}

/// One later block's cloud of a blocked Monte Carlo sample:
/// `world/<pose>/monte_carlo/cloud/block_<part>`.
///
/// ```
/// assert_eq!(posecov::scene::paths::block_cloud("T", 2), "world/T/monte_carlo/cloud/block_2");
/// ```
pub fn block_cloud(name: &str, part: usize) -> String {
    format!("{}/cloud/block_{part}", monte_carlo(name))
}

/// A propagated path's nominal poses: `world/<path>/nominal`.
///
/// ```
/// assert_eq!(posecov::scene::paths::nominal("X"), "world/X/nominal");
/// ```
pub fn nominal(output: &str) -> String {
    child(&pose(output), "nominal")
}

/// A propagated path's `i`-th sampled trajectory: `world/<path>/samples/<i>`.
///
/// ```
/// assert_eq!(posecov::scene::paths::sample_path("X", 4), "world/X/samples/4");
/// ```
pub fn sample_path(output: &str, i: usize) -> String {
    format!("{}/samples/{i}", pose(output))
}

/// An Euler integration's drift of axis `axis` (0, 1, 2 → x, y, z): `world/<frame>/euler/axis_x`.
///
/// ```
/// assert_eq!(posecov::scene::paths::euler_axis("R", 2), "world/R/euler/axis_z");
/// ```
pub fn euler_axis(output: &str, axis: usize) -> String {
    format!("{}/euler/axis_{}", pose(output), ["x", "y", "z"][axis])
}

/// The links between the poses of a scenario: `world/links`.
///
/// ```
/// assert_eq!(posecov::scene::paths::links(), "world/links");
/// ```
pub fn links() -> String {
    format!("{WORLD}/links")
}

/// A pose graph's drawn vertex estimates, one batch of frames: `world/vertices`.
///
/// ```
/// assert_eq!(posecov::scene::paths::vertices(), "world/vertices");
/// ```
pub fn vertices() -> String {
    format!("{WORLD}/vertices")
}

/// A pose graph's picture before optimisation: the initial labels `world/labels`.
///
/// ```
/// assert_eq!(posecov::scene::paths::initial_labels(), "world/labels");
/// ```
pub fn initial_labels() -> String {
    format!("{WORLD}/labels")
}

/// The subtree of a pose graph's picture after optimisation: `world/optimized`.
///
/// ```
/// assert_eq!(posecov::scene::paths::optimized(), "world/optimized");
/// ```
pub fn optimized() -> String {
    format!("{WORLD}/optimized")
}

/// A pose graph's robot-scale view of `what` (the largest marginal, the worst loop closure):
/// `world/zoom/<what>`, under [`zooms`].
///
/// ```
/// assert_eq!(posecov::scene::paths::zoom("largest_marginal"), "world/zoom/largest_marginal");
/// ```
pub fn zoom(what: &str) -> String {
    child(&zooms(), what)
}

/// The subtree of a pose graph's robot-scale views: `world/zoom`.
///
/// ```
/// assert_eq!(posecov::scene::paths::zooms(), "world/zoom");
/// ```
pub fn zooms() -> String {
    format!("{WORLD}/zoom")
}

/// A graph vertex's entity under `base` (its label or its banana): `base/v<id>`.
///
/// ```
/// assert_eq!(posecov::scene::paths::vertex("world/optimized/labels", 7), "world/optimized/labels/v7");
/// ```
pub fn vertex(base: &str, id: impl std::fmt::Display) -> String {
    format!("{base}/v{id}")
}

/// The relative pose of vertex `b` as vertex `a` sees it: `world/optimized/relative/v<a>_v<b>`.
///
/// ```
/// assert_eq!(posecov::scene::paths::relative(5, 9), "world/optimized/relative/v5_v9");
/// ```
pub fn relative(a: impl std::fmt::Display, b: impl std::fmt::Display) -> String {
    format!("{}/relative/v{a}_v{b}", optimized())
}

/// The entity under which a robot log's topic is drawn: `world/` and its name's segments
/// ([`topic_segments`]).
///
/// ```
/// assert_eq!(posecov::scene::paths::topic("/amcl pose"), "world/amcl_pose");
/// ```
pub fn topic(name: &str) -> String {
    format!("{WORLD}/{}", topic_segments(name))
}

/// A topic name's entity segments: `/a/b` → `a/b`; characters other than letters, digits,
/// `_`, `-` and `.` → `_`; a name without segments → `root` (a topic's series segment under
/// its plots, and its subtree under [`WORLD`]).
///
/// ```
/// use posecov::scene::paths::topic_segments;
/// assert_eq!(topic_segments("/a b/c"), "a_b/c");
/// assert_eq!(topic_segments("/"), "root");
/// ```
pub fn topic_segments(name: &str) -> String {
    let cleaned: Vec<String> = name
        .split('/')
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || "_-.".contains(c) {
                        c
                    } else {
                        '_'
                    }
                })
                .collect()
        })
        .collect();
    if cleaned.is_empty() {
        "root".into()
    } else {
        cleaned.join("/")
    }
}

/// A topic's robot view (the selected message at the robot's scale): `world/<topic>/robot`.
///
/// ```
/// assert_eq!(posecov::scene::paths::robot("/odom"), "world/odom/robot");
/// ```
pub fn robot(topic_name: &str) -> String {
    child(&topic(topic_name), "robot")
}

/// A NavSatFix topic's fixes in the local East-North plane at its first fix:
/// `world/<topic>/fixes`.
///
/// ```
/// assert_eq!(posecov::scene::paths::fixes("/gps/fix"), "world/gps/fix/fixes");
/// ```
pub fn fixes(topic_name: &str) -> String {
    child(&topic(topic_name), "fixes")
}

/// An IMU topic's orientation spray (SO(3) samples at one message):
/// `world/<topic>/orientation_spray`.
///
/// ```
/// assert_eq!(posecov::scene::paths::orientation_spray("/imu"), "world/imu/orientation_spray");
/// ```
pub fn orientation_spray(topic_name: &str) -> String {
    child(&topic(topic_name), "orientation_spray")
}

/// A plot's entity: `plots/<plot>`.
///
/// ```
/// use posecov::scene::{PlotId, paths};
/// assert_eq!(paths::plot(&PlotId::new("trace")), "plots/trace");
/// ```
pub fn plot(id: &PlotId) -> String {
    format!("{PLOTS}/{id}")
}

/// A series' entity: `plots/<plot>/<segment>`, or `plots/<plot>/g<N>/<segment>` for the
/// `N`-th generation of a restreamed scene (each evaluation's lines apart, so the viewer's
/// plot does not join an old line to a new one).
///
/// ```
/// use posecov::scene::{PlotId, paths};
/// let trace = PlotId::new("trace");
/// assert_eq!(paths::series(&trace, None, "first_order"), "plots/trace/first_order");
/// assert_eq!(paths::series(&trace, Some(3), "first_order"), "plots/trace/g3/first_order");
/// ```
pub fn series(plot: &PlotId, generation: Option<u64>, segment: &str) -> String {
    match generation {
        None => format!("{PLOTS}/{plot}/{segment}"),
        Some(g) => format!("{PLOTS}/{plot}/g{g}/{segment}"),
    }
}

/// What a scene item was drawn from, as data: a plan's node, or a robot log's topic and, for
/// an item of one message, that message (its index in the topic and its stamp). The app names
/// the place of an undrawable item from it, never from the item's entity path.
///
/// ```
/// use posecov::scene::Origin;
/// assert_eq!(Origin::Node("T_MC".into()).to_string(), "pose T_MC");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A scenario's pose or a pose graph's node, by name.
    Node(String),
    /// A topic of a robot log.
    Topic {
        /// The topic's name, as the log spells it.
        topic: String,
        /// The message the item shows; `None` for a topic's overview (trajectory, history).
        message: Option<MessageOrigin>,
    },
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::Node(name) => write!(f, "pose {name}"),
            Origin::Topic {
                topic,
                message: None,
            } => write!(f, "topic {topic}"),
            Origin::Topic {
                topic,
                message: Some(m),
            } => write!(f, "topic {topic}, message {}", m.index),
        }
    }
}

/// One message of a topic: its index among the topic's messages and its stamp.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MessageOrigin {
    /// Index among the topic's messages (0-based, as health findings count).
    pub index: u64,
    /// Header stamp, nanoseconds.
    pub stamp_ns: i64,
}
