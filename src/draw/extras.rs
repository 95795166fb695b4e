//! What a plan's scene draws besides its poses' regions: the propagated paths, the lines the
//! input asks for between poses, uncertain points and an Euler integration's frames.

use std::collections::BTreeMap;

use super::painter::Painter;
use super::{DrawSettings, legend, point_cloud_item, shapes, v3};
use crate::eval::{Evaluation, PathKind, PointEstimate, PointNode};
use crate::lie::LieGroup;
use crate::plan::choices::Link;
use crate::scene::{self, Arrows, Ellipsoids, FillMode, ItemKind, LineStrips, Swatch, Vec3, paths};
use crate::uncertain::Method;

/// The propagated paths: the nominal one and the Monte Carlo samples', as lines.
pub(super) fn trajectories<G: LieGroup<N>, const N: usize>(p: &mut Painter, e: &Evaluation<G, N>) {
    let radius = 0.004 * p.extent.max(0.25);
    for path in &e.trajectories {
        let (name, color, what) = match path.kind {
            PathKind::Nominal => (paths::nominal(&path.output), scene::NOMINAL, "nominal path"),
            PathKind::Sample(i) => (
                paths::sample_path(&path.output, i),
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

/// An uncertain point: each method's ellipsoid, and its Monte Carlo points when `clouds`.
pub(super) fn draw_point(p: &mut Painter, point: &PointNode, clouds: bool) {
    for PointEstimate { method, mean, cov } in &point.estimates {
        p.legend(
            format!(
                "{}: {} ellipsoid of the point",
                method.label(),
                p.confidence()
            ),
            method.color(),
            Swatch::Dashed,
        );
        let shape = shapes::ellipsoid_of(mean, cov, p.confidence().radius(3));
        p.push(
            paths::child(&paths::method(&point.name, method.slug()), "ellipsoid"),
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
    if let (Some(particles), true) = (&point.particles, clouds) {
        p.legend(
            format!("Monte Carlo points ({})", particles.len()),
            Method::MonteCarlo.color(),
            Swatch::Dots,
        );
        p.push(
            paths::child(&paths::monte_carlo(&point.name), "cloud"),
            None,
            point_cloud_item(particles.clone()),
        );
    }
}

/// An Euler integration's rotation matrix columns as arrows, at the steps drawn in detail.
pub(super) fn euler_frames<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    e: &Evaluation<G, N>,
    settings: &DrawSettings,
) {
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
                paths::euler_axis(&frame.output, k),
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
}

/// The lines the input asks for between two poses (a graph's loop closures), at
/// `world/links`, between the poses' nominal positions.
pub(super) fn links<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    e: &Evaluation<G, N>,
    links: &[Link],
) {
    let position = |name: &str| {
        e.nodes
            .iter()
            .find(|n| n.name == name)
            .map(|n| v3(n.nominal.to_se3().translation()))
    };
    let strips: Vec<Vec<Vec3>> = links
        .iter()
        .filter_map(|l| Some(vec![position(&l.from)?, position(&l.to)?]))
        .collect();
    if !strips.is_empty() {
        p.legend("links between poses".to_owned(), scene::LINK, Swatch::Line);
        p.push(
            paths::links(),
            None,
            ItemKind::LineStrips(LineStrips {
                strips,
                color: scene::LINK,
                radius: p.link_radius(),
            }),
        );
    }
}
