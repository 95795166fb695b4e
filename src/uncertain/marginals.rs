//! Marginals of an uncertain pose (docs/CONVENTIONS.md §7): first order in the position, exact
//! in the rotation; the one world-position covariance (`position_cov_in_world_3d`).

use nalgebra::{Matrix2, Matrix3, SMatrix, Vector2, Vector3};

use super::{Side, UncertainPose};
use crate::lie::{LieGroup, Se2, Se3, So2, So3};

/// R Σ Rᵀ.
fn rotate_cov<const D: usize>(
    r: &SMatrix<f64, D, D>,
    cov: &SMatrix<f64, D, D>,
) -> SMatrix<f64, D, D> {
    let out = r * cov * r.transpose();
    (out + out.transpose()) * 0.5
}

impl<G: LieGroup<N>, const N: usize> UncertainPose<G, N> {
    /// Position covariance in the **world** axes, first order, lifted into 3D for any group:
    /// R Σ_ρρ Rᵀ from the right form (planar groups: z row and column zero; rotation groups:
    /// `None`, they have no position). The one world-position covariance of the crate; the
    /// per-group [`position_cov_in_world`](UncertainPose::position_cov_in_world) are views of it.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2, So3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let yaw90 = Se2::from_xy_theta(5.0, 0.0, std::f64::consts::FRAC_PI_2);
    /// let p = UncertainPose::try_from_std_devs(yaw90, [0.1, 0.0, 0.0], Side::Right).unwrap();
    /// let c = p.position_cov_in_world_3d().unwrap();
    /// assert!((c[(1, 1)] - 0.01).abs() < 1e-15 && c[(2, 2)] == 0.0); // body x is world y
    /// assert!(UncertainPose::certain(So3::identity()).position_cov_in_world_3d().is_none());
    /// ```
    pub fn position_cov_in_world_3d(&self) -> Option<Matrix3<f64>> {
        let d = G::KIND.position_dims();
        if d == 0 {
            return None;
        }
        let cov = self.cov_right();
        let block = Matrix3::from_fn(|r, c| if r < d && c < d { cov[(r, c)] } else { 0.0 });
        Some(rotate_cov(
            &self.mean.to_se3().rotation().to_matrix(),
            &block,
        ))
    }
}

impl UncertainPose<Se3, 6> {
    /// The mean position t (the body origin in the world frame).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0; 3]));
    /// assert_eq!(p.position().x, 1.0);
    /// ```
    pub fn position(&self) -> Vector3<f64> {
        *self.mean.translation()
    }

    /// Position covariance in the **body** axes, first order: the ρρ block of the right-form
    /// Σ (X = μ Exp([ρ; θ]) moves the position by R Jl(θ) ρ ≈ R ρ; Solà et al. 2018 eq. 172).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se3::identity(), [0.1, 0.2, 0.3, 0.0, 0.0, 0.0], Side::Right).unwrap();
    /// assert!((p.position_cov_in_body()[(2, 2)] - 0.09).abs() < 1e-15);
    /// ```
    pub fn position_cov_in_body(&self) -> Matrix3<f64> {
        self.cov_right().fixed_view::<3, 3>(0, 0).into_owned()
    }

    /// Position covariance in the **world** axes, first order: R Σ_ρρ Rᵀ from the right form
    /// ([CONVENTIONS §7]). Note: this is *not* the ρρ block of the left form unless t = 0 — a
    /// left perturbation moves the position by ρ + θ × t.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let yaw90 = Se3::from_xyz_rpy([5.0, 0.0, 0.0], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
    /// let p = UncertainPose::try_from_std_devs(yaw90, [0.1, 0.0, 0.0, 0.0, 0.0, 0.0], Side::Right).unwrap();
    /// // body x is world y
    /// assert!((p.position_cov_in_world()[(1, 1)] - 0.01).abs() < 1e-15);
    /// ```
    ///
    /// [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty
    pub fn position_cov_in_world(&self) -> Matrix3<f64> {
        self.position_cov_in_world_3d()
            .unwrap_or_else(Matrix3::zeros)
    }

    /// Rotation covariance in the body frame: the θθ block of the right-form Σ (exact: the
    /// rotation of μ Exp([ρ; θ]) is R Exp(θ)).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se3::identity(), [0.0, 0.0, 0.0, 0.1, 0.0, 0.0], Side::Right).unwrap();
    /// assert!((p.rotation_cov_in_body()[(0, 0)] - 0.01).abs() < 1e-15);
    /// ```
    pub fn rotation_cov_in_body(&self) -> Matrix3<f64> {
        self.cov_right().fixed_view::<3, 3>(3, 3).into_owned()
    }

    /// Rotation covariance in the world frame: R Σ_θθ Rᵀ (exact: R Exp(θ) = Exp(R θ) R), equal
    /// to the θθ block of the left form.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let x = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
    /// let p = UncertainPose::try_from_std_devs(x, [0.1, 0.2, 0.3, 0.01, 0.02, 0.03], Side::Right).unwrap();
    /// let left = p.cov_left();
    /// assert!((p.rotation_cov_in_world() - left.fixed_view::<3, 3>(3, 3)).norm() < 1e-15);
    /// ```
    pub fn rotation_cov_in_world(&self) -> Matrix3<f64> {
        rotate_cov(
            &self.mean.rotation().to_matrix(),
            &self.rotation_cov_in_body(),
        )
    }

    /// The rotation marginal as an uncertain SO(3) element (right side, Σ = Σ_θθ; exact).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(Se3::from_xyz_rpy([1.0, 0.0, 0.0], [0.0, 0.0, 0.5]));
    /// assert!((p.rotation_marginal().mean().to_rpy()[2] - 0.5).abs() < 1e-15);
    /// ```
    pub fn rotation_marginal(&self) -> UncertainPose<So3, 3> {
        UncertainPose::new_unchecked(
            *self.mean.rotation(),
            self.rotation_cov_in_body(),
            Side::Right,
        )
    }
}

impl UncertainPose<Se2, 3> {
    /// The mean position (x, y).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::UncertainPose;
    /// assert_eq!(UncertainPose::certain(Se2::from_xy_theta(1.0, 2.0, 0.0)).position().y, 2.0);
    /// ```
    pub fn position(&self) -> Vector2<f64> {
        *self.mean.translation()
    }

    /// Position covariance in the **body** axes, first order: the ρρ block of the right-form Σ
    /// (μ Exp([ρ; θ]) moves the position by R V(θ) ρ ≈ R ρ; Solà et al. 2018 eq. 156).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.2, 0.3], Side::Right).unwrap();
    /// assert!((p.position_cov_in_body()[(1, 1)] - 0.04).abs() < 1e-15);
    /// ```
    pub fn position_cov_in_body(&self) -> Matrix2<f64> {
        self.cov_right().fixed_view::<2, 2>(0, 0).into_owned()
    }

    /// Position covariance in the **world** axes, first order: R Σ_ρρ Rᵀ from the right form
    /// ([CONVENTIONS §7]; the left form's ρρ block differs unless t = 0).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let x = Se2::from_xy_theta(3.0, 0.0, std::f64::consts::FRAC_PI_2);
    /// let p = UncertainPose::try_from_std_devs(x, [0.1, 0.0, 0.0], Side::Right).unwrap();
    /// assert!((p.position_cov_in_world()[(1, 1)] - 0.01).abs() < 1e-15);
    /// ```
    ///
    /// [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty
    pub fn position_cov_in_world(&self) -> Matrix2<f64> {
        self.position_cov_in_world_3d()
            .map_or_else(Matrix2::zeros, |c| c.fixed_view::<2, 2>(0, 0).into_owned())
    }

    /// Heading variance σ_θ² (the same in body and world frames: SO(2) is commutative; exact).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 2.0, 0.3), [0.1, 0.1, 0.2], Side::Left).unwrap();
    /// assert!((p.heading_variance() - 0.04).abs() < 1e-15);
    /// ```
    pub fn heading_variance(&self) -> f64 {
        self.cov[(2, 2)]
    }

    /// The rotation marginal as an uncertain SO(2) element (right side, Σ = σ_θ²; exact).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(Se2::from_xy_theta(0.0, 0.0, 0.4));
    /// assert!((p.rotation_marginal().mean().angle() - 0.4).abs() < 1e-15);
    /// ```
    pub fn rotation_marginal(&self) -> UncertainPose<So2, 1> {
        UncertainPose::new_unchecked(
            *self.mean.rotation(),
            nalgebra::Matrix1::new(self.heading_variance()),
            Side::Right,
        )
    }
}
