//! Records → a checked plan: vertex poses, edge covariances, the odometry chain and the loop
//! closures (see the [module docs](super)). Every check names the line and the value.

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::SMatrix;

use super::convention::{
    from_upper_triangle, se3_cov_from_g2o_error_cov, se3_information_from_g2o,
};
use super::parse::{Dimension, IdAt, Kind, Record, Records, information_axes};
use super::problem::{Edge, Fix, Prior, chain_initial_guess, pose_graph};
use super::{InputError, Locator};
use crate::input::{About, DrawChoices, FileSettings, Input};
use crate::lie::{LieGroup, Se2, Se3, TangentMatrix};
use crate::plan::choices::{GraphCounts, GraphFacts, Link};
use crate::plan::{
    AnyPlan, Control, FrameSide, OdometryModel, Op, Operand, Plan, StepNoise, StepPolicy, limits,
};
use crate::uncertain::{Method, Side, UncertainPose};

/// Most loop closures evaluated and drawn with their uncertainty (evenly chosen); the rest
/// are counted in the text panel. Twelve: each is a Monte Carlo cloud of the scenario's samples
/// with its Lie mean, and on a benchmark map more regions only pile over one another (on
/// parking-garage, whose loop closures say σ ≈ 1–2 rad, 30 of them were 100 ms of its 0.64 s
/// `--save`; issue 33).
pub const MAX_LOOP_CLOSURES: usize = 12;

/// Most vertex estimates drawn as axes (evenly chosen, plus the loop closures' ends).
pub const MAX_DRAWN_VERTICES: usize = 300;

/// What the two pose-graph groups need besides being Lie groups.
trait GraphGroup<const N: usize>: LieGroup<N> {
    /// A pose from the file's values (x y θ, or x y z qx qy qz qw).
    fn from_values(values: &[f64]) -> crate::Result<Self>;
    /// posecov's [ρ; θ] covariance from g2o's error covariance Ω⁻¹ ([`super::convention`]).
    fn cov_from_error_cov(cov_error: &TangentMatrix<N>) -> TangentMatrix<N>;
    /// The information over [ρ; θ] of g2o's Ω (the inverse of `cov_from_error_cov(Ω⁻¹)`).
    fn information_from_g2o(information: &TangentMatrix<N>) -> TangentMatrix<N>;
    /// The plan of this group.
    fn any(plan: Plan<Self, N>) -> AnyPlan;
}

impl GraphGroup<3> for Se2 {
    fn from_values(v: &[f64]) -> crate::Result<Self> {
        Ok(Se2::from_xy_theta(v[0], v[1], v[2]))
    }
    fn cov_from_error_cov(cov_error: &TangentMatrix<3>) -> TangentMatrix<3> {
        *cov_error
    }
    fn information_from_g2o(information: &TangentMatrix<3>) -> TangentMatrix<3> {
        *information
    }
    fn any(plan: Plan<Self, 3>) -> AnyPlan {
        AnyPlan::Se2(plan)
    }
}

impl GraphGroup<6> for Se3 {
    fn from_values(v: &[f64]) -> crate::Result<Self> {
        Se3::try_from_xyz_quaternion_xyzw([v[0], v[1], v[2]], [v[3], v[4], v[5], v[6]])
    }
    fn cov_from_error_cov(cov_error: &TangentMatrix<6>) -> TangentMatrix<6> {
        se3_cov_from_g2o_error_cov(cov_error)
    }
    fn information_from_g2o(information: &TangentMatrix<6>) -> TangentMatrix<6> {
        se3_information_from_g2o(information)
    }
    fn any(plan: Plan<Self, 6>) -> AnyPlan {
        AnyPlan::Se3(plan)
    }
}

/// The plan, the line of each operation's edge, and the counts.
pub(super) type Lowered = (Input, Vec<usize>, GraphCounts);

pub(super) fn lower(locator: &Locator, records: &Records) -> Result<Lowered, InputError> {
    let first = records.records.iter().find(|r| r.tag.kind != Kind::Fix);
    match first.map(|r| r.tag.dimension) {
        Some(Dimension::Spatial) => build::<Se3, 6>(locator, records),
        _ => build::<Se2, 3>(locator, records),
    }
}

fn label(r: &Record) -> String {
    let ids: Vec<String> = r.ids.iter().map(|i| i.id.to_string()).collect();
    format!("{} {}", r.tag.name, ids.join(" "))
}

/// (Σ = conversion(Ω⁻¹), Ω) of an edge or prior, with every failure at the information's
/// first number.
fn edge_cov<G: GraphGroup<N>, const N: usize>(
    locator: &Locator,
    r: &Record,
) -> Result<(TangentMatrix<N>, TangentMatrix<N>), InputError> {
    let values: Vec<f64> = r.information.iter().map(|v| v.value).collect();
    let information: SMatrix<f64, N, N> = from_upper_triangle::<N>(&values);
    let at = r.information.first().map_or(r.at, |v| v.at);
    let error =
        |message: String| locator.error(at..at, &format!("{} information", label(r)), message);
    let Some(cholesky) = information.cholesky() else {
        let smallest = nalgebra::DMatrix::from_iterator(N, N, information.iter().copied())
            .symmetric_eigenvalues()
            .min();
        let axes = information_axes(r.tag.dimension).join(", ");
        return Err(error(format!(
            "the information matrix over ({axes}) is not positive definite (smallest eigenvalue {smallest:.6e}); an edge's information must be, or the measurement says nothing in some direction"
        )));
    };
    let cov_error = cholesky.inverse();
    let cov = G::cov_from_error_cov(&((cov_error + cov_error.transpose()) * 0.5));
    let largest = cov.amax();
    if !largest.is_finite() || largest > limits::MAX_VARIANCE {
        return Err(error(format!(
            "the information matrix is so small that a variance reaches {largest:.3e} (σ beyond {:.0e}); posecov draws variances up to {:.0e}",
            limits::MAX_VARIANCE.sqrt(),
            limits::MAX_VARIANCE
        )));
    }
    Ok((cov, information))
}

fn build<G: GraphGroup<N>, const N: usize>(
    locator: &Locator,
    records: &Records,
) -> Result<Lowered, InputError> {
    let mut vertices: BTreeMap<u64, (G, usize)> = BTreeMap::new();
    let mut edges: Vec<Edge<G, N>> = Vec::new();
    let mut priors: Vec<Prior<G, N>> = Vec::new();
    // Every FIX record's ids.
    let mut fixes: Vec<Fix> = Vec::new();
    for r in &records.records {
        if r.tag.kind == Kind::Fix {
            fixes.extend(r.ids.iter().map(|&vertex| Fix {
                vertex,
                line: r.line,
            }));
            continue;
        }
        let values: Vec<f64> = r.pose.iter().map(|v| v.value).collect();
        let pose_at = r.pose.first().map_or(r.at, |v| v.at);
        let pose = G::from_values(&values)
            .map_err(|e| locator.error(pose_at..pose_at, &label(r), e.to_string()))?;
        check_coordinates(locator, r)?;
        match r.tag.kind {
            Kind::Vertex => {
                let IdAt { id, at: id_at } = r.ids[0];
                if let Some((_, first)) = vertices.get(&id) {
                    return Err(locator.error(
                        id_at..id_at,
                        &label(r),
                        format!("vertex {id} is defined twice (first on line {first})"),
                    ));
                }
                vertices.insert(id, (pose, r.line));
            }
            Kind::Edge => {
                let (from, IdAt { id: to, at: to_at }) = (r.ids[0].id, r.ids[1]);
                if from == to {
                    return Err(locator.error(
                        to_at..to_at,
                        &label(r),
                        format!("an edge from vertex {from} to itself says nothing"),
                    ));
                }
                let (cov, information) = edge_cov::<G, N>(locator, r)?;
                edges.push(Edge {
                    from,
                    to,
                    line: r.line,
                    measurement: pose,
                    cov,
                    information: G::information_from_g2o(&information),
                });
            }
            Kind::Prior | Kind::Fix => {
                let (_, information) = edge_cov::<G, N>(locator, r)?;
                priors.push(Prior {
                    vertex: r.ids[0],
                    line: r.line,
                    measurement: pose,
                    information: G::information_from_g2o(&information),
                });
            }
        }
    }
    let chained = vertices.is_empty();
    if chained {
        if edges.is_empty() {
            let r = &records.records[0];
            return Err(locator.error(
                r.at..r.at,
                r.tag.name,
                "the file has no vertices and no edges: a pose graph needs VERTEX_SE2 / EDGE_SE2 or VERTEX_SE3:QUAT / EDGE_SE3:QUAT lines",
            ));
        }
        // No VERTEX lines (M3500, CSAIL): the initial guess is chained from the edges.
        vertices = chain_initial_guess(&edges);
    }
    if vertices.len() as u64 > limits::MAX_STEPS + 1 {
        return Err(locator.error(
            0..0,
            "file",
            format!(
                "{} vertices; posecov draws graphs of up to {} vertices",
                vertices.len(),
                limits::MAX_STEPS + 1
            ),
        ));
    }
    for (r, e) in records
        .records
        .iter()
        .filter(|r| r.tag.kind == Kind::Edge)
        .zip(&edges)
    {
        for &IdAt { id, at } in &r.ids {
            if !vertices.contains_key(&id) {
                return Err(locator.error(
                    at..at,
                    &label(r),
                    format!(
                        "vertex {id} is not defined (no VERTEX line has id {id}); edge {} → {} cannot be drawn",
                        e.from, e.to
                    ),
                ));
            }
        }
    }
    let undefined = priors
        .iter()
        .map(|p| Fix {
            vertex: p.vertex,
            line: p.line,
        })
        .chain(fixes.iter().copied())
        .find(|f| !vertices.contains_key(&f.vertex.id));
    if let Some(Fix {
        vertex: IdAt { id, at },
        line,
    }) = undefined
    {
        let tag = records
            .records
            .iter()
            .find(|r| r.line == line)
            .map_or("record", |r| r.tag.name);
        return Err(locator.error(
            at..at,
            tag,
            format!("vertex {id} is not defined (no VERTEX line has id {id})"),
        ));
    }
    let graph = pose_graph(&vertices, &edges, &priors, &fixes);
    Ok(assemble(
        locator, records, &vertices, &edges, graph, chained,
    ))
}

/// Positions beyond [`limits::MAX_COORDINATE`] cannot be drawn.
fn check_coordinates(locator: &Locator, r: &Record) -> Result<(), InputError> {
    let translation = match r.tag.dimension {
        Dimension::Planar => &r.pose[..2],
        Dimension::Spatial => &r.pose[..3],
    };
    match translation
        .iter()
        .find(|v| v.value.abs() > limits::MAX_COORDINATE)
    {
        Some(v) => Err(locator.error(
            v.at..v.at,
            &label(r),
            format!(
                "coordinate {} is beyond ±{:.0e} m, too far to draw",
                v.value,
                limits::MAX_COORDINATE
            ),
        )),
        None => Ok(()),
    }
}

/// The odometry chain: from the first vertex, the first edge (k, k+1) or (k+1, k) of each
/// consecutive pair, as (edge index, increment, covariance) — a reversed edge inverted:
/// (Z Exp(ξ))⁻¹ = Z⁻¹ Exp(−Ad_Z ξ), so Σ' = Ad_Z Σ Ad_Zᵀ.
fn chain<G: LieGroup<N>, const N: usize>(
    vertices: &BTreeMap<u64, (G, usize)>,
    edges: &[Edge<G, N>],
) -> Vec<(usize, G, TangentMatrix<N>)> {
    let mut first_edge: BTreeMap<(u64, u64), usize> = BTreeMap::new();
    for (i, e) in edges.iter().enumerate() {
        if e.from.abs_diff(e.to) == 1 {
            first_edge
                .entry((e.from.min(e.to), e.from.max(e.to)))
                .or_insert(i);
        }
    }
    let mut out = Vec::new();
    let Some(mut k) = vertices.keys().next().copied() else {
        return out;
    };
    while let Some(&i) = k.checked_add(1).and_then(|next| first_edge.get(&(k, next))) {
        let e = &edges[i];
        if e.from == k {
            out.push((i, e.measurement, e.cov));
        } else {
            let ad = e.measurement.adj();
            out.push((i, e.measurement.inverse(), ad * e.cov * ad.transpose()));
        }
        k += 1;
    }
    out
}

/// At most `max` of `0..n`, evenly spaced (all when n ≤ max).
fn evenly(n: usize, max: usize) -> Vec<usize> {
    if n <= max {
        return (0..n).collect();
    }
    (0..max).map(|k| k * (n - 1) / (max - 1).max(1)).collect()
}

fn vertex_name(id: u64) -> String {
    format!("v{id}")
}

/// The plan, the drawing choices and the facts of a read graph: the drawn vertex estimates as
/// known poses, the odometry chain as one odometry operation, each drawn loop closure as the
/// pose it puts its second vertex at; with the line of each operation's edge.
fn assemble<G: GraphGroup<N>, const N: usize>(
    locator: &Locator,
    records: &Records,
    vertices: &BTreeMap<u64, (G, usize)>,
    edges: &[Edge<G, N>],
    graph: crate::plan::graph::PoseGraph<G, N>,
    chained: bool,
) -> Lowered {
    let chain = chain(vertices, edges);
    let in_chain: BTreeSet<usize> = chain.iter().map(|c| c.0).collect();
    let loops: Vec<usize> = (0..edges.len()).filter(|i| !in_chain.contains(i)).collect();
    let (drawn_loops, drawn_ids) = drawn(vertices, edges, &loops);
    let mut plan = Plan::<G, N> {
        graph: Some(graph),
        ..Plan::default()
    };
    let mut choices = DrawChoices {
        sample_axes: false,
        ..DrawChoices::default()
    };
    // Labels are drawn where they do not collide, by draw::graph.
    choices.labels = false;
    let mut operation_lines = Vec::new();
    for id in &drawn_ids {
        let name = vertex_name(*id);
        plan.known(&name, vertices[id].0);
        choices.shown.insert(name, true);
    }
    // The first vertex id (a graph without vertices is refused when read).
    let first = vertices.keys().next().copied().unwrap_or_default();
    if let Some(&(first_edge, ..)) = chain.first() {
        plan.operation(
            "odometry_chain",
            Op::Odometry {
                input: Operand::Known(vertices[&first].0),
                model: OdometryModel::Increment,
                controls: chain
                    .iter()
                    .map(|(_, z, _)| Control {
                        increment: *z,
                        tangent: z.log(),
                    })
                    .collect(),
                noise: StepNoise::PerStep(chain.iter().map(|c| c.2).collect()),
            },
        );
        operation_lines.push(edges[first_edge].line);
        choices.shown.insert("odometry_chain".to_owned(), true);
    }
    for &i in &drawn_loops {
        loop_closure(&mut plan, &mut choices, &edges[i], vertices);
        operation_lines.push(edges[i].line);
    }
    choices.axis_length = axis_length(&chain);
    let summary = GraphCounts {
        vertices: vertices.len(),
        edges: edges.len(),
        chain_edges: chain.len(),
        loop_closures: loops.len(),
        loop_closures_drawn: drawn_loops.len(),
        vertices_drawn: drawn_ids.len(),
    };
    choices.graph = Some(GraphFacts {
        planar: G::KIND.is_planar(),
        counts: summary.clone(),
        first,
        chain_end: first + chain.len() as u64,
        chained,
        skipped: records.skipped.clone(),
    });
    let about = About {
        title: format!(
            "Pose graph {}: {} {} poses, {} odometry edges, {} loop closures",
            locator.file(),
            summary.vertices,
            if G::KIND.is_planar() {
                "SE(2)"
            } else {
                "SE(3)"
            },
            summary.chain_edges,
            summary.loop_closures
        ),
        description: String::new(),
        source: String::new(),
    };
    let input = Input {
        about,
        plan: G::any(plan),
        defaults: FileSettings {
            methods: vec![Method::FirstOrder, Method::MonteCarlo],
            steps: Some(StepPolicy::GRAPH),
            ..FileSettings::default()
        },
        draw: choices,
    };
    (input, operation_lines, summary)
}

/// What is drawn of a graph: the loop closures (indices into `edges`, at most
/// [`MAX_LOOP_CLOSURES`] of `loops`, evenly chosen) and the vertex ids (at most
/// [`MAX_DRAWN_VERTICES`], evenly chosen, plus the drawn loop closures' ends).
fn drawn<G: LieGroup<N>, const N: usize>(
    vertices: &BTreeMap<u64, (G, usize)>,
    edges: &[Edge<G, N>],
    loops: &[usize],
) -> (Vec<usize>, BTreeSet<u64>) {
    let drawn_loops: Vec<usize> = evenly(loops.len(), MAX_LOOP_CLOSURES)
        .into_iter()
        .map(|k| loops[k])
        .collect();
    let ids: Vec<u64> = vertices.keys().copied().collect();
    let mut drawn_ids: BTreeSet<u64> = evenly(ids.len(), MAX_DRAWN_VERTICES)
        .into_iter()
        .map(|k| ids[k])
        .collect();
    drawn_ids.extend(
        drawn_loops
            .iter()
            .flat_map(|&i| [edges[i].from, edges[i].to]),
    );
    (drawn_loops, drawn_ids)
}

/// A drawn loop closure i → j: its measurement `v<i>_to_v<j>_measured` (an uncertain input,
/// not drawn) and `v<j>_via_v<i>` = X_i · Z, where it puts vertex j (drawn, linked to both
/// vertices).
fn loop_closure<G: LieGroup<N>, const N: usize>(
    plan: &mut Plan<G, N>,
    choices: &mut DrawChoices,
    e: &Edge<G, N>,
    vertices: &BTreeMap<u64, (G, usize)>,
) {
    let measured = format!("v{}_to_v{}_measured", e.from, e.to);
    let mut via = format!("v{}_via_v{}", e.to, e.from);
    if choices.shown.contains_key(&via) {
        via = format!("{via}_line{}", e.line);
    }
    let input = plan.uncertain(
        &measured,
        UncertainPose::new_unchecked(e.measurement, e.cov, Side::Right),
    );
    choices.shown.insert(measured, false);
    plan.operation(
        &via,
        Op::ChangeFrame {
            input,
            by: vertices[&e.from].0,
            side: FrameSide::Left,
        },
    );
    choices.shown.insert(via, true);
    choices.links.push(Link {
        from: vertex_name(e.from),
        to: vertex_name(e.to),
    });
}

/// The frames' axis length: 0.3 of the chain's median step (within the limits); `None`
/// without a step that moves.
fn axis_length<G: LieGroup<N>, const N: usize>(
    chain: &[(usize, G, TangentMatrix<N>)],
) -> Option<f64> {
    let mut steps: Vec<f64> = chain
        .iter()
        .map(|(_, z, _)| z.to_se3().translation().norm())
        .filter(|d| *d > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    steps
        .get(steps.len() / 2)
        .map(|median| (0.3 * median).clamp(limits::MIN_AXIS_LENGTH, limits::MAX_AXIS_LENGTH))
}
