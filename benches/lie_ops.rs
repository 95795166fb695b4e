//! Lie-group operations of posecov beside their peers, in the same criterion group so that
//! each ratio comes from one run on this (shared, noisy) machine. See BENCHMARKS.md.
//!
//! Run: `cargo bench --no-default-features --bench lie_ops -- --warm-up-time 1 --measurement-time 3`
//!
//! Peers:
//! - `sophus_lie` 0.15 (`Rotation2F64`, `Rotation3F64`, `Isometry2F64`, `Isometry3F64`). Its
//!   tangents are rotation first ([θ; ρ]); posecov's are translation first ([ρ; θ]). Inputs
//!   are permuted once, outside the timed loop, and the setup checks that both libraries
//!   compute the same numbers (up to that permutation) before anything is timed.
//!   sophus has no right Jacobian: its peer of Jr(τ) is Jl(−τ) = Jr(τ) (same matrix), with
//!   −τ formed outside the timed loop; likewise Jr⁻¹(τ) = Jl⁻¹(−τ).
//! - nalgebra where it has the same math: `UnitComplex` / `Rotation2` (SO(2)),
//!   `UnitQuaternion::from_scaled_axis` / `scaled_axis` / `ln` (SO(3)), `Isometry2` /
//!   `Isometry3` multiply, inverse, transform_point (SE(2), SE(3)).
//!
//! Each benchmark times one batch of [`BATCH`] operations on pre-generated random inputs
//! (seeded ChaCha8); criterion's time per iteration / [`BATCH`] is the time per operation.

use std::hint::black_box;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{
    Isometry2, Isometry3, Point2, Point3, Rotation2, Translation2, Translation3, UnitComplex,
    UnitQuaternion, Vector1, Vector2, Vector3, Vector6,
};
use posecov::lie::{LieGroup, Se2, Se3, So2, So3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sophus_autodiff::nalgebra as na33;
use sophus_lie::{Isometry2F64, Isometry3F64, Rotation2F64, Rotation3F64};

/// Operations per timed iteration.
const BATCH: usize = 1024;

/// Seed of the input generator.
const SEED: u64 = 0x5EED_2026;

/// Tolerance of the setup's cross-checks between posecov and sophus.
const AGREE: f64 = 1e-9;

// ---------------------------------------------------------------------------------------------
// Inputs.

/// A rotation vector with a uniformly random axis and angle in [0, 3] rad (below π, so Log is
/// unambiguous and every library takes its generic branch).
fn random_rotation_vector(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n * rng.random_range(0.0..3.0);
        }
    }
}

fn random_translation3(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    Vector3::new(
        rng.random_range(-2.0..2.0),
        rng.random_range(-2.0..2.0),
        rng.random_range(-2.0..2.0),
    )
}

fn random_translation2(rng: &mut ChaCha8Rng) -> Vector2<f64> {
    Vector2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0))
}

fn random_angle(rng: &mut ChaCha8Rng) -> f64 {
    rng.random_range(-3.0..3.0)
}

// ---------------------------------------------------------------------------------------------
// Conversions between the two nalgebra versions and the two tangent orders.

fn v1_33(v: &Vector1<f64>) -> na33::Vector1<f64> {
    na33::Vector1::new(v.x)
}

fn v2_33(v: &Vector2<f64>) -> na33::Vector2<f64> {
    na33::Vector2::new(v.x, v.y)
}

fn v3_33(v: &Vector3<f64>) -> na33::Vector3<f64> {
    na33::Vector3::new(v.x, v.y, v.z)
}

/// posecov SE(2) [ρx, ρy, θ] → sophus [θ, ρx, ρy].
fn se2_tangent_33(t: &Vector3<f64>) -> na33::Vector3<f64> {
    na33::Vector3::new(t.z, t.x, t.y)
}

/// posecov SE(3) [ρ; θ] → sophus [θ; ρ].
fn se3_tangent_33(t: &Vector6<f64>) -> na33::Vector6<f64> {
    na33::Vector6::new(t[3], t[4], t[5], t[0], t[1], t[2])
}

/// Asserts that `ours(i, j)` ≈ `theirs(perm(i), perm(j))` for an n×m block, where `perm`
/// maps a posecov tangent index to sophus' (identity for matrices of points).
fn assert_agree(
    what: &str,
    n: usize,
    m: usize,
    ours: impl Fn(usize, usize) -> f64,
    theirs: impl Fn(usize, usize) -> f64,
    perm_row: impl Fn(usize) -> usize,
    perm_col: impl Fn(usize) -> usize,
) {
    for i in 0..n {
        for j in 0..m {
            let (a, b) = (ours(i, j), theirs(perm_row(i), perm_col(j)));
            assert!(
                (a - b).abs() <= AGREE * (1.0 + a.abs()),
                "{what}: posecov ({i}, {j}) = {a} but peer = {b}"
            );
        }
    }
}

fn same(i: usize) -> usize {
    i
}

// ---------------------------------------------------------------------------------------------
// Timing helpers.

fn group<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(BATCH as u64));
    g
}

/// Times `f` over every input of the batch.
fn unary<I, O>(g: &mut BenchmarkGroup<'_, WallTime>, id: &str, inputs: &[I], f: impl Fn(&I) -> O) {
    assert_eq!(inputs.len(), BATCH);
    g.bench_function(id, |b| {
        b.iter(|| {
            for x in inputs {
                black_box(f(black_box(x)));
            }
        })
    });
}

// ---------------------------------------------------------------------------------------------
// SO(2).

fn so2(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let tau: Vec<Vector1<f64>> = (0..BATCH)
        .map(|_| Vector1::new(random_angle(&mut rng)))
        .collect();
    let tau_b: Vec<Vector1<f64>> = (0..BATCH)
        .map(|_| Vector1::new(random_angle(&mut rng)))
        .collect();
    let pts: Vec<Vector2<f64>> = (0..BATCH).map(|_| random_translation2(&mut rng)).collect();

    let ours: Vec<(So2, So2)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (So2::exp(a), So2::exp(b)))
        .collect();
    let s_tau: Vec<na33::Vector1<f64>> = tau.iter().map(v1_33).collect();
    let s_neg: Vec<na33::Vector1<f64>> = tau.iter().map(|t| v1_33(&-t)).collect();
    let s_pts: Vec<na33::Vector2<f64>> = pts.iter().map(v2_33).collect();
    let theirs: Vec<(Rotation2F64, Rotation2F64)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (Rotation2F64::exp(v1_33(a)), Rotation2F64::exp(v1_33(b))))
        .collect();
    let uc: Vec<(UnitComplex<f64>, UnitComplex<f64>)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (UnitComplex::new(a.x), UnitComplex::new(b.x)))
        .collect();
    let rot: Vec<(Rotation2<f64>, Rotation2<f64>)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (Rotation2::new(a.x), Rotation2::new(b.x)))
        .collect();
    let angles: Vec<f64> = tau.iter().map(|t| t.x).collect();

    for k in 0..16 {
        let (x, y) = (&ours[k].0, &ours[k].1);
        let (sx, sy) = (&theirs[k].0, &theirs[k].1);
        let m = x.to_matrix();
        assert_agree(
            "SO(2) exp",
            2,
            2,
            |i, j| m[(i, j)],
            |i, j| sx.matrix()[(i, j)],
            same,
            same,
        );
        assert_agree(
            "SO(2) log",
            1,
            1,
            |_, _| x.log().x,
            |_, _| sx.log().x,
            same,
            same,
        );
        let c = x.compose(y).to_matrix();
        let sc = sx.group_mul(*sy).matrix();
        assert_agree(
            "SO(2) compose",
            2,
            2,
            |i, j| c[(i, j)],
            |i, j| sc[(i, j)],
            same,
            same,
        );
        let a = x.act(&pts[k]);
        let sa = sx.transform(s_pts[k]);
        assert_agree("SO(2) act", 2, 1, |i, _| a[i], |i, _| sa[i], same, same);
        assert!((uc[k].0 * pts[k] - a).norm() < AGREE);
    }

    let mut g = group(c, "so2.exp");
    unary(&mut g, "posecov", &tau, So2::exp);
    unary(&mut g, "sophus_lie", &s_tau, |t| Rotation2F64::exp(*t));
    unary(&mut g, "nalgebra_UnitComplex", &angles, |a| {
        UnitComplex::new(*a)
    });
    unary(&mut g, "nalgebra_Rotation2", &angles, |a| {
        Rotation2::new(*a)
    });
    g.finish();

    let mut g = group(c, "so2.log");
    unary(&mut g, "posecov", &ours, |(x, _)| x.log());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.log());
    unary(&mut g, "nalgebra_UnitComplex", &uc, |(x, _)| x.angle());
    unary(&mut g, "nalgebra_Rotation2", &rot, |(x, _)| x.angle());
    g.finish();

    let mut g = group(c, "so2.compose");
    unary(&mut g, "posecov", &ours, |(x, y)| x.compose(y));
    unary(&mut g, "sophus_lie", &theirs, |(x, y)| x.group_mul(*y));
    unary(&mut g, "nalgebra_UnitComplex", &uc, |(x, y)| x * y);
    unary(&mut g, "nalgebra_Rotation2", &rot, |(x, y)| x * y);
    g.finish();

    let mut g = group(c, "so2.inverse");
    unary(&mut g, "posecov", &ours, |(x, _)| x.inverse());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.inverse());
    unary(&mut g, "nalgebra_UnitComplex", &uc, |(x, _)| x.inverse());
    unary(&mut g, "nalgebra_Rotation2", &rot, |(x, _)| x.inverse());
    g.finish();

    let act_ours: Vec<(So2, Vector2<f64>)> =
        ours.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let act_theirs: Vec<(Rotation2F64, na33::Vector2<f64>)> = theirs
        .iter()
        .zip(&s_pts)
        .map(|((x, _), p)| (*x, *p))
        .collect();
    let act_uc: Vec<(UnitComplex<f64>, Vector2<f64>)> =
        uc.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let act_rot: Vec<(Rotation2<f64>, Vector2<f64>)> =
        rot.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let mut g = group(c, "so2.act");
    unary(&mut g, "posecov", &act_ours, |(x, p)| x.act(p));
    unary(&mut g, "sophus_lie", &act_theirs, |(x, p)| x.transform(*p));
    unary(&mut g, "nalgebra_UnitComplex", &act_uc, |(x, p)| x * p);
    unary(&mut g, "nalgebra_Rotation2", &act_rot, |(x, p)| x * p);
    g.finish();

    let mut g = group(c, "so2.adj");
    unary(&mut g, "posecov", &ours, |(x, _)| x.adj());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.adj());
    g.finish();

    let mut g = group(c, "so2.jr");
    unary(&mut g, "posecov", &tau, So2::jr);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Rotation2F64::left_jacobian(*t)
    });
    g.finish();

    let mut g = group(c, "so2.jr_inv");
    unary(&mut g, "posecov", &tau, So2::jr_inv);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Rotation2F64::inv_left_jacobian(*t)
    });
    g.finish();
}

// ---------------------------------------------------------------------------------------------
// SO(3).

fn so3(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED + 1);
    let tau: Vec<Vector3<f64>> = (0..BATCH)
        .map(|_| random_rotation_vector(&mut rng))
        .collect();
    let tau_b: Vec<Vector3<f64>> = (0..BATCH)
        .map(|_| random_rotation_vector(&mut rng))
        .collect();
    let pts: Vec<Vector3<f64>> = (0..BATCH).map(|_| random_translation3(&mut rng)).collect();

    let ours: Vec<(So3, So3)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (So3::exp(a), So3::exp(b)))
        .collect();
    let s_tau: Vec<na33::Vector3<f64>> = tau.iter().map(v3_33).collect();
    let s_neg: Vec<na33::Vector3<f64>> = tau.iter().map(|t| v3_33(&-t)).collect();
    let s_pts: Vec<na33::Vector3<f64>> = pts.iter().map(v3_33).collect();
    let theirs: Vec<(Rotation3F64, Rotation3F64)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (Rotation3F64::exp(v3_33(a)), Rotation3F64::exp(v3_33(b))))
        .collect();
    let uq: Vec<(UnitQuaternion<f64>, UnitQuaternion<f64>)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| {
            (
                UnitQuaternion::from_scaled_axis(*a),
                UnitQuaternion::from_scaled_axis(*b),
            )
        })
        .collect();

    for k in 0..16 {
        let (x, y) = (&ours[k].0, &ours[k].1);
        let (sx, sy) = (&theirs[k].0, &theirs[k].1);
        let m = x.to_matrix();
        assert_agree(
            "SO(3) exp",
            3,
            3,
            |i, j| m[(i, j)],
            |i, j| sx.matrix()[(i, j)],
            same,
            same,
        );
        let (l, sl) = (x.log(), sx.log());
        assert_agree("SO(3) log", 3, 1, |i, _| l[i], |i, _| sl[i], same, same);
        assert!((uq[k].0.scaled_axis() - l).norm() < AGREE);
        let cm = x.compose(y).to_matrix();
        let sc = sx.group_mul(*sy).matrix();
        assert_agree(
            "SO(3) compose",
            3,
            3,
            |i, j| cm[(i, j)],
            |i, j| sc[(i, j)],
            same,
            same,
        );
        let inv = x.inverse().to_matrix();
        let sinv = sx.inverse().matrix();
        assert_agree(
            "SO(3) inverse",
            3,
            3,
            |i, j| inv[(i, j)],
            |i, j| sinv[(i, j)],
            same,
            same,
        );
        let a = x.act(&pts[k]);
        let sa = sx.transform(s_pts[k]);
        assert_agree("SO(3) act", 3, 1, |i, _| a[i], |i, _| sa[i], same, same);
        let ad = x.adj();
        let sad = sx.adj();
        assert_agree(
            "SO(3) adj",
            3,
            3,
            |i, j| ad[(i, j)],
            |i, j| sad[(i, j)],
            same,
            same,
        );
        let jr = So3::jr(&tau[k]);
        let sjr = Rotation3F64::left_jacobian(s_neg[k]);
        assert_agree(
            "SO(3) jr",
            3,
            3,
            |i, j| jr[(i, j)],
            |i, j| sjr[(i, j)],
            same,
            same,
        );
        let ji = So3::jr_inv(&tau[k]);
        let sji = Rotation3F64::inv_left_jacobian(s_neg[k]);
        assert_agree(
            "SO(3) jr_inv",
            3,
            3,
            |i, j| ji[(i, j)],
            |i, j| sji[(i, j)],
            same,
            same,
        );
    }

    let mut g = group(c, "so3.exp");
    unary(&mut g, "posecov", &tau, So3::exp);
    unary(&mut g, "sophus_lie", &s_tau, |t| Rotation3F64::exp(*t));
    unary(&mut g, "nalgebra_from_scaled_axis", &tau, |t| {
        UnitQuaternion::from_scaled_axis(*t)
    });
    g.finish();

    let mut g = group(c, "so3.log");
    unary(&mut g, "posecov", &ours, |(x, _)| x.log());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.log());
    unary(&mut g, "nalgebra_scaled_axis", &uq, |(x, _)| {
        x.scaled_axis()
    });
    unary(&mut g, "nalgebra_ln", &uq, |(x, _)| x.ln());
    g.finish();

    let mut g = group(c, "so3.compose");
    unary(&mut g, "posecov", &ours, |(x, y)| x.compose(y));
    unary(&mut g, "sophus_lie", &theirs, |(x, y)| x.group_mul(*y));
    unary(&mut g, "nalgebra_UnitQuaternion", &uq, |(x, y)| x * y);
    g.finish();

    let mut g = group(c, "so3.inverse");
    unary(&mut g, "posecov", &ours, |(x, _)| x.inverse());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.inverse());
    unary(&mut g, "nalgebra_UnitQuaternion", &uq, |(x, _)| x.inverse());
    g.finish();

    let act_ours: Vec<(So3, Vector3<f64>)> =
        ours.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let act_theirs: Vec<(Rotation3F64, na33::Vector3<f64>)> = theirs
        .iter()
        .zip(&s_pts)
        .map(|((x, _), p)| (*x, *p))
        .collect();
    let act_uq: Vec<(UnitQuaternion<f64>, Vector3<f64>)> =
        uq.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let mut g = group(c, "so3.act");
    unary(&mut g, "posecov", &act_ours, |(x, p)| x.act(p));
    unary(&mut g, "sophus_lie", &act_theirs, |(x, p)| x.transform(*p));
    unary(&mut g, "nalgebra_UnitQuaternion", &act_uq, |(x, p)| x * p);
    g.finish();

    let mut g = group(c, "so3.adj");
    unary(&mut g, "posecov", &ours, |(x, _)| x.adj());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.adj());
    unary(&mut g, "nalgebra_to_rotation_matrix", &uq, |(x, _)| {
        x.to_rotation_matrix()
    });
    g.finish();

    let mut g = group(c, "so3.jr");
    unary(&mut g, "posecov", &tau, So3::jr);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Rotation3F64::left_jacobian(*t)
    });
    g.finish();

    let mut g = group(c, "so3.jr_inv");
    unary(&mut g, "posecov", &tau, So3::jr_inv);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Rotation3F64::inv_left_jacobian(*t)
    });
    g.finish();
}

// ---------------------------------------------------------------------------------------------
// SE(2).

fn se2_perm(i: usize) -> usize {
    // posecov [ρx, ρy, θ] index → sophus [θ, ρx, ρy] index.
    (i + 1) % 3
}

fn se2(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED + 2);
    let tangent = |rng: &mut ChaCha8Rng| {
        let t = random_translation2(rng);
        Vector3::new(t.x, t.y, random_angle(rng))
    };
    let tau: Vec<Vector3<f64>> = (0..BATCH).map(|_| tangent(&mut rng)).collect();
    let tau_b: Vec<Vector3<f64>> = (0..BATCH).map(|_| tangent(&mut rng)).collect();
    let pts: Vec<Vector2<f64>> = (0..BATCH).map(|_| random_translation2(&mut rng)).collect();

    let ours: Vec<(Se2, Se2)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (Se2::exp(a), Se2::exp(b)))
        .collect();
    let s_tau: Vec<na33::Vector3<f64>> = tau.iter().map(se2_tangent_33).collect();
    let s_neg: Vec<na33::Vector3<f64>> = tau.iter().map(|t| se2_tangent_33(&-t)).collect();
    let s_pts: Vec<na33::Vector2<f64>> = pts.iter().map(v2_33).collect();
    let theirs: Vec<(Isometry2F64, Isometry2F64)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| {
            (
                Isometry2F64::exp(se2_tangent_33(a)),
                Isometry2F64::exp(se2_tangent_33(b)),
            )
        })
        .collect();
    let iso = |x: &Se2| {
        Isometry2::from_parts(
            Translation2::from(*x.translation()),
            *x.rotation().complex(),
        )
    };
    let na: Vec<(Isometry2<f64>, Isometry2<f64>)> =
        ours.iter().map(|(x, y)| (iso(x), iso(y))).collect();

    for k in 0..16 {
        let (x, y) = (&ours[k].0, &ours[k].1);
        let (sx, sy) = (&theirs[k].0, &theirs[k].1);
        let m = x.to_matrix();
        assert_agree(
            "SE(2) exp",
            3,
            3,
            |i, j| m[(i, j)],
            |i, j| sx.matrix()[(i, j)],
            same,
            same,
        );
        let (l, sl) = (x.log(), sx.log());
        assert_agree("SE(2) log", 3, 1, |i, _| l[i], |i, _| sl[i], se2_perm, same);
        let cm = x.compose(y).to_matrix();
        let sc = sx.group_mul(*sy).matrix();
        assert_agree(
            "SE(2) compose",
            3,
            3,
            |i, j| cm[(i, j)],
            |i, j| sc[(i, j)],
            same,
            same,
        );
        let inv = x.inverse().to_matrix();
        let sinv = sx.inverse().matrix();
        assert_agree(
            "SE(2) inverse",
            3,
            3,
            |i, j| inv[(i, j)],
            |i, j| sinv[(i, j)],
            same,
            same,
        );
        let a = x.act(&pts[k]);
        let sa = sx.transform(s_pts[k]);
        assert_agree("SE(2) act", 2, 1, |i, _| a[i], |i, _| sa[i], same, same);
        assert!((na[k].0.transform_point(&Point2::from(pts[k])).coords - a).norm() < AGREE);
        let ad = x.adj();
        let sad = sx.adj();
        assert_agree(
            "SE(2) adj",
            3,
            3,
            |i, j| ad[(i, j)],
            |i, j| sad[(i, j)],
            se2_perm,
            se2_perm,
        );
        let jr = Se2::jr(&tau[k]);
        let sjr = Isometry2F64::left_jacobian(s_neg[k]);
        assert_agree(
            "SE(2) jr",
            3,
            3,
            |i, j| jr[(i, j)],
            |i, j| sjr[(i, j)],
            se2_perm,
            se2_perm,
        );
        let ji = Se2::jr_inv(&tau[k]);
        let sji = Isometry2F64::inv_left_jacobian(s_neg[k]);
        assert_agree(
            "SE(2) jr_inv",
            3,
            3,
            |i, j| ji[(i, j)],
            |i, j| sji[(i, j)],
            se2_perm,
            se2_perm,
        );
    }

    let mut g = group(c, "se2.exp");
    unary(&mut g, "posecov", &tau, Se2::exp);
    unary(&mut g, "sophus_lie", &s_tau, |t| Isometry2F64::exp(*t));
    g.finish();

    let mut g = group(c, "se2.log");
    unary(&mut g, "posecov", &ours, |(x, _)| x.log());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.log());
    g.finish();

    let mut g = group(c, "se2.compose");
    unary(&mut g, "posecov", &ours, |(x, y)| x.compose(y));
    unary(&mut g, "sophus_lie", &theirs, |(x, y)| x.group_mul(*y));
    unary(&mut g, "nalgebra_Isometry2", &na, |(x, y)| x * y);
    g.finish();

    let mut g = group(c, "se2.inverse");
    unary(&mut g, "posecov", &ours, |(x, _)| x.inverse());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.inverse());
    unary(&mut g, "nalgebra_Isometry2", &na, |(x, _)| x.inverse());
    g.finish();

    let act_ours: Vec<(Se2, Vector2<f64>)> =
        ours.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let act_theirs: Vec<(Isometry2F64, na33::Vector2<f64>)> = theirs
        .iter()
        .zip(&s_pts)
        .map(|((x, _), p)| (*x, *p))
        .collect();
    let act_na: Vec<(Isometry2<f64>, Point2<f64>)> = na
        .iter()
        .zip(&pts)
        .map(|((x, _), p)| (*x, Point2::from(*p)))
        .collect();
    let mut g = group(c, "se2.act");
    unary(&mut g, "posecov", &act_ours, |(x, p)| x.act(p));
    unary(&mut g, "sophus_lie", &act_theirs, |(x, p)| x.transform(*p));
    unary(&mut g, "nalgebra_Isometry2", &act_na, |(x, p)| {
        x.transform_point(p)
    });
    g.finish();

    let mut g = group(c, "se2.adj");
    unary(&mut g, "posecov", &ours, |(x, _)| x.adj());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.adj());
    g.finish();

    let mut g = group(c, "se2.jr");
    unary(&mut g, "posecov", &tau, Se2::jr);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Isometry2F64::left_jacobian(*t)
    });
    g.finish();

    let mut g = group(c, "se2.jr_inv");
    unary(&mut g, "posecov", &tau, Se2::jr_inv);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Isometry2F64::inv_left_jacobian(*t)
    });
    g.finish();
}

// ---------------------------------------------------------------------------------------------
// SE(3).

fn se3_perm(i: usize) -> usize {
    // posecov [ρ; θ] index → sophus [θ; ρ] index.
    (i + 3) % 6
}

fn se3(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED + 3);
    let tangent = |rng: &mut ChaCha8Rng| {
        let (rho, theta) = (random_translation3(rng), random_rotation_vector(rng));
        Vector6::new(rho.x, rho.y, rho.z, theta.x, theta.y, theta.z)
    };
    let tau: Vec<Vector6<f64>> = (0..BATCH).map(|_| tangent(&mut rng)).collect();
    let tau_b: Vec<Vector6<f64>> = (0..BATCH).map(|_| tangent(&mut rng)).collect();
    let pts: Vec<Vector3<f64>> = (0..BATCH).map(|_| random_translation3(&mut rng)).collect();

    let ours: Vec<(Se3, Se3)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| (Se3::exp(a), Se3::exp(b)))
        .collect();
    let s_tau: Vec<na33::Vector6<f64>> = tau.iter().map(se3_tangent_33).collect();
    let s_neg: Vec<na33::Vector6<f64>> = tau.iter().map(|t| se3_tangent_33(&-t)).collect();
    let s_pts: Vec<na33::Vector3<f64>> = pts.iter().map(v3_33).collect();
    let theirs: Vec<(Isometry3F64, Isometry3F64)> = tau
        .iter()
        .zip(&tau_b)
        .map(|(a, b)| {
            (
                Isometry3F64::exp(se3_tangent_33(a)),
                Isometry3F64::exp(se3_tangent_33(b)),
            )
        })
        .collect();
    let iso = |x: &Se3| {
        Isometry3::from_parts(
            Translation3::from(*x.translation()),
            *x.rotation().quaternion(),
        )
    };
    let na: Vec<(Isometry3<f64>, Isometry3<f64>)> =
        ours.iter().map(|(x, y)| (iso(x), iso(y))).collect();

    for k in 0..16 {
        let (x, y) = (&ours[k].0, &ours[k].1);
        let (sx, sy) = (&theirs[k].0, &theirs[k].1);
        let m = x.to_matrix();
        assert_agree(
            "SE(3) exp",
            4,
            4,
            |i, j| m[(i, j)],
            |i, j| sx.matrix()[(i, j)],
            same,
            same,
        );
        let (l, sl) = (x.log(), sx.log());
        assert_agree("SE(3) log", 6, 1, |i, _| l[i], |i, _| sl[i], se3_perm, same);
        let cm = x.compose(y).to_matrix();
        let sc = sx.group_mul(*sy).matrix();
        assert_agree(
            "SE(3) compose",
            4,
            4,
            |i, j| cm[(i, j)],
            |i, j| sc[(i, j)],
            same,
            same,
        );
        let inv = x.inverse().to_matrix();
        let sinv = sx.inverse().matrix();
        assert_agree(
            "SE(3) inverse",
            4,
            4,
            |i, j| inv[(i, j)],
            |i, j| sinv[(i, j)],
            same,
            same,
        );
        let a = x.act(&pts[k]);
        let sa = sx.transform(s_pts[k]);
        assert_agree("SE(3) act", 3, 1, |i, _| a[i], |i, _| sa[i], same, same);
        assert!((na[k].0.transform_point(&Point3::from(pts[k])).coords - a).norm() < AGREE);
        let ad = x.adj();
        let sad = sx.adj();
        assert_agree(
            "SE(3) adj",
            6,
            6,
            |i, j| ad[(i, j)],
            |i, j| sad[(i, j)],
            se3_perm,
            se3_perm,
        );
        let jr = Se3::jr(&tau[k]);
        let sjr = Isometry3F64::left_jacobian(s_neg[k]);
        assert_agree(
            "SE(3) jr",
            6,
            6,
            |i, j| jr[(i, j)],
            |i, j| sjr[(i, j)],
            se3_perm,
            se3_perm,
        );
        let ji = Se3::jr_inv(&tau[k]);
        let sji = Isometry3F64::inv_left_jacobian(s_neg[k]);
        assert_agree(
            "SE(3) jr_inv",
            6,
            6,
            |i, j| ji[(i, j)],
            |i, j| sji[(i, j)],
            se3_perm,
            se3_perm,
        );
    }

    let mut g = group(c, "se3.exp");
    unary(&mut g, "posecov", &tau, Se3::exp);
    unary(&mut g, "sophus_lie", &s_tau, |t| Isometry3F64::exp(*t));
    g.finish();

    let mut g = group(c, "se3.log");
    unary(&mut g, "posecov", &ours, |(x, _)| x.log());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.log());
    g.finish();

    let mut g = group(c, "se3.compose");
    unary(&mut g, "posecov", &ours, |(x, y)| x.compose(y));
    unary(&mut g, "sophus_lie", &theirs, |(x, y)| x.group_mul(*y));
    unary(&mut g, "nalgebra_Isometry3", &na, |(x, y)| x * y);
    g.finish();

    let mut g = group(c, "se3.inverse");
    unary(&mut g, "posecov", &ours, |(x, _)| x.inverse());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.inverse());
    unary(&mut g, "nalgebra_Isometry3", &na, |(x, _)| x.inverse());
    g.finish();

    let act_ours: Vec<(Se3, Vector3<f64>)> =
        ours.iter().zip(&pts).map(|((x, _), p)| (*x, *p)).collect();
    let act_theirs: Vec<(Isometry3F64, na33::Vector3<f64>)> = theirs
        .iter()
        .zip(&s_pts)
        .map(|((x, _), p)| (*x, *p))
        .collect();
    let act_na: Vec<(Isometry3<f64>, Point3<f64>)> = na
        .iter()
        .zip(&pts)
        .map(|((x, _), p)| (*x, Point3::from(*p)))
        .collect();
    let mut g = group(c, "se3.act");
    unary(&mut g, "posecov", &act_ours, |(x, p)| x.act(p));
    unary(&mut g, "sophus_lie", &act_theirs, |(x, p)| x.transform(*p));
    unary(&mut g, "nalgebra_Isometry3", &act_na, |(x, p)| {
        x.transform_point(p)
    });
    g.finish();

    let mut g = group(c, "se3.adj");
    unary(&mut g, "posecov", &ours, |(x, _)| x.adj());
    unary(&mut g, "sophus_lie", &theirs, |(x, _)| x.adj());
    g.finish();

    let mut g = group(c, "se3.jr");
    unary(&mut g, "posecov", &tau, Se3::jr);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Isometry3F64::left_jacobian(*t)
    });
    g.finish();

    let mut g = group(c, "se3.jr_inv");
    unary(&mut g, "posecov", &tau, Se3::jr_inv);
    unary(&mut g, "sophus_lie", &s_neg, |t| {
        Isometry3F64::inv_left_jacobian(*t)
    });
    g.finish();
}

criterion_group!(benches, so2, so3, se2, se3);
criterion_main!(benches);
