//! The observables of avalanches and damage (`per_avalanche.csv`, `fronts.csv`,
//! `Avalanches`, `DamageFront`): checked against values computed here from `events.csv`
//! by a separate reading of the run, and against the numbers of issue 43's review of the
//! calibration run (computed by its reviewer's own script).

use crate::common::scratch;
use precursors::output::RunTables;
use precursors::{Avalanches, DamageFront, Event, Scene, SceneBuilder};
use std::collections::HashMap;
use std::path::Path;

fn calibration() -> Scene {
    SceneBuilder::from_json_file(Path::new("examples/scenes/calibration.json"))
        .unwrap()
        .build()
        .unwrap()
}

/// Runs `scene` into `dir` through the one run loop.
fn run(scene: &Scene, dir: &Path) {
    let mut driver = scene.driver().unwrap();
    let tables = RunTables::create(dir, &driver).unwrap();
    tables.run_to_slip(&mut driver, None, |_, _| {}).unwrap();
}

/// A table as rows of named cells.
fn table(path: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

fn num(row: &HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key}: {:?}", row[key]))
}

/// The avalanches of `events.csv` as this test reads them: for each `load_raised`, the
/// ruptures, attachments and flash ruptures (a site that attached earlier in the same
/// avalanche) up to the next `stable` or `global_slip`, the forces at both ends, and the
/// sites in contact at both ends (those in contact at zero shear are the sites whose first
/// event is a rupture or a detachment; a rupture or a detachment takes one out, an
/// attachment brings one back).
#[derive(Debug, PartialEq)]
struct Read {
    start: usize,
    end: usize,
    ruptures: usize,
    attaches: usize,
    flash: usize,
    before: String,
    after: String,
    contacts: (usize, usize),
    /// The columns `ix` of its ruptures.
    columns: Vec<usize>,
}

/// The index of the spanning avalanche as docs/statistics.md defines it: the first that
/// leaves at most half of the sites in contact when it started.
fn spanning(avalanches: &[Read]) -> usize {
    avalanches
        .iter()
        .position(|a| 2 * a.contacts.1 <= a.contacts.0)
        .unwrap()
}

fn read_avalanches(events: &[HashMap<String, String>]) -> Vec<Read> {
    let mut out = Vec::new();
    let mut open: Option<(Read, Vec<(String, String)>)> = None;
    let mut seen = std::collections::HashSet::new();
    let mut contacts = 0usize;
    for e in events {
        let site = (e["ix"].clone(), e["iy"].clone());
        if matches!(e["kind"].as_str(), "rupture" | "detach") && seen.insert(site.clone()) {
            contacts += 1;
        } else if e["kind"] == "attach" {
            seen.insert(site.clone());
        }
    }
    for e in events {
        let site = (e["ix"].clone(), e["iy"].clone());
        match e["kind"].as_str() {
            "rupture" | "detach" => contacts -= 1,
            "attach" => contacts += 1,
            _ => {}
        }
        match e["kind"].as_str() {
            "load_raised" => {
                let read = Read {
                    start: e["index"].parse().unwrap(),
                    end: 0,
                    ruptures: 0,
                    attaches: 0,
                    flash: 0,
                    before: e["force_N"].clone(),
                    after: String::new(),
                    contacts: (contacts, contacts),
                    columns: Vec::new(),
                };
                open = Some((read, Vec::new()));
            }
            "rupture" => {
                let (a, attached) = open.as_mut().unwrap();
                a.ruptures += 1;
                a.flash += usize::from(attached.contains(&site));
                a.columns.push(site.0.parse().unwrap());
            }
            "attach" => {
                let (a, attached) = open.as_mut().unwrap();
                a.attaches += 1;
                attached.push(site);
            }
            "stable" | "global_slip" => {
                if let Some((mut a, _)) = open.take() {
                    a.end = e["index"].parse().unwrap();
                    a.after = e["force_N"].clone();
                    a.contacts.1 = contacts;
                    out.push(a);
                }
            }
            _ => {}
        }
    }
    out
}

#[test]
fn the_calibration_runs_avalanches_and_damage_front() {
    let dir = scratch("calibration");
    run(&calibration(), &dir);
    let events = table(&dir.join("events.csv"));
    let rows = table(&dir.join("per_avalanche.csv"));
    let expected = read_avalanches(&events);
    assert_eq!(rows.len(), expected.len());
    for (k, (row, e)) in rows.iter().zip(&expected).enumerate() {
        let got = Read {
            start: row["start_event"].parse().unwrap(),
            end: row["end_event"].parse().unwrap(),
            ruptures: row["ruptures"].parse().unwrap(),
            attaches: row["attaches"].parse().unwrap(),
            flash: row["flash_ruptures"].parse().unwrap(),
            before: row["force_before_N"].clone(),
            after: row["force_after_N"].clone(),
            contacts: (
                row["contacts_before"].parse().unwrap(),
                row["contacts_after"].parse().unwrap(),
            ),
            columns: e.columns.clone(),
        };
        // Extent and centroid from the ruptures' columns in events.csv (1 mm cells), to
        // the 13 significant digits of the table.
        let low = *e.columns.iter().min().unwrap() as f64;
        let high = *e.columns.iter().max().unwrap() as f64;
        let mean = e.columns.iter().sum::<usize>() as f64 / e.columns.len() as f64;
        let extent = (high - low + 1.0) * 1e-3;
        let centroid = (mean + 0.5) * 1e-3;
        assert!((num(row, "extent_m") - extent).abs() < 1e-12 * extent);
        assert!((num(row, "centroid_m") - centroid).abs() < 1e-12 * centroid);
        assert_eq!(&got, e, "avalanche {}", k + 1);
        let span = spanning(&expected);
        assert_eq!(row["spanning"], if k == span { "1" } else { "0" });
        assert_eq!(row["after_spanning"], if k > span { "1" } else { "0" });
        assert_eq!(
            num(row, "ruptures_without_flash") as usize,
            got.ruptures - got.flash
        );
        // The paper's rod drive is force control: the force does not drop.
        assert_eq!(num(row, "force_drop_N"), 0.0);
        assert!((num(row, "broken_area_m2") - got.ruptures as f64 * 1e-6).abs() < 1e-18);
    }
    // Issue 43's review of this run: 980 ruptures, 379 attachments, each ending in a
    // rupture of the same site within the same avalanche.
    let sum = |f: fn(&Read) -> usize| expected.iter().map(f).sum::<usize>();
    assert_eq!(sum(|a| a.ruptures), 980);
    assert_eq!(sum(|a| a.attaches), 379);
    assert_eq!(sum(|a| a.flash), 379);
    assert_eq!(rows.last().unwrap()["global_slip"], "1");

    // The damage front beside ℓ at the review's loads: the last stable state at or below
    // F/(μF_N) = 0.3, 0.5, 0.8, 0.9 (the review's ℓ/Lx and front/Lx: 0.021/0.15,
    // 0.079/0.30, 0.221/0.52, 0.336/0.74).
    let fronts = table(&dir.join("fronts.csv"));
    let curve = table(&dir.join("curve.csv"));
    assert_eq!(fronts.len(), curve.len());
    // The fronts at a quarter and three quarters of the contacts lost, read here from
    // events.csv: a site's first event says whether it was in contact at zero shear, then
    // ruptures and detachments take it out, attachments bring it back (140 x 7 sites).
    let (nx, ny) = (140usize, 7usize);
    let site = |e: &HashMap<String, String>| -> usize {
        e["iy"].parse::<usize>().unwrap() * nx + e["ix"].parse::<usize>().unwrap()
    };
    let mut first: Vec<Option<bool>> = vec![None; nx * ny];
    for e in &events {
        if matches!(e["kind"].as_str(), "rupture" | "detach" | "attach") {
            let slot = &mut first[site(e)];
            slot.get_or_insert(e["kind"] != "attach");
        }
    }
    let mut attached: Vec<bool> = first.iter().map(|f| f.unwrap()).collect();
    let initial: Vec<usize> = (0..nx)
        .map(|ix| (0..ny).filter(|iy| attached[iy * nx + ix]).count())
        .collect();
    let mut by_state = Vec::new();
    for e in &events {
        match e["kind"].as_str() {
            "rupture" | "detach" => attached[site(e)] = false,
            "attach" => attached[site(e)] = true,
            "stable" => {
                let front = |lost: f64| {
                    let run = (0..nx)
                        .take_while(|&ix| {
                            let n = (0..ny).filter(|iy| attached[iy * nx + ix]).count();
                            n as f64 <= (1.0 - lost) * initial[ix] as f64
                        })
                        .count();
                    run as f64 * 1e-3
                };
                by_state.push([front(0.25), front(0.75)]);
            }
            _ => {}
        }
    }
    assert_eq!(by_state.len(), fronts.len());
    let mut apart = 0;
    for (f, [quarter, three_quarters]) in fronts.iter().zip(&by_state) {
        assert!(
            (num(f, "damage_front_quarter_m") - quarter).abs() < 1e-12,
            "{f:?}"
        );
        assert!((num(f, "damage_front_three_quarters_m") - three_quarters).abs() < 1e-12);
        assert!(
            three_quarters <= &num(f, "damage_front_m") && &num(f, "damage_front_m") <= quarter
        );
        apart += usize::from(quarter > three_quarters);
    }
    assert!(
        apart > fronts.len() / 2,
        "the thresholds differ at {apart} states"
    );
    for (f, c) in fronts.iter().zip(&curve) {
        assert_eq!(f["event"], c["event"]);
        assert_eq!(f["precursor_over_Lx"], c["precursor_over_Lx"]);
        let x = num(f, "damage_front_m") / 0.140;
        assert!((x - num(f, "damage_front_over_Lx")).abs() < 1e-12);
        // A multiple of Δx = 1 mm.
        assert!((x * 140.0 - (x * 140.0).round()).abs() < 1e-9);
    }
    // With docs/statistics.md's fronts at a quarter and three quarters lost (from this
    // test's reading above).
    for (load, ell, front, documented) in [
        (0.3, 0.021, 0.15, [0.164, 0.043]),
        (0.5, 0.079, 0.30, [0.314, 0.157]),
        (0.8, 0.221, 0.52, [0.586, 0.221]),
        (0.9, 0.336, 0.74, [0.743, 0.443]),
    ] {
        let row = fronts
            .iter()
            .rfind(|f| num(f, "force_over_mu_FN") <= load)
            .unwrap();
        assert!(
            (num(row, "precursor_over_Lx") - ell).abs() < 0.0015,
            "{row:?}"
        );
        assert!(
            (num(row, "damage_front_over_Lx") - front).abs() < 0.005,
            "{row:?}"
        );
        let [quarter, three_quarters] = by_state[fronts.iter().position(|f| f == row).unwrap()];
        assert!((quarter / 0.140 - documented[0]).abs() < 0.0015, "{row:?}");
        assert!(
            (three_quarters / 0.140 - documented[1]).abs() < 0.0015,
            "{row:?}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_spring_drive_drops_its_force_in_avalanches() {
    let scene = calibration()
        .to_builder()
        .drive(precursors::Drive::Spring {
            stiffness: 4e6,
            lateral: precursors::Lateral::Side,
        })
        .build()
        .unwrap();
    let dir = scratch("spring");
    run(&scene, &dir);
    let events = table(&dir.join("events.csv"));
    let rows = table(&dir.join("per_avalanche.csv"));
    let expected = read_avalanches(&events);
    assert_eq!(rows.len(), expected.len());
    let mut dropped = 0;
    for (row, e) in rows.iter().zip(&expected) {
        let (before, after): (f64, f64) = (e.before.parse().unwrap(), e.after.parse().unwrap());
        let drop = num(row, "force_drop_N");
        assert!((drop - (before - after)).abs() <= 1e-9 * before, "{row:?}");
        assert!(!row["drive_displacement_before_m"].is_empty());
        dropped += usize::from(drop > 0.0);
    }
    // Every avalanche but the last (at global slip the force is the last rupture's) ends
    // lower than it started: each rupture softens the block under the spring.
    assert!(dropped >= rows.len() - 1, "{dropped} of {}", rows.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_observers_agree_with_the_tables_and_a_resumed_run_derives_the_same() {
    let scene = calibration();
    let dir = scratch("observers");
    let mut driver = scene.driver().unwrap();
    let first = driver.step().unwrap().unwrap();
    let mut front = DamageFront::new(driver.grid(), driver.site_states()).unwrap();
    let mut avalanches = Avalanches::new(driver.grid());
    assert!(avalanches.observe(&first).is_none());
    let mut fronts = vec![front.position()];
    let mut all = Vec::new();
    let mut events = vec![first];
    let mut checkpoint = None;
    while let Some(event) = driver.step().unwrap() {
        front.observe(&event);
        all.extend(avalanches.observe(&event));
        if let Event::Stable { .. } = event {
            fronts.push(front.position());
            if fronts.len() == 100 {
                checkpoint = Some(driver.checkpoint());
            }
        }
        events.push(event);
    }
    // The zero-shear contacts read back from the events are the driver's.
    let mut again = scene.driver().unwrap();
    again.step().unwrap();
    assert_eq!(
        DamageFront::zero_shear_states(scene.grid(), &events).unwrap(),
        again.site_states()
    );
    // A run into a directory, cut at the checkpoint and resumed, derives the same tables
    // as the observers.
    run(&scene, &dir);
    let whole: Vec<Vec<u8>> = ["per_avalanche.csv", "fronts.csv"]
        .iter()
        .map(|n| std::fs::read(dir.join(n)).unwrap())
        .collect();
    let mut resumed = scene.resume(&checkpoint.unwrap()).unwrap();
    let tables = RunTables::resume(&dir, &resumed).unwrap();
    tables.run_to_slip(&mut resumed, None, |_, _| {}).unwrap();
    for (name, before) in ["per_avalanche.csv", "fronts.csv"].iter().zip(&whole) {
        assert!(
            &std::fs::read(dir.join(name)).unwrap() == before,
            "{name} differs"
        );
    }
    let rows = table(&dir.join("fronts.csv"));
    assert_eq!(rows.len(), fronts.len());
    for (row, x) in rows.iter().zip(&fronts) {
        assert!(
            (num(row, "damage_front_m") - x).abs() <= 1e-15,
            "{row:?} against {x}"
        );
    }
    let rows = table(&dir.join("per_avalanche.csv"));
    assert_eq!(rows.len(), all.len());
    for (row, a) in rows.iter().zip(&all) {
        assert_eq!(num(row, "ruptures") as usize, a.ruptures);
        assert_eq!(num(row, "flash_ruptures") as usize, a.flash_ruptures);
        assert!((num(row, "energy_J") - a.energy).abs() <= 1e-12 * a.energy);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small sweep: two normal loads, three realizations each, a driving spring.
const SWEEP: &str = r#"{
    "base": { "block": { "lx": 0.02, "ly": 0.004, "lz": 0.01 },
              "cells": { "kind": "count", "nx": 20, "ny": 4 },
              "normal_load": 100.0,
              "drive": { "kind": "spring", "stiffness": 4e6, "lateral": { "kind": "side" } } },
    "axes": [ { "key": "normal_load", "values": [100.0, 150.0] } ],
    "realizations": 3,
    "seed": 5
}"#;

#[test]
fn stats_pool_each_points_realizations() {
    use precursors::sweep::{statistics, StatsOptions, Sweep, SweepOptions};
    let dir = scratch("sweep");
    let sweep = Sweep::from_json_str(SWEEP).unwrap();
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    let options = StatsOptions::default().fit(
        precursors::statistics::PowerLawOptions::default()
            .bootstrap(10)
            .goodness_samples(10)
            .min_tail(5),
    );
    let summary = statistics(&dir, &options).unwrap();
    assert_eq!(
        (summary.points, summary.runs, summary.runs_missing),
        (2, 6, 0)
    );
    // The avalanches of each point's runs as this test reads their events.csv.
    let mut sizes: [Vec<usize>; 2] = Default::default();
    let mut drops: [usize; 2] = [0; 2];
    // Per avalanche: 1 - F/(μF_N) at its start (μ = 0.5), its size with and without flash
    // ruptures, its force drop.
    let mut values: [Vec<[f64; 4]>; 2] = Default::default();
    for run in sweep.runs() {
        let events = table(&dir.join(run.dir_name()).join("events.csv"));
        let all = read_avalanches(&events);
        let mu_fn = 0.5 * [100.0, 150.0][run.point()];
        // `stats` leaves out the spanning avalanche and those after it by default.
        for a in &all[..spanning(&all)] {
            sizes[run.point()].push(a.ruptures);
            let before = a.before.parse::<f64>().unwrap();
            let drop = before - a.after.parse::<f64>().unwrap();
            drops[run.point()] += usize::from(drop > 0.0);
            values[run.point()].push([
                1.0 - before / mu_fn,
                a.ruptures as f64,
                (a.ruptures - a.flash) as f64,
                drop,
            ]);
        }
    }
    let fits = table(&dir.join("power_laws.csv"));
    let bins = table(&dir.join("distributions.csv"));
    let means = table(&dir.join("binned_means.csv"));
    // 1.x's columns first and unchanged, the alternatives after them; each fitted row has
    // its tests (p-values in [0, 1]) and the verdict the summary printed.
    let header = std::fs::read_to_string(dir.join("power_laws.csv")).unwrap();
    let header = header.lines().next().unwrap();
    assert!(header.starts_with(
        "point,normal_load,observable,support,samples,tail,x_min,alpha,alpha_std_error,\
         alpha_low,alpha_high,x_min_low,x_min_high,ks_distance,p_value,confidence,cutoff_alpha,"
    ));
    assert!(
        header.ends_with(
            ",lr_cutoff_vs_lognormal_p,verdict,classes_excluded,cutoff_classes_excluded,runs"
        ),
        "{header}"
    );
    let fitted: Vec<_> = fits.iter().filter(|r| !r["alpha"].is_empty()).collect();
    assert_eq!(summary.verdicts.len(), fitted.len());
    for (row, verdict) in fitted.iter().zip(&summary.verdicts) {
        for test in [
            "lr_exponential",
            "lr_lognormal",
            "lr_cutoff",
            "lr_cutoff_vs_lognormal",
        ] {
            let p = num(row, &format!("{test}_p"));
            assert!((0.0..=1.0).contains(&p), "{test}: {row:?}");
        }
        assert!(num(row, "lr_cutoff") <= 0.0);
        assert!(verdict.ends_with(&row["verdict"]), "{verdict} vs {row:?}");
        assert!(row["verdict"].contains("cut-off law"));
    }
    for point in 0..2 {
        let of = |observable: &str| {
            fits.iter()
                .find(|r| r["point"] == point.to_string() && r["observable"] == observable)
                .unwrap()
                .clone()
        };
        let row = of("avalanche_ruptures");
        assert_eq!(row["normal_load"], ["100.0", "150.0"][point]);
        assert_eq!(num(&row, "samples") as usize, sizes[point].len());
        assert_eq!(num(&of("force_drop_N"), "samples") as usize, drops[point]);
        // The binned counts are the pooled sizes.
        let binned: Vec<_> = bins
            .iter()
            .filter(|r| r["point"] == point.to_string() && r["observable"] == "avalanche_ruptures")
            .collect();
        let total: usize = binned.iter().map(|r| num(r, "count") as usize).sum();
        assert_eq!(total, sizes[point].len());
        for b in &binned {
            let (lo, hi) = (num(b, "bin_low"), num(b, "bin_high"));
            let inside = sizes[point]
                .iter()
                .filter(|&&s| (s as f64) >= lo && (s as f64) < hi)
                .count();
            assert_eq!(num(b, "count") as usize, inside, "{b:?}");
        }
        // Each fit names the classes its intervals exclude: those of 3/2, 5/2 and 1.28
        // outside [low, high].
        for r in fits.iter().filter(|r| r["point"] == point.to_string()) {
            for (column, low, high) in [
                ("classes_excluded", "alpha_low", "alpha_high"),
                (
                    "cutoff_classes_excluded",
                    "cutoff_alpha_low",
                    "cutoff_alpha_high",
                ),
            ] {
                if r[low].is_empty() {
                    assert_eq!(r[column], "", "{r:?}");
                    continue;
                }
                let (low, high) = (num(r, low), num(r, high));
                let mut expected = Vec::new();
                for (name, tau) in [
                    ("mean-field depinning 3/2", 1.5),
                    ("fibre bundle near failure 3/2", 1.5),
                    ("fibre bundle far from failure 5/2", 2.5),
                    ("long-range elastic line 1.28", 1.28),
                ] {
                    if !(low..=high).contains(&tau) {
                        expected.push(name);
                    }
                }
                let expected = if expected.is_empty() {
                    "none".to_string()
                } else {
                    expected.join("; ")
                };
                assert_eq!(r[column].trim_matches('"'), expected, "{r:?}");
            }
        }
        // The mean size against 1 - F/(μF_N), and the mean drop against the size, in
        // bins [10^(k/5), 10^((k+1)/5)): counts, means and the 95 % standard-error
        // interval from the avalanches read here.
        type Pick = fn(&[f64; 4]) -> (f64, f64);
        let relations: [(&str, Pick); 3] = [
            ("ruptures_against_load_gap", |v| (v[0], v[1])),
            ("ruptures_without_flash_against_load_gap", |v| (v[0], v[2])),
            ("force_drop_N_against_ruptures", |v| (v[1], v[3])),
        ];
        let scaling = table(&dir.join("scaling.csv"));
        for (relation, pick) in relations {
            let pairs: Vec<(f64, f64)> = values[point]
                .iter()
                .map(pick)
                .filter(|(x, y)| *x > 0.0 && *y > 0.0)
                .collect();
            let rows: Vec<_> = means
                .iter()
                .filter(|r| r["point"] == point.to_string() && r["relation"] == relation)
                .collect();
            assert!(!rows.is_empty(), "{relation}");
            let mut counted = 0;
            for r in &rows {
                let k = (5.0 * num(r, "x_low").log10()).round();
                let (lo, hi) = (10f64.powf(k / 5.0), 10f64.powf((k + 1.0) / 5.0));
                let ys: Vec<f64> = pairs
                    .iter()
                    .filter(|(x, _)| *x >= lo && *x < hi)
                    .map(|p| p.1)
                    .collect();
                let n = ys.len() as f64;
                let mean = ys.iter().sum::<f64>() / n;
                assert_eq!(num(r, "count") as usize, ys.len(), "{r:?}");
                assert!((num(r, "mean") - mean).abs() <= 1e-9 * mean, "{r:?}");
                if ys.len() > 1 {
                    let sd =
                        (ys.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
                    let half = 1.959_963_984_540_054 * sd / n.sqrt(); // scipy norm.ppf(0.975)
                    assert!((num(r, "mean_high") - mean - half).abs() <= 1e-9 * mean.max(1.0));
                    assert!((mean - num(r, "mean_low") - half).abs() <= 1e-9 * mean.max(1.0));
                } else {
                    assert_eq!(r["mean_high"], "");
                }
                counted += ys.len();
            }
            assert_eq!(counted, pairs.len(), "{relation}");
            // The slope of ln y on ln x by least squares, computed here.
            let row = scaling
                .iter()
                .find(|r| r["point"] == point.to_string() && r["relation"] == relation)
                .unwrap();
            assert_eq!(num(row, "pairs") as usize, pairs.len());
            let n = pairs.len() as f64;
            let mx = pairs.iter().map(|p| p.0.ln()).sum::<f64>() / n;
            let my = pairs.iter().map(|p| p.1.ln()).sum::<f64>() / n;
            let sxy: f64 = pairs
                .iter()
                .map(|p| (p.0.ln() - mx) * (p.1.ln() - my))
                .sum();
            let sxx: f64 = pairs.iter().map(|p| (p.0.ln() - mx).powi(2)).sum();
            let slope = sxy / sxx;
            assert!((num(row, "exponent") - slope).abs() <= 1e-9, "{row:?}");
            assert!(num(row, "exponent_low") <= slope && slope <= num(row, "exponent_high"));
        }
    }
    // A sweep over a normal load has no collapse.
    assert!(!dir.join("collapse.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "cli")]
mod cli {
    use super::*;
    use crate::common::program::{path, precursors, stderr};

    #[test]
    fn stats_of_a_run_and_its_refusals() {
        let dir = scratch("cli");
        let run_dir = dir.join("run");
        std::fs::create_dir_all(&run_dir).unwrap();
        run(&calibration(), &run_dir);
        let o = precursors(&[
            "stats",
            path(&run_dir),
            "--bootstrap",
            "10",
            "--goodness",
            "10",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let fits = table(&run_dir.join("power_laws.csv"));
        assert_eq!(fits.len(), 14);
        assert_eq!(fits[0]["observable"], "avalanche_ruptures");
        // The observables appended in 1.2, against the run's avalanches read from
        // events.csv (`read_avalanches`): before the spanning one, its flash ruptures out,
        // its extent in cells, its size in the load window of its starting load.
        let events = table(&run_dir.join("events.csv"));
        let avalanches = read_avalanches(&events);
        let kept = &avalanches[..spanning(&avalanches)];
        let samples = |name: &str| {
            let row = fits.iter().find(|r| r["observable"] == name).unwrap();
            num(row, "samples") as usize
        };
        assert_eq!(samples("avalanche_ruptures_without_flash"), kept.len());
        assert!(kept.iter().all(|a| a.ruptures > a.flash));
        assert_eq!(samples("avalanche_extent_cells"), kept.len());
        // F/(μF_N) with μ = 0.5, F_N = 3.5 kN.
        let load = |a: &Read| a.before.parse::<f64>().unwrap() / (0.5 * 3500.0);
        let windows = [
            kept.iter().filter(|a| load(a) < 0.5).count(),
            kept.iter()
                .filter(|a| (0.5..0.8).contains(&load(a)))
                .count(),
            kept.iter().filter(|a| load(a) >= 0.8).count(),
        ];
        assert!(windows.iter().all(|&n| n > 0), "{windows:?}");
        assert_eq!(samples("avalanche_ruptures_load_below_0.5"), windows[0]);
        assert_eq!(samples("avalanche_ruptures_load_0.5_to_0.8"), windows[1]);
        assert_eq!(samples("avalanche_ruptures_load_from_0.8"), windows[2]);
        // The potencies and released energies that are positive, of the avalanches
        // per_avalanche.csv keeps (before the spanning one).
        let rows = table(&run_dir.join("per_avalanche.csv"));
        let kept_rows: Vec<_> = rows
            .iter()
            .filter(|r| {
                r["spanning"] == "0" && r["after_spanning"] == "0" && r["global_slip"] == "0"
            })
            .collect();
        assert_eq!(kept_rows.len(), kept.len());
        let positive = |key: &str| kept_rows.iter().filter(|r| num(r, key) > 0.0).count();
        assert!(positive("potency_m3") > kept.len() / 2);
        assert_eq!(samples("avalanche_potency_m3"), positive("potency_m3"));
        assert_eq!(
            samples("avalanche_released_energy_J"),
            positive("released_energy_J")
        );
        // The rod drive does not drop its force: no samples, no fit.
        assert_eq!(fits[1]["samples"], "0");
        assert_eq!(fits[1]["alpha"], "");
        // Bad options are a bad command line.
        for bad in [
            ["--confidence", "1"],
            ["--confidence", "nan"],
            ["--bootstrap", "10001"],
            ["--min-tail", "1"],
            ["--bins-per-decade", "0"],
        ] {
            let o = precursors(&["stats", path(&run_dir), bad[0], bad[1]]);
            assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        }
        // Neither a run nor a sweep; a damaged events.csv.
        let o = precursors(&["stats", path(&dir)]);
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("neither a run directory"),
            "{}",
            stderr(&o)
        );
        let events = run_dir.join("events.csv");
        let text = std::fs::read_to_string(&events).unwrap();
        let cut: Vec<&str> = text.lines().filter(|l| !l.contains(",rupture,")).collect();
        std::fs::write(&events, cut.join("\n") + "\n").unwrap();
        let o = precursors(&["stats", path(&run_dir)]);
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert!(stderr(&o).contains("events.csv"), "{}", stderr(&o));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn slip_profiles_balance_the_loads() {
    // docs/model.md section 1: ∫ φ_z = F_N and ∫ φ_x = -F over the interface; the column
    // averages times Δx Ly must give them back, at every stable state under shear.
    let scene = calibration();
    let mut driver = scene.driver().unwrap();
    let (dx, ly) = (scene.grid().dx(), scene.grid().block().ly());
    let mut checked = 0;
    while let Some(event) = driver.step().unwrap() {
        if let Event::Stable { load, .. } = event {
            let p = driver.slip_profile().unwrap();
            let normal: f64 = p.normal_traction().iter().sum::<f64>() * dx * ly;
            let shear: f64 = p.shear_traction().iter().sum::<f64>() * dx * ly;
            assert!((normal - 3500.0).abs() < 1e-6 * 3500.0, "{normal}");
            assert!(
                (shear + load.force).abs() < 1e-6 * 3500.0,
                "{shear} {}",
                load.force
            );
            // The rod pushes +x: every column has moved forward.
            if load.force > 0.0 {
                assert!(p.slip().iter().all(|u| *u > 0.0));
            }
            checked += 1;
            if checked == 40 {
                break;
            }
        }
    }
    assert_eq!(checked, 40);
}

/// The study's files (docs/statistics.md): each expands to 50 runs on the calibration
/// block with the drive, heights and grid its name says; the two cell sizes of the
/// correlated surface share their seeds, so realization `r` is one surface at both, and
/// both resolve it (cells of at most ξ/4).
#[test]
fn the_study_files_are_the_documented_study() {
    use precursors::sweep::Sweep;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sweeps/statistics");
    let mut seeds = Vec::new();
    for (name, drive, heights, nx) in [
        ("rod", "rod", "gaussian", 140),
        ("spring", "spring", "gaussian", 140),
        ("surface_0.7mm", "rod", "gaussian_surface", 200),
        ("surface_0.5mm", "rod", "gaussian_surface", 280),
    ] {
        let path = dir.join(format!("{name}.json"));
        let sweep = Sweep::from_json_file(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        assert_eq!(sweep.runs().len(), 50, "{path:?}");
        let scene = sweep.runs()[0].scene();
        let grid = scene.grid().unwrap();
        assert_eq!(grid.nx(), nx, "{path:?}");
        let b = grid.block();
        assert_eq!((b.lx(), b.ly(), b.lz()), (0.14, 0.007, 0.075));
        let json: serde_json::Value = serde_json::from_str(&scene.to_json().unwrap()).unwrap();
        assert_eq!(json["drive"]["kind"], drive, "{path:?}");
        assert_eq!(json["heights"]["kind"], heights, "{path:?}");
        assert_eq!(json["normal_load"], 3500.0, "{path:?}");
        if let Some(xi) = json["heights"]["correlation_length"].as_f64() {
            // docs/convergence.md's rule: a cell resolves the surface at ξ/4 or less.
            assert!(
                grid.dx() <= xi / 4.0 && grid.dy() <= xi / 4.0,
                "{path:?}: cells {} x {} against ξ = {xi}",
                grid.dx(),
                grid.dy()
            );
        }
        seeds.push(sweep.runs().iter().map(|r| r.seed()).collect::<Vec<u64>>());
    }
    assert_eq!(seeds[2], seeds[3]);
    let docs = std::fs::read_to_string("docs/statistics.md").unwrap();
    for name in [
        "rod.json",
        "spring.json",
        "surface_0.7mm.json",
        "surface_0.5mm.json",
    ] {
        assert!(
            docs.contains(name),
            "docs/statistics.md does not name {name}"
        );
    }
}

#[test]
fn stats_collapse_a_sweep_along_a_length() {
    // A sweep over block.lx at fixed cells and pressure: collapse.csv holds the fit of
    // `statistics::fit_collapse` to the sizes of each length's runs as this test reads
    // them from events.csv (before the spanning avalanche), grouped by run.
    use precursors::statistics::{
        compare_alternatives, fit_collapse, fit_cutoff_scaling, PowerLawOptions, Support,
    };
    use precursors::sweep::{statistics, StatsOptions, Sweep, SweepOptions};
    let dir = scratch("lengths");
    let sweep = Sweep::from_json_str(
        r#"{
        "base": { "block": { "lx": 0.02, "ly": 0.004, "lz": 0.01 },
                  "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
                  "normal_load": 100.0,
                  "drive": { "kind": "spring", "stiffness": 4e6, "lateral": { "kind": "side" } } },
        "axes": [ { "keys": ["block.lx", "normal_load"],
                    "values": [[0.02, 100.0], [0.04, 200.0], [0.08, 400.0]] } ],
        "realizations": 4,
        "seed": 9
    }"#,
    )
    .unwrap();
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    let fit = PowerLawOptions::default()
        .bootstrap(10)
        .goodness_samples(0)
        .min_tail(5);
    let summary = statistics(&dir, &StatsOptions::default().fit(fit.clone())).unwrap();
    assert!(summary.files.iter().any(|f| f.ends_with("collapse.csv")));
    let rows = table(&dir.join("collapse.csv"));
    assert_eq!(rows.len(), 2);
    let mut growths = 0;
    for (row, flash) in rows.iter().zip([false, true]) {
        let mut sets: Vec<(f64, Vec<Vec<f64>>)> = [0.02, 0.04, 0.08]
            .iter()
            .map(|l| (*l, Vec::new()))
            .collect();
        for run in sweep.runs() {
            let all = read_avalanches(&table(&dir.join(run.dir_name()).join("events.csv")));
            let sizes = all[..spanning(&all)]
                .iter()
                .map(|a| (a.ruptures - if flash { a.flash } else { 0 }) as f64)
                .collect();
            sets[run.point()].1.push(sizes);
        }
        let c = fit_collapse(&sets, Support::Discrete, 5, &fit).unwrap();
        assert_eq!(row["axis"], "block.lx");
        assert_eq!(num(row, "lengths"), 3.0);
        for (column, value) in [
            ("tau", c.tau),
            ("tau_low", c.tau_low),
            ("tau_high", c.tau_high),
            ("d", c.d),
            ("d_low", c.d_low),
            ("d_high", c.d_high),
            ("spread", c.spread),
        ] {
            assert!(
                (num(row, column) - value).abs() <= 1e-11 * value.abs().max(1.0),
                "{column}: {row:?}"
            );
        }
        assert_eq!(num(row, "overlaps") as usize, c.overlaps);
        assert!(c.overlaps > 0);
        // The cut-off's growth: the cut-off law of each length's pooled sizes (as
        // compare_alternatives fits it on this test's reading), through fit_cutoff_scaling.
        let (lengths, fits): (Vec<f64>, Vec<_>) = sets
            .iter()
            .filter_map(|(l, runs)| {
                let pooled: Vec<f64> = runs.concat();
                compare_alternatives(&pooled, Support::Discrete, &fit)
                    .ok()
                    .map(|c| (*l, c.cutoff))
            })
            .unzip();
        match fit_cutoff_scaling(&lengths, &fits, 0.95) {
            Ok(g) => {
                growths += 1;
                assert_eq!(num(row, "cutoff_lengths") as usize, g.lengths);
                for (column, value) in [
                    ("cutoff_exponent", g.exponent),
                    ("cutoff_exponent_low", g.exponent_low),
                    ("cutoff_exponent_high", g.exponent_high),
                    ("cutoff_prefactor", g.prefactor),
                ] {
                    assert!(
                        (num(row, column) - value).abs() <= 1e-11 * value.abs().max(1.0),
                        "{column}: {row:?}"
                    );
                }
            }
            Err(_) => assert_eq!(row["cutoff_exponent"], "", "{row:?}"),
        }
    }
    // At least one row fits the cut-off's growth, so the columns are checked.
    assert!(growths > 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_finite_size_study_files_are_the_documented_study() {
    // Issue 54's study: Lx 35 to 560 mm at Ly = 7 mm, Ly 7 to 28 mm at Lx = 140 mm, 1 mm
    // cells, the calibration block's load per area (3500 N on 140 x 7 mm), 50 realizations.
    use precursors::sweep::Sweep;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sweeps/finite_size");
    for (name, lengths) in [
        (
            "lx.json",
            vec![
                (0.035, 0.007),
                (0.07, 0.007),
                (0.14, 0.007),
                (0.28, 0.007),
                (0.56, 0.007),
            ],
        ),
        ("ly.json", vec![(0.14, 0.007), (0.14, 0.014), (0.14, 0.028)]),
    ] {
        let sweep = Sweep::from_json_file(dir.join(name)).unwrap();
        assert_eq!(sweep.runs().len(), 50 * lengths.len(), "{name}");
        for (point, (lx, ly)) in lengths.iter().enumerate() {
            let run = sweep.runs().iter().find(|r| r.point() == point).unwrap();
            let scene = run.scene();
            let grid = scene.grid().unwrap();
            let b = grid.block();
            assert_eq!((b.lx(), b.ly()), (*lx, *ly), "{name}");
            assert!((grid.dx() - 0.001).abs() < 1e-12 && (grid.dy() - 0.001).abs() < 1e-12);
            let json: serde_json::Value = serde_json::from_str(&scene.to_json().unwrap()).unwrap();
            let pressure = json["normal_load"].as_f64().unwrap() / (lx * ly);
            assert!(
                (pressure / (3500.0 / (0.14 * 0.007)) - 1.0).abs() < 1e-12,
                "{name}"
            );
        }
    }
}

#[test]
fn the_contact_rules_study_files_pair_the_rod_study() {
    // docs/contact-rules.md: each rule's sweep is the rod study's (examples/sweeps/
    // statistics/rod.json) with only `contact` changed, so realization r has the same
    // heights under every rule and the paper rule's rows are the rod study's.
    use precursors::sweep::Sweep;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sweeps");
    let rod = Sweep::from_json_file(root.join("statistics/rod.json")).unwrap();
    let json = |sweep: &Sweep, r: usize| -> serde_json::Value {
        serde_json::from_str(&sweep.runs()[r].scene().to_json().unwrap()).unwrap()
    };
    for (name, rule) in [("anchored", "anchored"), ("rejuvenation", "rejuvenation")] {
        let path = root.join(format!("contact-rules/{name}.json"));
        let sweep = Sweep::from_json_file(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        assert_eq!(sweep.runs().len(), rod.runs().len(), "{name}");
        for r in [0, 17, 49] {
            let mut scene = json(&sweep, r);
            assert_eq!(scene["contact"]["rule"], rule, "{name}");
            scene.as_object_mut().unwrap().remove("contact");
            assert_eq!(scene, json(&rod, r), "{name}: realization {r}");
        }
    }
}

#[test]
fn the_friction_map_study_files_are_the_documented_ensembles() {
    // docs/contact-rules.md, "Heterogeneous friction under a top load": the calibration
    // block under the top drive, without a map (20 runs) and with a Gaussian friction map
    // of mean 0.5 and spread 0.05, 0.1, 0.2 at five correlation lengths, 20 maps each.
    use precursors::sweep::Sweep;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sweeps/contact-rules");
    let json = |sweep: &Sweep, r: usize| -> serde_json::Value {
        serde_json::from_str(&sweep.runs()[r].scene().to_json().unwrap()).unwrap()
    };
    let uniform = Sweep::from_json_file(root.join("friction_map_uniform.json")).unwrap();
    assert_eq!(uniform.runs().len(), 20);
    let scene = json(&uniform, 0);
    assert_eq!(scene["drive"]["kind"], "top");
    assert!(scene.get("maps").is_none());
    for spread in [0.05, 0.1, 0.2] {
        let name = format!("friction_map_{spread}.json");
        let sweep =
            Sweep::from_json_file(root.join(&name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(sweep.runs().len(), 100, "{name}");
        let lengths: Vec<f64> = (0..5)
            .map(|p| {
                json(&sweep, 20 * p)["maps"]["friction_coefficient"]["correlation_length"]
                    .as_f64()
                    .unwrap()
            })
            .collect();
        assert_eq!(lengths, [0.002, 0.005, 0.01, 0.02, 0.04], "{name}");
        for r in [0, 1, 57] {
            let scene = json(&sweep, r);
            assert_eq!(scene["drive"]["kind"], "top", "{name}");
            let map = &scene["maps"]["friction_coefficient"];
            assert_eq!(
                (map["mean"].as_f64(), map["std_dev"].as_f64()),
                (Some(0.5), Some(spread))
            );
            assert_eq!(scene["block"], json(&uniform, 0)["block"], "{name}");
            assert_eq!(
                scene["normal_load"],
                json(&uniform, 0)["normal_load"],
                "{name}"
            );
        }
        // Each realization draws its own map.
        let seed = |r: usize| json(&sweep, r)["maps"]["friction_coefficient"]["seed"].clone();
        assert_ne!(seed(0), seed(1), "{name}");
    }
}

/// The fixture of tests/data/statistics/make_lr_fixtures.py: each case's samples and the
/// values scipy computed on them.
fn lr_fixture() -> Vec<(String, Vec<f64>, HashMap<String, f64>)> {
    let dir = Path::new("tests/data/statistics");
    let mut cases: Vec<(String, Vec<f64>, HashMap<String, f64>)> = Vec::new();
    let text = std::fs::read_to_string(dir.join("lr_samples.csv")).unwrap();
    for line in text.lines().skip(1) {
        let (case, value) = line.split_once(',').unwrap();
        if cases.last().is_none_or(|c| c.0 != case) {
            cases.push((case.to_string(), Vec::new(), HashMap::new()));
        }
        cases.last_mut().unwrap().1.push(value.parse().unwrap());
    }
    let text = std::fs::read_to_string(dir.join("lr_expected.csv")).unwrap();
    for line in text.lines().skip(1) {
        let mut cells = line.split(',');
        let (case, quantity, value) = (
            cells.next().unwrap(),
            cells.next().unwrap(),
            cells.next().unwrap(),
        );
        let entry = cases.iter_mut().find(|c| c.0 == case).unwrap();
        entry.2.insert(quantity.to_string(), value.parse().unwrap());
    }
    assert_eq!(cases.len(), 8);
    cases
}

/// Every law fitted on the whole sample (`min_tail` = its size, so `x_min` is its smallest
/// value), against scipy's fits of the same samples (make_lr_fixtures.py: its own
/// likelihoods, normalised by quadrature or direct sums, maximised by L-BFGS-B and
/// Nelder-Mead). Tolerances: both sides maximise to about 1e-12 in log-likelihood per
/// sample and normalise to about 1e-12 relative, so log-likelihoods and `R` (sums over 1000
/// samples, of order 1e3) agree to 1e-6 absolute; fitted parameters sit where the
/// likelihood is flat (an error `δ` in a parameter costs `δ²` in likelihood), so they agree
/// to 1e-4 relative (the discrete power law's `α`, from scipy's bounded scalar search, to
/// 1e-7: it stops at about 1e-8); Vuong's statistic divides `R` by its spread, both of first
/// order in those errors when `R` is near 0, so 1e-4 relative; p-values, which follow, 1e-4
/// relative or 1e-12 absolute.
#[test]
fn alternatives_agree_with_an_independent_scipy_fit() {
    use precursors::statistics::{compare_alternatives, PowerLawOptions, Support};
    let mut failures = Vec::new();
    for (case, samples, expected) in lr_fixture() {
        let support = if case.starts_with("discrete") {
            Support::Discrete
        } else {
            Support::Continuous
        };
        let options = PowerLawOptions::default()
            .bootstrap(0)
            .goodness_samples(0)
            .min_tail(samples.len());
        let c = compare_alternatives(&samples, support, &options).unwrap();
        let mut check = |quantity: &str, got: f64, abs: f64, rel: f64| {
            let want = expected[quantity];
            let ok = if want.is_infinite() {
                got == want
            } else {
                (got - want).abs() <= abs + rel * want.abs()
            };
            if !ok {
                failures.push(format!("{case} {quantity}: {got} vs scipy {want}"));
            }
        };
        check("x_min", c.power_law.x_min, 0.0, 0.0);
        check("power_law_alpha", c.power_law.alpha, 0.0, 1e-7);
        check("power_law_ll", c.power_law_log_likelihood, 1e-6, 0.0);
        check("exponential_lambda", c.exponential.lambda, 0.0, 1e-6);
        check("exponential_ll", c.exponential.log_likelihood, 1e-6, 0.0);
        check("lognormal_ll", c.lognormal.log_likelihood, 1e-6, 0.0);
        check("lognormal_mu", c.lognormal.mu, 1e-4, 1e-4);
        check("lognormal_sigma", c.lognormal.sigma, 0.0, 1e-4);
        check("cutoff_ll", c.cutoff.log_likelihood, 1e-6, 0.0);
        check("cutoff_alpha", c.cutoff.alpha, 1e-4, 1e-4);
        check("cutoff_lambda", c.cutoff.lambda, 1e-10, 1e-4);
        for (name, lr) in [
            ("vs_exponential", &c.vs_exponential),
            ("vs_lognormal", &c.vs_lognormal),
            ("vs_cutoff", &c.vs_cutoff),
            ("cutoff_vs_lognormal", &c.cutoff_vs_lognormal),
        ] {
            check(&format!("{name}_R"), lr.log_ratio, 1e-6, 0.0);
            check(&format!("{name}_normalized"), lr.normalized, 1e-6, 1e-4);
            check(&format!("{name}_p"), lr.p_value, 1e-12, 1e-4);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Samples of `p(x) ∝ x^(-α) e^(-λx)` above `x_min` (reals), or the same law on the
/// integers (`discrete`), by rejection from a power law (rand_distr's Pareto and Zeta:
/// samplers independent of the crate).
fn cutoff_samples(alpha: f64, lambda: f64, n: usize, discrete: bool, seed: u64) -> Vec<f64> {
    use rand::{RngExt, SeedableRng};
    use rand_distr::{Distribution, Pareto, Zeta};
    let mut r = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
    let pareto = Pareto::new(1.0, alpha - 1.0).unwrap();
    let zeta = Zeta::new(alpha).unwrap();
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let x: f64 = if discrete {
            zeta.sample(&mut r)
        } else {
            pareto.sample(&mut r)
        };
        if r.random::<f64>() < (-lambda * (x - 1.0)).exp() {
            out.push(x);
        }
    }
    out
}

/// Tests that can fail: each law's samples are preferred to the wrong laws, over ten
/// sample sets each (the tail fixed at the whole sample). A test of level 0.1 rejects a
/// true pure power law in about 1 set of 10; the bounds allow 3.
#[test]
fn likelihood_ratios_prefer_the_law_the_samples_come_from() {
    use precursors::statistics::{compare_alternatives, PowerLawOptions, Support};
    use rand::SeedableRng;
    use rand_distr::{Distribution, Exp};
    let n = 2000;
    let options = PowerLawOptions::default()
        .bootstrap(0)
        .goodness_samples(0)
        .min_tail(n);
    let (mut cut_found, mut pure_kept, mut exp_found) = ([0; 2], [0; 2], [0; 2]);
    for seed in 0..10 {
        for (i, support) in [Support::Continuous, Support::Discrete]
            .into_iter()
            .enumerate()
        {
            let discrete = support == Support::Discrete;
            // A cut-off law (α 1.5, 1/λ 100 or 50): the cut-off law wins, over the
            // pure law (Wilks) and over the log-normal is not required (Clauset et al.
            // find the two often indistinguishable).
            let xs = cutoff_samples(1.5, if discrete { 0.02 } else { 0.01 }, n, discrete, seed);
            let c = compare_alternatives(&xs, support, &options).unwrap();
            assert!(c.vs_cutoff.log_ratio <= 0.0 && c.vs_cutoff.nested);
            if c.vs_cutoff.p_value < 0.1 {
                cut_found[i] += 1;
                assert!(
                    c.verdict().contains("cut-off law preferred over power law"),
                    "{}",
                    c.verdict()
                );
                assert!((c.cutoff.alpha - 1.5).abs() < 0.3, "{:?}", c.cutoff);
            }
            // A pure power law (α 2.5 and 2.2): the cut-off is not needed.
            let xs = cutoff_samples(
                if discrete { 2.2 } else { 2.5 },
                0.0,
                n,
                discrete,
                100 + seed,
            );
            let c = compare_alternatives(&xs, support, &options).unwrap();
            pure_kept[i] += usize::from(c.vs_cutoff.p_value >= 0.1);
            assert!(c.vs_exponential.log_ratio > 0.0 && c.vs_exponential.p_value < 0.1);
            // Exponential samples (rate 1 above 1; geometric above 1 for integers).
            let exp = Exp::new(if discrete { 0.3f64 } else { 1.0 }).unwrap();
            let mut r = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(200 + seed);
            let xs: Vec<f64> = (0..n)
                .map(|_| {
                    let e = exp.sample(&mut r);
                    if discrete {
                        1.0 + e.floor()
                    } else {
                        1.0 + e
                    }
                })
                .collect();
            let c = compare_alternatives(&xs, support, &options).unwrap();
            exp_found[i] +=
                usize::from(c.vs_exponential.log_ratio < 0.0 && c.vs_exponential.p_value < 0.1);
        }
    }
    assert_eq!(cut_found, [10, 10], "cut-off found");
    assert!(
        pure_kept.iter().all(|&k| k >= 7),
        "pure laws kept: {pure_kept:?}"
    );
    assert_eq!(exp_found, [10, 10], "exponentials found");
}

/// The comparison's power law is `fit_power_law`'s bit for bit (the bootstrap shares its
/// streams), the cut-off law's bootstrap interval holds its estimate, and the result does
/// not depend on the samples' order.
#[test]
fn the_comparison_extends_the_power_law_fit_reproducibly() {
    use precursors::statistics::{compare_alternatives, fit_power_law, PowerLawOptions, Support};
    let options = PowerLawOptions::default()
        .bootstrap(30)
        .goodness_samples(10)
        .seed(9);
    for (support, discrete) in [(Support::Continuous, false), (Support::Discrete, true)] {
        let mut xs = cutoff_samples(1.5, 0.02, 1500, discrete, 31);
        let c = compare_alternatives(&xs, support, &options).unwrap();
        let fit = fit_power_law(&xs, support, &options).unwrap();
        assert_eq!(format!("{:?}", c.power_law), format!("{fit:?}"));
        let cut = &c.cutoff;
        assert!(
            cut.alpha_low <= cut.alpha && cut.alpha <= cut.alpha_high,
            "{cut:?}"
        );
        assert!(
            cut.cutoff_low <= cut.cutoff && cut.cutoff <= cut.cutoff_high,
            "{cut:?}"
        );
        assert!(cut.lambda > 0.0 && (cut.cutoff * cut.lambda - 1.0).abs() < 1e-15);
        xs.reverse();
        xs.swap(3, 700);
        let again = compare_alternatives(&xs, support, &options).unwrap();
        assert_eq!(format!("{again:?}"), format!("{c:?}"));
    }
}

/// `per_avalanche.csv`'s potency and slip centroid against the driver's own shear
/// displacements, read here at each avalanche's `load_raised` (the state before it at its
/// starting load) and at its `stable` state, summed by this test. The released energy
/// against two independent facts. Under a top load (`e = 0`) it is `½ F Δ⟨u_x⟩` with the
/// driver's `mean_shear_displacement`. And under any force drive it is bounded below by
/// what the state before it gives: at a fixed load the potential `Π = E - W` of the
/// system after the avalanche (its springs and their stiffnesses) is convex in `u`, its
/// minimum at most its value at the displacements `u_b` before, which is `Π_before` less
/// the energy `½ k_b u_b² ΔA` of the springs it removed (broken, detached), plus
/// `½ (k_a - k_b) u_b² ΔA` of those that stayed (the normal equilibrium changes their
/// `k_x`) and `½ k_a u_b² ΔA` of those that attached. So the release `Π_b - Π_a` is at
/// least the removed energy less those two. Under a driving spring the energy is not given.
#[test]
fn potency_slip_centroid_and_released_energy_follow_the_slip() {
    use precursors::{Drive, Lateral};
    let base = || {
        Scene::builder()
            .block(0.024, 0.004, 0.012)
            .cells(24, 4)
            .normal_load(60.0)
            .seed(3)
    };
    let spring = Drive::Spring {
        stiffness: 4e6,
        lateral: Lateral::Side,
    };
    /// A state as this test reads it from the driver.
    struct Snapshot {
        u: Vec<f64>,
        k: Vec<f64>,
        mean: f64,
    }
    for (name, drive) in [
        ("rod", Drive::default()),
        ("top", Drive::top()),
        ("spring", spring),
    ] {
        let scene = base().drive(drive).build().unwrap();
        let dir = scratch(&format!("slip-{name}"));
        let mut driver = scene.driver().unwrap();
        let tables = RunTables::create(&dir, &driver).unwrap();
        let area = driver.grid().cell_area();
        let (nx, dx) = (driver.grid().nx(), driver.grid().dx());
        let mut at_raise = Vec::new();
        let mut at_stable = Vec::new();
        tables
            .run_to_slip(&mut driver, None, |event, driver| {
                let snapshot = || {
                    let u_z = driver.normal_displacement().unwrap();
                    Snapshot {
                        u: driver.shear_displacement().unwrap().to_vec(),
                        k: driver.interface().tangential_stiffness(u_z).unwrap(),
                        mean: driver.mean_shear_displacement().unwrap(),
                    }
                };
                match event {
                    Event::LoadRaised { .. } => at_raise.push(snapshot()),
                    Event::Stable { .. } if !at_raise.is_empty() => at_stable.push(snapshot()),
                    _ => {}
                }
            })
            .unwrap();
        let rows = table(&dir.join("per_avalanche.csv"));
        assert_eq!(rows.len(), at_raise.len(), "{name}");
        assert!(rows.len() > 5, "{name}: {} avalanches", rows.len());
        let (mut bounded, mut tight) = (0, 0);
        for (k, row) in rows.iter().enumerate() {
            if row["global_slip"] == "1" {
                for key in ["potency_m3", "slip_centroid_m", "released_energy_J"] {
                    assert_eq!(row[key], "", "{name}: the global slip has no {key}");
                }
                continue;
            }
            let (b, a) = (&at_raise[k], &at_stable[k]);
            let sum = |u: &[f64]| u.iter().sum::<f64>() * area;
            let moment = |u: &[f64]| {
                let m: f64 = u
                    .iter()
                    .enumerate()
                    .map(|(i, u)| ((i % nx) as f64 + 0.5) * dx * u)
                    .sum();
                m * area
            };
            let potency = num(row, "potency_m3");
            let expected = sum(&a.u) - sum(&b.u);
            let scale = sum(&a.u).abs().max(sum(&b.u).abs());
            assert!(
                (potency - expected).abs() <= 1e-8 * scale,
                "{name} avalanche {}: potency {potency:e}, the driver's {expected:e}",
                k + 1
            );
            if expected > 1e-6 * scale {
                let centroid = num(row, "slip_centroid_m");
                let by_slip = (moment(&a.u) - moment(&b.u)) / expected;
                assert!(
                    (centroid - by_slip).abs() <= 1e-5 * 0.024,
                    "{name} avalanche {}: slip centroid {centroid}, the driver's {by_slip}",
                    k + 1
                );
            }
            if name == "spring" {
                assert_eq!(row["released_energy_J"], "", "{name}: no exact balance");
                continue;
            }
            let released = num(row, "released_energy_J");
            let force = num(row, "force_before_N");
            if name == "top" {
                let expected = 0.5 * force * (a.mean - b.mean);
                assert!(
                    (released - expected).abs() <= 1e-8 * (0.5 * force * a.mean.abs()),
                    "{name} avalanche {}: released {released:e}, ½FΔ⟨u⟩ {expected:e}",
                    k + 1
                );
            }
            let (mut removed, mut stiffened, mut attached) = (0.0, 0.0, 0.0);
            for i in 0..b.u.len() {
                let energy = |k: f64| 0.5 * k * b.u[i] * b.u[i] * area;
                match (b.k[i] > 0.0, a.k[i] > 0.0) {
                    (true, false) => removed += energy(b.k[i]),
                    (true, true) => stiffened += energy(a.k[i]) - energy(b.k[i]),
                    (false, true) => attached += energy(a.k[i]),
                    (false, false) => {}
                }
            }
            let bound = removed - stiffened - attached;
            assert!(
                released >= bound - 1e-9 * removed.abs().max(released.abs()),
                "{name} avalanche {}: released {released:e} J below the bound {bound:e} J",
                k + 1
            );
            bounded += 1;
            tight += usize::from(bound > 0.5 * released);
        }
        if name != "spring" {
            assert!(
                bounded > 5 && tight > 0,
                "{name}: {bounded} bounded, {tight} tight"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
