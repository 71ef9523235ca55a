//! Power-law fits of 1e6 pooled samples (issue 54: `precursors stats` on pooled sweeps):
//! `fit_power_law` and `compare_alternatives` with the default options (200 bootstrap
//! resamples, 200 synthetic sets: 401 whole fits, `x_min` search included), and one
//! `x_min` search alone. Samples: a power law `α = 2.5` above 1 below a uniform bulk on
//! [0.5, 1) (a fifth of them), continuous, from a seeded generator. Results:
//! docs/performance.md, "Power-law fits of 1e6 samples".

use criterion::{criterion_group, criterion_main, Criterion};
use precursors::statistics::{compare_alternatives, fit_power_law, PowerLawOptions, Support};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

fn samples(n: usize) -> Vec<f64> {
    let mut r = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(54);
    (0..n)
        .map(|i| {
            let u: f64 = r.random();
            if i % 5 == 0 {
                0.5 + 0.5 * u
            } else {
                (1.0 - u).powf(-1.0 / 1.5)
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let xs = samples(1_000_000);
    let mut group = c.benchmark_group("power_law_1e6");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    let search = PowerLawOptions::default().bootstrap(0).goodness_samples(0);
    group.bench_function("x_min_search", |b| {
        b.iter(|| fit_power_law(black_box(&xs), Support::Continuous, &search).unwrap())
    });
    let default = PowerLawOptions::default();
    group.bench_function("fit_power_law_default", |b| {
        b.iter(|| fit_power_law(black_box(&xs), Support::Continuous, &default).unwrap())
    });
    group.bench_function("compare_alternatives_default", |b| {
        b.iter(|| compare_alternatives(black_box(&xs), Support::Continuous, &default).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
