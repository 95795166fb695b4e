//! A pose graph file's description, written from its facts ([`GraphFacts`]): the odometry
//! chain, the vertex estimates, the loop closures, what is drawn of them, and the edge
//! covariance convention of its format.

use crate::plan::choices::{GraphFacts, SkippedRecords};

/// The Markdown description of a pose graph file (the input's own words in the text panel and
/// `report --json`'s `meta.description`).
pub(in crate::draw) fn description(f: &GraphFacts) -> String {
    let (first, chain_end) = (f.first, f.chain_end);
    let chain = if f.counts.chain_edges == 0 {
        format!(
            "- **No odometry chain**: no edge joins v{first} to v{}, so nothing is propagated.\n",
            first.saturating_add(1)
        )
    } else {
        format!(
            "- **Odometry chain** `odometry_chain`: the {} edges between consecutive vertex ids, \
             v{first} → v{chain_end}, composed from v{first}'s estimate with each edge's \
             covariance (first order in colour, Monte Carlo as the cloud). Scrub the `step` \
             timeline: step k is vertex v{first}+k, and the banana grows as the errors of every \
             edge add up.\n",
            f.counts.chain_edges
        )
    };
    let mut d = format!(
        "**{} vertices, {} edges** ({}).\n\n{chain}\
         - **Vertex estimates** `v<id>`: the file's poses, as axes. Where they part from the \
         chain's mean, the file's estimate is not dead reckoning (e.g. it was optimised).\n\
         - **Loop closures** (the other {} edges): a grey line between the two vertices, and \
         `v<j>_via_v<i>` = X_i · Z, where edge i → j puts vertex j, with the edge's own uncertainty.\n",
        f.counts.vertices,
        f.counts.edges,
        if f.planar { "SE(2)" } else { "SE(3)" },
        f.counts.loop_closures,
    );
    if f.counts.vertices_drawn < f.counts.vertices {
        d.push_str(&format!(
            "\n{} of the {} vertex estimates are drawn (evenly chosen, and the drawn loop closures' ends).\n",
            f.counts.vertices_drawn, f.counts.vertices
        ));
    }
    if f.counts.loop_closures_drawn < f.counts.loop_closures {
        d.push_str(&format!(
            "\n{} of the {} loop closures are drawn (evenly chosen).\n",
            f.counts.loop_closures_drawn, f.counts.loop_closures
        ));
    }
    if f.counts.chain_edges > 0 && f.counts.vertices as u64 > chain_end - first + 1 {
        d.push_str(&format!(
            "\nThe chain stops at v{chain_end}: no edge joins it to v{} (the later vertices are \
             drawn, not propagated).\n",
            chain_end.saturating_add(1)
        ));
    }
    if f.chained {
        d.push_str(
            "\nThe file has no VERTEX lines: the estimates are chained from the edges (the \
             odometry edges first, then the others, each placing a vertex not yet placed), as \
             GTSAM's reader does.\n",
        );
    }
    for SkippedRecords { tag, count } in &f.skipped {
        d.push_str(&format!(
            "\nSkipped {count} `{tag}` record(s) (not drawn).\n"
        ));
    }
    d.push_str(if f.planar {
        "\nEdge covariance: g2o's EDGE_SE2 information over (x, y, θ) of Z⁻¹ X_i⁻¹ X_j, \
         inverted: posecov's right-perturbation Σ over [ρx, ρy, θ] (GTSAM reads it the same way).\n"
    } else {
        "\nEdge covariance: g2o's EDGE_SE3:QUAT information is over (t, q.xyz) of \
         Z⁻¹ X_i⁻¹ X_j; q.xyz ≈ θ/2, so posecov's Σ over [ρ; θ] has the rotation block ×4 and \
         the cross block ×2 of Ω⁻¹. GTSAM's readG2o applies no such factor: its rotation σ is \
         half of this.\n"
    });
    d
}
