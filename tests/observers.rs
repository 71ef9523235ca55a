//! Observers within bounds (docs/scene-format.md, `max_output_bytes`; issue "exit 0 means
//! right", round three): the recorded tables stay within the size `RunOptions::cost`
//! estimates before the run, a recording above the limit is refused before anything is
//! written, and every observer at its documented maximum (10 000 planes, points or
//! loads) either runs under a memory bound or is refused at once, and `info` answers
//! without planning it.
//!
//! The reference is the files themselves: their sizes are counted on disk, not computed
//! by the code under test.

use crate::common::program::{command, path, stderr};
use crate::common::scratch;
use precursors::{Error, RunOptions, Scene};
use std::path::Path;
use std::process::Output;
use std::time::{Duration, Instant};

/// The documented maximum of each count (`probes.planes`, `fields.planes`, ...).
const MAX: usize = 10_000;

/// A small scene (10 x 4 cells of 1 mm, `Lz` = 10 mm) whose run takes milliseconds.
fn base(extra: &str) -> String {
    format!(
        r#"{{ "block": {{ "lx": 0.010, "ly": 0.004, "lz": 0.010 }},
        "cells": {{ "kind": "count", "nx": 10, "ny": 4 }},
        "heights": {{ "kind": "gaussian", "seed": 3 }},
        "normal_load": 140.0{extra} }}"#
    )
}

/// `n` heights evenly within the probe range of the small scene (1 to 9 mm).
fn heights(n: usize) -> String {
    let z: Vec<String> = (0..n)
        .map(|k| format!("{:e}", 0.001 + 0.008 * k as f64 / n as f64))
        .collect();
    format!("[{}]", z.join(","))
}

/// The program with `args` under a bound of virtual memory (`ulimit -v`, KiB) and of
/// time (a hang fails the test): the output, or a panic naming the bound passed.
fn bounded(args: &[&str], memory_kib: u64, seconds: u64) -> Output {
    let program = env!("CARGO_BIN_EXE_precursors");
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let mut child = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {memory_kib} && exec '{program}' {}",
            quoted.join(" ")
        ))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(seconds) {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    panic!("precursors {args:?} ran past {seconds} s");
}

/// `n` loads `F/(μF_N)` evenly within `[0, 1)`.
fn loads(n: usize) -> String {
    let l: Vec<String> = (0..n)
        .map(|k| format!("{:e}", k as f64 / n as f64))
        .collect();
    format!("[{}]", l.join(","))
}

fn size(file: &Path) -> f64 {
    std::fs::metadata(file).map_or(0.0, |m| m.len() as f64)
}

#[test]
fn the_recorded_tables_stay_within_their_estimate() {
    let dir = scratch("within");
    let scene_file = dir.join("scene.json");
    let extra = r#", "fields": { "every": 1, "planes": [0.002, 0.005] },
        "profiles": { "loads": [0.1, 0.3, 0.5, 0.7], "planes": [0.0, 0.002, 0.005] }"#;
    std::fs::write(&scene_file, base(extra)).unwrap();
    let builder = precursors::SceneBuilder::from_json_file(&scene_file).unwrap();
    let cost = builder.observer_cost().unwrap();
    let out = dir.join("run");
    let o = command(&["-q", "run", path(&scene_file), "--out", path(&out)])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let fields = size(&out.join("fields.csv"));
    let profiles = size(&out.join("profiles.csv"));
    // Upper bounds, and not loose by more than the stable states' bound (N + 1 = 41
    // states where a run has fewer) and the 21-byte value bound (values take 17-19).
    assert!(
        fields > 0.0 && fields <= cost.fields_bytes,
        "{fields} {cost:?}"
    );
    assert!(
        profiles > 0.0 && profiles <= cost.profiles_bytes,
        "{profiles} {cost:?}"
    );
    assert!(profiles >= 0.6 * cost.profiles_bytes, "{profiles} {cost:?}");
    let states = std::fs::read_to_string(out.join("curve.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    let per_state = cost.fields_bytes / 41.0;
    assert!(fields <= states as f64 * per_state && fields >= 0.6 * states as f64 * per_state);
}

#[test]
fn a_recording_above_the_limit_is_refused_before_anything_is_written() {
    // Library: the builder and the options of a run refuse it, naming the limit.
    let levels: Vec<f64> = (0..MAX).map(|k| k as f64 / MAX as f64).collect();
    let planes: Vec<f64> = (0..MAX)
        .map(|k| 0.001 + 0.008 * k as f64 / MAX as f64)
        .collect();
    let options = RunOptions::new().record_profiles(&levels, &planes);
    let small = Scene::builder()
        .block(0.010, 0.004, 0.010)
        .cells(10, 4)
        .normal_load(140.0);
    let refused = small.clone().run_options(options.clone()).check();
    match refused {
        Err(e @ Error::OutputTooLarge { .. }) => {
            let text = e.to_string();
            assert!(text.contains("max_output_bytes") && text.contains("profiles.planes"));
        }
        other => panic!("{other:?}"),
    }
    // 1e4 loads of 40 001 rows of about 300 B: about 120 GB, within a raised limit.
    assert!(small
        .clone()
        .run_options(options.clone().max_output_bytes(2e11))
        .check()
        .is_ok());
    let scene = small.build().unwrap();
    let driver = scene.driver().unwrap();
    let dir = scratch("refused");
    let run = dir.join("run");
    let refused = precursors::output::RunTables::create_with(&run, &driver, &options);
    assert!(
        matches!(refused, Err(Error::OutputTooLarge { .. })),
        "{refused:?}"
    );
    assert!(!run.exists() || std::fs::read_dir(&run).unwrap().next().is_none());
    // The program: exit 3, the estimate and the key in one message, nothing written.
    let scene_file = dir.join("scene.json");
    let extra = format!(
        r#", "profiles": {{ "loads": {}, "planes": {} }}"#,
        loads(MAX),
        heights(MAX)
    );
    std::fs::write(&scene_file, base(&extra)).unwrap();
    let out = dir.join("out");
    let o = bounded(
        &["-q", "run", path(&scene_file), "--out", path(&out)],
        4 << 20,
        60,
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("max_output_bytes"), "{}", stderr(&o));
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    // `info` refuses it the same way.
    let o = bounded(&["info", path(&scene_file)], 4 << 20, 60);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
}

#[test]
fn every_observer_at_its_maximum_runs_within_its_estimates_or_is_refused() {
    let dir = scratch("maxima");
    let points: Vec<String> = (0..MAX)
        .map(|k| {
            let t = k as f64 / MAX as f64;
            format!("[{:e}, 0.002, {:e}]", 0.001 + 0.008 * t, 0.002 + 0.007 * t)
        })
        .collect();
    let cases = [
        (
            "probes.planes",
            format!(r#", "probes": {{ "planes": {} }}"#, heights(MAX)),
        ),
        (
            "probes.points",
            format!(r#", "probes": {{ "points": [{}] }}"#, points.join(",")),
        ),
        (
            "fields.planes",
            format!(
                r#", "fields": {{ "every": 1000, "planes": {} }}"#,
                heights(MAX)
            ),
        ),
        (
            "profiles.planes",
            format!(
                r#", "profiles": {{ "loads": [0.5], "planes": {} }}"#,
                heights(MAX)
            ),
        ),
        (
            "profiles.loads",
            format!(r#", "profiles": {{ "loads": {} }}"#, loads(MAX)),
        ),
    ];
    for (key, extra) in cases {
        let scene_file = dir.join(format!("{key}.json"));
        std::fs::write(&scene_file, base(&extra)).unwrap();
        let builder = precursors::SceneBuilder::from_json_file(&scene_file).unwrap();
        let cost = builder.observer_cost().unwrap();
        // `info` answers from the estimates, without planning 10 000 kernels.
        let o = bounded(&["info", path(&scene_file)], 4 << 20, 60);
        assert!(o.status.success(), "{key}: {}", stderr(&o));
        let info = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(
            info.contains("output") && info.contains("observers"),
            "{info}"
        );
        // The run, under its memory estimate plus 1 GiB of address space for the
        // program, its threads' stacks and the allocator.
        let out = dir.join(key);
        let memory_kib = (cost.memory_bytes / 1024.0) as u64 + (1 << 20);
        let o = bounded(
            &["-q", "run", path(&scene_file), "--out", path(&out)],
            memory_kib,
            600,
        );
        assert!(o.status.success(), "{key}: {}", stderr(&o));
        let written = size(&out.join("fields.csv")) + size(&out.join("profiles.csv"));
        assert!(written <= cost.output_bytes(), "{key}: {written} {cost:?}");
        assert!(cost.memory_bytes > 0.0 || key == "profiles.loads", "{key}");
    }
}

#[test]
fn profile_loads_equal_to_the_digits_written_are_refused_before_the_run() {
    // 0.5 and the next f64 above it: distinct numbers, one text in profiles.csv, which
    // `plot` refused after `run` had written it.
    let next = f64::from_bits(0.5_f64.to_bits() + 1);
    let options = RunOptions::new().record_profiles(&[0.5, next], &[]);
    let refused = Scene::builder().run_options(options).check();
    match refused {
        Err(Error::InvalidParameter { name, value, .. }) => {
            assert_eq!((name, value), ("profiles.loads", next));
        }
        other => panic!("{other:?}"),
    }
    // Loads that differ in the 13th digit stay apart.
    let apart = RunOptions::new().record_profiles(&[0.5, 0.500000000001], &[]);
    assert!(Scene::builder().run_options(apart).check().is_ok());
}
