//! A log's sensor topics (`sensor_msgs/Imu`, `sensor_msgs/NavSatFix`, twists and accelerations
//! with covariance, an Odometry's twist) in words and plots: each finding's sentence
//! ([`sensor_sentence`]), a paragraph per topic in the text panel, and one σ plot per kind of
//! block (`σ orientation`, `σ angular velocity`, `σ linear acceleration`, `σ linear velocity`,
//! `σ angular acceleration`, a fix's `σ position`) over the stamp, one
//! line per topic and axis, in a unit fitted to the values. Velocities and accelerations are
//! σ plots only: there is nothing in the world view to put them on.

use std::fmt::Write;

use super::super::shapes::AXIS_COLORS;
use super::text::issue_word;
use crate::eval::log::LogEvaluation;
use crate::plan::log::{
    BlockSpec, BlockSummary, Class, Issue, LogSummary, SensorKind, SensorTopicSummary,
};
use crate::scene::paths::{self, topic_segments};
use crate::scene::{Corner, Plot, PlotId, ScalarSeries, Scene};

/// One plain sentence on what a finding means on a sensor topic `t`, on its `block` (`None`:
/// the topic's own finding, its stamps or bytes).
///
/// ```
/// use posecov::draw::log::sensor_sentence;
/// use posecov::input::log::{LogOptions, read_log};
/// use posecov::plan::log::Issue;
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
/// let plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
/// let imu = &plan.sensors[0];
/// let s = sensor_sentence(Issue::UnknownMarker, Some(&imu.blocks[0]), imu);
/// assert!(s.starts_with("orientation_covariance[0] = −1"), "{s}");
/// ```
pub fn sensor_sentence(
    issue: Issue,
    block: Option<&BlockSummary>,
    t: &SensorTopicSummary,
) -> String {
    let field = block.map_or_else(|| "the covariance".to_owned(), |b| t.kind.field(&b.spec));
    match issue {
        Issue::UnknownMarker => format!(
            "{field}[0] = −1: REP 145's \"not provided\"; the block is not checked and its σ \
             not plotted."
        ),
        Issue::AllZero => format!(
            "every entry of {field} is 0: REP 145's \"unknown\", which an estimator reads as \
             perfect certainty (publish −1 in element 0 when there is none, or the sensor's noise)."
        ),
        Issue::Constant => format!(
            "{field} is identical in every message (usual for a sensor whose noise is a datasheet \
             constant)."
        ),
        Issue::Placeholder => {
            format!("a variance ≥ 1e6 in {field}: \"not estimated\" on that axis.")
        }
        Issue::NonFinite => format!("NaN or ∞ in {field}."),
        Issue::Asymmetric => format!("{field}: Σ ≠ Σᵀ beyond the tolerance (1e-9 relative)."),
        Issue::NotPsd => match block.and_then(|b| b.health.min_eigenvalue) {
            Some(lo) => format!(
                "{field} has a negative variance along some direction: smallest eigenvalue \
                 {lo:.3e}."
            ),
            None => format!("{field} has a negative variance along some direction."),
        },
        Issue::Drop => format!("the trace of {field} fell ÷ ≥ 5 at once."),
        Issue::Growth => {
            format!("the trace of {field} reached ≥ 100 × its value since the last drop.")
        }
        Issue::Undecodable => format!(
            "the bytes are not a {} (truncated, or another definition).",
            t.kind.ros1_name()
        ),
        Issue::TypeChange => format!(
            "the topic also carries {}: those messages are not read, only its {} ones.",
            t.health.other_types.join(", "),
            t.kind.ros1_name()
        ),
        Issue::CovarianceTypeUnknown => format!(
            "position_covariance_type = COVARIANCE_TYPE_UNKNOWN (0): the receiver gives no \
             covariance; {field} is not checked and its σ not plotted (an estimator fusing this \
             fix needs one: set it from the receiver's accuracy, or a measured one)."
        ),
        Issue::CovarianceApproximated => format!(
            "position_covariance_type = COVARIANCE_TYPE_APPROXIMATED (1): {field} is made up \
             (e.g. from the dilution of precision), not the receiver's estimate."
        ),
        Issue::DiagonalKnownOffDiagonal => format!(
            "position_covariance_type = COVARIANCE_TYPE_DIAGONAL_KNOWN (2), but {field} has \
             off-diagonal entries that are not 0: the type says only the variances are known, \
             the numbers say more (use COVARIANCE_TYPE_KNOWN (3), or zero them)."
        ),
        Issue::NoFix => "status = STATUS_NO_FIX (−1): the receiver has no position; the fix \
             is not drawn."
            .to_owned(),
        Issue::FrozenStamp => "the same header stamp as the message before.".to_owned(),
        Issue::StampFallback => "a zero header stamp: the log time is used.".to_owned(),
        Issue::StampOrder => "stamped earlier than the message before.".to_owned(),
        other => format!("{}.", issue_word(other)),
    }
}

/// The text panel's paragraph on the sensor topics: per topic its type, frame and messages,
/// σ's range per block and axis, and each finding with its class, count and first message.
pub(super) fn sensor_paragraph(plan: &LogSummary, s: &mut String) {
    for t in &plan.sensors {
        let frame = match (t.frame_id.as_str(), t.kind.frame_field()) {
            ("", field) => format!("no {field}"),
            (id, "header.frame_id") => format!("frame `{id}`"),
            (id, field) => format!("frame `{id}` ({field})"),
        };
        let _ = writeln!(
            s,
            "\n**{}** (`{}`, {frame}): {} messages.",
            t.name,
            t.kind.ros1_name(),
            t.count
        );
        for b in &t.blocks {
            let sigma: Vec<String> = b
                .spec
                .axes
                .iter()
                .zip(&b.sigma_stats)
                .filter_map(|(axis, st)| {
                    let st = st.as_ref()?;
                    Some(format!("{axis} {:.3e}…{:.3e}", st.min, st.max))
                })
                .collect();
            if !sigma.is_empty() {
                let _ = writeln!(
                    s,
                    "- σ {} ({}): {}",
                    b.spec.name.replace('_', " "),
                    b.spec.unit,
                    sigma.join(", ")
                );
            }
        }
        for (block, issue, c, class) in t.findings() {
            let b = t.blocks.iter().find(|b| Some(b.spec.name) == block);
            let _ = writeln!(
                s,
                "- {} `{}` × {} (message {}): {}",
                match class {
                    Class::Defect => "**defect**",
                    Class::Note => "note",
                },
                issue.name(),
                c.count,
                c.first_index,
                sensor_sentence(issue, b, t)
            );
        }
    }
}

/// A sensor plot's unit for values whose largest is `max` (in SI `si`): its name and the
/// factor from SI.
fn unit_for(si: &'static str, max: f64) -> (&'static str, f64) {
    match si {
        "rad" if max.to_degrees() < 1.0 => ("mrad", 1e3),
        "rad" => ("°", 180.0 / std::f64::consts::PI),
        "rad/s" if max < 0.1 => ("mrad/s", 1e3),
        "m/s²" if max < 0.1 => ("mm/s²", 1e3),
        "m/s" if max < 0.1 => ("mm/s", 1e3),
        "rad/s²" if max < 0.1 => ("mrad/s²", 1e3),
        "m" if max < 0.1 => ("mm", 1e3),
        other => (other, 1.0),
    }
}

/// A sensor block's σ plot: `sigma_<block>`, but `sigma_fix_position` for a fix's `position`
/// (the pose topics' σ xyz plot is `sigma_position`).
fn plot_id(spec: &crate::plan::log::BlockSpec) -> PlotId {
    match spec.name {
        "position" => PlotId::new("sigma_fix_position"),
        name => PlotId::new(format!("sigma_{name}")),
    }
}

/// One σ plot per kind of block over the stamp (id [`plot_id`]), one line per sensor
/// topic and axis, ranged from 0 with room above.
pub(super) fn sensor_plots(scene: &mut Scene, e: &LogEvaluation) {
    let several = e.sensors.len() > 1;
    // A quantity's one plot, whichever kinds carry it (an IMU's and a twist's angular velocity).
    let mut specs: Vec<&BlockSpec> = Vec::new();
    for spec in SensorKind::ALL.iter().flat_map(|k| k.blocks()) {
        if !specs.contains(&spec) {
            specs.push(spec);
        }
    }
    for spec in specs {
        type Line = (String, String, usize, Vec<(i64, f64)>);
        let mut lines: Vec<Line> = Vec::new();
        for t in &e.sensors {
            let Some(k) = t.blocks.iter().position(|b| b.spec == *spec) else {
                continue;
            };
            let topic = topic_segments(&t.name);
            for (axis, name) in spec.axes.iter().enumerate() {
                let points: Vec<(i64, f64)> = t
                    .series
                    .iter()
                    .filter_map(|p| p.sigma[k][axis].map(|v| (p.stamp_ns, v)))
                    .collect();
                if points.is_empty() {
                    continue;
                }
                let tail = paths::child(&topic, &format!("{}_{name}", spec.name));
                let label = format!("σ{name}");
                let label = if several {
                    format!("{} {label}", t.name)
                } else {
                    label
                };
                lines.push((tail, label, axis, points));
            }
        }
        if lines.is_empty() {
            continue;
        }
        let max = lines
            .iter()
            .flat_map(|l| l.3.iter().map(|p| p.1))
            .fold(0.0, f64::max);
        let (unit, factor) = unit_for(spec.unit, max);
        let id = plot_id(spec);
        scene.plots.push(Plot {
            id: id.clone(),
            title: format!("σ {}", spec.name.replace('_', " ")),
            unit: unit.into(),
            range: Some([0.0, if max > 0.0 { 1.15 * max * factor } else { 1.0 }]),
            legend: Corner::LeftBottom,
        });
        for (tail, label, axis, points) in lines {
            scene.series.push(ScalarSeries::new(
                id.clone(),
                tail,
                label,
                AXIS_COLORS[axis],
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
    fn small_sigmas_get_small_units() {
        assert_eq!(unit_for("rad/s", 0.01), ("mrad/s", 1e3));
        assert_eq!(unit_for("m/s²", 0.5), ("m/s²", 1.0));
        assert_eq!(unit_for("rad", 0.001), ("mrad", 1e3));
        assert_eq!(unit_for("m", 0.05), ("mm", 1e3));
        assert_eq!(unit_for("m", 2.0), ("m", 1.0));
    }
}
