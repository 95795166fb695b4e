//! From the file's mean, covariance and control specifications to group elements and
//! validated matrices. Errors are [`ValueError`]s in the file's vocabulary; the lowering
//! attaches the location and the key.

use nalgebra::{Matrix4, SMatrix, Vector3};

use super::schema::{CovSpec, MeanSpec, Order};
use crate::interop::{
    EulerOrder, RosReading, VectorChart, ros_cov_to_right, rotation_first_permutation,
    se2_from_xytheta, se3_cov_from_euler,
};
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
    #[error("{key}[{index}] = {value} is negative; a standard deviation is ≥ 0")]
    NegativeStd {
        /// The key as the file writes it (`std` or `std_deg`).
        key: &'static str,
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
    /// A covariance key for other groups than the scenario's.
    #[error("`{key}` covariances are for {groups}; this scenario's group is {group}")]
    CovKeyNotForGroup {
        /// The key.
        key: &'static str,
        /// The groups it is for.
        groups: &'static str,
        /// The scenario's group.
        group: &'static str,
    },
    /// A modifier given without the key it modifies, or a key without its required modifier.
    #[error("{0}")]
    Modifier(&'static str),
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

    /// A ROS covariance (row-major numbers) at `mean` in the right form (SE(2), SE(3)).
    fn ros_cov(_ros: &[f64], _mean: &Self, _reading: RosReading) -> Result<TangentMatrix<N>> {
        Err(ValueError::CovKeyNotForGroup {
            key: "ros",
            groups: "SE(2) (9 numbers over x, y, yaw) and SE(3) (36 numbers)",
            group: Self::NAME,
        })
    }

    /// An Euler-angle covariance (row-major numbers) at `mean` in the right form (SE(3)).
    fn euler_cov(_euler: &[f64], _mean: &Self, _order: EulerOrder) -> Result<TangentMatrix<N>> {
        Err(ValueError::CovKeyNotForGroup {
            key: "euler",
            groups: "SE(3) (36 numbers)",
            group: Self::NAME,
        })
    }
}

/// `numbers` as an N×N row-major matrix, N² of them, each finite.
fn row_major<const N: usize>(key: &str, numbers: &[f64]) -> Result<TangentMatrix<N>> {
    check_values(key, numbers)?;
    if numbers.len() != N * N {
        return Err(ValueError::WrongCount {
            what: key.to_owned(),
            expected: N * N,
            why: format!("{N}×{N} row-major"),
            got: numbers.len(),
        });
    }
    Ok(TangentMatrix::<N>::from_row_slice(numbers))
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
    /// (x, y, yaw) with the position error in the parent axes: Σ_right = J⁻¹ Σ J⁻ᵀ,
    /// J = blkdiag(R, 1) ([`se2_from_xytheta`]). Both ROS readings agree in the plane (a yaw
    /// error is the same about the parent's z and the body's).
    fn ros_cov(ros: &[f64], mean: &Self, _reading: RosReading) -> Result<TangentMatrix<3>> {
        let ros = row_major::<3>("ros", ros)?;
        let ros = validate_covariance("ros", &ros)?;
        Ok(*se2_from_xytheta(&mean.to_coordinates(), &ros)?.cov())
    }

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
    /// [`ros_cov_to_right`]: Σ_right = B⁻¹ Σ_ros B⁻ᵀ, B = blkdiag(R, R) (tf2) or
    /// blkdiag(R, I₃) (body).
    fn ros_cov(ros: &[f64], mean: &Self, reading: RosReading) -> Result<TangentMatrix<6>> {
        let ros = row_major::<6>("ros", ros)?;
        Ok(ros_cov_to_right(&ros, mean.rotation(), reading))
    }

    /// [`se3_cov_from_euler`].
    fn euler_cov(euler: &[f64], mean: &Self, order: EulerOrder) -> Result<TangentMatrix<6>> {
        let euler = row_major::<6>("euler", euler)?;
        Ok(se3_cov_from_euler(mean, &euler, order))
    }

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
        ("euler", spec.euler.is_some()),
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
            allowed: "std, std_deg, matrix, ros, euler".to_owned(),
        });
    }
    let rot = G::rotation_range();
    let from_std = |std: &[f64], degrees: bool| -> Result<TangentMatrix<N>> {
        let key = if degrees { "std_deg" } else { "std" };
        let std = tangent_of::<N>(key, std, "one per tangent axis")?;
        if let Some(index) = std.iter().position(|s| *s < 0.0) {
            return Err(ValueError::NegativeStd {
                key,
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
    } else if let Some(ros) = &spec.ros {
        G::ros_cov(ros, mean, spec.reading.unwrap_or_default())?
    } else {
        let order = spec.euler_order.ok_or(ValueError::Modifier(
            "`euler` needs `euler_order`: \"xyz_rpy\" (robot_localization) or \"xyz_ypr\" (MRPT)",
        ))?;
        G::euler_cov(spec.euler.as_deref().unwrap_or(&[]), mean, order)?
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
    let converted = spec.ros.is_some() || spec.euler.is_some();
    if spec.order == Order::RotationFirst && converted {
        return Err(ValueError::Modifier(
            "`order` applies to `std`, `std_deg` and `matrix`; `ros` and `euler` name their own order",
        ));
    }
    if spec.side == Side::Left && converted {
        return Err(ValueError::Modifier(
            "`side` applies to `std`, `std_deg` and `matrix`; `ros` and `euler` are read in the parent axes",
        ));
    }
    if spec.reading.is_some() && spec.ros.is_none() {
        return Err(ValueError::Modifier("`reading` applies to `ros` only"));
    }
    if spec.euler_order.is_some() && spec.euler.is_none() {
        return Err(ValueError::Modifier(
            "`euler_order` applies to `euler` only",
        ));
    }
    if spec.order == Order::RotationFirst {
        let p = rotation_first_permutation::<G, N>();
        cov = p.transpose() * cov * p;
    }
    let cov = validate_covariance("covariance", &cov)?;
    let side = if converted { Side::Right } else { spec.side };
    Ok((cov, side))
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
