//! Mesh helpers for [`Surface`]s: a unit-sphere grid to push through a map (e.g. the
//! Exp-image of a tangent-space ellipsoid) and vertex normals.

use super::{Surface, Vec3};

/// A latitude–longitude triangulation of the unit sphere: `(vertices, triangles)`.
///
/// `n_lat` ≥ 2 bands from pole to pole, `n_lon` ≥ 3 meridians (smaller values are raised to
/// these minima). Poles are single vertices, so mapping the vertices through a smooth map
/// `f` gives a closed, watertight surface of `f(sphere)`; triangles are counter-clockwise
/// seen from outside.
///
/// ```
/// let (v, t) = posecov::scene::unit_sphere_mesh(8, 16);
/// assert_eq!(v.len(), 2 + 7 * 16);
/// assert_eq!(t.len(), 2 * 16 * 7);
/// assert!(v.iter().all(|p| ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs() < 1e-12));
/// ```
pub fn unit_sphere_mesh(n_lat: u32, n_lon: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (n_lat, n_lon) = (n_lat.max(2), n_lon.max(3));
    let mut vertices = vec![[0.0, 0.0, 1.0]];
    for i in 1..n_lat {
        let polar = std::f64::consts::PI * f64::from(i) / f64::from(n_lat);
        for j in 0..n_lon {
            let azimuth = std::f64::consts::TAU * f64::from(j) / f64::from(n_lon);
            vertices.push([
                polar.sin() * azimuth.cos(),
                polar.sin() * azimuth.sin(),
                polar.cos(),
            ]);
        }
    }
    vertices.push([0.0, 0.0, -1.0]);
    let south = n_lon * (n_lat - 1) + 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * n_lon + j % n_lon;
    let mut triangles = Vec::new();
    for j in 0..n_lon {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        for i in 1..n_lat - 1 {
            triangles.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            triangles.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
        triangles.push([ring(n_lat - 1, j), south, ring(n_lat - 1, j + 1)]);
    }
    (vertices, triangles)
}

impl Surface {
    /// Replaces `normals` with area-weighted vertex normals of the triangles (unit length;
    /// `[0, 0, 0]` for a vertex with no non-degenerate triangle). Out-of-range indices are
    /// skipped here and reported by [`Scene::validate`](super::Scene::validate).
    ///
    /// ```
    /// use posecov::scene::{Color, Surface};
    /// let s = Surface {
    ///     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ///     triangles: vec![[0, 1, 2]],
    ///     normals: vec![],
    ///     color: Color::rgb(9, 9, 9),
    /// }
    /// .with_computed_normals();
    /// assert_eq!(s.normals, vec![[0.0, 0.0, 1.0]; 3]);
    /// ```
    pub fn with_computed_normals(mut self) -> Self {
        let mut normals = vec![[0.0; 3]; self.vertices.len()];
        for tri in &self.triangles {
            let idx = tri.map(|v| v as usize);
            let (Some(a), Some(b), Some(c)) = (
                self.vertices.get(idx[0]),
                self.vertices.get(idx[1]),
                self.vertices.get(idx[2]),
            ) else {
                continue;
            };
            let n = cross(sub(*b, *a), sub(*c, *a));
            for &v in &idx {
                (0..3).for_each(|k| normals[v][k] += n[k]);
            }
        }
        for n in &mut normals {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                *n = n.map(|x| x / len);
            } else {
                *n = [0.0; 3];
            }
        }
        self.normals = normals;
        self
    }
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_normals_point_outwards() {
        let (vertices, triangles) = unit_sphere_mesh(12, 24);
        let s = Surface {
            vertices: vertices.clone(),
            triangles,
            normals: vec![],
            color: crate::scene::Color::rgb(0, 0, 0),
        }
        .with_computed_normals();
        for (v, n) in vertices.iter().zip(&s.normals) {
            let dot: f64 = (0..3).map(|k| v[k] * n[k]).sum();
            assert!(dot > 0.95, "{v:?} {n:?}");
        }
    }
}
