//! OpenVINS `ov_eval` text trajectories: the committed trajectories of tests/data/ov_eval (cut
//! to their first lines) and a small one mixing lines with and without covariance, mutated
//! token by token, line by line and byte by byte, then run twice: as an estimate (`report
//! --json` runs a log: read → evaluate → draw → validate → the JSON report) and as a NEES
//! reference (the TUM reader, which takes ov_eval's lines too).

use std::path::PathBuf;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use posecov::app::Overrides;
use posecov::app::log::report_json;
use posecov::app::run::{Opened, Run as AppRun, RunOptions};
use posecov::input::tum::parse_tum;
use posecov::input::{Format, Located, Place};

use crate::graph::{located, mutate_lines};
use crate::harness::{
    Family, Finding, Limits, Run, Stage, finding, json_null, mutate_bytes, run_guarded, settle,
    target_dir,
};

/// How many lines of a committed trajectory a seed keeps (its header and 24 poses).
const SEED_LINES: usize = 25;

/// A trajectory mixing lines of 20 and 8 columns, a blank line and comments.
const MIXED: &str = "# timestamp(s) tx ty tz qx qy qz qw Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23 Pt33\n\
1.00000 0.000000 0.000000 0.000000 0.000000 0.000000 0.000000 1.000000 0.0001 0 0 0.0001 0 0.0004 0.01 0.002 0 0.01 0 0.04\n\
1.10000 0.100000 0.000000 0.000000 0.000000 0.000000 0.049979 0.998750\n\
\n\
# a comment\n\
1.20000 0.200000 0.010000 0.000000 0.000000 0.000000 0.099833 0.995004 0.0001 0 0 0.0001 0 0.0004 0.011 0.002 0 0.011 0 0.041\n\
1.30000 0.300000 0.030000 0.001000 0.000000 0.000000 0.149438 0.988771 0.0001 0 0 0.0001 0 0.0004 0.012 0.002 0 0.012 0 0.042\n";

/// Tokens a number is replaced by (or inserted).
const TOKENS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e309",
    "0",
    "-0",
    "1e-320",
    "5e-324",
    "9.3e9",
    "-9.3e9",
    "1e13",
    "-1",
    "2",
    "0.7071",
    "99999999999999999999",
    "x",
    "0x10",
    "1_0",
    "",
    "#",
    "\u{e9}",
    "\t",
    "\r",
    "1.",
    ".5",
    "+1",
    "1e",
];

/// The ov_eval family.
pub struct OvEval {
    seeds: Vec<String>,
}

impl OvEval {
    pub fn new() -> Self {
        let cut = |text: &str| {
            let lines: Vec<&str> = text.lines().take(SEED_LINES).collect();
            lines.join("\n") + "\n"
        };
        Self {
            seeds: vec![
                cut(include_str!("../data/ov_eval/estimate.txt")),
                cut(include_str!("../data/ov_eval/overconfident.txt")),
                MIXED.to_owned(),
            ],
        }
    }

    /// The seeds (each reads without an error).
    pub fn seeds(&self) -> &[String] {
        &self.seeds
    }
}

impl Family for OvEval {
    fn name(&self) -> &'static str {
        "ov_eval"
    }
    fn extension(&self) -> &'static str {
        "txt"
    }
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(case);
        let k = rng.random_range(0..self.seeds.len());
        let mut lines: Vec<String> = self.seeds[k].lines().map(str::to_owned).collect();
        let mut log = vec![format!("from seed {k}")];
        for _ in 0..[1, 1, 1, 2, 3][rng.random_range(0..5)] {
            let first = "0 0 0 0 0 0 0 1";
            log.push(mutate_lines(&mut rng, &mut lines, TOKENS, first));
        }
        let mut bytes = (lines.join("\n") + "\n").into_bytes();
        if rng.random_bool(0.25) {
            log.push(mutate_bytes(&mut rng, &mut bytes, TOKENS));
        }
        (bytes, log.join("; "))
    }
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool) {
        let path = target_dir().join("fuzz-work-ov-eval.txt");
        if let Err(e) = std::fs::write(&path, input) {
            let message = format!("writing {}: {e}", path.display());
            return (vec![finding("harness", message)], false);
        }
        let file = path.display().to_string();
        let run = {
            let (path, file) = (path.clone(), file.clone());
            run_guarded(limits, move |stage| {
                let estimate = run_estimate(path, stage);
                stage("as a reference");
                let text = std::fs::read(&file).map_err(|e| e.to_string());
                let reference = text.and_then(|t| {
                    let t = String::from_utf8(t).map_err(|_| format!("{file}: not UTF-8"))?;
                    parse_tum(&file, &t)
                        .map(|s| s.len())
                        .map_err(|e| e.to_string())
                });
                (estimate, reference)
            })
        };
        let stuck = matches!(run, Run::Stuck { .. });
        let text = String::from_utf8_lossy(input);
        (judge(&file, &text, run, limits), stuck)
    }
}

/// Reads the file as an ov_eval estimate (whatever its content says: the reader is what is
/// fuzzed) and runs it as `report --json` does.
fn run_estimate(path: PathBuf, stage: Stage) -> Result<serde_json::Value, String> {
    stage("read, evaluate, draw");
    let overrides = Overrides {
        samples: Some(8),
        ..Default::default()
    };
    let located = Located {
        place: Place::File(path),
        format: Format::OvEval,
    };
    let AppRun::Log(log) = AppRun::start(Opened::Log(located), &overrides, RunOptions::shown())
        .map_err(|e| e.to_string())?
    else {
        return Err("read as a plan, not a log".to_owned());
    };
    stage("report");
    Ok(report_json("fuzz", &log))
}

type Outcome = (Result<serde_json::Value, String>, Result<usize, String>);

fn judge(file: &str, text: &str, run: Run<Outcome>, limits: &Limits) -> Vec<Finding> {
    let ((estimate, reference), mut found) = match settle(run, limits) {
        Ok(x) => x,
        Err(ended) => return ended,
    };
    // Each read's error must be located; `error_ok` once stands for both.
    let errors = [estimate.as_ref().err(), reference.as_ref().err()];
    let mut judged: Vec<Finding> = errors
        .into_iter()
        .flatten()
        .flat_map(|e| located(file, text, e))
        .collect();
    judged.dedup_by(|a, b| a.class == "error_ok" && b.class == "error_ok");
    found.extend(judged);
    if let Ok(json) = &estimate
        && let Some(path) = json_null(json, crate::logs::LOG_JSON_OPTIONAL)
    {
        found.push(finding("nonfinite_json", format!("null at {path}")));
    }
    // Whatever a read accepted has only lines it reads.
    if estimate.is_ok() || reference.is_ok() {
        found.extend(oracle(text));
    }
    if found.is_empty() {
        found.push(finding("ok", ""));
    }
    found
}

/// A text that was read without an error has only lines posecov reads: blank, comments, or
/// 8 or 20 finite numbers (separated by white space or commas, as both readers take them)
/// whose quaternion (columns 5–8) has norm 1 within 1e-3.
fn oracle(text: &str) -> Vec<Finding> {
    for (k, line) in text.lines().enumerate() {
        let line = line.trim_start();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let values: Vec<Option<f64>> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
            .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect();
        let at = k + 1;
        if values.len() != 8 && values.len() != 20 {
            let message = format!("line {at} of {} values accepted", values.len());
            return vec![finding("accepted_invalid_value", message)];
        }
        if values.iter().any(Option::is_none) {
            let message = format!("a value that is not a finite number on line {at} accepted");
            return vec![finding("accepted_invalid_value", message)];
        }
        let q: f64 = values[4..8].iter().flatten().map(|v| v * v).sum();
        if (q.sqrt() - 1.0).abs() > 1e-3 {
            let message = format!("line {at}: a quaternion of norm {} accepted", q.sqrt());
            return vec![finding("accepted_invalid_value", message)];
        }
    }
    Vec::new()
}
