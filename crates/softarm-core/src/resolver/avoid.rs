//! Obstacle avoidance as the lowest-priority task of the resolver (planning paper eq. 9).
//!
//! For each obstacle the exact closest pair to each piece of the resolver's [`Body`] (arcs,
//! end plates, gripper: [`crate::distance::bodies`]) is found. Within the influence
//! distance ρ₀ of the surface gap `g = d − r_piece − obstacle_radius`, the gap is asked to
//! grow by
//! `f = k_r (1/g − 1/ρ₀) / g²` per step (the gradient of Khatib's potential, the
//! repulsive term of eq. 9, with `g` clamped at 1 mm), by at least a tenth of the way to
//! ρ₀ ([`TAIL`]), or the whole way over its last hundredth ([`LAST_STRETCH`]), and by at
//! most what a step may move (half of `max_step`).
//!
//! The ask is a ONE-row task on the gap, solved in the null space of every task of the
//! mode, where eq. (20) puts the joint-limit gradient of eq. (14):
//! `Δq_j = c_j f_j / ‖c_j‖²` with `c_j = P ∇g_j`, `∇g_j = J_sjᵀ n_j` (n_j the unit
//! direction from the obstacle to the arm point, J_sj the point's 3×n Jacobian, P the
//! tasks' null-space projector), faded out where the null space has no leverage on the
//! gap ([`add_gap_step`]). Its first-order change of the gap is `f_j` where the null
//! space has leverage, and never negative; the step vanishes where the gap is stationary
//! on the tasks' self-motion manifold.
//!
//! Issue 27 item 1: it replaces `P Σ_j J_sj⁺ F_j`, the projection of the three-row push
//! of eq. (8)–(9). Projected, that vector is no ascent direction of the gap
//! (`nᵀ J_s P J_sᵀ (J_s J_sᵀ)⁻¹ n` has no sign), and it does not vanish where the gap is
//! stationary; with `F` ~1 m per step inside the body it always ran at the length cap.
//! The arm slid along its self-motion manifold onto the joint limits, where the higher
//! tasks lost columns, brought the body nearer the cane once the limits had reshaped the
//! projection, or oscillated by the cap (±2 mm) about the best clearance, and that
//! oscillation moved the gripper by second-order terms, always the same way: the pose
//! drifted by 0.05–0.4 mm. [`step_fraction`] also bounds what the step may cost the
//! position task at second order.
//!
//! The pairs are evaluated on the MODEL at the commanded `q`, not on the measurement, so
//! the repulsion adds no loop through the plant's lag.

use nalgebra::DMatrix;

use super::Gains;
use crate::body::{Body, Part};
use crate::chain::{forward_unchecked, point_unchecked};
use crate::distance::bodies::{pieces_within, BodyBox, BodyClosest, Piece};
use crate::distance::Obstacle;
use crate::kinematics::Kinematics;
use crate::math::Vec3;

/// Smallest surface gap (m) used in the law: below it the push no longer grows.
const MIN_GAP: f64 = 1e-3;

/// The smallest ask, as a fraction of the gap still to go to the influence distance ρ₀,
/// per step. Eq. (9) alone asks `k_r (ρ₀ − g) / ρ₀⁴` near ρ₀: with the blackberry gains
/// 0.2 % of the way per step, a time constant of 540 steps, so an arm whose null space
/// frees the body crept on for hundreds of steps (~1 mm per 50 steps). A tenth settles it
/// in tens of steps. With the blackberry gains eq. (9) is the larger below a 7.9 mm gap
/// (`g³ = k_r / (ρ₀ TAIL)`), and is unchanged there.
const TAIL: f64 = 0.1;

/// The last stretch to ρ₀, as a fraction of ρ₀, that is asked whole rather than by
/// [`TAIL`]. A tenth of the way per step is a geometric approach: where the null space's
/// leverage on the gap is small, the fade and the drift rule earned ~75 % of each ask,
/// and the body still moved 8 µm per step at step 150, 0.10–0.15 mm over steps 150–200
/// (4 of 2,000 cases on seed 29, 1 on seed 31; issue 40 item 5). Asking at least the
/// last 0.3 mm whole ends the approach in a few steps, and the repulsion then stops.
const LAST_STRETCH: f64 = 0.01;

/// One obstacle's push on its closest arm point.
#[derive(Debug, Clone)]
pub struct Repulsion {
    /// Surface gap (m); negative when the surfaces overlap.
    pub gap: f64,
    /// Closest arm point (base frame).
    pub arm_point: Vec3,
    /// Columns of the point's 3×n Jacobian.
    pub jac: Vec<Vec3>,
    /// Unit direction from the obstacle point to the arm point: ∂g/∂p.
    pub normal: Vec3,
    /// The gap increase asked of this piece this step (m): for the obstacle's nearest
    /// piece eq. (9)'s `f`, for a piece `a` farther `max(0, f − a)`, so that every tied
    /// piece is asked up to one common level ([`repulsions_into`]).
    pub ask: f64,
    /// How nearly this piece ties with its obstacle's nearest one ([`tie_weight`]): 1 for
    /// the nearest, falling continuously to 0 at [`tie_band`] beyond it.
    pub weight: f64,
    /// The index of the obstacle (the repulsions of one obstacle are consecutive).
    pub obstacle: usize,
}

/// The band (m) of surface gaps above an obstacle's nearest piece within which another
/// piece ties with it: the largest gap increase one step asks (half of `max_step`, the
/// repulsion's cap; at most ρ₀). A piece less than that farther than the nearest can be
/// the nearest after one step, so the step must raise it too.
pub fn tie_band(gains: &Gains) -> f64 {
    (0.5 * gains.max_step).min(gains.influence_distance)
}

/// The weight of a piece whose surface lies `t` bands beyond its obstacle's nearest:
/// `1 − 3t² + 2t³` on [0, 1] (1 at a tie, 0 from one band on, with zero slope at both
/// ends), so that no piece's row enters or leaves the task abruptly.
pub fn tie_weight(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    1.0 - t * t * (3.0 - 2.0 * t)
}

fn columns(j: &nalgebra::Matrix3xX<f64>) -> Vec<Vec3> {
    j.column_iter().map(|c| c.into_owned()).collect()
}

/// The buffers of [`repulsions_into`]: the body's pieces and one obstacle's near pieces.
pub type Buffers<'a> = (&'a mut Vec<Piece>, &'a mut Vec<BodyClosest>);

/// Fills `out` with the repulsions of every obstacle within the influence distance of the
/// model arm at `q`, measured on `body` (`jac`: the end-effector Jacobian at `q`): for each
/// obstacle, one per piece whose surface gap ties with the nearest one's ([`tie_band`]),
/// weighted by [`tie_weight`]. Returns the smallest surface gap among them, `+∞` when
/// none is that close.
pub fn repulsions_into<K: Kinematics + ?Sized>(
    (arm, body): (&K, &Body),
    q: &[f64],
    obstacles: &[Obstacle],
    gains: &Gains,
    jac: &DMatrix<f64>,
    (pieces, hits): Buffers<'_>,
    out: &mut Vec<Repulsion>,
) -> f64 {
    out.clear();
    if obstacles.is_empty() || gains.influence_distance <= 0.0 {
        return f64::INFINITY;
    }
    body.pieces_into(arm, q, pieces);
    // One box around the whole body's surface per step; each obstacle is tested against
    // it first.
    let bound = BodyBox::around(pieces);
    let rho = gains.influence_distance;
    // The surface distance (the piece's radius off its backbone) an obstacle's centre line
    // must come within to repel: its own radius and the influence distance.
    let cutoff = gains.obstacle_radius + rho;
    let band = tie_band(gains);
    let mut clearance = f64::INFINITY;
    for (j, ob) in obstacles.iter().enumerate() {
        hits.clear();
        pieces_within(pieces, &bound, ob, (cutoff, band), hits);
        let Some(nearest) = hits.iter().map(|h| h.surface).reduce(f64::min) else {
            continue;
        };
        clearance = clearance.min(nearest - gains.obstacle_radius);
        // The common level every tied piece is raised to this step: the nearest one's gap
        // plus its ask `f`. A piece `above` the nearest needs only `f − above`.
        let f = ask_for(gains, nearest - gains.obstacle_radius);
        for hit in hits.iter() {
            let above = hit.surface - nearest;
            let weight = tie_weight(above / band);
            if weight <= 0.0 {
                continue;
            }
            if let Some(r) = repulsion((arm, body), q, gains, jac, pieces, hit) {
                let ask = (f - above).max(0.0);
                out.push(Repulsion {
                    weight,
                    obstacle: j,
                    ask,
                    ..r
                });
            }
        }
    }
    clearance
}

/// The repulsion of one piece's closest pair `hit` (its surface gap within the influence
/// distance), or `None` where the backbone crosses the obstacle (no direction to push in).
fn repulsion<K: Kinematics + ?Sized>(
    (arm, body): (&K, &Body),
    q: &[f64],
    gains: &Gains,
    jac: &DMatrix<f64>,
    pieces: &[Piece],
    hit: &BodyClosest,
) -> Option<Repulsion> {
    let rho = gains.influence_distance;
    let c = &hit.closest;
    let gap = hit.surface - gains.obstacle_radius;
    let away = c.arm_point - c.obstacle_point;
    let d = away.norm();
    if gap >= rho || d == 0.0 {
        return None;
    }
    let ask = ask_for(gains, gap);
    Some(Repulsion {
        gap,
        arm_point: c.arm_point,
        jac: point_columns((arm, body), q, jac, pieces, hit),
        normal: away / d,
        ask,
        weight: 1.0,
        obstacle: 0,
    })
}

/// The gap increase (m) eq. (9) asks of a surface gap `gap` in one step.
fn ask_for(gains: &Gains, gap: f64) -> f64 {
    let rho = gains.influence_distance;
    let g = gap.max(MIN_GAP);
    // The ask is a gap increase for ONE step: never more than a step may move (half of
    // max_step, the repulsion's cap). Eq. (9) asks 1.45 m per step at the 1 mm clamp,
    // which would keep every step at its cap, also where P ∇g is small.
    let khatib = gains.repulsion_gain * (1.0 / g - 1.0 / rho) / (g * g);
    let tail = (TAIL * (rho - gap)).max((LAST_STRETCH * rho).min(rho - gap));
    khatib.max(tail).min(0.5 * gains.max_step)
}

/// The columns of the Jacobian of the arm point of `hit` (on `pieces`, the pieces of
/// `body` at `q`; `jac`: the end-effector Jacobian at `q`).
fn point_columns<K: Kinematics + ?Sized>(
    (arm, body): (&K, &Body),
    q: &[f64],
    jac: &DMatrix<f64>,
    pieces: &[Piece],
    hit: &BodyClosest,
) -> Vec<Vec3> {
    let c = &hit.closest;
    match body.part_of(pieces, hit.piece) {
        Part::Arc => columns(&point_unchecked(arm, q, c.section, c.s).1),
        Part::Plate => {
            // A point of a plate moves as the affine combination of the plate's ends.
            let start = columns(&point_unchecked(arm, q, c.section, 1.0).1);
            let end = columns(&point_unchecked(arm, q, c.section + 1, 0.0).1);
            start
                .iter()
                .zip(&end)
                .map(|(a, b)| a * (1.0 - c.s) + b * c.s)
                .collect()
        }
        Part::Gripper => {
            // A point fixed to the end-effector frame: ṗ = v + ω × (p − p_ee), with the
            // frame's origin `gripper_back` along the gripper from its start.
            let piece = &pieces[hit.piece];
            let z = piece.arc.frame.rot.column(2).into_owned();
            let r = c.arm_point - (piece.arc.frame.pos + z * body.gripper_back());
            (0..jac.ncols())
                .map(|k| {
                    let v = Vec3::new(jac[(0, k)], jac[(1, k)], jac[(2, k)]);
                    let w = Vec3::new(jac[(3, k)], jac[(4, k)], jac[(5, k)]);
                    v + w.cross(&r)
                })
                .collect()
        }
    }
}

/// Writes the gap's gradient `∇g = J_sᵀ n` of `r` into `row`, with the coordinates that
/// are not `free` zeroed (saturation rounds: they no longer move).
pub fn gap_row_into(r: &Repulsion, free: &[bool], row: &mut [f64]) {
    for ((o, c), &f) in row.iter_mut().zip(&r.jac).zip(free) {
        *o = if f { r.normal.dot(c) } else { 0.0 };
    }
}

/// `out += c f (1 − ε²/‖c‖²) / ‖c‖²`: the one-row pseudo-inverse (eq. 8) of the projected
/// gap row `c = P ∇g` applied to the ask `f`, faded out as the null space's leverage on
/// the gap, ‖c‖ (m of gap per m of elongation), falls to the singular threshold ε, and
/// nothing below it. There a step long enough to earn `f` would move the body far for
/// almost no clearance (2 mm steps earned 4 µm, and their second-order motion held the
/// gripper 0.3 mm off the pose); a damped one (`c f / λ²`) still crept along the
/// self-motion manifold at a constant rate and never settled.
pub fn add_gap_step(c: &[f64], ask: f64, threshold: f64, out: &mut [f64]) {
    let sigma2: f64 = c.iter().map(|x| x * x).sum();
    let t2 = threshold * threshold;
    if ask <= 0.0 || sigma2 <= t2 {
        return;
    }
    let k = ask * (1.0 - t2 / sigma2) / sigma2;
    for (o, x) in out.iter_mut().zip(c) {
        *o += k * x;
    }
}

/// The multi-row form of [`add_gap_step`], for the nearly tied pieces of one obstacle:
/// `rows` holds m projected gap rows `b_k = √w_k c_k` (row-major, m × n with n =
/// `out.len()`), `asks` their weighted asks `√w_k f_k`. With the Gram matrix
/// `B Bᵀ = U Λ Uᵀ`, `out += Bᵀ U h(Λ) Uᵀ y` with `h(λ) = (1 − ε²/λ)/λ` above ε² and 0
/// below: the pseudo-inverse of B applied to the asks, each singular direction faded as
/// [`add_gap_step`] fades its one row (which it equals for m = 1). Where the rows are
/// independent and well above ε, every piece's gap grows by its own ask, so that raising
/// one never closes another; a row of small weight has a small singular value and fades
/// in continuously (h is continuous and 0 below ε²), so no row switches in or out.
pub fn add_rows_step(rows: &[f64], asks: &[f64], threshold: f64, out: &mut [f64]) {
    let (m, n) = (asks.len(), out.len());
    if m == 1 {
        add_gap_step(&rows[..n], asks[0], threshold, out);
        return;
    }
    if m == 0 || asks.iter().all(|f| *f <= 0.0) {
        return;
    }
    let row = |k: usize| &rows[k * n..(k + 1) * n];
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let gram = DMatrix::from_fn(m, m, |i, j| dot(row(i), row(j)));
    let t2 = threshold * threshold;
    let asks = leveraged_asks(&gram, asks, t2);
    let eig = gram.symmetric_eigen();
    let mut z = eig.eigenvectors.transpose() * asks;
    for (zi, &l) in z.iter_mut().zip(eig.eigenvalues.iter()) {
        *zi *= if l > t2 { (1.0 - t2 / l) / l } else { 0.0 };
    }
    let z = &eig.eigenvectors * z;
    for (k, zk) in z.iter().enumerate() {
        for (o, x) in out.iter_mut().zip(row(k)) {
            *o += zk * x;
        }
    }
}

/// The asks of [`add_rows_step`], with the ask of a row the null space has no leverage
/// on (`‖b_k‖ ≤ ε`) taken out where another row has some: `y_k (1 − (1 − ψ_k) o_k)`, with
/// `ψ_k = clamp(‖b_k‖²/ε² − 1, 0, 1)` (0 up to ε, 1 from √2 ε on) and
/// `o_k = max_{j≠k} min(1, ‖b_j‖²/ε²)`. Without it such a row's ask leaked through a nearly
/// parallel row with leverage: the Gram matrix's large eigenvector mixes the two
/// (`u ≈ (‖b_k‖/‖b_j‖, 1)`), so the step raised the other piece, which asked nothing, by
/// `‖b_k‖/‖b_j‖` of the ask, for `‖b_k‖` of clearance per metre of motion, below ε: the
/// body crept on (seed 36 case 119 of the repulsion test: 5–40 µm per step, growing, for
/// 0.01 µm of clearance). A lone row, or rows all with leverage above √2 ε, keep their
/// asks; the asks are continuous as rows enter and leave.
fn leveraged_asks(gram: &DMatrix<f64>, asks: &[f64], t2: f64) -> nalgebra::DVector<f64> {
    let m = asks.len();
    let level = |k: usize| {
        if t2 > 0.0 {
            gram[(k, k)] / t2
        } else {
            f64::INFINITY
        }
    };
    nalgebra::DVector::from_fn(m, |k, _| {
        let own = (level(k) - 1.0).clamp(0.0, 1.0);
        let others = (0..m)
            .filter(|&j| j != k)
            .map(|j| level(j).min(1.0))
            .fold(0.0, f64::max);
        asks[k] * (1.0 - (1.0 - own) * others)
    })
}

/// How far (m) the repulsion's step may move the gripper, per metre of clearance it earns
/// to first order ([`step_fraction`]). The step lies in the tasks' null space, so the
/// gripper moves only by its second-order terms, ∝ t²; the tasks then take that motion
/// back, and their correction moves the body too. A 2 mm step earning 0.13 mm of gap
/// moved the gripper 0.1 mm: the correction took the gap back, and the pair cycled with
/// period 2 and the gripper 0.3 mm off the pose.
const DRIFT_PER_GAIN: f64 = 0.1;

/// The largest fraction t of a step whose gripper motion at t = 1 is `drift` (m, second
/// order, so t² `drift` at t) and whose first-order gap gain is `slope`:
/// t² drift ≤ [`DRIFT_PER_GAIN`] · t · slope.
pub fn fraction_for_drift(slope: f64, drift: f64) -> f64 {
    if drift <= 0.0 {
        return 1.0;
    }
    (DRIFT_PER_GAIN * slope.max(0.0) / drift).min(1.0)
}

/// The fraction of the repulsion step `a` (its part of the increment) to take from `q`
/// ([`fraction_for_drift`], with the largest first-order gain among the obstacles of
/// `reps`, each obstacle's the mean of its pieces' weighted by [`tie_weight`]):
/// the step is tried on the model, clamped into the limits, in `trial`. `tip` is the
/// gripper's position at `q` where the position is a task (else 1: a null space without
/// the position task moves the gripper at first order, on purpose).
pub fn step_fraction<K: Kinematics + ?Sized>(
    arm: &K,
    q: &[f64],
    a: &[f64],
    (reps, tip): (&[Repulsion], Option<&Vec3>),
    trial: &mut [f64],
) -> f64 {
    let Some(tip) = tip else {
        return 1.0;
    };
    if reps.is_empty() || a.iter().all(|x| *x == 0.0) {
        return 1.0;
    }
    let (mut gain, mut sum, mut weights) = (0.0_f64, 0.0, 0.0);
    for (i, r) in reps.iter().enumerate() {
        let g: f64 = r.jac.iter().zip(a).map(|(c, x)| r.normal.dot(c) * x).sum();
        sum += r.weight * g;
        weights += r.weight;
        if reps
            .get(i + 1)
            .is_none_or(|next| next.obstacle != r.obstacle)
        {
            gain = gain.max(sum / weights);
            (sum, weights) = (0.0, 0.0);
        }
    }
    let (lower, upper) = (arm.lower(), arm.upper());
    for k in 0..q.len() {
        trial[k] = (q[k] + a[k]).clamp(lower[k], upper[k]);
    }
    let drift = (forward_unchecked(arm, trial).pos - tip).norm();
    fraction_for_drift(gain, drift)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn random_matrix(rng: &mut StdRng, rows: usize, cols: usize) -> DMatrix<f64> {
        DMatrix::from_fn(rows, cols, |_, _| rng.random_range(-1.0..1.0))
    }

    /// `I − A⁺A` for a random 5×9 task Jacobian (position and two orientation rows of
    /// eq. 20).
    fn null_projector(rng: &mut StdRng) -> DMatrix<f64> {
        let a = random_matrix(rng, 5, 9);
        let Ok(pinv) = a.clone().pseudo_inverse(1e-12) else {
            panic!("the SVD of a 5×9 matrix");
        };
        DMatrix::identity(9, 9) - pinv * a
    }

    /// The mechanism of issue 27 item 1: projected onto the tasks' null space, the
    /// pseudo-inverse push `P J_s⁺ (f n)` of eq. (8)–(9) takes the gap DOWN to first order
    /// for some arms and obstacles; the gap's own row `P ∇g` never does, and earns the
    /// ask wherever the null space has leverage on the gap.
    #[test]
    fn the_projected_push_can_close_the_gap_and_the_gap_row_cannot() {
        let mut rng = StdRng::seed_from_u64(27);
        let ask = 1e-3;
        let mut closing = 0;
        for _ in 0..500 {
            let p = null_projector(&mut rng);
            let js = random_matrix(&mut rng, 3, 9);
            let n = DVector::from_fn(3, |_, _| rng.random_range(-1.0..1.0)).normalize();
            let grad = js.transpose() * &n;
            let Ok(js_pinv) = js.clone().pseudo_inverse(1e-12) else {
                panic!("the SVD of a 3×9 matrix");
            };
            let old = &p * js_pinv * (&n * ask);
            if grad.dot(&old) < -1e-12 {
                closing += 1;
            }
            let c: Vec<f64> = (&p * &grad).iter().copied().collect();
            let mut new = vec![0.0; 9];
            add_gap_step(&c, ask, 0.0, &mut new);
            let gain: f64 = grad.iter().zip(&new).map(|(g, d)| g * d).sum();
            assert!((gain - ask).abs() < 1e-9 * ask.max(1.0), "{gain}");
        }
        assert!(closing > 0, "the projected push never closed the gap");
    }

    #[test]
    fn the_step_fades_out_where_the_null_space_has_no_leverage() {
        let mut out = [0.0; 3];
        add_gap_step(&[0.03, 0.0, 0.04], 1e-3, 0.05, &mut out);
        assert_eq!(out, [0.0; 3], "‖c‖ = 0.05 is at the threshold");
        add_gap_step(&[0.06, 0.0, 0.08], 1e-3, 0.05, &mut out);
        let gain = 0.06 * out[0] + 0.08 * out[2];
        assert!(
            (gain - 0.75e-3).abs() < 1e-15,
            "{gain}: (1 − 1/4) of the ask"
        );
        let mut none = [0.0; 3];
        add_gap_step(&[1.0, 0.0, 0.0], 0.0, 0.05, &mut none);
        assert_eq!(none, [0.0; 3]);
    }

    /// The tied pieces' task: one row is `add_gap_step`; independent rows each earn their
    /// ask (raising one never closes the other); a row whose weight falls to 0 leaves the
    /// step continuously.
    #[test]
    fn tied_rows_each_earn_their_ask_and_fade_out_continuously() {
        let (a, b) = ([0.3, 0.1, -0.2, 0.0], [-0.25, 0.2, 0.1, 0.05]);
        let (mut one, mut same) = ([0.0; 4], [0.0; 4]);
        add_gap_step(&a, 1e-3, 0.05, &mut one);
        add_rows_step(&a, &[1e-3], 0.05, &mut same);
        assert_eq!(one, same);
        let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>();
        // The two rows, the second weighted by w, solved with singular threshold eps.
        let weighted = |w: f64, eps: f64| {
            let s = w.sqrt();
            let rows: Vec<f64> = a.iter().copied().chain(b.iter().map(|x| s * x)).collect();
            let mut out = [0.0; 4];
            add_rows_step(&rows, &[1e-3, s * 0.5e-3], eps, &mut out);
            out
        };
        let both = weighted(1.0, 0.0);
        assert!((dot(&a, &both) - 1e-3).abs() < 1e-12);
        assert!((dot(&b, &both) - 0.5e-3).abs() < 1e-12);
        // With the threshold, the second row's singular value falls below it before its
        // weight reaches 0: the step is then the first row's alone, and gets there
        // continuously.
        let fade = |w: f64| weighted(w, 0.05);
        let mut alone = [0.0; 4];
        add_gap_step(&a, 1e-3, 0.05, &mut alone);
        let norm = dot(&alone, &alone).sqrt();
        let off = |w: f64| {
            let x = fade(w);
            (dot(&x, &x) - 2.0 * dot(&x, &alone) + dot(&alone, &alone)).sqrt() / norm
        };
        let (o1, o2, o3) = (off(1e-2), off(1e-4), off(1e-6));
        assert!(o1 > o2 && o2 > o3 && o3 < 1e-5, "{o1} {o2} {o3}");
    }

    /// Seed 36 case 119 of the repulsion test: the nearest piece's row has no leverage
    /// (‖a‖ = 0.002, below ε) and a nearly parallel second row has leverage but asks
    /// nothing. The step is zero, as for the first row alone; it was `‖a‖/‖b‖` of the ask
    /// along b. A row with leverage between ε and √2 ε keeps its whole ask as the other row's
    /// weight falls to 0: the step tends to the lone row's.
    #[test]
    fn a_row_without_leverage_asks_nothing_through_a_parallel_one() {
        let b = [0.3, 0.1, -0.2, 0.0];
        let a: Vec<f64> = b
            .iter()
            .zip([0.0, 0.0, 0.0, 1.0])
            .map(|(x, e)| 0.005 * x + 0.001 * e)
            .collect();
        let rows: Vec<f64> = a.iter().chain(&b).copied().collect();
        let mut out = [0.0; 4];
        add_rows_step(&rows, &[1e-3, 0.0], 0.05, &mut out);
        assert_eq!(out, [0.0; 4]);
        let a = [0.0, 0.03, 0.0, 0.05]; // ‖a‖ = 0.058, between ε and √2 ε
        let mut alone = [0.0; 4];
        add_gap_step(&a, 1e-3, 0.05, &mut alone);
        let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let off = |w: f64| {
            let s = w.sqrt();
            let rows: Vec<f64> = a.iter().copied().chain(b.iter().map(|x| s * x)).collect();
            let mut out = [0.0; 4];
            add_rows_step(&rows, &[1e-3, 0.0], 0.05, &mut out);
            let d: Vec<f64> = out.iter().zip(&alone).map(|(x, y)| x - y).collect();
            norm(&d) / norm(&alone)
        };
        let (o1, o2, o3) = (off(1e-2), off(1e-4), off(1e-6));
        assert!(o1 > o2 && o2 > o3 && o3 < 1e-4, "{o1} {o2} {o3}");
    }

    #[test]
    fn a_step_that_moves_the_gripper_more_than_it_earns_is_cut() {
        // 0.1 mm of gripper motion (second order) against 0.13 mm of gap: t = 0.13.
        let t = fraction_for_drift(0.13e-3, 0.1e-3);
        assert!((t - 0.13).abs() < 1e-12, "{t}");
        assert!((t * t * 0.1e-3) <= DRIFT_PER_GAIN * t * 0.13e-3 + 1e-18);
        assert_eq!(fraction_for_drift(2e-3, 1e-6), 1.0);
        assert_eq!(fraction_for_drift(-1e-3, 1e-6), 0.0);
        assert_eq!(fraction_for_drift(0.0, 0.0), 1.0);
    }
}
