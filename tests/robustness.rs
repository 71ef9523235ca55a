//! No panic, no NaN: the builders and the scene-file reader, fed random values (zero,
//! negative, huge, tiny, NaN, infinite, and plausible ones), either succeed with finite
//! values all the way to the first equilibrium or return a typed error with a message.
//!
//! The draws are fixed (`RngSeed::Fixed`) so that CI is repeatable; each test was seen to
//! fail with a guard of the code under test removed (the commit message lists them).

use precursors::green::InfluencePlan;
use precursors::solver::SolverOptions;
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

/// Events a scene that builds is stepped through (tiny grids: milliseconds each).
const STEPS: usize = 5;

/// The most wall time one case may take (debug build, a machine shared by other jobs):
/// a scene is refused or stepped in milliseconds, so this catches a hang, not a slow path.
const CASE_SECONDS: f64 = 60.0;

/// The largest `F/(μF_N)` a state may carry: the friction limit, as `RunTables` refuses
/// beyond it (no stable state carries more than `μF_N`).
const LOAD_LIMIT: f64 = 1.0 + 1e-5;

/// The invariants of an equilibrium, whatever the scene: every field finite, the normal
/// tractions balance `F_N` and push (the springs do not pull), the springs' law holds, the
/// load is finite, the total real contact area is finite and (unless flagged) within the
/// nominal face.
fn check_state(driver: &Driver) -> Result<(), TestCaseError> {
    let phi = driver.normal_traction().unwrap();
    prop_assert!(all_finite(phi));
    prop_assert!(all_finite(driver.normal_displacement().unwrap()));
    prop_assert!(all_finite(driver.shear_traction().unwrap()));
    prop_assert!(all_finite(&driver.cell_contact_area().unwrap()));
    prop_assert!(driver.breaking_loads().iter().all(|b| !b.is_nan()));
    let f_n = driver.normal_load();
    let cell = driver.grid().cell_area();
    let sum: f64 = phi.iter().sum::<f64>() * cell;
    prop_assert!(
        (sum - f_n).abs() <= 1e-6 * f_n,
        "ΔA Σ φ_z = {sum} N, F_N = {f_n} N"
    );
    let largest = phi.iter().fold(0.0f64, |m, v| m.max(*v));
    let smallest = phi.iter().fold(0.0f64, |m, v| m.min(*v));
    prop_assert!(
        smallest >= -1e-6 * largest,
        "a spring pulls: φ_z = {smallest} Pa (largest {largest} Pa)"
    );
    // The springs' law holds: an attached site sits at `u_z = u0 - φ_z u0/c_z`, a
    // detached one above its height (to 1e-3 of the largest displacement or height: the
    // loosest solver tolerance is 1e-6; `solver.tolerance = 1` gave errors of order 1).
    let u = driver.normal_displacement().unwrap();
    let h = driver.interface().heights();
    let c_z = driver.interface().law().c_z();
    let scale = h.iter().chain(u).fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = (0..u.len()).fold(0.0f64, |m, i| {
        m.max(match driver.site_states()[i] {
            SiteState::Attached => (u[i] - (h[i] - phi[i] * h[i] / c_z)).abs(),
            SiteState::Detached => (h[i] - u[i]).max(0.0),
            _ => 0.0,
        })
    });
    prop_assert!(
        worst <= 1e-3 * scale,
        "the springs' law is off by {worst} m (scale {scale} m)"
    );
    let ratio = driver.force() / (driver.friction_coefficient() * f_n);
    prop_assert!(ratio.is_finite() && ratio >= 0.0, "F/(μF_N) = {ratio}");
    let area = driver.real_contact_area().unwrap();
    prop_assert!(area.is_finite() && area >= 0.0, "A_R = {area}");
    if !driver.area_exceeds_nominal().unwrap() {
        prop_assert!(
            area <= driver.nominal_area() * (1.0 + 1e-12),
            "A_R = {area} m²"
        );
    }
    Ok(())
}

/// Builds `builder` and, if it builds, steps it through its first [`STEPS`] events:
/// every state passes [`check_state`], or an error with a message is returned, within
/// [`CASE_SECONDS`]. [`SceneBuilder::check`] refuses exactly what `build` refuses, but a
/// plan that misses its tolerance.
fn build_and_step(builder: SceneBuilder) -> Result<(), TestCaseError> {
    let started = std::time::Instant::now();
    let checked = builder.check();
    let scene = match builder.build() {
        Ok(scene) => scene,
        Err(e) => {
            match (&checked, &e) {
                (Err(c), e) => prop_assert_eq!(c.to_string(), e.to_string()),
                (Ok(_), Error::SeriesNotConverged { .. } | Error::SingularPoint { .. }) => {}
                (Ok(_), e) => prop_assert!(false, "check() accepted what build refuses: {e}"),
            }
            return check_error(&e);
        }
    };
    prop_assert!(checked.is_ok(), "check() refused what build accepts");
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
    for step in 0..STEPS {
        match driver.step() {
            Ok(Some(event)) => {
                if let Event::Stable { load, .. }
                | Event::Rupture { load, .. }
                | Event::LoadRaised { load }
                | Event::GlobalSlip { load } = event
                {
                    prop_assert!(load.force.is_finite() && load.force >= 0.0, "{event:?}");
                    prop_assert!(load.drive_displacement.is_none_or(f64::is_finite));
                }
                // Within the friction limit at a stable state (in an avalanche a driving
                // spring's force may overshoot it).
                if let Event::Stable { load, .. } = event {
                    let ratio = load.force / (driver.friction_coefficient() * driver.normal_load());
                    prop_assert!(ratio <= LOAD_LIMIT, "F/(μF_N) = {ratio}");
                }
                check_state(&driver)?;
            }
            Ok(None) => {
                prop_assert!(step > 0, "no first event");
                break;
            }
            Err(e) => {
                check_error(&e)?;
                break;
            }
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    prop_assert!(seconds < CASE_SECONDS, "{seconds} s");
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
        (c_x, c_z) in (wild(SpringLaw::default().c_x()), wild(SpringLaw::default().c_z())),
        (mean, sd, seed) in (wild(1e-6), wild(1e-6), any::<u64>()),
        (load, drive_kind, a, b) in (wild(60.0), 0..5u8, wild(5e-3), wild(2e-3)),
        (plan_tol, solver_tol) in (wild(1e-6), wild(1e-13)),
        (active_set, linear) in (count(), count()),
        (wild_group, second) in (0..16u32, 0..24u32),
    ) {
        // One or two groups of values are wild (none when the draw is past the last
        // group), so that most draws reach the solver rather than fail at the first check.
        let wild_mask = (1u32 << wild_group) | (1u32 << second);
        let pick = |bit: u32, wild: f64, tame: f64| if wild_mask & (1 << bit) != 0 { wild } else { tame };
        // The value types refuse invalid values when made (a typed error: the property
        // holds); the scene checks the rest.
        let parts = (|| -> precursors::Result<_> {
            let material = Material::new(pick(0, young, 3e9), pick(1, poisson, 0.35), pick(2, mu, 0.5))?;
            let law = SpringLaw::new(
                pick(3, c_x, SpringLaw::default().c_x()),
                pick(3, c_z, SpringLaw::default().c_z()),
            )?;
            let distribution = HeightDistribution::new(pick(8, mean, 1e-6), pick(8, sd, 1e-6))?;
            let mut solver = SolverOptions::default().with_tolerance(pick(11, solver_tol, 1e-13))?;
            if wild_mask & (1 << 14) != 0 {
                solver = solver
                    .with_max_active_set_iterations(active_set)?
                    .with_max_linear_iterations(linear)?;
            }
            Ok((material, law, distribution, solver))
        })();
        let Ok((material, law, distribution, solver)) = parts else {
            return Ok(());
        };
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
                distribution,
                seed,
            })
            .normal_load(pick(9, load, 60.0))
            .drive(drive)
            .plan_tolerance(pick(10, plan_tol, 1e-6))
            .solver_options(solver)
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
            .seed(0)
            .drive(Drive::Spring {
                stiffness: 4e6,
                lateral: Lateral::Rod {
                    height: 5e-3,
                    half_width: 2e-3,
                },
            })
            .probes(
                precursors::ProbeSpec::default()
                    .with_plane(1e-3)
                    .with_point(Point::new(0.01, 0.002, 0.002)),
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

    /// Every number of a scene file, in turn, at each extreme a user can write (zero,
    /// negative, the smallest and largest normal and subnormal magnitudes, 1e±306, huge
    /// counts), on a spring-driven rod scene and a mixed-load scene: refused with a typed
    /// error, or stepped through its first events with every state finite and within
    /// the friction limit, each within the time bound. Not random: every key meets every
    /// extreme (the inputs of issue 23 among them: `drive.stiffness = 1e-306`, a block side
    /// of 1e308, `solver.tolerance` of 1, 10 and 1e308).
    #[test]
    fn every_key_at_every_extreme_is_refused_or_finite() {
        use serde_json::json;
        let extremes = [
            json!(0.0),
            json!(-1.0),
            json!(1.0),
            json!(10.0),
            json!(5e-324),
            json!(f64::MIN_POSITIVE),
            json!(1e-306),
            json!(1e-15),
            json!(1e15),
            json!(1e306),
            json!(1e308),
            json!(f64::MAX),
            json!(-f64::MAX),
            json!(u64::MAX),
            json!(1u64 << 40),
        ];
        let mixed = {
            let mut scene = base_scene();
            scene["drive"] = json!({"kind": "mixed", "ratio": 0.5, "lateral": {"kind": "side"}});
            scene
        };
        for base in [base_scene(), mixed] {
            let mut paths = Vec::new();
            leaves(&base, &mut Vec::new(), &mut paths);
            for path in &paths {
                if !at(&mut base.clone(), path).is_number() {
                    continue;
                }
                for value in &extremes {
                    let text = substitute(&base, path, value, 2, "");
                    let outcome = match SceneBuilder::from_json_str(&text) {
                        Err(e) => check_error(&e),
                        Ok(builder) => build_and_step(builder),
                    };
                    if let Err(e) = outcome {
                        panic!("{} = {value}: {e}", path.join("."));
                    }
                }
            }
        }
    }

    /// Each key at the bounds of its valid range (docs/scene-format.md, "Valid ranges"),
    /// alone on the spring-driven rod scene: the computation honours the range (refused
    /// for another key's range, or stepped with every state finite and the springs' law
    /// and the friction limit holding).
    #[test]
    fn every_key_at_the_bounds_of_its_range_is_honoured() {
        // The block's shear stiffness M·Ly·Lz/Lx of the base scene (N/m).
        let block = 3.833e9 / 1.38 * 0.004 * 0.010 / 0.020;
        let bounds: [(&str, f64, f64); 16] = [
            ("material.young_modulus", 1e-3, 1e15),
            ("material.poisson_ratio", -0.999_999, 0.5),
            ("material.friction_coefficient", 1e-6, 1e3),
            ("springs.c_x", 1e-3, 1e24),
            ("springs.c_z", 1e-3, 1e21),
            ("normal_load", 1e-9, 1e15),
            ("heights.mean", 1e-15, 1e3),
            ("heights.std_dev", 1e-15, 1e3),
            (
                "drive.stiffness",
                1.000_001e-12 * block,
                0.999_999e12 * block,
            ),
            ("drive.lateral.half_width", 1.01e-8, 2e-3),
            ("solver.tolerance", 1e-15, 1e-6),
            ("solver.max_active_set_iterations", 1.0, 1e6),
            ("solver.max_linear_iterations", 1.0, 1e7),
            ("plan_tolerance", 1e-8, 1e-2),
            ("probes.tolerance", 1e-15, 1e-2),
            ("block.lz", 0.02e-6 * 1.01, 4e3 * 0.99),
        ];
        for (key, low, high) in bounds {
            let mut base = base_scene();
            if key == "springs.c_z" {
                // Springs up to 1e21 N/m² are resolved against a stiff block only (the
                // solver tolerance's bound `5e-2·p/R`, docs/scene-format.md).
                base["material"]["young_modulus"] = serde_json::json!(1e15);
            }
            if key == "normal_load" {
                // Within 650 ΔA c_z (the last site's exponent) and the block's displacement
                // within 1e10 asperity heights up to 1e15 N: stiff springs and block.
                base["springs"]["c_z"] = serde_json::json!(1e21);
                base["material"]["young_modulus"] = serde_json::json!(1e15);
            }
            let path: Vec<String> = key.split('.').map(String::from).collect();
            for v in [low, high] {
                let value = if key.contains("iterations") {
                    serde_json::json!(v as u64)
                } else {
                    serde_json::json!(v)
                };
                let text = substitute(&base, &path, &value, 2, "");
                let builder = SceneBuilder::from_json_str(&text).unwrap();
                if let Err(Error::OutOfRange { key: k, .. }) = builder.check() {
                    assert_ne!(k, key, "{key} = {v} refused for its own key");
                }
                if let Err(e) = build_and_step(builder) {
                    panic!("{key} = {v}: {e}");
                }
            }
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

/// `contact_map.csv` cannot run away whatever the driver returns: a stable state beyond
/// the friction limit (impossible physics: `F/(μF_N) = 3e4` was seen, and `+∞` wrote rows
/// forever; JSON holds no infinity, `f64::MAX` N stands for it) is refused with
/// `Error::LoadBeyondFriction` and no row for it, and the levels of global slip stop at
/// the limit. The events are read from JSON (feature `serde`), as a broken driver could
/// return them.
#[cfg(feature = "serde")]
#[test]
fn the_contact_map_refuses_loads_beyond_the_friction_limit() {
    use precursors::output::RunTables;
    let dir = crate::common::scratch("map-guard");
    let scene = Scene::builder()
        .block(0.02, 0.004, 0.01)
        .cells(20, 4)
        .normal_load(60.0)
        .seed(0)
        .build()
        .unwrap();
    let mu_fn = 0.5 * 60.0;
    let event = |kind: &str, ratio: f64| -> Event {
        let force = serde_json::to_string(&(ratio * mu_fn).min(f64::MAX)).unwrap();
        let load = format!(r#"{{"force": {force}, "drive_displacement": null}}"#);
        let text = match kind {
            "stable" => format!(r#"{{"Stable": {{"load": {load}, "ruptures": 0}}}}"#),
            _ => format!(r#"{{"GlobalSlip": {{"load": {load}}}}}"#),
        };
        serde_json::from_str(&text).unwrap()
    };
    // (kind, F/(μF_N), refused): a stable state beyond the limit is refused; global slip
    // may overshoot it under a driving spring (the last avalanche), its rows stop at it.
    for (kind, ratio, refused) in [
        ("stable", 1.0, false),
        ("stable", 1.0 + 1e-6, false),
        ("stable", 1.001, true),
        ("stable", 3e4, true),
        ("stable", f64::INFINITY, true),
        ("slip", 1.0, false),
        ("slip", 1.04, false),
        ("slip", f64::INFINITY, false),
    ] {
        let mut driver = scene.driver().unwrap();
        let mut tables = RunTables::create(&dir, &driver).unwrap();
        let first = driver.step().unwrap().unwrap();
        tables.record(&driver, &first).unwrap();
        // On a thread: a loop without end must fail the test, not hang it.
        let event = event(kind, ratio);
        let (send, receive) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let result = tables.record(&driver, &event).map(|_| tables.flush());
            // The directory's lock goes with the tables: released before the answer.
            drop(tables);
            send.send(result.map_err(|e| e.to_string())).ok();
        });
        let result = receive
            .recv_timeout(std::time::Duration::from_secs(20))
            .unwrap_or_else(|_| panic!("{kind} at F/(μF_N) = {ratio}: no answer in 20 s"));
        // The run did not reach global slip: its tables are still `.partial`.
        let map = std::fs::read_to_string(dir.join("contact_map.csv.partial")).unwrap();
        if refused {
            let e = result.unwrap_err();
            assert!(e.contains("exceeds the friction limit"), "{e}");
            assert!(
                map.lines().count() <= 2,
                "{ratio}: {} rows",
                map.lines().count()
            );
        } else {
            assert!(result.is_ok(), "{kind} at {ratio}: {result:?}");
            // The header, then one row per level 0, 0.005, ... below the load, at most
            // up to 1 (201 levels).
            let levels = ((ratio / 0.005).ceil() as usize).min(201);
            assert_eq!(map.lines().count(), 1 + levels, "{kind} at {ratio}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
