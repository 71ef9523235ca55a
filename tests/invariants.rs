//! Invariants that cannot be bypassed (issue 24, item 2): every value type refuses an
//! invalid value when it is made, with a typed error naming it; there is no public field
//! to set afterwards and no `validate()` to forget. (Before, `Material`, `SpringLaw`,
//! `SolverOptions`, `ProbeSpec`, `HeightDistribution`, `SeriesOptions` and `FitOptions`
//! had public fields that took any value, and `SweepOptions::jobs(0)` silently ran one
//! job.)

use precursors::calibration::FitOptions;
use precursors::green::SeriesOptions;
use precursors::solver::{Backend, Parallelism, SolverOptions};
use precursors::{Error, HeightDistribution, Material, ProbeInput, ProbeSpec, SpringLaw};

fn invalid_parameter(r: Result<impl std::fmt::Debug, Error>, field: &str) -> bool {
    matches!(r, Err(Error::InvalidParameter { name, .. }) if name == field)
}

fn invalid_count(r: Result<impl std::fmt::Debug, Error>, field: &str) -> bool {
    matches!(r, Err(Error::InvalidCount { name, value: 0, .. }) if name == field)
}

#[test]
fn material_refuses_invalid_values_at_construction() {
    assert!(invalid_parameter(
        Material::new(-1.0, 0.3, 0.5),
        "young_modulus"
    ));
    assert!(invalid_parameter(
        Material::new(3e9, 0.6, 0.5),
        "poisson_ratio"
    ));
    assert!(invalid_parameter(
        Material::new(3e9, -1.0, 0.5),
        "poisson_ratio"
    ));
    assert!(invalid_parameter(
        Material::new(3e9, 0.3, f64::NAN),
        "friction_coefficient"
    ));
    let m = Material::default();
    assert!(invalid_parameter(
        m.with_young_modulus(0.0),
        "young_modulus"
    ));
    assert!(invalid_parameter(
        m.with_poisson_ratio(f64::NAN),
        "poisson_ratio"
    ));
    assert!(invalid_parameter(
        m.with_friction_coefficient(0.0),
        "friction_coefficient"
    ));
    // A valid change keeps the other values.
    let m = m.with_friction_coefficient(0.7).unwrap();
    assert_eq!(
        (
            m.young_modulus(),
            m.poisson_ratio(),
            m.friction_coefficient()
        ),
        (3.833e9, 0.38, 0.7)
    );
}

#[test]
fn spring_law_refuses_invalid_values_at_construction() {
    assert!(invalid_parameter(SpringLaw::new(0.0, 1e8), "c_x"));
    assert!(invalid_parameter(
        SpringLaw::new(1e12, f64::INFINITY),
        "c_z"
    ));
    let law = SpringLaw::default();
    assert!(invalid_parameter(law.with_c_x(-1.0), "c_x"));
    assert!(invalid_parameter(law.with_c_z(f64::NAN), "c_z"));
}

#[test]
fn height_distribution_refuses_invalid_values_at_construction() {
    assert!(invalid_parameter(
        HeightDistribution::new(f64::NAN, 1e-6),
        "mean"
    ));
    assert!(invalid_parameter(
        HeightDistribution::new(1e-6, -1e-6),
        "std_dev"
    ));
    // Below -3 standard deviations almost every draw would be cut at 0.
    assert!(invalid_parameter(
        HeightDistribution::new(-4e-6, 1e-6),
        "mean"
    ));
    assert!(invalid_parameter(HeightDistribution::new(0.0, 0.0), "mean"));
    let d = HeightDistribution::default();
    assert!(invalid_parameter(d.with_mean(-1.0), "mean"));
    assert!(invalid_parameter(d.with_std_dev(f64::INFINITY), "std_dev"));
}

#[test]
fn solver_options_refuse_invalid_values_at_construction() {
    let o = SolverOptions::default();
    for t in [0.0, -1e-13, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(o.with_tolerance(t), Err(Error::InvalidTolerance { .. })),
            "{t}"
        );
    }
    assert!(invalid_count(
        o.with_max_active_set_iterations(0),
        "max_active_set_iterations"
    ));
    assert!(invalid_count(
        o.with_max_linear_iterations(0),
        "max_linear_iterations"
    ));
    assert!(invalid_count(
        o.with_parallelism(Parallelism::Threads(0)),
        "threads"
    ));
    // The dense backend runs on one thread, in either order of the two modifiers.
    let dense = o.with_backend(Backend::Dense).unwrap();
    assert!(matches!(
        dense.with_parallelism(Parallelism::Threads(4)),
        Err(Error::DenseThreads { threads: 4, .. })
    ));
    let threads = o.with_parallelism(Parallelism::Threads(4)).unwrap();
    assert!(matches!(
        threads.with_backend(Backend::Dense),
        Err(Error::DenseThreads { threads: 4, .. })
    ));
    // Every field has its modifier and getter.
    let o = o
        .with_backend(Backend::Spectral)
        .and_then(|o| o.with_tolerance(1e-11))
        .and_then(|o| o.with_max_active_set_iterations(7))
        .and_then(|o| o.with_max_linear_iterations(99))
        .and_then(|o| o.with_parallelism(Parallelism::Threads(2)))
        .unwrap();
    assert_eq!(
        (
            o.backend(),
            o.tolerance(),
            o.max_active_set_iterations(),
            o.max_linear_iterations(),
            o.parallelism()
        ),
        (Backend::Spectral, 1e-11, 7, 99, Parallelism::Threads(2))
    );
}

#[test]
fn probe_spec_and_input_refuse_invalid_values_at_construction() {
    for t in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            ProbeSpec::default().with_tolerance(t),
            Err(Error::InvalidTolerance { .. })
        ));
    }
    let phi = [0.0; 4];
    let input = ProbeInput::new(&phi, &phi);
    assert!(matches!(
        input.with_loads(0.0, f64::NAN, 1.0),
        Err(Error::NonFinite {
            name: "lateral_force",
            ..
        })
    ));
    assert!(invalid_parameter(
        input.with_friction_coefficient(-0.5),
        "friction_coefficient"
    ));
}

#[test]
fn series_and_fit_options_refuse_invalid_values_at_construction() {
    let s = SeriesOptions::default();
    assert!(matches!(
        s.with_tolerance(0.0),
        Err(Error::InvalidTolerance { .. })
    ));
    assert!(invalid_count(s.with_max_terms(0), "max_terms"));
    let f = FitOptions::default();
    assert!(matches!(
        f.clone().with_tolerance(f64::NAN),
        Err(Error::InvalidTolerance { .. })
    ));
    assert!(invalid_count(
        f.clone().with_max_evaluations(0),
        "max_evaluations"
    ));
    assert!(matches!(
        f.with_scan_points(2),
        Err(Error::InvalidCount {
            name: "scan_points",
            value: 2,
            ..
        })
    ));
}

/// `SweepOptions::jobs(0)` ran one job without a word; now `with_jobs(0)` is refused, and
/// so is a share that does not exist.
#[cfg(feature = "serde")]
#[test]
fn sweep_options_refuse_zero_jobs_and_missing_shares() {
    use precursors::sweep::SweepOptions;
    let e = SweepOptions::new().with_jobs(0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidCount {
                name: "jobs",
                value: 0,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("jobs = 0 is invalid"), "{e}");
    assert!(matches!(
        SweepOptions::new().with_shard(2, 2),
        Err(Error::InvalidCount {
            name: "shard index",
            ..
        })
    ));
    assert!(matches!(
        SweepOptions::new().with_shard(0, 0),
        Err(Error::InvalidCount {
            name: "shard count",
            ..
        })
    ));
    let o = SweepOptions::new()
        .with_jobs(3)
        .unwrap()
        .with_shard(1, 4)
        .unwrap();
    assert_eq!((o.jobs(), o.shard()), (3, (1, 4)));
}
