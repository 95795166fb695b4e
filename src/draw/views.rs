//! The 3-D views of a scene and their cameras.
//!
//! **Layout** ([`Layout`]; the file's `[draw] layout`, else chosen here): several rotations
//! (which would all sit at the origin) get one view per pose; a pose compared by four or more
//! analytic methods gets one view per method, each with the Monte Carlo cloud; otherwise one
//! view with the main method in full and the other methods' outlines hidden at first (the
//! vector-space ellipse, a lesson of its own, stays shown).
//!
//! **Camera**: planar scenes are seen from straight above with x to the right and y up (the
//! eye tilted 2° towards −y so that orbiting turns about z); 3-D scenes look along the
//! direction in which what is drawn is thinnest (the smallest principal axis of all drawn
//! points, tilted 25° towards up so depth still reads; a scene lying flat, thin within 35° of
//! up, from 30° off the vertical on the −y side, x to the right; a scene with no thin
//! direction, such as a sphere of poses, from 30° above the horizon on the −y side, turned 30°
//! towards +x), rotations from the (+x, +y, +z) octant; `[draw] camera` overrides. The eye then stands at the distance at which every
//! drawn point of the view fits the viewer's 55° field of view with a margin, in the shape
//! the view really has at 1024 × 640 ([`crate::scene::layout::views_aspect`]: the left column
//! over the legend view, shared among the views).

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;

use crate::plan::choices::{CameraChoice, Layout};
use crate::scene::layout::views_aspect;
use crate::scene::paths;
use crate::scene::{Camera, ItemKind, Scene, SceneItem, Vec3, View3d, rotate};
use crate::uncertain::Method;

/// Rerun's default vertical field of view of a 3-D view (55°).
pub(super) const FOV_Y: f64 = 55.0 * std::f64::consts::PI / 180.0;
/// Room left around what is drawn.
const MARGIN: f64 = 1.2;
/// Tilt of the top view off the vertical, so that orbiting still turns about z.
const TOP_TILT_DEG: f64 = 2.0;
/// Tilt of a 3-D view off its thinnest direction.
const OBLIQUE_TILT_DEG: f64 = 25.0;
/// A scene whose thinnest direction is within this angle of up lies flat...
const FLAT_DEG: f64 = 35.0;
/// ...and is seen from this far off the vertical, from −y.
const FLAT_TILT_DEG: f64 = 30.0;
/// A scene whose least spread (variance along its thinnest axis) is more than this share of
/// its largest has no thin direction (a sphere of poses)...
const ROUND: f64 = 0.4;
/// ...and is seen from 30° above the horizon, 30° round from −y towards +x:
/// (sin 30° cos 30°, −cos 30° cos 30°, sin 30°).
const ROUND_EYE: [f64; 3] = [0.433, -0.75, 0.5];

/// What a pose's regions were drawn from: the input's own Gaussian, or a method's estimate.
/// Its entity-path segment is [`Estimate::segment`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Estimate {
    /// An input's own Gaussian (not computed by a method), `given`.
    Given,
    /// A method's estimate, under the method's slug.
    Method(Method),
}

impl Estimate {
    /// The entity-path segment: `given` or the method's slug.
    pub(super) fn segment(self) -> &'static str {
        match self {
            Estimate::Given => "given",
            Estimate::Method(m) => m.slug(),
        }
    }
}

/// Which estimates were drawn for one pose: the main one and the others.
#[derive(Default, Debug)]
pub(super) struct PoseMethods {
    /// The pose's name (its node).
    pub pose: String,
    pub main: Option<Estimate>,
    pub others: Vec<Estimate>,
}

/// What the views are made from besides the scene's items.
pub(super) struct ViewInputs<'a> {
    /// Per drawn (uncertain) pose, its methods.
    pub poses: &'a [PoseMethods],
    /// Rotations only (SO(2), SO(3)).
    pub rotation_only: bool,
    /// Seen from above (planar scenes, or `view = "top"`).
    pub top: bool,
    /// The layout.
    pub layout: Layout,
    /// The file's camera.
    pub camera: Option<CameraChoice>,
}

/// The layout chosen when the file names none: one view per pose for several rotations, one
/// view per method when a pose has four or more analytic methods, else [`Layout::Main`].
pub(super) fn default_layout(rotation_only: bool, poses: usize, most_methods: usize) -> Layout {
    if rotation_only && poses >= 2 {
        Layout::PerPose
    } else if most_methods >= 4 {
        Layout::PerMethod
    } else {
        Layout::Main
    }
}

/// The scene's views, each with its camera.
pub(super) fn views(scene: &Scene, plan: &ViewInputs) -> Vec<View3d> {
    let layout = plan.layout;
    let whole = |name: &str| View3d {
        name: name.to_owned(),
        ..Default::default()
    };
    let mut views = match layout {
        Layout::Together => vec![whole("3D")],
        Layout::Main => {
            let mut view = whole("3D");
            for drawn in plan.poses {
                view.hidden.extend(
                    drawn
                        .others
                        .iter()
                        .filter(|m| **m != Estimate::Method(Method::VectorSpace))
                        .map(|m| paths::method(&drawn.pose, m.segment())),
                );
            }
            vec![view]
        }
        Layout::PerMethod => per_method(plan),
        Layout::PerPose => plan
            .poses
            .iter()
            .map(|drawn| View3d {
                name: drawn.pose.clone(),
                include: vec![paths::pose(&drawn.pose)],
                ..Default::default()
            })
            .collect(),
    };
    if views.is_empty() {
        views.push(whole("3D"));
    }
    // Each view's real shape at 1024 × 640: the left column over the legend view, divided
    // among the views.
    let aspect = views_aspect(scene, views.len());
    for view in &mut views {
        view.camera = camera(&points_of(scene, view, |_| true), plan, aspect);
        view.grid_spacing = view.camera.as_ref().map(grid_spacing);
    }
    views
}

/// A pose graph's views: "before" (the file's estimates and the odometry chain, everything
/// but `after` and the zooms) and "after" (the subtree `after`: optimised poses and
/// marginals, true size), then one robot-scale view per zoom (its subtree), each with its own
/// camera.
pub(super) fn before_after(
    scene: &Scene,
    plan: &ViewInputs,
    after: &str,
    zooms: &[super::graph::Zoom],
) -> Vec<View3d> {
    let mut views = vec![
        View3d {
            name: "before: file estimates, odometry chain".to_owned(),
            exclude: vec![after.to_owned(), paths::zooms()],
            ..Default::default()
        },
        View3d {
            name: "after: optimised, marginals true size".to_owned(),
            include: vec![after.to_owned()],
            ..Default::default()
        },
    ];
    views.extend(zooms.iter().map(|z| View3d {
        name: z.name.clone(),
        include: vec![z.path.clone()],
        ..Default::default()
    }));
    let aspect = views_aspect(scene, views.len());
    // The after view opens on the final solution: fitted to its last state and what is
    // static, not to the dead-reckoning state it starts the timeline with.
    let last = scene
        .states
        .as_ref()
        .and_then(|s| s.steps.last())
        .map(|s| s.step);
    let keep = |i: &SceneItem| match i.timing {
        crate::scene::Timing::Step(k) => {
            !scene.states.as_ref().is_some_and(|s| s.contains(&i.path)) || Some(k) == last
        }
        _ => true,
    };
    // Each view's points (the before view's are every cloud: 10⁵ and more) on its own core.
    views.par_iter_mut().for_each(|view| {
        view.camera = camera(&robust(points_of(scene, view, keep)), plan, aspect);
        view.grid_spacing = view.camera.as_ref().map(grid_spacing);
    });
    views
}

/// The points without outliers: those within 1.5 × the 98th-percentile distance from the
/// median point (per axis), so that one far pose or cloud sample does not shrink the rest.
///
fn robust(points: Vec<Vector3<f64>>) -> Vec<Vector3<f64>> {
    if points.len() < 20 {
        return points;
    }
    // The k-th smallest of each list by selection (O(n)), not a sort: the same value.
    let kth = |mut v: Vec<f64>, k: usize| *v.select_nth_unstable_by(k, f64::total_cmp).1;
    let median = |axis: usize| {
        let v: Vec<f64> = points.iter().map(|p| p[axis]).collect();
        let half = v.len() / 2;
        kth(v, half)
    };
    let centre = Vector3::new(median(0), median(1), median(2));
    let d: Vec<f64> = points.iter().map(|p| (p - centre).norm()).collect();
    let at = (d.len() as f64 * 0.98) as usize;
    let reach = 1.5 * kth(d, at);
    points
        .into_iter()
        .filter(|p| (p - centre).norm() <= reach)
        .collect()
}

/// The ground grid's spacing for a view opening with `camera`: a nice length (1, 2 or 5 ×
/// 10ᵏ m) about a quarter of the eye's height over the grid's plane z = 0 (at least a fifth of
/// its distance to the target, for an eye level with the plane). The viewer draws lines this
/// far apart while the eye is less than 10^0.9 ≈ 7.9 spacings from the plane and fades in
/// every tenth line beyond (Rerun 0.36's `world_grid.wgsl`); here the eye is 2.7–7 spacings
/// away, so the title's spacing is the one drawn, four to eight lines across the view.
fn grid_spacing(camera: &Camera) -> f64 {
    let sight: f64 = (0..3)
        .map(|i| (camera.position[i] - camera.target[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    let height = camera.position[2].abs().max(0.2 * sight);
    crate::scene::units::nice_step(height, 4)
}

/// A sentence for the text panel on what the views leave out or hide, if anything.
pub(super) fn note(views: &[View3d]) -> Option<String> {
    let hidden: Vec<String> = views
        .iter()
        .flat_map(|v| &v.hidden)
        .map(|p| format!("`{p}`"))
        .collect();
    if !hidden.is_empty() {
        return Some(format!(
            "*Hidden at first, to keep the picture clear:* {}. Show them with the eye icon in the \
             blueprint panel (the left panel, under the 3D view).\n\n",
            hidden.join(", ")
        ));
    }
    (views.len() > 1).then(|| {
        let names: Vec<&str> = views.iter().map(|v| v.name.as_str()).collect();
        format!(
            "*One 3D view each:* {} — same data, one at a time, so nothing hides anything else.\n\n",
            names.join(", ")
        )
    })
}

/// One view per analytic method, each leaving out the other methods (an input's own
/// Gaussian is shown in every view).
fn per_method(plan: &ViewInputs) -> Vec<View3d> {
    let mut all: Vec<Method> = Vec::new();
    for m in plan.poses {
        for e in m.main.iter().chain(&m.others) {
            if let Estimate::Method(method) = e
                && !all.contains(method)
            {
                all.push(*method);
            }
        }
    }
    all.iter()
        .map(|&shown| View3d {
            name: shown.label().to_owned(),
            exclude: plan
                .poses
                .iter()
                .flat_map(|m| {
                    m.main
                        .iter()
                        .chain(&m.others)
                        .filter(move |e| matches!(e, Estimate::Method(o) if *o != shown))
                        .map(move |e| paths::method(&m.pose, e.segment()))
                })
                .collect(),
            ..Default::default()
        })
        .collect()
}

/// Every point a view draws (of the items `keep` accepts): positions, vertices, ellipsoid and
/// axis extremes.
pub(super) fn points_of(
    scene: &Scene,
    view: &View3d,
    keep: impl Fn(&SceneItem) -> bool,
) -> Vec<Vector3<f64>> {
    let items: Vec<&SceneItem> = scene
        .items
        .iter()
        .filter(|i| view.shows(&i.path) && keep(i))
        .collect();
    // Counted first: one allocation (a view of every cloud holds 10⁵–10⁶ points).
    let count = |item: &SceneItem| match &item.kind {
        ItemKind::Frame(_) => 4,
        ItemKind::Triads(t) => t.translations.len(),
        ItemKind::Points(p) => p.positions.len(),
        ItemKind::Ellipsoids(e) => 6 * e.shapes.len(),
        ItemKind::Surface(s) => s.vertices.len(),
        ItemKind::LineStrips(l) => l.strips.iter().map(Vec::len).sum(),
        ItemKind::Arrows(a) => 2 * a.origins.len(),
        ItemKind::Text(_) => 0,
    };
    let mut out: Vec<Vector3<f64>> = Vec::with_capacity(items.iter().map(|i| count(i)).sum());
    let all = |out: &mut Vec<Vector3<f64>>, points: &[Vec3]| {
        out.extend(points.iter().map(|p| Vector3::from(*p)));
    };
    for item in items {
        match &item.kind {
            ItemKind::Frame(f) => {
                out.push(f.translation.into());
                for k in 0..3 {
                    let mut axis = [0.0; 3];
                    axis[k] = f.axis_length;
                    out.push(add(&f.translation, &rotate(&f.rotation, axis)).into());
                }
            }
            ItemKind::Triads(t) => all(&mut out, &t.translations),
            ItemKind::Points(p) => all(&mut out, &p.positions),
            ItemKind::Ellipsoids(e) => {
                for s in &e.shapes {
                    for k in 0..3 {
                        let mut axis = [0.0; 3];
                        axis[k] = s.half_sizes[k];
                        let v = rotate(&s.rotation, axis);
                        out.push(add(&s.center, &v).into());
                        out.push(add(&s.center, &v.map(|x| -x)).into());
                    }
                }
            }
            ItemKind::Surface(s) => all(&mut out, &s.vertices),
            ItemKind::LineStrips(l) => {
                for strip in &l.strips {
                    all(&mut out, strip);
                }
            }
            ItemKind::Arrows(a) => {
                all(&mut out, &a.origins);
                out.extend(
                    a.origins
                        .iter()
                        .zip(&a.vectors)
                        .map(|(o, v)| Vector3::from(add(o, v))),
                );
            }
            ItemKind::Text(_) => {}
        }
    }
    out
}

fn add(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// The camera of a view that draws `points` ([module docs](self)); `None` without points.
pub(super) fn camera(points: &[Vector3<f64>], plan: &ViewInputs, aspect: f64) -> Option<Camera> {
    let choice = plan.camera.unwrap_or_default();
    let up = choice.up.map_or(Vector3::z(), Vector3::from).normalize();
    if let Some(position) = choice.position {
        let target = choice
            .target
            .map(Vector3::from)
            .or_else(|| centre(points))?;
        return Some(Camera {
            position,
            target: target.into(),
            up: up.into(),
        });
    }
    if points.is_empty() {
        return None;
    }
    let towards_eye = match choice.direction {
        Some(d) => Vector3::from(d).normalize(),
        None if plan.top => tilted(&up, &Vector3::y(), -TOP_TILT_DEG),
        None if plan.rotation_only => Vector3::new(1.0, 0.8, 0.7).normalize(),
        None => oblique(points, &up),
    };
    let (target, distance) = fit(
        points,
        &towards_eye,
        &up,
        choice.target.map(Vector3::from),
        aspect,
    );
    Some(Camera {
        position: (target + towards_eye * distance).into(),
        target: target.into(),
        up: up.into(),
    })
}

/// `axis` turned by `degrees` towards `towards` (both unit, orthogonal enough).
fn tilted(axis: &Vector3<f64>, towards: &Vector3<f64>, degrees: f64) -> Vector3<f64> {
    let side = (towards - axis * axis.dot(towards)).normalize();
    let a = degrees.to_radians();
    (axis * a.cos() + side * a.sin()).normalize()
}

/// The thinnest direction of the points, seen from above (+`up` side), tilted so depth reads.
fn oblique(points: &[Vector3<f64>], up: &Vector3<f64>) -> Vector3<f64> {
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let spread: Matrix3<f64> = points
        .iter()
        .map(|p| (p - mean) * (p - mean).transpose())
        .sum::<Matrix3<f64>>();
    let eigen = SymmetricEigen::new(spread);
    let k = eigen.eigenvalues.imin();
    // No thin direction (a sphere, a ball of poses): its thinnest axis is chance, so the eye
    // stands where a 3-D shape reads, above and to the side (x to the right, y away, z up).
    if eigen.eigenvalues[k] > ROUND * eigen.eigenvalues.max() {
        return Vector3::from(ROUND_EYE).normalize();
    }
    let mut n = eigen.eigenvectors.column(k).into_owned();
    if n.dot(up) < 0.0 {
        n = -n;
    }
    // Lying (nearly) flat: seen from the south and above, x still to the right.
    if n.dot(up) > FLAT_DEG.to_radians().cos() {
        return tilted(up, &Vector3::y(), -FLAT_TILT_DEG);
    }
    // Standing up: tilted from its thin direction towards the up axis, so depth reads.
    let towards = (up - n * n.dot(up)).normalize();
    tilted(&n, &towards, OBLIQUE_TILT_DEG)
}

/// The middle of the points' bounding box.
fn centre(points: &[Vector3<f64>]) -> Option<Vector3<f64>> {
    let first = points.first()?;
    let (lo, hi) = points
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    Some((lo + hi) / 2.0)
}

/// The look target (the middle of the points as seen along `towards_eye`, unless given) and
/// the eye's distance from it at which every point fits the field of view.
fn fit(
    points: &[Vector3<f64>],
    towards_eye: &Vector3<f64>,
    up: &Vector3<f64>,
    target: Option<Vector3<f64>>,
    aspect: f64,
) -> (Vector3<f64>, f64) {
    let forward = -towards_eye;
    let right = forward
        .cross(up)
        .try_normalize(1e-9)
        .unwrap_or_else(Vector3::x);
    let screen_up = right.cross(&forward);
    let coords: Vec<Vector3<f64>> = points
        .iter()
        .map(|p| Vector3::new(p.dot(&right), p.dot(&screen_up), p.dot(towards_eye)))
        .collect();
    let target_coords = match target {
        Some(t) => Vector3::new(t.dot(&right), t.dot(&screen_up), t.dot(towards_eye)),
        None => centre(&coords).unwrap_or_else(Vector3::zeros),
    };
    let (tan_y, tan_x) = ((FOV_Y / 2.0).tan(), (FOV_Y / 2.0).tan() * aspect);
    let distance = coords
        .iter()
        .map(|c| {
            let d = c - target_coords;
            d.z + (d.x.abs() / tan_x).max(d.y.abs() / tan_y)
        })
        .fold(0.0, f64::max)
        * MARGIN;
    let extent = coords
        .iter()
        .map(|c| (c - target_coords).norm())
        .fold(0.0, f64::max);
    let target =
        right * target_coords.x + screen_up * target_coords.y + towards_eye * target_coords.z;
    (target, distance.max(0.5 * extent).max(0.05))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A view's width over height (the one [`views_aspect`] gives without a legend).
    const ASPECT: f64 = 600.0 / 554.0;

    fn plan(poses: &[PoseMethods], top: bool) -> ViewInputs<'_> {
        ViewInputs {
            poses,
            rotation_only: false,
            top,
            layout: Layout::Main,
            camera: None,
        }
    }

    #[test]
    fn the_top_view_has_x_to_the_right_and_fits_the_points() {
        let poses = Vec::new();
        let points = [Vector3::new(-1.0, -1.0, 0.0), Vector3::new(3.0, 1.0, 0.0)];
        let c = camera(&points, &plan(&poses, true), ASPECT).unwrap();
        let (eye, target) = (Vector3::from(c.position), Vector3::from(c.target));
        assert!(
            (target - Vector3::new(1.0, 0.0, 0.0)).norm() < 0.05,
            "{target}"
        );
        let sight = (target - eye).normalize();
        // Looking down, within the tilt; the screen's right is +x.
        assert!(sight.z < -(TOP_TILT_DEG + 0.1).to_radians().cos());
        let right = sight.cross(&Vector3::from(c.up)).normalize();
        assert!((right - Vector3::x()).norm() < 1e-6, "{right}");
        // Both corners inside the horizontal field of view.
        let half_width = 2.0;
        assert!(half_width / (eye - target).norm() < (FOV_Y / 2.0).tan() * ASPECT);
        assert!(c.check("top").is_ok());
    }

    #[test]
    fn a_thin_3d_scene_is_seen_across_its_thin_direction() {
        let poses = Vec::new();
        // Points in the x–z plane: the thin direction is y.
        let points: Vec<Vector3<f64>> = (0..20)
            .map(|i| Vector3::new((i % 5) as f64, 0.01 * (i % 2) as f64, (i / 5) as f64))
            .collect();
        let c = camera(&points, &plan(&poses, false), ASPECT).unwrap();
        let sight = (Vector3::from(c.target) - Vector3::from(c.position)).normalize();
        let off = sight.dot(&Vector3::y()).abs().acos().to_degrees();
        assert!((off - OBLIQUE_TILT_DEG).abs() < 1.0, "{off}°");
    }

    #[test]
    fn a_round_3d_scene_is_seen_from_above_and_aside() {
        let poses = Vec::new();
        // Points on a sphere: no thin direction.
        let points: Vec<Vector3<f64>> = (0..400)
            .map(|i| {
                let (a, b) = (i as f64 * 0.61, (i as f64 / 400.0 * 2.0 - 1.0).acos());
                10.0 * Vector3::new(b.sin() * a.cos(), b.sin() * a.sin(), b.cos())
            })
            .collect();
        let c = camera(&points, &plan(&poses, false), ASPECT).unwrap();
        let towards_eye = (Vector3::from(c.position) - Vector3::from(c.target)).normalize();
        assert!((towards_eye - Vector3::from(ROUND_EYE).normalize()).norm() < 1e-9);
        assert!(c.check("sphere").is_ok());
    }

    #[test]
    fn one_far_point_does_not_shrink_the_rest() {
        let mut points: Vec<Vector3<f64>> = (0..99)
            .map(|i| Vector3::new((i % 10) as f64, (i / 10) as f64, 0.0))
            .collect();
        points.push(Vector3::new(1e6, 0.0, 0.0));
        let kept = robust(points);
        assert_eq!(kept.len(), 99);
        assert!(kept.iter().all(|p| p.x < 10.0));
    }

    #[test]
    fn a_file_camera_position_is_kept() {
        let poses = Vec::new();
        let mut p = plan(&poses, false);
        p.camera = Some(CameraChoice {
            position: Some([1.0, 2.0, 3.0]),
            ..Default::default()
        });
        let c = camera(&[Vector3::zeros()], &p, ASPECT).unwrap();
        assert_eq!(c.position, [1.0, 2.0, 3.0]);
        assert_eq!(c.target, [0.0; 3]);
    }
}
