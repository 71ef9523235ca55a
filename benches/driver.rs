//! The calibration scene (140 x 7 x 75 mm, 1 mm cells, F_N = 3.5 kN, rod at h = 6 mm,
//! Δh = 2 mm, seed 1) driven from zero shear to global slip: scene build (operator plan,
//! lateral table) and the whole run, with the default backend (dense at this size) and
//! with each backend forced, to compare them on the driver's real sequence of solves.
//! And the N = 1e4 scene of `examples/large_run.rs` (200 x 50 x 75 mm, seed 1) through
//! its first 300 ruptures on one and on two solver threads (the whole run takes about a
//! minute: the example times it). Results: docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion};
use precursors::solver::{Backend, Parallelism, SolverOptions};
use precursors::{Event, Scene};
use std::ops::ControlFlow;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("driver");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    group.bench_function("calibration_scene_build", |b| {
        b.iter(|| Scene::builder().seed(1).build().unwrap())
    });
    let scene = Scene::builder().seed(1).build().unwrap();
    group.bench_function("calibration_scene_to_global_slip", |b| {
        b.iter(|| {
            let mut d = scene.driver().unwrap();
            d.run(|_, _| ControlFlow::<()>::Continue(())).unwrap();
            d.event_count()
        })
    });
    for (name, backend) in [("dense", Backend::Dense), ("spectral", Backend::Spectral)] {
        let scene = Scene::builder()
            .seed(1)
            .solver_options(SolverOptions::default().with_backend(backend).unwrap())
            .build()
            .unwrap();
        group.bench_function(format!("calibration_scene_to_global_slip_{name}"), |b| {
            b.iter(|| {
                let mut d = scene.driver().unwrap();
                d.run(|_, _| ControlFlow::<()>::Continue(())).unwrap();
                d.event_count()
            })
        });
    }
    for threads in [1, 2] {
        let scene = Scene::builder()
            .block(0.200, 0.050, 0.075)
            .cell_size(1e-3, 1e-3)
            .seed(1)
            .normal_load(3.5e6 * 0.200 * 0.050)
            .solver_options(
                SolverOptions::default()
                    .with_parallelism(if threads > 1 {
                        Parallelism::Threads(threads)
                    } else {
                        Parallelism::Sequential
                    })
                    .unwrap(),
            )
            .build()
            .unwrap();
        group.bench_function(format!("n1e4_first_300_ruptures/threads{threads}"), |b| {
            b.iter(|| {
                let mut d = scene.driver().unwrap();
                let mut ruptures = 0;
                while ruptures < 300 {
                    if let Some(Event::Rupture { .. }) = d.step().unwrap() {
                        ruptures += 1;
                    }
                }
                d.event_count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
