//! Plots over the `step` timeline: what each quantity is, its unit and frame (as data, for
//! the sink's views), and one line per method.

use std::collections::BTreeSet;

use crate::eval::{Evaluation, Node, Role};
use crate::lie::LieGroup;
use crate::plan::OpKind;
use crate::scene::{self, Corner, Plot, PlotId, ScalarSeries};
use crate::uncertain::{Method, Region};

/// A kind of plot: entity id, title (what and in which frame), unit, and the corner its legend
/// sits in: where its lines do not go.
#[derive(Clone, Copy, PartialEq, Eq)]
struct PlotKind {
    id: &'static str,
    title: &'static str,
    unit: &'static str,
    legend: Corner,
}

const TRACE_POSITION: PlotKind = PlotKind {
    id: "trace_of_position_covariance_m_body_frame",
    // Short enough that a narrow view's title still shows the unit.
    title: "trace Σ_ρρ, body frame",
    unit: "m²",
    legend: Corner::LeftTop,
};
const TRACE_ROTATION: PlotKind = PlotKind {
    id: "trace_of_rotation_covariance_rad",
    title: "trace Σ_θθ",
    unit: "rad²",
    legend: Corner::LeftTop,
};
const ALONG_TRACK: PlotKind = PlotKind {
    id: "along_track_variance_x_x_left_form_m",
    title: "along-track Σ_ρxρx, world",
    unit: "m²",
    legend: Corner::LeftTop,
};
const ORTHOGONALITY: PlotKind = PlotKind {
    id: "orthogonality_error_max_r_t_r_i",
    title: "max |RᵗR − I|",
    unit: "",
    legend: Corner::LeftTop,
};

const COVERAGE: PlotKind = PlotKind {
    id: "share_of_monte_carlo_samples_inside_the_tangent_region",
    title: "samples inside the drawn region",
    unit: "",
    legend: Corner::LeftBottom,
};
const ANEES: PlotKind = PlotKind {
    id: "anees_of_monte_carlo_samples",
    title: "ANEES of the samples",
    unit: "",
    legend: Corner::LeftTop,
};

/// One line of a plot.
pub(super) struct Line {
    kind: PlotKind,
    /// The method (colour, legend); `None`: a line named by `label`.
    method: Option<Method>,
    /// Legend label.
    pub(super) label: String,
    /// A line that is not a method's: what the others are judged against (drawn in
    /// [`scene::REFERENCE`]), else the nominal colour.
    reference: bool,
    /// (step, value).
    pub(super) points: Vec<(i64, f64)>,
    /// The end of its entity path when two lines share a legend label (a band's two edges:
    /// one legend entry, two lines).
    tail: Option<&'static str>,
}

/// Adds each method's value at `step` to its line (a new line per method).
fn add(
    lines: &mut Vec<Line>,
    kind: PlotKind,
    step: i64,
    values: impl IntoIterator<Item = (Method, f64)>,
) {
    for (method, value) in values {
        match lines
            .iter_mut()
            .find(|l| l.kind == kind && l.method == Some(method))
        {
            Some(line) => line.points.push((step, value)),
            None => lines.push(Line {
                kind,
                method: Some(method),
                label: method.label().to_owned(),
                reference: false,
                points: vec![(step, value)],
                tail: None,
            }),
        }
    }
}

/// The outputs of propagations, in evaluation order.
fn propagations<G: LieGroup<N>, const N: usize>(e: &Evaluation<G, N>, op: OpKind) -> Vec<&str> {
    let mut seen = BTreeSet::new();
    e.nodes
        .iter()
        .filter(|n| n.op == Some(op) && n.step.is_some() && n.role == Role::Output)
        .filter_map(|n| seen.insert(n.name.as_str()).then_some(n.name.as_str()))
        .collect()
}

fn steps_of<'e, G: LieGroup<N>, const N: usize>(
    e: &'e Evaluation<G, N>,
    name: &'e str,
) -> impl Iterator<Item = &'e Node<G, N>> {
    e.nodes
        .iter()
        .filter(move |n| n.name == name && n.step.is_some())
}

/// Trace of the position covariance (rotation groups: of the rotation covariance), right
/// form, per method and step.
fn trace_lines<G: LieGroup<N>, const N: usize>(
    e: &Evaluation<G, N>,
    name: &str,
    lines: &mut Vec<Line>,
) {
    let rot = G::rotation_range();
    let (kind, block) = if G::KIND.is_rotation_only() {
        (TRACE_ROTATION, rot)
    } else {
        (TRACE_POSITION, 0..rot.start)
    };
    for node in steps_of(e, name) {
        let values = node.estimates.iter().map(|est| {
            let cov = est.result.pose.cov_right();
            (est.result.method, block.clone().map(|i| cov[(i, i)]).sum())
        });
        add(lines, kind, node.step.unwrap_or(0) as i64, values);
    }
}

/// Σ_ρxρx in the left (world) form per method and step: the along-track variance that
/// second-order compounding misses (Barfoot & Furgale 2014, Fig. 2). Monte Carlo is the
/// uncentred E[ξξᵀ] about the propagated mean, as in their experiments.
fn along_track_lines<G: LieGroup<N>, const N: usize>(
    e: &Evaluation<G, N>,
    name: &str,
) -> Vec<Line> {
    let mut lines = Vec::new();
    let values: Vec<_> = e
        .along_track()
        .into_iter()
        .filter(|a| a.output == name)
        .collect();
    let mut steps: Vec<u64> = values.iter().map(|a| a.step).collect();
    steps.dedup();
    for step in steps {
        let at_step = values
            .iter()
            .filter(|a| a.step == step)
            .map(|a| (a.method, a.variance_m2));
        add(&mut lines, ALONG_TRACK, step as i64, at_step);
    }
    // Monte Carlo's last value with its standard error in its legend entry, and its value ± 2
    // standard errors (batch means) as a band: how far its line is to be trusted.
    if let Some(last) = values
        .iter()
        .rfind(|a| a.method == Method::MonteCarlo && a.stderr_m2.is_some())
        && let Some(line) = lines
            .iter_mut()
            .find(|l| l.kind == ALONG_TRACK && l.method == Some(Method::MonteCarlo))
    {
        line.label = format!(
            "Monte Carlo (step {}: {} m²)",
            last.step,
            super::words::plus_minus(last.variance_m2, last.stderr_m2, 4)
        );
    }
    let band = |sign: f64| -> Vec<(i64, f64)> {
        values
            .iter()
            .filter_map(|a| Some((a.step as i64, a.variance_m2 + sign * 2.0 * a.stderr_m2?)))
            .collect()
    };
    for (sign, edge) in [(-1.0, "low"), (1.0, "high")] {
        let points = band(sign);
        if !points.is_empty() {
            lines.push(Line {
                kind: ALONG_TRACK,
                method: None,
                label: "Monte Carlo ± 2 standard errors".to_owned(),
                reference: true,
                points,
                tail: Some(edge),
            });
        }
    }
    lines
}

/// Per method and step, the share of the Monte Carlo samples inside the tangent region drawn
/// at the confidence (the vector-space method: inside its position ellipse) beside the
/// confidence claimed, and their ANEES beside its 95 % band
/// ([`crate::eval::consistency`]): where linearisation breaks, the lines leave p and the band.
fn consistency_lines<G: LieGroup<N>, const N: usize>(
    e: &Evaluation<G, N>,
    name: &str,
    lines: &mut Vec<Line>,
) {
    let mut claimed = Vec::new();
    let mut band: [Vec<(i64, f64)>; 2] = Default::default();
    for node in steps_of(e, name) {
        let step = node.step.unwrap_or(0) as i64;
        let measured = node
            .estimates
            .iter()
            .filter_map(|est| Some((est.result.method, est.consistency.as_ref()?)));
        let inside: Vec<(Method, f64)> = measured
            .clone()
            .filter_map(|(m, c)| {
                let region = c
                    .region(Region::Tangent)
                    .or(c.region(Region::VectorSpace))?;
                Some((m, region.inside))
            })
            .collect();
        // The confidence claimed only beside a region that holds samples: a singular Σ (a
        // direction with no variance, Barfoot's yaw-only noise) has no coverage, and a plot of
        // the claim alone would show no data.
        let covered = !inside.is_empty();
        add(lines, COVERAGE, step, inside);
        add(
            lines,
            ANEES,
            step,
            measured
                .clone()
                .filter_map(|(m, c)| Some((m, c.anees?.value))),
        );
        if let Some((_, c)) = measured.clone().next().filter(|_| covered) {
            claimed.push((step, c.confidence.get()));
        }
        if let Some(a) = measured.filter_map(|(_, c)| c.anees).find(|a| a.dof == N) {
            band[0].push((step, a.band[0]));
            band[1].push((step, a.band[1]));
        }
    }
    if !claimed.is_empty() {
        lines.push(Line {
            kind: COVERAGE,
            method: None,
            label: "confidence p drawn".to_owned(),
            reference: true,
            points: claimed,
            tail: None,
        });
    }
    for (points, edge) in band.into_iter().zip(["low", "high"]) {
        if !points.is_empty() {
            lines.push(Line {
                kind: ANEES,
                method: None,
                label: "95 % band of a right Σ".to_owned(),
                reference: true,
                points,
                tail: Some(edge),
            });
        }
    }
}

/// max |RᵀR − I| per step of the Euler matrices and of the Exp rotations (as evaluated:
/// [`MatrixFrame`](crate::eval::MatrixFrame)), for the Exp node `name`.
fn orthogonality_lines<G: LieGroup<N>, const N: usize>(
    e: &Evaluation<G, N>,
    name: &str,
    lines: &mut Vec<Line>,
) {
    let frames: Vec<_> = e
        .matrix_frames
        .iter()
        .filter(|f| f.exp_node == name)
        .collect();
    lines.push(Line {
        kind: ORTHOGONALITY,
        method: None,
        label: "Euler steps R(I + ω̂dt)".to_owned(),
        reference: false,
        points: frames
            .iter()
            .map(|f| (f.step as i64, f.orthogonality_error))
            .collect(),
        tail: None,
    });
    lines.push(Line {
        kind: ORTHOGONALITY,
        method: Some(Method::Exact),
        label: "exponential map R·Exp(ωdt)".to_owned(),
        reference: false,
        points: frames
            .iter()
            .map(|f| (f.step as i64, f.exp_orthogonality_error))
            .collect(),
        tail: None,
    });
}

/// Every plot of an evaluation and its lines, in evaluation order.
pub(super) fn plots<G: LieGroup<N>, const N: usize>(
    e: &Evaluation<G, N>,
) -> (Vec<Plot>, Vec<ScalarSeries>) {
    let mut lines = Vec::new();
    let mut order: Vec<(usize, &str, OpKind)> =
        [OpKind::Odometry, OpKind::Compound, OpKind::EulerVsExp]
            .into_iter()
            .flat_map(|op| propagations(e, op).into_iter().map(move |name| (op, name)))
            .map(|(op, name)| {
                let first = e.nodes.iter().position(|n| n.name == name).unwrap_or(0);
                (first, name, op)
            })
            .collect();
    order.sort_by_key(|(first, ..)| *first);
    for (_, name, op) in order {
        match op {
            OpKind::Odometry => {
                trace_lines(e, name, &mut lines);
                consistency_lines(e, name, &mut lines);
            }
            OpKind::Compound => {
                // The along-track variance first: Barfoot & Furgale's lesson, the plot a
                // reader sees first.
                lines.extend(along_track_lines(e, name));
                trace_lines(e, name, &mut lines);
                consistency_lines(e, name, &mut lines);
            }
            _ => orthogonality_lines(e, name, &mut lines),
        }
    }
    let mut plots: Vec<(PlotKind, PlotId)> = Vec::new();
    let mut series = Vec::new();
    for line in lines {
        let id = match plots.iter().find(|(k, _)| *k == line.kind) {
            Some((_, id)) => id.clone(),
            None => {
                let id = PlotId::new(format!("{}_{}", plots.len(), line.kind.id));
                plots.push((line.kind, id.clone()));
                id
            }
        };
        let (mut segment, color) = match line.method {
            Some(m) => (m.slug().to_owned(), m.color()),
            None if line.reference => (slug(&line.label), scene::REFERENCE),
            None => (slug(&line.label), scene::NOMINAL),
        };
        if let Some(tail) = line.tail {
            segment = format!("{segment}_{tail}");
        }
        series.push(ScalarSeries::new(
            id,
            segment,
            line.label,
            color,
            2.0,
            line.points,
        ));
    }
    let plots = plots
        .into_iter()
        .map(|(k, id)| Plot {
            id,
            title: k.title.to_owned(),
            unit: k.unit.to_owned(),
            range: fixed_range(k, N),
            legend: k.legend,
        })
        .collect();
    (plots, series)
}

/// The value range of a plot whose quantity has one, whatever the data (so a re-run keeps its
/// layout): a share of samples runs from 0 to 1, the claimed p near the top and the legend
/// below; an ANEES from 0 to 3 d, a right Σ's value d a third of the way up and the legend
/// above it. Other plots: the viewer's own fit.
fn fixed_range(kind: PlotKind, dof: usize) -> Option<[f64; 2]> {
    if kind == COVERAGE {
        Some([0.0, 1.05])
    } else if kind == ANEES {
        Some([0.0, 3.0 * dof as f64])
    } else {
        None
    }
}

/// An entity-path segment from a label: lower-case letters and digits, `_` between words.
fn slug(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_owned()
}
