//! Power-law fits of 1e6 pooled samples (issue 54: `precursors stats` on pooled sweeps):
//! `fit_power_law` and `compare_alternatives` with the default options (200 bootstrap
//! resamples, 200 synthetic sets: 401 whole fits, `x_min` search included), and one
//! `x_min` search alone, on the threads of rayon's global pool (every core; the results
//! do not depend on it). Samples, from a seeded generator:
//!
//! * `power_law_1e6`: reals, a power law `α = 2.5` above 1 below a uniform bulk on
//!   [0.5, 1) (a fifth of them);
//! * `sizes_1e6`: counts like pooled avalanche sizes, `⌊x⌋` of a power law `α = 2.5`
//!   above 1 (about 77 % ones).
//!
//! `PRECURSORS_BENCH_SAMPLES=DIR` writes both sample sets to `DIR/power_law_1e6.txt` and
//! `DIR/sizes_1e6.txt` (one a line, round-tripping), for scripts/powerlaw-stats.py.
//! Results: docs/performance.md, "Power-law fits of 1e6 samples".

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

fn sizes(n: usize) -> Vec<f64> {
    let mut r = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(55);
    (0..n)
        .map(|_| (1.0 - r.random::<f64>()).powf(-1.0 / 1.5).floor())
        .collect()
}

fn bench(c: &mut Criterion) {
    let sets = [
        ("power_law_1e6", samples(1_000_000), Support::Continuous),
        ("sizes_1e6", sizes(1_000_000), Support::Discrete),
    ];
    if let Some(dir) = std::env::var_os("PRECURSORS_BENCH_SAMPLES") {
        for (name, xs, _) in &sets {
            let text: String = xs.iter().map(|x| format!("{x:?}\n")).collect();
            std::fs::write(std::path::Path::new(&dir).join(format!("{name}.txt")), text)
                .expect("writing the samples");
        }
    }
    for (name, xs, support) in &sets {
        let mut group = c.benchmark_group(*name);
        group
            .sample_size(10)
            .measurement_time(Duration::from_secs(30));
        let search = PowerLawOptions::default().bootstrap(0).goodness_samples(0);
        group.bench_function("x_min_search", |b| {
            b.iter(|| fit_power_law(black_box(xs), *support, &search).unwrap())
        });
        let default = PowerLawOptions::default();
        group.bench_function("fit_power_law_default", |b| {
            b.iter(|| fit_power_law(black_box(xs), *support, &default).unwrap())
        });
        group.bench_function("compare_alternatives_default", |b| {
            b.iter(|| compare_alternatives(black_box(xs), *support, &default).unwrap())
        });
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
