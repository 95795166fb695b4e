//! [`Scene::validate`]: nothing non-finite, malformed or misplaced reaches a sink.

use super::{
    Arrows, Ellipsoids, Frame, ItemKind, LineStrips, PLOTS, PointCloud, QUAT_NORM_TOLERANCE,
    QuatXyzw, ScalarSeries, Scene, SceneItem, Surface, Triads, Vec3, WORLD,
};

/// Why a [`Scene`] cannot be drawn. Every variant names the entity path and the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A number is NaN or infinite (or overflows `f32`, the viewer's precision).
    #[error("{path}: {field}[{index}] = {value} is not a finite number (as f32)")]
    NonFinite {
        /// Entity path of the item.
        path: String,
        /// Which field.
        field: &'static str,
        /// Index of the element (flattened for nested data).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A quaternion is not of unit norm.
    #[error(
        "{path}: {field}[{index}] has norm {norm}, expected 1 (±{QUAT_NORM_TOLERANCE}; order [x, y, z, w])"
    )]
    NonUnitQuaternion {
        /// Entity path of the item.
        path: String,
        /// Which field.
        field: &'static str,
        /// Index of the quaternion.
        index: usize,
        /// Its norm.
        norm: f64,
    },
    /// A size, radius or length is negative (or zero where it must be positive).
    #[error("{path}: {field}[{index}] = {value} must be {requirement}")]
    OutOfRange {
        /// Entity path of the item.
        path: String,
        /// Which field.
        field: &'static str,
        /// Index of the element.
        index: usize,
        /// The offending value.
        value: f64,
        /// What it must be (`"> 0"`, `">= 0"`).
        requirement: &'static str,
    },
    /// Two parallel arrays differ in length.
    #[error("{path}: {field} has {got} entries, expected {expected}")]
    LengthMismatch {
        /// Entity path of the item.
        path: String,
        /// Which field.
        field: &'static str,
        /// Its length.
        got: usize,
        /// The length it must have.
        expected: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("{path}: triangle {triangle} refers to vertex {vertex}, but there are {num_vertices}")]
    BadTriangle {
        /// Entity path of the item.
        path: String,
        /// Index of the triangle.
        triangle: usize,
        /// The vertex index.
        vertex: u32,
        /// Number of vertices.
        num_vertices: usize,
    },
    /// An entity path is empty or has an empty or unusual segment.
    #[error("{path:?}: bad entity path: {reason}")]
    BadPath {
        /// The path.
        path: String,
        /// Why.
        reason: &'static str,
    },
    /// An item is outside the subtree the default layout shows for its kind.
    #[error("{path}: a {kind} must be under `{root}/` so the default layout shows it")]
    WrongRoot {
        /// The path.
        path: String,
        /// Kind of item.
        kind: &'static str,
        /// Required root.
        root: &'static str,
    },
    /// A 3-D view's camera cannot be used.
    #[error("3-D view {view:?}: bad camera: {reason}")]
    BadCamera {
        /// The view's name.
        view: String,
        /// Why.
        reason: &'static str,
    },
    /// An item lies under a frame's entity, whose transform would move it.
    #[error("{path}: lies under the frame entity {frame}, whose transform would move it")]
    UnderFrame {
        /// The item's path.
        path: String,
        /// The frame's path.
        frame: String,
    },
}

/// `Ok` when `v` is finite and stays finite as `f32`.
fn finite(path: &str, field: &'static str, index: usize, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && (v as f32).is_finite() {
        Ok(())
    } else {
        Err(SceneError::NonFinite {
            path: path.to_owned(),
            field,
            index,
            value: v,
        })
    }
}

fn vecs<'a>(
    path: &str,
    field: &'static str,
    vs: impl IntoIterator<Item = &'a Vec3>,
) -> Result<(), SceneError> {
    vs.into_iter()
        .flatten()
        .enumerate()
        .try_for_each(|(i, &v)| finite(path, field, i, v))
}

fn quats<'a>(
    path: &str,
    field: &'static str,
    qs: impl IntoIterator<Item = &'a QuatXyzw>,
) -> Result<(), SceneError> {
    for (index, q) in qs.into_iter().enumerate() {
        for (k, &v) in q.iter().enumerate() {
            finite(path, field, 4 * index + k, v)?;
        }
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (norm - 1.0).abs() > QUAT_NORM_TOLERANCE {
            return Err(SceneError::NonUnitQuaternion {
                path: path.to_owned(),
                field,
                index,
                norm,
            });
        }
    }
    Ok(())
}

/// `v` finite and `> 0` (`strict`) or `>= 0`.
fn positive(
    path: &str,
    field: &'static str,
    index: usize,
    v: f64,
    strict: bool,
) -> Result<(), SceneError> {
    finite(path, field, index, v)?;
    let ok = if strict { v > 0.0 } else { v >= 0.0 };
    if ok {
        Ok(())
    } else {
        Err(SceneError::OutOfRange {
            path: path.to_owned(),
            field,
            index,
            value: v,
            requirement: if strict { "> 0" } else { ">= 0" },
        })
    }
}

fn same_len(
    path: &str,
    field: &'static str,
    got: usize,
    expected: usize,
) -> Result<(), SceneError> {
    if got == expected {
        Ok(())
    } else {
        Err(SceneError::LengthMismatch {
            path: path.to_owned(),
            field,
            got,
            expected,
        })
    }
}

fn check_path(path: &str) -> Result<(), SceneError> {
    let bad = |reason| {
        Err(SceneError::BadPath {
            path: path.to_owned(),
            reason,
        })
    };
    if path.is_empty() {
        return bad("empty");
    }
    for segment in path.split('/') {
        if segment.is_empty() {
            return bad("empty segment (leading, trailing or double '/')");
        }
        if !segment
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        {
            return bad("segments may only use A-Z a-z 0-9 _ - .");
        }
    }
    Ok(())
}

fn is_under(path: &str, root: &str) -> bool {
    path.strip_prefix(root)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with('/'))
}

fn check_root(path: &str, kind: &'static str, root: &'static str) -> Result<(), SceneError> {
    if is_under(path, root) {
        Ok(())
    } else {
        Err(SceneError::WrongRoot {
            path: path.to_owned(),
            kind,
            root,
        })
    }
}

fn check_kind(path: &str, kind: &ItemKind) -> Result<(), SceneError> {
    match kind {
        ItemKind::Frame(Frame {
            translation,
            rotation,
            axis_length,
            label: _,
            tag: _,
        }) => {
            vecs(path, "translation", [translation])?;
            quats(path, "rotation", [rotation])?;
            positive(path, "axis_length", 0, *axis_length, true)
        }
        ItemKind::Triads(Triads {
            translations,
            rotations,
            axis_length,
            line_radius,
        }) => {
            same_len(path, "rotations", rotations.len(), translations.len())?;
            vecs(path, "translations", translations)?;
            quats(path, "rotations", rotations)?;
            positive(path, "axis_length", 0, *axis_length, true)?;
            positive(path, "line_radius", 0, *line_radius, true)
        }
        ItemKind::Points(PointCloud {
            positions, radius, ..
        }) => {
            vecs(path, "positions", positions)?;
            positive(path, "radius", 0, *radius, true)
        }
        ItemKind::Ellipsoids(Ellipsoids {
            shapes,
            line_radius,
            ..
        }) => {
            vecs(path, "center", shapes.iter().map(|s| &s.center))?;
            for (i, s) in shapes.iter().enumerate() {
                for (k, &h) in s.half_sizes.iter().enumerate() {
                    positive(path, "half_sizes", 3 * i + k, h, false)?;
                }
            }
            quats(path, "rotation", shapes.iter().map(|s| &s.rotation))?;
            positive(path, "line_radius", 0, *line_radius, true)
        }
        ItemKind::Surface(surface) => check_surface(path, surface),
        ItemKind::LineStrips(LineStrips { strips, radius, .. }) => {
            vecs(path, "strips", strips.iter().flatten())?;
            positive(path, "radius", 0, *radius, true)
        }
        ItemKind::Arrows(Arrows {
            origins,
            vectors,
            radius,
            ..
        }) => {
            same_len(path, "vectors", vectors.len(), origins.len())?;
            vecs(path, "origins", origins)?;
            vecs(path, "vectors", vectors)?;
            positive(path, "radius", 0, *radius, true)
        }
        ItemKind::Text(_) => Ok(()),
    }
}

fn check_surface(path: &str, surface: &Surface) -> Result<(), SceneError> {
    vecs(path, "vertices", &surface.vertices)?;
    if !surface.normals.is_empty() {
        same_len(
            path,
            "normals",
            surface.normals.len(),
            surface.vertices.len(),
        )?;
        vecs(path, "normals", &surface.normals)?;
    }
    let num_vertices = surface.vertices.len();
    for (triangle, tri) in surface.triangles.iter().enumerate() {
        if let Some(&vertex) = tri.iter().find(|&&v| v as usize >= num_vertices) {
            return Err(SceneError::BadTriangle {
                path: path.to_owned(),
                triangle,
                vertex,
                num_vertices,
            });
        }
    }
    Ok(())
}

impl SceneItem {
    /// Checks this item alone as [`Scene::validate`] does (every number finite, also as
    /// `f32`; sizes; quaternions; its path): to find which item of an invalid scene fails.
    ///
    /// ```
    /// use posecov::scene::{ItemKind, LineStrips, SceneItem, Timing, Color};
    /// let strips = LineStrips { strips: vec![vec![[0.0, 0.0, 0.0], [1e39, 0.0, 0.0]]], color: Color::rgb(0, 0, 0), radius: 0.01 };
    /// let item = SceneItem::new("world/t", Timing::Stamp(5), ItemKind::LineStrips(strips));
    /// assert!(item.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), SceneError> {
        check_item(self)
    }
}

fn check_item(item: &SceneItem) -> Result<(), SceneError> {
    check_path(&item.path)?;
    match &item.kind {
        ItemKind::Text(_) => Ok(()),
        _ => check_root(&item.path, "3-D item", WORLD),
    }?;
    check_kind(&item.path, &item.kind)
}

fn check_series(series: &ScalarSeries) -> Result<(), SceneError> {
    let path = series.path();
    let path = path.as_str();
    check_path(path)?;
    check_root(path, "scalar series", PLOTS)?;
    positive(path, "width", 0, series.width, true)?;
    series
        .points
        .iter()
        .enumerate()
        .try_for_each(|(i, &(_, v))| finite(path, "points", i, v))
}

impl Scene {
    /// Checks that the scene can be drawn: every number finite (also as `f32`), quaternions
    /// of unit norm, sizes non-negative and radii positive, parallel arrays of equal length,
    /// triangle indices in range, entity paths well formed, 3-D items under [`WORLD`], series
    /// under [`PLOTS`] and their plots' ranges finite, views' subtrees under [`WORLD`] and their cameras usable, and nothing placed under a [`Frame`]'s entity (its transform would
    /// move it).
    ///
    /// ```
    /// use posecov::scene::{Color, ItemKind, PointCloud, Scene, SceneError, SceneItem, Timing};
    /// let mut scene = Scene::new("t", "");
    /// scene.push(SceneItem::new("world/c", Timing::Static, ItemKind::Points(PointCloud {
    ///     positions: vec![[0.0, f64::NAN, 0.0]],
    ///     color: Color::rgb(0, 0, 0),
    ///     radius: 0.1,
    /// })));
    /// assert!(matches!(scene.validate(), Err(SceneError::NonFinite { index: 1, .. })));
    /// ```
    pub fn validate(&self) -> Result<(), SceneError> {
        self.items.iter().try_for_each(check_item)?;
        self.series.iter().try_for_each(check_series)?;
        for plot in &self.plots {
            for (i, v) in plot.range.iter().flatten().enumerate() {
                finite(&super::paths::plot(&plot.id), "range", i, *v)?;
            }
        }
        self.views.iter().try_for_each(super::View3d::check)?;
        // Each item's ancestors looked up among the frames: linear in items × depth.
        let frames: std::collections::HashSet<&str> = self
            .items
            .iter()
            .filter(|item| matches!(item.kind, ItemKind::Frame(_)))
            .map(|item| item.path.as_str())
            .collect();
        for path in self.items.iter().map(|item| item.path.as_str()) {
            let ancestors = path.match_indices('/').map(|(i, _)| &path[..i]);
            if let Some(frame) = ancestors.into_iter().find(|a| frames.contains(a)) {
                return Err(SceneError::UnderFrame {
                    path: path.to_owned(),
                    frame: frame.to_owned(),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Color, Ellipsoid, FillMode, QUAT_IDENTITY, Timing};

    fn one(path: &str, kind: ItemKind) -> Scene {
        let mut scene = Scene::new("t", "");
        scene.push(SceneItem::new(path, Timing::Static, kind));
        scene
    }

    fn cloud(p: Vec3) -> ItemKind {
        ItemKind::Points(PointCloud {
            positions: vec![[0.0; 3], p],
            color: Color::rgb(1, 2, 3),
            radius: 0.01,
        })
    }

    fn frame(translation: Vec3, rotation: QuatXyzw) -> ItemKind {
        ItemKind::Frame(Frame {
            translation,
            rotation,
            axis_length: 1.0,
            label: None,
            tag: None,
        })
    }

    #[test]
    fn rejects_nan_inf_and_f32_overflow_with_position() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300] {
            let err = one("world/c", cloud([0.0, 0.0, bad])).validate();
            assert!(
                matches!(
                    err,
                    Err(SceneError::NonFinite {
                        index: 5,
                        field: "positions",
                        ..
                    })
                ),
                "{bad}: {err:?}"
            );
        }
    }

    #[test]
    fn rejects_nan_in_series() {
        let mut scene = Scene::new("t", "");
        scene.series.push(ScalarSeries::new(
            crate::scene::PlotId::new("trace"),
            "a",
            "a",
            Color::rgb(0, 0, 0),
            2.0,
            vec![(0, 1.0), (1, f64::NAN)],
        ));
        assert!(matches!(
            scene.validate(),
            Err(SceneError::NonFinite { index: 1, .. })
        ));
    }

    #[test]
    fn rejects_non_unit_quaternion_and_negative_half_size() {
        let err = one("world/f", frame([0.0; 3], [0.0, 0.0, 0.0, 2.0])).validate();
        assert!(matches!(err, Err(SceneError::NonUnitQuaternion { .. })));
        let e = ItemKind::Ellipsoids(Ellipsoids {
            shapes: vec![Ellipsoid {
                center: [0.0; 3],
                half_sizes: [1.0, -1.0, 1.0],
                rotation: QUAT_IDENTITY,
            }],
            color: Color::rgb(0, 0, 0),
            fill: FillMode::MajorWireframe,
            line_radius: 0.01,
            label: None,
        });
        let err = one("world/e", e).validate();
        assert!(matches!(err, Err(SceneError::OutOfRange { index: 1, .. })));
    }

    #[test]
    fn rejects_bad_triangles_and_lengths() {
        let s = ItemKind::Surface(Surface {
            vertices: vec![[0.0; 3]; 3],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            normals: vec![],
            color: Color::rgb(0, 0, 0),
        });
        let err = one("world/s", s).validate();
        assert!(matches!(
            err,
            Err(SceneError::BadTriangle {
                triangle: 1,
                vertex: 3,
                ..
            })
        ));
        let t = ItemKind::Triads(Triads {
            translations: vec![[0.0; 3]; 2],
            rotations: vec![QUAT_IDENTITY],
            axis_length: 0.1,
            line_radius: 0.01,
        });
        assert!(matches!(
            one("world/t", t).validate(),
            Err(SceneError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn rejects_bad_paths_roots_and_items_under_frames() {
        for path in ["", "world//c", "world/c/", "world/a b"] {
            assert!(
                matches!(
                    one(path, cloud([0.0; 3])).validate(),
                    Err(SceneError::BadPath { .. })
                ),
                "{path:?}"
            );
        }
        assert!(matches!(
            one("worldly/c", cloud([0.0; 3])).validate(),
            Err(SceneError::WrongRoot { .. })
        ));
        let mut scene = one("world/a", frame([0.0; 3], QUAT_IDENTITY));
        scene.push(SceneItem::new(
            "world/a/c",
            Timing::Step(1),
            cloud([0.0; 3]),
        ));
        assert!(matches!(
            scene.validate(),
            Err(SceneError::UnderFrame { .. })
        ));
        // A sibling with a common prefix is fine.
        let mut scene = one("world/a", frame([0.0; 3], QUAT_IDENTITY));
        scene.push(SceneItem::new(
            "world/ab/c",
            Timing::Step(1),
            cloud([0.0; 3]),
        ));
        assert_eq!(scene.validate(), Ok(()));
    }
}
