//! Plots and their series: a plot's typed id ([`PlotId`]), the [`Plot`] a view shows and the
//! [`ScalarSeries`] (lines) drawn in it.

use super::{Color, paths};

/// A plot's id: its entity segment under [`PLOTS`](super::PLOTS) (`plots/<id>`), carried by every series
/// drawn in it.
///
/// ```
/// let id = posecov::scene::PlotId::new("trace");
/// assert_eq!(id.to_string(), "trace");
/// assert_eq!(id.as_str(), "trace");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PlotId(String);

impl PlotId {
    /// The id `segment` (letters, digits, `_`; checked with the scene by
    /// [`Scene::validate`](super::Scene::validate)).
    pub fn new(segment: impl Into<String>) -> Self {
        Self(segment.into())
    }

    /// The segment.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for PlotId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// A plot: one time-series view of the lines under `plots/<id>/…`. Title and unit are data,
/// written by the drawing stage and shown by the sink as they are.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// Its entity segment under [`PLOTS`](super::PLOTS) (letters, digits, `_`): the id its series carry.
    pub id: PlotId,
    /// What is plotted and in which frame, e.g. "trace of position covariance, body frame".
    pub title: String,
    /// The unit of the values, e.g. "m²".
    pub unit: String,
    /// The value axis's range `[low, high]` in `unit`, fitted to the data by the drawing stage
    /// (a constant σ is then a flat line at its level, not lost in the viewer's ±1 default);
    /// `None`: the viewer's own fit.
    pub range: Option<[f64; 2]>,
    /// The corner of the plot the legend sits in, chosen by the drawing stage where the lines
    /// are not (a growing quantity leaves the upper left empty).
    pub legend: Corner,
}

/// A corner of a plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Corner {
    /// Upper left.
    #[default]
    LeftTop,
    /// Upper right.
    RightTop,
    /// Lower left.
    LeftBottom,
    /// Lower right.
    RightBottom,
}

impl Plot {
    /// The title with its unit, as a view shows it: "trace of rotation covariance (rad²)".
    ///
    /// ```
    /// let p = posecov::scene::Plot { id: posecov::scene::PlotId::new("t"), title: "trace".into(), unit: "m²".into(), range: None, legend: Default::default() };
    /// assert_eq!(p.label(), "trace (m²)");
    /// ```
    pub fn label(&self) -> String {
        if self.unit.is_empty() {
            self.title.clone()
        } else {
            format!("{} ({})", self.title, self.unit)
        }
    }
}

/// A named scalar time series (one line in the plot), e.g. the trace of a method's covariance.
/// Its entity path is [`ScalarSeries::path`], built from its typed plot and segment.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarSeries {
    /// The plot it is drawn in (a sink groups series by it, never by their path).
    pub plot: PlotId,
    /// Its own segment under the plot, e.g. `first_order` (letters, digits, `_`).
    pub segment: String,
    /// The generation of a restreamed scene it belongs to (set by
    /// a restreaming sink only; `None` from the drawing stage): see [`paths::series`].
    pub generation: Option<u64>,
    /// Legend name, e.g. `"first order"`.
    pub name: String,
    /// Line colour (use the method's [`Method::color`](crate::uncertain::Method::color)).
    pub color: Color,
    /// Line width in UI points (with `marks`, the marks' diameter).
    pub width: f64,
    /// Drawn as a mark at each sample, unjoined (e.g. where loop closures join), not a line
    /// ([`ScalarSeries::as_marks`]).
    pub marks: bool,
    /// `(step, value)` samples (`(stamp ns, value)` when the scene's timeline is
    /// [`Timeline::Stamp`](super::Timeline::Stamp)).
    pub points: Vec<(i64, f64)>,
}

impl ScalarSeries {
    /// A series of plot `plot` at its segment `segment` (generation `None`).
    ///
    /// ```
    /// use posecov::scene::{Color, PlotId, ScalarSeries};
    /// let s = ScalarSeries::new(PlotId::new("trace"), "first_order", "first order", Color::rgb(0, 0, 0), 2.0, vec![(0, 1.0)]);
    /// assert_eq!(s.path(), "plots/trace/first_order");
    /// ```
    pub fn new(
        plot: PlotId,
        segment: impl Into<String>,
        name: impl Into<String>,
        color: Color,
        width: f64,
        points: Vec<(i64, f64)>,
    ) -> Self {
        Self {
            plot,
            segment: segment.into(),
            generation: None,
            name: name.into(),
            color,
            width,
            marks: false,
            points,
        }
    }

    /// The same samples drawn as unjoined marks of diameter `width` instead of a line.
    ///
    /// ```
    /// use posecov::scene::{Color, PlotId, ScalarSeries};
    /// let s = ScalarSeries::new(PlotId::new("sigma"), "ends", "ends", Color::rgb(0, 0, 0), 5.0, vec![(3, 1.0)]).as_marks();
    /// assert!(s.marks);
    /// ```
    pub fn as_marks(mut self) -> Self {
        self.marks = true;
        self
    }

    /// Its entity path, `plots/<plot>/<segment>` ([`paths::series`]).
    ///
    /// ```
    /// use posecov::scene::{Color, PlotId, ScalarSeries};
    /// let mut s = ScalarSeries::new(PlotId::new("trace"), "a", "a", Color::rgb(0, 0, 0), 2.0, vec![]);
    /// s.generation = Some(2);
    /// assert_eq!(s.path(), "plots/trace/g2/a");
    /// ```
    pub fn path(&self) -> String {
        paths::series(&self.plot, self.generation, &self.segment)
    }
}
