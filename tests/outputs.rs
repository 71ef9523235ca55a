//! Outputs that cannot overwrite each other, and inputs that are files (docs/cli.md,
//! "Guarantees"): every output option of the program against every file name of a run
//! and a sweep directory; a run and a sweep never share a directory; a new run leaves no
//! figure of the old one; a FIFO, a device or a directory given as an input or an output
//! gets an answer (never a hang, never a replaced device).
//!
//! Each case runs the program under a time bound (a hang fails the test) and compares the
//! directory's bytes before and after a refusal.

use crate::common::program::{command, contents, path, precursors, stderr};
use crate::common::{copy_dir, scratch};
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

/// A sweep of the tiny scene over the block's length (30 and 60 mm), two realizations.
const SWEEP_LX: &str = r#"{ "base": { "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 }, "normal_load": 500.0 },
    "axes": [ { "key": "block.lx", "values": [0.03, 0.06] } ],
    "realizations": 2, "seed": 5 }"#;

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

/// A sweep of [`SWEEP`] run to its end in `dir/sweep` (its file `dir/sweep-in.json`).
fn finished_sweep(dir: &Path) -> PathBuf {
    let sweep_file = dir.join("sweep-in.json");
    std::fs::write(&sweep_file, SWEEP).unwrap();
    let sweep = dir.join("sweep");
    let args = [
        "sweep",
        path(&sweep_file),
        "--out",
        path(&sweep),
        "-q",
        "--jobs",
        "1",
    ];
    let o = precursors(&args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    sweep
}

/// A sweep of two block lengths (two runs each) in `dir/lx`, with its `stats` tables and
/// its figures (the collapse among them).
fn lx_sweep(dir: &Path) -> PathBuf {
    let sweep_file = dir.join("lx-in.json");
    std::fs::write(&sweep_file, SWEEP_LX).unwrap();
    let sweep = dir.join("lx");
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
        vec!["stats", path(&sweep), "--bootstrap", "5", "--goodness", "5"],
        vec!["plot", path(&sweep)],
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    sweep
}

/// The names of every file a run directory and a sweep directory (and its run
/// directories) can hold.
fn every_name(dir: &Path, run: &Path) -> Vec<String> {
    let sweep = finished_sweep(dir);
    let o = precursors(&["plot", path(&sweep), "--format", "both"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
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

/// One command against a symbolic link at one path of its directories: the link's target
/// (a file outside the directory) must keep its bytes, the command must be refused with
/// code 4 (a path that is not a regular file: docs/cli.md) and its message must name the
/// link. `make` builds the case's directory (a copy) and returns the arguments.
#[cfg(unix)]
struct LinkCase<'a> {
    /// The directory the case's copies go into.
    dir: &'a Path,
    failures: Vec<String>,
    cases: usize,
}

#[cfg(unix)]
impl LinkCase<'_> {
    /// Runs `args` (made by `make` from the case's copy of `pristine`) with `name` (a path
    /// relative to the copy) replaced by a link to a file outside it.
    fn check(&mut self, pristine: &Path, name: &str, make: impl FnOnce(&Path) -> Vec<String>) {
        self.cases += 1;
        let case = self.dir.join(format!("case{}", self.cases));
        let copy = case.join("dir");
        copy_dir(pristine, &copy);
        let target = case.join("outside");
        let bytes = format!("the file outside, case {} ({name})\n", self.cases).into_bytes();
        std::fs::write(&target, &bytes).unwrap();
        let link = copy.join(name);
        let _ = std::fs::remove_file(&link);
        std::fs::create_dir_all(link.parent().unwrap()).unwrap();
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let args = make(&copy);
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let what = format!("{} with {name} a link", argv.join(" "));
        let Some(o) = bounded(&argv) else {
            self.failures.push(format!("{what}: hung"));
            return;
        };
        let text = stderr(&o);
        if std::fs::read(&target).unwrap() != bytes {
            self.failures
                .push(format!("{what}: the link's target was changed ({text})"));
        }
        if !std::fs::symlink_metadata(&link).is_ok_and(|m| m.is_symlink()) {
            self.failures.push(format!("{what}: the link was replaced"));
        }
        if o.status.code() != Some(4) || !text.contains(path(&link)) {
            self.failures
                .push(format!("{what}: code {:?}, {text}", o.status.code()));
        }
        std::fs::remove_dir_all(&case).unwrap();
    }
}

/// Issue 53: a symbolic link at any path of a run directory, a sweep directory, or of the
/// figures and PNG frames, is never followed out of its directory, nor replaced: every
/// reader and writer of that path refuses it (code 4) naming it, and the file it points to
/// keeps its bytes. (Before: `run` wrote its holder line into the target of a linked
/// `.precursors.lock`, then emptied it, with code 0; readers read tables through links.)
#[cfg(unix)]
#[test]
fn a_symbolic_link_at_any_path_of_a_directory_is_refused_and_its_target_kept() {
    let dir = scratch("links");
    let (scene, run, ck) = finished_run(&dir);
    let sweep = finished_sweep(&dir);
    let sweep_file = dir.join("sweep-in.json");
    for args in [
        vec!["plot", path(&sweep)],
        vec!["stats", path(&sweep), "--bootstrap", "5", "--goodness", "5"],
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    let mut cases = LinkCase {
        dir: &dir.join("cases"),
        failures: Vec::new(),
        cases: 0,
    };
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let tables = ["events.csv", "curve.csv", "contact_map.csv", "fields.csv"];
    let partials = tables.map(|t| format!("{t}.partial"));
    // `run` writes (or removes) every file of a run directory.
    let mut names: Vec<String> = [
        ".precursors.lock",
        "scene.json",
        "per_avalanche.csv",
        "fronts.csv",
        "power_laws.csv",
        "distributions.csv",
        "precursor_length.png",
        "contact_map.svg",
        "contact_area.gif",
    ]
    .iter()
    .chain(&tables)
    .map(|n| n.to_string())
    .chain(partials.iter().cloned())
    .collect();
    names.sort();
    for name in &names {
        cases.check(&run, name, |d| {
            vec!["run".into(), s(&scene), "--out".into(), s(d), "-q".into()]
        });
    }
    // `resume` reads the tables (a `.partial` first) and the scene record, and writes
    // the tables and the derived ones; its checkpoint is read and written over.
    for name in names.iter().filter(|n| {
        !n.ends_with(".png")
            && !n.ends_with(".svg")
            && !n.ends_with(".gif")
            && !["power_laws.csv", "distributions.csv"].contains(&n.as_str())
    }) {
        cases.check(&run, name, |d| {
            let ck2 = d.join("ck-copy.json");
            std::fs::copy(&ck, &ck2).unwrap();
            vec!["resume".into(), s(&ck2), "--out".into(), s(d), "-q".into()]
        });
    }
    cases.check(&run, "ck-link.json", |d| {
        vec![
            "resume".into(),
            s(&d.join("ck-link.json")),
            "--out".into(),
            s(d),
            "-q".into(),
        ]
    });
    cases.check(&run, "ck-link.json", |d| {
        vec![
            "run".into(),
            s(&scene),
            "--out".into(),
            s(d),
            "--checkpoint".into(),
            s(&d.join("ck-link.json")),
            "-q".into(),
        ]
    });
    // The readers: each path they read or write.
    let reads: [(&[&str], &[&str]); 3] = [
        (
            &["plot", "--format", "both"],
            &[
                ".precursors.lock",
                "scene.json",
                "events.csv",
                "curve.csv",
                "contact_map.csv",
                "precursor_length.png",
                "contact_area.svg",
                "contact_map.png",
                "fronts.svg",
                // The tables of `stats` the statistics figures read (issue 54).
                "power_laws.csv",
                "binned_means.csv",
                "scaling.csv",
            ],
        ),
        (
            &["stats", "--bootstrap", "5", "--goodness", "5"],
            &[
                ".precursors.lock",
                "scene.json",
                "events.csv",
                "curve.csv",
                "power_laws.csv",
                "distributions.csv",
            ],
        ),
        (
            &[
                "movie",
                "-q",
                "--max-frames",
                "3",
                "--width",
                "300",
                "--height",
                "200",
            ],
            &[
                ".precursors.lock",
                "scene.json",
                "fields.csv",
                "contact_area.gif",
                "coulomb_stress.gif",
            ],
        ),
    ];
    for (command, names) in reads {
        for name in names {
            cases.check(&run, name, |d| {
                let mut args = vec![command[0].to_string(), s(d)];
                args.extend(command[1..].iter().map(|a| a.to_string()));
                args
            });
        }
    }
    // The PNG frames of a movie, in a directory of the run's copy.
    for name in [
        "frames/contact_area_0000.png",
        "frames/contact_area_0002.png",
    ] {
        cases.check(&run, name, |d| {
            vec![
                "movie".into(),
                s(d),
                "-q".into(),
                "--field".into(),
                "contact-area".into(),
                "--max-frames".into(),
                "3".into(),
                "--width".into(),
                "300".into(),
                "--height".into(),
                "200".into(),
                "--png-frames".into(),
                s(&d.join("frames")),
            ]
        });
    }
    // A sweep directory: its lock and copy of the sweep for `sweep`, `plot` and `stats`,
    // the merged tables for `merge` and `plot`, a run's marker and tables for all.
    let one = "p0000-r0001";
    let sweep_cases: [(&[&str], &[&str]); 4] = [
        (
            &["sweep", "SWEEP", "-q", "--jobs", "1"],
            &[".precursors.lock", "sweep.json", "p0000-r0001/done"],
        ),
        (
            &["merge"],
            &[
                "sweep.json",
                "curves.csv",
                "slip.csv",
                "avalanches.csv",
                "runs.csv",
                "p0000-r0001/done",
                "p0000-r0001/curve.csv",
                "p0000-r0001/events.csv",
                "p0000-r0001/scene.json",
            ],
        ),
        (
            &["plot"],
            &[
                ".precursors.lock",
                "sweep.json",
                "curves.csv",
                "slip.csv",
                "avalanches.csv",
                "runs.csv",
                "power_laws.csv",
                "binned_means.csv",
                "scaling.csv",
                "precursor_length.png",
                "avalanche_sizes.png",
                "potency_against_size.png",
                "p0000-r0001/done",
                "p0000-r0001/curve.csv",
            ],
        ),
        (
            &["stats", "--bootstrap", "5", "--goodness", "5"],
            &[
                ".precursors.lock",
                "sweep.json",
                "power_laws.csv",
                "distributions.csv",
                "p0000-r0001/done",
                "p0000-r0001/events.csv",
            ],
        ),
    ];
    for (command, names) in sweep_cases {
        for name in names {
            cases.check(&sweep, name, |d| match command[0] {
                "sweep" => {
                    let mut args = vec!["sweep".into(), s(&sweep_file), "--out".into(), s(d)];
                    args.extend(command[2..].iter().map(|a| a.to_string()));
                    args
                }
                _ => {
                    let mut args = vec![command[0].to_string(), s(d)];
                    args.extend(command[1..].iter().map(|a| a.to_string()));
                    args
                }
            });
        }
    }
    // A sweep over the block's length: `plot` reads the collapse's tables.
    let lengths = lx_sweep(&dir);
    for name in ["collapse.csv", "distributions.csv", "collapse.png"] {
        cases.check(&lengths, name, |d| vec!["plot".into(), s(d)]);
    }
    // A cut run of the sweep (no marker): `sweep` runs it again, and refuses a link at
    // its lock, its scene record or a table rather than remove it or write through it.
    let cut = dir.join("cut");
    copy_dir(&sweep, &cut);
    std::fs::remove_file(cut.join(one).join("done")).unwrap();
    std::fs::remove_file(cut.join(one).join("meta.json")).unwrap();
    for name in [
        ".precursors.lock",
        "scene.json",
        "events.csv",
        "curve.csv.partial",
    ] {
        cases.check(&cut, &format!("{one}/{name}"), |d| {
            vec![
                "sweep".into(),
                s(&sweep_file),
                "--out".into(),
                s(d),
                "-q".into(),
                "--jobs".into(),
                "1".into(),
            ]
        });
    }
    assert!(cases.cases > 60, "{} cases", cases.cases);
    assert!(cases.failures.is_empty(), "{:#?}", cases.failures);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 54, item 7: a table of `stats` gone after the figures were drawn. `plot --figure`
/// of a figure drawn from it is refused (code 2) naming the table, and the figure already
/// there keeps its bytes; `plot` of every figure draws the others and says that the one
/// left in the directory is from an earlier plot, not from these tables (before: not a
/// word, the old figure passed for a new one).
#[test]
fn a_missing_statistics_table_is_said_and_its_old_figure_not_passed_off() {
    let dir = scratch("missing-tables");
    let lengths = lx_sweep(&dir);
    let cases = [
        ("collapse", "collapse.csv"),
        ("collapse", "distributions.csv"),
        ("potency_against_size", "binned_means.csv"),
        ("potency_against_size", "scaling.csv"),
    ];
    for (k, (figure, table)) in cases.into_iter().enumerate() {
        let copy = dir.join(format!("case{k}"));
        copy_dir(&lengths, &copy);
        let png = copy.join(format!("{figure}.png"));
        let old = std::fs::read(&png).unwrap_or_else(|e| panic!("{figure} not drawn: {e}"));
        std::fs::remove_file(copy.join(table)).unwrap();
        let o = precursors(&["plot", path(&copy), "--figure", figure]);
        let text = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{figure} without {table}: {text}");
        assert!(
            text.contains(&format!("no {table}")) && text.contains("precursors stats"),
            "{figure} without {table}: {text}"
        );
        assert_eq!(std::fs::read(&png).unwrap(), old);
        let o = precursors(&["plot", path(&copy)]);
        let text = stderr(&o);
        assert_eq!(o.status.code(), Some(0), "{text}");
        let note = format!("{figure}.png in the directory is from an earlier plot");
        assert!(
            text.contains(&note) && text.contains(&format!("no {table}")),
            "{figure} without {table}: {text}"
        );
        assert!(text.contains("precursor_length.png"), "{text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Holds `dir`'s lock as a writer (`run`, `sweep`) does, with its line in the file.
#[cfg(unix)]
fn hold_lock(dir: &Path, line: &str) -> std::fs::File {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(true)
        .open(dir.join(".precursors.lock"))
        .unwrap();
    file.try_lock().unwrap();
    std::fs::write(dir.join(".precursors.lock"), line).unwrap();
    file
}

/// The readers `plot`, `movie` and `stats` take the directory's lock shared: refused
/// (code 4, naming the holder) while a run or a sweep writes it, with nothing written
/// and the holder's line kept; they neither write nor empty the lock file, and two of
/// them read one directory at once.
#[cfg(unix)]
#[test]
fn readers_are_refused_while_a_writer_holds_the_directory_and_leave_its_lock_alone() {
    let dir = scratch("readlock");
    let (_, run, _) = finished_run(&dir);
    let sweep_file = dir.join("sweep-in.json");
    std::fs::write(&sweep_file, SWEEP).unwrap();
    let sweep = dir.join("sweep");
    let o = precursors(&["sweep", path(&sweep_file), "--out", path(&sweep), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let line = "pid 4242 on host elsewhere, since 2026-01-01T00:00:00Z: precursors run";
    let readers = |d: &Path| -> Vec<Vec<String>> {
        let d = path(d).to_string();
        let mut all = vec![
            vec!["plot".into(), d.clone()],
            vec![
                "stats".into(),
                d.clone(),
                "--bootstrap".into(),
                "5".into(),
                "--goodness".into(),
                "5".into(),
            ],
        ];
        if !d.ends_with("sweep") {
            all.push(vec![
                "movie".into(),
                d,
                "-q".into(),
                "--max-frames".into(),
                "2".into(),
                "--width".into(),
                "300".into(),
                "--height".into(),
                "200".into(),
            ]);
        }
        all
    };
    for d in [&run, &sweep] {
        let held = hold_lock(d, line);
        let before = contents(&dir);
        for args in readers(d) {
            let argv: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = bounded(&argv).expect("no hang");
            let text = stderr(&o);
            assert_eq!(o.status.code(), Some(4), "{argv:?}: {text}");
            assert!(
                text.contains("pid 4242 on host elsewhere"),
                "{argv:?}: {text}"
            );
            assert!(contents(&dir) == before, "{argv:?} wrote: {text}");
        }
        drop(held);
        // Unlocked, a stale line (a writer killed before it emptied the file) stays as
        // it is: a reader writes nothing into the lock file.
        std::fs::write(d.join(".precursors.lock"), "stale").unwrap();
        for args in readers(d) {
            let argv: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = precursors(&argv);
            assert_eq!(o.status.code(), Some(0), "{argv:?}: {}", stderr(&o));
            assert_eq!(std::fs::read(d.join(".precursors.lock")).unwrap(), b"stale");
        }
    }
    // Two readers at once: one holding the shared lock does not refuse another ...
    std::fs::write(run.join(".precursors.lock"), "a killed writer's line").unwrap();
    let reader = std::fs::File::open(run.join(".precursors.lock")).unwrap();
    reader.try_lock_shared().unwrap();
    let o = precursors(&["plot", path(&run), "--figure", "precursor_length"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // ... and keeps a writer out.
    let scene = dir.join("scene-in.json");
    let o = precursors(&["run", path(&scene), "--out", path(&run), "-q"]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(stderr(&o).contains("a reader"), "{}", stderr(&o));
    drop(reader);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A run directory holding a stray `sweep.json` is neither a run's nor a sweep's: `plot`,
/// `stats` and `merge` refuse it (code 3, naming both) and write nothing. (Before: `plot`
/// drew it as a sweep over the run's figures and ended with code 5.)
#[test]
fn a_run_directory_with_a_stray_sweep_json_is_refused_by_its_readers() {
    let dir = scratch("stray");
    let (_, run, _) = finished_run(&dir);
    std::fs::write(run.join("sweep.json"), SWEEP).unwrap();
    let before = contents(&dir);
    for args in [
        vec!["plot", path(&run)],
        vec!["stats", path(&run), "--bootstrap", "5", "--goodness", "5"],
        vec!["merge", path(&run)],
    ] {
        let o = bounded(&args).expect("no hang");
        let text = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{args:?}: {text}");
        assert!(
            text.contains("sweep.json") && text.contains("run's files"),
            "{args:?}: {text}"
        );
        assert!(contents(&dir) == before, "{args:?} wrote: {text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--png-frames DIR` owns the frames of its name there: the frames of an older, longer
/// movie that the new one does not overwrite are removed (an encoder reading
/// `contact_area_%04d.png` would show them after the new movie's), the program says so,
/// and files of other names stay.
#[test]
fn png_frames_of_an_older_longer_movie_are_removed_and_said() {
    let dir = scratch("frames");
    let (_, run, _) = finished_run(&dir);
    let frames = dir.join("frames");
    let movie = |n: &str| {
        precursors(&[
            "movie",
            path(&run),
            "--field",
            "contact-area",
            "--max-frames",
            n,
            "--width",
            "300",
            "--height",
            "200",
            "--png-frames",
            path(&frames),
        ])
    };
    let o = movie("5");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::write(frames.join("notes.txt"), "mine").unwrap();
    std::fs::write(frames.join("contact_area_0001.txt"), "mine").unwrap();
    std::fs::write(frames.join("coulomb_stress_0004.png"), "another movie's").unwrap();
    let o = movie("2");
    let text = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{text}");
    let left: Vec<String> = contents(&frames).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        left,
        [
            "contact_area_0000.png",
            "contact_area_0001.png",
            "contact_area_0001.txt",
            "coulomb_stress_0004.png",
            "notes.txt"
        ],
        "{text}"
    );
    assert!(text.contains("removed 3 PNG frames"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// docs/tables.md documents every column of every table a run, a sweep, `merge` and
/// `stats` write, under the file's own name (issue 56): the tables of a spring-driven run
/// recording fields and profiles, of a two-point sweep, merged, and `stats` of both are
/// written here, and each header is checked against the page both ways (`<k>` in the
/// page stands for the column indices, `<axis>` for the sweep's axis keys).
#[test]
fn every_column_is_documented() {
    use precursors::output::RunTables;
    use precursors::sweep::{merge, statistics, StatsOptions, Sweep, SweepOptions};
    use precursors::SceneBuilder;
    let base = r#"{"block": {"lx": 0.012, "ly": 0.002, "lz": 0.01},
        "cells": {"kind": "count", "nx": 12, "ny": 2}, "normal_load": 50.0,
        "drive": {"kind": "spring", "stiffness": 4e6, "lateral": {"kind": "side"}}"#;
    let dir = scratch("columns");
    let run = dir.join("run");
    std::fs::create_dir_all(&run).unwrap();
    let scene = SceneBuilder::from_json_str(&format!(
        r#"{base}, "fields": {{"every": 1, "planes": [0.002]}},
            "profiles": {{"loads": [0.5], "planes": [0.002]}}}}"#
    ))
    .unwrap()
    .build()
    .unwrap();
    let mut driver = scene.driver().unwrap();
    RunTables::create(&run, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let sweep_dir = dir.join("sweep");
    let sweep = Sweep::from_json_str(&format!(
        r#"{{"base": {base}}}, "axes": [{{"key": "normal_load", "values": [50.0, 60.0]}}],
            "realizations": 2}}"#
    ))
    .unwrap();
    sweep
        .execute(&sweep_dir, &SweepOptions::new(), |_| {})
        .unwrap();
    merge(&sweep_dir).unwrap();
    let options = StatsOptions::default().fit(
        precursors::statistics::PowerLawOptions::default()
            .bootstrap(2)
            .goodness_samples(2)
            .min_tail(2),
    );
    statistics(&run, &options).unwrap();
    statistics(&sweep_dir, &options).unwrap();
    // A sweep over a block length: its statistics add the finite-size collapse.
    let length_dir = dir.join("lengths");
    Sweep::from_json_str(&format!(
        r#"{{"base": {base}}}, "axes": [{{"key": "block.lx", "values": [0.012, 0.024]}}],
            "realizations": 2}}"#
    ))
    .unwrap()
    .execute(&length_dir, &SweepOptions::new(), |_| {})
    .unwrap();
    statistics(&length_dir, &options).unwrap();

    // The page's tables: `### `NAME`` then rows whose first cell is `column`.
    let page = std::fs::read_to_string("docs/tables.md").unwrap();
    let mut documented: Vec<(String, Vec<String>)> = Vec::new();
    for line in page.lines() {
        if let Some(name) = line.strip_prefix("### `").and_then(|l| l.strip_suffix('`')) {
            documented.push((name.to_string(), Vec::new()));
        } else if let (Some(row), Some((_, columns))) =
            (line.strip_prefix("| `"), documented.last_mut())
        {
            columns.push(row.split('`').next().unwrap().to_string());
        }
    }
    let matches = |pattern: &str, column: &str| match pattern.split_once("<k>") {
        Some((head, "")) => column
            .strip_prefix(head)
            .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit())),
        _ => {
            pattern == "<axis>" && ["normal_load", "block.lx"].contains(&column)
                || pattern == column
        }
    };
    let mut checked = 0;
    for (table, columns) in &documented {
        let mut found = false;
        for directory in [&run, &sweep_dir, &length_dir] {
            let Ok(text) = std::fs::read_to_string(directory.join(table)) else {
                continue;
            };
            found = true;
            let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
            for column in &header {
                assert!(
                    columns.iter().any(|p| matches(p, column)),
                    "{table}: column {column} is not in docs/tables.md"
                );
            }
            for pattern in columns {
                // `<axis>` has no column in a run directory's tables.
                let axis_in_run = pattern == "<axis>" && directory == &run;
                assert!(
                    axis_in_run || header.iter().any(|c| matches(pattern, c)),
                    "{table}: docs/tables.md's {pattern} is not in {}",
                    directory.display()
                );
            }
            checked += 1;
        }
        assert!(
            found,
            "docs/tables.md documents {table}, which no directory holds"
        );
    }
    // Every CSV table written is on the page.
    for directory in [&run, &sweep_dir, &length_dir] {
        for entry in std::fs::read_dir(directory).unwrap() {
            let name = entry.unwrap().file_name().into_string().unwrap();
            if name.ends_with(".csv") {
                assert!(
                    documented.iter().any(|(t, _)| *t == name),
                    "{name} is not in docs/tables.md"
                );
            }
        }
    }
    assert_eq!(checked, 24);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Sends `signal` to the program once `file` holds more than `lines` lines, and returns
/// its output.
#[cfg(unix)]
fn signalled(args: &[&str], file: &Path, lines: usize, signal: &str) -> Output {
    let child = command(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while std::fs::read_to_string(file).map_or(0, |t| t.lines().count()) <= lines {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "{} not written",
            file.display()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = std::process::Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    child.wait_with_output().unwrap()
}

/// Ctrl-C (SIGINT) or SIGTERM stops `run` at its next event with one line saying what was
/// kept and the exact command that continues (issue 56: it exited 130 saying nothing):
/// with `--checkpoint` a checkpoint at that event, and the command given resumes to the
/// uninterrupted run's tables byte for byte; without, it says the run cannot continue.
/// `sweep` stops its runs and says how to go on. Exit code 128 + the signal.
#[cfg(unix)]
#[test]
fn a_signal_stops_with_what_was_kept_and_how_to_continue() {
    let dir = scratch("signals");
    let scene = "examples/scenes/calibration.json";
    let whole = dir.join("whole");
    let o = precursors(&["run", scene, "--out", path(&whole), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let out = dir.join("stopped");
    let checkpoint = dir.join("cp.json");
    let o = signalled(
        &[
            "run",
            scene,
            "--out",
            path(&out),
            "--checkpoint",
            path(&checkpoint),
            "-q",
        ],
        &out.join("events.csv.partial"),
        50,
        "-INT",
    );
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let text = stderr(&o);
    let errors: Vec<&str> = text.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{text}");
    assert!(errors[0].starts_with("error: stopped by SIGINT"), "{text}");
    let again = format!(
        "precursors resume {} --out {}",
        path(&checkpoint),
        path(&out)
    );
    assert!(text.contains(&again), "{text}");
    assert!(!out.join("events.csv").exists());
    // The command it gives continues the run to the uninterrupted run's tables.
    let o = precursors(&["resume", path(&checkpoint), "--out", path(&out), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for table in ["events.csv", "curve.csv", "contact_map.csv"] {
        assert_eq!(
            std::fs::read(out.join(table)).unwrap(),
            std::fs::read(whole.join(table)).unwrap(),
            "{table}"
        );
    }

    let bare = dir.join("bare");
    let o = signalled(
        &["run", scene, "--out", path(&bare), "-q"],
        &bare.join("events.csv.partial"),
        50,
        "-TERM",
    );
    assert_eq!(o.status.code(), Some(143), "{}", stderr(&o));
    let text = stderr(&o);
    assert!(text.contains("stopped by SIGTERM"), "{text}");
    assert!(text.contains("cannot continue"), "{text}");

    let sweep = dir.join("sweep.json");
    std::fs::write(
        &sweep,
        r#"{"axes": [{"key": "normal_load", "values": [3000.0, 3500.0]}], "realizations": 2}"#,
    )
    .unwrap();
    let out = dir.join("sweep");
    let o = signalled(
        &[
            "sweep",
            path(&sweep),
            "--out",
            path(&out),
            "--jobs",
            "1",
            "-q",
        ],
        &out.join("p0000-r0000").join("events.csv.partial"),
        50,
        "-INT",
    );
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let text = stderr(&o);
    let again = format!("precursors sweep {} --out {}", path(&sweep), path(&out));
    assert!(text.contains(&again), "{text}");
    assert!(!out.join("p0000-r0000").join("done").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
