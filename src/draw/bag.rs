//! A robot log's scene ([`BagEvaluation`] → [`Scene`]) on the `stamp` timeline: per topic
//! (entity `world/<topic>/…`)
//! - `trajectory`: every (bounded) position, static; `history/rviz` and `history/meaning`:
//!   the position regions of every drawn message, faint, static;
//! - at each drawn message's stamp: `pose` (its frame), **RViz's picture** under `rviz/`
//!   (`position`: the ellipsoid of the parent-frame position block — an ellipse when RViz
//!   takes the pose as 2-D, i.e. Σzz, Σroll, Σpitch ≤ 0; `orientation`: RViz's per-axis
//!   discs at the axis tips, tan of the angular spread, or its yaw fan in 2-D), and **what the
//!   numbers mean** under `meaning/` (the body-frame right-form Gaussian's Exp-mapped
//!   `banana`, its `ellipsoid` and a sampled `cloud`; 3-D: the sampled axis tips `spray_x|y|z`);
//!   an unusable message is a red cross at `invalid` and clears the rest;
//! - plots over the stamp: σx σy σz (m), σroll σpitch σyaw (rad) and the position trace (m²).
//!
//! All regions at the chosen confidence: χ²(d) with d = 2 / 3 (planar position, pose) or
//! 3 / 6 (3-D), and d = 2 for RViz's discs, 1 for its yaw fan.

use nalgebra::{Matrix2, Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};

use super::shapes::{self, AXIS_COLORS, ellipsoid_of};
use super::{Painter, v3, views};
use crate::eval::bag::{BagEvaluation, PoseState, RvizNumbers, TopicEvaluation};
use crate::input::{About, Layout};
use crate::lie::{GroupKind, LieGroup, Se3};
use crate::scene::WORLD;
use crate::scene::{
    Color, Ellipsoid, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, PointCloud, Scene, Swatch,
    Timeline, Timing, Vec3,
};
use crate::uncertain::{Confidence, Method};

mod plots;
mod text;

pub use text::{description, issue_sentence, issue_word};

/// RViz's default covariance colour (its position shape).
const RVIZ: Color = Color::rgb(204, 51, 204);
/// The meaning (right-form Gaussian) colour.
const MEANING: Color = Method::FirstOrder.color();
/// Unusable messages.
const INVALID: Color = Color::rgb(230, 30, 30);
/// RViz bounds the drawn angular spread at 89°.
const RVIZ_MAX_ANGLE: f64 = 89.0 * std::f64::consts::PI / 180.0;

/// What drawing a log needs.
#[derive(Debug, Clone, PartialEq)]
pub struct BagDrawSettings {
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
/// use posecov::draw::bag::{BagDrawSettings, bag_scene, description};
/// use posecov::eval::bag::{BagEvalSettings, evaluate_bag};
/// use posecov::input::{About, Format, bag::{BagOptions, read_bag}};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
/// let plan = read_bag(path.as_ref(), &BagOptions::default(), &mut |_, _| {}, None).unwrap();
/// let e = evaluate_bag(&plan, &BagEvalSettings::default());
/// let about = About { title: "test2.bag".into(), description: String::new(), source: String::new() };
/// let settings = BagDrawSettings { about, confidence: posecov::uncertain::Confidence::DEFAULT, axis_length: None };
/// let scene = bag_scene(&e, &settings, &description(&plan, Format::Ros1Bag, &e, posecov::uncertain::Confidence::DEFAULT));
/// assert!(scene.validate().is_ok());
/// assert!(scene.items.iter().any(|i| i.path == "world/jackal_velocity_controller/odom/meaning/banana"));
/// ```
pub fn bag_scene(e: &BagEvaluation, settings: &BagDrawSettings, summary: &str) -> Scene {
    let extent = extent(e);
    let axis_length = settings
        .axis_length
        .unwrap_or((0.08 * extent).clamp(0.05, 2.0));
    let planar = !e.topics.is_empty() && e.topics.iter().all(|t| t.planar);
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
    };
    p.scene.planar = planar;
    p.scene.confidence = Some(settings.confidence);
    for (k, topic) in e.topics.iter().enumerate() {
        draw_topic(&mut p, k, topic);
    }
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
    p.scene.timeline = Timeline::for_stamps(stamps.chain(series));
    plots::plots(&mut p.scene, e);
    // Views and cameras as for every scene: a planar log from straight above.
    let plan = views::ViewInputs {
        poses: &p.methods,
        rotation_only: false,
        top: planar,
        layout: p.layout,
        camera: None,
    };
    p.scene.views = views::views(&p.scene, &plan);
    p.scene
}

/// The entity path under which a topic is drawn: `world/` and its name's segments (`/a/b` →
/// `world/a/b`; characters other than letters, digits, `_`, `-` and `.` → `_`).
///
/// ```
/// assert_eq!(posecov::draw::bag::topic_entity("/amcl pose"), "world/amcl_pose");
/// ```
pub fn topic_entity(name: &str) -> String {
    format!("{WORLD}/{}", topic_path(name))
}

/// An entity path segment list for a topic name (`/a/b` → `a/b`; other characters → `_`).
fn topic_path(name: &str) -> String {
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

fn extent(e: &BagEvaluation) -> f64 {
    let points: Vec<Vector3<f64>> = e
        .topics
        .iter()
        .flat_map(|t| t.trajectory.iter().map(|(_, p)| Vector3::from(*p)))
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    super::extent_of(&points)
}

fn flat(planar: bool, v: &Vector3<f64>) -> Vec3 {
    if planar { [v.x, v.y, 0.0] } else { v3(v) }
}

fn draw_topic(p: &mut Painter, k: usize, t: &TopicEvaluation) {
    let base = topic_entity(&t.name);
    let color = Method::ALL[k % Method::ALL.len()].color();
    let strip: Vec<Vec3> = t
        .trajectory
        .iter()
        .map(|(_, q)| flat(t.planar, &Vector3::from(*q)))
        .filter(|q| q.iter().all(|v| v.is_finite()))
        .collect();
    if !strip.is_empty() {
        p.legend(format!("{}: trajectory", t.name), color, Swatch::Line);
        p.place(
            format!("{base}/trajectory"),
            Timing::Static,
            ItemKind::LineStrips(LineStrips {
                strips: vec![strip],
                color: color.with_alpha(220),
                radius: 0.003 * p.extent,
            }),
        );
    }
    history(p, &base, t);
    let r_pos = p.confidence().radius(t.position_dof);
    let r_disc = p.confidence().radius(2);
    let r_fan = p.confidence().radius(1);
    for pose in &t.poses {
        let at = Timing::Stamp(pose.stamp_ns);
        let Some(mean) = pose.mean else {
            continue;
        };
        let origin = flat(t.planar, mean.translation());
        let frame_rotation = if t.planar {
            UnitQuaternion::from_euler_angles(0.0, 0.0, mean.rotation().to_rpy()[2])
        } else {
            {
                let [x, y, z, w] = mean.rotation().to_quaternion_xyzw();
                UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
            }
        };
        p.place(
            format!("{base}/pose"),
            at,
            ItemKind::Frame(Frame {
                translation: origin,
                rotation: [
                    frame_rotation.i,
                    frame_rotation.j,
                    frame_rotation.k,
                    frame_rotation.w,
                ],
                axis_length: p.axis_length,
                label: None,
            }),
        );
        if let Some(rviz) = &pose.rviz {
            rviz_picture(
                p,
                &base,
                at,
                &mean,
                origin,
                rviz,
                (r_pos, r_disc, r_fan),
                t.planar,
            );
        }
        match &pose.state {
            PoseState::Planar { pose: g, cloud } => {
                let meaning = format!("{base}/meaning");
                p.region_banana(&meaning, at, g, MEANING, |x| {
                    x.to_se3().translation().to_owned()
                });
                p.region_ellipsoid(&meaning, at, g, MEANING);
                let points = cloud.iter().map(|x| v3(x.to_se3().translation())).collect();
                cloud_item(p, &base, at, points);
                sprays(p, &base, at, &[]);
                clear_invalid(p, &base, at);
            }
            PoseState::Spatial { pose: g, cloud } => {
                let meaning = format!("{base}/meaning");
                p.region_banana(&meaning, at, g, MEANING, |x| *x.translation());
                p.region_ellipsoid(&meaning, at, g, MEANING);
                let points = cloud.iter().map(|x| v3(x.translation())).collect();
                cloud_item(p, &base, at, points);
                sprays(p, &base, at, cloud);
                clear_invalid(p, &base, at);
            }
            PoseState::Invalid { .. } => invalid(p, &base, at, origin),
        }
    }
}

/// The faint static overview: RViz's position region and the meaning's banana outline of
/// every drawn message.
fn history(p: &mut Painter, base: &str, t: &TopicEvaluation) {
    let r = p.confidence().radius(t.position_dof);
    let shapes_rviz: Vec<Ellipsoid> = t
        .poses
        .iter()
        .filter(|q| q.state.is_drawable())
        .filter_map(|q| {
            let rviz = q.rviz.as_ref()?;
            let mean = q.mean?;
            let c = Vector3::from(flat(t.planar, mean.translation()));
            // A planar topic's overview shows RViz's ellipse in the plane (its 3-D shape of a
            // placeholder is drawn, clipped, at the current stamp only).
            let mut flat_rviz = *rviz;
            flat_rviz.pose_2d |= t.planar;
            Some(rviz_position(&flat_rviz, &c, r, p.extent, t.planar).0)
        })
        .collect();
    let region = p.confidence().to_string();
    p.legend(
        format!("RViz's picture: the {region} ellipse of the numbers as given"),
        RVIZ,
        Swatch::Dashed,
    );
    p.legend(
        format!("what the covariance means: Exp-mapped {region} region (outlines)"),
        MEANING,
        Swatch::Line,
    );
    p.place(
        format!("{base}/history/rviz"),
        Timing::Static,
        ItemKind::Ellipsoids(Ellipsoids {
            shapes: shapes_rviz,
            color: RVIZ.with_alpha(90),
            fill: FillMode::MajorWireframe,
            line_radius: 0.001 * p.axis_length / 0.15,
            label: None,
        }),
    );
    // One static item with every outline, faint.
    let confidence = p.confidence();
    let strips: Vec<Vec<Vec3>> = t
        .poses
        .iter()
        .flat_map(|q| match &q.state {
            PoseState::Planar { pose, .. } => {
                shapes::outline_strips(pose, confidence, |x| x.to_se3().translation().to_owned())
            }
            PoseState::Spatial { pose, .. } => {
                shapes::outline_strips(pose, confidence, |x| *x.translation())
            }
            PoseState::Invalid { .. } => Vec::new(),
        })
        .collect();
    p.place(
        format!("{base}/history/meaning"),
        Timing::Static,
        ItemKind::LineStrips(LineStrips {
            strips,
            color: MEANING.with_alpha(90),
            radius: 0.001 * p.axis_length / 0.15,
        }),
    );
}

/// RViz's position shape: the 3-D ellipsoid of the parent-frame position block, or the
/// ellipse of its x–y block when RViz takes the pose as 2-D; half sizes clipped at half the
/// scene's size (a 1e6 placeholder would be kilometres). Returns the shape and whether it
/// was clipped.
fn rviz_position(
    rviz: &RvizNumbers,
    center: &Vector3<f64>,
    r: f64,
    extent: f64,
    planar: bool,
) -> (Ellipsoid, bool) {
    let mut cov = rviz.position_cov;
    let flat_2d = rviz.pose_2d || planar && rviz.position_cov[(2, 2)] <= 0.0;
    if flat_2d {
        cov.row_mut(2).fill(0.0);
        cov.column_mut(2).fill(0.0);
    }
    let mut shape = ellipsoid_of(center, &cov, r);
    let limit = 0.5 * extent;
    let clipped = shape.half_sizes.iter().any(|h| *h > limit);
    for h in &mut shape.half_sizes {
        *h = h.min(limit);
    }
    (shape, clipped)
}

#[allow(clippy::too_many_arguments)]
fn rviz_picture(
    p: &mut Painter,
    base: &str,
    at: Timing,
    mean: &Se3,
    origin: Vec3,
    rviz: &RvizNumbers,
    (r_pos, r_disc, r_fan): (f64, f64, f64),
    planar: bool,
) {
    let center = Vector3::from(origin);
    let (shape, _) = rviz_position(rviz, &center, r_pos, p.extent, planar);
    p.place(
        format!("{base}/rviz/position"),
        at,
        ItemKind::Ellipsoids(Ellipsoids {
            shapes: vec![shape],
            color: RVIZ,
            fill: FillMode::MajorWireframe,
            line_radius: 0.0015 * p.axis_length / 0.15,
            label: None,
        }),
    );
    let l = p.axis_length;
    if rviz.pose_2d || planar {
        // The yaw fan: ± r σ_yaw around the x axis, bounded at 89°.
        let yaw = mean.rotation().to_rpy()[2];
        let half = (r_fan * rviz.rotation_cov[(2, 2)].max(0.0).sqrt()).min(RVIZ_MAX_ANGLE);
        let tip = |a: f64| [origin[0] + l * a.cos(), origin[1] + l * a.sin(), origin[2]];
        let arc: Vec<Vec3> = (0..=24)
            .map(|i| tip(yaw - half + 2.0 * half * i as f64 / 24.0))
            .collect();
        let mut fan = vec![origin];
        fan.extend(arc);
        fan.push(origin);
        p.place(
            format!("{base}/rviz/orientation"),
            at,
            ItemKind::LineStrips(LineStrips {
                strips: vec![fan],
                color: AXIS_COLORS[2],
                radius: 0.0015 * l / 0.15,
            }),
        );
        return;
    }
    // 3-D: a disc at each body axis tip, from the 2 × 2 block of the other two angles.
    let rot = mean.rotation().to_matrix();
    let blocks = [(1, 2), (0, 2), (0, 1)];
    for (axis, (a, b)) in blocks.into_iter().enumerate() {
        let c = &rviz.rotation_cov;
        let m = Matrix2::new(c[(a, a)], c[(a, b)], c[(b, a)], c[(b, b)]);
        let eig = SymmetricEigen::new(m);
        let dir = |v: nalgebra::Vector2<f64>| {
            let mut t = Vector3::zeros();
            t[a] = v[0];
            t[b] = v[1];
            rot * t
        };
        let u = dir(eig.eigenvectors.column(0).into_owned());
        let w = dir(eig.eigenvectors.column(1).into_owned());
        let n = rot.column(axis).into_owned();
        let mut frame = Matrix3::from_columns(&[u, w, n]);
        if frame.determinant() < 0.0 {
            frame.set_column(1, &(-w));
        }
        let spread = |lambda: f64| l * (r_disc * lambda.max(0.0).sqrt()).min(RVIZ_MAX_ANGLE).tan();
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(frame));
        let h = [spread(eig.eigenvalues[0]), spread(eig.eigenvalues[1])];
        let thin = 0.01 * h[0].max(h[1]).max(1e-6);
        p.place(
            format!("{base}/rviz/orientation_{}", ["x", "y", "z"][axis]),
            at,
            ItemKind::Ellipsoids(Ellipsoids {
                shapes: vec![Ellipsoid {
                    center: v3(&(center + l * n)),
                    half_sizes: [h[0].max(thin), h[1].max(thin), thin],
                    rotation: [q.i, q.j, q.k, q.w],
                }],
                color: AXIS_COLORS[axis].with_alpha(160),
                fill: FillMode::TransparentFillMajorWireframe,
                line_radius: 0.001 * l / 0.15,
                label: None,
            }),
        );
    }
}

fn cloud_item(p: &mut Painter, base: &str, at: Timing, positions: Vec<Vec3>) {
    if !positions.is_empty() {
        p.legend(
            "samples of what the covariance means".to_owned(),
            Method::MonteCarlo.color(),
            Swatch::Dots,
        );
    }
    p.place(
        format!("{base}/meaning/cloud"),
        at,
        ItemKind::Points(PointCloud {
            positions,
            color: super::cloud_color(),
            radius: 0.05 * p.axis_length,
        }),
    );
}

/// The sampled axis tips of a 3-D cloud (what RViz's discs try to say); empty for planar.
fn sprays(p: &mut Painter, base: &str, at: Timing, cloud: &[Se3]) {
    if p.kind == GroupKind::Se2 {
        return;
    }
    let l = p.axis_length;
    for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
        let positions = cloud
            .iter()
            .map(|x| v3(&(x.translation() + l * x.rotation().to_matrix().column(axis))))
            .collect();
        p.place(
            format!("{base}/meaning/spray_{name}"),
            at,
            ItemKind::Points(PointCloud {
                positions,
                color: AXIS_COLORS[axis].with_alpha(150),
                radius: 0.03 * l,
            }),
        );
    }
}

/// An unusable message: a red cross; the meaning's shapes are cleared until the next one.
fn invalid(p: &mut Painter, base: &str, at: Timing, origin: Vec3) {
    p.legend(
        "an unusable message (red cross)".to_owned(),
        INVALID,
        Swatch::Line,
    );
    let s = 0.5 * p.axis_length;
    let [x, y, z] = origin;
    p.place(
        format!("{base}/invalid"),
        at,
        ItemKind::LineStrips(LineStrips {
            strips: vec![
                vec![[x - s, y - s, z], [x + s, y + s, z]],
                vec![[x - s, y + s, z], [x + s, y - s, z]],
            ],
            color: INVALID,
            radius: 0.004 * p.axis_length / 0.15,
        }),
    );
    let empty_strips = || {
        ItemKind::LineStrips(LineStrips {
            strips: Vec::new(),
            color: MEANING,
            radius: 0.001,
        })
    };
    p.place(format!("{base}/meaning/banana_outline"), at, empty_strips());
    p.place(
        format!("{base}/meaning/ellipsoid"),
        at,
        ItemKind::Ellipsoids(Ellipsoids {
            shapes: Vec::new(),
            color: MEANING,
            fill: FillMode::MajorWireframe,
            line_radius: 0.001,
            label: None,
        }),
    );
    p.place(
        format!("{base}/meaning/banana"),
        at,
        ItemKind::Surface(crate::scene::Surface {
            vertices: Vec::new(),
            triangles: Vec::new(),
            normals: Vec::new(),
            color: MEANING,
        }),
    );
    cloud_item(p, base, at, Vec::new());
    sprays(p, base, at, &[]);
}

fn clear_invalid(p: &mut Painter, base: &str, at: Timing) {
    p.place(
        format!("{base}/invalid"),
        at,
        ItemKind::LineStrips(LineStrips {
            strips: Vec::new(),
            color: INVALID,
            radius: 0.001,
        }),
    );
}
