//! From the file's mean, covariance and control specifications to group elements and
//! validated matrices. Errors are [`ValueError`]s in the file's vocabulary; the lowering
//! attaches the location and the key.

use nalgebra::{Matrix4, Matrix6, SMatrix, Vector3};

use super::schema::{CovSpec, MeanSpec, Order};
use crate::interop::{ros_cov_to_right, rotation_first_permutation};
use crate::lie::{GroupKind, LieGroup, Se2, Se3, So2, So3, Tangent, TangentMatrix};
use crate::plan::{Control, limits};
use crate::uncertain::{Side, validate_covariance};

/// Why a value in a scenario file is not acceptable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ValueError {
    /// A key that does not describe this group's elements.
    #[error("`{key}` does not describe an element of {group}; use one of {allowed}")]
    KeyNotForGroup {
        /// The key given.
        key: &'static str,
        /// The scenario's group.
        group: &'static str,
        /// The keys that do.
        allowed: String,
    },
    /// Zero or several ways of giving one value.
    #[error("give the {what} in exactly one way (got {got}); use one of {allowed}")]
    NotExactlyOne {
        /// "mean" or "covariance".
        what: &'static str,
        /// The keys given.
        got: String,
        /// The keys accepted.
        allowed: String,
    },
    /// A number that is NaN or infinite.
    #[error("{what}[{index}] is {value}; every number must be finite")]
    NotFinite {
        /// The key.
        what: String,
        /// Position in the list.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A list of the wrong length.
    #[error("{what} needs {expected} numbers ({why}), got {got}")]
    WrongCount {
        /// The key.
        what: String,
        /// How many it needs.
        expected: usize,
        /// Why that many.
        why: String,
        /// How many were given.
        got: usize,
    },
    /// A matrix of the wrong shape.
    #[error("{what} must be {rows}×{cols} (rows of {cols}); got {got} rows of lengths {lengths:?}")]
    WrongShape {
        /// The key.
        what: String,
        /// Rows needed.
        rows: usize,
        /// Columns needed.
        cols: usize,
        /// Rows given.
        got: usize,
        /// Their lengths.
        lengths: Vec<usize>,
    },
    /// A negative standard deviation.
    #[error("std[{index}] = {value} is negative; a standard deviation is ≥ 0")]
    NegativeStd {
        /// Position in the list.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A magnitude beyond what can be computed and drawn.
    #[error("{what} = {value:e} is too large: at most {limit:e} in magnitude")]
    TooLarge {
        /// What.
        what: &'static str,
        /// The value.
        value: f64,
        /// The limit.
        limit: f64,
    },
    /// A ROS covariance in a group other than SE(3).
    #[error("`ros` covariances are 6×6 (SE(3)); this scenario's group is {group}")]
    RosNeedsSe3 {
        /// The scenario's group.
        group: &'static str,
    },
    /// The value is not a valid group element or covariance (the library's reason).
    #[error("{0}")]
    Invalid(#[from] crate::Error),
}

type Result<T> = std::result::Result<T, ValueError>;

/// Mean keys accepted per group.
fn mean_keys(kind: GroupKind) -> &'static [&'static str] {
    match kind {
        GroupKind::So2 => &["angle", "angle_deg", "matrix", "tangent"],
        GroupKind::Se2 => &["xy_theta", "xy_theta_deg", "matrix", "tangent"],
        GroupKind::So3 => &[
            "quaternion_xyzw",
            "rpy",
            "rpy_deg",
            "axis_angle",
            "matrix",
            "tangent",
        ],
        GroupKind::Se3 => &[
            "xyz",
            "quaternion_xyzw",
            "rpy",
            "rpy_deg",
            "axis_angle",
            "matrix",
            "tangent",
        ],
    }
}

/// A group whose elements scenario files can describe.
pub trait SpecGroup<const N: usize>: LieGroup<N> {
    /// Builds the mean from the keys that are set (already checked to be allowed).
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self>;
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

/// A mean that sets only keys of its group, in exactly one way.
pub(crate) fn mean_for<G: SpecGroup<N>, const N: usize>(spec: &MeanSpec) -> Result<G> {
    let allowed = mean_keys(G::KIND);
    let keys = mean_keys_set(spec);
    if let Some(bad) = keys.iter().find(|k| !allowed.contains(k)) {
        return Err(ValueError::KeyNotForGroup {
            key: bad,
            group: G::NAME,
            allowed: allowed.join(", "),
        });
    }
    let rotations = keys.iter().filter(|k| **k != "xyz").count();
    if keys.is_empty()
        || rotations > 1
        || (keys.contains(&"xyz") && (keys.contains(&"matrix") || keys.contains(&"tangent")))
    {
        return Err(ValueError::NotExactlyOne {
            what: "mean",
            got: if keys.is_empty() {
                "none".to_owned()
            } else {
                keys.join(" + ")
            },
            allowed: allowed.join(", "),
        });
    }
    let mean = match &spec.tangent {
        Some(t) => G::exp(&tangent_of::<N>("tangent", t, "one per tangent axis")?),
        None => G::mean_from_spec(spec)?,
    };
    let largest = mean.to_se3().translation().amax();
    if largest > limits::MAX_COORDINATE {
        return Err(ValueError::TooLarge {
            what: "a coordinate of the position",
            value: largest,
            limit: limits::MAX_COORDINATE,
        });
    }
    Ok(mean)
}

/// Every number finite, else the first one that is not.
pub(crate) fn check_values(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(ValueError::NotFinite {
            what: what.to_owned(),
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Exactly `N` finite numbers as a tangent vector.
pub(crate) fn tangent_of<const N: usize>(
    what: &str,
    values: &[f64],
    why: &str,
) -> Result<Tangent<N>> {
    check_values(what, values)?;
    if values.len() != N {
        return Err(ValueError::WrongCount {
            what: what.to_owned(),
            expected: N,
            why: why.to_owned(),
            got: values.len(),
        });
    }
    Ok(Tangent::<N>::from_column_slice(values))
}

/// A row-major `rows` as a fixed R×C matrix, checking its shape and values.
pub(crate) fn fixed_matrix<const R: usize, const C: usize>(
    what: &str,
    rows: &[Vec<f64>],
) -> Result<SMatrix<f64, R, C>> {
    if rows.len() != R || rows.iter().any(|r| r.len() != C) {
        return Err(ValueError::WrongShape {
            what: what.to_owned(),
            rows: R,
            cols: C,
            got: rows.len(),
            lengths: rows.iter().map(Vec::len).collect(),
        });
    }
    for (i, row) in rows.iter().enumerate() {
        check_values(&format!("{what} row {i}"), row)?;
    }
    Ok(SMatrix::<f64, R, C>::from_fn(|r, c| rows[r][c]))
}

fn rotation3(spec: &MeanSpec) -> Result<So3> {
    if let Some(q) = spec.quaternion_xyzw {
        check_values("quaternion_xyzw", &q)?;
        return Ok(So3::try_from_quaternion_xyzw(q)?);
    }
    if let Some(a) = spec.axis_angle {
        check_values("axis_angle", &a)?;
        return Ok(So3::try_from_axis_angle(
            &Vector3::new(a[0], a[1], a[2]),
            a[3],
        )?);
    }
    let rpy = spec
        .rpy
        .or(spec.rpy_deg.map(|d| d.map(f64::to_radians)))
        .unwrap_or([0.0; 3]);
    check_values("rpy", &rpy)?;
    Ok(So3::from_rpy(rpy[0], rpy[1], rpy[2]))
}

impl SpecGroup<1> for So2 {
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self> {
        if let Some(m) = &spec.matrix {
            return Ok(So2::try_from_matrix(&fixed_matrix::<2, 2>("matrix", m)?)?);
        }
        let angle = spec
            .angle
            .or(spec.angle_deg.map(f64::to_radians))
            .unwrap_or(0.0);
        check_values("angle", &[angle])?;
        Ok(So2::from_angle(angle))
    }
}

impl SpecGroup<3> for Se2 {
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self> {
        if let Some(m) = &spec.matrix {
            return Ok(Se2::try_from_matrix(&fixed_matrix::<3, 3>("matrix", m)?)?);
        }
        let v = spec
            .xy_theta
            .or(spec.xy_theta_deg.map(|[x, y, t]| [x, y, t.to_radians()]))
            .unwrap_or([0.0; 3]);
        check_values("xy_theta", &v)?;
        Ok(Se2::from_xy_theta(v[0], v[1], v[2]))
    }
}

impl SpecGroup<3> for So3 {
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self> {
        if let Some(m) = &spec.matrix {
            return Ok(So3::try_from_matrix(&fixed_matrix::<3, 3>("matrix", m)?)?);
        }
        rotation3(spec)
    }
}

impl SpecGroup<6> for Se3 {
    fn mean_from_spec(spec: &MeanSpec) -> Result<Self> {
        if let Some(m) = &spec.matrix {
            let m: Matrix4<f64> = fixed_matrix::<4, 4>("matrix", m)?;
            return Ok(Se3::try_from_matrix(&m)?);
        }
        let xyz = spec.xyz.unwrap_or([0.0; 3]);
        check_values("xyz", &xyz)?;
        Ok(Se3::from_parts(Vector3::from(xyz), rotation3(spec)?))
    }
}

/// A validated covariance (on its stated side) from a specification.
pub(crate) fn cov_for<G: SpecGroup<N>, const N: usize>(
    spec: &CovSpec,
    mean: &G,
) -> Result<(TangentMatrix<N>, Side)> {
    let given = [
        ("std", spec.std.is_some()),
        ("std_deg", spec.std_deg.is_some()),
        ("matrix", spec.matrix.is_some()),
        ("ros", spec.ros.is_some()),
    ];
    let set: Vec<&str> = given.iter().filter(|g| g.1).map(|g| g.0).collect();
    if set.len() != 1 {
        return Err(ValueError::NotExactlyOne {
            what: "covariance",
            got: if set.is_empty() {
                "none".to_owned()
            } else {
                set.join(" + ")
            },
            allowed: "std, std_deg, matrix, ros".to_owned(),
        });
    }
    let rot = G::rotation_range();
    let from_std = |std: &[f64], degrees: bool| -> Result<TangentMatrix<N>> {
        let key = if degrees { "std_deg" } else { "std" };
        let std = tangent_of::<N>(key, std, "one per tangent axis")?;
        if let Some(index) = std.iter().position(|s| *s < 0.0) {
            return Err(ValueError::NegativeStd {
                index,
                value: std[index],
            });
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
    // NaN too: an entry that overflowed in a conversion.
    if let Some(value) = cov
        .iter()
        .copied()
        .find(|v| v.is_nan() || v.abs() > limits::MAX_VARIANCE)
    {
        return Err(ValueError::TooLarge {
            what: "a covariance entry",
            value: value.abs(),
            limit: limits::MAX_VARIANCE,
        });
    }
    if spec.order == Order::RotationFirst && spec.ros.is_none() {
        let p = rotation_first_permutation::<G, N>();
        cov = p.transpose() * cov * p;
    }
    let cov = validate_covariance("covariance", &cov)?;
    let side = if spec.ros.is_some() {
        Side::Right
    } else {
        spec.side
    };
    Ok((cov, side))
}

/// ROS (x, y, z, rotX, rotY, rotZ), position error in parent axes, to the right form
/// ([`ros_cov_to_right`]).
fn ros_covariance<G: SpecGroup<N>, const N: usize>(
    ros: &[f64],
    mean: &G,
) -> Result<TangentMatrix<N>> {
    if N != 6 {
        return Err(ValueError::RosNeedsSe3 { group: G::NAME });
    }
    check_values("ros", ros)?;
    if ros.len() != 36 {
        return Err(ValueError::WrongCount {
            what: "ros".to_owned(),
            expected: 36,
            why: "6×6 row-major".to_owned(),
            got: ros.len(),
        });
    }
    let right = ros_cov_to_right(&Matrix6::from_row_slice(ros), mean.to_se3().rotation());
    Ok(TangentMatrix::<N>::from_iterator(right.iter().copied()))
}

/// An odometry control: the `increment` model reads the numbers as the group's natural
/// coordinates ((x, y, θ), (x, y, z, roll, pitch, yaw), angle or rpy), the `exp` model as a
/// tangent vector.
pub(crate) fn control_for<G: SpecGroup<N>, const N: usize>(
    numbers: &[f64],
    increment: bool,
) -> Result<Control<G, N>> {
    let tangent = tangent_of::<N>("control", numbers, "one per tangent axis")?;
    if !increment {
        return Ok(Control {
            increment: G::exp(&tangent),
            tangent,
        });
    }
    let spec = match G::KIND {
        GroupKind::So2 => MeanSpec {
            angle: Some(numbers[0]),
            ..Default::default()
        },
        GroupKind::Se2 => MeanSpec {
            xy_theta: Some([numbers[0], numbers[1], numbers[2]]),
            ..Default::default()
        },
        GroupKind::So3 => MeanSpec {
            rpy: Some([numbers[0], numbers[1], numbers[2]]),
            ..Default::default()
        },
        GroupKind::Se3 => MeanSpec {
            xyz: Some([numbers[0], numbers[1], numbers[2]]),
            rpy: Some([numbers[3], numbers[4], numbers[5]]),
            ..Default::default()
        },
    };
    let g = mean_for::<G, N>(&spec)?;
    Ok(Control {
        increment: g,
        tangent: g.log(),
    })
}
