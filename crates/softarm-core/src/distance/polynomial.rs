//! Parametric polynomial curves `F_o(u)` (planning paper eq. 10) and line segments.

use crate::error::{check_count, Error, Result, MAX_POSITION, MAX_SAMPLES};
use crate::math::Vec3;

/// Largest magnitude of a curve parameter `u`, and largest speed or acceleration bound
/// (`|F_o'|`, `|F_o''|` over a grid interval). With positions below
/// [`MAX_POSITION`] (1e100), every product the closest-point search forms (positions
/// times speeds, speeds squared, parameters times slopes) stays below 1e300.
pub const MAX_PARAMETER: f64 = 1e150;

/// Most sample intervals a curve is bracketed with.
pub(crate) const MAX_INTERVALS: usize = 64;

/// A polynomial space curve `F_o(u) = Σ_k c_k u^k`, `u ∈ [u_min, u_max]` (eq. 10).
///
/// The curve also stores the sampling grid used by the arc ↔ curve query and, for each
/// grid interval, an upper bound on the speed `|F_o'(u)|` there (a Lipschitz constant of
/// the distance to any fixed set), computed once from the Taylor expansion of `F_o'`.
#[derive(Debug, Clone, PartialEq)]
pub struct PolynomialCurve {
    coeffs: Vec<Vec3>,
    u_min: f64,
    u_max: f64,
    grid: Vec<f64>,
    speed: Vec<f64>,
    accel: Vec<f64>,
    /// Bounding sphere (centre, radius) of the curve over each grid interval.
    spheres: Vec<(Vec3, f64)>,
    /// Bounding sphere of the whole curve: centre and radius.
    sphere: (Vec3, f64),
    /// Axis-aligned box (lowest, highest corner) around the interval spheres.
    aabb: (Vec3, Vec3),
    /// The largest radius of the interval spheres (whether the search may need to split).
    longest: f64,
}

impl PolynomialCurve {
    /// A curve from its vector coefficients in ascending powers of `u`
    /// (`coeffs[k]` multiplies `u^k`), over `[u_range.0, u_range.1]`.
    ///
    /// # Errors
    /// [`Error::Shape`] for no coefficient, [`Error::NonFinite`] for a NaN or infinite
    /// coefficient or bound, [`Error::Parameter`] for an empty range (`u_min >= u_max`),
    /// a bound beyond [`MAX_PARAMETER`], or a curve whose evaluation over its range is not
    /// finite: one that leaves the ball of radius [`MAX_POSITION`] (1e100 m) or whose speed
    /// or acceleration bound exceeds [`MAX_PARAMETER`]. The search's certificates are
    /// products of these quantities; a curve beyond them would overflow to NaN and infinity.
    ///
    /// # Example
    /// ```
    /// use softarm_core::{distance::PolynomialCurve, Vec3};
    /// // Simulation 2 of the planning paper: X = 0.5, Y = u, Z = 5u², −2 < u < 2.
    /// let c = PolynomialCurve::new(
    ///     &[Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 5.0)],
    ///     (-2.0, 2.0),
    /// ).unwrap();
    /// assert_eq!(c.eval(1.0), Vec3::new(0.5, 1.0, 5.0));
    /// ```
    pub fn new(coeffs: &[Vec3], u_range: (f64, f64)) -> Result<Self> {
        if coeffs.is_empty() {
            return Err(Error::shape("coeffs", "at least one coefficient", "none"));
        }
        for (k, c) in coeffs.iter().enumerate() {
            for (i, v) in c.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::NonFinite {
                        arg: "coeffs".into(),
                        index: i * coeffs.len() + k,
                        value: *v,
                    });
                }
            }
        }
        let (u_min, u_max) = u_range;
        for (i, v) in [u_min, u_max].into_iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    arg: "u_range".into(),
                    index: i,
                    value: v,
                });
            }
        }
        if u_min >= u_max {
            return Err(Error::parameter(
                "u_range",
                u_min,
                format!("u_min must be smaller than u_max = {u_max}"),
            ));
        }
        for v in [u_min, u_max] {
            if v.abs() > MAX_PARAMETER {
                return Err(Error::parameter(
                    "u_range",
                    v,
                    format!("must lie in [-{MAX_PARAMETER:e}, {MAX_PARAMETER:e}]"),
                ));
            }
        }
        // Trailing zero coefficients do not raise the degree.
        let mut coeffs = coeffs.to_vec();
        while coeffs.len() > 1 && coeffs.last().is_some_and(|c| *c == Vec3::zeros()) {
            coeffs.pop();
        }
        let curve = Self::build(coeffs, u_min, u_max);
        check_evaluation(&curve.speed, &curve.accel, &curve.spheres, curve.sphere)?;
        Ok(curve)
    }

    /// The grid, bounds and spheres of `coeffs` (trailing zeros dropped) over
    /// `[u_min, u_max]`, unchecked.
    fn build(coeffs: Vec<Vec3>, u_min: f64, u_max: f64) -> Self {
        let degree = coeffs.len() - 1;
        let n = (8 + 4 * degree).min(MAX_INTERVALS);
        let grid: Vec<f64> = (0..=n)
            .map(|k| {
                if k == n {
                    u_max
                } else {
                    u_min + (u_max - u_min) * (k as f64) / (n as f64)
                }
            })
            .collect();
        let deriv: Vec<Vec3> = coeffs
            .iter()
            .enumerate()
            .skip(1)
            .map(|(k, c)| c * k as f64)
            .collect();
        let deriv2: Vec<Vec3> = deriv
            .iter()
            .enumerate()
            .skip(1)
            .map(|(k, c)| c * k as f64)
            .collect();
        let speed: Vec<f64> = grid
            .windows(2)
            .map(|w| speed_bound(&deriv, w[0], w[1]))
            .collect();
        let accel: Vec<f64> = grid
            .windows(2)
            .map(|w| speed_bound(&deriv2, w[0], w[1]))
            .collect();
        let spheres: Vec<(Vec3, f64)> = grid
            .windows(2)
            .map(|w| bounding_sphere(&coeffs, w[0], w[1]))
            .collect();
        let sphere = bounding_sphere(&coeffs, u_min, u_max);
        let longest = spheres.iter().map(|s| s.1).fold(0.0, f64::max);
        let inf = Vec3::repeat(f64::INFINITY);
        let aabb = spheres.iter().fold((inf, -inf), |(lo, hi), (c, r)| {
            let r = Vec3::repeat(*r);
            (lo.inf(&(c - r)), hi.sup(&(c + r)))
        });
        PolynomialCurve {
            coeffs,
            u_min,
            u_max,
            grid,
            speed,
            accel,
            spheres,
            sphere,
            aabb,
            longest,
        }
    }

    /// The same polynomial restricted to `[a, b]` (inside the range, `a < b`), with its own
    /// grid: the closest-point search splits long curves into such pieces. Its bounds are
    /// over a sub-interval of a checked curve, so they need no new check.
    pub(crate) fn piece(&self, a: f64, b: f64) -> Self {
        Self::build(self.coeffs.clone(), a, b)
    }

    /// A sphere (centre, radius) holding the curve over `[a, b]`.
    pub(crate) fn sphere_over(&self, a: f64, b: f64) -> (Vec3, f64) {
        bounding_sphere(&self.coeffs, a, b)
    }

    /// A curve from a (3, d + 1) row-major array: row 0 holds x(u)'s coefficients.
    ///
    /// # Errors
    /// [`Error::Shape`] unless `rows.len()` is a positive multiple of 3, then as
    /// [`PolynomialCurve::new`].
    pub fn from_rows(rows: &[f64], u_range: (f64, f64)) -> Result<Self> {
        if rows.is_empty() || rows.len() % 3 != 0 {
            return Err(Error::shape(
                "coeffs",
                "shape (3, d + 1)",
                format!("{} values", rows.len()),
            ));
        }
        let m = rows.len() / 3;
        if let Some(index) = rows.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                arg: "coeffs".into(),
                index,
                value: rows[index],
            });
        }
        let coeffs: Vec<Vec3> = (0..m)
            .map(|k| Vec3::new(rows[k], rows[m + k], rows[2 * m + k]))
            .collect();
        Self::new(&coeffs, u_range)
    }

    /// Coefficients, ascending powers.
    pub fn coeffs(&self) -> &[Vec3] {
        &self.coeffs
    }

    /// Degree (after dropping trailing zero coefficients).
    pub fn degree(&self) -> usize {
        self.coeffs.len() - 1
    }

    /// `(u_min, u_max)`.
    pub fn u_range(&self) -> (f64, f64) {
        (self.u_min, self.u_max)
    }

    /// Sampling grid of the closest-point query (both ends included).
    pub(crate) fn grid(&self) -> &[f64] {
        &self.grid
    }

    /// Upper bound of `|F_o'|` on each grid interval.
    pub(crate) fn speed_bounds(&self) -> &[f64] {
        &self.speed
    }

    /// A sphere (centre, radius) holding the whole curve.
    pub fn bounding_sphere(&self) -> (Vec3, f64) {
        self.sphere
    }

    /// An axis-aligned box (lowest, highest corner) holding the curve: the box around
    /// its interval spheres.
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        self.aabb
    }

    /// The largest radius of [`PolynomialCurve::interval_spheres`].
    pub(crate) fn longest_interval(&self) -> f64 {
        self.longest
    }

    /// A sphere (centre, radius) holding the curve over each grid interval.
    pub(crate) fn interval_spheres(&self) -> &[(Vec3, f64)] {
        &self.spheres
    }

    /// Upper bound of `|F_o''|` on each grid interval.
    pub(crate) fn accel_bounds(&self) -> &[f64] {
        &self.accel
    }

    /// `F_o(u)` (eq. 10), Horner's scheme.
    #[inline]
    pub fn eval(&self, u: f64) -> Vec3 {
        let mut p = Vec3::zeros();
        for c in self.coeffs.iter().rev() {
            p = p * u + c;
        }
        p
    }

    /// `F_o(u)` and `F_o'(u)` together.
    #[inline]
    pub fn eval_with_derivative(&self, u: f64) -> (Vec3, Vec3) {
        let mut p = Vec3::zeros();
        let mut dp = Vec3::zeros();
        for c in self.coeffs.iter().rev() {
            dp = dp * u + p;
            p = p * u + c;
        }
        (p, dp)
    }

    /// `n` points evenly spaced in `u` (both ends included): the point-set model of the
    /// curve that the paper compares against.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for `n` above [`MAX_SAMPLES`].
    pub fn sample(&self, n: usize) -> Result<Vec<Vec3>> {
        check_count("n", n, 0, MAX_SAMPLES)?;
        Ok(match n {
            0 => Vec::new(),
            1 => vec![self.eval(0.5 * (self.u_min + self.u_max))],
            _ => (0..n)
                .map(|k| {
                    let t = k as f64 / (n - 1) as f64;
                    self.eval(self.u_min + t * (self.u_max - self.u_min))
                })
                .collect(),
        })
    }
}

/// Rejects a curve whose bounds over its range are not finite or too large (see
/// [`PolynomialCurve::new`]): the whole curve must lie within [`MAX_POSITION`] of the
/// origin, as every other obstacle (see [`super::obstacle::check_points`]).
fn check_evaluation(
    speed: &[f64],
    accel: &[f64],
    spheres: &[(Vec3, f64)],
    sphere: (Vec3, f64),
) -> Result<()> {
    let reach = |(c, r): (Vec3, f64)| c.norm() + r;
    let far = std::iter::once(sphere)
        .chain(spheres.iter().copied())
        .map(reach)
        .find(|v| v.is_nan() || *v > MAX_POSITION);
    if let Some(v) = far {
        return Err(Error::parameter(
            "coeffs",
            v,
            format!(
                "the curve reaches this far (m) from the origin over u_range; it must stay \
                 within {MAX_POSITION:e} m"
            ),
        ));
    }
    if let Some(v) = speed
        .iter()
        .chain(accel)
        .copied()
        .find(|v| v.is_nan() || *v > MAX_PARAMETER)
    {
        return Err(Error::parameter(
            "coeffs",
            v,
            format!(
                "the curve's speed or acceleration bound over u_range exceeds \
                 {MAX_PARAMETER:e}; rescale u"
            ),
        ));
    }
    Ok(())
}

/// Taylor coefficients of `P(m + h t)` in `t`, for `P` in ascending vector coefficients.
fn taylor(p: &[Vec3], m: f64, h: f64) -> Vec<Vec3> {
    let mut e = p.to_vec();
    let n = e.len();
    for i in 0..n {
        for j in (i..n - 1).rev() {
            let next = e[j + 1];
            e[j] += next * m;
        }
    }
    let mut hj = 1.0;
    for c in e.iter_mut() {
        *c *= hj;
        hj *= h;
    }
    e
}

/// A bound of the rounding error of [`taylor`] summed over all its coefficients: the same
/// shift of the absolute values (no cancellation) at `|m|`, times `4 n ε` (each coefficient
/// is a sum of at most `n` products, each rounded). Relative to the sizes involved, so that
/// it holds for curves far from the origin and for any scale of `u` (an absolute guard of
/// ε would swamp the speed bound of a curve parametrised over 1e96).
fn taylor_rounding(p: &[Vec3], m: f64, h: f64) -> f64 {
    let abs: Vec<Vec3> = p.iter().map(|c| c.abs()).collect();
    let total: f64 = taylor(&abs, m.abs(), h.abs()).iter().map(|c| c.sum()).sum();
    4.0 * (p.len() as f64 + 1.0) * f64::EPSILON * total
}

/// A sphere holding `P([a, b])`: centre `P(m)`, radius `Σ_{j≥1} |e_j|` (plus the rounding
/// of the shift).
fn bounding_sphere(p: &[Vec3], a: f64, b: f64) -> (Vec3, f64) {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let e = taylor(p, m, h);
    let r: f64 = e.iter().skip(1).map(|c| c.norm()).sum();
    (e[0], r + taylor_rounding(p, m, h) + f64::MIN_POSITIVE)
}

/// An upper bound of `|P(u)|` for `u ∈ [a, b]`, `P` given by ascending vector
/// coefficients: Taylor-shift `P` to the midpoint `m` and sum `|e_j| h^j`, `h = (b − a)/2`.
fn speed_bound(p: &[Vec3], a: f64, b: f64) -> f64 {
    if p.is_empty() {
        return 0.0;
    }
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let bound: f64 = taylor(p, m, h).iter().map(|c| c.norm()).sum();
    // Guard against rounding in the shift.
    bound + taylor_rounding(p, m, h)
}

/// A line segment from `a` to `b`: the degree-1 curve `a + u (b − a)`, `u ∈ [0, 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    a: Vec3,
    b: Vec3,
    curve: PolynomialCurve,
}

impl Segment {
    /// The segment from `a` to `b` (a point when `a == b`).
    ///
    /// # Errors
    /// As [`super::obstacle::check_points`] for either end.
    pub fn new(a: Vec3, b: Vec3) -> Result<Self> {
        for (name, v) in [("a", a), ("b", b)] {
            super::obstacle::check_points(name, &[v])?;
        }
        let curve = PolynomialCurve::new(&[a, b - a], (0.0, 1.0))?;
        Ok(Segment { a, b, curve })
    }

    /// First end point.
    pub fn a(&self) -> Vec3 {
        self.a
    }

    /// Second end point.
    pub fn b(&self) -> Vec3 {
        self.b
    }

    /// The segment as a degree-1 polynomial curve over [0, 1].
    pub fn as_curve(&self) -> &PolynomialCurve {
        &self.curve
    }

    /// Closest point of the segment to `x`: `(u, point)`.
    pub fn closest_to_point(&self, x: &Vec3) -> (f64, Vec3) {
        let ab = self.b - self.a;
        let len2 = ab.norm_squared();
        let u = if len2 > 0.0 {
            ((x - self.a).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (u, self.a + ab * u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_bound_bounds_sampled_speed() {
        let c = PolynomialCurve::new(
            &[
                Vec3::new(1.0, -2.0, 0.5),
                Vec3::new(0.3, 1.0, -1.0),
                Vec3::new(-2.0, 0.5, 3.0),
                Vec3::new(0.7, -0.2, 1.5),
            ],
            (-1.5, 2.0),
        )
        .unwrap();
        for (w, &bound) in c.grid().windows(2).zip(c.speed_bounds()) {
            let mut max: f64 = 0.0;
            for k in 0..=200 {
                let u = w[0] + (w[1] - w[0]) * k as f64 / 200.0;
                max = max.max(c.eval_with_derivative(u).1.norm());
            }
            assert!(max <= bound, "{max} > {bound}");
            assert!(bound < 2.0 * max + 1.0);
        }
    }

    #[test]
    fn derivative_matches_finite_differences() {
        let c = PolynomialCurve::new(
            &[
                Vec3::new(1.0, 0.0, 2.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(3.0, -1.0, 0.5),
            ],
            (0.0, 1.0),
        )
        .unwrap();
        let h = 1e-6;
        let (_, d) = c.eval_with_derivative(0.3);
        let fd = (c.eval(0.3 + h) - c.eval(0.3 - h)) / (2.0 * h);
        assert!((d - fd).norm() < 1e-8);
    }
}
