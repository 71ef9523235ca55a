//! Sweeps (feature `serde`, docs/sweep-format.md): format errors name the key, derived
//! seeds are stable, complete runs are skipped and cut ones redone, and the tables do not
//! depend on the jobs or the shards. The program's side (feature `cli`) is at the end.

use crate::common::scratch;
use precursors::sweep::{derive_seed, merge, Sweep, SweepError, SweepOptions};
use precursors::Error;
use std::path::Path;

// The documented file-format names and values (docs/cli.md, docs/sweep-format.md).
const DONE_FILE: &str = "done";

/// A tiny base scene: 30 x 5 = 150 cells (a run to global slip: about 10 ms).
const BASE: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 },
    "normal_load": 500.0,
    "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }"#;

fn sweep_text(axes: &str, realizations: usize) -> String {
    format!(r#"{{ "base": {BASE}, "axes": [{axes}], "realizations": {realizations}, "seed": 11 }}"#)
}

/// Two loads, two rod heights, two realizations: 8 runs.
fn small() -> String {
    sweep_text(
        r#"{ "key": "normal_load", "values": [400.0, 600.0] },
           { "key": "drive.height", "values": [0.004, 0.008] }"#,
        2,
    )
}

fn key_of(e: SweepError) -> String {
    match e {
        SweepError::Axis { key, .. } => key,
        other => panic!("expected SweepError::Axis, got {other:?}"),
    }
}

#[test]
fn format_errors_name_the_key() {
    let err = |axes: &str| Sweep::from_json_str(&sweep_text(axes, 1)).unwrap_err();
    // Not a scene key, at the top and inside an object.
    assert_eq!(
        key_of(err(r#"{ "key": "normal_lod", "values": [1.0] }"#)),
        "normal_lod"
    );
    let e = err(r#"{ "key": "block.lxx", "values": [0.02] }"#);
    assert!(e.to_string().contains("`block` has no `lxx`"), "{e}");
    assert_eq!(key_of(e), "block.lxx");
    // Below a number.
    assert_eq!(
        key_of(err(r#"{ "key": "normal_load.x", "values": [1.0] }"#)),
        "normal_load.x"
    );
    // A value of the wrong type, and values the scene refuses.
    let e = err(r#"{ "key": "normal_load", "values": [300.0, "heavy"] }"#);
    assert!(e.to_string().contains("\"heavy\""), "{e}");
    assert_eq!(key_of(e), "normal_load");
    assert_eq!(
        key_of(err(r#"{ "key": "block.lx", "values": [-0.03] }"#)),
        "block.lx"
    );
    assert_eq!(
        key_of(err(r#"{ "key": "normal_load", "values": [0.0] }"#)),
        "normal_load"
    );
    assert_eq!(
        key_of(err(r#"{ "key": "drive.height", "values": [0.5] }"#)),
        "drive.height"
    );
    // A cell size that does not divide the block.
    assert_eq!(
        key_of(err(r#"{ "key": "cells.dx", "values": [0.0007] }"#)),
        "cells.dx"
    );
    // No values, twice the same key, the seed (derived by the sweep).
    assert_eq!(
        key_of(err(r#"{ "key": "normal_load", "values": [] }"#)),
        "normal_load"
    );
    assert_eq!(
        key_of(err(
            r#"{ "key": "normal_load", "values": [1.0] }, { "key": "normal_load", "values": [2.0] }"#
        )),
        "normal_load"
    );
    // Keys that overlap (an object and a key inside it): the later one would win and
    // the tables would label points with values that never ran (issue 41).
    let block = r#"{ "lx": 0.03, "ly": 0.005, "lz": 0.02 }"#;
    let e = err(&format!(
        r#"{{ "key": "block.lx", "values": [0.03, 0.04] }}, {{ "key": "block", "values": [{block}] }}"#
    ));
    assert!(e.to_string().contains("overlaps `block.lx`"), "{e}");
    assert_eq!(key_of(e), "block");
    let drive = r#"{ "kind": "rod", "height": 0.004, "half_width": 0.001 }"#;
    let e = err(&format!(
        r#"{{ "keys": ["drive.height", "drive"], "values": [[0.004, {drive}]] }}"#
    ));
    assert_eq!(key_of(e), "drive");
    // Keys that only share a prefix of their names do not overlap.
    Sweep::from_json_str(&sweep_text(
        r#"{ "key": "drive.height", "values": [0.004] }, { "key": "drive.half_width", "values": [0.001] }"#,
        1,
    ))
    .unwrap();
    assert_eq!(
        key_of(err(r#"{ "key": "heights.seed", "values": [1, 2] }"#)),
        "heights.seed"
    );
    // A combination of valid values that is not valid: named by the axes' keys.
    let e = err(r#"{ "key": "block.lz", "values": [0.02, 0.005] },
                   { "key": "drive.height", "values": [0.004, 0.008] }"#);
    assert_eq!(key_of(e), "block.lz, drive.height");
    // Outside the axes: the file itself, and the counts.
    for text in [
        r#"{ "base": {}, "axis": [] }"#.to_string(),
        r#"{ "base": { "normal_lod": 3.0 } }"#.to_string(),
        "{ not json".to_string(),
    ] {
        let e = Sweep::from_json_str(&text).unwrap_err();
        assert!(matches!(e, SweepError::File { .. }), "{text}: {e:?}");
    }
    let e = Sweep::from_json_str(&sweep_text("", 0)).unwrap_err();
    assert!(
        matches!(
            e,
            SweepError::Core(Error::InvalidCount {
                name: "realizations",
                ..
            })
        ),
        "{e:?}"
    );
    let sweep = Sweep::from_json_str(&small()).unwrap();
    assert!(matches!(
        sweep.shard(2, 2),
        Err(SweepError::Core(Error::InvalidCount { .. }))
    ));
    assert!(matches!(
        sweep.shard(0, 0),
        Err(SweepError::Core(Error::InvalidCount { .. }))
    ));
}

#[test]
fn linked_axes_move_their_keys_together() {
    // Two keys on one axis: 2 points (not 2 x 2), one coordinate, one value per key.
    let linked = r#"{ "keys": ["block.lz", "drive.height"],
                      "values": [[0.02, 0.004], [0.03, 0.012]] }"#;
    let sweep = Sweep::from_json_str(&sweep_text(linked, 2)).unwrap();
    assert_eq!((sweep.points(), sweep.runs().len()), (2, 4));
    assert_eq!(sweep.keys(), ["block.lz", "drive.height"]);
    let run = &sweep.runs()[2];
    assert_eq!((run.point(), run.coordinates().to_vec()), (1, vec![1]));
    assert_eq!(run.seed(), derive_seed(11, &[1], 0));
    assert_eq!(
        run.values(),
        [
            ("block.lz".to_string(), "0.03".to_string()),
            ("drive.height".to_string(), "0.012".to_string())
        ]
    );
    let json = run.scene().to_json().unwrap();
    assert!(
        json.contains("\"lz\": 0.03") && json.contains("\"height\": 0.012"),
        "{json}"
    );
    // With a plain axis after it: the linked axis is the slower one.
    let both = format!(r#"{linked}, {{ "key": "normal_load", "values": [400.0, 600.0] }}"#);
    let sweep = Sweep::from_json_str(&sweep_text(&both, 1)).unwrap();
    assert_eq!(sweep.points(), 4);
    assert_eq!(sweep.keys(), ["block.lz", "drive.height", "normal_load"]);
    assert_eq!(sweep.runs()[1].coordinates(), vec![0, 1]);
    // A plain sweep's copy does not mention `keys` (directories of older sweeps still
    // match it).
    assert!(!Sweep::from_json_str(&small())
        .unwrap()
        .to_json()
        .unwrap()
        .contains("keys"));

    let err = |axes: &str| Sweep::from_json_str(&sweep_text(axes, 1)).unwrap_err();
    // A step that is not one value per key; a step the scene refuses (the rod above a
    // 20 mm block): named by the axis's keys.
    for bad in [
        r#"{ "keys": ["block.lz", "drive.height"], "values": [[0.02, 0.004], [0.03]] }"#,
        r#"{ "keys": ["block.lz", "drive.height"], "values": [0.02] }"#,
        r#"{ "keys": ["block.lz", "drive.height"], "values": [[0.02, 0.03]] }"#,
    ] {
        let e = err(bad);
        assert!(e.to_string().contains("(#"), "{e}");
        assert_eq!(key_of(e), "block.lz, drive.height", "{bad}");
    }
    // A key twice, within the axis or across axes; the derived seed.
    assert_eq!(
        key_of(err(
            r#"{ "keys": ["normal_load", "normal_load"], "values": [[1.0, 2.0]] }"#
        )),
        "normal_load"
    );
    assert_eq!(
        key_of(err(&format!(
            r#"{linked}, {{ "key": "drive.height", "values": [0.004] }}"#
        ))),
        "drive.height"
    );
    assert_eq!(
        key_of(err(
            r#"{ "keys": ["normal_load", "heights.seed"], "values": [[1.0, 2]] }"#
        )),
        "heights.seed"
    );
    // Neither or both of `key` and `keys`, or no keys: the file's shape.
    for bad in [
        r#"{ "values": [1.0] }"#,
        r#"{ "key": "normal_load", "keys": ["normal_load"], "values": [[1.0]] }"#,
        r#"{ "keys": [], "values": [] }"#,
    ] {
        let e = err(bad);
        assert!(
            matches!(e, SweepError::File { .. }) && crate::common::chain(&e).contains("axis #0"),
            "{bad}: {e:?}"
        );
    }
}

#[test]
fn a_linked_sweep_merges_with_a_column_per_key() {
    let sweep = Sweep::from_json_str(&sweep_text(
        r#"{ "keys": ["block.lz", "drive.height"], "values": [[0.02, 0.004], [0.03, 0.012]] }"#,
        1,
    ))
    .unwrap();
    let dir = scratch("linked");
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    let summary = merge(&dir).unwrap();
    assert_eq!((summary.points, summary.runs_merged), (2, 2));
    let curves = std::fs::read_to_string(dir.join("curves.csv")).unwrap();
    assert!(
        curves.starts_with("point,block.lz,drive.height,force_over_mu_FN,"),
        "{curves}"
    );
    assert!(curves
        .lines()
        .nth(20)
        .unwrap()
        .starts_with("1,0.03,0.012,0.05,"));
    let meta = std::fs::read_to_string(dir.join("p0001-r0000").join("meta.json")).unwrap();
    assert!(meta.contains("\"drive.height\": 0.012"), "{meta}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A sweep over the contact rule: `runs.csv` names each run's rule (read from its scene
/// record; the axis column gives the value as the sweep file wrote it), and so does its
/// `meta.json`. A run whose recorded scene is the paper's could not pass for an anchored
/// one: the rule columns differ.
#[test]
fn runs_csv_names_the_contact_rule() {
    let sweep = Sweep::from_json_str(&sweep_text(
        r#"{ "key": "contact.rule", "values": ["paper", "anchored"] }"#,
        1,
    ))
    .unwrap();
    let dir = scratch("contact-rule");
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    merge(&dir).unwrap();
    let runs = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    let mut lines = runs.lines();
    assert_eq!(
        lines.next().unwrap(),
        "run,point,realization,seed,contact.rule,stable_states,slip_over_mu_FN,contact_rule"
    );
    for (line, rule) in lines.zip(["paper", "anchored"]) {
        // The axis' cell: the JSON text `"paper"`, quoted as CSV.
        assert!(line.contains(&format!(",\"\"\"{rule}\"\"\",")), "{line}");
        assert!(line.ends_with(&format!(",{rule}")), "{line}");
    }
    let meta = std::fs::read_to_string(dir.join("p0001-r0000").join("meta.json")).unwrap();
    assert!(meta.contains("\"contact_rule\": \"anchored\""), "{meta}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn seeds_are_derived_stably_from_the_base_seed_and_the_coordinates() {
    // Pinned values: changing the derivation changes every sweep's heights.
    assert_eq!(derive_seed(11, &[0], 0), 8404586307421351767);
    assert_eq!(derive_seed(11, &[0], 1), 6972708929841935523);
    assert_eq!(derive_seed(11, &[1], 0), 17092487410889562692);
    assert_eq!(derive_seed(0, &[], 0), 12035550249420947055);
    assert_eq!(derive_seed(1, &[2, 3], 4), 10281589820224458653);
    let sweep = Sweep::from_json_str(&small()).unwrap();
    assert_eq!(sweep.runs().len(), 8);
    let mut seeds = Vec::new();
    for run in sweep.runs() {
        assert_eq!(run.index(), run.point() * 2 + run.realization());
        assert_eq!(
            run.seed(),
            derive_seed(11, run.coordinates(), run.realization())
        );
        // The scene draws its heights from it.
        let json = run.scene().to_json().unwrap();
        assert!(
            json.contains(&format!("\"seed\": {}", run.seed())),
            "{json}"
        );
        seeds.push(run.seed());
    }
    // The last axis is the fastest; every run has its own seed.
    assert_eq!(sweep.runs()[2].coordinates(), vec![0, 1]);
    assert_eq!(sweep.runs()[4].coordinates(), vec![1, 0]);
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), 8);
}

#[test]
fn the_documented_sweep_is_valid() {
    let doc = include_str!("../docs/sweep-format.md");
    let block = doc
        .split("```json\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .unwrap();
    let sweep = Sweep::from_json_str(block).unwrap();
    assert_eq!((sweep.points(), sweep.realizations()), (6, 10));
    assert_eq!(sweep.keys(), ["normal_load", "drive.height"]);
    assert_eq!(sweep.runs().len(), 60);
    // The linked axis's example.
    let block = doc
        .split("```json\n")
        .nth(2)
        .and_then(|rest| rest.split("```").next())
        .unwrap();
    let sweep = Sweep::from_json_str(block).unwrap();
    assert_eq!((sweep.points(), sweep.runs().len()), (4, 40));
    assert_eq!(sweep.keys(), ["block.lz", "drive.height"]);
}

/// Every file of the runs and the merge in `dir`, but the timings (`meta.json`).
fn tables(dir: &Path) -> Vec<(String, String)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "csv") {
                let name = path.strip_prefix(dir).unwrap().display().to_string();
                files.push((name, std::fs::read_to_string(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

#[test]
fn complete_runs_are_skipped_and_a_cut_one_is_redone() {
    let sweep = Sweep::from_json_str(&small()).unwrap();
    let dir = scratch("restart");
    let first = sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    assert_eq!((first.runs, first.completed, first.skipped), (8, 8, 0));
    merge(&dir).unwrap();
    let before = tables(&dir);
    // A run killed before its marker: the marker missing, a table cut, a stray file.
    let cut = dir.join(sweep.runs()[5].dir_name());
    std::fs::remove_file(cut.join(DONE_FILE)).unwrap();
    let curve = std::fs::read_to_string(cut.join("curve.csv")).unwrap();
    std::fs::write(cut.join("curve.csv"), &curve[..curve.len() / 2]).unwrap();
    std::fs::write(cut.join("stray"), "x").unwrap();
    // A complete run is not touched: a file put there survives.
    let complete = dir.join(sweep.runs()[2].dir_name());
    std::fs::write(complete.join("stray"), "x").unwrap();
    let reports = std::sync::Mutex::new(Vec::new());
    let second = sweep
        .execute(&dir, &SweepOptions::new().with_jobs(2).unwrap(), |r| {
            reports.lock().unwrap().push((r.index, r.skipped))
        })
        .unwrap();
    assert_eq!((second.runs, second.completed, second.skipped), (8, 1, 7));
    let mut reports = reports.into_inner().unwrap();
    reports.sort_unstable();
    assert!(
        reports.iter().all(|&(i, skipped)| skipped == (i != 5)),
        "{reports:?}"
    );
    assert!(!cut.join("stray").exists() && cut.join(DONE_FILE).is_file());
    assert!(complete.join("stray").exists());
    merge(&dir).unwrap();
    assert_eq!(tables(&dir), before);
    // The directory holds this sweep: another one is refused there.
    let other = Sweep::from_json_str(&sweep_text(
        r#"{ "key": "normal_load", "values": [450.0] }"#,
        1,
    ))
    .unwrap();
    let e = other
        .execute(&dir, &SweepOptions::new(), |_| {})
        .unwrap_err();
    assert!(matches!(e, SweepError::Directory { .. }), "{e:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tables_do_not_depend_on_jobs_or_shards() {
    let sweep = Sweep::from_json_str(&small()).unwrap();
    let one = scratch("jobs1");
    let two = scratch("jobs2");
    let sharded = scratch("shards");
    sweep
        .execute(&one, &SweepOptions::new().with_jobs(1).unwrap(), |_| {})
        .unwrap();
    sweep
        .execute(&two, &SweepOptions::new().with_jobs(2).unwrap(), |_| {})
        .unwrap();
    let a = sweep
        .execute(
            &sharded,
            &SweepOptions::new()
                .with_shard(0, 2)
                .unwrap()
                .with_jobs(2)
                .unwrap(),
            |_| {},
        )
        .unwrap();
    // Half the sweep: the merge counts the other half missing.
    assert_eq!(merge(&sharded).unwrap().runs_missing, 4);
    let b = sweep
        .execute(
            &sharded,
            &SweepOptions::new().with_shard(1, 2).unwrap(),
            |_| {},
        )
        .unwrap();
    assert_eq!((a.runs, b.runs, a.completed + b.completed), (4, 4, 8));
    for dir in [&one, &two, &sharded] {
        let summary = merge(dir).unwrap();
        assert_eq!(
            (summary.points, summary.runs_merged, summary.runs_missing),
            (4, 8, 0)
        );
    }
    let reference = tables(&one);
    // 8 runs x 3 tables (events, curve, contact_map) + 4 merged files.
    assert_eq!(reference.len(), 44); // 8 runs x (3 tables + 2 derived) + 4 merged files
    assert_eq!(tables(&two), reference);
    assert_eq!(tables(&sharded), reference);
    // The merge has the axes as columns and every grid load per point.
    let curves = &reference.iter().find(|(n, _)| n == "curves.csv").unwrap().1;
    assert!(curves.starts_with("point,normal_load,drive.height,force_over_mu_FN,runs,"));
    assert_eq!(curves.lines().count(), 1 + 4 * 19);
    for dir in [one, two, sharded] {
        std::fs::remove_dir_all(dir).unwrap();
    }
}

#[test]
fn merged_bands_are_student_t() {
    // One point, three realizations: the band is mean ± t(2)·s/√3 of the runs' values.
    let sweep = Sweep::from_json_str(&sweep_text("", 3)).unwrap();
    let dir = scratch("bands");
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    merge(&dir).unwrap();
    let slips: Vec<f64> = sweep
        .runs()
        .iter()
        .map(|run| {
            let curve =
                std::fs::read_to_string(dir.join(run.dir_name()).join("curve.csv")).unwrap();
            let last = curve.lines().last().unwrap();
            last.split(',').nth(2).unwrap().parse().unwrap()
        })
        .collect();
    let mean = slips.iter().sum::<f64>() / 3.0;
    let s = (slips.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
    let row: Vec<f64> = std::fs::read_to_string(dir.join("slip.csv"))
        .unwrap()
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .skip(7)
        .map(|x| x.parse().unwrap())
        .collect();
    let half = 4.303 * s / 3f64.sqrt();
    assert!(half > 0.0);
    for (got, want) in row.iter().zip([mean, mean - half, mean + half]) {
        assert!((got - want).abs() < 1e-11, "{row:?} vs {mean} ± {half}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The program (`src/bin/precursors.rs`).
#[cfg(feature = "cli")]
mod cli {
    use super::*;

    use crate::common::program::{command, path, precursors};

    /// The program with `vars` as its only SLURM array variables.
    fn precursors_in(vars: &[(&str, &str)], args: &[&str]) -> std::process::Output {
        command(args).envs(vars.iter().copied()).output().unwrap()
    }

    #[test]
    fn help_exits_0_and_lists_the_exit_codes() {
        let out = precursors(&["--help"]);
        assert_eq!(out.status.code(), Some(0));
        let text = String::from_utf8(out.stdout).unwrap();
        for word in ["run", "resume", "info", "sweep", "merge", "Exit codes"] {
            assert!(text.contains(word), "{text}");
        }
        assert_eq!(precursors(&["sweep", "--help"]).status.code(), Some(0));
        assert_eq!(precursors(&["frobnicate"]).status.code(), Some(2));
    }

    #[test]
    fn jobs_shards_and_slurm_give_the_same_tables() {
        let dir = scratch("cli");
        let file = dir.join("sweep.json");
        std::fs::write(&file, small()).unwrap();
        let (one, two, shards) = (dir.join("one"), dir.join("two"), dir.join("shards"));
        for (out, jobs) in [(&one, "1"), (&two, "2")] {
            let o = precursors(&["sweep", path(&file), "--out", path(out), "--jobs", jobs]);
            assert_eq!(
                o.status.code(),
                Some(0),
                "{}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        // Shards from SLURM's variables, as SLURM 22.05 sets them in the tasks of
        // `sbatch --array=1-2` (the minimum is subtracted) and `--array=10-16:2` (ids 10, 12,
        // 14, 16: divided by the step), and as older SLURM releases set them (no COUNT: N
        // from MIN and MAX). Seen on a real SLURM: docs/cluster.md, scripts/slurm-smoke.sh.
        // (directory, task ids, then MIN, MAX, STEP and COUNT as each task sees them)
        type Layout<'a> = (&'a str, &'a [&'a str], [&'a str; 3], Option<&'a str>);
        let layouts: [Layout; 3] = [
            ("shards", &["1", "2"], ["1", "2", "1"], Some("2")),
            (
                "step",
                &["10", "12", "14", "16"],
                ["10", "16", "2"],
                Some("4"),
            ),
            ("nocount", &["3", "4"], ["3", "4", "1"], None),
        ];
        for (name, ids, [min, max, step], count) in layouts {
            let out = dir.join(name);
            let n = ids.len();
            for (k, id) in ids.iter().enumerate() {
                let mut vars = vec![
                    ("SLURM_ARRAY_TASK_ID", *id),
                    ("SLURM_ARRAY_TASK_MIN", min),
                    ("SLURM_ARRAY_TASK_MAX", max),
                    ("SLURM_ARRAY_TASK_STEP", step),
                ];
                vars.extend(count.map(|c| ("SLURM_ARRAY_TASK_COUNT", c)));
                let o = precursors_in(
                    &vars,
                    &["sweep", path(&file), "--out", path(&out), "--jobs", "1"],
                );
                let text = String::from_utf8_lossy(&o.stderr).to_string();
                assert_eq!(o.status.code(), Some(0), "{name} {id}: {text}");
                let share = 8 / n;
                assert!(
                    text.contains(&format!("shard {k}/{n}: {share} runs")),
                    "{name} {id}: {text}"
                );
            }
        }
        let (step, nocount) = (dir.join("step"), dir.join("nocount"));
        for out in [&one, &two, &shards, &step, &nocount] {
            let o = precursors(&["merge", path(out)]);
            assert_eq!(
                o.status.code(),
                Some(0),
                "{}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let reference = tables(&one);
        assert_eq!(reference.len(), 44); // 8 runs x (3 tables + 2 derived) + 4 merged files
        assert_eq!(tables(&two), reference);
        assert_eq!(tables(&shards), reference);
        assert_eq!(tables(&step), reference);
        assert_eq!(tables(&nocount), reference);
        // A missing run: merge writes the rest and exits 5.
        std::fs::remove_file(shards.join("p0000-r0001").join(DONE_FILE)).unwrap();
        assert_eq!(precursors(&["merge", path(&shards)]).status.code(), Some(5));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_name_the_key_and_have_their_exit_codes() {
        let dir = scratch("cli-errors");
        let file = dir.join("bad.json");
        std::fs::write(
            &file,
            sweep_text(r#"{ "key": "block.lxx", "values": [0.02] }"#, 1),
        )
        .unwrap();
        let o = precursors(&["sweep", path(&file), "--out", path(&dir.join("o"))]);
        assert_eq!(o.status.code(), Some(3));
        let text = String::from_utf8_lossy(&o.stderr);
        assert!(text.starts_with("error: sweep axis `block.lxx`"), "{text}");
        let missing = dir.join("missing.json");
        let o = precursors(&["run", path(&missing), "--out", path(&dir.join("o"))]);
        assert_eq!(o.status.code(), Some(4));
        assert!(String::from_utf8_lossy(&o.stderr).contains("missing.json"));
        let o = precursors(&["sweep", path(&file), "--out", "o", "--shard", "2/2"]);
        assert_eq!(o.status.code(), Some(2));
        // info: cells and estimates of a scene.
        let scene = dir.join("scene.json");
        std::fs::write(&scene, BASE).unwrap();
        let o = precursors(&["info", path(&scene)]);
        assert_eq!(o.status.code(), Some(0));
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            text.contains("30 x 5 = 150") && text.contains("dense (auto)"),
            "{text}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn plot_draws_a_sweep_merged_first_and_a_run() {
        let dir = scratch("cli-plot");
        let file = dir.join("study.json");
        std::fs::write(&file, small()).unwrap();
        let out = dir.join("o");
        let o = precursors(&["sweep", path(&file), "--out", path(&out), "-q"]);
        assert_eq!(o.status.code(), Some(0));
        // No merge first: plot merges.
        let o = precursors(&["plot", path(&out), "--format", "both"]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        for name in [
            "curves.csv",
            "precursor_length.png",
            "precursor_length.svg",
            "contact_area.png",
        ] {
            assert!(out.join(name).is_file(), "{name}");
        }
        // One curve per point, named by the axes' values in the user's units and its runs
        // (`F_N` typeset: F, then N as a text of its own).
        let svg = std::fs::read_to_string(out.join("precursor_length.svg")).unwrap();
        for label in [
            ">\n= 400 N, h = 4 mm (2 runs)",
            ">\n= 600 N, h = 8 mm (2 runs)",
        ] {
            assert!(svg.contains(">\nN\n</text>"), "{label}");
            assert!(svg.contains(label), "{label}");
        }
        assert!(!svg.contains("F_N"));
        // The area figure: the median without an interval (2 runs are too few), said once
        // in a note, not in each entry.
        let svg = std::fs::read_to_string(out.join("contact_area.svg")).unwrap();
        assert_eq!(
            svg.matches("below 6 runs: the median without an interval")
                .count(),
            1
        );
        assert!(!svg.contains("(2 runs), no interval"));
        // A run of the sweep is a run directory: its three figures.
        let run = out.join("p0000-r0000");
        let o = precursors(&["plot", path(&run)]);
        assert_eq!(o.status.code(), Some(0));
        assert!(run.join("contact_map.png").is_file());
        // A run not complete: figures of the others, exit code 5.
        std::fs::remove_file(out.join("p0001-r0001").join(DONE_FILE)).unwrap();
        let o = precursors(&["plot", path(&out), "--format", "svg"]);
        assert_eq!(o.status.code(), Some(5));
        let svg = std::fs::read_to_string(out.join("precursor_length.svg")).unwrap();
        assert!(svg.contains("h = 8 mm (1 runs)"));
        // Neither a run nor a sweep: invalid input.
        let o = precursors(&["plot", path(&dir)]);
        assert_eq!(o.status.code(), Some(3));
        assert!(String::from_utf8_lossy(&o.stderr).contains("neither a sweep directory"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn slurm_variables_that_give_no_shard_are_refused() {
        let dir = scratch("cli-slurm");
        let file = dir.join("sweep.json");
        std::fs::write(&file, small()).unwrap();
        let out = dir.join("o");
        // (variables, words of the message); exit code 2 and nothing written for each.
        let cases: [(&[(&str, &str)], &str); 4] = [
            // `sbatch --array=1,3,8` on SLURM 22.05, task 8: ids not evenly spaced.
            (
                &[
                    ("SLURM_ARRAY_TASK_ID", "8"),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                    ("SLURM_ARRAY_TASK_MIN", "1"),
                    ("SLURM_ARRAY_TASK_MAX", "8"),
                    ("SLURM_ARRAY_TASK_STEP", "1"),
                ],
                "not evenly spaced",
            ),
            // An id alone: every task would run the whole sweep.
            (
                &[("SLURM_ARRAY_TASK_ID", "3")],
                "neither SLURM_ARRAY_TASK_COUNT nor SLURM_ARRAY_TASK_MAX",
            ),
            // An id off the step.
            (
                &[
                    ("SLURM_ARRAY_TASK_ID", "13"),
                    ("SLURM_ARRAY_TASK_COUNT", "4"),
                    ("SLURM_ARRAY_TASK_MIN", "10"),
                    ("SLURM_ARRAY_TASK_MAX", "16"),
                    ("SLURM_ARRAY_TASK_STEP", "2"),
                ],
                "plus a multiple of SLURM_ARRAY_TASK_STEP=2",
            ),
            // An id past the count (MIN missing: taken as 0).
            (
                &[
                    ("SLURM_ARRAY_TASK_ID", "4"),
                    ("SLURM_ARRAY_TASK_COUNT", "4"),
                ],
                "need 0 <= K < N",
            ),
        ];
        for (vars, words) in cases {
            let o = precursors_in(vars, &["sweep", path(&file), "--out", path(&out)]);
            let text = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{vars:?}: {text}");
            assert!(
                text.starts_with("error: ") && text.contains(words),
                "{vars:?}: {text}"
            );
            assert!(!out.exists(), "{vars:?}: wrote {}", out.display());
        }
        // An explicit --shard overrides the variables.
        let o = precursors_in(
            cases[0].0,
            &["sweep", path(&file), "--out", path(&out), "--shard", "1/4"],
        );
        let text = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{text}");
        assert!(text.contains("shard 1/4: 2 runs"), "{text}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn a_stopped_sweep_marks_only_complete_runs_and_ends_as_an_uninterrupted_one() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::{Duration, Instant};
    // Runs of 60 x 6 cells: hundreds of events each, long enough to stop one mid-way.
    let sweep = Sweep::from_json_str(
        r#"{ "base": { "block": { "lx": 0.06, "ly": 0.006, "lz": 0.03 }, "normal_load": 800.0 },
             "axes": [ { "key": "normal_load", "values": [700.0, 800.0, 900.0] } ],
             "seed": 3 }"#,
    )
    .unwrap();
    let whole = scratch("unstopped");
    sweep.execute(&whole, &SweepOptions::new(), |_| {}).unwrap();
    let dir = scratch("stopped");
    let (stop, ended) = (AtomicBool::new(false), AtomicBool::new(false));
    // Raised once the second run has written a few events (as Ctrl-C would be).
    let second = dir
        .join(sweep.runs()[1].dir_name())
        .join("events.csv.partial");
    let summary = std::thread::scope(|scope| {
        scope.spawn(|| {
            let start = Instant::now();
            while !ended.load(Ordering::SeqCst) && start.elapsed() < Duration::from_secs(60) {
                if std::fs::read_to_string(&second).is_ok_and(|t| t.lines().count() > 5) {
                    stop.store(true, Ordering::SeqCst);
                    return;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
        });
        let summary = sweep.execute_until(&dir, &SweepOptions::new(), |_| {}, &stop);
        ended.store(true, Ordering::SeqCst);
        summary.unwrap()
    });
    assert_eq!(
        (summary.runs, summary.completed, summary.stopped),
        (3, 1, 1)
    );
    // Only the complete run is marked done; the stopped one is left partial, the third
    // never started.
    let run = |k: usize| dir.join(sweep.runs()[k].dir_name());
    assert!(run(0).join(DONE_FILE).is_file());
    assert!(!run(1).join(DONE_FILE).exists() && second.is_file());
    assert!(!run(2).join(DONE_FILE).exists());
    // Executed again: the stopped run redone, the sweep as an uninterrupted one.
    let again = sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    assert_eq!((again.completed, again.skipped, again.stopped), (2, 1, 0));
    merge(&dir).unwrap();
    merge(&whole).unwrap();
    assert_eq!(tables(&dir), tables(&whole));
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&whole).unwrap();
}

/// An independent restatement of docs/sweep-format.md's derivation of a reseeded map's
/// seed: `splitmix64(s ^ splitmix64(0x6d61707300000000 + m))`, `s` the run's heights'
/// seed, `m` the map's place in (friction_coefficient, c_x, c_z).
fn documented_map_seed(s: u64, m: u64) -> u64 {
    fn splitmix64(x: u64) -> u64 {
        let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    splitmix64(s ^ splitmix64(0x6d61_7073_0000_0000 + m))
}

const MAPPED_BASE: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 },
    "normal_load": 500.0,
    "drive": { "kind": "top" },
    "maps": {
      "friction_coefficient": { "kind": "gaussian_surface", "correlation_length": 0.004,
                                "mean": 0.5, "std_dev": 0.1, "seed": 3 },
      "c_z": { "kind": "gaussian_surface", "correlation_length": 0.004,
               "mean": 1.65e8, "std_dev": 2e7, "seed": 3 } } }"#;

fn friction_map_of(scene: &precursors::SceneBuilder) -> Vec<f64> {
    let scene = scene.clone().build().unwrap();
    scene.interface().friction_map().unwrap().to_vec()
}

#[test]
fn realizations_reseed_the_maps_named_in_reseed_maps() {
    let text = format!(
        r#"{{ "base": {MAPPED_BASE}, "axes": [], "realizations": 3, "seed": 11,
             "reseed_maps": ["friction_coefficient"] }}"#
    );
    let sweep = Sweep::from_json_str(&text).unwrap();
    let maps: Vec<Vec<f64>> = sweep
        .runs()
        .iter()
        .map(|r| friction_map_of(r.scene()))
        .collect();
    assert_ne!(maps[0], maps[1]);
    assert_ne!(maps[1], maps[2]);
    for run in sweep.runs() {
        // The documented seed, and a map other than the heights' seed would draw.
        let expected = documented_map_seed(run.seed(), 0);
        let scene = |seed: u64| {
            let map = format!(
                r#""maps": {{ "friction_coefficient": {{ "kind": "gaussian_surface",
                    "correlation_length": 0.004, "mean": 0.5, "std_dev": 0.1,
                    "seed": {seed} }} }}"#
            );
            let text = MAPPED_BASE.split(r#""maps""#).next().unwrap().to_string() + &map + "}";
            precursors::SceneBuilder::from_json_str(&text).unwrap()
        };
        let map = friction_map_of(run.scene());
        assert_eq!(map, friction_map_of(&scene(expected)));
        assert_ne!(map, friction_map_of(&scene(run.seed())));
    }
    // A map not named keeps the base's seed in every run.
    let c_z: Vec<Vec<f64>> = sweep
        .runs()
        .iter()
        .map(|r| {
            r.scene()
                .clone()
                .build()
                .unwrap()
                .interface()
                .c_z_map()
                .unwrap()
                .to_vec()
        })
        .collect();
    assert_eq!(c_z[0], c_z[1]);
    // Without the key, the realizations share the map (as 1.x sweeps do).
    let plain =
        format!(r#"{{ "base": {MAPPED_BASE}, "axes": [], "realizations": 2, "seed": 11 }}"#);
    let plain = Sweep::from_json_str(&plain).unwrap();
    assert_eq!(
        friction_map_of(plain.runs()[0].scene()),
        friction_map_of(plain.runs()[1].scene())
    );
    assert!(!plain.to_json().unwrap().contains("reseed_maps"));
    assert!(sweep.to_json().unwrap().contains("reseed_maps"));
}

#[test]
fn reseed_maps_refuses_what_it_cannot_reseed() {
    let err = |reseed: &str, axes: &str| {
        let text = format!(
            r#"{{ "base": {MAPPED_BASE}, "axes": [{axes}], "realizations": 2, "seed": 11,
                 "reseed_maps": {reseed} }}"#
        );
        crate::common::chain(&Sweep::from_json_str(&text).unwrap_err())
    };
    let e = err(r#"["mu"]"#, "");
    assert!(e.contains("`mu` is not a map"), "{e}");
    let e = err(r#"["c_z", "c_z"]"#, "");
    assert!(e.contains("named twice"), "{e}");
    let e = err(r#"["c_x"]"#, "");
    assert!(e.contains("`c_x` is not in the base scene"), "{e}");
    let e = err(
        r#"["friction_coefficient"]"#,
        r#"{ "key": "maps.friction_coefficient.seed", "values": [1, 2] }"#,
    );
    assert!(e.contains("axis `maps.friction_coefficient.seed`"), "{e}");
    // A map of values has no seed.
    let values = vec!["0.5"; 150].join(", ");
    let text = format!(
        r#"{{ "base": {{ "block": {{ "lx": 0.03, "ly": 0.005, "lz": 0.02 }},
             "maps": {{ "friction_coefficient": {{ "kind": "values", "values": [{values}] }} }} }},
             "realizations": 1, "reseed_maps": ["friction_coefficient"] }}"#
    );
    let e = crate::common::chain(&Sweep::from_json_str(&text).unwrap_err());
    assert!(e.contains("is a `values` map"), "{e}");
}
