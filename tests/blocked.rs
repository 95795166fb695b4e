//! Blocked Monte Carlo (bounded memory for large samples): a sample split into blocks gives
//! the particles and the statistics of the same sample evaluated in one block.

use posecov::app::{Loaded, Overrides, Settings, load, load_text, resolve};
use posecov::draw::{particle_part, scene as build_scene};
use posecov::eval::{AnyEvaluation, Finding, PointEstimate, evaluate_block};
use posecov::propagate::ResultRecord;
use posecov::scene::ItemKind;
use posecov::uncertain::Method;

/// Every operation with Monte Carlo particles that no bundled scenario uses: point through
/// a pose and correlated compose, plus inverse, between and fuse (no particles of its own).
const OPERATIONS: &str = r#"
[scenario]
title = "all particle operations"
group = "se3"
seed = 11
samples = 3000
methods = ["first_order", "sigma_points", "monte_carlo"]

[[pose]]
name = "world_from_a"
mean = { xyz = [1.0, 0.5, 0.0], rpy_deg = [0.0, 10.0, 40.0] }
cov = { std = [0.05, 0.08, 0.02, 0.1, 0.05, 0.3] }

[[pose]]
name = "world_from_b"
mean = { xyz = [1.1, 0.4, 0.1], rpy_deg = [0.0, 12.0, 35.0] }
cov = { std = [0.06, 0.05, 0.03, 0.08, 0.06, 0.2] }

[[operation]]
kind = "point_through_pose"
input = "world_from_a"
point = [2.0, 0.0, 0.5]
point_cov = [[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.005]]
output = "landmark"

[[operation]]
kind = "compose_correlated"
lhs = "world_from_a"
rhs = "world_from_b"
cross_cov = [[0.001, 0, 0, 0, 0, 0], [0, 0.001, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0.002, 0, 0], [0, 0, 0, 0, 0.001, 0], [0, 0, 0, 0, 0, 0.01]]
output = "ab"

[[operation]]
kind = "between"
lhs = "world_from_a"
rhs = "world_from_b"
output = "a_from_b"

[[operation]]
kind = "inverse"
input = "world_from_a"
output = "a_from_world"

[[operation]]
kind = "fuse"
inputs = ["world_from_a", "world_from_b"]
output = "fused"
"#;

/// A scenario with the settings of `samples` (in blocks of `block`).
struct Case {
    loaded: Loaded,
    settings: Settings,
}

fn options(samples: u64, block: Option<usize>) -> Overrides {
    Overrides {
        samples: Some(samples),
        block_samples: block.map(|b| b as u64),
        ..Default::default()
    }
}

fn scenario(name: &str) -> Loaded {
    if name == "operations" {
        return load_text(OPERATIONS, "operations.toml").expect("parses");
    }
    load(name).expect("bundled")
}

fn case(loaded: &Loaded, overrides: &Overrides) -> Case {
    let settings = resolve(&loaded.input, overrides, None).expect("settings");
    Case {
        loaded: loaded.clone(),
        settings,
    }
}

fn evaluate(
    loaded: &Loaded,
    overrides: &Overrides,
) -> Result<AnyEvaluation, posecov::app::AppError> {
    let c = case(loaded, overrides);
    posecov::app::evaluate(&c.loaded, &c.settings.eval)
}

fn draw(loaded: &Loaded, e: &AnyEvaluation) -> posecov::scene::Scene {
    build_scene(e, &case(loaded, &Overrides::default()).settings.draw)
}

fn block_samples(e: &AnyEvaluation) -> usize {
    e.ran_with().block_samples
}

fn max_abs(m: &[[f64; 6]]) -> f64 {
    m.iter().flatten().fold(0.0, |a, v| a.max(v.abs()))
}

/// Records as flat numbers (the covariance padded to 6×6) for comparison.
fn flat(r: &ResultRecord) -> ([[f64; 6]; 6], Vec<f64>) {
    let mut cov = [[0.0; 6]; 6];
    for (i, row) in r.covariance.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            cov[i][j] = *v;
        }
    }
    (cov, r.mean_tangent.clone())
}

/// Blocked and single-block evaluations of `name` agree: analytic results bit for bit, Monte
/// Carlo means and covariances (and the errors against them) to 1e-8 relative — the Lie mean
/// stops at a 1e-10 step either way, from different starting points.
fn assert_blocked_matches(name: &str, samples: u64, block: usize) {
    let s = scenario(name);
    let single = evaluate(&s, &options(samples, None)).expect("evaluates");
    let blocked = evaluate(&s, &options(samples, Some(block))).expect("evaluates");
    assert_eq!(block_samples(&single), samples as usize, "{name}");
    assert_eq!(block_samples(&blocked), block, "{name}");
    let (a, b) = (single.records(), blocked.records());
    assert_eq!(a.len(), b.len(), "{name}: record count");
    let mut monte_carlo = 0;
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!((&ra.label, ra.method), (&rb.label, rb.method), "{name}");
        let ((ca, ma), (cb, mb)) = (flat(ra), flat(rb));
        if ra.method == Method::MonteCarlo {
            monte_carlo += 1;
            let scale = max_abs(&ca);
            for (x, y) in ca.iter().flatten().zip(cb.iter().flatten()) {
                assert!(
                    (x - y).abs() <= 1e-8 * scale,
                    "{name} {}: Monte Carlo covariance {x} vs {y}",
                    ra.label
                );
            }
            for (x, y) in ma.iter().zip(&mb) {
                assert!(
                    (x - y).abs() <= 1e-9,
                    "{name} {}: mean {x} vs {y}",
                    ra.label
                );
            }
        } else {
            assert_eq!((ca, ma), (cb, mb), "{name} {}: {:?}", ra.label, ra.method);
        }
        match (
            ra.relative_error_vs_monte_carlo,
            rb.relative_error_vs_monte_carlo,
        ) {
            (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-8, "{name} {}: {x} vs {y}", ra.label),
            (x, y) => assert_eq!(x, y, "{name} {}", ra.label),
        }
    }
    assert!(monte_carlo > 0, "{name}: no Monte Carlo results compared");
    if let (AnyEvaluation::Se3(a), AnyEvaluation::Se3(b)) = (&single, &blocked) {
        for (pa, pb) in a.points.iter().zip(&b.points) {
            assert_eq!(pa.estimates.len(), pb.estimates.len(), "{name} {}", pa.name);
            for (
                PointEstimate {
                    method: ma,
                    mean: mean_a,
                    cov: cov_a,
                },
                PointEstimate {
                    method: mb,
                    mean: mean_b,
                    cov: cov_b,
                },
            ) in pa.estimates.iter().zip(&pb.estimates)
            {
                assert_eq!(ma, mb);
                for (x, y) in mean_a.iter().zip(mean_b) {
                    assert!((x - y).abs() <= 1e-12, "{name} {}: {x} vs {y}", pa.name);
                }
                for (x, y) in cov_a.iter().zip(cov_b.iter()) {
                    assert!((x - y).abs() <= 1e-12, "{name} {}: {x} vs {y}", pa.name);
                }
            }
        }
    }
    let blocks = (samples as usize).div_ceil(block);
    assert!(
        blocked.findings().iter().any(|f| matches!(
            f,
            Finding::Blocked { samples: n, blocks: k, .. } if *n == samples as usize && *k == blocks
        )),
        "{name}: the blocked evaluation says so in its findings"
    );
}

#[test]
fn blocked_statistics_equal_single_block_statistics_for_every_group_and_operation() {
    assert_blocked_matches("operations", 3000, 1024);
    let ops = evaluate(&scenario("operations"), &options(3000, Some(1024))).expect("evaluates");
    let labels: Vec<String> = ops
        .records()
        .iter()
        .filter(|r| r.method == Method::MonteCarlo)
        .map(|r| r.label.clone())
        .collect();
    for name in ["ab", "a_from_b", "a_from_world"] {
        assert!(
            labels.iter().any(|l| l == name),
            "{name} has a Monte Carlo result: {labels:?}"
        );
    }
    let AnyEvaluation::Se3(e) = &ops else {
        panic!("SE(3)")
    };
    assert!(
        e.points[0]
            .estimates
            .iter()
            .any(|p| p.method == Method::MonteCarlo),
        "the landmark has a Monte Carlo estimate"
    );
    assert_blocked_matches("camera_on_robot", 3000, 1024);
    assert_blocked_matches("so3_sampling", 2500, 1024);
    assert_blocked_matches("na568_se2_odometry", 3000, 2048);
    assert_blocked_matches("na568_se3_odometry", 2100, 1024);
    assert_blocked_matches("vector_space_vs_lie", 2100, 1024);
}

#[test]
fn blocked_compounding_and_diff_drive_match_single_block() {
    // The along-track series (uncentred left covariance) and the diff-drive notes (Lie and
    // Cartesian means) are sums over blocks too.
    for (name, samples) in [("barfoot_compounding", 2100), ("diff_drive_banana", 2100)] {
        assert_blocked_matches(name, samples, 1024);
        let s = scenario(name);
        let single = evaluate(&s, &options(samples, None)).expect("evaluates");
        let blocked = evaluate(&s, &options(samples, Some(1024))).expect("evaluates");
        let (sa, sb) = (draw(&s, &single).series, draw(&s, &blocked).series);
        assert_eq!(sa.len(), sb.len(), "{name}");
        for (x, y) in sa.iter().zip(&sb) {
            assert_eq!(
                (&x.path(), x.points.len()),
                (&y.path(), y.points.len()),
                "{name}"
            );
            for ((kx, vx), (ky, vy)) in x.points.iter().zip(&y.points) {
                assert_eq!(kx, ky);
                assert!(
                    (vx - vy).abs() <= 1e-8 * vx.abs().max(1e-12),
                    "{name} {}: {vx} vs {vy}",
                    x.path()
                );
            }
        }
        // The means and their batch-means standard errors (the same batches in both runs).
        let means = |e: &AnyEvaluation| -> Vec<[f64; 2]> {
            e.findings()
                .iter()
                .filter_map(|f| match f {
                    Finding::DiffDriveMeans {
                        cartesian_mean,
                        cartesian_mean_stderr,
                        ..
                    } => Some([*cartesian_mean, cartesian_mean_stderr.expect("stderr")]),
                    _ => None,
                })
                .flatten()
                .collect()
        };
        let (ma, mb) = (means(&single), means(&blocked));
        assert_eq!(ma.len(), mb.len(), "{name}");
        for (a, b) in ma.iter().zip(&mb) {
            assert!(
                (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
                "{name}: {a:?} vs {b:?}"
            );
        }
    }
}

/// The particles of block k are exactly samples k·b.. of the single-block run.
#[test]
fn every_block_simulates_exactly_its_slice_of_the_whole_sample() {
    for name in ["operations", "na568_se3_odometry", "diff_drive_banana"] {
        let s = scenario(name);
        let (samples, block) = (2500, 1024);
        let single = evaluate(&s, &options(samples, None)).expect("evaluates");
        let blocked = evaluate(&s, &options(samples, Some(block))).expect("evaluates");
        let mut k = 0;
        let c = case(&s, &options(samples, Some(block)));
        while let Some(part) =
            evaluate_block(&c.loaded.input.plan, &c.settings.eval, &blocked, k).expect("evaluates")
        {
            let range = k * block..((k + 1) * block).min(samples as usize);
            match (&single, &part) {
                (AnyEvaluation::Se3(a), AnyEvaluation::Se3(b)) => {
                    for (na, nb) in a.nodes.iter().zip(&b.nodes) {
                        if let (Some(pa), Some(pb)) = (&na.particles, &nb.particles) {
                            assert_eq!(&pa[range.clone()], &pb[..], "{name} {} block {k}", na.name);
                        }
                    }
                    for (pa, pb) in a.points.iter().zip(&b.points) {
                        if let (Some(qa), Some(qb)) = (&pa.particles, &pb.particles) {
                            assert_eq!(&qa[range.clone()], &qb[..], "{name} {}", pa.name);
                        }
                    }
                }
                (AnyEvaluation::Se2(a), AnyEvaluation::Se2(b)) => {
                    for (na, nb) in a.nodes.iter().zip(&b.nodes) {
                        if let (Some(pa), Some(pb)) = (&na.particles, &nb.particles) {
                            assert_eq!(&pa[range.clone()], &pb[..], "{name} {} block {k}", na.name);
                        }
                    }
                }
                _ => panic!("{name}: unexpected group"),
            }
            k += 1;
        }
        assert_eq!(k, 3, "{name}: blocks of 1024, 1024 and 452 samples");
    }
}

#[test]
fn particle_parts_draw_each_later_block_once_with_the_main_scene_sizes() {
    let s = scenario("camera_on_robot");
    let opts = options(3000, Some(1024));
    let main = evaluate(&s, &opts).expect("evaluates");
    let c = case(&s, &opts);
    let scene = build_scene(&main, &c.settings.draw);
    let parts: Vec<_> = (1..)
        .map_while(|k| {
            evaluate_block(&c.loaded.input.plan, &c.settings.eval, &main, k)
                .expect("evaluates")
                .map(|block| particle_part(&main, &block, k, &c.settings.draw))
        })
        .collect();
    assert_eq!(parts.len(), 2);
    let cloud_points = |scene: &posecov::scene::Scene, suffix: &str| -> (usize, Vec<f64>) {
        let clouds: Vec<_> = scene
            .items
            .iter()
            .filter(|i| i.path.ends_with(suffix))
            .filter_map(|i| match &i.kind {
                ItemKind::Points(p) => Some(p),
                _ => None,
            })
            .collect();
        (
            clouds.iter().map(|c| c.positions.len()).sum(),
            clouds.iter().map(|c| c.radius).collect(),
        )
    };
    let (n0, r0) = cloud_points(&scene, "/cloud");
    let (n1, r1) = cloud_points(&parts[0], "/cloud/block_1");
    let (n2, r2) = cloud_points(&parts[1], "/cloud/block_2");
    let clouds = r0.len();
    assert!(clouds > 0);
    assert_eq!((n0, n1, n2), (1024 * clouds, 1024 * clouds, 952 * clouds));
    assert_eq!((&r0, &r0), (&r1, &r2), "same point size as the first block");
    for part in &parts {
        part.validate().expect("valid");
        assert!(
            part.items.iter().all(|i| i.path.contains("/block_")),
            "a part holds only later-block particles (no triads, frames or bananas)"
        );
        assert!(part.series.is_empty());
    }
    // Not blocked: no parts.
    let whole = evaluate(&s, &options(3000, None)).expect("evaluates");
    let c = case(&s, &options(3000, None));
    assert!(
        evaluate_block(&c.loaded.input.plan, &c.settings.eval, &whole, 1)
            .expect("evaluates")
            .is_none()
    );
}

#[test]
fn small_samples_are_never_blocked_and_block_sizes_round_to_whole_chunks() {
    let s = scenario("na568_se3_odometry");
    let e = evaluate(&s, &options(5000, None)).expect("evaluates");
    assert_eq!(block_samples(&e), 5000);
    let e = evaluate(&s, &options(3000, Some(1000))).expect("evaluates");
    assert_eq!(
        block_samples(&e),
        1024,
        "rounded up to a whole 1024-sample chunk"
    );
}
