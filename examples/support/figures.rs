//! Shared by the paper-figure examples: output paths, CSV writing and realization-averaged
//! precursor curves.
#![allow(dead_code)] // each example uses its own part

use precursors::calibration::{length_at, precursor_curve};
use precursors::{Result, SceneBuilder};
use std::io::Write;

/// The output directory: the first command-line argument, or `.`.
pub fn out_dir() -> String {
    std::env::args().nth(1).unwrap_or_else(|| ".".into())
}

/// Writes `rows` under `header` to `path`.
pub fn write_csv(path: &str, header: &str, rows: &[String]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "{header}")?;
    for r in rows {
        writeln!(out, "{r}")?;
    }
    out.flush()
}

/// `ℓ/Lx` averaged over the seeds at each `F/(μF_N)` of `grid`.
pub fn mean_precursor_curve(
    builder: &SceneBuilder,
    seeds: &[u64],
    grid: &[f64],
) -> Result<Vec<f64>> {
    let scene = builder.clone().build()?;
    let lx = scene.grid().block().lx();
    let mu_fn = scene.material().friction_coefficient * scene.normal_load();
    let mut mean = vec![0.0; grid.len()];
    for &seed in seeds {
        let curve = precursor_curve(&builder.clone().seed(seed))?;
        for (m, r) in mean.iter_mut().zip(grid) {
            *m += length_at(&curve, r * mu_fn) / lx / seeds.len() as f64;
        }
    }
    Ok(mean)
}

/// `0, step, 2 step, ..., 1`.
pub fn unit_grid(step: f64) -> Vec<f64> {
    let n = (1.0 / step).round() as usize;
    (0..=n).map(|i| i as f64 * step).collect()
}
