//! Inputs: each format is a module that reads its files, checks them with its own locations,
//! and produces an [`Input`]: a typed [`Plan`](crate::plan::Plan) plus the file's text and
//! settings. Nothing after this stage reads a file format.
//!
//! - [`scenario`]: TOML scenario files (and the bundled lecture scenarios).
//! - [`bag`]: robot logs, ROS 1 bags and MCAP files (ROS 2).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::plan::AnyPlan;
use crate::uncertain::Method;

pub mod bag;
pub mod scenario;

/// What an input describes, for the text panel and `posecov list`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct About {
    /// One-line title.
    pub title: String,
    /// Markdown: what the picture teaches.
    pub description: String,
    /// Where the example comes from (lecture, paper, figure), or empty.
    pub source: String,
}

/// Evaluation settings an input file gives (each validated; the command line overrides).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FileSettings {
    /// Seed of every random draw.
    pub seed: Option<u64>,
    /// Monte Carlo samples.
    pub samples: Option<u64>,
    /// Probability inside drawn regions.
    pub confidence: Option<f64>,
    /// Methods to compare.
    pub methods: Vec<Method>,
}

/// What an input file asks to draw (validated).
#[derive(Debug, Clone, PartialEq)]
pub struct DrawChoices {
    /// Mean frames as axis triads.
    pub axes: bool,
    /// Monte Carlo sample positions.
    pub clouds: bool,
    /// Axis triads (or headings) on a subsample of the samples.
    pub sample_axes: bool,
    /// Cartesian position ellipsoids.
    pub ellipsoids: bool,
    /// Exp-mapped banana surfaces.
    pub bananas: bool,
    /// Orientation sprays and their Exp-mapped ellipses.
    pub orientation: bool,
    /// Nominal and sampled trajectories.
    pub trajectories: bool,
    /// Length of the mean frames' axes (m), if given.
    pub axis_length: Option<f64>,
    /// Face the x–y plane from above (`Some(true)`), or not; `None`: by group.
    pub top_view: Option<bool>,
    /// Per pose name, whether to draw it (overrides the default rule).
    pub shown: BTreeMap<String, bool>,
}

impl Default for DrawChoices {
    fn default() -> Self {
        Self {
            axes: true,
            clouds: true,
            sample_axes: true,
            ellipsoids: true,
            bananas: true,
            orientation: true,
            trajectories: true,
            axis_length: None,
            top_view: None,
            shown: BTreeMap::new(),
        }
    }
}

/// A checked input: the plan to evaluate and what the file says about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// Title, description, source.
    pub about: About,
    /// What to evaluate.
    pub plan: AnyPlan,
    /// The file's evaluation settings.
    pub defaults: FileSettings,
    /// The file's drawing choices.
    pub draw: DrawChoices,
}
