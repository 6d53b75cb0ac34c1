//! Type aliases, the rigid frame type, and the even "sinc-like" functions that make the
//! constant-curvature arc exact and smooth through zero bending.

use nalgebra::{Matrix3, Matrix4, Vector3};

/// 3-vector of f64.
pub type Vec3 = Vector3<f64>;
/// 3×3 matrix of f64.
pub type Mat3 = Matrix3<f64>;
/// 4×4 homogeneous matrix of f64.
pub type Mat4 = Matrix4<f64>;

/// A rigid transform kept as rotation + translation (cheaper to compose than a 4×4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Rotation block.
    pub rot: Mat3,
    /// Translation.
    pub pos: Vec3,
}

impl Frame {
    /// The identity transform.
    #[inline]
    pub fn identity() -> Self {
        Frame {
            rot: Mat3::identity(),
            pos: Vec3::zeros(),
        }
    }

    /// `self · other`.
    #[inline]
    pub fn compose(&self, other: &Frame) -> Frame {
        Frame {
            rot: self.rot * other.rot,
            pos: self.pos + self.rot * other.pos,
        }
    }

    /// The 4×4 homogeneous matrix.
    #[inline]
    pub fn to_matrix(&self) -> Mat4 {
        let mut m = Mat4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.pos);
        m
    }

    /// Translation along z by `dz` followed by rotation about z by `angle`
    /// (the two commute), the plate offset of eq. (3).
    #[inline]
    pub fn z_offset(dz: f64, angle: f64) -> Frame {
        Frame {
            rot: rot_z(angle),
            pos: Vec3::new(0.0, 0.0, dz),
        }
    }
}

/// Rotation about z by `angle`.
#[inline]
pub fn rot_z(angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// The skew-symmetric matrix `[v]×` with `[v]× w = v × w`.
#[inline]
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Below this value of `x = t²` (bends under 1.5 rad, every bend the blackberry arm
/// reaches inside its limits) the arc functions come from their Maclaurin series, which
/// needs no `sqrt`, `sin_cos` or division; above it the closed forms, which lose no digits
/// there. At `x = 2.25` the first omitted term is below 1e-18.
const SERIES_BELOW: f64 = 2.25;

/// Number of series coefficients kept (powers `x⁰ … x¹⁰`).
const TERMS: usize = 11;

/// `(−1)ᵏ / (2k + first)!` for k = 0 … 11: the series in `x = t²` of `sin t / t`
/// (first = 1), `(1 − cos t)/t²` (2) and `(t − sin t)/t³` (3), one term beyond
/// [`TERMS`] for the derivatives.
const fn series_long(first: u32) -> [f64; TERMS + 1] {
    let mut c = [0.0; TERMS + 1];
    let mut fact = 1.0;
    let mut m = 2;
    while m <= first {
        fact *= m as f64;
        m += 1;
    }
    let mut k = 0;
    while k <= TERMS {
        c[k] = if k % 2 == 0 { 1.0 / fact } else { -1.0 / fact };
        let n = (2 * k as u32 + first) as f64;
        fact *= (n + 1.0) * (n + 2.0);
        k += 1;
    }
    c
}

/// The first [`TERMS`] coefficients of [`series_long`].
const fn series(first: u32) -> [f64; TERMS] {
    let long = series_long(first);
    let mut c = [0.0; TERMS];
    let mut k = 0;
    while k < TERMS {
        c[k] = long[k];
        k += 1;
    }
    c
}

/// The series of the derivative with respect to `x`: term by term `(k + 1) c_{k+1}`.
const fn derivative(first: u32) -> [f64; TERMS] {
    let long = series_long(first);
    let mut c = [0.0; TERMS];
    let mut k = 0;
    while k < TERMS {
        c[k] = (k + 1) as f64 * long[k + 1];
        k += 1;
    }
    c
}

const F1: [f64; TERMS] = series(1);
const F2: [f64; TERMS] = series(2);
const F3: [f64; TERMS] = series(3);
const G1: [f64; TERMS] = derivative(1);
const G2: [f64; TERMS] = derivative(2);

/// Powers of `x` shared by every polynomial evaluated at it.
#[derive(Clone, Copy)]
struct Powers {
    x: f64,
    x2: f64,
    x4: f64,
    x8: f64,
}

impl Powers {
    #[inline(always)]
    fn of(x: f64) -> Self {
        let x2 = x * x;
        let x4 = x2 * x2;
        Powers {
            x,
            x2,
            x4,
            x8: x4 * x4,
        }
    }

    /// `Σ c[k] xᵏ` by Estrin's scheme: a tree four multiply-adds deep instead of
    /// Horner's chain of ten, so that the arc's pose does not wait on a long latency chain.
    #[inline(always)]
    fn poly(&self, c: &[f64; TERMS]) -> f64 {
        let Powers { x, x2, x4, x8 } = *self;
        let q0 = (c[0] + c[1] * x) + (c[2] + c[3] * x) * x2;
        let q1 = (c[4] + c[5] * x) + (c[6] + c[7] * x) * x2;
        let q2 = (c[8] + c[9] * x) + c[10] * x2;
        (q0 + q1 * x4) + q2 * x8
    }
}

/// Values of the even functions of `t` used by the arc, all as functions of `x = t²`:
/// `f1 = sin t / t`, `f2 = (1 − cos t)/t²`, `f3 = (t − sin t)/t³`,
/// and the derivatives `g1 = df1/dx`, `g2 = df2/dx`.
#[derive(Debug, Clone, Copy)]
pub struct ArcFunctions {
    /// sin t / t
    pub f1: f64,
    /// (1 − cos t) / t²
    pub f2: f64,
    /// (t − sin t) / t³
    pub f3: f64,
    /// d f1 / d(t²)
    pub g1: f64,
    /// d f2 / d(t²)
    pub g2: f64,
}

/// `(f1, f2)` alone at `x = t²`: all that a pose needs (see [`ArcFunctions`]).
#[inline]
pub fn f1_f2(x: f64) -> (f64, f64) {
    if x < SERIES_BELOW {
        let p = Powers::of(x);
        (p.poly(&F1), p.poly(&F2))
    } else {
        let t = x.sqrt();
        let (s, c) = t.sin_cos();
        (s / t, (1.0 - c) / x)
    }
}

impl ArcFunctions {
    /// Evaluates all functions at `x = t² ≥ 0`. Exact limits at `x = 0`, no NaN.
    /// Always inlined, as [`crate::arc::ArcParams::frame_with_derivatives`] is.
    #[inline(always)]
    pub fn at(x: f64) -> Self {
        if x < SERIES_BELOW {
            let p = Powers::of(x);
            ArcFunctions {
                f1: p.poly(&F1),
                f2: p.poly(&F2),
                f3: p.poly(&F3),
                g1: p.poly(&G1),
                g2: p.poly(&G2),
            }
        } else {
            let t = x.sqrt();
            let (s, c) = t.sin_cos();
            let f1 = s / t;
            let f2 = (1.0 - c) / x;
            let f3 = (t - s) / (x * t);
            // d/dx = (1 / 2t) d/dt
            let g1 = (t * c - s) / (2.0 * x * t);
            let g2 = (t * s - 2.0 * (1.0 - c)) / (2.0 * x * x);
            ArcFunctions { f1, f2, f3, g1, g2 }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn closed(x: f64) -> ArcFunctions {
        let t = x.sqrt();
        let (s, c) = t.sin_cos();
        ArcFunctions {
            f1: s / t,
            f2: (1.0 - c) / x,
            f3: (t - s) / (x * t),
            g1: (t * c - s) / (2.0 * x * t),
            g2: (t * s - 2.0 * (1.0 - c)) / (2.0 * x * x),
        }
    }

    #[test]
    fn series_matches_closed_form_at_the_switch() {
        for &x in &[0.2, 0.25, 2.0, 2.249_999, 2.25] {
            let a = ArcFunctions::at(x);
            let b = closed(x);
            assert_relative_eq!(a.f1, b.f1, max_relative = 1e-13);
            assert_relative_eq!(a.f2, b.f2, max_relative = 1e-13);
            assert_relative_eq!(a.f3, b.f3, max_relative = 1e-11);
            assert_relative_eq!(a.g1, b.g1, max_relative = 1e-11);
            assert_relative_eq!(a.g2, b.g2, max_relative = 1e-10);
        }
    }

    #[test]
    fn limits_at_zero_are_exact() {
        let a = ArcFunctions::at(0.0);
        assert_eq!(a.f1, 1.0);
        assert_eq!(a.f2, 0.5);
        assert_eq!(a.f3, 1.0 / 6.0);
        assert_eq!(a.g1, -1.0 / 6.0);
        assert_eq!(a.g2, -1.0 / 24.0);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for &x in &[0.01, 0.1, 0.3, 1.0, 2.5, 6.0] {
            let h = 1e-6;
            let (p, m) = (ArcFunctions::at(x + h), ArcFunctions::at(x - h));
            let a = ArcFunctions::at(x);
            assert_relative_eq!(a.g1, (p.f1 - m.f1) / (2.0 * h), epsilon = 1e-8);
            assert_relative_eq!(a.g2, (p.f2 - m.f2) / (2.0 * h), epsilon = 1e-8);
        }
    }
}
