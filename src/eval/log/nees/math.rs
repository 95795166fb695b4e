//! The numbers of one message and of an alignment: the three NEES of an estimate against the
//! truth (SE(3), and SE(2) for planar topics) and Umeyama's SE(3) fit.

use nalgebra::{Matrix3, Matrix6, SVector, Vector2, Vector3};

use crate::lie::{LieGroup, Se2, Se3, So2, So3};
use crate::uncertain::{Information, try_information};

/// The three NEES of one message against the truth, or `None` for a singular covariance.
///
/// ```
/// use nalgebra::Matrix6;
/// use posecov::eval::log::nees::nees_se3;
/// use posecov::lie::Se3;
/// let estimate = Se3::from_xyz_rpy([0.0; 3], [0.0, 0.0, 0.0]);
/// let truth = Se3::from_xyz_rpy([0.2, 0.0, 0.0], [0.0, 0.0, 0.0]);
/// let [joint, position, orientation] = nees_se3(&estimate, &(Matrix6::identity() * 0.01), &truth).unwrap();
/// assert!((joint - 4.0).abs() < 1e-12 && (position - 4.0).abs() < 1e-12 && orientation.abs() < 1e-12);
/// ```
pub fn nees_se3(estimate: &Se3, cov: &Matrix6<f64>, truth: &Se3) -> Option<[f64; 3]> {
    let info = try_information("Σ", cov).ok()?;
    nees_se3_informed(estimate, cov, &info, truth)
}

/// [`nees_se3`] with Σ⁻¹ known (from the factorisation that validated Σ).
pub(super) fn nees_se3_informed(
    estimate: &Se3,
    cov: &Matrix6<f64>,
    info: &Information<6>,
    truth: &Se3,
) -> Option<[f64; 3]> {
    let e = truth.rminus(estimate);
    let r = estimate.rotation().to_matrix();
    let dp = r.transpose() * (truth.translation() - estimate.translation());
    let pos_info = try_information("Σ_ρρ", &cov.fixed_view::<3, 3>(0, 0).into_owned()).ok()?;
    let theta = truth.rotation().rminus(estimate.rotation());
    let rot_info = try_information("Σ_θθ", &cov.fixed_view::<3, 3>(3, 3).into_owned()).ok()?;
    Some([
        info.quadratic(&e),
        pos_info.quadratic(&dp),
        rot_info.quadratic(&theta),
    ])
}

/// [`nees_se3`] in the plane: the truth projected to (x, y, yaw), e = Log(X̂⁻¹ X_ref) on SE(2).
///
/// ```
/// use nalgebra::Matrix3;
/// use posecov::eval::log::nees::nees_se2;
/// use posecov::lie::{Se2, Se3};
/// let estimate = Se2::from_xy_theta(0.0, 0.0, 0.0);
/// let truth = Se3::from_xyz_rpy([0.0, 0.0, 0.0], [0.0, 0.0, 0.1]);
/// let [joint, _, orientation] = nees_se2(&estimate, &(Matrix3::identity() * 0.01), &truth).unwrap();
/// assert!((joint - 1.0).abs() < 1e-12 && (orientation - 1.0).abs() < 1e-12);
/// ```
pub fn nees_se2(estimate: &Se2, cov: &Matrix3<f64>, truth: &Se3) -> Option<[f64; 3]> {
    let info = try_information("Σ", cov).ok()?;
    nees_se2_informed(estimate, cov, &info, truth)
}

/// [`nees_se2`] with Σ⁻¹ known (from the factorisation that validated Σ).
pub(super) fn nees_se2_informed(
    estimate: &Se2,
    cov: &Matrix3<f64>,
    info: &Information<3>,
    truth: &Se3,
) -> Option<[f64; 3]> {
    let t = truth.translation();
    let yaw = truth.rotation().to_rpy()[2];
    let truth = Se2::from_parts(Vector2::new(t.x, t.y), So2::from_angle(yaw));
    let e = truth.rminus(estimate);
    let r = estimate.rotation().to_matrix();
    let dp: SVector<f64, 2> = r.transpose() * (truth.translation() - estimate.translation());
    let pos_info = try_information("Σ_ρρ", &cov.fixed_view::<2, 2>(0, 0).into_owned()).ok()?;
    let theta = truth.rotation().rminus(estimate.rotation())[0];
    let var = cov[(2, 2)];
    if var <= 0.0 {
        return None;
    }
    Some([
        info.quadratic(&e),
        pos_info.quadratic(&dp),
        theta * theta / var,
    ])
}

/// The SE(3) transform T that best maps the reference positions onto the estimates'
/// (Umeyama 1991 without scale: H = Σ (p_ref − μ_ref)(p̂ − μ̂)ᵀ = U S Vᵀ,
/// R = V diag(1, 1, det(V Uᵀ)) Uᵀ, t = μ̂ − R μ_ref) from (p_ref, p̂) pairs; `None` for fewer
/// than 3 pairs.
///
/// ```
/// use nalgebra::Vector3;
/// use posecov::eval::log::nees::umeyama;
/// use posecov::lie::{LieGroup, Se3};
/// let t = Se3::from_xyz_rpy([1.0, -2.0, 0.5], [0.3, -0.1, 1.2]);
/// let refs = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 2.0, 0.0), Vector3::new(0.0, 0.0, 3.0)];
/// let pairs: Vec<_> = refs.iter().map(|p| (*p, t.act(p))).collect();
/// let fit = umeyama(&pairs).unwrap();
/// assert!(fit.rminus(&t).norm() < 1e-12);
/// ```
pub fn umeyama(pairs: &[(Vector3<f64>, Vector3<f64>)]) -> Option<Se3> {
    if pairs.len() < 3 {
        return None;
    }
    let n = pairs.len() as f64;
    let refs: Vec<Vector3<f64>> = pairs.iter().map(|p| p.0).collect();
    let ests: Vec<Vector3<f64>> = pairs.iter().map(|p| p.1).collect();
    let mu_ref = refs.iter().sum::<Vector3<f64>>() / n;
    let mu_est = ests.iter().sum::<Vector3<f64>>() / n;
    let h = refs.iter().zip(&ests).fold(Matrix3::zeros(), |h, (r, e)| {
        h + (r - mu_ref) * (e - mu_est).transpose()
    });
    let svd = h.svd(true, true);
    let (u, v_t) = (svd.u?, svd.v_t?);
    let v = v_t.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    let rotation = So3::try_from_matrix(&r).ok()?;
    Some(Se3::from_parts(mu_est - r * mu_ref, rotation))
}
