//! A robot log's scene ([`LogEvaluation`] → [`Scene`]) on the `stamp` timeline: per topic
//! (entity `world/<topic>/…`)
//! - `trajectory`: every (bounded) position, static; `history/rviz` and `history/meaning`:
//!   the position regions of every drawn message, faint, static;
//! - at each drawn message's stamp: `pose` (its frame), **RViz's picture** under `rviz/`
//!   (`position`: the ellipsoid of the parent-frame position block — an ellipse when RViz
//!   takes the pose as 2-D, i.e. Σzz, Σroll, Σpitch ≤ 0; a placeholder axis clipped and
//!   labelled; `orientation`: RViz's per-axis discs at the axis tips, tan of the angular
//!   spread, or its yaw fan in 2-D), and **what the numbers mean** under `meaning/` (the
//!   body-frame right-form Gaussian's Exp-mapped `banana`, its `ellipsoid` and a sampled
//!   `cloud`; 3-D: the sampled axis tips `spray_x|y|z`); an unusable message is a red cross at
//!   `invalid` and clears the rest (`bag/message.rs`);
//! - `robot/…`: the same message at the origin, at the robot's scale, with its σ (`bag/robot.rs`);
//! - plots over the stamp: σx σy σz, σroll σpitch σyaw and the position trace, in units and
//!   ranges fitted to the data (`bag/plots.rs`); with `--reference`, each topic's NEES per
//!   drawn message with its 95 % bound and ANEES band (`bag/nees.rs`).
//!
//! Views: one whole-log view per frame (`header.frame_id`: topics in different frames are
//! never overlaid as if they were one — unless the log's `/tf` joins them, then they share
//! the common frame's view, `eval::log::frames`, said in the panel), and one robot view per topic.
//!
//! All regions at the chosen confidence: χ²(d) with d = 2 / 3 (planar position, pose) or
//! 3 / 6 (3-D), and d = 2 for RViz's discs, 1 for its yaw fan.

use std::collections::BTreeMap;

use nalgebra::Vector3;

use super::{Painter, v3, views};
use crate::eval::log::{LogEvaluation, TopicEvaluation};
use crate::lie::GroupKind;
use crate::plan::choices::{About, Layout};
use crate::scene::layout::views_aspect;
use crate::scene::{
    Color, ItemKind, LineStrips, Origin, Scene, Swatch, Timeline, Timing, Vec3, View3d, paths,
};
use crate::uncertain::{Confidence, Method};

mod frames;
mod message;
mod nees;
mod plots;
mod robot;
mod rviz;
mod sensor;
mod sensor_shapes;
mod text;

pub use frames::frame_problem_sentence;
pub use nees::verdict_word;
pub use plots::message_points;
pub use sensor::sensor_sentence;
pub use text::{description, issue_sentence, issue_word};

/// RViz's default covariance colour (its position shape).
const RVIZ: Color = Color::rgb(204, 51, 204);
/// The meaning (right-form Gaussian) colour.
const MEANING: Color = Method::FirstOrder.color();
/// Unusable messages.
const INVALID: Color = Color::rgb(230, 30, 30);

/// What drawing a log needs.
#[derive(Debug, Clone, PartialEq)]
pub struct LogDrawSettings {
    /// Title and description of the log (the text panel starts with it).
    pub about: About,
    /// Probability inside drawn regions, in (0, 1).
    pub confidence: Confidence,
    /// Length of the frames' axes (m); `None`: from the trajectory's size.
    pub axis_length: Option<f64>,
}

/// The scene of a log's evaluation; `summary` is the health summary's Markdown
/// ([`description`]), written by the caller from the plan.
///
/// ```
/// use posecov::draw::log::{LogDrawSettings, draw_log, description};
/// use posecov::eval::log::{LogEvalSettings, evaluate_log};
/// use posecov::input::{About, log::{LogOptions, read_log}};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
/// let mut plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
/// let e = evaluate_log(&mut plan, &LogEvalSettings::default());
/// let about = About { title: "test2.bag".into(), description: String::new(), source: String::new() };
/// let settings = LogDrawSettings { about, confidence: posecov::uncertain::Confidence::DEFAULT, axis_length: None };
/// let scene = draw_log(&e, &settings, &description(&plan, "ROS 1 bag", &e, posecov::uncertain::Confidence::DEFAULT));
/// assert!(scene.validate().is_ok());
/// use posecov::scene::paths;
/// let topic = paths::topic("/jackal_velocity_controller/odom");
/// assert_eq!(topic, "world/jackal_velocity_controller/odom");
/// assert!(scene.items.iter().any(|i| i.path == paths::child(&topic, "meaning/banana")));
/// // Beside the whole trajectory (84 m), the selected message at the robot's scale, and the
/// // IMU's orientation spray.
/// assert_eq!(scene.views.len(), 3);
/// assert_eq!(scene.views[1].include, vec![paths::child(&topic, "robot")]);
/// assert_eq!(scene.views[2].include, vec![paths::orientation_spray("/imu/data")]);
/// ```
pub fn draw_log(e: &LogEvaluation, settings: &LogDrawSettings, summary: &str) -> Scene {
    super::counted(build(e, settings, summary))
}

/// [`draw_log`], uncounted.
fn build(e: &LogEvaluation, settings: &LogDrawSettings, summary: &str) -> Scene {
    let extent = extent(e);
    let axis_length = settings
        .axis_length
        .unwrap_or((0.08 * extent).clamp(0.05, 2.0));
    let planar = !e.topics.is_empty() && e.topics.iter().all(|t| t.group.is_planar());
    let mut p = Painter {
        scene: Scene::new(settings.about.title.clone(), summary.to_owned()),
        confidence: settings.confidence,
        kind: if planar {
            GroupKind::Se2
        } else {
            GroupKind::Se3
        },
        axis_length,
        extent,
        layout: Layout::Together,
        methods: Vec::new(),
        origin: None,
    };
    p.scene.planar = planar;
    p.scene.plots_below = true;
    p.scene.confidence = Some(settings.confidence);
    let noting = rviz_noting(e);
    for (k, topic) in e.topics.iter().enumerate() {
        draw_topic(&mut p, k, topic, noting.contains(&topic.name.as_str()));
    }
    sensor_shapes::draw_sensor_shapes(&mut p, e);
    // Dates, or durations when the stamps are not dates (simulated time).
    let stamps = p.scene.items.iter().filter_map(|i| match i.timing {
        Timing::Stamp(ns) => Some(ns),
        Timing::Static | Timing::Step(_) => None,
    });
    let series = p
        .scene
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.0));
    let sensors = e
        .sensors
        .iter()
        .flat_map(|t| t.series.iter().map(|q| q.stamp_ns));
    p.scene.timeline = Timeline::for_stamps(stamps.chain(series).chain(sensors));
    plots::plots(&mut p.scene, e);
    nees::plots(&mut p.scene, e);
    sensor::sensor_plots(&mut p.scene, e);
    p.scene.views = log_views(&p.scene, e, planar);
    p.scene
}

/// The frame a topic's poses are in, as its view names it.
fn frame_name(t: &TopicEvaluation) -> &str {
    if t.frame_id.is_empty() {
        "(no frame_id)"
    } else {
        &t.frame_id
    }
}

/// The topics grouped by frame, in frame order: one whole-log view each.
fn by_frame(e: &LogEvaluation) -> BTreeMap<&str, Vec<&TopicEvaluation>> {
    let mut frames: BTreeMap<&str, Vec<&TopicEvaluation>> = BTreeMap::new();
    for t in &e.topics {
        frames.entry(frame_name(t)).or_default().push(t);
    }
    frames
}

/// The topics that say RViz's note on a clipped placeholder in their whole-log view: per view,
/// the first whose RViz shape has a clipped axis. A view's topics are drawn at much the same
/// place (an odometry, its EKF, AMCL: one robot), where the same note from each would be
/// written over the others; every topic's own placeholder finding is in the text panel.
fn rviz_noting(e: &LogEvaluation) -> Vec<&str> {
    by_frame(e)
        .into_values()
        .filter_map(|topics| {
            topics.into_iter().find(|t| {
                t.poses.iter().any(|q| {
                    q.rviz
                        .as_ref()
                        .is_some_and(|r| rviz::has_clipped_axis(r, t.group.is_planar()))
                })
            })
        })
        .map(|t| t.name.as_str())
        .collect()
}

/// The views: per frame the whole log of its topics (their robot views left out), then per
/// topic with a drawn pose its robot view, the camera fitted to its last drawn message (where
/// a recording opens). A planar log is seen from straight above.
fn log_views(scene: &Scene, e: &LogEvaluation, planar: bool) -> Vec<View3d> {
    let inputs = views::ViewInputs {
        poses: &[],
        rotation_only: false,
        top: planar,
        layout: Layout::Together,
        camera: None,
    };
    let mut out = Vec::new();
    for (frame, topics) in by_frame(e) {
        let joined: Vec<String> = topics
            .iter()
            .filter_map(|t| {
                let j = t.joined.as_ref()?;
                Some(format!("{} from {}", t.name, j.from))
            })
            .collect();
        let view = View3d {
            name: if joined.is_empty() {
                format!("frame {frame}: the whole log")
            } else {
                format!(
                    "frame {frame} (+ /tf: {}): the whole log",
                    joined.join(", ")
                )
            },
            include: topics.iter().map(|t| paths::topic(&t.name)).collect(),
            exclude: topics.iter().map(|t| paths::robot(&t.name)).collect(),
            ..Default::default()
        };
        let points = views::points_of(scene, &view, |_| true);
        out.push((view, points));
    }
    for t in &e.topics {
        let Some(last) = t.poses.iter().rev().find(|q| q.mean.is_some()) else {
            continue;
        };
        let view = View3d {
            name: format!("robot scale: {} at the time cursor", t.name),
            include: vec![paths::robot(&t.name)],
            ..Default::default()
        };
        let at = Timing::Stamp(last.stamp_ns);
        let points = views::points_of(scene, &view, |i| i.timing == at);
        out.push((view, points));
    }
    // A sensor's drawing (fixes seen from above, an IMU's spray): its own view.
    let sensors: Vec<_> = sensor_shapes::sensor_views(e)
        .into_iter()
        .map(|(view, top)| {
            let points = sensor_shapes::view_points(scene, &view);
            (view, points, top)
        })
        .collect();
    // Each camera fitted to the shape its view has above the plots.
    let aspect = views_aspect(scene, out.len() + sensors.len());
    let topics = out.into_iter().map(|(mut view, points)| {
        view.camera = views::camera(&points, &inputs, aspect);
        view
    });
    let sensors = sensors.into_iter().map(|(mut view, points, top)| {
        let inputs = views::ViewInputs { top, ..inputs };
        view.camera = views::camera(&points, &inputs, aspect);
        view
    });
    topics.chain(sensors).collect()
}

fn extent(e: &LogEvaluation) -> f64 {
    let points: Vec<Vector3<f64>> = e
        .topics
        .iter()
        .flat_map(|t| t.trajectory.iter().map(|p| Vector3::from(p.position)))
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    super::extent_of(&points)
}

fn flat(planar: bool, v: &Vector3<f64>) -> Vec3 {
    if planar { [v.x, v.y, 0.0] } else { v3(v) }
}

/// Draws topic `t` (number `k`, for its colour): its trajectory, the faint overview, each
/// drawn message in the whole-log view (RViz's placeholder note on the shape when
/// `rviz_note`, [`rviz_noting`]) and its robot view.
fn draw_topic(p: &mut Painter, k: usize, t: &TopicEvaluation, rviz_note: bool) {
    let base = paths::topic(&t.name);
    p.origin = Some(Origin::Topic {
        topic: t.name.clone(),
        message: None,
    });
    let color = Method::ALL[k % Method::ALL.len()].color();
    let strip: Vec<Vec3> = t
        .trajectory
        .iter()
        .map(|q| flat(t.group.is_planar(), &Vector3::from(q.position)))
        .filter(|q| q.iter().all(|v| v.is_finite()))
        .collect();
    if !strip.is_empty() {
        p.legend(format!("{}: trajectory", t.name), color, Swatch::Line);
        p.place(
            paths::child(&base, "trajectory"),
            Timing::Static,
            ItemKind::LineStrips(LineStrips {
                strips: vec![strip],
                color: color.with_alpha(220),
                radius: 0.003 * p.extent,
            }),
        );
    }
    message::history(p, &base, t);
    let place = message::Placement {
        base: &base,
        shift: Vector3::zeros(),
        label: None,
        rviz_note,
    };
    for pose in &t.poses {
        if let Some(mean) = pose.mean {
            message::message(p, &place, t, pose, &mean);
        }
    }
    robot::robot_view(p, t);
    p.origin = None;
}
