//! The readers check what they read, as a class (docs/cli.md, "Guarantees"): `merge`,
//! `plot`, `movie` and `resume` refuse a damaged table with code 3, naming the file, and
//! leave the directory as it was. Each damage is made by hand on a copy of a sweep that
//! ran undisturbed (its tables are the reference: the undamaged copy merges, plots and
//! draws its movies with code 0): truncated, shuffled, duplicated rows, the last state or
//! global slip dropped, values out of their physical bounds or not finite, another
//! point's `scene.json`, run directories swapped, `sweep.json` edited.

use crate::common::program::{contents, path, precursors, stderr};
use crate::common::{copy_dir, scratch};
use std::path::{Path, PathBuf};

/// Two loads, two realizations of a tiny scene (30 x 5 cells) recording its fields.
const SWEEP: &str = r#"{ "base": { "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 }, "normal_load": 500.0,
    "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 },
    "fields": { "every": 1, "planes": [0.005, 0.01] } },
    "axes": [ { "key": "normal_load", "values": [400.0, 600.0] } ],
    "realizations": 2, "seed": 5 }"#;

/// The run directory damaged in every case.
const RUN: &str = "p0000-r0000";

/// The lines of a table (header first).
fn lines(file: &Path) -> Vec<String> {
    std::fs::read_to_string(file)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

fn write_lines(file: &Path, lines: &[String]) {
    std::fs::write(
        file,
        lines.iter().map(|l| format!("{l}\n")).collect::<String>(),
    )
    .unwrap();
}

/// Sets cell `column` (by header name) of data row `row` (0-based, after the header).
fn set_cell(file: &Path, row: usize, column: &str, value: &str) {
    let mut l = lines(file);
    let k = l[0].split(',').position(|c| c == column).unwrap();
    let mut cells: Vec<String> = l[1 + row].split(',').map(str::to_string).collect();
    cells[k] = value.to_string();
    l[1 + row] = cells.join(",");
    write_lines(file, &l);
}

/// The rows of `fields.csv` per recorded state: 5 rows of area, 2 planes.
const PER_STATE: usize = 5 + 2;

type Damage = Box<dyn Fn(&Path)>;

/// (name, damage to the sweep directory, the file the message must name).
fn damages() -> Vec<(&'static str, Damage, &'static str)> {
    let run = |d: &Path, name: &str| d.join(RUN).join(name);
    vec![
        (
            "curve.csv cut short by a row",
            Box::new(move |d: &Path| {
                let mut l = lines(&run(d, "curve.csv"));
                l.pop();
                write_lines(&run(d, "curve.csv"), &l);
            }),
            "curve.csv",
        ),
        (
            "curve.csv with its header only",
            Box::new(move |d: &Path| {
                let l = lines(&run(d, "curve.csv"));
                write_lines(&run(d, "curve.csv"), &l[..1]);
            }),
            "curve.csv",
        ),
        (
            "curve.csv cut inside its last row",
            Box::new(move |d: &Path| {
                let text = std::fs::read_to_string(run(d, "curve.csv")).unwrap();
                std::fs::write(run(d, "curve.csv"), &text[..text.len() - 7]).unwrap();
            }),
            "curve.csv",
        ),
        (
            "events.csv without its global_slip row",
            Box::new(move |d: &Path| {
                let mut l = lines(&run(d, "events.csv"));
                assert!(l.last().unwrap().contains("global_slip"));
                l.pop();
                write_lines(&run(d, "events.csv"), &l);
            }),
            "events.csv",
        ),
        (
            "curve.csv rows shuffled",
            Box::new(move |d: &Path| {
                let mut l = lines(&run(d, "curve.csv"));
                l.swap(3, 7);
                write_lines(&run(d, "curve.csv"), &l);
            }),
            "curve.csv",
        ),
        (
            "events.csv rows shuffled",
            Box::new(move |d: &Path| {
                let mut l = lines(&run(d, "events.csv"));
                l.swap(4, 9);
                write_lines(&run(d, "events.csv"), &l);
            }),
            "events.csv",
        ),
        (
            "a curve.csv row duplicated",
            Box::new(move |d: &Path| {
                let mut l = lines(&run(d, "curve.csv"));
                let row = l[4].clone();
                l.insert(4, row);
                write_lines(&run(d, "curve.csv"), &l);
            }),
            "curve.csv",
        ),
        (
            "F/(μF_N) = 5",
            Box::new(move |d: &Path| {
                set_cell(
                    &run(d, "curve.csv"),
                    3,
                    "force_over_mu_FN",
                    "5.000000000000e0",
                );
            }),
            "curve.csv",
        ),
        (
            "ℓ/Lx = 7",
            Box::new(move |d: &Path| {
                set_cell(
                    &run(d, "curve.csv"),
                    3,
                    "precursor_over_Lx",
                    "7.000000000000e0",
                );
            }),
            "curve.csv",
        ),
        (
            "a negative real contact area",
            Box::new(move |d: &Path| {
                set_cell(
                    &run(d, "curve.csv"),
                    3,
                    "real_contact_area_m2",
                    "-1.000000000000e-6",
                );
            }),
            "curve.csv",
        ),
        (
            "an edited force (curve.csv against events.csv)",
            Box::new(move |d: &Path| {
                let f = &lines(&run(d, "curve.csv"))[4];
                let force: f64 = f.split(',').nth(1).unwrap().parse().unwrap();
                let mu_fn: f64 = force / f.split(',').nth(2).unwrap().parse::<f64>().unwrap();
                let force = force * 1.01;
                set_cell(&run(d, "curve.csv"), 3, "force_N", &format!("{force:.12e}"));
                set_cell(
                    &run(d, "curve.csv"),
                    3,
                    "force_over_mu_FN",
                    &format!("{:.12e}", force / mu_fn),
                );
            }),
            "curve.csv",
        ),
        (
            "NaN in events.csv",
            Box::new(move |d: &Path| {
                set_cell(&run(d, "events.csv"), 0, "force_N", "NaN");
            }),
            "events.csv",
        ),
        (
            "an edited event kind",
            Box::new(move |d: &Path| {
                let l = lines(&run(d, "events.csv"));
                let row = l
                    .iter()
                    .skip(1)
                    .position(|r| r.contains(",rupture,"))
                    .unwrap();
                set_cell(&run(d, "events.csv"), row, "kind", "attach");
            }),
            "events.csv",
        ),
        (
            "a site outside the grid",
            Box::new(move |d: &Path| {
                let l = lines(&run(d, "events.csv"));
                let row = l
                    .iter()
                    .skip(1)
                    .position(|r| r.contains(",rupture,"))
                    .unwrap();
                set_cell(&run(d, "events.csv"), row, "ix", "30");
            }),
            "events.csv",
        ),
        (
            "contact_map.csv with a column more than the scene's Nx",
            Box::new(move |d: &Path| {
                let l: Vec<String> = lines(&run(d, "contact_map.csv"))
                    .into_iter()
                    .enumerate()
                    .map(|(i, l)| {
                        if i == 0 {
                            format!("{l},area_m2_ix30")
                        } else {
                            format!("{l},0")
                        }
                    })
                    .collect();
                write_lines(&run(d, "contact_map.csv"), &l);
            }),
            "contact_map.csv",
        ),
        (
            "contact_map.csv without its last level",
            Box::new(move |d: &Path| {
                let mut l = lines(&run(d, "contact_map.csv"));
                l.pop();
                write_lines(&run(d, "contact_map.csv"), &l);
            }),
            "contact_map.csv",
        ),
        (
            "a negative area in contact_map.csv",
            Box::new(move |d: &Path| {
                set_cell(&run(d, "contact_map.csv"), 2, "area_m2_ix3", "-1e-7");
            }),
            "contact_map.csv",
        ),
        (
            "another point's scene.json",
            Box::new(move |d: &Path| {
                std::fs::copy(d.join("p0001-r0000/scene.json"), run(d, "scene.json")).unwrap();
            }),
            "scene",
        ),
        (
            "run directories swapped between points",
            Box::new(move |d: &Path| {
                std::fs::rename(d.join(RUN), d.join("x")).unwrap();
                std::fs::rename(d.join("p0001-r0000"), d.join(RUN)).unwrap();
                std::fs::rename(d.join("x"), d.join("p0001-r0000")).unwrap();
            }),
            "scene",
        ),
        (
            "an axis value edited in sweep.json",
            Box::new(move |d: &Path| {
                let text = std::fs::read_to_string(d.join("sweep.json")).unwrap();
                assert!(text.contains("400.0"), "{text}");
                std::fs::write(d.join("sweep.json"), text.replacen("400.0", "450.0", 1)).unwrap();
            }),
            "scene",
        ),
    ]
}

fn fields(d: &Path) -> PathBuf {
    d.join(RUN).join("fields.csv")
}

/// The header and the rows of each recorded state of `fields.csv`.
fn states(d: &Path) -> (String, Vec<Vec<String>>) {
    let l = lines(&fields(d));
    let header = l[0].clone();
    let blocks: Vec<Vec<String>> = l[1..].chunks(PER_STATE).map(<[String]>::to_vec).collect();
    (header, blocks)
}

fn write(d: &Path, header: String, blocks: Vec<Vec<String>>) {
    let mut l = vec![header];
    l.extend(blocks.into_iter().flatten());
    write_lines(&fields(d), &l);
}

/// Damage to `fields.csv` only (what `movie` reads beyond the run's tables).
fn field_damages() -> Vec<(&'static str, Damage)> {
    vec![
        (
            "states out of order",
            Box::new(move |d: &Path| {
                let (h, mut b) = states(d);
                b.swap(2, 3);
                write(d, h, b);
            }),
        ),
        (
            "a state duplicated",
            Box::new(move |d: &Path| {
                let (h, mut b) = states(d);
                let s = b[2].clone();
                b.insert(2, s);
                write(d, h, b);
            }),
        ),
        (
            "the last state missing",
            Box::new(move |d: &Path| {
                let (h, mut b) = states(d);
                b.pop();
                write(d, h, b);
            }),
        ),
        (
            "a negative area",
            Box::new(move |d: &Path| {
                set_cell(&fields(d), 1, "value_ix4", "-2e-9");
            }),
        ),
        (
            "a plane whose z changes within the file",
            Box::new(move |d: &Path| {
                set_cell(&fields(d), PER_STATE * 2 + 5, "z_m", "6.000000000000e-3");
            }),
        ),
        (
            "a plane outside the block",
            Box::new(move |d: &Path| {
                set_cell(&fields(d), 6, "z_m", "5.000000000000e-2");
            }),
        ),
        (
            "differing forces within one state",
            Box::new(move |d: &Path| {
                let l = lines(&fields(d));
                let x: f64 = l[1 + PER_STATE * 3]
                    .split(',')
                    .nth(1)
                    .unwrap()
                    .parse()
                    .unwrap();
                set_cell(
                    &fields(d),
                    PER_STATE * 3 + 2,
                    "force_over_mu_FN",
                    &format!("{:.12e}", x + 0.01),
                );
            }),
        ),
        (
            "NaN as a value",
            Box::new(move |d: &Path| {
                set_cell(&fields(d), 3, "value_ix0", "NaN");
            }),
        ),
    ]
}

/// Runs `args`; the code must be 3, the message must name `names`, and `dir` unchanged.
/// `stats` of `dir` with few resamples (the checks are what is tested, not the fits).
fn stats(dir: &Path) -> Vec<&str> {
    vec!["stats", path(dir), "--bootstrap", "5", "--goodness", "5"]
}

fn refused(case: &str, args: &[&str], names: &str, dir: &Path, failures: &mut Vec<String>) {
    let before = contents(dir);
    let o = precursors(args);
    let text = stderr(&o);
    if o.status.code() != Some(3) || !text.contains(names) {
        failures.push(format!(
            "{case}: {args:?} gave code {:?}: {text}",
            o.status.code()
        ));
    }
    if contents(dir) != before {
        failures.push(format!("{case}: {args:?} changed the directory"));
    }
}

fn pristine() -> PathBuf {
    let dir = scratch("pristine");
    let file = dir.join("sweep-in.json");
    std::fs::write(&file, SWEEP).unwrap();
    let sweep = dir.join("sweep");
    let o = precursors(&[
        "sweep",
        path(&file),
        "--out",
        path(&sweep),
        "-q",
        "--jobs",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    sweep
}

#[test]
fn merge_stats_plot_and_movie_refuse_every_damaged_table_with_its_name() {
    let sweep = pristine();
    let root = sweep.parent().unwrap().to_path_buf();
    // The undamaged copy is read (the checks refuse nothing a run writes).
    let whole = root.join("whole");
    copy_dir(&sweep, &whole);
    for args in [
        vec!["merge", path(&whole)],
        vec!["plot", path(&whole)],
        stats(&whole),
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    let whole_run = whole.join(RUN);
    for args in [
        vec!["plot", path(&whole_run)],
        stats(&whole_run),
        vec![
            "movie",
            path(&whole_run),
            "-q",
            "--max-frames",
            "2",
            "--width",
            "300",
            "--height",
            "200",
        ],
    ] {
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    let mut failures = Vec::new();
    for (k, (case, damage, names)) in damages().into_iter().enumerate() {
        let d = root.join(format!("case-{k}"));
        copy_dir(&sweep, &d);
        damage(&d);
        let run = d.join(RUN);
        refused(case, &["merge", path(&d)], names, &d, &mut failures);
        refused(case, &["plot", path(&d)], names, &d, &mut failures);
        refused(case, &stats(&d), names, &d, &mut failures);
        if !case.contains("sweep.json")
            && !case.contains("swapped")
            && !case.contains("another point")
        {
            refused(case, &["plot", path(&run)], names, &d, &mut failures);
            refused(case, &stats(&run), names, &d, &mut failures);
            refused(
                case,
                &[
                    "movie",
                    path(&run),
                    "-q",
                    "--width",
                    "300",
                    "--height",
                    "200",
                ],
                names,
                &d,
                &mut failures,
            );
        }
        std::fs::remove_dir_all(&d).unwrap();
    }
    for (k, (case, damage)) in field_damages().into_iter().enumerate() {
        let d = root.join(format!("fields-{k}"));
        copy_dir(&sweep, &d);
        damage(&d);
        let run = d.join(RUN);
        refused(
            case,
            &[
                "movie",
                path(&run),
                "-q",
                "--width",
                "300",
                "--height",
                "200",
            ],
            "fields.csv",
            &d,
            &mut failures,
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
    assert!(failures.is_empty(), "{failures:#?}");
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn resume_refuses_damaged_rows_before_its_checkpoint_and_writes_nothing() {
    let dir = scratch("resume");
    let scene = dir.join("scene-in.json");
    let base = SWEEP.split("\"axes\"").next().unwrap();
    let base = &base[base.find("{ \"block\"").unwrap()..base.rfind('}').unwrap() + 1];
    std::fs::write(&scene, base).unwrap();
    let run = dir.join("run");
    let ck = dir.join("ck.json");
    let o = precursors(&[
        "run",
        path(&scene),
        "--out",
        path(&run),
        "--checkpoint",
        path(&ck),
        "--every",
        "5",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // The undamaged directory resumes.
    let whole = dir.join("whole");
    copy_dir(&run, &whole);
    let o = precursors(&["resume", path(&ck), "--out", path(&whole), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let cases: Vec<(&str, Damage, &str)> = vec![
        (
            "NaN",
            Box::new(|d: &Path| set_cell(&d.join("curve.csv"), 1, "real_contact_area_m2", "NaN")),
            "curve.csv",
        ),
        (
            "an edited value",
            Box::new(|d: &Path| set_cell(&d.join("curve.csv"), 1, "precursor_over_Lx", "2.5e-1")),
            "curve.csv",
        ),
        (
            "an edited event kind",
            Box::new(|d: &Path| {
                let l = lines(&d.join("events.csv"));
                let row = l
                    .iter()
                    .skip(1)
                    .position(|r| r.contains(",rupture,"))
                    .unwrap();
                set_cell(&d.join("events.csv"), row, "kind", "detach");
            }),
            "events.csv",
        ),
        (
            "an edited force",
            Box::new(|d: &Path| set_cell(&d.join("events.csv"), 0, "force_N", "1.0e9")),
            "events.csv",
        ),
        (
            "a negative area in the map",
            Box::new(|d: &Path| set_cell(&d.join("contact_map.csv"), 0, "area_m2_ix2", "-3e-7")),
            "contact_map.csv",
        ),
        (
            "a NaN field",
            Box::new(|d: &Path| set_cell(&d.join("fields.csv"), 2, "value_ix1", "NaN")),
            "fields.csv",
        ),
    ];
    let mut failures = Vec::new();
    for (k, (case, damage, names)) in cases.into_iter().enumerate() {
        let d = dir.join(format!("case-{k}"));
        copy_dir(&run, &d);
        damage(&d);
        refused(
            case,
            &["resume", path(&ck), "--out", path(&d), "-q"],
            names,
            &d,
            &mut failures,
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
    assert!(failures.is_empty(), "{failures:#?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
