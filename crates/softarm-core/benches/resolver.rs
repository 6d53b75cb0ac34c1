//! criterion benches for one resolver step (DESIGN.md target: one hybrid step of eq. (20),
//! Jacobian included, ≤ 1 µs for the three-section arm).

use criterion::{criterion_group, criterion_main, Criterion};
use softarm_core::{Gains, Kinematics, Mode, Resolver, SoftArm, Target};
use std::hint::black_box;

fn bench_steps(c: &mut Criterion) {
    let arm = SoftArm::blackberry();
    let q = [
        0.010, 0.002, 0.025, 0.030, 0.012, 0.001, 0.005, 0.020, 0.015,
    ];
    let goal = [
        0.020, 0.010, 0.005, 0.002, 0.022, 0.011, 0.015, 0.003, 0.030,
    ];
    let target = match arm.forward(&goal) {
        Ok(t) => Target::Pose(t),
        Err(e) => panic!("{e}"),
    };
    // A mid-range state: no coordinate reaches a limit (the usual step).
    let mid = [
        0.016, 0.012, 0.020, 0.018, 0.015, 0.014, 0.017, 0.019, 0.013,
    ];
    let near = match arm.forward(&[
        0.017, 0.013, 0.019, 0.019, 0.014, 0.015, 0.016, 0.020, 0.012,
    ]) {
        Ok(t) => Target::Pose(t),
        Err(e) => panic!("{e}"),
    };
    for mode in [Mode::Hybrid, Mode::Position, Mode::Orientation] {
        let Ok(res) = Resolver::new(arm.clone(), mode, Gains::blackberry()) else {
            panic!("gains")
        };
        let mut ws = res.workspace();
        let mut out = [0.0; 9];
        c.bench_function(&format!("resolver/{}_step", mode.name()), |b| {
            b.iter(|| res.step_into(&mut ws, black_box(&mid), black_box(&near), None, &mut out))
        });
    }
    // Next to the limits with a far target: coordinates saturate and the step is
    // recomputed without them (saturation in the null space).
    {
        let mode = Mode::Hybrid;
        let Ok(res) = Resolver::new(arm.clone(), mode, Gains::blackberry()) else {
            panic!("gains")
        };
        let mut ws = res.workspace();
        let mut out = [0.0; 9];
        c.bench_function(&format!("resolver/{}_step_saturating", mode.name()), |b| {
            b.iter(|| res.step_into(&mut ws, black_box(&q), black_box(&target), None, &mut out))
        });
    }
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("gains")
    };
    c.bench_function("resolver/hybrid_step_allocating", |b| {
        b.iter(|| res.step(black_box(&mid), black_box(&near), None))
    });
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
