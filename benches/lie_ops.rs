//! Lie-group operations of posecov beside their peers, in the same criterion group so that
//! each ratio comes from one run on this (shared, noisy) machine. See BENCHMARKS.md.
//!
//! Run: `cargo bench --no-default-features --bench lie_ops -- --warm-up-time 1 --measurement-time 3`
//! (append a filter such as `so3` or `'se2\.(exp|log)'` to run part of it; `-- --list` lists
//! the ids).
//!
//! One benchmark body, [`lie_group_bench!`], is instantiated once per group (SO(2), SO(3),
//! SE(2), SE(3)), the way manif's `benchmark/common_benchmark.h` instantiates one templated
//! body per group. For every group it times, in this order, the criterion groups
//! `<group>.exp`, `.log`, `.compose`, `.inverse`, `.act`, `.adj`, `.jr` and `.jr_inv`, each
//! with `posecov` and `sophus_lie` first and then the group's nalgebra peers, which are the
//! only per-group part of the body beyond the types, the input generators and the tangent
//! permutation.
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
use std::ops::Index;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{
    Dim, Isometry2, Isometry3, Matrix, Point2, Point3, RawStorage, Rotation2, Translation2,
    Translation3, UnitComplex, UnitQuaternion, Vector1, Vector2, Vector3, Vector6,
};
use posecov::lie::{LieGroup, Se2, Se3, So2, So3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sophus_autodiff::nalgebra as na33;
use sophus_lie::{Isometry2F64, Isometry3F64, Rotation2F64, Rotation3F64};

/// Operations per timed iteration.
const BATCH: usize = 1024;

/// Seed of the input generator (group i of so2, so3, se2, se3 uses `SEED + i`).
const SEED: u64 = 0x5EED_2026;

/// Tolerance of the setup's cross-checks between posecov and its peers.
const AGREE: f64 = 1e-9;

/// Inputs cross-checked between posecov and its peers before timing.
const CHECKED: usize = 16;

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

/// SO(2) tangent θ.
fn so2_tangent(rng: &mut ChaCha8Rng) -> Vector1<f64> {
    Vector1::new(random_angle(rng))
}

/// SE(2) tangent [ρx, ρy, θ].
fn se2_tangent(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    let t = random_translation2(rng);
    Vector3::new(t.x, t.y, random_angle(rng))
}

/// SE(3) tangent [ρ; θ].
fn se3_tangent(rng: &mut ChaCha8Rng) -> Vector6<f64> {
    let (rho, theta) = (random_translation3(rng), random_rotation_vector(rng));
    Vector6::new(rho.x, rho.y, rho.z, theta.x, theta.y, theta.z)
}

/// `(f(a), f(b))` for each pair of tangents: the two operands of a binary operation.
fn pairs<T, X>(tau: &[T], tau_b: &[T], f: impl Fn(&T) -> X) -> Vec<(X, X)> {
    tau.iter().zip(tau_b).map(|(a, b)| (f(a), f(b))).collect()
}

/// `(x, p)`: the first element of each pair, with the point it acts on.
fn with_points<X: Copy, P>(pairs: &[(X, X)], points: impl IntoIterator<Item = P>) -> Vec<(X, P)> {
    pairs
        .iter()
        .zip(points)
        .map(|((x, _), p)| (*x, p))
        .collect()
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

/// A posecov tangent index → sophus' (the identity for rotations, matrices and points).
fn same(i: usize) -> usize {
    i
}

/// posecov SE(2) [ρx, ρy, θ] index → sophus [θ, ρx, ρy] index.
fn se2_perm(i: usize) -> usize {
    (i + 1) % 3
}

/// posecov SE(3) [ρ; θ] index → sophus [θ; ρ] index.
fn se3_perm(i: usize) -> usize {
    (i + 3) % 6
}

/// Asserts that `ours[(i, j)]` ≈ `theirs[(perm_row(i), perm_col(j))]` for every entry of `ours`.
fn assert_agree<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(
    what: &str,
    ours: &Matrix<f64, R, C, S>,
    theirs: &impl Index<(usize, usize), Output = f64>,
    perm_row: fn(usize) -> usize,
    perm_col: fn(usize) -> usize,
) {
    let (n, m) = ours.shape();
    for i in 0..n {
        for j in 0..m {
            let (a, b) = (ours[(i, j)], theirs[(perm_row(i), perm_col(j))]);
            assert!(
                (a - b).abs() <= AGREE * (1.0 + a.abs()),
                "{what}: posecov ({i}, {j}) = {a} but peer = {b}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Timing.

/// The operations timed for every group, in order; criterion group `<group>.<Op::id>`.
#[derive(Clone, Copy, PartialEq)]
enum Op {
    Exp,
    Log,
    Compose,
    Inverse,
    Act,
    Adj,
    Jr,
    JrInv,
}

impl Op {
    const ALL: [Op; 8] = [
        Op::Exp,
        Op::Log,
        Op::Compose,
        Op::Inverse,
        Op::Act,
        Op::Adj,
        Op::Jr,
        Op::JrInv,
    ];

    fn id(self) -> &'static str {
        match self {
            Op::Exp => "exp",
            Op::Log => "log",
            Op::Compose => "compose",
            Op::Inverse => "inverse",
            Op::Act => "act",
            Op::Adj => "adj",
            Op::Jr => "jr",
            Op::JrInv => "jr_inv",
        }
    }
}

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

/// Times posecov's `f` and then sophus_lie's `h`, the same operation on the same inputs.
fn side_by_side<I, O, J, P>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    ours: &[I],
    f: impl Fn(&I) -> O,
    theirs: &[J],
    h: impl Fn(&J) -> P,
) {
    unary(g, "posecov", ours, f);
    unary(g, "sophus_lie", theirs, h);
}

/// The benchmark body, instantiated once per group as `fn $name(c: &mut Criterion)`.
///
/// - `$name: $Ours vs $Theirs, seed $seed, perm $perm`: criterion group prefix and function
///   name, the posecov and sophus_lie types, the input seed, and posecov tangent index →
///   sophus tangent index.
/// - `tangent gen => to_sophus, point gen => to_sophus`: generators of posecov tangents and
///   points, and their conversions to sophus inputs (tangent permuted).
/// - `nalgebra |tau, tau_b, ours, pts| { … }`: builds the nalgebra inputs from the two tangent
///   operands, the posecov operand pairs and the points (slices, under the names given).
/// - `check |k| …`: input `k` agrees with nalgebra (the sophus checks are common to all).
/// - `Op { "id" on inputs, … => f; … }`: the nalgebra benchmarks of that operation, timed
///   after `posecov` and `sophus_lie`, in the order listed (`f` applied to each input set).
///
/// The second form, `nalgebra isometry "id" Isometry2(Translation2, complex), Point2;`, is
/// shorthand for the SE(n) peers: `IsometryN` compose, inverse and `transform_point`.
macro_rules! lie_group_bench {
    (
        $name:ident: $Ours:ident vs $Theirs:ident, seed $seed:expr, perm $perm:expr;
        tangent $tangent:expr => $s_tangent:expr, point $point:expr => $s_point:expr;
        nalgebra |$tau:ident, $tau_b:ident, $ours:ident, $pts:ident| { $($setup:tt)* }
        check |$k:ident| $check:expr;
        $( $op:ident { $( $( $id:literal on $inputs:expr ),+ => $f:expr );+ $(;)? } )*
    ) => {
        fn $name(c: &mut Criterion) {
            let mut rng = ChaCha8Rng::seed_from_u64($seed);
            let tau: Vec<_> = (0..BATCH).map(|_| $tangent(&mut rng)).collect();
            let tau_b: Vec<_> = (0..BATCH).map(|_| $tangent(&mut rng)).collect();
            let pts: Vec<_> = (0..BATCH).map(|_| $point(&mut rng)).collect();

            let ours: Vec<($Ours, $Ours)> = pairs(&tau, &tau_b, $Ours::exp);
            let theirs: Vec<($Theirs, $Theirs)> =
                pairs(&tau, &tau_b, |t| $Theirs::exp($s_tangent(t)));
            let s_tau: Vec<_> = tau.iter().map($s_tangent).collect();
            let s_neg: Vec<_> = tau.iter().map(|t| $s_tangent(&-t)).collect();
            let s_pts: Vec<_> = pts.iter().map($s_point).collect();
            let act_ours = with_points(&ours, pts.iter().copied());
            let act_theirs = with_points(&theirs, s_pts.iter().copied());

            let ($tau, $tau_b, $ours, $pts) = (&tau[..], &tau_b[..], &ours[..], &pts[..]);
            $($setup)*

            for $k in 0..CHECKED {
                let ((x, y), (sx, sy)) = (&ours[$k], &theirs[$k]);
                let what = |op: &str| format!("{} {op}", stringify!($name));
                assert_agree(&what("exp"), &x.to_matrix(), &sx.matrix(), same, same);
                assert_agree(&what("log"), &x.log(), &sx.log(), $perm, same);
                let (xy, sxy) = (x.compose(y), sx.group_mul(*sy));
                assert_agree(&what("compose"), &xy.to_matrix(), &sxy.matrix(), same, same);
                let (xi, sxi) = (x.inverse(), sx.inverse());
                assert_agree(&what("inverse"), &xi.to_matrix(), &sxi.matrix(), same, same);
                let (a, sa) = (x.act(&pts[$k]), sx.transform(s_pts[$k]));
                assert_agree(&what("act"), &a, &sa, same, same);
                assert_agree(&what("adj"), &x.adj(), &sx.adj(), $perm, $perm);
                let (jr, sjr) = ($Ours::jr(&tau[$k]), $Theirs::left_jacobian(s_neg[$k]));
                assert_agree(&what("jr"), &jr, &sjr, $perm, $perm);
                let (ji, sji) = ($Ours::jr_inv(&tau[$k]), $Theirs::inv_left_jacobian(s_neg[$k]));
                assert_agree(&what("jr_inv"), &ji, &sji, $perm, $perm);
                assert!($check, "{}: nalgebra disagrees", what("check"));
            }

            for op in Op::ALL {
                let mut bench = group(c, &format!("{}.{}", stringify!($name), op.id()));
                let g = &mut bench;
                match op {
                    Op::Exp => side_by_side(g, &tau, $Ours::exp, &s_tau, |t| $Theirs::exp(*t)),
                    Op::Log => side_by_side(g, &ours, |(x, _)| x.log(), &theirs, |(x, _)| x.log()),
                    Op::Compose => side_by_side(
                        g, &ours, |(x, y)| x.compose(y), &theirs, |(x, y)| x.group_mul(*y),
                    ),
                    Op::Inverse => side_by_side(
                        g, &ours, |(x, _)| x.inverse(), &theirs, |(x, _)| x.inverse(),
                    ),
                    Op::Act => side_by_side(
                        g, &act_ours, |(x, p)| x.act(p), &act_theirs, |(x, p)| x.transform(*p),
                    ),
                    Op::Adj => side_by_side(g, &ours, |(x, _)| x.adj(), &theirs, |(x, _)| x.adj()),
                    Op::Jr => side_by_side(
                        g, &tau, $Ours::jr, &s_neg, |t| $Theirs::left_jacobian(*t),
                    ),
                    Op::JrInv => side_by_side(
                        g, &tau, $Ours::jr_inv, &s_neg, |t| $Theirs::inv_left_jacobian(*t),
                    ),
                }
                $( if op == Op::$op { $( $( unary(g, $id, $inputs, $f); )+ )+ } )*
                bench.finish();
            }
        }
    };
    (
        $name:ident: $Ours:ident vs $Theirs:ident, seed $seed:expr, perm $perm:expr;
        tangent $tangent:expr => $s_tangent:expr, point $point:expr => $s_point:expr;
        nalgebra isometry $id:literal $Iso:ident($Translation:ident, $rotation:ident), $Point:ident;
    ) => {
        lie_group_bench! {
            $name: $Ours vs $Theirs, seed $seed, perm $perm;
            tangent $tangent => $s_tangent, point $point => $s_point;
            nalgebra |_tau, _tau_b, ours, pts| {
                let iso = |x: &$Ours| {
                    let rotation = *x.rotation().$rotation();
                    $Iso::from_parts($Translation::from(*x.translation()), rotation)
                };
                let na: Vec<($Iso<f64>, $Iso<f64>)> =
                    ours.iter().map(|(x, y)| (iso(x), iso(y))).collect();
                let act_na = with_points(&na, pts.iter().map(|p| $Point::from(*p)));
            }
            check |k| {
                let p = na[k].0.transform_point(&$Point::from(pts[k])).coords;
                (p - ours[k].0.act(&pts[k])).norm() < AGREE
            };
            Compose { $id on &na => |(x, y)| x * y }
            Inverse { $id on &na => |(x, _)| x.inverse() }
            Act { $id on &act_na => |(x, p)| x.transform_point(p) }
        }
    };
}

// ---------------------------------------------------------------------------------------------
// The groups: types, inputs and nalgebra peers.

lie_group_bench! {
    so2: So2 vs Rotation2F64, seed SEED, perm same;
    tangent so2_tangent => v1_33, point random_translation2 => v2_33;
    nalgebra |tau, tau_b, ours, pts| {
        let angles: Vec<f64> = tau.iter().map(|t| t.x).collect();
        let uc = pairs(tau, tau_b, |t| UnitComplex::new(t.x));
        let rot = pairs(tau, tau_b, |t| Rotation2::new(t.x));
        let act_uc = with_points(&uc, pts.iter().copied());
        let act_rot = with_points(&rot, pts.iter().copied());
    }
    check |k| (uc[k].0 * pts[k] - ours[k].0.act(&pts[k])).norm() < AGREE;
    Exp {
        "nalgebra_UnitComplex" on &angles => |a| UnitComplex::new(*a);
        "nalgebra_Rotation2" on &angles => |a| Rotation2::new(*a);
    }
    Log { "nalgebra_UnitComplex" on &uc, "nalgebra_Rotation2" on &rot => |(x, _)| x.angle() }
    Compose { "nalgebra_UnitComplex" on &uc, "nalgebra_Rotation2" on &rot => |(x, y)| x * y }
    Inverse { "nalgebra_UnitComplex" on &uc, "nalgebra_Rotation2" on &rot => |(x, _)| x.inverse() }
    Act { "nalgebra_UnitComplex" on &act_uc, "nalgebra_Rotation2" on &act_rot => |(x, p)| x * p }
}

lie_group_bench! {
    so3: So3 vs Rotation3F64, seed SEED + 1, perm same;
    tangent random_rotation_vector => v3_33, point random_translation3 => v3_33;
    nalgebra |tau, tau_b, ours, pts| {
        let uq = pairs(tau, tau_b, |t| UnitQuaternion::from_scaled_axis(*t));
        let act_uq = with_points(&uq, pts.iter().copied());
    }
    check |k| (uq[k].0.scaled_axis() - ours[k].0.log()).norm() < AGREE;
    Exp { "nalgebra_from_scaled_axis" on tau => |t| UnitQuaternion::from_scaled_axis(*t) }
    Log {
        "nalgebra_scaled_axis" on &uq => |(x, _)| x.scaled_axis();
        "nalgebra_ln" on &uq => |(x, _)| x.ln();
    }
    Compose { "nalgebra_UnitQuaternion" on &uq => |(x, y)| x * y }
    Inverse { "nalgebra_UnitQuaternion" on &uq => |(x, _)| x.inverse() }
    Act { "nalgebra_UnitQuaternion" on &act_uq => |(x, p)| x * p }
    Adj { "nalgebra_to_rotation_matrix" on &uq => |(x, _)| x.to_rotation_matrix() }
}

lie_group_bench! {
    se2: Se2 vs Isometry2F64, seed SEED + 2, perm se2_perm;
    tangent se2_tangent => se2_tangent_33, point random_translation2 => v2_33;
    nalgebra isometry "nalgebra_Isometry2" Isometry2(Translation2, complex), Point2;
}

lie_group_bench! {
    se3: Se3 vs Isometry3F64, seed SEED + 3, perm se3_perm;
    tangent se3_tangent => se3_tangent_33, point random_translation3 => v3_33;
    nalgebra isometry "nalgebra_Isometry3" Isometry3(Translation3, quaternion), Point3;
}

criterion_group!(benches, so2, so3, se2, se3);
criterion_main!(benches);
