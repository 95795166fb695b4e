//! Conversions at the boundary: nalgebra types and glam (f32, for rendering only).
//!
//! The math core is `f64`; glam `f32` values are produced only where data leaves for the
//! viewer (Rerun speaks glam). Quaternion component orders are named at every boundary:
//! nalgebra stores `[i, j, k, w]`, glam uses `from_xyzw`, ROS messages are `(x, y, z, w)`.

use glam::{Affine3A, Quat, Vec3};
use nalgebra::{Isometry2, Isometry3, UnitComplex, UnitQuaternion, Vector3};

use crate::lie::{LieGroup, Se2, Se3, So2, So3};

impl From<UnitQuaternion<f64>> for So3 {
    fn from(q: UnitQuaternion<f64>) -> Self {
        So3::from_quaternion(q)
    }
}

impl From<So3> for UnitQuaternion<f64> {
    fn from(r: So3) -> Self {
        *r.quaternion()
    }
}

impl From<Isometry3<f64>> for Se3 {
    fn from(iso: Isometry3<f64>) -> Self {
        Se3::from_isometry(&iso)
    }
}

impl From<Se3> for Isometry3<f64> {
    fn from(x: Se3) -> Self {
        x.to_isometry()
    }
}

impl From<Isometry2<f64>> for Se2 {
    fn from(iso: Isometry2<f64>) -> Self {
        Se2::from_isometry(&iso)
    }
}

impl From<Se2> for Isometry2<f64> {
    fn from(x: Se2) -> Self {
        x.to_isometry()
    }
}

impl From<UnitComplex<f64>> for So2 {
    fn from(z: UnitComplex<f64>) -> Self {
        So2::from_angle(z.angle())
    }
}

/// A 3D vector as glam `Vec3` (f32, for rendering).
///
/// ```
/// use posecov::convert::vec3_to_glam;
/// assert_eq!(vec3_to_glam(&nalgebra::Vector3::new(1.0, 2.0, 3.0)), glam::Vec3::new(1.0, 2.0, 3.0));
/// ```
pub fn vec3_to_glam(v: &Vector3<f64>) -> Vec3 {
    Vec3::new(v.x as f32, v.y as f32, v.z as f32)
}

/// A rotation as glam `Quat` (f32, x y z w order), renormalised after the cast.
///
/// ```
/// use posecov::{convert::so3_to_glam, lie::So3};
/// let q = so3_to_glam(&So3::from_rpy(0.0, 0.0, std::f64::consts::FRAC_PI_2));
/// assert!((q * glam::Vec3::X - glam::Vec3::Y).length() < 1e-6);
/// ```
pub fn so3_to_glam(r: &So3) -> Quat {
    let [x, y, z, w] = r.to_quaternion_xyzw();
    Quat::from_xyzw(x as f32, y as f32, z as f32, w as f32).normalize()
}

/// A pose as glam (translation, rotation), f32.
///
/// ```
/// use posecov::{convert::se3_to_glam, lie::Se3};
/// let (t, _q) = se3_to_glam(&Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0; 3]));
/// assert_eq!(t, glam::Vec3::new(1.0, 2.0, 3.0));
/// ```
pub fn se3_to_glam(x: &Se3) -> (Vec3, Quat) {
    (vec3_to_glam(x.translation()), so3_to_glam(x.rotation()))
}

/// A pose as a glam `Affine3A` (f32), p ↦ R p + t.
///
/// ```
/// use posecov::{convert::se3_to_glam_affine, lie::{LieGroup, Se3}};
/// use nalgebra::Vector3;
/// let x = Se3::from_xyz_rpy([1.0, 0.0, 0.0], [0.0, 0.0, 0.5]);
/// let p = se3_to_glam_affine(&x).transform_point3(glam::Vec3::Y);
/// let expect = x.act(&Vector3::y());
/// assert!((p - glam::Vec3::new(expect.x as f32, expect.y as f32, expect.z as f32)).length() < 1e-6);
/// ```
pub fn se3_to_glam_affine(x: &Se3) -> Affine3A {
    let (t, q) = se3_to_glam(x);
    Affine3A::from_rotation_translation(q, t)
}

/// A planar pose lifted to 3D (z = 0, rotation about z), as glam (translation, rotation).
///
/// ```
/// use posecov::{convert::se2_to_glam, lie::Se2};
/// let (t, q) = se2_to_glam(&Se2::from_xy_theta(1.0, 2.0, 0.0));
/// assert_eq!(t, glam::Vec3::new(1.0, 2.0, 0.0));
/// assert_eq!(q, glam::Quat::IDENTITY);
/// ```
pub fn se2_to_glam(x: &Se2) -> (Vec3, Quat) {
    let t = x.translation();
    (
        Vec3::new(t.x as f32, t.y as f32, 0.0),
        Quat::from_rotation_z(x.theta() as f32),
    )
}

/// Lifts a planar pose to SE(3): (x, y, 0) and a rotation θ about z
/// ([`LieGroup::to_se3`] of [`Se2`]).
///
/// ```
/// use posecov::{convert::se2_to_se3, lie::Se2};
/// let x3 = se2_to_se3(&Se2::from_xy_theta(1.0, 2.0, 0.5));
/// assert!((x3.rotation().to_rpy()[2] - 0.5).abs() < 1e-15);
/// ```
pub fn se2_to_se3(x: &Se2) -> Se3 {
    x.to_se3()
}
