//! The world panel: a scene's 3-D items projected orthographically on a coordinate plane,
//! with equal scales on both axes so lengths and shapes read true.
//!
//! - Point clouds: one dot per sample (at most [`MAX_DOTS`], evenly strided), each cloud one
//!   path of circles, leaving out the dots that the cloud's others cover whole
//!   ([`visible_dots`]).
//! - Ellipsoids: their exact shadow on the plane, the ellipse of the projected shape matrix
//!   P R diag(h)² Rᵀ Pᵀ (P the plane's two rows), dashed.
//! - Surfaces (Exp-mapped bananas): the union of their projected triangles, filled, with a
//!   darker outline where the union ends (drawn by the figure's region module).
//! - Line strips, arrows, frames (x red, y green, z blue) and sample triads as lines.

use nalgebra::{Matrix2, Matrix3, SymmetricEigen, UnitQuaternion, Vector3};

use super::svg::{Px, SIMPLIFY_TOLERANCE, Svg, darker, num, on_white, path_data, rgb, simplified};
use crate::scene::{AXIS_COLORS, Ellipsoid, FillMode, ItemKind, QuatXyzw, SceneItem, Vec3};

/// At most this many dots per cloud (a larger cloud is strided evenly; its statistics are
/// the evaluation's, not the picture's).
pub const MAX_DOTS: usize = 20_000;

/// Points on a projected ellipse.
const ELLIPSE_POINTS: usize = 96;

/// A coordinate plane a figure is drawn on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Plane {
    /// Seen from above: x to the right, y up.
    #[default]
    Xy,
    /// Seen from the side (−y): x to the right, z up.
    Xz,
    /// Seen from the front (+x): y to the right, z up.
    Yz,
}

impl Plane {
    /// The world axes shown right and up (0 = x, 1 = y, 2 = z).
    pub const fn axes(self) -> (usize, usize) {
        match self {
            Self::Xy => (0, 1),
            Self::Xz => (0, 2),
            Self::Yz => (1, 2),
        }
    }

    /// The axes' names, e.g. `("x", "y")`.
    pub const fn names(self) -> (&'static str, &'static str) {
        match self {
            Self::Xy => ("x", "y"),
            Self::Xz => ("x", "z"),
            Self::Yz => ("y", "z"),
        }
    }

    /// A world point's coordinates on the plane (metres).
    ///
    /// ```
    /// use posecov::sink::figure::Plane;
    /// assert_eq!(Plane::Xz.project([1.0, 2.0, 3.0]), [1.0, 3.0]);
    /// ```
    pub const fn project(self, v: Vec3) -> [f64; 2] {
        let (a, b) = self.axes();
        [v[a], v[b]]
    }
}

impl std::str::FromStr for Plane {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "xy" => Ok(Self::Xy),
            "xz" => Ok(Self::Xz),
            "yz" => Ok(Self::Yz),
            _ => Err(format!("{s:?} is not a plane: use xy, xz or yz")),
        }
    }
}

/// From plane metres to figure pixels: equal scale on both axes, y up.
#[derive(Clone, Copy, Debug)]
pub struct Mapping {
    /// Pixels per metre.
    pub scale: f64,
    /// The plane point at the panel's centre (metres).
    pub center: [f64; 2],
    /// The panel's centre (pixels).
    pub origin: Px,
}

impl Mapping {
    /// The pixel of a plane point.
    pub fn px(&self, p: [f64; 2]) -> Px {
        [
            self.origin[0] + self.scale * (p[0] - self.center[0]),
            self.origin[1] - self.scale * (p[1] - self.center[1]),
        ]
    }

    /// The plane point of a pixel (the inverse of [`Mapping::px`]).
    pub fn metres(&self, px: Px) -> [f64; 2] {
        [
            self.center[0] + (px[0] - self.origin[0]) / self.scale,
            self.center[1] - (px[1] - self.origin[1]) / self.scale,
        ]
    }
}

/// The boundary points of an ellipsoid's shadow on the plane (metres).
fn shadow(e: &Ellipsoid, plane: Plane) -> Vec<[f64; 2]> {
    let r = rotation(&e.rotation);
    let h = Matrix3::from_diagonal(&Vector3::from(e.half_sizes).map(|v| v * v));
    let m3 = r * h * r.transpose();
    let (a, b) = plane.axes();
    let m = Matrix2::new(m3[(a, a)], m3[(a, b)], m3[(b, a)], m3[(b, b)]);
    let eig = SymmetricEigen::new(m);
    let c = plane.project(e.center);
    (0..ELLIPSE_POINTS)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / ELLIPSE_POINTS as f64;
            let (s0, s1) = (
                eig.eigenvalues[0].max(0.0).sqrt(),
                eig.eigenvalues[1].max(0.0).sqrt(),
            );
            let v = eig.eigenvectors.column(0) * (s0 * t.cos())
                + eig.eigenvectors.column(1) * (s1 * t.sin());
            [c[0] + v[0], c[1] + v[1]]
        })
        .collect()
}

fn rotation(q: &QuatXyzw) -> Matrix3<f64> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
    *q.to_rotation_matrix().matrix()
}

fn rotate(q: &QuatXyzw, v: Vec3) -> Vec3 {
    crate::scene::rotate(q, v)
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Every plane point an item draws (for the panel's extent; clouds separately).
pub fn extent_points(item: &SceneItem, plane: Plane, out: &mut Vec<[f64; 2]>) {
    match &item.kind {
        ItemKind::Frame(f) => {
            out.push(plane.project(f.translation));
            for k in 0..3 {
                let mut axis = [0.0; 3];
                axis[k] = f.axis_length;
                out.push(plane.project(add(f.translation, rotate(&f.rotation, axis))));
            }
        }
        ItemKind::Triads(t) => out.extend(t.translations.iter().map(|v| plane.project(*v))),
        ItemKind::Ellipsoids(e) => {
            for shape in &e.shapes {
                out.extend(shadow(shape, plane));
            }
        }
        ItemKind::Surface(s) => out.extend(s.vertices.iter().map(|v| plane.project(*v))),
        ItemKind::LineStrips(l) => out.extend(l.strips.iter().flatten().map(|v| plane.project(*v))),
        ItemKind::Arrows(a) => {
            for (o, v) in a.origins.iter().zip(&a.vectors) {
                out.push(plane.project(*o));
                out.push(plane.project(add(*o, *v)));
            }
        }
        ItemKind::Points(_) | ItemKind::Text(_) => {}
    }
}

/// How thick lines are: `unit` pixels is a thin line at this figure's size.
#[derive(Clone, Copy, Debug)]
pub struct Pen {
    /// A thin line's width in pixels (grows with the figure).
    pub unit: f64,
    /// Text size of labels in pixels.
    pub font: f64,
}

/// Draws the clouds of `items`.
/// Each cloud's visible dots are found on its own core ([`visible_dots`]; written in order).
pub fn draw_clouds(svg: &mut Svg, items: &[&SceneItem], plane: Plane, m: &Mapping, pen: Pen) {
    use rayon::prelude::*;
    let clouds: Vec<(Vec<Px>, f64, String)> = items
        .par_iter()
        .filter_map(|item| {
            let ItemKind::Points(cloud) = &item.kind else {
                return None;
            };
            let stride = cloud.positions.len().div_ceil(MAX_DOTS).max(1);
            let radius = (cloud.radius * m.scale).clamp(0.6 * pen.unit, 1.6 * pen.unit);
            let alpha = (f64::from(cloud.color.0[3]) / 255.0).min(0.7);
            let color = on_white(darker(cloud.color, 0.25), alpha);
            let centers: Vec<Px> = cloud
                .positions
                .iter()
                .step_by(stride)
                .map(|p| m.px(plane.project(*p)))
                .collect();
            Some((
                visible_dots(&centers, radius),
                radius,
                format!("class=\"cloud\" stroke=\"{}\"", rgb(color)),
            ))
        })
        .collect();
    for (dots, radius, style) in clouds {
        svg.dots(dots, radius, &style);
    }
}

/// The dots of one opaque colour, all `radius` wide, that show: each dot, in order, unless
/// the dots before it already cover all of it. A cloud is one path filled in one colour, so a
/// dot inside the others adds nothing to the picture, at any zoom; a dense cloud's core is
/// most of its samples (BENCHMARKS.md §9).
///
/// Coverage is kept on a grid of cells a third of the radius wide: a cell counts as covered
/// when its four corners lie in one drawn dot (a disc is convex, so the cell does too), and a
/// dot is left out only when every cell it touches is covered. So a left-out dot is always
/// inside the drawn ones; near the cloud's edge, where cells are partly covered, dots are kept.
///
/// ```
/// use posecov::sink::figure::world::visible_dots;
/// // A dense 11 × 11 patch of dots, then one dot inside it: that one is left out.
/// let mut dots: Vec<[f64; 2]> = (0..121)
///     .map(|k| [19.0 + 0.2 * (k % 11) as f64, 19.0 + 0.2 * (k / 11) as f64])
///     .collect();
/// dots.push([20.1, 20.1]);
/// let shown = visible_dots(&dots, 1.0);
/// assert!(!shown.contains(&[20.1, 20.1]));
/// assert_eq!(shown.len(), 121);
/// ```
pub fn visible_dots(centers: &[Px], radius: f64) -> Vec<Px> {
    let finite: Vec<Px> = centers
        .iter()
        .copied()
        .filter(|c| c.iter().all(|v| v.is_finite()))
        .collect();
    if finite.is_empty() || radius <= 0.0 {
        return finite;
    }
    let cell = radius / 3.0;
    let (mut low, mut high) = ([f64::MAX; 2], [f64::MIN; 2]);
    for c in &finite {
        for k in 0..2 {
            low[k] = low[k].min(c[k] - radius);
            high[k] = high[k].max(c[k] + radius);
        }
    }
    let size = [0, 1].map(|k| ((high[k] - low[k]) / cell).ceil() as usize + 1);
    // A grid too large to keep (dots spread over far more than the figure): every dot.
    if size[0].saturating_mul(size[1]) > 1 << 26 {
        return finite;
    }
    let mut covered = vec![false; size[0] * size[1]];
    let r2 = radius * radius;
    let mut shown = Vec::new();
    for c in finite {
        // The cells the dot's bounding square touches, in grid coordinates.
        let first = [0, 1].map(|k| ((c[k] - radius - low[k]) / cell).floor().max(0.0) as usize);
        let last =
            [0, 1].map(|k| (((c[k] + radius - low[k]) / cell).floor() as usize).min(size[k] - 1));
        let cells =
            || (first[1]..=last[1]).flat_map(move |j| (first[0]..=last[0]).map(move |i| (i, j)));
        let corner = |i: usize, j: usize| [low[0] + i as f64 * cell, low[1] + j as f64 * cell];
        let near = |p: Px| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
        // A cell touches the dot when its nearest point to the centre is inside it.
        let touches = |i: usize, j: usize| {
            let [x0, y0] = corner(i, j);
            near([c[0].clamp(x0, x0 + cell), c[1].clamp(y0, y0 + cell)]) < r2
        };
        if cells().all(|(i, j)| !touches(i, j) || covered[j * size[0] + i]) {
            continue;
        }
        for (i, j) in cells() {
            let inside = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .iter()
                .all(|&(di, dj)| near(corner(i + di, j + dj)) <= r2);
            if inside {
                covered[j * size[0] + i] = true;
            }
        }
        shown.push(c);
    }
    shown
}

/// Draws the lines of `items`: ellipses, outlines, paths, arrows, triads and frames (their
/// labels: [`draw_labels`](super::labels::draw_labels)).
pub fn draw_lines(svg: &mut Svg, items: &[&SceneItem], plane: Plane, m: &Mapping, pen: Pen) {
    let to_px = |v: Vec3| m.px(plane.project(v));
    for item in items {
        match &item.kind {
            ItemKind::Ellipsoids(e) => {
                let color = darker(e.color, 0.1);
                let (fill, dash) = match e.fill {
                    FillMode::Solid | FillMode::TransparentFillMajorWireframe => (
                        format!(
                            " fill=\"{}\" fill-opacity=\"0.15\"",
                            rgb(e.color.with_alpha(255))
                        ),
                        "",
                    ),
                    _ => (String::new(), " stroke-dasharray=\"7 4\""),
                };
                for shape in &e.shapes {
                    let points: Vec<Px> =
                        shadow(shape, plane).into_iter().map(|p| m.px(p)).collect();
                    let points = simplified(&points, SIMPLIFY_TOLERANCE);
                    svg.raw(&format!(
                        "<path class=\"ellipse\" d=\"{}\" stroke=\"{}\" stroke-width=\"{}\"{dash}{}/>",
                        path_data(&points, true),
                        rgb(color),
                        num(1.6 * pen.unit),
                        if fill.is_empty() { " fill=\"none\"" } else { &fill },
                    ));
                }
            }
            ItemKind::LineStrips(l) => {
                let width = (2.0 * l.radius * m.scale).clamp(pen.unit, 2.5 * pen.unit);
                for strip in &l.strips {
                    let points: Vec<Px> = strip.iter().map(|v| to_px(*v)).collect();
                    svg.polyline(
                        &points,
                        false,
                        darker(l.color, 0.1),
                        width,
                        " class=\"line\"",
                    );
                }
            }
            ItemKind::Arrows(a) => {
                for (o, v) in a.origins.iter().zip(&a.vectors) {
                    arrow(svg, to_px(*o), to_px(add(*o, *v)), a.color, 0.8 * pen.unit);
                }
            }
            ItemKind::Triads(t) => {
                for (o, q) in t.translations.iter().zip(&t.rotations) {
                    axes(svg, *o, q, t.axis_length, 0.6 * pen.unit, &to_px);
                }
            }
            ItemKind::Frame(f) => {
                axes(
                    svg,
                    f.translation,
                    &f.rotation,
                    f.axis_length,
                    1.8 * pen.unit,
                    &to_px,
                );
            }
            ItemKind::Points(_) | ItemKind::Surface(_) | ItemKind::Text(_) => {}
        }
    }
}

/// A frame's three axes, x red, y green, z blue (an axis seen end-on is a dot).
fn axes(
    svg: &mut Svg,
    origin: Vec3,
    q: &QuatXyzw,
    length: f64,
    width: f64,
    to_px: &impl Fn(Vec3) -> Px,
) {
    let o = to_px(origin);
    for (k, color) in AXIS_COLORS.iter().enumerate() {
        let mut axis = [0.0; 3];
        axis[k] = length;
        let tip = to_px(add(origin, rotate(q, axis)));
        svg.line(
            o,
            tip,
            darker(*color, 0.15),
            width,
            " stroke-linecap=\"round\"",
        );
    }
}

/// An arrow from `a` to `b` (pixels) with a small head.
fn arrow(svg: &mut Svg, a: Px, b: Px, color: crate::scene::Color, unit: f64) {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len = dx.hypot(dy);
    if len < 0.5 {
        return;
    }
    let color = on_white(darker(color, 0.1), f64::from(color.0[3]) / 255.0);
    svg.line(a, b, color, unit, "");
    let head = (4.0 * unit).min(0.4 * len);
    let (ux, uy) = (dx / len, dy / len);
    let left = [b[0] - head * (ux - 0.5 * uy), b[1] - head * (uy + 0.5 * ux)];
    let right = [b[0] - head * (ux + 0.5 * uy), b[1] - head * (uy - 0.5 * ux)];
    svg.raw(&format!(
        "<path d=\"{}\" fill=\"{}\"/>",
        path_data(&[b, left, right], true),
        rgb(color)
    ));
}
