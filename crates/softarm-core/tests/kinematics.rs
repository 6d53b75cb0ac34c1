//! Kinematics against hand-checked cases, the papers' literal formulas, rotation axioms
//! and central finite differences.

use approx::assert_relative_eq;
use nalgebra::{DMatrix, Matrix3, Matrix4, Vector3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use softarm_core::{ArcChain, Error, Kinematics, SoftArm};

fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(c, -s, 0., 0., s, c, 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.)
}
fn rot_y(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(c, 0., s, 0., 0., 1., 0., 0., -s, 0., c, 0., 0., 0., 0., 1.)
}
fn trans(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    let mut m = Matrix4::identity();
    m[(0, 3)] = x;
    m[(1, 3)] = y;
    m[(2, 3)] = z;
    m
}

/// Redundancy paper eq. (1)–(3) written literally (valid away from straight).
fn paper_forward(arm: &SoftArm, q: &[f64]) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    for (i, sec) in arm.sections().iter().enumerate() {
        let (l1, l2, l3) = (q[3 * i], q[3 * i + 1], q[3 * i + 2]);
        let s = (l1 * l1 + l2 * l2 + l3 * l3 - l1 * l2 - l2 * l3 - l1 * l3).sqrt();
        let phi = 2.0 * s / (3.0 * sec.radius);
        let lambda = (3.0 * sec.rest_length + l1 + l2 + l3) * sec.radius / (2.0 * s);
        let theta = (3f64.sqrt() * (l3 - l2)).atan2(l2 + l3 - 2.0 * l1);
        let ti = rot_z(theta)
            * trans(lambda, 0., 0.)
            * rot_y(phi)
            * trans(-lambda, 0., 0.)
            * rot_z(-theta);
        t = t * ti * trans(0., 0., sec.offset) * rot_z(sec.twist);
    }
    t
}

/// Planning paper eq. (2)–(4) written literally (valid for Θ ≠ 0).
fn paper_chain_forward(q: &[f64]) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    for seg in q.chunks(3) {
        let (l, th, ph) = (seg[0], seg[1], seg[2]);
        let (sp, cp, st, ct) = (ph.sin(), ph.cos(), th.sin(), th.cos());
        let r = Matrix3::new(cp * ct, -sp, cp * st, sp * ct, cp, sp * st, -st, 0., ct);
        let p = Vector3::new(
            (1. - ct) * l / th * cp,
            (1. - ct) * l / th * sp,
            st * l / th,
        );
        let mut h = Matrix4::identity();
        h.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        h.fixed_view_mut::<3, 1>(0, 3).copy_from(&p);
        t *= h;
    }
    t
}

fn random_q(rng: &mut StdRng, arm: &SoftArm) -> Vec<f64> {
    (0..9)
        .map(|i| rng.random_range(arm.lower()[i]..arm.upper()[i]))
        .collect()
}

/// Central finite-difference Jacobian of the pose, angular part via (dR Rᵀ)^∨.
fn fd_jacobian<K: Kinematics>(m: &K, q: &[f64], h: f64) -> DMatrix<f64> {
    let n = q.len();
    let t0 = m.forward(q).unwrap();
    let r0 = t0.fixed_view::<3, 3>(0, 0).into_owned();
    let mut j = DMatrix::zeros(6, n);
    for k in 0..n {
        let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
        qp[k] += h;
        qm[k] -= h;
        let (tp, tm) = (m.forward(&qp).unwrap(), m.forward(&qm).unwrap());
        let dt = (tp - tm) / (2.0 * h);
        let dr = dt.fixed_view::<3, 3>(0, 0) * r0.transpose();
        j[(0, k)] = dt[(0, 3)];
        j[(1, k)] = dt[(1, 3)];
        j[(2, k)] = dt[(2, 3)];
        j[(3, k)] = 0.5 * (dr[(2, 1)] - dr[(1, 2)]);
        j[(4, k)] = 0.5 * (dr[(0, 2)] - dr[(2, 0)]);
        j[(5, k)] = 0.5 * (dr[(1, 0)] - dr[(0, 1)]);
    }
    j
}

fn assert_orthonormal(t: &Matrix4<f64>) {
    let r = t.fixed_view::<3, 3>(0, 0).into_owned();
    assert_relative_eq!(r.transpose() * r, Matrix3::identity(), epsilon = 1e-13);
    assert_relative_eq!(r.determinant(), 1.0, epsilon = 1e-13);
    assert_eq!(
        t.row(3).into_owned(),
        nalgebra::RowVector4::new(0., 0., 0., 1.)
    );
}

#[test]
fn straight_arm_is_a_line_along_z() {
    let arm = SoftArm::blackberry();
    let t = arm.forward(&[0.0; 9]).unwrap();
    assert_relative_eq!(t[(0, 3)], 0.0, epsilon = 1e-15);
    assert_relative_eq!(t[(1, 3)], 0.0, epsilon = 1e-15);
    assert_relative_eq!(
        t[(2, 3)],
        3.0 * 0.15 + 0.012 + 0.012 + 0.060,
        epsilon = 1e-15
    );
    // Twists of 60° + 60° + 0° about z.
    let mut expect = rot_z(2.0 * std::f64::consts::FRAC_PI_3);
    expect[(2, 3)] = 0.534;
    assert_relative_eq!(t, expect, epsilon = 1e-15);
}

#[test]
fn pure_elongation_lengthens_without_bending() {
    let arm = SoftArm::blackberry();
    let d = 0.02;
    let t = arm.forward(&[d; 9]).unwrap();
    assert_relative_eq!(t[(2, 3)], 0.534 + 3.0 * d, epsilon = 1e-14);
    assert_relative_eq!(t[(0, 3)], 0.0, epsilon = 1e-15);
}

#[test]
fn one_actuator_bends_the_section_away_from_it() {
    let arm = SoftArm::blackberry();
    // Actuator 1 of section 0 sits on +x: the section bends towards −x, in the xz plane.
    let mut q = [0.0; 9];
    q[0] = 0.02;
    let f = arm.frames(&q).unwrap();
    assert!(f[1][(0, 3)] < -1e-3);
    assert_relative_eq!(f[1][(1, 3)], 0.0, epsilon = 1e-15);
    // Actuator 2 sits at 120°: the tip moves towards −60°, θ = atan2(−√3 l, l).
    let mut q = [0.0; 9];
    q[1] = 0.02;
    let f = arm.frames(&q).unwrap();
    let dir = f[1][(1, 3)].atan2(f[1][(0, 3)]);
    assert_relative_eq!(dir, -std::f64::consts::FRAC_PI_3, epsilon = 1e-12);
    // Arc geometry: bend angle Θ = 2 s / (3 r) with s = l.
    let cfg = arm.polar_configs(&q).unwrap();
    assert_relative_eq!(cfg[0].bend, 2.0 * 0.02 / (3.0 * 0.028), epsilon = 1e-14);
}

#[test]
fn matches_the_papers_literal_formulas() {
    let arm = SoftArm::blackberry();
    let mut rng = StdRng::seed_from_u64(1);
    let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap();
    for _ in 0..200 {
        let q = random_q(&mut rng, &arm);
        assert_relative_eq!(
            arm.forward(&q).unwrap(),
            paper_forward(&arm, &q),
            epsilon = 1e-12
        );
        let qc: Vec<f64> = (0..9)
            .map(|i| match i % 3 {
                0 => rng.random_range(0.6..1.4),
                1 => rng.random_range(0.05..2.5),
                _ => rng.random_range(-3.0..3.0),
            })
            .collect();
        assert_relative_eq!(
            chain.forward(&qc).unwrap(),
            paper_chain_forward(&qc),
            epsilon = 1e-12
        );
    }
}

#[test]
fn rotations_are_orthonormal() {
    let arm = SoftArm::blackberry();
    let mut rng = StdRng::seed_from_u64(2);
    for _ in 0..200 {
        let q = random_q(&mut rng, &arm);
        for f in arm.frames(&q).unwrap() {
            assert_orthonormal(&f);
        }
    }
}

#[test]
fn jacobian_matches_finite_differences_at_random_configurations() {
    let arm = SoftArm::blackberry();
    let mut rng = StdRng::seed_from_u64(3);
    for _ in 0..100 {
        let q = random_q(&mut rng, &arm);
        let j = arm.jacobian(&q).unwrap();
        assert_relative_eq!(j, fd_jacobian(&arm, &q, 1e-7), epsilon = 2e-7);
    }
}

#[test]
fn jacobian_is_exact_at_and_near_straight() {
    let arm = SoftArm::blackberry();
    let mut rng = StdRng::seed_from_u64(4);
    let base = [0.01; 9];
    let j0 = arm.jacobian(&base).unwrap();
    assert!(j0.iter().all(|v| v.is_finite()));
    // Straight is a regular point: FD straddling it agrees.
    assert_relative_eq!(j0, fd_jacobian(&arm, &base, 1e-7), epsilon = 2e-7);
    for _ in 0..50 {
        let q: Vec<f64> = base
            .iter()
            .map(|b| b + rng.random_range(-1e-9..1e-9))
            .collect();
        let j = arm.jacobian(&q).unwrap();
        // Continuity across straight: ∂J/∂q is O(1e3) here (curvature per metre of
        // elongation is 1/(3r)), so a 1e-9 step moves J by O(1e-6), no jump.
        assert_relative_eq!(j, j0, epsilon = 1e-5);
        assert_relative_eq!(j, fd_jacobian(&arm, &q, 1e-6), epsilon = 1e-6);
    }
}

#[test]
fn point_jacobian_matches_finite_differences() {
    let arm = SoftArm::blackberry();
    let mut rng = StdRng::seed_from_u64(5);
    for trial in 0..60 {
        let q = if trial == 0 {
            vec![0.0; 9]
        } else {
            random_q(&mut rng, &arm)
        };
        let section = trial % 3;
        let s = rng.random_range(0.0..=1.0);
        let (p, j) = arm.point(&q, section, s).unwrap();
        let h = 1e-7;
        for k in 0..9 {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[k] += h;
            qm[k] -= h;
            let fd = (arm.point(&qp, section, s).unwrap().0
                - arm.point(&qm, section, s).unwrap().0)
                / (2.0 * h);
            assert_relative_eq!(j.column(k).into_owned(), fd, epsilon = 2e-7);
        }
        // End of a section's arc: s = 1 of the last section, then the gripper offset.
        if section == 2 {
            let (tip, _) = arm.point(&q, 2, 1.0).unwrap();
            let t = arm.forward(&q).unwrap();
            let z = t.fixed_view::<3, 1>(0, 2).into_owned();
            let ee = t.fixed_view::<3, 1>(0, 3).into_owned();
            assert_relative_eq!(tip + 0.060 * z, ee, epsilon = 1e-12);
        }
        assert!(p.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn arc_chain_jacobians_match_finite_differences() {
    let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap();
    let mut rng = StdRng::seed_from_u64(6);
    for trial in 0..60 {
        let q: Vec<f64> = (0..9)
            .map(|i| match i % 3 {
                0 => rng.random_range(0.6..1.4),
                1 if trial < 5 => 0.0,
                1 => rng.random_range(-2.5..2.5),
                _ => rng.random_range(-3.0..3.0),
            })
            .collect();
        assert_relative_eq!(
            chain.jacobian(&q).unwrap(),
            fd_jacobian(&chain, &q, 1e-6),
            epsilon = 1e-6
        );
        let (_, j) = chain.point(&q, 1, 0.3).unwrap();
        let h = 1e-6;
        for k in 0..9 {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[k] += h;
            qm[k] -= h;
            let fd = (chain.point(&qp, 1, 0.3).unwrap().0 - chain.point(&qm, 1, 0.3).unwrap().0)
                / (2.0 * h);
            assert_relative_eq!(j.column(k).into_owned(), fd, epsilon = 1e-6);
        }
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let arm = SoftArm::blackberry();
    assert!(matches!(arm.forward(&[0.0; 8]), Err(Error::Shape { .. })));
    let mut q = [0.0; 9];
    q[4] = f64::NAN;
    assert!(matches!(
        arm.jacobian(&q),
        Err(Error::NonFinite { index: 4, .. })
    ));
    assert!(matches!(
        arm.point(&[0.0; 9], 3, 0.5),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        arm.point(&[0.0; 9], 0, 1.5),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        arm.point(&[0.0; 9], 0, f64::NAN),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        arm.backbone(&[0.0; 9], 1),
        Err(Error::OutOfRange { .. })
    ));
    assert!(softarm_core::Section::new(-0.01, 0.15, 0.0, 0.03, 0.0, 0.0).is_err());
    assert!(softarm_core::Section::new(0.01, 0.15, 0.03, 0.03, 0.0, 0.0).is_err());
    assert!(softarm_core::Section::new(0.01, 0.0, 0.0, 0.03, 0.0, 0.0).is_err());
    assert!(ArcChain::new(&[]).is_err());
    assert!(ArcChain::new(&[1.0, f64::INFINITY]).is_err());
    let msg = arm.forward(&[0.0; 8]).unwrap_err().to_string();
    assert!(msg.contains("q"), "{msg}");
}
