//! The paper's studies as sweep files (`examples/sweeps/`): every file parses, expands to
//! the points and runs its README's table states, and every point is a valid scene (the
//! grid-size guard included) with the sizes, loads and drive of its figure's caption.
//!
//! The references are independent of the files: the counts come from the README's table
//! (checked against the list below), the fixed parameters from the paper's captions
//! (Figs. 5, 6, S4-S9), the points per figure from the figure examples' curves
//! (`examples/fig5_collapse.rs`, `fig6_aspect.rs`, `figS_sizes.rs`), and the 10
//! realizations from the captions of S4-S9 (Figs. 5 and 6 do not say; the examples use 10).

use precursors::green::Planner;
use precursors::sweep::{Sweep, SweepRun};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/sweeps");

/// File, points (curves of the figure), realizations: the paper's and the examples'.
const STUDIES: [(&str, usize, usize); 12] = [
    ("fig5a.json", 5, 10),
    ("fig5b.json", 8, 10),
    ("fig6a.json", 4, 10),
    ("fig6b.json", 4, 10),
    ("fig6c.json", 4, 10),
    ("fig6d.json", 5, 10),
    ("figS4.json", 4, 10),
    ("figS5.json", 4, 10),
    ("figS6.json", 3, 10),
    ("figS7.json", 3, 10),
    ("figS8.json", 3, 10),
    ("figS9.json", 4, 10),
];

/// The README's table: file -> (points, realizations, runs), by the header's names.
fn readme_table() -> BTreeMap<String, (usize, usize, usize)> {
    let text = std::fs::read_to_string(Path::new(DIR).join("README.md")).unwrap();
    let cells = |line: &str| -> Vec<String> {
        line.trim()
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_string())
            .collect()
    };
    let mut lines = text.lines().skip_while(|l| !l.starts_with("| file |"));
    let header = cells(lines.next().expect("README: no table with a `file` column"));
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("README table: no column `{name}` in {header:?}"))
    };
    let (file, points, realizations, runs) =
        (col("file"), col("points"), col("realizations"), col("runs"));
    let mut table = BTreeMap::new();
    for line in lines.skip(1).take_while(|l| l.starts_with('|')) {
        let row = cells(line);
        // `[`fig5a.json`](fig5a.json)` or `fig5a.json`: the name between the first backticks.
        let name = row[file]
            .split('`')
            .nth(1)
            .unwrap_or(&row[file])
            .to_string();
        let number = |c: usize| -> usize {
            row[c]
                .parse()
                .unwrap_or_else(|_| panic!("README row {name}: {:?} is not a count", row[c]))
        };
        let counts = (number(points), number(realizations), number(runs));
        assert!(table.insert(name.clone(), counts).is_none(), "{name} twice");
    }
    table
}

#[test]
fn every_sweep_file_expands_to_its_documented_runs() {
    let table = readme_table();
    let mut files: Vec<String> = std::fs::read_dir(DIR)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json"))
        .collect();
    files.sort();
    let documented: Vec<String> = table.keys().cloned().collect();
    assert_eq!(
        files, documented,
        "files in examples/sweeps vs the README's table"
    );
    let expected: BTreeMap<String, (usize, usize, usize)> = STUDIES
        .iter()
        .map(|&(f, p, r)| (f.to_string(), (p, r, p * r)))
        .collect();
    assert_eq!(
        table, expected,
        "the README's counts drifted from the figures'"
    );
    for (name, &(points, realizations, runs)) in &table {
        let sweep = Sweep::from_json_file(Path::new(DIR).join(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(
            (sweep.points(), sweep.realizations(), sweep.runs().len()),
            (points, realizations, runs),
            "{name}"
        );
    }
}

/// A run's scene as the scene file's JSON (every key written).
fn scene(run: &SweepRun) -> Value {
    serde_json::from_str(&run.scene().to_json().unwrap()).unwrap()
}

fn num(v: &Value, path: &str) -> f64 {
    path.split('.')
        .fold(v, |v, k| &v[k])
        .as_f64()
        .unwrap_or_else(|| panic!("no number at {path} in {v}"))
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// The rod of Figs. 5, 6d and S4-S9: half width Δh = 2 mm, at `h` (m; `None`: any).
fn rod(drive: &Value, h: Option<f64>) -> bool {
    drive["kind"] == "rod"
        && num(drive, "half_width") == 0.002
        && h.is_none_or(|h| num(drive, "height") == h)
}

/// Checks the caption's fixed parameters of one point's scene (sizes in mm, loads in N);
/// returns the parameter the figure varies.
fn check_caption(name: &str, s: &Value) -> f64 {
    let mm = |path: &str| num(s, path) * 1e3;
    let (lx, ly, lz) = (mm("block.lx"), mm("block.ly"), mm("block.lz"));
    let f_n = num(s, "normal_load");
    let drive = &s["drive"];
    let eq = |a: f64, b: f64| close(a, b, 1e-9);
    let side = drive["kind"] == "side";
    // Figs. S4-S8: the rod at h = 6 mm, F_N = 4 kN.
    let s4_8 = rod(drive, Some(0.006)) && f_n == 4000.0;
    let (fixed, varied) = match name {
        // Ly = 7, Lz = 75 mm, h = 6 mm, 100 <= Lx <= 350 mm; F_N with Lx (the example's
        // choice: the calibration scene's pressure, 3.5 kN on 140 x 7 mm).
        "fig5a.json" => (
            rod(drive, Some(0.006))
                && eq(ly, 7.0)
                && eq(lz, 75.0)
                && (100.0..=350.0).contains(&lx)
                && close(f_n / lx, 3500.0 / 140.0, 1e-9),
            lx,
        ),
        // Lx = 140, Ly = 7, Lz = 75 mm, F_N = 3 kN, 2 <= h <= 73 mm.
        "fig5b.json" => {
            let h = mm("drive.height");
            (
                rod(drive, None)
                    && eq(lx, 140.0)
                    && eq(ly, 7.0)
                    && eq(lz, 75.0)
                    && f_n == 3000.0
                    && (2.0..=73.0).contains(&h),
                h,
            )
        }
        // Uniform side shear, F_N = 4 kN: Lx/Ly ≈ 6.1 (Lz = 10 mm), Lx/Lz ≈ 2 (Ly = 7
        // mm), Ly/Lz ≈ 0.36 (Lx = 40 mm).
        "fig6a.json" => (
            side && f_n == 4000.0 && eq(lz, 10.0) && close(lx / ly, 6.1, 0.02),
            lx,
        ),
        "fig6b.json" => (
            side && f_n == 4000.0 && eq(ly, 7.0) && close(lx / lz, 2.0, 0.01),
            lx,
        ),
        "fig6c.json" => (
            side && f_n == 4000.0 && eq(lx, 40.0) && close(ly / lz, 0.36, 0.01),
            ly,
        ),
        // Rod (h = 6, Δh = 2 mm) plus top, F_top = n F_lat; F_N = 2.7 kN, 201 x 7 x 132 mm.
        "fig6d.json" => (
            drive["kind"] == "mixed"
                && rod(&drive["lateral"], Some(0.006))
                && f_n == 2700.0
                && eq(lx, 201.0)
                && eq(ly, 7.0)
                && eq(lz, 132.0),
            num(drive, "ratio"),
        ),
        "figS4.json" => (s4_8 && eq(lx, 41.0) && eq(lz, 132.0), ly),
        "figS5.json" => (s4_8 && eq(lx, 141.0) && eq(ly, 7.0), lz),
        "figS6.json" => (s4_8 && eq(lz, 100.0) && close(lx / ly, 6.0, 0.01), lx),
        "figS7.json" => (s4_8 && eq(ly, 7.0) && close(lx / lz, 4.0, 0.01), lx),
        "figS8.json" => (s4_8 && eq(lx, 141.0) && close(ly / lz, 0.36, 0.01), ly),
        // h/Lz ≈ 0.46 (h varies with Lz), F_N = 4 kN, Lx = 141, Ly = 7 mm.
        "figS9.json" => (
            rod(drive, None)
                && f_n == 4000.0
                && eq(lx, 141.0)
                && eq(ly, 7.0)
                && close(mm("drive.height") / lz, 0.46, 0.03),
            lz,
        ),
        other => panic!("{other}: no caption in this test"),
    };
    assert!(fixed, "{name}: a point differs from the caption: {s}");
    varied
}

#[test]
fn every_point_is_its_captions_scene_on_1_mm_cells() {
    let planner = Planner::new();
    for &(name, points, realizations) in &STUDIES {
        let sweep = Sweep::from_json_file(Path::new(DIR).join(name)).unwrap();
        let mut varied = Vec::new();
        for run in sweep.runs() {
            let s = scene(run);
            // Realizations differ by the seed only.
            assert_eq!(s["heights"]["kind"], "gaussian", "{name}");
            assert_eq!(s["heights"]["seed"], run.seed(), "{name}");
            if run.realization() > 0 {
                continue;
            }
            varied.push(check_caption(name, &s));
            // 1 mm cells (the paper's), within the grid-size guard.
            let grid = run.scene().grid().unwrap_or_else(|e| panic!("{name}: {e}"));
            let block = grid.block();
            assert_eq!(
                (grid.nx(), grid.ny()),
                (
                    (block.lx() / 1e-3).round() as usize,
                    (block.ly() / 1e-3).round() as usize
                ),
                "{name}"
            );
            // Planned and built (a few seconds for all: the largest grid has 3948 cells).
            run.scene()
                .clone()
                .build_with_planner(&planner)
                .unwrap_or_else(|e| panic!("{name} point {}: {e}", run.point()));
        }
        assert_eq!(varied.len(), points, "{name}");
        assert_eq!(sweep.runs().len(), points * realizations, "{name}");
        // The varied parameter grows along the axis: one curve per value.
        assert!(varied.windows(2).all(|w| w[0] < w[1]), "{name}: {varied:?}");
    }
}
