//! The joint-limit cost H of eq. (14) and its gradient η₂ = ∇H.
//!
//! ```text
//! H(q) = Σ_m ¼ (u_m − l_m)² / ((u_m − q_m)(q_m − l_m))
//! ∂H/∂q_m = ¼ (u_m − l_m)² (2 q_m − u_m − l_m) / ((u_m − q_m)(q_m − l_m))²
//! ```
//!
//! H is 1 per actuator at mid-range and infinite at a limit, and undefined beyond it.
//! The gradient is therefore evaluated at `q` clamped into the band
//! `[l + δ, u − δ]` with `δ = margin · (u − l)`: inside the band it is exact; at and
//! beyond a limit it keeps the finite value of the band's edge, which still points
//! away from the violated limit, so that descending it pulls the state back.

/// H(q) of eq. (14); `+∞` when any coordinate is at or beyond a limit.
pub fn cost(q: &[f64], lower: &[f64], upper: &[f64]) -> f64 {
    let mut h = 0.0;
    for ((&x, &l), &u) in q.iter().zip(lower).zip(upper) {
        if x <= l || x >= u {
            return f64::INFINITY;
        }
        let r = u - l;
        h += 0.25 * r * r / ((u - x) * (x - l));
    }
    h
}

/// Writes ∇H (eq. 14) into `grad`, with the gradient frozen in the outer `margin`
/// fraction of every range (see the module docs). All slices have the same length.
pub fn gradient_into(q: &[f64], lower: &[f64], upper: &[f64], margin: f64, grad: &mut [f64]) {
    for (((g, &x), &l), &u) in grad.iter_mut().zip(q).zip(lower).zip(upper) {
        let r = u - l;
        let d = margin * r;
        let x = x.clamp(l + d, u - d);
        let den = (u - x) * (x - l);
        *g = 0.25 * r * r * (2.0 * x - u - l) / (den * den);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_is_one_per_actuator_at_mid_range() {
        let h = cost(&[0.5, 1.5], &[0.0, 1.0], &[1.0, 2.0]);
        assert!((h - 2.0).abs() < 1e-15);
        assert_eq!(cost(&[1.0], &[0.0], &[1.0]), f64::INFINITY);
        assert_eq!(cost(&[-0.1], &[0.0], &[1.0]), f64::INFINITY);
    }

    #[test]
    fn gradient_matches_finite_differences_inside_the_band() {
        let (lo, hi) = ([0.0, 0.0, 0.0], [0.0333, 0.0333, 0.0333]);
        let q = [0.002, 0.0167, 0.03];
        let mut g = [0.0; 3];
        gradient_into(&q, &lo, &hi, 0.01, &mut g);
        for k in 0..3 {
            let h = 1e-8;
            let (mut p, mut m) = (q, q);
            p[k] += h;
            m[k] -= h;
            let fd = (cost(&p, &lo, &hi) - cost(&m, &lo, &hi)) / (2.0 * h);
            assert!(
                (g[k] - fd).abs() <= 1e-5 * fd.abs().max(1.0),
                "{k}: {} {fd}",
                g[k]
            );
        }
    }

    #[test]
    fn gradient_is_finite_and_points_inwards_beyond_the_limits() {
        let (lo, hi) = ([0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0]);
        let q = [-5.0, 0.0, 1.0, 7.0];
        let mut g = [0.0; 4];
        gradient_into(&q, &lo, &hi, 0.01, &mut g);
        assert!(g.iter().all(|v| v.is_finite()));
        // Descending H (−∇H) moves up from below and down from above.
        assert!(g[0] < 0.0 && g[1] < 0.0);
        assert!(g[2] > 0.0 && g[3] > 0.0);
        assert_eq!(g[0], g[1]);
    }
}
