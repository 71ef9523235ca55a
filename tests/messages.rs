//! The program's messages and exit codes (docs/cli.md): a closed stdout or stderr never
//! panics; messages are Display text in the scene file's spelling, with long values cut;
//! each class of failure has its exit code; `merge` and `plot` refuse non-finite cells and
//! write their files atomically; `info` refuses what `run` refuses.
//!
//! Full and read-only disks are real ones where the machine allows it: a small tmpfs
//! mounted over a directory in a private mount namespace (`unshare -rm`), filled up or
//! remounted read-only. Elsewhere (or with `PRECURSORS_TEST_NO_TMPFS` set) a directory
//! with permissions 0o555 stands for the read-only disk (when they stop this user's
//! writes), else a directory in the way of the file to write.

use crate::common::scratch;
use precursors::SceneBuilder;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A tiny scene: 30 x 5 = 150 cells (a run to global slip: about 10 ms).
const BASE: &str = r#"{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
    "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
    "heights": { "kind": "gaussian", "seed": 0 },
    "normal_load": 500.0,
    "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }"#;

/// A sweep of the tiny scene: one point, two realizations.
fn sweep_text() -> String {
    format!(r#"{{ "base": {BASE}, "axes": [], "realizations": 2, "seed": 5 }}"#)
}

fn program() -> Command {
    crate::common::program::command(&[])
}

use crate::common::program::{path, precursors, stderr};

/// Traces of Rust's `{:?}` or Rust names in a message a user reads.
fn debug_traces(text: &str) -> Vec<&'static str> {
    [
        "::",
        "Some(",
        "Os {",
        "kind:",
        "ZeroPivot",
        "IoError",
        "ImageError",
        "{ index",
    ]
    .into_iter()
    .filter(|t| text.contains(t))
    .collect()
}

/// The write end of a pipe whose read end is closed: every write fails (broken pipe).
fn closed_pipe() -> Stdio {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    writer.into()
}

/// The program's exit code with its stderr a closed pipe (stdout discarded): its messages
/// cannot be written, and it must neither panic (code 101) nor change its code.
fn code_with_closed_stderr(args: &[&str]) -> Option<i32> {
    program()
        .args(args)
        .stdout(Stdio::null())
        .stderr(closed_pipe())
        .status()
        .unwrap()
        .code()
}

#[test]
fn a_closed_stderr_or_stdout_ends_nothing_early() {
    let dir = scratch("pipes");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, BASE).unwrap();
    let out = dir.join("run");
    let code = code_with_closed_stderr(&["run", path(&scene), "--out", path(&out)]);
    assert_eq!(code, Some(0));
    // The run went to global slip: its tables end with it.
    let events = std::fs::read_to_string(out.join("events.csv")).unwrap();
    assert!(events.lines().last().unwrap().contains("global_slip"));
    let bad = dir.join("bad.json");
    std::fs::write(&bad, BASE.replace("normal_load", "normal_lode")).unwrap();
    assert_eq!(code_with_closed_stderr(&["info", path(&bad)]), Some(3));
    let sweep = dir.join("sweep.json");
    std::fs::write(&sweep, sweep_text()).unwrap();
    let sweep_dir = dir.join("sweep");
    let args = [
        "sweep",
        path(&sweep),
        "--out",
        path(&sweep_dir),
        "--jobs",
        "1",
    ];
    assert_eq!(code_with_closed_stderr(&args), Some(0));
    assert_eq!(
        code_with_closed_stderr(&["merge", path(&sweep_dir)]),
        Some(0)
    );
    assert_eq!(code_with_closed_stderr(&["plot", path(&out)]), Some(0));
    assert!(out.join("contact_map.png").is_file());
    // `info` with its stdout closed (`precursors info x | head -0`): quiet, code 0.
    let o = program()
        .args(["info", path(&scene)])
        .stdout(closed_pipe())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn messages_are_display_text_in_the_scene_files_spelling() {
    let dir = scratch("spelling");
    let scene = dir.join("dense.json");
    std::fs::write(
        &scene,
        BASE.replace(
            r#""normal_load""#,
            r#""solver": { "backend": "dense", "threads": 2 }, "normal_load""#,
        ),
    )
    .unwrap();
    let o = precursors(&["run", path(&scene), "--out", path(&dir.join("o"))]);
    assert_eq!(o.status.code(), Some(3));
    let text = stderr(&o);
    assert!(
        text.contains(r#"backend "dense""#) && text.contains("threads 2"),
        "{text}"
    );
    assert_eq!(debug_traces(&text), Vec::<&str>::new(), "{text}");
    // A block 1e308 m wide: whatever refuses it, it says so in words.
    let scene = dir.join("wide.json");
    std::fs::write(
        &scene,
        r#"{ "block": { "lx": 0.14, "ly": 1e308, "lz": 0.075 },
             "cells": { "kind": "count", "nx": 14, "ny": 7 }, "normal_load": 3500.0,
             "drive": { "kind": "rod", "height": 0.006, "half_width": 0.002 } }"#,
    )
    .unwrap();
    let o = precursors(&["run", path(&scene), "--out", path(&dir.join("o")), "-q"]);
    let text = stderr(&o);
    assert_ne!(o.status.code(), Some(0), "{text}");
    assert!(text.contains("error: "), "{text}");
    assert_eq!(debug_traces(&text), Vec::<&str>::new(), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The start of a long message.
fn head(text: &str) -> String {
    text.chars().take(300).collect()
}

/// 1 MiB of one letter.
const LONG: usize = 1 << 20;

#[test]
fn a_long_value_is_cut_in_the_message() {
    let long = "x".repeat(LONG);
    let scenes = [
        // An unknown variant, an unknown key, a string for a number: the parser echoes them.
        BASE.replace(
            r#""normal_load""#,
            &format!(r#""solver": {{ "backend": "{long}" }}, "normal_load""#),
        ),
        BASE.replace(
            r#""normal_load""#,
            &format!(r#""{long}": 1, "normal_load""#),
        ),
        BASE.replace("500.0", &format!(r#""{long}""#)),
    ];
    let dir = scratch("long");
    let cut = format!("... ({LONG} bytes)");
    for text in &scenes {
        // The library's Display leaves the parser's message, the source, out ...
        let e = SceneBuilder::from_json_str(text).unwrap_err();
        assert!(std::error::Error::source(&e).is_some());
        let e = e.to_string();
        assert!(e.len() < 1000, "{} bytes: {}", e.len(), head(&e));
        // ... and the program's message, every line of it, cuts the value it echoes.
        let file = dir.join("scene.json");
        std::fs::write(&file, text).unwrap();
        let o = precursors(&["info", path(&file)]);
        assert_eq!(o.status.code(), Some(3));
        let e = stderr(&o);
        assert!(
            e.len() < 1000 && e.contains(&cut),
            "{} bytes: {}",
            e.len(),
            head(&e)
        );
    }
    // A sweep axis's key, and a table cell that merge reads.
    let sweep = dir.join("sweep.json");
    std::fs::write(
        &sweep,
        format!(r#"{{ "base": {BASE}, "axes": [{{ "key": "{long}", "values": [1] }}] }}"#),
    )
    .unwrap();
    let o = precursors(&["sweep", path(&sweep), "--out", path(&dir.join("s"))]);
    assert_eq!(o.status.code(), Some(3));
    let e = stderr(&o);
    assert!(
        e.len() < 1000 && e.contains(&cut),
        "{} bytes: {}",
        e.len(),
        head(&e)
    );
    let sweep_dir = dir.join("t");
    std::fs::write(&sweep, sweep_text()).unwrap();
    let o = precursors(&["sweep", path(&sweep), "--out", path(&sweep_dir), "-q"]);
    assert_eq!(o.status.code(), Some(0));
    let curve = run_dir(&sweep_dir, 0).join("curve.csv");
    edit_cell(&curve, 2, "precursor_over_Lx", &long);
    let o = precursors(&["merge", path(&sweep_dir)]);
    assert_eq!(o.status.code(), Some(3));
    let e = stderr(&o);
    assert!(
        e.len() < 1000 && e.contains(&cut),
        "{} bytes: {}",
        e.len(),
        head(&e)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The directory of realization `r` of the one point of the sweep in `dir`
/// (docs/sweep-format.md).
fn run_dir(dir: &Path, r: usize) -> PathBuf {
    let run = dir.join(format!("p0000-r{r:04}"));
    assert!(run.is_dir(), "{}", run.display());
    run
}

/// Writes `value` into column `column` of line `line` (1-based; the header is line 1) of
/// the CSV table `file`.
fn edit_cell(file: &Path, line: usize, column: &str, value: &str) {
    let text = std::fs::read_to_string(file).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let k = lines[0].split(',').position(|h| h == column).unwrap();
    let mut cells: Vec<String> = lines[line - 1].split(',').map(String::from).collect();
    cells[k] = value.to_string();
    lines[line - 1] = cells.join(",");
    std::fs::write(file, lines.join("\n") + "\n").unwrap();
}

#[test]
fn merge_and_plot_refuse_non_finite_cells_with_their_place() {
    let dir = scratch("nan");
    let sweep = dir.join("sweep.json");
    std::fs::write(&sweep, sweep_text()).unwrap();
    let out = dir.join("s");
    let o = precursors(&["sweep", path(&sweep), "--out", path(&out), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let run = run_dir(&out, 1);
    let curve = run.join("curve.csv");
    let events = run.join("events.csv");
    let clean_curve = std::fs::read_to_string(&curve).unwrap();
    let clean_events = std::fs::read_to_string(&events).unwrap();
    let slip_line = clean_events.lines().count();
    // (table, line, column, value)
    let cases = [
        (&curve, 3, "force_over_mu_FN", "NaN"),
        (&curve, 2, "real_contact_area_m2", "inf"),
        (&curve, 4, "precursor_over_Lx", "-infinity"),
        (&events, slip_line, "force_N", "NaN"),
    ];
    for (file, line, column, value) in cases {
        edit_cell(file, line, column, value);
        let place = format!("{}, line {line}, column {column}", file.display());
        let o = precursors(&["merge", path(&out)]);
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert!(stderr(&o).contains(&place), "{place}: {}", stderr(&o));
        // plot reads the same tables: of the sweep (merged first) and, for curve.csv, of
        // the run.
        let o = precursors(&["plot", path(&out)]);
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert!(stderr(&o).contains(&place), "{place}: {}", stderr(&o));
        if file == &curve {
            let o = precursors(&["plot", path(&run)]);
            assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
            assert!(stderr(&o).contains(&place), "{place}: {}", stderr(&o));
        }
        std::fs::write(&curve, &clean_curve).unwrap();
        std::fs::write(&events, &clean_events).unwrap();
    }
    // A non-finite value in a contact map cell.
    let map = run.join("contact_map.csv");
    edit_cell(&map, 3, "area_m2_ix7", "nan");
    let o = precursors(&["plot", path(&run)]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("line 3, column area_m2_ix7"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A disk that refuses writes.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Disk {
    /// No space left (ENOSPC).
    Full,
    /// Mounted read-only (EROFS).
    ReadOnly,
}

/// Runs the program with `args`, where `{dir}` stands for a directory holding a copy of
/// `content`, on a small tmpfs that is `disk`, mounted in a private mount namespace:
/// the output and the directory's files afterwards (name and size). `None` when the
/// machine does not allow it (no `unshare`, no user namespaces, no tmpfs).
fn on_small_disk(
    content: &Path,
    disk: Disk,
    args: &[&str],
    scratch: &Path,
) -> Option<(Output, Vec<(String, u64)>)> {
    if std::env::var_os("PRECURSORS_TEST_NO_TMPFS").is_some() {
        return None;
    }
    let mount = scratch.join("mnt");
    std::fs::create_dir_all(&mount).unwrap();
    let probe = Command::new("unshare")
        .args(["-rm", "sh", "-c", "mount -t tmpfs -o size=1m none \"$0\""])
        .arg(&mount)
        .output()
        .ok()?;
    if !probe.status.success() {
        return None;
    }
    let listing = scratch.join("listing");
    let spoil = match disk {
        Disk::Full => "head -c 64m /dev/zero > \"$M/.fill\" 2>/dev/null || true",
        Disk::ReadOnly => "mount -o remount,ro \"$M\"",
    };
    let script = format!(
        "set -e; mount -t tmpfs -o size=16m none \"$M\"; cp -a \"$C\"/. \"$M\"/; {spoil}; \
         set +e; \"$@\"; code=$?; find \"$M\" -mindepth 1 -type f ! -name .fill \
         -printf '%P %s\\n' > \"$L\"; exit $code"
    );
    let args: Vec<String> = args
        .iter()
        .map(|a| a.replace("{dir}", path(&mount)))
        .collect();
    let output = Command::new("unshare")
        .args([
            "-rm",
            "sh",
            "-c",
            &script,
            "sh",
            env!("CARGO_BIN_EXE_precursors"),
        ])
        .args(&args)
        .env("M", &mount)
        .env("C", content)
        .env("L", &listing)
        .output()
        .unwrap();
    let files = std::fs::read_to_string(&listing)
        .unwrap_or_else(|_| panic!("no listing: {}", stderr(&output)))
        .lines()
        .map(|l| {
            let (name, size) = l.rsplit_once(' ').unwrap();
            (name.to_string(), size.parse().unwrap())
        })
        .collect();
    Some((output, files))
}

fn files(dir: &Path) -> Vec<(String, u64)> {
    let mut out: Vec<(String, u64)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.metadata().unwrap().is_file())
        .map(|e| {
            let size = e.metadata().unwrap().len();
            (e.file_name().to_string_lossy().into_owned(), size)
        })
        .collect();
    out.sort();
    out
}

/// Whether permissions 0o555 stop this user writing into a directory (not for root).
fn permissions_stop_writes(scratch: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch.join("probe-555");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    let stopped = std::fs::write(dir.join("x"), "x").is_err();
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    stopped
}

#[test]
fn plot_on_a_read_only_disk_is_an_io_failure_and_leaves_no_file() {
    let dir = scratch("readonly");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, BASE).unwrap();
    let run = dir.join("run");
    let o = precursors(&["run", path(&scene), "--out", path(&run), "-q"]);
    assert_eq!(o.status.code(), Some(0));
    let before = files(&run);
    let (o, after) = match on_small_disk(&run, Disk::ReadOnly, &["plot", "{dir}"], &dir) {
        Some(result) => result,
        None if permissions_stop_writes(&dir) => {
            use std::os::unix::fs::PermissionsExt;
            let mode = |m| std::fs::Permissions::from_mode(m);
            std::fs::set_permissions(&run, mode(0o555)).unwrap();
            let o = precursors(&["plot", path(&run)]);
            std::fs::set_permissions(&run, mode(0o755)).unwrap();
            (o, files(&run))
        }
        None => {
            // Root without a tmpfs: a directory in the way of the first figure.
            std::fs::create_dir(run.join("precursor_length.png")).unwrap();
            let o = precursors(&["plot", path(&run)]);
            std::fs::remove_dir(run.join("precursor_length.png")).unwrap();
            (o, files(&run))
        }
    };
    let text = stderr(&o);
    assert_eq!(o.status.code(), Some(4), "{text}");
    assert!(
        text.starts_with("error: writing figure") && text.contains("precursor_length.png"),
        "{text}"
    );
    assert_eq!(debug_traces(&text), Vec::<&str>::new(), "{text}");
    let mut after = after;
    after.sort();
    assert_eq!(after, before, "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn merge_on_a_full_disk_keeps_the_previous_tables_whole() {
    let dir = scratch("full");
    let sweep = dir.join("sweep.json");
    std::fs::write(&sweep, sweep_text()).unwrap();
    let out = dir.join("s");
    let o = precursors(&["sweep", path(&sweep), "--out", path(&out), "-q"]);
    assert_eq!(o.status.code(), Some(0));
    let o = precursors(&["merge", path(&out)]);
    assert_eq!(o.status.code(), Some(0));
    let tables = ["curves.csv", "slip.csv", "avalanches.csv", "runs.csv"];
    let sizes: Vec<(String, u64)> = files(&out)
        .into_iter()
        .filter(|(name, _)| tables.contains(&name.as_str()))
        .collect();
    assert_eq!(sizes.len(), 4);
    // One table older (it must stay whole), the others not written yet (they must not
    // appear empty). Rewriting a file in place on a full tmpfs can reuse the pages its
    // truncation frees: only new files show the full disk to the old in-place writes.
    std::fs::write(out.join("curves.csv"), "old\n").unwrap();
    for name in &tables[1..] {
        std::fs::remove_file(out.join(name)).unwrap();
    }
    let (o, after) = match on_small_disk(&out, Disk::Full, &["merge", "{dir}"], &dir) {
        Some(result) => result,
        None => {
            // No tmpfs here: a directory in the way of the second table (a failure to
            // write it, not a full disk).
            std::fs::create_dir(out.join("slip.csv")).unwrap();
            let o = precursors(&["merge", path(&out)]);
            (o, files(&out))
        }
    };
    let text = stderr(&o);
    assert_eq!(o.status.code(), Some(4), "{text}");
    assert_eq!(debug_traces(&text), Vec::<&str>::new(), "{text}");
    // Each table is the old one or a complete new one: never empty, never half, and no
    // temporary file is left.
    assert!(after.iter().any(|(n, _)| n == "curves.csv"), "{after:?}");
    for (name, size) in &after {
        // Hidden files are temporaries, but for the directories' lock files (kept by
        // design: docs/cli.md, "Guarantees").
        let lock = name == ".precursors.lock" || name.ends_with("/.precursors.lock");
        assert!(lock || !name.starts_with('.'), "{name} left: {after:?}");
        let merged = sizes.iter().find(|(n, _)| n == name);
        if name == "curves.csv" {
            let merged = merged.unwrap().1;
            assert!(*size == 4 || *size == merged, "{after:?} vs {sizes:?}");
        } else if let Some(old) = merged {
            assert_eq!(*size, old.1, "{after:?} vs {sizes:?}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn info_refuses_what_run_refuses_and_writes_lengths_plainly() {
    let dir = scratch("info");
    let refused = [
        // The solver's options, the load, the rod's place: checked when the scene is built.
        BASE.replace(
            r#""normal_load""#,
            r#""solver": { "backend": "dense", "threads": 2 }, "normal_load""#,
        ),
        BASE.replace("500.0", "-1.0"),
        BASE.replace(r#""height": 0.004"#, r#""height": 0.0195"#),
    ];
    for (k, text) in refused.iter().enumerate() {
        let scene = dir.join(format!("refused{k}.json"));
        std::fs::write(&scene, text).unwrap();
        let run = precursors(&["run", path(&scene), "--out", path(&dir.join("o")), "-q"]);
        let info = precursors(&["info", path(&scene)]);
        assert_eq!(run.status.code(), Some(3), "{}", stderr(&run));
        assert_eq!(info.status.code(), Some(3), "{}", stderr(&info));
        assert_eq!(stderr(&info), stderr(&run));
    }
    // 140 mm in 200 cells: 0.7 mm each, which 0.14 / 200 rounds to 0.0007000000000000001.
    let scene = dir.join("cells.json");
    std::fs::write(
        &scene,
        BASE.replace(
            r#""kind": "size", "dx": 0.001, "dy": 0.001"#,
            r#""kind": "count", "nx": 200, "ny": 10"#,
        )
        .replace(r#""lx": 0.03, "ly": 0.005"#, r#""lx": 0.14, "ly": 0.007"#),
    )
    .unwrap();
    let o = precursors(&["info", path(&scene)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(
        text.contains("block      0.14 x 0.007 x 0.02 m")
            && text.contains("cells      200 x 10 = 2000 (cell 0.0007 x 0.0007 m)"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `info` prints one line per map the scene gives (docs/cli.md): its key and unit, its
/// kind (a file's path, a random map's correlation length in mm and seed) and its values'
/// mean, standard deviation (over the sites, 1/N), smallest and largest, to the four
/// digits printed. References: a `file` map of `c_x` = 1e12 + i·1e9 N/m³ (i = 0..149:
/// mean 1.0745e12, std 1e9·√((150² − 1)/12)), a `values` map of `c_z` =
/// 1.65e8·(1 + 0.5·(i mod 3)) N/m² (50 sites each of 1.65e8, 2.475e8, 3.3e8: mean
/// 2.475e8, std 0.825e8·√(2/3)), and a drawn μ against the built scene's map, its
/// moments computed here. A scene without maps has no such line.
#[test]
fn info_describes_the_scenes_maps() {
    let dir = scratch("info-maps");
    let sites = 150;
    let c_x: String = (0..sites)
        .map(|i| format!("{}\n", 1e12 + f64::from(i) * 1e9))
        .collect();
    std::fs::write(dir.join("c_x.txt"), c_x).unwrap();
    let c_z: Vec<String> = (0..sites)
        .map(|i| format!("{}", 1.65e8 * (1.0 + 0.5 * f64::from(i % 3))))
        .collect();
    let maps = format!(
        r#""maps": {{
            "friction_coefficient": {{ "kind": "gaussian_surface", "correlation_length": 0.005,
                                       "mean": 0.5, "std_dev": 0.1, "seed": 7 }},
            "c_x": {{ "kind": "file", "path": "c_x.txt" }},
            "c_z": {{ "kind": "values", "values": [{}] }} }},
        "normal_load""#,
        c_z.join(", ")
    );
    let scene = dir.join("maps.json");
    std::fs::write(&scene, BASE.replace(r#""normal_load""#, &maps)).unwrap();
    let o = precursors(&["info", path(&scene)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let line = |start: &str| -> &str {
        let found: Vec<&str> = text.lines().filter(|l| l.starts_with(start)).collect();
        assert_eq!(found.len(), 1, "{start} in {text}");
        found[0]
    };
    // The mean, std, min and max a line gives.
    let moments = |line: &str| -> [f64; 4] {
        let after = |word: &str| -> f64 {
            let tail = line.split_once(&format!(" {word} ")).unwrap().1;
            tail.split([',', ' ']).next().unwrap().parse().unwrap()
        };
        [after("mean"), after("std"), after("min"), after("max")]
    };
    let close = |found: [f64; 4], expected: [f64; 4], what: &str| {
        for (f, e) in found.iter().zip(expected) {
            // Four significant digits: within 5e-4 relative.
            assert!(
                (f - e).abs() <= 5e-4 * e.abs(),
                "{what}: {found:?} vs {expected:?}"
            );
        }
    };
    let c_x = line("map        c_x (N/m³): file c_x.txt; over 150 sites mean ");
    let spread = 1e9 * ((150.0f64 * 150.0 - 1.0) / 12.0).sqrt();
    close(moments(c_x), [1.0745e12, spread, 1e12, 1.149e12], "c_x");
    let c_z = line("map        c_z (N/m²): values; over 150 sites mean ");
    let spread = 0.825e8 * (2.0f64 / 3.0).sqrt();
    close(moments(c_z), [2.475e8, spread, 1.65e8, 3.3e8], "c_z");
    let mu = line(
        "map        friction_coefficient (dimensionless): gaussian_surface (ξ = 5 mm, seed 7); \
         over 150 sites mean ",
    );
    let built = SceneBuilder::from_json_file(&scene)
        .unwrap()
        .build()
        .unwrap();
    let values = built.interface().friction_map().unwrap();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(0.0, f64::max);
    assert!(std > 0.01, "{values:?}");
    close(moments(mu), [mean, std, min, max], "μ");
    // The maps' lines between the contact rule's and the memory's.
    let order: Vec<&str> = text
        .lines()
        .map(|l| l.split_whitespace().next().unwrap_or(""))
        .collect();
    let at = |key: &str| order.iter().position(|k| *k == key).unwrap();
    assert_eq!(
        (at("contact") + 1, at("memory") - 3),
        (at("map"), at("map")),
        "{text}"
    );
    // No maps, no such line.
    let plain = dir.join("plain.json");
    std::fs::write(&plain, BASE).unwrap();
    let o = precursors(&["info", path(&plain)]);
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(!text.lines().any(|l| l.starts_with("map ")), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_without_checkpoint_is_a_command_line_error() {
    let dir = scratch("every");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, BASE).unwrap();
    let out = dir.join("o");
    let o = precursors(&["run", path(&scene), "--out", path(&out), "--every", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--checkpoint"), "{}", stderr(&o));
    assert!(!out.exists());
    let checkpoint = dir.join("c.json");
    let args = ["run", path(&scene), "--out", path(&out), "-q"];
    let o = precursors(
        &[
            &args[..],
            &["--checkpoint", path(&checkpoint), "--every", "5"],
        ]
        .concat(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(checkpoint.is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_file_that_is_not_text_is_invalid_input() {
    let dir = scratch("binary");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, b"\xff\xfe{ \"block\": 1 }").unwrap();
    for command in ["info", "run"] {
        let mut args = vec![command, path(&scene)];
        let out = dir.join("o");
        if command == "run" {
            args.extend(["--out", path(&out)]);
        }
        let o = precursors(&args);
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert!(stderr(&o).contains("scene.json"), "{}", stderr(&o));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The program prints an error and each of its causes once: a missing scene file, sweep
/// file or figure directory's sweep file names the file and the system's message, each
/// once, over the lines `error: ...` and `  caused by: ...`.
#[test]
fn each_cause_is_printed_once() {
    let dir = scratch("causes");
    let missing = dir.join("missing.json");
    let os = std::fs::read(&missing).unwrap_err().to_string();
    let (run_out, sweep_out) = (dir.join("o"), dir.join("s"));
    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("sweep.json"), "{ not json\n").unwrap();
    let cases: [(Vec<&str>, &str, i32); 4] = [
        (vec!["info", path(&missing)], os.as_str(), 4),
        (
            vec!["run", path(&missing), "--out", path(&run_out)],
            os.as_str(),
            4,
        ),
        (
            vec!["sweep", path(&missing), "--out", path(&sweep_out)],
            os.as_str(),
            4,
        ),
        (
            vec!["merge", path(&bad)],
            "key must be a string at line 1 column 3",
            3,
        ),
    ];
    for (args, cause, code) in cases {
        let o = precursors(&args);
        let text = stderr(&o);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {text}");
        assert!(text.starts_with("error: "), "{args:?}: {text}");
        assert_eq!(text.matches(cause).count(), 1, "{args:?}: {text}");
        let file = if args[0] == "merge" {
            bad.join("sweep.json")
        } else {
            missing.clone()
        };
        let file = file.display().to_string();
        assert_eq!(text.matches(file.as_str()).count(), 1, "{args:?}: {text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The seconds of `info`'s "run ~X to global slip" line.
fn info_run_seconds(scene: &str) -> f64 {
    let dir = scratch("estimate");
    let file = dir.join("scene.json");
    std::fs::write(&file, scene).unwrap();
    let out = precursors(&["info", path(&file)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text.lines().find(|l| l.starts_with("run ")).unwrap();
    let mut words = line.split('~').nth(1).unwrap().split_whitespace();
    let value: f64 = words.next().unwrap().parse().unwrap();
    let scale = match words.next().unwrap() {
        "s" => 1.0,
        "min" => 60.0,
        "h" => 3600.0,
        "days" => 86400.0,
        unit => panic!("unit {unit} in {line}"),
    };
    value * scale
}

#[test]
fn info_estimates_the_measured_large_runs_within_a_factor_two() {
    // The whole runs of docs/performance.md, one thread, release build, 1 mm cells, rod
    // drive, paper heights: N = 1e4 (200 x 50, 3.5 MPa) 115-119 s; N = 1e5 (1000 x 100,
    // 1 MPa) 9 200 s on two threads, 1.66-1.69x faster than one thread on its first 500
    // ruptures: about 15 400 s. (On the older machine of those pages, N = 1e4 took 70-76 s.)
    let scene = |lx: f64, ly: f64, pressure: f64| {
        format!(
            r#"{{ "block": {{ "lx": {lx}, "ly": {ly}, "lz": 0.075 }},
            "cells": {{ "kind": "size", "dx": 0.001, "dy": 0.001 }},
            "normal_load": {} }}"#,
            pressure * lx * ly
        )
    };
    for (lx, ly, pressure, measured) in [(0.2, 0.05, 3.5e6, 117.0), (1.0, 0.1, 1e6, 15_400.0)] {
        let estimate = info_run_seconds(&scene(lx, ly, pressure));
        let ratio = estimate / measured;
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{lx} x {ly} m: info estimates {estimate} s, measured about {measured} s"
        );
    }
}

/// `info` and `run` agree on planes near the interface (issue 41): a plane at 1e-6 m or
/// at the smallest positive double is refused by both, naming `fields.planes` (or
/// `probes.planes`) and its valid range, before `run` writes anything; a plane at the
/// range's printed lower end runs.
#[test]
fn info_and_run_agree_on_planes_near_the_interface() {
    let dir = scratch("planes");
    let scene = |planes: &str, key: &str| {
        let text = BASE.trim_end().trim_end_matches('}').to_string()
            + &match key {
                "fields" => format!(r#", "fields": {{ "every": 5, "planes": [{planes}] }} }}"#),
                _ => format!(r#", "probes": {{ "planes": [{planes}] }} }}"#),
            };
        let path = dir.join(format!("{key}-{planes}.json"));
        std::fs::write(&path, text).unwrap();
        path
    };
    for key in ["fields", "probes"] {
        for z in ["1e-6", "5e-324"] {
            let path = scene(z, key);
            let out = dir.join(format!("out-{key}-{z}"));
            let info = precursors(&["info", path_str(&path)]);
            let run = precursors(&["run", path_str(&path), "--out", path_str(&out), "-q"]);
            for o in [&info, &run] {
                let text = stderr(o);
                assert_eq!(o.status.code(), Some(3), "{text}");
                assert!(text.contains(&format!("{key}.planes = {z}")), "{text}");
                assert!(text.contains("the valid range is 0 or ["), "{text}");
            }
            assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
        }
    }
    // The printed lower end runs (the range holds only what runs).
    let text = stderr(&precursors(&["info", path_str(&scene("1e-6", "fields"))]));
    let low = text
        .split("0 or [")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_string();
    let path = scene(&low, "fields");
    let out = dir.join("out-low");
    let o = precursors(&["run", path_str(&path), "--out", path_str(&out), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn path_str(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Messages that named a Rust type, a thread count not asked for, or a range holding the
/// refused value (issue 41 item 10).
#[test]
fn scene_messages_say_what_is_valid() {
    let with = |extra: &str| {
        let text = BASE.trim_end().trim_end_matches('}').to_string() + extra + " }";
        let builder = SceneBuilder::from_json_str(&text);
        match builder {
            Err(e) => crate::common::chain(&e),
            Ok(b) => b.build().unwrap_err().to_string(),
        }
    };
    let text = with(r#", "solver": { "threads": "2" }"#);
    assert!(
        !text.contains("untagged") && !text.contains("ThreadsSpec"),
        "{text}"
    );
    assert!(
        text.contains("solver.threads") && text.contains("\"all\""),
        "{text}"
    );
    // threads 0 asks for one per core: refused with the dense backend where there are
    // several.
    if std::thread::available_parallelism().is_ok_and(|n| n.get() > 1) {
        let text = with(r#", "solver": { "threads": 0, "backend": "dense" }"#);
        assert!(text.contains("solver.threads 0 and \"all\""), "{text}");
    }
    let text = with(r#", "material": { "poisson_ratio": -0.9999991 }"#);
    assert!(text.contains("[-0.999999, 0.5]"), "{text}");
    let text = with(r#", "fields": { "every": 1, "planes": [1e-7] }"#);
    assert!(text.starts_with("fields.planes = 1e-7"), "{text}");
    // A probe point outside the block, and one nearer the interface than its sums reach.
    let text = with(r#", "probes": { "points": [[0.05, 0.002, 0.01]] }"#);
    assert!(
        text.starts_with("probes.points = 0.05") && text.contains("for x"),
        "{text}"
    );
    let text = with(r#", "probes": { "points": [[0.01, 0.002, 1e-300]] }"#);
    assert!(
        text.starts_with("probes.points = 1e-300") && text.contains("0 or ["),
        "{text}"
    );
}

/// `info` says whether the CUDA backend has a GPU: which one, or why none is usable (the
/// libraries or the driver; without the feature, the feature). CI has no GPU.
#[test]
fn info_says_whether_a_gpu_is_usable() {
    let dir = scratch("info-gpu");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, BASE).unwrap();
    let o = precursors(&["info", path(&scene)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("gpu ")).collect();
    assert_eq!(lines.len(), 1, "{text}");
    let gpu = lines[0]
        .strip_prefix("gpu        ")
        .expect("aligned as the others");
    if !cfg!(feature = "cuda") {
        assert_eq!(gpu, "this build has no CUDA backend (feature cuda)");
    } else if let Some(why) = gpu.strip_prefix("none usable: ") {
        assert!(
            why.starts_with("the CUDA backend is unavailable: ") && why.contains("LD_LIBRARY_PATH"),
            "{why}"
        );
    } else {
        assert!(gpu.contains("compute capability"), "{gpu}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `info` names the scene's contact rule (with a re-forming rule's delay) and lists the
/// rules the key takes.
#[test]
fn info_names_the_contact_rule() {
    let dir = scratch("info-contact");
    let scene = dir.join("scene.json");
    let rejuvenation = BASE.replacen(
        "{ \"block\"",
        r#"{ "contact": { "rule": "rejuvenation", "delay": { "stable_states": 3, "load": 0.02 } }, "block""#,
        1,
    );
    for (text, expected) in [
        (BASE, "contact    paper "),
        (
            rejuvenation.as_str(),
            "contact    rejuvenation (delay 3 stable states and 0.02 μF_N) ",
        ),
    ] {
        std::fs::write(&scene, text).unwrap();
        let o = precursors(&["info", path(&scene)]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let out = String::from_utf8(o.stdout).unwrap();
        let line = out
            .lines()
            .find(|l| l.starts_with("contact "))
            .unwrap_or_else(|| panic!("no contact line: {out}"));
        assert!(
            line.starts_with(expected) && line.ends_with("paper, anchored, rejuvenation)"),
            "{line}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene asking for the CUDA backend where it cannot run ends with code 6 and the
/// reason (docs/cli.md), from `run` and `info` alike, with nothing written.
#[test]
fn a_cuda_scene_without_a_gpu_ends_with_code_6() {
    #[cfg(feature = "cuda")]
    if precursors::solver::cuda_device().is_ok() {
        return; // a GPU here: the scene runs (tests/scene_file.rs builds its driver)
    }
    let dir = scratch("cuda-code");
    let scene = dir.join("scene.json");
    let cuda = BASE.replace(
        r#""normal_load""#,
        r#""solver": { "backend": "cuda" }, "normal_load""#,
    );
    std::fs::write(&scene, cuda).unwrap();
    let out = dir.join("o");
    let run = precursors(&["run", path(&scene), "--out", path(&out), "-q"]);
    let info = precursors(&["info", path(&scene)]);
    for o in [&run, &info] {
        assert_eq!(o.status.code(), Some(6), "{}", stderr(o));
        let message = stderr(o);
        assert!(
            message.contains("the CUDA backend is unavailable"),
            "{message}"
        );
        let names = if cfg!(feature = "cuda") {
            "LD_LIBRARY_PATH"
        } else {
            "feature `cuda` is off"
        };
        assert!(message.contains(names), "{message}");
    }
    assert_eq!(stderr(&info), stderr(&run));
    assert!(!out.join("events.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
