//! One constant-curvature arc, parametrised by its length and its *bending vector*.
//!
//! The papers write an arc as (length `L`, bending angle `Θ`, bending direction `φ`)
//! (planning paper eq. 2–3, redundancy paper eq. 2). Polar coordinates (Θ, φ) are
//! singular at the straight arc, so the kinematics here use the Cartesian bending vector
//! `u = (ux, uy) = Θ (cos φ, sin φ)`. In `u` the arc is an analytic function everywhere:
//! the point at fraction `s` is
//!
//! ```text
//! p(s) = L s [ s f2(t²) ux,  s f2(t²) uy,  f1(t²) ]ᵀ,   t = s |u|,
//! R(s) = exp([ω]×),  ω = s (−uy, ux, 0)
//! ```
//!
//! which is eq. (3)/(5) of the planning paper rewritten with `f1 = sin t / t` and
//! `f2 = (1 − cos t)/t²` (see [`crate::math::ArcFunctions`]). The straight arc is then an
//! ordinary point: no perturbation, no special case, exact limits.

use crate::math::{f1_f2, ArcFunctions, Frame, Mat3, Vec3};

/// Arc parameters in the smooth parametrisation: length and bending vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcParams {
    /// Arc length `L` (m).
    pub length: f64,
    /// `Θ cos φ`: bending angle times the x component of the bending direction (rad).
    pub ux: f64,
    /// `Θ sin φ` (rad).
    pub uy: f64,
}

/// A point on an arc with its derivatives.
#[derive(Debug, Clone, Copy)]
pub struct ArcPoint {
    /// Position in the arc's base frame.
    pub pos: Vec3,
    /// Columns: ∂p/∂L, ∂p/∂ux, ∂p/∂uy.
    pub d_params: Mat3,
    /// ∂p/∂s (the tangent times L).
    pub d_s: Vec3,
}

impl ArcParams {
    /// From (length, bending angle Θ, bending direction φ).
    pub fn from_polar(length: f64, bend: f64, direction: f64) -> Self {
        let (s, c) = direction.sin_cos();
        ArcParams {
            length,
            ux: bend * c,
            uy: bend * s,
        }
    }

    /// Bending angle `Θ = |u|` of the whole arc.
    pub fn bend(&self) -> f64 {
        self.ux.hypot(self.uy)
    }

    /// Bending direction φ in (−π, π]; 0 for the straight arc (where it is undefined).
    pub fn direction(&self) -> f64 {
        self.uy.atan2(self.ux)
    }

    /// Curvature `Θ / L` (1/m).
    pub fn curvature(&self) -> f64 {
        self.bend() / self.length
    }

    /// Rotation vector of the frame at fraction `s` (the rotation axis is in the xy plane).
    #[inline]
    pub fn rotation_vector(&self, s: f64) -> Vec3 {
        Vec3::new(-self.uy * s, self.ux * s, 0.0)
    }

    /// Position of the point at fraction `s` (planning paper eq. 5, smooth form).
    #[inline]
    pub fn point(&self, s: f64) -> Vec3 {
        let (f1, f2) = f1_f2(s * s * (self.ux * self.ux + self.uy * self.uy));
        let ls = self.length * s;
        Vec3::new(ls * s * f2 * self.ux, ls * s * f2 * self.uy, ls * f1)
    }

    /// Position at fraction `s` with its derivatives with respect to (L, ux, uy) and s.
    pub fn point_with_derivatives(&self, s: f64) -> ArcPoint {
        let x = s * s * (self.ux * self.ux + self.uy * self.uy);
        self.point_with_derivatives_from(s, &ArcFunctions::at(x))
    }

    /// [`ArcParams::point_with_derivatives`] given the functions at `x = s² |u|²`.
    #[inline]
    fn point_with_derivatives_from(&self, s: f64, f: &ArcFunctions) -> ArcPoint {
        let (ux, uy, l) = (self.ux, self.uy, self.length);
        let u2 = ux * ux + uy * uy;
        let s2 = s * s;
        let pos = Vec3::new(l * s2 * f.f2 * ux, l * s2 * f.f2 * uy, l * s * f.f1);
        // ∂x/∂ux where x = s² u²  is 2 s² ux.
        let (dxu, dxv) = (2.0 * s2 * ux, 2.0 * s2 * uy);
        let ls2 = l * s2;
        let d_l = Vec3::new(s2 * f.f2 * ux, s2 * f.f2 * uy, s * f.f1);
        let d_ux = Vec3::new(
            ls2 * (f.f2 + ux * f.g2 * dxu),
            ls2 * uy * f.g2 * dxu,
            l * s * f.g1 * dxu,
        );
        let d_uy = Vec3::new(
            ls2 * ux * f.g2 * dxv,
            ls2 * (f.f2 + uy * f.g2 * dxv),
            l * s * f.g1 * dxv,
        );
        // ∂x/∂s = 2 s u²
        let dxs = 2.0 * s * u2;
        let d_s = Vec3::new(
            l * (2.0 * s * f.f2 + s2 * f.g2 * dxs) * ux,
            l * (2.0 * s * f.f2 + s2 * f.g2 * dxs) * uy,
            l * (f.f1 + s * f.g1 * dxs),
        );
        ArcPoint {
            pos,
            d_params: Mat3::from_columns(&[d_l, d_ux, d_uy]),
            d_s,
        }
    }

    /// Frame (rotation and position) at fraction `s`: Rodrigues' formula
    /// `R = I + f1 [ω]× + f2 [ω]×²` written out for ω = (wx, wy, 0), using
    /// `[ω]×² = ω ωᵀ − |ω|² I`.
    #[inline]
    pub fn frame(&self, s: f64) -> Frame {
        let (wx, wy) = (-self.uy * s, self.ux * s);
        let (f1, f2) = f1_f2(wx * wx + wy * wy);
        let ls = self.length * s;
        Frame {
            rot: rodrigues(wx, wy, f1, f2),
            pos: Vec3::new(ls * f2 * wy, -ls * f2 * wx, ls * f1),
        }
    }

    /// Frame at fraction `s`, plus the derivatives of the frame with respect to
    /// (L, ux, uy): column k of the first matrix is ∂p/∂param_k, and column k of the
    /// second the angular velocity `(∂R/∂param_k Rᵀ)^∨` (redundancy paper eq. 5),
    /// computed as `J_l(ω) ∂ω/∂param_k` with the left Jacobian of SO(3)
    /// `J_l = I + f2 [ω]× + f3 [ω]×²`.
    ///
    /// Always inlined: the kinematics' hot loop calls it once per section, and where the
    /// compiler kept it out of line (the criterion bench) its 33 values went through
    /// memory and `forward_jacobian_into` took 230 ns instead of 180.
    #[inline(always)]
    pub fn frame_with_derivatives(&self, s: f64) -> (Frame, Mat3, Mat3) {
        let (wx, wy) = (-self.uy * s, self.ux * s);
        let f = ArcFunctions::at(wx * wx + wy * wy);
        let pt = self.point_with_derivatives_from(s, &f);
        let rot = rodrigues(wx, wy, f.f1, f.f2);
        // Columns 0 and 1 of J_l (ω_z = 0).
        let jl0 = Vec3::new(1.0 - f.f3 * wy * wy, f.f3 * wx * wy, -f.f2 * wy);
        let jl1 = Vec3::new(f.f3 * wx * wy, 1.0 - f.f3 * wx * wx, f.f2 * wx);
        // ω = s (−uy, ux, 0): ∂ω/∂L = 0, ∂ω/∂ux = (0, s, 0), ∂ω/∂uy = (−s, 0, 0).
        let d_rot = Mat3::from_columns(&[Vec3::zeros(), jl1 * s, -jl0 * s]);
        (Frame { rot, pos: pt.pos }, pt.d_params, d_rot)
    }
}

/// `I + a [ω]× + b [ω]×²` for ω = (wx, wy, 0).
#[inline]
fn rodrigues(wx: f64, wy: f64, a: f64, b: f64) -> Mat3 {
    let bxy = b * wx * wy;
    Mat3::new(
        1.0 - b * wy * wy,
        bxy,
        a * wy,
        bxy,
        1.0 - b * wx * wx,
        -a * wx,
        -a * wy,
        a * wx,
        1.0 - b * (wx * wx + wy * wy),
    )
}
