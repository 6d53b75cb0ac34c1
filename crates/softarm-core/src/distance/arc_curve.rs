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
//! Cost. The curve's coefficients are moved into the arc's frame once per query, so an
//! evaluation is one Horner pass (value and derivative together) plus a few square roots:
//! the foot on the circle and whether it lies on the arc come from the in-plane
//! coordinates against the arc's end directions, without trigonometry, and the foot's
//! distance from the arc (in `s`) is bounded below by chords (a chord never exceeds its
//! arc). Grid intervals are sampled nearest first and only while a lower bound (the
//! curve's Taylor sphere over the interval against the arc's sphere of radius `L/2`
//! around its middle) beats the best distance so far; the other intervals cannot hold a
//! closer point. The Lipschitz bound of the circle branch uses the true distance at the
//! samples (the circle branch matters only where it is the true distance), bisection
//! midpoints are shared between the branches, and on a bracket proven convex the regula
//! falsi stops once the tangent bound is within 1e-12 m of the best distance. An interval
//! is also discarded for branch `b` when the second-order bound (`d_b²/2` has slope `g_b`
//! and curvature `≥ −M`, expanded from both ends to the midpoint) stays at or above the
//! best distance.
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
    /// The true distance to the arc: the smallest valid branch.
    dist: f64,
    d: [f64; BRANCHES],
    /// Half derivative of d_b² in u: (F_o − p_b)·F_o'.
    g: [f64; BRANCHES],
    /// ρ / r of the curve point (distance from the circle's axis over the radius).
    ratio: f64,
    /// |F_o'(u)|.
    speed: f64,
    /// F_o'(u) · t, t the circle's unit tangent at the foot.
    along: f64,
    /// A lower bound of how far (in s, around the circle) the circle foot lies outside the
    /// arc's [0, 1] (0 when on the arc).
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

/// How many times a bracket not proven convex is bisected.
const SPLIT_LEVELS: u32 = 4;

/// Most evaluations spent certifying one pair.
const BUDGET: u32 = 200;

impl Sample {
    /// A sign change from − to + (a zero at either end counts: the minimum is there).
    #[inline]
    fn falls_then_rises(a: &Sample, b: &Sample, k: usize) -> bool {
        (a.g[k] < 0.0 && b.g[k] >= 0.0) || (a.g[k] <= 0.0 && b.g[k] > 0.0)
    }
}

/// Most coefficients kept on the stack for the curve in the arc's frame.
const STACK_COEFFS: usize = 16;

/// The arc's geometry in its plane, precomputed once per query.
struct Geometry {
    length: f64,
    theta: f64,
    dir: (f64, f64),
    tip: Vec3,
    cos: f64,
    sin: f64,
    /// sin Θ / Θ (1 at Θ = 0).
    sinc: f64,
    /// Θ > π: the arc covers more than half its circle.
    wide: bool,
}

struct Query {
    geo: Geometry,
    /// The curve's coefficients in the arc's base frame (ascending powers).
    stack: [Vec3; STACK_COEFFS],
    heap: Vec<Vec3>,
    ncoeffs: usize,
    best_d: f64,
    best_u: f64,
    best_k: usize,
    evals: u32,
    /// Bisection midpoints already evaluated (the branches of one interval share them).
    memo_u: [f64; MEMO],
    memo: [Sample; MEMO],
    memo_len: usize,
}

/// Bisection midpoints remembered per query.
const MEMO: usize = 16;

/// Absolute tolerance (m) of the regula falsi's stopping test on a convex bracket.
const STOP_TOL: f64 = 1e-12;

/// Lower bound, in fractions of the arc, of the angle between the unit vector along
/// `(a, b)` (`h = |(a, b)|`, `b = Θ bs`) and the unit vector along the x axis: the chord
/// `|f − e| = |b| √(2 / (h (h + a)))` (no cancellation) when `a > 0`, else `√(2 (1 − a/h))`;
/// a chord never exceeds its arc.
#[inline]
fn chord_fraction(bs: f64, a: f64, h: f64, theta: f64) -> f64 {
    if a > 0.0 {
        bs.abs() * (2.0 / (h * (h + a))).sqrt()
    } else {
        (2.0 * (1.0 - a / h)).sqrt() / theta
    }
}

impl Query {
    #[inline]
    fn coeffs(&self) -> &[Vec3] {
        if self.ncoeffs <= STACK_COEFFS {
            &self.stack[..self.ncoeffs]
        } else {
            &self.heap
        }
    }

    /// The curve point and tangent at `u`, in the arc's frame (Horner, value and
    /// derivative together).
    #[inline]
    fn curve_local(&self, u: f64) -> (Vec3, Vec3) {
        let c = self.coeffs();
        let mut p = c[c.len() - 1];
        let mut dp = Vec3::zeros();
        for ck in c[..c.len() - 1].iter().rev() {
            dp = dp * u + p;
            p = p * u + ck;
        }
        (p, dp)
    }

    /// Distances, derivatives and certificates' data of the three branches at `u`. No
    /// trigonometry: the foot of the perpendicular on the circle and whether it lies on
    /// the arc come from the plane coordinates `(a, b) = Θ (r − x_d, x_z)` against the
    /// arc's end directions (1, 0) and (cos Θ, sin Θ).
    #[inline]
    fn eval(&mut self, u: f64) -> Sample {
        let (x, dx) = self.curve_local(u);
        self.evals += 1;
        let geo = &self.geo;
        let (l, theta) = (geo.length, geo.theta);
        let xd = x.x * geo.dir.0 + x.y * geo.dir.1;
        let xz = x.z;
        let a = l - theta * xd; // Θ · (r − x_d)
        let b = theta * xz; // Θ · x_z
        let h = (a * a + b * b).sqrt();
        let ratio = h / l;
        let (tangent, foot, on_arc, gap) = if h > 0.0 {
            let ih = 1.0 / h;
            let (sa, ca) = (b * ih, a * ih);
            let along = l * xz * ih;
            let across = if a > 0.0 {
                l * theta * xz * xz * ih / (h + a)
            } else {
                (l / theta) * (1.0 - ca)
            };
            // (a, b) rotated by −Θ, with its second component over Θ.
            let a1 = a * geo.cos + b * geo.sin;
            let bs1 = xz * geo.cos - a * geo.sinc;
            let (past0, past1) = (xz >= 0.0, bs1 <= 0.0);
            let on = if geo.wide {
                past0 || past1
            } else {
                past0 && past1
            };
            let gap = if on {
                0.0
            } else {
                chord_fraction(xz, a, h, theta).min(chord_fraction(bs1, a1, h, theta))
            };
            (
                Vec3::new(sa * geo.dir.0, sa * geo.dir.1, ca),
                Vec3::new(across * geo.dir.0, across * geo.dir.1, along),
                on,
                gap,
            )
        } else {
            // On the circle's axis: every circle point is a foot; take the base.
            (Vec3::z(), Vec3::zeros(), true, 0.0)
        };
        let vs = [x - foot, x, x - geo.tip];
        let d = [vs[0].norm(), vs[1].norm(), vs[2].norm()];
        let g = [vs[0].dot(&dx), vs[1].dot(&dx), vs[2].dot(&dx)];
        // The true distance: the smallest valid branch.
        let (mut dd, mut kk) = if d[1] <= d[2] { (d[1], 1) } else { (d[2], 2) };
        if on_arc && d[0] < dd {
            dd = d[0];
            kk = 0;
        }
        if dd < self.best_d {
            self.best_d = dd;
            self.best_u = u;
            self.best_k = kk;
        }
        Sample {
            u,
            dist: dd,
            d,
            g,
            ratio,
            speed: dx.norm(),
            along: dx.dot(&tangent),
            gap,
        }
    }

    /// [`Query::eval`] at the midpoint of [a, b], remembered: the bisections of the
    /// three branches of one interval hit the same points.
    fn eval_mid(&mut self, a: &Sample, b: &Sample) -> Sample {
        let u = 0.5 * (a.u + b.u);
        let n = self.memo_len.min(MEMO);
        if let Some(i) = self.memo_u[..n].iter().position(|&v| v == u) {
            return self.memo[i];
        }
        let m = self.eval(u);
        let slot = self.memo_len % MEMO;
        self.memo_u[slot] = u;
        self.memo[slot] = m;
        self.memo_len += 1;
        m
    }

    /// Illinois regula falsi for the root of branch `k`'s derivative on [a, b],
    /// g(a) < 0 < g(b). On a bracket proven `convex`, it stops as soon as the tangent
    /// bound shows that the branch cannot go `STOP_TOL` below the best distance.
    fn refine(&mut self, k: usize, mut a: Sample, mut b: Sample, speed: f64, convex: bool) {
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
            // The secant root as a fraction of the bracket: no product of u and g, which
            // could overflow for long parameter ranges.
            let mut u = a.u + (b.u - a.u) * (ga / (ga - gb));
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
            if Self::lower_bound(l, r, k, speed) >= self.best_d
                || (convex && Self::tangent_bound(l, r, k) >= self.best_d - STOP_TOL)
            {
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

    /// Lipschitz lower bound on [a, b] of branch `k` (an end) or, for the circle branch,
    /// of the true distance (where the circle branch is valid it is the true distance, and
    /// elsewhere it cannot give the minimum): both are 1-Lipschitz in the curve point.
    #[inline]
    fn lower_bound(a: &Sample, b: &Sample, k: usize, speed: f64) -> f64 {
        0.5 * (a.d[k].max(a.dist) + b.d[k].max(b.dist) - speed * (b.u - a.u))
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

    /// A bracket [a, b] where branch `k`'s derivative goes from − to +. Unless the branch
    /// is proven convex there it may hold two minima, so it is bisected a few times; the
    /// circle branch has a concave kink where the curve crosses the circle's axis, with a
    /// minimum on either side, so while the interval may contain such a crossing it is
    /// bisected further.
    fn bracket(&mut self, k: usize, a: &Sample, b: &Sample, bo: &Bounds, depth: u32) {
        if Self::lower_bound(a, b, k, bo.speed) >= self.best_d
            || (k == 0 && Self::foot_off_arc(a, b, bo))
        {
            return;
        }
        let convex = Self::convex(a, b, k, bo);
        if convex && Self::tangent_bound(a, b, k) >= self.best_d {
            return;
        }
        // A bracket not proven convex may hold two minima (with a maximum between them):
        // it is bisected up to SPLIT_LEVELS times, and without limit near the circle's axis.
        let near_axis = k == 0 && Self::ratio_min(a, b, bo) <= 0.0;
        if !convex && depth > 0 && self.evals < BUDGET && (near_axis || depth > 24 - SPLIT_LEVELS) {
            let m = self.eval_mid(a, b);
            for (l, r) in [(a, &m), (&m, b)] {
                if Sample::falls_then_rises(l, r, k) {
                    self.bracket(k, l, r, bo, depth - 1);
                } else {
                    self.certify(k, l, r, bo, depth - 1);
                }
            }
        } else {
            self.refine(k, *a, *b, bo.speed, convex);
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
        // g = (F_o − p)·F_o' is in m² per unit of u: it is compared with the speed (m per
        // unit of u) times a length, so that the test reads the same for any scale of u
        // (with an absolute 1e-12, every g of a curve parametrised over 1e50 passed).
        let tol = 1e-12 * (1.0 + a.d[k]);
        (a.d[k] - b.d[k]).abs() <= tol
            && a.g[k].abs() <= tol * a.speed
            && b.g[k].abs() <= tol * b.speed
    }

    /// Lower bound of branch `k` on a bracket where it is convex: `d_k²` lies above its
    /// tangents at both ends (slopes `2 g`), so above their intersection.
    fn tangent_bound(a: &Sample, b: &Sample, k: usize) -> f64 {
        let (da, db) = (a.d[k] * a.d[k], b.d[k] * b.d[k]);
        let (ga, gb) = (a.g[k], b.g[k]);
        if ga >= gb {
            return 0.0;
        }
        // The tangents meet at a + x; measured from a, so that no product of u (which may be
        // large, e.g. 1e96) and a slope cancels.
        let w = b.u - a.u;
        let x = ((db - da - 2.0 * gb * w) / (2.0 * (ga - gb))).clamp(0.0, w);
        (da + 2.0 * ga * x).max(0.0).sqrt()
    }

    /// Bound `M ≥ |g_k'|` on [a, b] (`None` near the circle's axis):
    /// `g_k' = |F_o'|² − p_k'·F_o' + (F_o − p_k)·F_o''`.
    fn curvature_bound(a: &Sample, b: &Sample, k: usize, bo: &Bounds) -> Option<f64> {
        let w = b.u - a.u;
        let d_max = a.d[k].min(b.d[k]) + bo.speed * w;
        let foot_speed = match k {
            0 => {
                let ratio_min = Self::ratio_min(a, b, bo);
                if ratio_min <= 0.0 {
                    return None;
                }
                bo.speed / ratio_min
            }
            _ => 0.0,
        };
        Some(bo.speed * bo.speed + bo.speed * foot_speed + d_max * bo.accel)
    }

    /// Whether branch `k` provably stays at or above `best` on [a, b]: `f = d_k² / 2` has
    /// `f' = g_k` and `f'' ≥ −M`, so on [a, m] (m the midpoint) it lies above the concave
    /// `f(a) + g(a)(u − a) − M (u − a)² / 2`, whose minimum there is at a or m, and
    /// likewise on [m, b] from b.
    fn above_best(a: &Sample, b: &Sample, k: usize, bo: &Bounds, best: f64) -> bool {
        let Some(m) = Self::curvature_bound(a, b, k, bo) else {
            return false;
        };
        let h = 0.5 * (b.u - a.u);
        let (fa, fb) = (0.5 * a.d[k] * a.d[k], 0.5 * b.d[k] * b.d[k]);
        let drop = 0.5 * m * h * h;
        let low = (fa + a.g[k] * h - drop).min(fb - b.g[k] * h - drop);
        low.min(fa).min(fb) >= 0.5 * best * best
    }

    /// Whether branch `k`'s derivative provably keeps one sign on [a, b].
    fn monotone(a: &Sample, b: &Sample, k: usize, bo: &Bounds) -> bool {
        let (ga, gb) = (a.g[k], b.g[k]);
        if ga.signum() != gb.signum() || ga == 0.0 {
            return false;
        }
        // |g_k'| ≤ M on [a, b]: g cannot cross zero if the endpoint values outweigh it.
        let Some(m) = Self::curvature_bound(a, b, k, bo) else {
            return false;
        };
        0.5 * (ga.abs() + gb.abs() - m * (b.u - a.u)) > 0.0
    }

    /// Certify, or search, branch `k` on an interval without a − → + sign change.
    fn certify(&mut self, k: usize, a: &Sample, b: &Sample, bo: &Bounds, depth: u32) {
        if depth == 0
            || self.evals >= BUDGET
            || Self::lower_bound(a, b, k, bo.speed) >= self.best_d
            || (k == 0 && Self::foot_off_arc(a, b, bo))
            || Self::monotone(a, b, k, bo)
            || (self.best_d.is_finite() && Self::above_best(a, b, k, bo, self.best_d))
            || (Self::convex(a, b, k, bo) && !Sample::falls_then_rises(a, b, k))
            || Self::flat(a, b, k)
        {
            return;
        }
        let m = self.eval_mid(a, b);
        for (l, r) in [(a, &m), (&m, b)] {
            if Sample::falls_then_rises(l, r, k) {
                self.bracket(k, l, r, bo, depth - 1);
            } else {
                self.certify(k, l, r, bo, depth - 1);
            }
        }
    }
}

/// Θ / L.
fn inv_radius_of(arc: &super::arc_point::LocalArc) -> f64 {
    arc.theta() / arc.params.length
}

/// Sorts a short slice by a key (insertion sort: the slices hold at most a few dozen).
fn insertion_sort<T: Copy>(v: &mut [T], key: impl Fn(&T) -> f64) {
    for i in 1..v.len() {
        let x = v[i];
        let kx = key(&x);
        let mut j = i;
        while j > 0 && key(&v[j - 1]) > kx {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// Samples the grid intervals that can beat the best distance, then searches their
/// brackets (lowest first) and certifies the rest. `M` ≥ grid points, `B` ≥ 3 intervals.
fn search<const M: usize, const B: usize>(
    q: &mut Query,
    curve: &PolynomialCurve,
    middle: Vec3,
    inv_radius: f64,
) {
    let grid = curve.grid();
    let speed = curve.speed_bounds();
    let accel = curve.accel_bounds();
    let spheres = curve.interval_spheres();
    let length = q.geo.length;
    let n = grid.len().min(M);
    let intervals = n - 1;
    // A lower bound of the distance over each grid interval: the curve's sphere there
    // against the arc's (the arc lies within L/2 of its middle point). Intervals are
    // sampled nearest first, and only while their bound beats the best distance so far.
    let (middle, half) = (middle, 0.5 * length);
    let mut lower = [0.0f64; M];
    let mut order = [0usize; M];
    for i in 0..intervals {
        let (c, r) = spheres[i];
        lower[i] = ((c - middle).norm() - r - half).max(0.0);
        order[i] = i;
    }
    let order = &mut order[..intervals];
    insertion_sort(order, |&i| lower[i]);
    let mut samples = [Sample::default(); M];
    let mut sampled = [false; M];
    let mut active = [false; M];
    for &i in order.iter() {
        if lower[i] >= q.best_d {
            break;
        }
        for j in [i, i + 1] {
            if !sampled[j] {
                samples[j] = q.eval(grid[j]);
                sampled[j] = true;
            }
        }
        active[i] = true;
    }
    // Brackets of local minima, lowest first, so that later ones prune against a good bound.
    let mut brackets = [(0.0f64, 0usize, 0usize); B];
    let mut nb = 0;
    for i in (0..intervals).filter(|&i| active[i]) {
        for k in 0..BRANCHES {
            if Sample::falls_then_rises(&samples[i], &samples[i + 1], k) {
                brackets[nb] = (samples[i].d[k].min(samples[i + 1].d[k]), i, k);
                nb += 1;
            }
        }
    }
    let brackets = &mut brackets[..nb];
    insertion_sort(brackets, |b| b.0);
    let bounds = |i: usize| Bounds {
        speed: speed[i],
        accel: accel[i],
        inv_radius,
        length,
    };
    for &(_, i, k) in brackets.iter() {
        if lower[i] < q.best_d {
            q.bracket(k, &samples[i], &samples[i + 1], &bounds(i), 24);
        }
    }
    for &i in order.iter() {
        if !active[i] || lower[i] >= q.best_d {
            continue;
        }
        for k in 0..BRANCHES {
            if !Sample::falls_then_rises(&samples[i], &samples[i + 1], k) {
                q.certify(k, &samples[i], &samples[i + 1], &bounds(i), 24);
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

/// Curve extent, in arc lengths, above which a grid interval near the arc is split before
/// the search. The search's certificates hold when the curve does not turn on the scale of
/// one grid interval *relative to the arc*: a grid interval holding kilometres of curve
/// can pass a 1 m arc's circle twice (two minima of one branch, only one of which a
/// bracket finds). Pieces no longer than this are in the regime the search is tested in.
const LONG_PIECE: f64 = 8.0;

/// Most bounding spheres computed while splitting one long curve: enough to go from 1e100 m
/// down to a millimetre arc (about 340 halvings) along a few approaches.
const SPLIT_BUDGET: usize = 8192;

/// [`closest_arc_curve`] when closer than `cutoff`, else `None` (exact either way). A
/// bounding-sphere test (the arc lies within `L/2` of its middle point) skips far pairs
/// without sampling, and every bound prunes against `cutoff` from the start.
///
/// A curve whose grid intervals near the arc are long compared with the arc (their
/// bounding spheres wider than 8 arc lengths) is first split: those intervals are halved,
/// keeping only halves whose sphere can come closer than the best distance so far, until
/// each piece is at most 8 arc lengths across; each piece is then searched as a curve of
/// its own (same polynomial, its own grid), nearest first.
pub fn closest_arc_curve_within(
    arc: &PlacedArc,
    curve: &PolynomialCurve,
    cutoff: f64,
) -> Option<ArcCurveHit> {
    let (centre, radius) = curve.bounding_sphere();
    let middle = arc.point(0.5);
    let half = 0.5 * arc.arc.params.length;
    let gap = (middle - centre).norm() - radius - half;
    if gap >= cutoff {
        return None;
    }
    let long = LONG_PIECE * arc.arc.params.length;
    // Usual curves (intervals shorter than 8 arc lengths) skip the loop: one comparison.
    let needs_split = curve.longest_interval() > long
        && curve
            .interval_spheres()
            .iter()
            .any(|(c, r)| *r > long && (middle - c).norm() - r - half < cutoff);
    if needs_split {
        closest_in_pieces(arc, curve, cutoff)
    } else {
        search_curve(arc, curve, cutoff)
    }
}

/// The split search of [`closest_arc_curve_within`] for curves long compared with the arc.
fn closest_in_pieces(arc: &PlacedArc, curve: &PolynomialCurve, cutoff: f64) -> Option<ArcCurveHit> {
    let middle = arc.point(0.5);
    let half = 0.5 * arc.arc.params.length;
    let long = LONG_PIECE * arc.arc.params.length;
    let lower = |(c, r): (Vec3, f64)| ((middle - c).norm() - r - half).max(0.0);
    // An upper bound of the distance from actual curve points (piece midpoints): pieces
    // whose lower bound exceeds it cannot hold the minimum.
    let mut upper = cutoff;
    let mut leaves: Vec<(f64, f64, f64)> = Vec::new();
    let grid = curve.grid();
    let mut stack: Vec<(f64, f64, (Vec3, f64))> = grid
        .windows(2)
        .zip(curve.interval_spheres())
        .map(|(w, s)| (w[0], w[1], *s))
        .collect();
    let mut spent = 0usize;
    while let Some((a, b, sphere)) = stack.pop() {
        let lo = lower(sphere);
        if lo > upper {
            continue;
        }
        let m = 0.5 * (a + b);
        upper = upper.min(arc.closest_to_point(&curve.eval(m)).2);
        if sphere.1 <= long || spent >= SPLIT_BUDGET || !(m > a && m < b) {
            leaves.push((lo, a, b));
            continue;
        }
        spent += 2;
        stack.push((a, m, curve.sphere_over(a, m)));
        stack.push((m, b, curve.sphere_over(m, b)));
    }
    leaves.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut best: Option<ArcCurveHit> = None;
    let mut limit = cutoff;
    let mut evaluations = 0;
    for &(lo, a, b) in &leaves {
        if lo > upper || lo >= limit {
            continue;
        }
        if let Some(h) = search_curve(arc, &curve.piece(a, b), limit) {
            evaluations += h.evaluations;
            limit = h.distance;
            best = Some(h);
        }
    }
    best.map(|h| ArcCurveHit { evaluations, ..h })
}

/// The search of one curve (the module docs), without splitting.
fn search_curve(arc: &PlacedArc, curve: &PolynomialCurve, cutoff: f64) -> Option<ArcCurveHit> {
    let middle = arc.point(0.5);
    let local = &arc.arc;
    let theta = local.theta();
    let params = local.params;
    let dir = if theta > 0.0 {
        (params.ux / theta, params.uy / theta)
    } else {
        (1.0, 0.0)
    };
    let (sin, cos) = theta.sin_cos();
    let geo = Geometry {
        length: params.length,
        theta,
        dir,
        tip: local.tip(),
        cos,
        sin,
        sinc: crate::math::f1_f2(theta * theta).0,
        wide: theta > std::f64::consts::PI,
    };
    let coeffs = curve.coeffs();
    let mut q = Query {
        geo,
        stack: [Vec3::zeros(); STACK_COEFFS],
        heap: Vec::new(),
        ncoeffs: coeffs.len(),
        best_d: cutoff,
        best_u: 0.0,
        best_k: 1,
        evals: 0,
        memo_u: [f64::NAN; MEMO],
        memo: [Sample::default(); MEMO],
        memo_len: 0,
    };
    let to_local = |k: usize, c: &Vec3| {
        if k == 0 {
            arc.to_local(c)
        } else {
            arc.dir_to_local(c)
        }
    };
    if coeffs.len() <= STACK_COEFFS {
        for (k, (dst, c)) in q.stack.iter_mut().zip(coeffs).enumerate() {
            *dst = to_local(k, c);
        }
    } else {
        q.heap = coeffs
            .iter()
            .enumerate()
            .map(|(k, c)| to_local(k, c))
            .collect();
    }
    // Fixed-size scratch arrays: small ones for the usual low degrees.
    if curve.grid().len() <= 25 {
        search::<25, 75>(&mut q, curve, middle, inv_radius_of(local));
    } else {
        search::<{ MAX_INTERVALS + 1 }, { 3 * MAX_INTERVALS }>(
            &mut q,
            curve,
            middle,
            inv_radius_of(local),
        );
    }
    if q.best_d >= cutoff {
        return None;
    }
    let u = q.best_u;
    let s = match q.best_k {
        1 => 0.0,
        2 => 1.0,
        _ => {
            let (x, _) = q.curve_local(u);
            local.circle_fraction(&x).clamp(0.0, 1.0)
        }
    };
    Some(ArcCurveHit {
        distance: q.best_d,
        s,
        u,
        arc_point: arc.point(s),
        curve_point: curve.eval(u),
        evaluations: q.evals,
    })
}
