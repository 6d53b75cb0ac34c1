//! The potential-field planner (eq. 9) on the paper's scenarios and on the soft arm.

use softarm_core::distance::{
    closest, placed_arcs, Obstacle, PointCloud, PolynomialCurve, Segment,
};
use softarm_core::planner::scenarios::{scenario, ARM_POINTS_PER_SEGMENT, NAMES, SEGMENT_LENGTHS};
use softarm_core::planner::{clearance, path_clearance, Termination};
use softarm_core::{
    ArcChain, Error, Kinematics, PlannerOptions, PotentialFieldPlanner, SoftArm, Vec3,
};

fn chain_planner(options: PlannerOptions) -> PotentialFieldPlanner<ArcChain> {
    PotentialFieldPlanner::new(ArcChain::new(&SEGMENT_LENGTHS).unwrap(), options).unwrap()
}

#[test]
fn proposed_method_reaches_every_paper_goal_without_collision() {
    for name in NAMES {
        let sc = scenario(name).unwrap();
        let p = chain_planner(PlannerOptions::default());
        let plan = p
            .plan(&p.model().straight(), &sc.goal, &sc.curve_obstacles())
            .unwrap();
        assert!(plan.reached, "{name}: {:?}", plan.termination);
        assert_eq!(plan.termination, Termination::Reached);
        assert!((plan.tip_path.last().unwrap() - sc.goal).norm() <= 0.01);
        assert_eq!(plan.path.len(), plan.iterations + 1);
        // The recorded clearance is the exact one at every step, and the path between
        // steps (8 substeps) stays clear of the true curves too.
        let steps = path_clearance(p.model(), &plan.path, &sc.curve_obstacles(), 1).unwrap();
        assert!((steps - plan.min_clearance).abs() < 1e-12);
        let fine = path_clearance(p.model(), &plan.path, &sc.curve_obstacles(), 8).unwrap();
        assert!(fine > 0.01, "{name}: true clearance {fine}");
        // Limits are respected at every step.
        let (lo, hi) = (p.model().lower(), p.model().upper());
        for q in &plan.path {
            assert!(q.iter().zip(lo).zip(hi).all(|((v, l), h)| v >= l && v <= h));
        }
    }
}

#[test]
fn a_sparse_point_model_lets_the_arm_through_the_curve() {
    // Simulation 2: with each curve as 10 points the arm passes between them.
    let sc = scenario("curve").unwrap();
    let o = PlannerOptions {
        arm_samples: Some(ARM_POINTS_PER_SEGMENT),
        ..PlannerOptions::default()
    };
    let p = chain_planner(o);
    let plan = p
        .plan(
            &p.model().straight(),
            &sc.goal,
            &sc.point_obstacles(10).unwrap(),
        )
        .unwrap();
    let truth = path_clearance(p.model(), &plan.path, &sc.curve_obstacles(), 8).unwrap();
    assert!(truth < 0.01, "true clearance {truth}");
}

#[test]
fn clearance_is_never_negative_and_matches_closest() {
    let sc = scenario("tree").unwrap();
    let p = chain_planner(PlannerOptions::default());
    let plan = p
        .plan(&p.model().straight(), &sc.goal, &sc.curve_obstacles())
        .unwrap();
    for q in &plan.path {
        let c = clearance(&placed_arcs(p.model(), q), &sc.curve_obstacles());
        assert!(c >= 0.0);
        let direct = sc
            .curve_obstacles()
            .iter()
            .map(|o| closest(p.model(), q, o).unwrap().distance)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(c, direct);
        assert!(c >= plan.min_clearance);
    }
}

#[test]
fn repulsion_pushes_the_closest_point_away() {
    // A point obstacle 5 cm beside the middle of the straight chain, goal straight ahead:
    // with repulsion the arm moves away from it; without, it does not.
    let chain = ArcChain::new(&SEGMENT_LENGTHS).unwrap();
    let q0 = chain.straight();
    let ob = vec![Obstacle::Point(Vec3::new(0.05, 0.0, 1.5))];
    let goal = Vec3::new(0.0, 0.0, 2.9);
    let one_step = |kr: f64| {
        let o = PlannerOptions {
            repulsion_gain: kr,
            max_iterations: 1,
            ..PlannerOptions::default()
        };
        let p = PotentialFieldPlanner::new(chain.clone(), o).unwrap();
        let plan = p.plan(&q0, &goal, &ob).unwrap();
        closest(&chain, &plan.path[1], &ob[0]).unwrap()
    };
    let before = closest(&chain, &q0, &ob[0]).unwrap();
    let with = one_step(3e-5);
    let without = one_step(0.0);
    assert!(
        with.distance > before.distance + 1e-3,
        "{} vs {}",
        with.distance,
        before.distance
    );
    assert!(with.distance > without.distance + 1e-3);
    // It moved along −x, away from the obstacle.
    assert!(with.arm_point.x < before.arm_point.x);
}

#[test]
fn soft_arm_plans_stay_within_actuator_limits() {
    let arm = SoftArm::blackberry();
    // Start mid-range; the goal is the end effector at a reachable bent configuration.
    let q0 = vec![0.01; 9];
    let t = arm
        .forward(&[0.03, 0.0, 0.01, 0.0, 0.03, 0.01, 0.01, 0.0, 0.03])
        .unwrap();
    let goal = Vec3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)]);
    let o = PlannerOptions {
        max_tip_step: 0.01,
        goal_tolerance: 0.002,
        influence_distance: 0.03,
        repulsion_gain: 1e-8,
        stall_tolerance: 1e-5,
        ..PlannerOptions::default()
    };
    let p = PotentialFieldPlanner::new(arm.clone(), o).unwrap();
    let obstacles = vec![
        Obstacle::Segment(
            Segment::new(Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.1, 0.2, 0.3)).unwrap(),
        ),
        Obstacle::Cloud(
            PointCloud::new(vec![Vec3::new(-0.1, 0.0, 0.2), Vec3::new(-0.1, 0.05, 0.25)]).unwrap(),
        ),
        Obstacle::Curve(
            PolynomialCurve::new(
                &[Vec3::new(0.0, 0.15, 0.0), Vec3::new(0.0, 0.0, 1.0)],
                (0.0, 0.5),
            )
            .unwrap(),
        ),
    ];
    let plan = p.plan(&q0, &goal, &obstacles).unwrap();
    for q in &plan.path {
        for (i, v) in q.iter().enumerate() {
            assert!(*v >= arm.lower()[i] && *v <= arm.upper()[i], "q[{i}] = {v}");
        }
    }
    assert!(plan.min_clearance > 0.0);
    // The tip moved towards the goal.
    let first = (plan.tip_path[0] - goal).norm();
    let last = (plan.tip_path.last().unwrap() - goal).norm();
    assert!(last < 0.5 * first, "{last} vs {first}");
}

#[test]
fn ends_on_the_iteration_limit_or_a_stall() {
    let sc = scenario("tree").unwrap();
    let p = chain_planner(PlannerOptions {
        max_iterations: 3,
        ..PlannerOptions::default()
    });
    let plan = p
        .plan(&p.model().straight(), &sc.goal, &sc.curve_obstacles())
        .unwrap();
    assert_eq!(plan.termination, Termination::IterationLimit);
    assert_eq!(plan.iterations, 3);
    assert!(!plan.reached);
    // An unreachable goal (beyond the chain's longest reach) stalls.
    let p = chain_planner(PlannerOptions::default());
    let plan = p
        .plan(&p.model().straight(), &Vec3::new(0.0, 0.0, 10.0), &[])
        .unwrap();
    assert_eq!(plan.termination, Termination::Stalled);
    assert_eq!(plan.min_clearance, f64::INFINITY);
}

#[test]
fn bad_input_gets_typed_errors() {
    let p = chain_planner(PlannerOptions::default());
    let q0 = p.model().straight();
    let g = Vec3::new(1.0, 0.0, 1.0);
    assert!(matches!(
        p.plan(&q0[..8], &g, &[]),
        Err(Error::Shape { .. })
    ));
    assert!(
        matches!(p.plan(&q0, &Vec3::new(f64::NAN, 0.0, 0.0), &[]), Err(Error::NonFinite { ref arg, .. }) if arg == "goal")
    );
    let mut out = q0.clone();
    out[0] = 5.0;
    assert!(
        matches!(p.plan(&out, &g, &[]), Err(Error::OutOfRange { ref arg, .. }) if arg == "q0[0]")
    );
    let bad = PlannerOptions {
        influence_distance: -1.0,
        ..PlannerOptions::default()
    };
    assert!(
        matches!(PotentialFieldPlanner::new(ArcChain::new(&[1.0]).unwrap(), bad), Err(Error::Parameter { ref arg, .. }) if arg == "influence_distance")
    );
    let bad = PlannerOptions {
        arm_samples: Some(1),
        ..PlannerOptions::default()
    };
    assert!(matches!(
        PotentialFieldPlanner::new(ArcChain::new(&[1.0]).unwrap(), bad),
        Err(Error::Parameter { .. })
    ));
    let sampled = chain_planner(PlannerOptions {
        arm_samples: Some(10),
        ..PlannerOptions::default()
    });
    let curves = scenario("line").unwrap().curve_obstacles();
    assert!(
        matches!(sampled.plan(&q0, &g, &curves), Err(Error::Parameter { ref arg, .. }) if arg == "obstacles[0]")
    );
    assert!(matches!(scenario("forest"), Err(Error::Parameter { .. })));
    assert!(matches!(
        scenario("line").unwrap().point_obstacles(0),
        Err(Error::Shape { .. })
    ));
}
