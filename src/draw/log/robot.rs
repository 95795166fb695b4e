//! The view at the robot's scale: beside the whole trajectory, each topic's selected message
//! (the one at the time cursor) drawn at the origin (`world/<topic>/robot/…`, shifted by its own
//! position; axes stay the parent frame's), its banana, RViz's picture and its σ numbers on the
//! pose. Its camera is fitted to the last drawn message (where a recording opens), so that a
//! σ of a few centimetres fills the view; other messages keep their true size.

use nalgebra::Vector3;

use super::super::Painter;
use super::message::{Placement, message};
use crate::eval::log::{PoseEvaluation, PoseState, TopicEvaluation};
use crate::plan::log::{PLACEHOLDER, ROS_AXES};
use crate::scene::paths;

/// A σ in words at its scale: mm below 1 m, else m; degrees for angles (mrad below 0.1°).
fn sigma_words(axis: usize, sigma: f64) -> String {
    let name = ROS_AXES[axis];
    if axis < 3 {
        if sigma < 1.0 {
            format!("σ{name} {:.1} mm", sigma * 1e3)
        } else {
            format!("σ{name} {sigma:.3} m")
        }
    } else if sigma.to_degrees() < 0.1 {
        format!("σ{name} {:.2} mrad", sigma * 1e3)
    } else {
        format!("σ{name} {:.2}°", sigma.to_degrees())
    }
}

/// The label of a message in the robot view: its number and σ per estimated axis (x, y, yaw
/// when planar), "placeholder" for an axis that is one.
fn label(t: &TopicEvaluation, pose: &PoseEvaluation) -> String {
    let axes: &[usize] = if t.group.is_planar() {
        &[0, 1, 5]
    } else {
        &[0, 1, 2, 3, 4, 5]
    };
    let parts: Vec<String> = axes
        .iter()
        .map(|&i| match pose.sigma[i] {
            Some(s) => sigma_words(i, s),
            None => format!("σ{} –", ROS_AXES[i]),
        })
        .collect();
    let state = match &pose.state {
        PoseState::Invalid { .. } => " (unusable)",
        _ => "",
    };
    format!("message {}{state}: {}", pose.index, parts.join(", "))
}

/// The robot-scale length of a message: its position region's largest estimated half-size
/// (RViz's numbers; placeholders aside), at least 1 mm; `None` when it has none.
fn scale(pose: &PoseEvaluation, r: f64) -> Option<f64> {
    let rviz = pose.rviz.as_ref()?;
    let largest = (0..3)
        .map(|i| rviz.position_cov[(i, i)])
        .filter(|v| *v < PLACEHOLDER)
        .fold(0.0, f64::max);
    (largest > 0.0).then(|| (r * largest.sqrt()).max(1e-3))
}

/// Draws topic `t`'s robot view under its topic's `robot` entity ([`paths::robot`], see the
/// [module docs](self)).
pub(super) fn robot_view(p: &mut Painter, t: &TopicEvaluation) {
    let world_axis = p.axis_length;
    let r = p.confidence().radius(t.group.position_dims());
    let robot_base = paths::robot(&t.name);
    let mut last_scale = None;
    for pose in &t.poses {
        let Some(mean) = pose.mean else {
            continue;
        };
        let s = scale(pose, r).or(last_scale).unwrap_or(0.1 * world_axis);
        last_scale = Some(s);
        // Axes a little longer than the region, so the yaw fan and the discs stand out.
        p.axis_length = 1.3 * s;
        let shift: Vector3<f64> = *mean.translation();
        let place = Placement {
            base: &robot_base,
            shift: if t.group.is_planar() {
                Vector3::new(shift.x, shift.y, 0.0)
            } else {
                shift
            },
            label: Some(label(t, pose)),
            rviz_note: false,
        };
        message(p, &place, t, pose, &mean);
    }
    p.axis_length = world_axis;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigma_words_pick_a_readable_unit() {
        assert_eq!(sigma_words(0, 0.001f64.sqrt()), "σx 31.6 mm");
        assert_eq!(sigma_words(1, 2.5), "σy 2.500 m");
        assert_eq!(sigma_words(5, 0.03f64.sqrt()), "σyaw 9.92°");
        assert_eq!(sigma_words(3, 0.001), "σroll 1.00 mrad");
    }
}
