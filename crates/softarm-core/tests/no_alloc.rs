//! The resolver's hot path allocates nothing: after a first step has sized the
//! workspace, a hybrid step (with no obstacle, and with canes beyond the influence
//! distance) makes no heap allocation. A counting global allocator checks it.

use softarm_core::distance::{Obstacle, PolynomialCurve};
use softarm_core::resolver::StepInput;
use softarm_core::{Gains, Kinematics, Mode, Resolver, SoftArm, Target, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn hybrid_steps_allocate_nothing_after_the_first() {
    let arm = SoftArm::blackberry();
    let mid = [
        0.016, 0.012, 0.020, 0.018, 0.015, 0.014, 0.017, 0.019, 0.013,
    ];
    let goal = [
        0.017, 0.013, 0.019, 0.019, 0.014, 0.015, 0.016, 0.020, 0.012,
    ];
    let target = Target::Pose(arm.forward(&goal).unwrap());
    let far: Vec<Obstacle> = (0..6)
        .map(|k| {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            let coeffs = [
                Vec3::new(0.25 * a.cos(), 0.25 * a.sin(), 0.0),
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.03, 0.01, 0.0),
            ];
            Obstacle::Curve(PolynomialCurve::new(&coeffs, (0.0, 0.6)).unwrap())
        })
        .collect();
    let res = Resolver::new(arm, Mode::Hybrid, Gains::blackberry()).unwrap();
    let mut ws = res.workspace();
    let mut out = [0.0; 9];
    for obstacles in [&[][..], &far[..]] {
        let input = StepInput {
            obstacles,
            ..StepInput::default()
        };
        res.step_input_into(&mut ws, &mid, &target, &input, &mut out)
            .unwrap();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for _ in 0..10 {
            let info = res
                .step_input_into(&mut ws, &mid, &target, &input, &mut out)
                .unwrap();
            assert!(info.clearance.is_infinite());
        }
        let made = ALLOCATIONS.load(Ordering::SeqCst) - before;
        assert_eq!(made, 0, "{} obstacles: {made} allocations", obstacles.len());
    }
}
