//! Distance queries against independent references: dense 2-D sampling of (s, u) with
//! local grid refinement for curves, brute force for clouds, dense arc sampling for meshes.

use rand::{rngs::StdRng, Rng, SeedableRng};
use softarm_core::distance::{
    closest, closest_arc_curve, LocalArc, Obstacle, PlacedArc, PointCloud, PolynomialCurve,
    Segment, TriangleMesh,
};
use softarm_core::{ArcChain, ArcParams, Error, Frame, Kinematics, Mat3, SoftArm, Vec3};

fn random_rotation(rng: &mut StdRng) -> Mat3 {
    let axis = Vec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let angle = rng.random_range(0.0..std::f64::consts::PI);
    nalgebra::Rotation3::from_scaled_axis(axis.normalize() * angle).into_inner()
}

fn random_arc(rng: &mut StdRng) -> PlacedArc {
    let length = rng.random_range(0.2..1.5);
    let bend = match rng.random_range(0..10) {
        0 => 0.0,
        1 => 1e-9,
        2 => rng.random_range(3.0..6.0),
        _ => rng.random_range(0.0..std::f64::consts::PI),
    };
    let dir = rng.random_range(-3.2..3.2);
    let frame = Frame {
        rot: random_rotation(rng),
        pos: Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ),
    };
    PlacedArc::new(frame, ArcParams::from_polar(length, bend, dir))
}

/// A random curve of degree 1..=4 passing near a random point of the arc.
fn random_curve(rng: &mut StdRng, arc: &PlacedArc) -> PolynomialCurve {
    let degree = rng.random_range(1..=4);
    let u_min = rng.random_range(-2.0..0.5);
    let u_max = u_min + rng.random_range(0.3..3.0);
    let mut coeffs: Vec<Vec3> = (0..=degree)
        .map(|k| {
            let scale = 1.0 / (1.0 + k as f64);
            Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            ) * scale
        })
        .collect();
    // Shift so that F(u0) lies within 0.3 m of the arc point at a random s.
    let u0 = rng.random_range(u_min..u_max);
    let target = arc.point(rng.random_range(0.0..1.0))
        + Vec3::new(
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.3..0.3),
        );
    let f0 = PolynomialCurve::new(&coeffs, (u_min, u_max))
        .unwrap()
        .eval(u0);
    coeffs[0] += target - f0;
    PolynomialCurve::new(&coeffs, (u_min, u_max)).unwrap()
}

/// Dense (s, u) sampling, then repeated local grid refinement around the best cells.
fn reference(arc: &PlacedArc, curve: &PolynomialCurve, ns: usize, nu: usize) -> f64 {
    let (u0, u1) = curve.u_range();
    let d = |s: f64, u: f64| (arc.point(s) - curve.eval(u)).norm();
    let mut cand: Vec<(f64, f64, f64)> = Vec::with_capacity(ns * nu);
    for i in 0..=ns {
        let s = i as f64 / ns as f64;
        for j in 0..=nu {
            let u = u0 + (u1 - u0) * j as f64 / nu as f64;
            cand.push((d(s, u), s, u));
        }
    }
    cand.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = f64::INFINITY;
    for &(_, mut s, mut u) in cand.iter().take(12) {
        let (mut hs, mut hu) = (1.0 / ns as f64, (u1 - u0) / nu as f64);
        for _ in 0..24 {
            let mut b = (d(s, u), s, u);
            for a in -5..=5 {
                for c in -5..=5 {
                    let ss = (s + hs * a as f64 / 5.0).clamp(0.0, 1.0);
                    let uu = (u + hu * c as f64 / 5.0).clamp(u0, u1);
                    let v = d(ss, uu);
                    if v < b.0 {
                        b = (v, ss, uu);
                    }
                }
            }
            s = b.1;
            u = b.2;
            hs *= 0.4;
            hu *= 0.4;
        }
        best = best.min(d(s, u));
    }
    best
}

fn check_hit(arc: &PlacedArc, curve: &PolynomialCurve) -> f64 {
    let hit = closest_arc_curve(arc, curve);
    // The reported pair is a real pair at the reported parameters.
    assert!((0.0..=1.0).contains(&hit.s));
    let (u0, u1) = curve.u_range();
    assert!(hit.u >= u0 && hit.u <= u1);
    assert!((hit.arc_point - arc.point(hit.s)).norm() < 1e-12);
    assert!((hit.curve_point - curve.eval(hit.u)).norm() < 1e-12);
    assert!((hit.distance - (hit.arc_point - hit.curve_point).norm()).abs() < 1e-12);
    hit.distance
}

#[test]
fn arc_curve_matches_dense_sampling_on_random_cases() {
    let mut rng = StdRng::seed_from_u64(7);
    let cases = if cfg!(debug_assertions) { 300 } else { 3000 };
    let mut worst: f64 = 0.0;
    for case in 0..cases {
        let arc = random_arc(&mut rng);
        let curve = random_curve(&mut rng, &arc);
        let got = check_hit(&arc, &curve);
        let want = reference(&arc, &curve, 60, 120);
        worst = worst.max(got - want);
        assert!(
            got <= want + 1e-9,
            "case {case}: exact {got} > reference {want} (arc {:?}, curve {:?})",
            arc.arc.params,
            curve
        );
    }
    assert!(worst <= 1e-9, "worst excess {worst}");
}

#[test]
fn point_to_arc_is_exact() {
    let mut rng = StdRng::seed_from_u64(3);
    for _ in 0..2000 {
        let arc = random_arc(&mut rng);
        let x = arc.point(rng.random_range(0.0..1.0))
            + Vec3::new(
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
            );
        let (s, p, d) = arc.closest_to_point(&x);
        assert!((p - arc.point(s)).norm() < 1e-12);
        // Dense sampling plus golden-section refinement around the best sample.
        let n = 2000;
        let f = |s: f64| (arc.point(s) - x).norm();
        let k = (0..=n)
            .min_by(|&a, &b| f(a as f64 / n as f64).total_cmp(&f(b as f64 / n as f64)))
            .unwrap();
        let (mut a, mut b) = (
            ((k as f64) - 1.0).max(0.0) / n as f64,
            ((k as f64) + 1.0).min(n as f64) / n as f64,
        );
        for _ in 0..80 {
            let (m1, m2) = (a + (b - a) / 3.0, b - (b - a) / 3.0);
            if f(m1) < f(m2) {
                b = m2
            } else {
                a = m1
            }
        }
        let want = f(0.5 * (a + b)).min(f(0.0)).min(f(1.0));
        assert!((d - want).abs() < 1e-9, "{d} vs {want}");
    }
}

#[test]
fn straight_arc_and_parallel_line() {
    // Straight arc along z from the origin; a line parallel to it at distance 0.3.
    let arc = PlacedArc::new(Frame::identity(), ArcParams::from_polar(1.0, 0.0, 0.0));
    let line = PolynomialCurve::new(
        &[Vec3::new(0.3, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
        (-1.0, 2.0),
    )
    .unwrap();
    assert!((check_hit(&arc, &line) - 0.3).abs() < 1e-12);
    // Beyond the tip: the pair is the arc's tip and the line's nearest point.
    let line = PolynomialCurve::new(
        &[Vec3::new(0.3, 0.0, 1.5), Vec3::new(0.0, 0.0, 1.0)],
        (0.0, 1.0),
    )
    .unwrap();
    let want = (0.3f64 * 0.3 + 0.5 * 0.5).sqrt();
    assert!((check_hit(&arc, &line) - want).abs() < 1e-12);
}

#[test]
fn crossing_and_touching_curves_give_zero() {
    let mut rng = StdRng::seed_from_u64(11);
    for _ in 0..500 {
        let arc = random_arc(&mut rng);
        let s0 = rng.random_range(0.0..1.0);
        let p0 = arc.point(s0);
        // A parabola through p0 (crossing), and one tangent to the arc at p0 (touching).
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let w = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let crossing = PolynomialCurve::new(&[p0, v, w], (-1.0, 1.0)).unwrap();
        assert!(check_hit(&arc, &crossing) < 1e-9);
        let h = 1e-6;
        let tangent = (arc.point((s0 + h).min(1.0)) - arc.point((s0 - h).max(0.0))).normalize();
        let touching = PolynomialCurve::new(&[p0, tangent, w], (-1.0, 1.0)).unwrap();
        assert!(check_hit(&arc, &touching) < 1e-9);
    }
}

#[test]
fn chain_closest_is_the_minimum_over_sections() {
    let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap();
    let q = [1.0, 0.4, 0.3, 1.1, -0.6, 1.0, 0.9, 0.8, -2.0];
    let curve = PolynomialCurve::new(
        &[
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 5.0),
        ],
        (-2.0, 2.0),
    )
    .unwrap();
    let c = closest(&chain, &q, &Obstacle::Curve(curve.clone())).unwrap();
    let (p, _) = chain.point(&q, c.section, c.s).unwrap();
    assert!((p - c.arm_point).norm() < 1e-12);
    assert!((curve.eval(c.u) - c.obstacle_point).norm() < 1e-12);
    // Dense check over the whole backbone.
    let pts = chain.backbone(&q, 400).unwrap();
    let mut dense = f64::INFINITY;
    for x in &pts {
        for j in 0..=2000 {
            let u = -2.0 + 4.0 * j as f64 / 2000.0;
            dense = dense.min((curve.eval(u) - x).norm());
        }
    }
    assert!(c.distance <= dense + 1e-12 && c.distance > dense - 0.01);
}

#[test]
fn segment_point_and_cloud_agree_with_brute_force() {
    let mut rng = StdRng::seed_from_u64(5);
    let arm = SoftArm::blackberry();
    for _ in 0..50 {
        let q: Vec<f64> = arm
            .lower()
            .iter()
            .zip(arm.upper())
            .map(|(l, u)| rng.random_range(*l..*u))
            .collect();
        let pts: Vec<Vec3> = (0..3000)
            .map(|_| {
                Vec3::new(
                    rng.random_range(-0.4..0.4),
                    rng.random_range(-0.4..0.4),
                    rng.random_range(0.0..0.7),
                )
            })
            .collect();
        let cloud = PointCloud::new(pts.clone()).unwrap();
        let c = closest(&arm, &q, &Obstacle::Cloud(cloud)).unwrap();
        let mut brute = f64::INFINITY;
        for (k, p) in pts.iter().enumerate() {
            let d = closest(&arm, &q, &Obstacle::Point(*p)).unwrap();
            if d.distance < brute {
                brute = d.distance;
                if k == c.u as usize {
                    assert_eq!(d.distance, c.distance);
                }
            }
        }
        assert!(
            (c.distance - brute).abs() < 1e-12,
            "{} vs {brute}",
            c.distance
        );
        assert_eq!(pts[c.u as usize], c.obstacle_point);
        // A segment equals the degree-1 curve and the dense reference.
        let (a, b) = (pts[0], pts[1]);
        let seg = Segment::new(a, b).unwrap();
        let s = closest(&arm, &q, &Obstacle::Segment(seg)).unwrap();
        assert!((s.obstacle_point - (a + (b - a) * s.u)).norm() < 1e-12);
    }
}

#[test]
fn mesh_distance_is_conservative_within_its_bound() {
    let tol = 1e-4;
    // A unit square in the plane z = 1.2 with a 0.2 m hole-free tessellation.
    let mut verts = Vec::new();
    let mut tris = Vec::new();
    let n = 10u32;
    for i in 0..=n {
        for j in 0..=n {
            verts.push(Vec3::new(
                0.2 + 0.1 * i as f64,
                -0.5 + 0.1 * j as f64,
                1.2 + 0.05 * (i as f64),
            ));
        }
    }
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            tris.push([a, a + 1, a + n + 1]);
            tris.push([a + 1, a + n + 2, a + n + 1]);
        }
    }
    let mesh = TriangleMesh::new(&verts, &tris, tol).unwrap();
    let mut rng = StdRng::seed_from_u64(9);
    for _ in 0..30 {
        let arc = PlacedArc::new(
            Frame::identity(),
            ArcParams::from_polar(
                rng.random_range(0.8..1.5),
                rng.random_range(0.0..2.0),
                rng.random_range(-3.0..3.0),
            ),
        );
        let hit = mesh.closest_to_arc(&arc);
        let mut dense = f64::INFINITY;
        for k in 0..=4000 {
            dense = dense.min(mesh.closest_to_point(&arc.point(k as f64 / 4000.0)).0);
        }
        assert!(hit.distance <= dense + 1e-12, "{} > {dense}", hit.distance);
        assert!(
            hit.distance >= dense - 2.0 * tol - 1e-6,
            "{} << {dense}",
            hit.distance
        );
    }
}

#[test]
fn chord_error_bounds_the_chords() {
    let arc = LocalArc::new(ArcParams::from_polar(1.0, 2.0, 0.3));
    for k in [1usize, 2, 5, 17] {
        let e = arc.chord_error(k);
        let mut worst: f64 = 0.0;
        for i in 0..k {
            let (a, b) = (
                arc.params.point(i as f64 / k as f64),
                arc.params.point((i + 1) as f64 / k as f64),
            );
            for j in 0..=100 {
                let s = (i as f64 + j as f64 / 100.0) / k as f64;
                let p = arc.params.point(s);
                let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                worst = worst.max((p - (a + (b - a) * t)).norm());
            }
        }
        assert!(worst <= e + 1e-12 && worst > 0.99 * e, "{worst} vs {e}");
    }
}

#[test]
fn bad_input_gets_typed_errors() {
    let c = |v: &[Vec3], r| PolynomialCurve::new(v, r);
    let one = [Vec3::new(1.0, 0.0, 0.0)];
    assert!(
        matches!(c(&one, (1.0, 1.0)), Err(Error::Parameter { ref arg, .. }) if arg == "u_range")
    );
    assert!(matches!(c(&one, (2.0, 1.0)), Err(Error::Parameter { .. })));
    assert!(
        matches!(c(&one, (f64::NAN, 1.0)), Err(Error::NonFinite { ref arg, .. }) if arg == "u_range")
    );
    assert!(
        matches!(c(&[Vec3::new(f64::NAN, 0.0, 0.0)], (0.0, 1.0)), Err(Error::NonFinite { ref arg, .. }) if arg == "coeffs")
    );
    assert!(matches!(c(&[], (0.0, 1.0)), Err(Error::Shape { .. })));
    assert!(matches!(
        PolynomialCurve::from_rows(&[1.0, 2.0], (0.0, 1.0)),
        Err(Error::Shape { .. })
    ));
    assert!(
        matches!(PointCloud::new(vec![]), Err(Error::Shape { ref arg, .. }) if arg == "points")
    );
    assert!(matches!(
        PointCloud::new(vec![Vec3::new(0.0, f64::INFINITY, 0.0)]),
        Err(Error::NonFinite { index: 1, .. })
    ));
    assert!(
        matches!(Segment::new(Vec3::zeros(), Vec3::new(f64::NAN, 0.0, 0.0)), Err(Error::NonFinite { ref arg, .. }) if arg == "b")
    );
    assert!(matches!(
        TriangleMesh::new(&[Vec3::zeros()], &[[0, 1, 2]], 1e-3),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        TriangleMesh::new(&[Vec3::zeros()], &[], 1e-3),
        Err(Error::Shape { .. })
    ));
    let chain = ArcChain::new(&[1.0]).unwrap();
    assert!(matches!(
        closest(&chain, &[1.0, 0.0], &Obstacle::Point(Vec3::zeros())),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        closest(
            &chain,
            &[1.0, f64::NAN, 0.0],
            &Obstacle::Point(Vec3::zeros())
        ),
        Err(Error::NonFinite { .. })
    ));
}
