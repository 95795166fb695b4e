//! A world panel's labels: each frame's label (and an all-steps figure's step numbers) placed
//! beside its frame where its box keeps clear of every other label and of the scale bar
//! ([`place_label`]), broken into lines that end before the panel's edge ([`label_lines`]).

use super::chart::Rect;
use super::svg::{Px, Svg, num};
use super::world::{Mapping, Pen, Plane};
use crate::scene::{ItemKind, SceneItem};

/// Labels: each frame's own label, and in an all-steps figure the step number beside each
/// step's frame (at most about a dozen, evenly spaced, always the last). A label too long for
/// the room left of the panel's right edge is broken into lines ([`label_lines`]). Each label
/// is placed where its box overlaps no label placed before it and none of the boxes of
/// `avoid` (the scale bar), inside the panel `area` ([`place_label`]); one moved away from its
/// frame gets a thin leader line to it; one with no free place is left out.
pub fn draw_labels(
    svg: &mut Svg,
    items: &[&SceneItem],
    (plane, m): (Plane, &Mapping),
    pen: Pen,
    (steps, area): (bool, Rect),
    avoid: &[Rect],
) {
    let frames: Vec<(&SceneItem, &crate::scene::Frame)> = items
        .iter()
        .filter_map(|i| match &i.kind {
            ItemKind::Frame(f) => Some((*i, f)),
            _ => None,
        })
        .collect();
    let stepped: Vec<i64> = {
        let mut s: Vec<i64> = frames
            .iter()
            .filter_map(|(i, _)| match i.timing {
                crate::scene::Timing::Step(k) => Some(k),
                _ => None,
            })
            .collect();
        s.sort_unstable();
        s.dedup();
        s
    };
    let stride = stepped.len().div_ceil(12).max(1);
    let last = stepped.last().copied();
    let labelled = |k: i64| {
        let index = stepped.iter().position(|s| *s == k).unwrap_or(0);
        index % stride == 0 || Some(k) == last
    };
    let mut named = std::collections::BTreeSet::new();
    let mut placed: Vec<Rect> = avoid.to_vec();
    let f = pen.font;
    for (item, frame) in frames {
        let anchor = m.px(plane.project(frame.translation));
        let text = match (item.timing, steps) {
            (crate::scene::Timing::Step(k), true) => labelled(k).then(|| format!("{k}")),
            _ => frame.label.clone().filter(|l| named.insert(l.clone())),
        };
        let Some(text) = text else {
            continue;
        };
        let (_, lines) = label_lines(&text, anchor[0] + 0.5 * f, f, area.right());
        let Some(at) = place_label(anchor, &lines, f, area, &placed) else {
            continue;
        };
        placed.push(at.rect);
        if at.moved {
            let to = [
                anchor[0].clamp(at.rect.x, at.rect.right()),
                anchor[1].clamp(at.rect.y, at.rect.bottom()),
            ];
            svg.line(
                anchor,
                to,
                crate::scene::Color::rgb(90, 90, 90),
                0.6 * pen.unit,
                " class=\"label-leader\"",
            );
        }
        for (i, line) in lines.iter().enumerate() {
            svg.raw(&format!(
                "<text class=\"label\" x=\"{}\" y=\"{}\" font-size=\"{}\" fill=\"#222\" stroke=\"white\" stroke-width=\"{}\" paint-order=\"stroke\">{}</text>",
                num(at.rect.x),
                num(at.rect.y + LABEL_ASCENT * f + LABEL_LINE * f * i as f64),
                num(f),
                num(0.25 * f),
                super::svg::escape(line)
            ));
        }
    }
}

/// A label line's height, in font sizes: the lines of one label are this far apart.
pub const LABEL_LINE: f64 = 1.2;
/// From a label's top to its first line's baseline, in font sizes.
pub const LABEL_ASCENT: f64 = 0.9;

/// Where a label goes: its box (pixels) and whether it left its first place beside its frame.
#[derive(Clone, Copy, Debug)]
pub struct LabelPlace {
    /// The box its lines fill (each line [`LABEL_LINE`] font sizes high).
    pub rect: Rect,
    /// Whether it sits away from its first place (and needs a leader line).
    pub moved: bool,
}

/// The first free place for a label of `lines` at font size `f` beside `anchor` (a frame's
/// pixel): above right of it first (where labels always went), then in eight directions at
/// growing distances (up to 12 font sizes away); free means inside `area` and at least
/// [`LABEL_GAP`] font sizes from each of `taken` (two labels that touch read as one phrase).
/// `None` when no place is free.
///
/// ```
/// use posecov::sink::figure::chart::Rect;
/// use posecov::sink::figure::labels::place_label;
/// let area = Rect { x: 0.0, y: 0.0, w: 400.0, h: 300.0 };
/// let lines = vec!["v12: first pose".to_owned()];
/// let first = place_label([100.0, 100.0], &lines, 10.0, area, &[]).unwrap();
/// assert!(!first.moved);
/// // The same label at the same pose again: placed elsewhere, not on the first (still beside
/// // the pose, so no leader line); with the places near it taken too, farther, with one.
/// let second = place_label([100.0, 100.0], &lines, 10.0, area, &[first.rect]).unwrap();
/// assert!(!second.moved && !posecov::sink::figure::labels::overlaps(&first.rect, &second.rect));
/// let near = [first.rect, second.rect, Rect { x: 20.0, y: 60.0, w: 200.0, h: 80.0 }];
/// let third = place_label([100.0, 100.0], &lines, 10.0, area, &near).unwrap();
/// assert!(third.moved && near.iter().all(|r| !posecov::sink::figure::labels::overlaps(r, &third.rect)));
/// ```
pub fn place_label(
    anchor: Px,
    lines: &[String],
    f: f64,
    area: Rect,
    taken: &[Rect],
) -> Option<LabelPlace> {
    let w = lines
        .iter()
        .map(|l| super::svg::text_width(l, f))
        .fold(0.0, f64::max);
    let h = LABEL_LINE * f * lines.len().max(1) as f64;
    let at = |x: f64, y: f64| Rect { x, y, w, h };
    // Above right, as a label always sat: its first line's baseline half a font size up.
    let first = at(anchor[0] + 0.5 * f, anchor[1] - 0.5 * f - LABEL_ASCENT * f);
    let mut candidates = vec![(first, false)];
    for r in [0.6, 1.5, 3.0, 5.0, 8.0, 12.0] {
        let d = r * f;
        let (left, right) = (anchor[0] - d - w, anchor[0] + d);
        let (above, below) = (anchor[1] - d - h, anchor[1] + d);
        let (middle_x, middle_y) = (anchor[0] - 0.5 * w, anchor[1] - 0.5 * h);
        for (x, y) in [
            (right, above),
            (left, above),
            (right, below),
            (left, below),
            (middle_x, above),
            (middle_x, below),
            (right, middle_y),
            (left, middle_y),
        ] {
            candidates.push((at(x, y), r > 0.6));
        }
    }
    candidates
        .into_iter()
        .find(|(rect, _)| {
            rect.x >= area.x
                && rect.y >= area.y
                && rect.right() <= area.right()
                && rect.bottom() <= area.bottom()
                && !taken.iter().any(|t| {
                    let gap = LABEL_GAP * f;
                    let around = Rect {
                        x: t.x - gap,
                        y: t.y - gap,
                        w: t.w + 2.0 * gap,
                        h: t.h + 2.0 * gap,
                    };
                    overlaps(&around, rect)
                })
        })
        .map(|(rect, moved)| LabelPlace { rect, moved })
}

/// The least room between two labels' boxes, in font sizes ([`place_label`]).
pub const LABEL_GAP: f64 = 0.5;

/// Whether two boxes overlap (sharing an edge is not overlapping).
///
/// ```
/// use posecov::sink::figure::{chart::Rect, labels::overlaps};
/// let a = Rect { x: 0.0, y: 0.0, w: 10.0, h: 10.0 };
/// assert!(overlaps(&a, &Rect { x: 5.0, y: 5.0, w: 10.0, h: 10.0 }));
/// assert!(!overlaps(&a, &Rect { x: 10.0, y: 0.0, w: 10.0, h: 10.0 }));
/// ```
pub fn overlaps(a: &Rect, b: &Rect) -> bool {
    a.x < b.right() && b.x < a.right() && a.y < b.bottom() && b.y < a.bottom()
}

/// A label starting at column `x` as lines that end before the panel's `right` edge: whole when
/// it fits, else broken at spaces to the room it has (at least twelve font sizes) and moved
/// left as far as its widest line needs. Returns the lines' left edge and the lines.
///
/// ```
/// use posecov::sink::figure::labels::label_lines;
/// assert_eq!(label_lines("step 3", 10.0, 10.0, 500.0), (10.0, vec!["step 3".to_owned()]));
/// let (x, lines) = label_lines("message 7: σx 31.6 mm, σy 31.6 mm, σyaw 10.00°", 400.0, 10.0, 500.0);
/// assert!(lines.len() == 2 && x < 400.0);
/// ```
pub fn label_lines(text: &str, x: f64, font: f64, right: f64) -> (f64, Vec<String>) {
    let margin = 0.3 * font;
    let room = right - x - margin;
    if super::svg::text_width(text, font) <= room {
        return (x, vec![text.to_owned()]);
    }
    let lines = super::svg::wrap(text, font, room.max(12.0 * font));
    let widest = lines
        .iter()
        .map(|l| super::svg::text_width(l, font))
        .fold(0.0, f64::max);
    (x.min(right - margin - widest), lines)
}
