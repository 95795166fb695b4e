//! The numbers of a log's sensor topics (`sensor_msgs/Imu`): per covariance block and axis,
//! σ's streamed statistics with the median of the kept series ([`SigmaSummary`]), in the
//! block's unit; the σ series moves out of the plan for the plots.
//!
//! ```
//! use posecov::eval::log::sensor::evaluate_sensor;
//! use posecov::input::log::{LogOptions, read_log};
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
//! let mut plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
//! let e = evaluate_sensor(&mut plan.sensors[0]);
//! assert_eq!(e.blocks[1].spec.unit, "rad/s");
//! let x = e.blocks[1].sigma[0].unwrap();
//! assert_eq!(x.min, x.max); // test2.bag's IMU publishes one covariance throughout
//! ```

use super::sensor_shapes::{LocalFixes, OrientationSpray, local_fixes};
use super::{SigmaSummary, summary_of};
use crate::plan::log::{BlockSpec, SensorSeriesPoint, SensorTopicSummary};

/// One covariance block's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockEvaluation {
    /// Which block (its unit and axes).
    pub spec: BlockSpec,
    /// σ per axis, in `spec.unit`; `None` where no usable message estimates the axis.
    pub sigma: [Option<SigmaSummary>; 3],
}

/// One sensor topic's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorEvaluation {
    /// Topic name.
    pub name: String,
    /// Per block, in the message's order.
    pub blocks: Vec<BlockEvaluation>,
    /// σ over the stamp (moved out of the plan).
    pub series: Vec<SensorSeriesPoint>,
    /// A NavSatFix's drawn fixes in the tangent plane at the first ([`local_fixes`]).
    pub fixes: Option<LocalFixes>,
    /// An IMU's orientation spray at its newest usable message (set by `evaluate_log`, which
    /// holds the seed and the reading).
    pub orientation: Option<OrientationSpray>,
}

/// Evaluates one sensor topic: its σ series moves out of `topic` (empty afterwards).
///
/// See the [module docs](self) for an example.
pub fn evaluate_sensor(topic: &mut SensorTopicSummary) -> SensorEvaluation {
    let series = std::mem::take(&mut topic.series);
    let blocks = topic
        .blocks
        .iter()
        .enumerate()
        .map(|(k, b)| BlockEvaluation {
            spec: b.spec,
            sigma: std::array::from_fn(|axis| {
                summary_of(
                    b.sigma_stats[axis],
                    series.iter().filter_map(|p| p.sigma[k][axis]).collect(),
                )
            }),
        })
        .collect();
    SensorEvaluation {
        name: topic.name.clone(),
        blocks,
        series,
        fixes: local_fixes(&topic.drawn.fixes),
        orientation: None,
    }
}
