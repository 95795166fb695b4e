//! Filled regions: the projected triangles of a surface mesh (an Exp-mapped banana) drawn as
//! their union with a darker rim, written as the few edges where the union can end rather than
//! as every triangle (a figure's size and its conversion time grow with its path corners:
//! BENCHMARKS.md §9).

use std::collections::BTreeMap;

use super::svg::{Px, Svg, darker, num, path_data, rgb};
use super::world::{Mapping, Pen, Plane};
use crate::scene::{ItemKind, SceneItem};

/// Draws the filled regions (surfaces) of `items`: first, under everything else.
///
/// A region is its mesh's projected triangles, filled (their union), over a darker stroke of
/// the same path: the fill covers the inner half of the stroke, so only the outer half shows,
/// a rim round the shadow. The path is `boundary`: the union's edges, not its triangles.
pub fn draw_regions(svg: &mut Svg, items: &[&SceneItem], plane: Plane, m: &Mapping, pen: Pen) {
    for item in items {
        let ItemKind::Surface(s) = &item.kind else {
            continue;
        };
        let px: Vec<Px> = s.vertices.iter().map(|v| m.px(plane.project(*v))).collect();
        let d = boundary(&px, &s.triangles);
        if d.is_empty() {
            continue;
        }
        let color = s.color;
        svg.open("class=\"region\" opacity=\"0.45\"");
        svg.raw(&format!(
            "<path d=\"{d}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"/>",
            rgb(darker(color, 0.35)),
            num(2.4 * pen.unit),
        ));
        svg.raw(&format!("<path d=\"{d}\" fill=\"{}\"/>", rgb(color)));
        svg.close();
    }
}

/// Below this absolute screen area (pixels²) a projected triangle is edge-on: it covers
/// nothing.
const EDGE_ON: f64 = 1e-9;

/// The path whose non-zero fill is exactly the union of a mesh's projected triangles (`px`
/// its vertices on screen), as closed loops of edges.
///
/// Each triangle that is not edge-on is taken counter-clockwise on screen; its three edges,
/// so directed, wind once round its inside. Summed over the triangles, an edge that two of
/// them run in opposite directions cancels (inside the union, where two neighbours meet), and
/// the rest wind round each point as often as triangles cover it: at least once inside the
/// union, never outside. So the non-zero fill of the edges left over is the union, and those
/// are only the edges where the union can end (the shadow's outline, a fold where the surface
/// turns away), a few dozen where the mesh has hundreds of triangles. Every vertex has as many
/// of them leaving as arriving, so they join into closed loops.
fn boundary(px: &[Px], triangles: &[[u32; 3]]) -> String {
    // Net count of each undirected edge (smaller index first): + run forwards, − backwards.
    let mut net = BTreeMap::<(u32, u32), i32>::new();
    for t in triangles {
        if !t.iter().all(|&i| (i as usize) < px.len()) {
            continue;
        }
        let [a, b, c] = t.map(|i| px[i as usize]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if area.abs() < EDGE_ON {
            continue;
        }
        let mut t = *t;
        if area < 0.0 {
            t.swap(1, 2);
        }
        for e in 0..3 {
            let (from, to) = (t[e], t[(e + 1) % 3]);
            *net.entry((from.min(to), from.max(to))).or_default() += if from < to { 1 } else { -1 };
        }
    }
    // The edges left, directed, once per net count.
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for ((low, high), n) in net {
        let directed = if n > 0 { (low, high) } else { (high, low) };
        edges.extend(std::iter::repeat_n(directed, n.unsigned_abs() as usize));
    }
    let mut leaving = BTreeMap::<u32, Vec<usize>>::new();
    for (k, (from, _)) in edges.iter().enumerate() {
        leaving.entry(*from).or_default().push(k);
    }
    // Walk each loop: from an unused edge on through unused edges leaving its end, until back.
    let mut used = vec![false; edges.len()];
    let mut d = String::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let (first, mut end) = edges[start];
        let mut corners = vec![px[first as usize]];
        while end != first {
            corners.push(px[end as usize]);
            let Some(&next) = leaving[&end].iter().find(|&&k| !used[k]) else {
                break;
            };
            used[next] = true;
            end = edges[next].1;
        }
        d.push_str(&path_data(&corners, true));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere seen from above, 100 px in radius.
    fn sphere() -> (Vec<Px>, Vec<[u32; 3]>) {
        let (vertices, triangles) = crate::scene::unit_sphere_mesh(8, 16);
        let px = vertices
            .iter()
            .map(|v| [100.0 * v[0], 100.0 * v[1]])
            .collect();
        (px, triangles)
    }

    fn corners(d: &str) -> Vec<[f64; 2]> {
        d.split(['M', 'L', 'Z'])
            .filter(|s| !s.is_empty())
            .map(|s| {
                let (x, y) = s.split_once(' ').unwrap();
                [x.parse().unwrap(), y.parse().unwrap()]
            })
            .collect()
    }

    #[test]
    fn a_sphere_is_filled_by_its_outline() {
        let (px, triangles) = sphere();
        let d = boundary(&px, &triangles);
        // The equator twice (both hemispheres end there), 16 edges each: 224 triangles become
        // two loops of 16 corners.
        assert_eq!(d.matches('M').count(), 2, "{d}");
        let c = corners(&d);
        assert_eq!(c.len(), 32);
        assert!(c.iter().all(|p| (p[0].hypot(p[1]) - 100.0).abs() < 0.1));
    }

    #[test]
    fn a_fold_keeps_both_layers() {
        // Two triangles folded over each other along the edge 0–1: the union is the larger.
        let px = [[0.0, 0.0], [10.0, 0.0], [5.0, 5.0], [5.0, 8.0]];
        let d = boundary(&px, &[[0, 1, 2], [1, 0, 3]]);
        // Both outlines: the shared edge runs the same way in both and does not cancel.
        assert_eq!(d.matches('M').count(), 2, "{d}");
        assert_eq!(corners(&d).len(), 6);
    }

    #[test]
    fn neighbours_share_no_edge_in_the_path() {
        // A square of two triangles: one loop of its four sides.
        let px = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let d = boundary(&px, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(d.matches('M').count(), 1, "{d}");
        assert_eq!(corners(&d).len(), 4);
    }
}
