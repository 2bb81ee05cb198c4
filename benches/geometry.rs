//! Cost of the knot diagnostics versus N: self-distance (expected N log N),
//! ray-closure writhe (all segment pairs) and knot type.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use knotrod::geometry::closure::ray_closure;
use knotrod::geometry::distance::min_self_distance;
use knotrod::geometry::knot::knot_type;
use knotrod::geometry::writhe::writhe_closed;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// An open trefoil-like curve of unit length scale with n segments.
fn open_trefoil(n: usize) -> (Vec<Vector3<f64>>, Vec<f64>) {
    let pts: Vec<Vector3<f64>> = (0..=n)
        .map(|k| {
            let t = 0.2 + (2.0 * PI - 0.4) * k as f64 / n as f64;
            0.1 * Vector3::new(
                (2.0 + (3.0 * t).cos()) * (2.0 * t).cos(),
                (2.0 + (3.0 * t).cos()) * (2.0 * t).sin(),
                (3.0 * t).sin(),
            )
        })
        .collect();
    let arc = (0..=n).map(|k| k as f64 / n as f64).collect();
    (pts, arc)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("self_distance");
    for n in [100, 200, 400, 800, 1600, 3200, 10_000] {
        let (p, arc) = open_trefoil(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| min_self_distance(&p, &arc, 0.05))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("writhe");
    g.sample_size(10);
    for n in [100, 200, 400, 800, 1600] {
        let (p, _) = open_trefoil(n);
        let closed = ray_closure(&p, -Vector3::z(), Vector3::z(), 1e6);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| writhe_closed(&closed))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("knot_type");
    g.sample_size(10);
    for n in [100, 200, 400, 800, 1600] {
        let (p, _) = open_trefoil(n);
        let closed = ray_closure(&p, -Vector3::z(), Vector3::z(), 2.0);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| knot_type(&closed))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
