//! Pseudo-inverses that stay sane where a Jacobian loses rank.
//!
//! Damped least squares with *adaptive* damping (Chiaverini 1997): with σ_min the
//! smallest singular value of the (active rows of the) task Jacobian J and threshold ε,
//!
//! ```text
//! λ² = 0                          if σ_min ≥ ε
//! λ² = λ_max² (1 − (σ_min/ε)²)    otherwise
//! J⁺ = Jᵀ (J Jᵀ + λ² I)⁻¹
//! ```
//!
//! Away from singularities J⁺ is the exact Moore–Penrose inverse (so the null-space
//! projectors of eq. (9)–(20) are exact); near one it is continuous in J (λ grows
//! continuously from 0), finite, and never NaN, also when a row of J vanishes as the
//! rotation about z does at the straight configuration.
//!
//! [`normal_inverse3`] is the no-allocation path for tasks of three rows (the hybrid
//! step): it inverts the 3×3 normal matrix in closed form. [`pinv_general`] is the exact
//! SVD path for any shape (the 6-row conventional controller, and tests).

use nalgebra::DMatrix;

use crate::math::Mat3;

/// Smallest eigenvalue of a symmetric 3×3 matrix, in closed form (Smith 1961).
pub fn min_eigenvalue_sym3(a: &Mat3) -> f64 {
    let p1 = a[(0, 1)].powi(2) + a[(0, 2)].powi(2) + a[(1, 2)].powi(2);
    if p1 == 0.0 {
        return a[(0, 0)].min(a[(1, 1)]).min(a[(2, 2)]);
    }
    let q = a.trace() / 3.0;
    let p2 = (a[(0, 0)] - q).powi(2) + (a[(1, 1)] - q).powi(2) + (a[(2, 2)] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let b = (a - Mat3::identity() * q) / p;
    let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos()
}

/// λ² of the adaptive damping for smallest squared singular value `sigma2_min`.
#[inline]
pub fn damping_squared(sigma2_min: f64, threshold: f64, damping: f64) -> f64 {
    let t2 = threshold * threshold;
    if sigma2_min >= t2 || t2 == 0.0 {
        0.0
    } else {
        damping * damping * (1.0 - sigma2_min.max(0.0) / t2)
    }
}

/// For a 3-row Jacobian J whose normal matrix is `gram = J Jᵀ`, returns
/// `P = (J Jᵀ + λ² I)⁻¹` restricted to the `active` rows (inactive rows and columns
/// of P are zero), so that `J⁺ = Jᵀ P`. Rows that are inactive must be zero in J (or
/// are ignored). Never NaN: a normal matrix that is still singular after damping (only
/// possible with `damping = 0`) yields P = 0.
pub fn normal_inverse3(gram: &Mat3, active: [bool; 3], threshold: f64, damping: f64) -> Mat3 {
    let mut g = *gram;
    let big = g.trace().abs() + 1.0;
    for i in 0..3 {
        if !active[i] {
            for k in 0..3 {
                g[(i, k)] = 0.0;
                g[(k, i)] = 0.0;
            }
            g[(i, i)] = big;
        }
    }
    // For a positive definite 3×3 matrix λ_min ≥ det / (λ₂λ₃) ≥ 4·det / trace²: when that
    // bound already clears the threshold the damping is zero and the eigenvalue is not
    // needed (the common, well-conditioned case).
    let tr = g.trace();
    let bound = 4.0 * g.determinant() / (tr * tr);
    let lambda2 = if tr > 0.0 && bound >= threshold * threshold {
        0.0
    } else {
        damping_squared(min_eigenvalue_sym3(&g), threshold, damping)
    };
    for i in 0..3 {
        if active[i] {
            g[(i, i)] += lambda2;
        }
    }
    let mut p = match g.try_inverse() {
        Some(p) if p.iter().all(|v| v.is_finite()) => p,
        _ => Mat3::zeros(),
    };
    for i in 0..3 {
        if !active[i] {
            for k in 0..3 {
                p[(i, k)] = 0.0;
                p[(k, i)] = 0.0;
            }
        }
    }
    p
}

/// Damped pseudo-inverse of any matrix through its SVD, with the same adaptive damping
/// as [`normal_inverse3`] (σ_min is the smallest of the min(rows, cols) singular
/// values): each σ is inverted as σ / (σ² + λ²), and singular values below the
/// numerical rank tolerance `max(rows, cols)·ε·σ_max` count as zero.
pub fn pinv_general(j: &DMatrix<f64>, threshold: f64, damping: f64) -> DMatrix<f64> {
    let (r, c) = j.shape();
    if r == 0 || c == 0 || j.iter().any(|v| !v.is_finite()) {
        return DMatrix::zeros(c, r);
    }
    let svd = j.clone().svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
        return DMatrix::zeros(c, r);
    };
    let s = &svd.singular_values;
    let smin = s.iter().cloned().fold(f64::INFINITY, f64::min);
    let lambda2 = damping_squared(smin * smin, threshold, damping);
    // Singular values below the numerical rank tolerance are zero.
    let smax = s.iter().cloned().fold(0.0, f64::max);
    let rank_tol = (r.max(c) as f64) * f64::EPSILON * smax;
    let mut inv_s = s.clone();
    for x in inv_s.iter_mut() {
        let den = *x * *x + lambda2;
        *x = if *x > rank_tol && den > 0.0 {
            *x / den
        } else {
            0.0
        };
    }
    v_t.transpose() * DMatrix::from_diagonal(&inv_s) * u.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn closed_form_eigenvalue_matches_nalgebra() {
        let m =
            nalgebra::Matrix3x4::new(1.0, 2.0, 0.5, -1.0, 0.3, -0.7, 2.0, 0.1, 0.0, 1.0, 1.0, 3.0);
        let g = m * m.transpose();
        let e = g.symmetric_eigenvalues();
        assert_relative_eq!(min_eigenvalue_sym3(&g), e.min(), epsilon = 1e-12);
        let d = Mat3::from_diagonal(&nalgebra::Vector3::new(3.0, 0.5, 2.0));
        assert_eq!(min_eigenvalue_sym3(&d), 0.5);
    }

    #[test]
    fn fast_and_svd_paths_agree_also_when_damped() {
        for scale in [1.0, 1e-3] {
            let j = nalgebra::Matrix3x4::new(
                1.0,
                2.0,
                0.5,
                -1.0,
                0.3,
                -0.7,
                2.0,
                0.1,
                0.0,
                1.0,
                1.0,
                3.0 * scale,
            );
            let j = j.fixed_rows::<3>(0) * 1.0;
            let p = normal_inverse3(&(j * j.transpose()), [true; 3], 0.5, 0.1);
            let fast = j.transpose() * p;
            let jd = DMatrix::from_column_slice(3, 4, j.as_slice());
            let slow = pinv_general(&jd, 0.5, 0.1);
            for (a, b) in fast.iter().zip(slow.iter()) {
                assert_relative_eq!(*a, *b, epsilon = 1e-10);
            }
        }
    }

    #[test]
    fn zero_matrix_gives_zero_not_nan() {
        let p = normal_inverse3(&Mat3::zeros(), [true; 3], 0.1, 0.0);
        assert_eq!(p, Mat3::zeros());
        let p = normal_inverse3(&Mat3::zeros(), [true; 3], 0.1, 0.05);
        assert!(p.iter().all(|v| v.is_finite()));
        let z = pinv_general(&DMatrix::zeros(6, 9), 0.1, 0.0);
        assert!(z.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn inactive_rows_are_ignored() {
        let g = Mat3::new(2.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.3, 0.0, 1.0);
        let p = normal_inverse3(&g, [true, false, true], 0.01, 0.0);
        let sub = nalgebra::Matrix2::new(2.0, 0.3, 0.3, 1.0)
            .try_inverse()
            .unwrap();
        assert_relative_eq!(p[(0, 0)], sub[(0, 0)], epsilon = 1e-14);
        assert_relative_eq!(p[(2, 0)], sub[(1, 0)], epsilon = 1e-14);
        assert_eq!(p[(1, 1)], 0.0);
    }
}
