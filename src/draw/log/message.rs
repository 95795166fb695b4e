//! One drawn message, wherever it is drawn: its frame, RViz's picture, what the numbers mean
//! (the banana, the Cartesian ellipsoid, a cloud; 3-D: the sampled axis tips) or a red cross
//! for an unusable message. The whole-trajectory view draws it where it is; the robot view
//! ([`super::robot`]) draws it at the origin, shifted by its own position. Also the faint
//! static overview of every drawn message (`history/`).

use nalgebra::{UnitQuaternion, Vector2, Vector3};

use super::super::shapes::{self, AXIS_COLORS};
use super::super::{Painter, v3};
use super::rviz::{rviz_picture, rviz_position};
use super::{INVALID, MEANING, RVIZ, flat};
use crate::eval::log::{PoseEvaluation, PoseState, TopicEvaluation};
use crate::lie::{GroupKind, LieGroup, Se2, Se3};
use crate::scene::{
    Ellipsoid, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, MessageOrigin, Origin,
    PointCloud, Swatch, Timing, Vec3, paths,
};
use crate::uncertain::{Method, Side, UncertainPose};

/// Where a message is drawn (at its stamp): under `base`, with `shift` subtracted from every
/// position (zero in the whole-trajectory view; the message's own position in the robot view,
/// which puts it at the origin: X ↦ T(−shift) · X keeps a right-form covariance as it is).
pub(super) struct Placement<'a> {
    /// Entity path of the drawing.
    pub base: &'a str,
    /// Subtracted from every position.
    pub shift: Vector3<f64>,
    /// The frame's label, if any.
    pub label: Option<String>,
    /// Whether RViz's note on a clipped placeholder is said on its shape (where no frame label
    /// is, and only by one topic of a view: [`rviz_noting`](super::rviz_noting)).
    pub rviz_note: bool,
}

/// Draws one message of topic `t` at `place` (see the [module docs](self)).
pub(super) fn message(
    p: &mut Painter,
    place: &Placement,
    t: &TopicEvaluation,
    pose: &PoseEvaluation,
    mean: &Se3,
) {
    // Every item of this message carries it as its origin (an undrawable one is reported there).
    if let Some(Origin::Topic { message, .. }) = &mut p.origin {
        *message = Some(MessageOrigin {
            index: pose.index,
            stamp_ns: pose.stamp_ns,
        });
    }
    let base = place.base;
    let at = Timing::Stamp(pose.stamp_ns);
    let origin = flat(t.group.is_planar(), &(mean.translation() - place.shift));
    let radii = (
        p.confidence().radius(t.group.position_dims()),
        p.confidence().radius(2),
        p.confidence().radius(1),
    );
    // RViz's note on a clipped placeholder labels its shape where no frame label is (the
    // whole-log view, one topic of it); the robot view's frame label is the message's σ.
    if let Some(rviz) = &pose.rviz {
        let label_shape = place.label.is_none() && place.rviz_note;
        rviz_picture(
            p,
            base,
            at,
            mean,
            origin,
            rviz,
            radii,
            t.group.is_planar(),
            label_shape,
        );
    }
    let label = place.label.clone();
    let frame_rotation = if t.group.is_planar() {
        UnitQuaternion::from_euler_angles(0.0, 0.0, mean.rotation().to_rpy()[2])
    } else {
        let [x, y, z, w] = mean.rotation().to_quaternion_xyzw();
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
    };
    p.place(
        paths::child(base, "pose"),
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
            label,
            tag: None,
        }),
    );
    let shift = place.shift;
    match &pose.state {
        PoseState::Planar { pose: g, cloud } => {
            let s = Vector2::new(shift.x, shift.y);
            let moved = |x: &Se2| Se2::from_parts(x.translation() - s, *x.rotation());
            let g = UncertainPose::new_unchecked(moved(g.mean()), *g.cov(), Side::Right);
            let meaning = paths::child(base, "meaning");
            p.region_banana(&meaning, at, &g, MEANING, |x| {
                x.to_se3().translation().to_owned()
            });
            p.region_ellipsoid(&meaning, at, &g, MEANING);
            let points = cloud
                .iter()
                .map(|x| v3(moved(x).to_se3().translation()))
                .collect();
            cloud_item(p, base, at, points);
            sprays(p, base, at, &[]);
            clear_invalid(p, base, at);
        }
        PoseState::Spatial { pose: g, cloud } => {
            let moved = |x: &Se3| Se3::from_parts(x.translation() - shift, *x.rotation());
            let g = UncertainPose::new_unchecked(moved(g.mean()), *g.cov(), Side::Right);
            let meaning = paths::child(base, "meaning");
            p.region_banana(&meaning, at, &g, MEANING, |x| *x.translation());
            p.region_ellipsoid(&meaning, at, &g, MEANING);
            let cloud: Vec<Se3> = cloud.iter().map(moved).collect();
            let points = cloud.iter().map(|x| v3(x.translation())).collect();
            cloud_item(p, base, at, points);
            sprays(p, base, at, &cloud);
            clear_invalid(p, base, at);
        }
        PoseState::Invalid { .. } => invalid(p, base, at, origin),
    }
    if let Some(Origin::Topic { message, .. }) = &mut p.origin {
        *message = None;
    }
}

/// The faint static overview: RViz's position region and the meaning's banana outline of
/// every drawn message.
pub(super) fn history(p: &mut Painter, base: &str, t: &TopicEvaluation) {
    let r = p.confidence().radius(t.group.position_dims());
    let axis_length = p.axis_length;
    let shapes_rviz: Vec<Ellipsoid> = t
        .poses
        .iter()
        .filter(|q| q.state.is_drawable())
        .filter_map(|q| {
            let rviz = q.rviz.as_ref()?;
            let mean = q.mean?;
            let c = Vector3::from(flat(t.group.is_planar(), mean.translation()));
            // A planar topic's overview shows RViz's ellipse in the plane (its 3-D shape of a
            // placeholder is drawn, clipped, at the current stamp only).
            let mut flat_rviz = *rviz;
            flat_rviz.pose_2d |= t.group.is_planar();
            Some(rviz_position(&flat_rviz, &c, r, axis_length, t.group.is_planar()).0)
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
        paths::child(base, "history/rviz"),
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
        paths::child(base, "history/meaning"),
        Timing::Static,
        ItemKind::LineStrips(LineStrips {
            strips,
            color: MEANING.with_alpha(90),
            radius: 0.001 * p.axis_length / 0.15,
        }),
    );
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
        paths::child(base, "meaning/cloud"),
        at,
        ItemKind::Points(PointCloud {
            positions,
            color: super::super::cloud_color(),
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
            paths::child(base, &format!("meaning/spray_{name}")),
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
        paths::child(base, "invalid"),
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
    p.place(
        paths::child(base, "meaning/banana_outline"),
        at,
        empty_strips(),
    );
    p.place(
        paths::child(base, "meaning/ellipsoid"),
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
        paths::child(base, "meaning/banana"),
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
        paths::child(base, "invalid"),
        at,
        ItemKind::LineStrips(LineStrips {
            strips: Vec::new(),
            color: INVALID,
            radius: 0.001,
        }),
    );
}
