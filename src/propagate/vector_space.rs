//! The vector-space baseline: Smith, Self & Cheeseman (1990, "Estimating uncertain spatial
//! relationships in robotics", in *Autonomous Robot Vehicles*, pp. 167–193) linearisation in
//! (x, y, θ) for SE(2) and (x, y, z, roll, pitch, yaw) for SE(3), [`Method::VectorSpace`].
//!
//! A pose is a vector v with a Gaussian N(v̄, Σ_v) *in those coordinates*; compounding
//! v₃ = v₁ ⊕ v₂ = φ(φ⁻¹(v₁) · φ⁻¹(v₂)) is linearised: Σ₃ = J₁ Σ₁ J₁ᵀ + J₂ Σ₂ J₂ᵀ,
//! J_i = ∂v₃/∂v_i. For SE(2) these are SSC's closed forms
//!
//! J₁ = [[1, 0, −(y₃ − y₁)], [0, 1, x₃ − x₁], [0, 0, 1]],  J₂ = [[cos θ₁, −sin θ₁, 0], [sin θ₁, cos θ₁, 0], [0, 0, 1]];
//!
//! here they are computed for both groups by the chain rule through the chart Jacobian of
//! [`VectorChart`]: J₁ = J(v₃) Ad_{X₂⁻¹} J(v₁)⁻¹, J₂ = J(v₃) J(v₂)⁻¹ (identical to the
//! derivative of the Euler-angle compounding, without writing it out for SE(3)).
//!
//! # What the approximation is
//! To first order the SSC numbers and the Lie first-order numbers are the *same linearisation
//! in two charts*: mapping a Lie result through J(v) Σ J(v)ᵀ gives the SSC result, provided
//! the noise is specified consistently. The baseline differs from the Lie picture in two ways
//! the lectures contrast: (1) the distribution it implies is a Gaussian in (x, y, θ) — an
//! ellipse in the plane — where the true cloud after a turn is a banana, which a Gaussian in
//! the tangent space (drawn through Exp) follows; (2) motion noise is usually added to the
//! increment's coordinates (dx, dy, dθ) rather than in its tangent, and Euler angles add their
//! own singularity at pitch = ±π/2 (an error here). [`VectorPose::to_uncertain`] converts a
//! result with the first-order chart map so it can be compared and drawn next to the others.

use std::marker::PhantomData;

use nalgebra::SVector;

use crate::error::{Result, check_finite};
use crate::interop::{VectorChart, from_coordinates, to_coordinates};
use crate::lie::TangentMatrix;
use crate::uncertain::{Method, UncertainPose, validate_covariance};

use super::Propagated;

/// A pose as a Gaussian in vector-space coordinates ([`VectorChart::COORDINATES`] of `G`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VectorPose<G: VectorChart<N>, const N: usize> {
    mean: SVector<f64, N>,
    cov: TangentMatrix<N>,
    group: PhantomData<G>,
}

impl<G: VectorChart<N>, const N: usize> VectorPose<G, N> {
    /// A validated vector-space pose (v finite; Σ_v finite, symmetric, PSD).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::propagate::vector_space::VectorPose;
    /// use nalgebra::{Matrix3, Vector3};
    /// assert!(VectorPose::<Se2, 3>::try_new(Vector3::new(0.0, 0.0, 0.0), Matrix3::identity()).is_ok());
    /// assert!(VectorPose::<Se2, 3>::try_new(Vector3::new(f64::NAN, 0.0, 0.0), Matrix3::identity()).is_err());
    /// ```
    pub fn try_new(mean: SVector<f64, N>, cov: TangentMatrix<N>) -> Result<Self> {
        check_finite("vector-space pose", mean.iter().copied())?;
        let cov = validate_covariance("vector-space covariance", &cov)?;
        Ok(Self {
            mean,
            cov,
            group: PhantomData,
        })
    }

    /// An uncertain pose in coordinates, first order ([`to_coordinates`]). Errors where the
    /// chart is singular (gimbal lock).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::propagate::vector_space::VectorPose;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 0.0, 0.0), [0.1, 0.2, 0.3], Side::Right).unwrap();
    /// let v = VectorPose::from_uncertain(&p).unwrap();
    /// assert!((v.cov()[(1, 1)] - 0.04).abs() < 1e-15);
    /// ```
    pub fn from_uncertain(pose: &UncertainPose<G, N>) -> Result<Self> {
        let (mean, cov) = to_coordinates(pose)?;
        Ok(Self {
            mean,
            cov,
            group: PhantomData,
        })
    }

    /// The mean coordinates v̄.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::propagate::vector_space::VectorPose;
    /// use nalgebra::{Matrix3, Vector3};
    /// let v = VectorPose::<Se2, 3>::try_new(Vector3::new(1.0, 2.0, 0.0), Matrix3::zeros()).unwrap();
    /// assert_eq!(v.mean().y, 2.0);
    /// ```
    pub fn mean(&self) -> &SVector<f64, N> {
        &self.mean
    }

    /// The covariance Σ_v in coordinates.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::propagate::vector_space::VectorPose;
    /// use nalgebra::{Matrix3, Vector3};
    /// let v = VectorPose::<Se2, 3>::try_new(Vector3::zeros(), Matrix3::identity()).unwrap();
    /// assert_eq!(v.cov()[(2, 2)], 1.0);
    /// ```
    pub fn cov(&self) -> &TangentMatrix<N> {
        &self.cov
    }

    /// This result as an uncertain pose (right side) so it can be compared with and drawn next
    /// to the Lie methods: μ = φ⁻¹(v̄), Σ_right = J(v̄)⁻¹ Σ_v J(v̄)⁻ᵀ (first order, see the
    /// [module docs](self)), labelled [`Method::VectorSpace`].
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::propagate::vector_space::VectorPose;
    /// use posecov::uncertain::Method;
    /// use nalgebra::{Matrix3, Vector3};
    /// let v = VectorPose::<Se2, 3>::try_new(Vector3::new(1.0, 2.0, 0.0), Matrix3::identity() * 0.01).unwrap();
    /// let p = v.to_uncertain().unwrap();
    /// assert_eq!(p.method, Method::VectorSpace);
    /// assert!((p.pose.cov() - Matrix3::identity() * 0.01).norm() < 1e-15);
    /// ```
    pub fn to_uncertain(&self) -> Result<Propagated<G, N>> {
        Ok(Propagated {
            pose: from_coordinates::<G, N>(&self.mean, &self.cov)?,
            method: Method::VectorSpace,
        })
    }
}

/// Jacobians (J₁, J₂) of v₃ = v₁ ⊕ v₂ and v₃ itself.
fn compose_jacobians<G: VectorChart<N>, const N: usize>(
    v1: &SVector<f64, N>,
    v2: &SVector<f64, N>,
) -> Result<(SVector<f64, N>, TangentMatrix<N>, TangentMatrix<N>)> {
    let (x1, x2) = (G::try_from_coordinates(v1)?, G::try_from_coordinates(v2)?);
    let v3 = x1.compose(&x2).to_coordinates();
    let j3 = G::coordinates_jacobian(&v3)?;
    let j1 = j3 * x2.inverse().adj() * G::coordinates_jacobian_inverse(v1);
    let j2 = j3 * G::coordinates_jacobian_inverse(v2);
    Ok((v3, j1, j2))
}

/// J Σ Jᵀ, symmetrised.
fn congruence<const N: usize>(j: &TangentMatrix<N>, cov: &TangentMatrix<N>) -> TangentMatrix<N> {
    let out = j * cov * j.transpose();
    (out + out.transpose()) * 0.5
}

/// SSC compounding of independent vector-space poses: v₃ = v₁ ⊕ v₂,
/// Σ₃ = J₁ Σ₁ J₁ᵀ + J₂ Σ₂ J₂ᵀ (Smith, Self & Cheeseman 1990, compounding operation; see the
/// [module docs](self) for J). Errors at gimbal lock.
///
/// ```
/// use posecov::lie::Se2;
/// use posecov::propagate::vector_space::{ssc_compose, VectorPose};
/// use nalgebra::{Matrix3, Vector3};
/// let a = VectorPose::<Se2, 3>::try_new(Vector3::zeros(), Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, 0.01))).unwrap();
/// let b = VectorPose::<Se2, 3>::try_new(Vector3::new(2.0, 0.0, 0.0), Matrix3::zeros()).unwrap();
/// let c = ssc_compose(&a, &b).unwrap();
/// assert!((c.cov()[(1, 1)] - 0.04).abs() < 1e-15); // (2 m · 0.1 rad)²
/// ```
pub fn ssc_compose<G: VectorChart<N>, const N: usize>(
    a: &VectorPose<G, N>,
    b: &VectorPose<G, N>,
) -> Result<VectorPose<G, N>> {
    let (mean, j1, j2) = compose_jacobians::<G, N>(&a.mean, &b.mean)?;
    Ok(VectorPose {
        mean,
        cov: congruence(&j1, &a.cov) + congruence(&j2, &b.cov),
        group: PhantomData,
    })
}

/// SSC inverse ⊖v: v′ = φ(φ⁻¹(v)⁻¹), Σ′ = J Σ Jᵀ with J = J(v′) (−Ad_X) J(v)⁻¹ (for SE(2)
/// SSC's [[−cos θ, −sin θ, y′], [sin θ, −cos θ, −x′], [0, 0, −1]]). Errors at gimbal lock.
///
/// ```
/// use posecov::lie::Se2;
/// use posecov::propagate::vector_space::{ssc_inverse, VectorPose};
/// use nalgebra::{Matrix3, Vector3};
/// let a = VectorPose::<Se2, 3>::try_new(Vector3::new(1.0, 2.0, 0.3), Matrix3::identity() * 0.01).unwrap();
/// let back = ssc_inverse(&ssc_inverse(&a).unwrap()).unwrap();
/// assert!((back.cov() - a.cov()).norm() < 1e-14);
/// ```
pub fn ssc_inverse<G: VectorChart<N>, const N: usize>(
    a: &VectorPose<G, N>,
) -> Result<VectorPose<G, N>> {
    let x = G::try_from_coordinates(&a.mean)?;
    let mean = x.inverse().to_coordinates();
    let j = G::coordinates_jacobian(&mean)? * (-x.adj()) * G::coordinates_jacobian_inverse(&a.mean);
    Ok(VectorPose {
        mean,
        cov: congruence(&j, &a.cov),
        group: PhantomData,
    })
}

/// SSC dead reckoning: v_{k+1} = v_k ⊕ (u_k + w_k), w_k ~ N(0, Σ_w) added to the increment's
/// coordinates (e.g. (dx, dy, dθ)): Σ_{k+1} = J₁ Σ_k J₁ᵀ + J₂ Σ_w J₂ᵀ. Returns the whole
/// trajectory, the start included. Errors: a non-finite increment, Σ_w invalid, gimbal lock.
///
/// ```
/// use posecov::lie::Se2;
/// use posecov::propagate::vector_space::{ssc_odometry, VectorPose};
/// use nalgebra::{Matrix3, Vector3};
/// let start = VectorPose::<Se2, 3>::try_new(Vector3::zeros(), Matrix3::zeros()).unwrap();
/// let u = Vector3::new(1.0, 0.0, 0.1);
/// let path = ssc_odometry(&start, &[u, u], &(Matrix3::identity() * 1e-4)).unwrap();
/// assert_eq!(path.len(), 3);
/// assert!((path[1].cov() - Matrix3::identity() * 1e-4).norm() < 1e-18);
/// ```
pub fn ssc_odometry<G: VectorChart<N>, const N: usize>(
    start: &VectorPose<G, N>,
    increments: &[SVector<f64, N>],
    cov_noise: &TangentMatrix<N>,
) -> Result<Vec<VectorPose<G, N>>> {
    let cov_noise = validate_covariance("SSC noise covariance Σ_w", cov_noise)?;
    let mut out = vec![*start];
    let mut current = *start;
    for u in increments {
        let step = VectorPose::<G, N>::try_new(*u, cov_noise)?;
        current = ssc_compose(&current, &step)?;
        out.push(current);
    }
    Ok(out)
}
