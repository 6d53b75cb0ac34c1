//! Exact closest points between a constant-curvature arc and a polynomial curve
//! (planning paper eq. 12–18), global over both parameters.
//!
//! # Method
//! The arc is a piece of a circle (or of a line, when straight). For a point `x`, the
//! closest arc point is either the closest point of the full circle, when that lies on the
//! arc (eq. 13 solved in closed form, [`super::arc_point`]), or one of the arc's two ends.
//! So the distance from the curve to the arc is `d(u) = min(d_c(u), d_0(u), d_1(u))` over
//! the *valid* branches: `d_c` the distance of `F_o(u)` to the full circle (valid where its
//! foot lies on the arc), `d_0`, `d_1` its distances to the arc's ends. Each branch is a
//! smooth function of `u` (the circle branch has only concave kinks, on the circle's
//! axis), while `d` itself has concave kinks where the closest arc point jumps, and these
//! can hide a second minimum next to a first one. A global minimum `u*` of `d` is a local
//! minimum of the branch that realises it (a branch is never below `d` where it is valid,
//! and the circle branch is below `d` everywhere), so:
//!
//! - branch c gives the interior solutions of eq. (13)–(14) and, at `u_min`/`u_max`,
//!   eq. (15)/(16); branches 0 and 1 give the edge cases eq. (17)/(18) and, at `u_min`,
//!   `u_max`, the four endpoint pairs;
//! - every branch is sampled with its derivative `(d_b²)'/2 = (F_o − p_b)·F_o'` (envelope
//!   theorem) on a grid of `8 + 4·degree` intervals;
//! - every interval where a branch's derivative goes from negative to positive holds a
//!   local minimum of that branch, found by a bracketing root solver (Illinois regula
//!   falsi); minima of the circle branch count only when their foot lies on the arc;
//! - every other interval can hide a minimum of a branch only between two more turning
//!   points of that branch; it is discarded when the Lipschitz lower bound
//!   `(d_b(a) + d_b(b) − S (b − a)) / 2 ≥ best` holds (`S` bounds `|F_o'|` on the
//!   interval and a distance to a fixed set is 1-Lipschitz), or when the derivative
//!   `g_b = (F_o − p_b)·F_o'` provably keeps its sign there:
//!   `(|g_b(a)| + |g_b(b)| − M (b − a)) / 2 > 0` with equal signs, where
//!   `|g_b'| ≤ M = S² + S·|p_b'|_max + d_max·A` (`A` bounds `|F_o''|`, `p_b' = 0` for the
//!   ends and `|p_c'| ≤ S r / ρ` for the circle, `ρ` the distance from its axis);
//!   when the branch is provably convex there (`g_b' > 0`: `|F_o'|² > d_max A` for the
//!   ends, `|F_o'|² − (r/ρ)(F_o'·t)² > d_max A` for the circle, `t` its tangent at the
//!   foot), so its derivative cannot change sign without a − → + change at the samples;
//!   for the circle branch, also when its foot provably stays off the arc (it moves along
//!   the circle at most `S r / ρ` per unit of `u`); otherwise it is bisected and searched again (to depth 24, within a budget of 200
//!   evaluations per pair).
//!
//! Every distance reported is evaluated exactly at the final `(s, u)`. The only case this
//! does not certify is a single grid interval in which one smooth branch has a minimum
//! *and* two more turning points with a lower minimum, which needs the curve to turn on
//! the scale of one grid interval; the tests check the answer against dense
//! two-dimensional sampling with local refinement on thousands of random arcs and curves.

use super::arc_point::PlacedArc;
use super::polynomial::{PolynomialCurve, MAX_INTERVALS};
use crate::math::Vec3;

/// Closest pair between one arc and one curve.
#[derive(Debug, Clone, Copy)]
pub struct ArcCurveHit {
    /// Distance.
    pub distance: f64,
    /// Fraction along the arc.
    pub s: f64,
    /// Curve parameter.
    pub u: f64,
    /// Arc point (world).
    pub arc_point: Vec3,
    /// Curve point (world).
    pub curve_point: Vec3,
    /// Number of curve points evaluated (cost of the query).
    pub evaluations: u32,
}

/// Branches: 0 the full circle (eq. 13–14), 1 the end s = 0 (eq. 17), 2 the end s = 1
/// (eq. 18).
const BRANCHES: usize = 3;

#[derive(Debug, Clone, Copy, Default)]
struct Sample {
    u: f64,
    d: [f64; BRANCHES],
    /// Half derivative of d_b² in u: (F_o − p_b)·F_o'.
    g: [f64; BRANCHES],
    /// ρ / r of the curve point (distance from the circle's axis over the radius).
    ratio: f64,
    /// |F_o'(u)|.
    speed: f64,
    /// F_o'(u) · t, t the circle's unit tangent at the foot.
    along: f64,
    /// How far (in s, around the circle) the circle foot lies outside the arc's [0, 1].
    gap: f64,
}

/// Bounds of the curve on one grid interval.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    /// |F_o'| ≤ speed.
    speed: f64,
    /// |F_o''| ≤ accel.
    accel: f64,
    /// Θ / L: the Lipschitz constant of ρ / r in the point.
    inv_radius: f64,
    /// Arc length L.
    length: f64,
}

/// Most evaluations spent certifying one pair.
const BUDGET: u32 = 200;

impl Sample {
    /// A sign change from − to + (a zero at either end counts: the minimum is there).
    #[inline]
    fn falls_then_rises(a: &Sample, b: &Sample, k: usize) -> bool {
        (a.g[k] < 0.0 && b.g[k] >= 0.0) || (a.g[k] <= 0.0 && b.g[k] > 0.0)
    }
}

struct Query<'a> {
    arc: &'a PlacedArc,
    curve: &'a PolynomialCurve,
    best_d: f64,
    best_u: f64,
    best_s: f64,
    evals: u32,
}

impl Query<'_> {
    #[inline]
    fn eval(&mut self, u: f64) -> Sample {
        let (f, df) = self.curve.eval_with_derivative(u);
        let x = self.arc.to_local(&f);
        let dx = self.arc.dir_to_local(&df);
        let local = &self.arc.arc;
        self.evals += 1;
        let (sc, ratio, tangent, foot) = local.circle_foot(&x);
        let vs = [x - foot, x, x - local.tip()];
        let d = [vs[0].norm(), vs[1].norm(), vs[2].norm()];
        let g = [vs[0].dot(&dx), vs[1].dot(&dx), vs[2].dot(&dx)];
        // The true distance: the smallest valid branch.
        let (mut dd, mut ss) = if d[1] <= d[2] {
            (d[1], 0.0)
        } else {
            (d[2], 1.0)
        };
        if (0.0..=1.0).contains(&sc) && d[0] < dd {
            dd = d[0];
            ss = sc;
        }
        if dd < self.best_d {
            self.best_d = dd;
            self.best_u = u;
            self.best_s = ss;
        }
        let gap = if (0.0..=1.0).contains(&sc) {
            0.0
        } else {
            let theta = local.theta();
            let ahead = if sc > 1.0 { sc - 1.0 } else { -sc };
            if theta > 0.0 {
                // The other way round the circle (period 2π/Θ in s).
                let period = std::f64::consts::TAU / theta;
                let behind = if sc > 1.0 {
                    period - sc
                } else {
                    sc + period - 1.0
                };
                ahead.min(behind.max(0.0))
            } else {
                ahead
            }
        };
        Sample {
            u,
            d,
            g,
            ratio,
            speed: df.norm(),
            along: dx.dot(&tangent),
            gap,
        }
    }

    /// Illinois regula falsi for the root of branch `k`'s derivative on [a, b],
    /// g(a) < 0 < g(b).
    fn refine(&mut self, k: usize, mut a: Sample, mut b: Sample, speed: f64) {
        let (mut ga, mut gb) = (a.g[k], b.g[k]);
        if ga == 0.0 || gb == 0.0 {
            // The minimum is the end sample, already counted.
            return;
        }
        let mut side = 0i8;
        // The distance is stationary at the root, so an error δu in u costs ~κ δu² in the
        // distance: 1e-11 relative in u is far below 1e-9 m.
        let tol = 1e-11 * (1.0 + a.u.abs().max(b.u.abs()));
        let mut prev = f64::NAN;
        for _ in 0..80 {
            if b.u - a.u <= tol {
                break;
            }
            let mut u = (a.u * gb - b.u * ga) / (gb - ga);
            if !(u > a.u && u < b.u) {
                u = 0.5 * (a.u + b.u);
            }
            let c = self.eval(u);
            let gc = c.g[k];
            if gc == 0.0 || c.d[k] == 0.0 || (u - prev).abs() <= tol {
                break;
            }
            prev = u;
            // Stop as soon as the shrinking bracket cannot beat the best any more.
            let (l, r) = if gc > 0.0 { (&a, &c) } else { (&c, &b) };
            if Self::lower_bound(l, r, k, speed) >= self.best_d {
                break;
            }
            if gc > 0.0 {
                b = c;
                gb = gc;
                if side == 1 {
                    ga *= 0.5;
                }
                side = 1;
            } else {
                a = c;
                ga = gc;
                if side == -1 {
                    gb *= 0.5;
                }
                side = -1;
            }
        }
    }

    /// Lipschitz lower bound of branch `k` on [a, b].
    #[inline]
    fn lower_bound(a: &Sample, b: &Sample, k: usize, speed: f64) -> f64 {
        0.5 * (a.d[k] + b.d[k] - speed * (b.u - a.u))
    }

    /// Lower bound of ρ / r on [a, b] (ρ / r is (Θ/L)·S-Lipschitz in u).
    #[inline]
    fn ratio_min(a: &Sample, b: &Sample, bo: &Bounds) -> f64 {
        0.5 * (a.ratio + b.ratio - bo.inv_radius * bo.speed * (b.u - a.u))
    }

    /// Whether the circle branch's foot provably stays off the arc on [a, b]: the foot moves
    /// along the circle at most `S r / ρ` per unit u, i.e. `S / (L ρ/r)` in s.
    fn foot_off_arc(a: &Sample, b: &Sample, bo: &Bounds) -> bool {
        let ratio_min = Self::ratio_min(a, b, bo);
        ratio_min > 0.0 && a.gap + b.gap > bo.speed * (b.u - a.u) / (ratio_min * bo.length)
    }

    /// A bracket [a, b] where branch `k`'s derivative goes from − to +. The circle branch
    /// has a concave kink where the curve crosses the circle's axis, with a minimum on
    /// either side; while the interval may contain such a crossing it is bisected.
    fn bracket(&mut self, k: usize, a: Sample, b: Sample, bo: &Bounds, depth: u32) {
        if Self::lower_bound(&a, &b, k, bo.speed) >= self.best_d
            || (k == 0 && Self::foot_off_arc(&a, &b, bo))
        {
            return;
        }
        let convex = Self::convex(&a, &b, k, bo);
        if convex && Self::tangent_bound(&a, &b, k) >= self.best_d {
            return;
        }
        if !convex
            && k == 0
            && depth > 0
            && self.evals < BUDGET
            && Self::ratio_min(&a, &b, bo) <= 0.0
        {
            let m = self.eval(0.5 * (a.u + b.u));
            for (l, r) in [(a, m), (m, b)] {
                if Sample::falls_then_rises(&l, &r, k) {
                    self.bracket(k, l, r, bo, depth - 1);
                } else {
                    self.certify(k, l, r, bo, depth - 1);
                }
            }
        } else {
            self.refine(k, a, b, bo.speed);
        }
    }

    /// Whether an end branch (k = 1, 2) is provably convex on [a, b]: its
    /// `g' = |F_o'|² + (F_o − p)·F_o'' ≥ v_min² − d_max A > 0`, so it has at most one
    /// minimum there.
    ///
    /// For the circle branch `g' = |F_o'|² − (r/ρ)(F_o'·t)² + (F_o − p)·F_o''` (the Hessian
    /// of the squared distance to a circle has eigenvalue `2(1 − r/ρ)` along its tangent
    /// `t`), bounded below with `F_o'·t` being `(A + S²/ρ_min)`-Lipschitz in u.
    fn convex(a: &Sample, b: &Sample, k: usize, bo: &Bounds) -> bool {
        let w = b.u - a.u;
        let v_min = 0.5 * (a.speed + b.speed - bo.accel * w);
        if v_min <= 0.0 {
            return false;
        }
        let d_max = a.d[k].min(b.d[k]) + bo.speed * w;
        let mut lower = v_min * v_min - d_max * bo.accel;
        if k == 0 {
            let ratio_min = Self::ratio_min(a, b, bo);
            if ratio_min <= 0.0 {
                return false;
            }
            let rho_min = ratio_min * bo.length / bo.inv_radius.max(f64::MIN_POSITIVE);
            let lip = bo.accel + bo.speed * bo.speed / rho_min;
            let along = 0.5 * (a.along.abs() + b.along.abs() + lip * w);
            lower -= along.min(bo.speed).powi(2) / ratio_min;
        }
        lower > 0.0
    }

    /// A branch that is flat at both ends at the level of the best distance (a curve
    /// parallel to the arc or its circle): the distance there is already the best.
    fn flat(a: &Sample, b: &Sample, k: usize) -> bool {
        let tol = 1e-12 * (1.0 + a.d[k]);
        (a.d[k] - b.d[k]).abs() <= tol
            && a.g[k].abs() <= tol * (1.0 + a.speed)
            && b.g[k].abs() <= tol * (1.0 + b.speed)
    }

    /// Lower bound of branch `k` on a bracket where it is convex: `d_k²` lies above its
    /// tangents at both ends (slopes `2 g`), so above their intersection.
    fn tangent_bound(a: &Sample, b: &Sample, k: usize) -> f64 {
        let (da, db) = (a.d[k] * a.d[k], b.d[k] * b.d[k]);
        let (ga, gb) = (a.g[k], b.g[k]);
        if ga >= gb {
            return 0.0;
        }
        let u = (db - da + 2.0 * ga * a.u - 2.0 * gb * b.u) / (2.0 * (ga - gb));
        let u = u.clamp(a.u, b.u);
        (da + 2.0 * ga * (u - a.u)).max(0.0).sqrt()
    }

    /// Whether branch `k`'s derivative provably keeps one sign on [a, b].
    fn monotone(a: &Sample, b: &Sample, k: usize, bo: &Bounds) -> bool {
        let (ga, gb) = (a.g[k], b.g[k]);
        if ga.signum() != gb.signum() || ga == 0.0 {
            return false;
        }
        let w = b.u - a.u;
        let d_max = a.d[k].min(b.d[k]) + bo.speed * w;
        let foot_speed = match k {
            0 => {
                let ratio_min = Self::ratio_min(a, b, bo);
                if ratio_min <= 0.0 {
                    return false;
                }
                bo.speed / ratio_min
            }
            _ => 0.0,
        };
        let m = bo.speed * bo.speed + bo.speed * foot_speed + d_max * bo.accel;
        0.5 * (ga.abs() + gb.abs() - m * w) > 0.0
    }

    /// Certify, or search, branch `k` on an interval without a − → + sign change.
    fn certify(&mut self, k: usize, a: Sample, b: Sample, bo: &Bounds, depth: u32) {
        if depth == 0
            || self.evals >= BUDGET
            || Self::lower_bound(&a, &b, k, bo.speed) >= self.best_d
            || (k == 0 && Self::foot_off_arc(&a, &b, bo))
            || Self::monotone(&a, &b, k, bo)
            || (Self::convex(&a, &b, k, bo) && !Sample::falls_then_rises(&a, &b, k))
            || Self::flat(&a, &b, k)
        {
            return;
        }
        let m = self.eval(0.5 * (a.u + b.u));
        for (l, r) in [(a, m), (m, b)] {
            if Sample::falls_then_rises(&l, &r, k) {
                self.bracket(k, l, r, bo, depth - 1);
            } else {
                self.certify(k, l, r, bo, depth - 1);
            }
        }
    }
}

/// Global closest pair between `arc` and `curve` (eq. 12–18); see the module docs.
pub fn closest_arc_curve(arc: &PlacedArc, curve: &PolynomialCurve) -> ArcCurveHit {
    closest_arc_curve_within(arc, curve, f64::INFINITY).unwrap_or(ArcCurveHit {
        distance: f64::INFINITY,
        s: 0.0,
        u: curve.u_range().0,
        arc_point: arc.point(0.0),
        curve_point: curve.eval(curve.u_range().0),
        evaluations: 0,
    })
}

/// [`closest_arc_curve`] when closer than `cutoff`, else `None` (exact either way). A
/// bounding-sphere test (the arc lies within `L/2` of its middle point) skips far pairs
/// without sampling, and every bound prunes against `cutoff` from the start.
pub fn closest_arc_curve_within(
    arc: &PlacedArc,
    curve: &PolynomialCurve,
    cutoff: f64,
) -> Option<ArcCurveHit> {
    let (centre, radius) = curve.bounding_sphere();
    let gap = (arc.point(0.5) - centre).norm() - radius - 0.5 * arc.arc.params.length;
    if gap >= cutoff {
        return None;
    }
    let mut q = Query {
        arc,
        curve,
        best_d: cutoff,
        best_u: 0.0,
        best_s: 0.0,
        evals: 0,
    };
    let grid = curve.grid();
    let speed = curve.speed_bounds();
    let accel = curve.accel_bounds();
    let length = arc.arc.params.length;
    let inv_radius = arc.arc.theta() / length;
    let n = grid.len().min(MAX_INTERVALS + 1);
    let mut samples = [Sample::default(); MAX_INTERVALS + 1];
    for (smp, &u) in samples.iter_mut().zip(grid).take(n) {
        *smp = q.eval(u);
    }
    // Brackets of local minima, lowest first, so that later ones prune against a good bound.
    let mut brackets: [(f64, usize, usize); 3 * MAX_INTERVALS] = [(0.0, 0, 0); 3 * MAX_INTERVALS];
    let mut nb = 0;
    for i in 0..n - 1 {
        for k in 0..BRANCHES {
            if Sample::falls_then_rises(&samples[i], &samples[i + 1], k) {
                brackets[nb] = (samples[i].d[k].min(samples[i + 1].d[k]), i, k);
                nb += 1;
            }
        }
    }
    let brackets = &mut brackets[..nb];
    brackets.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let bounds = |i: usize| Bounds {
        speed: speed[i],
        accel: accel[i],
        inv_radius,
        length,
    };
    for &(_, i, k) in brackets.iter() {
        q.bracket(k, samples[i], samples[i + 1], &bounds(i), 24);
    }
    for i in 0..n - 1 {
        for k in 0..BRANCHES {
            if !Sample::falls_then_rises(&samples[i], &samples[i + 1], k) {
                q.certify(k, samples[i], samples[i + 1], &bounds(i), 24);
            }
        }
    }
    if q.best_d >= cutoff {
        return None;
    }
    let (u, s) = (q.best_u, q.best_s);
    Some(ArcCurveHit {
        distance: q.best_d,
        s,
        u,
        arc_point: arc.point(s),
        curve_point: curve.eval(u),
        evaluations: q.evals,
    })
}
