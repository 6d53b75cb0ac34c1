//! Closest point of one constant-curvature arc to a point: closed form.
//!
//! In its base frame an arc of length `L` and bending vector `u = Θ (cos φ, sin φ)` is a
//! circle arc of radius `L / Θ` in the plane spanned by `z` and the bending direction
//! `d = (cos φ, sin φ, 0)`, centred at `(L / Θ) d`, swept from angle 0 to `Θ`
//! (planning paper eq. 5 / 11). The squared distance from `x` to the point at angle `θ`
//! is `|x − c|² + r² − 2 r ρ cos(θ − α)`, with `(ρ, α)` the polar coordinates of the
//! projection of `x − c` onto the arc's plane, so the closest point is at `θ = α` when
//! `α ∈ [0, Θ]` and otherwise at the nearer end. That is eq. (13) solved exactly.
//!
//! For a nearly straight arc `r → ∞`; the angle is computed as
//! `α / Θ = atan2(Θ x_z, L − Θ x_d) / Θ`, evaluated through `atan(y)/y` so that `Θ = 0`
//! (a straight segment) is an ordinary case with no division by zero.

use crate::arc::ArcParams;
use crate::math::{Frame, Vec3};

/// An arc prepared for repeated closest-point queries in its own base frame.
#[derive(Debug, Clone, Copy)]
pub struct LocalArc {
    /// The arc.
    pub params: ArcParams,
    /// Bending angle Θ = |u|.
    theta: f64,
    /// Unit bending direction (x, y); (1, 0) for a straight arc.
    dir: (f64, f64),
    /// Tip position in the base frame.
    tip: Vec3,
}

/// `atan(y) / y`, exact at 0.
#[inline]
fn atanc(y: f64) -> f64 {
    if y.abs() < 1e-4 {
        let y2 = y * y;
        1.0 - y2 / 3.0 + y2 * y2 / 5.0
    } else {
        y.atan() / y
    }
}

impl LocalArc {
    /// Prepares `params` for queries.
    #[inline]
    pub fn new(params: ArcParams) -> Self {
        let theta = params.bend();
        let dir = if theta > 0.0 {
            (params.ux / theta, params.uy / theta)
        } else {
            (1.0, 0.0)
        };
        LocalArc {
            params,
            theta,
            dir,
            tip: params.point(1.0),
        }
    }

    /// Sagitta of one of `chords` equal chords: the largest distance of the arc from its
    /// chord polyline, `r (1 − cos(Θ / 2k))`, computed without cancellation as
    /// `2 r sin²(Θ / 4k)`.
    pub fn chord_error(&self, chords: usize) -> f64 {
        if self.theta == 0.0 {
            return 0.0;
        }
        let half = self.theta / (4.0 * chords.max(1) as f64);
        2.0 * (self.params.length / self.theta) * half.sin().powi(2)
    }

    /// Tip position (fraction 1) in the base frame.
    #[inline]
    pub fn tip(&self) -> Vec3 {
        self.tip
    }

    /// Fraction of the point of the arc's *full circle* (or, for a straight arc, its full
    /// line) closest to `x`, unclamped: the solution of eq. (13) with `s` free. Values in
    /// [0, 1] are on the arc. `p(s)` of [`ArcParams::point`] continues the arc for any `s`.
    #[inline]
    pub fn circle_fraction(&self, x: &Vec3) -> f64 {
        self.circle_fraction_and_ratio(x).0
    }

    /// [`LocalArc::circle_fraction`] and `ρ / r`: the distance of `x` from the circle's axis
    /// over the radius (1 for a straight arc). The closest circle point moves at most
    /// `r / ρ` times as fast as `x`.
    #[inline]
    pub fn circle_fraction_and_ratio(&self, x: &Vec3) -> (f64, f64) {
        let (s, ratio, _, _) = self.circle_foot(x);
        (s, ratio)
    }

    /// [`LocalArc::circle_fraction_and_ratio`], the unit tangent of the circle at the foot
    /// (z for a straight arc, or for a point on the axis) and the foot itself, computed
    /// without trigonometry: `r sin α = L x_z / h`, `r (1 − cos α) = L Θ x_z² / (h (h + a))`
    /// (no cancellation as Θ → 0), with `(a, b) = Θ (r − x_d, x_z)`, `h = |(a, b)|`.
    #[inline]
    pub fn circle_foot(&self, x: &Vec3) -> (f64, f64, Vec3, Vec3) {
        let l = self.params.length;
        let xd = x.x * self.dir.0 + x.y * self.dir.1;
        let a = l - self.theta * xd; // Θ · (r − x_d)
        let b = self.theta * x.z; // Θ · x_z
        let s = if a > 0.0 && b.abs() <= a {
            // |α| ≤ π/4: α / Θ = (x_z / a) · atan(b/a) / (b/a), finite at Θ = 0.
            x.z / a * atanc(b / a)
        } else {
            // Here Θ > 0 (Θ = 0 gives a = L > 0, b = 0).
            b.atan2(a) / self.theta
        };
        let h = (a * a + b * b).sqrt();
        let ratio = h / l;
        let (tangent, foot) = if h > 0.0 {
            let (sa, ca) = (b / h, a / h);
            let along = l * x.z / h;
            let across = if a > 0.0 {
                l * self.theta * x.z * x.z / (h * (h + a))
            } else {
                (l / self.theta) * (1.0 - ca)
            };
            (
                Vec3::new(sa * self.dir.0, sa * self.dir.1, ca),
                Vec3::new(across * self.dir.0, across * self.dir.1, along),
            )
        } else {
            (Vec3::z(), self.params.point(s))
        };
        if s < 0.0 && self.theta > 0.0 && s * self.theta + std::f64::consts::TAU <= self.theta {
            // Arcs bent beyond 2π − |α| (only for Θ > π): the same angle one turn later.
            (s + std::f64::consts::TAU / self.theta, ratio, tangent, foot)
        } else {
            (s, ratio, tangent, foot)
        }
    }

    /// Bending angle Θ.
    #[inline]
    pub fn theta(&self) -> f64 {
        self.theta
    }

    /// Fraction `s ∈ [0, 1]` and position of the point of the arc closest to `x` (all in the
    /// arc's base frame), and the squared distance.
    #[inline]
    pub fn closest(&self, x: &Vec3) -> (f64, Vec3, f64) {
        let s = self.circle_fraction(x);
        let d0 = x.norm_squared();
        let d1 = (x - self.tip).norm_squared();
        if (0.0..=1.0).contains(&s) {
            let p = self.params.point(s);
            let d2 = (x - p).norm_squared();
            // The formula is exact; still never return worse than an end point.
            if d2 <= d0 && d2 <= d1 {
                return (s, p, d2);
            }
        }
        if d0 <= d1 {
            (0.0, Vec3::zeros(), d0)
        } else {
            (1.0, self.tip, d1)
        }
    }
}

/// An arc placed in the base frame of the arm: the frame of its base and its parameters.
#[derive(Debug, Clone, Copy)]
pub struct PlacedArc {
    /// Base frame of the section in the arm's base frame.
    pub frame: Frame,
    /// The arc in that frame.
    pub arc: LocalArc,
}

impl PlacedArc {
    /// An arc at `frame`.
    pub fn new(frame: Frame, params: ArcParams) -> Self {
        PlacedArc {
            frame,
            arc: LocalArc::new(params),
        }
    }

    /// World point → arc frame.
    #[inline]
    pub fn to_local(&self, x: &Vec3) -> Vec3 {
        self.frame.rot.tr_mul(&(x - self.frame.pos))
    }

    /// World direction → arc frame.
    #[inline]
    pub fn dir_to_local(&self, v: &Vec3) -> Vec3 {
        self.frame.rot.tr_mul(v)
    }

    /// Arc frame point → world.
    #[inline]
    pub fn to_world(&self, p: &Vec3) -> Vec3 {
        self.frame.pos + self.frame.rot * p
    }

    /// Point at fraction `s`, in the world.
    #[inline]
    pub fn point(&self, s: f64) -> Vec3 {
        self.to_world(&self.arc.params.point(s))
    }

    /// Closest point to a world point `x`: `(s, world point, distance)`.
    #[inline]
    pub fn closest_to_point(&self, x: &Vec3) -> (f64, Vec3, f64) {
        let (s, p, d2) = self.arc.closest(&self.to_local(x));
        (s, self.to_world(&p), d2.sqrt())
    }
}
