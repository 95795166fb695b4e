//! One evaluated node drawn: its frame, every method's regions (ellipsoid, banana,
//! orientation spray) on one side, and its Monte Carlo particles.

use super::*;
use crate::uncertain::{Region, UncertainPose};

/// Colour of the Monte Carlo heading arrows of planar poses (light red).
const HEADING_COLOR: Color = Color::rgb(255, 120, 120);

/// Draws `node`: its nominal frame, then (unless fixed) every method's regions on the main
/// method's side — only the main method's ellipsoid between the detailed steps — then says
/// which ellipses coincide, and draws its Monte Carlo particles.
pub(super) fn draw_node<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    settings: &DrawSettings,
) {
    let choices = &settings.choices;
    if choices.axes {
        nominal_frame(p, node, choices.labels);
    }
    if node.role == Role::Fixed {
        return;
    }
    let primary = primary_method(node);
    let primary_estimate = node
        .estimates
        .iter()
        .find(|e| Some(e.result.method) == primary);
    if !detailed(&settings.steps, node) {
        // Between detailed steps only the (light) frame and the primary ellipsoid are logged,
        // so the step slider still shows the growth.
        if let Some(e) = primary_estimate
            && choices.ellipsoids
            && !p.kind.is_rotation_only()
        {
            let who = e.result.method.label().to_owned();
            cartesian_legend(p, who, e.result.method, "");
            p.region_ellipsoid(
                &paths::method(&node.name, e.result.method.slug()),
                at_step(node.step),
                &e.result.pose,
                e.result.method.color(),
            );
        }
        return;
    }
    // Every method's regions on the main method's side: a banana is a 3-D slice of the tangent
    // ellipsoid along its largest principal directions, which depend on the side, so one
    // Gaussian read on two sides would look like two.
    let side = primary_estimate.map(|e| e.result.pose.side());
    // The Cartesian ellipses drawn for this pose.
    let mut cartesian: Vec<Drawn> = Vec::new();
    for evaluated in &node.estimates {
        let method = evaluated.result.method;
        if method == Method::MonteCarlo && node.particles.is_some() {
            continue; // the cloud itself shows Monte Carlo
        }
        let pose = side.map_or(evaluated.result.pose, |s| evaluated.result.pose.to_side(s));
        let shown = DrawnAs {
            estimate: record_method(p, node, method, Some(method) == primary),
            primary: Some(method) == primary,
        };
        cartesian.extend(regions(p, node, evaluated, &pose, shown, choices));
    }
    coinciding(p, &node.name, &cartesian, &node.coinciding_ellipses());
    if let Some(particles) = &node.particles {
        draw_particles(p, node, particles, None, choices);
    }
}

/// A pose's nominal frame as axes, with its name when `labels`.
fn nominal_frame<G: LieGroup<N>, const N: usize>(p: &mut Painter, node: &Node<G, N>, labels: bool) {
    let pose3 = node.nominal.to_se3();
    p.scene.add_legend(legend::axes("pose frames"));
    p.push(
        paths::pose_frame(&node.name),
        node.step,
        ItemKind::Frame(Frame {
            translation: v3(pose3.translation()),
            rotation: pose3.rotation().to_quaternion_xyzw(),
            axis_length: p.axis_length,
            label: labels.then(|| node.name.clone()),
            tag: None,
        }),
    );
}

/// Records that `method`'s estimate of `node` is drawn (the main one, or one of the others:
/// what the views show and hide); returns what it is drawn as (an input's own Gaussian is
/// given, not computed by a method).
fn record_method<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    method: Method,
    is_primary: bool,
) -> views::Estimate {
    let estimate = if node.role == Role::Input && method == Method::Exact {
        views::Estimate::Given
    } else {
        views::Estimate::Method(method)
    };
    let drawn = match p.methods.iter().position(|m| m.pose == node.name) {
        Some(i) => &mut p.methods[i],
        None => {
            p.methods.push(views::PoseMethods {
                pose: node.name.clone(),
                ..Default::default()
            });
            &mut p.methods.last_mut().expect("just pushed")
        }
    };
    if is_primary {
        drawn.main = Some(estimate);
    } else if method != Method::MonteCarlo && !drawn.others.contains(&estimate) {
        drawn.others.push(estimate);
    }
    estimate
}

/// How one estimate of a pose is drawn: as what, and whether it is the pose's main method.
#[derive(Clone, Copy)]
struct DrawnAs {
    /// What it is drawn as.
    estimate: views::Estimate,
    /// The pose's main method (its banana is a mesh, its ellipsoid drawn).
    primary: bool,
}

/// One estimate's regions (`pose`: on the main method's side): the Cartesian ellipsoid (the
/// main method's, to contrast with its banana, and the vector-space baseline's: a Gaussian in
/// (x, y, θ) is exactly that ellipse), the Exp-mapped region (a mesh for the main method or
/// every method of a per-method layout, principal outlines otherwise) and, for rotations, each
/// axis tip's region. Returns the Cartesian ellipse drawn, if one was.
fn regions<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    evaluated: &crate::eval::Estimate<G, N>,
    pose: &UncertainPose<G, N>,
    shown: DrawnAs,
    choices: &DrawChoices,
) -> Option<Drawn> {
    let method = evaluated.result.method;
    let rotation_only = p.kind.is_rotation_only();
    let timing = at_step(node.step);
    let base = paths::method(&node.name, shown.estimate.segment());
    let color = method.color();
    let who = legend::who(shown.estimate, method.label());
    let mut cartesian = None;
    if !rotation_only && choices.ellipsoids && (shown.primary || method == Method::VectorSpace) {
        let ellipse_held = held(node, evaluated, &[Region::Cartesian, Region::VectorSpace]);
        cartesian_legend(p, who.clone(), method, &ellipse_held);
        if pose.position_cov_in_world_3d().is_some() {
            cartesian = Some(Drawn {
                method,
                who: who.clone(),
                held: ellipse_held,
            });
        }
        p.region_ellipsoid(&base, timing, pose, color);
    }
    let region = p.confidence().to_string();
    if choices.bananas && !rotation_only && method != Method::VectorSpace {
        let point_of = |x: &G| *x.to_se3().translation();
        if shown.primary || p.layout == Layout::PerMethod {
            p.legend_with(
                format!("{who}: Exp-mapped {region} region"),
                held(node, evaluated, &[Region::Tangent]),
                color,
                Swatch::Region,
            );
            p.region_banana(&base, timing, pose, color, point_of);
        } else {
            p.legend(
                format!("{who}: Exp-mapped {region} region, principal outlines"),
                color,
                Swatch::Line,
            );
            p.region_outlines(
                &paths::child(&base, "banana_outline"),
                timing,
                pose,
                color,
                point_of,
            );
        }
    }
    if choices.orientation && rotation_only {
        p.legend(
            format!("{who}: {region} region of each axis tip"),
            color,
            Swatch::Line,
        );
        for (k, axis) in ["axis_x", "axis_y", "axis_z"].iter().enumerate() {
            let len = p.axis_length;
            let path = paths::child(&base, axis);
            p.region_outlines(&path, timing, pose, color, move |x| {
                let s = x.to_se3();
                s.translation() + s.rotation().act(&(Vector3::ith(k, 1.0) * len))
            });
        }
    }
    cartesian
}

/// A Cartesian ellipse drawn for a pose.
struct Drawn {
    /// Its method.
    method: Method,
    /// Whose it is, in the legend's words.
    who: String,
    /// The share of samples its legend entry states.
    held: String,
}

/// Says when the vector-space ellipse and another drawn method's Cartesian ellipse of one pose
/// are the same (`same`: the evaluation's [`Node::coinciding_ellipses`]): one hides the other
/// exactly, and a reader would conclude the hidden one is missing. Once per pose name, in the
/// text panel, and in the legend in place of the hidden ellipse's own entry (one entry per
/// line drawn).
fn coinciding(p: &mut Painter, pose: &str, drawn: &[Drawn], same: &[Method]) {
    if !drawn.iter().any(|d| d.method == Method::VectorSpace) {
        return;
    }
    for Drawn { method, who, held } in drawn.iter().filter(|d| d.method != Method::VectorSpace) {
        if !same.contains(method) {
            continue;
        }
        let region = p.confidence().to_string();
        let own = cartesian_label(p, who, *method);
        let label = format!(
            "{who}: Cartesian {region} ellipse = the vector-space one here (same matrix; drawn under it)"
        );
        let color = method.color().with_alpha(255);
        match p
            .scene
            .legend
            .iter_mut()
            .find(|e| e.label == own && e.detail == *held && e.color == color)
        {
            Some(entry) => entry.label = label,
            None => p.legend_with(label, held.clone(), method.color(), Swatch::Dashed),
        }
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

/// The legend entry of a method's Cartesian position ellipse (the vector-space baseline's is
/// its whole Gaussian in (x, y[, z])), with the share of samples it holds (`held`).
fn cartesian_legend(p: &mut Painter, who: String, method: Method, held: &str) {
    let label = cartesian_label(p, &who, method);
    p.legend_with(label, held.to_owned(), method.color(), Swatch::Dashed);
}

/// The words of a method's Cartesian ellipse in the legend.
fn cartesian_label(p: &Painter, who: &str, method: Method) -> String {
    let region = p.confidence().to_string();
    if method == Method::VectorSpace {
        format!("{who}: {region} ellipse")
    } else {
        format!("{who}: Cartesian {region} ellipse (first-order position)")
    }
}

/// The share of the Monte Carlo samples an output's region holds, for its legend entry
/// (", holds 70.1 % of map_from_camera's samples"; [`crate::eval::consistency`]): only for
/// single results, whose entries name one pose's numbers.
fn held<G: LieGroup<N>, const N: usize>(
    node: &Node<G, N>,
    estimate: &crate::eval::Estimate<G, N>,
    regions: &[Region],
) -> String {
    if node.role != Role::Output || node.step.is_some() {
        return String::new();
    }
    let Some(c) = estimate.consistency.as_ref() else {
        return String::new();
    };
    regions
        .iter()
        .find_map(|r| c.region(*r))
        .map_or(String::new(), |c| {
            format!(
                "; holds {:.1} % of {}'s samples",
                100.0 * c.inside,
                node.name
            )
        })
}

pub(super) fn draw_particles<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    particles: &[G],
    part: Option<usize>,
    choices: &DrawChoices,
) {
    let base = paths::monte_carlo(&node.name);
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
            paths::child(&base, &format!("cloud{suffix}")),
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
            paths::child(&base, "headings"),
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
            paths::child(&base, "triads"),
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
                paths::child(&base, &format!("{name}{suffix}")),
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
