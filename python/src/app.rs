//! The commands that print, from Python: `report`, `check`, `figure` and `list` call the
//! library's app layer exactly as the `posecov` binary does (`posecov::app::commands`,
//! `posecov::app::figure`), so a report is the object `posecov report --json` prints and an
//! error carries the CLI's located message. Keyword overrides are the CLI's flags.

use std::path::PathBuf;

use posecov::app::{AppError, Overrides, commands, figure};
use posecov::eval::graph::{GraphReading, Optimizer};
use posecov::sink::figure::{FigureOptions, Plane, Steps};
use posecov::uncertain::Confidence;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::PosecovError;

/// The keyword arguments `report`, `check` and `figure` take, each one of the CLI's flags.
pub const OVERRIDES: [&str; 12] = [
    "seed",
    "samples",
    "confidence",
    "block_samples",
    "topic",
    "every",
    "ros_reading",
    "reference",
    "align",
    "graph_reading",
    "optimizer",
    "joint",
];

/// An app error as a `PosecovError`: the message the CLI prints after `error: `, with
/// `exit_code` and `details` (the `error` object of `report --json`: file, line, column,
/// key or place where known).
pub fn app_err(py: Python<'_>, e: &AppError) -> PyErr {
    let err = PosecovError::new_err(e.to_string());
    let value = err.value(py);
    let json = e.to_json();
    let attach = || -> PyResult<()> {
        value.setattr("exit_code", e.exit_code())?;
        let details = py
            .import("json")?
            .call_method1("loads", (json["error"].to_string(),))?;
        value.setattr("details", details)
    };
    // An attribute that cannot be set still leaves the message: never hide the error.
    let _ = attach();
    err
}

/// A usage error (a keyword the CLI would refuse), as the CLI words it.
fn usage(flag: &str, value: impl std::fmt::Display, why: impl std::fmt::Display) -> PyErr {
    PosecovError::new_err(format!("--{} {value}: {why}", flag.replace('_', "-")))
}

fn words(flag: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if let Ok(one) = value.extract::<String>() {
        return Ok(vec![one]);
    }
    value.extract::<Vec<String>>().map_err(|_| {
        usage(
            flag,
            value.repr().map(|r| r.to_string()).unwrap_or_default(),
            "expected a string or a list of strings",
        )
    })
}

fn int(flag: &str, value: &Bound<'_, PyAny>) -> PyResult<u64> {
    value.extract::<u64>().map_err(|_| {
        usage(
            flag,
            value.repr().map(|r| r.to_string()).unwrap_or_default(),
            "expected a non-negative integer",
        )
    })
}

fn word(flag: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    value.extract::<String>().map_err(|_| {
        usage(
            flag,
            value.repr().map(|r| r.to_string()).unwrap_or_default(),
            "expected a string",
        )
    })
}

/// The overrides of keyword arguments, each checked as the CLI checks its flag; an unknown
/// keyword is a `TypeError` naming the known ones.
pub fn overrides(kwargs: Option<&Bound<'_, PyDict>>, extra: &[&str]) -> PyResult<Overrides> {
    let mut o = Overrides::default();
    let Some(kwargs) = kwargs else {
        return Ok(o);
    };
    for (key, value) in kwargs.iter() {
        let key: String = key.extract()?;
        if value.is_none() || extra.contains(&key.as_str()) {
            continue;
        }
        match key.as_str() {
            "seed" => o.seed = Some(int(&key, &value)?),
            "samples" => o.samples = Some(int(&key, &value)?),
            "block_samples" => o.block_samples = Some(int(&key, &value)?),
            "every" => {
                let n = int(&key, &value)?;
                if n == 0 {
                    return Err(usage(&key, n, "out of range: at least 1"));
                }
                o.every = Some(n);
            }
            "confidence" => {
                let p: f64 = value
                    .extract()
                    .map_err(|_| usage(&key, value.to_string(), "expected a probability"))?;
                o.confidence = Some(Confidence::new(p).map_err(|e| usage(&key, p, e))?);
            }
            "topic" => o.topics = words(&key, &value)?,
            "ros_reading" => {
                let w = word(&key, &value)?;
                o.ros_reading = Some(w.parse().map_err(|e| usage(&key, &w, e))?);
            }
            "reference" => o.reference = Some(word(&key, &value)?),
            "align" => {
                let w = word(&key, &value)?;
                o.align = Some(w.parse().map_err(|e| usage(&key, &w, e))?);
            }
            "graph_reading" => {
                o.graph_reading = Some(match word(&key, &value)?.as_str() {
                    "g2o" => GraphReading::G2o,
                    "gtsam" => GraphReading::Gtsam,
                    w => return Err(usage(&key, w, "expected \"g2o\" or \"gtsam\"")),
                });
            }
            "optimizer" => {
                o.optimizer = Some(match word(&key, &value)?.as_str() {
                    "lm" => Optimizer::LevenbergMarquardt,
                    "gn" => Optimizer::GaussNewton,
                    w => return Err(usage(&key, w, "expected \"lm\" or \"gn\"")),
                });
            }
            "joint" => {
                let pairs: Vec<(u64, u64)> = match value.extract::<(u64, u64)>() {
                    Ok(one) => vec![one],
                    Err(_) => value.extract().map_err(|_| {
                        usage(
                            &key,
                            value.to_string(),
                            "expected vertex ids (A, B) or a list of them",
                        )
                    })?,
                };
                o.joints = pairs;
            }
            other => {
                let mut known: Vec<&str> = OVERRIDES.to_vec();
                known.extend(extra);
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument {other:?}; the keywords are the CLI's flags: {}",
                    known.join(", ")
                )));
            }
        }
    }
    if let Some(0) = o.block_samples {
        return Err(usage("block_samples", 0, "out of range: at least 1"));
    }
    Ok(o)
}

/// `posecov report NAME --json` as a JSON string (the wrapper parses it).
#[pyfunction]
#[pyo3(signature = (source, **kwargs))]
pub fn report_json(
    py: Python<'_>,
    source: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let o = overrides(kwargs, &[])?;
    let source = source.to_owned();
    py.detach(|| commands::report(&source, &o, true))
        .map_err(|e| app_err(py, &e))
}

/// `posecov check NAME`: (line, defects, exit code).
#[pyfunction]
#[pyo3(signature = (source, allow = None, **kwargs))]
pub fn check_raw(
    py: Python<'_>,
    source: &str,
    allow: Option<Vec<String>>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<(String, Vec<String>, u8)> {
    let o = overrides(kwargs, &[])?;
    let allow = commands::allowed(&allow.unwrap_or_default()).map_err(|e| app_err(py, &e))?;
    let source = source.to_owned();
    let checked = py
        .detach(|| commands::check(&source, &o, &allow))
        .map_err(|e| app_err(py, &e))?;
    let code = checked.exit_code();
    Ok((checked.line, checked.defects, code))
}

/// The figure options of keyword arguments `size`, `plane`, `step`.
fn figure_options(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<FigureOptions> {
    let mut options = FigureOptions::default();
    let Some(kwargs) = kwargs else {
        return Ok(options);
    };
    if let Some(size) = kwargs.get_item("size")?.filter(|v| !v.is_none()) {
        let (w, h): (u32, u32) = size
            .extract()
            .map_err(|_| usage("size", size.to_string(), "expected (width, height)"))?;
        if !(16..=8192).contains(&w) || !(16..=8192).contains(&h) {
            return Err(usage("size", format!("{w}x{h}"), "sides in 16..=8192"));
        }
        options.size = (w, h);
    }
    if let Some(plane) = kwargs.get_item("plane")?.filter(|v| !v.is_none()) {
        let w = word("plane", &plane)?;
        options.plane = w.parse::<Plane>().map_err(|e| usage("plane", &w, e))?;
    }
    if let Some(step) = kwargs.get_item("step")?.filter(|v| !v.is_none()) {
        let w = match step.extract::<u64>() {
            Ok(k) => k.to_string(),
            Err(_) => word("step", &step)?,
        };
        options.steps = w.parse::<Steps>().map_err(|e| usage("step", &w, e))?;
    }
    Ok(options)
}

const FIGURE_OPTIONS: [&str; 3] = ["size", "plane", "step"];

/// `posecov figure NAME -o PATH`.
#[pyfunction]
#[pyo3(signature = (source, path, **kwargs))]
pub fn figure_file(
    py: Python<'_>,
    source: &str,
    path: PathBuf,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let o = overrides(kwargs, &FIGURE_OPTIONS)?;
    let options = figure_options(kwargs)?;
    let source = source.to_owned();
    py.detach(|| figure::figure(&source, &o, &options, &path))
        .map_err(|e| app_err(py, &e))
}

/// The SVG text `posecov figure NAME -o x.svg` writes.
#[pyfunction]
#[pyo3(signature = (source, **kwargs))]
pub fn figure_svg(
    py: Python<'_>,
    source: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let o = overrides(kwargs, &FIGURE_OPTIONS)?;
    let options = figure_options(kwargs)?;
    let source = source.to_owned();
    let scene = py
        .detach(|| figure::scene_of(&source, &o))
        .map_err(|e| app_err(py, &e))?;
    Ok(posecov::sink::figure::svg(&scene, &options))
}

/// `posecov list`'s bundled examples: (name, format) pairs.
#[pyfunction]
pub fn examples(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let items: Vec<Bound<'_, PyTuple>> = posecov::input::examples()
        .iter()
        .map(|e| PyTuple::new(py, [e.name, e.format.name()]))
        .collect::<PyResult<_>>()?;
    PyList::new(py, items)
}

/// Every input of `args` as `posecov report DIR` expands them (a directory: its logs, sorted).
#[pyfunction]
pub fn expand(py: Python<'_>, args: Vec<String>) -> PyResult<Vec<String>> {
    posecov::app::many::expand(&args)
        .map(|inputs| inputs.names)
        .map_err(|e| app_err(py, &e))
}
