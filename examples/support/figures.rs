//! Shared by the paper-figure examples: output paths, CSV writing and realization-averaged
//! precursor curves.
#![allow(dead_code)] // each example uses its own part

use precursors::calibration::{length_at, precursor_curve};
use precursors::plot::{Chart, Colours, Corner};
use precursors::{Drive, ForceLoad, Lateral, Result, Scene, SceneBuilder};

/// The block of Figs. 7, 8 and S10: 200 x 7 x 100 mm, F_N = 6.25 kN, rod (h = 6 mm,
/// Δh = 2 mm) plus top shear with F_top = F_lat (the paper does not give the split).
pub fn stress_block() -> SceneBuilder {
    Scene::builder()
        .block(0.200, 0.007, 0.100)
        .normal_load(6.25e3)
        .drive(Drive::Force(ForceLoad::Mixed {
            ratio: 1.0,
            lateral: Lateral::Rod {
                height: 6e-3,
                half_width: 2e-3,
            },
        }))
}
use crate::report::{AtPath, FileError};
use std::io::Write;

/// The command line of a figure example: `[output directory] [realizations]`.
pub struct Args {
    /// The output directory (default `.`), created and found writable.
    pub dir: String,
    /// Seeds `1..=k`, `k` the realizations (default 10, the paper's count); `[1]` for the
    /// single-realization figures.
    pub seeds: Vec<u64>,
}

/// Reads the command line, then creates the output directory and checks that it takes a
/// file, all before any computing: a figure can take minutes, and a typo should not cost
/// them. `realizations` is `Some(minimum)` for figures averaged over realizations (which
/// take the count as second argument), `None` for single-realization figures (which
/// refuse a second argument rather than ignore it).
pub fn args(realizations: Option<u64>) -> std::result::Result<Args, Box<dyn std::error::Error>> {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let usage = match realizations {
        Some(_) => "[output directory] [realizations]",
        None => "[output directory]",
    };
    let most = if realizations.is_some() { 2 } else { 1 };
    if argv.len() > most {
        return Err(format!(
            "unexpected argument '{}': the arguments are {usage}",
            argv[most]
        )
        .into());
    }
    let seeds = match (realizations, argv.get(1)) {
        (None, _) => vec![1],
        (Some(_), None) => (1..=10).collect(),
        (Some(min), Some(text)) => match text.parse::<u64>() {
            Ok(k) if k >= min => (1..=k).collect(),
            _ => {
                return Err(format!(
                    "realizations must be a whole number >= {min}, got '{text}' \
                     (the arguments are {usage})"
                )
                .into())
            }
        },
    };
    let dir = argv.first().cloned().unwrap_or_else(|| ".".into());
    crate::report::writable_dir(&dir)?;
    Ok(Args { dir, seeds })
}

/// Writes `rows` under `header` to `path`.
pub fn write_csv(path: &str, header: &str, rows: &[String]) -> std::result::Result<(), FileError> {
    let write = || -> std::io::Result<()> {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(out, "{header}")?;
        for r in rows {
            writeln!(out, "{r}")?;
        }
        out.flush()
    };
    write().at("write", path)
}

/// `ℓ/Lx` averaged over the seeds at each `F/(μF_N)` of `grid`.
pub fn mean_precursor_curve(
    builder: &SceneBuilder,
    seeds: &[u64],
    grid: &[f64],
) -> Result<Vec<f64>> {
    let scene = builder.clone().build()?;
    let lx = scene.grid().block().lx();
    let mu_fn = scene.material().friction_coefficient() * scene.normal_load();
    let mut mean = vec![0.0; grid.len()];
    for &seed in seeds {
        let curve = precursor_curve(&builder.clone().seed(seed))?;
        for (m, r) in mean.iter_mut().zip(grid) {
            *m += length_at(&curve, r * mu_fn) / lx / seeds.len() as f64;
        }
    }
    Ok(mean)
}

/// One curve of a precursor panel.
pub struct Curve {
    /// The CSV column's suffix (`ell_over_Lx_<column>`), e.g. `Lx100mm`.
    pub column: String,
    /// The legend entry, with units, e.g. `Lx = 100 mm`.
    pub legend: String,
    /// The scene (without seed: the realizations set it).
    pub builder: SceneBuilder,
}

impl Curve {
    pub fn new(
        column: impl Into<String>,
        legend: impl Into<String>,
        builder: SceneBuilder,
    ) -> Self {
        Self {
            column: column.into(),
            legend: legend.into(),
            builder,
        }
    }
}

/// Realization-averaged precursor curves `ℓ/Lx` of several scenes on one grid of
/// `F/(μF_N)` (step 0.005): writes `<name>.csv` (one column per curve) and `<name>.png`
/// (titled `<title>, mean of <k> realizations`; ℓ/Lx against F/(μF_N), both from 0 to 1;
/// one colour per curve along a sequential map, in column order (each panel's curves are
/// one parameter in increasing order), with its legend entry in the upper left) and
/// prints where each curve reaches ℓ/Lx = 0.1 and 0.5.
pub fn precursor_panel(
    dir: &str,
    name: &str,
    title: &str,
    curves: &[Curve],
    seeds: &[u64],
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let grid = unit_grid(0.005);
    let mut columns = Vec::new();
    for curve in curves {
        let mean = mean_precursor_curve(&curve.builder, seeds, &grid)?;
        let reach = |level: f64| {
            grid.iter()
                .zip(&mean)
                .find(|(_, l)| **l >= level)
                .map_or(f64::NAN, |(f, _)| *f)
        };
        println!(
            "{name} {:<30} ℓ/Lx reaches 0.1 at F/(μF_N) = {:.3}, 0.5 at {:.3}",
            format!("{}:", curve.legend),
            reach(0.1),
            reach(0.5)
        );
        columns.push(mean);
    }
    let header = std::iter::once("force_over_mu_FN".to_string())
        .chain(curves.iter().map(|c| format!("ell_over_Lx_{}", c.column)))
        .collect::<Vec<_>>()
        .join(",");
    let rows: Vec<String> = grid
        .iter()
        .enumerate()
        .map(|(i, f)| {
            std::iter::once(format!("{f:.3}"))
                .chain(columns.iter().map(|c| format!("{:.5}", c[i])))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    write_csv(&format!("{dir}/{name}.csv"), &header, &rows)?;
    let mut chart = Chart::new(
        &format!("{title}, {}", realizations(seeds.len())),
        "F/(μF_N)",
        "ℓ/Lx",
    )
    .x_range(0.0, 1.0)
    .y_range(0.0, 1.0)
    .colours(Colours::Ordered)
    .legend(Corner::UpperLeft)
    .size(900, 600);
    for (curve, c) in curves.iter().zip(&columns) {
        let points: Vec<(f64, f64)> = grid.iter().copied().zip(c.iter().copied()).collect();
        chart = chart.line(&curve.legend, &points);
    }
    chart.save(format!("{dir}/{name}.png"))?;
    Ok(())
}

/// "mean of k realizations" ("1 realization" for one).
pub fn realizations(k: usize) -> String {
    if k == 1 {
        "1 realization".into()
    } else {
        format!("mean of {k} realizations")
    }
}

/// `0, step, 2 step, ..., 1`.
pub fn unit_grid(step: f64) -> Vec<f64> {
    let n = (1.0 / step).round() as usize;
    (0..=n).map(|i| i as f64 * step).collect()
}
