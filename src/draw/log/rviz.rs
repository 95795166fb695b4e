//! RViz's picture of one message (its `CovarianceVisual`): the position block's ellipsoid (an
//! ellipse when RViz takes the pose as 2-D) and the orientation discs or yaw fan. A placeholder
//! axis (σ² ≥ 1e6, "not estimated") is drawn as RViz draws it but clipped, and labelled: RViz
//! would draw it kilometres long.

use nalgebra::{Matrix2, Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};

use super::super::shapes::{AXIS_COLORS, ellipsoid_of};
use super::super::{Painter, v3};
use super::RVIZ;
use crate::eval::log::RvizNumbers;
use crate::lie::{LieGroup, Se3};
use crate::plan::log::{PLACEHOLDER, ROS_AXES};
use crate::scene::{Ellipsoid, Ellipsoids, FillMode, ItemKind, LineStrips, Timing, Vec3, paths};

/// RViz bounds the drawn angular spread at 89°.
const RVIZ_MAX_ANGLE: f64 = 89.0 * std::f64::consts::PI / 180.0;
/// A placeholder axis is clipped at this many times the largest estimated half-size.
const PLACEHOLDER_CLIP: f64 = 3.0;

/// The position block RViz draws (its x–y block alone when it takes the pose as 2-D) and its
/// placeholder axes (σ² ≥ [`PLACEHOLDER`]), which [`rviz_position`] clips and labels.
fn position_block(rviz: &RvizNumbers, planar: bool) -> (Matrix3<f64>, Vec<usize>) {
    let mut cov = rviz.position_cov;
    let flat_2d = rviz.pose_2d || planar && rviz.position_cov[(2, 2)] <= 0.0;
    if flat_2d {
        cov.row_mut(2).fill(0.0);
        cov.column_mut(2).fill(0.0);
    }
    let placeholders = (0..3).filter(|&i| cov[(i, i)] >= PLACEHOLDER).collect();
    (cov, placeholders)
}

/// Whether RViz's position shape of this message has a clipped placeholder axis (then
/// [`rviz_position`] returns its label).
pub(super) fn has_clipped_axis(rviz: &RvizNumbers, planar: bool) -> bool {
    !position_block(rviz, planar).1.is_empty()
}

/// RViz's position shape: the 3-D ellipsoid of the parent-frame position block, or the
/// ellipse of its x–y block when RViz takes the pose as 2-D. An axis whose variance is a
/// placeholder (≥ 1e6) is drawn clipped at [`PLACEHOLDER_CLIP`] × the largest estimated
/// half-size (or `fallback` when no axis is estimated), its correlations dropped, and the label
/// says so. (Decomposing the matrix with the 1e6 in place loses the small axes: an eigen
/// solver's error is relative to the largest entry, and gave test2.bag's 3 cm σ as 10 m.)
/// Returns the shape and the label.
pub(super) fn rviz_position(
    rviz: &RvizNumbers,
    center: &Vector3<f64>,
    r: f64,
    fallback: f64,
    planar: bool,
) -> (Ellipsoid, Option<String>) {
    let (cov, placeholders) = position_block(rviz, planar);
    if placeholders.is_empty() {
        return (ellipsoid_of(center, &cov, r), None);
    }
    let label = format!(
        "RViz: {} placeholder (σ² ≥ 1e6), clipped",
        placeholders
            .iter()
            .map(|&i| ROS_AXES[i])
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut estimated = cov;
    for &i in &placeholders {
        estimated.row_mut(i).fill(0.0);
        estimated.column_mut(i).fill(0.0);
    }
    let largest = ellipsoid_of(center, &estimated, r)
        .half_sizes
        .into_iter()
        .fold(0.0, f64::max);
    let limit = if largest > 0.0 {
        PLACEHOLDER_CLIP * largest
    } else {
        fallback
    };
    for &i in &placeholders {
        estimated[(i, i)] = (limit / r).powi(2);
    }
    (ellipsoid_of(center, &estimated, r), Some(label))
}

/// RViz's picture of one message at `origin`: its position shape (radius `r_pos`) and its
/// orientation — the yaw fan (± `r_fan` σ_yaw, bounded at 89°) when 2-D, else a disc at each
/// axis tip (tan of the angular spread, radius `r_disc`). Axes are `p.axis_length` long.
/// A clipped placeholder axis is said on the shape when `label_shape`.
#[allow(clippy::too_many_arguments)]
pub(super) fn rviz_picture(
    p: &mut Painter,
    base: &str,
    at: Timing,
    mean: &Se3,
    origin: Vec3,
    rviz: &RvizNumbers,
    (r_pos, r_disc, r_fan): (f64, f64, f64),
    planar: bool,
    label_shape: bool,
) {
    let center = Vector3::from(origin);
    let l = p.axis_length;
    let (shape, note) = rviz_position(rviz, &center, r_pos, l, planar);
    p.place(
        paths::child(base, "rviz/position"),
        at,
        ItemKind::Ellipsoids(Ellipsoids {
            shapes: vec![shape],
            color: RVIZ,
            fill: FillMode::MajorWireframe,
            line_radius: 0.0015 * l / 0.15,
            label: note.filter(|_| label_shape),
        }),
    );
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
            paths::child(base, "rviz/orientation"),
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
        // A placeholder angle (σ² ≥ 1e6) is RViz's 89° bound, tan 89° = 57 axis lengths:
        // drawn clipped, like a placeholder position axis.
        let spread = |lambda: f64| {
            let angle = (r_disc * lambda.max(0.0).sqrt()).min(RVIZ_MAX_ANGLE);
            l * if lambda >= PLACEHOLDER {
                PLACEHOLDER_CLIP
            } else {
                angle.tan()
            }
        };
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(frame));
        let h = [spread(eig.eigenvalues[0]), spread(eig.eigenvalues[1])];
        let thin = 0.01 * h[0].max(h[1]).max(1e-6);
        p.place(
            paths::child(base, &format!("rviz/orientation_{}", ["x", "y", "z"][axis])),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_placeholder_axis_is_clipped_and_labelled() {
        // test2.bag: Σxx = Σyy = 0.001 m², Σzz = 1e6 (RViz draws it 3-D: Σzz > 0).
        let rviz = RvizNumbers {
            position_cov: Matrix3::from_diagonal(&Vector3::new(0.001, 0.001, 1e6)),
            rotation_cov: Matrix3::from_diagonal(&Vector3::new(1e6, 1e6, 0.03)),
            pose_2d: false,
        };
        let r = 2.0;
        let (shape, label) = rviz_position(&rviz, &Vector3::zeros(), r, 1.0, false);
        let mut h = shape.half_sizes;
        h.sort_by(f64::total_cmp);
        let xy = r * 0.001f64.sqrt();
        assert!(
            (h[0] - xy).abs() < 1e-12 && (h[1] - xy).abs() < 1e-12,
            "{h:?}"
        );
        assert!((h[2] - PLACEHOLDER_CLIP * xy).abs() < 1e-12, "{h:?}");
        assert_eq!(
            label.as_deref(),
            Some("RViz: z placeholder (σ² ≥ 1e6), clipped")
        );
        // Estimated axes only: unclipped, no label.
        let small = RvizNumbers {
            position_cov: Matrix3::identity() * 0.01,
            ..rviz
        };
        assert_eq!(
            rviz_position(&small, &Vector3::zeros(), r, 1.0, false).1,
            None
        );
    }
}
