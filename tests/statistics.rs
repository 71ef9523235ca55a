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
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    lines
        .map(|l| header.iter().cloned().zip(l.split(',').map(String::from)).collect())
        .collect()
}

fn num(row: &HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key}: {:?}", row[key]))
}

/// The avalanches of `events.csv` as this test reads them: for each `load_raised`, the
/// ruptures, attachments and flash ruptures (a site that attached earlier in the same
/// avalanche) up to the next `stable` or `global_slip`, and the forces at both ends.
#[derive(Debug, PartialEq)]
struct Read {
    start: usize,
    end: usize,
    ruptures: usize,
    attaches: usize,
    flash: usize,
    before: String,
    after: String,
}

fn read_avalanches(events: &[HashMap<String, String>]) -> Vec<Read> {
    let mut out = Vec::new();
    let mut open: Option<(Read, Vec<(String, String)>)> = None;
    for e in events {
        let site = (e["ix"].clone(), e["iy"].clone());
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
                };
                open = Some((read, Vec::new()));
            }
            "rupture" => {
                let (a, attached) = open.as_mut().unwrap();
                a.ruptures += 1;
                a.flash += usize::from(attached.contains(&site));
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
    let dir = scratch("statistics", "calibration");
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
        };
        assert_eq!(&got, e, "avalanche {}", k + 1);
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
    for (f, c) in fronts.iter().zip(&curve) {
        assert_eq!(f["event"], c["event"]);
        assert_eq!(f["precursor_over_Lx"], c["precursor_over_Lx"]);
        let x = num(f, "damage_front_m") / 0.140;
        assert!((x - num(f, "damage_front_over_Lx")).abs() < 1e-12);
        // A multiple of Δx = 1 mm.
        assert!((x * 140.0 - (x * 140.0).round()).abs() < 1e-9);
    }
    for (load, ell, front) in [
        (0.3, 0.021, 0.15),
        (0.5, 0.079, 0.30),
        (0.8, 0.221, 0.52),
        (0.9, 0.336, 0.74),
    ] {
        let row = fronts
            .iter()
            .rfind(|f| num(f, "force_over_mu_FN") <= load)
            .unwrap();
        assert!((num(row, "precursor_over_Lx") - ell).abs() < 0.0015, "{row:?}");
        assert!((num(row, "damage_front_over_Lx") - front).abs() < 0.005, "{row:?}");
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
    let dir = scratch("statistics", "spring");
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
    let dir = scratch("statistics", "observers");
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
        assert!((num(row, "damage_front_m") - x).abs() <= 1e-15, "{row:?} against {x}");
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
