//! Pose validation and the orientation error of docs/architecture.md (conventions): the
//! rotation vector of `R_target · R_currentᵀ`, in the base frame (the `e_ζ` of eq. 8), with an axis mask.

use nalgebra::{Quaternion, Rotation3, UnitQuaternion};

use crate::error::{Error, Result};
use crate::math::{Mat3, Mat4, Vec3};

/// Largest deviation of `RᵀR` from the identity accepted in a pose.
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-6;

/// Checks a 4×4 homogeneous pose: finite, last row `[0, 0, 0, 1]`, rotation block
/// orthonormal (to [`ORTHONORMAL_TOLERANCE`]) with determinant +1.
///
/// # Errors
/// [`Error::Pose`] naming `arg` and what is wrong.
pub fn check_pose(arg: &str, pose: &Mat4) -> Result<()> {
    let bad = |reason: String| {
        Err(Error::Pose {
            arg: arg.to_owned(),
            reason,
        })
    };
    if let Some(i) = pose.iter().position(|v| !v.is_finite()) {
        // Column-major storage: element (i % 4, i / 4).
        return bad(format!(
            "non-finite value {} at ({}, {})",
            pose[i],
            i % 4,
            i / 4
        ));
    }
    let last = pose.fixed_view::<1, 4>(3, 0);
    if (last[0].abs() + last[1].abs() + last[2].abs() + (last[3] - 1.0).abs()) > 1e-9 {
        return bad(format!(
            "last row must be [0, 0, 0, 1], got [{}, {}, {}, {}]",
            last[0], last[1], last[2], last[3]
        ));
    }
    let r: Mat3 = pose.fixed_view::<3, 3>(0, 0).into_owned();
    let dev = (r.transpose() * r - Mat3::identity()).amax();
    if dev > ORTHONORMAL_TOLERANCE {
        return bad(format!(
            "rotation block is not orthonormal (max |RᵀR − I| = {dev:.3e})"
        ));
    }
    if r.determinant() < 0.0 {
        return bad("rotation block has determinant −1 (a reflection)".to_owned());
    }
    Ok(())
}

/// The rotation vector (axis · angle, angle in [0, π]) of a rotation matrix, computed
/// through a unit quaternion with `2·atan2(|v|, |w|)`: accurate for tiny angles and
/// finite at π.
pub fn log_so3(r: &Mat3) -> Vec3 {
    let q: UnitQuaternion<f64> =
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    let q: &Quaternion<f64> = q.as_ref();
    let (w, v) = (q.w, q.imag());
    let n = v.norm();
    let sign = if w < 0.0 { -1.0 } else { 1.0 };
    if n < 1e-300 {
        return Vec3::zeros();
    }
    v * (sign * 2.0 * n.atan2(w.abs()) / n)
}

/// Orientation error `e_ζ = log(R_target · R_currentᵀ)` (base frame), with the
/// components whose `mask` entry is false set to zero.
#[inline]
pub fn orientation_error(r_target: &Mat3, r_current: &Mat3, mask: [bool; 3]) -> Vec3 {
    let mut e = log_so3(&(r_target * r_current.transpose()));
    for i in 0..3 {
        if !mask[i] {
            e[i] = 0.0;
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn rot(axis: Vec3, angle: f64) -> Mat3 {
        *Rotation3::from_scaled_axis(axis.normalize() * angle).matrix()
    }

    #[test]
    fn log_inverts_exp_over_the_whole_range() {
        let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
        for &a in &[0.0, 1e-9, 1e-4, 0.5, 2.0, 3.1, std::f64::consts::PI - 1e-9] {
            let r = rot(axis, a);
            assert_relative_eq!(log_so3(&r), axis * a, epsilon = 1e-9);
        }
        let at_pi = log_so3(&rot(axis, std::f64::consts::PI));
        assert_relative_eq!(at_pi.norm(), std::f64::consts::PI, epsilon = 1e-12);
    }

    #[test]
    fn error_is_in_the_base_frame_and_masked() {
        let rc = rot(Vec3::new(1.0, 2.0, 0.0), 0.7);
        let d = Vec3::new(0.01, -0.02, 0.03);
        let rt = rot(d, d.norm()) * rc;
        assert_relative_eq!(orientation_error(&rt, &rc, [true; 3]), d, epsilon = 1e-12);
        let m = orientation_error(&rt, &rc, [true, false, true]);
        assert_eq!(m.y, 0.0);
        assert_relative_eq!(m.x, d.x, epsilon = 1e-12);
    }

    #[test]
    fn malformed_poses_are_rejected() {
        let mut p = Mat4::identity();
        assert!(check_pose("target", &p).is_ok());
        p[(0, 1)] = 0.1;
        assert!(matches!(check_pose("target", &p), Err(Error::Pose { .. })));
        let mut p = Mat4::identity();
        p[(3, 0)] = 1.0;
        assert!(check_pose("target", &p).is_err());
        let mut p = Mat4::identity();
        p[(2, 2)] = -1.0;
        assert!(check_pose("target", &p).is_err());
        let mut p = Mat4::identity();
        p[(1, 3)] = f64::NAN;
        match check_pose("current", &p) {
            Err(Error::Pose { arg, reason }) => {
                assert_eq!(arg, "current");
                assert!(reason.contains("(1, 3)"), "{reason}");
            }
            other => panic!("{other:?}"),
        }
    }
}
