//! The kinematics' hot loop (issue 40 item 6) pinned against the implementation it
//! replaced: `old` below is a verbatim copy of that code (commit 7ac15dc: the arc
//! functions' 6-term Horner series below x = 0.25 and closed forms above, the section's
//! arc through eq. (1)'s divisions, and the sweep that rotated each column's twist).
//! Poses and points must agree to 1e-12 (m, rotation entries) and Jacobian entries to
//! 1e-12 relative (they reach 40 per m of elongation), over random configurations inside
//! and beyond the limits, straight sections and both series' switches. The largest
//! differences (3e-14 relative, in Jacobians with a section bent near 0.5 rad) are the old
//! 6-term series' own error just below its switch at x = 0.25 (4e-14 in `sin t / t`
//! against an exact evaluation; the 11-term series now used is within 1e-16).

use nalgebra::{DMatrix, Matrix3xX};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use softarm_core::chain::{
    forward_jacobian_into, forward_unchecked, point_unchecked, SectionModel, SectionState,
};
use softarm_core::{ArcChain, Frame, Kinematics, SoftArm, Vec3};

/// The replaced implementation, copied unchanged apart from being free functions.
mod old {
    use nalgebra::{DMatrix, Matrix3xX};
    use softarm_core::arc::ArcParams;
    use softarm_core::chain::SectionState;
    use softarm_core::pneumatic::{arc_params, arc_params_jacobian};
    use softarm_core::{Frame, Mat3, SoftArm, Vec3};

    pub struct Fns {
        f1: f64,
        f2: f64,
        f3: f64,
        g1: f64,
        g2: f64,
    }

    pub fn f1_f2(x: f64) -> (f64, f64) {
        if x < 0.25 {
            let f1 = 1.0
                + x * (-1.0 / 6.0
                    + x * (1.0 / 120.0
                        + x * (-1.0 / 5040.0 + x * (1.0 / 362_880.0 - x / 39_916_800.0))));
            let f2 = 0.5
                + x * (-1.0 / 24.0
                    + x * (1.0 / 720.0
                        + x * (-1.0 / 40_320.0 + x * (1.0 / 3_628_800.0 - x / 479_001_600.0))));
            (f1, f2)
        } else {
            let t = x.sqrt();
            let (s, c) = t.sin_cos();
            (s / t, (1.0 - c) / x)
        }
    }

    pub fn fns(x: f64) -> Fns {
        if x < 0.25 {
            let (f1, f2) = f1_f2(x);
            let f3 = 1.0 / 6.0
                + x * (-1.0 / 120.0
                    + x * (1.0 / 5040.0
                        + x * (-1.0 / 362_880.0 + x * (1.0 / 39_916_800.0 - x / 6_227_020_800.0))));
            let g1 = -1.0 / 6.0
                + x * (2.0 / 120.0
                    + x * (-3.0 / 5040.0
                        + x * (4.0 / 362_880.0
                            + x * (-5.0 / 39_916_800.0 + 6.0 * x / 6_227_020_800.0))));
            let g2 = -1.0 / 24.0
                + x * (2.0 / 720.0
                    + x * (-3.0 / 40_320.0
                        + x * (4.0 / 3_628_800.0
                            + x * (-5.0 / 479_001_600.0 + 6.0 * x / 87_178_291_200.0))));
            Fns { f1, f2, f3, g1, g2 }
        } else {
            let t = x.sqrt();
            let (s, c) = t.sin_cos();
            Fns {
                f1: s / t,
                f2: (1.0 - c) / x,
                f3: (t - s) / (x * t),
                g1: (t * c - s) / (2.0 * x * t),
                g2: (t * s - 2.0 * (1.0 - c)) / (2.0 * x * x),
            }
        }
    }

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

    pub fn frame(a: &ArcParams, s: f64) -> Frame {
        let (wx, wy) = (-a.uy * s, a.ux * s);
        let (f1, f2) = f1_f2(wx * wx + wy * wy);
        let ls = a.length * s;
        Frame {
            rot: rodrigues(wx, wy, f1, f2),
            pos: Vec3::new(ls * f2 * wy, -ls * f2 * wx, ls * f1),
        }
    }

    /// Position at `s` and its derivatives with respect to (L, ux, uy).
    pub fn point_with_derivatives(a: &ArcParams, s: f64, f: &Fns) -> (Vec3, Mat3) {
        let (ux, uy, l) = (a.ux, a.uy, a.length);
        let s2 = s * s;
        let pos = Vec3::new(l * s2 * f.f2 * ux, l * s2 * f.f2 * uy, l * s * f.f1);
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
        (pos, Mat3::from_columns(&[d_l, d_ux, d_uy]))
    }

    pub fn frame_with_derivatives(a: &ArcParams, s: f64) -> (Frame, Mat3, Mat3) {
        let (wx, wy) = (-a.uy * s, a.ux * s);
        let f = fns(wx * wx + wy * wy);
        let (pos, d_pos) = point_with_derivatives(a, s, &f);
        let rot = rodrigues(wx, wy, f.f1, f.f2);
        let jl0 = Vec3::new(1.0 - f.f3 * wy * wy, f.f3 * wx * wy, -f.f2 * wy);
        let jl1 = Vec3::new(f.f3 * wx * wy, 1.0 - f.f3 * wx * wx, f.f2 * wx);
        let d_rot = Mat3::from_columns(&[Vec3::zeros(), jl1 * s, -jl0 * s]);
        (Frame { rot, pos }, d_pos, d_rot)
    }

    fn tip_then_tail(st: &SectionState, tip: &Frame) -> Frame {
        let (c, s) = st.twist;
        let (r0, r1, r2) = (tip.rot.column(0), tip.rot.column(1), tip.rot.column(2));
        Frame {
            rot: Mat3::from_columns(&[r0 * c + r1 * s, r1 * c - r0 * s, r2.into_owned()]),
            pos: tip.pos + r2 * st.offset,
        }
    }

    /// The section state of the replaced `SoftArm::section_state` (eq. 1 with divisions).
    pub fn arm_state(arm: &SoftArm, q: &[f64], i: usize) -> SectionState {
        let s = &arm.sections()[i];
        SectionState {
            arc: arc_params(s.radius, s.rest_length, &q[3 * i..3 * i + 3]),
            d_arc: arc_params_jacobian(s.radius),
            offset: s.offset,
            twist: (s.twist.cos(), s.twist.sin()),
            d_twist: Vec3::zeros(),
        }
    }

    pub fn forward(n: usize, state: &dyn Fn(usize) -> SectionState) -> Frame {
        let mut f = Frame::identity();
        for i in 0..n {
            let st = state(i);
            f = f.compose(&tip_then_tail(&st, &frame(&st.arc, 1.0)));
        }
        f
    }

    fn sweep(upto: usize, state: &dyn Fn(usize) -> SectionState, jac: &mut DMatrix<f64>) -> Frame {
        let mut f = Frame::identity();
        for i in 0..upto {
            let st = state(i);
            let (tip, d_pos, d_rot) = frame_with_derivatives(&st.arc, 1.0);
            let v_local = d_pos * st.d_arc;
            let z_tip = tip.rot.column(2).into_owned();
            let w_local = d_rot * st.d_arc + z_tip * st.d_twist.transpose();
            let p_tip = f.pos + f.rot * tip.pos;
            for k in 0..3 {
                let w = f.rot * w_local.column(k);
                let v = f.rot * v_local.column(k) - w.cross(&p_tip);
                let col = 3 * i + k;
                jac.fixed_view_mut::<3, 1>(0, col).copy_from(&v);
                jac.fixed_view_mut::<3, 1>(3, col).copy_from(&w);
            }
            f = f.compose(&tip_then_tail(&st, &tip));
        }
        f
    }

    pub fn forward_jacobian(
        n: usize,
        state: &dyn Fn(usize) -> SectionState,
    ) -> (Frame, DMatrix<f64>) {
        let mut jac = DMatrix::zeros(6, 3 * n);
        let f = sweep(n, state, &mut jac);
        for col in 0..jac.ncols() {
            let w = jac.fixed_view::<3, 1>(3, col).into_owned();
            let mut v = jac.fixed_view_mut::<3, 1>(0, col);
            v += w.cross(&f.pos);
        }
        (f, jac)
    }

    pub fn point(
        n: usize,
        state: &dyn Fn(usize) -> SectionState,
        section: usize,
        s: f64,
    ) -> (Vec3, Matrix3xX<f64>) {
        let mut twists = DMatrix::zeros(6, 3 * n);
        let f = sweep(section, state, &mut twists);
        let st = state(section);
        let (wx, wy) = (-st.arc.uy * s, st.arc.ux * s);
        let (pos, d_params) = point_with_derivatives(&st.arc, s, &fns(wx * wx + wy * wy));
        let point = f.pos + f.rot * pos;
        let mut jac = Matrix3xX::zeros(3 * n);
        for col in 0..3 * section {
            let v = twists.fixed_view::<3, 1>(0, col);
            let w = twists.fixed_view::<3, 1>(3, col);
            jac.set_column(col, &(v + w.cross(&point)));
        }
        let own = f.rot * d_params * st.d_arc;
        jac.fixed_view_mut::<3, 3>(0, 3 * section).copy_from(&own);
        (point, jac)
    }
}

const TOL: f64 = 1e-12;

fn max_frame_diff(a: &Frame, b: &Frame) -> f64 {
    (a.rot - b.rot).amax().max((a.pos - b.pos).amax())
}

/// Largest `|a − b|` over a column divided by `max(1, largest |b| in that column)`: a
/// Jacobian's columns are derivatives of one pose by one elongation, and for the
/// blackberry arm their entries reach 40 (rad or m per m), so 1e-12 relative to the
/// column's scale; entries of a column under 1 in scale are held to 1e-12 absolute.
fn max_column_diff(a: &[f64], b: &[f64], rows: usize) -> f64 {
    a.chunks(rows)
        .zip(b.chunks(rows))
        .map(|(ca, cb)| {
            let diff = ca
                .iter()
                .zip(cb)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            diff / cb.iter().map(|y| y.abs()).fold(1.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// Forward, Jacobian and three backbone points of `model` at `q` against the old code:
/// the largest difference, Jacobians' scaled as [`max_column_diff`].
fn compare<M: SectionModel>(model: &M, q: &[f64], state: &dyn Fn(usize) -> SectionState) -> f64 {
    let n = model.n_sections();
    let mut worst = max_frame_diff(&forward_unchecked(model, q), &old::forward(n, state));
    let mut jac = DMatrix::zeros(6, 3 * n);
    let f = forward_jacobian_into(model, q, &mut jac);
    let (f_old, jac_old) = old::forward_jacobian(n, state);
    worst = worst.max(max_frame_diff(&f, &f_old)).max(max_column_diff(
        jac.as_slice(),
        jac_old.as_slice(),
        6,
    ));
    for (section, s) in [(0, 0.3), (n / 2, 0.7), (n - 1, 1.0)] {
        let (p, pj): (Vec3, Matrix3xX<f64>) = point_unchecked(model, q, section, s);
        let (p_old, pj_old) = old::point(n, state, section, s);
        worst =
            worst
                .max((p - p_old).amax())
                .max(max_column_diff(pj.as_slice(), pj_old.as_slice(), 3));
    }
    worst
}

fn arm_worst(arm: &SoftArm, q: &[f64]) -> f64 {
    compare(arm, q, &|i| old::arm_state(arm, q, i))
}

#[test]
fn soft_arm_matches_the_replaced_code_inside_and_beyond_its_limits() {
    let arm = SoftArm::blackberry();
    let mut rng = StdRng::seed_from_u64(40);
    let (lo, hi) = (arm.lower().to_vec(), arm.upper().to_vec());
    let mut worst: f64 = 0.0;
    for case in 0..4000 {
        // Half inside the limits, half up to twice the range beyond them (bends past the
        // series' switch at 1.5 rad).
        let spread = if case % 2 == 0 { 0.0 } else { 1.0 };
        let q: Vec<f64> = lo
            .iter()
            .zip(&hi)
            .map(|(&l, &u)| l + (u - l) * rng.random_range(-spread..1.0 + spread))
            .collect();
        worst = worst.max(arm_worst(&arm, &q));
    }
    println!("largest difference {worst:e}");
    assert!(worst <= TOL, "largest difference {worst:e}");
}

#[test]
fn soft_arm_matches_when_straight_and_at_the_series_switches() {
    let arm = SoftArm::blackberry();
    let mut worst: f64 = 0.0;
    // Straight sections, then single-actuator bends that put x = Θ² near 0.25 and 2.25
    // in the distal section (Θ = 2 l / (3 r) for one actuator at elongation l).
    let r = arm.sections()[2].radius;
    let mut cases = vec![vec![0.0; 9], vec![0.02; 9]];
    for theta in [0.5f64, 1.5] {
        for d in [-1e-9, 0.0, 1e-9] {
            let l = 1.5 * r * (theta + d);
            cases.push(vec![0.01, 0.01, 0.01, 0.0, 0.02, 0.01, l, 0.0, 0.0]);
        }
    }
    for q in &cases {
        worst = worst.max(arm_worst(&arm, q));
    }
    println!("largest difference {worst:e}");
    assert!(worst <= TOL, "largest difference {worst:e}");
}

#[test]
fn arc_chain_matches_the_replaced_code() {
    let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap_or_else(|e| panic!("{e}"));
    let mut rng = StdRng::seed_from_u64(41);
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        let q: Vec<f64> = (0..3)
            .flat_map(|_| {
                [
                    rng.random_range(0.2..1.5),
                    rng.random_range(0.0..3.0),
                    rng.random_range(-3.2..3.2),
                ]
            })
            .collect();
        worst = worst.max(compare(&chain, &q, &|i| {
            chain.section_state(i, &q[3 * i..3 * i + 3])
        }));
    }
    println!("largest difference {worst:e}");
    assert!(worst <= TOL, "largest difference {worst:e}");
}
