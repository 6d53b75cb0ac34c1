//! Issue 27 item 1: the obstacle repulsion, the lowest task of eq. (20), holding a pose
//! next to a cane. Over random poses (elongations in 10–90 % of the range) and straight
//! canes 8–30 mm from a random backbone point, iterating the hybrid step towards the pose
//! the arm already holds must keep the pose (within 0.05 mm), not bring the body closer
//! to the cane, and settle (under 0.1 mm of motion between steps 150 and 200).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use softarm_core::chain::SectionModel;
use softarm_core::distance::{Obstacle, Segment};
use softarm_core::resolver::{StepInput, Workspace};
use softarm_core::{Gains, Kinematics, Mode, Resolver, SoftArm, Target, Vec3};

/// One case: the pose q holds, its target and the cane.
struct Case {
    q: Vec<f64>,
    target: Target,
    cane: Obstacle,
}

fn random_case(rng: &mut StdRng, arm: &SoftArm) -> Case {
    let q: Vec<f64> = arm
        .lower()
        .iter()
        .zip(arm.upper())
        .map(|(&l, &u)| l + (u - l) * rng.random_range(0.1..0.9))
        .collect();
    let Ok(pose) = arm.forward(&q) else {
        panic!("forward at a state inside the limits");
    };
    let section = rng.random_range(0..arm.n_sections());
    let s = rng.random_range(0.0..1.0);
    let (Ok((p, _)), Ok(frames)) = (arm.point(&q, section, s), arm.frames(&q)) else {
        panic!("point and frames at a state inside the limits");
    };
    let z = frames[section].fixed_view::<3, 1>(0, 2).into_owned();
    let r = Vec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let side = z.cross(&r).normalize();
    let along = z.cross(&side);
    let c = p + side * rng.random_range(0.008..0.030);
    let Ok(seg) = Segment::new(c - along * 0.2, c + along * 0.2) else {
        panic!("a segment of length 0.4 m");
    };
    Case {
        q,
        target: Target::Pose(pose),
        cane: Obstacle::Segment(seg),
    }
}

/// What iterating one case gives: (pose error m, motion over steps 150–200 m,
/// clearance change m).
fn run_case(res: &Resolver<SoftArm>, case: &Case) -> (f64, f64, f64) {
    let arm = res.arm();
    let n = case.q.len();
    let mut ws = Workspace::new(n);
    let obstacles = [case.cane.clone()];
    let input = StepInput {
        obstacles: &obstacles,
        ..StepInput::default()
    };
    let mut q = case.q.clone();
    let mut out = vec![0.0; n];
    let mut first_clearance = None;
    let mut at_150 = Vec::new();
    let mut motion: f64 = 0.0;
    let mut last_clearance = 0.0;
    for k in 0..=200 {
        let Ok(info) = res.step_input_into(&mut ws, &q, &case.target, &input, &mut out) else {
            panic!("a step inside the limits");
        };
        first_clearance.get_or_insert(info.clearance);
        last_clearance = info.clearance;
        if k == 200 {
            break;
        }
        if k == 150 {
            at_150 = body_points(arm, &q);
        }
        if k > 150 {
            let now = body_points(arm, &q);
            for (a, b) in at_150.iter().zip(&now) {
                motion = motion.max((a - b).norm());
            }
        }
        q.copy_from_slice(&out);
    }
    let (Ok(held), Target::Pose(t)) = (arm.forward(&q), &case.target) else {
        panic!("a pose target");
    };
    let err = (held.fixed_view::<3, 1>(0, 3) - t.fixed_view::<3, 1>(0, 3)).norm();
    (err, motion, last_clearance - first_clearance.unwrap_or(0.0))
}

/// The body's backbone at the ends and middles of its sections.
fn body_points(arm: &SoftArm, q: &[f64]) -> Vec<Vec3> {
    let mut pts = Vec::new();
    for section in 0..arm.n_sections() {
        for s in [0.5, 1.0] {
            if let Ok((p, _)) = arm.point(q, section, s) {
                pts.push(p);
            }
        }
    }
    pts
}

#[test]
fn the_repulsion_holds_the_pose_grows_the_clearance_and_settles() {
    let arm = SoftArm::blackberry();
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("the blackberry gains are valid");
    };
    let mut rng = StdRng::seed_from_u64(27);
    let (mut drift, mut moving, mut closer) = (0, 0, 0);
    for i in 0..200 {
        let case = random_case(&mut rng, &arm);
        let (err, motion, dclear) = run_case(&res, &case);
        let bad = (err > 5e-5, motion > 1e-4, dclear < -1e-6);
        drift += usize::from(bad.0);
        moving += usize::from(bad.1);
        closer += usize::from(bad.2);
        if bad.0 || bad.1 || bad.2 {
            println!(
                "case {i}: pose error {:.3} mm, motion {:.3} mm, clearance change {:.2} mm",
                err * 1e3,
                motion * 1e3,
                dclear * 1e3
            );
        }
    }
    println!("drift {drift}, still moving {moving}, closer {closer} (of 200)");
    assert_eq!((drift, moving, closer), (0, 0, 0));
}

/// Issue 40 item 5: 200 fresh cases (seed 33, not the seed the fix was tuned on) where
/// one (case 195) still moved 0.35 mm over steps 150–200 while its clearance crept the
/// last fraction of a millimetre to the influence distance, a tenth of the way per step.
/// Asking the last stretch whole (`avoid::LAST_STRETCH`) ends that approach: every case
/// holds the pose, keeps its clearance and settles.
#[test]
fn the_last_stretch_to_the_influence_distance_settles() {
    let arm = SoftArm::blackberry();
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("the blackberry gains are valid");
    };
    let mut rng = StdRng::seed_from_u64(33);
    let mut bad = Vec::new();
    for i in 0..200 {
        let (err, motion, dclear) = run_case(&res, &random_case(&mut rng, &arm));
        if err > 5e-5 || motion > 1e-4 || dclear < -1e-6 {
            bad.push((i, err * 1e3, motion * 1e3, dclear * 1e3));
        }
    }
    assert!(
        bad.is_empty(),
        "(case, pose error, motion, clearance change; mm): {bad:?}"
    );
}

/// The cases traced for the saturation rounds' priority (seed 27, beyond the 200 above):
/// the repulsion pushed four coordinates past their limits, and fixing them for every
/// task left the hybrid tasks five coordinates for five rows, cycling by millimetres.
#[test]
fn coordinates_only_the_repulsion_saturates_stay_with_the_tasks() {
    let arm = SoftArm::blackberry();
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("the blackberry gains are valid");
    };
    let mut rng = StdRng::seed_from_u64(27);
    for i in 0..=1679 {
        let case = random_case(&mut rng, &arm);
        if i == 317 || i == 1679 {
            let (err, motion, dclear) = run_case(&res, &case);
            assert!(err <= 5e-5 && motion <= 1e-4 && dclear >= -1e-6, "case {i}");
        }
    }
}

/// Case `i` (from 0) of the random cases drawn from `seed`.
fn nth_case(arm: &SoftArm, seed: u64, i: usize) -> Case {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut case = random_case(&mut rng, arm);
    for _ in 0..i {
        case = random_case(&mut rng, arm);
    }
    case
}

/// Issue 40 item 5, traced on seed 36 case 119 (of seeds 27–70 checked): the nearest
/// piece's gap was stationary on the tasks' self-motion manifold (its projected row
/// 0.002, below ε = 0.05) while a second piece 0.4 mm farther, nearly parallel, had
/// leverage 0.3 and asked nothing. The two-row solve carried the first row's ask through
/// the second's direction: the body slid along it, 5 µm a step growing to 40 µm, 0.75 mm
/// over steps 150–200, for 0.01 µm of clearance a step. A row without leverage now asks
/// nothing where another row has some (`avoid::add_rows_step`), as a lone row never did.
#[test]
fn a_tied_row_without_leverage_asks_nothing_through_another() {
    let arm = SoftArm::blackberry();
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("the blackberry gains are valid");
    };
    let (err, motion, dclear) = run_case(&res, &nth_case(&arm, 36, 119));
    assert!(
        err <= 5e-5 && motion <= 1e-4 && dclear >= -1e-6,
        "pose error {err}, motion {motion}, clearance change {dclear} (m)"
    );
}

/// Issue 40 item 5, seed 53 case 70: the cane starts 10.8 mm deep in the body where the
/// null space's leverage on the gap is 0.07 (1.4 ε). The push is held to a tenth of the
/// clearance it earns in gripper motion (`avoid::fraction_for_drift`): 0.3 mm of
/// elongation and 0.024 mm of gap a step, a walk that ends on the joint limits after 168
/// steps, 3.8 mm out. It holds the pose and never closes the gap; it settles by step 200,
/// not by step 150 (not fixed: see docs/control.md).
#[test]
fn the_deep_low_leverage_escape_holds_the_pose_and_ends_on_the_limits() {
    let arm = SoftArm::blackberry();
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("the blackberry gains are valid");
    };
    let case = nth_case(&arm, 53, 70);
    let n = case.q.len();
    let mut ws = Workspace::new(n);
    let obstacles = [case.cane.clone()];
    let input = StepInput {
        obstacles: &obstacles,
        ..StepInput::default()
    };
    let (mut q, mut out) = (case.q.clone(), vec![0.0; n]);
    let (mut clearance, mut at_180) = (f64::NEG_INFINITY, Vec::new());
    for k in 0..=200 {
        let Ok(info) = res.step_input_into(&mut ws, &q, &case.target, &input, &mut out) else {
            panic!("a step inside the limits");
        };
        assert!(
            info.clearance >= clearance - 1e-6,
            "step {k}: the gap closed"
        );
        assert!(
            info.position_error < 2e-5,
            "step {k}: {}",
            info.position_error
        );
        clearance = info.clearance;
        if k == 180 {
            at_180 = body_points(&arm, &q);
        }
        q.copy_from_slice(&out);
    }
    let moved = at_180
        .iter()
        .zip(body_points(&arm, &q))
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(moved < 1e-4, "{moved} m over steps 180–200");
    assert!(clearance > -7.5e-3, "{clearance}");
}
