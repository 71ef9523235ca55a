//! Bad input gets a typed error that names the offending value.

use precursors::green::{GreenFunction, InfluencePlan, RodLoad, SeriesOptions};
use precursors::{Block, Error, Grid, Point};

#[test]
fn block_sizes_must_be_finite_and_positive() {
    for (lx, ly, lz) in [
        (0.0, 1.0, 1.0),
        (1.0, -1.0, 1.0),
        (1.0, 1.0, f64::NAN),
        (f64::INFINITY, 1.0, 1.0),
    ] {
        assert!(matches!(
            Block::new(lx, ly, lz),
            Err(Error::InvalidLength { .. })
        ));
    }
}

#[test]
fn grid_must_divide_the_face() {
    let b = Block::new(0.14, 0.007, 0.075).unwrap();
    let e = Grid::from_cell_size(b, 0.003, 0.001).unwrap_err();
    assert!(
        matches!(e, Error::GridDoesNotDivide { axis: "x", .. }),
        "{e}"
    );
    assert!(matches!(
        Grid::from_cell_size(b, 0.0, 0.001),
        Err(Error::InvalidLength { .. })
    ));
    assert!(matches!(
        Grid::new(b, 0, 3),
        Err(Error::EmptyGrid { axis: "x" })
    ));
    let g = Grid::from_cell_size(b, 0.001, 0.001).unwrap();
    assert_eq!((g.nx(), g.ny()), (140, 7));
}

#[test]
fn points_outside_the_block_are_refused() {
    let b = Block::new(0.1, 0.01, 0.05).unwrap();
    let gf = GreenFunction::new(b);
    let inside = Point::new(0.05, 0.005, 0.01);
    for bad in [
        Point::new(-1e-9, 0.005, 0.01),
        Point::new(0.05, 0.02, 0.01),
        Point::new(0.05, 0.005, f64::NAN),
    ] {
        assert!(matches!(
            gf.value(bad, inside, 1e-6),
            Err(Error::OutsideBlock { .. })
        ));
        assert!(matches!(
            gf.dz(inside, bad, 1e-6),
            Err(Error::OutsideBlock { .. })
        ));
    }
}

#[test]
fn tolerances_must_be_positive() {
    let b = Block::new(0.1, 0.01, 0.05).unwrap();
    let gf = GreenFunction::new(b);
    let (r, s) = (Point::new(0.05, 0.005, 0.01), Point::new(0.02, 0.001, 0.0));
    for tol in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            gf.value(r, s, tol),
            Err(Error::InvalidTolerance { .. })
        ));
    }
    let grid = Grid::new(b, 10, 2).unwrap();
    assert!(matches!(
        InfluencePlan::builder(grid).tolerance(0.0).build(),
        Err(Error::InvalidTolerance { .. })
    ));
    let opts = SeriesOptions::with_tolerance(1e-6).max_terms(0);
    assert!(matches!(
        gf.value_with(r, s, &opts),
        Err(Error::InvalidCount { .. })
    ));
}

#[test]
fn rod_band_must_lie_on_the_face() {
    let b = Block::new(0.1, 0.01, 0.05).unwrap();
    assert!(matches!(
        RodLoad::new(&b, 0.001, 0.002),
        Err(Error::RodBandOutsideFace { .. })
    ));
    assert!(matches!(
        RodLoad::new(&b, 0.049, 0.002),
        Err(Error::RodBandOutsideFace { .. })
    ));
    assert!(matches!(
        RodLoad::new(&b, 0.01, 0.0),
        Err(Error::InvalidLength { .. })
    ));
    assert!(RodLoad::new(&b, 0.025, 0.025).is_ok());
}

#[test]
fn heights_outside_the_block_are_refused() {
    let b = Block::new(0.1, 0.01, 0.05).unwrap();
    let grid = Grid::new(b, 10, 2).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    assert!(matches!(
        plan.plane_transfer(0.06, 1e-8),
        Err(Error::OutsideBlock { .. })
    ));
    assert!(matches!(
        plan.plane_transfer(-0.001, 1e-8),
        Err(Error::OutsideBlock { .. })
    ));
    assert!(matches!(
        precursors::green::loads::top_stress_influence(&b, f64::NAN),
        Err(Error::OutsideBlock { .. })
    ));
}

#[test]
fn operator_inputs_are_checked() {
    let b = Block::new(0.1, 0.01, 0.05).unwrap();
    let grid = Grid::new(b, 10, 2).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let mut out = vec![0.0; 20];
    assert!(matches!(
        plan.apply(&[1.0; 19], &mut out),
        Err(Error::LengthMismatch { .. })
    ));
    let mut v = vec![1.0; 20];
    v[3] = f64::NAN;
    assert!(matches!(
        plan.apply(&v, &mut out),
        Err(Error::NonFinite { index: 3, .. })
    ));
    let big = Grid::new(b, 200, 101).unwrap();
    let plan = InfluencePlan::builder(big).tolerance(1e-2).build().unwrap();
    assert!(matches!(plan.dense(), Err(Error::TooLargeForDense { .. })));
}

#[test]
fn zero_solver_threads_are_refused() {
    let built = precursors::Scene::builder()
        .solver(
            precursors::SolverOptions::default().parallelism(precursors::Parallelism::Threads(0)),
        )
        .build()
        .and_then(|scene| scene.driver());
    match built {
        Err(Error::InvalidCount { name, value, .. }) => {
            assert_eq!(name, "threads");
            assert_eq!(value, 0);
        }
        other => panic!("threads = 0: {other:?}"),
    }
    // Any other count is valid, beyond the machine's cores too.
    for threads in [1, 3, 64] {
        let scene = precursors::Scene::builder()
            .block(0.010, 0.005, 0.010)
            .solver(
                precursors::SolverOptions::default()
                    .parallelism(precursors::Parallelism::Threads(threads)),
            )
            .build()
            .unwrap();
        assert!(scene.driver().is_ok(), "threads = {threads}");
    }
}

#[test]
fn cell_indices_past_the_grid_are_refused() {
    let b = Block::new(0.14, 0.007, 0.075).unwrap();
    let g = Grid::from_cell_size(b, 1e-3, 1e-3).unwrap();
    // Without the check, (140, 0) aliased cell (0, 1).
    assert_eq!(g.index(140, 0), None);
    assert_eq!(g.index(0, 7), None);
    assert_eq!(g.index(usize::MAX, usize::MAX), None);
    assert_eq!(g.index(139, 6), Some(6 * 140 + 139));
    assert_eq!(g.index(0, 1), Some(140));
    assert_eq!(g.centre(140, 0), None);
    assert_eq!(g.centre(0, 7), None);
    let (x, y) = g.centre(139, 6).unwrap();
    assert!((x - 0.1395).abs() < 1e-15 && (y - 0.0065).abs() < 1e-15);
}

#[test]
fn absurdly_fine_cells_get_a_typed_error_not_a_panic() {
    let b = Block::new(0.14, 0.007, 0.075).unwrap();
    // Each of these once gave a grid whose `len()` overflowed or whose count saturated
    // `usize` (any cell below 2^-53 L "divides" the face in f64).
    for (dx, dy) in [
        (1e-300, 1e-3),
        (1e-3, 1e-300),
        (5e-324, 5e-324),
        (1e-17, 1e-3),
    ] {
        let e = Grid::from_cell_size(b, dx, dy).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    }
    // L / cell = inf passed the divisibility test (inf - inf is NaN, never > tolerance).
    let huge = Block::new(1e300, 1.0, 1.0).unwrap();
    let e = Grid::from_cell_size(huge, 1e-300, 1.0).unwrap_err();
    assert!(
        matches!(e, Error::InvalidParameter { name: "dx", .. }),
        "{e}"
    );
    for (nx, ny) in [(usize::MAX, 2), (2, usize::MAX), (1 << 32, 1 << 32)] {
        let e = Grid::new(b, nx, ny).unwrap_err();
        assert!(
            matches!(e, Error::GridTooLarge { cells, .. } if cells == nx as u128 * ny as u128),
            "{e}"
        );
    }
    // The largest counts that are still accepted keep `len()` exact.
    let g = Grid::new(b, 1 << 40, 1 << 19).unwrap();
    assert_eq!(g.len(), 1 << 59);
}

#[test]
fn cells_and_blocks_that_underflow_or_overflow_are_refused() {
    // Each side is a valid length, the volume is not (inf / 0).
    let e = Block::new(1e200, 1e200, 1e200).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    let e = Block::new(1e-200, 1e-200, 1e-200).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    // A cell of 5e-324 / 2 m rounds to zero; a cell area of 1e-326 m² underflows.
    let tiny = Block::new(5e-324, 1.0, 1.0).unwrap();
    assert!(matches!(
        Grid::new(tiny, 2, 1),
        Err(Error::InvalidLength { name: "dx", .. })
    ));
    let thin = Block::new(1e-160, 1e-160, 1e300).unwrap();
    assert!(Grid::new(thin, 1, 1).is_ok());
    let e = Grid::new(thin, 1000, 1000).unwrap_err();
    assert!(
        matches!(e, Error::InvalidParameter { name: "ΔA", .. }),
        "{e}"
    );
}

/// `μ = 0` is refused where it would make every load ratio `F/(μF_N)` NaN.
#[test]
fn zero_friction_is_refused() {
    for mu in [0.0, -0.1, f64::NAN] {
        assert!(
            matches!(
                precursors::Material::new(3e9, 0.38, mu),
                Err(Error::InvalidParameter {
                    name: "friction_coefficient",
                    ..
                })
            ),
            "μ = {mu}"
        );
        let mut material = precursors::Material::default();
        material.friction_coefficient = mu;
        let built = precursors::Scene::builder().material(material).build();
        assert!(
            matches!(
                built,
                Err(Error::InvalidParameter {
                    name: "friction_coefficient",
                    ..
                })
            ),
            "μ = {mu}"
        );
    }
}

/// `use precursors::*` brings `Result` with a default error type: naming another error
/// still works.
#[test]
fn result_alias_takes_another_error_type() {
    use precursors::*;
    fn parse(text: &str) -> Result<u32, std::num::ParseIntError> {
        text.parse()
    }
    fn build() -> Result<Grid> {
        Grid::from_cell_size(Block::new(0.01, 0.01, 0.01)?, 1e-3, 1e-3)
    }
    assert!(parse("x").is_err() && parse("7") == Ok(7));
    assert_eq!(build().unwrap().len(), 100);
}

/// A grid above the cell limit is refused at once, before anything is allocated, with
/// the count, the limit and the estimated cost; the limit can be raised.
#[test]
fn grids_above_the_cell_limit_are_refused_quickly() {
    use precursors::green::DEFAULT_MAX_CELLS;
    let clock = std::time::Instant::now();
    let huge = precursors::Scene::builder()
        .block(10.0, 10.0, 0.075)
        .cells(10_000, 10_000)
        .build()
        .unwrap_err();
    assert!(clock.elapsed().as_secs_f64() < 1.0, "{:?}", clock.elapsed());
    match &huge {
        Error::GridTooLarge {
            nx: 10_000,
            ny: 10_000,
            cells: 100_000_000,
            limit,
            memory_bytes,
            plan_seconds,
            solve_seconds,
        } => {
            assert_eq!(*limit, DEFAULT_MAX_CELLS);
            // 240 B and 1.5 µs per cell (docs/performance.md).
            assert!((*memory_bytes - 2.4e10).abs() < 1e8, "{memory_bytes}");
            assert!((*plan_seconds - 150.0).abs() < 0.01, "{plan_seconds}");
            assert!(*solve_seconds > 3600.0, "{solve_seconds}");
        }
        other => panic!("{other:?}"),
    }
    let text = huge.to_string();
    for part in [
        "10000 x 10000 = 100000000 cells",
        "1000000 cells",
        "24.000 GB",
        "max_cells",
    ] {
        assert!(text.contains(part), "{part:?} not in {text}");
    }
    // The same guard on the plan builder; the documented large run (1000 x 100) passes
    // the default limit, and a limit below a grid refuses it.
    let block = Block::new(1.0, 0.1, 0.075).unwrap();
    let big = Grid::new(block, 1000, 100).unwrap();
    let e = InfluencePlan::builder(big)
        .max_cells(99_999)
        .build()
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::GridTooLarge {
                cells: 100_000,
                limit: 99_999,
                ..
            }
        ),
        "{e}"
    );
    let small = precursors::Scene::builder()
        .max_cells(979)
        .build()
        .unwrap_err();
    assert!(
        matches!(small, Error::GridTooLarge { cells: 980, .. }),
        "{small}"
    );
    let scene = precursors::Scene::builder().max_cells(980).build().unwrap();
    assert_eq!(scene.grid().len(), 980);
    // The limit is part of neither the physics nor the run: a raised one plans alike.
    let raised = precursors::Scene::builder()
        .max_cells(usize::MAX)
        .build()
        .unwrap();
    assert_eq!(raised.interface().heights(), scene.interface().heights());
}

/// The dense backend runs on one thread: an explicit thread count with it is refused and
/// says what to do; `Backend::Auto` accepts any parallelism and reports the threads used.
#[test]
fn threads_with_the_dense_backend() {
    use precursors::{Backend, Parallelism, Scene, SolverOptions};
    let options = |backend, parallelism| {
        SolverOptions::default()
            .backend(backend)
            .parallelism(parallelism)
    };
    let e = Scene::builder()
        .solver(options(Backend::Dense, Parallelism::Threads(4)))
        .build()
        .unwrap_err();
    assert!(matches!(e, Error::DenseThreads { threads: 4 }), "{e}");
    assert!(e.to_string().contains(r#"backend "spectral""#), "{e}");
    for parallelism in [
        Parallelism::Sequential,
        Parallelism::Threads(1),
        Parallelism::CurrentPool,
    ] {
        let scene = Scene::builder()
            .solver(options(Backend::Dense, parallelism))
            .build()
            .unwrap();
        assert_eq!(scene.driver().unwrap().threads(), 1);
    }
    // Auto picks dense at 980 cells: threads accepted, one used.
    let scene = Scene::builder()
        .solver(options(Backend::Auto, Parallelism::Threads(4)))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    assert_eq!(driver.backend(), Backend::Dense);
    assert_eq!(driver.threads(), 1);
    // Spectral: as many as asked, up to the parts of the grid (one part below 2048 cells).
    let spectral = Scene::builder()
        .block(0.128, 0.032, 0.075)
        .solver(options(Backend::Spectral, Parallelism::Threads(2)))
        .build()
        .unwrap()
        .driver()
        .unwrap();
    assert_eq!(spectral.threads(), 2);
    // Setting threads later: the same rule.
    driver.set_parallelism(Parallelism::Threads(3)).unwrap();
    let mut dense = Scene::builder()
        .solver(options(Backend::Dense, Parallelism::Sequential))
        .build()
        .unwrap()
        .driver()
        .unwrap();
    assert!(matches!(
        dense.set_parallelism(Parallelism::Threads(2)),
        Err(Error::DenseThreads { threads: 2 })
    ));
}

/// Asking a driver for its equilibrium before it solved one, or for stresses without
/// probes, is a misuse with its own error, not an empty contact.
#[test]
fn misuse_of_the_driver_has_its_own_errors() {
    let driver = precursors::Scene::builder()
        .build()
        .unwrap()
        .driver()
        .unwrap();
    for e in [
        driver.normal_traction().map(|_| ()).unwrap_err(),
        driver.shear_traction().map(|_| ()).unwrap_err(),
        driver.real_contact_area().map(|_| ()).unwrap_err(),
    ] {
        assert!(matches!(e, Error::NotSolved { .. }), "{e}");
        assert!(e.to_string().contains("call step() first"), "{e}");
    }
    assert!(matches!(driver.stresses(), Err(Error::NoProbes)));
}

/// Integer parameters are reported as integers.
#[test]
fn counts_are_reported_as_integers() {
    let b = Block::new(0.1, 0.01, 0.05).unwrap();
    let gf = GreenFunction::new(b);
    let (r, s) = (Point::new(0.05, 0.005, 0.01), Point::new(0.02, 0.001, 0.0));
    let e = gf
        .value_with(r, s, &SeriesOptions::with_tolerance(1e-6).max_terms(0))
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidCount {
                name: "max_terms",
                value: 0,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("max_terms = 0 is invalid"), "{e}");
}
