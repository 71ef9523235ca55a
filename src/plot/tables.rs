//! The tables `precursors stats` writes (`power_laws.csv`, `binned_means.csv`,
//! `scaling.csv`, `collapse.csv`; module [`crate::sweep::stats`]) read back for the
//! figures, by their header's names; and the model the likelihood-ratio tests prefer
//! ([`preferred`]).

use crate::error::{Error, Result};
use crate::statistics::{Comparison, PowerLawFit, LR_SIGNIFICANCE};
use std::path::Path;

/// The goodness p-value at or below which the pure power law is ruled out (Clauset et
/// al.; the rule of `Comparison::verdict`).
pub(super) const GOODNESS_REJECTS: f64 = 0.1;

/// A table read whole: its header and its rows, cells unquoted.
pub(super) struct Table {
    path: std::path::PathBuf,
    header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// The table at `path`, `None` when there is none.
    ///
    /// # Errors
    /// [`Error::Io`] when it cannot be read, [`Error::CorruptTable`] for a row whose cells
    /// are not the header's.
    pub(super) fn read(path: &Path) -> Result<Option<Table>> {
        if !crate::files::is_file(path, "examining a statistics table")? {
            return Ok(None);
        }
        let text = crate::files::read_text(path, "reading a statistics table")?;
        let mut lines = text.lines();
        let header = split(lines.next().unwrap_or(""));
        let mut rows = Vec::new();
        for (k, line) in lines.enumerate() {
            let row = split(line);
            if row.len() != header.len() {
                return Err(Error::CorruptTable {
                    path: Some(path.to_path_buf()),
                    reason: format!(
                        "line {}: {} cells under a header of {}",
                        k + 2,
                        row.len(),
                        header.len()
                    ),
                });
            }
            rows.push(row);
        }
        Ok(Some(Table {
            path: path.to_path_buf(),
            header,
            rows,
        }))
    }

    /// The place of column `name`.
    ///
    /// # Errors
    /// [`Error::CorruptTable`] when the header has no such column.
    pub(super) fn column(&self, name: &str) -> Result<usize> {
        self.header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| Error::CorruptTable {
                path: Some(self.path.clone()),
                reason: format!("no column {name} in its header"),
            })
    }

    /// Row `row`'s cell of column `name` as a number: `None` for an empty cell (the
    /// tables' infinity or missing value).
    ///
    /// # Errors
    /// [`Error::CorruptTable`] for a cell that is not a number, or no such column.
    pub(super) fn number(&self, row: &[String], name: &str) -> Result<Option<f64>> {
        let text = &row[self.column(name)?];
        if text.is_empty() {
            return Ok(None);
        }
        text.parse::<f64>()
            .map(Some)
            .map_err(|_| Error::CorruptTable {
                path: Some(self.path.clone()),
                reason: format!("{name} = {text:?} is not a number"),
            })
    }

    /// The rows of point `point` (the `point` column) whose column `key` holds `value`.
    pub(super) fn rows_of<'a>(
        &'a self,
        point: usize,
        (key, value): (&str, &str),
    ) -> Result<Vec<&'a [String]>> {
        let (p, k) = (self.column("point")?, self.column(key)?);
        let point = point.to_string();
        Ok(self
            .rows
            .iter()
            .filter(|r| r[p] == point && r[k] == value)
            .map(|r| r.as_slice())
            .collect())
    }
}

/// A CSV line's cells, a quoted cell unquoted (`"a, b"` is one cell, `""` a quote).
fn split(line: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                cells.last_mut().expect("one cell").push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => cells.push(String::new()),
            (c, _) => cells.last_mut().expect("one cell").push(c),
        }
    }
    cells
}

/// A likelihood-ratio test as the figures read it: `R` (positive: the first law is the
/// more likely) and its p-value.
#[derive(Debug, Clone, Copy)]
pub(super) struct Test {
    pub log_ratio: f64,
    pub p: f64,
}

/// The cut-off law's `α` with its interval and `1/λ` with its interval (`None`: infinite).
pub(super) type CutoffFits = ((f64, f64, f64), [Option<f64>; 3]);

/// A distribution's fits as a figure draws them: the power law and, where `stats` compared
/// them, the cut-off law and the tests (`power_laws.csv`'s row, or
/// [`crate::statistics::compare_alternatives`]'s result).
#[derive(Debug, Clone)]
pub(super) struct Fits {
    /// `n`, the positive samples.
    pub samples: usize,
    /// `n_tail`, those at or above `x_min`.
    pub tail: usize,
    pub x_min: f64,
    /// `α` and its interval.
    pub alpha: (f64, f64, f64),
    /// The goodness-of-fit p-value (none when not computed).
    pub p: Option<f64>,
    /// The cut-off law: `α` and its interval, `1/λ` and its interval (`None`: infinite).
    pub cutoff: Option<CutoffFits>,
    /// Power law against exponential, log-normal and cut-off law; cut-off law against
    /// log-normal.
    pub tests: Option<[Test; 4]>,
}

impl Fits {
    /// The fits of a comparison (the figure's own, when `stats` wrote none).
    pub(super) fn of(c: &Comparison) -> Fits {
        let mut fits = Fits::of_power_law(&c.power_law);
        let k = &c.cutoff;
        let finite = |v: f64| v.is_finite().then_some(v);
        fits.cutoff = Some((
            (k.alpha, k.alpha_low, k.alpha_high),
            [
                finite(k.cutoff),
                finite(k.cutoff_low),
                finite(k.cutoff_high),
            ],
        ));
        let test = |t: &crate::statistics::LikelihoodRatio| Test {
            log_ratio: t.log_ratio,
            p: t.p_value,
        };
        fits.tests = Some([
            test(&c.vs_exponential),
            test(&c.vs_lognormal),
            test(&c.vs_cutoff),
            test(&c.cutoff_vs_lognormal),
        ]);
        fits
    }

    /// The power law alone.
    pub(super) fn of_power_law(f: &PowerLawFit) -> Fits {
        Fits {
            samples: f.samples,
            tail: f.tail,
            x_min: f.x_min,
            alpha: (f.alpha, f.alpha_low, f.alpha_high),
            p: f.p_value,
            cutoff: None,
            tests: None,
        }
    }

    /// The row of `observable` at point `point` in `power_laws.csv` (`table`): `None`
    /// without one; else its samples `n` and its fits (`None` where the row's fit is
    /// empty: too few samples).
    ///
    /// # Errors
    /// [`Error::CorruptTable`] for a damaged row, or several for the pair.
    pub(super) fn read(
        table: &Table,
        point: usize,
        observable: &str,
    ) -> Result<Option<(usize, Option<Fits>)>> {
        let rows = table.rows_of(point, ("observable", observable))?;
        let row = match rows.as_slice() {
            [] => return Ok(None),
            [row] => row,
            _ => {
                return Err(Error::CorruptTable {
                    path: Some(table.path.clone()),
                    reason: format!(
                        "{} rows of point {point}, observable {observable}: one expected",
                        rows.len()
                    ),
                })
            }
        };
        let n = |name: &str| table.number(row, name);
        let needed = |name: &str| {
            n(name)?.ok_or_else(|| Error::CorruptTable {
                path: Some(table.path.clone()),
                reason: format!("point {point}, {observable}: {name} is empty"),
            })
        };
        let samples = needed("samples")? as usize;
        let Some(tail) = n("tail")? else {
            return Ok(Some((samples, None)));
        };
        let mut fits = Fits {
            samples,
            tail: tail as usize,
            x_min: needed("x_min")?,
            alpha: (
                needed("alpha")?,
                needed("alpha_low")?,
                needed("alpha_high")?,
            ),
            p: n("p_value")?,
            cutoff: None,
            tests: None,
        };
        if let Some(alpha) = n("cutoff_alpha")? {
            fits.cutoff = Some((
                (
                    alpha,
                    needed("cutoff_alpha_low")?,
                    needed("cutoff_alpha_high")?,
                ),
                [
                    n("cutoff_scale")?,
                    n("cutoff_scale_low")?,
                    n("cutoff_scale_high")?,
                ],
            ));
            let test = |name: &str| -> Result<Test> {
                Ok(Test {
                    log_ratio: needed(name)?,
                    p: needed(&format!("{name}_p"))?,
                })
            };
            fits.tests = Some([
                test("lr_exponential")?,
                test("lr_lognormal")?,
                test("lr_cutoff")?,
                test("lr_cutoff_vs_lognormal")?,
            ]);
        }
        Ok(Some((samples, Some(fits))))
    }

    /// Whether the pure power law is ruled out by its goodness test (`p ≤ 0.1`).
    pub(super) fn rejected(&self) -> bool {
        self.p.is_some_and(|p| p <= GOODNESS_REJECTS)
    }
}

/// The model the tests prefer, in words: of the pure power law, the exponential, the
/// log-normal and the power law with cut-off, the ones that lose no test, a test counting
/// where its p-value is below [`LR_SIGNIFICANCE`] (the sign of `R` says who wins) and the
/// power law losing where its goodness test rejects it (`p ≤ 0.1`). One such model: its
/// name; several: `A or B (not distinguished)` (no test separates them: the cut-off law
/// and the exponential are never compared); where none of them wins a test, that the
/// tests do not decide. A cut-off law fitted at `λ = 0` is the power law itself. Without the alternatives: the power law's goodness alone.
pub(super) fn preferred(fits: &Fits) -> String {
    const NAMES: [&str; 4] = ["power law", "exponential", "log-normal", "cut-off law"];
    let Some(tests) = fits.tests else {
        return match fits.p {
            Some(p) if p <= GOODNESS_REJECTS => "none: power law rejected, no alternative fitted",
            Some(_) => "power law (not rejected; no alternative fitted)",
            None => "not tested",
        }
        .to_string();
    };
    let (mut wins, mut losses) = ([0; 4], [0; 4]);
    if fits.rejected() {
        losses[0] += 1;
    }
    // (first, second) of each test: power law against exponential, log-normal, cut-off
    // law; cut-off law against log-normal.
    for ((a, b), t) in [(0, 1), (0, 2), (0, 3), (3, 2)].into_iter().zip(tests) {
        if t.p < LR_SIGNIFICANCE && t.log_ratio != 0.0 {
            let (w, l) = if t.log_ratio > 0.0 { (a, b) } else { (b, a) };
            wins[w] += 1;
            losses[l] += 1;
        }
    }
    // At λ = 0 the cut-off law is the pure power law (nested): one model.
    let same = fits.cutoff.is_some_and(|(_, scale)| scale[0].is_none());
    if same {
        wins[0] += wins[3];
        losses[0] += losses[3];
    }
    let models = if same { 0..3 } else { 0..4 };
    let unbeaten: Vec<usize> = models.filter(|&m| losses[m] == 0).collect();
    if unbeaten.iter().all(|&m| wins[m] == 0) {
        return "none: the tests do not decide".to_string();
    }
    let names: Vec<&str> = unbeaten.iter().map(|&m| NAMES[m]).collect();
    match names.as_slice() {
        [one] => one.to_string(),
        many => format!("{} (not distinguished)", many.join(" or ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fits(p: Option<f64>, tests: [(f64, f64); 4]) -> Fits {
        Fits {
            samples: 100,
            tail: 50,
            x_min: 1.0,
            alpha: (2.0, 1.9, 2.1),
            p,
            cutoff: Some(((1.5, 1.4, 1.6), [Some(10.0), Some(8.0), Some(12.0)])),
            tests: Some(tests.map(|(log_ratio, p)| Test { log_ratio, p })),
        }
    }

    /// Rows of docs/statistics.md's study table (R of the power law against the
    /// exponential made up: the table leaves it out).
    #[test]
    fn the_preferred_model_is_the_one_that_loses_no_test_and_wins_one() {
        // rod, avalanche_ruptures: PL rejected (0.07), cut-off over PL (0.02), cut-off
        // over log-normal (R 0.3, p 0.06).
        let rod = fits(
            Some(0.07),
            [(5.0, 0.01), (-2.4, 0.15), (-3.0, 0.02), (0.3, 0.06)],
        );
        assert_eq!(preferred(&rod), "cut-off law");
        // spring, avalanche_ruptures: nothing decides.
        let spring = fits(
            Some(0.26),
            [(0.5, 0.6), (-0.4, 0.52), (-0.6, 0.25), (0.3, 0.67)],
        );
        assert_eq!(preferred(&spring), "none: the tests do not decide");
        // surface 0.5 mm, precursor leaps: cut-off over PL, cut-off and log-normal alike.
        let both = fits(
            Some(0.0),
            [(9.0, 0.0), (-2.7, 0.22), (-2.0, 0.02), (-0.1, 0.91)],
        );
        assert_eq!(
            preferred(&both),
            "log-normal or cut-off law (not distinguished)"
        );
        // The exponential is compared with the power law only.
        let exponential = fits(
            Some(0.0),
            [(-1.0, 0.5), (-2.7, 0.02), (-2.0, 0.02), (0.1, 0.01)],
        );
        assert_eq!(
            preferred(&exponential),
            "exponential or cut-off law (not distinguished)"
        );
        // A power law not rejected that beats every alternative.
        let power = fits(
            Some(0.5),
            [(4.0, 0.01), (3.0, 0.05), (0.0, 1.0), (0.1, 0.9)],
        );
        assert_eq!(
            preferred(&power),
            "power law or cut-off law (not distinguished)",
            "the nested test cannot favour the power law"
        );
        let alone = fits(
            Some(0.5),
            [(4.0, 0.01), (3.0, 0.05), (-2.0, 0.5), (0.3, 0.05)],
        );
        assert_eq!(
            preferred(&alone),
            "power law or cut-off law (not distinguished)"
        );
        // rod, precursor leaps: the cut-off law at λ = 0 is the rejected power law.
        let mut leaps = fits(
            Some(0.03),
            [(2.0, 0.05), (-0.3, 0.02), (0.0, 1.0), (-0.3, 0.02)],
        );
        leaps.cutoff = Some(((3.97, 3.3, 4.4), [None, Some(18.5), None]));
        assert_eq!(preferred(&leaps), "log-normal");
    }

    #[test]
    fn quoted_cells_are_one_cell() {
        assert_eq!(
            split("1,\"a, b\",\"say \"\"hi\"\"\","),
            ["1", "a, b", "say \"hi\"", ""]
        );
    }
}
