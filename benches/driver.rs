//! The calibration scene (140 x 7 x 75 mm, 1 mm cells, F_N = 3.5 kN, rod at h = 6 mm,
//! Δh = 2 mm, seed 1) driven from zero shear to global slip: scene build (operator plan,
//! lateral table) and the whole run, with the default backend (dense at this size) and
//! with each backend forced, to compare them on the driver's real sequence of solves.
//! Results: docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion};
use precursors::{Backend, Scene, SolverOptions};
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
            d.run(|_, _| {}).unwrap();
            d.event_count()
        })
    });
    for (name, backend) in [("dense", Backend::Dense), ("spectral", Backend::Spectral)] {
        let scene = Scene::builder()
            .seed(1)
            .solver(SolverOptions::default().with_backend(backend))
            .build()
            .unwrap();
        group.bench_function(format!("calibration_scene_to_global_slip_{name}"), |b| {
            b.iter(|| {
                let mut d = scene.driver().unwrap();
                d.run(|_, _| {}).unwrap();
                d.event_count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
