//! Scenario TOML: the bundled scenarios (and three extra seeds), mutated in structure and in
//! bytes, run through the pure path `posecov check` and `report --json` take: parse → lower →
//! resolve → evaluate (few samples) → draw → `Scene::validate` → records and findings.

mod classify;
mod generate;
mod mutate;
mod seeds;

use nalgebra::DMatrix;

use posecov::app::{AppError, DEFAULT_SAMPLES, Overrides, evaluate, load_text, resolve};
use posecov::eval::{AnyEvaluation, Evaluation, Finding as EvalFinding};
use posecov::input::scenario::ScenarioError;
use posecov::propagate::ResultRecord;
use posecov::scene::{ItemKind, Scene};

use crate::harness::{Family, Finding, Limits, Run, run_guarded};
pub use generate::Generator;
pub use seeds::EXTRA_SEEDS;

/// The name failing inputs are run under (errors are located in it).
pub const ORIGIN: &str = "fuzz.toml";

/// The scenario family.
pub struct Scenarios {
    generator: Generator,
}

impl Scenarios {
    pub fn new() -> Self {
        Self {
            generator: Generator::new(),
        }
    }
}

impl Family for Scenarios {
    fn name(&self) -> &'static str {
        "scenario"
    }
    fn extension(&self) -> &'static str {
        "toml"
    }
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String) {
        let (text, how) = self.generator.case(seed, case);
        (text.into_bytes(), how)
    }
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool) {
        let text = String::from_utf8_lossy(input).into_owned();
        let run = run_text(&text, limits);
        let stuck = matches!(run, Run::Stuck { .. });
        (classify::classify(&text, ORIGIN, run, limits), stuck)
    }
}

/// One text through [`run_pipeline`] under the watchdog.
pub fn run_text(text: &str, limits: &Limits) -> Run<Result<Output, Reported>> {
    let text = text.to_owned();
    run_guarded(limits, move |stage| run_pipeline(&text, ORIGIN, stage))
}

/// Line-based reduction: drop lines while the input keeps a finding with dedup key `key`.
/// Stops on a hang (returned as `Err`).
pub fn reduce(text: &str, key: &str, limits: &Limits) -> Result<String, String> {
    let still = |t: &str| -> Result<bool, String> {
        let run = run_text(t, limits);
        if let Run::Stuck { .. } = run {
            return Err(t.to_owned());
        }
        let findings = classify::classify(t, ORIGIN, run, limits);
        Ok(findings.iter().any(|f| crate::harness::dedup_key(f) == key))
    };
    let mut lines: Vec<String> = text.split_inclusive('\n').map(str::to_owned).collect();
    let mut chunk = (lines.len() / 2).max(1);
    let mut tries = 0;
    loop {
        let mut changed = false;
        let mut i = 0;
        while i < lines.len() && tries < 2000 {
            let end = (i + chunk).min(lines.len());
            let candidate: String = lines[..i].concat() + &lines[end..].concat();
            tries += 1;
            if still(&candidate)? {
                lines.drain(i..end);
                changed = true;
            } else {
                i += chunk;
            }
        }
        if tries >= 2000 || (!changed && chunk == 1) {
            break;
        }
        if !changed {
            chunk = (chunk / 2).max(1);
        }
    }
    Ok(lines.concat())
}

pub use classify::classify;

/// Samples per evaluation, as `posecov check` caps them.
pub const CHECK_SAMPLES: u64 = 32;

/// What the checks look at, as plain data.
pub struct Output {
    /// Every record, as the library returns it.
    pub records: Vec<ResultRecord>,
    /// The same records through serde_json (what `--json` prints).
    pub records_json: serde_json::Value,
    /// The evaluation's findings (a covariance reported indefinite is not silent).
    pub findings: Vec<EvalFinding>,
    /// The findings through serde_json.
    pub findings_json: serde_json::Value,
    /// Every covariance of the output, labelled (records and uncertain points).
    pub covariances: Vec<(String, DMatrix<f64>)>,
    /// The scene.
    pub scene: Scene,
    /// `Scene::validate`.
    pub scene_valid: Result<(), String>,
}

/// An error the path reported.
pub struct Reported {
    /// `Display` of the error.
    pub text: String,
    /// The field it names, where the error type has one.
    pub field: Option<String>,
}

/// Runs the whole pure path. `stage` is told where the run is (for hang reports).
pub fn run_pipeline(
    text: &str,
    origin: &str,
    stage: &dyn Fn(&'static str),
) -> Result<Output, Reported> {
    let reported = |e: AppError| Reported {
        text: e.to_string(),
        field: match &e {
            AppError::Input(ScenarioError::At { field, .. }) => Some(field.clone()),
            _ => None,
        },
    };
    stage("parse");
    let loaded = load_text(text, origin).map_err(reported)?;
    let file_samples = loaded.input.defaults.samples.unwrap_or(DEFAULT_SAMPLES);
    let overrides = Overrides {
        samples: Some(file_samples.min(CHECK_SAMPLES)),
        ..Default::default()
    };
    let settings = resolve(&loaded.input, &overrides, None).map_err(|e| reported(e.into()))?;
    stage("evaluate");
    let evaluation = evaluate(&loaded, &settings.eval).map_err(reported)?;
    stage("build_scene");
    let scene = posecov::draw::scene(&evaluation, &settings.draw);
    stage("validate");
    let scene_valid = scene.validate().map_err(|e| e.to_string());
    stage("records");
    let records = evaluation.records();
    let records_json = serde_json::to_value(&records).expect("records serialise");
    let findings = evaluation.findings().to_vec();
    let findings_json = serde_json::to_value(&findings).expect("findings serialise");
    let mut covariances: Vec<(String, DMatrix<f64>)> = records
        .iter()
        .map(|r| {
            let n = r.covariance.len();
            let m = DMatrix::from_fn(n, n, |i, j| {
                r.covariance[i].get(j).copied().unwrap_or(f64::NAN)
            });
            (format!("{} ({:?})", r.label, r.method), m)
        })
        .collect();
    fn points<G: posecov::lie::LieGroup<N>, const N: usize>(
        e: &Evaluation<G, N>,
        out: &mut Vec<(String, DMatrix<f64>)>,
    ) {
        for p in &e.points {
            for estimate in &p.estimates {
                out.push((
                    format!("point {} ({:?})", p.name, estimate.method),
                    DMatrix::from_fn(3, 3, |i, j| estimate.cov[(i, j)]),
                ));
            }
        }
    }
    match &evaluation {
        AnyEvaluation::So2(e) => points(e, &mut covariances),
        AnyEvaluation::Se2(e) => points(e, &mut covariances),
        AnyEvaluation::So3(e) => points(e, &mut covariances),
        AnyEvaluation::Se3(e) => points(e, &mut covariances),
    }
    stage("done");
    Ok(Output {
        records,
        records_json,
        findings,
        findings_json,
        covariances,
        scene,
        scene_valid,
    })
}

/// The first non-finite numbers of a scene (path, field, value).
pub fn scene_nonfinite(scene: &Scene) -> Vec<(String, &'static str, f64)> {
    let mut bad = Vec::new();
    let mut check = |path: &str, field: &'static str, values: &mut dyn Iterator<Item = f64>| {
        if let Some(v) = Iterator::find(&mut { values }, |v| !v.is_finite()) {
            bad.push((path.to_owned(), field, v));
        }
    };
    let flat = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<f64>>();
    for item in &scene.items {
        let p = item.path.as_str();
        match &item.kind {
            ItemKind::Frame(f) => {
                check(p, "translation", &mut f.translation.iter().copied());
                check(p, "rotation", &mut f.rotation.iter().copied());
                check(p, "axis_length", &mut std::iter::once(f.axis_length));
            }
            ItemKind::Triads(t) => {
                check(p, "translations", &mut flat(&t.translations).into_iter());
                check(p, "rotations", &mut t.rotations.iter().flatten().copied());
                check(
                    p,
                    "axis_length",
                    &mut [t.axis_length, t.line_radius].into_iter(),
                );
            }
            ItemKind::Points(c) => {
                check(p, "positions", &mut flat(&c.positions).into_iter());
                check(p, "radius", &mut std::iter::once(c.radius));
            }
            ItemKind::Ellipsoids(e) => {
                for s in &e.shapes {
                    check(p, "center", &mut s.center.iter().copied());
                    check(p, "half_sizes", &mut s.half_sizes.iter().copied());
                    check(p, "rotation", &mut s.rotation.iter().copied());
                }
                check(p, "line_radius", &mut std::iter::once(e.line_radius));
            }
            ItemKind::Surface(s) => {
                check(p, "vertices", &mut flat(&s.vertices).into_iter());
                check(p, "normals", &mut flat(&s.normals).into_iter());
            }
            ItemKind::LineStrips(l) => {
                check(
                    p,
                    "strips",
                    &mut l.strips.iter().flatten().flatten().copied(),
                );
                check(p, "radius", &mut std::iter::once(l.radius));
            }
            ItemKind::Arrows(a) => {
                check(p, "origins", &mut flat(&a.origins).into_iter());
                check(p, "vectors", &mut flat(&a.vectors).into_iter());
                check(p, "radius", &mut std::iter::once(a.radius));
            }
            ItemKind::Text(_) => {}
        }
    }
    for s in &scene.series {
        check(
            &s.path(),
            "series",
            &mut s.points.iter().map(|p| p.1).chain([s.width]),
        );
    }
    bad
}
