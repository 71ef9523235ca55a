//! The profiles a run records at requested loads (`profiles.csv`, scene key `profiles`,
//! `RunOptions::record_profiles`).
//!
//! The table is checked against a second driver of the same scene read at every stable
//! state through the public observables (`Driver::slip_profile`, the stresses of probes
//! the scene plans itself), with the state in effect at each load chosen here from the
//! whole list of stable states ("the last state at or below the load; none below the
//! first state or at loads the run never passes"), not by the table's incremental rule.
//! Recording must leave the other tables byte for byte as they are, and a resumed run
//! must end with the uninterrupted run's table.

use crate::common::scratch;
use precursors::output::RunTables;
use precursors::{Drive, Error, Event, ProbeSpec, RunOptions, Scene, SceneBuilder};
use std::path::Path;

/// A 20 x 4-cell scene driven by the rod (the default drive) to global slip.
fn builder() -> SceneBuilder {
    Scene::builder()
        .block(0.02, 0.004, 0.01)
        .cell_size(1e-3, 1e-3)
        .normal_load(300.0)
        .seed(5)
}

const LOADS: [f64; 8] = [0.9, 0.0, 0.05, 0.2, 0.45, 0.7, 0.999, 1.0];
const PLANE: f64 = 0.002;

fn options() -> RunOptions {
    RunOptions::new().record_profiles(&LOADS, &[PLANE])
}

fn run(scene: &Scene, options: &RunOptions, dir: &Path) {
    let mut driver = scene.driver().unwrap();
    RunTables::create_with(dir, &driver, options)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
}

/// A stable state read through the public observables: its event, load `F/(μF_N)` and
/// the rows the table should hold for it (field, z, values).
struct State {
    event: usize,
    load: f64,
    rows: Vec<(&'static str, f64, Vec<f64>)>,
}

/// Every stable state of `builder`'s run, and the load of global slip.
fn states(builder: SceneBuilder) -> (Vec<State>, f64) {
    let scene = builder
        .probes(ProbeSpec::default().with_plane(PLANE))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    let mu_fn = driver.friction_coefficient() * driver.normal_load();
    let mut out = Vec::new();
    while let Some(event) = driver.step().unwrap() {
        match event {
            Event::Stable { load, .. } => {
                let slip = driver.slip_profile().unwrap();
                let stresses = driver.stresses().unwrap();
                let p = stresses.planes[0].profile();
                out.push(State {
                    event: driver.event_count(),
                    load: load.force / mu_fn,
                    rows: vec![
                        ("slip_m", 0.0, slip.slip().to_vec()),
                        ("shear_traction_Pa", 0.0, slip.shear_traction().to_vec()),
                        ("normal_traction_Pa", 0.0, slip.normal_traction().to_vec()),
                        ("shear_Pa", PLANE, p.shear().to_vec()),
                        ("normal_Pa", PLANE, p.normal().to_vec()),
                        ("coulomb_of_means_Pa", PLANE, p.coulomb_of_means().to_vec()),
                        ("mean_coulomb_Pa", PLANE, p.mean_coulomb().to_vec()),
                    ],
                });
            }
            Event::GlobalSlip { load } => return (out, load.force / mu_fn),
            _ => {}
        }
    }
    panic!("no global slip");
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-11 * scale.max(a.abs())
}

#[test]
fn the_profiles_are_the_states_in_effect_at_each_load_and_change_no_other_table() {
    let plain = scratch("plain");
    let recorded = scratch("recorded");
    run(&builder().build().unwrap(), &RunOptions::new(), &plain);
    run(&builder().build().unwrap(), &options(), &recorded);
    for name in ["events.csv", "curve.csv", "contact_map.csv"] {
        let a = std::fs::read(plain.join(name)).unwrap();
        let b = std::fs::read(recorded.join(name)).unwrap();
        assert!(a == b, "{name} changed by recording profiles");
    }
    assert!(!plain.join("profiles.csv").exists());

    let (states, slip) = states(builder());
    // Under the rod the loads of the stable states never drop: the state in effect at a
    // load is the last one at or below it, when the run passes the load at all.
    let mut sorted = LOADS.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut expected = Vec::new();
    for &level in &sorted {
        let passed = level < slip && states[0].load <= level;
        if let (true, Some(s)) = (passed, states.iter().rev().find(|s| s.load <= level)) {
            expected.push((level, s));
        }
    }
    // The calibration of the loads: the run passes most of them, not the last ones.
    assert!(
        expected.len() >= 5 && expected.len() < LOADS.len(),
        "{}",
        expected.len()
    );

    let text = std::fs::read_to_string(recorded.join("profiles.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header[..5],
        ["level", "event", "force_over_mu_FN", "field", "z_m"]
    );
    assert_eq!(header.len(), 5 + 20);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), expected.len() * 7);
    for (group, (level, state)) in rows.chunks(7).zip(&expected) {
        for (row, (field, z, values)) in group.iter().zip(&state.rows) {
            assert_eq!(row[0].parse::<f64>().unwrap(), *level);
            assert_eq!(row[1].parse::<usize>().unwrap(), state.event);
            assert!(close(row[2].parse().unwrap(), state.load, 1.0));
            assert_eq!(row[3], *field);
            assert_eq!(row[4].parse::<f64>().unwrap(), *z);
            let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (cell, v) in row[5..].iter().zip(values) {
                let found: f64 = cell.parse().unwrap();
                assert!(
                    close(found, *v, scale),
                    "{field} at {level}: {found} vs {v}"
                );
            }
        }
    }
    std::fs::remove_dir_all(&plain).unwrap();
    std::fs::remove_dir_all(&recorded).unwrap();
}

#[test]
fn under_a_spring_a_load_holds_the_state_in_effect_when_first_passed() {
    // A driving spring: the force drops at each slip, so later states can sit below a
    // load already passed; its rows stay those of the state before the first passage.
    let spring = || {
        builder().drive(Drive::Spring {
            stiffness: 4e5,
            lateral: precursors::Lateral::Rod {
                height: 0.006,
                half_width: 0.001,
            },
        })
    };
    let dir = scratch("spring");
    let loads: Vec<f64> = (0..=20).map(|k| k as f64 / 20.0).collect();
    let options = RunOptions::new().record_profiles(&loads, &[]);
    run(&spring().build().unwrap(), &options, &dir);
    let (states, slip) = states(spring());
    assert!(
        states.windows(2).any(|w| w[1].load < w[0].load),
        "the spring's force never drops: the test does not test the rule"
    );
    let mut expected = Vec::new();
    let mut passed_up_to = f64::NEG_INFINITY;
    for w in 0..states.len() {
        let next = states.get(w + 1).map_or(slip, |s| s.load);
        for &level in &loads {
            if level >= passed_up_to.max(states[0].load) && level < next {
                expected.push((level, states[w].event));
            }
        }
        passed_up_to = passed_up_to.max(next);
    }
    let text = std::fs::read_to_string(dir.join("profiles.csv")).unwrap();
    let found: Vec<(f64, usize)> = text
        .lines()
        .skip(1)
        .step_by(3)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[0].parse().unwrap(), c[1].parse().unwrap())
        })
        .collect();
    assert_eq!(found, expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resumed_profiles_end_as_the_uninterrupted_ones_and_other_loads_are_refused() {
    let scene = builder().run_options(options()).build().unwrap();
    let whole = scratch("whole");
    run(&scene, scene.run_options(), &whole);
    // The same run killed 40 events after a checkpoint at its 15th stable state.
    let cut = scratch("cut");
    let checkpoint = crate::common::killed_after_checkpoint(&scene, &cut, 15, 40);
    // The checkpoint's state passed some loads already: recorded at other loads, the
    // table does not match and is refused, naming it.
    let driver = scene.resume(&checkpoint).unwrap();
    let other = RunOptions::new().record_profiles(&[0.01, 0.02, 0.03], &[PLANE]);
    match RunTables::resume_with(&cut, &driver, &other) {
        Err(Error::CorruptTable { path, reason }) => {
            assert!(path.unwrap().ends_with("profiles.csv.partial"));
            assert!(reason.contains("profiles"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    let mut driver = scene.resume(&checkpoint).unwrap();
    let mut tables = RunTables::resume(&cut, &driver).unwrap();
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
    }
    tables.finish().unwrap();
    for name in ["events.csv", "profiles.csv"] {
        let a = std::fs::read(whole.join(name)).unwrap();
        let b = std::fs::read(cut.join(name)).unwrap();
        assert!(a == b, "{name} differs after resume");
    }
    std::fs::remove_dir_all(&whole).unwrap();
    std::fs::remove_dir_all(&cut).unwrap();
}

#[test]
fn loads_and_planes_out_of_range_are_refused_naming_their_key() {
    for (options, key) in [
        (
            RunOptions::new().record_profiles(&[1.5], &[]),
            "profiles.loads",
        ),
        (
            RunOptions::new().record_profiles(&[f64::NAN], &[]),
            "profiles.loads",
        ),
        (
            RunOptions::new().record_profiles(&[-0.1], &[]),
            "profiles.loads",
        ),
        (
            RunOptions::new().record_profiles(&[0.5], &[0.5]),
            "profiles.planes",
        ),
        (
            RunOptions::new().record_fields(1, &[-1e-3]),
            "fields.planes",
        ),
    ] {
        match builder().run_options(options.clone()).build() {
            Err(Error::OutOfRange { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{other:?}"),
        }
        // Given to the tables directly: refused before anything is written.
        let dir = scratch("refused");
        let driver = builder().build().unwrap().driver().unwrap();
        match RunTables::create_with(&dir, &driver, &options) {
            Err(Error::OutOfRange { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{other:?}"),
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// The `<text>` contents of an SVG.
#[cfg(feature = "plot")]
fn svg_texts(path: &Path) -> Vec<String> {
    let svg = std::fs::read_to_string(path).unwrap();
    svg.split("<text")
        .skip(1)
        .map(|rest| {
            let tail = rest.split_once('>').unwrap().1;
            tail.split_once("</text>")
                .unwrap()
                .0
                .trim_matches('\n')
                .to_string()
        })
        .collect()
}

#[cfg(feature = "plot")]
#[test]
fn plot_draws_a_curve_per_recorded_load_and_the_fig7_stresses() {
    use precursors::plot::{draw, Format};
    let dir = scratch("figures");
    let options = RunOptions::new().record_profiles(&[0.2, 0.5, 0.8], &[0.0, PLANE]);
    run(&builder().build().unwrap(), &options, &dir);
    let drawn = draw(&dir, &[Format::Svg]).unwrap();
    let names: Vec<String> = drawn
        .files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for name in [
        "slip_profiles",
        "shear_profiles",
        "normal_profiles",
        "coulomb_profiles",
    ] {
        assert!(
            names.contains(&format!("{name}.svg")),
            "{name} not in {names:?}"
        );
    }
    // The loads the table holds (read here from profiles.csv), one legend entry each.
    let text = std::fs::read_to_string(dir.join("profiles.csv")).unwrap();
    let mut levels: Vec<String> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    levels.dedup();
    assert_eq!(levels.len(), 3, "{levels:?}");
    // "F/(μF_N) = 0.2" typeset: "F/(μF", the subscript "N", then ") = 0.2".
    let labels: Vec<String> = levels
        .iter()
        .map(|l| format!(") = {}", l.parse::<f64>().unwrap()))
        .collect();
    for name in ["slip_profiles", "shear_profiles", "normal_profiles"] {
        let texts = svg_texts(&dir.join(format!("{name}.svg")));
        for label in &labels {
            assert!(texts.contains(label), "{label} not in {name}: {texts:?}");
        }
    }
    let shear = svg_texts(&dir.join("shear_profiles.svg"));
    assert!(shear.iter().any(|t| t.contains("2 mm")), "{shear:?}");
    // Fig. 7: the first recorded load, four curves, τ_C at the interface among them.
    let coulomb = svg_texts(&dir.join("coulomb_profiles.svg"));
    assert!(coulomb.iter().any(|t| t.contains("0.2")), "{coulomb:?}");
    for entry in ["|τ(x, z", "|σ(x, z", "= |τ| - μ|σ|", "averaged over y"] {
        assert!(
            coulomb.iter().any(|t| t.contains(entry)),
            "{entry} not in {coulomb:?}"
        );
    }
    // Without a plane above the interface: the slip profiles only, and a note says why.
    let bare = scratch("bare");
    run(
        &builder().build().unwrap(),
        &RunOptions::new().record_profiles(&[0.5], &[]),
        &bare,
    );
    let drawn = draw(&bare, &[Format::Svg]).unwrap();
    assert!(bare.join("slip_profiles.svg").is_file());
    assert!(!bare.join("shear_profiles.svg").exists());
    assert!(drawn.notes.iter().any(|n| n.contains("profiles.planes")));
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&bare).unwrap();
}

/// `plot` reads `profiles.csv` through its checks: a damaged or foreign table is refused
/// with its file (and line), and no profiles figure is drawn from it.
#[cfg(feature = "plot")]
#[test]
fn plot_refuses_a_damaged_or_foreign_profiles_table() {
    use precursors::plot::{draw_with_options, DrawOptions, Format, PlotError};
    let dir = scratch("damaged");
    let options = RunOptions::new().record_profiles(&[0.2, 0.5], &[PLANE]);
    run(&builder().build().unwrap(), &options, &dir);
    let path = dir.join("profiles.csv");
    let good = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let edit = |line: usize, from: &str, to: &str| {
        let mut l = lines.clone();
        let changed = l[line].replacen(from, to, 1);
        l[line] = &changed;
        l.join("\n") + "\n"
    };
    let damages = [
        ("a row cut", good[..good.len() - 40].to_string()),
        ("a group left out", lines[..8].join("\n") + "\n"),
        (
            "another level",
            edit(1, "2.000000000000e-1", "3.000000000000e-1"),
        ),
        ("a field out of order", edit(1, "slip_m", "shear_Pa")),
        (
            "another plane",
            edit(4, "2.000000000000e-3", "3.000000000000e-3"),
        ),
        (
            "a NaN",
            edit(2, ",0.000000000000e0,", ",0.000000000000e0,NaN,"),
        ),
        ("another state", {
            let event = lines[1].split(',').nth(1).unwrap();
            edit(
                1,
                &format!(",{event},"),
                &format!(",{},", event.parse::<usize>().unwrap() + 1),
            )
        }),
    ];
    let figures = DrawOptions::default()
        .formats(&[Format::Svg])
        .figures(["slip_profiles"]);
    for (what, text) in &damages {
        std::fs::write(&path, text).unwrap();
        match draw_with_options(&dir, &figures) {
            Err(PlotError::Core(Error::CorruptTable { path: Some(p), .. }))
            | Err(PlotError::Core(Error::NonFiniteCell { path: p, .. })) => {
                assert!(p.ends_with("profiles.csv"), "{what}: {p:?}")
            }
            other => panic!("{what}: {other:?}"),
        }
        assert!(!dir.join("slip_profiles.svg").exists(), "{what}");
    }
    // A table the run's scene does not record (another run's) is not drawn from: left
    // out when not named, refused when named.
    let plain = scratch("foreign");
    run(&builder().build().unwrap(), &RunOptions::new(), &plain);
    std::fs::write(plain.join("profiles.csv"), &good).unwrap();
    let drawn = precursors::plot::draw(&plain, &[Format::Svg]).unwrap();
    let names: Vec<String> = drawn
        .files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.contains("profiles")), "{names:?}");
    let e = draw_with_options(&plain, &figures).unwrap_err();
    assert!(matches!(&e, PlotError::FigureUnavailable { .. }), "{e:?}");
    // Whole again: drawn.
    std::fs::write(&path, &good).unwrap();
    draw_with_options(&dir, &figures).unwrap();
    assert!(dir.join("slip_profiles.svg").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&plain).unwrap();
}
