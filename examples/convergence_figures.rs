//! The grid-convergence study's figures and table (issue 28; docs/convergence.md).
//!
//! Reads the study's merged sweep directories (`OUTDIR/convergence_*/`, each run with
//! `precursors sweep` and merged with `precursors merge`; docs/sweep-format.md gives the
//! tables' layout) and, per heights kind (the Gaussian surface, the paper's white noise),
//! draws into `FIGDIR` (default `docs/figures`):
//!
//! * `convergence_KIND_precursor_length.png`: ℓ/Lx against F/(μF_N), ensemble mean and
//!   95 % band (`curves.csv`), one curve per cell size;
//! * `convergence_KIND_area.png`: `A_R/A_R(0) − 1` on a log axis against F/(μF_N) (the area's
//!   relative growth spans 1e-5 to 10 under the paper's area law: a log axis shows every
//!   load), same layout;
//! * `convergence_KIND_first_precursor.png`: the first-precursor load (below) of every run
//!   against the cell size, with the per-size mean and 95 % band;
//! * `convergence_KIND_avalanches.png`: the avalanche-size distribution
//!   (`avalanches.csv`, pooled over the realizations) as the fraction of avalanches of at
//!   least a given slipped area (ruptures x cell area, mm²: a rupture count means another
//!   area at each cell size, and the cumulative form needs no bins), log-log, one set of
//!   markers per cell size.
//!
//! and prints (the figures' paths go to stderr), per kind, a markdown table: cell size | N | runs | cores x time (the sum of
//! the runs' `seconds.total` from their `meta.json`: one core per run) | the distance to
//! the finest size of that kind (the largest difference of the ensemble means of ℓ/Lx
//! over the loads of `curves.csv`, the same for `A_R/A_R(0)`, the difference of the mean
//! first-precursor loads; and their mean and band) with the observed order `ln(d_coarse/d_h)/ln(h_coarse/h)`
//! between consecutive sizes (`log2(d_2h/d_h)` for halved cells). Then, for each size of
//! every other kind, at how many loads its ℓ/Lx band overlaps the finest Gaussian
//! surface's (the question whether the paper's 1 mm white noise lies in the converged
//! band).
//!
//! The first-precursor load of a run is `F/(μF_N)` at its first stable state with ℓ > 0
//! (`curve.csv`): the first detachment at the trailing edge (the paper's "force needed to
//! nucleate the first precursor"; ℓ is docs/model.md's, the region whose y-averaged area
//! fell below its zero-shear value).
//!
//! Run: `cargo run --release --features plot --example convergence_figures -- OUTDIR
//! [FIGDIR] [--up-to LOAD]` (`--up-to` takes the distances over the loads up to LOAD
//! only, and draws the area figure up to it, e.g. 0.9 to leave out the last load, where
//! the area law makes `A_R` jump by orders of magnitude just before global slip). Its arithmetic is unit-tested:
//! `cargo test --features plot --example convergence_figures`.

#[path = "support/report.rs"]
mod report;

use precursors::plot::{Chart, Colours, Corner};
use precursors::sweep::mean_band;
use report::AtPath;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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

/// [`mean_band`] as `(mean, lo, hi)`.
fn band(x: &[f64]) -> (f64, f64, f64) {
    let b = mean_band(x);
    (b.mean, b.lo, b.hi)
}

/// Two loads of `curves.csv` are the same grid load (written with 2 decimals).
fn same_load(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// The largest `|a - b|` of two curves `(load, mean)` over the loads they share up to
/// `up_to` (both values finite); `None` when they share no such load.
fn max_difference(a: &[(f64, f64)], b: &[(f64, f64)], up_to: f64) -> Option<f64> {
    let mut worst: Option<f64> = None;
    for &(fa, ya) in a {
        if fa > up_to + 1e-9 || !ya.is_finite() {
            continue;
        }
        if let Some(&(_, yb)) = b
            .iter()
            .find(|(fb, yb)| same_load(fa, *fb) && yb.is_finite())
        {
            let d = (ya - yb).abs();
            worst = Some(worst.map_or(d, |w: f64| w.max(d)));
        }
    }
    worst
}

/// The observed order of convergence from the distances to the reference at a coarse and
/// a fine cell size: `ln(d_coarse/d_fine)/ln(h_coarse/h_fine)` (`log2(d_2h/d_h)` when the
/// cell is halved). `None` when a distance is zero or not finite or the sizes are not
/// ordered (no order can be read).
fn observed_order(d_coarse: f64, d_fine: f64, h_coarse: f64, h_fine: f64) -> Option<f64> {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if ok(d_coarse) && ok(d_fine) && ok(h_coarse) && ok(h_fine) && h_coarse > h_fine {
        Some((d_coarse / d_fine).ln() / (h_coarse / h_fine).ln())
    } else {
        None
    }
}

/// The first-precursor load of a run: `F/(μF_N)` at the first row of its `curve.csv`
/// (the stable states) with ℓ > 0; `None` if there is none.
fn first_precursor_load(curve: &Table) -> Result<Option<f64>, Box<dyn std::error::Error>> {
    let load = curve.numbers("force_over_mu_FN")?;
    let ell = curve.numbers("precursor_length_m")?;
    Ok(load
        .iter()
        .zip(&ell)
        .find(|(_, &l)| l > 0.0)
        .map(|(&f, _)| f))
}

/// At how many of the loads two banded curves `(load, lo, hi)` share, their bands
/// overlap; and how many loads they share with finite bands.
fn overlapping_loads(a: &[(f64, f64, f64)], b: &[(f64, f64, f64)]) -> (usize, usize) {
    let (mut overlap, mut shared) = (0, 0);
    for &(fa, la, ha) in a {
        let found = b.iter().find(|(fb, _, _)| same_load(fa, *fb));
        if let Some(&(_, lb, hb)) = found {
            if [la, ha, lb, hb].iter().all(|v| v.is_finite()) {
                shared += 1;
                if la <= hb && lb <= ha {
                    overlap += 1;
                }
            }
        }
    }
    (overlap, shared)
}

/// `(mean, lo, hi)`: an ensemble mean and its 95 % band.
type Band = (f64, f64, f64);

/// One merged sweep directory: one cell size of one heights kind.
struct Study {
    /// The heights' description, e.g. `Gaussian surface, ξ = 3 mm`.
    heights: String,
    /// For file names: `surface`, `white` or the heights kind.
    slug: String,
    /// Cell size along x and y (m).
    dx: f64,
    dy: f64,
    cells: usize,
    runs: usize,
    runs_incomplete: usize,
    core_seconds: f64,
    /// `curves.csv`: load, then (mean, lo, hi) of ℓ/Lx and of `A_R/A_R(0)`.
    loads: Vec<f64>,
    ell: Vec<(f64, f64, f64)>,
    area: Vec<(f64, f64, f64)>,
    /// The first-precursor load of each complete run with one.
    first: Vec<f64>,
    /// `avalanches.csv`: (ruptures, count).
    avalanches: Vec<(f64, f64)>,
}

impl Study {
    fn label(&self) -> String {
        if (self.dx - self.dy).abs() < 1e-12 {
            format!("{} mm", mm(self.dx))
        } else {
            format!("{} x {} mm", mm(self.dx), mm(self.dy))
        }
    }

    fn ell_means(&self) -> Vec<(f64, f64)> {
        self.loads
            .iter()
            .zip(&self.ell)
            .map(|(&f, e)| (f, e.0))
            .collect()
    }

    fn area_means(&self) -> Vec<(f64, f64)> {
        self.loads
            .iter()
            .zip(&self.area)
            .map(|(&f, a)| (f, a.0))
            .collect()
    }

    fn first_mean(&self) -> f64 {
        band(&self.first).0
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

fn read_study(dir: &Path) -> Result<Study, Box<dyn std::error::Error>> {
    let sweep_path = dir.join("sweep.json");
    let sweep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sweep_path).at("read", &sweep_path)?)
            .at("parse", &sweep_path)?;
    if sweep["axes"].as_array().is_some_and(|a| !a.is_empty()) {
        return Err(format!(
            "{}: a sweep with axes; the study's sweeps have one point each",
            sweep_path.display()
        )
        .into());
    }
    let base = &sweep["base"];
    let lx = number(base, &["block", "lx"], &sweep_path)?;
    let ly = number(base, &["block", "ly"], &sweep_path)?;
    let (dx, dy, nx, ny) = match base["cells"]["kind"].as_str() {
        Some("size") => {
            let dx = number(base, &["cells", "dx"], &sweep_path)?;
            let dy = number(base, &["cells", "dy"], &sweep_path)?;
            (dx, dy, (lx / dx).round(), (ly / dy).round())
        }
        Some("count") => {
            let nx = number(base, &["cells", "nx"], &sweep_path)?;
            let ny = number(base, &["cells", "ny"], &sweep_path)?;
            (lx / nx, ly / ny, nx, ny)
        }
        other => return Err(format!("{}: cells kind {other:?}", sweep_path.display()).into()),
    };
    let kind = base["heights"]["kind"].as_str().unwrap_or("gaussian");
    let (heights, slug) = match kind {
        "gaussian" => ("white noise (the paper's)".to_owned(), "white".to_owned()),
        "gaussian_surface" => {
            let xi = number(base, &["heights", "correlation_length"], &sweep_path)?;
            (
                format!("Gaussian surface, ξ = {} mm", mm(xi)),
                "surface".to_owned(),
            )
        }
        other => (other.replace('_', " "), other.to_owned()),
    };

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
    let triple = |name: &str| -> Result<Vec<Band>, Box<dyn std::error::Error>> {
        let m = curves.numbers(&format!("{name}_mean"))?;
        let lo = curves.numbers(&format!("{name}_lo"))?;
        let hi = curves.numbers(&format!("{name}_hi"))?;
        Ok((0..m.len()).map(|k| (m[k], lo[k], hi[k])).collect())
    };
    let ell = triple("precursor_over_Lx")?;
    let area = triple("area_ratio")?;

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
    let (mut runs, mut runs_incomplete, mut core_seconds, mut first) = (0, 0, 0.0, Vec::new());
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
        let meta: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&meta_path).at("read", &meta_path)?)
                .at("parse", &meta_path)?;
        core_seconds += number(&meta, &["seconds", "total"], &meta_path)?;
        if let Some(f) = first_precursor_load(&Table::read(&run.join("curve.csv"))?)? {
            first.push(f);
        }
        runs += 1;
    }
    Ok(Study {
        heights,
        slug,
        dx,
        dy,
        cells: (nx * ny) as usize,
        runs,
        runs_incomplete,
        core_seconds,
        loads,
        ell,
        area,
        first,
        avalanches,
    })
}

struct Args {
    out: PathBuf,
    figures: PathBuf,
    up_to: f64,
}

fn args() -> Result<Args, Box<dyn std::error::Error>> {
    let usage = "usage: convergence_figures OUTDIR [FIGDIR] [--up-to LOAD]";
    let mut positional = Vec::new();
    let mut up_to = f64::INFINITY;
    let mut argv = std::env::args().skip(1);
    while let Some(a) = argv.next() {
        if a == "--up-to" {
            let v = argv.next().ok_or(usage)?;
            up_to = v
                .parse::<f64>()
                .ok()
                .filter(|x| *x > 0.0 && *x <= 1.0)
                .ok_or_else(|| format!("--up-to {v}: a load F/(μF_N) in (0, 1] is needed"))?;
        } else if a.starts_with("--") {
            return Err(format!("unknown option {a}; {usage}").into());
        } else {
            positional.push(PathBuf::from(a));
        }
    }
    if positional.is_empty() || positional.len() > 2 {
        return Err(usage.into());
    }
    let figures = positional
        .get(1)
        .cloned()
        .unwrap_or_else(|| PathBuf::from("docs/figures"));
    Ok(Args {
        out: positional.swap_remove(0),
        figures,
        up_to,
    })
}

fn run() -> report::Outcome {
    let args = args()?;
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&args.out)
        .at("list", &args.out)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_dir()
                && p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("convergence_"))
        })
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        return Err(format!("{} holds no convergence_* directory", args.out.display()).into());
    }
    report::writable_dir(&args.figures)?;

    // Per heights kind, the sizes from the coarsest to the finest.
    let mut kinds: BTreeMap<String, Vec<Study>> = BTreeMap::new();
    for dir in &dirs {
        let study = read_study(dir)?;
        if study.runs_incomplete > 0 {
            eprintln!(
                "note: {}: {} runs not complete, left out",
                dir.display(),
                study.runs_incomplete
            );
        }
        kinds.entry(study.slug.clone()).or_default().push(study);
    }
    for studies in kinds.values_mut() {
        studies.sort_by(|a, b| b.dx.total_cmp(&a.dx));
        figures(studies, &args.figures, args.up_to)?;
        table(studies, args.up_to);
    }
    if let Some(surface) = kinds.get("surface") {
        let finest = surface.last().expect("a kind holds a study");
        for (slug, studies) in &kinds {
            if slug == "surface" {
                continue;
            }
            println!(
                "ℓ/Lx bands of {} against the finest {} ({}):\n",
                studies[0].heights,
                finest.heights,
                finest.label()
            );
            println!("| cell size | loads where the 95 % bands overlap | largest Δ ℓ/Lx |");
            println!("| --- | --- | --- |");
            for s in studies {
                let (overlap, shared) = overlapping_loads(
                    &bands_with_loads(&s.loads, &s.ell, args.up_to),
                    &bands_with_loads(&finest.loads, &finest.ell, args.up_to),
                );
                let d = max_difference(&s.ell_means(), &finest.ell_means(), args.up_to);
                println!("| {} | {overlap} of {shared} | {} |", s.label(), fmt(d));
            }
            println!();
        }
    }
    Ok(())
}

/// `(load, lo, hi)` of a banded curve at the loads up to `up_to`.
fn bands_with_loads(loads: &[f64], b: &[(f64, f64, f64)], up_to: f64) -> Vec<(f64, f64, f64)> {
    loads
        .iter()
        .zip(b)
        .filter(|(&f, _)| f <= up_to + 1e-9)
        .map(|(&f, t)| (f, t.1, t.2))
        .collect()
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

fn fmt(x: Option<f64>) -> String {
    match x {
        Some(0.0) => "0".into(),
        Some(v) if v.is_finite() => format!("{v:.3e}"),
        _ => "—".into(),
    }
}

fn table(studies: &[Study], up_to: f64) {
    let finest = studies.last().expect("a kind holds a study");
    let loads = if up_to.is_finite() {
        format!("loads F/(μF_N) ≤ {up_to}")
    } else {
        "all loads of curves.csv".to_owned()
    };
    println!(
        "{}: distance to the finest ({}), {loads}\n",
        finest.heights,
        finest.label()
    );
    println!(
        "| cell size | N | runs | cores x time (s) | max Δ ℓ/Lx | order | max Δ A_R/A_R(0) | \
         order | Δ first-precursor load | order | first-precursor load, mean [95 % band] |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let distances: Vec<[Option<f64>; 3]> = studies
        .iter()
        .map(|s| {
            [
                max_difference(&s.ell_means(), &finest.ell_means(), up_to),
                max_difference(&s.area_means(), &finest.area_means(), up_to),
                Some((s.first_mean() - finest.first_mean()).abs()).filter(|d| d.is_finite()),
            ]
        })
        .collect();
    for (k, s) in studies.iter().enumerate() {
        let mut cells = vec![
            s.label(),
            s.cells.to_string(),
            s.runs.to_string(),
            format!("{:.1}", s.core_seconds),
        ];
        for (q, &distance) in distances[k].iter().enumerate() {
            cells.push(fmt(distance));
            let order = match (k.checked_sub(1), distance) {
                (Some(c), Some(d)) => distances[c][q]
                    .and_then(|dc| observed_order(dc, d, studies[c].dx, s.dx))
                    .map(|p| format!("{p:.2}"))
                    .unwrap_or_else(|| "—".into()),
                _ => "—".into(),
            };
            cells.push(order);
        }
        let (m, lo, hi) = band(&s.first);
        cells.push(format!(
            "{m:.4} [{lo:.4}, {hi:.4}] ({} runs)",
            s.first.len()
        ));
        println!("| {} |", cells.join(" | "));
    }
    println!();
}

fn figures(studies: &[Study], dir: &Path, up_to: f64) -> report::Outcome {
    let heights = &studies[0].heights;
    let slug = &studies[0].slug;
    let path = |name: &str| dir.join(format!("convergence_{slug}_{name}.png"));

    let mut ell = Chart::new(
        &format!("Precursor length, {heights}: mean and 95 % band per cell size"),
        "F/(μF_N)",
        "ℓ/Lx",
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
        ell = ell.band(&format!("{} ({} runs)", s.label(), s.runs), &rows);
    }
    let p = path("precursor_length");
    ell.save(&p)?;
    eprintln!("wrote {}", p.display());

    // The relative growth of the real contact area, on a log axis, up to `--up-to` (the
    // area law's jump just before slip would set the axis otherwise).
    let growth = |x: f64| x - 1.0;
    let mut area = Chart::new(
        &format!("Real contact area, {heights}: mean and 95 % band per cell size"),
        "F/(μF_N)",
        "A_R/A_R(0) − 1",
    )
    .x_range(0.0, up_to.min(1.0))
    .log_y()
    .colours(Colours::Ordered)
    .legend(Corner::UpperLeft);
    for s in studies {
        let rows: Vec<_> = s
            .loads
            .iter()
            .zip(&s.area)
            .filter(|(&f, _)| f <= up_to + 1e-9)
            .map(|(&f, &(m, lo, hi))| (f, growth(m), growth(lo), growth(hi)))
            .collect();
        area = area.band(&s.label(), &rows);
    }
    let p = path("area");
    area.save(&p)?;
    eprintln!("wrote {}", p.display());

    let mut first = Chart::new(
        &format!("First precursor (ℓ > 0), {heights}"),
        "cell size Δx (mm)",
        "F/(μF_N)",
    )
    .legend(Corner::UpperRight);
    let band: Vec<_> = studies
        .iter()
        .map(|s| {
            let (m, lo, hi) = band(&s.first);
            (s.dx * 1e3, m, lo, hi)
        })
        .collect();
    first = first.band("mean, 95 % band", &band);
    let runs: Vec<_> = studies
        .iter()
        .flat_map(|s| s.first.iter().map(move |&f| (s.dx * 1e3, f)))
        .collect();
    first = first.markers("runs", &runs);
    let p = path("first_precursor");
    first.save(&p)?;
    eprintln!("wrote {}", p.display());

    let mut aval = Chart::new(
        &format!("Avalanche sizes, {heights}: pooled over the realizations"),
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
    let p = path("avalanches");
    aval.save(&p)?;
    eprintln!("wrote {}", p.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_difference_takes_the_largest_gap_over_shared_loads_up_to_the_limit() {
        // By hand: at 0.1 |0.2 - 0.25| = 0.05, at 0.2 |0.5 - 0.3| = 0.2, at 0.3 (only
        // in a) nothing, at 0.4 |0.9 - 0.1| = 0.8 but beyond up_to = 0.35.
        let a = [(0.1, 0.2), (0.2, 0.5), (0.3, 7.0), (0.4, 0.9)];
        let b = [(0.1, 0.25), (0.2, 0.3), (0.4, 0.1)];
        assert!((max_difference(&a, &b, 0.35).unwrap() - 0.2).abs() < 1e-15);
        assert!((max_difference(&a, &b, f64::INFINITY).unwrap() - 0.8).abs() < 1e-15);
        // A NaN mean (no realization at that load) is skipped, not propagated.
        let c = [(0.1, f64::NAN), (0.2, 0.35)];
        assert!((max_difference(&c, &b, 1.0).unwrap() - 0.05).abs() < 1e-15);
        assert_eq!(max_difference(&a, &[(0.9, 1.0)], 1.0), None);
    }

    #[test]
    fn observed_order_is_the_log_ratio_of_distances_over_that_of_cell_sizes() {
        // Halved cells, distance quartered: order 2; from 2 mm to 0.5 mm a factor 8 in
        // distance is order log(8)/log(4) = 1.5.
        assert!((observed_order(0.04, 0.01, 2.0, 1.0).unwrap() - 2.0).abs() < 1e-12);
        assert!((observed_order(0.8, 0.1, 2.0, 0.5).unwrap() - 1.5).abs() < 1e-12);
        // No convergence: the distance grows, the order is negative.
        assert!((observed_order(0.01, 0.02, 2.0, 1.0).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(observed_order(0.0, 0.01, 2.0, 1.0), None);
        assert_eq!(observed_order(0.1, 0.0, 2.0, 1.0), None);
        assert_eq!(observed_order(0.1, 0.05, 1.0, 2.0), None);
    }

    #[test]
    fn first_precursor_is_the_first_stable_state_with_a_front() {
        let text = "event,force_N,force_over_mu_FN,precursor_length_m\n\
                    1,0,0,0\n4,65,0.037,0\n7,82,0.047,1e-3\n10,90,0.05,0\n13,95,0.06,2e-3\n";
        let t = Table::parse(Path::new("curve.csv"), text).unwrap();
        assert_eq!(first_precursor_load(&t).unwrap(), Some(0.047));
        let none = "force_over_mu_FN,precursor_length_m\n0,0\n0.5,0\n";
        let t = Table::parse(Path::new("curve.csv"), none).unwrap();
        assert_eq!(first_precursor_load(&t).unwrap(), None);
        // A ragged row or a cell that is not a number is refused with the line.
        let bad = Table::parse(Path::new("c.csv"), "a,b\n1\n");
        assert!(bad.err().unwrap().to_string().contains("line 2"));
        let t = Table::parse(
            Path::new("c.csv"),
            "force_over_mu_FN,precursor_length_m\nx,0\n",
        );
        let e = first_precursor_load(&t.unwrap()).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("`x`"), "{e}");
    }

    #[test]
    fn bands_overlap_where_their_intervals_meet() {
        // At 0.1 [0, 1] and [0.5, 2] meet; at 0.2 [0, 1] and [1.5, 2] do not; at 0.3 a
        // NaN bound leaves the load out; 0.4 is only in a.
        let a = [
            (0.1, 0.0, 1.0),
            (0.2, 0.0, 1.0),
            (0.3, f64::NAN, 1.0),
            (0.4, 0.0, 1.0),
        ];
        let b = [(0.1, 0.5, 2.0), (0.2, 1.5, 2.0), (0.3, 0.0, 1.0)];
        assert_eq!(overlapping_loads(&a, &b), (1, 2));
    }

    #[test]
    fn at_least_is_the_complementary_cumulative_distribution() {
        // Counts 6, 3, 1 of sizes 1, 2, 5 (given out of order; a zero count dropped):
        // P(S ≥ 1) = 1, P(S ≥ 2) = 4/10, P(S ≥ 5) = 1/10.
        let rows = [(2.0, 3.0), (1.0, 6.0), (7.0, 0.0), (5.0, 1.0)];
        assert_eq!(at_least(&rows), vec![(1.0, 1.0), (2.0, 0.4), (5.0, 0.1)]);
    }

    #[test]
    fn lengths_print_in_millimetres_without_trailing_zeros() {
        assert_eq!(mm(0.00025), "0.25");
        assert_eq!(mm(0.001), "1");
        assert_eq!(mm(0.00175), "1.75");
    }
}
