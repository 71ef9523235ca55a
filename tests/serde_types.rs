//! Serde on the configuration and result types (feature `serde`, issue 45 item 5): every
//! type goes through JSON and back to an equal value, built away from its default so a
//! field that were skipped or defaulted would show; and the validated types refuse an
//! invalid value with their constructor's error, naming the value or the key.

use precursors::solver::{Backend, Parallelism, SolverOptions};
use precursors::statistics::{fit_power_law, log_binned, PowerLawOptions, Support};
use precursors::{
    AreaLaw, Avalanches, Block, Drive, Event, ForceLoad, Grid, GridCost, HeightDistribution,
    HeightSource, Lateral, Material, Point, ProbeSpec, RunOptions, Scene, SpringLaw,
    SurfaceSpectrum,
};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt::Debug;

/// `value` through JSON and back: equal, and written again to the same text.
fn round_trip<T: Serialize + DeserializeOwned + PartialEq + Debug>(value: &T) -> String {
    let text = serde_json::to_string(value).unwrap();
    let back: T =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{text} does not read back: {e}"));
    assert_eq!(&back, value, "{text}");
    assert_eq!(serde_json::to_string(&back).unwrap(), text);
    text
}

/// The error of reading `text` as a `T`, which must be refused.
fn refused<T: DeserializeOwned + Debug>(text: &str) -> String {
    match serde_json::from_str::<T>(text) {
        Ok(value) => panic!("{text} was accepted as {value:?}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `message` contains every one of `parts`.
fn names(message: &str, parts: &[&str]) {
    for part in parts {
        assert!(message.contains(part), "{message:?} does not name {part:?}");
    }
}

#[test]
fn geometry_round_trips_and_is_validated() {
    let block = Block::new(0.012, 0.004, 0.007).unwrap();
    let text = round_trip(&block);
    assert_eq!(text, r#"{"lx":0.012,"ly":0.004,"lz":0.007}"#); // the scene file's keys
    let grid = Grid::new(block, 6, 2).unwrap();
    round_trip(&grid);
    round_trip(&Point::new(0.001, 0.002, 0.003));

    let e = refused::<Block>(r#"{"lx":-0.01,"ly":0.004,"lz":0.007}"#);
    names(&e, &["Lx = -0.01", "finite and > 0"]);
    let e = refused::<Block>(r#"{"lx":0.01,"ly":0.004,"lz":0.007,"lw":1}"#);
    names(&e, &["unknown field", "lw"]);
    let e = refused::<Grid>(r#"{"block":{"lx":0.01,"ly":0.004,"lz":0.007},"nx":0,"ny":2}"#);
    names(&e, &["at least one cell along x", "got 0"]);
    let e = refused::<Point>(r#"{"x":0,"y":0,"z":0,"w":0}"#);
    names(&e, &["unknown field", "w"]);
}

#[test]
fn interface_configuration_round_trips_and_is_validated() {
    let material = Material::new(2.5e9, 0.3, 0.6).unwrap();
    let text = round_trip(&material);
    names(
        &text,
        &["young_modulus", "poisson_ratio", "friction_coefficient"],
    );
    let law = SpringLaw::new(2.0e12, 1.0e8)
        .unwrap()
        .with_area_law(AreaLaw::Capped);
    round_trip(&law);
    round_trip(&HeightDistribution::new(2e-6, 0.5e-6).unwrap());

    // A missing key takes the default, as in the scene file.
    let partial: Material = serde_json::from_str(r#"{"friction_coefficient":0.7}"#).unwrap();
    assert_eq!(
        partial,
        Material::default().with_friction_coefficient(0.7).unwrap()
    );

    let e = refused::<Material>(r#"{"young_modulus":-1.0}"#);
    names(&e, &["young_modulus", "-1"]);
    let e = refused::<Material>(r#"{"poisson_ratio":0.6}"#);
    names(&e, &["poisson_ratio", "0.6"]);
    let e = refused::<Material>(r#"{"youngs_modulus":1e9}"#);
    names(&e, &["unknown field", "youngs_modulus"]);
    let e = refused::<SpringLaw>(r#"{"c_z":0.0}"#);
    names(&e, &["c_z", "0"]);
    let e = refused::<SpringLaw>(r#"{"area_law":"round"}"#);
    names(&e, &["round"]);
    let e = refused::<HeightDistribution>(r#"{"mean":1e-6,"std_dev":-1e-6}"#);
    names(&e, &["std_dev = -1e-6"]);
}

#[test]
fn solver_options_round_trip_and_are_validated() {
    let options = SolverOptions::default()
        .with_backend(Backend::Spectral)
        .unwrap()
        .with_tolerance(1e-12)
        .unwrap()
        .with_max_active_set_iterations(77)
        .unwrap()
        .with_max_linear_iterations(1234)
        .unwrap()
        .with_parallelism(Parallelism::Threads(3))
        .unwrap();
    round_trip(&options);
    round_trip(
        &SolverOptions::default()
            .with_parallelism(Parallelism::CurrentPool)
            .unwrap(),
    );

    let e = refused::<SolverOptions>(r#"{"tolerance":0.0}"#);
    names(&e, &["tolerance 0", "finite and > 0"]);
    let e = refused::<SolverOptions>(r#"{"max_linear_iterations":0}"#);
    names(&e, &["max_linear_iterations = 0"]);
    // The dense backend runs on one thread, whatever the order of the keys.
    let e = refused::<SolverOptions>(r#"{"backend":"Dense","parallelism":{"Threads":4}}"#);
    names(&e, &["4"]);
    let e = refused::<SolverOptions>(r#"{"parallelism":{"Threads":0}}"#);
    names(&e, &["threads = 0"]);
    let e = refused::<SolverOptions>(r#"{"threads":2}"#);
    names(&e, &["unknown field", "threads"]);
}

#[test]
fn probes_and_run_options_round_trip_and_keep_their_invariants() {
    let spec = ProbeSpec::default()
        .with_plane(0.002)
        .with_plane(0.0)
        .with_point(Point::new(0.005, 0.002, 0.003))
        .with_tolerance(1e-12)
        .unwrap();
    let text = round_trip(&spec);
    assert_eq!(
        text,
        r#"{"planes":[0.002,0.0],"points":[[0.005,0.002,0.003]],"tolerance":1e-12}"#
    );
    let e = refused::<ProbeSpec>(r#"{"tolerance":-1.0}"#);
    names(&e, &["tolerance -1"]);
    let e = refused::<ProbeSpec>(r#"{"plane":[0.002]}"#);
    names(&e, &["unknown field", "plane"]);

    let options = RunOptions::new()
        .record_fields(5, &[0.002])
        .record_profiles(&[0.9, 0.1, 0.5], &[0.0, 0.003]);
    round_trip(&options);
    // Read through `record_profiles`: the loads sorted, each once.
    let read: RunOptions =
        serde_json::from_str(r#"{"profiles":{"loads":[0.9,0.1,0.5,0.1],"planes":[0.002]}}"#)
            .unwrap();
    assert_eq!(read.profile_loads(), [0.1, 0.5, 0.9]);
    assert_eq!(
        read,
        RunOptions::new().record_profiles(&[0.1, 0.5, 0.9], &[0.002])
    );
    let e = refused::<RunOptions>(r#"{"fields":{"every":2,"plane":[]}}"#);
    names(&e, &["unknown field", "plane"]);
    // Probes and threads: written only when given, so options without them read and
    // write as before they existed.
    let observed = options
        .clone()
        .probes(ProbeSpec::default().with_plane(0.002))
        .threads(3);
    let text = round_trip(&observed);
    assert!(
        text.contains(r#""probes":{"#) && text.contains(r#""threads":3"#),
        "{text}"
    );
    assert!(!round_trip(&options).contains("probes"));
    let read: RunOptions = serde_json::from_str(r#"{"threads":2}"#).unwrap();
    assert_eq!((read.thread_count(), read.probe_spec()), (2, None));
}

#[test]
fn surfaces_and_height_sources_round_trip_and_are_validated() {
    let gaussian = SurfaceSpectrum::gaussian(2e-3).unwrap();
    let text = round_trip(&gaussian);
    assert_eq!(text, r#"{"kind":"gaussian","correlation_length":0.002}"#);
    let affine = SurfaceSpectrum::self_affine(0.8, 2e-3, 5e-4, 4e-3).unwrap();
    round_trip(&affine);
    let e = refused::<SurfaceSpectrum>(
        r#"{"kind":"self_affine","hurst":0.8,"roll_off":2e-3,"short_cutoff":3e-3,"long_cutoff":4e-3}"#,
    );
    names(&e, &["short_cutoff"]);
    let e = refused::<SurfaceSpectrum>(r#"{"kind":"gaussian","correlation_length":-1.0}"#);
    names(&e, &["correlation_length", "-1"]);

    let distribution = HeightDistribution::new(2e-6, 0.5e-6).unwrap();
    for source in [
        HeightSource::Random {
            distribution,
            seed: 7,
        },
        HeightSource::Values(vec![1e-6, 2e-6, 1.5e-6]),
        HeightSource::Surface {
            spectrum: gaussian,
            distribution,
            seed: 3,
        },
        HeightSource::Surface {
            spectrum: affine,
            distribution,
            seed: 4,
        },
    ] {
        round_trip(&source);
    }
    // The scene file's `heights` object and its defaults.
    let read: HeightSource = serde_json::from_str(r#"{"kind":"gaussian","seed":9}"#).unwrap();
    assert_eq!(
        read,
        HeightSource::Random {
            distribution: HeightDistribution::default(),
            seed: 9
        }
    );
    let e = refused::<HeightSource>(r#"{"kind":"gaussian","std_dev":-2e-6}"#);
    names(&e, &["std_dev"]);
    let e = refused::<HeightSource>(r#"{"kind":"file","path":"heights.txt"}"#);
    names(&e, &["unknown variant", "file"]);
    let e = refused::<HeightSource>(r#"{"kind":"values","values":[1e-6],"seed":1}"#);
    names(&e, &["unknown field", "seed"]);
}

#[test]
fn drives_round_trip_as_the_scene_file_spells_them() {
    let rod = Lateral::Rod {
        height: 5e-3,
        half_width: 1e-3,
    };
    assert_eq!(
        round_trip(&rod),
        r#"{"kind":"rod","height":0.005,"half_width":0.001}"#
    );
    assert_eq!(round_trip(&Lateral::Side), r#"{"kind":"side"}"#);
    for load in [
        ForceLoad::Top,
        ForceLoad::Lateral(rod),
        ForceLoad::Lateral(Lateral::Side),
        ForceLoad::Mixed {
            ratio: 2.0,
            lateral: rod,
        },
    ] {
        round_trip(&load);
        round_trip(&Drive::Force(load));
    }
    let spring = Drive::Spring {
        stiffness: 4e6,
        lateral: Lateral::Side,
    };
    assert_eq!(
        round_trip(&spring),
        r#"{"kind":"spring","stiffness":4000000.0,"lateral":{"kind":"side"}}"#
    );
    // A scene file's `drive` object reads as a drive.
    let read: Drive = serde_json::from_str(
        r#"{"kind":"mixed","ratio":2.0,"lateral":{"kind":"rod","height":0.005,"half_width":0.001}}"#,
    )
    .unwrap();
    assert_eq!(
        read,
        Drive::Force(ForceLoad::Mixed {
            ratio: 2.0,
            lateral: rod
        })
    );
    let e = refused::<ForceLoad>(r#"{"kind":"spring","stiffness":1.0,"lateral":{"kind":"side"}}"#);
    names(&e, &["unknown variant", "spring"]);
    let e = refused::<Lateral>(r#"{"kind":"rod","height":0.005}"#);
    names(&e, &["missing field", "half_width"]);
    let e = refused::<Drive>(r#"{"kind":"top","ratio":1.0}"#);
    names(&e, &["unknown field", "ratio"]);
    let e = refused::<Lateral>(r#"{"kind":"side","height":0.005}"#);
    names(&e, &["unknown field", "height"]);
}

#[test]
fn results_of_a_run_round_trip() {
    let scene = Scene::builder()
        .block(0.010, 0.004, 0.010)
        .normal_load(100.0)
        .probes(
            ProbeSpec::default()
                .with_plane(0.002)
                .with_point(Point::new(0.005, 0.002, 0.003)),
        )
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    let mut avalanches = Avalanches::new(scene.grid());
    let mut found = Vec::new();
    let mut events = 0;
    while let Some(event) = driver.step().unwrap() {
        events += 1;
        found.extend(avalanches.observe(&event));
        if events == 12 {
            // Mid-run, under shear: the stresses and profiles are not those at rest.
            let stresses = driver.stresses().unwrap();
            assert_eq!((stresses.planes.len(), stresses.points.len()), (1, 1));
            round_trip(&stresses);
            let plane = &stresses.planes[0];
            round_trip(plane);
            round_trip(&plane.profile());
            round_trip(&plane.at(3, 1).unwrap());
            round_trip(&stresses.points[0]);
            let slip = driver.slip_profile().unwrap();
            assert!(slip.slip().iter().any(|&u| u != 0.0));
            round_trip(&slip);
        }
        if matches!(event, Event::GlobalSlip { .. }) {
            break;
        }
    }
    assert!(events > 12, "{events} events");
    let stats = driver.solve_stats();
    assert!(stats.normal_solves > 0 && stats.tangential_solves > 0);
    round_trip(&stats);
    assert!(found.len() > 1, "{} avalanches", found.len());
    for avalanche in &found {
        round_trip(avalanche);
    }
    round_trip(&GridCost::of(140, 7));
}

#[test]
fn a_plane_of_stresses_is_checked_when_read() {
    let scene = Scene::builder()
        .block(0.010, 0.004, 0.010)
        .normal_load(100.0)
        .probes(ProbeSpec::default().with_plane(0.002))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    driver.step().unwrap();
    let plane = driver.stresses().unwrap().planes.remove(0);
    let mut json: serde_json::Value = serde_json::to_value(&plane).unwrap();
    // A plane and a profile written before 1.2 (no `dx`, no `x`) read back; the profile
    // then has no abscissa. A written `dx` is a length.
    let profile = plane.profile();
    assert_eq!(profile.x().len(), 10);
    let mut old = json.clone();
    old.as_object_mut()
        .unwrap()
        .remove("dx")
        .expect("dx is written");
    let old: precursors::PlaneStress = serde_json::from_value(old).unwrap();
    assert_eq!(old.shear(), plane.shear());
    assert!(old.profile().x().is_empty());
    let mut old_profile = serde_json::to_value(&profile).unwrap();
    old_profile
        .as_object_mut()
        .unwrap()
        .remove("x")
        .expect("x is written");
    let old_profile: precursors::Profile = serde_json::from_value(old_profile).unwrap();
    assert_eq!(old_profile.mean_coulomb(), profile.mean_coulomb());
    assert!(old_profile.x().is_empty());
    let mut bad = json.clone();
    bad["dx"] = (-1.0).into();
    let e = refused::<precursors::PlaneStress>(&bad.to_string());
    names(&e, &["dx"]);
    json["nx"] = 0.into();
    let e = refused::<precursors::PlaneStress>(&json.to_string());
    names(&e, &["at least one cell along x"]);
    json["nx"] = 3.into();
    let e = refused::<precursors::PlaneStress>(&json.to_string());
    names(&e, &["shear has 40 values", "needs 12"]);
}

#[test]
fn statistics_round_trip() {
    // Pareto samples with α = 2.5 above 1 (quantiles, no generator needed).
    let samples: Vec<f64> = (1..=400)
        .map(|i| (1.0 - (i as f64 - 0.5) / 400.0).powf(-1.0 / 1.5))
        .collect();
    let options = PowerLawOptions::default()
        .bootstrap(20)
        .goodness_samples(20)
        .seed(5);
    round_trip(&options);
    let fit = fit_power_law(&samples, Support::Continuous, &options).unwrap();
    assert!(fit.p_value.is_some());
    round_trip(&fit);
    let bins = log_binned(&samples, Support::Continuous, 5).unwrap();
    assert!(bins.len() > 2);
    round_trip(&bins);
    round_trip(&Support::Discrete);
}
