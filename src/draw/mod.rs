//! From an [`Evaluation`] and [`DrawSettings`] to a plain-data [`Scene`]: what each method's
//! uncertainty looks like, drawn the same way in every input. Drawing never evaluates: the
//! caller hands it the numbers (and, for a blocked Monte Carlo sample, each later block's
//! particles to [`particle_part`]).
//!
//! Per pose and method (entity `world/<pose>/<method>/…`, so each can be toggled):
//! - `ellipsoid`: the first-order **Cartesian** position region, world frame, at the chosen
//!   confidence with d = 3 (SE(3)) or d = 2 (SE(2)) degrees of freedom
//!   ([CONVENTIONS §7](crate::conventions));
//! - `banana`: the **Exp-image** { μ · Exp(L u) : ‖u‖ = r } of the method's tangent-space
//!   ellipsoid (L Lᵀ = Σ, r² = χ²_k(p) with k the rank of Σ), swept over the sphere of the
//!   three largest principal directions of Σ and drawn through each point's translation — a
//!   mesh for the main method, the images of its three principal ellipses for every method;
//! - `axis_x|y|z` (rotation groups): the Exp-image of the same ellipsoid seen through each
//!   body axis tip, R̄ Exp(L u) e_k, around each mean axis;
//! - `monte_carlo/cloud`, `monte_carlo/triads`, `monte_carlo/spray_*`: particle positions, a
//!   subsample of small axis triads, and axis-tip sprays; later blocks of a blocked sample as
//!   children `…/cloud/block_k`.
//!
//! ```
//! use posecov::app::{Overrides, load_text, pipeline};
//! use posecov::draw::{DrawSettings, scene};
//! let loaded = load_text("[scenario]\ntitle='t'\ngroup='se2'\nmethods=['first_order']\n[[pose]]\nname='a'\nmean={xy_theta=[1,2,0]}\ncov={std=[0.1,0.1,0.3]}\n", "t.toml").unwrap();
//! let (evaluation, _) = pipeline(&loaded, &Overrides::default(), None).unwrap();
//! let s = scene(&evaluation, &DrawSettings::from_input(&loaded.input, 0.95));
//! assert!(s.items.iter().any(|i| i.path == "world/a/given/banana"));
//! assert!(s.validate().is_ok());
//! ```

use std::collections::BTreeMap;

use nalgebra::Vector3;

use crate::eval::{AnyEvaluation, Evaluation, Node, PathKind, Role};
use crate::input::{About, DrawChoices, Input, Layout};
use crate::lie::{GroupKind, LieGroup, Se3};
use crate::plan::StepPolicy;
use crate::scene::{
    self, Arrows, Color, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, PointCloud, Scene,
    SceneItem, Swatch, Timing, Triads, Vec3,
};
use crate::uncertain::Method;

pub mod bag;
mod graph;
mod legend;
mod plots;
mod shapes;
mod text;
mod views;

use shapes::chi2_radius;

/// Colour of the Monte Carlo heading arrows of planar poses (light red).
const HEADING_COLOR: Color = Color::rgb(255, 120, 120);

/// At most this many Monte Carlo particles get a small axis triad.
const TRIAD_SUBSAMPLE: usize = 60;

/// What drawing needs besides the evaluation, resolved once by the caller.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawSettings {
    /// Title, description, source for the text panel.
    pub about: About,
    /// Probability inside drawn regions, in (0, 1).
    pub confidence: f64,
    /// What to draw.
    pub choices: DrawChoices,
    /// Which steps of a propagation are drawn in full (the same policy the evaluation used).
    pub steps: StepPolicy,
}

impl DrawSettings {
    /// The settings an input asks for, at `confidence`, with the default step policy.
    ///
    /// ```
    /// use posecov::draw::DrawSettings;
    /// use posecov::input::scenario::{Scenario, lower};
    /// let input = lower(&Scenario::load_any("camera_on_robot").unwrap()).unwrap();
    /// assert_eq!(DrawSettings::from_input(&input, 0.9).confidence, 0.9);
    /// ```
    pub fn from_input(input: &Input, confidence: f64) -> Self {
        Self {
            about: input.about.clone(),
            confidence,
            choices: input.draw.clone(),
            steps: StepPolicy::default(),
        }
    }
}

/// The scene of an evaluation.
///
/// See the [module docs](self) for an example.
pub fn scene(evaluation: &AnyEvaluation, settings: &DrawSettings) -> Scene {
    crate::with_evaluation!(evaluation, e => build(e, settings))
}

/// The particle clouds of block `part` (≥ 1) of a blocked Monte Carlo sample, sized as in
/// `main`'s scene: `…/monte_carlo/cloud/block_k` and `spray_*/block_k`. Log it after the
/// main scene and drop it: memory stays bounded.
///
/// ```
/// use posecov::app::{Overrides, load, resolve};
/// use posecov::draw::particle_part;
/// // The caller evaluates (here as `app::session` does); drawing only draws.
/// use posecov::eval::{evaluate as run, evaluate_block as run_block};
/// let loaded = load("camera_on_robot").unwrap();
/// let overrides = Overrides { samples: Some(3000), block_samples: Some(1024), ..Default::default() };
/// let settings = resolve(&loaded.input, &overrides, None).unwrap();
/// let main = run(&loaded.input.plan, &settings.eval).unwrap();
/// let block = run_block(&loaded.input.plan, &settings.eval, &main, 2).unwrap().unwrap();
/// let part = particle_part(&main, &block, 2, &settings.draw);
/// assert!(part.items.iter().any(|i| i.path.ends_with("/cloud/block_2")));
/// ```
pub fn particle_part(
    main: &AnyEvaluation,
    block: &AnyEvaluation,
    part: usize,
    settings: &DrawSettings,
) -> Scene {
    match (main, block) {
        (AnyEvaluation::So2(m), AnyEvaluation::So2(b)) => part_of(m, b, part, settings),
        (AnyEvaluation::Se2(m), AnyEvaluation::Se2(b)) => part_of(m, b, part, settings),
        (AnyEvaluation::So3(m), AnyEvaluation::So3(b)) => part_of(m, b, part, settings),
        (AnyEvaluation::Se3(m), AnyEvaluation::Se3(b)) => part_of(m, b, part, settings),
        _ => Scene::new(settings.about.title.clone(), String::new()),
    }
}

fn part_of<G: LieGroup<N>, const N: usize>(
    main: &Evaluation<G, N>,
    block: &Evaluation<G, N>,
    part: usize,
    settings: &DrawSettings,
) -> Scene {
    // A part is logged after the main scene: its items only, no description.
    let mut p = Painter::new(main, settings, String::new());
    let shown = Shown::new(main, &settings.choices);
    for node in block
        .nodes
        .iter()
        .filter(|n| n.role != Role::Fixed && shown.node(n))
    {
        if let Some(particles) = node.particles.as_ref().filter(|_| p.detailed(node)) {
            draw_particles(&mut p, node, particles, Some(part));
        }
    }
    if settings.choices.clouds {
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

/// Which poses are drawn: each pose's own choice, else uncertain poses and results, and known
/// transforms `a_from_b` only when `a` is the root frame (the parent of the first uncertain
/// input) — a relative mount such as `robot_from_camera` drawn at world coordinates would
/// mislead. Results named `a_from_b` with `a` not the root are relative too — except rotations,
/// which all turn about the same origin: each result gets its own view.
struct Shown<'a> {
    root: Option<&'a str>,
    choices: &'a DrawChoices,
    /// Rotations all sit at the origin, each in its own view: every result is drawn.
    rotation_only: bool,
}

impl<'a> Shown<'a> {
    fn new<G: LieGroup<N>, const N: usize>(
        e: &'a Evaluation<G, N>,
        choices: &'a DrawChoices,
    ) -> Self {
        let root = e
            .nodes
            .iter()
            .find(|n| n.role == Role::Input)
            .and_then(|n| parent_frame(&n.name));
        Self {
            root,
            choices,
            rotation_only: G::KIND.is_rotation_only(),
        }
    }

    fn node<G: LieGroup<N>, const N: usize>(&self, node: &Node<G, N>) -> bool {
        if let Some(choice) = self.choices.shown.get(&node.name) {
            return *choice;
        }
        match (self.root, parent_frame(&node.name)) {
            _ if self.rotation_only && node.role == Role::Output => true,
            (Some(root), Some(parent)) => parent == root,
            _ => node.role != Role::Fixed,
        }
    }
}

/// The parent frame of a name `a_from_b` (`a`), if it follows that convention.
fn parent_frame(name: &str) -> Option<&str> {
    name.split_once("_from_").map(|(parent, _)| parent)
}

/// Context shared by the drawing helpers of one scene.
struct Painter<'s> {
    scene: Scene,
    settings: &'s DrawSettings,
    kind: GroupKind,
    axis_length: f64,
    /// Size of the drawing, metres ([`scene_extent`]).
    extent: f64,
    /// How the 3-D views split methods and poses (decided before drawing: one view per method
    /// draws every method's banana as a surface).
    layout: Layout,
    /// Per drawn uncertain pose, the methods drawn for it (for the views).
    methods: Vec<(String, views::PoseMethods)>,
}

impl<'s> Painter<'s> {
    fn new<G: LieGroup<N>, const N: usize>(
        e: &Evaluation<G, N>,
        settings: &'s DrawSettings,
        description: String,
    ) -> Self {
        let extent = scene_extent(e);
        let axis_length = settings
            .choices
            .axis_length
            .unwrap_or(if G::KIND.is_rotation_only() {
                1.0
            } else {
                (0.12 * extent).clamp(0.05, 2.0)
            });
        Painter {
            scene: Scene::new(settings.about.title.clone(), description),
            settings,
            kind: G::KIND,
            axis_length,
            extent,
            methods: Vec::new(),
            layout: settings.choices.layout.unwrap_or(Layout::Main),
        }
    }

    fn confidence(&self) -> f64 {
        self.settings.confidence
    }

    /// Adds a legend entry (once per label and colour).
    fn legend(&mut self, label: String, color: Color, swatch: Swatch) {
        self.scene.add_legend(legend::entry(label, color, swatch));
    }

    /// Whether a node's step is drawn in full (clouds, surfaces), not only its ellipsoid.
    fn detailed<G: LieGroup<N>, const N: usize>(&self, node: &Node<G, N>) -> bool {
        node.step
            .is_none_or(|k| self.settings.steps.detailed(k, node.last_step.unwrap_or(k)))
    }

    fn push(&mut self, path: String, step: Option<u64>, kind: ItemKind) {
        let timing = step.map_or(Timing::Static, |k| Timing::Step(k as i64));
        self.scene.push(SceneItem::new(path, timing, kind));
    }
}

fn build<G: LieGroup<N>, const N: usize>(e: &Evaluation<G, N>, settings: &DrawSettings) -> Scene {
    let mut p = Painter::new(e, settings, text::description(e, settings));
    p.scene.confidence = Some(settings.confidence);
    let choices = &settings.choices;
    p.scene.planar = choices.top_view.unwrap_or(G::KIND.is_planar());
    let shown = Shown::new(e, choices);
    if choices.layout.is_none() {
        let drawn: Vec<&Node<G, N>> = e
            .nodes
            .iter()
            .filter(|n| shown.node(n) && n.role != Role::Fixed)
            .collect();
        let mut names: Vec<&str> = drawn.iter().map(|n| n.name.as_str()).collect();
        names.dedup();
        let most_methods = drawn
            .iter()
            .map(|n| {
                n.estimates
                    .iter()
                    .filter(|x| is_analytic(n, x.result.method))
                    .count()
            })
            .max()
            .unwrap_or(0);
        p.layout = views::default_layout(G::KIND.is_rotation_only(), names.len(), most_methods);
    }
    for node in e.nodes.iter().filter(|n| shown.node(n)) {
        draw_node(&mut p, node);
    }
    if choices.trajectories {
        let radius = 0.004 * p.extent.max(0.25);
        for path in &e.paths {
            let (name, color, what) = match path.kind {
                PathKind::Nominal => (
                    format!("world/{}/nominal", path.output),
                    scene::NOMINAL,
                    "nominal path",
                ),
                PathKind::Sample(i) => (
                    format!("world/{}/samples/{i}", path.output),
                    Method::MonteCarlo.color(),
                    "Monte Carlo sample paths",
                ),
            };
            p.legend(what.to_owned(), color, Swatch::Line);
            let strip: Vec<Vec3> = path
                .poses
                .iter()
                .map(|x| v3(x.to_se3().translation()))
                .collect();
            p.push(
                name,
                None,
                ItemKind::LineStrips(LineStrips {
                    strips: vec![strip],
                    color,
                    radius,
                }),
            );
        }
    }
    links(&mut p, e);
    if let Some(g) = &e.graph {
        graph::draw_optimized(&mut p, g);
    }
    for point in &e.points {
        for (method, mean, cov) in &point.estimates {
            p.legend(
                format!(
                    "{}: {} ellipsoid of the point",
                    method.label(),
                    legend::percent(p.confidence())
                ),
                method.color(),
                Swatch::Dashed,
            );
            let shape = shapes::ellipsoid_of(mean, cov, chi2_radius(p.confidence(), 3));
            p.push(
                format!("world/{}/{}/ellipsoid", point.name, method.slug()),
                None,
                ItemKind::Ellipsoids(Ellipsoids {
                    shapes: vec![shape],
                    color: method.color(),
                    fill: FillMode::MajorWireframe,
                    line_radius: 0.003,
                    label: None,
                }),
            );
        }
        if let (Some(particles), true) = (&point.particles, choices.clouds) {
            p.legend(
                format!("Monte Carlo points ({})", particles.len()),
                Method::MonteCarlo.color(),
                Swatch::Dots,
            );
            p.push(
                format!("world/{}/monte_carlo/cloud", point.name),
                None,
                point_cloud_item(particles.clone()),
            );
        }
    }
    let last_frame: BTreeMap<&str, u64> =
        e.matrix_frames.iter().fold(BTreeMap::new(), |mut m, f| {
            let last = m.entry(f.output.as_str()).or_insert(0);
            *last = (*last).max(f.step);
            m
        });
    for frame in &e.matrix_frames {
        let last = last_frame
            .get(frame.output.as_str())
            .copied()
            .unwrap_or(frame.step);
        if !settings.steps.detailed(frame.step, last) {
            continue;
        }
        p.scene
            .add_legend(legend::axes("Euler-angle frame (rotation matrix columns)"));
        for (k, color) in shapes::AXIS_COLORS.iter().enumerate() {
            let c = frame.columns.column(k);
            p.push(
                format!("world/{}/euler/axis_{}", frame.output, ["x", "y", "z"][k]),
                Some(frame.step),
                ItemKind::Arrows(Arrows {
                    origins: vec![[0.0; 3]],
                    vectors: vec![[c[0], c[1], c[2]]],
                    color: *color,
                    radius: 0.01,
                }),
            );
        }
    }
    let (plots, series) = plots::plots(e);
    p.scene.plots = plots;
    p.scene.series = series;
    let plan = views::ViewPlan {
        poses: &p.methods,
        rotation_only: G::KIND.is_rotation_only(),
        top: p.scene.planar,
        layout: p.layout,
        camera: choices.camera,
    };
    p.scene.views = if e.graph.is_some() {
        views::before_after(&p.scene, &plan, graph::AFTER)
    } else {
        views::views(&p.scene, &plan)
    };
    if let Some(note) = views::note(&p.scene.views) {
        p.scene.description_markdown.push_str(&note);
    }
    p.scene
}

/// The lines the input asks for between two poses (a graph's loop closures), at
/// `world/links`, between the poses' nominal positions.
fn links<G: LieGroup<N>, const N: usize>(p: &mut Painter, e: &Evaluation<G, N>) {
    let position = |name: &str| {
        e.nodes
            .iter()
            .find(|n| n.name == name)
            .map(|n| v3(n.nominal.to_se3().translation()))
    };
    let strips: Vec<Vec<Vec3>> = p
        .settings
        .choices
        .links
        .iter()
        .filter_map(|(a, b)| Some(vec![position(a)?, position(b)?]))
        .collect();
    if !strips.is_empty() {
        p.legend("links between poses".to_owned(), scene::LINK, Swatch::Line);
        p.push(
            "world/links".to_owned(),
            None,
            ItemKind::LineStrips(LineStrips {
                strips,
                color: scene::LINK,
                radius: 0.003 * p.extent.max(0.25),
            }),
        );
    }
}

/// The Monte Carlo points of a `point_through_pose` output.
fn point_cloud_item(positions: Vec<Vec3>) -> ItemKind {
    ItemKind::Points(PointCloud {
        positions,
        color: cloud_color(),
        radius: 0.01,
    })
}

fn cloud_color() -> Color {
    Method::MonteCarlo.color().with_alpha(150)
}

fn v3(v: &Vector3<f64>) -> Vec3 {
    [v.x, v.y, v.z]
}

/// Size of the drawing: the largest distance of a nominal pose or path point from the
/// centroid (1 m for a scene without extent).
fn scene_extent<G: LieGroup<N>, const N: usize>(e: &Evaluation<G, N>) -> f64 {
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
    extent_of(&points)
}

/// The largest distance of a point from the points' centroid (1 m for none, or all equal).
fn extent_of(points: &[Vector3<f64>]) -> f64 {
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

/// The method drawn in full (banana surface, Cartesian ellipsoid, orientation outlines): first
/// order where it ran, else the closed form, else the first estimate.
fn primary_method<G: LieGroup<N>, const N: usize>(node: &Node<G, N>) -> Option<Method> {
    [Method::FirstOrder, Method::ClosedForm, Method::Exact]
        .into_iter()
        .find(|m| node.estimates.iter().any(|e| e.result.method == *m))
        .or(node.estimates.first().map(|e| e.result.method))
}

/// A method computed for `node` (not Monte Carlo, not an input's given Gaussian).
fn is_analytic<G: LieGroup<N>, const N: usize>(node: &Node<G, N>, method: Method) -> bool {
    method != Method::MonteCarlo && !(node.role == Role::Input && method == Method::Exact)
}

fn draw_node<G: LieGroup<N>, const N: usize>(p: &mut Painter, node: &Node<G, N>) {
    let choices = &p.settings.choices;
    let (axes, ellipsoids, bananas, orientation) = (
        choices.axes,
        choices.ellipsoids,
        choices.bananas,
        choices.orientation,
    );
    let pose3 = node.nominal.to_se3();
    if axes {
        p.scene.add_legend(legend::axes("pose frames"));
        p.push(
            format!("world/{}/frame", node.name),
            node.step,
            ItemKind::Frame(Frame {
                translation: v3(pose3.translation()),
                rotation: pose3.rotation().to_quaternion_xyzw(),
                axis_length: p.axis_length,
                label: choices.labels.then(|| node.name.clone()),
            }),
        );
    }
    if node.role == Role::Fixed {
        return;
    }
    let rotation_only = p.kind.is_rotation_only();
    let primary = primary_method(node);
    if !p.detailed(node) {
        // Between detailed steps only the (light) frame and the primary ellipsoid are logged,
        // so the step slider still shows the growth.
        if let Some(e) = node
            .estimates
            .iter()
            .find(|e| Some(e.result.method) == primary)
            && ellipsoids
            && !rotation_only
        {
            let who = e.result.method.label().to_owned();
            cartesian_legend(p, who, e.result.method);
            shapes::position_ellipsoid(
                p,
                &format!("world/{}/{}", node.name, e.result.method.slug()),
                node.step,
                &e.result.pose,
                e.result.method.color(),
            );
        }
        return;
    }
    // Every method's regions on the main method's side: a banana is a 3-D slice of the tangent
    // ellipsoid along its largest principal directions, which depend on the side, so one
    // Gaussian read on two sides would look like two.
    let side = node
        .estimates
        .iter()
        .find(|e| Some(e.result.method) == primary)
        .map(|e| e.result.pose.side());
    // The Cartesian ellipses drawn for this pose: (method, who, centre, covariance).
    let mut cartesian: Vec<(Method, String, Vec3, nalgebra::Matrix3<f64>)> = Vec::new();
    for estimate in &node.estimates {
        let pose = side.map_or(estimate.result.pose, |s| estimate.result.pose.to_side(s));
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
        let drawn = match p.methods.iter().position(|(n, _)| *n == node.name) {
            Some(i) => &mut p.methods[i].1,
            None => {
                p.methods
                    .push((node.name.clone(), views::PoseMethods::default()));
                &mut p.methods.last_mut().expect("just pushed").1
            }
        };
        if is_primary {
            drawn.main = Some(segment);
        } else if method != Method::MonteCarlo && !drawn.others.contains(&segment) {
            drawn.others.push(segment);
        }
        let base = format!("world/{}/{segment}", node.name);
        let color = method.color();
        // The Cartesian ellipsoid: the primary method's (to contrast with its banana) and the
        // vector-space baseline's (a Gaussian in (x, y, θ) is exactly that ellipse).
        let who = legend::who(segment, method.label());
        if !rotation_only && ellipsoids && (is_primary || method == Method::VectorSpace) {
            cartesian_legend(p, who.clone(), method);
            if let Some(cov) = pose.position_cov_in_world_3d() {
                let centre = v3(pose.mean().to_se3().translation());
                cartesian.push((method, who.clone(), centre, cov));
            }
            shapes::position_ellipsoid(p, &base, node.step, &pose, color);
        }
        let region = legend::percent(p.confidence());
        if bananas && !rotation_only && method != Method::VectorSpace {
            let point_of = |x: &G| *x.to_se3().translation();
            if is_primary || p.layout == Layout::PerMethod {
                p.legend(
                    format!("{who}: Exp-mapped {region} region"),
                    color,
                    Swatch::Region,
                );
                shapes::banana(p, &base, node.step, &pose, color, point_of);
            } else {
                p.legend(
                    format!("{who}: Exp-mapped {region} region, principal outlines"),
                    color,
                    Swatch::Line,
                );
                shapes::outlines(
                    p,
                    &format!("{base}/banana_outline"),
                    node.step,
                    &pose,
                    color,
                    point_of,
                );
            }
        }
        if orientation && rotation_only {
            p.legend(
                format!("{who}: {region} region of each axis tip"),
                color,
                Swatch::Line,
            );
            for (k, axis) in ["axis_x", "axis_y", "axis_z"].iter().enumerate() {
                let len = p.axis_length;
                let path = format!("{base}/{axis}");
                shapes::outlines(p, &path, node.step, &pose, color, move |x| {
                    let s = x.to_se3();
                    s.translation() + s.rotation().act(&(Vector3::ith(k, 1.0) * len))
                });
            }
        }
    }
    coinciding(p, &node.name, &cartesian);
    if let Some(particles) = &node.particles {
        draw_particles(p, node, particles, None);
    }
}

/// Says when the vector-space ellipse and another method's Cartesian ellipse of one pose are
/// the same (same centre and matrix to 1e-9 relative): one hides the other exactly, and a
/// reader would conclude the hidden one is missing. Once per pose name, in the legend and the
/// text panel.
fn coinciding(
    p: &mut Painter,
    pose: &str,
    drawn: &[(Method, String, Vec3, nalgebra::Matrix3<f64>)],
) {
    let Some((_, _, c0, m0)) = drawn.iter().find(|d| d.0 == Method::VectorSpace) else {
        return;
    };
    for (method, who, c, m) in drawn.iter().filter(|d| d.0 != Method::VectorSpace) {
        let scale = m0.amax().max(f64::MIN_POSITIVE);
        let same_matrix = (m - m0).amax() <= 1e-9 * scale;
        let same_centre = (0..3).all(|k| (c[k] - c0[k]).abs() <= 1e-9 * (1.0 + c0[k].abs()));
        if !(same_matrix && same_centre) {
            continue;
        }
        let region = legend::percent(p.confidence());
        p.legend(
            format!(
                "{who}: Cartesian {region} ellipse = the vector-space one here (same matrix; drawn under it)"
            ),
            method.color(),
            Swatch::Dashed,
        );
        let sentence = format!(
            "**{pose}:** the vector-space ellipse ({}) coincides with the {who} Cartesian one ({}) here: same matrix, so only one line shows.\n\n",
            Method::VectorSpace.color_name(),
            method.color_name()
        );
        if !p.scene.description_markdown.contains(&sentence) {
            p.scene.description_markdown.push_str(&sentence);
        }
    }
}

fn draw_particles<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    particles: &[G],
    part: Option<usize>,
) {
    let choices = p.settings.choices.clone();
    let base = format!("world/{}/monte_carlo", node.name);
    // Later blocks of a blocked sample: their points only, as children of the first block's.
    let suffix = part.map_or_else(String::new, |k| format!("/block_{k}"));
    let poses: Vec<Se3> = particles.iter().map(LieGroup::to_se3).collect();
    let rotation_only = p.kind.is_rotation_only();
    if choices.clouds && !rotation_only {
        p.legend(
            format!("Monte Carlo samples ({})", particles.len()),
            Method::MonteCarlo.color(),
            Swatch::Dots,
        );
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
    let stride = (poses.len() / TRIAD_SUBSAMPLE).max(1);
    let subsample: Vec<&Se3> = poses.iter().step_by(stride).take(TRIAD_SUBSAMPLE).collect();
    if part.is_some() || !choices.sample_axes || rotation_only {
        // Triads and headings are a subsample, drawn once from the first block.
    } else if p.kind == GroupKind::Se2 {
        // Planar poses: a heading arrow per subsampled particle (a z axis would only clutter).
        p.legend(
            "Monte Carlo headings (a subsample)".to_owned(),
            HEADING_COLOR,
            Swatch::Line,
        );
        p.push(
            format!("{base}/headings"),
            node.step,
            ItemKind::Arrows(Arrows {
                origins: subsample.iter().map(|x| v3(x.translation())).collect(),
                vectors: subsample
                    .iter()
                    .map(|x| v3(&x.rotation().act(&(Vector3::x() * 0.35 * p.axis_length))))
                    .collect(),
                color: HEADING_COLOR.with_alpha(200),
                radius: 0.0015 * p.axis_length / 0.15,
            }),
        );
    } else {
        p.scene
            .add_legend(legend::axes("Monte Carlo samples' axes (a subsample)"));
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
    if choices.orientation && (rotation_only || p.kind == GroupKind::Se3) {
        p.scene.add_legend(legend::axes("Monte Carlo axis tips"));
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
                    color: shapes::AXIS_COLORS[k].with_alpha(140),
                    radius: 0.004 * p.axis_length.max(0.3),
                }),
            );
        }
    }
}

/// The legend entry of a method's Cartesian position ellipse (the vector-space baseline's is
/// its whole Gaussian in (x, y[, z])).
fn cartesian_legend(p: &mut Painter, who: String, method: Method) {
    let region = legend::percent(p.confidence());
    let label = if method == Method::VectorSpace {
        format!("{who}: {region} ellipse")
    } else {
        format!("{who}: Cartesian {region} ellipse (first-order position)")
    };
    p.legend(label, method.color(), Swatch::Dashed);
}
