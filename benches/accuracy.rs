//! Error against run time: point series and grid operator at several tolerances.
//! The achieved errors are printed by `cargo run --release --example accuracy`;
//! both go into docs/accuracy.md.

use criterion::{criterion_group, criterion_main, Criterion};
use precursors::green::{GreenFunction, InfluencePlan, SeriesOptions};
use precursors::{Block, Grid, Point};
use std::hint::black_box;

fn paper_block() -> Block {
    Block::new(0.14, 0.007, 0.075).unwrap()
}

fn point_series(c: &mut Criterion) {
    let gf = GreenFunction::new(paper_block());
    let (r, s) = (
        Point::new(0.04, 0.0035, 0.0),
        Point::new(0.043, 0.0045, 0.0),
    );
    let mut group = c.benchmark_group("point_rapid");
    for tol in [1e-4, 1e-8, 1e-12] {
        group.bench_function(format!("tol={tol:e}"), |b| {
            b.iter(|| gf.value(black_box(r), black_box(s), tol).unwrap())
        });
    }
    group.finish();
    let small = GreenFunction::new(Block::new(0.03, 0.02, 0.025).unwrap());
    let (r, s) = (
        Point::new(0.007, 0.004, 0.003),
        Point::new(0.021, 0.013, 0.017),
    );
    let mut group = c.benchmark_group("point_raw");
    group.sample_size(10);
    for tol in [1e-1, 1e-2] {
        let opts = SeriesOptions::default()
            .with_tolerance(tol)
            .unwrap()
            .with_max_terms(400_000_000)
            .unwrap();
        group.bench_function(format!("tol={tol:e}"), |b| {
            b.iter(|| small.raw_series(black_box(r), black_box(s), &opts).unwrap())
        });
    }
    group.finish();
}

fn grid_operator(c: &mut Criterion) {
    let grid = Grid::new(paper_block(), 140, 7).unwrap();
    // The plan's cost does not depend on its tolerance: the eigenvalues are computed to
    // about 1e-13 always (docs/accuracy.md).
    let mut group = c.benchmark_group("operator_build");
    group.sample_size(10);
    for (lx, ly, nx, ny) in [
        (0.14, 0.007, 140, 7),
        (0.2, 0.05, 200, 50),
        (1.0, 0.1, 1000, 100),
    ] {
        let g = Grid::new(Block::new(lx, ly, 0.075).unwrap(), nx, ny).unwrap();
        group.bench_function(format!("{nx}x{ny}"), |b| {
            b.iter(|| InfluencePlan::builder(g).build().unwrap())
        });
    }
    group.finish();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let v: Vec<f64> = (0..grid.len()).map(|i| (i as f64 * 0.37).sin()).collect();
    let mut out = vec![0.0; grid.len()];
    c.bench_function("operator_apply_140x7", |b| {
        b.iter(|| plan.apply(black_box(&v), &mut out).unwrap())
    });
    let big = Grid::new(Block::new(1.0, 0.1, 0.5).unwrap(), 1000, 100).unwrap();
    let plan = InfluencePlan::builder(big)
        .plan_tolerance(1e-3)
        .build()
        .unwrap();
    let v: Vec<f64> = (0..big.len()).map(|i| (i as f64 * 0.37).sin()).collect();
    let mut out = vec![0.0; big.len()];
    c.bench_function("operator_apply_1000x100", |b| {
        b.iter(|| plan.apply(black_box(&v), &mut out).unwrap())
    });
}

criterion_group!(benches, point_series, grid_operator);
criterion_main!(benches);
