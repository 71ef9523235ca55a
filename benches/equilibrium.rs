//! One normal and one tangential equilibrium per backend at N = 980 (140 x 7), 1e4
//! (200 x 50) and 1e5 (1000 x 100), paper heights and 3.5 MPa; the dense backend at
//! N = 980 only (its 1e4 one-shot timing is in docs/performance.md).
//! `cold`: a fresh solver (all sites attached at the start; the dense factor built).
//! `warm`: the solver re-equilibrates after one rupture (the driver's common step);
//! `tangential_warm` times the tangential solve that follows it. At N >= 1e4 the spectral
//! backend also runs with two threads (`Spectral2`, `Parallelism::Threads(2)`: the same
//! results; compare the ratio, the machine has two cores).
//! Results: docs/performance.md.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use precursors::green::InfluencePlan;
use precursors::solver::{Backend, EquilibriumSolver, Parallelism, SolverOptions};
use precursors::*;
use std::time::{Duration, Instant};

fn setup(nx: usize, ny: usize) -> (InfluencePlan, Interface, f64) {
    let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075).unwrap();
    let grid = Grid::new(block, nx, ny).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), 1).unwrap();
    let iface = Interface::new(grid, heights, SpringLaw::default()).unwrap();
    (plan, iface, 3.5e6 * block.lx() * block.ly())
}

fn solver(plan: &InfluencePlan, (backend, threads): (Backend, usize)) -> EquilibriumSolver {
    EquilibriumSolver::builder(plan.clone())
        .solver_options(
            SolverOptions::default()
                .with_backend(backend)
                .unwrap()
                .with_parallelism(if threads > 1 {
                    Parallelism::Threads(threads)
                } else {
                    Parallelism::Sequential
                })
                .unwrap(),
        )
        .build()
        .unwrap()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("equilibrium");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(4));
    for (nx, ny) in [(140, 7), (200, 50), (1000, 100)] {
        let (plan, iface, load) = setup(nx, ny);
        let n = nx * ny;
        let zeros = vec![0.0; n];
        for (backend, threads) in [
            (Backend::Dense, 1),
            (Backend::Spectral, 1),
            (Backend::Spectral, 2),
        ] {
            if (backend == Backend::Dense && n > 1_000) || (threads > 1 && n < 10_000) {
                continue;
            }
            let backend = (backend, threads);
            let name = match backend {
                (b, 1) => format!("{b:?}"),
                (b, t) => format!("{b:?}{t}"),
            };
            let tag = format!("{name}/{n}");
            // Cold normal: a fresh solver from an all-attached interface.
            group.bench_function(format!("normal_cold/{tag}"), |b| {
                b.iter_batched(
                    || (solver(&plan, backend), iface.clone()),
                    |(mut s, i)| s.solve_normal(&i, load).unwrap(),
                    BatchSize::PerIteration,
                )
            });
            // Warm: equilibrium known, one attached site breaks, the normal equilibrium is
            // solved again (the driver's common step); heal when a quarter is left.
            let mut s = solver(&plan, backend);
            let mut i = iface.clone();
            let mut eq = s.solve_normal(&i, load).unwrap();
            i.set_states(&eq.states).unwrap();
            s.solve_tangential(&i, &eq.displacement, &zeros).unwrap();
            let rupture = |s: &mut EquilibriumSolver, i: &mut Interface| {
                if i.attached_count() < n / 4 {
                    i.heal();
                    let eq = s.solve_normal(i, load).unwrap();
                    i.set_states(&eq.states).unwrap();
                }
                let site = (0..n)
                    .find(|&k| i.states()[k] == SiteState::Attached)
                    .unwrap();
                i.break_site(site).unwrap();
            };
            group.bench_function(format!("normal_warm/{tag}"), |b| {
                b.iter_custom(|iters| {
                    let mut spent = Duration::ZERO;
                    for _ in 0..iters {
                        rupture(&mut s, &mut i);
                        let t = Instant::now();
                        eq = s.solve_normal(&i, load).unwrap();
                        spent += t.elapsed();
                        i.set_states(&eq.states).unwrap();
                    }
                    spent
                })
            });
            // Tangential after a rupture: the set and k_x changed since the last solve.
            group.bench_function(format!("tangential_warm/{tag}"), |b| {
                b.iter_custom(|iters| {
                    let mut spent = Duration::ZERO;
                    for _ in 0..iters {
                        rupture(&mut s, &mut i);
                        eq = s.solve_normal(&i, load).unwrap();
                        i.set_states(&eq.states).unwrap();
                        let t = Instant::now();
                        s.solve_tangential(&i, &eq.displacement, &zeros).unwrap();
                        spent += t.elapsed();
                    }
                    spent
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
