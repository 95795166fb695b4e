//! `posecov figure`: a static figure of any input — evaluated and drawn as for the viewer,
//! then written by [`sink::figure`](crate::sink::figure) as SVG, PNG or PDF — and the gallery
//! of every bundled example.

use std::path::{Path, PathBuf};

use super::run::{Run, RunOptions, open, with_spinner};
use super::{AppError, Overrides};
use crate::eval::graph::StepMarginals;
use crate::scene::Scene;
use crate::sink::figure::{self, FigureOptions};

/// The scene of any input posecov reads (a scenario, a graph, a robot log), as the viewer
/// would get it ([`Run::start`]).
///
/// ```
/// let scene = posecov::app::figure::scene_of("so3_sampling", &Default::default()).unwrap();
/// assert!(!scene.legend.is_empty());
/// ```
pub fn scene_of(name_or_path: &str, overrides: &Overrides) -> Result<Scene, AppError> {
    scene_with(name_or_path, overrides, RunOptions::shown())
}

/// [`scene_of`] run with `options`.
fn scene_with(
    name_or_path: &str,
    overrides: &Overrides,
    options: RunOptions,
) -> Result<Scene, AppError> {
    let run = Run::start(open(name_or_path)?, overrides, options)?;
    Ok(match run {
        Run::Plan(r) => r.scene,
        Run::Log(r) => r.scene,
    })
}

/// `posecov figure NAME_OR_FILE -o OUT`: the figure of an input, written whole to `out` in the
/// format of its extension (.svg, .png, .pdf).
///
/// ```
/// use posecov::app::{Overrides, figure::figure};
/// use posecov::sink::figure::FigureOptions;
/// let out = std::env::temp_dir().join("posecov-doc-figure.svg");
/// let overrides = Overrides { samples: Some(100), ..Default::default() };
/// figure("camera_on_robot", &overrides, &FigureOptions::default(), &out).unwrap();
/// assert!(std::fs::read_to_string(&out).unwrap().contains("camera"));
/// ```
pub fn figure(
    name_or_path: &str,
    overrides: &Overrides,
    options: &FigureOptions,
    out: &Path,
) -> Result<(), AppError> {
    figure::FigureFormat::of(out)?;
    // A pose graph's figure of every step at once shows the graph before and its final
    // state: the loop-closure steps between are solved only for a figure of one of them
    // (`--step K`).
    let run = RunOptions {
        step_marginals: match options.steps {
            figure::Steps::At(_) => StepMarginals::Every,
            figure::Steps::All => StepMarginals::DeadReckoningOnly,
        },
        ..RunOptions::shown()
    };
    let scene = scene_with(name_or_path, overrides, run)?;
    let what = format!("writing {}", out.display());
    Ok(with_spinner(&what, |_, _| {
        figure::write(&scene, options, out)
    })?)
}

/// Writes `NAME.png` for every bundled example into `dir` (created if missing), with the
/// inputs' own settings; returns the files written, in `posecov list` order.
pub fn gallery(dir: &Path, options: &FigureOptions) -> Result<Vec<PathBuf>, AppError> {
    std::fs::create_dir_all(dir).map_err(|source| figure::FigureError::Io {
        path: dir.to_owned(),
        source,
    })?;
    let mut written = Vec::new();
    for example in crate::input::examples() {
        let out = dir.join(format!("{}.png", example.name));
        figure(example.name, &Overrides::default(), options, &out)?;
        written.push(out);
    }
    Ok(written)
}
