//! Which figures [`super::draw_with_options`] draws for a directory: those named, or every
//! one the directory allows, found from its scene or sweep file before any table is read;
//! the drawers of `figures.rs`, `distributions.rs` and `paper.rs` ask it ([`Selection`]).

use super::PlotError;
use crate::output::layout::{
    ARCHARD_FIGURE, COLLAPSE_FIGURE, COULOMB_PROFILES_FIGURE, DROPS_FIGURE, FIGURES,
    FIGURE_EXTENSIONS, MAP_FIGURE, NORMAL_PROFILES_FIGURE, SHEAR_PROFILES_FIGURE,
    SLIP_PROFILES_FIGURE, STICK_SLIP_FIGURE,
};
use crate::sweep::SWEEP_FILE;
use std::path::Path;

/// The scene key of the normal load `F_N` (N), the axis of `archard`.
pub(super) const NORMAL_LOAD: &str = "normal_load";

/// The figures [`super::draw_with_options`] draws: those named, or every one the directory
/// allows as far as known before its tables are read.
#[derive(Debug)]
pub(super) struct Selection {
    figures: Vec<&'static str>,
    named: bool,
}

impl Selection {
    /// The selection for the run or sweep directory `dir` from the figures `named` (none:
    /// all), and the notes on those left out.
    ///
    /// # Errors
    /// [`PlotError::FigureUnavailable`] for a named figure the directory cannot give.
    pub(super) fn of(
        dir: &Path,
        sweep: bool,
        named: Vec<&'static str>,
    ) -> Result<(Selection, Vec<String>), PlotError> {
        let facts = Facts::of(dir, sweep);
        let mut notes = Vec::new();
        let asked = !named.is_empty();
        let mut figures = Vec::new();
        for figure in if asked { named } else { FIGURES.to_vec() } {
            match facts.unavailable(figure, dir) {
                None => figures.push(figure),
                Some((reason, _)) if asked => {
                    return Err(PlotError::FigureUnavailable {
                        figure: figure.to_string(),
                        dir: dir.to_path_buf(),
                        reason,
                    })
                }
                Some((reason, Leave::WithNote)) => {
                    notes.push(format!("no {figure} figure: {reason}"))
                }
                Some((_, Leave::Silently)) => {}
                Some((_, Leave::ToTheTables)) => figures.push(figure),
            }
        }
        Ok((
            Selection {
                figures,
                named: asked,
            },
            notes,
        ))
    }

    /// Whether `figure` is to be drawn.
    pub(super) fn wants(&self, figure: &str) -> bool {
        self.figures.contains(&figure)
    }

    /// `figure` cannot be drawn, found from the tables: an error when it was named, else
    /// a note in `notes`.
    pub(super) fn skip(
        &self,
        figure: &str,
        dir: &Path,
        reason: String,
        notes: &mut Vec<String>,
    ) -> Result<(), PlotError> {
        if self.named {
            return Err(PlotError::FigureUnavailable {
                figure: figure.to_string(),
                dir: dir.to_path_buf(),
                reason,
            });
        }
        notes.push(format!("no {figure} figure: {reason}"));
        Ok(())
    }

    /// `figure` cannot be drawn, found from the tables: an error when it was named, else
    /// left out without a word (the figures of `stats`' tables before `stats` ran), but
    /// where the directory holds a file of that figure from an earlier plot: a note in
    /// `notes` then says that it no longer matches the tables.
    pub(super) fn skip_quietly(
        &self,
        figure: &str,
        dir: &Path,
        reason: String,
        notes: &mut Vec<String>,
    ) -> Result<(), PlotError> {
        let mut earlier = Vec::new();
        for extension in FIGURE_EXTENSIONS {
            let name = format!("{figure}.{extension}");
            if crate::files::is_file(&dir.join(&name), "examining an earlier figure")? {
                earlier.push(name);
            }
        }
        if earlier.is_empty() || self.named {
            return self.skip(figure, dir, reason, &mut Vec::new());
        }
        notes.push(format!(
            "no {figure} figure: {reason}; {} in the directory {} from an earlier plot, \
             not from these tables",
            earlier.join(" and "),
            if earlier.len() == 1 { "is" } else { "are" }
        ));
        Ok(())
    }
}

/// How a figure the directory does not allow is left out when it was not named.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Leave {
    /// Without a word (a run's figure of a sweep, a sweep's of a run).
    Silently,
    /// With a note in [`super::Drawn::notes`].
    WithNote,
    /// By its drawer, which finds it from the tables and notes it.
    ToTheTables,
}

/// What a directory allows, read from its scene or sweep file (`None` where that file
/// cannot be read: the figures' readers then report why).
struct Facts {
    sweep: bool,
    /// Whether a run (for a sweep: any run) is driven through a spring.
    spring: Option<bool>,
    /// A sweep's axis keys.
    keys: Option<Vec<String>>,
    /// A run's profiles: whether it records any, and a plane above the interface.
    profiles: Option<(bool, bool)>,
}

impl Facts {
    fn of(dir: &Path, sweep: bool) -> Facts {
        let spring_of = |scene: &crate::scene::SceneBuilder| {
            crate::scene::file::all_keys(scene)
                .iter()
                .any(|(k, v)| k == "drive.kind" && v == "spring")
        };
        if sweep {
            match crate::sweep::Sweep::from_json_file(dir.join(SWEEP_FILE)) {
                Ok(s) => Facts {
                    sweep,
                    spring: Some(s.runs().iter().any(|r| spring_of(r.scene()))),
                    keys: Some(s.keys().iter().map(|k| k.to_string()).collect()),
                    profiles: None,
                },
                Err(_) => Facts {
                    sweep,
                    spring: None,
                    keys: None,
                    profiles: None,
                },
            }
        } else {
            let scene =
                crate::scene::SceneBuilder::from_json_file(dir.join(crate::output::RUN_SCENE));
            let profiles_of = |scene: &crate::scene::SceneBuilder| {
                let run = scene.current_run();
                (
                    !run.profile_loads().is_empty(),
                    run.profile_planes().iter().any(|&z| z > 0.0),
                )
            };
            Facts {
                sweep,
                spring: scene.as_ref().ok().map(spring_of),
                keys: None,
                profiles: scene.as_ref().ok().map(profiles_of),
            }
        }
    }

    /// Why `figure` cannot be drawn for `dir`, and how it is left out when it was not
    /// named; `None` where it can (or where only the tables can tell).
    fn unavailable(&self, figure: &str, dir: &Path) -> Option<(String, Leave)> {
        let run_only = |what: &str| {
            format!(
                "{what} is a run's figure, and {} is a sweep's directory: plot one of its run \
                 directories",
                dir.display()
            )
        };
        let no_spring = "the run is not driven through a spring (drive.kind \"spring\"): under \
                         force control the force never drops";
        let profile = [
            SLIP_PROFILES_FIGURE,
            SHEAR_PROFILES_FIGURE,
            NORMAL_PROFILES_FIGURE,
            COULOMB_PROFILES_FIGURE,
        ]
        .contains(&figure);
        match (figure, self.sweep) {
            (_, true) if profile => Some((run_only("a profiles figure"), Leave::Silently)),
            (_, false) if profile && self.profiles.is_some_and(|p| !p.0) => Some((
                "the run records no profiles (scene key `profiles`, \
                 `RunOptions::record_profiles`)"
                    .into(),
                Leave::Silently,
            )),
            (SLIP_PROFILES_FIGURE, false) => None,
            (_, false) if profile && self.profiles.is_some_and(|p| !p.1) => Some((
                "no plane above the interface is recorded (`profiles.planes`)".into(),
                Leave::WithNote,
            )),
            (MAP_FIGURE, true) => Some((run_only("the contact map"), Leave::Silently)),
            (COLLAPSE_FIGURE, false) => Some((
                format!(
                    "a sweep's figure (the avalanche sizes of its lengths collapsed), and {} is \
                     a run's directory: plot the sweep's",
                    dir.display()
                ),
                Leave::Silently,
            )),
            (COLLAPSE_FIGURE, true) => match &self.keys {
                Some(keys) if !keys.iter().any(|k| k == "block.lx" || k == "block.ly") => Some((
                    "the sweep has no axis block.lx or block.ly: the collapse needs points at \
                     several lengths"
                        .into(),
                    Leave::Silently,
                )),
                // Whether `stats` wrote the collapse: the tables tell.
                _ => None,
            },
            (STICK_SLIP_FIGURE, true) => Some((
                run_only("stick-slip"),
                if self.spring == Some(true) {
                    Leave::WithNote
                } else {
                    Leave::Silently
                },
            )),
            (MAP_FIGURE, false) if !dir.join("contact_map.csv").is_file() => Some((
                format!(
                    "{} is missing (written by this version's `run`)",
                    dir.join("contact_map.csv").display()
                ),
                Leave::ToTheTables,
            )),
            (STICK_SLIP_FIGURE, false) if self.spring == Some(false) => {
                Some((no_spring.into(), Leave::WithNote))
            }
            (DROPS_FIGURE, _) if self.spring == Some(false) => Some((
                if self.sweep {
                    "no run of the sweep is driven through a spring (drive.kind \"spring\"): \
                     under force control the force never drops"
                        .into()
                } else {
                    no_spring.into()
                },
                Leave::ToTheTables,
            )),
            (ARCHARD_FIGURE, false) => Some((
                format!(
                    "a sweep's figure (the real contact area at zero shear against the normal \
                     loads of its points), and {} is a run's directory: plot the sweep's",
                    dir.display()
                ),
                Leave::Silently,
            )),
            (ARCHARD_FIGURE, true) => match &self.keys {
                Some(keys) if !keys.iter().any(|k| k == NORMAL_LOAD) => Some((
                    format!(
                        "the sweep has no axis {NORMAL_LOAD} (its axes: {}): the real contact \
                         area against the normal load needs points at several loads",
                        if keys.is_empty() {
                            "none".to_string()
                        } else {
                            keys.join(", ")
                        }
                    ),
                    Leave::WithNote,
                )),
                _ => None,
            },
            _ => None,
        }
    }
}
