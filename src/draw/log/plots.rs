//! A log's plots over the stamp: σ of position (parent axes), σ of rotation, and the position
//! trace, one line per topic and axis. Each plot's unit fits its values — mm below 0.5 m, m
//! above; degrees, or mrad below 1° — and its range is fitted to them from 0 (a constant σ is
//! a flat line at its level, not lost in a ±1 default).

use super::super::shapes::AXIS_COLORS;
use super::MEANING;
use crate::eval::log::LogEvaluation;
use crate::plan::log::{ROS_AXES, SeriesPoint};
use crate::scene::paths::{self, topic_segments};
use crate::scene::{Corner, Plot, PlotId, ScalarSeries, Scene};

/// Room above the largest value.
const HEADROOM: f64 = 1.15;

/// Each unit a plot is drawn in and its factor from SI.
const UNITS: [(&str, f64); 6] = [
    ("mm", 1e3),
    ("m", 1.0),
    ("mrad", 1e3),
    ("°", 180.0 / std::f64::consts::PI),
    ("mm²", 1e6),
    ("m²", 1.0),
];

/// The factor from SI of a plot's `unit` (one of [`UNITS`]; 1 for another).
fn factor_of(unit: &str) -> f64 {
    UNITS
        .iter()
        .find(|(name, _)| *name == unit)
        .map_or(1.0, |(_, factor)| *factor)
}

/// A plot's unit for values whose largest is `max` (in SI `si`): its name and the factor
/// from SI.
fn unit_for(si: &str, max: f64) -> (&'static str, f64) {
    let name = match si {
        "m" if max < 0.5 => "mm",
        "m" => "m",
        "rad" if max.to_degrees() < 1.0 => "mrad",
        "rad" => "°",
        "m²" if max < 0.25 => "mm²",
        _ => "m²",
    };
    (name, factor_of(name))
}

/// What one message adds to the lines of a picture already shown (`scene`, its series as
/// they were logged): a one-point series for each of its topic's lines in `scene` — σ per
/// axis, the position trace — its value (`point`, as the topic's series holds it) in the
/// plot's unit, the line's generation, name and colour kept. A live view streams these as
/// each message arrives, between whole pictures; a line the picture does not have (a topic
/// or axis new since) gets nothing until the next picture.
///
/// ```
/// use posecov::draw::log::message_points;
/// use posecov::plan::log::SeriesPoint;
/// use posecov::scene::{Color, Plot, PlotId, ScalarSeries, Scene};
/// let mut shown = Scene::new("live", "");
/// shown.plots.push(Plot { id: PlotId::new("sigma_position"), title: "σ xy".into(), unit: "mm".into(), range: None, legend: Default::default() });
/// shown.series.push(ScalarSeries::new(PlotId::new("sigma_position"), "odom/x", "σx", Color::rgb(0, 0, 0), 1.5, vec![(1, 50.0)]));
/// let point = SeriesPoint { stamp_ns: 2, sigma: [Some(0.06), None, None, None, None, None], position_trace: Some(0.0036) };
/// let added = message_points(&shown, "/odom", &point);
/// assert_eq!(added.len(), 1);
/// assert_eq!(added[0].path(), "plots/sigma_position/odom/x");
/// assert_eq!(added[0].points.len(), 1);
/// assert!((added[0].points[0].1 - 60.0).abs() < 1e-9);
/// ```
pub fn message_points(scene: &Scene, topic: &str, point: &SeriesPoint) -> Vec<ScalarSeries> {
    let segments = topic_segments(topic);
    let value_in = |plot: &str, si: f64| {
        let unit = scene
            .plots
            .iter()
            .find(|p| p.id.as_str() == plot)
            .map_or("", |p| p.unit.as_str());
        si * factor_of(unit)
    };
    let mut values: Vec<(&str, String, f64)> = ROS_AXES
        .iter()
        .zip(point.sigma)
        .enumerate()
        .filter_map(|(axis, (name, sigma))| {
            let plot = if axis < 3 {
                "sigma_position"
            } else {
                "sigma_rotation"
            };
            sigma.map(|v| (plot, paths::child(&segments, name), v))
        })
        .collect();
    if let Some(trace) = point.position_trace {
        values.push(("position_trace", segments.clone(), trace));
    }
    values
        .into_iter()
        .filter_map(|(plot, segment, si)| {
            let line = scene
                .series
                .iter()
                .find(|s| s.plot.as_str() == plot && s.segment == segment)?;
            let value = value_in(plot, si);
            value.is_finite().then(|| ScalarSeries {
                plot: line.plot.clone(),
                segment: line.segment.clone(),
                generation: line.generation,
                name: line.name.clone(),
                color: line.color,
                width: line.width,
                marks: line.marks,
                points: vec![(point.stamp_ns, value)],
            })
        })
        .collect()
}

/// σ per axis and the position trace over the stamp, one line per topic and axis, each plot
/// in its fitted unit and range.
pub(super) fn plots(scene: &mut Scene, e: &LogEvaluation) {
    let planar = scene.planar;
    // (plot id, title, SI unit, lines: (path tail, name, colour, points in SI)).
    type Line = (String, String, crate::scene::Color, Vec<(i64, f64)>);
    let mut position: Vec<Line> = Vec::new();
    let mut rotation: Vec<Line> = Vec::new();
    let mut trace: Vec<Line> = Vec::new();
    // A line's name: its axis, after its topic when several topics share the plot.
    let several = e.topics.iter().filter(|t| !t.series.is_empty()).count() > 1;
    let named = |topic: &str, what: &str| {
        if several {
            format!("{topic} {what}")
        } else {
            what.to_owned()
        }
    };
    for t in &e.topics {
        let topic = topic_segments(&t.name);
        for (axis, name) in ROS_AXES.iter().enumerate() {
            let points: Vec<(i64, f64)> = t
                .series
                .iter()
                .filter_map(|s| s.sigma[axis].map(|v| (s.stamp_ns, v)))
                .collect();
            if points.is_empty() || (planar && [2, 3, 4].contains(&axis)) {
                continue;
            }
            let line = (
                paths::child(&topic, name),
                named(&t.name, &format!("σ{name}")),
                AXIS_COLORS[axis % 3],
                points,
            );
            if axis < 3 {
                position.push(line);
            } else {
                rotation.push(line);
            }
        }
        let points: Vec<(i64, f64)> = t
            .series
            .iter()
            .filter_map(|s| s.position_trace.map(|v| (s.stamp_ns, v)))
            .collect();
        if !points.is_empty() {
            trace.push((topic, named(&t.name, "tr Σ_position"), MEANING, points));
        }
    }
    scene.plots.clear();
    let titles = if planar {
        ["σ xy", "σ yaw", "tr Σxy"]
    } else {
        ["σ xyz", "σ rpy", "tr Σxyz"]
    };
    for (id, title, si, lines) in [
        // Short titles (at 1024 × 640 a plot's tab shows about 12 characters): the axes.
        ("sigma_position", titles[0], "m", position),
        ("sigma_rotation", titles[1], "rad", rotation),
        ("position_trace", titles[2], "m²", trace),
    ] {
        let max = lines
            .iter()
            .flat_map(|l| l.3.iter().map(|p| p.1))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let (unit, factor) = unit_for(si, max);
        let top = if max > 0.0 {
            HEADROOM * max * factor
        } else {
            1.0
        };
        scene.plots.push(Plot {
            id: PlotId::new(id),
            title: title.into(),
            unit: unit.into(),
            range: Some([0.0, top]),
            // Where the viewer puts it by default: these plots leave room below their lines.
            legend: Corner::LeftBottom,
        });
        for (tail, name, color, points) in lines {
            scene.series.push(ScalarSeries::new(
                PlotId::new(id),
                tail,
                name,
                color,
                1.5,
                points.into_iter().map(|(t, v)| (t, v * factor)).collect(),
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_sigmas_are_plotted_in_mm_and_degrees() {
        assert_eq!(unit_for("m", 0.0316), ("mm", 1e3));
        assert_eq!(unit_for("m", 3.0), ("m", 1.0));
        assert_eq!(unit_for("rad", 0.173).0, "°");
        assert_eq!(unit_for("rad", 0.001), ("mrad", 1e3));
        assert_eq!(unit_for("m²", 0.002), ("mm²", 1e6));
        assert_eq!(
            factor_of(unit_for("rad", 0.5).0),
            180.0 / std::f64::consts::PI
        );
    }
}
