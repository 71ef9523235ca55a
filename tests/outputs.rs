//! Outputs that cannot overwrite each other, and inputs that are files (docs/cli.md,
//! "Guarantees"): every output option of the program against every file name of a run
//! and a sweep directory; a run and a sweep never share a directory; a new run leaves no
//! figure of the old one; a FIFO, a device or a directory given as an input or an output
//! gets an answer (never a hang, never a replaced device).
//!
//! Each case runs the program under a time bound (a hang fails the test) and compares the
//! directory's bytes before and after a refusal.

use crate::common::program::{command, contents, path, precursors, stderr};
use crate::common::scratch;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

/// A tiny scene (30 x 5 cells, about 10 ms to global slip) recording its fields (one
/// plane) for the movies.
const SCENE: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 },
    "normal_load": 500.0,
    "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 },
    "fields": { "every": 1, "planes": [0.005] } }"#;

/// Another scene: the same block under another load.
const OTHER: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 1 },
    "normal_load": 700.0 }"#;

/// A sweep of the tiny scene: one point, two realizations.
const SWEEP: &str = r#"{ "base": { "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 }, "normal_load": 500.0 },
    "axes": [], "realizations": 2, "seed": 5 }"#;

/// The program with `args`, killed after 60 s: `None` when it had to be (it hung).
fn bounded(args: &[&str]) -> Option<Output> {
    let mut child = command(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(60) {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

/// A finished run of [`SCENE`] in `dir/run` with its figures and movies drawn, and a
/// checkpoint `dir/ck.json` taken during it: (scene file, run directory, checkpoint).
fn finished_run(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let scene = dir.join("scene-in.json");
    std::fs::write(&scene, SCENE).unwrap();
    let run = dir.join("run");
    let ck = dir.join("ck.json");
    for args in [
        vec![
            "run",
            path(&scene),
            "--out",
            path(&run),
            "--checkpoint",
            path(&ck),
            "--every",
            "3",
            "-q",
        ],
        vec!["plot", path(&run), "--format", "both"],
        vec!["stats", path(&run), "--bootstrap", "5", "--goodness", "5"],
        vec![
            "movie",
            path(&run),
            "-q",
            "--max-frames",
            "3",
            "--width",
            "300",
            "--height",
            "200",
        ],
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    (scene, run, ck)
}

/// The names of every file a run directory and a sweep directory (and its run
/// directories) can hold.
fn every_name(dir: &Path, run: &Path) -> Vec<String> {
    let sweep_file = dir.join("sweep-in.json");
    std::fs::write(&sweep_file, SWEEP).unwrap();
    let sweep = dir.join("sweep");
    for args in [
        vec![
            "sweep",
            path(&sweep_file),
            "--out",
            path(&sweep),
            "-q",
            "--jobs",
            "1",
        ],
        vec!["plot", path(&sweep), "--format", "both"],
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    let mut names: Vec<String> = contents(run)
        .into_iter()
        .chain(contents(&sweep))
        .map(|(name, _)| name.rsplit('/').next().unwrap().to_string())
        .collect();
    // The names a run in progress holds.
    for table in ["events.csv", "curve.csv", "contact_map.csv", "fields.csv"] {
        names.push(format!("{table}.partial"));
    }
    names.sort();
    names.dedup();
    for expected in [
        ".precursors.lock",
        "done",
        "meta.json",
        "sweep.json",
        "runs.csv",
        "contact_map.svg",
        "coulomb_stress.gif",
        "scene.json",
        "per_avalanche.csv",
        "fronts.csv",
        "power_laws.csv",
        "distributions.csv",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} not made: {names:?}"
        );
    }
    std::fs::remove_dir_all(&sweep).unwrap();
    names
}

#[test]
fn no_output_option_can_name_a_file_of_a_run_or_a_sweep_directory() {
    let dir = scratch("collide");
    let (scene, run, ck) = finished_run(&dir);
    let names = every_name(&dir, &run);
    let before = contents(&dir);
    let mut failures = Vec::new();
    for name in &names {
        let target = run.join(name);
        // A checkpoint of `run` or `resume` may not take the name: refused (code 2) before
        // anything is written. `movie --out` writes GIFs only: its own movies it may
        // replace (they are derived), any other name is refused.
        let cases: Vec<(Vec<&str>, &[i32])> = vec![
            (
                vec![
                    "run",
                    path(&scene),
                    "--out",
                    path(&run),
                    "--checkpoint",
                    path(&target),
                    "-q",
                ],
                &[2],
            ),
            (
                vec!["resume", path(&target), "--out", path(&run), "-q"],
                &[2],
            ),
        ];
        for (args, codes) in cases {
            let Some(o) = bounded(&args) else {
                failures.push(format!("{args:?} hung"));
                continue;
            };
            if !codes.contains(&o.status.code().unwrap_or(-1)) {
                failures.push(format!(
                    "{args:?}: code {:?}, {}",
                    o.status.code(),
                    stderr(&o)
                ));
            }
            if contents(&dir) != before {
                failures.push(format!("{args:?} changed the directory: {}", stderr(&o)));
                panic!("{failures:#?}");
            }
        }
        if !name.ends_with(".gif") {
            let args = [
                "movie",
                path(&run),
                "--field",
                "contact-area",
                "--out",
                path(&target),
                "-q",
            ];
            match bounded(&args) {
                None => failures.push(format!("{args:?} hung")),
                Some(o) if o.status.success() => failures.push(format!("{args:?} succeeded")),
                Some(_) => {}
            }
            assert!(contents(&dir) == before, "{args:?} changed the directory");
        }
    }
    // The checkpoint beside the tables under a name of its own still works, and the run
    // may not take its own scene file as its checkpoint.
    let args = [
        "run",
        path(&scene),
        "--out",
        path(&run),
        "--checkpoint",
        path(&scene),
        "-q",
    ];
    let o = precursors(&args);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), SCENE);
    let o = precursors(&["resume", path(&ck), "--out", path(&run), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(failures.is_empty(), "{failures:#?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_and_a_sweep_never_share_a_directory() {
    let dir = scratch("share");
    let scene = dir.join("scene-in.json");
    std::fs::write(&scene, OTHER).unwrap();
    let sweep_file = dir.join("sweep-in.json");
    std::fs::write(&sweep_file, SWEEP).unwrap();
    let (run, sweep) = (dir.join("run"), dir.join("sweep"));
    for args in [
        ["run", path(&scene), "--out", path(&run), "-q"],
        ["sweep", path(&sweep_file), "--out", path(&sweep), "-q"],
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let before = contents(&dir);
    let one_run = sweep.join("p0000-r0000");
    assert!(one_run.join("done").is_file());
    for (args, says) in [
        // The README's order: a run, then a sweep into the same folder.
        (
            vec!["sweep", path(&sweep_file), "--out", path(&run), "-q"],
            "run's files",
        ),
        (
            vec!["run", path(&scene), "--out", path(&sweep), "-q"],
            "sweep's directory",
        ),
        (
            vec!["run", path(&scene), "--out", path(&one_run), "-q"],
            "run directory of a sweep",
        ),
    ] {
        let o = bounded(&args).expect("no hang");
        let text = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{args:?}: {text}");
        assert!(text.contains(says), "{args:?}: {text}");
        assert!(
            contents(&dir) == before,
            "{args:?} changed the directories: {text}"
        );
    }
    let o = precursors(&["merge", path(&sweep)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_new_run_removes_the_figures_and_movies_of_the_old() {
    // And the statistics of the old (`power_laws.csv`, `distributions.csv`); the new run
    // derives its own `per_avalanche.csv` and `fronts.csv`.
    let dir = scratch("stale");
    let (_, run, _) = finished_run(&dir);
    let drawn: Vec<String> = contents(&run)
        .into_iter()
        .map(|(n, _)| n)
        .filter(|n| n.ends_with(".png") || n.ends_with(".svg") || n.ends_with(".gif"))
        .collect();
    assert_eq!(drawn.len(), 12, "{drawn:?}"); // 5 figures x 2 formats, 2 movies
    let mine = run.join("notes.png");
    std::fs::write(&mine, "the user's own file").unwrap();
    let other = dir.join("other.json");
    std::fs::write(&other, OTHER).unwrap();
    let o = precursors(&["run", path(&other), "--out", path(&run), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let left: Vec<String> = contents(&run).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        left,
        [
            ".precursors.lock",
            "contact_map.csv",
            "curve.csv",
            "events.csv",
            "fronts.csv",
            "notes.png",
            "per_avalanche.csv",
            "scene.json"
        ],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Makes a FIFO (and, as root, a character device: /dev/null's numbers) under `dir`.
fn special_files(dir: &Path) -> Vec<PathBuf> {
    let fifo = dir.join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
    let mut out = vec![fifo];
    let device = dir.join("null-device");
    let made = std::process::Command::new("mknod")
        .arg(&device)
        .args(["c", "1", "3"])
        .stderr(std::process::Stdio::null())
        .status();
    if made.is_ok_and(|s| s.success()) {
        out.push(device);
    } else {
        eprintln!("note: mknod not permitted here: the device-node cases are left out");
    }
    out.push(dir.to_path_buf()); // a directory
    out
}

#[cfg(unix)]
#[test]
fn special_files_as_inputs_and_outputs_get_an_answer_and_stay() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("special");
    let (scene, run, ck) = finished_run(&dir);
    let specials = special_files(&dir);
    let kinds = |p: &Path| std::fs::symlink_metadata(p).unwrap().file_type();
    let mut inputs: Vec<PathBuf> = specials.clone();
    if Path::new("/dev/zero").exists() {
        inputs.push("/dev/zero".into());
    }
    let mut failures = Vec::new();
    let check = |args: Vec<&str>, failures: &mut Vec<String>| match bounded(&args) {
        None => failures.push(format!("{args:?} hung")),
        Some(o) => {
            let text = stderr(&o);
            if o.status.code() != Some(4) || !text.contains("not a regular file") {
                failures.push(format!("{args:?}: code {:?}, {text}", o.status.code()));
            }
        }
    };
    for input in &inputs {
        let heights = dir.join("with-heights.json");
        let with_heights = SCENE.replace(
            r#""heights": { "kind": "gaussian", "seed": 0 }"#,
            &format!(
                r#""heights": {{ "kind": "file", "path": {:?} }}"#,
                path(input)
            ),
        );
        std::fs::write(&heights, with_heights).unwrap();
        let out = dir.join("out");
        check(vec!["info", path(input)], &mut failures);
        check(
            vec!["run", path(input), "--out", path(&out), "-q"],
            &mut failures,
        );
        check(vec!["info", path(&heights)], &mut failures);
        check(
            vec!["resume", path(input), "--out", path(&run), "-q"],
            &mut failures,
        );
        check(
            vec!["sweep", path(input), "--out", path(&out), "-q"],
            &mut failures,
        );
    }
    for output in &specials {
        let before = kinds(output);
        let gif = dir.join("special.gif");
        let _ = std::fs::remove_file(&gif);
        if output.is_dir() {
            std::fs::create_dir(&gif).unwrap();
        } else {
            std::fs::hard_link(output, &gif)
                .or_else(|_| std::os::unix::fs::symlink(output, &gif))
                .unwrap();
        }
        check(
            vec![
                "run",
                path(&scene),
                "--out",
                path(&run),
                "--checkpoint",
                path(output),
                "-q",
            ],
            &mut failures,
        );
        check(
            vec![
                "movie",
                path(&run),
                "--field",
                "contact-area",
                "--out",
                path(&gif),
                "-q",
            ],
            &mut failures,
        );
        let after = kinds(output);
        assert!(
            before.is_fifo() == after.is_fifo()
                && before.is_char_device() == after.is_char_device()
                && before.is_dir() == after.is_dir(),
            "{} was replaced",
            output.display()
        );
        if gif.is_dir() {
            std::fs::remove_dir(&gif).unwrap();
        } else {
            std::fs::remove_file(&gif).unwrap();
        }
    }
    // A symbolic link named as the checkpoint is not written through, nor replaced.
    let link = dir.join("link.json");
    std::os::unix::fs::symlink(&ck, &link).unwrap();
    let kept = std::fs::read(&ck).unwrap();
    check(
        vec![
            "run",
            path(&scene),
            "--out",
            path(&run),
            "--checkpoint",
            path(&link),
            "-q",
        ],
        &mut failures,
    );
    assert_eq!(std::fs::read(&ck).unwrap(), kept);
    assert!(failures.is_empty(), "{failures:#?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
