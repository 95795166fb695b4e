//! g2o / GTSAM / TORO pose graphs: the bundled and committed graphs (and a small TORO one),
//! mutated token by token and byte by byte, run as `report --json` runs a graph: read →
//! lower → evaluate (few samples) → draw → validate → the JSON report.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use posecov::app::{Loaded, Overrides, pipeline, report_json};
use posecov::input::{Format, open_text};

use crate::harness::{
    Family, Finding, Limits, Run, finding, json_null, mutate_bytes,
    null_error_where_monte_carlo_ran, run_guarded, settle,
};

/// The name inputs are read under.
const ORIGIN: &str = "fuzz.g2o";
/// Monte Carlo samples per evaluation.
const SAMPLES: u64 = 16;

/// A small TORO graph (`VERTEX2` / `EDGE2`, TORO's information order) with a loop closure.
const TORO: &str = "# TORO\nVERTEX2 0 0 0 0\nVERTEX2 1 1 0 0.1\nVERTEX2 2 2 0.2 0.2\nVERTEX2 3 2 1 1.6\nEDGE2 0 1 1 0 0.1 100 0 100 400 0 0\nEDGE2 1 2 1 0.1 0.1 100 0 100 400 0 0\nEDGE2 2 3 0.8 0 1.4 100 0 100 400 0 0\nEDGE2 3 0 -2 1 -1.6 20 0 20 100 0 0\n";

/// The seeds: every graph text the project carries.
const SEEDS: [&str; 5] = [
    include_str!("../data/gtsam/pose2example.txt"),
    include_str!("../data/gtsam/pose3example.txt"),
    include_str!("../data/gtsam/pose3example-offdiagonal.txt"),
    include_str!("../data/gtsam/noisyToyGraph.txt"),
    TORO,
];

/// Tokens a number or a tag is replaced by.
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
    "99999999999999999999",
    "-1",
    "1e16",
    "x",
    "0x10",
    "1_0",
    "",
    "#",
    "VERTEX_SE2",
    "EDGE_SE2",
    "VERTEX2",
    "EDGE2",
    "VERTEX_SE3:QUAT",
    "EDGE_SE3:QUAT",
    "FIX",
    "\u{e9}",
    "\t",
    "\r",
];

/// The graph family.
pub struct Graphs;

impl Family for Graphs {
    fn name(&self) -> &'static str {
        "graph"
    }
    fn extension(&self) -> &'static str {
        "g2o"
    }
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(case);
        let k = rng.random_range(0..SEEDS.len());
        let mut lines: Vec<String> = SEEDS[k].lines().map(str::to_owned).collect();
        let mut log = vec![format!("from seed {k}")];
        for _ in 0..[1, 1, 1, 2, 3][rng.random_range(0..5)] {
            log.push(mutate_lines(
                &mut rng,
                &mut lines,
                TOKENS,
                "VERTEX_SE2 0 0 0 0",
            ));
        }
        let mut bytes = (lines.join("\n") + "\n").into_bytes();
        if rng.random_bool(0.25) {
            log.push(mutate_bytes(&mut rng, &mut bytes, TOKENS));
        }
        (bytes, log.join("; "))
    }
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool) {
        let text = String::from_utf8_lossy(input).into_owned();
        let run = {
            let text = text.clone();
            run_guarded(limits, move |stage| run_graph(&text, stage))
        };
        let stuck = matches!(run, Run::Stuck { .. });
        (judge(&text, run, limits), stuck)
    }
}

/// One mutation of a text's lines (a graph's, a trajectory's): a token replaced by one of
/// `replacements`, dropped or added, a line dropped or repeated, the third token (a graph
/// edge's second id) changed; an empty text becomes `first`.
pub fn mutate_lines(
    rng: &mut ChaCha8Rng,
    lines: &mut Vec<String>,
    replacements: &[&str],
    first: &str,
) -> String {
    if lines.is_empty() {
        lines.push(first.into());
        return "was empty".into();
    }
    let i = rng.random_range(0..lines.len());
    let mut tokens: Vec<String> = lines[i].split_whitespace().map(str::to_owned).collect();
    let pick =
        |rng: &mut ChaCha8Rng| replacements[rng.random_range(0..replacements.len())].to_owned();
    let what = match rng.random_range(0..8) {
        0..=2 if !tokens.is_empty() => {
            let t = rng.random_range(0..tokens.len());
            tokens[t] = pick(rng);
            format!("line {i} token {t} = {:?}", tokens[t])
        }
        3 if !tokens.is_empty() => {
            let t = rng.random_range(0..tokens.len());
            tokens.remove(t);
            format!("line {i} drop token {t}")
        }
        4 => {
            let t = rng.random_range(0..=tokens.len());
            tokens.insert(t, pick(rng));
            format!("line {i} insert token at {t}")
        }
        5 => {
            lines.remove(i);
            return format!("drop line {i}");
        }
        6 => {
            let j = rng.random_range(0..lines.len());
            let copy = lines[i].clone();
            lines.insert(j, copy);
            return format!("repeat line {i} at {j}");
        }
        _ => {
            // An edge between other vertices (a self-loop, an unknown id, a huge id).
            if tokens.len() > 2 {
                let id = ["0", "1", "2", "7", "4294967296", "-1"][rng.random_range(0..6)];
                tokens[2] = id.to_owned();
            }
            format!("line {i} second id changed")
        }
    };
    lines[i] = tokens.join(" ");
    what
}

/// What the checks look at.
struct Output {
    json: serde_json::Value,
    scene_valid: Result<(), String>,
}

fn run_graph(text: &str, stage: crate::harness::Stage) -> Result<Output, String> {
    stage("read");
    let (source, input) = open_text(text, ORIGIN, Format::Graph).map_err(|e| e.to_string())?;
    let loaded = Loaded { source, input };
    let overrides = Overrides {
        samples: Some(SAMPLES),
        ..Default::default()
    };
    stage("evaluate");
    let (evaluation, scene) = pipeline(&loaded, &overrides, None).map_err(|e| e.to_string())?;
    stage("report");
    let json = report_json(
        "fuzz",
        &loaded,
        &evaluation,
        posecov::uncertain::Confidence::DEFAULT,
    );
    Ok(Output {
        json,
        scene_valid: scene.validate().map_err(|e| e.to_string()),
    })
}

fn judge(text: &str, run: Run<Result<Output, String>>, limits: &Limits) -> Vec<Finding> {
    let (result, mut found) = match settle(run, limits) {
        Ok(x) => x,
        Err(ended) => return ended,
    };
    match result {
        Err(e) => found.extend(located(ORIGIN, text, &e)),
        Ok(out) => {
            let optional = [
                "step",
                "relative_error_vs_monte_carlo",
                "uncentred_about_nominal_left",
                "uncentred_about_nominal_right",
                "cartesian_mean",
                // Batch means need two samples per batch (and the value they belong to).
                "uncentred_about_nominal_left_stderr",
                "cartesian_mean_stderr",
                // The consistency of an estimate whose Σ is singular has no ANEES.
                "anees",
                "anees_dof",
                "anees_band",
                // No marginal: a vertex held fixed, one not connected, or marginals that
                // failed (then a finding says why).
                ".optimized.poses[#].covariance",
                ".optimized.loop_closures[#].relative_covariance",
                ".optimized.joints[#].covariance",
                ".optimized.joints[#].relative_covariance",
                // No σ: a vertex held fixed or not connected (after), or one the graph
                // without its loop closures does not reach (before).
                ".optimized.poses[#].sigma",
                ".optimized.poses[#].sigma_before",
            ];
            if let Some(path) = json_null(&out.json, &optional) {
                found.push(finding("nonfinite_json", format!("null at {path}")));
            }
            if let Some(which) = null_error_where_monte_carlo_ran(&out.json) {
                found.push(finding(
                    "nonfinite_json",
                    format!("relative_error_vs_monte_carlo null where Monte Carlo ran: {which}"),
                ));
            }
            if let Err(e) = out.scene_valid {
                found.push(finding("scene_invalid", e));
            }
            found.extend(oracle(text));
        }
    }
    if found.is_empty() {
        found.push(finding("ok", ""));
    }
    found
}

/// An error names the file `origin`, and where it gives `line:column`, a place inside the
/// text.
pub fn located(origin: &str, text: &str, e: &str) -> Vec<Finding> {
    let first = e.lines().next().unwrap_or("");
    let Some(rest) = first.strip_prefix(origin) else {
        return vec![finding("error_unlocated", first)];
    };
    let mut parts = rest.strip_prefix(':').unwrap_or("").splitn(3, ':');
    let (line, column) = (parts.next(), parts.next());
    if let (Some(Ok(line)), Some(Ok(column))) = (
        line.map(str::parse::<usize>),
        column.map(str::parse::<usize>),
    ) {
        let lines: Vec<&str> = text.split('\n').collect();
        let fits = line >= 1
            && line <= lines.len()
            && column >= 1
            && column <= lines[line - 1].chars().count() + 1;
        if !fits {
            return vec![finding("error_bad_location", first)];
        }
    }
    vec![finding("error_ok", first)]
}

/// A record posecov reads with a non-finite number must be refused.
fn oracle(text: &str) -> Vec<Finding> {
    let read = [
        "VERTEX_SE2",
        "EDGE_SE2",
        "VERTEX2",
        "EDGE2",
        "VERTEX_SE3:QUAT",
        "EDGE_SE3:QUAT",
    ];
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        if tokens.next().is_some_and(|t| read.contains(&t))
            && tokens.any(|t| t.parse::<f64>().is_ok_and(|x| !x.is_finite()))
        {
            return vec![finding(
                "accepted_invalid_value",
                format!("a non-finite number on line {} accepted", k + 1),
            )];
        }
    }
    Vec::new()
}
