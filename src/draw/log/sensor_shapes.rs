//! What is drawn of a log's sensor topics besides their σ plots, where a picture teaches:
//! - a NavSatFix's fixes (`world/<topic>/fixes`, [`paths::fixes`]) in the local East-North
//!   plane at its first drawn fix (the projection: `eval::log::sensor_shapes`), thinned as a
//!   pose topic's drawn messages: the track, each fix a dot, each fix's horizontal position
//!   region at the chosen confidence (χ² with d = 2) — every one faint and static, the one at
//!   the time cursor bold at its stamp — and at the origin an East (red) / North (green)
//!   triad labelled with the first fix's latitude, longitude and height. Up is not drawn (its
//!   σ is in the `σ position` plot);
//! - an IMU's orientation uncertainty at its newest usable message
//!   (`world/<topic>/orientation_spray`, [`paths::orientation_spray`]): the mean orientation's
//!   axes (1 m) and the tips of each seeded sample's x, y and z axes (CONVENTIONS §7's axis-tip
//!   spray), the covariance read about the parent's fixed axes (tf2's reading, or the body's
//!   with `--ros-reading body`).
//!
//! Each gets its own view, which says the projection and its origin, or the message, the
//! samples and the side.

use std::fmt::Write;

use nalgebra::{Matrix2, SymmetricEigen, Vector3};

use super::super::Painter;
use super::super::shapes::AXIS_COLORS;
use crate::eval::log::LogEvaluation;
use crate::eval::log::sensor::SensorEvaluation;
use crate::eval::log::sensor_shapes::{LocalFixes, OrientationSpray};
use crate::scene::{
    Color, Frame, ItemKind, LineStrips, Origin, PointCloud, Scene, Swatch, Timing, Vec3, View3d,
    paths,
};
use crate::uncertain::{Confidence, Side};

/// The fixes' colour.
const FIXES: Color = Color::rgb(20, 110, 200);
/// Points on a drawn ellipse.
const ELLIPSE_POINTS: usize = 64;

/// Draws every sensor topic's fixes and orientation spray (see the [module docs](self)).
pub(super) fn draw_sensor_shapes(p: &mut Painter, e: &LogEvaluation) {
    for t in &e.sensors {
        p.origin = Some(Origin::Topic {
            topic: t.name.clone(),
            message: None,
        });
        if let Some(l) = &t.fixes {
            fixes(p, t, l);
        }
        if let Some(s) = &t.orientation {
            spray(p, t, s);
        }
    }
    p.origin = None;
}

/// The outline of the ellipse { c + x : xᵀ Σ⁻¹ x ≤ r² } of a 2 × 2 covariance `cov`
/// (row-major), closed; `None` when it is not a finite PSD matrix.
fn ellipse(center: [f64; 2], cov: [f64; 4], r: f64) -> Option<Vec<Vec3>> {
    let m = Matrix2::new(
        cov[0],
        0.5 * (cov[1] + cov[2]),
        0.5 * (cov[1] + cov[2]),
        cov[3],
    );
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let eig = SymmetricEigen::new(m);
    if eig.eigenvalues.min() < 0.0 {
        return None;
    }
    let axes = eig.eigenvectors * Matrix2::from_diagonal(&eig.eigenvalues.map(f64::sqrt)) * r;
    Some(
        (0..=ELLIPSE_POINTS)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / ELLIPSE_POINTS as f64;
                let v = axes * nalgebra::Vector2::new(a.cos(), a.sin());
                [center[0] + v.x, center[1] + v.y, 0.0]
            })
            .collect(),
    )
}

/// The size of a topic's fixes drawing: the largest distance from the origin of a fix or of
/// its ellipse, at least 1 m.
fn fixes_size(l: &LocalFixes, r: f64) -> f64 {
    l.fixes
        .iter()
        .map(|f| {
            let [e, n, _] = f.east_north_up;
            let reach = f
                .covariance_en
                .map_or(0.0, |c| r * c[0].max(c[3]).max(0.0).sqrt());
            e.hypot(n) + if reach.is_finite() { reach } else { 0.0 }
        })
        .fold(1.0, f64::max)
}

fn fixes(p: &mut Painter, t: &SensorEvaluation, l: &LocalFixes) {
    let base = paths::fixes(&t.name);
    let r = p.confidence().radius(2);
    let size = fixes_size(l, r);
    let line = 0.002 * size;
    let points: Vec<Vec3> = l
        .fixes
        .iter()
        .map(|f| [f.east_north_up[0], f.east_north_up[1], 0.0])
        .collect();
    p.legend(
        format!("{}: fixes (East-North)", t.name),
        FIXES,
        Swatch::Line,
    );
    p.place(
        paths::child(&base, "track"),
        Timing::Static,
        ItemKind::LineStrips(LineStrips {
            strips: vec![points.clone()],
            color: FIXES.with_alpha(160),
            radius: line,
        }),
    );
    p.place(
        paths::child(&base, "points"),
        Timing::Static,
        ItemKind::Points(PointCloud {
            positions: points,
            color: FIXES,
            radius: 2.5 * line,
        }),
    );
    let outlines: Vec<(i64, Vec<Vec3>)> = l
        .fixes
        .iter()
        .filter_map(|f| {
            let c = f.covariance_en?;
            let [e, n, _] = f.east_north_up;
            Some((f.stamp_ns, ellipse([e, n], c, r)?))
        })
        .collect();
    if !outlines.is_empty() {
        p.legend(
            format!("{}: position region, {} (d = 2)", t.name, p.confidence),
            FIXES,
            Swatch::Dashed,
        );
        p.place(
            paths::child(&base, "history"),
            Timing::Static,
            ItemKind::LineStrips(LineStrips {
                strips: outlines.iter().map(|o| o.1.clone()).collect(),
                color: FIXES.with_alpha(70),
                radius: 0.5 * line,
            }),
        );
    }
    for (stamp_ns, outline) in outlines {
        p.place(
            paths::child(&base, "region"),
            Timing::Stamp(stamp_ns),
            ItemKind::LineStrips(LineStrips {
                strips: vec![outline],
                color: FIXES,
                radius: 1.5 * line,
            }),
        );
    }
    let [lat, lon, h] = l.origin;
    p.place(
        paths::child(&base, "origin"),
        Timing::Static,
        ItemKind::Frame(Frame {
            translation: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            axis_length: 0.15 * size,
            label: Some(format!(
                "first fix {}: x east, y north",
                origin_words(lat, lon, h)
            )),
            tag: None,
        }),
    );
}

/// A geodetic position in words: `48.1370000° N, 11.5750000° E, 520.00 m`.
fn origin_words(lat: f64, lon: f64, h: f64) -> String {
    format!(
        "{:.7}° {}, {:.7}° {}, {h:.2} m",
        lat.abs(),
        if lat < 0.0 { 'S' } else { 'N' },
        lon.abs(),
        if lon < 0.0 { 'W' } else { 'E' }
    )
}

fn spray(p: &mut Painter, t: &SensorEvaluation, s: &OrientationSpray) {
    let base = paths::orientation_spray(&t.name);
    p.place(
        paths::child(&base, "mean"),
        Timing::Static,
        ItemKind::Frame(Frame {
            translation: [0.0; 3],
            rotation: s.mean.to_quaternion_xyzw(),
            axis_length: 1.0,
            label: Some(format!("mean orientation at message {}", s.index)),
            tag: None,
        }),
    );
    for (axis, color) in AXIS_COLORS.iter().enumerate() {
        let tips: Vec<Vec3> = s
            .samples
            .iter()
            .map(|r| {
                let c = r.column(axis);
                [c.x, c.y, c.z]
            })
            .collect();
        p.place(
            paths::child(&base, &format!("tips_{}", ["x", "y", "z"][axis])),
            Timing::Static,
            ItemKind::Points(PointCloud {
                positions: tips,
                color: *color,
                radius: 0.012,
            }),
        );
    }
    p.legend(
        format!("{}: orientation samples (axis tips)", t.name),
        AXIS_COLORS[0],
        Swatch::Dots,
    );
}

/// The side of a spray in words.
fn side_words(side: Side) -> &'static str {
    match side {
        Side::Left => "about the parent's fixed axes, R̃ = Exp(δφ)·R (tf2's reading)",
        Side::Right => "about the IMU's own axes, R̃ = R·Exp(δθ) (body reading)",
    }
}

/// One view per topic with fixes (seen from above) and per IMU with a spray: its view, and
/// whether it is seen from above.
pub(super) fn sensor_views(e: &LogEvaluation) -> Vec<(View3d, bool)> {
    let mut out = Vec::new();
    for t in &e.sensors {
        if let Some(l) = &t.fixes {
            let [lat, lon, h] = l.origin;
            let view = View3d {
                name: format!(
                    "{}: fixes, East-North (m) of the first fix {} (local tangent plane, WGS84)",
                    t.name,
                    origin_words(lat, lon, h)
                ),
                include: vec![paths::fixes(&t.name)],
                ..Default::default()
            };
            out.push((view, true));
        }
        if let Some(s) = &t.orientation {
            let view = View3d {
                name: format!(
                    "{}: orientation at message {}, {} samples {}",
                    t.name,
                    s.index,
                    s.samples.len(),
                    side_words(s.side)
                ),
                include: vec![paths::orientation_spray(&t.name)],
                ..Default::default()
            };
            out.push((view, false));
        }
    }
    out
}

/// The text panel's words on what is drawn of the sensor topics.
pub(super) fn shapes_paragraph(e: &LogEvaluation, confidence: Confidence, s: &mut String) {
    for t in &e.sensors {
        if let Some(l) = &t.fixes {
            let [lat, lon, h] = l.origin;
            let regions = l.fixes.iter().filter(|f| f.covariance_en.is_some()).count();
            let _ = writeln!(
                s,
                "\n**{}** drawn: {} fixes in the East-North plane of the first, {} (local \
                 tangent plane: east = (N + h₀) cos φ₀ Δλ, north = (M + h₀) Δφ, WGS84 radii \
                 M = {:.1} m, N = {:.1} m); {regions} with their position region at {confidence} \
                 (χ², d = 2){}. Up is in the σ plot only.",
                t.name,
                l.fixes.len(),
                origin_words(lat, lon, h),
                l.radii[0],
                l.radii[1],
                if regions < l.fixes.len() {
                    "; the others have no usable covariance"
                } else {
                    ""
                }
            );
        }
        if let Some(sp) = &t.orientation {
            let sigma: Vec<String> = ["x", "y", "z"]
                .iter()
                .zip(sp.sigma)
                .map(|(a, v)| match v {
                    Some(v) => format!("σ{a} {:.2}°", v.to_degrees()),
                    None => format!("σ{a} not estimated (not sprayed)"),
                })
                .collect();
            let _ = writeln!(
                s,
                "\n**{}** drawn: its orientation at message {} with {} seeded samples' axis \
                 tips, the covariance read {}: {}.{}",
                t.name,
                sp.index,
                sp.samples.len(),
                side_words(sp.side),
                sigma.join(", "),
                zoom_words(sp)
            );
        }
    }
}

/// When a spray is too tight to see at 1 m (largest σ below 1°): how close to the axis tips
/// its samples lie (3 σ at 1 m), and that the view must be zoomed.
fn zoom_words(s: &OrientationSpray) -> String {
    let largest = s.sigma.iter().flatten().fold(0.0, |m: f64, v| m.max(*v));
    if largest.to_degrees() >= 1.0 {
        return String::new();
    }
    format!(
        " The samples lie within about {:.1} mm of the 1 m axis tips (3 σ): zoom on a tip to \
         see them.",
        3.0 * largest * 1e3
    )
}

/// The points a view's static items draw (for its camera).
pub(super) fn view_points(scene: &Scene, view: &View3d) -> Vec<Vector3<f64>> {
    super::super::views::points_of(scene, view, |i| i.timing == Timing::Static)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_ellipse_has_its_sigmas_on_its_axes() {
        // σ east 2 m, σ north 1 m, at r = 1: the outline reaches ±2 east and ±1 north.
        let o = ellipse([10.0, 0.0], [4.0, 0.0, 0.0, 1.0], 1.0).unwrap();
        let east = o.iter().map(|p| p[0] - 10.0).fold(0.0, f64::max);
        let north = o.iter().map(|p| p[1]).fold(0.0, f64::max);
        assert!(
            (east - 2.0).abs() < 1e-9 && (north - 1.0).abs() < 1e-3,
            "{east} {north}"
        );
        assert!(ellipse([0.0; 2], [-1.0, 0.0, 0.0, 1.0], 1.0).is_none());
        assert!(ellipse([0.0; 2], [f64::NAN, 0.0, 0.0, 1.0], 1.0).is_none());
        assert_eq!(
            origin_words(-33.5, -70.25, 5.0),
            "33.5000000° S, 70.2500000° W, 5.00 m"
        );
    }
}
