//! The viewer's labels, fitted to the views they open in.
//!
//! The viewer draws a label at a fixed size (its 13-point text, centred under the labelled
//! point) whatever the view's scale, so in a view a few hundred points wide the labels of poses
//! a few metres apart would cover each other. Per 3-D view, with the camera it opens with and
//! its size at 1024 × 640 ([`crate::scene::layout::views_aspect`]), each labelled frame it
//! draws is projected to the view's points and its viewer label's box measured
//! ([`viewer_text_width`]); in order of importance (frames with a tag first — those were chosen
//! by importance — then the others, each in the scene's order) a label whose box overlaps one
//! kept before it, or whose point lies outside the view, is left out of the viewer (its
//! frame's tag set empty, [`Frame::viewer_label`]). A figure places its labels itself and
//! keeps them all. The text panel gets one paragraph: each tag with its whole words, and the
//! labels left out.

use std::collections::HashMap;
use std::fmt::Write as _;

use nalgebra::Vector3;

use crate::scene::layout::{DESIGN_WIDTH, viewer_text_width, views_aspect};
use crate::scene::{Camera, Frame, ItemKind, Scene, SceneItem, Timing, grid_columns};

/// Padding the viewer puts around a label's words, each side, in points.
const PAD_X: f64 = 4.0;
/// A label box's height (one line of text and its padding), in points.
const BOX_HEIGHT: f64 = 19.0;
/// The gap between the labelled point and its box's top, in points.
const BELOW: f64 = 3.0;
/// Room kept between two labels, in points.
const GAP: f64 = 3.0;

/// A label's box in a view, in points from the view's top left.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LabelBox {
    x: [f64; 2],
    y: [f64; 2],
}

impl LabelBox {
    /// The box of `words` drawn under the point `at`.
    fn under(at: [f64; 2], words: &str) -> Self {
        let half = 0.5 * viewer_text_width(words) + PAD_X;
        Self {
            x: [at[0] - half, at[0] + half],
            y: [at[1] + BELOW, at[1] + BELOW + BOX_HEIGHT],
        }
    }

    /// Whether the two boxes come closer than [`GAP`].
    fn crowds(&self, other: &Self) -> bool {
        self.x[0] < other.x[1] + GAP
            && other.x[0] < self.x[1] + GAP
            && self.y[0] < other.y[1] + GAP
            && other.y[0] < self.y[1] + GAP
    }
}

/// A view's opening camera as a projection to the view's points.
struct Screen {
    eye: Vector3<f64>,
    forward: Vector3<f64>,
    right: Vector3<f64>,
    up: Vector3<f64>,
    /// tan of half the horizontal and the vertical field of view.
    tan: [f64; 2],
    /// The view's width and height in points.
    size: [f64; 2],
}

impl Screen {
    /// The projection of `camera` in a view `width` points wide of width over height
    /// `aspect`, with the viewer's vertical field of view `fov_y` (radians).
    fn new(camera: &Camera, (width, aspect): (f64, f64), fov_y: f64) -> Option<Self> {
        let eye = Vector3::from(camera.position);
        let forward = (Vector3::from(camera.target) - eye).try_normalize(1e-12)?;
        let right = forward
            .cross(&Vector3::from(camera.up))
            .try_normalize(1e-12)?;
        let up = right.cross(&forward);
        let tan_y = (0.5 * fov_y).tan();
        Some(Self {
            eye,
            forward,
            right,
            up,
            tan: [tan_y * aspect, tan_y],
            size: [width, width / aspect],
        })
    }

    /// A world point in the view's points (from its top left); `None` behind the eye.
    fn point(&self, p: &[f64; 3]) -> Option<[f64; 2]> {
        let d = Vector3::from(*p) - self.eye;
        let depth = d.dot(&self.forward);
        (depth > 1e-12).then(|| {
            let x = d.dot(&self.right) / (depth * self.tan[0]);
            let y = d.dot(&self.up) / (depth * self.tan[1]);
            [
                0.5 * self.size[0] * (1.0 + x),
                0.5 * self.size[1] * (1.0 - y),
            ]
        })
    }

    /// Whether a point lies inside the view.
    fn inside(&self, at: [f64; 2]) -> bool {
        (0.0..=self.size[0]).contains(&at[0]) && (0.0..=self.size[1]).contains(&at[1])
    }
}

/// Leaves out of the viewer every label of `scene` that would cover a more important one (or
/// whose point lies outside its view) as the views open ([module docs](self)), with the
/// viewer's vertical field of view `fov_y`, and adds the paragraph on the labels to the text
/// panel. Run once the views have their cameras.
pub(super) fn fit_tags(scene: &mut Scene, fov_y: f64) {
    let count = scene.views.len();
    if count == 0 {
        return;
    }
    let aspect = views_aspect(scene, count);
    let width = DESIGN_WIDTH / grid_columns(count) as f64;
    // Per entity, the item the views open with: the latest (static first, then by step).
    let mut latest: HashMap<&str, usize> = HashMap::new();
    for (k, item) in scene.items.iter().enumerate() {
        if matches!(&item.kind, ItemKind::Frame(f) if f.viewer_label().is_some()) {
            let newer = latest
                .get(item.path.as_str())
                .is_none_or(|&old| opens_later(item, &scene.items[old]));
            if newer {
                latest.insert(item.path.as_str(), k);
            }
        }
    }
    let mut labelled: Vec<usize> = latest.into_values().collect();
    // Tags first (chosen by importance), then the others; each in the scene's order.
    labelled.sort_by_key(|&k| (frame(&scene.items[k]).tag.is_none(), k));
    let mut left_out: Vec<(usize, String)> = Vec::new();
    for view in &scene.views {
        let Some(screen) = view
            .camera
            .as_ref()
            .and_then(|c| Screen::new(c, (width, aspect.max(1e-6)), fov_y))
        else {
            continue;
        };
        let mut kept: Vec<LabelBox> = Vec::new();
        for &k in labelled
            .iter()
            .filter(|&&k| view.draws(&scene.items[k].path))
        {
            let f = frame(&scene.items[k]);
            let words = f.viewer_label().unwrap_or_default();
            let placed = screen
                .point(&f.translation)
                .filter(|at| screen.inside(*at))
                .map(|at| LabelBox::under(at, words));
            match placed {
                Some(b) if !kept.iter().any(|o| o.crowds(&b)) => kept.push(b),
                _ => left_out.push((k, view.name.clone())),
            }
        }
    }
    let paragraph = paragraph(scene, &labelled, &left_out);
    for (k, _) in &left_out {
        if let ItemKind::Frame(f) = &mut scene.items[*k].kind {
            f.tag = Some(String::new());
        }
    }
    scene.description_markdown.push_str(&paragraph);
}

/// The frame of an item known to be one.
fn frame(item: &SceneItem) -> &Frame {
    match &item.kind {
        ItemKind::Frame(f) => f,
        _ => unreachable!("only frames are labelled"),
    }
}

/// Whether `a` is what the viewer shows of its entity at the last step rather than `b`.
fn opens_later(a: &SceneItem, b: &SceneItem) -> bool {
    let rank = |t: Timing| match t {
        Timing::Static => (0, 0),
        Timing::Step(k) => (1, k),
        Timing::Stamp(ns) => (2, ns),
    };
    rank(a.timing) >= rank(b.timing)
}

/// The text panel's paragraph: each tag and the whole words it stands for, and the labels
/// left out of the viewer (empty when no label has a tag and none is left out).
fn paragraph(scene: &Scene, labelled: &[usize], left_out: &[(usize, String)]) -> String {
    let tagged: Vec<String> = labelled
        .iter()
        .map(|&k| frame(&scene.items[k]))
        .filter_map(|f| match (&f.tag, &f.label) {
            (Some(tag), Some(label)) if !tag.is_empty() && tag != label => {
                Some(format!("*{tag}*: {label}"))
            }
            _ => None,
        })
        .collect();
    let out: Vec<String> = left_out
        .iter()
        .map(|(k, view)| {
            let words = frame(&scene.items[*k]).viewer_label().unwrap_or_default();
            format!("*{words}* ({view})")
        })
        .collect();
    if tagged.is_empty() && out.is_empty() {
        return String::new();
    }
    let mut s = String::from("\n\n**Labels**");
    if !tagged.is_empty() {
        let _ = write!(
            s,
            " (the viewer writes short tags; a figure the whole words): {}.",
            tagged.join("; ")
        );
    }
    if !out.is_empty() {
        let _ = write!(
            s,
            " Left out of the viewer, where they would cover a more important label as the view opens (zoom in, or see the figure): {}.",
            out.join(", ")
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::View3d;

    fn labelled(path: &str, at: [f64; 3], tag: &str) -> SceneItem {
        SceneItem::new(
            path,
            Timing::Static,
            ItemKind::Frame(Frame {
                translation: at,
                rotation: [0.0, 0.0, 0.0, 1.0],
                axis_length: 0.1,
                label: Some(format!("{tag}: the whole words")),
                tag: Some(tag.to_owned()),
            }),
        )
    }

    fn top_view(height: f64) -> View3d {
        View3d {
            name: "top".into(),
            camera: Some(Camera {
                position: [0.0, 0.0, height],
                target: [0.0; 3],
                up: [0.0, 1.0, 0.0],
            }),
            ..Default::default()
        }
    }

    fn viewer_label(scene: &Scene, k: usize) -> Option<&str> {
        frame(&scene.items[k]).viewer_label()
    }

    #[test]
    fn a_label_on_a_more_important_one_is_left_out_and_said() {
        let mut scene = Scene::new("t", "");
        scene.push(labelled("world/a", [0.0, 0.0, 0.0], "v1 worst"));
        scene.push(labelled("world/b", [0.01, 0.0, 0.0], "v2 first"));
        scene.push(labelled("world/c", [8.0, 8.0, 0.0], "v3 last"));
        scene.views = vec![top_view(30.0)];
        fit_tags(&mut scene, 55f64.to_radians());
        assert_eq!(viewer_label(&scene, 0), Some("v1 worst"));
        assert_eq!(viewer_label(&scene, 1), None);
        assert_eq!(viewer_label(&scene, 2), Some("v3 last"));
        let d = &scene.description_markdown;
        assert!(d.contains("*v2 first*: v2 first: the whole words"), "{d}");
        assert!(
            d.contains("Left out of the viewer") && d.contains("*v2 first* (top)"),
            "{d}"
        );
    }

    #[test]
    fn labels_far_apart_on_screen_all_stay() {
        let mut scene = Scene::new("t", "");
        scene.push(labelled("world/a", [-5.0, 0.0, 0.0], "v1 worst"));
        scene.push(labelled("world/b", [5.0, 0.0, 0.0], "v2 first"));
        scene.views = vec![top_view(30.0)];
        fit_tags(&mut scene, 55f64.to_radians());
        assert!((0..2).all(|k| viewer_label(&scene, k).is_some()));
        // Seen from far away, the same two poses come together on screen.
        scene.views = vec![top_view(3000.0)];
        fit_tags(&mut scene, 55f64.to_radians());
        assert_eq!(viewer_label(&scene, 1), None);
    }

    #[test]
    fn boxes_are_measured_in_points_under_their_point() {
        let b = LabelBox::under([100.0, 50.0], "v1");
        assert!(b.x[0] < 100.0 && b.x[1] > 100.0 && b.y[0] > 50.0);
        let far = LabelBox::under([100.0, 50.0 + BOX_HEIGHT + BELOW + 2.0 * GAP], "v1");
        assert!(!b.crowds(&far) && b.crowds(&LabelBox::under([110.0, 52.0], "v2")));
    }
}
