//! Figures (feature `plot`) and the contact-map table they draw from.
//!
//! The map table is checked against its definition recomputed from the driver's states
//! (the column areas of every stable state, the last state at or below each load level);
//! resumed tables against the uninterrupted run's; figures by decoding the PNG (the
//! series' colours are drawn, the text of the embedded font is drawn where the title
//! goes) and by reading the SVG's text.

use crate::common::scratch;
use precursors::output::RunTables;
use precursors::plot::{draw, Format};
use precursors::plot::{Chart, Corner, Map, Palette, PlotError, Style};
use precursors::{Drive, Error, Event, Lateral, Scene, SceneBuilder};
use std::path::Path;

// The documented file-format names and values (docs/cli.md, docs/sweep-format.md).
const CONTACT_MAP_STEP: f64 = 0.005;

/// A 40 x 5-cell rod-driven scene: about 200 events to global slip.
fn scene() -> Scene {
    Scene::builder()
        .block(0.04, 0.005, 0.02)
        .cell_size(1e-3, 1e-3)
        .normal_load(700.0)
        .drive(Drive::Force(precursors::ForceLoad::Lateral(Lateral::Rod {
            height: 4e-3,
            half_width: 1e-3,
        })))
        .seed(3)
        .build()
        .unwrap()
}

/// Decoded RGB pixels, width and height.
fn decode(path: &Path) -> (Vec<u8>, u32, u32) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (buf, info.width, info.height)
}

#[test]
fn the_contact_map_is_the_state_in_effect_at_each_load_level() {
    let scene = scene();
    let dir = scratch("map");
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&dir, &driver).unwrap();
    let mu_fn = driver.friction_coefficient() * driver.normal_load();
    // (event, F/(μF_N), column areas) of every stable state; the slip load.
    let mut states = Vec::new();
    let mut slip = f64::NAN;
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
        match event {
            Event::Stable { load, .. } => states.push((
                driver.event_count(),
                load.force / mu_fn,
                driver.column_contact_area().unwrap(),
            )),
            Event::GlobalSlip { load } => slip = load.force / mu_fn,
            _ => {}
        }
    }
    tables.finish().unwrap();
    assert!(slip > 0.9 && states.len() > 10, "{slip} {}", states.len());
    // The reference: level k·step from the first state's up to the slip load (levels
    // below the load, rounding aside), each with the last stable state at or below it.
    let text = std::fs::read_to_string(dir.join("contact_map.csv")).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert_eq!(header.split(',').count(), 2 + 40);
    assert!(header.starts_with("event,force_over_mu_FN,area_m2_ix0,area_m2_ix1,"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    let mut expected = Vec::new();
    for k in 0u32.. {
        let level = f64::from(k) * CONTACT_MAP_STEP;
        if level >= slip {
            break;
        }
        if let Some(state) = states.iter().rev().find(|s| s.1 <= level + 1e-12) {
            expected.push((level, state));
        }
    }
    assert_eq!(rows.len(), expected.len());
    for (row, (level, (event, _, columns))) in rows.iter().zip(&expected) {
        assert_eq!(row[0], *event as f64, "level {level}");
        assert!((row[1] - level).abs() < 1e-12);
        for (a, b) in row[2..].iter().zip(columns) {
            assert!(
                (a - b).abs() <= 1e-12 * b.abs(),
                "level {level}: {a} vs {b}"
            );
        }
    }
    // The first state is the zero-shear one: its columns are the initial ones.
    assert_eq!(rows[0][1], 0.0);
    for (a, b) in rows[0][2..]
        .iter()
        .zip(driver.initial_column_contact_area())
    {
        assert!((a - b).abs() <= 1e-12 * b.abs());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resumed_tables_end_as_the_uninterrupted_ones() {
    let scene = scene();
    let whole = scratch("whole");
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&whole, &driver).unwrap();
    let mut checkpoint = None;
    let mut stable = 0;
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
        if matches!(event, Event::Stable { .. }) {
            stable += 1;
            if stable == 20 {
                tables.flush().unwrap();
                checkpoint = Some(driver.checkpoint());
            }
        }
    }
    tables.finish().unwrap();
    // The same run, killed some events after the checkpoint (its tables hold rows past
    // it, the last one cut), then resumed.
    let cut = scratch("cut");
    let checkpoint = checkpoint.unwrap();
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&cut, &driver).unwrap();
    for _ in 0..checkpoint.event_count() + 40 {
        let event = driver.step().unwrap().unwrap();
        tables.record(&driver, &event).unwrap();
    }
    tables.flush().unwrap();
    drop(tables);
    let map = cut.join("contact_map.csv.partial");
    let text = std::fs::read_to_string(&map).unwrap();
    std::fs::write(&map, &text[..text.len() - 7]).unwrap();
    let mut driver = scene.resume(&checkpoint).unwrap();
    let mut tables = RunTables::resume(&cut, &driver).unwrap();
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
    }
    tables.finish().unwrap();
    for name in ["events.csv", "curve.csv", "contact_map.csv"] {
        let a = std::fs::read_to_string(whole.join(name)).unwrap();
        let b = std::fs::read_to_string(cut.join(name)).unwrap();
        assert!(a == b, "{name} differs after resume");
    }
    std::fs::remove_dir_all(&whole).unwrap();
    std::fs::remove_dir_all(&cut).unwrap();
}

#[test]
fn a_chart_draws_its_series_and_its_text() {
    let dir = scratch("chart");
    let line: Vec<(f64, f64)> = (0..=20)
        .map(|k| (k as f64 / 20.0, (k as f64 / 20.0).powi(2)))
        .collect();
    let band: Vec<(f64, f64, f64, f64)> = line
        .iter()
        .map(|&(x, y)| (x, 0.5 * y, 0.4 * y, 0.6 * y))
        .collect();
    let titled = dir.join("titled.png");
    Chart::new("A title", "F/(μF_N)", "ℓ/Lx")
        .x_range(0.0, 1.0)
        .y_range(0.0, 1.0)
        .line("first", &line)
        .band("second", &band)
        .legend(Corner::UpperLeft)
        .save(&titled)
        .unwrap();
    let (pixels, w, h) = decode(&titled);
    assert_eq!((w, h), (800, 560));
    let count = |rgb: [u8; 3]| pixels.chunks_exact(3).filter(|p| *p == rgb).count();
    // Tableau blue and red: the first and the second series (lines 2 px wide).
    assert!(count([31, 119, 180]) > 500, "{}", count([31, 119, 180]));
    assert!(count([214, 39, 40]) > 300, "{}", count([214, 39, 40]));
    // The title is drawn in the top band of the picture; without a title that band is
    // white: the embedded font draws text on a machine without fonts.
    let dark_on_top = |pixels: &[u8]| {
        pixels[..(w * 30 * 3) as usize]
            .chunks_exact(3)
            .filter(|p| p.iter().all(|c| *c < 100))
            .count()
    };
    assert!(dark_on_top(&pixels) > 50, "{}", dark_on_top(&pixels));
    let untitled = dir.join("untitled.png");
    Chart::new("", "F/(μF_N)", "ℓ/Lx")
        .x_range(0.0, 1.0)
        .y_range(0.0, 1.0)
        .line("first", &line)
        .save(&untitled)
        .unwrap();
    assert_eq!(dark_on_top(&decode(&untitled).0), 0);
    // SVG: the labels as text.
    let svg = dir.join("chart.svg");
    Chart::new("A title", "F/(μF_N)", "ℓ/Lx")
        .line("first", &line)
        .band("second", &band)
        .save(&svg)
        .unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    let texts: Vec<&str> = text
        .split("<text")
        .skip(1)
        .filter_map(|t| Some(t.split_once('>')?.1.split_once("</text>")?.0.trim()))
        .collect();
    for label in ["A title", "ℓ/Lx", "first", "second", "0.4"] {
        assert!(
            texts.contains(&label),
            "{label} not in the SVG's text: {texts:?}"
        );
    }
    // The x label typeset: `F_N` as F with the subscript N.
    assert!(
        texts.windows(3).any(|w| w == ["F/(μF", "N", ")"]),
        "{texts:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A fixed colour replaces the chart's colouring for its series only, and a dashed line
/// leaves gaps: counted on a horizontal line's pixel row.
#[test]
fn a_styled_series_has_its_colour_and_its_dashes() {
    let dir = scratch("styles");
    let flat = |y: f64| vec![(0.0, y), (1.0, y)];
    let path = dir.join("styles.png");
    Chart::new("", "x", "y")
        .x_range(0.0, 1.0)
        .y_range(0.0, 1.0)
        .line("reference", &flat(0.25))
        .style(Style::new().colour(120, 120, 120).dashed())
        .line("solid", &flat(0.75))
        .save(&path)
        .unwrap();
    let (pixels, w, h) = decode(&path);
    let at = |x: u32, y: u32| {
        let i = 3 * (y * w + x) as usize;
        [pixels[i], pixels[i + 1], pixels[i + 2]]
    };
    // The row (and the one below: 2 px lines) holding most pixels of a colour, and how
    // many of that row's pixels have it.
    let best_row = |rgb: [u8; 3]| {
        (0..h - 1)
            .map(|y| {
                (0..w)
                    .filter(|&x| at(x, y) == rgb || at(x, y + 1) == rgb)
                    .count()
            })
            .max()
            .unwrap()
    };
    let grey = best_row([120, 120, 120]);
    // The second series, the first without a fixed colour, takes the first colour of
    // the chart's turn (Tableau blue), not the second (red).
    let blue = best_row([31, 119, 180]);
    assert_eq!(best_row([214, 39, 40]), 0);
    // The plotting area is about 700 px wide: the solid line covers it, the dashed line
    // (9 px dashes, 6 px gaps) about 60 % of it, plus the legend's samples.
    assert!(blue > 600, "solid line: {blue} px");
    assert!(grey > 300 && grey < 500, "dashed line: {grey} px");
    // Styles that cannot apply are refused.
    let e = Chart::new("t", "x", "y")
        .style(Style::new().dashed())
        .line("a", &flat(0.5))
        .save(dir.join("orphan.png"))
        .unwrap_err();
    assert!(matches!(e, PlotError::Figure { .. }), "{e:?}");
    assert!(e.to_string().contains("before any series"), "{e}");
    let e = Chart::new("t", "x", "y")
        .markers("m", &flat(0.5))
        .style(Style::new().dashed())
        .save(dir.join("markers.png"))
        .unwrap_err();
    assert!(
        e.to_string().contains("markers 'm' have a dashed style"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_map_draws_its_cells_through_the_palette_and_grey_for_nan() {
    let dir = scratch("map-figure");
    // Two cells: the low end and the high end of a diverging scale, and a NaN.
    let path = dir.join("map.png");
    Map::new(3, 1, vec![-1.0, 1.0, f64::NAN])
        .unwrap()
        .labels("t", "x (mm)", "y (mm)", "σ (MPa)")
        .colour_scale(Palette::Diverging, Some((-1.0, 1.0)))
        .save(&path)
        .unwrap();
    let (pixels, ..) = decode(&path);
    let count = |rgb: [u8; 3]| pixels.chunks_exact(3).filter(|p| *p == rgb).count();
    // Each cell covers about a third of the 900 x 560 plot area's ~640 x 440 pixels.
    for rgb in [[33, 102, 172], [178, 24, 43], [200, 200, 200]] {
        assert!(count(rgb) > 50_000, "{rgb:?}: {}", count(rgb));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_figures_are_refused_with_typed_errors() {
    let dir = scratch("bad");
    let e = Chart::new("t", "x", "y")
        .save(dir.join("chart.jpg"))
        .unwrap_err();
    assert!(matches!(e, PlotError::Figure { .. }), "{e:?}");
    assert!(e.to_string().contains(".png or .svg"), "{e}");
    let e = Chart::new("t", "x", "y")
        .x_range(1.0, 0.0)
        .save(dir.join("chart.png"))
        .unwrap_err();
    assert!(e.to_string().contains("x range [1, 0] is invalid"), "{e}");
    let e = Chart::new("t", "x", "y")
        .size(10, 10)
        .save(dir.join("chart.png"))
        .unwrap_err();
    assert!(e.to_string().contains("too small"), "{e}");
    // Drawn in memory first (3 bytes a pixel): a size that would need gigabytes is refused.
    let e = Chart::new("t", "x", "y")
        .size(100_000, 100_000)
        .save(dir.join("chart.png"))
        .unwrap_err();
    assert!(e.to_string().contains("too large"), "{e}");
    assert!(matches!(
        Map::new(3, 2, vec![0.0; 5]),
        Err(PlotError::Core(Error::LengthMismatch {
            expected: 6,
            found: 5,
            ..
        }))
    ));
    assert!(matches!(
        Map::new(0, 2, vec![]),
        Err(PlotError::Core(Error::InvalidCount { .. }))
    ));
    // A directory that is neither a run's nor a sweep's.
    let e = draw(&dir, &[Format::Png]).unwrap_err();
    assert!(e.to_string().contains("neither a sweep directory"), "{e}");
    // A run cut before global slip (its tables still `.partial`): said so.
    let cut = dir.join("cut");
    std::fs::create_dir_all(&cut).unwrap();
    std::fs::write(cut.join("curve.csv.partial"), "event\n").unwrap();
    let e = draw(&cut, &[Format::Png]).unwrap_err();
    assert!(e.to_string().contains("has not reached global slip"), "{e}");
    // A file that cannot be created (its directory is missing): an I/O failure, which
    // names the file.
    let e = Chart::new("t", "x", "y")
        .save(dir.join("missing").join("chart.png"))
        .unwrap_err();
    assert!(matches!(e, PlotError::Core(Error::Io { .. })), "{e:?}");
    assert!(e.to_string().contains("chart.png"), "{e}");
    // Non-finite data is not drawn and does not fail.
    Chart::new("t", "x", "y")
        .line("nan", &[(0.0, f64::NAN), (1.0, 1.0), (f64::INFINITY, 2.0)])
        .save(dir.join("nan.png"))
        .unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_directory_gets_its_five_figures() {
    let scene = scene();
    let dir = scratch("run");
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&dir, &driver).unwrap();
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
    }
    tables.finish().unwrap();
    let drawn = draw(&dir, &[Format::Png, Format::Svg]).unwrap();
    let mut names: Vec<String> = drawn
        .files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "avalanche_sizes.png",
            "avalanche_sizes.svg",
            "contact_area.png",
            "contact_area.svg",
            "contact_map.png",
            "contact_map.svg",
            "fronts.png",
            "fronts.svg",
            "precursor_length.png",
            "precursor_length.svg"
        ]
    );
    // A force-controlled run has no force drops and no spring: neither figure, and
    // notes saying why.
    assert_eq!(drawn.notes.len(), 2, "{:?}", drawn.notes);
    assert!(drawn.notes[0].contains("no force_drops figure"));
    assert!(drawn.notes[1].contains("no stick_slip figure"));
    assert!(drawn.merge.is_none());
    // Without the map table: the four other figures and a note saying why.
    std::fs::remove_file(dir.join("contact_map.csv")).unwrap();
    let drawn = draw(&dir, &[Format::Png]).unwrap();
    assert_eq!(drawn.files.len(), 4);
    assert!(drawn.notes[0].contains("contact_map.csv is missing"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_whose_zero_shear_area_is_zero_is_refused_not_drawn_empty() {
    // An edited curve.csv: A_R(0) = 0 divided every A_R/A_R(0), and the area figure was
    // drawn empty with exit 0 (issue 53). A stable state carries F_N on its contacts, so
    // the table check refuses it, naming the cell.
    let scene = scene();
    let dir = scratch("zero_area");
    let mut driver = scene.driver().unwrap();
    let mut tables = RunTables::create(&dir, &driver).unwrap();
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
    }
    tables.finish().unwrap();
    let curve = std::fs::read_to_string(dir.join("curve.csv")).unwrap();
    for (column, value) in [(4, "0.000000000000e0"), (8, "0")] {
        let edited: String = curve
            .lines()
            .enumerate()
            .map(|(k, line)| {
                let mut cells: Vec<&str> = line.split(',').collect();
                if k == 1 {
                    cells[column] = value;
                }
                cells.join(",") + "\n"
            })
            .collect();
        std::fs::write(dir.join("curve.csv"), edited).unwrap();
        let refused = draw(&dir, &[Format::Png]).unwrap_err();
        let text = refused.to_string();
        assert!(text.contains("line 2") && text.contains("F_N"), "{text}");
        assert!(!dir.join("contact_area.png").exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The `<text>` elements of an SVG: (attributes, content).
fn svg_texts(path: &Path) -> Vec<(String, String)> {
    let svg = std::fs::read_to_string(path).unwrap();
    svg.split("<text")
        .skip(1)
        .map(|rest| {
            let (attributes, tail) = rest.split_once('>').unwrap();
            let content = tail.split_once("</text>").unwrap().0.trim_matches('\n');
            (attributes.to_string(), content.to_string())
        })
        .collect()
}

/// Whether `pieces` (text, is a subscript) follow each other among `texts`, each
/// subscript in a smaller font than the piece before it, all turned to read up
/// (`rotate(270`) when `up`, none turned otherwise. A piece ending in `…` matches a text
/// that starts with the rest.
fn typeset_in(texts: &[(String, String)], pieces: &[(&str, bool)], up: bool) -> bool {
    let size = |attributes: &str| -> f64 {
        let tail = attributes.split_once("font-size=\"").unwrap().1;
        tail.split_once('"').unwrap().0.parse().unwrap()
    };
    texts.windows(pieces.len()).any(|w| {
        w.iter()
            .zip(pieces)
            .all(|((_, t), (p, _))| match p.strip_suffix('…') {
                Some(start) => t.starts_with(start),
                None => t == p,
            })
            && w.iter().all(|(a, _)| a.contains("rotate(270") == up)
            && (1..w.len()).all(|k| !pieces[k].1 || size(&w[k].0) < size(&w[k - 1].0))
    })
}

/// Every text of a run's three figures and of a movie frame is typeset: no `_` of the
/// subscript notation is left in any text, and the labels with subscripts are there as
/// pieces, the subscripts smaller: the x axis (`F/(μF_N)`), the y axis of the area chart
/// and the colour bar of the contact map (reading up), the legends.
#[test]
fn labels_colour_bars_and_legends_are_typeset() {
    let dir = scratch("typeset");
    let mut driver = scene().driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let drawn = draw(&dir, &[Format::Svg]).unwrap();
    assert_eq!(drawn.files.len(), 5);
    for file in &drawn.files {
        for (_, text) in svg_texts(file) {
            assert!(!text.contains('_'), "{}: {text:?}", file.display());
        }
    }
    let texts = |name: &str| svg_texts(&dir.join(name));
    let force = [("F/(μF", false), ("N", true), (")", false)];
    for name in ["precursor_length.svg", "contact_area.svg"] {
        assert!(typeset_in(&texts(name), &force, false), "{name}");
    }
    // The contact map's load axis reads up.
    assert!(typeset_in(&texts("contact_map.svg"), &force, true));
    let ratio = [("A", false), ("R", true), ("/A", false), ("R", true)];
    let area = texts("contact_area.svg");
    assert!(typeset_in(
        &area,
        &[ratio.as_slice(), &[("(0)", false)]].concat(),
        true
    ));
    let legend = [ratio.as_slice(), &[("(0) at the stable states…", false)]].concat();
    assert!(typeset_in(&area, &legend, false), "{area:?}");
    let colour_bar = [
        ("A", false),
        ("R", true),
        ("(x, F)/A", false),
        ("R", true),
        ("(x, 0)", false),
    ];
    assert!(typeset_in(&texts("contact_map.svg"), &colour_bar, true));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An SVG figure carries the embedded font (docs/cli.md, "Figures"): an `@font-face` whose
/// data, decoded here, is the font file in assets/fonts, and a rule setting its family on
/// every text.
#[test]
fn an_svg_carries_the_embedded_font() {
    let dir = scratch("svg-font");
    let line = [(0.0, 0.0), (1.0, 1.0)];
    let path = dir.join("chart.svg");
    Chart::new("T", "x", "y")
        .line("a", &line)
        .save(&path)
        .unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let face = svg.split_once("@font-face{").unwrap().1;
    assert!(
        face.starts_with("font-family:\"precursors-DejaVuSans\""),
        "{face:.80}"
    );
    let data = face
        .split_once("base64,")
        .unwrap()
        .1
        .split_once(')')
        .unwrap()
        .0;
    let alphabet = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let (mut bytes, mut bits, mut held) = (Vec::new(), 0u32, 0u32);
    for c in data.bytes().filter(|&c| c != b'=') {
        let v = alphabet.iter().position(|&a| a == c).unwrap() as u32;
        held = (held << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            bytes.push((held >> bits) as u8);
            held &= (1 << bits) - 1;
        }
    }
    let font = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/fonts/DejaVuSans-subset.ttf"
    ))
    .unwrap();
    assert!(
        bytes == font,
        "{} bytes decoded, {} in the font",
        bytes.len(),
        font.len()
    );
    assert!(svg.contains("text{font-family:\"precursors-DejaVuSans\",\"DejaVu Sans\",sans-serif;}"));
    assert!(svg.contains("font-family=\"DejaVu Sans, sans-serif\""));
    // The size docs/cli.md gives: 68.6 kB added.
    let style = svg
        .split_once("<style>")
        .unwrap()
        .1
        .split_once("</style>")
        .unwrap()
        .0;
    assert_eq!((style.len() + 15) / 100, 686, "{}", style.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn run_figures_say_the_scene_mark_global_slip_and_reach_one_on_the_load_axis() {
    let dir = scratch("scene-title");
    let mut driver = scene().driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let drawn = draw(&dir, &[Format::Svg]).unwrap();
    let texts = |name: &str| {
        svg_texts(
            &drawn
                .files
                .iter()
                .find(|f| f.ends_with(name))
                .unwrap()
                .clone(),
        )
    };
    // The title names the scene of `scene()` (40 x 5 x 20 mm, 700 N, rod at 4 mm, seed 3,
    // 1 mm cells), not the directory; `F_N` typeset: `N` a text of its own, smaller.
    let title: Vec<String> = texts("precursor_length.svg")
        .iter()
        .take(3)
        .map(|(_, t)| t.clone())
        .collect();
    assert_eq!(
        title,
        [
            "Precursor length: 40 x 5 x 20 mm, F",
            "N",
            "= 700 N, rod at h = 4 mm, seed 3, 40 x 5 cells of 1 mm"
        ]
    );
    // Global slip: the load of events.csv's last row over μF_N (μ = 0.5, F_N = 700 N).
    let events = std::fs::read_to_string(dir.join("events.csv")).unwrap();
    let last: Vec<&str> = events.lines().last().unwrap().split(',').collect();
    assert_eq!(last[1], "global_slip");
    let slip = last[4].parse::<f64>().unwrap() / (0.5 * 700.0);
    let legend = [
        ("global slip at F/(μF", false),
        ("N", true),
        (&format!(") = {slip:.3}"), false),
    ];
    assert!(
        typeset_in(&texts("precursor_length.svg"), &legend, false),
        "no legend {legend:?}"
    );
    // The contact map's load axis has a tick at 1.0 although its last row lies below.
    let map = std::fs::read_to_string(dir.join("contact_map.csv")).unwrap();
    let last_row: f64 = map
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        last_row + CONTACT_MAP_STEP / 2.0 < 1.0,
        "last row at {last_row}"
    );
    assert!(texts("contact_map.svg")
        .iter()
        .any(|(a, t)| t == "1.0" && a.contains("text-anchor=\"end\"")));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn figures_take_the_size_asked_for_within_limits() {
    let dir = scratch("size");
    let mut driver = scene().driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let drawn = precursors::plot::draw_with_size(&dir, &[Format::Png], (1200, 840)).unwrap();
    for file in &drawn.files {
        let (_, width, height) = decode(file);
        assert_eq!((width, height), (1200, 840), "{}", file.display());
    }
    for size in [(199, 560), (800, 16385)] {
        let error = precursors::plot::draw_with_size(&dir, &[Format::Png], size).unwrap_err();
        assert!(matches!(error, PlotError::InvalidSize { .. }), "{error:?}");
        assert!(error.to_string().contains("[200, 16384]"), "{error}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The statistics figures show what the run's tables give: `avalanche_sizes` the log-binned
/// sizes of `per_avalanche.csv` (read here, the spanning avalanche and those after it
/// left out) with a counting error bar on every non-empty bin, and the power law with
/// `n_tail`, its goodness p and the preferred model in the legend: computed as `stats`
/// would with its defaults while the directory has no `power_laws.csv`, `stats`' own
/// numbers once it has (read here from the table); on logarithmic axes labelled at the
/// powers of ten; `fronts` both fronts.
#[test]
fn statistics_figures_show_the_runs_fit_and_fronts() {
    use precursors::statistics::{compare_alternatives, PowerLawOptions, Support};
    let dir = scratch("statistics");
    let scene = SceneBuilder::from_json_file(Path::new("examples/scenes/calibration.json"))
        .unwrap()
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    draw(&dir, &[Format::Svg]).unwrap();
    let text = std::fs::read_to_string(dir.join("per_avalanche.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // The avalanches before the spanning one (docs/statistics.md), as `stats` pools them.
    let span = rows
        .iter()
        .position(|r| r[column("spanning")] == "1")
        .unwrap();
    assert!(rows[span + 1..]
        .iter()
        .all(|r| r[column("after_spanning")] == "1"));
    let sizes: Vec<f64> = rows[..span]
        .iter()
        .map(|r| r[column("ruptures")].parse().unwrap())
        .collect();
    // No power_laws.csv: the fits `stats` would write with its default options.
    let c = compare_alternatives(&sizes, Support::Discrete, &PowerLawOptions::default()).unwrap();
    let fit = &c.power_law;
    let p = fit.p_value.unwrap();
    let texts = svg_words(&dir.join("avalanche_sizes.svg"));
    let joined = squash(&texts.concat());
    let status = if p <= 0.1 {
        format!("(rejected, p = {p:.2})")
    } else {
        format!(", p = {p:.2}")
    };
    let legend = format!(
        "power law, S ≥ {}: α = {:.2} [{:.2}, {:.2}], n_{{tail}} = {}{status}",
        fit.x_min, fit.alpha, fit.alpha_low, fit.alpha_high, fit.tail
    );
    assert!(
        joined.contains(&squash(&legend.replace("_{tail}", "tail"))),
        "{legend} not in {texts:?}"
    );
    assert!(
        joined.contains("fitscomputedherewiththedefaultsofstats"),
        "{texts:?}"
    );
    assert!(
        texts.iter().any(|t| t.starts_with("pure power law ")),
        "{texts:?}"
    );
    assert!(texts
        .iter()
        .any(|t| t == &format!("{} avalanche sizes", sizes.len())));
    assert!(texts
        .iter()
        .any(|t| t.starts_with("Distribution of avalanche sizes")));
    // `stats` run (few resamples, to be quick): the figure shows its table's numbers.
    let options = precursors::sweep::StatsOptions::default().fit(
        PowerLawOptions::default()
            .bootstrap(30)
            .goodness_samples(60)
            .seed(5),
    );
    precursors::sweep::statistics(&dir, &options).unwrap();
    draw(&dir, &[Format::Svg]).unwrap();
    let table = read_csv(&dir.join("power_laws.csv"));
    let row = table
        .iter()
        .find(|r| r["observable"] == "avalanche_ruptures")
        .unwrap();
    let cell = |name: &str| row[name].parse::<f64>().unwrap();
    let p = cell("p_value");
    let rejected = p <= 0.1;
    let status = if rejected {
        format!("(rejected, p = {p:.2})")
    } else {
        format!(", p = {p:.2}")
    };
    let legend = format!(
        "power law, S ≥ {}: α = {:.2} [{:.2}, {:.2}], ntail = {}{status}",
        cell("x_min"),
        cell("alpha"),
        cell("alpha_low"),
        cell("alpha_high"),
        row["tail"]
    );
    let svg_path = dir.join("avalanche_sizes.svg");
    let texts = svg_words(&svg_path);
    let joined = squash(&texts.concat());
    assert!(
        joined.contains(&squash(&legend)),
        "{legend} not in {texts:?}"
    );
    assert!(!joined.contains("fitscomputedhere"), "{texts:?}");
    // The verdict, a clause a line: the goodness test, then each law preferred over
    // others, each as the verdict column's tests say (which the figure does not read).
    let verdict = &row["verdict"];
    let goodness = if rejected { "rejected" } else { "not rejected" };
    let p_shown = if p >= 0.01 || p == 0.0 {
        format!("{p:.2}")
    } else {
        format!("{p:.1e}")
    };
    assert!(
        texts.contains(&format!("pure power law {goodness} (p = {p_shown})")),
        "{texts:?}"
    );
    let mut preferred = Vec::new();
    for clause in texts.iter().filter(|t| t.contains(" preferred over ")) {
        let (winner, losers) = clause.trim().split_once(" preferred over ").unwrap();
        for loser in losers.split(" and ") {
            let loser = loser.split(" (p = ").next().unwrap();
            let said = format!("{winner} preferred over {loser}");
            assert!(verdict.contains(&said), "{said} against {verdict}");
        }
        preferred.push(winner.to_string());
    }
    if rejected {
        assert!(!preferred.contains(&"power law".to_string()), "{texts:?}");
    }
    // The laws the tests cannot tell apart from a preferred one are drawn with it.
    let untold = texts
        .iter()
        .find(|t| t.contains("the tests cannot tell "))
        .cloned()
        .unwrap_or_default();
    // The solid curves (2 px, many vertices) in the series' colour: the power law unless
    // rejected (then dashed: short pieces), the cut-off law where it is preferred.
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let blue = "#1F77B4";
    let curves = svg_polylines(&svg, 2)
        .iter()
        .filter(|(stroke, v)| stroke == blue && v.len() > 20)
        .count();
    let cutoff_drawn = (preferred.contains(&"cut-off law".to_string())
        || !preferred.is_empty() && untold.contains("cut-off law"))
        && !row["cutoff_scale"].is_empty();
    assert_eq!(
        curves,
        usize::from(!rejected) + usize::from(cutoff_drawn),
        "{texts:?}"
    );
    assert_eq!(joined.contains("cut-offlaw:α="), cutoff_drawn, "{texts:?}");
    // One error bar (a vertical 1 px line in the series' colour) per non-empty bin of
    // stats' distributions.csv.
    let bins = read_csv(&dir.join("distributions.csv"))
        .iter()
        .filter(|r| r["observable"] == "avalanche_ruptures" && r["count"] != "0")
        .count();
    let bars = svg_polylines(&svg, 1)
        .iter()
        .filter(|(stroke, v)| stroke == blue && v.len() == 2 && v[0].0 == v[1].0)
        .count();
    assert!(bins > 3);
    assert_eq!(bars, bins);
    assert!(
        joined.contains("errorbars:P(1±1/√count),thePoissoncountingerror"),
        "{texts:?}"
    );
    // Log axes: the y axis (the densities span more than two decades) labelled at every
    // power of ten between the binned densities, written 10⁻ⁿ; no "log" in any label.
    let densities: Vec<f64> = precursors::statistics::log_binned(&sizes, Support::Discrete, 5)
        .unwrap()
        .iter()
        .filter(|b| b.count > 0)
        .map(|b| b.density)
        .collect();
    let (low, high) = densities
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), d| (a.min(*d), b.max(*d)));
    assert!(high / low > 100.0, "{densities:?}");
    let superscript = |n: i32| -> String {
        let digits = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
        let sign = if n < 0 { "⁻" } else { "" };
        let magnitude: String = n
            .unsigned_abs()
            .to_string()
            .chars()
            .map(|c| digits[c.to_digit(10).unwrap() as usize])
            .collect();
        format!("10{sign}{magnitude}")
    };
    for n in (low.log10().ceil() as i32)..=(high.log10().floor() as i32) {
        let label = superscript(n);
        assert!(texts.contains(&label), "{label} not in {texts:?}");
    }
    assert!(texts
        .iter()
        .all(|t| !t.replace("log-normal", "").contains("log")));
    let fronts: Vec<String> = svg_texts(&dir.join("fronts.svg"))
        .into_iter()
        .map(|(_, t)| t)
        .collect();
    assert!(fronts
        .iter()
        .any(|t| t.contains("columns with half their contacts lost")));
    assert!(fronts
        .iter()
        .any(|t| t.contains("columns below their zero-shear area")));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The contact map carries ℓ (a solid black line) and the damage front (black dashes)
/// over its cells, and its title says which is which. (Where the lines run is the
/// derivation's, tested in tests/statistics.rs; here: that they are drawn.)
#[test]
fn the_contact_map_carries_both_fronts() {
    let dir = scratch("map-fronts");
    let mut driver = scene().driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    draw(&dir, &[Format::Svg]).unwrap();
    let svg = std::fs::read_to_string(dir.join("contact_map.svg")).unwrap();
    let title: Vec<String> = svg_texts(&dir.join("contact_map.svg"))
        .into_iter()
        .map(|(_, t)| t)
        .collect();
    assert!(title
        .iter()
        .any(|t| t.starts_with("Contact area per column; ℓ solid, x")));
    // Two black polylines of 3 px: the solid one (one path) and the dashes (many).
    let black = svg.matches("stroke=\"#000000\" stroke-width=\"3\"").count();
    assert!(black >= 3, "{black} black lines");
    let fronts = std::fs::read_to_string(dir.join("fronts.csv")).unwrap();
    let moved = fronts
        .lines()
        .skip(1)
        .any(|l| l.split(',').nth(5).unwrap().parse::<f64>().unwrap() > 0.0);
    assert!(
        moved,
        "the damage front never left the trailing edge: {fronts}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The contact map's colour scale ends at twice the zero-shear area: the share of its
/// cells above (each column's area in `contact_map.csv` over the column's area in the
/// first row, the documented `A_R(x, F)/A_R(x, 0)`, counted here from the table) is
/// given under the map with the largest ratio, and the bar carries a triangle in the
/// top colour (the diverging palette's documented red) and none below (no ratio is
/// negative); the note under the map names the two lines and where they come from.
#[test]
fn the_contact_map_marks_the_ratios_above_its_scale() {
    let dir = scratch("map-saturation");
    let mut driver = Scene::builder()
        .block(0.03, 0.005, 0.02)
        .cell_size(1e-3, 1e-3)
        .normal_load(500.0)
        .seed(2)
        .build()
        .unwrap()
        .driver()
        .unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    draw(&dir, &[Format::Svg]).unwrap();
    let table = std::fs::read_to_string(dir.join("contact_map.csv")).unwrap();
    let rows: Vec<Vec<f64>> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(2).map(|v| v.parse().unwrap()).collect())
        .collect();
    let ratios: Vec<f64> = rows
        .iter()
        .flat_map(|row| {
            row.iter()
                .zip(&rows[0])
                .filter(|(_, r)| **r > 0.0)
                .map(|(a, r)| a / r)
        })
        .collect();
    let above = ratios.iter().filter(|v| **v > 2.0).count();
    assert!(
        above > 0,
        "no ratio above 2: the test's scene must reach one"
    );
    let share = 100.0 * above as f64 / ratios.len() as f64;
    let svg = std::fs::read_to_string(dir.join("contact_map.svg")).unwrap();
    let fills: Vec<&str> = svg
        .split("<polygon")
        .skip(1)
        .filter_map(|p| Some(p.split_once("fill=\"")?.1.split_once('"')?.0))
        .collect();
    assert_eq!(fills, ["#B2182B"]);
    let texts: Vec<String> = svg_texts(&dir.join("contact_map.svg"))
        .into_iter()
        .map(|(_, t)| t)
        .collect();
    let line = texts
        .iter()
        .find(|t| t.starts_with("colour scale saturated: "))
        .unwrap_or_else(|| panic!("{texts:?}"));
    let said: f64 = line["colour scale saturated: ".len()..]
        .split_once(" %")
        .unwrap()
        .0
        .parse()
        .unwrap();
    assert!(
        (said - share).abs() <= 0.05 + 1e-9,
        "{line}: {share:.3} % above 2"
    );
    assert!(line.contains("of the cells above 2.0 (up to "), "{line}");
    assert!(!line.contains("below"), "{line}");
    assert!(
        texts
            .iter()
            .any(|t| t.starts_with("solid: ℓ(F)/Lx, the precursor length of curve.csv")),
        "{texts:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A run of a small block (30 x 5 cells of 1 mm, 500 N) driven through a spring on its
/// side, to global slip, in `dir`.
fn spring_run(dir: &Path) {
    let scene = Scene::builder()
        .block(0.03, 0.005, 0.02)
        .cell_size(1e-3, 1e-3)
        .normal_load(500.0)
        .drive(Drive::Spring {
            stiffness: 4e6,
            lateral: Lateral::Side,
        })
        .seed(2)
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    RunTables::create(dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
}

/// `text` without its spaces (an SVG text's leading space is an advance, not a character).
fn squash(text: &str) -> String {
    text.replace(' ', "")
}

/// A CSV table's rows as maps from its header's names to the cells (a quoted cell, with
/// commas or `""` in it, read whole).
fn read_csv(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let split = |line: &str| {
        let mut cells = vec![String::new()];
        let mut quoted = false;
        let mut previous = ' ';
        for c in line.chars() {
            match c {
                '"' if quoted && previous == '"' => {}
                '"' => quoted = !quoted,
                ',' if !quoted => cells.push(String::new()),
                c => cells.last_mut().unwrap().push(c),
            }
            previous = c;
        }
        cells
    };
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = split(lines.next().unwrap());
    lines
        .map(|l| header.iter().cloned().zip(split(l)).collect())
        .collect()
}

/// The texts of an SVG, without their attributes.
fn svg_words(path: &Path) -> Vec<String> {
    svg_texts(path).into_iter().map(|(_, t)| t).collect()
}

/// `stick_slip` (paper Fig. 4) draws, from a spring-driven run's `events.csv`, one point
/// per event with a load (read here from the table: the polyline of the first series
/// has as many vertices), counts the avalanches that drop the force (a stable state
/// below the raise before it, from the table's cells) and marks global slip at its drive
/// displacement and load; the axes are `U_S (µm)` and `F/(μF_N)`.
#[test]
fn stick_slip_draws_the_spring_force_against_the_drive_displacement() {
    use precursors::plot::{draw_with_options, DrawOptions};
    let dir = scratch("stick-slip");
    spring_run(&dir);
    let options = DrawOptions::default()
        .formats(&[Format::Svg])
        .figures(["stick_slip"]);
    let drawn = draw_with_options(&dir, &options).unwrap();
    assert_eq!(drawn.files, [dir.join("stick_slip.svg")]);
    // The reference from events.csv: loaded rows, the force drops, global slip.
    let events = std::fs::read_to_string(dir.join("events.csv")).unwrap();
    let rows: Vec<Vec<&str>> = events
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let loaded: Vec<&Vec<&str>> = rows
        .iter()
        .filter(|r| ["load_raised", "rupture", "stable", "global_slip"].contains(&r[1]))
        .collect();
    assert!(loaded.iter().all(|r| !r[5].is_empty()), "a row without U_S");
    let force = |r: &[&str]| r[4].parse::<f64>().unwrap();
    let (mut drops, mut raised) = (0, None);
    for r in &rows {
        match r[1] {
            "load_raised" => raised = Some(force(r)),
            "stable" => drops += usize::from(raised.take().is_some_and(|f| f > force(r))),
            _ => {}
        }
    }
    assert!(drops > 0, "the spring never dropped the force");
    let last = rows.last().unwrap();
    assert_eq!(last[1], "global_slip");
    let mu_fn = 0.5 * 500.0;
    let u_slip = last[5].parse::<f64>().unwrap() * 1e6;
    let f_slip = force(last) / mu_fn;
    let svg_path = dir.join("stick_slip.svg");
    let texts = svg_texts(&svg_path);
    let words = svg_words(&svg_path);
    assert!(
        words[0].starts_with("Stick-slip: 30 x 5 x 20 mm"),
        "{words:?}"
    );
    assert!(typeset_in(
        &texts,
        &[("U", false), ("S", true), ("(µm)", false)],
        false
    ));
    let force_axis = [("F/(μF", false), ("N", true), (")", false)];
    assert!(typeset_in(&texts, &force_axis, true), "{words:?}");
    let count = format!("at each load step and rupture: {drops} force drops");
    assert!(
        words.iter().any(|t| t.ends_with(&count)),
        "{count} not in {words:?}"
    );
    let slip = [
        ("global slip at U", false),
        ("S", true),
        (&*format!("= {u_slip:.4} µm, F/(μF"), false),
        ("N", true),
        (&*format!(") = {f_slip:.3}"), false),
    ];
    assert!(
        typeset_in(&texts, &slip, false),
        "{slip:?} not in {words:?}"
    );
    // The first series' polyline (Tableau blue): a vertex per loaded event.
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let vertices = svg
        .split("<polyline")
        .skip(1)
        .filter(|p| p.contains("stroke=\"#1F77B4\""))
        .map(|p| {
            let points = p
                .split_once("points=\"")
                .unwrap()
                .1
                .split_once('"')
                .unwrap()
                .0;
            points.split_whitespace().count()
        })
        .max()
        .unwrap();
    assert_eq!(vertices, loaded.len());
    // By default a spring-driven run gets it with the others, in each format.
    let drawn = draw(&dir, &[Format::Png]).unwrap();
    assert!(drawn.files.contains(&dir.join("stick_slip.png")));
    assert!(drawn.files.contains(&dir.join("force_drops.png")));
    assert!(
        drawn.notes.iter().all(|n| !n.contains("figure:")),
        "{:?}",
        drawn.notes
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--figure`'s library side: only the named figures are drawn; a name that is no
/// figure is `UnknownFigure` (its message lists the figures), a figure the directory
/// cannot give `FigureUnavailable` before any file is written; a figure the directory
/// does not allow and not named is left out with a note.
#[test]
fn named_figures_are_drawn_alone_and_unknown_or_unavailable_ones_refused() {
    use precursors::plot::{draw_with_options, DrawOptions};
    let dir = scratch("named");
    let mut driver = scene().driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let svg = DrawOptions::default().formats(&[Format::Svg]);
    let drawn = draw_with_options(
        &dir,
        &svg.clone().figures(["fronts", "contact_map", "fronts"]),
    )
    .unwrap();
    assert_eq!(
        drawn.files,
        [dir.join("contact_map.svg"), dir.join("fronts.svg")]
    );
    assert!(
        drawn.notes.iter().all(|n| !n.contains("figure:")),
        "{:?}",
        drawn.notes
    );
    let figures = |dir: &Path| {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".svg") || n.ends_with(".png"))
            .collect();
        names.sort();
        names
    };
    assert_eq!(figures(&dir), ["contact_map.svg", "fronts.svg"]);
    let e =
        draw_with_options(&dir, &svg.clone().figures(["contact_area", "stickslip"])).unwrap_err();
    assert!(matches!(&e, PlotError::UnknownFigure { name, .. } if name == "stickslip"));
    let text = e.to_string();
    for name in [
        "precursor_length",
        "contact_area",
        "contact_map",
        "stick_slip",
        "archard",
        "fronts",
        "avalanche_sizes",
        "force_drops",
    ] {
        assert!(text.contains(name), "{name} not in {text}");
    }
    // Force control: no spring, no drops; a run is no sweep. Nothing is drawn first.
    for name in ["stick_slip", "force_drops", "archard"] {
        let e = draw_with_options(&dir, &svg.clone().figures(["contact_area", name])).unwrap_err();
        assert!(
            matches!(&e, PlotError::FigureUnavailable { figure, .. } if figure == name),
            "{e:?}"
        );
        assert!(e.to_string().contains(&format!("no {name} figure")), "{e}");
    }
    assert_eq!(figures(&dir), ["contact_map.svg", "fronts.svg"]);
    // Not named: left out with notes.
    let drawn = draw(&dir, &[Format::Svg]).unwrap();
    assert_eq!(drawn.files.len(), 5);
    assert!(
        drawn.notes[0].contains("no force_drops figure"),
        "{:?}",
        drawn.notes
    );
    assert!(
        drawn.notes[1].starts_with("no stick_slip figure: the run is not driven through a spring")
    );
    // A named contact map without its table.
    std::fs::remove_file(dir.join("contact_map.csv")).unwrap();
    let e = draw_with_options(&dir, &svg.figures(["contact_map"])).unwrap_err();
    assert!(e.to_string().contains("contact_map.csv is missing"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `archard` (paper Fig. 2a) of a sweep over the normal load: the least-squares slope
/// through the origin in its legend is the one of the zero-shear areas (each run's first
/// row of `curve.csv`, read here) against the loads the sweep gave its runs; the mean and
/// the standard deviation have their legends. A sweep without the axis: a note, or an
/// error when named; a run: an error when named.
#[test]
fn archard_fits_the_zero_shear_areas_of_a_sweep_over_the_normal_load() {
    use precursors::plot::{draw_with_options, DrawOptions};
    use precursors::sweep::{Sweep, SweepOptions};
    let dir = scratch("archard");
    let base = r#"{ "block": { "lx": 0.02, "ly": 0.004, "lz": 0.01 },
        "cells": { "kind": "count", "nx": 20, "ny": 4 }, "normal_load": 100.0 }"#;
    let sweep = Sweep::from_json_str(&format!(
        r#"{{ "base": {base}, "axes": [ {{ "key": "normal_load",
              "values": [100.0, 200.0, 400.0] }} ], "realizations": 3, "seed": 4 }}"#
    ))
    .unwrap();
    let out = dir.join("loads");
    sweep.execute(&out, &SweepOptions::new(), |_| {}).unwrap();
    let options = DrawOptions::default()
        .formats(&[Format::Svg])
        .figures(["archard"]);
    let drawn = draw_with_options(&out, &options).unwrap();
    assert_eq!(drawn.files, [out.join("archard.svg")]);
    // The reference: α = Σ F_N A_R / Σ F_N² over the runs.
    let (mut fa, mut ff) = (0.0, 0.0);
    for run in sweep.runs() {
        let load: f64 = run.values()[0].1.parse().unwrap();
        let curve = std::fs::read_to_string(out.join(run.dir_name()).join("curve.csv")).unwrap();
        let mut lines = curve.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let column = header
            .iter()
            .position(|h| *h == "real_contact_area_m2")
            .unwrap();
        let area: f64 = lines
            .next()
            .unwrap()
            .split(',')
            .nth(column)
            .unwrap()
            .parse()
            .unwrap();
        fa += load * area;
        ff += load * load;
    }
    let alpha = fa / ff;
    let path = out.join("archard.svg");
    let texts = svg_texts(&path);
    let words = svg_words(&path);
    let fit = [
        ("least squares A", false),
        ("R", true),
        ("= α F", false),
        ("N", true),
        (", α = …", false),
    ];
    assert!(typeset_in(&texts, &fit, false), "{words:?}");
    let shown: f64 = words
        .iter()
        .find_map(|t| t.strip_prefix(", α = ")?.strip_suffix(" m²/N"))
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (shown - alpha).abs() <= 1e-4 * alpha,
        "α = {shown} in the legend, {alpha} from curve.csv"
    );
    assert!(
        words.iter().any(|t| t == "mean at each load (9 runs)"),
        "{words:?}"
    );
    assert!(
        words.iter().any(|t| t == "± one standard deviation"),
        "{words:?}"
    );
    assert!(
        words[0].starts_with("Real contact area at zero shear: "),
        "{words:?}"
    );
    assert!(typeset_in(
        &texts,
        &[("F", false), ("N", true), ("(N)", false)],
        false
    ));
    // Drawn by default beside the sweep's other figures.
    let drawn = draw(&out, &[Format::Png]).unwrap();
    assert!(drawn.files.contains(&out.join("archard.png")));
    // A sweep without the axis: a note, or an error when named.
    let flat = Sweep::from_json_str(&format!(
        r#"{{ "base": {base}, "axes": [], "realizations": 2, "seed": 4 }}"#
    ))
    .unwrap();
    let flat_out = dir.join("flat");
    flat.execute(&flat_out, &SweepOptions::new(), |_| {})
        .unwrap();
    let drawn = draw(&flat_out, &[Format::Svg]).unwrap();
    assert!(!flat_out.join("archard.svg").exists());
    assert!(
        drawn
            .notes
            .iter()
            .any(|n| n.starts_with("no archard figure: the sweep has no axis normal_load")),
        "{:?}",
        drawn.notes
    );
    let e = draw_with_options(&flat_out, &options).unwrap_err();
    assert!(matches!(e, PlotError::FigureUnavailable { .. }), "{e:?}");
    // A run's directory, and a run's figure of a sweep.
    let run = out.join(sweep.runs()[0].dir_name());
    let e = draw_with_options(&run, &options).unwrap_err();
    assert!(e.to_string().contains("a sweep's figure"), "{e}");
    let e = draw_with_options(&out, &options.figures(["contact_map"])).unwrap_err();
    assert!(
        e.to_string().contains("plot one of its run directories"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "cli")]
mod cli {
    use super::*;
    use crate::common::program::{path, precursors, stderr};

    /// `precursors plot --figure`: repeatable and comma separated, only those files; a
    /// name that is no figure or one the directory cannot give is a bad command line
    /// (code 2) whose message names the figures, or says why, and nothing is written.
    #[test]
    fn plot_figure_draws_only_the_named_figures() {
        let dir = scratch("cli-figure");
        spring_run(&dir);
        let figures = || {
            let mut names: Vec<String> = std::fs::read_dir(&dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".svg") || n.ends_with(".png"))
                .collect();
            names.sort();
            names
        };
        let o = precursors(&[
            "plot",
            path(&dir),
            "--figure",
            "stick_slip,force_drops",
            "--figure",
            "contact_area",
            "--format",
            "svg",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert_eq!(
            figures(),
            ["contact_area.svg", "force_drops.svg", "stick_slip.svg"]
        );
        let o = precursors(&["plot", path(&dir), "--figure", "fig4"]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let text = stderr(&o);
        assert!(text.contains("no figure is named \"fig4\""), "{text}");
        assert!(
            text.contains(
                "precursor_length, contact_area, contact_map, stick_slip, archard, fronts, \
                 avalanche_sizes, force_drops"
            ),
            "{text}"
        );
        let o = precursors(&["plot", path(&dir), "--figure", "precursor_length,archard"]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("no archard figure"), "{}", stderr(&o));
        assert_eq!(
            figures(),
            ["contact_area.svg", "force_drops.svg", "stick_slip.svg"]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `precursors plot --dpi`: the PNG's pixels at that resolution (800 x 560 at 300
    /// dpi: 1600 x 1120); a resolution out of range is a bad command line (code 2) that
    /// says the range, and nothing is drawn.
    #[test]
    fn plot_dpi_sets_the_pixels() {
        let dir = scratch("cli-dpi");
        spring_run(&dir);
        let args = |dpi: &'static str| ["plot", path(&dir), "--figure", "stick_slip", "--dpi", dpi];
        let o = precursors(&args("300"));
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let (_, w, h) = decode(&dir.join("stick_slip.png"));
        assert_eq!((w, h), (1600, 1120));
        std::fs::remove_file(dir.join("stick_slip.png")).unwrap();
        let o = precursors(&args("20"));
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("20 dpi") && stderr(&o).contains("50 to 1200"),
            "{}",
            stderr(&o)
        );
        assert!(!dir.join("stick_slip.png").exists());
        // Each value in range, their PNG too large (16384 at 1200 dpi: 131072 pixels
        // wide): a bad command line too, not a figure that failed (code 3, issue 53).
        let o = precursors(&[
            "plot",
            path(&dir),
            "--figure",
            "stick_slip",
            "--dpi",
            "1200",
            "--width",
            "16384",
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("131072 x 4480 pixels") && stderr(&o).contains("16384"),
            "{}",
            stderr(&o)
        );
        assert!(!dir.join("stick_slip.png").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// An attribute's number in a tag's attributes (`y`, `font-size`).
fn attribute(attributes: &str, name: &str) -> f64 {
    let tail = attributes
        .split_once(&format!(" {name}=\""))
        .unwrap_or_else(|| panic!("no {name} in {attributes}"))
        .1;
    tail.split_once('"').unwrap().0.parse().unwrap()
}

/// The smallest font-size an SVG text of a line may have (pixels of font height
/// SMALLEST in the PNG, written in em of DejaVu Sans: 2384/2048 em of height, the
/// font's hhea ascender − descender over its units per em, from DejaVuSans.sfd).
fn svg_font_size(pixels: f64) -> f64 {
    pixels * 2048.0 / 2384.0
}

/// The vertices of each `<polyline>` of an SVG drawn `width` wide, with its stroke.
fn svg_polylines(svg: &str, width: u32) -> Vec<(String, Vec<(f64, f64)>)> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|rest| {
            let tag = rest.split_once("/>")?.0;
            if !tag.contains(&format!("stroke-width=\"{width}\"")) {
                return None;
            }
            let stroke = tag
                .split_once("stroke=\"")?
                .1
                .split_once('"')?
                .0
                .to_string();
            let points = tag.split_once("points=\"")?.1.split_once('"')?.0;
            let vertices = points
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect();
            Some((stroke, vertices))
        })
        .collect()
}

/// A sweep over the rod's height (given out of order, two runs a point): the titles of
/// `precursor_length` and `contact_area` name the rod without the value the axis gives
/// (no "h =  mm"), are set no smaller than 14 pixels, and the legend gives each height,
/// in increasing order, coloured along viridis (its published colours at 0, 0.375 and
/// 0.75: #440154, #2C728E, #5EC962); that no interval is drawn below 6 runs is said once,
/// in a note, not in every entry.
#[test]
fn a_sweep_over_the_rod_height_is_titled_whole_and_coloured_in_order() {
    use precursors::plot::{draw_with_options, DrawOptions};
    use precursors::sweep::{Sweep, SweepOptions};
    let dir = scratch("height-sweep");
    let base = r#"{ "block": { "lx": 0.02, "ly": 0.004, "lz": 0.01 },
        "cells": { "kind": "count", "nx": 20, "ny": 4 }, "normal_load": 100.0,
        "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }"#;
    let sweep = Sweep::from_json_str(&format!(
        r#"{{ "base": {base}, "axes": [ {{ "key": "drive.height",
              "values": [0.006, 0.002, 0.004] }} ], "realizations": 2, "seed": 4 }}"#
    ))
    .unwrap();
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    let options = DrawOptions::default()
        .formats(&[Format::Svg])
        .figures(["precursor_length", "contact_area"]);
    draw_with_options(&dir, &options).unwrap();
    for name in ["precursor_length", "contact_area"] {
        let path = dir.join(format!("{name}.svg"));
        let texts = svg_texts(&path);
        // The title: the texts above the plotting area (its top at 50 pixels or lower).
        let title: Vec<&(String, String)> = texts
            .iter()
            .filter(|(a, _)| attribute(a, "y") < 45.0)
            .collect();
        let words: String = title.iter().map(|(_, t)| t.as_str()).collect();
        assert!(
            words.contains("rod,") && words.contains("2 realizations"),
            "{name}: {words}"
        );
        assert!(
            !words.contains("h =") && !words.contains('…'),
            "{name}: {words}"
        );
        for (a, t) in title.iter().filter(|(_, t)| t.len() > 2) {
            assert!(
                attribute(a, "font-size") >= svg_font_size(14.0) - 1e-9,
                "{t}: {a}"
            );
        }
        let entries: Vec<&str> = texts
            .iter()
            .map(|(_, t)| t.as_str())
            .filter(|t| t.starts_with("h = "))
            .collect();
        assert_eq!(
            entries,
            [
                "h = 2 mm (2 runs)",
                "h = 4 mm (2 runs)",
                "h = 6 mm (2 runs)"
            ],
            "{name}"
        );
        // The curves (2 pixels wide, after the axes' 1-pixel lines): along viridis.
        let svg = std::fs::read_to_string(&path).unwrap();
        let mut strokes: Vec<String> = Vec::new();
        for (stroke, _) in svg_polylines(&svg, 2) {
            if !strokes.contains(&stroke) {
                strokes.push(stroke);
            }
        }
        assert_eq!(strokes, ["#440154", "#2C728E", "#5EC962"], "{name}");
    }
    let area = svg_words(&dir.join("contact_area.svg"));
    let notes = area
        .iter()
        .filter(|t| t.contains("runs: the median"))
        .count();
    assert_eq!(notes, 1, "{area:?}");
    assert!(area.iter().all(|t| !t.contains("no interval")), "{area:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A title too long for one line at a readable size goes on two, and one too long for two
/// is cut with `…`; both stay at 14 pixels or more.
#[test]
fn long_titles_wrap_and_shorten_instead_of_shrinking() {
    let dir = scratch("long-title");
    let line = [(0.0, 0.0), (1.0, 1.0)];
    let clause = "median and 95 % interval of the real contact area";
    for (k, repeats) in [(0, 3), (1, 12)] {
        let title = vec![clause; repeats].join(", ");
        let path = dir.join(format!("title{k}.svg"));
        Chart::new(&title, "x", "y")
            .line("", &line)
            .save(&path)
            .unwrap();
        let title: Vec<(String, String)> = svg_texts(&path)
            .into_iter()
            .filter(|(a, _)| attribute(a, "y") < 45.0)
            .collect();
        let rows: Vec<f64> = title.iter().map(|(a, _)| attribute(a, "y")).collect();
        assert_eq!(rows.len(), 2, "{title:?}");
        assert!(rows[1] > rows[0] + 14.0, "{rows:?}");
        for (a, t) in &title {
            assert!(
                attribute(a, "font-size") >= svg_font_size(14.0) - 1e-9,
                "{t}: {a}"
            );
        }
        // The first line whole, the second cut where too long.
        assert!(!title[0].1.ends_with('…'), "{title:?}");
        assert_eq!(title[1].1.ends_with('…'), repeats == 12, "{title:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A logarithmic axis is labelled at the powers of ten (10⁻³ to 10² for values from
/// 1e-3 to 1e2: the decades written out here), its label the quantity, not its log; a
/// staircase's polyline holds each value until the next x (vertices alternate horizontal
/// and vertical moves, 2n − 1 of them for n points); a note is drawn once.
#[test]
fn log_axes_show_decades_and_staircases_their_jumps() {
    let dir = scratch("log-steps");
    let growth: Vec<(f64, f64)> = (0..=50)
        .map(|k| (k as f64 / 50.0, 10f64.powf(-3.0 + 5.0 * k as f64 / 50.0)))
        .collect();
    let path = dir.join("log.svg");
    Chart::new("Growth", "F/(μF_N)", "A_R/A_R(0) − 1")
        .log_y()
        .line("growth", &growth)
        .note("said once")
        .save(&path)
        .unwrap();
    let words = svg_words(&path);
    for decade in ["10⁻³", "10⁻²", "10⁻¹", "10⁰", "10¹", "10²"] {
        assert!(words.iter().any(|w| w == decade), "{decade}: {words:?}");
    }
    assert!(words.iter().all(|w| !w.contains("log")), "{words:?}");
    assert_eq!(words.iter().filter(|w| *w == "said once").count(), 1);
    // Along y the decades are evenly spaced: 10⁻³ to 10² at equal steps.
    let ys: Vec<f64> = svg_texts(&path)
        .iter()
        .filter(|(_, t)| t.starts_with("10"))
        .map(|(a, _)| attribute(a, "y"))
        .collect();
    let steps: Vec<f64> = ys.windows(2).map(|w| w[0] - w[1]).collect();
    assert!(
        steps
            .iter()
            .all(|s| (s - steps[0]).abs() <= 1.0 && *s > 40.0),
        "{ys:?}"
    );
    // A staircase through three points: five vertices, horizontal then vertical moves.
    let steps_path = dir.join("steps.svg");
    Chart::new("Staircase", "F/(μF_N)", "ℓ/Lx")
        .steps("ℓ", &[(0.0, 0.1), (0.5, 0.4), (1.0, 0.9)])
        .save(&steps_path)
        .unwrap();
    let svg = std::fs::read_to_string(&steps_path).unwrap();
    let lines = svg_polylines(&svg, 2);
    assert_eq!(lines.len(), 1, "{lines:?}");
    let v = &lines[0].1;
    assert_eq!(v.len(), 5, "{v:?}");
    for k in 0..4 {
        let horizontal = k % 2 == 0;
        let same = if horizontal {
            v[k].1 == v[k + 1].1
        } else {
            v[k].0 == v[k + 1].0
        };
        assert!(same, "move {k} of {v:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Fig. 7's legend: `|τ_{xz}|` and `|σ_{zz}|` are typeset whole, the two letters of each
/// subscript one smaller piece after the symbol.
#[test]
fn two_letter_subscripts_are_typeset_whole_in_a_legend() {
    let dir = scratch("fig7-legend");
    let path = dir.join("legend.svg");
    Chart::new("Stresses", "x (mm)", "stress (MPa)")
        .line("|τ_{xz}| at z_P = 2 mm", &[(0.0, 0.0), (1.0, 1.0)])
        .line("|σ_{zz}| at z_P = 2 mm", &[(0.0, 1.0), (1.0, 0.0)])
        .legend(Corner::UpperRight)
        .save(&path)
        .unwrap();
    let texts = svg_texts(&path);
    for symbol in ["|τ", "|σ"] {
        let sub = if symbol == "|τ" { "xz" } else { "zz" };
        let pieces = [
            (symbol, false),
            (sub, true),
            ("| at z", false),
            ("P", true),
            ("= 2 mm", false),
        ];
        assert!(typeset_in(&texts, &pieces, false), "{symbol}: {texts:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PNG at a resolution: `size · dpi/150` pixels (800 x 560 at 300 dpi: 1600 x 1120; at
/// 75: 400 x 280), its title's ink scaled with it (about four times the dark pixels at
/// twice the resolution); a resolution outside 50 to 1200 dpi is an `InvalidDpi`, a PNG
/// over 16384 pixels a side a `Figure` error, both before anything is drawn.
#[test]
fn a_png_has_the_pixels_of_its_resolution() {
    use precursors::plot::{draw_with_options, DrawOptions};
    let dir = scratch("dpi");
    let mut driver = scene().driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let options = DrawOptions::default().figures(["precursor_length"]);
    let mut ink = Vec::new();
    for (dpi, pixels) in [(75, (400, 280)), (150, (800, 560)), (300, (1600, 1120))] {
        let drawn = draw_with_options(&dir, &options.clone().dpi(dpi)).unwrap();
        let (rgb, w, h) = decode(&drawn.files[0]);
        assert_eq!((w, h), pixels, "{dpi} dpi");
        // The title's band: the top 40 of 560 rows.
        let band = (w * (h * 40 / 560) * 3) as usize;
        ink.push(
            rgb[..band]
                .chunks_exact(3)
                .filter(|p| p.iter().all(|c| *c < 100))
                .count() as f64,
        );
    }
    let ratio = ink[2] / ink[1];
    assert!((3.0..5.0).contains(&ratio), "{ink:?}");
    for dpi in [49, 1201, 0] {
        let e = draw_with_options(&dir, &options.clone().dpi(dpi)).unwrap_err();
        assert!(
            matches!(e, PlotError::InvalidDpi { dpi: d, low: 50, high: 1200 } if d == dpi),
            "{e:?}"
        );
    }
    let e = draw_with_options(&dir, &options.clone().size(8000, 5600).dpi(600)).unwrap_err();
    assert!(matches!(e, PlotError::InvalidSize { .. }), "{e:?}");
    assert!(e.to_string().contains("32000 x 22400 pixels"), "{e}");
    // An SVG does not depend on the resolution.
    let svg = options.clone().formats(&[Format::Svg]);
    draw_with_options(&dir, &svg.clone().dpi(300)).unwrap();
    let at_300 = std::fs::read(dir.join("precursor_length.svg")).unwrap();
    draw_with_options(&dir, &svg).unwrap();
    assert_eq!(
        at_300,
        std::fs::read(dir.join("precursor_length.svg")).unwrap()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The colours of an SVG's markers (`<circle>` fills), in order, each once.
fn marker_colours(svg: &str) -> Vec<String> {
    let mut colours: Vec<String> = Vec::new();
    for tag in svg.split("<circle").skip(1) {
        let Some(fill) = tag
            .split_once("fill=\"")
            .map(|t| t.1.split_once('"').unwrap().0)
        else {
            continue;
        };
        if fill != "none" && !colours.iter().any(|c| c == fill) {
            colours.push(fill.to_string());
        }
    }
    colours
}

/// Error bars of an SVG: vertical 1 px lines in a markers' colour.
fn error_bars(svg: &str) -> usize {
    let colours = marker_colours(svg);
    svg_polylines(svg, 1)
        .iter()
        .filter(|(stroke, v)| colours.contains(stroke) && v.len() == 2 && v[0].0 == v[1].0)
        .count()
}

/// The legend's box of an SVG chart (its grey frame): left, top, right, bottom.
fn legend_box(svg: &str) -> (f64, f64, f64, f64) {
    *legend_boxes(svg).first().expect("a legend's frame")
}

/// The legends' boxes of an SVG figure (their grey frames), in the order drawn.
fn legend_boxes(svg: &str) -> Vec<(f64, f64, f64, f64)> {
    svg.split("<rect")
        .skip(1)
        .map(|t| t.split_once("/>").unwrap().0)
        .filter(|t| t.contains("fill=\"none\" stroke=\"#A0A0A0\""))
        .map(|tag| {
            let (x, y) = (attribute(tag, "x"), attribute(tag, "y"));
            (
                x,
                y,
                x + attribute(tag, "width"),
                y + attribute(tag, "height"),
            )
        })
        .collect()
}

/// The data of an SVG chart drawn in the rectangle `(left, top, right, bottom)`: its
/// markers (circles of radius 3, by their extent), its lines (polylines 2 pixels wide,
/// sampled along each segment) and its error bars (vertical 1-pixel polylines in a
/// marker's colour), each said with where it is.
fn data_under(svg: &str, (left, top, right, bottom): (f64, f64, f64, f64)) -> Vec<String> {
    let inside = |(x, y): (f64, f64), pad: f64| {
        (left - pad..=right + pad).contains(&x) && (top - pad..=bottom + pad).contains(&y)
    };
    let mut found = Vec::new();
    for tag in svg.split("<circle").skip(1) {
        let tag = tag.split_once("/>").unwrap().0;
        if attribute(tag, "r") != 3.0 {
            continue; // a legend's marker glyph is 4 wide
        }
        let centre = (attribute(tag, "cx"), attribute(tag, "cy"));
        if inside(centre, 3.0) {
            found.push(format!("marker at {centre:?}"));
        }
    }
    let colours = marker_colours(svg);
    let bars = svg_polylines(svg, 1)
        .into_iter()
        .filter(|(stroke, v)| colours.contains(stroke) && v.len() == 2 && v[0].0 == v[1].0);
    for (stroke, vertices) in svg_polylines(svg, 2).into_iter().chain(bars) {
        for pair in vertices.windows(2) {
            let hit = (0..=20).map(|k| k as f64 / 20.0).find_map(|t| {
                let at = (
                    pair[0].0 + t * (pair[1].0 - pair[0].0),
                    pair[0].1 + t * (pair[1].1 - pair[0].1),
                );
                inside(at, 0.0).then_some(at)
            });
            if let Some(at) = hit {
                found.push(format!("{stroke} line at {at:?}"));
                break;
            }
        }
    }
    found
}

/// A sweep of `count` points (the rod at 2, 3, ... mm, two realizations each) run in a
/// scratch directory named `name`, and its `figure` drawn as SVG and read back: the panel
/// figures' tests.
struct PanelFigure {
    dir: std::path::PathBuf,
    drawn: precursors::plot::Drawn,
    svg: String,
    /// The SVG's width and height.
    size: (f64, f64),
    /// The legend boxes `(left, top, right, bottom)`.
    frames: Vec<(f64, f64, f64, f64)>,
    texts: Vec<(String, String)>,
}

/// A panel's size, and the default figure's (1/150 inch at 150 dpi: SVG units).
const PANEL: (f64, f64) = (800.0, 560.0);
/// The rod heights (mm) of the panel sweeps' points, in order.
const PANEL_HEIGHTS: [u32; 6] = [2, 3, 4, 5, 6, 7];

fn panel_figure(name: &str, count: usize, figure: &str) -> PanelFigure {
    use precursors::plot::{draw_with_options, DrawOptions};
    use precursors::sweep::{Sweep, SweepOptions};
    let base = r#"{ "block": { "lx": 0.04, "ly": 0.005, "lz": 0.02 },
        "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 }, "normal_load": 700.0,
        "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }"#;
    let dir = scratch(&format!("{name}-{count}"));
    let values: Vec<String> = PANEL_HEIGHTS[..count]
        .iter()
        .map(|h| format!("{}", f64::from(*h) * 1e-3))
        .collect();
    let sweep = Sweep::from_json_str(&format!(
        r#"{{ "base": {base}, "axes": [ {{ "key": "drive.height",
              "values": [{}] }} ], "realizations": 2, "seed": 3 }}"#,
        values.join(", ")
    ))
    .unwrap();
    sweep.execute(&dir, &SweepOptions::new(), |_| {}).unwrap();
    let options = DrawOptions::default()
        .formats(&[Format::Svg])
        .figures([figure]);
    let drawn = draw_with_options(&dir, &options).unwrap();
    let path = dir.join(format!("{figure}.svg"));
    let svg = std::fs::read_to_string(&path).unwrap();
    let svg_tag = svg.split_once("<svg").unwrap().1.split_once('>').unwrap().0;
    let size = (attribute(svg_tag, "width"), attribute(svg_tag, "height"));
    let frames = legend_boxes(&svg);
    let texts = svg_texts(&path);
    PanelFigure {
        dir,
        drawn,
        svg,
        size,
        frames,
        texts,
    }
}

impl PanelFigure {
    /// For a figure of six points: three columns of panels, two rows, under the title
    /// and its notes; point `k`'s title (`h = … mm (2 runs)`) once, in panel `k` in the
    /// points' order, above its own legend, which lies in the panel and covers no data.
    /// Each point's name and legend box.
    fn six_panels(&self) -> Vec<(String, (f64, f64, f64, f64))> {
        let (width, height) = PANEL;
        assert_eq!(self.size.0, 3.0 * width);
        let head = self.size.1 - 2.0 * height;
        assert!((30.0..150.0).contains(&head), "{:?}", self.size);
        assert_eq!(self.frames.len(), 6, "{:?}", self.frames);
        let cell = |(x, y): (f64, f64)| ((x / width) as usize, ((y - head) / height) as usize);
        let at = |a: &str| (attribute(a, "x"), attribute(a, "y"));
        let mut panels = Vec::new();
        for (k, h) in PANEL_HEIGHTS.iter().enumerate() {
            let name = format!("h = {h} mm (2 runs)");
            let titles: Vec<(f64, f64)> = self
                .texts
                .iter()
                .filter(|(_, t)| *t == name)
                .map(|(a, _)| at(a))
                .collect();
            assert_eq!(titles.len(), 1, "{name}: {:?}", self.texts);
            let panel = cell(titles[0]);
            assert_eq!(panel, (k % 3, k / 3), "{name}");
            let frame = self
                .frames
                .iter()
                .copied()
                .find(|f| cell((f.0, f.1)) == panel)
                .unwrap_or_else(|| panic!("{name}: no legend in its panel"));
            assert_eq!(cell((frame.2, frame.3)), panel, "{name}: {frame:?}");
            assert!(titles[0].1 < frame.1, "{name}: the title under the legend");
            let under = data_under(&self.svg, frame);
            assert!(under.is_empty(), "{name}: {under:?}");
            panels.push((name, frame));
        }
        panels
    }
}

/// A sweep of more than four points draws `avalanche_sizes` one panel a point
/// (docs/statistics.md): a grid of 3 x 2 panels of the figure's size for 6 points, in the
/// points' order, each titled by its point and with its own legend in its panel, clear of
/// its data: the point's avalanche count and its power law's `α`, interval and `n_tail`
/// (fitted here from the runs' `per_avalanche.csv`, as `stats` pools them) and the
/// goodness test's verdict. Four points keep one chart with one legend. Before, every
/// point's entries went into one legend, taller than the figure for many points.
#[test]
fn many_points_get_a_panel_each() {
    use precursors::statistics::{compare_alternatives, PowerLawOptions, Support};
    for count in [4, 6] {
        let figure = panel_figure("panels", count, "avalanche_sizes");
        let (texts, dir) = (&figure.texts, &figure.dir);
        let at = |a: &str| (attribute(a, "x"), attribute(a, "y"));
        if count == 4 {
            assert_eq!(figure.size, PANEL);
            assert_eq!(figure.frames.len(), 1, "{:?}", figure.frames);
            // The points named in the legend's entries.
            let named = texts
                .iter()
                .filter(|(_, t)| t.starts_with("h = ") && t.ends_with("avalanche sizes"))
                .count();
            assert_eq!(named, 4, "{texts:?}");
            std::fs::remove_dir_all(dir).unwrap();
            continue;
        }
        let mut fitted = 0;
        for (k, (name, frame)) in figure.six_panels().into_iter().enumerate() {
            let inside = |(x, y): (f64, f64)| {
                (frame.0..=frame.2).contains(&x) && (frame.1..=frame.3).contains(&y)
            };
            let legend: Vec<&str> = texts
                .iter()
                .filter(|(a, _)| inside(at(a)))
                .map(|(_, t)| t.as_str())
                .collect();
            let joined = squash(&legend.concat());
            // The point's sizes as `stats` pools them: each run's avalanches before the
            // spanning one.
            let mut sizes = Vec::new();
            for run in 0..2 {
                let table = dir.join(format!("p{k:04}-r{run:04}/per_avalanche.csv"));
                for row in read_csv(&table) {
                    if row["spanning"] == "0" && row["after_spanning"] == "0" {
                        sizes.push(row["ruptures"].parse::<f64>().unwrap());
                    }
                }
            }
            assert!(
                legend.contains(&format!("{} avalanche sizes", sizes.len()).as_str()),
                "{name}: {legend:?}"
            );
            match compare_alternatives(&sizes, Support::Discrete, &PowerLawOptions::default()) {
                Ok(c) => {
                    let fit = &c.power_law;
                    let entry = format!(
                        "α = {:.2} [{:.2}, {:.2}], ntail = {}",
                        fit.alpha, fit.alpha_low, fit.alpha_high, fit.tail
                    );
                    assert!(
                        joined.contains(&squash(&entry)),
                        "{name}: {entry} not in {legend:?}"
                    );
                    assert!(
                        legend.iter().any(|t| t.starts_with("pure power law ")),
                        "{name}: {legend:?}"
                    );
                    fitted += 1;
                }
                Err(_) => assert!(
                    figure
                        .drawn
                        .notes
                        .iter()
                        .any(|n| n.contains(&name) && n.contains("no power law fitted")),
                    "{name}: {:?}",
                    figure.drawn.notes
                ),
            }
        }
        assert!(fitted >= 3, "{fitted} of 6 points fitted");
        // What holds for every panel is said once, under the title.
        let notes = texts
            .iter()
            .filter(|(_, t)| t.starts_with("error bars: P"))
            .count();
        assert_eq!(notes, 1);
        std::fs::remove_dir_all(dir).unwrap();
    }
}

/// Issue 54, item 7: a legend never covers data. Markers over the left half of a chart
/// send a legend asked for in the upper left corner to the upper right, clear of them;
/// markers over the whole chart send it below the plotting area, which shrinks to keep
/// them all above it. Read back from the SVGs: the legend's frame against every marker,
/// line and error bar. Before, the legend stayed where it was asked to go, over the
/// markers.
#[test]
fn a_legend_goes_where_it_covers_no_data() {
    let dir = scratch("legend-place");
    // 21 x 21 markers over x in [0, x_max], y in [0, 1], with error bars.
    let grid = |x_max: f64| -> Vec<(f64, f64, f64, f64)> {
        (0..=20)
            .flat_map(|i| {
                (0..=20).map(move |j| {
                    let y = j as f64 / 20.0;
                    (x_max * i as f64 / 20.0, y, y - 0.01, y + 0.01)
                })
            })
            .collect()
    };
    let draw = |name: &str, x_max: f64| -> String {
        let path = dir.join(name);
        Chart::new("Legend placement", "x", "y")
            .x_range(0.0, 1.0)
            .y_range(0.0, 1.0)
            .error_bars("samples", &grid(x_max))
            .line("a line", &[(0.0, 0.0), (x_max, 0.4)])
            .note("a note under the entries")
            .legend(Corner::UpperLeft)
            .save(&path)
            .unwrap();
        std::fs::read_to_string(&path).unwrap()
    };
    let markers = |svg: &str| -> Vec<(f64, f64)> {
        svg.split("<circle")
            .skip(1)
            .map(|t| t.split_once("/>").unwrap().0)
            .filter(|t| attribute(t, "r") == 3.0)
            .map(|t| (attribute(t, "cx"), attribute(t, "cy")))
            .collect()
    };
    // The left half taken: the upper right corner, right of every marker.
    let svg = draw("left.svg", 0.45);
    let frame = legend_box(&svg);
    assert_eq!(data_under(&svg, frame), Vec::<String>::new(), "{frame:?}");
    let points = markers(&svg);
    assert_eq!(points.len(), 21 * 21);
    let rightmost = points.iter().map(|p| p.0).fold(f64::MIN, f64::max);
    let highest = points.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    assert!(frame.0 > rightmost, "{frame:?} left of {rightmost}");
    assert!(frame.1 < highest + 10.0, "{frame:?}: not the upper corner");
    // The whole chart taken: below every marker, within the picture.
    let svg = draw("full.svg", 1.0);
    let frame = legend_box(&svg);
    assert_eq!(data_under(&svg, frame), Vec::<String>::new(), "{frame:?}");
    let points = markers(&svg);
    let lowest = points.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    assert!(frame.1 > lowest, "{frame:?} above the marker at {lowest}");
    assert!(frame.3 <= 560.0, "{frame:?} off the picture");
    // The x label stays between the plotting area and the legend.
    let label = svg_texts(&dir.join("full.svg"))
        .into_iter()
        .find(|(_, t)| t == "x")
        .map(|(a, _)| attribute(&a, "y"))
        .unwrap();
    assert!(
        lowest < label && label < frame.1,
        "{lowest} {label} {frame:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The figures of `stats`' tables on a spring-driven sweep over `Lx` (three lengths, four
/// runs each; the sweep of tests/statistics.rs' collapse): `drop_against_size` and
/// `potency_against_size` carry each point's binned means with their intervals as error
/// bars (one per row of `binned_means.csv` with an interval) and the exponent of
/// `scaling.csv` with its interval in the legend; `collapse` the `τ` and `D` of
/// `collapse.csv` with their intervals, and one error bar per bin of `distributions.csv`
/// holding 3 avalanches or more; `fronts` of a sweep the median and quartiles of ℓ and
/// of the damage front for each point. The title names the grid (`Δx = 1 mm`: `Lx` is
/// the axis). Before these figures, the names were unknown and a sweep had no `fronts`.
#[test]
fn stats_tables_give_the_relation_collapse_and_ensemble_figures() {
    use precursors::plot::{draw_with_options, DrawOptions};
    use precursors::statistics::PowerLawOptions;
    use precursors::sweep::{statistics, StatsOptions, Sweep, SweepOptions};
    let dir = scratch("relations");
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
    let options = DrawOptions::default().formats(&[Format::Svg]).figures([
        "drop_against_size",
        "potency_against_size",
        "collapse",
        "fronts",
    ]);
    // Before `stats`: the tables' figures cannot be drawn, and say why.
    let e = draw_with_options(&dir, &options).unwrap_err();
    assert!(e.to_string().contains("precursors stats"), "{e}");
    let fit = PowerLawOptions::default()
        .bootstrap(10)
        .goodness_samples(0)
        .min_tail(5);
    statistics(&dir, &StatsOptions::default().fit(fit.clone())).unwrap();
    let drawn = draw_with_options(&dir, &options).unwrap();
    assert_eq!(drawn.files.len(), 4, "{:?}", drawn.notes);
    let means = read_csv(&dir.join("binned_means.csv"));
    let scaling = read_csv(&dir.join("scaling.csv"));
    for (figure, relation) in [
        ("drop_against_size", "force_drop_N_against_ruptures"),
        ("potency_against_size", "potency_m3_against_ruptures"),
    ] {
        let path = dir.join(format!("{figure}.svg"));
        let svg = std::fs::read_to_string(&path).unwrap();
        let joined = squash(&svg_words(&path).concat());
        let with_interval = means
            .iter()
            .filter(|r| r["relation"] == relation && !r["mean_high"].is_empty())
            .count();
        assert!(with_interval > 3, "{figure}");
        assert_eq!(error_bars(&svg), with_interval, "{figure}");
        for row in scaling.iter().filter(|r| r["relation"] == relation) {
            let v = |c: &str| row[c].parse::<f64>().unwrap();
            let legend = format!(
                "β = {:.2} [{:.2}, {:.2}] (95 %), {} avalanches",
                v("exponent"),
                v("exponent_low"),
                v("exponent_high"),
                row["pairs"]
            );
            assert!(
                joined.contains(&squash(&legend)),
                "{figure}: {legend} not in {joined}"
            );
        }
        assert!(joined.contains("Δx=1mm"), "{figure}: {joined}");
    }
    let collapse = read_csv(&dir.join("collapse.csv"));
    let row = collapse
        .iter()
        .find(|r| r["observable"] == "avalanche_ruptures")
        .unwrap();
    let v = |c: &str| row[c].parse::<f64>().unwrap();
    let legend = format!(
        "τ = {:.2} [{:.2}, {:.2}], D = {:.2} [{:.2}, {:.2}] (95 %, collapse.csv)",
        v("tau"),
        v("tau_low"),
        v("tau_high"),
        v("d"),
        v("d_low"),
        v("d_high")
    );
    let path = dir.join("collapse.svg");
    let svg = std::fs::read_to_string(&path).unwrap();
    let words = svg_words(&path);
    assert!(words.contains(&legend), "{legend} not in {words:?}");
    let bins = read_csv(&dir.join("distributions.csv"))
        .iter()
        .filter(|r| {
            r["observable"] == "avalanche_ruptures" && r["count"].parse::<usize>().unwrap() >= 3
        })
        .count();
    assert!(bins > 3);
    assert_eq!(error_bars(&svg), bins);
    // The points (F_N typeset: `N` a subscript of its own).
    let points = [
        "Lx=20mm,FN=100N(4runs)",
        "Lx=40mm,FN=200N(4runs)",
        "Lx=80mm,FN=400N(4runs)",
    ];
    let joined = squash(&words.concat());
    for point in points {
        assert!(joined.contains(point), "{point} not in {words:?}");
    }
    // The ensemble fronts: both bands of each point.
    let fronts = squash(&svg_words(&dir.join("fronts.svg")).concat());
    for point in points {
        for front in ["ℓ/Lx", "xD/Lx"] {
            let entry = format!("{front},medianandquartiles:{point}");
            assert!(fronts.contains(&entry), "{entry} not in {fronts}");
        }
    }
    // Issue 54, item 7: no legend covers data (on the finite-size study, those of the
    // collapse and of the relations covered their points).
    let figures = ["drop_against_size", "potency_against_size", "collapse"];
    for figure in figures {
        let svg = std::fs::read_to_string(dir.join(format!("{figure}.svg"))).unwrap();
        let under = data_under(&svg, legend_box(&svg));
        assert!(under.is_empty(), "{figure}: {under:?}");
    }
    // A run of the longest block cut after `stats` ran (no completion marker, no record,
    // as a killed run's): the figures of stats' tables still count the 4 runs it pooled
    // there (they said 3, the runs complete now), and a note says so.
    let cut = dir.join("p0002-r0003");
    std::fs::remove_file(cut.join("done")).unwrap();
    std::fs::remove_file(cut.join("meta.json")).unwrap();
    let drawn = draw_with_options(&dir, &options).unwrap();
    for figure in figures {
        let words = squash(&svg_words(&dir.join(format!("{figure}.svg"))).concat());
        assert!(words.contains("Δx=1mm,4realizations"), "{figure}: {words}");
        assert!(
            words.contains("Lx=80mm,FN=400N(4runs)"),
            "{figure}: {words}"
        );
    }
    assert!(
        drawn
            .notes
            .iter()
            .any(|n| n.contains("(4, 4, 4 a point); 4, 4, 3 are complete now")),
        "{:?}",
        drawn.notes
    );
    // Tables written before power_laws.csv's `runs`: the runs complete now, said so.
    let fits_path = dir.join("power_laws.csv");
    let with_runs = std::fs::read_to_string(&fits_path).unwrap();
    let without: String = with_runs
        .lines()
        .map(|l| format!("{}\n", &l[..l.rfind(',').unwrap()]))
        .collect();
    std::fs::write(&fits_path, without).unwrap();
    let drawn = draw_with_options(&dir, &options).unwrap();
    assert!(
        drawn
            .notes
            .iter()
            .any(|n| n.contains("power_laws.csv names no runs")),
        "{:?}",
        drawn.notes
    );
    // `stats` again pools the 3 complete ones: the titles say 3 to 4 of the 4
    // realizations (they said 4 realizations, the sweep's plan), the legend 3 runs.
    statistics(&dir, &StatsOptions::default().fit(fit)).unwrap();
    draw_with_options(&dir, &options).unwrap();
    for figure in figures {
        let words = squash(&svg_words(&dir.join(format!("{figure}.svg"))).concat());
        assert!(
            words.contains("3-4of4realizationsperpoint"),
            "{figure}: {words}"
        );
        assert!(
            words.contains("Lx=80mm,FN=400N(3runs)"),
            "{figure}: {words}"
        );
        assert!(
            words.contains("Lx=20mm,FN=100N(4runs)"),
            "{figure}: {words}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The paper's Fig. 7 on its own set-up (`examples/scenes/fig7.json`: 200 x 7 x 100 mm,
/// 1 mm cells, `F_N` = 6.25 kN, rod and top sheared together, `F_top = F_lat`): the
/// profiles it records are those of its last stable state before `ℓ` first exceeds 5 mm
/// (the rule of `examples/fig7_stresses`), found here from the run's `curve.csv`; and
/// `coulomb_profiles` is titled with that set-up and load.
#[test]
fn the_fig7_scene_records_the_stresses_just_before_the_first_precursor() {
    let dir = scratch("fig7");
    let path = Path::new("examples/scenes/fig7.json");
    let builder = SceneBuilder::from_json_file(path).unwrap();
    let scene = builder.build().unwrap();
    let mut driver = scene.driver().unwrap();
    RunTables::create(&dir, &driver)
        .unwrap()
        .run_to_slip(&mut driver, None, |_, _| {})
        .unwrap();
    let curve = read_csv(&dir.join("curve.csv"));
    let load = |r: &std::collections::HashMap<String, String>| -> f64 {
        r["force_over_mu_FN"].parse().unwrap()
    };
    let first = curve
        .iter()
        .position(|r| r["precursor_length_m"].parse::<f64>().unwrap() > 5e-3)
        .unwrap();
    // The stable states before the first precursor: rows with ℓ (stable states).
    let before = curve[..first]
        .iter()
        .rfind(|r| !r["precursor_length_m"].is_empty())
        .unwrap();
    let (low, high) = (load(before), load(&curve[first]));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let recorded = json["profiles"]["loads"][0].as_f64().unwrap();
    assert!(
        low <= recorded && recorded < high,
        "record at a load in [{low}, {high}), not {recorded}"
    );
    draw_with(&dir, "coulomb_profiles");
    let words = squash(&svg_words(&dir.join("coulomb_profiles.svg")).concat());
    for part in [
        "200x7x100mm",
        "FN=6.25kN",
        "topandrodath=6mmshear,n=1",
        "seed1",
        "200x7cellsof1mm",
        "zP=2mm",
    ] {
        assert!(words.contains(part), "{part} not in {words}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Draws the figure `name` of `dir` as SVG.
fn draw_with(dir: &Path, name: &str) {
    use precursors::plot::{draw_with_options, DrawOptions};
    let options = DrawOptions::default()
        .formats(&[Format::Svg])
        .figures([name]);
    draw_with_options(dir, &options).unwrap();
}

/// A sweep's `fronts` of more than 4 points: one panel a point, titled by it, each with its
/// own legend clear of its bands (the one-chart legend of 5 points and up had ten entries
/// and covered the data); 4 points keep one chart.
#[test]
fn ensemble_fronts_of_many_points_get_a_panel_each() {
    for count in [4, 6] {
        let figure = panel_figure("fronts-panels", count, "fronts");
        if count == 4 {
            assert_eq!(figure.size, PANEL);
            assert_eq!(figure.frames.len(), 1, "{:?}", figure.frames);
        } else {
            figure.six_panels();
        }
        std::fs::remove_dir_all(&figure.dir).unwrap();
    }
}
