//! Maps of the friction coefficient and of `c_x`, `c_z` (issue 55, item 2; the scene key
//! `maps`): a uniform map gives the scalar scene's events bit for bit, a drawn map is
//! value-stable against an independent computation, every state balances its loads and
//! holds each site's own Coulomb bound, the two backends agree, a run resumes to the
//! same tables, and bad maps are refused with typed errors naming the key, the site or
//! the file's line.

use crate::common::events::{assert_balanced, backends_agree, run};
use crate::common::scratch;
use precursors::{
    Block, Drive, Error, Event, Grid, Heights, Interface, Scene, SceneBuilder, SiteMap, SiteState,
    SpringLaw, SurfaceSpectrum,
};
use proptest::prelude::*;

/// A 16 x 4 scene of random heights (1 mm cells, F_N = 60 N) under `drive`.
fn base(drive: Drive, seed: u64) -> SceneBuilder {
    Scene::builder()
        .block(0.016, 0.004, 0.010)
        .cells(16, 4)
        .normal_load(60.0)
        .drive(drive)
        .seed(seed)
}

fn events(scene: &Scene) -> Vec<Event> {
    run(scene, |_, _| ()).into_iter().map(|(e, _)| e).collect()
}

/// The scene with every value of `μ`, `c_x` and `c_z` given as a map equal to its scalar.
fn uniform(builder: SceneBuilder, mu: f64, c_x: f64, c_z: f64) -> SceneBuilder {
    let n = builder.grid().unwrap().len();
    builder
        .friction_map(SiteMap::Values(vec![mu; n]))
        .c_x_map(SiteMap::Values(vec![c_x; n]))
        .c_z_map(SiteMap::Values(vec![c_z; n]))
}

/// A map whose every value is the scalar gives exactly the scalar scene's events (loads
/// compared bit for bit, `Event`'s `==`), under a rod drive, a top drive and the anchored
/// rule. At the paper's constants this is the promise of issue 55; at other values
/// (μ = 0.7, c_x = 4e11, c_z = 3e8 against the defaults in the material and the springs)
/// it also shows that every read of μ, c_x and c_z takes the map: a read left on the
/// scalar would run the defaults and give other events. Shown by dropping the c_x map
/// from `Interface::tangential_compliance_at` (then the events at 4e11 differ).
#[test]
fn a_uniform_map_gives_the_scalar_scenes_events() {
    let anchored = SceneBuilder::from_json_str(r#"{"contact": {"rule": "anchored"}}"#)
        .unwrap()
        .block(0.016, 0.004, 0.010)
        .cells(16, 4)
        .normal_load(60.0)
        .seed(3);
    let cases = [
        (base(Drive::rod(3e-3, 1e-3), 1), "rod"),
        (base(Drive::top(), 2), "top"),
        (anchored, "anchored, rod"),
    ];
    let law = SpringLaw::default();
    for (builder, name) in cases {
        // The paper's constants: the scalar scene as it is.
        let scalar = events(&builder.clone().build().unwrap());
        let mapped = events(
            &uniform(builder.clone(), 0.5, law.c_x(), law.c_z())
                .build()
                .unwrap(),
        );
        assert!(scalar.len() > 10, "{name}: {} events", scalar.len());
        assert_eq!(scalar, mapped, "{name}: the paper's constants");
        // Other constants, as scalars and as maps.
        let other = builder
            .clone()
            .material(
                precursors::Material::default()
                    .with_friction_coefficient(0.7)
                    .unwrap(),
            )
            .springs(SpringLaw::new(4e11, 3e8).unwrap());
        let scalar = events(&other.build().unwrap());
        let mapped = events(&uniform(builder, 0.7, 4e11, 3e8).build().unwrap());
        assert_eq!(scalar, mapped, "{name}: μ 0.7, c_x 4e11, c_z 3e8");
    }
}

/// A drawn map without spread (`std_dev` 0) is its mean at every site: the scalar
/// scene's events too, through the generator's path.
#[test]
fn a_drawn_map_without_spread_gives_the_scalar_scenes_events() {
    let builder = base(Drive::rod(3e-3, 1e-3), 5);
    let flat = |mean| SiteMap::Surface {
        spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
        mean,
        std_dev: 0.0,
        seed: 4,
    };
    let scalar = events(&builder.clone().build().unwrap());
    let mapped = events(
        &builder
            .friction_map(flat(0.5))
            .c_x_map(flat(SpringLaw::default().c_x()))
            .build()
            .unwrap(),
    );
    assert_eq!(scalar, mapped);
}

/// Maps pinned to values computed once by `docs/experiments/surface_reference.py`
/// (`heights(0.008, 0.004, 4, 2, gaussian(ξ), mean, sd, seed, 16)`: pure Python and mpmath,
/// written from docs/model.md section 3.1, not from the Rust code), as the heights'
/// `surfaces::pinned_gaussian_surface`: the map is the heights' generator with its own
/// marginal and seed. Tolerance `2e-10 sd` on each value.
#[test]
fn pinned_drawn_maps() {
    let grid = Block::new(0.008, 0.004, 0.005).unwrap();
    let builder = Scene::builder()
        .block(grid.lx(), grid.ly(), grid.lz())
        .cells(4, 2)
        .normal_load(1.0)
        .drive(Drive::top());
    let mu = SiteMap::Surface {
        spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
        mean: 0.5,
        std_dev: 0.1,
        seed: 13,
    };
    let c_x = SiteMap::Surface {
        spectrum: SurfaceSpectrum::gaussian(1.5e-3).unwrap(),
        mean: 1.65e12,
        std_dev: 0.5e12,
        seed: 21,
    };
    let scene = builder.friction_map(mu).c_x_map(c_x).build().unwrap();
    let interface = scene.interface();
    let cases: [(&[f64], &[f64], f64); 2] = [
        (interface.friction_map().unwrap(), &PINNED_MU, 0.1),
        (interface.c_x_map().unwrap(), &PINNED_C_X, 0.5e12),
    ];
    for (found, expected, sd) in cases {
        assert_eq!(found.len(), 8);
        for (i, (v, e)) in found.iter().zip(expected).enumerate() {
            assert!((v - e).abs() < 2e-10 * sd, "cell {i}: {v:e} vs {e:e}");
        }
    }
    assert!(interface.c_z_map().is_none());
}

/// `pinned_drawn_maps`' μ: ξ = 2 mm, mean 0.5, sd 0.1, seed 13.
const PINNED_MU: [f64; 8] = [
    0.44832447725752345,
    0.5768700875990376,
    0.5160583753935883,
    0.5276559056861501,
    0.5557029503213355,
    0.6003900095686759,
    0.5206854011502802,
    0.528631667446412,
];
/// `pinned_drawn_maps`' c_x (N/m³): ξ = 1.5 mm, mean 1.65e12, sd 0.5e12, seed 21.
const PINNED_C_X: [f64; 8] = [
    1536352643918.5803,
    1808205553087.5068,
    1738104282175.4365,
    1120264437520.9434,
    895741681478.317,
    1749356520007.9219,
    2361076541581.991,
    1543456255625.4795,
];

/// Heterogeneous maps (μ from 0.35 to 0.9, c_x and c_z drawn): after every event the
/// state balances its loads (`ΔA Σ φ_z = F_N`, `ΔA Σ φ_x = -F`), and at every stable
/// state each attached site holds its own bound `|φ_x,i| ≤ μ_i φ_z,i`; some site holds
/// more than the material's μ allows (so the bound is the map's, not the scalar's: the
/// scalar rule would have broken it), and the tables' unit, the friction limit, is
/// `max μ_i F_N`, which no stable state exceeds.
#[test]
fn every_state_balances_its_loads_and_holds_each_sites_bound() {
    for (drive, name) in [(Drive::top(), "top"), (Drive::rod(3e-3, 1e-3), "rod")] {
        let builder = base(drive, 7);
        let n = 64;
        let mu: Vec<f64> = (0..n)
            .map(|i| 0.35 + 0.55 * ((i * 37) % n) as f64 / (n - 1) as f64)
            .collect();
        let scene = builder
            .friction_map(SiteMap::Values(mu.clone()))
            .c_z_map(SiteMap::Surface {
                spectrum: SurfaceSpectrum::gaussian(3e-3).unwrap(),
                mean: 1.65e8,
                std_dev: 0.4e8,
                seed: 8,
            })
            .build()
            .unwrap();
        let material = scene.material().friction_coefficient();
        let f_n = scene.normal_load();
        // The definition: the larger of the material's μ and the map's largest (0.9).
        let limit = mu.iter().fold(material, |a, &b| a.max(b)) * f_n;
        assert!((limit / f_n - 0.9).abs() < 1e-15);
        let cell = scene.grid().cell_area();
        let mut beyond_material = false;
        let mut stable = 0;
        run(&scene, |event, driver| {
            assert_eq!(driver.friction_limit(), limit, "{name}");
            if matches!(event, Event::GlobalSlip { .. }) {
                return;
            }
            let (phi_x, phi_z) = assert_balanced(driver, event, (cell, f_n), name);
            if let Event::Stable { load, .. } = event {
                stable += 1;
                assert!(
                    load.force <= driver.friction_limit() * (1.0 + 1e-9),
                    "{name}"
                );
                for (i, s) in driver.site_states().iter().enumerate() {
                    if *s == SiteState::Attached {
                        assert!(
                            phi_x[i].abs() <= mu[i] * phi_z[i] * (1.0 + 1e-9),
                            "{name}: site {i} beyond its μ_i = {}: |{:e}| > {:e}",
                            mu[i],
                            phi_x[i],
                            mu[i] * phi_z[i]
                        );
                        beyond_material |= phi_x[i].abs() > material * phi_z[i] * (1.0 + 1e-6);
                    }
                }
            }
        });
        assert!(stable > 5, "{name}: {stable} stable states");
        assert!(
            beyond_material,
            "{name}: no site held more than the material's μ: the map untested"
        );
    }
}

/// A small scene with heterogeneous maps of μ, c_x and c_z drawn from `seed`.
fn heterogeneous_maps(seed: u64) -> SceneBuilder {
    let drawn = |mean: f64, spread: f64, seed: u64| SiteMap::Surface {
        spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
        mean,
        std_dev: spread * mean,
        seed,
    };
    Scene::builder()
        .block(0.012, 0.002, 0.010)
        .cells(12, 2)
        .normal_load(40.0)
        .seed(seed)
        .friction_map(drawn(0.5, 0.3, seed + 1))
        .c_x_map(drawn(1.65e12, 0.3, seed + 2))
        .c_z_map(drawn(1.65e8, 0.3, seed + 3))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3))]
    /// The dense and the spectral backends give the same events, in order, with the
    /// same loads (to 1e-8 of `μ F_N`), on heterogeneous maps of μ, c_x and c_z; small scenes,
    /// random seeds.
    #[test]
    fn dense_and_spectral_agree_event_by_event(seed in 0u64..10_000) {
        // The material's μF_N = 20 N: the loads' scale (as tests/contact_rules.rs).
        backends_agree(heterogeneous_maps(seed), 20.0)?;
    }
}

/// The maps' scene: a top drive on μ above the material's at some sites (loads beyond
/// the material's μF_N), c_x drawn, c_z given.
fn mapped_scene() -> Scene {
    let n = 64;
    let mu: Vec<f64> = (0..n)
        .map(|i| 0.4 + 0.5 * ((i * 13) % 7) as f64 / 6.0)
        .collect();
    let c_z: Vec<f64> = (0..n)
        .map(|i| 1.65e8 * (1.0 + 0.5 * (i % 3) as f64))
        .collect();
    base(Drive::top(), 4)
        .friction_map(SiteMap::Values(mu))
        .c_x_map(SiteMap::Surface {
            spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
            mean: 1.65e12,
            std_dev: 0.5e12,
            seed: 12,
        })
        .c_z_map(SiteMap::Values(c_z))
        .build()
        .unwrap()
}

/// A run with maps records them in its `scene.json` (read back: the scene's builder), its
/// tables pass the row checks with loads beyond the material's `μF_N` (their unit is the
/// friction limit), and a run cut after a checkpoint and resumed ends with the tables of
/// the uninterrupted run, byte for byte.
#[cfg(feature = "serde")]
#[test]
fn a_resumed_run_with_maps_writes_the_uninterrupted_runs_tables() {
    use crate::common::killed_after_checkpoint;
    use precursors::output::RunTables;
    let scene = mapped_scene();
    let whole = scratch("maps-whole");
    let mut driver = scene.driver().unwrap();
    let mut slip = 0.0;
    RunTables::create(&whole, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |event, _| {
            if let Event::GlobalSlip { load } = event {
                slip = load.force;
            }
        })
        .unwrap();
    let material = scene.material().friction_coefficient() * scene.normal_load();
    assert!(
        slip > material,
        "slip at {slip} N, not beyond μF_N = {material} N"
    );
    let recorded = SceneBuilder::from_json_file(whole.join("scene.json")).unwrap();
    assert!(recorded == scene.to_builder(), "scene.json lost the maps");
    let text = std::fs::read_to_string(whole.join("scene.json")).unwrap();
    assert!(text.contains("\"maps\"") && text.contains("gaussian_surface"));
    let cut = scratch("maps-cut");
    let checkpoint = killed_after_checkpoint(&scene, &cut, 6, 5);
    let checkpoint = precursors::Checkpoint::from_json_str(&checkpoint.to_json().unwrap()).unwrap();
    let mut driver = scene.resume(&checkpoint).unwrap();
    RunTables::resume(&cut, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    for table in ["events.csv", "curve.csv", "contact_map.csv"] {
        let a = std::fs::read(whole.join(table)).unwrap();
        let b = std::fs::read(cut.join(table)).unwrap();
        assert!(a == b, "{table} differs after the resume");
    }
    // Another map is another scene: its checkpoint is refused.
    let other = scene
        .to_builder()
        .friction_map(SiteMap::Values(vec![0.5; 64]))
        .build()
        .unwrap();
    assert!(matches!(
        other.resume(&checkpoint),
        Err(Error::CheckpointSceneMismatch { .. })
    ));
    std::fs::remove_dir_all(&whole).unwrap();
    std::fs::remove_dir_all(&cut).unwrap();
}

/// Maps the scene refuses, each with a typed error naming the key and the site.
#[test]
fn bad_maps_are_refused_naming_the_key_and_the_site() {
    let b = base(Drive::top(), 1);
    let err = |builder: SceneBuilder| builder.build().unwrap_err();
    let e = err(b.clone().friction_map(SiteMap::Values(vec![0.5; 63])));
    assert!(
        matches!(
            e,
            Error::LengthMismatch {
                name: "maps.friction_coefficient",
                expected: 64,
                found: 63
            }
        ),
        "{e}"
    );
    let mut values = vec![1.65e12; 64];
    values[9] = 1e30;
    let e = err(b.clone().c_x_map(SiteMap::Values(values.clone())));
    assert!(
        matches!(
            e,
            Error::MapValue {
                key: "maps.c_x",
                index: 9,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("maps.c_x[9]"), "{e}");
    values[9] = f64::NAN;
    let e = err(b.clone().c_x_map(SiteMap::Values(values)));
    assert!(
        matches!(
            e,
            Error::MapValue {
                key: "maps.c_x",
                index: 9,
                ..
            }
        ),
        "{e}"
    );
    let mut mu = vec![0.5; 64];
    mu[63] = 0.0;
    let e = err(b.clone().friction_map(SiteMap::Values(mu)));
    assert!(
        matches!(
            e,
            Error::MapValue {
                key: "maps.friction_coefficient",
                index: 63,
                ..
            }
        ),
        "{e}"
    );
    let surface = |mean, std_dev| SiteMap::Surface {
        spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
        mean,
        std_dev,
        seed: 1,
    };
    let e = err(b.clone().c_z_map(surface(-1.0, 1.0)));
    assert!(
        matches!(
            e,
            Error::OutOfRange {
                key: "maps.c_z.mean",
                ..
            }
        ),
        "{e}"
    );
    let e = err(b.clone().friction_map(surface(0.5, -0.1)));
    assert!(
        matches!(
            e,
            Error::OutOfRange {
                key: "maps.friction_coefficient.std_dev",
                ..
            }
        ),
        "{e}"
    );
    // A drawn map whose values leave the range (half of them above μ = 1e3): refused when
    // drawn, naming the first such site.
    let e = err(b.clone().friction_map(surface(999.0, 100.0)));
    assert!(
        matches!(e, Error::MapValue { key: "maps.friction_coefficient", value, .. } if value > 1e3),
        "{e}"
    );
    // One site with a c_z so small that the load it may carry overflows its stiffness:
    // F_N ≤ 650 ΔA c_z for the smallest c_z, as for the scalar.
    let mut c_z = vec![1.65e8; 64];
    c_z[5] = 1.0;
    let e = err(b.clone().c_z_map(SiteMap::Values(c_z)));
    assert!(
        matches!(
            e,
            Error::OutOfRange {
                key: "normal_load",
                ..
            }
        ),
        "{e}"
    );
    // The interface's own maps.
    let grid = Grid::new(Block::new(0.002, 0.001, 0.005).unwrap(), 2, 1).unwrap();
    let interface = Interface::new(
        grid,
        Heights::from_values(&grid, vec![1e-6; 2]).unwrap(),
        SpringLaw::default(),
    )
    .unwrap();
    assert!(matches!(
        interface.clone().with_c_z_map(vec![1e8]),
        Err(Error::LengthMismatch {
            name: "maps.c_z",
            ..
        })
    ));
    assert!(matches!(
        interface.with_friction_map(vec![0.5, f64::INFINITY]),
        Err(Error::MapValue {
            key: "maps.friction_coefficient",
            index: 1,
            ..
        })
    ));
    // A calibration of a scalar that a map replaces.
    let e = precursors::calibration::fit_normal_stiffness(
        &b.c_z_map(SiteMap::Values(vec![1.65e8; 64])),
        1e-5,
        (1e7, 1e10),
        &Default::default(),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidChoice {
                name: "maps.c_z",
                ..
            }
        ),
        "{e}"
    );
}

/// The scene file's `maps`: every kind reads to its map; a map file's values are read
/// relative to the scene file, and its bad lines are refused naming the key, the file and
/// the line; a file without maps writes none (its identity is a 1.x scene's).
#[cfg(feature = "serde")]
#[test]
fn the_scene_files_maps() {
    let dir = scratch("maps-file");
    let lines: String = (0..8)
        .map(|i| format!("{}\n", 1e12 + 1e11 * i as f64))
        .collect();
    std::fs::write(dir.join("cx.txt"), format!("# c_x (N/m³)\n\n{lines}")).unwrap();
    let scene = |maps: &str| {
        format!(
            r#"{{"block": {{"lx": 0.008, "ly": 0.004, "lz": 0.005}},
                 "cells": {{"kind": "count", "nx": 4, "ny": 2}}, "normal_load": 1.0,
                 "drive": {{"kind": "top"}},
                 "maps": {maps}}}"#
        )
    };
    let path = dir.join("scene.json");
    std::fs::write(
        &path,
        scene(
            r#"{"c_x": {"kind": "file", "path": "cx.txt"},
                "friction_coefficient": {"kind": "values", "values": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]},
                "c_z": {"kind": "self_affine_surface", "hurst": 0.7, "roll_off": 3e-3,
                        "short_cutoff": 0.6e-3, "long_cutoff": 5e-3, "mean": 2e8, "std_dev": 5e7}}"#,
        ),
    )
    .unwrap();
    let builder = SceneBuilder::from_json_file(&path).unwrap();
    let built = builder.clone().build().unwrap();
    let c_x: Vec<f64> = (0..8).map(|i| 1e12 + 1e11 * i as f64).collect();
    assert_eq!(built.interface().c_x_map(), Some(&c_x[..]));
    assert_eq!(built.interface().friction_map().unwrap()[7], 0.8);
    assert_eq!(built.interface().c_z_map().unwrap().len(), 8);
    // Written back with the file's values, and read again: the same scene.
    let json = builder.to_json().unwrap();
    assert!(json.contains("\"self_affine_surface\"") && !json.contains("cx.txt"));
    assert!(SceneBuilder::from_json_str(&json).unwrap() == builder);
    assert_eq!(
        SiteMap::from_file(dir.join("cx.txt")).unwrap(),
        SiteMap::Values(c_x)
    );
    // No maps, no key.
    let plain = Scene::builder().to_json().unwrap();
    assert!(!plain.contains("maps"), "{plain}");
    // Bad files: a value out of c_x's range at line 4, a ninth value, no value.
    for (text, line, what) in [
        ("# c_x\n1e12\n\n-5\n", 4, "not a value of maps.c_x"),
        (&*format!("{lines}1e12\n"), 9, "one value more"),
        ("# nothing\n", 0, "holds no values"),
    ] {
        std::fs::write(dir.join("cx.txt"), text).unwrap();
        let e = SceneBuilder::from_json_file(&path).unwrap_err();
        match &e {
            Error::MapFile {
                key: "maps.c_x",
                path,
                line: l,
                reason,
            } => {
                assert!(path.ends_with("cx.txt") && *l == line, "{e}");
                assert!(reason.contains(what), "{e}");
            }
            _ => panic!("{e:?}"),
        }
    }
    // Keys outside the format.
    for maps in [
        r#"{"mu": {"kind": "values", "values": [0.5]}}"#,
        r#"{"c_x": {"kind": "gaussian_surface", "mean": 1e12, "std_dev": 1e11}}"#,
        r#"{"c_x": {"kind": "values", "values": [1e12], "seed": 3}}"#,
    ] {
        assert!(
            matches!(
                SceneBuilder::from_json_str(&scene(maps)),
                Err(Error::SceneFile { .. })
            ),
            "{maps}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An interface's maps enter each site's laws, computed here from docs/model.md section
/// 3: `k_z,i = c_z,i/u0_i`, `k_x,i = c_x,i e^{-u_z,i/u0_i}` (0 off the attached sites) and
/// `λ_i = μ_i φ_z,i / |φ_x,i(1)|`; the scalars where a quantity has no map.
#[test]
fn each_site_takes_its_own_values() {
    let grid = Grid::new(Block::new(0.003, 0.001, 0.005).unwrap(), 3, 1).unwrap();
    let u0 = [1e-6, 2e-6, 0.5e-6];
    let (mu, c_x, c_z) = ([0.3, 0.6, 0.9], [1e12, 2e12, 3e12], [1e8, 2e8, 4e8]);
    let bare = Interface::new(
        grid,
        Heights::from_values(&grid, u0.to_vec()).unwrap(),
        SpringLaw::default(),
    )
    .unwrap();
    let mut interface = bare
        .clone()
        .with_friction_map(mu.to_vec())
        .unwrap()
        .with_c_x_map(c_x.to_vec())
        .unwrap()
        .with_c_z_map(c_z.to_vec())
        .unwrap();
    interface
        .set_states(&[
            SiteState::Attached,
            SiteState::Attached,
            SiteState::Detached,
        ])
        .unwrap();
    let u_z = [0.2e-6, -0.4e-6, 0.0];
    let k_z = interface.normal_stiffness();
    let k_x = interface.tangential_stiffness(&u_z).unwrap();
    let lambda = interface
        .breaking_loads(&[1e3, 2e3, 3e3], &[10.0, -20.0, 0.0], 0.5)
        .unwrap();
    for i in 0..3 {
        assert!((k_z[i] / (c_z[i] / u0[i]) - 1.0).abs() < 1e-15, "k_z {i}");
        let expected = if i < 2 {
            c_x[i] * (-u_z[i] / u0[i]).exp()
        } else {
            0.0
        };
        assert!((k_x[i] - expected).abs() <= 1e-15 * expected, "k_x {i}");
    }
    assert!((lambda[0] - 0.3 * 1e3 / 10.0).abs() < 1e-12);
    assert!((lambda[1] - 0.6 * 2e3 / 20.0).abs() < 1e-12);
    assert!(lambda[2].is_infinite());
    assert_eq!(interface.friction_map(), Some(&mu[..]));
    // Without maps: the scalars (μ the argument's, c_x and c_z the law's).
    let law = SpringLaw::default();
    assert_eq!(bare.normal_stiffness()[1], law.c_z() / u0[1]);
    assert_eq!(
        bare.breaking_loads(&[1e3; 3], &[10.0; 3], 0.5).unwrap()[2],
        0.5 * 1e3 / 10.0
    );
    assert!(bare.friction_map().is_none() && bare.c_x_map().is_none() && bare.c_z_map().is_none());
}
