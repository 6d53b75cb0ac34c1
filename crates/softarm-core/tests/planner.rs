//! The potential-field planner (eq. 9) on the paper's scenarios and on the soft arm.

use softarm_core::distance::{closest, Obstacle, PointCloud, PolynomialCurve, Segment};
use softarm_core::planner::scenarios::{scenario, ARM_POINTS_PER_SEGMENT, NAMES, SEGMENT_LENGTHS};
use softarm_core::planner::{path_clearance, Termination};
use softarm_core::{ArcChain, Error, Kinematics, PlannerOptions, PotentialFieldPlanner, SoftArm, Vec3};

fn chain_planner(options: PlannerOptions) -> PotentialFieldPlanner<ArcChain> {
    PotentialFieldPlanner::new(ArcChain::new(&SEGMENT_LENGTHS).unwrap(), options).unwrap()
}

#[test]
fn tune_print() {
    for name in NAMES {
        let sc = scenario(name).unwrap();
        let p = chain_planner(PlannerOptions::default());
        let q0 = p.model().straight();
        let plan = p.plan(&q0, &sc.goal, &sc.curve_obstacles()).unwrap();
        let truth = path_clearance(p.model(), &plan.path, &sc.curve_obstacles(), 8).unwrap();
        println!("{name} exact: it {} reached {} clear {:.4} truth {:.4} {:?} tip {:?}", plan.iterations, plan.reached, plan.min_clearance, truth, plan.termination, plan.tip_path.last().unwrap().as_slice());
        for n in [1usize, 10, 50, 100] {
            let o = PlannerOptions { arm_samples: Some(ARM_POINTS_PER_SEGMENT), ..PlannerOptions::default() };
            let p = chain_planner(o);
            let plan = p.plan(&q0, &sc.goal, &sc.point_obstacles(n).unwrap()).unwrap();
            let truth = path_clearance(p.model(), &plan.path, &sc.curve_obstacles(), 8).unwrap();
            println!("{name} {n} pts: it {} reached {} truth {:.4} {:?}", plan.iterations, plan.reached, truth, plan.termination);
        }
    }
}
