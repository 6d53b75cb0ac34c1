//! criterion benches for whole plans of the planning paper's simulations (docs/architecture.md
//! target: simulation 3 ≤ 1 ms; the paper: 0.74 s in MATLAB). The proposed method and the
//! point-set baselines (1, 10, 50, 100 points per curve; 10 arm points per segment,
//! brute force) run in the same process, so they are compared on equal terms.

use criterion::{criterion_group, criterion_main, Criterion};
use softarm_core::planner::scenarios::{scenario, ARM_POINTS_PER_SEGMENT, NAMES, SEGMENT_LENGTHS};
use softarm_core::{ArcChain, PlannerOptions, PotentialFieldPlanner};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let chain = ArcChain::new(&SEGMENT_LENGTHS).unwrap();
    let q0 = chain.straight();
    let exact = PotentialFieldPlanner::new(chain.clone(), PlannerOptions::default()).unwrap();
    let points = PotentialFieldPlanner::new(
        chain,
        PlannerOptions {
            arm_samples: Some(ARM_POINTS_PER_SEGMENT),
            ..PlannerOptions::default()
        },
    )
    .unwrap();
    for name in NAMES {
        let sc = scenario(name).unwrap();
        let mut group = c.benchmark_group(format!("plan/{name}"));
        let curves = sc.curve_obstacles();
        group.bench_function("proposed (exact curves)", |b| {
            b.iter(|| exact.plan(black_box(&q0), &sc.goal, &curves))
        });
        for n in [1usize, 10, 50, 100] {
            let obs = sc.point_obstacles(n).unwrap();
            group.bench_function(format!("{n} points"), |b| {
                b.iter(|| points.plan(black_box(&q0), &sc.goal, &obs))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
