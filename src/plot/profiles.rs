//! The figures of the profiles a run recorded at requested loads (`profiles.csv`, scene
//! key `profiles`), drawn by [`super::draw`] for a run that records them:
//!
//! * `slip_profiles`: the slip `⟨u_x⟩_y` (µm) along `x` at each recorded load;
//! * `shear_profiles` and `normal_profiles` (the paper's Fig. S10): `|τ(x, z_P)|` and
//!   `|σ(x, z_P)|` (MPa) on the lowest recorded plane above the interface, at each load;
//! * `coulomb_profiles` (the paper's Fig. 7): at the first recorded load, `|τ|`, `|σ|`
//!   and `τ_C = |τ| - μ|σ|` of the y-averages on that plane, and `τ_C` averaged over `y`
//!   at the interface when the plane `z = 0` is recorded too.
//!
//! One curve per load, coloured along the sequential map [`Colours::Ordered`] (dark at
//! the lowest load).

use super::selection::Selection;
use super::{short, Canvas, Chart, Colours, Corner, PlotError, Style};
use crate::output::check::RunRecord;
use crate::output::layout::{
    COULOMB_PROFILES_FIGURE, NORMAL_PROFILES_FIGURE, SHEAR_PROFILES_FIGURE, SLIP_PROFILES_FIGURE,
};
use crate::output::profiles::ProfileRow;
use std::path::{Path, PathBuf};

/// What [`draw_profiles`] drew, and what it left out and why.
#[derive(Debug, Default)]
pub(super) struct Profiles {
    pub files: Vec<PathBuf>,
    pub notes: Vec<String>,
}

/// One recorded load's rows.
struct Level<'a> {
    load: f64,
    rows: Vec<&'a ProfileRow>,
}

impl Level<'_> {
    /// The values of `field` at height `z`, against `x` (mm) at the columns' centres.
    fn curve(&self, field: &str, z: f64, dx_mm: f64, f: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
        self.rows
            .iter()
            .find(|r| r.field == field && r.z == z)
            .map(|r| {
                r.values
                    .iter()
                    .enumerate()
                    .map(|(ix, &v)| ((ix as f64 + 0.5) * dx_mm, f(v)))
                    .collect()
            })
            .unwrap_or_default()
    }

    fn label(&self) -> String {
        format!("F/(μF_N) = {}", short(self.load))
    }
}

/// Draws the profiles figures `selection` wants of the run `record` (read from `dir`)
/// into `dir`, as files of each of `extensions`.
pub(super) fn draw_profiles(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (title, record): (&str, &RunRecord),
    selection: &Selection,
) -> Result<Profiles, PlotError> {
    let mut drawn = Profiles::default();
    let names = [
        SLIP_PROFILES_FIGURE,
        SHEAR_PROFILES_FIGURE,
        NORMAL_PROFILES_FIGURE,
        COULOMB_PROFILES_FIGURE,
    ];
    if !names.iter().any(|n| selection.wants(n)) {
        return Ok(drawn);
    }
    let Some(rows) = crate::output::profiles::read(dir, record)? else {
        return Ok(drawn);
    };
    let levels = levels(&rows, record.options.profile_loads());
    if levels.is_empty() {
        for name in names.iter().filter(|n| selection.wants(n)) {
            let reason = "the run passed none of the loads of `profiles.loads`".to_string();
            selection.skip(name, dir, reason, &mut drawn.notes)?;
        }
        return Ok(drawn);
    }
    let figures = Figures {
        dir,
        extensions,
        canvas,
        title,
        selection,
        levels: &levels,
        dx_mm: record.grid.dx() * 1e3,
        lx_mm: record.bounds.lx * 1e3,
    };
    let micro = |v: f64| v * 1e6;
    let slip = figures.family(
        "Slip profiles ⟨u_x⟩_y",
        "⟨u_x⟩_y (µm)",
        ("slip_m", 0.0),
        &micro,
    );
    figures.save(slip, SLIP_PROFILES_FIGURE, &mut drawn)?;
    let planes = record.options.profile_planes();
    // Without a plane above the interface, the selection left the stress figures out
    // (with a note).
    let Some(z_p) = planes.iter().copied().filter(|&z| z > 0.0).reduce(f64::min) else {
        return Ok(drawn);
    };
    let at = format!("z_P = {} mm", short(z_p * 1e3));
    let shear = figures.family(
        &format!("|τ(x, z_P)|, {at}"),
        "|τ_{xz}| (MPa)",
        ("shear_Pa", z_p),
        &magnitude_mpa,
    );
    figures.save(shear, SHEAR_PROFILES_FIGURE, &mut drawn)?;
    let normal = figures.family(
        &format!("|σ(x, z_P)|, {at}"),
        "|σ_{zz}| (MPa)",
        ("normal_Pa", z_p),
        &magnitude_mpa,
    );
    figures.save(normal, NORMAL_PROFILES_FIGURE, &mut drawn)?;
    let coulomb = figures.coulomb((z_p, &at), planes.contains(&0.0), &mut drawn);
    figures.save(coulomb, COULOMB_PROFILES_FIGURE, &mut drawn)?;
    Ok(drawn)
}

/// `|v|` in MPa (`v` in Pa).
fn magnitude_mpa(v: f64) -> f64 {
    v.abs() * 1e-6
}

/// The rows of `profiles.csv` grouped by load, in the table's (increasing) order.
fn levels<'a>(rows: &'a [ProfileRow], loads: &[f64]) -> Vec<Level<'a>> {
    let mut levels: Vec<Level> = Vec::new();
    for row in rows {
        match levels.last_mut() {
            Some(l) if l.load == loads[row.level] => l.rows.push(row),
            _ => levels.push(Level {
                load: loads[row.level],
                rows: vec![row],
            }),
        }
    }
    levels
}

/// What every profiles figure of a run shares.
struct Figures<'a> {
    dir: &'a Path,
    extensions: &'a [&'a str],
    canvas: Canvas,
    title: &'a str,
    selection: &'a Selection,
    levels: &'a [Level<'a>],
    /// The cell size and the block's length (mm).
    dx_mm: f64,
    lx_mm: f64,
}

impl Figures<'_> {
    /// Writes `chart` as the figure `name` in each format, when the selection wants it.
    fn save(&self, chart: Chart, name: &str, drawn: &mut Profiles) -> Result<(), PlotError> {
        if !self.selection.wants(name) {
            return Ok(());
        }
        for extension in self.extensions {
            let path = self.dir.join(format!("{name}.{extension}"));
            chart.save(&path)?;
            drawn.files.push(path);
        }
        Ok(())
    }

    /// A chart against `x` (mm): the profile `field` at height `z`, one curve per load,
    /// its values through `f`.
    fn family(
        &self,
        what: &str,
        y: &str,
        (field, z): (&str, f64),
        f: &dyn Fn(f64) -> f64,
    ) -> Chart {
        self.levels.iter().fold(
            self.canvas
                .chart(&format!("{what}: {}", self.title), "x (mm)", y)
                .x_range(0.0, self.lx_mm)
                .colours(Colours::Ordered)
                .legend(Corner::UpperRight),
            |chart, level| chart.line(&level.label(), &level.curve(field, z, self.dx_mm, f)),
        )
    }

    /// The paper's Fig. 7 at the first recorded load: `|τ|`, `|σ|` and `τ_C` of the
    /// y-averages on the plane `z_p` (described by `at`), and with `interface` `τ_C`
    /// averaged over `y` at `z = 0` (else a note, when the figure is wanted).
    fn coulomb(&self, (z_p, at): (f64, &str), interface: bool, drawn: &mut Profiles) -> Chart {
        let first = &self.levels[0];
        let mpa = |v: f64| v * 1e-6;
        let chart = self
            .canvas
            .chart(
                &format!("Stresses at {}, {at}: {}", first.label(), self.title),
                "x (mm)",
                "stress (MPa)",
            )
            .x_range(0.0, self.lx_mm)
            .legend(Corner::UpperRight)
            .line(
                "|τ(x, z_P)|",
                &first.curve("shear_Pa", z_p, self.dx_mm, magnitude_mpa),
            )
            .line(
                "|σ(x, z_P)|",
                &first.curve("normal_Pa", z_p, self.dx_mm, magnitude_mpa),
            )
            .line(
                "τ_C(x, z_P) = |τ| - μ|σ|",
                &first.curve("coulomb_of_means_Pa", z_p, self.dx_mm, mpa),
            );
        if interface {
            return chart
                .line(
                    "τ_C(x, 0), averaged over y",
                    &first.curve("mean_coulomb_Pa", 0.0, self.dx_mm, mpa),
                )
                .style(Style::new().dashed());
        }
        if self.selection.wants(COULOMB_PROFILES_FIGURE) {
            drawn.notes.push(
                "coulomb_profiles: no τ_C at the interface (record the plane z = 0 in \
                 `profiles.planes`)"
                    .into(),
            );
        }
        chart
    }
}
