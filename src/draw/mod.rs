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
//! let s = scene(&evaluation, &DrawSettings::new(loaded.input.about.clone(), loaded.input.draw.clone(), posecov::uncertain::Confidence::DEFAULT));
//! assert!(s.items.iter().any(|i| i.path == "world/a/given/banana"));
//! assert!(s.validate().is_ok());
//! ```
//!
//! # What this folder owns
//!
//! - `scene(&Evaluation, &DrawSettings) → Scene`: which poses are shown (a result relative to a
//!   frame other than the root, `b_from_world`, drawn from the root's drawn pose of that frame,
//!   `world_from_b`'s mean, and said so), (and the lines the input asks for between named poses,
//!   `DrawChoices::links`), each node's regions and particles (`node.rs`), what a plan draws
//!   besides its poses — paths, links, points, Euler frames (`extras.rs`) — shapes as geometry
//!   (`shapes.rs`: ellipsoids, banana meshes, outlines; the caller places them), the painter
//!   (`painter.rs`: the scene being drawn, its confidence and sizes, and the one place a shape is
//!   placed on an entity path, at a step or a stamp), the legend's words (`legend.rs`), particles,
//!   plots with titles and units as data (`plots.rs`), the text panel and every finding in words
//!   (`text.rs`; `words.rs`: the placeholders of a title or description, `{{coverage …}}` and the
//!   like, filled with the run's numbers and their standard errors — the one way a number the run
//!   computes reaches the author's words; a pose graph file's description from its facts,
//!   `graph/about.rs`; a pose graph's findings and its paragraph — loop closures
//!   before and after, joint marginals — in `graph/mod.rs`, its after picture — marginals true
//!   to scale following the loop-closure timeline on the `step` timeline after the chain's
//!   steps, loop closures, relative uncertainties, a legend entry for every mark — in
//!   `graph/after.rs`, its few labels by importance in `graph/labels.rs`, the σ colours of its trajectory and ellipses in
//!   `graph/ramp.rs`, the close-ups of the largest marginal and the worst loop closure in
//!   `graph/zoom.rs`; the σ before and after against pose index in `graph/sigma.rs`), the 3-D
//!   views —
//!   layout, hidden entities, each view's camera fitted to what it draws (`views.rs`); the
//!   viewer's labels fitted to the views they open in, a label that would cover a more
//!   important one left out of the viewer and said in the text panel (`tags.rs`);
//! - `log.rs` (`draw_log`: a robot log's scene on the `stamp` timeline and its views: one whole-log
//!   view per `frame_id`, never overlaid, and per topic a view at the robot's scale whose camera is
//!   fitted to its last message) with `log/message.rs` (one drawn message wherever it is placed —
//!   frame, RViz's picture, the meaning's banana, ellipsoid and cloud, or a red cross — and the
//!   faint history)
//! - `log/rviz.rs` (RViz's picture; a placeholder axis ≥ 1e6 clipped and labelled)
//! - `log/robot.rs` (the selected message at the origin with its σ)
//! - `log/plots.rs` (σ and trace plots in units and ranges fitted to the data)
//! - `log/frames.rs` (which topic was joined to which frame by which transforms, and each frame
//!   problem's sentence)
//! - `log/nees.rs` (with `--reference`: one NEES plot per topic with the 95 % bound and ANEES band,
//!   its paragraph, the verdict's words) and `log/text.rs` (the health summary and every health
//!   word, `issue_word`)
//!
//! It does not evaluate.

use std::fmt::Write as _;
use std::sync::atomic::{AtomicU64, Ordering as AtomicOrdering};

use nalgebra::Vector3;

use crate::eval::{AnyEvaluation, Evaluation, Node, Role};
use crate::lie::{GroupKind, LieGroup, Se3};
use crate::plan::StepPolicy;
use crate::plan::choices::{About, DrawChoices, Layout};
use crate::scene::{Arrows, Color, Frame, ItemKind, PointCloud, Scene, Swatch, Triads, Vec3};
use crate::scene::{Origin, paths};
use crate::uncertain::{Confidence, Method};

mod extras;
mod graph;
mod legend;
pub mod log;
mod node;
mod painter;
use node::{draw_node, draw_particles};
use painter::{Painter, at_step, detailed};
mod plots;
mod shapes;
mod tags;
mod text;
mod views;
mod words;

/// At most this many Monte Carlo particles get a small axis triad.
const TRIAD_SUBSAMPLE: usize = 60;

/// What drawing needs besides the evaluation, resolved once by the caller.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawSettings {
    /// Title, description, source for the text panel.
    pub about: About,
    /// Probability inside drawn regions, in (0, 1).
    pub confidence: Confidence,
    /// What to draw.
    pub choices: DrawChoices,
    /// Which steps of a propagation are drawn in full (the same policy the evaluation used).
    pub steps: StepPolicy,
}

impl DrawSettings {
    /// What an input is about and asks to draw, at `confidence`, with the default step policy.
    ///
    /// ```
    /// use posecov::draw::DrawSettings;
    /// use posecov::input::scenario::{Scenario, lower};
    /// use posecov::uncertain::Confidence;
    /// let input = lower(&Scenario::load_any("camera_on_robot").unwrap()).unwrap();
    /// let p = Confidence::new(0.9).unwrap();
    /// assert_eq!(DrawSettings::new(input.about, input.draw, p).confidence, p);
    /// ```
    pub fn new(about: About, choices: DrawChoices, confidence: Confidence) -> Self {
        Self {
            about,
            confidence,
            choices,
            steps: StepPolicy::default(),
        }
    }
}

/// The scene of an evaluation.
///
/// See the [module docs](self) for an example.
pub fn scene(evaluation: &AnyEvaluation, settings: &DrawSettings) -> Scene {
    counted(crate::with_evaluation!(evaluation, e => build(e, settings)))
}

/// Scene items built by the draw stage in this process ([`scene`], [`log::draw_log`]).
static ITEMS_DRAWN: AtomicU64 = AtomicU64::new(0);

/// How many scene items the draw stage has built in this process, over every scene: a command
/// that only prints numbers (`report`, a log's `check`) leaves it where it was.
///
/// ```
/// use posecov::draw::items_drawn;
/// let before = items_drawn();
/// posecov::app::pipeline(&posecov::app::load("camera_on_robot").unwrap(), &Default::default(), None).unwrap();
/// assert!(items_drawn() > before);
/// ```
pub fn items_drawn() -> u64 {
    ITEMS_DRAWN.load(AtomicOrdering::Relaxed)
}

/// A scene just built, its items counted in [`items_drawn`].
fn counted(scene: Scene) -> Scene {
    ITEMS_DRAWN.fetch_add(scene.items.len() as u64, AtomicOrdering::Relaxed);
    scene
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
    let mut p = Painter::for_plan(main, settings, String::new());
    let shown = Shown::new(main, &settings.choices);
    for node in block
        .nodes
        .iter()
        .filter(|n| n.role != Role::Fixed && shown.node(n))
    {
        if let Some(particles) = node
            .particles
            .as_ref()
            .filter(|_| detailed(&settings.steps, node))
        {
            p.origin = Some(Origin::Node(node.name.clone()));
            draw_particles(&mut p, node, particles, Some(part), &settings.choices);
            p.origin = None;
        }
    }
    if settings.choices.clouds {
        for point in &block.points {
            if let Some(particles) = &point.particles {
                p.origin = Some(Origin::Node(point.name.clone()));
                p.push(
                    paths::block_cloud(&point.name, part),
                    None,
                    point_cloud_item(particles.clone()),
                );
                p.origin = None;
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

impl Shown<'_> {
    /// The pose through which a result `a_from_c` that is relative to a frame `a` other than
    /// the root is drawn: the single, drawn pose `root_from_a` (`world_from_b` for
    /// `b_from_world`). `None` when the file chose for the result, or there is no such pose.
    fn through<'e, G: LieGroup<N>, const N: usize>(
        &self,
        e: &'e Evaluation<G, N>,
        node: &Node<G, N>,
    ) -> Option<&'e Node<G, N>> {
        if self.choices.shown.contains_key(&node.name)
            || node.role != Role::Output
            || node.step.is_some()
            || self.rotation_only
        {
            return None;
        }
        let (root, parent) = (self.root?, parent_frame(&node.name)?);
        let via = format!("{root}_from_{parent}");
        e.nodes
            .iter()
            .rev()
            .find(|n| n.name == via && n.step.is_none() && self.node(n))
    }
}

/// A result `a_from_c` relative to a frame `a` that is not the root, drawn where it puts `c`
/// seen from `a`'s mean: moved by the mean of `via` = `root_from_a`, μ_via · X, a known change
/// of frame of the picture ([`change_frame_left`](crate::propagate::first_order::change_frame_left):
/// a right-form Σ is unchanged, so the spread drawn is the result's own), and said so in the
/// legend and the text panel.
fn draw_through<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    via: &Node<G, N>,
    settings: &DrawSettings,
) {
    use crate::propagate::first_order::change_frame_left;
    let by = via.nominal;
    let mut moved = node.clone();
    moved.nominal = by.compose(&node.nominal);
    for estimate in &mut moved.estimates {
        estimate.result.pose = change_frame_left(&by, &estimate.result.pose).pose;
    }
    moved.particles = node
        .particles
        .as_ref()
        .map(|x| std::sync::Arc::new(x.iter().map(|g| by.compose(g)).collect()));
    draw_node(p, &moved, settings);
    let (name, from) = (&node.name, &via.name);
    let child = node.name.split_once("_from_").map_or("", |(_, c)| c);
    p.scene
        .add_legend(legend::axes(&format!("{name}, drawn from {from}'s mean")));
    let _ = write!(
        p.scene.description_markdown,
        "**`{name}`** is relative to its own frame, so it is drawn where it puts `{child}` seen from          `{from}`'s mean: μ_{from} · {name}, a known change of frame of the picture (its right-form Σ          is unchanged: the spread drawn is `{name}`'s own).\n\n"
    );
}

/// The parent frame of a name `a_from_b` (`a`), if it follows that convention.
fn parent_frame(name: &str) -> Option<&str> {
    name.split_once("_from_").map(|(parent, _)| parent)
}

/// A plan's scene: its poses (each item carrying its node as origin), paths, links, a graph's
/// optimised picture, points, Euler frames, then the plots and the views over what was drawn.
fn build<G: LieGroup<N>, const N: usize>(e: &Evaluation<G, N>, settings: &DrawSettings) -> Scene {
    let mut p = Painter::for_plan(e, settings, text::description(e, settings));
    p.scene.confidence = Some(settings.confidence);
    let choices = &settings.choices;
    p.scene.planar = choices.top_view.unwrap_or(G::KIND.is_planar());
    let shown = Shown::new(e, choices);
    if choices.layout.is_none() {
        p.layout = default_layout(e, &shown);
    }
    // A graph's drawn vertex estimates (its fixed poses, hundreds) are one batch of frames.
    let mut vertices = Vec::new();
    for node in &e.nodes {
        // Every item of a node carries it as its origin (an undrawable one is reported there).
        p.origin = Some(Origin::Node(node.name.clone()));
        if shown.node(node) {
            if e.graph.is_some() && node.role == Role::Fixed {
                vertices.push(node.nominal.to_se3());
            } else {
                draw_node(&mut p, node, settings);
            }
        } else if let Some(via) = shown.through(e, node) {
            draw_through(&mut p, node, via, settings);
        }
        p.origin = None;
    }
    if choices.trajectories {
        extras::trajectories(&mut p, e);
    }
    if choices.axes {
        graph::vertex_frames(&mut p, &vertices);
    }
    extras::links(&mut p, e, &choices.links);
    let zooms = match &e.graph {
        Some(g) => graph::draw_optimized(&mut p, g),
        None => Vec::new(),
    };
    for point in &e.points {
        p.origin = Some(Origin::Node(point.name.clone()));
        extras::draw_point(&mut p, point, choices.clouds);
        p.origin = None;
    }
    extras::euler_frames(&mut p, e, settings);
    let (plots, series) = plots::plots(e);
    p.scene.plots = plots;
    p.scene.series = series;
    if let Some(g) = &e.graph {
        graph::sigma_plot(&mut p.scene, g);
    }
    let plan = views::ViewInputs {
        poses: &p.methods,
        rotation_only: G::KIND.is_rotation_only(),
        top: p.scene.planar,
        layout: p.layout,
        camera: choices.camera,
    };
    if e.graph.is_some() {
        p.scene.views = views::before_after(&p.scene, &plan, &paths::optimized(), &zooms);
        tags::fit_tags(&mut p.scene, views::FOV_Y);
    } else {
        p.scene.views = views::views(&p.scene, &plan);
    }
    if let Some(note) = views::note(&p.scene.views) {
        p.scene.description_markdown.push_str(&note);
    }
    p.scene
}

/// The layout when the input does not choose one: by the group, the number of drawn poses
/// (fixed ones left out) and the most analytic methods one of them shows.
fn default_layout<G: LieGroup<N>, const N: usize>(e: &Evaluation<G, N>, shown: &Shown) -> Layout {
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
    views::default_layout(G::KIND.is_rotation_only(), names.len(), most_methods)
}

/// An input's own description, as the text panel and `report --json` (`meta.description`)
/// show it: the file's words, or for a pose graph the words written from its facts
/// ([`DrawChoices::graph`]) followed by any words added to it (a live edit's note).
///
/// ```
/// let input = posecov::input::graph::read_text("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\n", "a.g2o").unwrap().1;
/// let d = posecov::draw::input_description(&input.about, &input.draw);
/// assert!(d.starts_with("**2 vertices, 1 edges** (SE(2))."), "{d}");
/// ```
pub fn input_description(about: &About, choices: &DrawChoices) -> String {
    match &choices.graph {
        Some(facts) => graph::file_description(facts) + &about.description,
        None => about.description.clone(),
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
            e.trajectories
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
