//! The JSON scene format (feature `serde`, docs/scene-format.md): every builder option
//! round-trips, hand-written files give the builder the Rust API gives, defaults are the
//! calibration scene's, mistakes are typed errors, and the documented examples and the
//! files in `examples/scenes/` stay valid.

use crate::common::scratch;
use precursors::solver::{Backend, Parallelism, SolverOptions};
use precursors::*;
use std::path::Path;

// The documented file-format names and values (docs/cli.md, docs/sweep-format.md).
const MAX_RUNS: usize = 100_000;

/// A builder with every option away from its default.
fn everything() -> SceneBuilder {
    let material = Material::new(2.5e9, 0.3, 0.7).unwrap();
    let law = SpringLaw::new(1.1e12, 2.2e8).unwrap();
    let solver = SolverOptions::default()
        .with_backend(Backend::Spectral)
        .unwrap()
        .with_tolerance(1e-11)
        .unwrap()
        .with_parallelism(Parallelism::Threads(2))
        .unwrap()
        .with_max_active_set_iterations(77)
        .unwrap()
        .with_max_linear_iterations(999)
        .unwrap();
    Scene::builder()
        .block(0.030, 0.006, 0.020)
        .cells(15, 3)
        .material(material)
        .springs(law)
        .heights(HeightSource::Values(
            (0..45).map(|i| 1e-7 * (1.0 + i as f64) / 3.0).collect(),
        ))
        .normal_load(123.456)
        .drive(Drive::Spring {
            stiffness: 3.3e6,
            lateral: Lateral::Rod {
                height: 4e-3,
                half_width: 1.5e-3,
            },
        })
        .solver_options(solver)
        .plan_tolerance(1e-7)
        .probes(
            ProbeSpec::default()
                .with_plane(2e-3)
                .with_plane(0.0)
                .with_point(Point::new(0.01, 0.003, 0.001))
                .with_tolerance(1e-9)
                .unwrap(),
        )
}

#[test]
fn every_option_round_trips_exactly() {
    let drives = [
        Drive::Force(ForceLoad::Top),
        Drive::Force(ForceLoad::Lateral(Lateral::Side)),
        Drive::Force(ForceLoad::Lateral(Lateral::Rod {
            height: 0.1 + 0.2, // not representable exactly: the round trip must still be
            half_width: 1e-3,
        })),
        Drive::Force(ForceLoad::Mixed {
            ratio: 1.0 / 3.0,
            lateral: Lateral::Side,
        }),
    ];
    let builders = std::iter::once(everything())
        .chain(drives.into_iter().map(|d| everything().drive(d)))
        .chain([
            everything().cell_size(2e-3, 2e-3),
            everything().heights(HeightSource::Random {
                distribution: HeightDistribution::new(2e-6, 0.5e-6).unwrap(),
                seed: u64::MAX,
            }),
            Scene::builder(),
        ]);
    for b in builders {
        let text = b.to_json().unwrap();
        let back = SceneBuilder::from_json_str(&text).unwrap();
        assert_eq!(back, b, "{text}");
    }
}

#[test]
fn a_hand_written_file_gives_the_rust_builder() {
    let text = r#"{
        "block": {"lx": 0.030, "ly": 0.006, "lz": 0.020},
        "cells": {"kind": "count", "nx": 15, "ny": 3},
        "material": {"young_modulus": 2.5e9, "poisson_ratio": 0.3, "friction_coefficient": 0.7},
        "springs": {"c_x": 1.1e12, "c_z": 2.2e8},
        "heights": {"kind": "values", "values": [VALUES]},
        "normal_load": 123.456,
        "drive": {"kind": "spring", "stiffness": 3.3e6,
                  "lateral": {"kind": "rod", "height": 0.004, "half_width": 0.0015}},
        "solver": {"backend": "spectral", "tolerance": 1e-11,
                   "max_active_set_iterations": 77, "max_linear_iterations": 999,
                   "threads": 2},
        "plan_tolerance": 1e-7,
        "probes": {"planes": [0.002, 0], "points": [[0.01, 0.003, 0.001]], "tolerance": 1e-9}
    }"#;
    let values: Vec<String> = (0..45)
        .map(|i| format!("{:e}", 1e-7 * (1.0 + i as f64) / 3.0))
        .collect();
    let text = text.replace("VALUES", &values.join(", "));
    assert_eq!(SceneBuilder::from_json_str(&text).unwrap(), everything());
}

/// A scene or sweep file that starts with a UTF-8 byte order mark (as editors on Windows
/// write them) reads as the same file without it; serde_json alone refused it with
/// "expected value at line 1 column 1" (issue 53).
#[test]
fn a_byte_order_mark_is_ignored() {
    let dir = scratch("bom");
    let text = r#"{"block": {"lx": 0.012, "ly": 0.002, "lz": 0.01}, "normal_load": 50.0}"#;
    let (plain, marked) = (dir.join("plain.json"), dir.join("marked.json"));
    std::fs::write(&plain, text).unwrap();
    std::fs::write(&marked, [&b"\xEF\xBB\xBF"[..], text.as_bytes()].concat()).unwrap();
    assert_eq!(
        SceneBuilder::from_json_file(&marked).unwrap(),
        SceneBuilder::from_json_file(&plain).unwrap()
    );
    let sweep = format!(r#"{{"base": {text}, "axes": [], "realizations": 1}}"#);
    std::fs::write(&marked, [&b"\xEF\xBB\xBF"[..], sweep.as_bytes()].concat()).unwrap();
    assert!(sweep::Sweep::from_json_file(&marked).is_ok());
    // Only at the start: a mark inside the text is still an error with its place.
    std::fs::write(&marked, format!(" \u{feff}{text}")).unwrap();
    assert!(SceneBuilder::from_json_file(&marked).is_err());
}

#[test]
fn missing_keys_take_the_calibration_defaults() {
    assert_eq!(SceneBuilder::from_json_str("{}").unwrap(), Scene::builder());
    let partial = SceneBuilder::from_json_str(
        r#"{"material": {"friction_coefficient": 0.6}, "heights": {"kind": "gaussian", "seed": 9}}"#,
    )
    .unwrap();
    let material = Material::default().with_friction_coefficient(0.6).unwrap();
    assert_eq!(partial, Scene::builder().material(material).seed(9));
}

/// The default heights are the calibration scene's, seed 1 (README, docs/scene-format.md),
/// in the builder, in `HeightSource::default` and for a file's `heights` without a seed.
#[test]
fn the_default_seed_is_the_calibration_scenes() {
    let seed_one = HeightSource::Random {
        distribution: HeightDistribution::default(),
        seed: 1,
    };
    assert_eq!(HeightSource::default(), seed_one);
    assert_eq!(Scene::builder(), Scene::builder().seed(1));
    assert_ne!(Scene::builder(), Scene::builder().seed(0));
    let file = SceneBuilder::from_json_str(r#"{"heights": {"kind": "gaussian"}}"#).unwrap();
    assert_eq!(file, Scene::builder().heights(seed_one));
}

#[test]
fn mistakes_are_typed_errors() {
    let cases = [
        r#"{"normal_lod": 10}"#,                          // misspelt key
        r#"{"material": {"mu": 0.5}}"#,                   // unknown nested key
        r#"{"block": {"lx": 0.1, "ly": 0.01}}"#,          // incomplete block
        r#"{"drive": {"kind": "rod", "height": 0.006}}"#, // incomplete drive
        r#"{"drive": {"kind": "sled"}}"#,                 // unknown kind
        r#"{"drive": {"kind": "top", "half_width": 1}}"#, // a key the kind lacks
        r#"{"drive": {"kind": "side", "stiffness": 1}}"#, // a key the kind lacks
        r#"{"drive": {"kind": "mixed", "ratio": 1, "lateral": {"kind": "side", "height": 5}}}"#,
        r#"{"cells": {"kind": "count", "nx": -3, "ny": 2}}"#, // negative count
        r#"{"solver": {"backend": "gpu"}}"#,                  // unknown backend
        r#"{"normal_load": "3.5 kN"}"#,                       // wrong type
        r#"{"block": {"lx": 0.1, "ly": 0.01, "lz": 0.05}"#,   // truncated
    ];
    for text in cases {
        match SceneBuilder::from_json_str(text) {
            Err(e @ Error::SceneFile { line, .. }) => {
                // The parser's message, with its line and column, is the source.
                let source = std::error::Error::source(&e).expect("the parser's error");
                assert!(line >= 1 && source.to_string().contains("line"), "{e}");
                assert!(!e.to_string().contains(&source.to_string()), "{e}");
            }
            other => panic!("{text}: {other:?}"),
        }
    }
    // Valid JSON, invalid physics: refused when built, with the builder's errors.
    let b = SceneBuilder::from_json_str(r#"{"normal_load": -1.0}"#).unwrap();
    assert!(matches!(b.build(), Err(Error::InvalidParameter { .. })));
}

#[test]
fn heights_file_is_read_relative_to_the_scene_file() {
    let dir = scratch("heights");
    std::fs::create_dir_all(dir.join("maps")).unwrap();
    let values: Vec<f64> = (0..20).map(|i| 1e-6 * (0.5 + 0.1 * i as f64)).collect();
    let mut text = String::from("# a measured map\n\n");
    for v in &values {
        text.push_str(&format!("  {v:e}\n"));
    }
    std::fs::write(dir.join("maps/h.txt"), text).unwrap();
    let scene_path = dir.join("scene.json");
    std::fs::write(
        &scene_path,
        r#"{"block": {"lx": 0.010, "ly": 0.002, "lz": 0.010},
            "cells": {"kind": "count", "nx": 10, "ny": 2},
            "heights": {"kind": "file", "path": "maps/h.txt"}, "normal_load": 20.0}"#,
    )
    .unwrap();
    let scene = SceneBuilder::from_json_file(&scene_path)
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(scene.interface().heights(), &values[..]);
    // Written back, the heights are values: the file is no longer needed.
    let again = SceneBuilder::from_json_str(&scene.to_builder().to_json().unwrap()).unwrap();
    assert_eq!(again, scene.to_builder());
}

#[test]
fn bad_heights_files_name_the_line() {
    let dir = scratch("bad-heights");
    let cases = [
        ("1e-6\n2e-6\nabc\n", 3),
        ("1e-6\n\n# c\n-2e-6\n", 4),
        ("1e-6\ninf\n", 2),
        ("# only a comment\n", 0),
    ];
    for (k, (text, line)) in cases.iter().enumerate() {
        let path = dir.join(format!("h{k}.txt"));
        std::fs::write(&path, text).unwrap();
        match HeightSource::from_file(&path) {
            Err(Error::HeightsFile { line: l, .. }) => assert_eq!(l, *line, "{text:?}"),
            other => panic!("{text:?}: {other:?}"),
        }
    }
    // A missing file: the I/O error keeps its kind, the message the operation and path.
    let missing = dir.join("missing.txt");
    match HeightSource::from_file(&missing) {
        Err(e @ Error::Io { .. }) => {
            let Error::Io { source, path, .. } = &e else {
                unreachable!()
            };
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
            assert_eq!(path, &missing);
            // The operation and the file; the system's message is the source.
            assert_eq!(
                e.to_string(),
                format!("reading heights file {}", missing.display())
            );
            let cause = std::error::Error::source(&e).expect("the io::Error");
            assert!(cause.downcast_ref::<std::io::Error>().is_some());
        }
        other => panic!("{other:?}"),
    }
    // Too few values for the grid: refused at build with the sizes.
    let path = dir.join("short.txt");
    std::fs::write(&path, "1e-6\n2e-6\n").unwrap();
    let b = Scene::builder()
        .cells(10, 2)
        .block(0.01, 0.002, 0.01)
        .heights(HeightSource::from_file(&path).unwrap());
    assert!(matches!(b.build(), Err(Error::LengthMismatch { .. })));
}

/// The JSON blocks of docs/scene-format.md and the files of examples/scenes/ parse and
/// build (heights files resolved against examples/scenes/).
#[test]
fn documented_scenes_are_valid() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/scene-format.md")).unwrap();
    let mut blocks = 0;
    for chunk in doc.split("```json").skip(1) {
        let text = chunk.split("```").next().unwrap();
        let dir = scratch("doc");
        std::fs::copy(
            root.join("examples/scenes/heights_10x2.txt"),
            dir.join("heights_10x2.txt"),
        )
        .unwrap();
        std::fs::write(dir.join("scene.json"), text).unwrap();
        let b = SceneBuilder::from_json_file(dir.join("scene.json"))
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        b.build().unwrap_or_else(|e| panic!("{e}\n{text}"));
        blocks += 1;
    }
    assert_eq!(blocks, 4);
    let mut files = 0;
    for entry in std::fs::read_dir(root.join("examples/scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            let b = SceneBuilder::from_json_file(&path).unwrap_or_else(|e| panic!("{e}"));
            b.build()
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            files += 1;
        }
    }
    assert!(files >= 3);
}

/// `solver.threads`: a count, `0` or `"all"` (every core), `"current"` (the caller's pool);
/// the same parallelism comes back out of `to_json`.
#[test]
fn solver_threads_take_counts_and_names() {
    let cores = Parallelism::all_cores();
    for (value, want) in [
        ("1", Parallelism::Sequential),
        ("3", Parallelism::Threads(3)),
        ("0", cores),
        ("\"all\"", cores),
        ("\"current\"", Parallelism::CurrentPool),
    ] {
        let text = format!(
            r#"{{"block": {{"lx": 0.01, "ly": 0.004, "lz": 0.01}}, "solver": {{"threads": {value}}}}}"#
        );
        let builder = SceneBuilder::from_json_str(&text).unwrap();
        let scene = builder.clone().build().unwrap();
        assert_eq!(
            scene.solver_options().parallelism(),
            want,
            "threads = {value}"
        );
        let again = SceneBuilder::from_json_str(&builder.to_json().unwrap()).unwrap();
        assert_eq!(again, builder, "threads = {value}");
    }
    for bad in ["-1", "\"some\"", "2.5"] {
        let text = format!(r#"{{"solver": {{"threads": {bad}}}}}"#);
        assert!(
            SceneBuilder::from_json_str(&text).is_err(),
            "threads = {bad}"
        );
    }
}

/// Files that cannot be read or parsed: the error names the operation and the file and
/// chains the cause (the `std::io::Error` with its kind, the parser's error).
#[test]
fn file_errors_name_the_file_and_chain_the_cause() {
    let dir = scratch("file-errors");
    let missing = dir.join("no-such-scene.json");
    let e = SceneBuilder::from_json_file(&missing).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("reading scene file {}", missing.display())
    );
    let cause = std::error::Error::source(&e).expect("the io::Error");
    assert_eq!(
        cause.to_string(),
        std::fs::read_to_string(&missing).unwrap_err().to_string()
    );
    assert_eq!(
        cause.downcast_ref::<std::io::Error>().map(|io| io.kind()),
        Some(std::io::ErrorKind::NotFound)
    );
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\n  \"normal_load\": }\n").unwrap();
    let e = SceneBuilder::from_json_file(&bad).unwrap_err();
    match &e {
        Error::SceneFile {
            path, line, column, ..
        } => {
            assert_eq!(path.as_deref(), Some(bad.as_path()));
            assert_eq!((*line, *column), (2, 18));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        e.to_string(),
        format!("invalid scene file {}", bad.display())
    );
    assert!(std::error::Error::source(&e).is_some());
    // Text given directly has no path.
    let e = SceneBuilder::from_json_str("{").unwrap_err();
    assert!(matches!(e, Error::SceneFile { path: None, .. }), "{e}");
}

/// `max_cells` and the dense backend's threads in scene files.
#[test]
fn the_cell_limit_and_dense_threads_in_scene_files() {
    let b = SceneBuilder::from_json_str(r#"{"max_cells": 500}"#).unwrap();
    assert!(matches!(
        b.clone().build(),
        Err(Error::GridTooLarge {
            cells: 980,
            limit: 500,
            ..
        })
    ));
    // Written only away from its default, and read back.
    assert!(b.to_json().unwrap().contains("\"max_cells\": 500"));
    assert_eq!(
        SceneBuilder::from_json_str(&b.to_json().unwrap()).unwrap(),
        b
    );
    assert!(!Scene::builder().to_json().unwrap().contains("max_cells"));
    let dense = r#"{"solver": {"backend": "dense", "threads": 2}}"#;
    let e = SceneBuilder::from_json_str(dense).unwrap_err();
    assert!(matches!(e, Error::DenseThreads { threads: 2, .. }), "{e}");
    let auto = r#"{"solver": {"backend": "auto", "threads": 2}}"#;
    let scene = SceneBuilder::from_json_str(auto).unwrap().build().unwrap();
    assert_eq!(scene.driver().unwrap().threads(), 1);
}

/// Where the format has an object, an array is refused (serde would read a struct's fields
/// by position: `"block": [lx, ly, lz]` was accepted though undocumented), in scene files
/// and in a sweep's base scene, axes and top level, with the key path.
#[test]
fn arrays_are_refused_where_the_format_has_objects() {
    for (text, place) in [
        (r#"{"block": [0.02, 0.004, 0.01]}"#, "`block`"),
        (r#"{"cells": ["count", 20, 4]}"#, "`cells`"),
        (r#"{"material": [3e9, 0.3, 0.5]}"#, "`material`"),
        (r#"{"heights": ["gaussian", 1e-6, 1e-6, 1]}"#, "`heights`"),
        (
            r#"{"drive": {"kind": "spring", "stiffness": 4e6, "lateral": ["side"]}}"#,
            "`drive.lateral`",
        ),
        (r#"{"solver": ["dense", 1e-13, 10, 10, 1]}"#, "`solver`"),
        (
            r#"[{"lx": 0.02, "ly": 0.004, "lz": 0.01}]"#,
            "the top level",
        ),
    ] {
        let e = SceneBuilder::from_json_str(text).unwrap_err();
        assert!(matches!(e, Error::SceneFile { line: 1, .. }), "{text}: {e}");
        let text = crate::common::chain(&e);
        assert!(
            text.contains(place) && text.contains("positional"),
            "{text}"
        );
    }
    // Arrays where the format has arrays are read.
    let b = SceneBuilder::from_json_str(
        r#"{"probes": {"planes": [0.001], "points": [[0.01, 0.002, 0.002]]}}"#,
    )
    .unwrap();
    assert_eq!(b.build().unwrap().probes().points().len(), 1);
    use precursors::sweep::Sweep;
    for (text, place) in [
        (
            r#"{"base": {"block": [0.02, 0.004, 0.01]}}"#,
            "`base.block`",
        ),
        (r#"{"axes": [["normal_load", [1.0, 2.0]]]}"#, "`axes[]`"),
        (r#"[{}, [], 1, 0]"#, "the top level"),
    ] {
        let e = Sweep::from_json_str(text).unwrap_err();
        assert!(
            matches!(e, precursors::sweep::SweepError::File { line: 1, .. }),
            "{text}: {e}"
        );
        let chain = crate::common::chain(&e);
        assert!(chain.contains(place), "{chain}");
    }
    // An axis value that is an array where the scene has an object.
    let e = Sweep::from_json_str(
        r#"{"base": {"block": {"lx": 0.02, "ly": 0.004, "lz": 0.01}, "cells": {"kind": "count", "nx": 20, "ny": 4}},
            "axes": [{"key": "block", "values": [[0.02, 0.004, 0.01]]}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(e, precursors::sweep::SweepError::Axis { .. })
            && e.to_string().contains("`block`"),
        "{e}"
    );
}

/// A file that is not UTF-8 text is invalid input (exit code 3 in the program), at the
/// line and column of its first bad byte, not a failure to read it (exit code 4).
#[test]
fn files_that_are_not_utf8_are_invalid_input() {
    let dir = scratch("utf8");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, b"{\n  \"normal_load\": 6\xff0\n}\n").unwrap();
    let e = SceneBuilder::from_json_file(&scene).unwrap_err();
    assert!(
        matches!(
            e,
            Error::SceneFile {
                line: 2,
                column: 19,
                ..
            }
        ),
        "{e}"
    );
    assert!(crate::common::chain(&e).contains("not UTF-8"), "{e}");
    let sweep = dir.join("sweep.json");
    std::fs::write(&sweep, b"{\"seed\": 1\xc0}").unwrap();
    let e = precursors::sweep::Sweep::from_json_file(&sweep).unwrap_err();
    assert!(
        matches!(
            e,
            precursors::sweep::SweepError::File {
                line: 1,
                column: 11,
                ..
            }
        ),
        "{e}"
    );
    let heights = dir.join("h.txt");
    std::fs::write(&heights, b"1e-6\n2e-6\n\xfe\n").unwrap();
    let e = HeightSource::from_file(&heights).unwrap_err();
    assert!(matches!(e, Error::HeightsFile { line: 3, .. }), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A heights file is bounded by the grid it is for before it is read whole: longer than
/// 1 MiB plus 256 bytes a cell (a sparse file of 4 GiB here, which took the whole file
/// into memory and echoed it back), or with more heights than cells, it is refused at once.
#[test]
fn heights_files_are_bounded_by_the_grid() {
    let dir = scratch("heights-bound");
    let big = dir.join("big.txt");
    let file = std::fs::File::create(&big).unwrap();
    file.set_len(4 << 30).unwrap();
    std::fs::write(
        dir.join("big.json"),
        r#"{"cells": {"kind": "count", "nx": 20, "ny": 4},
            "block": {"lx": 0.02, "ly": 0.004, "lz": 0.01},
            "heights": {"kind": "file", "path": "big.txt"}}"#,
    )
    .unwrap();
    let started = std::time::Instant::now();
    let e = SceneBuilder::from_json_file(dir.join("big.json")).unwrap_err();
    assert!(started.elapsed().as_secs_f64() < 1.0);
    assert!(
        matches!(e, Error::HeightsFile { line: 0, .. })
            && e.to_string().contains("4294967296 bytes"),
        "{e}"
    );
    std::fs::remove_file(&big).ok();
    let long: String = (0..81).map(|i| format!("{}e-7\n", i + 1)).collect();
    std::fs::write(dir.join("long.txt"), long).unwrap();
    std::fs::write(
        dir.join("long.json"),
        r#"{"cells": {"kind": "count", "nx": 20, "ny": 4},
            "block": {"lx": 0.02, "ly": 0.004, "lz": 0.01},
            "heights": {"kind": "file", "path": "long.txt"}}"#,
    )
    .unwrap();
    let e = SceneBuilder::from_json_file(dir.join("long.json")).unwrap_err();
    assert!(matches!(e, Error::HeightsFile { line: 81, .. }), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A sweep is bounded before any run is built: `realizations` of 1e9 (800 GB of runs:
/// aborted) and 2^64-1 (a "capacity overflow" panic), and an axis of 1e6 values (accepted
/// and started) are refused at once with the count and the limit of 1e5 runs.
#[test]
fn sweeps_beyond_the_run_limit_are_refused_at_once() {
    use precursors::sweep::Sweep;
    let base = r#""base": {"block": {"lx": 0.02, "ly": 0.004, "lz": 0.01},
                          "cells": {"kind": "count", "nx": 20, "ny": 4}}"#;
    let values: Vec<String> = (0..1_000_000)
        .map(|i| format!("{}", 10.0 + i as f64))
        .collect();
    let million = format!(
        r#"{{ {base}, "axes": [{{"key": "normal_load", "values": [{}]}}]}}"#,
        values.join(",")
    );
    for (text, runs) in [
        (
            format!(r#"{{ {base}, "realizations": 1000000000 }}"#),
            1_000_000_000u128,
        ),
        (
            format!(r#"{{ {base}, "realizations": 18446744073709551615 }}"#),
            u64::MAX as u128,
        ),
        (million, 1_000_000),
        (
            format!(
                r#"{{ {base}, "realizations": 50001,
                     "axes": [{{"key": "normal_load", "values": [10.0, 20.0]}}] }}"#
            ),
            100_002,
        ),
    ] {
        let started = std::time::Instant::now();
        let e = Sweep::from_json_str(&text).unwrap_err();
        assert!(
            matches!(e, precursors::sweep::SweepError::TooLarge { runs: r, limit: 100_000, .. } if r == runs),
            "{e}"
        );
        assert!(e.to_string().contains("split it"), "{e}");
        assert!(started.elapsed().as_secs_f64() < 10.0);
    }
    // At the limit the sweep is read.
    let sweep = Sweep::from_json_str(&format!(
        r#"{{ {base}, "realizations": 50000,
             "axes": [{{"key": "normal_load", "values": [10.0, 20.0]}}] }}"#
    ))
    .unwrap();
    assert_eq!(sweep.runs().len(), MAX_RUNS);
}

/// A file too large for the machine's memory (a sparse 1 TiB file: read whole, it would
/// abort the process) is refused before it is read, by every reader of a user's file:
/// scene files, checkpoints, and the tables `plot` reads (Linux, where the memory
/// available is known; elsewhere no check is made and the test only runs the readers on
/// small files).
#[test]
fn files_too_large_for_memory_are_refused_before_reading() {
    if !cfg!(target_os = "linux") {
        return;
    }
    let dir = scratch("too-large");
    let huge = |name: &str| {
        let path = dir.join(name);
        std::fs::File::create(&path)
            .unwrap()
            .set_len(1 << 40)
            .unwrap();
        path
    };
    let started = std::time::Instant::now();
    let scene = SceneBuilder::from_json_file(huge("scene.json")).unwrap_err();
    let checkpoint = precursors::Checkpoint::read_from(huge("checkpoint.json")).unwrap_err();
    for e in [&scene, &checkpoint] {
        assert!(matches!(e, Error::OutOfMemory { .. }), "{e}");
        assert!(e.to_string().contains("1099511627776 bytes"), "{e}");
    }
    #[cfg(feature = "plot")]
    {
        let run = dir.join("run");
        std::fs::create_dir_all(&run).unwrap();
        // A run directory (plot checks the tables against the recorded scene) whose first
        // table read is huge.
        let scene = Scene::builder().block(0.010, 0.004, 0.010);
        std::fs::write(run.join("scene.json"), scene.to_json().unwrap()).unwrap();
        std::fs::write(run.join("curve.csv"), "").unwrap();
        std::fs::rename(huge("events.csv"), run.join("events.csv")).unwrap();
        let e = precursors::plot::draw(&run, &[precursors::plot::Format::Png]).unwrap_err();
        assert!(
            matches!(
                e,
                precursors::plot::PlotError::Core(Error::OutOfMemory { .. })
            ),
            "{e}"
        );
    }
    assert!(started.elapsed().as_secs_f64() < 5.0);
    std::fs::remove_dir_all(&dir).ok();
}

/// A heights file named in a scene file is reported by the path it was read from: resolved
/// against the scene file's directory, not as written in the file (issue 45, item 10).
#[test]
fn a_heights_file_is_reported_by_its_resolved_path() {
    let dir = scratch("heights-resolved");
    std::fs::create_dir_all(dir.join("maps")).unwrap();
    std::fs::write(dir.join("maps/bad.txt"), "1e-6\nabc\n").unwrap();
    let scene = |path: &str| {
        let scene_path = dir.join(format!("{}.json", path.replace(['/', '.'], "_")));
        std::fs::write(
            &scene_path,
            format!(
                r#"{{"block": {{"lx": 0.010, "ly": 0.002, "lz": 0.010}},
                    "cells": {{"kind": "count", "nx": 10, "ny": 2}},
                    "heights": {{"kind": "file", "path": "{path}"}}}}"#
            ),
        )
        .unwrap();
        SceneBuilder::from_json_file(&scene_path).unwrap_err()
    };
    let missing = dir.join("maps/missing.txt");
    match scene("maps/missing.txt") {
        Error::Io { path, .. } => assert_eq!(path, missing),
        other => panic!("{other:?}"),
    }
    match scene("maps/bad.txt") {
        e @ Error::HeightsFile { .. } => {
            let text = e.to_string();
            let resolved = dir.join("maps/bad.txt");
            assert!(
                text.starts_with(&format!("{}, line 2", resolved.display())),
                "{text}"
            );
        }
        other => panic!("{other:?}"),
    }
}

/// A tiny scene (15 x 3 cells) with the CUDA backend.
const CUDA_SCENE: &str = r#"{
    "block": {"lx": 0.030, "ly": 0.006, "lz": 0.020},
    "cells": {"kind": "count", "nx": 15, "ny": 3},
    "solver": {"backend": "cuda"}
}"#;

/// The backend `cuda` is read, written back as `cuda` and reaches the solver's options
/// (docs/scene-format.md, docs/gpu.md).
#[test]
fn the_cuda_backend_round_trips() {
    let builder = SceneBuilder::from_json_str(CUDA_SCENE).unwrap();
    let json: serde_json::Value = serde_json::from_str(&builder.to_json().unwrap()).unwrap();
    assert_eq!(json["solver"]["backend"], "cuda");
    let again = SceneBuilder::from_json_str(&json.to_string()).unwrap();
    assert_eq!(again, builder);
    let spectral = SceneBuilder::from_json_str(&CUDA_SCENE.replace("cuda", "spectral")).unwrap();
    assert_ne!(
        builder, spectral,
        "the backend is kept, not mapped to spectral"
    );
    let cuda = builder.clone().solver_options(
        SolverOptions::default()
            .with_backend(Backend::Cuda)
            .unwrap(),
    );
    assert_eq!(cuda, builder);
}

/// Without a usable GPU (CI, this feature off) a driver of a `cuda` scene is refused with
/// [`Error::CudaUnavailable`], whose message says what is missing: the feature, or (with
/// it) the library or the driver, and what to do. With a usable GPU it builds.
#[test]
fn a_cuda_scene_without_a_gpu_says_what_is_missing() {
    let scene = SceneBuilder::from_json_str(CUDA_SCENE)
        .unwrap()
        .build()
        .unwrap();
    #[cfg(feature = "cuda")]
    if precursors::solver::cuda_device().is_ok() {
        scene.driver().unwrap();
        return;
    }
    let e = scene.driver().unwrap_err();
    assert!(matches!(e, Error::CudaUnavailable { .. }), "{e:?}");
    let message = e.to_string();
    assert!(
        message.starts_with("the CUDA backend is unavailable: "),
        "{message}"
    );
    if cfg!(feature = "cuda") {
        // The libraries searched (one not found: named, with the directories) or the
        // driver's answer; and where to point the loader.
        let names_what = (message.contains("not found") && message.contains("lib"))
            || message.contains("CUDA driver")
            || message.contains("LD_LIBRARY_PATH lists");
        assert!(names_what, "{message}");
        assert!(message.contains("LD_LIBRARY_PATH"), "{message}");
        assert!(!message.contains("feature `cuda` is off"), "{message}");
    } else {
        assert!(message.contains("feature `cuda` is off"), "{message}");
        assert!(message.contains("--features cuda"), "{message}");
        assert!(message.contains("backend \"spectral\""), "{message}");
    }
}

/// A scene whose numbers point to millimetres typed as metres (issue 56: `"lx": 140` for
/// 140 mm and the calibration's 3.5 kN, a 140 m block under 3.6 Pa, ran to global slip
/// with 5 of 980 sites in contact) is refused, by cell size or count, from the builder, a
/// scene file and the program, naming the likely mistake and the key that confirms it.
#[cfg(feature = "cli")]
#[test]
fn a_block_in_millimetres_is_refused_unless_confirmed() {
    use crate::common::program::{path, precursors, stderr};
    for cells in [
        r#"{"kind": "size", "dx": 1, "dy": 1}"#,
        r#"{"kind": "count", "nx": 140, "ny": 7}"#,
    ] {
        let text = format!(r#"{{"block": {{"lx": 140, "ly": 7, "lz": 75}}, "cells": {cells}}}"#);
        let builder = SceneBuilder::from_json_str(&text).unwrap();
        let e = builder.clone().build().unwrap_err();
        match &e {
            Error::LikelyMillimetres {
                block,
                pressure,
                young_modulus,
            } => {
                assert_eq!(*block, (140.0, 7.0, 75.0));
                assert!((pressure - 3500.0 / 980.0).abs() < 1e-12, "{pressure}");
                assert_eq!(*young_modulus, Material::default().young_modulus());
            }
            other => panic!("{other:?}"),
        }
        let message = e.to_string();
        assert!(message.contains("140 x 7 x 75 mm"), "{message}");
        assert!(message.contains("\"confirm_metres\": true"), "{message}");
        // Confirmed, it is a scene (and the key round-trips through its file).
        let confirmed = builder.confirm_metres(true);
        confirmed.check().unwrap();
        let again = SceneBuilder::from_json_str(&confirmed.to_json().unwrap()).unwrap();
        assert_eq!(again, confirmed);
    }
    // The same pressure on a block under a metre, or a metre block pressed as the
    // calibration's, is not a likely mistake.
    Scene::builder()
        .block(0.14, 0.007, 0.075)
        .normal_load(3500.0 * 1e-6)
        .check()
        .unwrap();
    Scene::builder()
        .block(1.4, 0.07, 0.75)
        .cell_size(0.01, 0.01)
        .normal_load(3500.0 * 100.0)
        .check()
        .unwrap();
    let dir = scratch("millimetres");
    let file = dir.join("mm.json");
    std::fs::write(
        &file,
        r#"{"block": {"lx": 140, "ly": 7, "lz": 75}, "cells": {"kind": "size", "dx": 1, "dy": 1}}"#,
    )
    .unwrap();
    let o = precursors(&["run", path(&file), "--out", path(&dir.join("out"))]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("did you mean 140 x 7 x 75 mm"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("out").join("events.csv").exists());
}
