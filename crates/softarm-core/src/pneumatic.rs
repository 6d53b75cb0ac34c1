//! One pneumatic section: three actuator elongations → arc (redundancy paper eq. 1).
//!
//! Actuator j (j = 1, 2, 3) sits at angle (j − 1)·120° about the section's z axis, at
//! radius r, actuator 1 on +x. Eq. (1) gives
//!
//! ```text
//! s  = sqrt(l1² + l2² + l3² − l1 l2 − l2 l3 − l1 l3)
//! Θ  = 2 s / (3 r)                           (bending angle, the paper's φ_i)
//! θ  = atan2(√3 (l3 − l2), l2 + l3 − 2 l1)   (bending direction, the paper's θ_i)
//! L  = L0 + (l1 + l2 + l3) / 3               (arc length = λ_i Θ)
//! ```
//!
//! The paper writes `arctan`; the four-quadrant `atan2` is the reading under which the
//! section bends away from its longest actuator. Since
//! `(l2 + l3 − 2 l1)² + 3 (l3 − l2)² = 4 s²`, the bending vector is *linear* in the
//! elongations:
//!
//! ```text
//! ux = Θ cos θ = (l2 + l3 − 2 l1) / (3 r),    uy = Θ sin θ = √3 (l3 − l2) / (3 r)
//! ```
//!
//! so the map to the smooth arc parameters has a constant Jacobian, exact at and near
//! `l1 = l2 = l3`. (Θ and θ themselves are polar coordinates and are not differentiable
//! at the straight configuration; nothing here differentiates them.)

use crate::arc::ArcParams;
use crate::math::Mat3;

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Arc length, bending angle and bending direction of eq. (1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarConfig {
    /// Arc length L (m).
    pub length: f64,
    /// Bending angle Θ (rad), ≥ 0.
    pub bend: f64,
    /// Bending direction θ in (−π, π] (rad); 0 when straight, where it is undefined.
    pub direction: f64,
}

/// Arc parameters of a section of actuator radius `radius` and rest length `rest_length`
/// at elongations `l` (eq. 1, smooth form).
#[inline]
pub fn arc_params(radius: f64, rest_length: f64, l: &[f64]) -> ArcParams {
    let (l1, l2, l3) = (l[0], l[1], l[2]);
    ArcParams {
        length: rest_length + (l1 + l2 + l3) / 3.0,
        ux: (l2 + l3 - 2.0 * l1) / (3.0 * radius),
        uy: SQRT3 * (l3 - l2) / (3.0 * radius),
    }
}

/// ∂(L, ux, uy)/∂(l1, l2, l3): constant for a given radius.
pub fn arc_params_jacobian(radius: f64) -> Mat3 {
    let k = 1.0 / (3.0 * radius);
    Mat3::new(
        1.0 / 3.0,
        1.0 / 3.0,
        1.0 / 3.0,
        -2.0 * k,
        k,
        k,
        0.0,
        -SQRT3 * k,
        SQRT3 * k,
    )
}

/// Eq. (1) as the paper writes it: (L, Θ, θ).
pub fn polar_config(radius: f64, rest_length: f64, l: &[f64]) -> PolarConfig {
    let (l1, l2, l3) = (l[0], l[1], l[2]);
    // The quadratic form can round to a tiny negative number when l1 ≈ l2 ≈ l3.
    let s = (l1 * l1 + l2 * l2 + l3 * l3 - l1 * l2 - l2 * l3 - l1 * l3)
        .max(0.0)
        .sqrt();
    let direction = if s == 0.0 {
        0.0
    } else {
        (SQRT3 * (l3 - l2)).atan2(l2 + l3 - 2.0 * l1)
    };
    PolarConfig {
        length: rest_length + (l1 + l2 + l3) / 3.0,
        bend: 2.0 * s / (3.0 * radius),
        direction,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn smooth_and_polar_forms_agree() {
        let l = [0.010, 0.003, 0.021];
        let a = arc_params(0.02, 0.15, &l);
        let p = polar_config(0.02, 0.15, &l);
        assert_relative_eq!(a.bend(), p.bend, epsilon = 1e-14);
        assert_relative_eq!(a.direction(), p.direction, epsilon = 1e-14);
        assert_relative_eq!(a.length, p.length, epsilon = 1e-15);
    }

    #[test]
    fn jacobian_is_exact() {
        let r = 0.022;
        let jac = arc_params_jacobian(r);
        let l = [0.004, 0.004, 0.004];
        let h = 1e-7;
        for k in 0..3 {
            let (mut lp, mut lm) = (l, l);
            lp[k] += h;
            lm[k] -= h;
            let (p, m) = (arc_params(r, 0.15, &lp), arc_params(r, 0.15, &lm));
            assert_relative_eq!(
                jac[(0, k)],
                (p.length - m.length) / (2.0 * h),
                epsilon = 1e-8
            );
            assert_relative_eq!(jac[(1, k)], (p.ux - m.ux) / (2.0 * h), epsilon = 1e-6);
            assert_relative_eq!(jac[(2, k)], (p.uy - m.uy) / (2.0 * h), epsilon = 1e-6);
        }
    }
}
