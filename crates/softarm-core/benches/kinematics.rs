//! criterion benches for the kinematics (docs/architecture.md targets: forward ≤ 150 ns,
//! forward + Jacobian ≤ 300 ns, for the three-section arm).

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;
use softarm_core::chain::{forward_jacobian_into, forward_unchecked};
use softarm_core::{ArcChain, Kinematics, SoftArm};
use std::hint::black_box;

fn configuration() -> [f64; 9] {
    [
        0.010, 0.002, 0.025, 0.030, 0.012, 0.001, 0.005, 0.020, 0.015,
    ]
}

fn bench_soft_arm(c: &mut Criterion) {
    let arm = SoftArm::blackberry();
    let q = configuration();
    c.bench_function("soft_arm/forward", |b| {
        b.iter(|| arm.forward(black_box(&q)))
    });
    c.bench_function("soft_arm/forward_unchecked", |b| {
        b.iter(|| forward_unchecked(&arm, black_box(&q)))
    });
    c.bench_function("soft_arm/forward_jacobian", |b| {
        b.iter(|| arm.forward_jacobian(black_box(&q)))
    });
    let mut jac = DMatrix::zeros(6, 9);
    c.bench_function("soft_arm/forward_jacobian_into", |b| {
        b.iter(|| forward_jacobian_into(&arm, black_box(&q), &mut jac))
    });
    c.bench_function("soft_arm/point", |b| {
        b.iter(|| arm.point(black_box(&q), 2, black_box(0.5)))
    });
}

fn bench_arc_chain(c: &mut Criterion) {
    let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap();
    let q = [1.0, 0.3, 0.2, 1.1, 0.5, -1.0, 0.9, 0.8, 2.0];
    c.bench_function("arc_chain/forward_jacobian", |b| {
        b.iter(|| chain.forward_jacobian(black_box(&q)))
    });
}

criterion_group!(benches, bench_soft_arm, bench_arc_chain);
criterion_main!(benches);
