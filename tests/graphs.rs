//! g2o / GTSAM pose graphs: numbers read exactly, the EDGE_SE3:QUAT information convention
//! against a numeric Jacobian and against GTSAM's reading (pose3example-offdiagonal.txt), the
//! odometry chain's first order against Monte Carlo, every bad input located, and the format
//! detection.

use nalgebra::{Matrix3, Matrix6, SMatrix, Vector6};
use posecov::eval::{EvalSettings, evaluate};
use posecov::input::graph::convention::{
    from_upper_triangle, se3_cov_as_gtsam_reads, se3_cov_from_g2o_error_cov,
};
use posecov::input::graph::{MAX_FILE_BYTES, read_file, read_text};
use posecov::input::{Format, Input, open, open_text};
use posecov::interop::cov_to_rotation_first;
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::plan::{AnyPlan, Op, PoseValue, StepNoise};
use posecov::uncertain::Method;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

const POSE2: &str = include_str!("data/gtsam/pose2example.txt");
const POSE3: &str = include_str!("data/gtsam/pose3example.txt");
const OFFDIAGONAL: &str = include_str!("data/gtsam/pose3example-offdiagonal.txt");
const TOY: &str = include_str!("data/gtsam/noisyToyGraph.txt");

fn input(text: &str) -> Input {
    read_text(text, "g.g2o").expect("a valid graph").1
}

fn chain_noise<const N: usize>(ops: &[Op<impl LieGroup<N>, N>]) -> Vec<SMatrix<f64, N, N>> {
    match &ops[0] {
        Op::Odometry {
            noise: StepNoise::PerStep(v),
            ..
        } => v.clone(),
        _ => panic!("the first operation is the odometry chain"),
    }
}

fn relative(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm).sqrt()
}

#[test]
fn pose2example_numbers_are_read_exactly() {
    let AnyPlan::Se2(plan) = input(POSE2).plan else {
        panic!("planar")
    };
    // VERTEX_SE2 1 1.030390 0.011350 -0.081596
    let v1 = plan.poses.iter().find(|p| p.name == "v1").expect("v1");
    assert_eq!(
        v1.value,
        PoseValue::Known(Se2::from_xy_theta(1.030390, 0.011350, -0.081596))
    );
    assert_eq!(
        plan.poses
            .iter()
            .filter(|p| p.name.starts_with('v') && !p.name.contains("_"))
            .count(),
        11
    );
    // EDGE_SE2 0 1 1.030390 0.011350 -0.081596 44.721360 0 0 44.721360 0 30.901699
    let Op::Odometry { controls, .. } = &plan.operations[0].op else {
        panic!("chain")
    };
    assert_eq!(controls.len(), 10);
    assert_eq!(
        controls[0].increment,
        Se2::from_xy_theta(1.030390, 0.011350, -0.081596)
    );
    let information = from_upper_triangle::<3>(&[44.721360, 0.0, 0.0, 44.721360, 0.0, 30.901699]);
    let expected = information.try_inverse().expect("invertible");
    let got = chain_noise(
        &plan
            .operations
            .iter()
            .map(|o| o.op.clone())
            .collect::<Vec<_>>(),
    )[0];
    assert!((got - expected).norm() <= 1e-15 * expected.norm(), "{got}");
    // Two loop closures (5 → 9, 3 → 10): each a measured input and its prediction.
    let names: Vec<&str> = plan.operations.iter().map(|o| o.output.as_str()).collect();
    assert_eq!(names, ["odometry_chain", "v9_via_v5", "v10_via_v3"]);
}

/// TORO's `EDGE2` (OpenSLAM TORO's format) writes the information as xx xy yy θθ xθ yθ; the
/// same edge written as `EDGE_SE2` (upper triangle xx xy xθ yy yθ θθ) reads to the same Σ, and
/// a bad number is named by its entry where it stands in the TORO line.
#[test]
fn toro_edge2_reads_the_information_in_toros_order() {
    let g2o = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0.1 40 3 1.5 25 -2 90\n";
    let toro = "VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0.1 40 3 25 90 1.5 -2\n";
    let noise = |text: &str| {
        let AnyPlan::Se2(plan) = input(text).plan else {
            panic!("planar")
        };
        let ops: Vec<_> = plan.operations.iter().map(|o| o.op.clone()).collect();
        chain_noise(&ops)[0]
    };
    let expected = Matrix3::new(40.0, 3.0, 1.5, 3.0, 25.0, -2.0, 1.5, -2.0, 90.0)
        .try_inverse()
        .expect("invertible");
    assert!((noise(g2o) - expected).norm() <= 1e-15 * expected.norm());
    assert!((noise(toro) - expected).norm() <= 1e-15 * expected.norm());
    // TORO's classic isotropic edge (xx 0 yy θθ 0 0) is positive definite in TORO's order
    // (read as an upper triangle it would put θθ = 0 and be refused).
    let diagonal = "VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0 20 0 20 100 0 0\n";
    let d = noise(diagonal);
    assert!((d - Matrix3::from_diagonal(&nalgebra::Vector3::new(0.05, 0.05, 0.01))).norm() < 1e-15);
    // The 4th information number of a TORO line is I(θ,θ), at its own column.
    let bad = "VERTEX2 0 0 0 0\nEDGE2 0 1 1 0 0 20 0 20 nan 0 0\n";
    let e = read_text(bad, "g.graph").unwrap_err().to_string();
    assert!(
        e.starts_with("g.graph:2:25: EDGE2 0 1: I(θ,θ) = nan is not a finite number"),
        "{e}"
    );
}

#[test]
fn reversed_chain_edge_is_inverted_with_its_covariance_moved() {
    // noisyToyGraph has edges 0→1, 1→2, 2→3 and loop closures 2→0, 0→3. Reverse one.
    let text =
        "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0.5\nEDGE_SE2 1 0 -1 0.2 -0.5 100 10 0 200 0 300\n";
    let AnyPlan::Se2(plan) = input(text).plan else {
        panic!("planar")
    };
    let z = Se2::from_xy_theta(-1.0, 0.2, -0.5);
    let Op::Odometry { controls, .. } = &plan.operations[0].op else {
        panic!("chain")
    };
    assert!(controls[0].increment.between(&z.inverse()).log().norm() < 1e-15);
    let cov = from_upper_triangle::<3>(&[100.0, 10.0, 0.0, 200.0, 0.0, 300.0])
        .try_inverse()
        .expect("invertible");
    let ad = z.adj();
    let expected = ad * cov * ad.transpose();
    let ops: Vec<_> = plan.operations.iter().map(|o| o.op.clone()).collect();
    assert!((chain_noise(&ops)[0] - expected).norm() < 1e-15);
}

/// g2o's EDGE_SE3:QUAT error e(ξ) = (t, q.xyz) of Δ = Exp(ξ), ξ = [ρ; θ].
fn g2o_error(xi: &Vector6<f64>) -> Vector6<f64> {
    let delta = Se3::exp(xi);
    let t = delta.translation();
    let [qx, qy, qz, _] = delta.rotation().to_quaternion_xyzw();
    Vector6::new(t.x, t.y, t.z, qx, qy, qz)
}

#[test]
fn se3_information_convention_matches_a_numeric_jacobian() {
    let h = 1e-6;
    let jacobian = Matrix6::from_fn(|r, c| {
        let mut step = Vector6::zeros();
        step[c] = h;
        (g2o_error(&step)[r] - g2o_error(&-step)[r]) / (2.0 * h)
    });
    let expected = Matrix6::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, 0.5, 0.5, 0.5));
    assert!((jacobian - expected).amax() < 1e-9, "{jacobian}");
    // Σ_ξ = J⁻¹ Ω⁻¹ J⁻ᵀ for the off-diagonal file's information.
    let information = offdiagonal_information();
    let cov_error = information.try_inverse().expect("invertible");
    let j_inv = jacobian.try_inverse().expect("invertible");
    let numeric = j_inv * cov_error * j_inv.transpose();
    let closed = se3_cov_from_g2o_error_cov(&cov_error);
    assert!(
        (numeric - closed).norm() < 1e-8 * closed.norm(),
        "{numeric}\n{closed}"
    );
}

#[test]
fn se3_information_convention_matches_sampled_errors() {
    // Draw ξ ~ N(0, Σ_ξ), map each through g2o's error: its covariance is Ω⁻¹.
    let cov_error = offdiagonal_information().try_inverse().expect("invertible");
    let cov_xi = se3_cov_from_g2o_error_cov(&cov_error);
    let l = cov_xi.cholesky().expect("positive definite").l();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let n = 200_000;
    let mut sum = Matrix6::zeros();
    for _ in 0..n {
        let u = Vector6::from_fn(|_, _| StandardNormal.sample(&mut rng));
        let e = g2o_error(&(l * u));
        sum += e * e.transpose();
    }
    let sampled = sum / n as f64;
    for k in 0..6 {
        let ratio = sampled[(k, k)] / cov_error[(k, k)];
        assert!(
            (ratio - 1.0).abs() < 0.02,
            "axis {k}: sampled/Ω⁻¹ = {ratio}"
        );
    }
}

/// The 21 numbers of pose3example-offdiagonal.txt's edge, as the upper triangle.
fn offdiagonal_information() -> Matrix6<f64> {
    #[rustfmt::skip]
    let upper = [
        10000.0, 1.0, 1.0, 1.0, 1.0, 1.0,
        10000.0, 2.0, 2.0, 2.0, 2.0,
        10000.0, 3.0, 3.0, 3.0,
        10000.0, 4.0, 4.0,
        10000.0, 5.0,
        10000.0,
    ];
    from_upper_triangle::<6>(&upper)
}

#[test]
fn pose3example_offdiagonal_reads_as_g2o_defines_it_and_as_gtsam_does() {
    let AnyPlan::Se3(plan) = input(OFFDIAGONAL).plan else {
        panic!("3D")
    };
    let ops: Vec<_> = plan.operations.iter().map(|o| o.op.clone()).collect();
    let posecov = chain_noise(&ops)[0];
    let information = offdiagonal_information();
    let d = Matrix6::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, 2.0, 2.0, 2.0));
    let expected = d * information.try_inverse().expect("invertible") * d;
    assert!((posecov - expected).norm() < 1e-12 * expected.norm());
    // The measurement: x y z qx qy qz qw as written (the quaternion normalised).
    let Op::Odometry { controls, .. } = &ops[0] else {
        panic!("chain")
    };
    let z = controls[0].increment;
    assert_eq!(
        *z.translation(),
        nalgebra::Vector3::new(1.001367, 0.015390, 0.004948)
    );
    let q = z.rotation().to_quaternion_xyzw();
    let norm =
        (0.190253f64.powi(2) + 0.283162f64.powi(2) + 0.392318f64.powi(2) + 0.854230f64.powi(2))
            .sqrt();
    for (got, want) in q.iter().zip([0.190253, 0.283162, -0.392318, 0.854230]) {
        assert!((got - want / norm).abs() < 1e-12, "{q:?}");
    }

    // GTSAM: blocks swapped to [ω; v], the tθ block kept as the (v, ω) block (not transposed),
    // no half-angle factor.
    let gtsam = se3_cov_as_gtsam_reads(&information).expect("invertible");
    let gtsam_information = gtsam.try_inverse().expect("invertible");
    let t_theta = Matrix3::new(1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0);
    let v_omega = gtsam_information.fixed_view::<3, 3>(3, 0).into_owned();
    assert!((v_omega - t_theta).amax() < 1e-6, "{v_omega}");
    assert!((gtsam_information[(0, 0)] - 10000.0).abs() < 1e-6);
    // posecov in GTSAM's order against GTSAM: rotation ×4, cross ×2, translation equal.
    let ours = cov_to_rotation_first(&posecov);
    for r in 0..6 {
        for c in 0..6 {
            let factor = match (r < 3, c < 3) {
                (true, true) => 4.0,
                (false, false) => 1.0,
                _ => 2.0,
            };
            assert!(
                (ours[(r, c)] - factor * gtsam[(r, c)]).abs() < 1e-12 * ours.amax(),
                "({r}, {c}): {} vs {factor} × {}",
                ours[(r, c)],
                gtsam[(r, c)]
            );
        }
    }
}

fn settings(samples: usize) -> EvalSettings {
    EvalSettings {
        seed: 3,
        samples,
        methods: vec![Method::FirstOrder, Method::MonteCarlo],
        ..EvalSettings::default()
    }
}

/// First order against 20 000 Monte Carlo samples at the chain's last step. Sampling error is
/// about 1 %; the rest is the chain's nonlinearity: pose2example's edges have σ_θ = 0.18 rad
/// (first order 5 % off after 10 steps), pose3example's 0.02 rad (2 %), and noisyToyGraph's
/// σ = 1 m, 1 rad per edge make a banana no Gaussian in the tangent space of the mean can
/// follow (31 %): the picture's point.
#[test]
fn chain_first_order_agrees_with_monte_carlo_where_the_noise_is_small() {
    for (name, text, range) in [
        ("pose2example", POSE2, 0.02..0.08),
        ("pose3example", POSE3, 0.0..0.04),
        ("noisyToyGraph", TOY, 0.2..0.5),
    ] {
        let records = evaluate(&input(text).plan, &settings(20_000))
            .expect("evaluates")
            .records();
        let chain: Vec<_> = records
            .iter()
            .filter(|r| r.label.starts_with("odometry_chain@") && r.method == Method::FirstOrder)
            .collect();
        assert!(chain.len() >= 3, "{name}");
        let last = chain.last().expect("steps");
        let error = last.relative_error_vs_monte_carlo.expect("compared");
        println!(
            "{name}: last step {} first order vs Monte Carlo {:.2} %",
            last.label,
            100.0 * error
        );
        assert!(range.contains(&error), "{name}: {error}");
        // The covariance grows along the chain from the (certain) first vertex.
        let trace = |r: &posecov::propagate::ResultRecord| -> f64 {
            (0..r.covariance.len()).map(|k| r.covariance[k][k]).sum()
        };
        assert_eq!(trace(chain[0]), 0.0);
        assert!(trace(last) > trace(chain[1]), "{name}");
    }
}

#[test]
fn small_noise_chain_first_order_is_monte_carlo() {
    // 8 steps of 1 m and 0.2 rad, σ = 1 cm, 0.01 rad: first order is exact to sampling error.
    let mut text = String::new();
    let step = Se2::from_xy_theta(1.0, 0.0, 0.2);
    let mut x = Se2::identity();
    for k in 0..=8 {
        text += &format!("VERTEX_SE2 {k} {} {} {}\n", x.x(), x.y(), x.theta());
        x = x.compose(&step);
    }
    for k in 0..8 {
        text += &format!("EDGE_SE2 {k} {} 1 0 0.2 10000 0 0 10000 0 10000\n", k + 1);
    }
    let records = evaluate(&input(&text).plan, &settings(40_000))
        .expect("evaluates")
        .records();
    let last = records
        .iter()
        .find(|r| r.label == "odometry_chain@8" && r.method == Method::FirstOrder)
        .expect("last step");
    let error = last.relative_error_vs_monte_carlo.expect("compared");
    assert!(error < 0.03, "{error}");
    let mc = records
        .iter()
        .find(|r| r.label == "odometry_chain@8" && r.method == Method::MonteCarlo)
        .expect("Monte Carlo");
    let flat = |r: &posecov::propagate::ResultRecord| r.covariance.concat();
    assert!(relative(&flat(last), &flat(mc)) < 0.03);
}

/// (text, the error's expected start) for every kind of bad graph.
#[rustfmt::skip]
const BAD: &[(&str, &str)] = &[
    ("VERTEX_SE2 0 0 nan 0\n", "g.g2o:1:16: VERTEX_SE2 0: y = nan is not a finite number"),
    ("VERTEX_SE2 0 0 inf 0\n", "g.g2o:1:16: VERTEX_SE2 0: y = inf is not a finite number"),
    ("VERTEX_SE2 0 abc 0 0\n", "g.g2o:1:14: VERTEX_SE2 0: x = `abc` is not a number"),
    ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 -400\n",
     "g.g2o:3:20: EDGE_SE2 0 1 information: the information matrix over (x, y, θ) is not positive definite (smallest eigenvalue -4.0"),
    ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 0\n",
     "g.g2o:3:20: EDGE_SE2 0 1 information: the information matrix over (x, y, θ) is not positive definite (smallest eigenvalue 0"),
    ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1e-30\n",
     "g.g2o:3:20: EDGE_SE2 0 1 information: the information matrix is so small that a variance reaches 1.000e30"),
    ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 x\n",
     "g.g2o:3:30: EDGE_SE2 0 1: I(θ,θ) = `x` is not a number"),
    ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n", "g.g2o:2:12: VERTEX_SE2 0: vertex 0 is defined twice (first on line 1)"),
    ("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 7 1 0 0 1 0 0 1 0 1\n", "g.g2o:2:12: EDGE_SE2 0 7: vertex 7 is not defined"),
    ("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 0 1 0 0 1 0 0 1 0 1\n", "g.g2o:2:12: EDGE_SE2 0 0: an edge from vertex 0 to itself says nothing"),
    ("VERTEX_SE2 0 0 0 0\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n",
     "g.g2o:2:1: VERTEX_SE3:QUAT: a 3D (SE(3)) record in a planar (SE(2)) graph (line 1 is planar (SE(2)))"),
    ("", "g.g2o:1:1: file: no vertices or edges: a pose graph needs"),
    ("# only a comment\n\n", "g.g2o:1:1: file: no vertices or edges"),
    ("FIX 0\n", "g.g2o:1:1: FIX: the file has no vertices and no edges"),
    ("VERTEX_SE2 0 0 0 0\nFIX\n", "g.g2o:2:1: FIX: expected the ids of the vertices to hold fixed"),
    ("VERTEX_SE2 0 0 0 0\nFIX 0 x\n", "g.g2o:2:7: FIX: id = `x` is not a vertex id"),
    ("VERTEX_SE2 0 0 0 0\nFIX 3\n", "g.g2o:2:5: FIX: vertex 3 is not defined"),
    ("VERTEX_SE2 0 0 0 0\nEDGE_PRIOR_SE2 2 0 0 0 1 0 0 1 0 1\n", "g.g2o:2:16: EDGE_PRIOR_SE2: vertex 2 is not defined"),
    ("VERTEX_SE2 0 0 0 0\nEDGE_PRIOR_SE2 0 0 0 0 1 0 0 1 0 0\n",
     "g.g2o:2:24: EDGE_PRIOR_SE2 0 information: the information matrix over (x, y, θ) is not positive definite"),
    ("VERTEX_SE2 0 0 0 0\nFOO 1 2\n", "g.g2o:2:1: record: `FOO` is not a g2o record posecov reads"),
    ("VERTEX_SE2 0 0 0\n", "g.g2o:1:1: VERTEX_SE2: expected 4 values after the tag (id x y θ), found 3"),
    ("VERTEX_SE2 0 0 0 0 5\n", "g.g2o:1:20: VERTEX_SE2: expected 4 values after the tag (id x y θ), found 5"),
    ("VERTEX_SE2 -1 0 0 0\n", "g.g2o:1:12: VERTEX_SE2: id = `-1` is not a vertex id"),
    ("VERTEX_SE2 0 1e13 0 0\n", "g.g2o:1:14: VERTEX_SE2 0: coordinate 10000000000000 is beyond ±1e12 m"),
    ("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 2\n", "g.g2o:1:19: VERTEX_SE3:QUAT 0: quaternion (x, y, z, w) = [0.0, 0.0, 0.0, 2.0] has norm 2"),
    ("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 0\n", "g.g2o:1:19: VERTEX_SE3:QUAT 0: quaternion (x, y, z, w) = [0.0, 0.0, 0.0, 0.0] has norm 0"),
    ("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nVERTEX_SE2 0 0 0 0\n", "g.g2o:1:12: EDGE_SE2 0 1: vertex 1 is not defined"),
];

#[test]
fn every_bad_graph_is_refused_at_its_place() {
    for (text, expected) in BAD {
        let e = read_text(text, "g.g2o").expect_err(text).to_string();
        assert!(
            e.starts_with(expected),
            "{text:?}\n got: {e}\nwant: {expected}"
        );
    }
}

#[test]
fn bad_graphs_never_panic_when_cut_anywhere() {
    // Every prefix of a valid file is refused with a message or read: never a panic.
    for text in [POSE2, OFFDIAGONAL] {
        for cut in (0..text.len()).step_by(7) {
            let _ = read_text(&text[..cut], "g.g2o");
        }
    }
}

fn scratch(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-graphs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write");
    path
}

#[test]
fn huge_files_are_refused_before_reading() {
    let path = scratch("huge.g2o", b"VERTEX_SE2 0 0 0 0\n");
    std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .and_then(|f| f.set_len(MAX_FILE_BYTES + 1))
        .expect("sparse file");
    let e = read_file(&path).expect_err("too large").to_string();
    assert!(e.contains("larger than the 256 MiB"), "{e}");
    std::fs::remove_file(&path).ok();
}

#[test]
fn formats_are_decided_by_content_and_extension() {
    let graph = scratch("g.g2o", POSE2.as_bytes());
    let (source, _) = open(graph.to_str().expect("utf-8")).expect("a graph");
    assert_eq!(source.format(), Format::Graph);
    let toro = scratch(
        "w.graph",
        b"VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0 20 0 20 100 0 0\n",
    );
    let (source, _) = open(toro.to_str().expect("utf-8")).expect("a TORO graph");
    assert_eq!(source.format(), Format::Graph);
    let no_extension = scratch("pose2", POSE2.as_bytes());
    assert_eq!(
        open(no_extension.to_str().expect("utf-8"))
            .expect("by content")
            .0
            .format(),
        Format::Graph
    );
    for (name, bytes, expected) in [
        (
            "g.toml",
            POSE2.as_bytes(),
            "the extension .toml says TOML scenario, but its content is a g2o / GTSAM pose graph",
        ),
        (
            "s.txt",
            b"[scenario]\ntitle = 'x'\n".as_slice(),
            "the extension .txt says g2o / GTSAM pose graph, but its content is a TOML scenario",
        ),
        (
            "b.bag",
            b"\x89MCAP0\r\nrest".as_slice(),
            "the extension .bag says ROS 1 bag, but its content is a MCAP file (ROS 2 bag)",
        ),
        (
            "m.mcap",
            b"#ROSBAG V2.0\nrest".as_slice(),
            "the extension .mcap says MCAP file (ROS 2 bag), but its content is a ROS 1 bag",
        ),
        (
            "e.bag",
            b"".as_slice(),
            "the extension .bag says ROS 1 bag, but it is empty",
        ),
        (
            "x.g2o",
            b"\xff\xfe\x00binary".as_slice(),
            // A byte that is not text is located (the file name, then `:line:column`).
            ":1:1: file: byte 0xFF is not UTF-8 text; a g2o / GTSAM pose graph is text",
        ),
        (
            "notes.csv",
            b"1,2,3\n".as_slice(),
            "not a file posecov reads: its content is none of these (it starts with \"1,2,3·\"); expected a TOML scenario (.toml)",
        ),
    ] {
        let path = scratch(name, bytes);
        let e = open(path.to_str().expect("utf-8"))
            .expect_err(name)
            .to_string();
        let want = match expected.strip_prefix(':') {
            Some(place) => format!("{}:{place}", path.display()),
            None => format!("{}: {expected}", path.display()),
        };
        assert!(e.starts_with(&want), "{name}\n got: {e}\nwant: {want}");
    }
    // A bundled graph by name, and its text through the same reader.
    let (source, input) = open("gtsam_pose3example").expect("bundled");
    assert_eq!(source.format(), Format::Graph);
    assert_eq!(
        open_text(POSE3, "p.txt", Format::Graph)
            .expect("same text")
            .1
            .plan,
        input.plan
    );
}

#[test]
fn large_graphs_are_drawn_bounded_and_said_so() {
    let mut text = String::new();
    for k in 0..1000 {
        text += &format!("VERTEX_SE2 {k} {} 0 0\n", k as f64 * 0.5);
    }
    for k in 0..999 {
        text += &format!("EDGE_SE2 {k} {} 0.5 0 0 400 0 0 400 0 2500\n", k + 1);
    }
    for k in 0..50 {
        text += &format!(
            "EDGE_SE2 {} {} 5 0 0 100 0 0 100 0 100\n",
            10 * k,
            10 * k + 10
        );
    }
    let (graph, input) = read_text(&text, "big.g2o").expect("valid");
    let s = graph.summary();
    assert_eq!((s.chain_edges, s.loop_closures), (999, 50));
    assert_eq!(
        s.loop_closures_drawn,
        posecov::input::graph::MAX_LOOP_CLOSURES
    );
    assert!(
        s.vertices_drawn <= 300 + 2 * s.loop_closures_drawn,
        "{}",
        s.vertices_drawn
    );
    assert!(!input.draw.labels);
    assert_eq!(input.draw.links.len(), s.loop_closures_drawn);
    let d = &posecov::draw::input_description(&input.about, &input.draw);
    assert!(d.contains("12 of the 50 loop closures are drawn"), "{d}");
    assert!(
        d.contains(&format!(
            "{} of the 1000 vertex estimates are drawn",
            s.vertices_drawn
        )),
        "{d}"
    );

    // Without consecutive edges there is no chain, and the text says so.
    let (_, input) = read_text(
        "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 5 1 0 0\nEDGE_SE2 0 5 1 0 0 100 0 0 100 0 100\n",
        "l.g2o",
    )
    .expect("valid");
    let d = posecov::draw::input_description(&input.about, &input.draw);
    assert!(d.contains("No odometry chain"), "{d}");
}

#[test]
fn crlf_tabs_and_a_byte_order_mark_read_like_plain_text() {
    let plain = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\n";
    let windows = format!("\u{feff}{}", plain.replace('\n', "\r\n").replace(' ', "\t"));
    assert_eq!(input(&windows).plan, input(plain).plan);
    let path = scratch("windows.g2o", windows.as_bytes());
    assert_eq!(
        open(path.to_str().expect("utf-8"))
            .expect("by content")
            .0
            .format(),
        Format::Graph
    );
    // Errors still point at the right line and column.
    let e = read_text(&windows.replace("\t400", "\tnan"), "w.g2o")
        .expect_err("nan")
        .to_string();
    assert!(
        e.starts_with("w.g2o:3:34: EDGE_SE2 0 1: I(θ,θ) = nan"),
        "{e}"
    );
}
