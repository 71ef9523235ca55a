//! The names of the files in run and sweep directories, one list for every writer and
//! every check: an output the user names (a checkpoint) may not take one of them, a new
//! run removes the derived ones (figures, movies) of the old, and a run and a sweep never
//! share a directory.

use crate::error::{Error, Result};
use crate::lock::LOCK_FILE;
use std::path::Path;

use super::derived::{AVALANCHE_TABLE, FRONTS_TABLE};
use super::{FIELDS_FILE, PARTIAL, RUN_SCENE, TABLES};

/// The profiles a run records at given loads (`output/profiles.rs`).
pub(crate) const PROFILES_TABLE: &str = "profiles.csv";
/// The completion marker of a sweep's run.
pub(crate) const DONE: &str = "done";
/// A sweep's run's record of its coordinates, counts and timings.
pub(crate) const META: &str = "meta.json";
/// A sweep's copy of its file (`crate::sweep::SWEEP_FILE`).
pub(crate) const SWEEP: &str = "sweep.json";
/// The tables `merge` writes into a sweep's directory.
pub(crate) const MERGED: [&str; 4] = ["curves.csv", "slip.csv", "avalanches.csv", "runs.csv"];
/// The figure of ℓ/Lx against the load (each figure as `.png` and `.svg`).
pub(crate) const PRECURSOR_FIGURE: &str = "precursor_length";
/// The figure of the real contact area against the load.
pub(crate) const AREA_FIGURE: &str = "contact_area";
/// The figure of a run's `contact_map.csv`.
pub(crate) const MAP_FIGURE: &str = "contact_map";
/// The figure of `ℓ` and the damage front against the load.
pub(crate) const FRONTS_FIGURE: &str = "fronts";
/// The figure of the avalanche sizes' distribution.
pub(crate) const SIZES_FIGURE: &str = "avalanche_sizes";
/// The figure of the force drops' distribution.
pub(crate) const DROPS_FIGURE: &str = "force_drops";
/// The slip profiles at the recorded loads (`profiles.csv`).
pub(crate) const SLIP_PROFILES_FIGURE: &str = "slip_profiles";
/// `|τ(x, z_P)|` at the recorded loads (paper Fig. S10).
pub(crate) const SHEAR_PROFILES_FIGURE: &str = "shear_profiles";
/// `|σ(x, z_P)|` at the recorded loads (paper Fig. S10).
pub(crate) const NORMAL_PROFILES_FIGURE: &str = "normal_profiles";
/// The stresses and Coulomb stresses at the first recorded load (paper Fig. 7).
pub(crate) const COULOMB_PROFILES_FIGURE: &str = "coulomb_profiles";
/// The figure of a driving spring's force against the drive displacement (paper Fig. 4).
pub(crate) const STICK_SLIP_FIGURE: &str = "stick_slip";
/// The figure of a sweep's real contact area at zero shear against the normal load
/// (paper Fig. 2a).
pub(crate) const ARCHARD_FIGURE: &str = "archard";
/// The mean force drop against the avalanche size, from `stats`' tables.
pub(crate) const DROP_SIZE_FIGURE: &str = "drop_against_size";
/// The mean potency against the avalanche size, from `stats`' tables.
pub(crate) const POTENCY_SIZE_FIGURE: &str = "potency_against_size";
/// The finite-size collapse of the avalanche sizes, from `stats`' tables.
pub(crate) const COLLAPSE_FIGURE: &str = "collapse";
/// The figures `plot` draws (the names `plot --figure` takes).
pub(crate) const FIGURES: [&str; 15] = [
    PRECURSOR_FIGURE,
    AREA_FIGURE,
    MAP_FIGURE,
    STICK_SLIP_FIGURE,
    ARCHARD_FIGURE,
    FRONTS_FIGURE,
    SIZES_FIGURE,
    DROPS_FIGURE,
    SLIP_PROFILES_FIGURE,
    SHEAR_PROFILES_FIGURE,
    NORMAL_PROFILES_FIGURE,
    COULOMB_PROFILES_FIGURE,
    DROP_SIZE_FIGURE,
    POTENCY_SIZE_FIGURE,
    COLLAPSE_FIGURE,
];
/// The extensions of the figures.
pub(crate) const FIGURE_EXTENSIONS: [&str; 2] = ["png", "svg"];
/// The movie of the real contact area (Movie S1), `movie`'s default name.
pub(crate) const AREA_MOVIE: &str = "contact_area.gif";
/// The movie of the Coulomb stress (Movie S2), `movie`'s default name.
pub(crate) const STRESS_MOVIE: &str = "coulomb_stress.gif";
/// The movies `movie` draws by default.
pub(crate) const MOVIES: [&str; 2] = [AREA_MOVIE, STRESS_MOVIE];

/// The tables a run's end derives from its events (`output/derived.rs`).
pub(crate) const DERIVED_TABLES: [&str; 2] = [AVALANCHE_TABLE, FRONTS_TABLE];
/// The power-law fits `stats` writes into a run or sweep directory.
pub(crate) const POWER_LAWS: &str = "power_laws.csv";
/// The log-binned distributions `stats` writes.
pub(crate) const DISTRIBUTIONS: &str = "distributions.csv";
/// The binned means of one observable against another `stats` writes (the mean size
/// against `1 - F/(μF_N)`, the mean drop against the size).
pub(crate) const BINNED_MEANS: &str = "binned_means.csv";
/// The power-law relations between observables `stats` fits (drop against size).
pub(crate) const SCALING: &str = "scaling.csv";
/// The finite-size data collapse `stats` writes for a sweep over a block length.
pub(crate) const COLLAPSE: &str = "collapse.csv";
/// The tables `stats` writes.
pub(crate) const STATS_TABLES: [&str; 5] =
    [POWER_LAWS, DISTRIBUTIONS, BINNED_MEANS, SCALING, COLLAPSE];

/// Whether `name` is a derived table, a figure or a movie: derived or drawn from a run's
/// tables, so stale once the tables are another run's.
pub(crate) fn derived(name: &str) -> bool {
    MOVIES.contains(&name)
        || DERIVED_TABLES.contains(&name)
        || STATS_TABLES.contains(&name)
        || name
            .rsplit_once('.')
            .is_some_and(|(stem, ext)| FIGURES.contains(&stem) && FIGURE_EXTENSIONS.contains(&ext))
}

/// Whether `name` is a name the program writes, holds or reads in a run or sweep
/// directory (a table, `NAME.partial`, the scene record, the lock, the sweep's markers
/// and merged tables, a figure, a movie, or a temporary file of one of them).
pub(crate) fn reserved(name: &str) -> bool {
    let base = name.strip_suffix(PARTIAL).unwrap_or(name);
    TABLES.contains(&base)
        || base == FIELDS_FILE
        || base == PROFILES_TABLE
        || [RUN_SCENE, LOCK_FILE, DONE, META, SWEEP].contains(&name)
        || MERGED.contains(&name)
        || derived(name)
        // `write_atomically`'s temporaries: `.NAME.tmp<pid>-...`.
        || name
            .strip_prefix('.')
            .and_then(|n| n.split_once(".tmp"))
            .is_some_and(|(n, _)| reserved(n))
}

/// Whether `path` lies in the directory `dir` (the same directory once both are resolved:
/// `d/./x`, a symbolic link to `d`, a relative and an absolute spelling).
fn in_directory(path: &Path, dir: &Path) -> bool {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    // Resolved where both exist; else (a directory not made yet) compared as absolute
    // paths without `.` components.
    let resolve = |p: &Path| {
        p.canonicalize().or_else(|_| {
            std::path::absolute(p).map(|a| a.components().collect::<std::path::PathBuf>())
        })
    };
    match (resolve(parent), resolve(dir)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Refuses an output `path` the user names (`what`: "the checkpoint") that would take a
/// name of a file the run directory `dir` holds ([`reserved`]), so that no output of a
/// command overwrites another or the lock.
///
/// # Errors
/// [`Error::OutputCollision`].
pub(crate) fn check_output(path: &Path, dir: &Path, what: &'static str) -> Result<()> {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return Ok(());
    };
    if reserved(name) && in_directory(path, dir) {
        return Err(Error::OutputCollision {
            what,
            path: path.to_path_buf(),
            reason: format!(
                "{name} is a file of the run directory {} (its tables, NAME.partial, \
                 {RUN_SCENE}, the lock {LOCK_FILE}, a sweep's {DONE} and {META}, figures \
                 and movies): name the {what} otherwise or put it elsewhere",
                dir.display()
            ),
        });
    }
    Ok(())
}

/// Refuses to write a run into a sweep's directory or into one of a sweep's run
/// directories: the sweep's markers (`done`, `meta.json`) would describe another run's
/// tables, and `merge` would count them.
///
/// # Errors
/// [`Error::RunDirectory`]; [`Error::Io`] when `dir` cannot be examined.
pub(crate) fn check_not_a_sweeps(dir: &Path) -> Result<()> {
    let take_over =
        format!("choose another directory, or remove {DONE} and {META} to take it over");
    for (name, whose, hint) in [
        (
            SWEEP,
            "a sweep's directory (its sweep.json is there)",
            "choose another directory",
        ),
        (
            DONE,
            "a run directory of a sweep (its marker `done` is there)",
            take_over.as_str(),
        ),
        (
            META,
            "a run directory of a sweep (its meta.json is there)",
            take_over.as_str(),
        ),
    ] {
        let path = dir.join(name);
        match std::fs::symlink_metadata(&path) {
            Ok(_) => {
                return Err(Error::RunDirectory {
                    path: dir.to_path_buf(),
                    reason: format!(
                        "it is {whose}: a run of its own there would mix with the sweep's \
                         (`merge` counts what the markers name): {hint}"
                    ),
                })
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io("examining the run directory", &path, e)),
        }
    }
    Ok(())
}

/// Whether `dir` is a sweep's directory (it holds `sweep.json`) rather than a run's, for
/// the readers that take either (`plot`, `stats`, `merge`). A run directory with a stray
/// `sweep.json` (a copy, a mistake) is neither: read as a sweep's, its figures would be
/// drawn over the run's from runs it does not hold.
///
/// # Errors
/// [`Error::RunDirectory`] for a directory that holds both `sweep.json` and a run's files
/// ([`holds_a_run`]); [`Error::NotARegularFile`] for a `sweep.json` that is a link or not
/// a regular file; [`Error::Io`] when `dir` cannot be examined.
#[cfg(feature = "serde")]
pub(crate) fn is_sweep(dir: &Path) -> Result<bool> {
    if !crate::files::is_file(&dir.join(SWEEP), "examining the directory")? {
        return Ok(false);
    }
    match holds_a_run(dir)? {
        None => Ok(true),
        Some(name) => Err(Error::RunDirectory {
            path: dir.to_path_buf(),
            reason: format!(
                "it holds both a sweep's {SWEEP} and a run's files ({name}): it is neither a \
                 run's directory nor a sweep's, and read as either its figures, statistics \
                 or merged tables would be another's; remove the file that does not belong"
            ),
        }),
    }
}

/// Whether `dir` holds a run's files (its scene record, a table, `NAME.partial`): a
/// sweep is not written there.
///
/// # Errors
/// [`Error::Io`] when `dir` cannot be read.
#[cfg(feature = "serde")]
pub(crate) fn holds_a_run(dir: &Path) -> Result<Option<String>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Error::io("reading directory", dir, e)),
    };
    for entry in entries {
        let entry = entry.map_err(|e| Error::io("reading directory", dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let base = name.strip_suffix(PARTIAL).unwrap_or(&name);
        if name == RUN_SCENE || TABLES.contains(&base) || base == FIELDS_FILE {
            return Ok(Some(name));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_file_of_a_directory_is_reserved_and_only_those() {
        for name in [
            "events.csv",
            "curve.csv.partial",
            "contact_map.csv",
            "fields.csv.partial",
            "scene.json",
            ".precursors.lock",
            "done",
            "meta.json",
            "sweep.json",
            "runs.csv",
            "contact_map.svg",
            "precursor_length.png",
            "stick_slip.svg",
            "archard.png",
            "coulomb_stress.gif",
            "per_avalanche.csv",
            "fronts.csv",
            "power_laws.csv",
            "distributions.csv",
            ".fronts.csv.tmp12-0-5",
            ".curve.csv.partial.tmp12-0-5",
        ] {
            assert!(reserved(name), "{name}");
        }
        for name in [
            "checkpoint.json",
            "events.csv.bak",
            "curve.png",
            ".x.tmp1",
            "notes",
        ] {
            assert!(!reserved(name), "{name}");
        }
        assert!(derived("contact_area.gif") && derived("contact_map.png"));
        assert!(derived("per_avalanche.csv") && derived("fronts.csv"));
        assert!(!derived("contact_map.csv") && !derived("scene.json"));
    }
}
