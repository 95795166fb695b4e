//! The painter: the scene being drawn, the confidence of its regions and the sizes every
//! helper shares, and the one place a shape's geometry ([`super::shapes`]) is placed on an
//! entity path at a time.

use nalgebra::Vector3;

use super::{DrawSettings, legend, scene_extent, views};
use crate::eval::{Evaluation, Node};
use crate::lie::{GroupKind, LieGroup};
use crate::plan::StepPolicy;
use crate::plan::choices::Layout;
use crate::scene::{
    Color, Ellipsoids, FillMode, ItemKind, LineStrips, Origin, Scene, SceneItem, Surface, Swatch,
    Timing, paths,
};
use crate::uncertain::{Confidence, UncertainPose};

use super::shapes;

/// Context shared by the drawing helpers of one scene.
pub(super) struct Painter {
    pub scene: Scene,
    /// The probability inside every drawn region.
    pub confidence: Confidence,
    pub kind: GroupKind,
    pub axis_length: f64,
    /// Size of the drawing, metres ([`scene_extent`]).
    pub extent: f64,
    /// How the 3-D views split methods and poses (decided before drawing: one view per method
    /// draws every method's banana as a surface).
    pub layout: Layout,
    /// Per drawn uncertain pose, the methods drawn for it (for the views).
    pub methods: Vec<views::PoseMethods>,
    /// What the items placed now are drawn from (a robot log's topic and message), stamped on
    /// each of them ([`SceneItem::origin`]); `None` for a plan's scene.
    pub origin: Option<Origin>,
}

/// A step's timing: on the step timeline, or static for results without a step.
pub(super) fn at_step(step: Option<u64>) -> Timing {
    step.map_or(Timing::Static, |k| Timing::Step(k as i64))
}

/// Whether a node's step is drawn in full (clouds, surfaces), not only its ellipsoid.
pub(super) fn detailed<G: LieGroup<N>, const N: usize>(
    steps: &StepPolicy,
    node: &Node<G, N>,
) -> bool {
    node.step
        .is_none_or(|k| steps.detailed(k, node.last_step.unwrap_or(k)))
}

impl Painter {
    /// A painter for a plan's evaluation, sized by what it draws.
    pub(super) fn for_plan<G: LieGroup<N>, const N: usize>(
        e: &Evaluation<G, N>,
        settings: &DrawSettings,
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
            scene: Scene::new(
                super::words::fill(&settings.about.title, e, settings.confidence),
                description,
            ),
            confidence: settings.confidence,
            kind: G::KIND,
            axis_length,
            extent,
            methods: Vec::new(),
            layout: settings.choices.layout.unwrap_or(Layout::Main),
            origin: None,
        }
    }

    pub(super) fn confidence(&self) -> Confidence {
        self.confidence
    }

    /// Adds a legend entry (once per label and colour).
    pub(super) fn legend(&mut self, label: String, color: Color, swatch: Swatch) {
        self.legend_with(label, String::new(), color, swatch);
    }

    /// Adds a legend entry with what the run measured about it ([`LegendEntry::detail`](crate::scene::LegendEntry::detail)).
    pub(super) fn legend_with(
        &mut self,
        label: String,
        detail: String,
        color: Color,
        swatch: Swatch,
    ) {
        self.scene
            .add_legend(legend::entry(label, detail, color, swatch));
    }

    /// An item on the step timeline (static without a step).
    pub(super) fn push(&mut self, path: String, step: Option<u64>, kind: ItemKind) {
        self.place(path, at_step(step), kind);
    }

    /// An item at a time.
    pub(super) fn place(&mut self, path: String, timing: Timing, kind: ItemKind) {
        let mut item = SceneItem::new(path, timing, kind);
        item.origin.clone_from(&self.origin);
        self.scene.push(item);
    }

    /// A pose's Cartesian position region ([`shapes::position_region`]) at `base/ellipsoid`.
    pub(super) fn region_ellipsoid<G: LieGroup<N>, const N: usize>(
        &mut self,
        base: &str,
        timing: Timing,
        pose: &UncertainPose<G, N>,
        color: Color,
    ) {
        let Some(shape) = shapes::position_region(pose, self.confidence) else {
            return;
        };
        let line_radius = 0.002 * self.axis_length / 0.15;
        self.place(
            paths::child(base, "ellipsoid"),
            timing,
            ItemKind::Ellipsoids(Ellipsoids {
                shapes: vec![shape],
                color,
                fill: FillMode::MajorWireframe,
                line_radius,
                label: None,
            }),
        );
    }

    /// A pose's Exp-mapped region: the surface ([`shapes::banana_surface`]) at `base/banana`
    /// and its principal outlines at `base/banana_outline`.
    pub(super) fn region_banana<G: LieGroup<N>, const N: usize>(
        &mut self,
        base: &str,
        timing: Timing,
        pose: &UncertainPose<G, N>,
        color: Color,
        point_of: impl Fn(&G) -> Vector3<f64> + Copy,
    ) {
        let (vertices, triangles) = shapes::banana_surface(pose, self.confidence, point_of);
        let surface = Surface {
            vertices,
            triangles,
            normals: Vec::new(),
            color: color.with_alpha(70),
        }
        .with_computed_normals();
        self.place(
            paths::child(base, "banana"),
            timing,
            ItemKind::Surface(surface),
        );
        self.region_outlines(
            &paths::child(base, "banana_outline"),
            timing,
            pose,
            color,
            point_of,
        );
    }

    /// The principal outlines of a pose's Exp-mapped region ([`shapes::outline_strips`]) at
    /// `path`, thin: they sit on top of clouds and surfaces.
    pub(super) fn region_outlines<G: LieGroup<N>, const N: usize>(
        &mut self,
        path: &str,
        timing: Timing,
        pose: &UncertainPose<G, N>,
        color: Color,
        point_of: impl Fn(&G) -> Vector3<f64>,
    ) {
        let strips = shapes::outline_strips(pose, self.confidence, point_of);
        let radius = self.outline_radius();
        self.place(
            path.to_owned(),
            timing,
            ItemKind::LineStrips(LineStrips {
                strips,
                color,
                radius,
            }),
        );
    }

    /// The radius of a line between poses (links, a graph's trajectory and loop closures,
    /// its vertex frames): 0.3 % of the scene's extent, or of 0.25 m when it is smaller.
    pub(super) fn link_radius(&self) -> f64 {
        0.003 * self.extent.max(0.25)
    }

    /// The line radius of region outlines.
    pub(super) fn outline_radius(&self) -> f64 {
        0.004 * self.axis_length.min(0.5)
    }
}
