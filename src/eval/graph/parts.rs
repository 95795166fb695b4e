//! The gauge: a pose graph says where poses are relative to each other, so each connected
//! part needs something absolute. A part is anchored by its priors or `FIX` records if it has
//! any; otherwise its first vertex (smallest id) is held at its estimate. A vertex no edge or
//! prior reaches is its own part, kept as given, with no marginal.

use crate::lie::LieGroup;
use crate::plan::graph::PoseGraph;

/// What holds a part in place.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Anchor {
    /// The file's priors (`EDGE_PRIOR_SE2`, `EDGE_SE3_PRIOR`) on the part's vertices.
    Priors {
        /// How many.
        count: usize,
    },
    /// The file's `FIX` records.
    Fixed {
        /// The fixed vertex ids.
        ids: Vec<u64>,
    },
    /// Nothing in the file: the first vertex is held at its estimate (posecov's gauge).
    FirstVertex {
        /// Its id.
        id: u64,
    },
    /// A vertex no edge or prior reaches: kept as given, no marginal.
    Isolated {
        /// Its id.
        id: u64,
    },
}

/// One connected part of the graph.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Part {
    /// Vertices in the part.
    pub vertices: usize,
    /// The smallest vertex id in it.
    pub first_id: u64,
    /// What holds it.
    pub anchor: Anchor,
}

/// A graph's parts and what they hold fixed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Parts {
    /// Every part, in the order of its smallest vertex.
    pub parts: Vec<Part>,
    /// Per vertex: whether it is held fixed (not an unknown).
    pub fixed: Vec<bool>,
    /// Per vertex: its part (an index into `parts`).
    pub part_of: Vec<usize>,
}

/// The parts of `graph`: each is anchored by its priors or `FIX` records, else by holding its
/// first vertex; a vertex nothing reaches is its own part ([`Anchor`]).
///
/// ```
/// use posecov::eval::graph::{Anchor, parts};
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::plan::graph::{GraphEdge, GraphVertex, PoseGraph};
/// let mut g = PoseGraph::<Se2, 3>::default();
/// for id in 0..3 {
///     g.vertices.push(GraphVertex { id, estimate: Se2::identity(), line: 0 });
/// }
/// g.edges.push(GraphEdge { from: 0, to: 1, measurement: Se2::identity(), information: nalgebra::Matrix3::identity(), line: 4 });
/// let p = parts(&g);
/// assert_eq!(p.part_of, vec![0, 0, 1]);
/// assert_eq!(p.parts[1].anchor, Anchor::Isolated { id: 2 });
/// assert_eq!(p.fixed, vec![true, false, true]);
/// ```
pub fn parts<G: LieGroup<N>, const N: usize>(graph: &PoseGraph<G, N>) -> Parts {
    let n = graph.vertices.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    let mut touched = vec![false; n];
    for e in &graph.edges {
        let (a, b) = (root(&mut parent, e.from), root(&mut parent, e.to));
        // The smaller index (smaller id: vertices are sorted) becomes the root.
        parent[a.max(b)] = a.min(b);
        touched[e.from] = true;
        touched[e.to] = true;
    }
    let mut priors = vec![0usize; n];
    for p in &graph.priors {
        priors[p.vertex] += 1;
        touched[p.vertex] = true;
    }
    let mut fixed = vec![false; n];
    for f in &graph.fixed {
        fixed[f.index] = true;
    }
    let roots: Vec<usize> = (0..n).map(|v| root(&mut parent, v)).collect();
    let mut members: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (v, &r) in roots.iter().enumerate() {
        members.entry(r).or_default().push(v);
    }
    let mut out = Vec::new();
    let mut part_of = vec![0; n];
    for (r, vs) in members {
        for &v in &vs {
            part_of[v] = out.len();
        }
        let first_id = graph.vertices[r].id;
        let fixed_ids: Vec<u64> = vs
            .iter()
            .filter(|&&v| fixed[v])
            .map(|&v| graph.vertices[v].id)
            .collect();
        let prior_count: usize = vs.iter().map(|&v| priors[v]).sum();
        let anchor = if vs.len() == 1 && !touched[r] && !fixed[r] {
            fixed[r] = true;
            Anchor::Isolated { id: first_id }
        } else if !fixed_ids.is_empty() {
            Anchor::Fixed { ids: fixed_ids }
        } else if prior_count > 0 {
            Anchor::Priors { count: prior_count }
        } else {
            fixed[r] = true;
            Anchor::FirstVertex { id: first_id }
        };
        out.push(Part {
            vertices: vs.len(),
            first_id,
            anchor,
        });
    }
    Parts {
        parts: out,
        fixed,
        part_of,
    }
}
