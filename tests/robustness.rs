//! No panic, no NaN: the builders and the scene-file reader, fed random values (zero,
//! negative, huge, tiny, NaN, infinite, and plausible ones), either succeed with finite
//! values all the way to the first equilibrium or return a typed error with a message.
//!
//! The draws are fixed (`RngSeed::Fixed`) so that CI is repeatable; each test was seen to
//! fail with a guard of the code under test removed (the commit message lists them).

use precursors::green::InfluencePlan;
use precursors::*;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

/// A cell limit that keeps every accepted scene small (and fast) in these tests; larger
/// grids are refused by the guard, which is part of what is tested.
const MAX_CELLS: usize = 3000;

/// Any `f64` a user could pass: special values, tiny and huge magnitudes of both signs,
/// and values near `typical` (within a factor of 10 either way).
fn wild(typical: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => (-1.0f64..1.0).prop_map(move |e| typical * 10f64.powf(e)),
        1 => prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            Just(f64::MAX),
            Just(f64::MIN_POSITIVE),
            Just(5e-324),
            Just(-typical),
        ],
        1 => (-320.0f64..308.0).prop_map(|e| 10f64.powf(e)),
        1 => (-320.0f64..308.0).prop_map(|e| -(10f64.powf(e))),
    ]
}

/// A cell count: mostly small, sometimes zero or enormous.
fn count() -> impl Strategy<Value = usize> {
    prop_oneof![
        4 => 1usize..40,
        1 => Just(0usize),
        1 => prop_oneof![Just(usize::MAX), Just(1usize << 32), Just(100_000usize)],
    ]
}

/// Checks that an error is typed (it is, by construction) and says something.
fn check_error(e: &Error) -> Result<(), TestCaseError> {
    prop_assert!(!e.to_string().trim().is_empty(), "empty message: {e:?}");
    Ok(())
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Builds `builder` and, if it builds, runs it to its first stable state: every value
/// read is finite, or an error with a message is returned.
fn build_and_step(builder: SceneBuilder) -> Result<(), TestCaseError> {
    let scene = match builder.build() {
        Ok(scene) => scene,
        Err(e) => return check_error(&e),
    };
    let grid = *scene.grid();
    prop_assert!(grid.len() <= MAX_CELLS && !grid.is_empty());
    prop_assert!(grid.dx().is_finite() && grid.dx() > 0.0);
    prop_assert!(grid.dy().is_finite() && grid.dy() > 0.0);
    prop_assert!(grid.cell_area().is_finite() && grid.cell_area() > 0.0);
    prop_assert!(all_finite(scene.interface().heights()));
    prop_assert!(scene.plan().max_relative_error().is_finite());
    let mut driver = match scene.driver() {
        Ok(driver) => driver,
        Err(e) => return check_error(&e),
    };
    match driver.step() {
        Ok(Some(_)) => {
            prop_assert!(all_finite(driver.normal_traction().unwrap()));
            prop_assert!(all_finite(driver.normal_displacement().unwrap()));
            prop_assert!(all_finite(driver.shear_traction().unwrap()));
            prop_assert!(all_finite(&driver.real_contact_area().unwrap()));
            prop_assert!(driver.force().is_finite());
            prop_assert!(driver.total_contact_area().unwrap().is_finite());
            prop_assert!(driver.breaking_loads().iter().all(|b| !b.is_nan()));
        }
        Ok(None) => prop_assert!(false, "no first event"),
        Err(e) => check_error(&e)?,
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 128,
        rng_seed: RngSeed::Fixed(0x0e44_0014),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Blocks and grids, by cell size and by cell count: `Ok` with a finite, positive
    /// geometry, or a typed error.
    #[test]
    fn blocks_and_grids_never_panic(
        (lx, ly, lz) in (wild(0.14), wild(0.007), wild(0.075)),
        (dx, dy) in (wild(1e-3), wild(1e-3)),
        (nx, ny) in (count(), count()),
    ) {
        match Block::new(lx, ly, lz) {
            Err(e) => check_error(&e)?,
            Ok(block) => {
                prop_assert!(block.volume().is_finite() && block.volume() > 0.0);
                for grid in [Grid::from_cell_size(block, dx, dy), Grid::new(block, nx, ny)] {
                    match grid {
                        Err(e) => check_error(&e)?,
                        Ok(g) => {
                            prop_assert!(g.nx() >= 1 && g.ny() >= 1);
                            prop_assert!(g.len() == g.nx() * g.ny());
                            prop_assert!(g.dx().is_finite() && g.dx() > 0.0);
                            prop_assert!(g.dy().is_finite() && g.dy() > 0.0);
                            prop_assert!(g.cell_area().is_finite() && g.cell_area() > 0.0);
                            // The plan builder's guard refuses large grids at once.
                            if g.len() > MAX_CELLS {
                                let e = InfluencePlan::builder(g)
                                    .max_cells(MAX_CELLS)
                                    .build()
                                    .unwrap_err();
                                let refused = matches!(e, Error::GridTooLarge { .. });
                                prop_assert!(refused, "{}", e);
                            }
                        }
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 192,
        rng_seed: RngSeed::Fixed(0x0e44_0015),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// The scene builder with one to all of its numbers wild: `Ok` with finite values up
    /// to the first equilibrium, or a typed error.
    #[test]
    fn scene_builder_never_panics_nor_returns_nan(
        (lx, ly, lz) in (wild(0.02), wild(0.004), wild(0.01)),
        (dx, dy, by_size) in (wild(1e-3), wild(1e-3), any::<bool>()),
        (nx, ny) in (count(), count()),
        (young, poisson, mu) in (wild(3e9), wild(0.3), wild(0.5)),
        (c_x, c_z) in (wild(SpringLaw::default().c_x), wild(SpringLaw::default().c_z)),
        (mean, sd, seed) in (wild(1e-6), wild(1e-6), any::<u64>()),
        (load, drive_kind, a, b) in (wild(60.0), 0..5u8, wild(5e-3), wild(2e-3)),
        (plan_tol, solver_tol) in (wild(1e-6), wild(1e-13)),
        (wild_group, second) in (0..16u32, 0..24u32),
    ) {
        // One or two groups of values are wild (none when the draw is past the last
        // group), so that most draws reach the solver rather than fail at the first check.
        let wild_mask = (1u32 << wild_group) | (1u32 << second);
        let pick = |bit: u32, wild: f64, tame: f64| if wild_mask & (1 << bit) != 0 { wild } else { tame };
        let mut material = Material::default();
        material.young_modulus = pick(0, young, 3e9);
        material.poisson_ratio = pick(1, poisson, 0.35);
        material.friction_coefficient = pick(2, mu, 0.5);
        let mut law = SpringLaw::default();
        law.c_x = pick(3, c_x, law.c_x);
        law.c_z = pick(3, c_z, law.c_z);
        let lateral = Lateral::Rod { height: pick(4, a, 5e-3), half_width: pick(4, b, 2e-3) };
        let drive = match drive_kind {
            0 => Drive::Force(ForceLoad::Top),
            1 => Drive::Force(lateral.into()),
            2 => Drive::Force(ForceLoad::Mixed { ratio: pick(5, a * 100.0, 0.5), lateral: Lateral::Side }),
            3 => Drive::Spring { stiffness: pick(5, b * 1e9, 4e6), lateral },
            _ => Drive::Force(Lateral::Side.into()),
        };
        let mut builder = Scene::builder()
            .block(pick(6, lx, 0.02), pick(6, ly, 0.004), pick(7, lz, 0.01))
            .material(material)
            .springs(law)
            .heights(HeightSource::Random {
                distribution: HeightDistribution::new(pick(8, mean, 1e-6), pick(8, sd, 1e-6)),
                seed,
            })
            .normal_load(pick(9, load, 60.0))
            .drive(drive)
            .plan_tolerance(pick(10, plan_tol, 1e-6))
            .solver(SolverOptions::default().tolerance(pick(11, solver_tol, 1e-13)))
            .max_cells(MAX_CELLS);
        builder = if by_size {
            builder.cell_size(pick(12, dx, 1e-3), pick(12, dy, 1e-3))
        } else if wild_mask & (1 << 13) != 0 {
            builder.cells(nx, ny)
        } else {
            builder.cells(20, 4)
        };
        build_and_step(builder)?;
    }
}

/// The scene-file reader (feature `serde`).
#[cfg(feature = "serde")]
mod file {
    use super::*;

    /// Every path to a leaf of `value` (object keys and array indices).
    fn leaves(value: &serde_json::Value, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
        match value {
            serde_json::Value::Object(map) => {
                for (k, v) in map {
                    path.push(k.clone());
                    leaves(v, path, out);
                    path.pop();
                }
            }
            serde_json::Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    path.push(i.to_string());
                    leaves(v, path, out);
                    path.pop();
                }
            }
            _ => {}
        }
        out.push(path.clone());
    }

    fn at<'a>(value: &'a mut serde_json::Value, path: &[String]) -> &'a mut serde_json::Value {
        path.iter().fold(value, |v, key| match v {
            serde_json::Value::Array(items) => &mut items[key.parse::<usize>().unwrap()],
            other => &mut other[key.as_str()],
        })
    }

    /// A JSON value of any kind, numbers wild.
    fn json_value() -> impl Strategy<Value = serde_json::Value> {
        use serde_json::{json, Value};
        prop_oneof![
            Just(Value::Null),
            any::<bool>().prop_map(Value::Bool),
            wild(1.0)
                .prop_map(|x| serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)),
            (-1e6f64..1e6).prop_map(|x| json!(x)),
            any::<i64>().prop_map(|x| json!(x)),
            prop_oneof![
                Just(0u64),
                Just(1),
                Just(2),
                Just(7),
                Just(u64::MAX),
                Just(1 << 20)
            ]
            .prop_map(|x| json!(x)),
            prop_oneof![
                Just("auto"),
                Just("dense"),
                Just("spectral"),
                Just("rod"),
                Just("side"),
                Just("top"),
                Just("mixed"),
                Just("spring"),
                Just("size"),
                Just("count"),
                Just("gaussian"),
                Just("values"),
                Just("file"),
                Just("all"),
                Just("current"),
                Just(""),
                Just("1e-3"),
            ]
            .prop_map(|s| json!(s)),
            Just(json!([])),
            Just(json!({})),
            Just(json!([1e-6, 2e-6])),
            Just(json!({"kind": "count", "nx": 3, "ny": 2})),
        ]
    }

    /// A valid scene file away from the defaults, small enough to solve in milliseconds.
    fn base_scene() -> serde_json::Value {
        let builder = Scene::builder()
            .block(0.020, 0.004, 0.010)
            .cells(20, 4)
            .normal_load(60.0)
            .drive(Drive::Spring {
                stiffness: 4e6,
                lateral: Lateral::Rod {
                    height: 5e-3,
                    half_width: 2e-3,
                },
            })
            .probes(
                precursors::probe::ProbeSpec::default()
                    .plane(1e-3)
                    .point(Point::new(0.01, 0.002, 0.002)),
            )
            .max_cells(MAX_CELLS);
        serde_json::from_str(&builder.to_json().unwrap()).unwrap()
    }

    /// `base` with the value at `path` replaced by `value` (`how == 0`: the key removed;
    /// `how == 1`: the number text `huge`, which JSON or f64/u64 cannot hold), as text.
    fn substitute(
        base: &serde_json::Value,
        path: &[String],
        value: &serde_json::Value,
        how: u8,
        huge: &str,
    ) -> String {
        let mut scene = base.clone();
        if path.is_empty() {
            return value.to_string();
        }
        if how == 0 {
            let (last, parent) = path.split_last().unwrap();
            match at(&mut scene, parent) {
                serde_json::Value::Object(map) => {
                    map.remove(last);
                }
                other => *at(other, std::slice::from_ref(last)) = serde_json::Value::Null,
            }
            scene.to_string()
        } else if how == 1 {
            *at(&mut scene, path) = serde_json::json!("@@");
            scene.to_string().replace("\"@@\"", huge)
        } else {
            *at(&mut scene, path) = value.clone();
            scene.to_string()
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 48,
            rng_seed: RngSeed::Fixed(0x0e44_0016),
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// The scene-file reader with a key of a valid scene replaced by a random JSON
        /// value (or removed, or a number written as text that JSON cannot hold), every key
        /// in turn: `Ok` with finite values up to the first equilibrium, or a typed error.
        #[test]
        fn scene_files_with_a_random_value_never_panic(
            value in json_value(),
            how in 0..8u8,
            huge in prop_oneof![Just("1e400"), Just("-1e400"), Just("1e-400"), Just("NaN"), Just("18446744073709551616")],
        ) {
            let base = base_scene();
            let mut paths = Vec::new();
            leaves(&base, &mut Vec::new(), &mut paths);
            for path in &paths {
                let text = substitute(&base, path, &value, how, huge);
                match SceneBuilder::from_json_str(&text) {
                    Err(e) => check_error(&e)?,
                    Ok(builder) => build_and_step(builder)?,
                }
            }
        }
    }
}
