//! criterion benches for the distance queries (docs/architecture.md target: arc ↔ polynomial curve,
//! exact, ≤ 1 µs per pair). Baselines: brute force over a point cloud.

use criterion::{criterion_group, criterion_main, Criterion};
use softarm_core::distance::{
    closest_arc_curve, closest_to_arc, placed_arcs, Obstacle, PointCloud, Segment,
};
use softarm_core::planner::scenarios::scenario;
use softarm_core::{ArcChain, Vec3};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap();
    // A bent configuration mid-way through simulation 2.
    let q = [0.65, 0.25, 0.66, 0.67, 0.36, 0.24, 0.7, 0.13, 0.02];
    let arcs = placed_arcs(&chain, &q);
    let curve2 = scenario("curve").unwrap().curves[0].clone();
    let tree = scenario("tree").unwrap().curves;
    c.bench_function("arc_curve/parabola (sim 2), one pair", |b| {
        b.iter(|| closest_arc_curve(black_box(&arcs[1]), black_box(&curve2)))
    });
    c.bench_function("arc_curve/tree (sim 3), 6 curves x 3 arcs, per pair", |b| {
        b.iter(|| {
            let mut d = f64::INFINITY;
            for arc in &arcs {
                for cv in &tree {
                    d = d.min(closest_arc_curve(black_box(arc), cv).distance);
                }
            }
            d
        })
    });
    let seg = Obstacle::Segment(
        Segment::new(Vec3::new(1.0, -2.0, 2.5), Vec3::new(1.0, 2.0, -1.5)).unwrap(),
    );
    c.bench_function("arc_segment/one pair", |b| {
        b.iter(|| closest_to_arc(black_box(&arcs[1]), 1, &seg))
    });
    let pt = Obstacle::Point(Vec3::new(0.5, 0.3, 1.2));
    c.bench_function("arc_point/one pair", |b| {
        b.iter(|| closest_to_arc(black_box(&arcs[1]), 1, &pt))
    });
    // 10 000 points on a noisy sphere shell around the arm's middle.
    let mut pts = Vec::new();
    for i in 0..100 {
        for j in 0..100 {
            let (th, ph) = (
                std::f64::consts::PI * (i as f64 + 0.5) / 100.0,
                std::f64::consts::TAU * j as f64 / 100.0,
            );
            pts.push(Vec3::new(
                0.6 + 0.5 * th.sin() * ph.cos(),
                0.5 * th.sin() * ph.sin(),
                1.5 + 0.5 * th.cos(),
            ));
        }
    }
    let cloud = PointCloud::new(pts).unwrap();
    c.bench_function("arc_cloud/10k points, parry BVH", |b| {
        b.iter(|| cloud.closest_to_arc(black_box(&arcs[1]), f64::MAX))
    });
    c.bench_function("arc_cloud/10k points, brute force (baseline)", |b| {
        b.iter(|| cloud.closest_to_arc_brute_force(black_box(&arcs[1])))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
