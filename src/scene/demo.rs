//! A self-contained demo scene that exercises every kind of item (until scenarios land).
//!
//! Model: a robot starts at the origin heading ψ₀ = 30° and drives a distance `d_k` along its
//! heading; at step k its pose error, in the subspace τ = (ρx, ρz, θ) (along-track, vertical,
//! heading), is τ ~ N(0, diag(σ²)) with σ growing like √(k+1). The position is
//!
//! p(τ) = Rz(ψ₀) · ( (d + ρx) cos θ, (d + ρx) sin θ, ρz ),
//!
//! so the Monte-Carlo cloud bends into a banana. Drawn per step: the cloud and a subsample of
//! its triads (Monte Carlo), the first-order ellipsoid (J Σ J^T with J = ∂p/∂τ at τ = 0, i.e.
//! half sizes k·(σx, d·σθ, σz)), the exact image p({τ : ‖τ/σ‖ = k}) of the confidence sphere
//! as a surface, and the position-covariance trace of both in a plot.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use super::{
    Arrows, Ellipsoid, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, Method, PointCloud,
    QUAT_IDENTITY, QuatXyzw, ScalarSeries, Scene, SceneError, SceneItem, Surface, Timing, Triads,
    Vec3, unit_sphere_mesh,
};

/// Default number of Monte-Carlo samples per step in the demo.
pub const DEMO_SAMPLES: usize = 500;

const STEPS: i64 = 10;
const HEADING0: f64 = std::f64::consts::PI / 6.0;
const STEP_LENGTH: f64 = 0.3;
/// Standard deviations (ρx, ρz, θ) at the last step; earlier steps scale with √((k+1)/STEPS).
const SIGMA_LAST: Vec3 = [0.08, 0.04, 0.2];
const TRIADS_PER_STEP: usize = 40;

/// The demo at 95 % confidence with [`DEMO_SAMPLES`] samples per step.
///
/// ```
/// let scene = posecov::scene::demo_scene(1);
/// assert_eq!(scene.steps(), (0..10).collect::<Vec<i64>>());
/// assert_eq!(scene, posecov::scene::demo_scene(1)); // seeded: reproducible
/// ```
pub fn demo_scene(seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    build(&mut rng, DEMO_SAMPLES, 0.95, chi2_3_quantile(0.95).sqrt())
}

/// The demo with `samples` Monte-Carlo samples per step and region probability `confidence`.
///
/// # Errors
/// [`SceneError::OutOfRange`] when `confidence` is not strictly between 0 and 1.
///
/// ```
/// let scene = posecov::scene::demo_scene_with(3, 50, 0.99)?;
/// assert!(scene.validate().is_ok());
/// assert!(posecov::scene::demo_scene_with(3, 50, 1.0).is_err());
/// # Ok::<(), posecov::scene::SceneError>(())
/// ```
pub fn demo_scene_with(seed: u64, samples: usize, confidence: f64) -> Result<Scene, SceneError> {
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(SceneError::OutOfRange {
            path: "demo".into(),
            field: "confidence",
            index: 0,
            value: confidence,
            requirement: "strictly between 0 and 1",
        });
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let k = chi2_3_quantile(confidence).sqrt();
    Ok(build(&mut rng, samples, confidence, k))
}

fn build(rng: &mut ChaCha8Rng, samples: usize, confidence: f64, k: f64) -> Scene {
    let mut scene = Scene::new("demo", description(samples, confidence, k));
    add_static(&mut scene);
    let mut trace_fo = Vec::new();
    let mut trace_mc = Vec::new();
    for step in 0..STEPS {
        let scale = ((step + 1) as f64 / STEPS as f64).sqrt();
        let sigma = SIGMA_LAST.map(|s| s * scale);
        let d = STEP_LENGTH * (step + 1) as f64;
        let taus: Vec<Vec3> = (0..samples)
            .map(|_| sigma.map(|s| s * rng.sample::<f64, _>(StandardNormal)))
            .collect();
        add_step(&mut scene, step, d, sigma, k, &taus);
        trace_fo.push((
            step,
            sigma[0].powi(2) + (d * sigma[2]).powi(2) + sigma[1].powi(2),
        ));
        let positions: Vec<Vec3> = taus.iter().map(|t| position(d, t)).collect();
        if let Some(trace) = sample_trace(&positions) {
            trace_mc.push((step, trace));
        }
    }
    for (method, points) in [
        (Method::FirstOrder, trace_fo),
        (Method::MonteCarlo, trace_mc),
    ] {
        scene.series.push(ScalarSeries {
            path: format!("plots/position_trace/{}", method.slug()),
            name: method.label().into(),
            color: method.color(),
            width: 2.0,
            points,
        });
    }
    scene
}

fn description(samples: usize, confidence: f64, k: f64) -> String {
    format!(
        "# posecov demo\n\n\
         A robot drives straight from the origin while its heading uncertainty grows; \
         scrub the `step` timeline to watch the position distribution bend.\n\n\
         - **Monte Carlo** ({samples} samples per step; triads show 40 of them)\n\
         - **first order**: ellipsoid J Σ J^T at {pct:.2} % (k = {k:.3}, χ²₃)\n\
         - translucent surface: the exact image of the same {pct:.2} % tangent-space sphere\n\n\
         Colours:\n{legend}\n\
         The plot compares the trace of the position covariance (m²) of both methods.\n\n\
         *Synthetic data — scenarios replace this demo.*\n",
        pct = 100.0 * confidence,
        legend =
            Method::legend_markdown(&[Method::MonteCarlo, Method::FirstOrder, Method::Nominal]),
    )
}

fn add_static(scene: &mut Scene) {
    scene.push(SceneItem::new(
        "world/origin",
        Timing::Static,
        ItemKind::Frame(Frame {
            translation: [0.0; 3],
            rotation: QUAT_IDENTITY,
            axis_length: 0.5,
            label: Some("world".into()),
        }),
    ));
    let end = STEP_LENGTH * STEPS as f64;
    scene.push(SceneItem::new(
        "world/demo/nominal/path",
        Timing::Static,
        ItemKind::LineStrips(LineStrips {
            strips: vec![vec![[0.0; 3], rotate_z(HEADING0, [end, 0.0, 0.0])]],
            color: Method::Nominal.color(),
            radius: 0.005,
        }),
    ));
}

fn add_step(scene: &mut Scene, step: i64, d: f64, sigma: Vec3, k: f64, taus: &[Vec3]) {
    let at = Timing::Step(step);
    let mean = rotate_z(HEADING0, [d, 0.0, 0.0]);
    let path = |what: &str| format!("world/demo/{what}");
    scene.push(SceneItem::new(
        path("nominal/frame"),
        at,
        ItemKind::Frame(Frame {
            translation: mean,
            rotation: quat_z(HEADING0),
            axis_length: 0.25,
            label: Some("mean".into()),
        }),
    ));
    scene.push(SceneItem::new(
        path("nominal/heading"),
        at,
        ItemKind::Arrows(Arrows {
            origins: vec![[0.0; 3]],
            vectors: vec![mean],
            color: Method::Nominal.color(),
            radius: 0.004,
        }),
    ));
    scene.push(SceneItem::new(
        path("monte_carlo/cloud"),
        at,
        ItemKind::Points(PointCloud {
            positions: taus.iter().map(|t| position(d, t)).collect(),
            color: Method::MonteCarlo.color(),
            radius: 0.008,
        }),
    ));
    let few = &taus[..taus.len().min(TRIADS_PER_STEP)];
    scene.push(SceneItem::new(
        path("monte_carlo/triads"),
        at,
        ItemKind::Triads(Triads {
            translations: few.iter().map(|t| position(d, t)).collect(),
            rotations: few.iter().map(|t| quat_z(HEADING0 + t[2])).collect(),
            axis_length: 0.08,
            line_radius: 0.003,
        }),
    ));
    scene.push(SceneItem::new(
        path("first_order/ellipsoid"),
        at,
        ItemKind::Ellipsoids(Ellipsoids {
            shapes: vec![Ellipsoid {
                center: mean,
                half_sizes: [k * sigma[0], k * d * sigma[2], k * sigma[1]],
                rotation: quat_z(HEADING0),
            }],
            color: Method::FirstOrder.color(),
            fill: FillMode::MajorWireframe,
            line_radius: 0.006,
            label: None,
        }),
    ));
    let (unit, triangles) = unit_sphere_mesh(16, 32);
    let vertices = unit
        .iter()
        .map(|u| {
            position(
                d,
                &[
                    k * sigma[0] * u[0],
                    k * sigma[1] * u[1],
                    k * sigma[2] * u[2],
                ],
            )
        })
        .collect();
    scene.push(SceneItem::new(
        path("first_order/banana"),
        at,
        ItemKind::Surface(
            Surface {
                vertices,
                triangles,
                normals: Vec::new(),
                color: Method::FirstOrder.color().with_alpha(60),
            }
            .with_computed_normals(),
        ),
    ));
}

/// World position for tangent error τ = (ρx, ρz, θ) after driving `d`.
fn position(d: f64, tau: &Vec3) -> Vec3 {
    let [rho_x, rho_z, theta] = *tau;
    let r = d + rho_x;
    rotate_z(HEADING0, [r * theta.cos(), r * theta.sin(), rho_z])
}

fn rotate_z(angle: f64, v: Vec3) -> Vec3 {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

fn quat_z(angle: f64) -> QuatXyzw {
    let (s, c) = (0.5 * angle).sin_cos();
    [0.0, 0.0, s, c]
}

/// Trace of the sample covariance (1/(N−1)) of `points`; `None` below two points.
fn sample_trace(points: &[Vec3]) -> Option<f64> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let mut mean = [0.0; 3];
    for p in points {
        (0..3).for_each(|i| mean[i] += p[i] / n as f64);
    }
    let sum: f64 = points
        .iter()
        .map(|p| (0..3).map(|i| (p[i] - mean[i]).powi(2)).sum::<f64>())
        .sum();
    Some(sum / (n - 1) as f64)
}

/// χ²₃ quantile by bisection of the closed-form CDF erf(√(x/2)) − √(2x/π)·e^(−x/2).
/// Demo-only helper (accuracy ~1e-6 from the erf approximation); the math core owns the
/// real one.
fn chi2_3_quantile(p: f64) -> f64 {
    let cdf =
        |x: f64| erf((x / 2.0).sqrt()) - (2.0 * x / std::f64::consts::PI).sqrt() * (-x / 2.0).exp();
    let (mut lo, mut hi) = (0.0, 200.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// erf(x) for x ≥ 0, Abramowitz & Stegun 7.1.26 (|error| ≤ 1.5e-7).
fn erf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    1.0 - poly * (-x * x).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_quantiles_match_the_table() {
        // RERUN_NOTES / CONVENTIONS §7: k = √χ²₃(p).
        for (p, k) in [(0.6827, 1.878), (0.90, 2.500), (0.95, 2.795), (0.99, 3.368)] {
            assert!((chi2_3_quantile(p).sqrt() - k).abs() < 2e-3, "{p}");
        }
    }

    #[test]
    fn seeds_change_the_cloud_only() {
        let (a, b) = (demo_scene(1), demo_scene(2));
        assert_ne!(a, b);
        assert_eq!(a.items.len(), b.items.len());
    }

    #[test]
    fn zero_samples_still_draws() {
        let scene = demo_scene_with(0, 0, 0.9).expect("valid confidence");
        assert_eq!(scene.validate(), Ok(()));
        assert!(scene.series[1].points.is_empty());
    }
}
