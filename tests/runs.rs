//! Runs that cannot be corrupted (feature `serde`; the program's side with `cli`): a run
//! directory is locked while written and a second writer is refused naming the holder;
//! the tables are `NAME.partial` until global slip; two sweeps on one directory share its
//! runs; `resume` refuses, before it writes anything, a checkpoint of another scene, tables
//! that do not reach the checkpoint, damaged tables and edited checkpoints; a run killed at
//! random moments and continued ends with the tables of an undisturbed run. The reference
//! is always an undisturbed run or sweep of the same scene.

use crate::common::scratch;
use precursors::output::RunTables;
use precursors::sweep::{merge, Sweep, SweepError, SweepOptions};
use precursors::{Error, Scene};
use std::path::{Path, PathBuf};

// The documented file-format names and values (docs/cli.md, docs/sweep-format.md).
const PARTIAL_SUFFIX: &str = ".partial";
const TABLE_NAMES: [&str; 3] = ["events.csv", "curve.csv", "contact_map.csv"];
const DONE_FILE: &str = "done";

/// A tiny scene: 30 x 5 = 150 cells, about 330 events to global slip.
const SCENE: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 },
    "normal_load": 500.0,
    "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }"#;

/// Two loads, two rod heights, two realizations of [`SCENE`]: 8 runs.
fn sweep_text() -> String {
    format!(
        r#"{{ "base": {SCENE}, "axes": [
            {{ "key": "normal_load", "values": [400.0, 600.0] }},
            {{ "key": "drive.height", "values": [0.004, 0.008] }} ],
            "realizations": 2, "seed": 11 }}"#
    )
}

/// Every file under `dir` (relative name, bytes), sorted; `skip` leaves out names.
fn files(dir: &Path, skip: &[&str]) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let name = path.strip_prefix(dir).unwrap().display().to_string();
            if path.is_dir() {
                stack.push(path);
            } else if !skip.iter().any(|s| name.ends_with(s)) {
                out.push((name, std::fs::read(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// The CSV files under `dir` (the runs' tables and the merged ones), sorted.
fn tables(dir: &Path) -> Vec<(String, Vec<u8>)> {
    files(dir, &[])
        .into_iter()
        .filter(|(n, _)| n.ends_with(".csv"))
        .collect()
}

fn scene() -> Scene {
    precursors::SceneBuilder::from_json_str(SCENE)
        .unwrap()
        .build()
        .unwrap()
}

#[test]
fn tables_are_partial_until_global_slip_and_the_directory_is_locked() {
    let dir = scratch("partial");
    let scene = scene();
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&dir, &driver).unwrap();
    // A second writer, even in this process, is refused naming the holder.
    let holder = format!("pid {}", std::process::id());
    for second in [
        RunTables::create(&dir, &driver),
        RunTables::resume(&dir, &driver),
    ] {
        match second {
            Err(e @ Error::DirectoryLocked { .. }) => {
                let text = e.to_string();
                assert!(text.contains(&holder) && text.contains("since"), "{text}");
            }
            other => panic!("a second writer was not refused: {other:?}"),
        }
    }
    for _ in 0..100 {
        let event = driver.step().unwrap().unwrap();
        tables.record(&driver, &event).unwrap();
    }
    tables.flush().unwrap();
    for name in TABLE_NAMES {
        assert!(!dir.join(name).exists(), "{name} before global slip");
        let partial = std::fs::read_to_string(dir.join(format!("{name}{PARTIAL_SUFFIX}")));
        assert!(partial.unwrap().lines().count() > 1, "{name}");
    }
    // Not finished before global slip: refused, the tables stay partial.
    let e = tables.finish().unwrap_err();
    assert!(matches!(e, Error::RunDirectory { .. }), "{e:?}");
    assert!(!dir.join("events.csv").exists());
    // The lock ended with the writer: a new run takes the directory and ends with the
    // tables under their names, none partial.
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&dir, &driver).unwrap();
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
    }
    let paths = tables.finish().unwrap();
    for (path, name) in paths.iter().zip(TABLE_NAMES) {
        assert_eq!(path, &dir.join(name));
        assert!(path.is_file(), "{name}");
        assert!(!dir.join(format!("{name}{PARTIAL_SUFFIX}")).exists());
    }
    assert_eq!(
        std::fs::read(dir.join(".precursors.lock")).unwrap(),
        b"",
        "the lock file is emptied when released"
    );
    // A new run in a finished directory removes the earlier tables at once.
    let driver = scene.driver().unwrap();
    let tables = RunTables::create(&dir, &driver).unwrap();
    assert!(TABLE_NAMES.iter().all(|n| !dir.join(n).exists()));
    drop(tables);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_sweep_leaves_a_run_held_elsewhere_to_its_holder() {
    let sweep = Sweep::from_json_str(&sweep_text()).unwrap();
    let reference = scratch("held-reference");
    sweep
        .execute(&reference, &SweepOptions::new(), |_| {})
        .unwrap();
    merge(&reference).unwrap();
    let dir = scratch("held");
    // Another writer holds run 3's directory (here: this process, through the tables of
    // a run; the lock is per open file, so the sweep's threads are refused it too).
    let held = dir.join(sweep.runs()[3].dir_name());
    std::fs::create_dir_all(&held).unwrap();
    let holder_scene = sweep.runs()[3].scene().clone().build().unwrap();
    let holder = RunTables::create(&held, &holder_scene.driver().unwrap()).unwrap();
    let first = sweep
        .execute(&dir, &SweepOptions::new().with_jobs(2).unwrap(), |_| {})
        .unwrap();
    assert_eq!(
        (
            first.runs,
            first.completed,
            first.skipped,
            first.held_elsewhere
        ),
        (8, 7, 0, 1)
    );
    // Neither run nor marked complete; its holder's files untouched.
    assert!(!held.join(DONE_FILE).exists());
    assert!(held.join("events.csv.partial").is_file());
    assert_eq!(merge(&dir).unwrap().runs_missing, 1);
    // The holder gone (it did not finish), the next sweep redoes the run.
    drop(holder);
    let second = sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    assert_eq!(
        (second.completed, second.skipped, second.held_elsewhere),
        (1, 7, 0)
    );
    assert_eq!(merge(&dir).unwrap().runs_missing, 0);
    assert_eq!(tables(&dir), tables(&reference));
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&reference).unwrap();
}

#[test]
fn of_sweeps_starting_together_on_a_new_directory_one_takes_it() {
    // Four different sweeps (one run each) started at once on one new directory: the
    // check and write of sweep.json is under the directory's lock, so exactly one runs
    // there and the others find its sweep.json.
    let dir = scratch("prepare").join("out");
    let sweeps: Vec<Sweep> = (0..4)
        .map(|k| {
            Sweep::from_json_str(&format!(
                r#"{{ "base": {SCENE}, "axes": [{{ "key": "normal_load", "values": [{}] }}] }}"#,
                400.0 + 10.0 * f64::from(k)
            ))
            .unwrap()
        })
        .collect();
    let barrier = std::sync::Barrier::new(sweeps.len());
    let outcomes: Vec<Result<_, SweepError>> = std::thread::scope(|s| {
        let handles: Vec<_> = sweeps
            .iter()
            .map(|sweep| {
                let (barrier, dir) = (&barrier, &dir);
                s.spawn(move || {
                    barrier.wait();
                    sweep.execute(dir, &SweepOptions::new(), |_| {})
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let won: Vec<usize> = (0..4).filter(|&k| outcomes[k].is_ok()).collect();
    assert_eq!(won.len(), 1, "{outcomes:?}");
    for (k, outcome) in outcomes.iter().enumerate() {
        if let Err(e) = outcome {
            assert!(matches!(e, SweepError::Directory { .. }), "{k}: {e:?}");
        }
    }
    let copy = std::fs::read_to_string(dir.join("sweep.json")).unwrap();
    assert_eq!(copy, sweeps[won[0]].to_json().unwrap());
    std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
}

/// The program (`src/bin/precursors.rs`).
#[cfg(feature = "cli")]
mod cli {
    use super::*;
    use std::process::{Child, Stdio};
    use std::time::{Duration, Instant};

    use crate::common::program::{command, path, precursors, stderr};

    fn spawn(args: &[&str]) -> Child {
        command(args)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    }

    /// The runs a sweep says it ran ("N runs done, ...").
    fn runs_done(text: &str) -> usize {
        let line = text
            .lines()
            .find(|l| l.contains(" runs done, "))
            .unwrap_or_else(|| panic!("no summary: {text}"));
        line.split(' ').next().unwrap().parse().unwrap()
    }

    #[test]
    fn two_sweeps_on_one_directory_give_the_tables_of_one() {
        let dir = scratch("cli-two");
        let file = dir.join("sweep.json");
        std::fs::write(&file, sweep_text()).unwrap();
        let (one, shared) = (dir.join("one"), dir.join("shared"));
        let o = precursors(&["sweep", path(&file), "--out", path(&one), "--jobs", "1"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert_eq!(precursors(&["merge", path(&one)]).status.code(), Some(0));
        // Two processes at once on one directory (a job array submitted twice).
        let args = ["sweep", path(&file), "--out", path(&shared), "--jobs", "2"];
        let (a, b) = (spawn(&args), spawn(&args));
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        assert_eq!(a.status.code(), Some(0), "{}", stderr(&a));
        assert_eq!(b.status.code(), Some(0), "{}", stderr(&b));
        // Each run was run once, by one of them.
        assert_eq!(
            runs_done(&stderr(&a)) + runs_done(&stderr(&b)),
            8,
            "{}\n{}",
            stderr(&a),
            stderr(&b)
        );
        let o = precursors(&["merge", path(&shared)]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let reference = tables(&one);
        assert_eq!(reference.len(), 44); // 8 runs x (3 tables + 2 derived) + 4 merged files
        assert!(tables(&shared) == reference, "the merged tables differ");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_run_on_a_locked_directory_is_refused_naming_the_holder() {
        let dir = scratch("cli-locked");
        let file = dir.join("scene.json");
        std::fs::write(&file, SCENE).unwrap();
        let out = dir.join("out");
        std::fs::create_dir_all(&out).unwrap();
        // The holder: this process, writing a run there.
        let tables = RunTables::create(&out, &scene().driver().unwrap()).unwrap();
        let before = files(&out, &[]);
        let o = precursors(&["run", path(&file), "--out", path(&out)]);
        let text = stderr(&o);
        assert_ne!(o.status.code(), Some(0), "{text}");
        assert!(
            text.contains("in use by another process")
                && text.contains(&format!("pid {}", std::process::id())),
            "{text}"
        );
        assert!(files(&out, &[]) == before, "the refused run wrote");
        drop(tables);
        // The holder another `precursors run`: named by its pid and command.
        let big = dir.join("big.json");
        std::fs::write(
            &big,
            SCENE.replace(r#""lx": 0.03, "ly": 0.005"#, r#""lx": 0.06, "ly": 0.02"#),
        )
        .unwrap();
        let mut child = spawn(&["run", path(&big), "--out", path(&out)]);
        let lock = out.join(".precursors.lock");
        let start = Instant::now();
        while std::fs::read_to_string(&lock)
            .unwrap_or_default()
            .is_empty()
        {
            assert!(start.elapsed() < Duration::from_secs(60), "no lock taken");
            std::thread::sleep(Duration::from_millis(5));
        }
        let o = precursors(&["run", path(&file), "--out", path(&out)]);
        let text = stderr(&o);
        let _ = child.kill();
        let _ = child.wait();
        assert_ne!(o.status.code(), Some(0), "{text}");
        assert!(
            text.contains(&format!("pid {}", child.id())) && text.contains("big.json"),
            "{text}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A complete run of `scene` with checkpoints every 3 stable states into `dir/a`, and
    /// its checkpoint's text.
    fn checkpointed_run(dir: &Path, name: &str, scene: &str) -> (PathBuf, String) {
        let file = dir.join(format!("{name}.json"));
        std::fs::write(&file, scene).unwrap();
        let out = dir.join(name);
        let cp = out.join("cp.json");
        let o = precursors(&[
            "run",
            path(&file),
            "--out",
            path(&out),
            "--checkpoint",
            path(&cp),
            "--every",
            "3",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let text = std::fs::read_to_string(&cp).unwrap();
        (out, text)
    }

    /// `text` without its lines `from..to` (1-based, the header is line 1).
    fn without_lines(text: &str, from: usize, to: usize) -> String {
        text.split_inclusive('\n')
            .enumerate()
            .filter(|(i, _)| !(from..to).contains(&(i + 1)))
            .map(|(_, l)| l)
            .collect()
    }

    #[test]
    fn resume_refuses_what_does_not_belong_and_writes_nothing() {
        let dir = scratch("cli-resume");
        let (base, checkpoint) = checkpointed_run(&dir, "a", SCENE);
        let (_, other) = checkpointed_run(&dir, "b", &SCENE.replace("500.0", "600.0"));
        let k: usize = {
            let at = checkpoint.find("\"events\":").unwrap() + "\"events\":".len();
            let digits: String = checkpoint[at..]
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            digits.parse().unwrap()
        };
        assert!(k > 100, "checkpoint at event {k}");
        let read = |name: &str| std::fs::read_to_string(base.join(name)).unwrap();
        let events = read("events.csv");
        let curve = read("curve.csv");
        let map = read("contact_map.csv");
        let states = checkpoint.find("\"states\":[").unwrap();
        let attached = states + checkpoint[states..].find("\"Attached\"").unwrap();
        // The line of curve.csv (1-based) holding the state of event `e`.
        let curve_line = |e: usize| {
            1 + curve
                .lines()
                .position(|l| l.starts_with(&format!("{e},")))
                .unwrap()
        };
        let stable_before_k = curve
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse::<usize>().unwrap())
            .filter(|&e| e < k)
            .nth(5)
            .unwrap();
        type Edit<'a> = Box<dyn Fn(&Path) + 'a>;
        let write = |name: &'static str, text: String| -> Edit {
            Box::new(move |d: &Path| std::fs::write(d.join(name), &text).unwrap())
        };
        // (case, how the copy is changed, words of the message)
        let cases: Vec<(&str, Edit, &str)> = vec![
            (
                "another scene's checkpoint",
                write("cp.json", other.clone()),
                "differ at `normal_load`",
            ),
            (
                "no scene record",
                Box::new(|d: &Path| std::fs::remove_file(d.join("scene.json")).unwrap()),
                "holds no scene.json",
            ),
            (
                "events.csv short of the checkpoint",
                write("events.csv", without_lines(&events, k - 10, usize::MAX)),
                "are missing",
            ),
            (
                "a gap in events.csv",
                write("events.csv", without_lines(&events, 50, 52)),
                "follows event",
            ),
            (
                "a stable state missing from curve.csv",
                write(
                    "curve.csv",
                    without_lines(
                        &curve,
                        curve_line(stable_before_k),
                        curve_line(stable_before_k) + 1,
                    ),
                ),
                "curve.csv",
            ),
            (
                "contact_map.csv short of the checkpoint",
                write("contact_map.csv", without_lines(&map, 10, usize::MAX)),
                "are missing",
            ),
            (
                "an edited event count",
                write(
                    "cp.json",
                    checkpoint.replacen(&format!("\"events\":{k},"), "\"events\":7,", 1),
                ),
                "does not match its digest",
            ),
            (
                "an edited site state",
                write(
                    "cp.json",
                    format!(
                        "{}\"Broken\"{}",
                        &checkpoint[..attached],
                        &checkpoint[attached + "\"Attached\"".len()..]
                    ),
                ),
                "does not match its digest",
            ),
            (
                "an unknown key",
                write(
                    "cp.json",
                    checkpoint.replacen("{\"format\"", "{\"extra\":true,\"format\"", 1),
                ),
                "unknown field `extra`",
            ),
            (
                "a flipped byte",
                write("cp.json", {
                    let mut bytes = checkpoint.clone().into_bytes();
                    let at = 3 * bytes.len() / 4;
                    bytes[at] ^= 0x02;
                    String::from_utf8(bytes).unwrap()
                }),
                "cp.json",
            ),
            (
                "a damaged header of curve.csv",
                write("curve.csv", curve.replacen("event,", "evnt,", 1)),
                "line 1 is not the header",
            ),
            (
                "a damaged header of contact_map.csv",
                write("contact_map.csv", map.replacen("event,", "evnt,", 1)),
                "line 1 is not the header",
            ),
        ];
        let work = dir.join("work");
        for (case, edit, words) in cases {
            crate::common::copy_dir(&base, &work);
            edit(&work);
            let before = files(&work, &[]);
            let cp = work.join("cp.json");
            let o = precursors(&["resume", path(&cp), "--out", path(&work)]);
            let text = stderr(&o);
            assert_eq!(o.status.code(), Some(3), "{case}: {text}");
            assert!(
                text.starts_with("error: ") && text.contains(words),
                "{case}: {text}"
            );
            assert!(files(&work, &[]) == before, "{case}: the directory changed");
        }
        // The same resume on the untouched copy continues the finished run (from its
        // complete tables) and ends with the same tables.
        crate::common::copy_dir(&base, &work);
        let cp = work.join("cp.json");
        let o = precursors(&["resume", path(&cp), "--out", path(&work)]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(tables(&work) == tables(&base));
        assert!(TABLE_NAMES
            .iter()
            .all(|n| !work.join(format!("{n}{PARTIAL_SUFFIX}")).exists()));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// SplitMix64: the kill moments' pseudo-random numbers.
    fn splitmix(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// After a kill: every table present under its name is the complete one.
    fn only_complete_tables(out: &Path, reference: &Path, context: &str) {
        for name in TABLE_NAMES {
            if let Ok(text) = std::fs::read(out.join(name)) {
                assert!(
                    text == std::fs::read(reference.join(name)).unwrap(),
                    "{context}: {name} is under its name but not complete"
                );
            }
        }
    }

    #[test]
    fn runs_and_sweeps_killed_at_random_moments_end_as_undisturbed_ones() {
        let seed = std::env::var("PRECURSORS_KILL_SEED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| {
                std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .unwrap()
                    .subsec_nanos()
                    .into()
            });
        let mut state = seed;
        let dir = scratch("cli-kill");
        // A scene of 40 x 10 cells (a few hundred ms to global slip).
        let file = dir.join("scene.json");
        std::fs::write(
            &file,
            SCENE.replace(r#""lx": 0.03, "ly": 0.005"#, r#""lx": 0.04, "ly": 0.01"#),
        )
        .unwrap();
        let reference = dir.join("reference");
        let start = Instant::now();
        let o = precursors(&["run", path(&file), "--out", path(&reference)]);
        let seconds = start.elapsed().as_secs_f64();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let out = dir.join("killed");
        let cp = out.join("cp.json");
        // Three kills at random moments of a run or its continuation, then one left to end;
        // `cut`: kills that left partial tables.
        let mut cut = 0;
        for round in 0..4 {
            let args: Vec<&str> = if cp.is_file() {
                vec!["resume", path(&cp), "--out", path(&out), "--every", "2"]
            } else {
                vec![
                    "run",
                    path(&file),
                    "--out",
                    path(&out),
                    "--checkpoint",
                    path(&cp),
                    "--every",
                    "2",
                ]
            };
            let context = format!("seed {seed}, round {round}, {}", args[0]);
            let mut child = spawn(&args);
            if round < 3 {
                let fraction = (splitmix(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
                std::thread::sleep(Duration::from_secs_f64((0.1 + 0.8 * fraction) * seconds));
                child.kill().unwrap();
                let _ = child.wait();
                only_complete_tables(&out, &reference, &context);
                cut += usize::from(
                    TABLE_NAMES
                        .iter()
                        .any(|n| out.join(format!("{n}{PARTIAL_SUFFIX}")).exists()),
                );
            } else {
                let o = child.wait_with_output().unwrap();
                assert_eq!(o.status.code(), Some(0), "{context}: {}", stderr(&o));
            }
        }
        // A kill fell inside the run (the first one at least: the run with checkpoints is
        // slower than the reference).
        assert!(cut >= 1, "seed {seed}: no kill cut the run");
        for name in TABLE_NAMES {
            assert!(
                std::fs::read(out.join(name)).unwrap()
                    == std::fs::read(reference.join(name)).unwrap(),
                "seed {seed}: {name} differs from the undisturbed run's"
            );
            assert!(!out.join(format!("{name}{PARTIAL_SUFFIX}")).exists());
        }
        // No temporary file of the tables or the scene record is left by the kills.
        for entry in std::fs::read_dir(&out).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            assert!(
                !(name.contains(".csv") || name.contains("scene.json")) || !name.contains(".tmp"),
                "seed {seed}: {name} left behind"
            );
        }
        // A sweep killed at a random moment, run again: the undisturbed sweep's tables.
        let sweep = dir.join("sweep.json");
        std::fs::write(&sweep, sweep_text()).unwrap();
        let (whole, killed) = (dir.join("whole"), dir.join("killed-sweep"));
        let start = Instant::now();
        let o = precursors(&["sweep", path(&sweep), "--out", path(&whole), "--jobs", "2"]);
        let seconds = start.elapsed().as_secs_f64();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let args = ["sweep", path(&sweep), "--out", path(&killed), "--jobs", "2"];
        let mut child = spawn(&args);
        let fraction = (splitmix(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
        std::thread::sleep(Duration::from_secs_f64((0.1 + 0.8 * fraction) * seconds));
        child.kill().unwrap();
        let _ = child.wait();
        for run in std::fs::read_dir(&killed).unwrap() {
            let run = run.unwrap().path();
            if run.is_dir() {
                let name = run.file_name().unwrap().to_owned();
                only_complete_tables(&run, &whole.join(name), &format!("seed {seed}: sweep"));
            }
        }
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        for d in [&whole, &killed] {
            assert_eq!(precursors(&["merge", path(d)]).status.code(), Some(0));
        }
        assert!(
            tables(&killed) == tables(&whole),
            "seed {seed}: the killed sweep's tables differ"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// The one run loop stops where its observer says and continues from there: stopped at
/// every 25th event, each time with the rows so far on disk under their `.partial`
/// names, a run ends with the tables of a run never stopped; and a checkpoint written on
/// the way resumes the scene at its event.
#[test]
fn a_run_stopped_by_its_observer_continues_to_the_tables_of_an_unstopped_one() {
    use std::ops::ControlFlow;
    let scene = scene();
    let whole = scratch("unstopped");
    let mut driver = scene.driver().unwrap();
    RunTables::create(&whole, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let dir = scratch("stopped");
    let checkpoint = scratch("stopped-checkpoint").join("cp.bin");
    let mut driver = scene.driver().unwrap();
    let mut run = RunTables::create(&dir, &driver).unwrap();
    let every = std::num::NonZeroU64::new(10).unwrap();
    let mut stops = 0;
    loop {
        let stopped = run
            .run_until(&mut driver, Some((&checkpoint, every)), |_, d| {
                match d.event_count() % 25 {
                    0 => ControlFlow::Break(d.event_count()),
                    _ => ControlFlow::Continue(()),
                }
            })
            .unwrap();
        let Some(at) = stopped else { break };
        stops += 1;
        // On disk: the events up to the stop.
        let partial = dir.join(format!("events.csv{PARTIAL_SUFFIX}"));
        assert_eq!(
            std::fs::read_to_string(&partial).unwrap().lines().count(),
            1 + at
        );
        assert!(!dir.join("events.csv").exists());
    }
    run.finish().unwrap();
    assert!(stops > 5, "{stops}");
    assert_eq!(tables(&dir), tables(&whole));
    let cp = precursors::Checkpoint::read_from(&checkpoint).unwrap();
    assert_eq!(scene.resume(&cp).unwrap().event_count(), cp.event_count());
    for d in [&dir, &whole, &checkpoint.parent().unwrap().to_path_buf()] {
        std::fs::remove_dir_all(d).unwrap();
    }
}
