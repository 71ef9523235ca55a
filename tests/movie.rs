//! The recorded fields (`fields.csv`, scene key `fields`) and the movies drawn from them
//! (feature `plot`).
//!
//! The recording is checked against the driver's own observables read at the same states
//! by a second driver (the cells' contact area, the y-averaged Coulomb stress of probes
//! the driver plans itself) and must leave the other tables byte for byte as they are;
//! the movies against a hand-written `fields.csv` whose colours and frame order follow
//! from the palette's documented stops (not from the code that draws them).

use crate::common::scratch;
use precursors::output::RunTables;
use precursors::plot::{Movie, MovieKind, PlotError};
use precursors::{Error, Event, ProbeSpec, RunOptions, Scene, SceneBuilder};
use std::path::{Path, PathBuf};

// The documented file-format names and values (docs/cli.md, docs/sweep-format.md).
const FIELDS_TABLE: &str = "fields.csv";

/// A 20 x 4-cell scene driven by the rod (the default drive) to global slip.
fn builder() -> SceneBuilder {
    Scene::builder()
        .block(0.02, 0.004, 0.01)
        .cell_size(1e-3, 1e-3)
        .normal_load(300.0)
        .seed(5)
}

const PLANES: [f64; 3] = [0.0, 0.002, 0.006];

fn run(scene: &Scene, dir: &Path) {
    let mut driver = scene.driver().unwrap();
    RunTables::create(dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
}

#[test]
fn recording_fields_changes_no_table_and_records_the_drivers_fields() {
    let plain = scratch("plain");
    let recorded = scratch("recorded");
    run(&builder().build().unwrap(), &plain);
    let every = 3;
    let scene = builder()
        .run_options(RunOptions::new().record_fields(every, &PLANES))
        .build()
        .unwrap();
    run(&scene, &recorded);
    for name in ["events.csv", "curve.csv", "contact_map.csv"] {
        let a = std::fs::read(plain.join(name)).unwrap();
        let b = std::fs::read(recorded.join(name)).unwrap();
        assert!(a == b, "{name} differs when fields are recorded");
    }
    assert!(!plain.join(FIELDS_TABLE).exists());

    // The reference: a driver of the scene with the planes as its own probes, read at
    // the 1st, 4th, 7th, ... stable state.
    let probed = builder()
        .probes(
            PLANES
                .iter()
                .fold(ProbeSpec::default(), |s, &z| s.with_plane(z)),
        )
        .build()
        .unwrap();
    let mut driver = probed.driver().unwrap();
    let mut expected: Vec<String> = Vec::new();
    let mut stable = 0;
    let mu_fn = driver.friction_coefficient() * driver.normal_load();
    while let Some(event) = driver.step().unwrap() {
        let Event::Stable { load, .. } = event else {
            continue;
        };
        stable += 1;
        if (stable - 1) % every != 0 {
            continue;
        }
        let head = format!(
            "{},{:.12e},{:.12e}",
            driver.event_count(),
            load.force / mu_fn,
            driver.precursor_length().unwrap() / 0.02
        );
        let area = driver.cell_contact_area().unwrap();
        for iy in 0..4 {
            let cells: Vec<String> = area[iy * 20..(iy + 1) * 20]
                .iter()
                .map(|v| format!("{v:.12e}"))
                .collect();
            expected.push(format!(
                "{head},area_m2,{iy},{:.12e},{}",
                0.0,
                cells.join(",")
            ));
        }
        for (k, plane) in driver.stresses().unwrap().planes.iter().enumerate() {
            let cells: Vec<String> = plane
                .profile()
                .coulomb_of_means()
                .iter()
                .map(|v| format!("{v:.12e}"))
                .collect();
            expected.push(format!(
                "{head},coulomb_Pa,{k},{:.12e},{}",
                PLANES[k],
                cells.join(",")
            ));
        }
    }
    let text = std::fs::read_to_string(recorded.join(FIELDS_TABLE)).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("event,force_over_mu_FN,precursor_over_Lx,field,row,z_m,value_ix0,"));
    assert_eq!(header.split(',').count(), 6 + 20);
    let rows: Vec<&str> = lines.collect();
    assert!(stable > 3 * every, "{stable} stable states");
    assert_eq!(rows.len(), expected.len());
    for (row, want) in rows.iter().zip(&expected) {
        assert_eq!(row, want);
    }
    std::fs::remove_dir_all(&plain).unwrap();
    std::fs::remove_dir_all(&recorded).unwrap();
}

#[test]
fn resumed_fields_end_as_the_uninterrupted_ones_and_another_recording_is_refused() {
    let scene = builder()
        .run_options(RunOptions::new().record_fields(2, &PLANES))
        .build()
        .unwrap();
    let whole = scratch("whole");
    run(&scene, &whole);
    // The same run killed 30 events after a checkpoint at its 12th stable state.
    let cut = scratch("cut");
    let checkpoint = crate::common::killed_after_checkpoint(&scene, &cut, 12, 30);
    // Recorded every 3rd state instead: the table does not match, refused.
    let other = builder()
        .run_options(RunOptions::new().record_fields(3, &PLANES))
        .build()
        .unwrap();
    let driver = other.resume(&checkpoint).unwrap();
    match RunTables::resume(&cut, &driver) {
        Err(Error::CorruptTable { path, reason }) => {
            assert!(path.unwrap().ends_with("fields.csv.partial"));
            assert!(reason.contains("fields.every"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    let mut driver = scene.resume(&checkpoint).unwrap();
    let mut tables = RunTables::resume(&cut, &driver).unwrap();
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
    }
    tables.finish().unwrap();
    for name in ["events.csv", FIELDS_TABLE] {
        let a = std::fs::read(whole.join(name)).unwrap();
        let b = std::fs::read(cut.join(name)).unwrap();
        assert!(a == b, "{name} differs after resume");
    }
    std::fs::remove_dir_all(&whole).unwrap();
    std::fs::remove_dir_all(&cut).unwrap();
}

/// The palette's documented stops (docs: `Palette::Sequential`).
const LOW: [u8; 3] = [255, 255, 217];
const MID: [u8; 3] = [65, 182, 196];
const HIGH: [u8; 3] = [8, 29, 88];

/// A run directory of a 10 x 4-cell scene (a 10 x 4 x 10 mm block) holding a
/// hand-written `fields.csv`: five states; in state `s` the columns `ix <= s` hold `v_s`
/// in every row (0 elsewhere), `v_0 = 1 mm²`, `v_s = 2 mm²` after; one plane (z = 1 mm)
/// with `τ_C = +1 MPa` on columns `ix <= s`, −1 MPa elsewhere. The run's `events.csv` and
/// `curve.csv` are written to match (the movie checks the recording against them): a
/// load raised and six ruptures between states, global slip after the last. Returns the
/// directory and the events of the states.
fn handwritten(name: &str) -> (PathBuf, Vec<usize>) {
    handwritten_on(name, &[0.001])
}

/// [`handwritten`] with the Coulomb stress recorded on `planes` (m), each as its one plane.
fn handwritten_on(name: &str, planes: &[f64]) -> (PathBuf, Vec<usize>) {
    let dir = scratch(name);
    let builder = Scene::builder()
        .block(0.010, 0.004, 0.010)
        .cell_size(1e-3, 1e-3)
        .run_options(RunOptions::new().record_fields(1, planes));
    std::fs::write(dir.join("scene.json"), builder.to_json().unwrap()).unwrap();
    let mut text = String::from("event,force_over_mu_FN,precursor_over_Lx,field,row,z_m");
    for ix in 0..10 {
        text.push_str(&format!(",value_ix{ix}"));
    }
    text.push('\n');
    let events: Vec<usize> = (0..5).map(|s| 1 + 7 * s).collect();
    for (s, &event) in events.iter().enumerate() {
        let v = if s == 0 { 1e-6 } else { 2e-6 };
        let head = format!(
            "{event},{:.12e},{:.12e}",
            0.1 * s as f64 + 0.5,
            0.1 * (s + 1) as f64
        );
        for iy in 0..4 {
            text.push_str(&format!("{head},area_m2,{iy},0"));
            for ix in 0..10 {
                text.push_str(&format!(",{:e}", if ix <= s { v } else { 0.0 }));
            }
            text.push('\n');
        }
        for (k, z) in planes.iter().enumerate() {
            text.push_str(&format!("{head},coulomb_Pa,{k},{z:e}"));
            for ix in 0..10 {
                text.push_str(if ix <= s { ",1e6" } else { ",-1e6" });
            }
            text.push('\n');
        }
    }
    std::fs::write(dir.join(FIELDS_TABLE), text).unwrap();
    let scene = builder.build().unwrap();
    let mu_fn = scene.material().friction_coefficient() * scene.normal_load();
    let mut events_csv = String::from(precursors::output::EVENTS_HEADER);
    let mut curve_csv = String::from(precursors::output::CURVE_HEADER);
    events_csv.push('\n');
    curve_csv.push('\n');
    for (s, &event) in events.iter().enumerate() {
        let x = 0.1 * s as f64 + 0.5;
        let force = format!("{:.12e}", x * mu_fn);
        if s > 0 {
            events_csv.push_str(&format!("{},load_raised,,,{force},,,,0\n", event - 6));
            for k in 1..6 {
                events_csv.push_str(&format!(
                    "{},rupture,{k},1,{force},,1e-9,,0\n",
                    event - 6 + k
                ));
            }
        }
        events_csv.push_str(&format!(
            "{event},stable,,,{force},,,{},0\n",
            if s > 0 { 5 } else { 0 }
        ));
        let ell = 0.1 * (s + 1) as f64;
        curve_csv.push_str(&format!(
            "{event},{force},{x:.12e},,1e-6,{:.12e},{ell:.12e},{s},30,0,1e-9,1e-12,1e-9\n",
            ell * 0.010
        ));
    }
    events_csv.push_str(&format!("30,global_slip,,,{:.12e},,,,0\n", mu_fn));
    std::fs::write(dir.join("events.csv"), events_csv).unwrap();
    std::fs::write(dir.join("curve.csv"), curve_csv).unwrap();
    (dir, events)
}

/// The RGBA pictures a GIF of 900 x 560 shows, frame after frame: each frame drawn over
/// the picture before at its place, its transparent pixels leaving that picture's (the
/// GIF's "keep" disposal); the first frame covers the whole picture.
fn decode_frames(path: &Path) -> Vec<Vec<u8>> {
    let (width, height) = (900, 560);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::io::BufReader::new(std::fs::File::open(path).unwrap()))
        .unwrap();
    assert_eq!((decoder.width(), decoder.height()), (width, height));
    let mut shown = vec![0u8; 4 * width as usize * height as usize];
    let mut out = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        if out.is_empty() {
            assert_eq!(
                (frame.left, frame.top, frame.width, frame.height),
                (0, 0, width, height)
            );
        }
        assert!(frame.left + frame.width <= width && frame.top + frame.height <= height);
        let w = usize::from(frame.width);
        for (k, pixel) in frame.buffer.chunks_exact(4).enumerate() {
            if pixel[3] == 0 {
                continue;
            }
            let (x, y) = (
                usize::from(frame.left) + k % w,
                usize::from(frame.top) + k / w,
            );
            let at = 4 * (y * usize::from(width) + x);
            shown[at..at + 4].copy_from_slice(pixel);
        }
        out.push(shown.clone());
    }
    out
}

/// Pixels within 6 per channel of `rgb` (the GIF's quantisation moves colours a little).
fn near(frame: &[u8], rgb: [u8; 3]) -> usize {
    frame
        .chunks_exact(4)
        .filter(|p| (0..3).all(|c| (p[c] as i32 - rgb[c] as i32).abs() <= 6))
        .count()
}

#[test]
fn a_movie_has_one_frame_per_state_in_order_on_one_colour_scale() {
    let (dir, events) = handwritten("hand1");
    let path = dir.join("s1.gif");
    let report = Movie::new(&dir, MovieKind::ContactArea)
        .save(&path)
        .unwrap();
    assert_eq!((report.frames, report.states, report.stride), (5, 5, 1));
    assert_eq!(report.events, events);
    assert_eq!(report.colour_range, (0.0, 2.0));
    let frames = decode_frames(&path);
    assert_eq!(frames.len(), 5);
    // The plot area is about 660 x 445 pixels (the frame less its margins, title, axes
    // and colour bar): a column of 4 cells about 66 x 445, 29 000 pixels.
    let column = 20_000;
    let (least, most) = (26_000, 32_000);
    // Frame 0: one column at half the scale (the middle stop), nothing at its top: on a
    // scale per frame it would be the top colour.
    assert!(near(&frames[0], MID) > column, "{}", near(&frames[0], MID));
    assert!(near(&frames[0], HIGH) < column / 10);
    // Frame s: s + 1 columns at the top of the scale, in order.
    for (s, frame) in frames.iter().enumerate().skip(1) {
        let high = near(frame, HIGH);
        let low = near(frame, LOW);
        assert!(
            high > (s + 1) * least && high < (s + 1) * most,
            "frame {s}: {high} pixels of the top colour"
        );
        assert!(low > (9 - s) * column, "frame {s}: {low} pixels of zero");
    }
    // Every 2nd state, at most 3 frames: the stride rises to 2, the last state kept.
    let report = Movie::new(&dir, MovieKind::ContactArea)
        .every(2)
        .unwrap()
        .max_frames(3)
        .unwrap()
        .save(&path)
        .unwrap();
    assert_eq!(report.events, [events[0], events[2], events[4]]);
    assert_eq!(decode_frames(&path).len(), 3);
    let report = Movie::new(&dir, MovieKind::ContactArea)
        .max_frames(2)
        .unwrap()
        .save(&path)
        .unwrap();
    assert_eq!(report.events, [events[0], events[4]]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_coulomb_movie_is_red_where_tau_c_is_positive_and_frames_are_titled() {
    let (dir, _) = handwritten("hand2");
    let path = dir.join("s2.gif");
    let report = Movie::new(&dir, MovieKind::CoulombStress)
        .save(&path)
        .unwrap();
    // Symmetric about 0: ±1 MPa are the ends of the diverging palette.
    assert_eq!(report.colour_range, (-1.0, 1.0));
    let (red, blue) = ([178, 24, 43], [33, 102, 172]);
    let frames = decode_frames(&path);
    for (s, frame) in frames.iter().enumerate() {
        // One plane: a column is about 64 x 440 pixels.
        let (r, b) = (near(frame, red), near(frame, blue));
        assert!(
            r > (s + 1) * 20_000 && r < (s + 2) * 30_000,
            "frame {s}: {r} red"
        );
        assert!(b > (9 - s) * 20_000, "frame {s}: {b} blue");
    }
    // A frame as SVG: its title says the load and the precursor length of its state.
    let svg = dir.join("frame.svg");
    Movie::new(&dir, MovieKind::CoulombStress)
        .save_frame(2, &svg)
        .unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    let texts: Vec<&str> = text
        .split("<text")
        .skip(1)
        .filter_map(|t| Some(t.split_once('>')?.1.split_once("</text>")?.0.trim()))
        .collect();
    // The title typeset: `F_N` as F with the subscript N.
    let title = ["F/(μF", "N", ") = 0.700, ℓ/Lx = 0.300  (event 15)"];
    assert!(texts.windows(3).any(|w| w == title), "{texts:?}");
    // The colour bar's label typeset too, and no `_` left in any text.
    let colour = ["τ", "C", "= |τ| − μ|σ| (MPa)"];
    assert!(texts.windows(3).any(|w| w == colour), "{texts:?}");
    assert!(texts.iter().all(|t| !t.contains('_')), "{texts:?}");
    let e = Movie::new(&dir, MovieKind::CoulombStress)
        .save_frame(5, &svg)
        .unwrap_err();
    assert!(matches!(e, PlotError::Figure { .. }), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_directory_without_recorded_fields_is_refused_saying_how_to_record_them() {
    let dir = scratch("without");
    run(&builder().build().unwrap(), &dir);
    let e = Movie::new(&dir, MovieKind::ContactArea)
        .save(dir.join("s1.gif"))
        .unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, PlotError::NoFields { .. }), "{e:?}");
    assert!(text.contains("no fields.csv"), "{text}");
    assert!(text.contains("\"fields\": {\"every\": 1"), "{text}");
    assert!(text.contains("precursors run"), "{text}");
    // The contact area only: the Coulomb stress movie is refused, naming the key.
    let scene = builder()
        .run_options(RunOptions::new().record_fields(4, &[]))
        .build()
        .unwrap();
    run(&scene, &dir);
    Movie::new(&dir, MovieKind::ContactArea)
        .save(dir.join("s1.gif"))
        .unwrap();
    let e = Movie::new(&dir, MovieKind::CoulombStress)
        .save(dir.join("s2.gif"))
        .unwrap_err();
    assert!(e.to_string().contains("fields.planes"), "{e}");
    assert!(!dir.join("s2.gif").exists());
    // Bad options are refused, typed.
    for e in [
        Movie::new(&dir, MovieKind::ContactArea)
            .every(0)
            .unwrap_err(),
        Movie::new(&dir, MovieKind::ContactArea)
            .max_frames(1)
            .unwrap_err(),
        Movie::new(&dir, MovieKind::ContactArea)
            .frame_duration(0.0)
            .unwrap_err(),
        Movie::new(&dir, MovieKind::ContactArea)
            .save(dir.join("s1.png"))
            .unwrap_err(),
        Movie::new(&dir, MovieKind::ContactArea)
            .colour_range(1.0, 1.0)
            .save(dir.join("s1.gif"))
            .unwrap_err(),
    ] {
        assert!(matches!(e, PlotError::Figure { .. }), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "cli")]
#[test]
fn the_program_draws_the_movies_and_refuses_a_directory_without_fields() {
    use std::process::Command;
    let (dir, _) = handwritten("hand3");
    let frames = dir.join("frames");
    let out = Command::new(env!("CARGO_BIN_EXE_precursors"))
        .args(["movie", "--max-frames", "3", "--png-frames"])
        .arg(&frames)
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("3 frames of 5 recorded states"), "{stderr}");
    assert_eq!(decode_frames(&dir.join("contact_area.gif")).len(), 3);
    assert_eq!(decode_frames(&dir.join("coulomb_stress.gif")).len(), 3);
    // `--png-frames`: both movies' frames, numbered, named after their GIFs.
    let mut names: Vec<String> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = ["contact_area", "coulomb_stress"]
        .iter()
        .flat_map(|stem| (0..3).map(move |k| format!("{stem}_{k:04}.png")))
        .collect();
    assert_eq!(names, expected);
    std::fs::remove_file(dir.join(FIELDS_TABLE)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_precursors"))
        .arg("movie")
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("\"fields\""), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_movie_stopped_by_its_progress_writes_nothing() {
    use std::ops::ControlFlow;
    let (dir, _) = handwritten("stopped");
    let path = dir.join("s1.gif");
    let mut seen = Vec::new();
    let outcome = Movie::new(&dir, MovieKind::ContactArea)
        .save_until(&path, |drawn, frames| {
            seen.push((drawn, frames));
            match drawn {
                2 => ControlFlow::Break(()),
                _ => ControlFlow::Continue(()),
            }
        })
        .unwrap();
    assert!(outcome.is_none());
    assert_eq!(seen, [(1, 5), (2, 5)]);
    assert!(!path.exists());
    // Not stopped: the whole movie, as `save` draws it.
    let report = Movie::new(&dir, MovieKind::ContactArea)
        .save_until(&path, |_, _| ControlFlow::Continue(()))
        .unwrap()
        .unwrap();
    assert_eq!(report.frames, 5);
    assert_eq!(decode_frames(&path).len(), 5);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The `<text>` contents of an SVG, in order.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            Some(
                t.split_once('>')?
                    .1
                    .split_once("</text>")?
                    .0
                    .trim()
                    .to_string(),
            )
        })
        .collect()
}

/// The value of attribute `name` of an SVG element's text `element`.
fn attribute(element: &str, name: &str) -> Option<f64> {
    let tail = element.split_once(&format!(" {name}=\""))?.1;
    tail.split_once('"')?.0.parse().ok()
}

/// The `<rect>`s of an SVG filled with `fill` (`#RRGGBB`): x, y, width, height.
fn rects(svg: &str, fill: &str) -> Vec<[f64; 4]> {
    svg.split("<rect")
        .skip(1)
        .map(|r| r.split_once('>').map_or(r, |(e, _)| e))
        .filter(|r| r.contains(&format!("fill=\"{fill}\"")))
        .filter_map(|r| {
            Some([
                attribute(r, "x")?,
                attribute(r, "y")?,
                attribute(r, "width")?,
                attribute(r, "height")?,
            ])
        })
        .collect()
}

/// The fills of the SVG's `<polygon>`s (the colour bar's saturation triangles).
fn polygon_fills(svg: &str) -> Vec<String> {
    svg.split("<polygon")
        .skip(1)
        .filter_map(|p| Some(p.split_once("fill=\"")?.1.split_once('"')?.0.to_string()))
        .collect()
}

/// Movie S2 on unevenly spaced planes (z = 1 and 4 mm of a 10 mm block) at a colour scale
/// of −2 to 0.5 MPa: the hand-written `τ_C = +1 MPa` (columns `ix <= s` in state `s`) lies
/// above the scale, nothing below it. Read back from the frame's SVG: each plane paints the
/// band nearer to it than to the other (0 to 2.5 mm, 2.5 to 10 mm: heights 1 : 3), the z
/// axis ends at the block's top (10 mm, as the x axis at Lx = 10 mm: no tick beyond), the
/// bar carries the top end's triangle only, and the line under the frame gives the
/// frame's share above the scale (3 of 10 columns in state 2), the aspect measured from the
/// cells drawn, and the scene.
#[test]
fn a_coulomb_frame_ends_at_the_block_and_says_its_saturation_aspect_and_scene() {
    let (dir, _) = handwritten_on("uneven_planes", &[0.001, 0.004]);
    let svg_path = dir.join("frame.svg");
    Movie::new(&dir, MovieKind::CoulombStress)
        .colour_range(-2.0, 0.5)
        .save_frame(2, &svg_path)
        .unwrap();
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    // The palette's documented stops: red at the top end, blue at the bottom.
    let red = "#B2182B";
    // Column 0 holds +1 MPa on both planes: two red cells, the lowest x.
    let mut cells = rects(&svg, red);
    let left = cells.iter().map(|r| r[0]).fold(f64::MAX, f64::min);
    cells.retain(|r| r[0] == left && r[2] < 200.0);
    cells.sort_by(|a, b| b[1].total_cmp(&a[1]));
    assert_eq!(cells.len(), 2, "{cells:?}");
    let (lower, upper) = (cells[0], cells[1]);
    let ratio = upper[3] / lower[3];
    assert!((ratio - 3.0).abs() < 0.05, "bands {lower:?} {upper:?}");
    // The two bands tile the axis: 0 to 10 mm is their whole height.
    let axis_pixels = lower[3] + upper[3];
    let texts = svg_texts(&svg);
    let numbers: Vec<f64> = texts
        .iter()
        .filter_map(|t| t.replace('−', "-").parse().ok())
        .collect();
    assert!(numbers.iter().all(|v| *v <= 10.0), "{numbers:?}");
    assert!(
        numbers.iter().filter(|v| **v == 10.0).count() >= 2,
        "{numbers:?}"
    );
    // The bar: the top end's triangle, none at the bottom.
    assert_eq!(polygon_fills(&svg), [red]);
    assert!(
        texts
            .iter()
            .any(|t| t.contains("30.0 % of the cells above 0.5 (up to 1.0)")),
        "{texts:?}"
    );
    assert!(!texts.iter().any(|t| t.contains("below")), "{texts:?}");
    // The aspect: 10 mm of x over the plot's width (10 columns of cells), 10 mm of z over
    // its height.
    let stretch = 10.0 * lower[2] / axis_pixels;
    let expected = format!("not to scale: x drawn {stretch:.1} times stretched against y");
    assert!(
        stretch > 1.05 && texts.iter().any(|t| t.contains(&expected)),
        "{expected} {texts:?}"
    );
    // The scene line: the directory, the block, F_N typeset, the cells and their size.
    let name = dir.file_name().unwrap().to_string_lossy().into_owned();
    let scene = texts
        .iter()
        .position(|t| t.starts_with(&format!("{name}: 10 x 4 x 10 mm, F")))
        .unwrap_or_else(|| panic!("{texts:?}"));
    assert_eq!(texts[scene + 1], "N");
    assert!(
        texts[scene + 2].ends_with(", 10 x 4 cells of 1 mm, 2 planes"),
        "{texts:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A movie within its scale marks nothing: no triangle, no saturation line (the automatic
/// scale of the hand-written contact area is 0 to 2 mm², its largest value).
#[test]
fn a_movie_within_its_scale_marks_no_saturation() {
    let (dir, _) = handwritten("within");
    let svg_path = dir.join("frame.svg");
    Movie::new(&dir, MovieKind::ContactArea)
        .save_frame(4, &svg_path)
        .unwrap();
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(polygon_fills(&svg).is_empty());
    let texts = svg_texts(&svg);
    assert!(!texts.iter().any(|t| t.contains("saturated")), "{texts:?}");
    // A 10 x 4 mm face drawn wider than tall: stretched, and said so.
    assert!(
        texts.iter().any(|t| t.contains("not to scale: y drawn")),
        "{texts:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The colours down the middle of the colour bar of a GIF's first frame: from the bar's
/// top to its bottom, the run of pixels that are neither white nor black.
fn bar_colours(frame: &[u8], x: usize) -> Vec<[u8; 3]> {
    let pixel = |y: usize| {
        let at = 4 * (y * 900 + x);
        [frame[at], frame[at + 1], frame[at + 2]]
    };
    let coloured = |p: [u8; 3]| p != [255, 255, 255] && p.iter().any(|c| *c > 40);
    let start = (0..560).find(|&y| coloured(pixel(y))).unwrap();
    (start..560)
        .map(pixel)
        .take_while(|p| coloured(*p))
        .collect()
}

/// A GIF's colour bar shows the sequential palette without bands: along the bar each of
/// the documented stops' channels falls steadily (all three fall from the low stop to the
/// high one), no step between neighbouring pixels is larger than 6 units (a band's edge is
/// tens), and it holds well over a hundred distinct colours (a quantiser that bands it
/// holds a few dozen).
#[test]
fn a_gifs_colour_bar_has_no_bands() {
    let (dir, _) = handwritten("banding");
    let path = dir.join("s1.gif");
    Movie::new(&dir, MovieKind::ContactArea)
        .save(&path)
        .unwrap();
    let frames = decode_frames(&path);
    // The bar is the one-column chart near the right edge: 130 pixels wide with 8 of
    // margin and 80 for its values, so its plot spans about x = 778 to 812.
    let bar = bar_colours(&frames[0], 795);
    assert!(bar.len() > 300, "{} pixels of bar", bar.len());
    let (top, bottom) = (bar[0], bar[bar.len() - 1]);
    let close = |a: [u8; 3], b: [u8; 3]| (0..3).all(|c| (a[c] as i32 - b[c] as i32).abs() <= 3);
    assert!(close(top, HIGH) && close(bottom, LOW), "{top:?} {bottom:?}");
    for w in bar.windows(2) {
        for c in 0..3 {
            // Top to bottom: the colours rise towards the low stop.
            assert!(w[1][c] >= w[0][c], "{:?} then {:?}", w[0], w[1]);
            assert!(
                w[1][c] - w[0][c] <= 6,
                "a band's edge: {:?} then {:?}",
                w[0],
                w[1]
            );
        }
    }
    let mut distinct = bar.clone();
    distinct.dedup();
    assert!(distinct.len() > 150, "{} distinct colours", distinct.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The numbered PNG frames: one per GIF frame, `STEM_0000.png` on, each the frame's size
/// and showing what the GIF shows (within the GIF palette's steps); a directory that
/// cannot be made is refused, typed.
#[test]
fn png_frames_are_numbered_and_show_the_gifs_frames() {
    let (dir, _) = handwritten("pngs");
    let frames_dir = dir.join("frames");
    let path = dir.join("s1.gif");
    let report = Movie::new(&dir, MovieKind::ContactArea)
        .png_frames(&frames_dir)
        .save(&path)
        .unwrap();
    let gif = decode_frames(&path);
    let mut names: Vec<String> = std::fs::read_dir(&frames_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (0..report.frames)
        .map(|k| format!("s1_{k:04}.png"))
        .collect();
    assert_eq!(names, expected);
    for (k, name) in names.iter().enumerate() {
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(frames_dir.join(name)).unwrap(),
        ));
        let mut reader = decoder.read_info().unwrap();
        let mut rgb = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut rgb).unwrap();
        assert_eq!(
            (info.width, info.height, info.color_type),
            (900, 560, png::ColorType::Rgb)
        );
        let alike = rgb
            .chunks_exact(3)
            .zip(gif[k].chunks_exact(4))
            .filter(|(p, g)| (0..3).all(|c| (p[c] as i32 - g[c] as i32).abs() <= 12))
            .count();
        assert!(
            alike as f64 > 0.99 * (900.0 * 560.0),
            "frame {k}: {alike} pixels alike"
        );
    }
    // A file where the directory should be.
    let blocked = dir.join("blocked");
    std::fs::write(&blocked, "a file").unwrap();
    let e = Movie::new(&dir, MovieKind::ContactArea)
        .png_frames(&blocked)
        .save(dir.join("other.gif"))
        .unwrap_err();
    assert!(matches!(e, PlotError::Core(Error::Io { .. })), "{e:?}");
    assert!(!dir.join("other.gif").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A real run's movie (the 20 x 4-cell scene, every stable state, three planes): the GIF
/// has one frame per state at 900 x 560 and stays within 15 kB a frame on average (each
/// frame after the first holds only the pixels that changed: the title's numbers, the
/// cells that changed colour, the front). A GIF of whole frames, each quantised on its
/// own, took about 60 kB a frame (10 MB for the 158 frames of the calibration movie).
#[test]
fn a_runs_movie_stays_within_its_size_budget() {
    let dir = scratch("budget");
    let scene = builder()
        .run_options(RunOptions::new().record_fields(1, &PLANES))
        .build()
        .unwrap();
    run(&scene, &dir);
    for kind in [MovieKind::ContactArea, MovieKind::CoulombStress] {
        let path = dir.join("movie.gif");
        let report = Movie::new(&dir, kind).save(&path).unwrap();
        assert!(report.frames >= 10, "{} frames", report.frames);
        let frames = decode_frames(&path);
        assert_eq!(frames.len(), report.frames);
        let bytes = std::fs::metadata(&path).unwrap().len() as usize;
        assert!(
            bytes < 15_000 * report.frames,
            "{kind:?}: {bytes} bytes for {} frames",
            report.frames
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A map's colour bar starts level with its cells under a title of one line and of two
/// (issue 44: a fixed margin left the bar about 20 px above a map whose title wrapped).
/// Read back from the SVG: the cells (all at the top of the scale, `#081D58`) and the
/// bar's slices (right of the cells) have the same top.
#[test]
fn a_map_colour_bar_is_level_with_the_cells_under_a_wrapped_title() {
    use precursors::plot::{Map, Palette};
    let dir = scratch("bar-top");
    std::fs::create_dir_all(&dir).unwrap();
    let long = "The real contact area per column of a very long scene description, \
                over the whole run, at every recorded state of the interface";
    let mut tops = Vec::new();
    for (name, title) in [("short", "Contact area"), ("long", long)] {
        let path = dir.join(format!("{name}.svg"));
        Map::new(4, 2, vec![1.0; 8])
            .unwrap()
            .labels(title, "x (mm)", "y (mm)", "A_R (mm²)")
            .colour_scale(Palette::Sequential, Some((0.0, 1.0)))
            .save(&path)
            .unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        let cells = rects(&svg, "#081D58");
        assert_eq!(cells.len(), 8, "{name}: {cells:?}");
        let cells_right = cells.iter().map(|r| r[0] + r[2]).fold(0.0, f64::max);
        let cells_top = cells.iter().map(|r| r[1]).fold(f64::INFINITY, f64::min);
        let bar_top = svg
            .split("<rect")
            .skip(1)
            .filter_map(|r| {
                let r = r.split_once('>').map_or(r, |(e, _)| e);
                let x = attribute(r, "x")?;
                (x > cells_right + 1.0 && !r.contains("fill=\"#FFFFFF\"")).then_some(())?;
                attribute(r, "y")
            })
            .fold(f64::INFINITY, f64::min);
        assert!(bar_top.is_finite(), "{name}: no colour bar found");
        assert!(
            (bar_top - cells_top).abs() <= 2.0,
            "{name}: bar top {bar_top}, cells top {cells_top}"
        );
        tops.push(cells_top);
    }
    assert!(
        tops[1] > tops[0] + 10.0,
        "the long title did not wrap: {tops:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
