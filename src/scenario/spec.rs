//! From the file's mean and covariance specifications to group elements and matrices.

use std::ops::Range;

use nalgebra::{Matrix4, Matrix6, SMatrix, Vector3};

use super::schema::{CovSpec, MeanSpec, Order};
use crate::lie::{LieGroup, Se2, Se3, So2, So3, Tangent, TangentMatrix};
use crate::uncertain::{Side, validate_covariance};

/// A group that scenario files can describe, and that the viewer can draw (lifted into SE(3)).
pub trait SpecGroup<const N: usize>: LieGroup<N> {
    /// Mean-specification keys this group accepts.
    const MEAN_KEYS: &'static [&'static str];
    /// The index range of the rotation part of the tangent.
    fn rotation_range() -> Range<usize>;
    /// Builds the mean from the keys that are set (already checked to be allowed).
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self, String>;
    /// The element as a 3D pose, for drawing (planar groups at z = 0, rotation about z).
    fn to_se3(&self) -> Se3;
}

/// The names of the keys set in a mean specification.
fn mean_keys_set(spec: &MeanSpec) -> Vec<&'static str> {
    let set = [
        ("xy_theta", spec.xy_theta.is_some()),
        ("xy_theta_deg", spec.xy_theta_deg.is_some()),
        ("angle", spec.angle.is_some()),
        ("angle_deg", spec.angle_deg.is_some()),
        ("xyz", spec.xyz.is_some()),
        ("quaternion_xyzw", spec.quaternion_xyzw.is_some()),
        ("rpy", spec.rpy.is_some()),
        ("rpy_deg", spec.rpy_deg.is_some()),
        ("axis_angle", spec.axis_angle.is_some()),
        ("matrix", spec.matrix.is_some()),
        ("tangent", spec.tangent.is_some()),
    ];
    set.iter().filter(|(_, on)| *on).map(|(k, _)| *k).collect()
}

/// Checks that a mean sets only keys of its group, and exactly one way of giving it.
pub(crate) fn mean_for<G: SpecGroup<N>, const N: usize>(spec: &MeanSpec) -> Result<G, String> {
    let keys = mean_keys_set(spec);
    if let Some(bad) = keys.iter().find(|k| !G::MEAN_KEYS.contains(k)) {
        return Err(format!(
            "`{bad}` does not describe an element of {}; use one of {}",
            G::NAME,
            G::MEAN_KEYS.join(", ")
        ));
    }
    let rotations = keys.iter().filter(|k| **k != "xyz").count();
    if keys.is_empty()
        || rotations > 1
        || (keys.contains(&"xyz") && (keys.contains(&"matrix") || keys.contains(&"tangent")))
    {
        return Err(format!(
            "give the mean in exactly one way (got {}); {} accepts {}",
            if keys.is_empty() {
                "none".to_owned()
            } else {
                keys.join(" + ")
            },
            G::NAME,
            G::MEAN_KEYS.join(", ")
        ));
    }
    if let Some(t) = &spec.tangent {
        check_values("tangent", t)?;
        if t.len() != N {
            return Err(format!(
                "tangent needs {N} numbers for {}, got {}",
                G::NAME,
                t.len()
            ));
        }
        return Ok(G::exp(&Tangent::<N>::from_column_slice(t)));
    }
    G::mean_from_spec(spec)
}

fn check_values(what: &str, values: &[f64]) -> Result<(), String> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(format!(
            "{what}[{i}] is {}, every number must be finite",
            values[i]
        )),
        None => Ok(()),
    }
}

/// A row-major `rows` as a fixed R×C matrix, checking its shape and values.
pub(crate) fn fixed_matrix<const R: usize, const C: usize>(
    what: &str,
    rows: &[Vec<f64>],
) -> Result<SMatrix<f64, R, C>, String> {
    if rows.len() != R || rows.iter().any(|r| r.len() != C) {
        let shape: Vec<usize> = rows.iter().map(Vec::len).collect();
        return Err(format!(
            "{what} must be {R}×{C} (rows of {C}); got {} rows of lengths {shape:?}",
            rows.len()
        ));
    }
    for (i, row) in rows.iter().enumerate() {
        check_values(&format!("{what} row {i}"), row)?;
    }
    Ok(SMatrix::<f64, R, C>::from_fn(|r, c| rows[r][c]))
}

fn rotation3(spec: &MeanSpec) -> Result<So3, String> {
    if let Some(q) = spec.quaternion_xyzw {
        return So3::try_from_quaternion_xyzw(q).map_err(|e| e.to_string());
    }
    if let Some(a) = spec.axis_angle {
        return So3::try_from_axis_angle(&Vector3::new(a[0], a[1], a[2]), a[3])
            .map_err(|e| e.to_string());
    }
    let rpy = spec
        .rpy
        .or(spec.rpy_deg.map(|d| d.map(f64::to_radians)))
        .unwrap_or([0.0; 3]);
    check_values("rpy", &rpy)?;
    Ok(So3::from_rpy(rpy[0], rpy[1], rpy[2]))
}

impl SpecGroup<1> for So2 {
    const MEAN_KEYS: &'static [&'static str] = &["angle", "angle_deg", "matrix", "tangent"];
    fn rotation_range() -> Range<usize> {
        0..1
    }
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self, String> {
        if let Some(m) = &spec.matrix {
            return So2::try_from_matrix(&fixed_matrix::<2, 2>("matrix", m)?)
                .map_err(|e| e.to_string());
        }
        let angle = spec
            .angle
            .or(spec.angle_deg.map(f64::to_radians))
            .unwrap_or(0.0);
        check_values("angle", &[angle])?;
        Ok(So2::from_angle(angle))
    }
    fn to_se3(&self) -> Se3 {
        Se3::from_parts(Vector3::zeros(), So3::from_rpy(0.0, 0.0, self.angle()))
    }
}

impl SpecGroup<3> for Se2 {
    const MEAN_KEYS: &'static [&'static str] = &["xy_theta", "xy_theta_deg", "matrix", "tangent"];
    fn rotation_range() -> Range<usize> {
        2..3
    }
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self, String> {
        if let Some(m) = &spec.matrix {
            return Se2::try_from_matrix(&fixed_matrix::<3, 3>("matrix", m)?)
                .map_err(|e| e.to_string());
        }
        let v = spec
            .xy_theta
            .or(spec.xy_theta_deg.map(|[x, y, t]| [x, y, t.to_radians()]))
            .unwrap_or([0.0; 3]);
        check_values("xy_theta", &v)?;
        Ok(Se2::from_xy_theta(v[0], v[1], v[2]))
    }
    fn to_se3(&self) -> Se3 {
        crate::convert::se2_to_se3(self)
    }
}

impl SpecGroup<3> for So3 {
    const MEAN_KEYS: &'static [&'static str] = &[
        "quaternion_xyzw",
        "rpy",
        "rpy_deg",
        "axis_angle",
        "matrix",
        "tangent",
    ];
    fn rotation_range() -> Range<usize> {
        0..3
    }
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self, String> {
        if let Some(m) = &spec.matrix {
            return So3::try_from_matrix(&fixed_matrix::<3, 3>("matrix", m)?)
                .map_err(|e| e.to_string());
        }
        rotation3(spec)
    }
    fn to_se3(&self) -> Se3 {
        Se3::from_parts(Vector3::zeros(), *self)
    }
}

impl SpecGroup<6> for Se3 {
    const MEAN_KEYS: &'static [&'static str] = &[
        "xyz",
        "quaternion_xyzw",
        "rpy",
        "rpy_deg",
        "axis_angle",
        "matrix",
        "tangent",
    ];
    fn rotation_range() -> Range<usize> {
        3..6
    }
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self, String> {
        if let Some(m) = &spec.matrix {
            let m: Matrix4<f64> = fixed_matrix::<4, 4>("matrix", m)?;
            return Se3::try_from_matrix(&m).map_err(|e| e.to_string());
        }
        let xyz = spec.xyz.unwrap_or([0.0; 3]);
        check_values("xyz", &xyz)?;
        Ok(Se3::from_parts(Vector3::from(xyz), rotation3(spec)?))
    }
    fn to_se3(&self) -> Se3 {
        *self
    }
}

/// The permutation P with v_rotation_first = P v_translation_first.
fn rotation_first_permutation<G: SpecGroup<N>, const N: usize>() -> TangentMatrix<N> {
    let rot = G::rotation_range();
    let order: Vec<usize> = rot
        .clone()
        .chain((0..N).filter(|i| !rot.contains(i)))
        .collect();
    TangentMatrix::<N>::from_fn(|r, c| if order[r] == c { 1.0 } else { 0.0 })
}

/// Builds a validated covariance (on its stated side) from a specification.
pub(crate) fn cov_for<G: SpecGroup<N>, const N: usize>(
    spec: &CovSpec,
    mean: &G,
) -> Result<(TangentMatrix<N>, Side), String> {
    let given = [
        spec.std.is_some(),
        spec.std_deg.is_some(),
        spec.matrix.is_some(),
        spec.ros.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(
            "give the covariance in exactly one way: std, std_deg, matrix or ros".to_owned(),
        );
    }
    let rot = G::rotation_range();
    let from_std = |std: &[f64], degrees: bool| -> Result<TangentMatrix<N>, String> {
        check_values("std", std)?;
        if std.len() != N {
            return Err(format!(
                "std needs {N} numbers for {} (one per tangent axis), got {}",
                G::NAME,
                std.len()
            ));
        }
        if let Some(i) = std.iter().position(|s| *s < 0.0) {
            return Err(format!(
                "std[{i}] = {} is negative; a standard deviation is ≥ 0",
                std[i]
            ));
        }
        let mut cov = TangentMatrix::<N>::zeros();
        for (i, s) in std.iter().enumerate() {
            let s = if degrees && rot.contains(&i) {
                s.to_radians()
            } else {
                *s
            };
            cov[(i, i)] = s * s;
        }
        Ok(cov)
    };
    let mut cov = if let Some(std) = &spec.std {
        from_std(std, false)?
    } else if let Some(std) = &spec.std_deg {
        from_std(std, true)?
    } else if let Some(rows) = &spec.matrix {
        fixed_matrix::<N, N>("matrix", rows)?
    } else {
        ros_covariance::<G, N>(spec.ros.as_deref().unwrap_or(&[]), mean)?
    };
    if spec.order == Order::RotationFirst && spec.ros.is_none() {
        let p = rotation_first_permutation::<G, N>();
        cov = p.transpose() * cov * p;
    }
    let cov = validate_covariance("covariance", &cov).map_err(|e| e.to_string())?;
    let side = if spec.ros.is_some() {
        Side::Right
    } else {
        spec.side
    };
    Ok((cov, side))
}

/// ROS (x, y, z, rotX, rotY, rotZ), position error in parent axes, to the right form:
/// Σ_right = B⁻¹ Σ_ros B⁻ᵀ with B = blkdiag(R, I₃) (first order; CONVENTIONS §6).
fn ros_covariance<G: SpecGroup<N>, const N: usize>(
    ros: &[f64],
    mean: &G,
) -> Result<TangentMatrix<N>, String> {
    if N != 6 {
        return Err(format!(
            "`ros` covariances are 6×6 (SE(3)); this scenario's group is {}",
            G::NAME
        ));
    }
    check_values("ros", ros)?;
    if ros.len() != 36 {
        return Err(format!(
            "ros needs 36 numbers (6×6 row-major), got {}",
            ros.len()
        ));
    }
    let sigma_ros = Matrix6::from_row_slice(ros);
    let r = mean.to_se3().rotation().to_matrix();
    let mut b_inv = Matrix6::identity();
    b_inv.fixed_view_mut::<3, 3>(0, 0).copy_from(&r.transpose());
    let right = b_inv * sigma_ros * b_inv.transpose();
    Ok(TangentMatrix::<N>::from_iterator(right.iter().copied()))
}
