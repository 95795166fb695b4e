//! A figure's world panels: one per 3-D view of the scene, as the viewer lays them out, and
//! their places in a grid.

use super::Steps;
use super::chart::Rect;
use super::svg;
use crate::scene::{Scene, SceneItem};

/// A world panel of a figure: the items one 3-D view of the scene shows, with the view's name
/// when the scene has several (each its own panel, as the viewer lays them out: a log's frames
/// and its robot-scale view, a graph's before and after, one method each).
pub(super) struct Panel<'a> {
    /// The view's name, for a figure of several panels.
    pub title: Option<&'a str>,
    /// What the panel draws.
    pub items: Vec<&'a SceneItem>,
}

/// The figure's world panels (see [`Panel`]); one for a scene of one view or none, and one
/// untitled empty panel when no view of several shows anything (its axes, as one empty view
/// gets: never a figure without its world).
pub(super) fn panels(scene: &Scene, steps: Steps) -> Vec<Panel<'_>> {
    let items = super::selected(scene, steps);
    let in_view = |view: &crate::scene::View3d, path: &str| view.draws(path);
    match scene.views.as_slice() {
        [] => vec![Panel { title: None, items }],
        [view] => vec![Panel {
            title: None,
            items: items
                .into_iter()
                .filter(|i| in_view(view, &i.path))
                .collect(),
        }],
        views => {
            let shown: Vec<Panel<'_>> = views
                .iter()
                .map(|view| Panel {
                    title: Some(view.name.as_str()),
                    items: items
                        .iter()
                        .copied()
                        .filter(|i| in_view(view, &i.path))
                        .collect(),
                })
                .filter(|panel| !panel.items.is_empty())
                .collect();
            if shown.is_empty() {
                vec![Panel {
                    title: None,
                    items: Vec::new(),
                }]
            } else {
                shown
            }
        }
    }
}

/// `count` cells filling `area` in a grid: the columns that give the largest square-ish cell
/// (a world is drawn at equal scale on both axes), fewer rows on a tie.
pub(super) fn cells(area: Rect, count: usize) -> Vec<Rect> {
    let count = count.max(1);
    let size = |cols: usize| {
        let rows = count.div_ceil(cols);
        (area.w / cols as f64).min(area.h / rows as f64)
    };
    let cols = (1..=count)
        .max_by(|a, b| size(*a).total_cmp(&size(*b)).then(a.cmp(b)))
        .unwrap_or(1);
    let rows = count.div_ceil(cols);
    let (w, h) = (area.w / cols as f64, area.h / rows as f64);
    (0..count)
        .map(|i| Rect {
            x: area.x + w * (i % cols) as f64,
            y: area.y + h * (i / cols) as f64,
            w,
            h,
        })
        .collect()
}

/// A panel's name in at most two lines no wider than `width` at font size `size`, the second
/// ending in "…" when the name is longer.
pub(super) fn title_lines(name: &str, size: f64, width: f64) -> Vec<String> {
    let mut lines = svg::wrap(name, size, width);
    if lines.len() > 2 {
        lines.truncate(2);
        lines[1].push_str(" …");
    }
    lines
}

/// `text` on one line no wider than `width` at font size `size`: whole when it fits, else a
/// path in it shortened to its file name ("/a/b/c.g2o" → "…/c.g2o"), then words left off its
/// end for " …". The figure's title and the line under it never run off the page (the
/// viewer's text panel has the whole title).
pub(super) fn fit_line(text: &str, size: f64, width: f64) -> String {
    let fits = |t: &str| svg::text_width(t, size) <= width;
    if fits(text) {
        return text.to_owned();
    }
    let short: Vec<String> = text
        .split(' ')
        .map(|word| match word.rfind('/') {
            Some(at) if word[..at].contains('/') => format!("…{}", &word[at..]),
            _ => word.to_owned(),
        })
        .collect();
    let mut words = short.join(" ");
    while !fits(&words) {
        let Some((head, _)) = words.trim_end_matches(" …").rsplit_once(' ') else {
            break;
        };
        words = format!("{head} …");
    }
    words
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::View3d;

    #[test]
    fn a_long_title_is_shortened_to_fit_never_cut() {
        let title = "Pose graph /work/shared/data/posegraphs/sphere2500.g2o: 2500 SE(3) poses, 2499 odometry edges, 2449 loop closures";
        assert_eq!(fit_line(title, 10.0, 2000.0), title);
        let short = fit_line(title, 10.0, 420.0);
        assert!(
            short.starts_with("Pose graph …/sphere2500.g2o: 2500 SE(3) poses"),
            "{short}"
        );
        assert!(svg::text_width(&short, 10.0) <= 420.0);
        let shorter = fit_line(title, 10.0, 250.0);
        assert!(
            shorter.ends_with(" …") && svg::text_width(&shorter, 10.0) <= 250.0,
            "{shorter}"
        );
    }

    #[test]
    fn views_that_show_nothing_leave_one_empty_panel() {
        let mut scene = Scene::new("t", "d");
        scene.views = ["a", "b"]
            .map(|name| View3d {
                name: name.into(),
                include: vec![format!("world/{name}")],
                ..Default::default()
            })
            .to_vec();
        let panels = panels(&scene, Steps::All);
        assert_eq!(panels.len(), 1);
        assert!(panels[0].title.is_none() && panels[0].items.is_empty());
    }
}
