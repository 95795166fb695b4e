//! The unscented transform on the manifold (sigma points): deterministic samples of the
//! inputs' tangent Gaussians, pushed through the exact operation, summarised by a weighted
//! Lie mean and covariance.
//!
//! # Algorithm
//! For inputs X₁ … X_k whose stacked tangent [ε₁; …; ε_k] (L = Σ dim(Xᵢ) dimensions) is
//! Gaussian with joint covariance Σ_joint (Julier & Uhlmann 2004, "Unscented filtering and
//! nonlinear estimation", Proc. IEEE 92(3), eqs. 12 and 15; on manifolds: Hauberg et al. 2013,
//! Brossard, Barrau & Bonnabel 2020 "A code for unscented Kalman filtering on manifolds
//! (UKF-M)"):
//! - λ = α² (L + κ) − L, γ = √(L + λ);
//! - a square root S Sᵀ = Σ_joint ([`JointInputs`]): for independent inputs
//!   S = blkdiag(L₁, …, L_k), Lᵢ Lᵢᵀ = Σᵢ; for a correlated pair (compose or between with a
//!   cross-covariance Σ_XY) the eigen-based root of the 2N × 2N
//!   [[Σ_XX, Σ_XY], [Σ_YX, Σ_YY]] ([`CorrelatedPair::joint`], the matrix first order and Monte
//!   Carlo use);
//! - sigma points: all inputs at their means, and for every column Sⱼ and sign ±: every input
//!   i at μᵢ ⊕ (±γ Sⱼ,ᵢ), Sⱼ,ᵢ the rows of input i (its own side: μ · Exp(·) or Exp(·) · μ) —
//!   2L + 1 points. Independent inputs: one input moves, the others stay at their means;
//!   correlated inputs move together;
//! - weights W₀⁽ᵐ⁾ = λ/(L + λ), W₀⁽ᶜ⁾ = W₀⁽ᵐ⁾ + 1 − α² + β, Wⱼ⁽ᵐ⁾ = Wⱼ⁽ᶜ⁾ = 1/(2(L + λ));
//! - map every point, Yⱼ = f(points); mean: the weighted Lie mean
//!   μ ← μ ⊕ Σ Wⱼ⁽ᵐ⁾ (Yⱼ ⊖ μ) from the nominal output; covariance Σ Wⱼ⁽ᶜ⁾ ξⱼ ξⱼᵀ, ξⱼ = Yⱼ ⊖ μ on
//!   [`Unscented::side`].
//!
//! # When it differs from first order
//! With independent inputs every sigma point moves *one* input. For products of group
//! elements the output is then exactly linear in that input's tangent
//! (X · Exp(ε) · Y = XY · Exp(Ad_{Y⁻¹} ε)), so for compose, between, inverse and their chains
//! the unscented covariance equals the first-order one (cross terms between inputs, which
//! 4th-order compounding captures, never appear) — **as long as every sigma point's rotation
//! stays below π**. The points sit at ±γ times the columns of the square root, γ = α√(L + κ):
//! at α = 1 an SE(2) pose with a 2 rad heading σ moved by a known transform (L = 3) puts them
//! √3 · 2 = 3.46 rad out. Exp of a 3.46 rad turn is the same rotation as −(2π − 3.46) =
//! −2.82 rad, so Log brings the point back on the other side and its share of the covariance
//! shrinks by (2.82 / 3.46)² = 0.66: the unscented covariance comes out 34 % below first
//! order (exact at α = 0.3). [`wrap_around`] measures the largest turn for given inputs, and
//! the evaluation reports it where it exceeds π. It also differs where the nonlinearity sits
//! inside one input, e.g. X · Exp(u + w) ([REFERENCE_CASES R4]) or a map using an input twice.
//!
//! Correlated inputs move together, so X · Exp(a) · Y · Exp(b) carries the cross terms of
//! BCH: the unscented covariance keeps Mangelson et al.'s correlated first order
//! ([`first_order::compose_correlated`](crate::propagate::first_order::compose_correlated),
//! [`between_correlated`](crate::propagate::first_order::between_correlated)) to second order
//! in the noise and departs from it beyond. Treating such inputs as independent would miss
//! Σ_XY altogether (e.g. two poses of one odometry chain: a far too wide relative pose).
//! The wrap-around check measures these joint points.
//!
//! # Parameters
//! Defaults α = 1, β = 2, κ = 0 (λ = 0: points at ±√L σ, W₀⁽ᵐ⁾ = 0, all weights ≥ 0, so the
//! covariance stays PSD); β = 2 is optimal for Gaussian inputs. Smaller α pulls the points
//! in towards the first-order result (and inside the wrap-around at π). A scenario sets them
//! with `[methods.sigma_points] alpha, beta, kappa`.
//!
//! ```
//! use posecov::lie::{LieGroup, Se2};
//! use posecov::propagate::sigma_point::{Unscented, compose};
//! use posecov::uncertain::{Method, Side, UncertainPose};
//! let a = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 0.0, 0.0), [0.05, 0.05, 0.1], Side::Right).unwrap();
//! let z = compose(&a, &a, &Unscented::default()).unwrap();
//! assert_eq!(z.method, Method::SigmaPoints);
//! ```
//!
//! [REFERENCE_CASES R4]: crate::reference_cases#r4-se3-odometry-noise-inside-exp-rob-530

use nalgebra::DMatrix;

use crate::error::{Error, Result};
use crate::lie::{LieGroup, Tangent};
use crate::propagate::Propagated;
use crate::propagate::first_order::CorrelatedPair;
use crate::sample::{
    covariance_square_root, joint_square_root, retract, weighted_covariance, weighted_lie_mean,
};
use crate::uncertain::{Method, Side, UncertainPose};

/// Unscented-transform parameters (see the [module docs](self#parameters)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unscented {
    /// Spread α > 0 (default 1).
    pub alpha: f64,
    /// Prior-knowledge weight β (default 2, optimal for Gaussians).
    pub beta: f64,
    /// Secondary scaling κ (default 0); L + κ must stay > 0.
    pub kappa: f64,
    /// Side of the output covariance (default right / body).
    pub side: Side,
}

impl Default for Unscented {
    /// α = 1, β = 2, κ = 0, right side.
    ///
    /// ```
    /// use posecov::propagate::sigma_point::Unscented;
    /// assert_eq!(Unscented::default().beta, 2.0);
    /// ```
    fn default() -> Self {
        Self {
            alpha: 1.0,
            beta: 2.0,
            kappa: 0.0,
            side: Side::Right,
        }
    }
}

/// The scale γ and the weights of the 2L + 1 sigma points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmaWeights {
    /// γ = √(L + λ): sigma points sit at ±γ times the columns of the square root.
    pub scale: f64,
    /// W₀⁽ᵐ⁾ = λ/(L + λ).
    pub mean_centre: f64,
    /// W₀⁽ᶜ⁾ = W₀⁽ᵐ⁾ + 1 − α² + β.
    pub cov_centre: f64,
    /// Wⱼ = 1/(2(L + λ)) for every other point (mean and covariance).
    pub other: f64,
}

impl Unscented {
    /// The scale and weights for `dim` = L tangent dimensions (Julier & Uhlmann 2004, eq. 15).
    /// Errors: [`Error::OutOfRange`] for a non-finite parameter, α ≤ 0, or L + λ ≤ 0.
    ///
    /// ```
    /// use posecov::propagate::sigma_point::Unscented;
    /// let w = Unscented::default().weights(6).unwrap();
    /// assert_eq!(w.mean_centre, 0.0);
    /// assert!((w.other * 12.0 - 1.0).abs() < 1e-15);
    /// assert!(Unscented { kappa: -6.0, ..Default::default() }.weights(6).is_err());
    /// ```
    pub fn weights(&self, dim: usize) -> Result<SigmaWeights> {
        let check = |what, value: f64, ok: bool, expected| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    what,
                    value,
                    expected,
                })
            }
        };
        check(
            "unscented α",
            self.alpha,
            self.alpha > 0.0,
            "a finite α > 0",
        )?;
        check("unscented β", self.beta, true, "a finite β")?;
        check("unscented κ", self.kappa, true, "a finite κ")?;
        let l = dim as f64;
        let spread = self.alpha * self.alpha * (l + self.kappa); // L + λ
        check(
            "unscented L + λ = α²(L + κ)",
            spread,
            spread > 0.0,
            "L + λ > 0",
        )?;
        let lambda = spread - l;
        Ok(SigmaWeights {
            scale: spread.sqrt(),
            mean_centre: lambda / spread,
            cov_centre: lambda / spread + 1.0 - self.alpha * self.alpha + self.beta,
            other: 0.5 / spread,
        })
    }
}

/// The inputs of one unscented transform: k poses X₁ … X_k, each perturbed on its own side,
/// and a square root S (S Sᵀ = Σ_joint) of the joint covariance of their stacked tangents
/// [ε₁; …; ε_k] (L = kN dimensions). Sigma point ±j moves every input i by its block of the
/// column ±γ Sⱼ, so correlated inputs move together ([module docs](self#algorithm)).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::first_order::CorrelatedPair;
/// use posecov::propagate::sigma_point::JointInputs;
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.1], Side::Right).unwrap();
/// assert_eq!(JointInputs::independent(&[a, a]).unwrap().dim(), 6);
/// assert_eq!(JointInputs::correlated(&CorrelatedPair::independent(&a, &a)).dim(), 6);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct JointInputs<G: LieGroup<N>, const N: usize> {
    means: Vec<G>,
    sides: Vec<Side>,
    root: DMatrix<f64>,
}

impl<G: LieGroup<N>, const N: usize> JointInputs<G, N> {
    /// Independent inputs: S = blkdiag(L₁, …, L_k), Lᵢ Lᵢᵀ = Σᵢ ([`covariance_square_root`]),
    /// so every sigma point moves one input and leaves the others at their means.
    /// Errors: a non-finite covariance.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::sigma_point::JointInputs;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let a = UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap();
    /// assert_eq!(JointInputs::independent(&[a, a, a]).unwrap().dim(), 3);
    /// ```
    pub fn independent(inputs: &[UncertainPose<G, N>]) -> Result<Self> {
        let mut root = DMatrix::zeros(inputs.len() * N, inputs.len() * N);
        for (i, input) in inputs.iter().enumerate() {
            root.view_mut((i * N, i * N), (N, N))
                .copy_from(&covariance_square_root(input.cov())?);
        }
        Ok(Self {
            means: inputs.iter().map(|p| *p.mean()).collect(),
            sides: inputs.iter().map(|p| p.side()).collect(),
            root,
        })
    }

    /// A correlated pair (X, Y): S Sᵀ = its 2N × 2N joint covariance [[Σ_XX, Σ_XY], [Σ_YX, Σ_YY]]
    /// ([`CorrelatedPair::joint`], the matrix first order and Monte Carlo use; S from
    /// [`joint_square_root`]), both inputs on the pair's side. Every sigma point moves X and Y
    /// together, as the cross-covariance says.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::propagate::sigma_point::{JointInputs, Unscented};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Matrix3;
    /// // Y shares X's error exactly: the relative pose X⁻¹ · Y is certain.
    /// let x = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 0.0, 0.3), [0.1, 0.1, 0.1], Side::Right).unwrap();
    /// let pair = CorrelatedPair::with_cross(&x, &x, x.cov()).unwrap();
    /// let z = JointInputs::correlated(&pair).map(|g: &[Se2]| g[0].between(&g[1]), &Unscented::default()).unwrap();
    /// assert!(z.pose.cov().norm() < 1e-12);
    /// ```
    pub fn correlated(pair: &CorrelatedPair<G, N>) -> Self {
        let (x, y) = pair.means();
        Self {
            means: vec![x, y],
            sides: vec![pair.side(); 2],
            root: joint_square_root(&pair.joint()),
        }
    }

    /// L, the joint tangent dimension (kN).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::propagate::sigma_point::JointInputs;
    /// use posecov::uncertain::UncertainPose;
    /// assert_eq!(JointInputs::independent(&[UncertainPose::certain(Se3::identity())]).unwrap().dim(), 6);
    /// ```
    pub fn dim(&self) -> usize {
        self.root.nrows()
    }

    /// Input i's tangent offset in sigma point ±j: γ · (rows iN .. iN + N of Sⱼ), times ±1.
    fn offsets(&self, w: &SigmaWeights) -> impl Iterator<Item = Vec<Tangent<N>>> + '_ {
        let scale = w.scale;
        self.root.column_iter().map(move |column| {
            (0..self.means.len())
                .map(|i| {
                    Tangent::<N>::from_iterator(column.rows(i * N, N).iter().map(|v| v * scale))
                })
                .collect()
        })
    }

    /// The 2L + 1 input tuples (flattened, k inputs per tuple) and their mean / covariance
    /// weights. An input its offset leaves at zero stays exactly at its mean.
    fn sigma_points(&self, w: &SigmaWeights) -> (Vec<G>, Vec<f64>, Vec<f64>) {
        let mut tuples = self.means.clone();
        let (mut wm, mut wc) = (vec![w.mean_centre], vec![w.cov_centre]);
        for offsets in self.offsets(w) {
            for sign in [1.0, -1.0] {
                for ((mean, side), offset) in self.means.iter().zip(&self.sides).zip(&offsets) {
                    tuples.push(if offset.iter().all(|v| *v == 0.0) {
                        *mean
                    } else {
                        retract(mean, &(offset * sign), *side)
                    });
                }
                wm.push(w.other);
                wc.push(w.other);
            }
        }
        debug_assert_eq!(tuples.len(), self.means.len() * wm.len());
        (tuples, wm, wc)
    }

    /// The sigma points of [`JointInputs::map`]: 2L + 1 tuples of k inputs, flattened (k
    /// inputs per tuple, the means' tuple first), and their mean and covariance weights. Errors: bad parameters ([`Unscented::weights`]).
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::sigma_point::{JointInputs, Unscented};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let a = [UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap()];
    /// let (x, wm, _) = JointInputs::independent(&a).unwrap().points(&Unscented::default()).unwrap();
    /// assert!(x.len() == 3 && (x[1].angle() - 0.1).abs() < 1e-15 && wm[0] == 0.0);
    /// ```
    pub fn points(&self, params: &Unscented) -> Result<(Vec<G>, Vec<f64>, Vec<f64>)> {
        let weights = params.weights(self.dim())?;
        Ok(self.sigma_points(&weights))
    }

    /// The unscented transform of Y = f(X₁, …, X_k) over these inputs
    /// ([module docs](self#algorithm)); the output group may differ from the inputs'. Method
    /// [`Method::SigmaPoints`], covariance on `params.side`.
    ///
    /// Errors: [`Error::TooFewSamples`] for no inputs, bad parameters ([`Unscented::weights`]),
    /// a non-converging weighted Lie mean ([`Error::NotConverged`]).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::sigma_point::{JointInputs, Unscented};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let a = UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap();
    /// let inputs = JointInputs::independent(&[a, a]).unwrap();
    /// let z = inputs.map(|x: &[So2]| x[0].compose(&x[1]), &Unscented::default()).unwrap();
    /// assert!((z.pose.cov()[(0, 0)] - 0.02).abs() < 1e-12);
    /// ```
    pub fn map<H, const M: usize, F>(&self, f: F, params: &Unscented) -> Result<Propagated<H, M>>
    where
        H: LieGroup<M>,
        F: Fn(&[G]) -> H,
    {
        if self.means.is_empty() {
            return Err(Error::TooFewSamples {
                what: "sigma-point inputs",
                needed: 1,
                got: 0,
            });
        }
        let weights = params.weights(self.dim())?;
        let (tuples, wm, wc) = self.sigma_points(&weights);
        let outputs: Vec<H> = tuples.chunks_exact(self.means.len()).map(&f).collect();
        let mean = weighted_lie_mean(&outputs, Some(&wm), &outputs[0], params.side)?.mean;
        let cov = weighted_covariance(&outputs, &wc, &mean, params.side)?;
        Ok(Propagated {
            pose: UncertainPose::new_unchecked(mean, cov, params.side),
            method: Method::SigmaPoints,
        })
    }

    /// The largest rotation angle |θ| (rad) of any input's tangent offset in any sigma point:
    /// max over columns j and inputs i of ‖θ(γ Sⱼ,ᵢ)‖, θ the rotation part
    /// ([`LieGroup::rotation_range`]); the same offsets as [`JointInputs::map`], 0 for no inputs.
    ///
    /// Errors: bad parameters ([`Unscented::weights`]).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::propagate::sigma_point::{JointInputs, Unscented};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let a = UncertainPose::try_from_std_devs(So2::identity(), [1.0], Side::Right).unwrap();
    /// // Fully correlated: one principal axis (1, 1) of σ √2; γ = √2, so each input turns √2 · 1.
    /// let pair = CorrelatedPair::with_cross(&a, &a, a.cov()).unwrap();
    /// let turn = JointInputs::correlated(&pair).largest_rotation(&Unscented::default()).unwrap();
    /// assert!((turn - 2f64.sqrt()).abs() < 1e-12);
    /// ```
    pub fn largest_rotation(&self, params: &Unscented) -> Result<f64> {
        if self.means.is_empty() {
            return Ok(0.0);
        }
        let range = G::rotation_range();
        let w = params.weights(self.dim())?;
        Ok(self
            .offsets(&w)
            .flatten()
            .map(|o| o.rows(range.start, range.len()).norm())
            .fold(0.0, f64::max))
    }

    /// Where a sigma point turns an input further than π
    /// ([module docs](self#when-it-differs-from-first-order)): there Log wraps it to the other
    /// side and the unscented estimate departs from first order. `None` while every offset
    /// stays within π. Errors: as [`JointInputs::largest_rotation`].
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::sigma_point::{JointInputs, Unscented};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// // L = 1, γ = 1: a σ of 4 rad puts the points 4 rad out, beyond π; α = 0.7 keeps them in.
    /// let a = UncertainPose::try_from_std_devs(So2::identity(), [4.0], Side::Right).unwrap();
    /// let inputs = JointInputs::independent(&[a]).unwrap();
    /// assert_eq!(inputs.wrap_around(&Unscented::default()).unwrap().unwrap().largest_rotation, 4.0);
    /// let inside = Unscented { alpha: 0.7, ..Default::default() };
    /// assert_eq!(inputs.wrap_around(&inside).unwrap(), None);
    /// ```
    pub fn wrap_around(&self, params: &Unscented) -> Result<Option<WrapAround>> {
        let largest = self.largest_rotation(params)?;
        Ok((largest > std::f64::consts::PI).then(|| WrapAround {
            largest_rotation: largest,
            alpha: params.alpha,
            alpha_below_pi: params.alpha * std::f64::consts::PI / largest,
        }))
    }
}

/// The unscented transform of any map Y = f(X₁, …, X_k) of independent uncertain inputs
/// ([module docs](self#algorithm)); the output group may differ from the inputs'. Method
/// [`Method::SigmaPoints`], covariance on `params.side`.
///
/// Errors: [`Error::TooFewSamples`] for no inputs, bad parameters ([`Unscented::weights`]),
/// a non-converging weighted Lie mean ([`Error::NotConverged`]).
///
/// ```
/// use posecov::lie::{LieGroup, So3};
/// use posecov::propagate::sigma_point::{Unscented, map};
/// use posecov::uncertain::{Side, UncertainPose};
/// let r = UncertainPose::try_from_std_devs(So3::identity(), [0.1, 0.2, 0.3], Side::Right).unwrap();
/// // A deterministic identity map returns the input distribution.
/// let y = map(&[r], |x: &[So3]| x[0], &Unscented::default()).unwrap();
/// assert!((y.pose.cov() - r.cov()).norm() < 1e-12);
/// ```
pub fn map<G, const N: usize, H, const M: usize, F>(
    inputs: &[UncertainPose<G, N>],
    f: F,
    params: &Unscented,
) -> Result<Propagated<H, M>>
where
    G: LieGroup<N>,
    H: LieGroup<M>,
    F: Fn(&[G]) -> H,
{
    JointInputs::independent(inputs)?.map(f, params)
}

/// The unscented transform of the composition Z = X · Y of independent uncertain poses
/// (L = 2N sigma dimensions). See [`map`].
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::propagate::sigma_point::{Unscented, compose};
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap();
/// // SO(2) is commutative and flat: variances add exactly.
/// let z = compose(&a, &a, &Unscented::default()).unwrap();
/// assert!((z.pose.cov()[(0, 0)] - 0.02).abs() < 1e-12);
/// ```
pub fn compose<G: LieGroup<N>, const N: usize>(
    a: &UncertainPose<G, N>,
    b: &UncertainPose<G, N>,
    params: &Unscented,
) -> Result<Propagated<G, N>> {
    map(&[*a, *b], |x: &[G]| x[0].compose(&x[1]), params)
}

/// How far the sigma points of some inputs turn, where one turns further than π.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrapAround {
    /// The largest rotation angle |θ| (rad) of any sigma point's tangent offset ±γ Lᵢ,ⱼ from
    /// its input's mean, θ the rotation part ([`LieGroup::rotation_range`]).
    pub largest_rotation: f64,
    /// The α used.
    pub alpha: f64,
    /// The α at which the largest rotation is exactly π: the offsets scale with
    /// γ = α√(L + κ), so every α below α · π / |θ|max keeps every sigma point inside.
    pub alpha_below_pi: f64,
}

/// The largest rotation angle |θ| (rad) reached by any sigma point of `inputs` under `params`:
/// max over inputs i and columns j of ‖θ(γ Lᵢ,ⱼ)‖, the rotation part of the tangent offset
/// (the same square roots and γ as [`map`]; 0 for no inputs).
///
/// Errors: bad parameters ([`Unscented::weights`]), a non-finite covariance.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::sigma_point::{Unscented, largest_rotation};
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 2.0], Side::Right).unwrap();
/// // L = 3, γ = √3: the heading offset is √3 · 2 rad.
/// let turn = largest_rotation(&[a], &Unscented::default()).unwrap();
/// assert!((turn - 3f64.sqrt() * 2.0).abs() < 1e-12);
/// ```
pub fn largest_rotation<G: LieGroup<N>, const N: usize>(
    inputs: &[UncertainPose<G, N>],
    params: &Unscented,
) -> Result<f64> {
    JointInputs::independent(inputs)?.largest_rotation(params)
}

/// Where a sigma point of `inputs` turns further than π ([module docs](self#when-it-differs-from-first-order)):
/// there Log wraps it to the other side and the unscented estimate departs from first order.
/// `None` while every sigma point stays within π.
///
/// Errors: as [`largest_rotation`].
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::sigma_point::{Unscented, wrap_around};
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 2.0], Side::Right).unwrap();
/// let wrap = wrap_around(&[a], &Unscented::default()).unwrap().unwrap();
/// assert!((wrap.alpha_below_pi - std::f64::consts::PI / (3f64.sqrt() * 2.0)).abs() < 1e-12);
/// let inside = Unscented { alpha: 0.3, ..Default::default() };
/// assert_eq!(wrap_around(&[a], &inside).unwrap(), None);
/// ```
pub fn wrap_around<G: LieGroup<N>, const N: usize>(
    inputs: &[UncertainPose<G, N>],
    params: &Unscented,
) -> Result<Option<WrapAround>> {
    JointInputs::independent(inputs)?.wrap_around(params)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{PI, TAU};

    use nalgebra::{Matrix3, Vector3};

    use super::*;
    use crate::lie::Se2;
    use crate::propagate::first_order;

    fn se2(xy_theta: [f64; 3], std: [f64; 3]) -> UncertainPose<Se2, 3> {
        let mean = Se2::from_xy_theta(xy_theta[0], xy_theta[1], xy_theta[2]);
        UncertainPose::try_from_std_devs(mean, std, Side::Right).unwrap()
    }

    fn relative(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
        (a - b).norm() / b.norm()
    }

    /// First order with the heading σ's share scaled by r = ((2π − θ)/θ)²: a sigma point at
    /// a turn θ ∈ (π, 2π) is the same pose as one at θ − 2π, so Log brings it back shorter.
    fn wrapped_first_order(
        first: &Matrix3<f64>,
        lever: &Se2,
        heading_var: f64,
        turn: f64,
    ) -> Matrix3<f64> {
        let r = ((TAU - turn) / turn).powi(2);
        let ad = lever.inverse().adj() * Vector3::z();
        first - ad * ad.transpose() * heading_var * (1.0 - r)
    }

    #[test]
    fn a_known_mount_on_a_2_rad_heading_wraps_at_alpha_1_and_not_at_0_3() {
        // The camera-on-robot case with a heading σ of 2 rad: L = 3, γ = √3, turn √3 · 2.
        let robot = se2([2.0, 1.0, 0.5], [0.05, 0.05, 2.0]);
        let mount = Se2::from_xy_theta(1.5, 0.0, 0.0);
        let f = |x: &[Se2]| x[0].compose(&mount);
        let first = *first_order::change_frame_right(&robot, &mount).pose.cov();

        let wide = Unscented::default();
        let turn = largest_rotation(&[robot], &wide).unwrap();
        assert!((turn - 3f64.sqrt() * 2.0).abs() < 1e-12, "{turn}");
        let wrap = wrap_around(&[robot], &wide).unwrap().expect("beyond π");
        assert_eq!(wrap.largest_rotation, turn);
        assert_eq!(wrap.alpha, 1.0);
        assert!((wrap.alpha_below_pi - PI / turn).abs() < 1e-15);
        let unscented = *map(&[robot], f, &wide).unwrap().pose.cov();
        let expected = wrapped_first_order(&first, &mount, 4.0, turn);
        assert!(relative(&unscented, &expected) < 1e-9);
        // (2.82 / 3.46)² = 0.662 of the heading share survives: 33.8 % off in all.
        let off = relative(&unscented, &first);
        assert!((off - 0.3377).abs() < 5e-4, "{off}");

        let narrow = Unscented { alpha: 0.3, ..wide };
        assert!((largest_rotation(&[robot], &narrow).unwrap() - 0.3 * turn).abs() < 1e-12);
        assert_eq!(wrap_around(&[robot], &narrow).unwrap(), None);
        let unscented = *map(&[robot], f, &narrow).unwrap().pose.cov();
        assert!(relative(&unscented, &first) < 1e-9);
    }

    #[test]
    fn a_compose_of_two_uncertain_poses_wraps_at_sqrt_12_rad() {
        // L = 6, γ = √6; a heading σ of √2 rad puts the points √12 = 3.46 rad out.
        let a = se2([2.0, 1.0, 0.5], [0.05, 0.05, 2f64.sqrt()]);
        let b = se2([1.5, 0.0, 0.0], [0.05, 0.05, 0.05]);
        let first = *first_order::compose(&a, &b).pose.cov();
        let wide = Unscented::default();
        let turn = largest_rotation(&[a, b], &wide).unwrap();
        assert!((turn - 12f64.sqrt()).abs() < 1e-12, "{turn}");
        assert!(wrap_around(&[a, b], &wide).unwrap().is_some());
        let unscented = *compose(&a, &b, &wide).unwrap().pose.cov();
        let expected = wrapped_first_order(&first, b.mean(), 2.0, turn);
        assert!(relative(&unscented, &expected) < 1e-9);

        let below = wrap_around(&[a, b], &wide).unwrap().unwrap().alpha_below_pi;
        let inside = Unscented {
            alpha: below * 0.99,
            ..wide
        };
        assert_eq!(wrap_around(&[a, b], &inside).unwrap(), None);
        let unscented = *compose(&a, &b, &inside).unwrap().pose.cov();
        assert!(relative(&unscented, &first) < 1e-9);
    }

    #[test]
    fn only_the_rotation_part_counts() {
        // Large translation σ, small heading σ: no sigma point turns far.
        let a = se2([0.0, 0.0, 0.0], [50.0, 50.0, 0.1]);
        let turn = largest_rotation(&[a], &Unscented::default()).unwrap();
        assert!((turn - 3f64.sqrt() * 0.1).abs() < 1e-12, "{turn}");
        assert_eq!(
            largest_rotation::<Se2, 3>(&[], &Unscented::default()).unwrap(),
            0.0
        );
    }
}
