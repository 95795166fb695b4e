//! `posecov.UncertainPose`: a mean on a group, a covariance in its tangent space and the side
//! it multiplies (CONVENTIONS §3), with the library's propagations (first order, Barfoot &
//! Furgale's second and fourth order, sigma points) and seeded sampling. Every number goes
//! through `posecov::uncertain`, `posecov::propagate` and `posecov::sample`: nothing here
//! computes a covariance itself.

use nalgebra::SMatrix;
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use posecov::interop::rotation_first_permutation;
use posecov::lie::{LieGroup, Se2, Se3, So2, So3, TangentMatrix};
use posecov::propagate::first_order;
use posecov::propagate::fourth_order::{self, Order};
use posecov::propagate::sigma_point::{self, JointInputs, Unscented};
use posecov::sample::{Sampler, sample_statistics};
use posecov::uncertain::{Side, UncertainPose as Pose};
use pyo3::prelude::*;

use crate::PosecovError;
use crate::arrays::{bad, lib_err, matrix, out_matrix};
use crate::groups::{PyGroup, element};

/// At most this many samples per call (8 × 10⁶ SE(3) samples are 1 GiB of matrices).
const MAX_SAMPLES: usize = 10_000_000;

/// One uncertain pose of any of the four groups. It only lives inside a Python object (already
/// one heap allocation of its own), so the SE(3) variant's size is not boxed away.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
enum Any {
    So2(Pose<So2, 1>),
    So3(Pose<So3, 3>),
    Se2(Pose<Se2, 3>),
    Se3(Pose<Se3, 6>),
}

/// Runs `$body` with `$p` bound to the typed pose and `$G`, `$N`, `$D` its group, DOF and
/// matrix size, wrapping a pose result back into `Any` with `$wrap`.
macro_rules! each {
    ($any:expr, |$p:ident: $G:ident, $N:ident, $D:ident, $wrap:ident| $body:expr) => {
        match $any {
            Any::So2($p) => {
                #[allow(dead_code)]
                type $G = So2;
                #[allow(dead_code)]
                const $N: usize = 1;
                #[allow(dead_code)]
                const $D: usize = 2;
                let $wrap = Any::So2;
                $body
            }
            Any::So3($p) => {
                #[allow(dead_code)]
                type $G = So3;
                #[allow(dead_code)]
                const $N: usize = 3;
                #[allow(dead_code)]
                const $D: usize = 3;
                let $wrap = Any::So3;
                $body
            }
            Any::Se2($p) => {
                #[allow(dead_code)]
                type $G = Se2;
                #[allow(dead_code)]
                const $N: usize = 3;
                #[allow(dead_code)]
                const $D: usize = 3;
                let $wrap = Any::Se2;
                $body
            }
            Any::Se3($p) => {
                #[allow(dead_code)]
                type $G = Se3;
                #[allow(dead_code)]
                const $N: usize = 6;
                #[allow(dead_code)]
                const $D: usize = 4;
                let $wrap = Any::Se3;
                $body
            }
        }
    };
}

fn side_of(word: &str) -> PyResult<Side> {
    match word.to_ascii_lowercase().as_str() {
        "right" | "body" | "local" => Ok(Side::Right),
        "left" | "world" | "global" => Ok(Side::Left),
        _ => Err(bad(
            "side",
            format!("{word:?}: expected \"right\" (body, local) or \"left\" (world, global)"),
        )),
    }
}

fn side_word(side: Side) -> &'static str {
    match side {
        Side::Right => "right",
        Side::Left => "left",
    }
}

/// Whether `order` names rotation first ([θ; ρ]); refused unless it is one of the two words.
fn rotation_first(order: &str) -> PyResult<bool> {
    match order {
        "translation_first" => Ok(false),
        "rotation_first" => Ok(true),
        _ => Err(bad(
            "order",
            format!(
                "{order:?}: expected \"translation_first\" ([ρ; θ], posecov's) or \"rotation_first\" ([θ; ρ], GTSAM, pytransform3d)"
            ),
        )),
    }
}

/// Σ in posecov's order from Σ in `order` (Pᵀ Σ' P), or the other way (P Σ Pᵀ).
fn reorder<G: LieGroup<N>, const N: usize>(
    cov: &TangentMatrix<N>,
    rotation_first: bool,
    into_posecov: bool,
) -> TangentMatrix<N> {
    if !rotation_first {
        return *cov;
    }
    let p = rotation_first_permutation::<G, N>();
    if into_posecov {
        p.transpose() * cov * p
    } else {
        p * cov * p.transpose()
    }
}

fn typed<G: PyGroup<N, D>, const N: usize, const D: usize>(
    mean: &Bound<'_, PyAny>,
    cov: &Bound<'_, PyAny>,
    side: Side,
    rotation_first: bool,
) -> PyResult<Pose<G, N>> {
    let mean = element::<G, N, D>("mean", mean)?;
    let cov: SMatrix<f64, N, N> = matrix::<N, N>("cov", cov)?;
    Pose::try_new(mean, reorder::<G, N>(&cov, rotation_first, true), side).map_err(lib_err)
}

fn check_samples(n: usize) -> PyResult<()> {
    if (2..=MAX_SAMPLES).contains(&n) {
        Ok(())
    } else {
        Err(bad(
            "samples",
            format!("{n} is out of range: 2 ..= {MAX_SAMPLES}"),
        ))
    }
}

/// Poses as an (n, D, D) array of their matrices.
fn stack<'py, G: LieGroup<N, Matrix = SMatrix<f64, D, D>>, const N: usize, const D: usize>(
    py: Python<'py>,
    poses: &[G],
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let mut flat = Vec::with_capacity(poses.len() * D * D);
    for x in poses {
        let m = x.to_matrix();
        for r in 0..D {
            for c in 0..D {
                flat.push(m[(r, c)]);
            }
        }
    }
    PyArray1::from_vec(py, flat).reshape([poses.len(), D, D])
}

/// A pose with a Gaussian uncertainty on its group: mean μ (a matrix), covariance Σ and the
/// side it multiplies. Right (body, the default): X = μ · Exp(ε); left (world):
/// X = Exp(ε) · μ; ε ~ N(0, Σ) (CONVENTIONS §3). Σ is given in the tangent order `order`:
/// "translation_first" (posecov's: SE(2) [ρx, ρy, θ], SE(3) [ρ; θ]) or "rotation_first"
/// ([θ; ρ], as GTSAM's Pose3 and pytransform3d's exponential coordinates), converted once at
/// the boundary (Σ = Pᵀ Σ' P); `cov` always returns posecov's order, `cov_in(order)` either.
/// Refused (`PosecovError`): a mean that is not a group element, a Σ of the wrong shape, not
/// finite, not symmetric or not positive semi-definite.
///
/// >>> import numpy as np, posecov
/// >>> x = posecov.UncertainPose("SE2", posecov.SE2.exp([1.0, 0.0, 0.0]), np.diag([0.0, 0.0, 0.01]))
/// >>> z = x.compose(posecov.UncertainPose("SE2", posecov.SE2.exp([2.0, 0.0, 0.0]), np.zeros((3, 3))))
/// >>> round(float(z.cov[1, 1]), 6)  # a 0.1 rad heading σ swings 2 m ahead by 0.2 m
/// 0.04
#[pyclass(frozen, module = "posecov._posecov")]
#[derive(Clone)]
pub struct UncertainPose {
    pose: Any,
}

impl UncertainPose {
    fn wrap(pose: Any) -> Self {
        Self { pose }
    }

    /// `other` as the same group as `self`, or an error naming both.
    fn same_group(&self, other: &UncertainPose) -> PyResult<()> {
        if std::mem::discriminant(&self.pose) == std::mem::discriminant(&other.pose) {
            Ok(())
        } else {
            Err(bad(
                "other",
                format!(
                    "a pose of {} cannot be combined with a pose of {}",
                    other.group(),
                    self.group()
                ),
            ))
        }
    }
}

#[pymethods]
impl UncertainPose {
    #[new]
    #[pyo3(signature = (group, mean, cov, side = "right", order = "translation_first"))]
    fn new(
        group: &str,
        mean: &Bound<'_, PyAny>,
        cov: &Bound<'_, PyAny>,
        side: &str,
        order: &str,
    ) -> PyResult<Self> {
        let side = side_of(side)?;
        let rf = rotation_first(order)?;
        let pose = match group.to_ascii_uppercase().replace(['(', ')'], "").as_str() {
            "SO2" => Any::So2(typed::<So2, 1, 2>(mean, cov, side, rf)?),
            "SO3" => Any::So3(typed::<So3, 3, 3>(mean, cov, side, rf)?),
            "SE2" => Any::Se2(typed::<Se2, 3, 3>(mean, cov, side, rf)?),
            "SE3" => Any::Se3(typed::<Se3, 6, 4>(mean, cov, side, rf)?),
            _ => {
                return Err(bad(
                    "group",
                    format!("{group:?}: expected one of \"SO2\", \"SO3\", \"SE2\", \"SE3\""),
                ));
            }
        };
        Ok(Self::wrap(pose))
    }

    /// The group's name: "SO2", "SO3", "SE2" or "SE3".
    #[getter]
    fn group(&self) -> &'static str {
        match self.pose {
            Any::So2(_) => "SO2",
            Any::So3(_) => "SO3",
            Any::Se2(_) => "SE2",
            Any::Se3(_) => "SE3",
        }
    }

    /// The mean μ as a matrix (2×2, 3×3, 3×3 or 4×4).
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        each!(self.pose, |p: G, N, D, _w| out_matrix(
            py,
            &p.mean().to_matrix()
        ))
    }

    /// Σ in posecov's tangent order (translation first), on `side`.
    #[getter]
    fn cov<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        each!(self.pose, |p: G, N, D, _w| out_matrix(py, p.cov()))
    }

    /// "right" (X = μ · Exp(ε), Σ in the body frame) or "left" (X = Exp(ε) · μ, world frame).
    #[getter]
    fn side(&self) -> &'static str {
        each!(self.pose, |p: G, N, D, _w| side_word(p.side()))
    }

    /// The tangent order of `cov`: "translation_first" (posecov's, CONVENTIONS §2).
    #[getter]
    fn order(&self) -> &'static str {
        "translation_first"
    }

    /// Σ in the tangent order `order` ("translation_first" or "rotation_first").
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE3", np.eye(4), np.diag([1., 2, 3, 4, 5, 6]))
    /// >>> np.diag(x.cov_in("rotation_first")).tolist()
    /// [4.0, 5.0, 6.0, 1.0, 2.0, 3.0]
    fn cov_in<'py>(&self, py: Python<'py>, order: &str) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rf = rotation_first(order)?;
        Ok(each!(self.pose, |p: G, N, D, _w| out_matrix(
            py,
            &reorder::<G, N>(p.cov(), rf, false)
        )))
    }

    /// The same distribution (to first order) on the other side: Σ_left = Ad_μ Σ_right Ad_μᵀ.
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", posecov.SE2.exp([1, 2, 0.5]), np.eye(3) * 0.01)
    /// >>> x.to_side("left").side
    /// 'left'
    fn to_side(&self, side: &str) -> PyResult<Self> {
        let side = side_of(side)?;
        Ok(Self::wrap(each!(self.pose, |p: G, N, D, w| w(
            p.to_side(side)
        ))))
    }

    /// X⁻¹, exact on both sides: right Σ → Ad_μ Σ Ad_μᵀ (CONVENTIONS §5).
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", posecov.SE2.exp([1, 2, 0.5]), np.eye(3) * 0.01)
    /// >>> np.allclose(x.inverse().inverse().cov, x.cov)
    /// True
    fn inverse(&self) -> Self {
        Self::wrap(each!(self.pose, |p: G, N, D, w| w(first_order::inverse(
            &p
        )
        .pose)))
    }

    /// A known transform on the left, A · X (the pose re-expressed in another reference frame,
    /// `world_from_map · map_from_robot`): exact, right Σ unchanged, left Ad_A Σ Ad_Aᵀ.
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", np.eye(3), np.eye(3) * 0.01)
    /// >>> np.allclose(x.change_frame_left(posecov.SE2.exp([5, 0, 1])).cov, x.cov)
    /// True
    fn change_frame_left(&self, a_from_b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self::wrap(each!(self.pose, |p: G, N, D, w| {
            let a = element::<G, N, D>("a_from_b", a_from_b)?;
            w(first_order::change_frame_left(&a, &p).pose)
        })))
    }

    /// A known transform on the right, X · B (a sensor mounting, `world_from_body ·
    /// body_from_cam`): exact, right Ad_{B⁻¹} Σ Ad_{B⁻¹}ᵀ, left Σ unchanged.
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", np.eye(3), np.diag([0, 0, 0.01]))
    /// >>> round(float(x.change_frame_right(posecov.SE2.exp([1, 0, 0])).cov[1, 1]), 6)
    /// 0.01
    fn change_frame_right(&self, b_from_c: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self::wrap(each!(self.pose, |p: G, N, D, w| {
            let b = element::<G, N, D>("b_from_c", b_from_c)?;
            w(first_order::change_frame_right(&p, &b).pose)
        })))
    }

    /// Z = X · Y of two independent uncertain poses of the same group.
    ///
    /// `method`: "first_order" (on X's side; right Σ_Z = Ad_{μY⁻¹} Σ_X Ad_{μY⁻¹}ᵀ + Σ_Y,
    /// CONVENTIONS §5), "second_order" or "fourth_order" (Barfoot & Furgale 2014 eq. 38 and
    /// eq. 55, SE(2) and SE(3) only; the result is on the left side, as in the paper),
    /// "sigma_points" (the unscented transform on the manifold with `alpha`, `beta`, `kappa`,
    /// result on X's side).
    ///
    /// >>> import numpy as np, posecov
    /// >>> step = posecov.UncertainPose("SE3", posecov.SE3.exp([1, 0, 0, 0, 0, 0]), np.diag([0, 0, 0, 0, 0, 0.0009]), side="left")
    /// >>> two = step.compose(step, method="fourth_order")
    /// >>> two.side, float(two.cov[0, 0]) > 0.0
    /// ('left', True)
    #[pyo3(signature = (other, method = "first_order", alpha = 1.0, beta = 2.0, kappa = 0.0))]
    fn compose(
        &self,
        other: &UncertainPose,
        method: &str,
        alpha: f64,
        beta: f64,
        kappa: f64,
    ) -> PyResult<Self> {
        self.same_group(other)?;
        let order = match method {
            "second_order" => Some(Order::Second),
            "fourth_order" => Some(Order::Fourth),
            _ => None,
        };
        let pose = match (self.pose, other.pose, order) {
            (Any::Se3(a), Any::Se3(b), Some(o)) => {
                Any::Se3(fourth_order::compound_se3(&a, &b, o).pose)
            }
            (Any::Se2(a), Any::Se2(b), Some(o)) => {
                Any::Se2(fourth_order::compound_se2(&a, &b, o).pose)
            }
            (_, _, Some(_)) => {
                return Err(bad(
                    "method",
                    format!(
                        "{method:?} compounds SE(2) and SE(3) poses, not {}",
                        self.group()
                    ),
                ));
            }
            (a, b, None) => {
                let params = Unscented {
                    alpha,
                    beta,
                    kappa,
                    side: Side::Right,
                };
                pair(a, b, method, params)?
            }
        };
        Ok(Self::wrap(pose))
    }

    /// Z = X⁻¹ · Y (Y seen from X) of two independent uncertain poses, first order, on X's
    /// side (CONVENTIONS §5).
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", np.eye(3), np.diag([0.01, 0.01, 0]))
    /// >>> round(float(x.between(x).cov[0, 0]), 6)
    /// 0.02
    fn between(&self, other: &UncertainPose) -> PyResult<Self> {
        self.same_group(other)?;
        let pose = match (self.pose, other.pose) {
            (Any::So2(a), Any::So2(b)) => Any::So2(first_order::between(&a, &b).pose),
            (Any::So3(a), Any::So3(b)) => Any::So3(first_order::between(&a, &b).pose),
            (Any::Se2(a), Any::Se2(b)) => Any::Se2(first_order::between(&a, &b).pose),
            (Any::Se3(a), Any::Se3(b)) => Any::Se3(first_order::between(&a, &b).pose),
            _ => unreachable!("same_group checked the groups"),
        };
        Ok(Self::wrap(pose))
    }

    /// `n` poses drawn from this distribution with `seed` (ChaCha8, the same numbers whatever
    /// the thread count), as an (n, D, D) array of matrices: X = μ · Exp(L z) (right) or
    /// Exp(L z) · μ (left), L Lᵀ = Σ, z ~ N(0, I).
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", np.eye(3), np.eye(3) * 0.01)
    /// >>> x.sample(1000, seed=7).shape
    /// (1000, 3, 3)
    #[pyo3(signature = (n, seed = 0))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        n: usize,
        seed: u64,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        check_samples(n)?;
        each!(self.pose, |p: G, N, D, _w| {
            let samples = Sampler::new(&p).map_err(lib_err)?.draw_par(n, seed);
            stack::<G, N, D>(py, &samples)
        })
    }

    /// Monte Carlo of Z = X · Y: `n` seeded samples of each (X from `seed`, Y from `seed + 1`),
    /// composed, then the iterative Lie mean and the centred covariance (1/(n−1)) about it on
    /// X's side (CONVENTIONS §8).
    ///
    /// >>> import numpy as np, posecov
    /// >>> x = posecov.UncertainPose("SE2", np.eye(3), np.diag([0.0, 0.0, 0.01]))
    /// >>> y = posecov.UncertainPose("SE2", posecov.SE2.exp([2, 0, 0]), np.zeros((3, 3)))
    /// >>> abs(float(x.monte_carlo_compose(y, 20000, seed=1).cov[1, 1]) / 0.04 - 1) < 0.05
    /// True
    #[pyo3(signature = (other, n, seed = 0))]
    fn monte_carlo_compose(&self, other: &UncertainPose, n: usize, seed: u64) -> PyResult<Self> {
        self.same_group(other)?;
        check_samples(n)?;
        let pose = match (self.pose, other.pose) {
            (Any::So2(a), Any::So2(b)) => Any::So2(monte_carlo(&a, &b, n, seed)?),
            (Any::So3(a), Any::So3(b)) => Any::So3(monte_carlo(&a, &b, n, seed)?),
            (Any::Se2(a), Any::Se2(b)) => Any::Se2(monte_carlo(&a, &b, n, seed)?),
            (Any::Se3(a), Any::Se3(b)) => Any::Se3(monte_carlo(&a, &b, n, seed)?),
            _ => unreachable!("same_group checked the groups"),
        };
        Ok(Self::wrap(pose))
    }

    /// The 2L + 1 sigma points of this pose (L its DOF) as an (2L + 1, D, D) array, with their
    /// mean and covariance weights (Julier & Uhlmann 2004; the points the "sigma_points"
    /// method of `compose` uses): μ, then μ ⊕ ±γ Lⱼ on the pose's side, γ = α √(L + κ).
    ///
    /// >>> import numpy as np, posecov
    /// >>> pts, wm, wc = posecov.UncertainPose("SE2", np.eye(3), np.eye(3) * 0.01).sigma_points()
    /// >>> pts.shape, round(float(wm.sum()), 12)
    /// ((7, 3, 3), 1.0)
    #[pyo3(signature = (alpha = 1.0, beta = 2.0, kappa = 0.0))]
    #[allow(clippy::type_complexity)]
    fn sigma_points<'py>(
        &self,
        py: Python<'py>,
        alpha: f64,
        beta: f64,
        kappa: f64,
    ) -> PyResult<(
        Bound<'py, PyArray3<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let params = Unscented {
            alpha,
            beta,
            kappa,
            side: Side::Right,
        };
        each!(self.pose, |p: G, N, D, _w| {
            let inputs = JointInputs::independent(&[p]).map_err(lib_err)?;
            let (points, wm, wc) = inputs.points(&params).map_err(lib_err)?;
            Ok((
                stack::<G, N, D>(py, &points)?,
                PyArray1::from_vec(py, wm),
                PyArray1::from_vec(py, wc),
            ))
        })
    }

    fn __repr__(&self) -> String {
        each!(self.pose, |p: G, N, D, _w| format!(
            "UncertainPose({:?}, mean={}, side={:?}, cov diagonal {:?})",
            self.group(),
            p.mean(),
            side_word(p.side()),
            p.cov().diagonal().as_slice()
        ))
    }
}

/// First order or sigma points of X · Y, both of one group.
fn pair(a: Any, b: Any, method: &str, params: Unscented) -> PyResult<Any> {
    fn one<G: LieGroup<N>, const N: usize>(
        a: &Pose<G, N>,
        b: &Pose<G, N>,
        method: &str,
        params: Unscented,
    ) -> PyResult<Pose<G, N>> {
        match method {
            "first_order" => Ok(first_order::compose(a, b).pose),
            "sigma_points" => sigma_point::compose(
                a,
                b,
                &Unscented {
                    side: a.side(),
                    ..params
                },
            )
            .map(|r| r.pose)
            .map_err(lib_err),
            _ => Err(bad(
                "method",
                format!(
                    "{method:?}: expected \"first_order\", \"second_order\", \"fourth_order\" or \"sigma_points\""
                ),
            )),
        }
    }
    Ok(match (a, b) {
        (Any::So2(a), Any::So2(b)) => Any::So2(one(&a, &b, method, params)?),
        (Any::So3(a), Any::So3(b)) => Any::So3(one(&a, &b, method, params)?),
        (Any::Se2(a), Any::Se2(b)) => Any::Se2(one(&a, &b, method, params)?),
        (Any::Se3(a), Any::Se3(b)) => Any::Se3(one(&a, &b, method, params)?),
        _ => return Err(PosecovError::new_err("poses of different groups")),
    })
}

fn monte_carlo<G: LieGroup<N>, const N: usize>(
    a: &Pose<G, N>,
    b: &Pose<G, N>,
    n: usize,
    seed: u64,
) -> PyResult<Pose<G, N>> {
    let xs = Sampler::new(a).map_err(lib_err)?.draw_par(n, seed);
    let ys = Sampler::new(b)
        .map_err(lib_err)?
        .draw_par(n, seed.wrapping_add(1));
    let zs: Vec<G> = xs.iter().zip(&ys).map(|(x, y)| x.compose(y)).collect();
    let stats =
        sample_statistics(&zs, a.side()).map_err(|e| PosecovError::new_err(e.to_string()))?;
    Ok(stats.to_pose())
}
