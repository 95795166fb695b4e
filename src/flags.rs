//! The binary's flag values: the words clap accepts for `--graph-reading` and `--optimizer`
//! (matched exhaustively onto the library's types) and the parsers of `--joint`,
//! `--confidence`, `--size` and `--duration`. Part of the `posecov` binary, not of the library.

use clap::ValueEnum;
use posecov::eval::graph::{GraphReading, Optimizer};

/// `--graph-reading`'s values (the flag's words for [`GraphReading`]).
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum GraphReadingArg {
    /// As g2o defines the information matrices.
    G2o,
    /// As GTSAM's readG2o reads them.
    Gtsam,
}

/// `--optimizer`'s values (the flag's words for [`Optimizer`]).
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum OptimizerArg {
    /// Levenberg–Marquardt.
    Lm,
    /// Gauss–Newton.
    Gn,
}

impl GraphReadingArg {
    /// The library's reading this word names.
    pub(crate) fn reading(self) -> GraphReading {
        match self {
            GraphReadingArg::G2o => GraphReading::G2o,
            GraphReadingArg::Gtsam => GraphReading::Gtsam,
        }
    }
}

impl OptimizerArg {
    /// The library's optimiser this word names.
    pub(crate) fn optimizer(self) -> Optimizer {
        match self {
            OptimizerArg::Lm => Optimizer::LevenbergMarquardt,
            OptimizerArg::Gn => Optimizer::GaussNewton,
        }
    }
}

/// `A,B`: two vertex ids.
pub(crate) fn parse_joint(text: &str) -> Result<(u64, u64), String> {
    let parse = |s: &str| s.trim().parse::<u64>().ok();
    match text.split_once(',') {
        Some((a, b)) => match (parse(a), parse(b)) {
            (Some(a), Some(b)) => Ok((a, b)),
            _ => Err(format!(
                "expected two vertex ids A,B (non-negative integers), got `{text}`"
            )),
        },
        None => Err(format!(
            "expected two vertex ids separated by a comma, A,B, got `{text}`"
        )),
    }
}

/// `--confidence P`: a probability strictly between 0 and 1.
pub(crate) fn parse_probability(s: &str) -> Result<posecov::uncertain::Confidence, String> {
    let p = s.parse::<f64>().map_err(|e| e.to_string())?;
    posecov::uncertain::Confidence::new(p).map_err(|e| e.to_string())
}

/// `--size WxH`: pixels, each side in 16 ..= 8192.
pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|n| (16..=8192).contains(n))
    };
    match s.split_once(['x', 'X']).map(|(w, h)| (parse(w), parse(h))) {
        Some((Some(w), Some(h))) => Ok((w, h)),
        _ => Err(format!(
            "{s:?} is not WIDTHxHEIGHT with sides in 16..=8192, e.g. 1024x640"
        )),
    }
}

/// `--duration`: `30s`, `2m`, `1h`, `500ms`, or plain seconds (`30`, `0.5`), more than zero.
pub(crate) fn parse_duration(text: &str) -> Result<std::time::Duration, String> {
    let t = text.trim();
    let (number, unit) = match t.find(|c: char| c.is_ascii_alphabetic()) {
        Some(i) => t.split_at(i),
        None => (t, "s"),
    };
    let scale = match unit {
        "ms" => 1e-3,
        "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        other => {
            return Err(format!("unit `{other}`: use ms, s, m or h (e.g. 30s, 2m)"));
        }
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a duration (e.g. 30s, 2m, 500ms)"))?;
    let seconds = value * scale;
    if !(seconds.is_finite() && seconds > 0.0 && seconds < 1e9) {
        return Err(format!("`{text}`: give a duration above zero"));
    }
    Ok(std::time::Duration::from_secs_f64(seconds))
}
