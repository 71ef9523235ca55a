//! The grid-convergence study's analysis, figures and tables (issues 28 and 44;
//! docs/convergence.md).
//!
//! Reads the study's merged sweep directories (every directory under `OUTDIR` that holds
//! a `sweep.json`, each run with `precursors sweep` and merged with `precursors merge`;
//! docs/sweep-format.md gives the tables' layout), groups them by heights (the Gaussian
//! surface of each correlation length `ξ`, the paper's white noise), and per group:
//!
//! * measures per run the observables with physical cut-offs ([`OBSERVABLES`]): the real
//!   contact area at zero shear per nominal area, the loads at which the precursor length
//!   ℓ first reaches 5 mm and 20 mm and the damage front 5 mm, and ℓ/Lx at
//!   `F/(μF_N)` = 0.75;
//! * takes the three finest grids (by the representative cell size `h = √(ΔxΔy)`) and
//!   prints per observable the ensemble means and the differences between consecutive
//!   grids and, for a surface with a correlation length, the observed order `p`, the
//!   Richardson limit `Q∞` and the error left on the finest grid, each with a 95 %
//!   percentile-bootstrap interval over the realizations that counts the unresolved
//!   resamples as unbounded (`support/richardson.rs`); below a resolved share of
//!   [`RESOLVED_SHARE`] the order, limit and error read "not resolved". The Gaussian
//!   surface with one seed is the same surface on every grid, so its grids are *paired*:
//!   the realizations are resampled together and the differences are taken between grids
//!   on the same realization. The white noise is a new surface on every grid, whose
//!   correlation length is the cell: its grids are resampled apart and have no limit to
//!   extrapolate to (docs/convergence.md), so no order or limit is printed;
//! * draws into `FIGDIR` (default `docs/figures`) `convergence_SLUG_precursor_length.png`
//!   (ℓ/Lx against `F/(μF_N)`, ensemble mean and 95 % band per cell size, `curves.csv`),
//!   `convergence_SLUG_thresholds.png` (the threshold loads against `h` with their
//!   intervals, and the Richardson limit at `h` = 0 where it is established with a
//!   bounded interval) and `convergence_SLUG_avalanches.png` (the fraction of avalanches
//!   at least as large as a slipped area, ruptures x cell area, pooled over the
//!   realizations, log-log).
//!
//! Run: `cargo run --release --features plot --example convergence_figures -- OUTDIR
//! [FIGDIR]`. Its arithmetic is unit-tested:
//! `cargo test --release --features plot --example convergence_figures`.

#[path = "support/report.rs"]
mod report;
#[path = "support/richardson.rs"]
mod richardson;

use precursors::plot::{Chart, Colours, Corner, Style};
use report::AtPath;
use richardson::{estimate, Estimate, Interval, RESOLVED_SHARE};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Bootstrap resamples per estimate, and the stream's seed (fixed: the tables repeat).
const RESAMPLES: usize = 4000;
const BOOTSTRAP_SEED: u64 = 44;

fn main() -> ExitCode {
    report::report(run())
}

/// A CSV table as `precursors merge` and the run tables write it: a header, then rows of
/// plain cells (no quoting in the columns read here).
struct Table {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn read(path: &Path) -> Result<Self, Box<dyn std::error::Error>> {
        let text = std::fs::read_to_string(path).at("read", path)?;
        Self::parse(path, &text)
    }

    fn parse(path: &Path, text: &str) -> Result<Self, Box<dyn std::error::Error>> {
        let mut lines = text.lines().filter(|l| !l.is_empty());
        let header = lines
            .next()
            .ok_or_else(|| format!("{}: empty table", path.display()))?
            .split(',')
            .map(str::to_owned)
            .collect::<Vec<_>>();
        let rows: Vec<Vec<String>> = lines
            .map(|l| l.split(',').map(str::to_owned).collect())
            .collect();
        for (k, row) in rows.iter().enumerate() {
            if row.len() != header.len() {
                return Err(format!(
                    "{}: line {} has {} cells, the header {}",
                    path.display(),
                    k + 2,
                    row.len(),
                    header.len()
                )
                .into());
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            header,
            rows,
        })
    }

    fn column(&self, name: &str) -> Result<usize, Box<dyn std::error::Error>> {
        self.header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("{}: no column `{name}`", self.path.display()).into())
    }

    /// The column's numbers; an empty cell (a band of fewer than two runs, a run not
    /// complete) is NaN.
    fn numbers(&self, name: &str) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
        let c = self.column(name)?;
        self.rows
            .iter()
            .enumerate()
            .map(|(k, row)| {
                let cell = row[c].trim();
                if cell.is_empty() {
                    Ok(f64::NAN)
                } else {
                    cell.parse::<f64>().map_err(|_| {
                        format!(
                            "{}: line {}, column `{name}`: `{cell}` is not a number",
                            self.path.display(),
                            k + 2
                        )
                        .into()
                    })
                }
            })
            .collect()
    }
}

/// The observables of one run, each with a physical cut-off rather than a one-cell event.
const OBSERVABLES: [&str; 5] = [
    "A_R(0)/(Lx·Ly)",
    "F/(μF_N) at ℓ ≥ 5 mm",
    "F/(μF_N) at ℓ ≥ 20 mm",
    "F/(μF_N) at front ≥ 5 mm",
    "ℓ/Lx at F/(μF_N) = 0.75",
];

/// The precursor-length and damage-front thresholds (m) and the load of the ℓ/Lx reading.
const ELL_SHORT: f64 = 5e-3;
const ELL_LONG: f64 = 20e-3;
const FRONT: f64 = 5e-3;
const READING_LOAD: f64 = 0.75;

/// The load `F/(μF_N)` at the first stable state whose `value` reaches `threshold`
/// (rows in the order of the run); NaN if none does.
fn first_reaching(loads: &[f64], values: &[f64], threshold: f64) -> f64 {
    loads
        .iter()
        .zip(values)
        .find(|(_, &v)| v >= threshold)
        .map_or(f64::NAN, |(&f, _)| f)
}

/// The value in effect at `load`: that of the last stable state at or below it (the
/// contact map's rule); NaN before the first state.
fn value_at(loads: &[f64], values: &[f64], load: f64) -> f64 {
    loads
        .iter()
        .zip(values)
        .take_while(|(&f, _)| f <= load + 1e-12)
        .last()
        .map_or(f64::NAN, |(_, &v)| v)
}

/// [`OBSERVABLES`] of one run from its `curve.csv` and `fronts.csv`.
fn observe(
    curve: &Table,
    fronts: &Table,
    nominal_area: f64,
    lx: f64,
) -> Result<[f64; 5], Box<dyn std::error::Error>> {
    let loads = curve.numbers("force_over_mu_FN")?;
    let ell = curve.numbers("precursor_length_m")?;
    let area = curve.numbers("real_contact_area_m2")?;
    let front_loads = fronts.numbers("force_over_mu_FN")?;
    let front = fronts.numbers("damage_front_m")?;
    let ell_over_lx: Vec<f64> = ell.iter().map(|l| l / lx).collect();
    Ok([
        area.first().map_or(f64::NAN, |a| a / nominal_area),
        first_reaching(&loads, &ell, ELL_SHORT),
        first_reaching(&loads, &ell, ELL_LONG),
        first_reaching(&front_loads, &front, FRONT),
        value_at(&loads, &ell_over_lx, READING_LOAD),
    ])
}

/// One merged sweep directory: one cell size of one heights kind.
struct Study {
    /// The heights' description, e.g. `Gaussian surface, ξ = 8 mm`.
    heights: String,
    /// For file names: `xi8`, `white`, ...
    slug: String,
    /// Correlation length (m); `None` for white noise.
    xi: Option<f64>,
    /// Cell size along x and y (m).
    dx: f64,
    dy: f64,
    cells: usize,
    runs_incomplete: usize,
    core_seconds: f64,
    /// `curves.csv`: load, then (mean, lo, hi) of ℓ/Lx.
    loads: Vec<f64>,
    ell: Vec<(f64, f64, f64)>,
    /// `avalanches.csv`: (ruptures, count).
    avalanches: Vec<(f64, f64)>,
    /// Per realization: its seed and [`OBSERVABLES`].
    observed: BTreeMap<usize, (String, [f64; 5])>,
}

impl Study {
    /// The representative cell size `√(ΔxΔy)` (m): the one length of a cell refined by
    /// different ratios along x and y (2 x 1.75 mm → 1 mm).
    fn h(&self) -> f64 {
        (self.dx * self.dy).sqrt()
    }

    fn label(&self) -> String {
        if (self.dx - self.dy).abs() < 1e-12 {
            format!("{} mm", mm(self.dx))
        } else {
            format!("{} x {} mm", mm(self.dx), mm(self.dy))
        }
    }
}

/// A length in m as mm, without trailing zeros (`0.25`, `1`, `1.75`).
fn mm(x: f64) -> String {
    let s = format!("{:.4}", x * 1e3);
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

fn number(v: &serde_json::Value, path: &[&str], file: &Path) -> Result<f64, String> {
    let mut at = v;
    for key in path {
        at = &at[*key];
    }
    at.as_f64()
        .ok_or_else(|| format!("{}: no number at `{}`", file.display(), path.join(".")))
}

fn read_json(path: &Path) -> Result<serde_json::Value, Box<dyn std::error::Error>> {
    Ok(serde_json::from_str(&std::fs::read_to_string(path).at("read", path)?).at("parse", path)?)
}

/// The cell sizes `(dx, dy, nx, ny)` of a sweep's base scene.
fn cells(base: &serde_json::Value, file: &Path) -> Result<(f64, f64, f64, f64), String> {
    let lx = number(base, &["block", "lx"], file)?;
    let ly = number(base, &["block", "ly"], file)?;
    match base["cells"]["kind"].as_str() {
        Some("size") => {
            let dx = number(base, &["cells", "dx"], file)?;
            let dy = number(base, &["cells", "dy"], file)?;
            Ok((dx, dy, (lx / dx).round(), (ly / dy).round()))
        }
        Some("count") => {
            let nx = number(base, &["cells", "nx"], file)?;
            let ny = number(base, &["cells", "ny"], file)?;
            Ok((lx / nx, ly / ny, nx, ny))
        }
        other => Err(format!("{}: cells kind {other:?}", file.display())),
    }
}

/// The heights' description, file slug and correlation length.
fn heights(base: &serde_json::Value, file: &Path) -> Result<(String, String, Option<f64>), String> {
    Ok(
        match base["heights"]["kind"].as_str().unwrap_or("gaussian") {
            "gaussian" => ("white noise (the paper's)".into(), "white".into(), None),
            "gaussian_surface" => {
                let xi = number(base, &["heights", "correlation_length"], file)?;
                (
                    format!("Gaussian surface, ξ = {} mm", mm(xi)),
                    format!("xi{}", mm(xi)),
                    Some(xi),
                )
            }
            other => (other.replace('_', " "), other.to_owned(), None),
        },
    )
}

fn read_study(dir: &Path) -> Result<Study, Box<dyn std::error::Error>> {
    let sweep_path = dir.join("sweep.json");
    let sweep = read_json(&sweep_path)?;
    if sweep["axes"].as_array().is_some_and(|a| !a.is_empty()) {
        return Err(format!(
            "{}: a sweep with axes; the study's sweeps have one point each",
            sweep_path.display()
        )
        .into());
    }
    let base = &sweep["base"];
    let (dx, dy, nx, ny) = cells(base, &sweep_path)?;
    let (heights, slug, xi) = heights(base, &sweep_path)?;
    let lx = number(base, &["block", "lx"], &sweep_path)?;
    let nominal_area = lx * number(base, &["block", "ly"], &sweep_path)?;

    let merged = dir.join("curves.csv");
    if !merged.exists() {
        return Err(format!(
            "{} has no curves.csv: run `precursors merge {}` first",
            dir.display(),
            dir.display()
        )
        .into());
    }
    let curves = Table::read(&merged)?;
    let loads = curves.numbers("force_over_mu_FN")?;
    let (m, lo, hi) = (
        curves.numbers("precursor_over_Lx_mean")?,
        curves.numbers("precursor_over_Lx_lo")?,
        curves.numbers("precursor_over_Lx_hi")?,
    );
    let ell = (0..m.len()).map(|k| (m[k], lo[k], hi[k])).collect();

    let av = Table::read(&dir.join("avalanches.csv"))?;
    let avalanches = av
        .numbers("ruptures")?
        .into_iter()
        .zip(av.numbers("count")?)
        .collect();

    let runs_table = Table::read(&dir.join("runs.csv"))?;
    let points = runs_table.numbers("point")?;
    let realizations = runs_table.numbers("realization")?;
    let slips = runs_table.numbers("slip_over_mu_FN")?;
    let seeds = runs_table.column("seed")?;
    let (mut runs_incomplete, mut core_seconds) = (0, 0.0);
    let mut observed = BTreeMap::new();
    for k in 0..points.len() {
        if !slips[k].is_finite() {
            runs_incomplete += 1;
            continue;
        }
        let run = dir.join(format!(
            "p{:04}-r{:04}",
            points[k] as usize, realizations[k] as usize
        ));
        let meta_path = run.join("meta.json");
        core_seconds += number(&read_json(&meta_path)?, &["seconds", "total"], &meta_path)?;
        let values = observe(
            &Table::read(&run.join("curve.csv"))?,
            &Table::read(&run.join("fronts.csv"))?,
            nominal_area,
            lx,
        )?;
        let seed = runs_table.rows[k][seeds].clone();
        observed.insert(realizations[k] as usize, (seed, values));
    }
    Ok(Study {
        heights,
        slug,
        xi,
        dx,
        dy,
        cells: (nx * ny) as usize,
        runs_incomplete,
        core_seconds,
        loads,
        ell,
        avalanches,
        observed,
    })
}

struct Args {
    out: PathBuf,
    figures: PathBuf,
}

fn args() -> Result<Args, Box<dyn std::error::Error>> {
    let usage = "usage: convergence_figures OUTDIR [FIGDIR]";
    let positional: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if positional.is_empty() || positional.len() > 2 {
        return Err(usage.into());
    }
    if let Some(flag) = positional
        .iter()
        .find(|p| p.to_string_lossy().starts_with("--"))
    {
        return Err(format!("unknown option {}; {usage}", flag.display()).into());
    }
    Ok(Args {
        out: positional[0].clone(),
        figures: positional
            .get(1)
            .cloned()
            .unwrap_or_else(|| PathBuf::from("docs/figures")),
    })
}

fn run() -> report::Outcome {
    let args = args()?;
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&args.out)
        .at("list", &args.out)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("sweep.json").is_file())
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        return Err(format!("{} holds no sweep directory", args.out.display()).into());
    }
    report::writable_dir(&args.figures)?;

    // Per heights, the sizes from the coarsest to the finest.
    let mut groups: BTreeMap<String, Vec<Study>> = BTreeMap::new();
    for dir in &dirs {
        let study = read_study(dir)?;
        if study.runs_incomplete > 0 {
            eprintln!(
                "note: {}: {} runs not complete, left out",
                dir.display(),
                study.runs_incomplete
            );
        }
        groups.entry(study.slug.clone()).or_default().push(study);
    }
    for studies in groups.values_mut() {
        studies.sort_by(|a, b| b.h().total_cmp(&a.h()));
        let finest: &[Study] = &studies[studies.len().saturating_sub(3)..];
        cost_table(studies);
        let estimates = estimates(finest);
        if let Some(estimates) = &estimates {
            println!("{}", estimate_table(finest, estimates));
        }
        figures(studies, estimates.as_deref(), &args.figures)?;
    }
    Ok(())
}

/// Whether the grids are paired: the same surface kind with the same seed per
/// realization on each (the Gaussian surface is then the same surface on every grid).
fn paired(studies: &[Study]) -> bool {
    studies[0].xi.is_some()
        && studies[0].observed.iter().all(|(k, (seed, _))| {
            studies[1..]
                .iter()
                .all(|s| s.observed.get(k).is_none_or(|(other, _)| other == seed))
        })
}

/// The estimates of [`OBSERVABLES`] on the three grids; `None` (with a note) when the
/// group has fewer than three distinct cell sizes. Only a surface with a correlation
/// length of its own is extrapolated: the white noise's correlation length is the cell,
/// so its grids share no limit.
fn estimates(studies: &[Study]) -> Option<Vec<Option<Estimate>>> {
    let name = &studies[0].heights;
    let decreasing =
        studies.len() >= 3 && studies[0].h() > studies[1].h() && studies[1].h() > studies[2].h();
    if !decreasing {
        eprintln!("note: {name}: fewer than three cell sizes, no extrapolation");
        return None;
    }
    let h = studies[0]
        .xi
        .map(|_| [studies[0].h(), studies[1].h(), studies[2].h()]);
    let paired = paired(studies);
    let realizations = studies
        .iter()
        .flat_map(|s| s.observed.keys().copied())
        .max()
        .map_or(0, |k| k + 1);
    Some(
        (0..OBSERVABLES.len())
            .map(|q| {
                let observed: [Vec<f64>; 3] = std::array::from_fn(|g| {
                    (0..realizations)
                        .map(|k| studies[g].observed.get(&k).map_or(f64::NAN, |o| o.1[q]))
                        .collect()
                });
                estimate(&observed, h, paired, RESAMPLES, BOOTSTRAP_SEED + q as u64)
            })
            .collect(),
    )
}

/// A number with three significant figures; an open interval's end is `±∞`.
fn sig(x: f64) -> String {
    if x.is_nan() {
        return "—".into();
    }
    if x.is_infinite() {
        return if x > 0.0 {
            "∞".into()
        } else {
            "−∞".into()
        };
    }
    if x == 0.0 || (1e-2..1e3).contains(&x.abs()) {
        let decimals = (2 - x.abs().log10().floor() as i32).clamp(0, 4) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.2e}")
    }
}

fn interval(i: Option<Interval>) -> String {
    match i {
        Some(i) => format!("{} [{}, {}]", sig(i.value), sig(i.lo), sig(i.hi)),
        None => "—".into(),
    }
}

fn cost_table(studies: &[Study]) {
    println!("### {}: cost\n", studies[0].heights);
    println!("| cell size | N | complete runs | run time, one core per run (s) |");
    println!("| --- | --- | --- | --- |");
    for s in studies {
        println!(
            "| {} | {} | {} | {:.0} |",
            s.label(),
            s.cells,
            s.observed.len(),
            s.core_seconds
        );
    }
    println!();
}

fn estimate_table(studies: &[Study], estimates: &[Option<Estimate>]) -> String {
    let paired = if paired(studies) {
        "paired: differences on the same realization"
    } else {
        "unpaired: a new surface on every grid"
    };
    let labels: Vec<String> = studies.iter().map(Study::label).collect();
    let sizes: Vec<String> = studies.iter().map(|s| mm(s.h())).collect();
    let extrapolated = studies[0].xi.is_some();
    let mut out = format!(
        "### {}: cells {} (h = √(ΔxΔy) = {} mm), means and 95 % bootstrap intervals; {paired}\n\n",
        studies[0].heights,
        labels.join(", "),
        sizes.join(", "),
    );
    let mut header = format!(
        "| observable | {} | {} | {} | Δ {}→{} | Δ {}→{} |",
        labels[0], labels[1], labels[2], labels[0], labels[1], labels[1], labels[2]
    );
    if extrapolated {
        header += &format!(
            " order p | resolved | limit h → 0 | error at {} |",
            labels[2]
        );
    }
    let columns = header.matches('|').count() - 1;
    out += &format!("{header}\n|{}\n", " --- |".repeat(columns));
    for (name, e) in OBSERVABLES.iter().zip(estimates) {
        out += &estimate_row(name, e.as_ref(), columns);
        out.push('\n');
    }
    if extrapolated {
        out += &format!(
            "\n(Not resolved: fewer than {:.0} % of the resamples resolved.)\n",
            100.0 * RESOLVED_SHARE
        );
    } else {
        out += "\n(No order and no limit: a new surface on every grid, whose correlation length is the cell.)\n";
    }
    out
}

/// One observable's row of [`estimate_table`]: the extrapolation's cells where the
/// estimate has one; "not resolved" below [`RESOLVED_SHARE`], "—" where the full sample
/// gives no positive order.
fn estimate_row(name: &str, e: Option<&Estimate>, columns: usize) -> String {
    let Some(e) = e else {
        return format!(
            "| {name} | fewer than two realizations reach it |{}",
            " |".repeat(columns - 2)
        );
    };
    let mut row = format!(
        "| {name} ({} runs) | {} | {} | {} | {} | {} |",
        e.realizations[2],
        interval(Some(e.means[0])),
        interval(Some(e.means[1])),
        interval(Some(e.means[2])),
        interval(Some(e.differences[0])),
        interval(Some(e.differences[1])),
    );
    if let Some(x) = &e.extrapolation {
        let resolved = format!("{:.0} %", 100.0 * x.resolved);
        if x.established() {
            row += &format!(
                " {} | {resolved} | {} | {} |",
                interval(x.order),
                interval(x.limit),
                interval(x.finest_error)
            );
        } else {
            row += &format!(" not resolved | {resolved} | not resolved | not resolved |");
        }
    }
    row
}

/// The fraction of avalanches of at least each size, from `(size, count)` rows: the
/// complementary cumulative distribution `(size, P(S ≥ size))` at the sizes present.
fn at_least(rows: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut rows: Vec<_> = rows.iter().copied().filter(|r| r.1 > 0.0).collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let mut above = total;
    rows.iter()
        .map(|&(size, count)| {
            let p = above / total;
            above -= count;
            (size, p)
        })
        .collect()
}

fn figures(
    studies: &[Study],
    estimates: Option<&[Option<Estimate>]>,
    dir: &Path,
) -> report::Outcome {
    let heights = &studies[0].heights;
    let path = |name: &str| dir.join(format!("convergence_{}_{name}.png", studies[0].slug));

    let mut ell = Chart::new(
        &format!("Precursor length, {heights}"),
        "F/(μF_N)",
        "ℓ/Lx (ensemble mean, 95 % band)",
    )
    .x_range(0.0, 1.0)
    .colours(Colours::Ordered)
    .legend(Corner::UpperLeft);
    for s in studies {
        let rows: Vec<_> = s
            .loads
            .iter()
            .zip(&s.ell)
            .map(|(&f, &(m, lo, hi))| (f, m, lo.max(0.0), hi.min(1.0)))
            .collect();
        ell = ell.band(&format!("{} ({} runs)", s.label(), s.observed.len()), &rows);
    }
    save(ell, &path("precursor_length"))?;

    if let Some(estimates) = estimates {
        thresholds(
            &studies[studies.len() - 3..],
            estimates,
            &path("thresholds"),
        )?;
    }

    let mut aval = Chart::new(
        &format!("Avalanche sizes, {heights}"),
        "slipped area: ruptures x cell area (mm²)",
        "fraction of avalanches at least as large",
    )
    .log_x()
    .log_y()
    .colours(Colours::Ordered)
    .legend(Corner::UpperRight);
    for s in studies {
        let cell_mm2 = s.dx * s.dy * 1e6;
        let points: Vec<_> = at_least(&s.avalanches)
            .iter()
            .filter(|(n, _)| *n > 0.0)
            .map(|(n, p)| (n * cell_mm2, *p))
            .collect();
        aval = aval.markers(&s.label(), &points);
    }
    save(aval, &path("avalanches"))
}

/// The threshold loads against `h = √(ΔxΔy)`, with the Richardson limit at `h` = 0
/// where it is established with a bounded interval.
fn thresholds(studies: &[Study], estimates: &[Option<Estimate>], path: &Path) -> report::Outcome {
    let mut chart = Chart::new(
        &format!(
            "Threshold loads, {}{}",
            studies[0].heights,
            // The white noise has no limit to draw (docs/convergence.md).
            if studies[0].xi.is_some() {
                " (h = 0: Richardson limit)"
            } else {
                ""
            }
        ),
        "cell size h = √(ΔxΔy) (mm)",
        "F/(μF_N) (mean, 95 % interval)",
    )
    .x_range(0.0, studies[0].h() * 1e3 * 1.05)
    .legend(Corner::UpperRight);
    for q in 1..=3 {
        let Some(e) = &estimates[q] else { continue };
        let mut rows: Vec<(f64, f64, f64, f64)> = Vec::new();
        if let Some(l) = e.extrapolation.as_ref().and_then(drawn_limit) {
            rows.push((0.0, l.value, l.lo, l.hi));
        }
        for (s, m) in studies.iter().rev().zip(e.means.iter().rev()) {
            rows.push((s.h() * 1e3, m.value, m.lo, m.hi));
        }
        chart = chart.band(OBSERVABLES[q], &rows);
    }
    // A load cannot pass global slip: an interval above it is the extrapolation's, not
    // the model's.
    let slip = [(0.0, 1.0), (studies[0].h() * 1e3 * 1.05, 1.0)];
    chart = chart
        .line("global slip", &slip)
        .style(Style::new().colour(120, 120, 120).dashed());
    save(chart, path)
}

/// The limit a figure draws: established, with a bounded interval.
fn drawn_limit(x: &richardson::Extrapolation) -> Option<Interval> {
    x.limit
        .filter(|l| x.established() && l.lo.is_finite() && l.hi.is_finite())
}

fn save(chart: Chart, path: &Path) -> report::Outcome {
    chart.save(path)?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_reaching_takes_the_first_state_at_the_threshold() {
        // By hand: ℓ = 0, 3, 5, 4, 9 mm at loads 0, 0.1, 0.2, 0.3, 0.4: 5 mm is first
        // reached at 0.2 (equal counts), 6 mm at 0.4, 10 mm never.
        let loads = [0.0, 0.1, 0.2, 0.3, 0.4];
        let ell = [0.0, 3e-3, 5e-3, 4e-3, 9e-3];
        assert_eq!(first_reaching(&loads, &ell, 5e-3), 0.2);
        assert_eq!(first_reaching(&loads, &ell, 6e-3), 0.4);
        assert!(first_reaching(&loads, &ell, 10e-3).is_nan());
    }

    #[test]
    fn value_at_is_the_state_in_effect() {
        let loads = [0.0, 0.1, 0.25, 0.8];
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(value_at(&loads, &v, 0.75), 3.0);
        assert_eq!(value_at(&loads, &v, 0.8), 4.0);
        assert!(value_at(&[0.1], &[1.0], 0.05).is_nan());
    }

    #[test]
    fn observe_reads_the_run_tables() {
        let curve = Table::parse(
            Path::new("curve.csv"),
            "force_over_mu_FN,real_contact_area_m2,precursor_length_m\n\
             0,2e-5,0\n0.3,2.1e-5,6e-3\n0.7,2.2e-5,21e-3\n0.9,2.3e-5,40e-3\n",
        )
        .unwrap();
        let fronts = Table::parse(
            Path::new("fronts.csv"),
            "force_over_mu_FN,damage_front_m\n0,0\n0.3,1e-3\n0.7,5e-3\n",
        )
        .unwrap();
        // A_R(0) over 1e-3 m² = 0.02; ℓ ≥ 5 mm at 0.3, ≥ 20 mm at 0.7; front at 0.7;
        // ℓ/Lx at 0.75 is 21 mm / 0.14 m = 0.15.
        let o = observe(&curve, &fronts, 1e-3, 0.14).unwrap();
        assert!((o[0] - 0.02).abs() < 1e-15);
        assert_eq!(&o[1..4], &[0.3, 0.7, 0.7]);
        assert!((o[4] - 0.15).abs() < 1e-15);
    }

    #[test]
    fn numbers_print_with_three_significant_figures() {
        assert_eq!(sig(0.123456), "0.123");
        assert_eq!(sig(12.3456), "12.3");
        assert_eq!(sig(-0.0456), "-0.0456");
        assert_eq!(sig(0.00123), "1.23e-3");
        assert_eq!(sig(f64::NAN), "—");
    }

    #[test]
    fn a_table_refuses_ragged_rows_and_words_in_number_columns() {
        let bad = Table::parse(Path::new("c.csv"), "a,b\n1\n");
        assert!(bad.err().unwrap().to_string().contains("line 2"));
        let t = Table::parse(Path::new("c.csv"), "a\nx\n").unwrap();
        let e = t.numbers("a").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("`x`"), "{e}");
    }

    #[test]
    fn at_least_is_the_complementary_cumulative_distribution() {
        // Counts 6, 3, 1 of sizes 1, 2, 5 (given out of order; a zero count dropped):
        // P(S ≥ 1) = 1, P(S ≥ 2) = 4/10, P(S ≥ 5) = 1/10.
        let rows = [(2.0, 3.0), (1.0, 6.0), (7.0, 0.0), (5.0, 1.0)];
        assert_eq!(at_least(&rows), vec![(1.0, 1.0), (2.0, 0.4), (5.0, 0.1)]);
    }

    /// A study of `runs` realizations whose every observable is `value(realization)`.
    fn study(
        xi: Option<f64>,
        dx: f64,
        dy: f64,
        runs: usize,
        value: impl Fn(usize) -> f64,
    ) -> Study {
        Study {
            heights: "test".into(),
            slug: "test".into(),
            xi,
            dx,
            dy,
            cells: 1,
            runs_incomplete: 0,
            core_seconds: 0.0,
            loads: Vec::new(),
            ell: Vec::new(),
            avalanches: Vec::new(),
            observed: (0..runs)
                .map(|k| (k, (k.to_string(), [value(k); 5])))
                .collect(),
        }
    }

    #[test]
    fn the_order_uses_the_cell_area_not_the_ratio_along_x() {
        // Grids of 2 x 1.75, 1 and 0.5 mm carrying Q = 0.1 + (h/1 mm)^1.5 with h = √(ΔxΔy)
        // exactly (every realization alike): the table's order is 1.50 and the limit
        // 0.100; with the ratio along x (2) it would read log₂(D₁₂/D₂₃) = 1.27 and a
        // limit of −0.0044 (by hand: Q = 2.6589, 1.1, 0.4536).
        let q = |dx: f64, dy: f64| 0.1 + (dx * dy * 1e6).sqrt().powf(1.5);
        let studies: Vec<Study> = [(2e-3, 1.75e-3), (1e-3, 1e-3), (0.5e-3, 0.5e-3)]
            .into_iter()
            .map(|(dx, dy)| study(Some(8e-3), dx, dy, 4, |_| q(dx, dy)))
            .collect();
        assert!((studies[0].h() - 3.5e-6_f64.sqrt()).abs() < 1e-15);
        let estimates = estimates(&studies).unwrap();
        let x = estimates[1]
            .as_ref()
            .unwrap()
            .extrapolation
            .clone()
            .unwrap();
        let (p, limit) = (x.order.unwrap().value, x.limit.unwrap().value);
        assert!(
            (p - 1.5).abs() < 1e-9 && (limit - 0.1).abs() < 1e-9,
            "{p} {limit}"
        );
        let table = estimate_table(&studies, &estimates);
        assert!(table.contains("h = √(ΔxΔy) = 1.8708, 1, 0.5 mm"), "{table}");
        assert!(
            table.contains("| 1.50 [1.50, 1.50] | 100 % | 0.100 [0.100, 0.100] |"),
            "{table}"
        );
    }

    #[test]
    fn the_white_noise_prints_no_order_and_no_limit() {
        // The same exact power law on a white noise (no correlation length): the table
        // has the means and differences and no order, limit or error columns.
        let studies: Vec<Study> = [2e-3, 1e-3, 0.5e-3]
            .into_iter()
            .map(|dx| study(None, dx, dx, 4, |k| 1.0 + dx * 1e3 + 0.01 * k as f64))
            .collect();
        let estimates = estimates(&studies).unwrap();
        assert!(estimates[0].as_ref().unwrap().extrapolation.is_none());
        let table = estimate_table(&studies, &estimates);
        assert!(
            !table.contains("order p") && !table.contains("limit h → 0"),
            "{table}"
        );
        let header = table
            .lines()
            .find(|l| l.starts_with("| observable"))
            .unwrap();
        let row = table.lines().find(|l| l.starts_with("| A_R(0)")).unwrap();
        assert_eq!(header.matches('|').count(), 7, "{header}");
        assert_eq!(row.matches('|').count(), 7, "{row}");
    }

    #[test]
    fn an_unresolved_row_says_so() {
        // Paired grids whose middle grid scatters by realization: the full sample's
        // differences shrink (Q = 2, 1.02, 0.5 on average) but in part of the resamples
        // they do not; below 95 % resolved the row reads "not resolved" in place of an
        // order and a limit.
        let scatter = [0.3, -0.2, 0.25, -0.35, 0.1, -0.05, 0.4, -0.3, 0.15, -0.25];
        let studies: Vec<Study> = [(2e-3, 0.0), (1e-3, 1.0), (0.5e-3, 0.0)]
            .into_iter()
            .map(|(dx, w)| study(Some(8e-3), dx, dx, 10, |k| dx * 1e3 + w * 4.0 * scatter[k]))
            .collect();
        let estimates = estimates(&studies).unwrap();
        let x = estimates[0]
            .as_ref()
            .unwrap()
            .extrapolation
            .clone()
            .unwrap();
        assert!(x.resolved < RESOLVED_SHARE, "{}", x.resolved);
        let table = estimate_table(&studies, &estimates);
        let row = table.lines().find(|l| l.starts_with("| A_R(0)")).unwrap();
        assert!(row.ends_with("| not resolved | not resolved |"), "{row}");
        assert_eq!(row.matches("not resolved").count(), 3, "{row}");
    }

    #[test]
    fn open_ends_print_as_infinities() {
        assert_eq!(sig(f64::INFINITY), "∞");
        assert_eq!(sig(f64::NEG_INFINITY), "−∞");
        let open = Interval {
            value: 0.5,
            lo: f64::NEG_INFINITY,
            hi: 0.9,
        };
        assert_eq!(interval(Some(open)), "0.500 [−∞, 0.900]");
    }

    #[test]
    fn lengths_print_in_millimetres_without_trailing_zeros() {
        assert_eq!(mm(0.00025), "0.25");
        assert_eq!(mm(0.001), "1");
        assert_eq!(mm(0.00175), "1.75");
    }
}
