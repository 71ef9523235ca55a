//! The tables `precursors stats` writes (`power_laws.csv`, `binned_means.csv`,
//! `scaling.csv`, `collapse.csv`; module [`crate::sweep::stats`]) read back for the
//! figures, by their header's names; the runs `stats` pooled ([`runs_pooled`]); and what
//! the likelihood-ratio tests say ([`preferred`]).

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

/// The complete runs `stats` pooled at point `point` (`power_laws.csv`'s `runs`, `table`):
/// `None` for a table written before that column, or without a row of the point.
///
/// # Errors
/// [`Error::CorruptTable`] for a damaged cell.
pub(super) fn runs_pooled(table: &Table, point: usize) -> Result<Option<usize>> {
    if !table.header.iter().any(|h| h == "runs") {
        return Ok(None);
    }
    let column = table.column("point")?;
    let point = point.to_string();
    let Some(row) = table.rows.iter().find(|r| r[column] == point) else {
        return Ok(None);
    };
    Ok(table.number(row, "runs")?.map(|v| v as usize))
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

/// The laws a distribution's tests compare, in the order of [`Fits::tests`]' pairs.
const MODELS: [&str; 4] = ["power law", "exponential", "log-normal", "cut-off law"];

/// The laws each test of [`Fits::tests`] compares: power law against exponential,
/// log-normal and cut-off law; cut-off law against log-normal.
const PAIRS: [(usize, usize); 4] = [(0, 1), (0, 2), (0, 3), (3, 2)];

/// What the tests of a distribution's fits say ([`preferred`]).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Verdict {
    /// The laws that lose no test, where one of them wins one (none where no law does).
    pub preferred: Vec<&'static str>,
    /// The verdict in clauses, each a line of a legend.
    pub clauses: Vec<String>,
}

/// What the tests say, in clauses that follow them (Clauset et al.; a test counts where its
/// p-value is below [`LR_SIGNIFICANCE`], the sign of `R` saying who wins):
///
/// 1. the goodness test of the pure power law: `pure power law rejected (p = …)` (`p ≤
///    0.1`), `… not rejected (p = …)`, or `power law's goodness not tested`;
/// 2. for each law that wins a test and loses none, in the order power law, exponential,
///    log-normal, cut-off law: `A preferred over B (p = …) and C (p = …)`;
/// 3. where several laws lose no test and one of them wins one: that the tests cannot tell
///    them apart, with the p of the test between two of them or `never compared` (the
///    exponential is compared with the power law only);
/// 4. where no law wins a test: `the likelihood-ratio tests cannot tell the laws apart
///    (every p ≥ 0.1)`; where each law that wins one loses another: `no law preferred: each
///    that wins a test loses another`.
///
/// A cut-off law fitted at `λ = 0` is the power law itself (said so; its tests are the
/// power law's). Without the alternatives: the goodness test and `no alternative fitted`.
pub(super) fn preferred(fits: &Fits) -> Verdict {
    let mut clauses = vec![match fits.p {
        Some(p) if p <= GOODNESS_REJECTS => format!("pure power law rejected (p = {})", p_text(p)),
        Some(p) => format!("pure power law not rejected (p = {})", p_text(p)),
        None => "power law's goodness not tested".to_string(),
    }];
    let Some(tests) = fits.tests else {
        clauses.push("no alternative fitted".into());
        return Verdict {
            preferred: Vec::new(),
            clauses,
        };
    };
    // At λ = 0 the cut-off law is the pure power law (nested): its tests are the power
    // law's own, and it is left out.
    let same = fits.cutoff.is_some_and(|(_, scale)| scale[0].is_none());
    let laws: &[usize] = if same { &[0, 1, 2] } else { &[0, 1, 2, 3] };
    let mut losses = [0; 4];
    if fits.rejected() {
        losses[0] += 1;
    }
    // (winner, loser, p) of each test that decides.
    let mut decided = Vec::new();
    for (&(a, b), t) in PAIRS.iter().zip(tests) {
        if !(laws.contains(&a) && laws.contains(&b)) {
            continue;
        }
        if t.p < LR_SIGNIFICANCE && t.log_ratio != 0.0 {
            let (w, l) = if t.log_ratio > 0.0 { (a, b) } else { (b, a) };
            losses[l] += 1;
            decided.push((w, l, t.p));
        }
    }
    let unbeaten: Vec<usize> = laws.iter().copied().filter(|&m| losses[m] == 0).collect();
    let winners: Vec<usize> = unbeaten
        .iter()
        .copied()
        .filter(|&m| decided.iter().any(|d| d.0 == m))
        .collect();
    if same {
        clauses.push("cut-off law fitted at λ = 0: the power law itself".into());
    }
    if decided.is_empty() {
        clauses.push(format!(
            "the likelihood-ratio tests cannot tell the laws apart (every p ≥ {LR_SIGNIFICANCE})"
        ));
    } else if winners.is_empty() {
        clauses.push("no law preferred: each that wins a test loses another".into());
    }
    for &w in &winners {
        let beaten: Vec<String> = decided
            .iter()
            .filter(|d| d.0 == w)
            .map(|&(_, l, p)| format!("{} (p = {})", MODELS[l], p_text(p)))
            .collect();
        clauses.push(format!(
            "{} preferred over {}",
            MODELS[w],
            beaten.join(" and ")
        ));
    }
    if !winners.is_empty() && unbeaten.len() > 1 {
        let names: Vec<&str> = unbeaten.iter().map(|&m| MODELS[m]).collect();
        clauses.push(match unbeaten.as_slice() {
            [a, b] => {
                let (a, b) = (*a, *b);
                let test = PAIRS
                    .iter()
                    .zip(tests)
                    .find(|(pair, _)| **pair == (a, b) || **pair == (b, a));
                let p = match test {
                    Some((_, t)) => format!("p = {}", p_text(t.p)),
                    None => "never compared".into(),
                };
                format!("the tests cannot tell {} from {} ({p})", names[0], names[1])
            }
            _ => format!(
                "the tests cannot tell {} and {} apart",
                names[..names.len() - 1].join(", "),
                names[names.len() - 1]
            ),
        });
    }
    let preferred = if winners.is_empty() {
        Vec::new()
    } else {
        unbeaten.iter().map(|&m| MODELS[m]).collect()
    };
    Verdict { preferred, clauses }
}

/// A p-value in a legend: two decimals, or two digits below 0.01.
pub(super) fn p_text(p: f64) -> String {
    if p >= 0.01 || p == 0.0 {
        format!("{p:.2}")
    } else {
        format!("{p:.1e}")
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

    /// The verdict's clauses.
    fn says(fits: &Fits) -> Vec<String> {
        preferred(fits).clauses
    }

    /// Rows of docs/statistics.md's study table (R of the power law against the
    /// exponential made up: the table leaves it out); each expected clause read off the
    /// tests by hand: a test decides at p < 0.1, for the law its R's sign favours.
    #[test]
    fn the_verdict_says_what_each_test_decides() {
        // rod, avalanche_ruptures: PL rejected (0.07); PL over exponential (0.01),
        // cut-off over PL (0.02), cut-off over log-normal (R 0.3, p 0.06); PL against
        // log-normal undecided (0.15). The cut-off law alone loses nothing.
        let rod = fits(
            Some(0.07),
            [(5.0, 0.01), (-2.4, 0.15), (-3.0, 0.02), (0.3, 0.06)],
        );
        assert_eq!(
            says(&rod),
            [
                "pure power law rejected (p = 0.07)",
                "cut-off law preferred over power law (p = 0.02) and log-normal (p = 0.06)",
            ]
        );
        assert_eq!(preferred(&rod).preferred, ["cut-off law"]);
        // spring, avalanche_ruptures: no test decides.
        let spring = fits(
            Some(0.26),
            [(0.5, 0.6), (-0.4, 0.52), (-0.6, 0.25), (0.3, 0.67)],
        );
        assert_eq!(
            says(&spring),
            [
                "pure power law not rejected (p = 0.26)",
                "the likelihood-ratio tests cannot tell the laws apart (every p ≥ 0.1)",
            ]
        );
        assert!(preferred(&spring).preferred.is_empty());
        // surface 0.5 mm, precursor leaps: cut-off over PL; cut-off against log-normal
        // undecided (0.91), log-normal against PL undecided (0.22): both unbeaten.
        let both = fits(
            Some(0.0),
            [(9.0, 0.0), (-2.7, 0.22), (-2.0, 0.02), (-0.1, 0.91)],
        );
        assert_eq!(
            says(&both),
            [
                "pure power law rejected (p = 0.00)",
                "cut-off law preferred over power law (p = 0.02)",
                "the tests cannot tell log-normal from cut-off law (p = 0.91)",
            ]
        );
        assert_eq!(preferred(&both).preferred, ["log-normal", "cut-off law"]);
        // The rod sweep's case: the exponential is compared with the power law only,
        // which it does not beat (0.5): it and the cut-off law are both unbeaten.
        let exponential = fits(
            Some(0.0),
            [(-1.0, 0.5), (-2.7, 0.02), (-2.0, 0.02), (0.1, 0.004)],
        );
        assert_eq!(
            says(&exponential),
            [
                "pure power law rejected (p = 0.00)",
                "cut-off law preferred over power law (p = 0.02) and log-normal (p = 4.0e-3)",
                "the tests cannot tell exponential from cut-off law (never compared)",
            ]
        );
        assert_eq!(
            preferred(&exponential).preferred,
            ["exponential", "cut-off law"]
        );
        // A power law not rejected that beats the exponential and the log-normal: the
        // nested test cannot favour it over the cut-off law (R = 0).
        let power = fits(
            Some(0.5),
            [(4.0, 0.01), (3.0, 0.05), (0.0, 1.0), (0.1, 0.9)],
        );
        assert_eq!(
            says(&power),
            [
                "pure power law not rejected (p = 0.50)",
                "power law preferred over exponential (p = 0.01) and log-normal (p = 0.05)",
                "the tests cannot tell power law from cut-off law (p = 1.00)",
            ]
        );
        let alone = fits(
            Some(0.5),
            [(4.0, 0.01), (3.0, 0.05), (-2.0, 0.5), (0.3, 0.05)],
        );
        assert_eq!(
            says(&alone),
            [
                "pure power law not rejected (p = 0.50)",
                "power law preferred over exponential (p = 0.01) and log-normal (p = 0.05)",
                "cut-off law preferred over log-normal (p = 0.05)",
                "the tests cannot tell power law from cut-off law (p = 0.50)",
            ]
        );
        // rod, precursor leaps: the cut-off law at λ = 0 is the rejected power law; the
        // log-normal beats it (0.02), which beats the exponential (0.05).
        let mut leaps = fits(
            Some(0.03),
            [(2.0, 0.05), (-0.3, 0.02), (0.0, 1.0), (-0.3, 0.02)],
        );
        leaps.cutoff = Some(((3.97, 3.3, 4.4), [None, Some(18.5), None]));
        assert_eq!(
            says(&leaps),
            [
                "pure power law rejected (p = 0.03)",
                "cut-off law fitted at λ = 0: the power law itself",
                "log-normal preferred over power law (p = 0.02)",
            ]
        );
        assert_eq!(preferred(&leaps).preferred, ["log-normal"]);
        // A cycle: the power law beats the log-normal, which beats the cut-off law,
        // which beats the power law.
        let cycle = fits(
            Some(0.5),
            [(0.0, 1.0), (2.0, 0.01), (-2.0, 0.01), (-2.0, 0.01)],
        );
        assert_eq!(
            says(&cycle)[1],
            "no law preferred: each that wins a test loses another"
        );
        assert!(preferred(&cycle).preferred.is_empty());
        // Without the alternatives: the goodness test alone.
        let mut bare = fits(Some(0.05), [(0.0, 1.0); 4]);
        bare.tests = None;
        assert_eq!(
            says(&bare),
            [
                "pure power law rejected (p = 0.05)",
                "no alternative fitted"
            ]
        );
    }

    #[test]
    fn quoted_cells_are_one_cell() {
        assert_eq!(
            split("1,\"a, b\",\"say \"\"hi\"\"\","),
            ["1", "a, b", "say \"hi\"", ""]
        );
    }
}
