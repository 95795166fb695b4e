//! From an evaluated scenario to a plain-data [`Scene`]: what each method's uncertainty looks
//! like, drawn the same way in every scenario.
//!
//! Per pose and method (entity `world/<pose>/<method>/…`, so each can be toggled):
//! - `ellipsoid`: the first-order **Cartesian** position region, world frame, at the chosen
//!   confidence with d = 3 (SE(3)) or d = 2 (SE(2)) degrees of freedom (CONVENTIONS §7);
//! - `banana`: the **Exp-image** { μ · Exp(L u) : ‖u‖ = r } of the method's tangent-space
//!   ellipsoid (L Lᵀ = Σ, r² = χ²_k(p) with k the rank of Σ, at most the group's DOF), swept
//!   over the sphere of the three largest principal directions of Σ and drawn through each
//!   point's translation — a mesh for the main method, the images of its three principal
//!   ellipses for every method;
//! - `axis_x|y|z` (rotation groups): the Exp-image of the same ellipsoid seen through each
//!   body axis tip, R̄ Exp(L u) e_k, around each mean axis;
//! - `monte_carlo/cloud`, `monte_carlo/triads`, `monte_carlo/spray`: particle positions, a
//!   subsample of small axis triads, and axis-tip sprays. A sample simulated in blocks
//!   ([blocked Monte Carlo](crate::scenario::eval#blocked-monte-carlo-bounded-memory)) draws
//!   its first block here and each later block `k` as a child `…/cloud/block_k` (and
//!   `spray_x/block_k`, …) from [`particle_parts`].

use std::collections::BTreeMap;
use std::fmt::Write as _;

use nalgebra::{DMatrix, Matrix3, SymmetricEigen, Vector3};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::lie::{LieGroup, Se3, Tangent, TangentMatrix};
use crate::scenario::model::{AnyEvaluation, Evaluation, Node, Role};
use crate::scenario::schema::View;
use crate::scenario::{GroupName, SpecGroup};
use crate::scene::{
    self, Arrows, Color, Ellipsoid, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, PointCloud,
    ScalarSeries, Scene, SceneItem, Surface, Timing, Triads, Vec3,
};
use crate::uncertain::{Method, Side, UncertainPose};

/// Sphere-mesh resolution of banana surfaces (latitude bands, meridians).
const BANANA_MESH: (u32, u32) = (16, 32);
/// Points per principal-ellipse outline.
const OUTLINE_POINTS: usize = 96;
/// Eigenvalues below this fraction of the largest count as zero when choosing the χ² degrees
/// of freedom of a drawn region.
const RANK_TOLERANCE: f64 = 1e-9;
/// At most this many steps of a propagation show their particle clouds.
const MAX_PARTICLE_STEPS: u64 = 20;
/// How many Monte Carlo particles get a small axis triad.
const TRIAD_SUBSAMPLE: usize = 60;

/// Evaluates a scenario and builds its scene: the whole pure data path in one call.
///
/// ```
/// use posecov::scenario::{Scenario, eval::EvalOptions};
/// let s = Scenario::load_any("camera_on_robot").unwrap();
/// let options = EvalOptions { samples: Some(50), ..Default::default() };
/// assert!(posecov::draw::scene_of(&s, &options).unwrap().validate().is_ok());
/// ```
pub fn scene_of(
    scenario: &crate::scenario::Scenario,
    options: &crate::scenario::eval::EvalOptions,
) -> Result<Scene, crate::scenario::ScenarioError> {
    Ok(build_scene(&crate::scenario::eval::evaluate(
        scenario, options,
    )?))
}

/// Builds the scene of an evaluated scenario.
///
/// ```
/// use posecov::scenario::{Scenario, eval::{evaluate, EvalOptions}};
/// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='se2'\nmethods=['first_order']\n[[pose]]\nname='a'\nmean={xy_theta=[1,2,0]}\ncov={std=[0.1,0.1,0.3]}\n", "t.toml").unwrap();
/// let scene = posecov::draw::build_scene(&evaluate(&s, &EvalOptions::default()).unwrap());
/// assert!(scene.items.iter().any(|i| i.path == "world/a/given/banana"));
/// assert!(scene.validate().is_ok());
/// ```
pub fn build_scene(evaluation: &AnyEvaluation) -> Scene {
    match evaluation {
        AnyEvaluation::So2(e) => build(e),
        AnyEvaluation::Se2(e) => build(e),
        AnyEvaluation::So3(e) => build(e),
        AnyEvaluation::Se3(e) => build(e),
    }
}

/// The clouds of a blocked Monte Carlo sample beyond its first block
/// ([blocked Monte Carlo](crate::scenario::eval#blocked-monte-carlo-bounded-memory)): one
/// scene per block `k ≥ 1`, evaluated when the iterator reaches it and holding only that
/// block's particle clouds and axis-tip sprays, at `…/monte_carlo/cloud/block_k` (and
/// `spray_x/block_k`, …), drawn with `main`'s sizes. Log each with
/// `sink::log_part_cancellable` after the main scene and drop it: memory stays bounded.
/// Empty when the whole sample fit in one block.
///
/// ```
/// use posecov::scenario::{Scenario, eval::{EvalOptions, evaluate}};
/// let s = Scenario::load_any("camera_on_robot").unwrap();
/// let options = EvalOptions { samples: Some(3000), block_samples: Some(1024), ..Default::default() };
/// let main = evaluate(&s, &options).unwrap();
/// let parts: Vec<_> = posecov::draw::particle_parts(&s, &options, &main).collect::<Result<_, _>>().unwrap();
/// assert_eq!(parts.len(), 2); // samples 1024..2048 and 2048..3000
/// assert!(parts[1].items.iter().any(|i| i.path.ends_with("/cloud/block_2")));
/// ```
pub fn particle_parts<'a>(
    scenario: &'a crate::scenario::Scenario,
    options: &'a crate::scenario::eval::EvalOptions,
    main: &'a AnyEvaluation,
) -> impl Iterator<Item = Result<Scene, crate::scenario::ScenarioError>> + 'a {
    (1..).map_while(move |k| {
        match crate::scenario::eval::evaluate_block(scenario, options, main, k) {
            Ok(Some(block)) => Some(Ok(particle_part(main, &block, k))),
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    })
}

/// The particle items of `block` (block `part` of `main`'s sample), sized as in `main`'s scene.
fn particle_part(main: &AnyEvaluation, block: &AnyEvaluation, part: usize) -> Scene {
    match (main, block) {
        (AnyEvaluation::So2(m), AnyEvaluation::So2(b)) => part_of(m, b, part),
        (AnyEvaluation::Se2(m), AnyEvaluation::Se2(b)) => part_of(m, b, part),
        (AnyEvaluation::So3(m), AnyEvaluation::So3(b)) => part_of(m, b, part),
        (AnyEvaluation::Se3(m), AnyEvaluation::Se3(b)) => part_of(m, b, part),
        _ => Scene::new(main.meta().title.clone(), String::new()),
    }
}

fn part_of<G: SpecGroup<N>, const N: usize>(
    main: &Evaluation<G, N>,
    block: &Evaluation<G, N>,
    part: usize,
) -> Scene {
    let rotation_group = G::rotation_range().start == 0;
    // A part is logged after the main scene: its items only, no description.
    let mut p = painter(main, String::new());
    for node in block
        .nodes
        .iter()
        .filter(|n| n.draw && n.role != Role::Fixed)
    {
        if let Some(particles) = node
            .particles
            .as_ref()
            .filter(|_| p.particles_at(node.step))
        {
            draw_particles(
                &mut p,
                node,
                particles,
                rotation_group,
                &main.meta.draw,
                Some(part),
            );
        }
    }
    if main.meta.draw.clouds {
        for point in &block.points {
            if let Some(particles) = &point.particles {
                p.push(
                    format!("world/{}/monte_carlo/cloud/block_{part}", point.name),
                    None,
                    point_cloud_item(particles.clone()),
                );
            }
        }
    }
    p.scene
}

/// The Monte Carlo points of a `point_through_pose` output.
fn point_cloud_item(positions: Vec<Vec3>) -> ItemKind {
    ItemKind::Points(PointCloud {
        positions,
        color: cloud_color(),
        radius: 0.01,
    })
}

/// χ²_d quantile radius r = √χ²_d(p): the Mahalanobis radius of a p-confidence region.
fn chi2_radius(p: f64, d: usize) -> f64 {
    ChiSquared::new(d as f64).map_or(f64::NAN, |c| c.inverse_cdf(p).sqrt())
}

fn timing(step: Option<u64>) -> Timing {
    step.map_or(Timing::Static, |k| Timing::Step(k as i64))
}

fn v3(v: &Vector3<f64>) -> Vec3 {
    [v.x, v.y, v.z]
}

/// Principal axes of a symmetric matrix: (eigenvalues ≥ 0, eigenvectors as columns), sorted
/// by decreasing eigenvalue.
fn principal_axes<const N: usize>(cov: &TangentMatrix<N>) -> (Vec<f64>, Vec<Tangent<N>>) {
    let eig = SymmetricEigen::new(DMatrix::from_iterator(N, N, cov.iter().copied()));
    let mut order: Vec<usize> = (0..N).collect();
    order.sort_by(|a, b| eig.eigenvalues[*b].total_cmp(&eig.eigenvalues[*a]));
    let values = order.iter().map(|&i| eig.eigenvalues[i].max(0.0)).collect();
    let vectors = order
        .iter()
        .map(|&i| Tangent::<N>::from_iterator(eig.eigenvectors.column(i).iter().copied()))
        .collect();
    (values, vectors)
}

/// The first-order world-frame position covariance of an uncertain pose (SE(2): 3×3 with a
/// zero z row). From the right form: t(μ Exp(ε)) ≈ t + R ρ, so Σ_p = R Σ_ρρ Rᵀ.
fn position_cov_world<G: SpecGroup<N>, const N: usize>(
    pose: &UncertainPose<G, N>,
) -> Option<Matrix3<f64>> {
    let rot = G::rotation_range();
    if rot.start == 0 {
        return None; // a rotation group has no position
    }
    let cov = pose.to_side(Side::Right);
    let cov = cov.cov();
    let mut block = Matrix3::zeros();
    for r in 0..rot.start {
        for c in 0..rot.start {
            block[(r, c)] = cov[(r, c)];
        }
    }
    let rotation = pose.mean().to_se3().rotation().to_matrix();
    Some(rotation * block * rotation.transpose())
}

/// An ellipsoid from a 3×3 covariance: half sizes r√λ along the eigenvectors (a flat one for
/// a planar covariance gets a small thickness so it stays visible).
fn ellipsoid_of(center: &Vector3<f64>, cov: &Matrix3<f64>, radius: f64) -> Ellipsoid {
    let eig = SymmetricEigen::new(*cov);
    let mut axes = eig.eigenvectors;
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    let half: Vec<f64> = eig
        .eigenvalues
        .iter()
        .map(|l| radius * l.max(0.0).sqrt())
        .collect();
    let floor = half.iter().copied().fold(0.0, f64::max) * 0.01;
    let rotation = nalgebra::UnitQuaternion::from_matrix(&axes);
    Ellipsoid {
        center: v3(center),
        half_sizes: [half[0].max(floor), half[1].max(floor), half[2].max(floor)],
        rotation: [rotation.i, rotation.j, rotation.k, rotation.w],
    }
}

/// Context shared by the drawing helpers of one scenario.
struct Painter {
    scene: Scene,
    confidence: f64,
    axis_length: f64,
    /// Size of the drawing, metres ([`scene_extent`]).
    extent: f64,
    /// Particles are drawn every `particle_stride` steps (and at the last), so long
    /// propagations stay light.
    particle_stride: u64,
    last_step: u64,
}

impl Painter {
    fn particles_at(&self, step: Option<u64>) -> bool {
        step.is_none_or(|k| k % self.particle_stride == 0 || k == self.last_step)
    }

    fn push(&mut self, path: String, step: Option<u64>, kind: ItemKind) {
        self.scene.push(SceneItem::new(path, timing(step), kind));
    }
}

/// The sizes of a scenario's drawing (from its nominal poses and paths) and an empty scene
/// with that description.
fn painter<G: SpecGroup<N>, const N: usize>(e: &Evaluation<G, N>, description: String) -> Painter {
    let rotation_group = G::rotation_range().start == 0;
    let extent = scene_extent(e);
    let axis_length = e.meta.draw.axis_length.unwrap_or(if rotation_group {
        1.0
    } else {
        (0.12 * extent).clamp(0.05, 2.0)
    });
    let last_step = e.nodes.iter().filter_map(|n| n.step).max().unwrap_or(0);
    Painter {
        scene: Scene::new(e.meta.title.clone(), description),
        confidence: e.meta.confidence,
        axis_length,
        extent,
        particle_stride: last_step.div_ceil(MAX_PARTICLE_STEPS).max(1),
        last_step,
    }
}

fn build<G: SpecGroup<N>, const N: usize>(e: &Evaluation<G, N>) -> Scene {
    let rotation_group = G::rotation_range().start == 0;
    let mut p = painter(e, description(e));
    let extent = p.extent;
    p.scene.planar = match e.meta.draw.view {
        Some(View::Top) => true,
        Some(View::Perspective) => false,
        None => matches!(e.meta.group, GroupName::Se2 | GroupName::So2),
    };
    for node in e.nodes.iter().filter(|n| n.draw) {
        draw_node(&mut p, node, rotation_group, e);
    }
    if e.meta.draw.trajectories {
        for path in &e.paths {
            let strip: Vec<Vec3> = path
                .poses
                .iter()
                .map(|x| v3(x.to_se3().translation()))
                .collect();
            let color = path.method.map_or(scene::NOMINAL, Method::color);
            p.push(
                format!("world/{}", path.name),
                None,
                ItemKind::LineStrips(LineStrips {
                    strips: vec![strip],
                    color,
                    radius: 0.004 * extent.max(0.25),
                }),
            );
        }
    }
    for point in &e.points {
        for (method, mean, cov) in &point.estimates {
            let cov = Matrix3::from_fn(|r, c| cov[r][c]);
            let shape = ellipsoid_of(&Vector3::from(*mean), &cov, chi2_radius(p.confidence, 3));
            p.push(
                format!("world/{}/{}/ellipsoid", point.name, Method::slug(*method)),
                None,
                ItemKind::Ellipsoids(Ellipsoids {
                    shapes: vec![shape],
                    color: Method::color(*method),
                    fill: FillMode::MajorWireframe,
                    line_radius: 0.003,
                    label: None,
                }),
            );
        }
        if let (Some(particles), true) = (&point.particles, e.meta.draw.clouds) {
            p.push(
                format!("world/{}/monte_carlo/cloud", point.name),
                None,
                point_cloud_item(particles.clone()),
            );
        }
    }
    let drawn: Vec<_> = e
        .matrix_frames
        .iter()
        .filter(|f| p.particles_at(f.step))
        .collect();
    for frame in drawn {
        let colors = [
            Color::rgb(255, 90, 90),
            Color::rgb(90, 220, 90),
            Color::rgb(100, 140, 255),
        ];
        for (k, color) in colors.iter().enumerate() {
            let c = frame.columns.column(k);
            p.push(
                format!("world/{}/axis_{}", frame.name, ["x", "y", "z"][k]),
                frame.step,
                ItemKind::Arrows(Arrows {
                    origins: vec![frame.origin],
                    vectors: vec![[c[0], c[1], c[2]]],
                    color: *color,
                    radius: 0.01,
                }),
            );
        }
    }
    let mut by_quantity: BTreeMap<&str, usize> = BTreeMap::new();
    for s in &e.series {
        let n = by_quantity.len();
        let plot = *by_quantity.entry(&s.quantity).or_insert(n);
        let (segment, color) = match s.method {
            Some(m) => (m.slug().to_owned(), m.color()),
            None => (slug(&s.label), scene::NOMINAL),
        };
        p.scene.series.push(ScalarSeries {
            path: format!("{}/{plot}_{}/{segment}", scene::PLOTS, slug(&s.quantity)),
            name: s.label.clone(),
            color,
            width: 2.0,
            points: s.points.clone(),
        });
    }
    p.scene
}

fn cloud_color() -> Color {
    Method::color(Method::MonteCarlo).with_alpha(150)
}

fn slug(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    while out.contains("__") {
        out = out.replace("__", "_");
    }
    out.trim_matches('_').to_owned()
}

/// Size of the drawing: the largest distance of a nominal pose or particle from the centroid
/// (at least 1 m for rotation-only scenes).
fn scene_extent<G: SpecGroup<N>, const N: usize>(e: &Evaluation<G, N>) -> f64 {
    let points: Vec<Vector3<f64>> = e
        .nodes
        .iter()
        .map(|n| *n.nominal.to_se3().translation())
        .chain(
            e.paths
                .iter()
                .flat_map(|p| p.poses.iter().map(|x| *x.to_se3().translation())),
        )
        .collect();
    if points.is_empty() {
        return 1.0;
    }
    let centroid = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let extent = points
        .iter()
        .map(|p| (p - centroid).norm())
        .fold(0.0, f64::max);
    if extent > 0.0 { extent } else { 1.0 }
}

fn draw_node<G: SpecGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    rotation_group: bool,
    e: &Evaluation<G, N>,
) {
    let draw = &e.meta.draw;
    let pose3 = node.nominal.to_se3();
    if draw.axes {
        let [x, y, z, w] = crate::lie::So3::to_quaternion_xyzw(pose3.rotation());
        p.push(
            format!("world/{}/frame", node.name),
            node.step,
            ItemKind::Frame(Frame {
                translation: v3(pose3.translation()),
                rotation: [x, y, z, w],
                axis_length: p.axis_length,
                label: Some(node.name.clone()),
            }),
        );
    }
    if node.role == Role::Fixed {
        return;
    }
    if !p.particles_at(node.step) && node.step != Some(0) {
        // Between drawn steps only the (light) frame and ellipsoids are logged.
        draw_ellipsoids_only(p, node, rotation_group, draw);
        return;
    }
    let primary = primary_method(node);
    for estimate in &node.estimates {
        let pose = estimate.result.pose;
        let method = estimate.result.method;
        if method == Method::MonteCarlo && node.particles.is_some() {
            continue; // the cloud itself shows Monte Carlo
        }
        let is_primary = Some(method) == primary;
        // An input's own Gaussian is "given", not computed by a method.
        let segment = if node.role == Role::Input && method == Method::Exact {
            "given"
        } else {
            method.slug()
        };
        let base = format!("world/{}/{segment}", node.name);
        let color = Method::color(method);
        // The Cartesian ellipsoid: the primary method's (to contrast with its banana) and the
        // vector-space baseline's (a Gaussian in (x, y, θ) is exactly that ellipse).
        let ellipsoid = is_primary || method == Method::VectorSpace;
        if !rotation_group
            && draw.ellipsoids
            && ellipsoid
            && let Some(cov) = position_cov_world(&pose)
        {
            let d = if G::rotation_range().start == 2 { 2 } else { 3 };
            let shape = ellipsoid_of(
                pose.mean().to_se3().translation(),
                &cov,
                chi2_radius(p.confidence, d),
            );
            p.push(
                format!("{base}/ellipsoid"),
                node.step,
                ItemKind::Ellipsoids(Ellipsoids {
                    shapes: vec![shape],
                    color,
                    fill: FillMode::MajorWireframe,
                    line_radius: 0.002 * p.axis_length / 0.15,
                    label: None,
                }),
            );
        }
        if draw.bananas && !rotation_group && method != Method::VectorSpace {
            let point_of = |x: &G| *x.to_se3().translation();
            if is_primary {
                banana(p, &base, node.step, &pose, color, point_of);
            } else {
                outlines(
                    p,
                    &format!("{base}/banana_outline"),
                    node.step,
                    &pose,
                    color,
                    point_of,
                );
            }
        }
        if draw.orientation && rotation_group {
            for (k, axis) in ["axis_x", "axis_y", "axis_z"].iter().enumerate() {
                let len = p.axis_length;
                let path = format!("{base}/{axis}");
                outlines(p, &path, node.step, &pose, color, move |x| {
                    let s = x.to_se3();
                    s.translation() + s.rotation().act(&(Vector3::ith(k, 1.0) * len))
                });
            }
        }
    }
    if let Some(particles) = node
        .particles
        .as_ref()
        .filter(|_| p.particles_at(node.step))
    {
        draw_particles(p, node, particles, rotation_group, draw, None);
    }
}

/// On steps between the drawn ones: the primary method's Cartesian ellipsoid only, so the
/// step slider still shows the growth without logging a surface per step.
fn draw_ellipsoids_only<G: SpecGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    rotation_group: bool,
    draw: &crate::scenario::schema::DrawSpec,
) {
    let Some(primary) = primary_method(node) else {
        return;
    };
    if rotation_group || !draw.ellipsoids {
        return;
    }
    for e in node.estimates.iter().filter(|e| e.result.method == primary) {
        if let Some(cov) = position_cov_world(&e.result.pose) {
            let d = if G::rotation_range().start == 2 { 2 } else { 3 };
            let shape = ellipsoid_of(
                e.result.pose.mean().to_se3().translation(),
                &cov,
                chi2_radius(p.confidence, d),
            );
            p.push(
                format!("world/{}/{}/ellipsoid", node.name, primary.slug()),
                node.step,
                ItemKind::Ellipsoids(Ellipsoids {
                    shapes: vec![shape],
                    color: primary.color(),
                    fill: FillMode::MajorWireframe,
                    line_radius: 0.002 * p.axis_length / 0.15,
                    label: None,
                }),
            );
        }
    }
}

/// The method drawn in full (banana surface, Cartesian ellipsoid, orientation outlines): first
/// order where it ran, else the closed form, else the first estimate.
fn primary_method<G: LieGroup<N>, const N: usize>(node: &Node<G, N>) -> Option<Method> {
    [Method::FirstOrder, Method::ClosedForm, Method::Exact]
        .into_iter()
        .find(|m| node.estimates.iter().any(|e| e.result.method == *m))
        .or(node.estimates.first().map(|e| e.result.method))
}

/// The Exp-image surface and its principal outlines.
fn banana<G: SpecGroup<N>, const N: usize>(
    p: &mut Painter,
    base: &str,
    step: Option<u64>,
    pose: &UncertainPose<G, N>,
    color: Color,
    point_of: impl Fn(&G) -> Vector3<f64> + Copy,
) {
    let frame = principal_frame(pose, p.confidence);
    let (sphere, triangles) = scene::unit_sphere_mesh(BANANA_MESH.0, BANANA_MESH.1);
    let vertices: Vec<Vec3> = sphere
        .iter()
        .map(|u| v3(&point_of(&frame.apply(pose, [u[0], u[1], u[2]]))))
        .collect();
    let surface = Surface {
        vertices,
        triangles,
        normals: Vec::new(),
        color: color.with_alpha(70),
    }
    .with_computed_normals();
    p.push(format!("{base}/banana"), step, ItemKind::Surface(surface));
    outlines(
        p,
        &format!("{base}/banana_outline"),
        step,
        pose,
        color,
        point_of,
    );
}

/// Images of the three principal great circles of the tangent ellipsoid.
fn outlines<G: SpecGroup<N>, const N: usize>(
    p: &mut Painter,
    path: &str,
    step: Option<u64>,
    pose: &UncertainPose<G, N>,
    color: Color,
    point_of: impl Fn(&G) -> Vector3<f64>,
) {
    let frame = principal_frame(pose, p.confidence);
    let strips: Vec<Vec<Vec3>> = [(0, 1), (0, 2), (1, 2)]
        .iter()
        .map(|&(a, b)| {
            (0..=OUTLINE_POINTS)
                .map(|i| {
                    let s = std::f64::consts::TAU * i as f64 / OUTLINE_POINTS as f64;
                    let mut u = [0.0; 3];
                    u[a] = s.cos();
                    u[b] = s.sin();
                    v3(&point_of(&frame.apply(pose, u)))
                })
                .collect()
        })
        .collect();
    p.push(
        path.to_owned(),
        step,
        ItemKind::LineStrips(LineStrips {
            strips,
            color,
            // Thin: outlines sit on top of clouds and surfaces.
            radius: 0.004 * p.axis_length.min(0.5),
        }),
    );
}

/// The three largest principal directions of Σ scaled by r√λ: u ∈ S² ↦ Σᵢ uᵢ r√λᵢ eᵢ.
struct PrincipalFrame<const N: usize> {
    columns: [Tangent<N>; 3],
}

fn principal_frame<G: SpecGroup<N>, const N: usize>(
    pose: &UncertainPose<G, N>,
    confidence: f64,
) -> PrincipalFrame<N> {
    let (values, vectors) = principal_axes(pose.cov());
    // A Gaussian of rank k < N lives in a k-dimensional subspace: its p-region has the χ²_k
    // radius, not χ²_N (R5's yaw-only noise would otherwise be drawn far too wide).
    let largest = values.first().copied().unwrap_or(0.0);
    let rank = values
        .iter()
        .filter(|l| **l > RANK_TOLERANCE * largest)
        .count()
        .max(1);
    let r = chi2_radius(confidence, rank);
    let column = |i: usize| match (values.get(i), vectors.get(i)) {
        (Some(l), Some(v)) => v * (r * l.sqrt()),
        _ => Tangent::<N>::zeros(),
    };
    PrincipalFrame {
        columns: [column(0), column(1), column(2)],
    }
}

impl<const N: usize> PrincipalFrame<N> {
    /// μ · Exp(τ) (right) or Exp(τ) · μ (left) for τ = Σ uᵢ cᵢ.
    fn apply<G: LieGroup<N>>(&self, pose: &UncertainPose<G, N>, u: [f64; 3]) -> G {
        let tau = self.columns[0] * u[0] + self.columns[1] * u[1] + self.columns[2] * u[2];
        match pose.side() {
            Side::Right => pose.mean().rplus(&tau),
            Side::Left => pose.mean().lplus(&tau),
        }
    }
}

fn draw_particles<G: SpecGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    particles: &[G],
    rotation_group: bool,
    draw: &crate::scenario::schema::DrawSpec,
    part: Option<usize>,
) {
    let base = format!("world/{}/monte_carlo", node.name);
    // Later blocks of a blocked sample: their points only, as children of the first block's.
    let suffix = part.map_or_else(String::new, |k| format!("/block_{k}"));
    let poses: Vec<Se3> = particles.iter().map(SpecGroup::to_se3).collect();
    if draw.clouds && !rotation_group {
        p.push(
            format!("{base}/cloud{suffix}"),
            node.step,
            ItemKind::Points(PointCloud {
                positions: poses.iter().map(|x| v3(x.translation())).collect(),
                color: cloud_color(),
                radius: 0.006 * p.axis_length / 0.15,
            }),
        );
    }
    if part.is_some() {
        // Triads and headings are a subsample, drawn once from the first block.
    } else if draw.sample_axes && !rotation_group && N == 3 {
        // Planar poses: a heading arrow per subsampled particle (a z axis would only clutter).
        let stride = (poses.len() / TRIAD_SUBSAMPLE).max(1);
        let subsample: Vec<&Se3> = poses.iter().step_by(stride).take(TRIAD_SUBSAMPLE).collect();
        p.push(
            format!("{base}/headings"),
            node.step,
            ItemKind::Arrows(Arrows {
                origins: subsample.iter().map(|x| v3(x.translation())).collect(),
                vectors: subsample
                    .iter()
                    .map(|x| v3(&x.rotation().act(&(Vector3::x() * 0.35 * p.axis_length))))
                    .collect(),
                color: Color::rgb(255, 120, 120).with_alpha(200),
                radius: 0.0015 * p.axis_length / 0.15,
            }),
        );
    } else if draw.sample_axes && !rotation_group {
        let stride = (poses.len() / TRIAD_SUBSAMPLE).max(1);
        let subsample: Vec<&Se3> = poses.iter().step_by(stride).take(TRIAD_SUBSAMPLE).collect();
        p.push(
            format!("{base}/triads"),
            node.step,
            ItemKind::Triads(Triads {
                translations: subsample.iter().map(|x| v3(x.translation())).collect(),
                rotations: subsample
                    .iter()
                    .map(|x| x.rotation().to_quaternion_xyzw())
                    .collect(),
                axis_length: 0.35 * p.axis_length,
                line_radius: 0.0015 * p.axis_length / 0.15,
            }),
        );
    }
    if draw.orientation && (rotation_group || N == 6) {
        let axis_colors = [
            Color::rgb(255, 90, 90),
            Color::rgb(90, 220, 90),
            Color::rgb(100, 140, 255),
        ];
        for (k, name) in ["spray_x", "spray_y", "spray_z"].iter().enumerate() {
            let tips = poses
                .iter()
                .map(|x| {
                    v3(&(x.translation()
                        + x.rotation().act(&(Vector3::ith(k, 1.0) * p.axis_length))))
                })
                .collect();
            p.push(
                format!("{base}/{name}{suffix}"),
                node.step,
                ItemKind::Points(PointCloud {
                    positions: tips,
                    color: axis_colors[k].with_alpha(140),
                    radius: 0.004 * p.axis_length.max(0.3),
                }),
            );
        }
    }
}

/// The text panel: the scenario's own description, then what is drawn, the convention, and
/// each method's measured error against Monte Carlo.
fn description<G: SpecGroup<N>, const N: usize>(e: &Evaluation<G, N>) -> String {
    let m = &e.meta;
    let mut s = format!("# {}\n\n", m.title);
    if !m.source.is_empty() {
        let _ = writeln!(s, "*Source: {}*\n", m.source);
    }
    let _ = writeln!(s, "{}\n", m.description.trim());
    let _ = writeln!(
        s,
        "**Convention:** {} with tangent order {}; covariances are read as X = μ · Exp(ε) (right / body) unless marked left. \
         Regions are drawn at {:.1} % confidence (χ² radius {:.3} for the {}-DOF tangent ellipsoid).\n",
        G::NAME,
        tangent_order(N, G::rotation_range().start == 0),
        m.confidence * 100.0,
        chi2_radius(m.confidence, N),
        N
    );
    if !m.methods.is_empty() {
        let _ = writeln!(s, "| method | colour |\n|---|---|");
        for method in &m.methods {
            let _ = writeln!(
                s,
                "| {} | {} |",
                method.label(),
                Method::color_name(*method)
            );
        }
        let _ = writeln!(
            s,
            "| Monte Carlo samples | grey cloud ({} samples, seed {}) |\n",
            m.samples, m.seed
        );
    }
    let finals = final_nodes(e);
    let with_errors: Vec<_> = finals
        .iter()
        .filter(|n| n.estimates.iter().any(|x| x.error_vs_monte_carlo.is_some()))
        .collect();
    if !with_errors.is_empty() {
        let _ = writeln!(
            s,
            "**Error against Monte Carlo** (‖Σ − Σ_MC‖_F / ‖Σ_MC‖_F, right side):\n"
        );
        let _ = writeln!(s, "| pose | method | error |\n|---|---|---|");
        for node in with_errors {
            let label = node
                .step
                .map_or(node.name.clone(), |k| format!("{} (step {k})", node.name));
            for est in node
                .estimates
                .iter()
                .filter(|x| x.result.method != Method::MonteCarlo)
            {
                let Some(err) = est.error_vs_monte_carlo else {
                    continue;
                };
                let method = if node.role == Role::Input {
                    "given Σ (sampling noise floor)"
                } else {
                    est.result.method.label()
                };
                let _ = writeln!(s, "| {label} | {method} | {:.1} % |", 100.0 * err);
            }
        }
        s.push('\n');
    }
    for note in &e.notes {
        let _ = writeln!(s, "{note}\n");
    }
    s
}

fn tangent_order(n: usize, rotation_group: bool) -> &'static str {
    match (n, rotation_group) {
        (1, _) => "[θ]",
        (3, true) => "[θx, θy, θz]",
        (3, false) => "[ρx, ρy, θ]",
        _ => "[ρx, ρy, ρz, θx, θy, θz]",
    }
}

/// The last step of every node name (or the node itself when static).
fn final_nodes<G: SpecGroup<N>, const N: usize>(e: &Evaluation<G, N>) -> Vec<&Node<G, N>> {
    let mut last: BTreeMap<&str, &Node<G, N>> = BTreeMap::new();
    let mut order = Vec::new();
    for node in &e.nodes {
        if !last.contains_key(node.name.as_str()) {
            order.push(node.name.as_str());
        }
        last.insert(&node.name, node);
    }
    order.iter().filter_map(|n| last.get(n).copied()).collect()
}
