//! criterion benches for one resolver step (docs/architecture.md target: one hybrid step of eq. (20),
//! Jacobian included, ≤ 1 µs for the three-section arm).

use criterion::{criterion_group, criterion_main, Criterion};
use softarm_core::distance::{Obstacle, PolynomialCurve};
use softarm_core::resolver::StepInput;
use softarm_core::{Gains, Kinematics, Mode, Resolver, SoftArm, Target, Vec3};
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
    bench_obstacles(c, &arm, &mid, &near);
}

/// Hybrid steps with 6 curved canes (vertical parabolas, planning paper eq. 10): all
/// beyond the influence distance (the usual case, culled by bounding spheres), and one
/// of them within it (one exact closest pair, its point Jacobian and pseudo-inverse).
fn bench_obstacles(c: &mut Criterion, arm: &SoftArm, mid: &[f64; 9], near: &Target) {
    let cane = |x: f64, y: f64| {
        let coeffs = [
            Vec3::new(x, y, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.03, 0.01, 0.0),
        ];
        match PolynomialCurve::new(&coeffs, (0.0, 0.6)) {
            Ok(c) => Obstacle::Curve(c),
            Err(e) => panic!("{e}"),
        }
    };
    let far: Vec<Obstacle> = (0..6)
        .map(|k| {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            cane(0.25 * a.cos(), 0.25 * a.sin())
        })
        .collect();
    let Ok((p, _)) = arm.point(mid, 1, 0.5) else {
        panic!("point")
    };
    let mut one_near = far.clone();
    one_near[0] = cane(p.x + 0.06, p.y);
    let Ok(res) = Resolver::new(arm.clone(), Mode::Hybrid, Gains::blackberry()) else {
        panic!("gains")
    };
    let mut ws = res.workspace();
    let mut out = [0.0; 9];
    for (name, obstacles) in [("far", &far), ("one_near", &one_near)] {
        let input = StepInput {
            obstacles,
            ..StepInput::default()
        };
        c.bench_function(&format!("resolver/hybrid_step_6_curves_{name}"), |b| {
            b.iter(|| {
                res.step_input_into(&mut ws, black_box(mid), black_box(near), &input, &mut out)
            })
        });
    }
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
