//! Every bundled scenario parses, evaluates and builds a valid scene; their numbers match the
//! reference cases they reproduce.
#![allow(clippy::needless_range_loop)] // matrices are compared entry by entry, by index

use posecov::app::{Overrides, load, load_text, pipeline};
use posecov::input::scenario::bundled::BUNDLED;

fn small() -> Overrides {
    Overrides {
        samples: Some(400),
        ..Default::default()
    }
}

#[test]
fn every_bundled_scenario_evaluates_and_draws() {
    for b in BUNDLED {
        let loaded = load_text(b.text, b.name).unwrap_or_else(|e| panic!("{}: {e}", b.name));
        let (evaluation, scene) =
            pipeline(&loaded, &small(), None).unwrap_or_else(|e| panic!("{}: {e}", b.name));
        assert!(!scene.items.is_empty(), "{} draws nothing", b.name);
        assert!(
            scene
                .description_markdown
                .contains(&loaded.input.about.title),
            "{}",
            b.name
        );
        // The bundled scenarios are well posed: nothing failed, nothing indefinite.
        assert!(
            evaluation.findings().iter().all(|f| !matches!(
                f,
                posecov::eval::Finding::MethodFailed { .. }
                    | posecov::eval::Finding::NotPositiveSemiDefinite { .. }
            )),
            "{}: {:?}",
            b.name,
            evaluation.findings()
        );
        // No text shown to users names an internal document, writes a transpose as `^T`, or
        // uses a glyph the viewer's font lacks (ᵀ U+1D40, ⊤, ⊺ render as boxes; ᵗ renders).
        let plot_titles: Vec<String> = scene.plots.iter().map(|p| p.label()).collect();
        for text in std::iter::once(&scene.description_markdown).chain(&plot_titles) {
            for bad in ["REFERENCE_CASES", "CONVENTIONS", "^T", "ᵀ", "⊤", "⊺"] {
                assert!(!text.contains(bad), "{} shows {bad:?}", b.name);
            }
        }
    }
}

/// The guide's commented scenario example (docs/guide/scenarios.md) is a valid scenario.
#[test]
fn guide_example_parses_and_evaluates() {
    let readme = include_str!("../docs/guide/scenarios.md");
    let start = readme
        .find("```toml\n")
        .expect("docs/guide/scenarios.md has a ```toml block")
        + "```toml\n".len();
    let end = start + readme[start..].find("```").expect("closed block");
    let loaded =
        load_text(&readme[start..end], "docs/guide/scenarios.md").unwrap_or_else(|e| panic!("{e}"));
    pipeline(&loaded, &small(), None).unwrap_or_else(|e| panic!("{e}"));
}

fn record<'a>(
    records: &'a [posecov::propagate::ResultRecord],
    label: &str,
    method: posecov::uncertain::Method,
) -> &'a posecov::propagate::ResultRecord {
    records
        .iter()
        .find(|r| r.label == label && r.method == method)
        .unwrap_or_else(|| panic!("no {method:?} record for {label}"))
}

fn bundled_records(name: &str, samples: u64) -> Vec<posecov::propagate::ResultRecord> {
    let loaded = load(name).expect("bundled");
    let overrides = Overrides {
        samples: Some(samples),
        ..Default::default()
    };
    pipeline(&loaded, &overrides, None)
        .expect("evaluates")
        .0
        .records()
}

/// `na568_se2_odometry` reproduces [REFERENCE_CASES R2] at step 7 (1e-6).
///
/// [REFERENCE_CASES R2]: posecov::reference_cases#r2-se2-odometry-na-568
#[test]
fn na568_se2_scenario_reproduces_r2() {
    use posecov::uncertain::{Method, Side};
    let records = bundled_records("na568_se2_odometry", 100);
    let r = record(&records, "robot@7", Method::FirstOrder);
    assert_eq!(r.side, Side::Right);
    let expect = [
        [0.010612, -0.013364, -0.010833],
        [-0.013364, 0.358141, 0.131531],
        [-0.010833, 0.131531, 0.07],
    ];
    for i in 0..3 {
        for j in 0..3 {
            assert!(
                (r.covariance[i][j] - expect[i][j]).abs() < 1e-6,
                "Σ[{i}][{j}] = {}",
                r.covariance[i][j]
            );
        }
    }
    // The table and its inputs are rounded to 6 decimals: the nominal agrees to ~1e-6.
    assert!(
        (r.mean_matrix[0][2] - 3.802082).abs() < 2e-6
            && (r.mean_matrix[1][2] - 1.827062).abs() < 2e-6,
        "{:?}",
        r.mean_matrix
    );
}

/// `na568_se3_odometry` reproduces the R4 step-4 diagonals with and without Jr.
#[test]
fn na568_se3_scenario_reproduces_r4() {
    use posecov::uncertain::Method;
    let records = bundled_records("na568_se3_odometry", 100);
    let with_jr = [0.867324, 5.207498, 9.044747, 0.012427, 0.081679, 0.083749];
    let lecture = [0.852095, 4.488039, 7.399204, 0.012156, 0.070807, 0.097036];
    for (method, expect) in [
        (Method::FirstOrder, with_jr),
        (Method::LectureNoJr, lecture),
    ] {
        let r = record(&records, "drone@4", method);
        for (i, e) in expect.iter().enumerate() {
            assert!(
                (r.covariance[i][i] - e).abs() < 2e-6,
                "{method:?} Σ[{i}][{i}] = {}",
                r.covariance[i][i]
            );
        }
    }
}

/// `barfoot_compounding` reproduces R5: 2nd order misses the along-track variance, 4th order
/// gives 1.677522.
#[test]
fn barfoot_scenario_reproduces_r5() {
    use posecov::uncertain::{Method, Side};
    let records = bundled_records("barfoot_compounding", 100);
    let fourth = record(&records, "robot@100", Method::FourthOrder);
    let second = record(&records, "robot@100", Method::SecondOrder);
    assert_eq!(fourth.side, Side::Left);
    assert!(
        (fourth.covariance[0][0] - 1.677522).abs() < 1e-6,
        "{}",
        fourth.covariance[0][0]
    );
    assert!(
        (fourth.covariance[1][1] - 294.400746).abs() < 1e-6,
        "{}",
        fourth.covariance[1][1]
    );
    assert!(
        second.covariance[0][0].abs() < 1e-12 && (second.covariance[1][1] - 295.515).abs() < 1e-3
    );
}

/// `diff_drive_banana` reproduces R7's straight-run closed form (D = 4: Σ11 = D r² t / 2).
#[test]
fn diff_drive_scenario_reproduces_r7() {
    use posecov::uncertain::Method;
    let records = bundled_records("diff_drive_banana", 100);
    let straight = record(&records, "straight", Method::ClosedForm);
    assert!((straight.covariance[0][0] - 4.0 * 5.445e-4).abs() < 1e-12);
    assert!((straight.covariance[2][2] - 4.0 * 0.05445).abs() < 1e-9);
    let arc = record(&records, "arc", Method::ClosedForm);
    let integral = record(&records, "arc", Method::NumericIntegral);
    for i in 0..3 {
        for j in 0..3 {
            assert!((arc.covariance[i][j] - integral.covariance[i][j]).abs() < 1e-9);
        }
    }
    assert!(
        (arc.covariance[0][0] - 0.012619).abs() < 1e-6
            && (arc.covariance[1][2] - 0.034664).abs() < 1e-6
    );
}
