//! A robot log's plots over the stamp: σ per axis and the position trace, one line per
//! topic and axis.

use super::{AXIS_COLORS, MEANING, topic_path};
use crate::eval::bag::BagEvaluation;
use crate::scene::{Plot, ScalarSeries, Scene};

/// σ per axis and the position trace over the stamp, one line per topic and axis.
pub(super) fn plots(scene: &mut Scene, e: &BagEvaluation) {
    let planar = scene.planar;
    scene.plots = vec![
        Plot {
            id: "sigma_position".into(),
            title: "σ of position, parent axes".into(),
            unit: "m".into(),
        },
        Plot {
            id: "sigma_rotation".into(),
            title: "σ of rotation (roll, pitch, yaw)".into(),
            unit: "rad".into(),
        },
        Plot {
            id: "position_trace".into(),
            title: "trace of the position covariance".into(),
            unit: "m²".into(),
        },
    ];
    let names = ["x", "y", "z", "roll", "pitch", "yaw"];
    for t in &e.topics {
        let topic = topic_path(&t.name);
        for (axis, name) in names.iter().enumerate() {
            let points: Vec<(i64, f64)> = t
                .series
                .iter()
                .filter_map(|s| s.sigma[axis].map(|v| (s.stamp_ns, v)))
                .collect();
            if points.is_empty() || (planar && [2, 3, 4].contains(&axis)) {
                continue;
            }
            let plot = if axis < 3 {
                "sigma_position"
            } else {
                "sigma_rotation"
            };
            scene.series.push(ScalarSeries {
                path: format!("{}/{plot}/{topic}/{name}", crate::scene::PLOTS),
                name: format!("{} σ{name}", t.name),
                color: AXIS_COLORS[axis % 3],
                width: 1.5,
                points,
            });
        }
        let points: Vec<(i64, f64)> = t
            .series
            .iter()
            .filter_map(|s| s.position_trace.map(|v| (s.stamp_ns, v)))
            .collect();
        if !points.is_empty() {
            scene.series.push(ScalarSeries {
                path: format!("{}/position_trace/{topic}", crate::scene::PLOTS),
                name: format!("{} tr Σ_position", t.name),
                color: MEANING,
                width: 1.5,
                points,
            });
        }
    }
}
