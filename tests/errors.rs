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
        InfluencePlan::builder(grid).plan_tolerance(0.0).build(),
        Err(Error::InvalidTolerance { .. })
    ));
    assert!(matches!(
        SeriesOptions::default().with_max_terms(0),
        Err(Error::InvalidCount { .. })
    ));
    assert!(matches!(
        gf.value(r, s, 0.0),
        Err(Error::InvalidTolerance { .. })
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
        precursors::green::top_stress_influence(&b, f64::NAN),
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
    let plan = InfluencePlan::builder(big)
        .plan_tolerance(1e-2)
        .build()
        .unwrap();
    assert!(matches!(plan.dense(), Err(Error::TooLargeForDense { .. })));
}

#[test]
fn zero_solver_threads_are_refused() {
    // Refused when the options are made (there is no later point to refuse them at).
    let built = precursors::solver::SolverOptions::default()
        .with_parallelism(precursors::solver::Parallelism::Threads(0));
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
            .solver_options(
                precursors::solver::SolverOptions::default()
                    .with_parallelism(precursors::solver::Parallelism::Threads(threads))
                    .unwrap(),
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
        assert!(
            matches!(
                precursors::Material::default().with_friction_coefficient(mu),
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
    use precursors::solver::{Backend, Parallelism, SolverOptions};
    use precursors::Scene;
    let options = |backend, parallelism| {
        SolverOptions::default()
            .with_backend(backend)
            .unwrap()
            .with_parallelism(parallelism)
            .unwrap()
    };
    // Refused when the options are made, in either order.
    let e = SolverOptions::default()
        .with_backend(Backend::Dense)
        .unwrap()
        .with_parallelism(Parallelism::Threads(4))
        .unwrap_err();
    let other = SolverOptions::default()
        .with_parallelism(Parallelism::Threads(4))
        .unwrap()
        .with_backend(Backend::Dense)
        .unwrap_err();
    assert_eq!(e.to_string(), other.to_string());
    assert!(matches!(e, Error::DenseThreads { threads: 4, .. }), "{e}");
    assert!(e.to_string().contains(r#"backend "spectral""#), "{e}");
    for parallelism in [
        Parallelism::Sequential,
        Parallelism::Threads(1),
        Parallelism::CurrentPool,
    ] {
        let scene = Scene::builder()
            .solver_options(options(Backend::Dense, parallelism))
            .build()
            .unwrap();
        assert_eq!(scene.driver().unwrap().threads(), 1);
    }
    // Auto picks dense at 980 cells: threads accepted, one used.
    let scene = Scene::builder()
        .solver_options(options(Backend::Auto, Parallelism::Threads(4)))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    assert_eq!(driver.backend(), Backend::Dense);
    assert_eq!(driver.threads(), 1);
    // Spectral: as many as asked, up to the parts of the grid (one part below 2048 cells).
    let spectral = Scene::builder()
        .block(0.128, 0.032, 0.075)
        .solver_options(options(Backend::Spectral, Parallelism::Threads(2)))
        .build()
        .unwrap()
        .driver()
        .unwrap();
    assert_eq!(spectral.threads(), 2);
    // Setting threads later: the same rule.
    driver.set_parallelism(Parallelism::Threads(3)).unwrap();
    let mut dense = Scene::builder()
        .solver_options(options(Backend::Dense, Parallelism::Sequential))
        .build()
        .unwrap()
        .driver()
        .unwrap();
    assert!(matches!(
        dense.set_parallelism(Parallelism::Threads(2)),
        Err(Error::DenseThreads { threads: 2, .. })
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
        driver.cell_contact_area().map(|_| ()).unwrap_err(),
    ] {
        assert!(matches!(e, Error::NotSolved { .. }), "{e}");
        assert!(e.to_string().contains("call step() first"), "{e}");
    }
    assert!(matches!(driver.stresses(), Err(Error::NoProbes)));
}

/// Integer parameters are reported as integers.
#[test]
fn counts_are_reported_as_integers() {
    let e = SeriesOptions::default().with_max_terms(0).unwrap_err();
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

/// The valid ranges of `docs/scene-format.md` ("Valid ranges"), key by key: the
/// documented bounds are not refused for the key, values just outside are refused at
/// once by `SceneBuilder::check` and `build` with `Error::OutOfRange` naming the key, and
/// the message gives the range. The bounds are the table's (the reference), not read
/// from the code.
mod ranges {
    use precursors::solver::SolverOptions;
    use precursors::*;

    /// A small valid scene: 20 x 4 cells of 1 mm on a 20 x 4 x 10 mm block.
    fn base() -> SceneBuilder {
        Scene::builder()
            .block(0.020, 0.004, 0.010)
            .cells(20, 4)
            .normal_load(60.0)
            .seed(0)
    }

    fn material(e: f64, nu: f64, mu: f64) -> SceneBuilder {
        base().material(Material::new(e, nu, mu).unwrap())
    }

    fn springs(c_x: f64, c_z: f64) -> SceneBuilder {
        base().springs(SpringLaw::new(c_x, c_z).unwrap())
    }

    /// The scene with solver options changed by `f` (values the options themselves
    /// refuse, e.g. 0 iterations, are refused at construction:
    /// `solver_options_refuse_invalid_values_at_construction`).
    fn solver(f: impl FnOnce(SolverOptions) -> Result<SolverOptions>) -> SceneBuilder {
        base().solver_options(f(SolverOptions::default()).unwrap())
    }

    /// The block's shear stiffness `M·Ly·Lz/Lx` of [`base`] (N/m), the paper's PMMA.
    fn block_stiffness() -> f64 {
        3.833e9 / 1.38 * 0.004 * 0.010 / 0.020
    }

    fn spring(k: f64) -> SceneBuilder {
        base().drive(Drive::Spring {
            stiffness: k,
            lateral: Lateral::Side,
        })
    }

    fn refused(b: &SceneBuilder, key: &str) -> bool {
        matches!(b.check(), Err(Error::OutOfRange { key: k, .. }) if k == key)
    }

    /// `(key, scene with the value, [accepted values], [refused values])`.
    type Case = (
        &'static str,
        Box<dyn Fn(f64) -> SceneBuilder>,
        Vec<f64>,
        Vec<f64>,
    );

    fn cases() -> Vec<Case> {
        let k = block_stiffness();
        vec![
            (
                "block.lx",
                Box::new(|v| base().block(v, v, v).cells(1, 1).normal_load(1e-9)),
                vec![1e-9, 1e9],
                vec![0.99e-9, 1.01e9, 1e308],
            ),
            (
                "block.ly",
                Box::new(|v| base().block(0.02, v, 0.01)),
                vec![0.020001e-6, 0.004],
                vec![0.0199e-6, 1e308],
            ),
            (
                "block.lz",
                Box::new(|v| base().block(0.02, 0.004, v)),
                vec![8e-8, 3.99e3],
                vec![4.01e3, 1e308],
            ),
            (
                "cells.nx",
                // Δx ≥ Lz/1e6 = 9.99e-7 m on a block 1 mm long.
                Box::new(|v| base().block(1e-3, 1e-3, 0.999).cells(v as usize, 1)),
                vec![1000.0],
                vec![1002.0],
            ),
            (
                // Δx ≥ Lz/1e6 = 1e-8 m on a block 0.1 mm long.
                "cells.dx",
                Box::new(|v| base().block(1e-4, 0.004, 0.01).cell_size(v, 0.004)),
                vec![2e-8, 1e-4],
                vec![0.5e-8],
            ),
            (
                "material.young_modulus",
                Box::new(|v| material(v, 0.38, 0.5)),
                vec![1e-3, 1e15],
                vec![0.99e-3, 1.01e15, 1e308],
            ),
            (
                "material.poisson_ratio",
                Box::new(|v| material(3e9, v, 0.5)),
                vec![-0.999_999, 0.5],
                vec![-0.999_999_5],
            ),
            (
                "material.friction_coefficient",
                Box::new(|v| material(3e9, 0.38, v)),
                vec![1e-6, 1e3],
                vec![0.99e-6, 1.01e3, 1e-300],
            ),
            (
                "springs.c_x",
                Box::new(|v| springs(v, 1.65e8)),
                vec![1e-3, 1e24],
                vec![0.99e-3, 1.01e24],
            ),
            (
                "springs.c_z",
                // A stiff block (E = 1e15 Pa): springs up to 1e21 N/m² are then resolved
                // against it (the tolerance's bound `5e-2·p/R`, docs/scene-format.md).
                Box::new(|v| {
                    let m = Material::default().with_young_modulus(1e15).unwrap();
                    springs(1.65e12, v).material(m)
                }),
                vec![1e-3, 1e21],
                vec![0.99e-3, 1.01e21],
            ),
            (
                "normal_load",
                // A stiff block on stiff springs: within 650 ΔA c_z, and the block's
                // displacement within 1e10 asperity heights.
                Box::new(|v| {
                    let m = Material::default().with_young_modulus(1e15).unwrap();
                    springs(1.65e12, 1e21).material(m).normal_load(v)
                }),
                vec![1e-9, 1e15],
                vec![0.99e-9, 1.01e15],
            ),
            (
                // At most 650 ΔA c_z: 650 · 1e-6 m² · 1.65e8 N/m² = 107250 N.
                "normal_load",
                Box::new(|v| base().normal_load(v)),
                vec![107_000.0],
                vec![107_500.0],
            ),
            (
                "heights.mean",
                Box::new(|v| {
                    base().heights(HeightSource::Random {
                        distribution: HeightDistribution::new(v, v).unwrap(),
                        seed: 1,
                    })
                }),
                vec![1e-15, 1e3],
                vec![0.99e-15, 1.01e3],
            ),
            (
                "heights.std_dev",
                Box::new(|v| {
                    base().heights(HeightSource::Random {
                        distribution: HeightDistribution::new(1e-6, v).unwrap(),
                        seed: 1,
                    })
                }),
                vec![0.0, 1e-15, 1e3],
                vec![0.99e-15, 1.01e3],
            ),
            (
                "heights.values",
                Box::new(|v| base().heights(HeightSource::Values(vec![v; 80]))),
                vec![1e-15, 1e3],
                vec![0.99e-15, 1.01e3, 1e300],
            ),
            (
                "drive.ratio",
                Box::new(|v| {
                    base().drive(Drive::Force(ForceLoad::Mixed {
                        ratio: v,
                        lateral: Lateral::Side,
                    }))
                }),
                vec![0.0, 1e12],
                vec![1.01e12],
            ),
            (
                "drive.half_width",
                Box::new(|v| {
                    base().drive(Drive::Force(
                        Lateral::Rod {
                            height: 0.005,
                            half_width: v,
                        }
                        .into(),
                    ))
                }),
                vec![1.01e-8, 0.005],
                vec![0.99e-8],
            ),
            (
                "drive.stiffness",
                Box::new(spring),
                vec![1e-12 * k * 1.000001, 4e6, 1e12 * k * 0.999999],
                vec![1e-12 * k * 0.999, 1e12 * k * 1.001, 1e-306, 1e-300, 1e300],
            ),
            (
                "solver.tolerance",
                Box::new(|v| solver(|o| o.with_tolerance(v))),
                vec![1e-15, 1e-6],
                vec![0.99e-15, 1e-17, 1.01e-6, 1.0, 10.0, 1e308],
            ),
            (
                "solver.max_active_set_iterations",
                Box::new(|v| solver(|o| o.with_max_active_set_iterations(v as usize))),
                vec![1.0, 1e6],
                vec![1e6 + 1.0, 1e19],
            ),
            (
                "solver.max_linear_iterations",
                Box::new(|v| solver(|o| o.with_max_linear_iterations(v as usize))),
                vec![1.0, 1e7],
                vec![1e7 + 1.0],
            ),
            (
                "plan_tolerance",
                Box::new(|v| base().plan_tolerance(v)),
                vec![1e-8, 1e-2],
                vec![1.01e-2, 1.0, 1e308],
            ),
            (
                "probes.tolerance",
                Box::new(|v| {
                    base().probes(
                        ProbeSpec::default()
                            .with_plane(1e-3)
                            .with_tolerance(v)
                            .unwrap(),
                    )
                }),
                vec![1e-15, 1e-2],
                vec![0.99e-15, 1.01e-2, 1.0],
            ),
        ]
    }

    #[test]
    fn values_outside_the_documented_ranges_are_refused_naming_the_key() {
        for (key, scene, accepted, outside) in cases() {
            for v in accepted {
                let b = scene(v);
                assert!(!refused(&b, key), "{key} = {v}: {:?}", b.check().err());
            }
            for v in outside {
                let b = scene(v);
                let e = b.check().unwrap_err();
                assert!(refused(&b, key), "{key} = {v}: {e}");
                let text = e.to_string();
                assert!(
                    text.starts_with(&format!("{key} = ")) && text.contains("valid range is ["),
                    "{text}"
                );
                // `build` refuses it the same way, before planning.
                assert_eq!(b.build().unwrap_err().to_string(), text);
            }
        }
    }

    /// The inputs of issue 23: `block.ly = 1e308` ran into "faer reported ZeroPivot",
    /// `block.lx = 1e308` into "tolerance inf is invalid", a spring of `1e-306` N/m into an
    /// endless contact map, `solver.tolerance` 1, 10 or 1e308 into wrong tables with exit
    /// 0.
    #[test]
    fn the_reported_inputs_are_refused_with_their_key() {
        for (b, key) in [
            (base().block(0.02, 1e308, 0.01), "block.ly"),
            (base().block(1e308, 0.004, 0.01), "block.lx"),
            (spring(1e-306), "drive.stiffness"),
            (solver(|o| o.with_tolerance(1.0)), "solver.tolerance"),
            (solver(|o| o.with_tolerance(10.0)), "solver.tolerance"),
            (solver(|o| o.with_tolerance(1e308)), "solver.tolerance"),
        ] {
            assert!(refused(&b, key), "{key}: {:?}", b.check());
        }
        // The paper's spring on the calibration block is in range.
        assert!(Scene::builder()
            .drive(Drive::Spring {
                stiffness: 4e6,
                lateral: Lateral::Side
            })
            .check()
            .is_ok());
    }

    /// A grid whose estimated memory exceeds what the machine has is refused by `check`
    /// before anything is allocated (it aborted on an 80 GB allocation); `info` runs the
    /// same check. 1e5 x 1e5 cells need about 2.4 TB (240 bytes a cell).
    #[test]
    fn a_grid_larger_than_the_memory_is_refused_before_allocating() {
        if !std::path::Path::new("/proc/meminfo").exists() {
            return; // the check needs Linux's MemAvailable
        }
        let b = base().cells(100_000, 100_000).max_cells(usize::MAX);
        let started = std::time::Instant::now();
        let e = b.check().unwrap_err();
        assert!(
            matches!(e, Error::OutOfMemory { needed_bytes, .. } if needed_bytes > 2e12),
            "{e}"
        );
        assert!(e.to_string().contains("TB of memory, but only"), "{e}");
        assert!(started.elapsed().as_secs_f64() < 1.0);
        assert_eq!(b.build().unwrap_err().to_string(), e.to_string());
    }
}

/// Lengths typed in millimetres (`lx = 140` for 140 mm) with cells of 1 mm: the grid is
/// too large, and the error asks whether metres were meant (issue 45, item 10), holding
/// the grid's `GridTooLarge` as its source. Cells given by count keep `GridTooLarge`.
#[test]
fn millimetres_typed_as_metres_are_asked_about() {
    let e = precursors::Scene::builder()
        .block(140.0, 7.0, 75.0)
        .cell_size(1e-3, 1e-3)
        .grid()
        .unwrap_err();
    let Error::LengthInMillimetres { key, value, source } = &e else {
        panic!("another error: {e}")
    };
    assert_eq!((*key, *value), ("block.lx", 140.0));
    assert!(matches!(
        **source,
        Error::GridTooLarge {
            nx: 140_000,
            ny: 7000,
            ..
        }
    ));
    let text = e.to_string();
    assert!(
        text.contains("lengths are in metres: did you mean 0.14 m?"),
        "{text}"
    );
    let cause = std::error::Error::source(&e)
        .map(|c| c.to_string())
        .unwrap_or_default();
    assert!(cause.contains("140000 x 7000"), "{cause}");
    // A count of cells does not depend on the lengths' unit: no question then.
    let e = precursors::Scene::builder()
        .block(1.4, 0.007, 0.075)
        .cells(10_000, 1_000)
        .grid()
        .unwrap_err();
    assert!(matches!(e, Error::GridTooLarge { .. }), "{e}");
}
