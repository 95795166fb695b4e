//! Second- and fourth-order compounding of two independent uncertain poses
//! (Barfoot & Furgale 2014, "Associating Uncertainty With Three-Dimensional Poses for Use in
//! Estimation Problems", IEEE T-RO 30(3), §III-A: eq. 38 and eq. 55).
//!
//! # Form
//! **Left** perturbations, as in the paper: Tᵢ = Exp(ξᵢ) T̄ᵢ, ξᵢ = [ρ; θ] ~ N(0, Σᵢ). Then
//! T₁ T₂ = Exp(ξ₁) Exp(ξ₂') T̄₁ T̄₂ with ξ₂' = Ad(T̄₁) ξ₂, Σ₂' = Ad(T̄₁) Σ₂ Ad(T̄₁)ᵀ, and the
//! compound T = Exp(ξ) T̄, T̄ = T̄₁ T̄₂, ξ = BCH(ξ₁, ξ₂'). Inputs given on the right side are
//! converted to the left first (Σ_left = Ad_μ Σ_right Ad_μᵀ); the result is on the left side.
//!
//! # Terms
//! With the operators (Barfoot & Furgale 2014, defined with eq. 55)
//! ⟨⟨A⟩⟩ = −tr(A) 1 + A and ⟨⟨A, B⟩⟩ = ⟨⟨A⟩⟩⟨⟨B⟩⟩ + ⟨⟨BA⟩⟩ (3×3),
//! - 2nd order (eq. 38): Σ ≈ Σ₁ + Σ₂'.
//! - 4th order (eq. 55): Σ ≈ Σ₁ + Σ₂' + ¼ B + 1⁄12 (A₁ Σ₂' + Σ₂' A₁ᵀ + A₂' Σ₁ + Σ₁ A₂'ᵀ), where
//!   Aᵢ = ⟨⟨Σᵢ⟩⟩ = [[⟨⟨Σθθ⟩⟩, ⟨⟨Σρθ + Σρθᵀ⟩⟩], [0, ⟨⟨Σθθ⟩⟩]] = E[ξ^⋏ ξ^⋏] and
//!   B = [[B_ρρ, B_ρθ], [B_ρθᵀ, B_θθ]] = E[ξ₁^⋏ Σ₂' ξ₁^⋏ᵀ] with
//!   B_ρρ = ⟨⟨Σ₁θθ, Σ₂'ρρ⟩⟩ + ⟨⟨Σ₁ρθᵀ, Σ₂'ρθ⟩⟩ + ⟨⟨Σ₁ρθ, Σ₂'ρθᵀ⟩⟩ + ⟨⟨Σ₁ρρ, Σ₂'θθ⟩⟩,
//!   B_ρθ = ⟨⟨Σ₁θθ, Σ₂'ρθᵀ⟩⟩ + ⟨⟨Σ₁ρθᵀ, Σ₂'θθ⟩⟩, B_θθ = ⟨⟨Σ₁θθ, Σ₂'θθ⟩⟩.
//!   (ξ^⋏ = ad(ξ); ¼ B comes from the ½ ξ₁^⋏ ξ₂' term of BCH, the 1⁄12 terms from
//!   1⁄12 ξ₁^⋏ ξ₁^⋏ ξ₂' + 1⁄12 ξ₂'^⋏ ξ₂'^⋏ ξ₁.) The mean stays T̄₁ T̄₂.
//!
//! # SE(2)
//! By embedding: SE(2) is the subgroup of SE(3) with z = roll = pitch = 0, and the embedding
//! [ρx, ρy, θ] ↦ [ρx, ρy, 0, 0, 0, θ] commutes with Exp, Ad and BCH. The 3×3 covariances are
//! lifted into 6×6 with zero z / roll / pitch rows, compounded with the SE(3) formula, and the
//! (ρx, ρy, θz) block is read back (the other rows stay exactly 0). Tested against SE(2)
//! Monte Carlo.
//!
//! ```
//! use posecov::lie::{LieGroup, Se3};
//! use posecov::propagate::fourth_order::{Order, compound_se3};
//! use posecov::uncertain::{Side, UncertainPose};
//! use nalgebra::{Matrix6, Vector6};
//! // Barfoot & Furgale Fig. 2, one step: the 4th order adds along-track variance.
//! let step = Se3::exp(&Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0));
//! let yaw = Matrix6::from_diagonal(&Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0009));
//! let a = UncertainPose::try_new(step, yaw, Side::Left).unwrap();
//! let b = compound_se3(&a, &a, Order::Second);
//! let c = compound_se3(&a, &a, Order::Fourth);
//! assert_eq!(b.pose.cov()[(0, 0)], 0.0);
//! assert!(c.pose.cov()[(0, 0)] > 0.0);
//! ```

use nalgebra::{Matrix3, Matrix6};

use super::Propagated;
/// SE(2) as the planar subgroup of SE(3) (re-exported: one definition, in [`crate::convert`]).
pub use crate::convert::se2_to_se3;
use crate::lie::{LieGroup, Se2, Se3};
use crate::uncertain::{Method, Side, UncertainPose};

/// Which truncation of the compound covariance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Order {
    /// Σ₁ + Σ₂' (Barfoot & Furgale 2014, eq. 38): equals first-order left-form compounding.
    Second,
    /// Eq. 55: adds the ¼ B and 1⁄12 A terms, exact to fourth order in ξ.
    Fourth,
}

impl Order {
    /// The [`Method`] a result of this order carries.
    ///
    /// ```
    /// use posecov::propagate::fourth_order::Order;
    /// assert_eq!(Order::Fourth.method(), posecov::uncertain::Method::FourthOrder);
    /// ```
    pub fn method(self) -> Method {
        match self {
            Order::Second => Method::SecondOrder,
            Order::Fourth => Method::FourthOrder,
        }
    }
}

/// Known wrong transcriptions of eq. 55 found in public code: kept only so the test suite can
/// show that the Gauss–Hermite oracle ([REFERENCE_CASES R6]) rejects each of them. Not API.
///
/// [REFERENCE_CASES R6]: crate::reference_cases#r6-a-deterministic-oracle-for-fourth-order
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Eq. 55 as published.
    Paper,
    /// B_ρθ with ⟨⟨Σ₁ρθ, Σ₂'θθ⟩⟩ instead of ⟨⟨Σ₁ρθᵀ, Σ₂'θθ⟩⟩.
    BRhoThetaUntransposed,
    /// A₁'s off-diagonal block ⟨⟨Σ₁ρθ Σ₁ρθᵀ⟩⟩ instead of ⟨⟨Σ₁ρθ + Σ₁ρθᵀ⟩⟩.
    A1Product,
    /// ⟨⟨A, B⟩⟩ = ⟨⟨A⟩⟩⟨⟨B⟩⟩ · ⟨⟨BA⟩⟩ instead of the sum.
    DoubleBracketProduct,
}

/// ⟨⟨A⟩⟩ = −tr(A) 1 + A (Barfoot & Furgale 2014, with eq. 55); for A = E\[θθᵀ\],
/// ⟨⟨A⟩⟩ = E[θ^ θ^].
///
/// ```
/// use posecov::propagate::fourth_order::bracket;
/// use nalgebra::Matrix3;
/// assert_eq!(bracket(&Matrix3::identity()), Matrix3::identity() * -2.0);
/// ```
pub fn bracket(a: &Matrix3<f64>) -> Matrix3<f64> {
    a - Matrix3::identity() * a.trace()
}

/// ⟨⟨A, B⟩⟩ = ⟨⟨A⟩⟩⟨⟨B⟩⟩ + ⟨⟨BA⟩⟩ (Barfoot & Furgale 2014, with eq. 55); for A = E\[θθᵀ\],
/// E[θ^ B θ^ᵀ] = ⟨⟨A, B⟩⟩ when B is symmetric.
///
/// ```
/// use posecov::propagate::fourth_order::{bracket, bracket2};
/// use nalgebra::Matrix3;
/// let s = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 2.0, 3.0));
/// // E[θ^ θ^ᵀ] = tr(S) 1 − S
/// assert_eq!(bracket2(&s, &Matrix3::identity()), -bracket(&s));
/// ```
pub fn bracket2(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix3<f64> {
    bracket2_variant(a, b, Variant::Paper)
}

fn bracket2_variant(a: &Matrix3<f64>, b: &Matrix3<f64>, variant: Variant) -> Matrix3<f64> {
    let (first, second) = (bracket(a) * bracket(b), bracket(&(b * a)));
    match variant {
        Variant::DoubleBracketProduct => first * second,
        _ => first + second,
    }
}

/// 3×3 block (`row`, `col`) ∈ {0, 1}² of a 6×6 matrix (0 = ρ, 1 = θ).
fn block(m: &Matrix6<f64>, row: usize, col: usize) -> Matrix3<f64> {
    m.fixed_view::<3, 3>(3 * row, 3 * col).into_owned()
}

/// [[tl, tr], [bl, br]] from 3×3 blocks.
fn from_blocks(
    tl: &Matrix3<f64>,
    tr: &Matrix3<f64>,
    bl: &Matrix3<f64>,
    br: &Matrix3<f64>,
) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(tl);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(tr);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(bl);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(br);
    m
}

/// A = ⟨⟨Σ⟩⟩ = [[⟨⟨Σθθ⟩⟩, ⟨⟨Σρθ + Σρθᵀ⟩⟩], [0, ⟨⟨Σθθ⟩⟩]] = E[ξ^⋏ ξ^⋏] for ξ = [ρ; θ] ~ N(0, Σ)
/// (Barfoot & Furgale 2014, with eq. 55).
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::fourth_order::bracket_se3;
/// use nalgebra::{Matrix6, Vector6};
/// // A pure translation covariance has no rotation to couple with: A = 0.
/// let s = Matrix6::from_diagonal(&Vector6::new(1.0, 2.0, 3.0, 0.0, 0.0, 0.0));
/// assert_eq!(bracket_se3(&s), Matrix6::zeros());
/// ```
pub fn bracket_se3(cov: &Matrix6<f64>) -> Matrix6<f64> {
    bracket_se3_variant(cov, false)
}

fn bracket_se3_variant(cov: &Matrix6<f64>, product: bool) -> Matrix6<f64> {
    let (rho_theta, theta_theta) = (block(cov, 0, 1), block(cov, 1, 1));
    let coupling = if product {
        rho_theta * rho_theta.transpose()
    } else {
        rho_theta + rho_theta.transpose()
    };
    let diagonal = bracket(&theta_theta);
    from_blocks(&diagonal, &bracket(&coupling), &Matrix3::zeros(), &diagonal)
}

/// B = E[ξ₁^⋏ Σ₂ ξ₁^⋏ᵀ] in block form (Barfoot & Furgale 2014, with eq. 55; see the
/// [module docs](self#terms)).
fn b_matrix(cov1: &Matrix6<f64>, cov2: &Matrix6<f64>, variant: Variant) -> Matrix6<f64> {
    let b2 = |a: &Matrix3<f64>, b: &Matrix3<f64>| bracket2_variant(a, b, variant);
    let (s1_rr, s1_rt, s1_tt) = (block(cov1, 0, 0), block(cov1, 0, 1), block(cov1, 1, 1));
    let (s2_rr, s2_rt, s2_tt) = (block(cov2, 0, 0), block(cov2, 0, 1), block(cov2, 1, 1));
    let b_rr = b2(&s1_tt, &s2_rr)
        + b2(&s1_rt.transpose(), &s2_rt)
        + b2(&s1_rt, &s2_rt.transpose())
        + b2(&s1_rr, &s2_tt);
    let s1_rt_in_b_rt = match variant {
        Variant::BRhoThetaUntransposed => s1_rt,
        _ => s1_rt.transpose(),
    };
    let b_rt = b2(&s1_tt, &s2_rt.transpose()) + b2(&s1_rt_in_b_rt, &s2_tt);
    let b_tt = b2(&s1_tt, &s2_tt);
    from_blocks(&b_rr, &b_rt, &b_rt.transpose(), &b_tt)
}

/// The left-form compound covariance of ξ = BCH(ξ₁, ξ₂') for independent ξ₁ ~ N(0, Σ₁),
/// ξ₂' ~ N(0, Σ₂') (Σ₂' already moved through Ad(T̄₁)): eq. 38 (`Order::Second`,
/// Σ₁ + Σ₂') or eq. 55 (`Order::Fourth`, see the [module docs](self#terms)). Symmetrised.
///
/// ```
/// use posecov::propagate::fourth_order::{Order, compound_covariance};
/// use nalgebra::Matrix6;
/// let s = Matrix6::identity() * 1e-4;
/// assert_eq!(compound_covariance(&s, &s, Order::Second), s * 2.0);
/// let d = compound_covariance(&s, &s, Order::Fourth) - s * 2.0;
/// assert!(d.norm() < 1e-6 && d.norm() > 0.0); // 4th-order terms are O(Σ²)
/// ```
pub fn compound_covariance(
    cov1: &Matrix6<f64>,
    cov2_prime: &Matrix6<f64>,
    order: Order,
) -> Matrix6<f64> {
    match order {
        Order::Second => symmetrise(&(cov1 + cov2_prime)),
        Order::Fourth => compound_covariance_variant(cov1, cov2_prime, Variant::Paper),
    }
}

/// Eq. 55 or one of the known wrong [`Variant`]s. Test support only.
#[doc(hidden)]
pub fn compound_covariance_variant(
    cov1: &Matrix6<f64>,
    cov2_prime: &Matrix6<f64>,
    variant: Variant,
) -> Matrix6<f64> {
    let a1 = bracket_se3_variant(cov1, variant == Variant::A1Product);
    let a2 = bracket_se3(cov2_prime);
    let b = b_matrix(cov1, cov2_prime, variant);
    let twelfth = a1 * cov2_prime + cov2_prime * a1.transpose() + a2 * cov1 + cov1 * a2.transpose();
    symmetrise(&(cov1 + cov2_prime + b * 0.25 + twelfth / 12.0))
}

fn symmetrise(m: &Matrix6<f64>) -> Matrix6<f64> {
    (m + m.transpose()) * 0.5
}

/// Compounds two independent uncertain SE(3) poses, T = T₁ T₂, to second (eq. 38) or fourth
/// (eq. 55) order (Barfoot & Furgale 2014, §III-A). Inputs on either side; the result is on
/// the **left** side: T = Exp(ξ) T̄₁T̄₂, ξ ~ N(0, Σ).
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::fourth_order::{Order, compound_se3};
/// use posecov::uncertain::{Method, Side, UncertainPose};
/// use nalgebra::Matrix6;
/// let a = UncertainPose::try_new(Se3::from_xyz_rpy([1.0, 0.0, 0.0], [0.0, 0.0, 0.3]), Matrix6::identity() * 1e-3, Side::Right).unwrap();
/// let c = compound_se3(&a, &a, Order::Fourth);
/// assert_eq!(c.method, Method::FourthOrder);
/// assert_eq!(c.pose.side(), Side::Left);
/// ```
pub fn compound_se3(
    a: &UncertainPose<Se3, 6>,
    b: &UncertainPose<Se3, 6>,
    order: Order,
) -> Propagated<Se3, 6> {
    let (cov1, cov2_prime) = left_inputs(a, b);
    let cov = compound_covariance(&cov1, &cov2_prime, order);
    Propagated {
        pose: UncertainPose::new_unchecked(a.mean().compose(b.mean()), cov, Side::Left),
        method: order.method(),
    }
}

/// Σ₁ and Σ₂' = Ad(T̄₁) Σ₂ Ad(T̄₁)ᵀ, both on the left side.
fn left_inputs(
    a: &UncertainPose<Se3, 6>,
    b: &UncertainPose<Se3, 6>,
) -> (Matrix6<f64>, Matrix6<f64>) {
    let ad = a.mean().adj();
    (a.cov_left(), ad * b.cov_left() * ad.transpose())
}

/// [`compound_se3`] with a known wrong [`Variant`] of eq. 55. Test support only.
#[doc(hidden)]
pub fn compound_se3_variant(
    a: &UncertainPose<Se3, 6>,
    b: &UncertainPose<Se3, 6>,
    variant: Variant,
) -> Propagated<Se3, 6> {
    let (cov1, cov2_prime) = left_inputs(a, b);
    Propagated {
        pose: UncertainPose::new_unchecked(
            a.mean().compose(b.mean()),
            compound_covariance_variant(&cov1, &cov2_prime, variant),
            Side::Left,
        ),
        method: Method::FourthOrder,
    }
}

/// Tangent indices of SE(2)'s [ρx, ρy, θ] inside SE(3)'s [ρ; θ].
const SE2_IN_SE3: [usize; 3] = [0, 1, 5];

/// The planar part of an SE(3) pose: (x, y, yaw), dropping z, roll and pitch (the inverse of
/// [`se2_to_se3`] on the planar subgroup).
///
/// ```
/// use posecov::lie::Se3;
/// use posecov::propagate::fourth_order::se3_to_se2;
/// let p = se3_to_se2(&Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0, 0.0, 0.4]));
/// assert!((p.theta() - 0.4).abs() < 1e-15 && p.y() == 2.0);
/// ```
pub fn se3_to_se2(x: &Se3) -> Se2 {
    let r = x.rotation().to_matrix();
    let t = x.translation();
    Se2::from_xy_theta(t.x, t.y, r[(1, 0)].atan2(r[(0, 0)]))
}

/// Lifts an SE(2) covariance in [ρx, ρy, θ] into SE(3)'s [ρ; θ] with zero z / roll / pitch
/// rows and columns.
///
/// ```
/// use posecov::propagate::fourth_order::lift_se2_covariance;
/// let s = lift_se2_covariance(&nalgebra::Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 5.0, 3.0, 5.0, 6.0));
/// assert_eq!((s[(0, 5)], s[(5, 5)], s[(2, 2)]), (3.0, 6.0, 0.0));
/// ```
pub fn lift_se2_covariance(cov: &Matrix3<f64>) -> Matrix6<f64> {
    let mut lifted = Matrix6::zeros();
    for (i, &row) in SE2_IN_SE3.iter().enumerate() {
        for (j, &col) in SE2_IN_SE3.iter().enumerate() {
            lifted[(row, col)] = cov[(i, j)];
        }
    }
    lifted
}

/// The (ρx, ρy, θz) block of an SE(3) covariance, the inverse of [`lift_se2_covariance`].
///
/// ```
/// use posecov::propagate::fourth_order::{lift_se2_covariance, project_se2_covariance};
/// let c = nalgebra::Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 5.0, 3.0, 5.0, 6.0);
/// assert_eq!(project_se2_covariance(&lift_se2_covariance(&c)), c);
/// ```
pub fn project_se2_covariance(cov: &Matrix6<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| cov[(SE2_IN_SE3[i], SE2_IN_SE3[j])])
}

/// Compounds two independent uncertain SE(2) poses to second or fourth order by embedding in
/// SE(3) ([module docs](self#se2)): lift, [`compound_covariance`], project. Result on the left
/// side.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::fourth_order::{Order, compound_se2};
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 0.0, 0.0), [0.0, 0.0, 0.1], Side::Left).unwrap();
/// let c = compound_se2(&a, &a, Order::Fourth);
/// assert!(c.pose.cov()[(0, 0)] > 0.0); // along-track variance from the yaw noise
/// assert!((c.pose.mean().x() - 2.0).abs() < 1e-15);
/// ```
pub fn compound_se2(
    a: &UncertainPose<Se2, 3>,
    b: &UncertainPose<Se2, 3>,
    order: Order,
) -> Propagated<Se2, 3> {
    let ad = se2_to_se3(a.mean()).adj();
    let cov1 = lift_se2_covariance(&a.cov_left());
    let cov2_prime = ad * lift_se2_covariance(&b.cov_left()) * ad.transpose();
    let cov = project_se2_covariance(&compound_covariance(&cov1, &cov2_prime, order));
    Propagated {
        pose: UncertainPose::new_unchecked(a.mean().compose(b.mean()), cov, Side::Left),
        method: order.method(),
    }
}
