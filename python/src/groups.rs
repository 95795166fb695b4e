//! The groups SO(2), SO(3), SE(2), SE(3) on NumPy arrays: one Python class per group, whose
//! static methods call `posecov::lie` (one copy of every formula: the library's). Elements are
//! their matrices (2×2, 3×3, 3×3, 4×4), tangents 1-D arrays in posecov's order (CONVENTIONS
//! §2: SE(2) [ρx, ρy, θ], SE(3) [ρ; θ], translation first), Jacobians with respect to right
//! perturbations (CONVENTIONS §4).

use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix};
use numpy::{PyArray1, PyArray2};
use posecov::lie::{LieGroup, Se2, Se3, So2, So3};
use pyo3::prelude::*;

use crate::arrays::{lib_err, matrix, out_matrix, out_vector, vector};

/// A group whose elements cross the boundary as D×D matrices, checked on the way in.
pub trait PyGroup<const N: usize, const D: usize>:
    LieGroup<N, Matrix = SMatrix<f64, D, D>>
{
    /// The element of a matrix, refused unless it is one (a rotation, a homogeneous transform).
    fn from_matrix(m: &SMatrix<f64, D, D>) -> posecov::Result<Self>;
}

impl PyGroup<1, 2> for So2 {
    fn from_matrix(m: &Matrix2<f64>) -> posecov::Result<Self> {
        So2::try_from_matrix(m)
    }
}

impl PyGroup<3, 3> for So3 {
    fn from_matrix(m: &Matrix3<f64>) -> posecov::Result<Self> {
        So3::try_from_matrix(m)
    }
}

impl PyGroup<3, 3> for Se2 {
    fn from_matrix(m: &Matrix3<f64>) -> posecov::Result<Self> {
        Se2::try_from_matrix(m)
    }
}

impl PyGroup<6, 4> for Se3 {
    fn from_matrix(m: &Matrix4<f64>) -> posecov::Result<Self> {
        Se3::try_from_matrix(m)
    }
}

/// The element of the array-like `value` (argument `what`): shape, finiteness, then the
/// group's own check (orthonormal, right-handed, last row [0, …, 0, 1]).
pub fn element<G: PyGroup<N, D>, const N: usize, const D: usize>(
    what: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<G> {
    let m = matrix::<D, D>(what, value)?;
    G::from_matrix(&m).map_err(|e| crate::arrays::bad(what, e))
}

/// A pair of Jacobians as a tuple of arrays.
type Pair<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// One class per group, its static methods the library's operations.
macro_rules! group_class {
    ($class:ident, $name:literal, $G:ty, $N:literal, $D:literal, $order:literal, $tau:literal,
     { $($extra:tt)* }) => {
        #[doc = concat!("The group ", $name, " on NumPy arrays (static methods only). Elements are ",
            stringify!($D), "×", stringify!($D), " matrices; tangent vectors τ have ", stringify!($N),
            " entries in the order ", $order, " (posecov's CONVENTIONS §2); Jacobians are taken \
            with respect to right perturbations X ⊕ δ = X · Exp(δ) (CONVENTIONS §4).\n\n\
            >>> import numpy as np, posecov\n\
            >>> X = posecov.", stringify!($class), ".exp(", $tau, ")\n\
            >>> np.allclose(posecov.", stringify!($class), ".log(X), ", $tau, ")\nTrue")]
        #[pyclass(frozen, module = "posecov._posecov")]
        pub struct $class;

        #[pymethods]
        impl $class {
            #[doc = concat!("The tangent dimension of ", $name, " (", stringify!($N), ").")]
            #[classattr]
            const DOF: usize = $N;

            #[doc = concat!("The tangent order of ", $name, ": ", $order, ".")]
            #[classattr]
            const ORDER: &'static str = $order;

            #[doc = concat!("The identity of ", $name, ", a ", stringify!($D), "×", stringify!($D),
                " matrix.\n\n>>> posecov.", stringify!($class), ".identity().shape\n(",
                stringify!($D), ", ", stringify!($D), ")")]
            #[staticmethod]
            fn identity(py: Python<'_>) -> Bound<'_, PyArray2<f64>> {
                out_matrix(py, &<$G>::identity().to_matrix())
            }

            #[doc = concat!("Exp(τ) = exp(hat(τ)): the element of the tangent τ, order ", $order,
                ".\n\n>>> posecov.", stringify!($class), ".exp(", $tau, ").shape\n(",
                stringify!($D), ", ", stringify!($D), ")")]
            #[staticmethod]
            fn exp<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::exp(&vector::<$N>("tau", tau)?).to_matrix()))
            }

            #[doc = concat!("Log(X): the tangent τ (order ", $order, ") with Exp(τ) = X, rotation \
                angle |θ| ≤ π.\n\n>>> posecov.", stringify!($class), ".log(posecov.",
                stringify!($class), ".identity()).shape\n(", stringify!($N), ",)")]
            #[staticmethod]
            fn log<'py>(py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
                Ok(out_vector(py, &element::<$G, $N, $D>("x", x)?.log()))
            }

            #[doc = concat!("hat(τ): the Lie-algebra matrix of τ (order ", $order, ").\n\n\
                >>> posecov.", stringify!($class), ".hat(", $tau, ").shape\n(", stringify!($D),
                ", ", stringify!($D), ")")]
            #[staticmethod]
            fn hat<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::hat(&vector::<$N>("tau", tau)?)))
            }

            #[doc = concat!("vee(A): the tangent of a Lie-algebra matrix (reads the entries hat \
                writes), order ", $order, ".\n\n>>> posecov.", stringify!($class), ".vee(posecov.",
                stringify!($class), ".hat(", $tau, ")).shape\n(", stringify!($N), ",)")]
            #[staticmethod]
            fn vee<'py>(py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
                Ok(out_vector(py, &<$G>::vee(&matrix::<$D, $D>("a", a)?)))
            }

            #[doc = concat!("X · Y, e.g. world_from_cam = compose(world_from_body, body_from_cam).\n\n\
                >>> I = posecov.", stringify!($class), ".identity()\n\
                >>> bool((posecov.", stringify!($class), ".compose(I, I) == I).all())\nTrue")]
            #[staticmethod]
            fn compose<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, y: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let (x, y) = (element::<$G, $N, $D>("x", x)?, element::<$G, $N, $D>("y", y)?);
                Ok(out_matrix(py, &x.compose(&y).to_matrix()))
            }

            #[doc = concat!("X⁻¹.\n\n>>> X = posecov.", stringify!($class), ".exp(", $tau, ")\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class),
                ".compose(X, posecov.", stringify!($class), ".inverse(X)), np.eye(", stringify!($D), "))\nTrue")]
            #[staticmethod]
            fn inverse<'py>(py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &element::<$G, $N, $D>("x", x)?.inverse().to_matrix()))
            }

            #[doc = concat!("X⁻¹ · Y: Y seen from X (between(world_from_a, world_from_b) = a_from_b).\n\n\
                >>> X = posecov.", stringify!($class), ".exp(", $tau, ")\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class), ".between(X, X), np.eye(",
                stringify!($D), "))\nTrue")]
            #[staticmethod]
            fn between<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, y: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let (x, y) = (element::<$G, $N, $D>("x", x)?, element::<$G, $N, $D>("y", y)?);
                Ok(out_matrix(py, &x.between(&y).to_matrix()))
            }

            #[doc = concat!("X ⊕ τ = X · Exp(τ) (right plus; τ in X's body frame, order ", $order, ").\n\n\
                >>> X = posecov.", stringify!($class), ".identity()\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class), ".rplus(X, ", $tau,
                "), posecov.", stringify!($class), ".exp(", $tau, "))\nTrue")]
            #[staticmethod]
            fn rplus<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let x = element::<$G, $N, $D>("x", x)?;
                Ok(out_matrix(py, &x.rplus(&vector::<$N>("tau", tau)?).to_matrix()))
            }

            #[doc = concat!("Y ⊖ X = Log(X⁻¹ · Y) (right minus; in X's body frame, order ", $order, ").\n\n\
                >>> X = posecov.", stringify!($class), ".exp(", $tau, ")\n\
                >>> float(abs(posecov.", stringify!($class), ".rminus(X, X)).max()) < 1e-15\nTrue")]
            #[staticmethod]
            fn rminus<'py>(py: Python<'py>, y: &Bound<'py, PyAny>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
                let (y, x) = (element::<$G, $N, $D>("y", y)?, element::<$G, $N, $D>("x", x)?);
                Ok(out_vector(py, &y.rminus(&x)))
            }

            #[doc = concat!("The adjoint Ad_X (", stringify!($N), "×", stringify!($N),
                "), Ad_X τ = vee(X · hat(τ) · X⁻¹); Σ_left = Ad_μ Σ_right Ad_μᵀ (CONVENTIONS §3–4).\n\n\
                >>> posecov.", stringify!($class), ".adjoint(posecov.", stringify!($class),
                ".identity()).shape\n(", stringify!($N), ", ", stringify!($N), ")")]
            #[staticmethod]
            fn adjoint<'py>(py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &element::<$G, $N, $D>("x", x)?.adj()))
            }

            #[doc = concat!("The small adjoint ad_τ, ad_τ σ = vee([hat τ, hat σ]).\n\n\
                >>> posecov.", stringify!($class), ".small_adjoint(", $tau, ").shape\n(",
                stringify!($N), ", ", stringify!($N), ")")]
            #[staticmethod]
            fn small_adjoint<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::ad(&vector::<$N>("tau", tau)?)))
            }

            #[doc = concat!("Right Jacobian Jr(τ): Exp(τ + δ) ≈ Exp(τ) · Exp(Jr(τ) δ) (order ", $order, ").\n\n\
                >>> posecov.", stringify!($class), ".jr(", $tau, ").shape\n(", stringify!($N), ", ",
                stringify!($N), ")")]
            #[staticmethod]
            fn jr<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::jr(&vector::<$N>("tau", tau)?)))
            }

            #[doc = concat!("Left Jacobian Jl(τ) = Jr(−τ): Exp(τ + δ) ≈ Exp(Jl(τ) δ) · Exp(τ).\n\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class), ".jl(", $tau,
                "), posecov.", stringify!($class), ".jr(-np.asarray(", $tau, ", dtype=float)))\nTrue")]
            #[staticmethod]
            fn jl<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::jl(&vector::<$N>("tau", tau)?)))
            }

            #[doc = concat!("Jr(τ)⁻¹ (finite for rotation angles below 2π).\n\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class), ".jr_inv(", $tau,
                ") @ posecov.", stringify!($class), ".jr(", $tau, "), np.eye(", stringify!($N), "))\nTrue")]
            #[staticmethod]
            fn jr_inv<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::jr_inv(&vector::<$N>("tau", tau)?)))
            }

            #[doc = concat!("Jl(τ)⁻¹.\n\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class), ".jl_inv(", $tau,
                ") @ posecov.", stringify!($class), ".jl(", $tau, "), np.eye(", stringify!($N), "))\nTrue")]
            #[staticmethod]
            fn jl_inv<'py>(py: Python<'py>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &<$G>::jl_inv(&vector::<$N>("tau", tau)?)))
            }

            #[doc = concat!("Jacobians of Z = X · Y with respect to right perturbations of X and \
                of Y: (Ad_Y⁻¹, I) (CONVENTIONS §4).\n\n\
                >>> I = posecov.", stringify!($class), ".identity()\n\
                >>> [j.shape for j in posecov.", stringify!($class), ".compose_jacobians(I, I)]\n[(",
                stringify!($N), ", ", stringify!($N), "), (", stringify!($N), ", ", stringify!($N), ")]")]
            #[staticmethod]
            fn compose_jacobians<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, y: &Bound<'py, PyAny>) -> PyResult<Pair<'py>> {
                let (x, y) = (element::<$G, $N, $D>("x", x)?, element::<$G, $N, $D>("y", y)?);
                let j = x.compose_jacobians(&y);
                Ok((out_matrix(py, &j.wrt_lhs), out_matrix(py, &j.wrt_rhs)))
            }

            #[doc = concat!("Jacobians of Z = X⁻¹ · Y with respect to right perturbations of X \
                and of Y.\n\n>>> I = posecov.", stringify!($class), ".identity()\n\
                >>> len(posecov.", stringify!($class), ".between_jacobians(I, I))\n2")]
            #[staticmethod]
            fn between_jacobians<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, y: &Bound<'py, PyAny>) -> PyResult<Pair<'py>> {
                let (x, y) = (element::<$G, $N, $D>("x", x)?, element::<$G, $N, $D>("y", y)?);
                let j = x.between_jacobians(&y);
                Ok((out_matrix(py, &j.wrt_lhs), out_matrix(py, &j.wrt_rhs)))
            }

            #[doc = concat!("Jacobian of X⁻¹ with respect to a right perturbation of X: −Ad_X.\n\n\
                >>> import numpy as np; X = posecov.", stringify!($class), ".exp(", $tau, ")\n\
                >>> np.allclose(posecov.", stringify!($class), ".inverse_jacobian(X), -posecov.",
                stringify!($class), ".adjoint(X))\nTrue")]
            #[staticmethod]
            fn inverse_jacobian<'py>(py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                Ok(out_matrix(py, &element::<$G, $N, $D>("x", x)?.inverse_jacobian()))
            }

            #[doc = concat!("Jacobians of X ⊕ τ with respect to X and to τ: (Ad_{Exp τ}⁻¹, Jr(τ)).\n\n\
                >>> I = posecov.", stringify!($class), ".identity()\n\
                >>> len(posecov.", stringify!($class), ".rplus_jacobians(I, ", $tau, "))\n2")]
            #[staticmethod]
            fn rplus_jacobians<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, tau: &Bound<'py, PyAny>) -> PyResult<Pair<'py>> {
                let x = element::<$G, $N, $D>("x", x)?;
                let j = x.rplus_jacobians(&vector::<$N>("tau", tau)?);
                Ok((out_matrix(py, &j.wrt_group), out_matrix(py, &j.wrt_tangent)))
            }

            #[doc = concat!("The geodesic X · Exp(t · Log(X⁻¹ Y)), t in [0, 1].\n\n\
                >>> I = posecov.", stringify!($class), ".identity()\n\
                >>> import numpy as np; np.allclose(posecov.", stringify!($class), ".interpolate(I, I, 0.5), I)\nTrue")]
            #[staticmethod]
            fn interpolate<'py>(py: Python<'py>, x: &Bound<'py, PyAny>, y: &Bound<'py, PyAny>, t: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let (x, y) = (element::<$G, $N, $D>("x", x)?, element::<$G, $N, $D>("y", y)?);
                if !t.is_finite() {
                    return Err(crate::arrays::bad("t", format!("{t} is not finite")));
                }
                Ok(out_matrix(py, &x.interpolate(&y, t).to_matrix()))
            }

            $($extra)*
        }
    };
}

group_class!(SO2, "SO(2)", So2, 1, 2, "[θ]", "0.3", {});

group_class!(
    SO3,
    "SO(3)",
    So3,
    3,
    3,
    "[θx, θy, θz] (axis times angle)",
    "[0.1, 0.2, 0.3]",
    {
        /// The rotation of a quaternion given as (x, y, z, w) (ROS order); refused unless its norm
        /// is within 1e-6 of 1 (small rounding is normalised away).
        ///
        /// >>> import numpy as np; np.allclose(posecov.SO3.from_quaternion([0, 0, 0, 1]), np.eye(3))
        /// True
        #[staticmethod]
        fn from_quaternion<'py>(
            py: Python<'py>,
            xyzw: &Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyArray2<f64>>> {
            let q = vector::<4>("xyzw", xyzw)?;
            let r = So3::try_from_quaternion_xyzw([q[0], q[1], q[2], q[3]]).map_err(lib_err)?;
            Ok(out_matrix(py, &r.to_matrix()))
        }

        /// The unit quaternion (x, y, z, w) of a rotation matrix (w ≥ 0).
        ///
        /// >>> posecov.SO3.to_quaternion(posecov.SO3.identity()).tolist()
        /// [0.0, 0.0, 0.0, 1.0]
        #[staticmethod]
        fn to_quaternion<'py>(
            py: Python<'py>,
            r: &Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyArray1<f64>>> {
            let r = element::<So3, 3, 3>("r", r)?;
            Ok(PyArray1::from_slice(py, &r.to_quaternion_xyzw()))
        }
    }
);

group_class!(
    SE2,
    "SE(2)",
    Se2,
    3,
    3,
    "[ρx, ρy, θ]",
    "[1.0, 2.0, 0.5]",
    {}
);

group_class!(
    SE3,
    "SE(3)",
    Se3,
    6,
    4,
    "[ρx, ρy, ρz, θx, θy, θz] (translation first)",
    "[1.0, -0.5, 2.0, 0.1, 0.2, 0.3]",
    {
        /// The transform of a position (x, y, z) and a quaternion (x, y, z, w) (ROS order).
        ///
        /// >>> posecov.SE3.from_xyz_quaternion([1, 2, 3], [0, 0, 0, 1])[:3, 3].tolist()
        /// [1.0, 2.0, 3.0]
        #[staticmethod]
        fn from_xyz_quaternion<'py>(
            py: Python<'py>,
            xyz: &Bound<'py, PyAny>,
            xyzw: &Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyArray2<f64>>> {
            let p = vector::<3>("xyz", xyz)?;
            let q = vector::<4>("xyzw", xyzw)?;
            let x = Se3::try_from_xyz_quaternion_xyzw([p[0], p[1], p[2]], [q[0], q[1], q[2], q[3]])
                .map_err(lib_err)?;
            Ok(out_matrix(py, &x.to_matrix()))
        }
    }
);
