//! One evaluated node drawn: its frame, every method's regions (ellipsoid, banana,
//! orientation spray) on one side, and its Monte Carlo particles.

use super::*;
use crate::uncertain::Region;

/// Colour of the Monte Carlo heading arrows of planar poses (light red).
const HEADING_COLOR: Color = Color::rgb(255, 120, 120);

pub(super) fn draw_node<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    node: &Node<G, N>,
    settings: &DrawSettings,
) {
    let choices = &settings.choices;
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
            format!("{WORLD}/{}/frame", node.name),
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
    let timing = at_step(node.step);
    if !detailed(&settings.steps, node) {
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
            cartesian_legend(p, who, e.result.method, "");
            p.region_ellipsoid(
                &format!("{WORLD}/{}/{}", node.name, e.result.method.slug()),
                timing,
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
    // The Cartesian ellipses drawn for this pose.
    let mut cartesian: Vec<Drawn> = Vec::new();
    for evaluated in &node.estimates {
        let pose = side.map_or(evaluated.result.pose, |s| evaluated.result.pose.to_side(s));
        let method = evaluated.result.method;
        if method == Method::MonteCarlo && node.particles.is_some() {
            continue; // the cloud itself shows Monte Carlo
        }
        let is_primary = Some(method) == primary;
        // An input's own Gaussian is given, not computed by a method.
        let estimate = if node.role == Role::Input && method == Method::Exact {
            views::Estimate::Given
        } else {
            views::Estimate::Method(method)
        };
        let segment = estimate.segment();
        let drawn = match p.methods.iter().position(|(n, _)| *n == node.name) {
            Some(i) => &mut p.methods[i].1,
            None => {
                p.methods
                    .push((node.name.clone(), views::PoseMethods::default()));
                &mut p.methods.last_mut().expect("just pushed").1
            }
        };
        if is_primary {
            drawn.main = Some(estimate);
        } else if method != Method::MonteCarlo && !drawn.others.contains(&estimate) {
            drawn.others.push(estimate);
        }
        let base = format!("{WORLD}/{}/{segment}", node.name);
        let color = method.color();
        // The Cartesian ellipsoid: the primary method's (to contrast with its banana) and the
        // vector-space baseline's (a Gaussian in (x, y, θ) is exactly that ellipse).
        let who = legend::who(estimate, method.label());
        if !rotation_only && ellipsoids && (is_primary || method == Method::VectorSpace) {
            let ellipse_held = held(node, evaluated, &[Region::Cartesian, Region::VectorSpace]);
            cartesian_legend(p, who.clone(), method, &ellipse_held);
            if let Some(cov) = pose.position_cov_in_world_3d() {
                let centre = v3(pose.mean().to_se3().translation());
                cartesian.push((method, who.clone(), centre, cov, ellipse_held));
            }
            p.region_ellipsoid(&base, timing, &pose, color);
        }
        let region = p.confidence().to_string();
        if bananas && !rotation_only && method != Method::VectorSpace {
            let point_of = |x: &G| *x.to_se3().translation();
            if is_primary || p.layout == Layout::PerMethod {
                p.legend_with(
                    format!("{who}: Exp-mapped {region} region"),
                    held(node, evaluated, &[Region::Tangent]),
                    color,
                    Swatch::Region,
                );
                p.region_banana(&base, timing, &pose, color, point_of);
            } else {
                p.legend(
                    format!("{who}: Exp-mapped {region} region, principal outlines"),
                    color,
                    Swatch::Line,
                );
                p.region_outlines(
                    &format!("{base}/banana_outline"),
                    timing,
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
                p.region_outlines(&path, timing, &pose, color, move |x| {
                    let s = x.to_se3();
                    s.translation() + s.rotation().act(&(Vector3::ith(k, 1.0) * len))
                });
            }
        }
    }
    coinciding(p, &node.name, &cartesian);
    if let Some(particles) = &node.particles {
        draw_particles(p, node, particles, None, choices);
    }
}

/// A Cartesian ellipse drawn for a pose: (method, who, centre, covariance, the share of
/// samples its legend entry states).
type Drawn = (Method, String, Vec3, nalgebra::Matrix3<f64>, String);

/// Says when the vector-space ellipse and another method's Cartesian ellipse of one pose are
/// the same (same centre and matrix to 1e-9 relative): one hides the other exactly, and a
/// reader would conclude the hidden one is missing. Once per pose name, in the text panel, and
/// in the legend in place of the hidden ellipse's own entry (one entry per line drawn).
fn coinciding(p: &mut Painter, pose: &str, drawn: &[Drawn]) {
    let Some((_, _, c0, m0, _)) = drawn.iter().find(|d| d.0 == Method::VectorSpace) else {
        return;
    };
    for (method, who, c, m, held) in drawn.iter().filter(|d| d.0 != Method::VectorSpace) {
        let scale = m0.amax().max(f64::MIN_POSITIVE);
        let same_matrix = (m - m0).amax() <= 1e-9 * scale;
        let same_centre = (0..3).all(|k| (c[k] - c0[k]).abs() <= 1e-9 * (1.0 + c0[k].abs()));
        if !(same_matrix && same_centre) {
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
    let base = format!("{WORLD}/{}/monte_carlo", node.name);
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
