//! The error types of the sweep (`SweepError`) and of the figures (`PlotError`): a real
//! failing call returns the type's variant, which holds the nested core `Error`, and the
//! messages are those of the single error type before the split, except that from 1.1 a
//! message leaves out the cause its `source()` returns: each cause is printed once.
//!
//! The expected messages were written down by running the program built from main
//! before the split (commit 1b83f13, `precursors sweep/merge/plot` on the same inputs,
//! its `error: ...` line): an earlier, independent computation of the same text.

use crate::common::scratch;
use precursors::sweep::{merge, Sweep, SweepError};
use precursors::Error;
use std::error::Error as _;

/// The tiny base scene of tests/sweep.rs (30 x 5 cells).
const BASE: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "normal_load": 500.0,
    "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }"#;

fn sweep_text(axes: &str, realizations: usize) -> String {
    format!(r#"{{ "base": {BASE}, "axes": [{axes}], "realizations": {realizations}, "seed": 11 }}"#)
}

#[test]
fn a_sweep_file_that_is_not_json_is_a_sweep_file_error() {
    let dir = scratch("file");
    let path = dir.join("bad.json");
    std::fs::write(&path, "{ not json\n").unwrap();
    let e = Sweep::from_json_file(&path).unwrap_err();
    assert!(
        matches!(
            e,
            SweepError::File {
                line: 1,
                column: 3,
                ..
            }
        ),
        "{e:?}"
    );
    // main: "error: sweep file bad.json: key must be a string at line 1 column 3"; from
    // 1.1 the message names the file and its source is the parser's error (each once).
    assert_eq!(
        e.to_string(),
        format!("invalid sweep file {}", path.display())
    );
    // Its cause is the parser's error, not a core error.
    let cause = e.source().expect("the parser's error");
    assert!(cause.downcast_ref::<Error>().is_none());
    assert_eq!(cause.to_string(), "key must be a string at line 1 column 3");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_axis_that_is_not_a_scene_key_is_an_axis_error() {
    let e = Sweep::from_json_str(&sweep_text(
        r#"{ "key": "normal_lod", "values": [1.0] }"#,
        1,
    ))
    .unwrap_err();
    match &e {
        SweepError::Axis { key, .. } => assert_eq!(key, "normal_lod"),
        other => panic!("expected SweepError::Axis, got {other:?}"),
    }
    // main at 1b83f13 printed the same line after "error: ", without `max_cells` (and,
    // before issue 27, without `fields`) in the list: the one scene schema
    // (scene/schema.rs) lists every top-level key of the scene format
    // (docs/scene-format.md), `max_cells`, `fields`, `profiles`, `confirm_metres`,
    // `max_output_bytes`, `contact` and `maps` included.
    assert_eq!(
        e.to_string(),
        "sweep axis `normal_lod`: not a scene key: the scene has no `normal_lod` (it has: \
         block, cells, confirm_metres, contact, drive, fields, heights, maps, material, \
         max_cells, max_output_bytes, normal_load, plan_tolerance, probes, profiles, solver, \
         springs)"
    );
}

#[test]
fn a_sweep_of_too_many_runs_is_too_large() {
    let e = Sweep::from_json_str(&sweep_text(
        r#"{ "key": "normal_load", "values": [1.0,2.0,3.0,4.0,5.0,6.0,7.0,8.0,9.0,10.0] }"#,
        20000,
    ))
    .unwrap_err();
    assert!(
        matches!(
            e,
            SweepError::TooLarge {
                points: 10,
                realizations: 20000,
                runs: 200_000,
                limit: 100_000,
            }
        ),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        "the sweep has 10 points x 20000 realizations = 200000 runs, more than the limit of \
         100000 runs per sweep: split it into several sweeps (fewer values per axis or fewer \
         realizations each, with other output directories)"
    );
}

#[test]
fn merging_a_directory_without_a_sweep_is_a_directory_error() {
    let dir = scratch("no-sweep");
    let e = merge(&dir).unwrap_err();
    assert!(
        matches!(&e, SweepError::Directory { path, .. } if *path == dir),
        "{e:?}"
    );
    // main: "error: sweep directory e2: no sweep.json: not the output directory of a sweep".
    assert_eq!(
        e.to_string(),
        format!(
            "sweep directory {}: no sweep.json: not the output directory of a sweep",
            dir.display()
        )
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_core_failure_under_a_sweep_is_nested_and_its_source() {
    let e = Sweep::from_json_str(&sweep_text("", 0)).unwrap_err();
    assert!(
        matches!(
            e,
            SweepError::Core(Error::InvalidCount {
                name: "realizations",
                value: 0,
                ..
            })
        ),
        "{e:?}"
    );
    // main: the same line after "error: ".
    let text = "realizations = 0 is invalid: a sweep needs at least one realization per point";
    assert_eq!(e.to_string(), text);
    // `Core` is transparent (from 1.1): its source is the core error's, here none; the
    // core error is the variant's.
    assert!(e.source().is_none());
    let SweepError::Core(core) = &e else {
        unreachable!()
    };
    assert_eq!(core.to_string(), text);
    // `?` turns a core error into a sweep error.
    fn lift() -> Result<(), SweepError> {
        Err(Error::EmptyGrid { axis: "x" })?
    }
    assert!(matches!(
        lift(),
        Err(SweepError::Core(Error::EmptyGrid { axis: "x" }))
    ));
}

#[cfg(feature = "plot")]
mod plot {
    use super::scratch;
    use precursors::plot::PlotError;
    use precursors::plot::{draw, Format};
    use precursors::sweep::SweepError;
    use precursors::Error;
    use std::error::Error as _;

    #[test]
    fn a_directory_neither_a_run_nor_a_sweep_is_a_figure_error() {
        let dir = scratch("plot-empty");
        let e = draw(&dir, &[Format::Png]).unwrap_err();
        assert!(
            matches!(&e, PlotError::Figure { path: Some(p), .. } if *p == dir),
            "{e:?}"
        );
        // main: "error: figure empty: neither a sweep directory (sweep.json) nor a run
        // directory (curve.csv)".
        assert_eq!(
            e.to_string(),
            format!(
                "figure {}: neither a sweep directory (sweep.json) nor a run directory \
                 (curve.csv)",
                dir.display()
            )
        );
        assert!(e.source().is_none());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A directory that does not exist is a file error (issue 45, item 10), not a figure's.
    #[test]
    fn a_missing_directory_is_a_not_found_io_error() {
        let dir = scratch("plot-missing").join("no-such-directory");
        let e = draw(&dir, &[Format::Png]).unwrap_err();
        let PlotError::Core(Error::Io { path, source, .. }) = &e else {
            panic!("another error: {e:?}")
        };
        assert_eq!((path, source.kind()), (&dir, std::io::ErrorKind::NotFound));
        assert!(e.to_string().contains("no-such-directory"), "{e}");
    }

    #[test]
    fn a_nan_in_a_run_table_is_a_nested_core_error() {
        let dir = scratch("plot-nan");
        // A run to global slip (its tables and scene record), then one cell made NaN.
        let scene = precursors::Scene::builder()
            .block(0.010, 0.004, 0.010)
            .normal_load(100.0)
            .build()
            .unwrap();
        let mut driver = scene.driver().unwrap();
        let tables = precursors::output::RunTables::create(&dir, &driver).unwrap();
        tables.run_to_slip(&mut driver, None, |_, _| {}).unwrap();
        let curve = dir.join("curve.csv");
        let text = std::fs::read_to_string(&curve).unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let mut cells: Vec<&str> = lines[2].split(',').collect();
        cells[2] = "NaN";
        lines[2] = cells.join(",");
        std::fs::write(&curve, lines.join("\n") + "\n").unwrap();
        let e = draw(&dir, &[Format::Png]).unwrap_err();
        assert!(
            matches!(
                &e,
                PlotError::Core(Error::NonFiniteCell { line: 3, column, .. })
                    if column == "force_over_mu_FN"
            ),
            "{e:?}"
        );
        // main, on this table: "error: table handnan/curve.csv, line 3, column
        // force_over_mu_FN: "NaN" is not a finite number".
        let text = format!(
            "table {}, line 3, column force_over_mu_FN: \"NaN\" is not a finite number",
            curve.display()
        );
        assert_eq!(e.to_string(), text);
        // `Core` is transparent (from 1.1): the core error is the variant's, not a source.
        assert!(e.source().is_none());
        let PlotError::Core(core) = &e else {
            unreachable!()
        };
        assert_eq!(core.to_string(), text);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_damaged_sweep_file_under_a_figure_is_a_nested_sweep_error() {
        let dir = scratch("plot-sweep");
        std::fs::write(dir.join("sweep.json"), "{ not json\n").unwrap();
        let e = draw(&dir, &[Format::Png]).unwrap_err();
        assert!(
            matches!(&e, PlotError::Sweep(SweepError::File { line: 1, .. })),
            "{e:?}"
        );
        // main: "error: sweep file badsweep/sweep.json: key must be a string at line 1
        // column 3"; from 1.1 the message names the file, its source is the parser's error.
        let text = format!("invalid sweep file {}", dir.join("sweep.json").display());
        assert_eq!(e.to_string(), text);
        // `Sweep` is transparent (from 1.1): its source is the sweep error's.
        let PlotError::Sweep(sweep) = &e else {
            unreachable!()
        };
        assert_eq!(sweep.to_string(), text);
        let cause = e.source().expect("the parser's error");
        assert_eq!(cause.to_string(), "key must be a string at line 1 column 3");
        // A core error under the figure: `?` nests it.
        fn lift() -> Result<(), PlotError> {
            Err(Error::EmptyGrid { axis: "y" })?
        }
        assert!(matches!(
            lift(),
            Err(PlotError::Core(Error::EmptyGrid { axis: "y" }))
        ));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn each_cause_of_a_nested_figure_error_is_printed_once() {
        let dir = scratch("plot-chain");
        std::fs::write(dir.join("sweep.json"), "{ not json\n").unwrap();
        // A figure error nesting a sweep error nesting the parser's.
        let e = draw(&dir, &[Format::Png]).unwrap_err();
        assert!(
            matches!(&e, PlotError::Sweep(SweepError::File { .. })),
            "{e:?}"
        );
        let joined = super::assert_each_cause_once(&e);
        assert!(
            joined.ends_with(": key must be a string at line 1 column 3"),
            "{joined}"
        );
        // A figure error nesting a core `Io`, and one nesting a sweep error nesting it.
        let missing = dir.join("missing.json");
        let os = std::fs::read(&missing).unwrap_err().to_string();
        let io = || precursors::SceneBuilder::from_json_file(&missing).unwrap_err();
        let expected = format!("reading scene file {}: {os}", missing.display());
        let e = PlotError::from(io());
        assert_eq!(super::assert_each_cause_once(&e), expected);
        let e = PlotError::from(SweepError::from(io()));
        assert_eq!(super::assert_each_cause_once(&e), expected);
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// Each level's message of `e` and its causes (`source()`), outermost first, and the
/// chain as `anyhow` prints it with `{:#}`: the messages joined by ": ".
fn chain(e: &(dyn std::error::Error + 'static)) -> (Vec<String>, String) {
    let mut levels = vec![e.to_string()];
    let mut source = e.source();
    while let Some(cause) = source {
        levels.push(cause.to_string());
        source = cause.source();
    }
    let joined = levels.join(": ");
    (levels, joined)
}

/// Every level's message appears exactly once in the printed chain: no wrapper repeats
/// the error it returns from `source()`, no message embeds its own cause.
fn assert_each_cause_once(e: &(dyn std::error::Error + 'static)) -> String {
    let (levels, joined) = chain(e);
    for text in &levels {
        assert_eq!(
            joined.matches(text.as_str()).count(),
            1,
            "{text:?} is not printed exactly once in {joined:?} (levels {levels:?})"
        );
    }
    joined
}

#[test]
fn each_cause_of_a_nested_error_is_printed_once() {
    let dir = scratch("chain");
    let missing = dir.join("missing.json");
    let os = std::fs::read(&missing).unwrap_err().to_string();
    // A sweep error nesting a core `Io` nesting the operating system's error.
    let e = Sweep::from_json_file(&missing).unwrap_err();
    assert!(matches!(e, SweepError::Core(Error::Io { .. })), "{e:?}");
    assert_eq!(
        assert_each_cause_once(&e),
        format!("reading sweep file {}: {os}", missing.display())
    );
    let mut io = None;
    let mut source = e.source();
    while let Some(cause) = source {
        io = io.or(cause.downcast_ref::<std::io::Error>());
        source = cause.source();
    }
    let io = io.expect("the io::Error is in the chain");
    assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
    // A core `Io` alone, and a scene file the parser refuses (with or without a path).
    let e = precursors::SceneBuilder::from_json_file(&missing).unwrap_err();
    assert_eq!(
        assert_each_cause_once(&e),
        format!("reading scene file {}: {os}", missing.display())
    );
    let e = precursors::SceneBuilder::from_json_str("{ not json").unwrap_err();
    assert!(matches!(e, Error::SceneFile { .. }), "{e:?}");
    assert!(assert_each_cause_once(&e).ends_with(": key must be a string at line 1 column 3"));
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{ not json\n").unwrap();
    let e = precursors::SceneBuilder::from_json_file(&bad).unwrap_err();
    assert!(assert_each_cause_once(&e).contains(&bad.display().to_string()));
    // A sweep file the parser refuses.
    let e = Sweep::from_json_file(&bad).unwrap_err();
    assert!(matches!(e, SweepError::File { .. }), "{e:?}");
    let joined = assert_each_cause_once(&e);
    assert!(
        joined.contains(&bad.display().to_string())
            && joined.ends_with(": key must be a string at line 1 column 3"),
        "{joined}"
    );
    // A base scene whose heights file is missing: the reason, in a sweep file's error,
    // keeps the operating system's message (once).
    let base = BASE.replace(
        r#""normal_load""#,
        &format!(
            r#""heights": {{ "kind": "file", "path": {:?} }}, "normal_load""#,
            dir.join("no-heights.txt").display().to_string()
        ),
    );
    let text = format!(r#"{{ "base": {base}, "axes": [], "realizations": 1, "seed": 1 }}"#);
    let e = Sweep::from_json_str(&text).unwrap_err();
    let joined = assert_each_cause_once(&e);
    assert_eq!(joined.matches(os.as_str()).count(), 1, "{joined}");
    // A core error with another library's cause: the thread pool's.
    let e = Error::ThreadPool {
        threads: 4,
        source: "the system refused a thread".into(),
    };
    assert!(assert_each_cause_once(&e).ends_with(": the system refused a thread"));
    std::fs::remove_dir_all(&dir).ok();
}
