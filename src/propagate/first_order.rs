//! Operations on uncertain poses with their covariance, for both sides ([CONVENTIONS §5]).
//!
//! | operation | right form (X = μ Exp ε) | left form (X = Exp ε μ) | method |
//! |---|---|---|---|
//! | A · X, A known ([`change_frame_left`]) | Σ | Ad_A Σ Ad_Aᵀ | exact |
//! | X · B, B known ([`change_frame_right`]) | Ad_{B⁻¹} Σ Ad_{B⁻¹}ᵀ | Σ | exact |
//! | X⁻¹ ([`inverse`]) | Ad_μ Σ Ad_μᵀ | Ad_{μ⁻¹} Σ Ad_{μ⁻¹}ᵀ | exact |
//! | X · Y independent ([`compose`]) | Ad_{μY⁻¹} Σ_X Ad_{μY⁻¹}ᵀ + Σ_Y | Σ_X + Ad_{μX} Σ_Y Ad_{μX}ᵀ | first order |
//! | X⁻¹ · Y independent ([`between`]) | Ad_{Z⁻¹} Σ_X Ad_{Z⁻¹}ᵀ + Σ_Y | Ad_{μX⁻¹} (Σ_X + Σ_Y) Ad_{μX⁻¹}ᵀ | first order |
//! | X · Y, X⁻¹ · Y correlated ([`compose_correlated`], [`between_correlated`]) | J Σ_joint Jᵀ | J Σ_joint Jᵀ | first order |
//! | X · p, p uncertain ([`act_point`]) | J_X Σ_X J_Xᵀ + R Σ_p Rᵀ | (converted to right) | first order |
//!
//! Why the first three are exact: a deterministic factor or an inversion moves the
//! perturbation through an adjoint without truncating anything — A μ Exp(ε) = (A μ) Exp(ε);
//! μ Exp(ε) B = (μ B) Exp(Ad_{B⁻¹} ε); (μ Exp ε)⁻¹ = μ⁻¹ Exp(−Ad_μ ε) — so a Gaussian ε stays
//! an exactly Gaussian ε′ (Solà et al. 2018 eq. 31). Composing two uncertain poses needs
//! Exp(a) Exp(b) ≈ Exp(a + b) (BCH truncated after the first term): first order.
//!
//! [CONVENTIONS §5]: crate::conventions#5-first-order-propagation

use nalgebra::{DMatrix, SMatrix, SVector};

use crate::error::{Error, Result, check_finite};
use crate::lie::{BinaryJacobians, LieGroup, TangentMatrix};
use crate::uncertain::{Method, Side, UncertainPose, validate_covariance, validate_covariance_dyn};

use super::Propagated;

/// Ad Σ Adᵀ, symmetrised.
fn congruence<const N: usize>(a: &TangentMatrix<N>, cov: &TangentMatrix<N>) -> TangentMatrix<N> {
    let out = a * cov * a.transpose();
    (out + out.transpose()) * 0.5
}

/// A deterministic change of reference frame on the left, `a_from_b · (b_from_x)` (e.g.
/// `world_from_map · map_from_robot`; the EEME E6911 AHRS example). Exact: right form Σ
/// unchanged, left form Ad_A Σ Ad_Aᵀ (A μ Exp ε = (A μ) Exp ε; A Exp(ε) μ = Exp(Ad_A ε) A μ).
/// The result keeps the input's side.
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::first_order::change_frame_left;
/// use posecov::uncertain::{Method, Side, UncertainPose};
/// let map_from_robot = UncertainPose::try_from_std_devs(Se3::identity(), [0.1; 6], Side::Right).unwrap();
/// let world_from_map = Se3::from_xyz_rpy([10.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
/// let world_from_robot = change_frame_left(&world_from_map, &map_from_robot);
/// assert_eq!(world_from_robot.method, Method::Exact);
/// assert_eq!(world_from_robot.pose.cov(), map_from_robot.cov()); // body-frame Σ unchanged
/// ```
pub fn change_frame_left<G: LieGroup<N>, const N: usize>(
    a_from_b: &G,
    b_from_x: &UncertainPose<G, N>,
) -> Propagated<G, N> {
    let mean = a_from_b.compose(b_from_x.mean());
    let cov = match b_from_x.side() {
        Side::Right => *b_from_x.cov(),
        Side::Left => congruence(&a_from_b.adj(), b_from_x.cov()),
    };
    exact(mean, cov, b_from_x.side())
}

/// A deterministic change of frame on the right, `(world_from_body) · body_from_camera`
/// (a sensor mounting; the EEME E6911 camera-on-robot example). Exact: right form
/// Ad_{B⁻¹} Σ Ad_{B⁻¹}ᵀ (μ Exp(ε) B = μ B Exp(Ad_{B⁻¹} ε)), left form Σ unchanged.
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::first_order::change_frame_right;
/// use posecov::uncertain::{Side, UncertainPose};
/// let world_from_body = UncertainPose::try_from_std_devs(Se3::identity(), [0.0, 0.0, 0.0, 0.0, 0.0, 0.1], Side::Right).unwrap();
/// let body_from_cam = Se3::from_xyz_rpy([1.0, 0.0, 0.0], [0.0; 3]);
/// let world_from_cam = change_frame_right(&world_from_body, &body_from_cam);
/// // a yaw error of the body swings the camera 1 m away sideways: σ_y = 0.1 in the camera frame
/// assert!((world_from_cam.pose.cov()[(1, 1)] - 0.01).abs() < 1e-15);
/// ```
pub fn change_frame_right<G: LieGroup<N>, const N: usize>(
    world_from_b: &UncertainPose<G, N>,
    b_from_c: &G,
) -> Propagated<G, N> {
    let mean = world_from_b.mean().compose(b_from_c);
    let cov = match world_from_b.side() {
        Side::Right => congruence(&b_from_c.inverse().adj(), world_from_b.cov()),
        Side::Left => *world_from_b.cov(),
    };
    exact(mean, cov, world_from_b.side())
}

/// The inverse of an uncertain pose, exact on both sides: right Ad_μ Σ Ad_μᵀ
/// ((μ Exp ε)⁻¹ = μ⁻¹ Exp(−Ad_μ ε)), left Ad_{μ⁻¹} Σ Ad_{μ⁻¹}ᵀ; Solà et al. 2018 eq. 160
/// (J = −Ad_μ).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::first_order::inverse;
/// use posecov::uncertain::{Side, UncertainPose};
/// let x = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 2.0, 0.3), [0.1, 0.2, 0.05], Side::Right).unwrap();
/// let back = inverse(&inverse(&x).pose).pose;
/// assert!((back.cov() - x.cov()).norm() < 1e-14);
/// ```
pub fn inverse<G: LieGroup<N>, const N: usize>(x: &UncertainPose<G, N>) -> Propagated<G, N> {
    let ad = match x.side() {
        Side::Right => x.mean().adj(),
        Side::Left => x.mean().inverse().adj(),
    };
    exact(x.mean().inverse(), congruence(&ad, x.cov()), x.side())
}

fn exact<G: LieGroup<N>, const N: usize>(
    mean: G,
    cov: TangentMatrix<N>,
    side: Side,
) -> Propagated<G, N> {
    Propagated {
        pose: UncertainPose::new_unchecked(mean, cov, side),
        method: Method::Exact,
    }
}

/// Two uncertain poses with a joint Gaussian: [εX; εY] ~ N(0, [[Σ_XX, Σ_XY], [Σ_YX, Σ_YY]]),
/// both perturbations on the same side (Mangelson, Ghaffari, Vasudevan & Eustice 2020,
/// "Characterizing the uncertainty of jointly distributed poses in the Lie algebra",
/// IEEE T-RO 36(5), §III).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CorrelatedPair<G: LieGroup<N>, const N: usize> {
    x: G,
    y: G,
    cov_xx: TangentMatrix<N>,
    cov_xy: TangentMatrix<N>,
    cov_yy: TangentMatrix<N>,
    side: Side,
}

impl<G: LieGroup<N>, const N: usize> CorrelatedPair<G, N> {
    /// From the means and the 2N × 2N joint covariance (rows/columns: εX then εY), validated
    /// as a whole (shape 2N × 2N, finite, symmetric, PSD — each block alone is not enough).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::Side;
    /// use nalgebra::DMatrix;
    /// let mut joint = DMatrix::<f64>::identity(6, 6) * 0.01;
    /// joint[(0, 3)] = 0.009;
    /// joint[(3, 0)] = 0.009;
    /// assert!(CorrelatedPair::try_new(Se2::identity(), Se2::identity(), &joint, Side::Right).is_ok());
    /// joint[(0, 3)] = 0.02; // |ρ| > 1
    /// joint[(3, 0)] = 0.02;
    /// assert!(CorrelatedPair::try_new(Se2::identity(), Se2::identity(), &joint, Side::Right).is_err());
    /// ```
    pub fn try_new(x: G, y: G, joint: &DMatrix<f64>, side: Side) -> Result<Self> {
        if joint.shape() != (2 * N, 2 * N) {
            return Err(Error::WrongShape {
                what: "joint covariance",
                expected_rows: 2 * N,
                expected_cols: 2 * N,
                rows: joint.nrows(),
                cols: joint.ncols(),
            });
        }
        let joint = validate_covariance_dyn("joint covariance", joint)?;
        let block =
            |r: usize, c: usize| TangentMatrix::<N>::from_fn(|i, j| joint[(r * N + i, c * N + j)]);
        Ok(Self {
            x,
            y,
            cov_xx: block(0, 0),
            cov_xy: block(0, 1),
            cov_yy: block(1, 1),
            side,
        })
    }

    /// Two independent uncertain poses (Σ_XY = 0), on the side of `x` (`y` is converted).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::UncertainPose;
    /// let a = UncertainPose::certain(So3::identity());
    /// assert_eq!(CorrelatedPair::independent(&a, &a).joint().nrows(), 6);
    /// ```
    pub fn independent(x: &UncertainPose<G, N>, y: &UncertainPose<G, N>) -> Self {
        let side = x.side();
        Self {
            x: *x.mean(),
            y: *y.mean(),
            cov_xx: *x.cov(),
            cov_xy: TangentMatrix::<N>::zeros(),
            cov_yy: *y.to_side(side).cov(),
            side,
        }
    }

    /// The pair (X, Y) with cross-covariance Σ_XY = `cross_cov` = E\[εX εYᵀ\], `y` moved to the
    /// side of `x` first; the joint covariance [[Σ_X, Σ_XY], [Σ_XYᵀ, Σ_Y]] is validated as in
    /// [`CorrelatedPair::try_new`].
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Matrix3;
    /// let x = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.1], Side::Right).unwrap();
    /// let pair = CorrelatedPair::with_cross(&x, &x, &(Matrix3::identity() * 0.009)).unwrap();
    /// assert_eq!(pair.joint()[(0, 3)], 0.009);
    /// assert!(CorrelatedPair::with_cross(&x, &x, &(Matrix3::identity() * 0.02)).is_err()); // |ρ| > 1
    /// ```
    pub fn with_cross(
        x: &UncertainPose<G, N>,
        y: &UncertainPose<G, N>,
        cross_cov: &TangentMatrix<N>,
    ) -> Result<Self> {
        let unchecked = Self {
            cov_xy: *cross_cov,
            ..Self::independent(x, y)
        };
        Self::try_new(*x.mean(), *y.mean(), &unchecked.joint(), x.side())
    }

    /// The joint covariance as a 2N × 2N matrix.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::Side;
    /// use nalgebra::DMatrix;
    /// let j = DMatrix::<f64>::identity(6, 6);
    /// let pair = CorrelatedPair::try_new(Se2::identity(), Se2::identity(), &j, Side::Right).unwrap();
    /// assert_eq!(pair.joint(), j);
    /// ```
    pub fn joint(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(2 * N, 2 * N);
        m.view_mut((0, 0), (N, N)).copy_from(&self.cov_xx);
        m.view_mut((0, N), (N, N)).copy_from(&self.cov_xy);
        m.view_mut((N, 0), (N, N))
            .copy_from(&self.cov_xy.transpose());
        m.view_mut((N, N), (N, N)).copy_from(&self.cov_yy);
        m
    }

    /// The means (X, Y).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::UncertainPose;
    /// let a = UncertainPose::certain(So2::from_angle(0.5));
    /// assert_eq!(CorrelatedPair::independent(&a, &a).means().0, So2::from_angle(0.5));
    /// ```
    pub fn means(&self) -> (G, G) {
        (self.x, self.y)
    }

    /// The side both perturbations live on.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let a = UncertainPose::certain(So2::identity());
    /// assert_eq!(CorrelatedPair::independent(&a, &a).side(), Side::Right);
    /// ```
    pub fn side(&self) -> Side {
        self.side
    }

    /// The same joint distribution on `side`: blkdiag(Ad_X, Ad_Y) Σ_joint blkdiag(Ad_X, Ad_Y)ᵀ
    /// (or with the inverse adjoints towards the right).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::first_order::CorrelatedPair;
    /// use posecov::uncertain::Side;
    /// use nalgebra::DMatrix;
    /// let j = DMatrix::<f64>::identity(6, 6) * 0.01;
    /// let pair = CorrelatedPair::try_new(Se2::from_xy_theta(1.0, 2.0, 0.3), Se2::identity(), &j, Side::Right).unwrap();
    /// let back = pair.to_side(Side::Left).to_side(Side::Right);
    /// assert!((back.joint() - j).norm() < 1e-14);
    /// ```
    pub fn to_side(&self, side: Side) -> Self {
        if side == self.side {
            return *self;
        }
        let ad = |g: &G| match side {
            Side::Left => g.adj(),
            Side::Right => g.inverse().adj(),
        };
        let (ax, ay) = (ad(&self.x), ad(&self.y));
        Self {
            cov_xx: congruence(&ax, &self.cov_xx),
            cov_xy: ax * self.cov_xy * ay.transpose(),
            cov_yy: congruence(&ay, &self.cov_yy),
            side,
            ..*self
        }
    }

    /// Σ_Z = J_X Σ_XX J_Xᵀ + J_X Σ_XY J_Yᵀ + J_Y Σ_YX J_Xᵀ + J_Y Σ_YY J_Yᵀ for right-form
    /// Jacobians `right` of Z = f(X, Y), moved to this pair's side.
    fn push_forward(&self, z: &G, right: BinaryJacobians<N>) -> Propagated<G, N> {
        let (jx, jy) = match self.side {
            Side::Right => (right.wrt_lhs, right.wrt_rhs),
            // Left perturbations δᴸ = Ad δᴿ: Jᴸ = Ad_Z Jᴿ Ad_input⁻¹.
            Side::Left => (
                z.adj() * right.wrt_lhs * self.x.inverse().adj(),
                z.adj() * right.wrt_rhs * self.y.inverse().adj(),
            ),
        };
        let cross = jx * self.cov_xy * jy.transpose();
        let cov = jx * self.cov_xx * jx.transpose()
            + cross
            + cross.transpose()
            + jy * self.cov_yy * jy.transpose();
        Propagated {
            pose: UncertainPose::new_unchecked(*z, cov, self.side),
            method: Method::FirstOrder,
        }
    }
}

/// Z = X · Y of correlated poses, first order: Σ_Z = J Σ_joint Jᵀ with J = [J_X, J_Y] from
/// [`LieGroup::compose_jacobians`] — right form J = [Ad_{μY⁻¹}, I], left form J = [I, Ad_{μX}]
/// (Mangelson et al. 2020, IEEE T-RO 36(5), the first-order term of their compounding of
/// correlated poses). With Σ_XY = 0 this is [`compose`].
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::first_order::{compose_correlated, CorrelatedPair};
/// use posecov::uncertain::Side;
/// use nalgebra::DMatrix;
/// // Y = X⁻¹ exactly (perfectly anti-correlated at the identity): X · Y is certain.
/// let mut joint = DMatrix::<f64>::zeros(6, 6);
/// for i in 0..3 { joint[(i, i)] = 0.01; joint[(i + 3, i + 3)] = 0.01; joint[(i, i + 3)] = -0.01; joint[(i + 3, i)] = -0.01; }
/// let pair = CorrelatedPair::try_new(Se2::identity(), Se2::identity(), &joint, Side::Right).unwrap();
/// assert!(compose_correlated(&pair).pose.cov().norm() < 1e-15);
/// ```
pub fn compose_correlated<G: LieGroup<N>, const N: usize>(
    pair: &CorrelatedPair<G, N>,
) -> Propagated<G, N> {
    let z = pair.x.compose(&pair.y);
    pair.push_forward(&z, pair.x.compose_jacobians(&pair.y))
}

/// Z = X⁻¹ · Y (the relative pose, "Y seen from X") of correlated poses, first order:
/// Σ_Z = J Σ_joint Jᵀ with J from [`LieGroup::between_jacobians`] — right form
/// J = [−Ad_{Z⁻¹}, I], left form J = [−Ad_{μX⁻¹}, Ad_{μX⁻¹}] (Mangelson et al. 2020).
/// Positively correlated poses (e.g. two poses of one odometry chain) have a relative pose
/// far more certain than the independent formula claims.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::first_order::{between_correlated, CorrelatedPair};
/// use posecov::uncertain::Side;
/// use nalgebra::DMatrix;
/// // X and Y share the same error: the relative pose is certain.
/// let joint = DMatrix::<f64>::from_fn(6, 6, |r, c| if r % 3 == c % 3 { 0.01 } else { 0.0 });
/// let pair = CorrelatedPair::try_new(Se2::identity(), Se2::identity(), &joint, Side::Right).unwrap();
/// assert!(between_correlated(&pair).pose.cov().norm() < 1e-15);
/// ```
pub fn between_correlated<G: LieGroup<N>, const N: usize>(
    pair: &CorrelatedPair<G, N>,
) -> Propagated<G, N> {
    let z = pair.x.between(&pair.y);
    pair.push_forward(&z, pair.x.between_jacobians(&pair.y))
}

/// Z = X · Y of independent uncertain poses, first order ([CONVENTIONS §5]): right form
/// Σ_Z = Ad_{μY⁻¹} Σ_X Ad_{μY⁻¹}ᵀ + Σ_Y, left form Σ_X + Ad_{μX} Σ_Y Ad_{μX}ᵀ (Barfoot &
/// Furgale 2014 §III-A, first-order term). The result is on the side of `x` (`y` is converted).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::first_order::compose;
/// use posecov::uncertain::{Side, UncertainPose};
/// let x = UncertainPose::try_from_std_devs(Se2::identity(), [0.0, 0.0, 0.1], Side::Right).unwrap();
/// let step = UncertainPose::certain(Se2::from_xy_theta(2.0, 0.0, 0.0));
/// let z = compose(&x, &step);
/// // a heading error of 0.1 rad swings a point 2 m ahead by 0.2 m sideways
/// assert!((z.pose.cov()[(1, 1)] - 0.04).abs() < 1e-15);
/// ```
///
/// [CONVENTIONS §5]: crate::conventions#5-first-order-propagation
pub fn compose<G: LieGroup<N>, const N: usize>(
    x: &UncertainPose<G, N>,
    y: &UncertainPose<G, N>,
) -> Propagated<G, N> {
    compose_correlated(&CorrelatedPair::independent(x, y))
}

/// Z = X⁻¹ · Y of independent uncertain poses, first order: right form
/// Σ_Z = Ad_{Z⁻¹} Σ_X Ad_{Z⁻¹}ᵀ + Σ_Y, left form Ad_{μX⁻¹} (Σ_X + Σ_Y) Ad_{μX⁻¹}ᵀ. On the
/// side of `x`.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::first_order::between;
/// use posecov::uncertain::{Side, UncertainPose};
/// let x = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.0], Side::Right).unwrap();
/// let y = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.0], Side::Right).unwrap();
/// assert!((between(&x, &y).pose.cov()[(0, 0)] - 0.02).abs() < 1e-15);
/// ```
pub fn between<G: LieGroup<N>, const N: usize>(
    x: &UncertainPose<G, N>,
    y: &UncertainPose<G, N>,
) -> Propagated<G, N> {
    between_correlated(&CorrelatedPair::independent(x, y))
}

/// An uncertain point: mean and covariance in the frame its name says (e.g. `p_in_world`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UncertainPoint<const D: usize> {
    /// The mean position.
    pub mean: SVector<f64, D>,
    /// Its D × D covariance.
    pub cov: SMatrix<f64, D, D>,
    /// How the covariance was computed.
    pub method: Method,
}

/// An uncertain point seen from an uncertain pose: `p_in_world = world_from_cam · p_in_cam`,
/// with the pose and the point independent. First order, from [`LieGroup::act_jacobians`]
/// (Solà et al. 2018 eqs. 181–182 for SE(3): J_X = [R, −R p^], J_p = R):
/// Σ_q = J_X Σ_right J_Xᵀ + J_p Σ_p J_pᵀ (the pose's Σ is moved to the right side first).
/// Errors: the point or Σ_p not finite, Σ_p asymmetric or not PSD.
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::first_order::act_point;
/// use posecov::uncertain::{Side, UncertainPose};
/// use nalgebra::{Matrix3, Vector3};
/// // camera yaw σ = 0.01 rad, landmark 10 m ahead with σ = 0.05 m along each axis
/// let world_from_cam = UncertainPose::try_from_std_devs(Se3::identity(), [0.0, 0.0, 0.0, 0.0, 0.0, 0.01], Side::Right).unwrap();
/// let p = act_point(&world_from_cam, &Vector3::new(10.0, 0.0, 0.0), &(Matrix3::identity() * 0.0025)).unwrap();
/// assert!((p.cov[(1, 1)] - (0.01 + 0.0025)).abs() < 1e-12); // (10 · 0.01)² + 0.05²
/// ```
pub fn act_point<G, const N: usize, const D: usize>(
    world_from_cam: &UncertainPose<G, N>,
    p_in_cam: &SVector<f64, D>,
    cov_in_cam: &SMatrix<f64, D, D>,
) -> Result<UncertainPoint<D>>
where
    G: LieGroup<
            N,
            Point = SVector<f64, D>,
            ActJacobian = SMatrix<f64, D, N>,
            PointJacobian = SMatrix<f64, D, D>,
        >,
{
    check_finite("point", p_in_cam.iter().copied())?;
    let cov_point = validate_covariance("point covariance", cov_in_cam)?;
    let mean_pose = world_from_cam.mean();
    let j = mean_pose.act_jacobians(p_in_cam);
    let cov = j.wrt_group * world_from_cam.cov_right() * j.wrt_group.transpose()
        + j.wrt_point * cov_point * j.wrt_point.transpose();
    Ok(UncertainPoint {
        mean: mean_pose.act(p_in_cam),
        cov: (cov + cov.transpose()) * 0.5,
        method: Method::FirstOrder,
    })
}
