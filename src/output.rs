//! The tables of a run, as written by the `precursors` program (`run`, `resume`, `sweep`)
//! and by `Sweep::run_one` (module `sweep`, feature `serde`): CSV files that survive a crash.
//!
//! * `events.csv`, one row per event ([`EVENTS_HEADER`]): `index,kind,ix,iy,force_N,
//!   drive_displacement_m,energy_J,ruptures,area_exceeds_nominal` (empty cells where a
//!   column does not apply);
//! * `curve.csv`, one row per stable state ([`CURVE_HEADER`]): `event,force_N,
//!   force_over_mu_FN,drive_displacement_m,real_contact_area_m2,precursor_length_m,
//!   precursor_over_Lx,broken,attached,area_exceeds_nominal,potency_m3_per_N,
//!   potency_moment_m4_per_N,load_compliance_m_per_N`, the last three the slip per newton
//!   of load ([`crate::SlipPerNewton`], 17 significant digits);
//! * `contact_map.csv` (header `event,force_over_mu_FN`, then `area_m2_ix0`, `area_m2_ix1`, ...): the map over x and F of the paper's
//!   Fig. 2b inset, one row per load level `F/(μF_N)` = 0, 0.005, 0.01, ...
//!   (`0.005`) from the first stable state up to global slip: the real
//!   contact area of each column `ix` (m², summed over y) in the stable state in effect
//!   at that load (the last one reached at or below it), and that state's event index:
//!   `event,force_over_mu_FN,area_m2_ix0,...`. At most about 200 rows whatever the
//!   number of stable states. Levels are passed in order: where the load drops (a
//!   driving spring's slip), a level's row is the state in effect when the load first
//!   passed it.
//!
//! * `fields.csv`, only when the run records fields
//!   ([`crate::RunOptions::record_fields`], scene-file key `fields`): the fields of the
//!   1st, `(1 + every)`-th, `(1 + 2·every)`-th, ... stable state, for the movies (`precursors
//!   movie`), header `event,force_over_mu_FN,precursor_over_Lx,field,row,z_m,value_ix0,
//!   ...,value_ix{Nx-1}`. Each recorded state has `Ny` rows of field `area_m2` (row `iy`,
//!   `z_m` 0: the real contact area of the cells `(ix, iy)`, m²), then one row of field
//!   `coulomb_Pa` per recorded plane (row `k`, `z_m` its height: the y-averaged Coulomb
//!   stress `τ_C(x, z) = |⟨τ⟩_y| - μ|⟨σ⟩_y|` of each column, Pa, as
//!   [`crate::Profile::coulomb_of_means`]). About `(Ny + planes)·Nx·20` bytes per recorded
//!   state: `every` bounds the size.
//!
//! * `profiles.csv`, only when the run records profiles
//!   ([`crate::RunOptions::record_profiles`], scene-file key `profiles`): profiles along
//!   `x`, averaged over `y`, in the stable state in effect at each requested load (the
//!   last one reached at or below it, as in `contact_map.csv`; a load below the first
//!   state's or one the run never passes has no rows), header `level,event,
//!   force_over_mu_FN,field,z_m,value_ix0,...,value_ix{Nx-1}`. Per load, in increasing
//!   order: three rows at the interface (`z_m` 0) of field `slip_m` (`⟨u_x⟩_y`, m),
//!   `shear_traction_Pa` (`⟨φ_x⟩_y`) and `normal_traction_Pa` (`⟨φ_z⟩_y`,
//!   compressive positive), then four per recorded plane (`z_m` its height) of field
//!   `shear_Pa` (`⟨τ⟩_y`), `normal_Pa` (`⟨σ⟩_y`), `coulomb_of_means_Pa` (`|⟨τ⟩_y| -
//!   μ|⟨σ⟩_y|`) and `mean_coulomb_Pa` (`⟨|τ| - μ|σ|⟩_y`), as [`crate::Profile`]'s.
//!   `level` is the requested load, `event` and `force_over_mu_FN` the state's.
//!
//! * `per_avalanche.csv` and `fronts.csv`, derived from the whole `events.csv` and
//!   `curve.csv` when the run reaches global slip ([`RunTables::finish`], before the
//!   tables take their names): one row per avalanche ([`crate::Avalanche`]: `avalanche,
//!   start_event,end_event,ruptures,broken_area_m2,force_before_N,force_after_N,
//!   force_drop_N,drive_displacement_before_m,drive_displacement_after_m,energy_J,
//!   attaches,detaches,flash_ruptures,global_slip,ruptures_without_flash,contacts_before,
//!   contacts_after,spanning,after_spanning,extent_m,centroid_m,potency_m3,slip_centroid_m,
//!   released_energy_J`), and the damage front beside `ℓ` at
//!   every stable state ([`crate::DamageFront`]: `event,force_N,force_over_mu_FN,
//!   precursor_over_Lx,damage_front_m,damage_front_over_Lx`); docs/statistics.md.
//!
//! `area_exceeds_nominal` is 1 when the total real contact area of the state after the
//! event exceeds the nominal area `Lx·Ly` (the paper's unbounded area law), 0 otherwise.
//! Numbers are written with 13 significant digits (`{:.12e}`), so the tables of two runs
//! compare equal exactly when their results do.
//!
//! **Complete or marked partial.** While a run is under way its tables are written as
//! `events.csv.partial`, `curve.csv.partial` and `contact_map.csv.partial`
//! (`.partial`); [`RunTables::finish`], once the run reached global slip, syncs
//! them to disk and renames them to their names. A crash, a kill or a full disk leaves
//! `.partial` files (or the tables of a complete run), never a table under its name that
//! is not complete. The directory is locked while the tables are written (an advisory lock
//! of the operating system, on the file `.precursors.lock`, that ends with the process): a
//! second writer is refused ([`Error::DirectoryLocked`], naming the holder). With the
//! `serde` feature the run's scene is recorded in the directory (`scene.json`).
//!
//! **Resume.** [`RunTables::resume`] continues the tables of a run from a checkpoint taken
//! at a stable state: it checks, before it writes anything, that the directory's recorded
//! scene is the checkpoint's, that the three tables have their headers and whole rows
//! (a last row cut by a crash is dropped), that `events.csv` numbers its
//! rows 1, 2, 3, ... up to at least the checkpoint's event, and that `curve.csv` and
//! `contact_map.csv` hold the stable states and load levels reached by then; then it
//! rewrites the `.partial` tables with the rows up to the checkpoint's event. With fields
//! recorded, `fields.csv` must hold exactly the recorded states up to the checkpoint's
//! event (the same `every` and planes), and is cut back the same way; with profiles
//! recorded, `profiles.csv` the loads passed by then (the same loads and planes).

pub(crate) mod check;
pub(crate) mod derived;
pub(crate) mod layout;
pub(crate) mod profiles;
mod resume;

use crate::driver::{Driver, Event, RowDigest, TableDigest};
use crate::error::{Error, Result};
use crate::files::{check_replaceable, read_text_if_exists, sync_dir, write_atomically};
use crate::interface::SiteState;
use crate::lock::DirLock;
use crate::probe::StressProbe;
use crate::recording::RunOptions;
use profiles::ProfilesTable;
use resume::{continuation, fields_continuation};
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
#[cfg(feature = "serde")]
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// The header of `events.csv`.
pub const EVENTS_HEADER: &str =
    "index,kind,ix,iy,force_N,drive_displacement_m,energy_J,ruptures,area_exceeds_nominal";
/// The header of `curve.csv`. Its last three columns (the slip per newton of load,
/// [`crate::SlipPerNewton`]) came in 1.2: a run begun by 1.1 and resumed keeps them empty
/// on its earlier rows, and a 1.1 table (without them) is still read.
pub const CURVE_HEADER: &str = "event,force_N,force_over_mu_FN,drive_displacement_m,\
                                real_contact_area_m2,precursor_length_m,precursor_over_Lx,\
                                broken,attached,area_exceeds_nominal,potency_m3_per_N,\
                                potency_moment_m4_per_N,load_compliance_m_per_N";

/// Columns of `curve.csv` as 1.1 wrote it (the first of [`CURVE_HEADER`]'s).
pub(crate) const CURVE_COLUMNS_1_1: usize = 10;

/// The header of `curve.csv` as 1.1 wrote it: [`CURVE_HEADER`]'s first
/// [`CURVE_COLUMNS_1_1`] columns.
pub(crate) fn curve_header_1_1() -> &'static str {
    let end = CURVE_HEADER
        .match_indices(',')
        .nth(CURVE_COLUMNS_1_1 - 1)
        .map_or(CURVE_HEADER.len(), |(i, _)| i);
    &CURVE_HEADER[..end]
}

/// The spacing in `F/(μF_N)` of the rows of `contact_map.csv`.
pub(crate) const MAP_STEP: f64 = 0.005;

/// The names of a run's tables, in the order of [`RunTables::paths`].
pub(crate) const TABLES: [&str; 3] = ["events.csv", "curve.csv", "contact_map.csv"];

/// Appended to a table's name while its run is under way (`events.csv.partial`).
pub(crate) const PARTIAL: &str = ".partial";

/// The record of a run's scene in its directory (feature `serde`: the scene file of
/// `SceneBuilder::to_json`), written when the run starts, checked on resume.
pub(crate) const RUN_SCENE: &str = "scene.json";

/// The table of the fields a run records for the movies.
pub(crate) const FIELDS_FILE: &str = "fields.csv";

/// The spacing in `F/(μF_N)` of the rows of `contact_map.csv` (0.005).
#[deprecated(
    since = "1.1.0",
    note = "a file-format detail (the module docs give the layout); removed in 2.0"
)]
pub const CONTACT_MAP_STEP: f64 = MAP_STEP;

/// The names of a run's tables, in the order of [`RunTables::paths`].
#[deprecated(
    since = "1.1.0",
    note = "a file-format detail: use `RunTables::paths`; removed in 2.0"
)]
pub const TABLE_NAMES: [&str; 3] = TABLES;

/// Appended to a table's name while its run is under way (`events.csv.partial`).
#[deprecated(
    since = "1.1.0",
    note = "a file-format detail (the module docs give the layout); removed in 2.0"
)]
pub const PARTIAL_SUFFIX: &str = PARTIAL;

/// The record of a run's scene in its directory (`scene.json`).
#[deprecated(
    since = "1.1.0",
    note = "a file-format detail (the module docs give the layout); removed in 2.0"
)]
pub const SCENE_RECORD: &str = RUN_SCENE;

/// The table of the fields a run records for the movies (`fields.csv`).
#[deprecated(
    since = "1.1.0",
    note = "a file-format detail: use `RunTables::fields_path`; removed in 2.0"
)]
pub const FIELDS_TABLE: &str = FIELDS_FILE;

/// The `field` of the rows of `fields.csv` that hold the real contact area of a row `iy`
/// of cells (m²), and of those that hold the y-averaged Coulomb stress on a plane (Pa).
pub(crate) const FIELD_AREA: &str = "area_m2";
pub(crate) const FIELD_COULOMB: &str = "coulomb_Pa";

/// The header of `fields.csv` for a grid of `nx` columns.
pub(crate) fn fields_header(nx: usize) -> String {
    let mut header = String::from("event,force_over_mu_FN,precursor_over_Lx,field,row,z_m");
    for ix in 0..nx {
        header.push_str(&format!(",value_ix{ix}"));
    }
    header
}

/// The header of `contact_map.csv` for a grid of `nx` columns.
pub(crate) fn contact_map_header(nx: usize) -> String {
    let mut header = String::from("event,force_over_mu_FN");
    for ix in 0..nx {
        header.push_str(&format!(",area_m2_ix{ix}"));
    }
    header
}

/// Refuses an output `path` a caller names beside a run writing into `dir` (a
/// checkpoint) that would replace a file of the run directory: a table, `NAME.partial`,
/// the scene record, the lock, a sweep's `done` or `meta.json`, a merged table, a figure
/// or a movie; and one that exists but is not a regular file (a FIFO, a device, a
/// directory, a symbolic link), which a checkpoint written atomically would replace.
/// `RunTables::run_to_slip` (feature `serde`) checks its checkpoint so; call it before
/// [`RunTables::create`] to refuse before anything is written.
///
/// ```
/// use precursors::output::check_output_path;
/// let dir = std::path::Path::new(".");
/// assert!(check_output_path(dir, &dir.join("curve.csv.partial")).is_err());
/// assert!(check_output_path(dir, &dir.join(".precursors.lock")).is_err());
/// assert!(check_output_path(dir, &dir.join("checkpoint.json")).is_ok());
/// ```
///
/// # Errors
/// [`Error::OutputCollision`]; [`Error::NotARegularFile`]; [`Error::Io`] when `path`
/// cannot be examined.
pub fn check_output_path(dir: &Path, path: &Path) -> Result<()> {
    layout::check_output(path, dir, "checkpoint")?;
    check_replaceable(path, "writing checkpoint")
}

/// The three tables of a run in a directory: `events.csv`, `curve.csv` and
/// `contact_map.csv`, written as `NAME.partial` until [`RunTables::finish`].
///
/// ```
/// use precursors::output::{RunTables, CURVE_HEADER};
/// use precursors::Scene;
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // 10 x 4 cells of 1 mm under 100 N, driven by the paper's rod to global slip.
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// let mut tables = RunTables::create(&dir, &driver)?;
/// while let Some(event) = driver.step()? {
///     tables.record(&driver, &event)?;
/// }
/// let stable_states = tables.stable_states();
/// assert!(!tables.paths()[1].exists());           // only curve.csv.partial until finish
/// let [events, curve, map] = tables.finish()?;
/// let text = std::fs::read_to_string(&curve)?;
/// assert_eq!(text.lines().next(), Some(CURVE_HEADER));
/// assert_eq!(text.lines().count(), 1 + stable_states); // one row per stable state
/// assert!(events.is_file() && map.is_file());
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct RunTables {
    events: TableFile,
    curve: TableFile,
    map: TableFile,
    dir: PathBuf,
    /// The tables' names (after [`RunTables::finish`]).
    paths: [PathBuf; 3],
    /// The files written until then.
    partials: [PathBuf; 3],
    stable_states: usize,
    /// The next level of `contact_map.csv`, in steps of `0.005`.
    next_level: u64,
    /// The stable state in effect: the rows of the levels below the next state's load.
    in_effect: Option<MapState>,
    /// Global slip was recorded.
    slipped: bool,
    /// `fields.csv`, when the run records fields.
    fields: Option<FieldsTable>,
    /// `profiles.csv`, when the run records profiles.
    profiles: Option<ProfilesTable>,
    /// The run's grid and the bounds of its rows, for the tables derived at its end.
    grid: crate::geometry::Grid,
    bounds: check::Bounds,
    /// The directory's lock, `None` when the caller holds it (a sweep's run).
    _lock: Option<DirLock>,
}

/// `fields.csv` of a run that records fields ([`crate::RunOptions::record_fields`]).
#[derive(Debug)]
struct FieldsTable {
    file: TableFile,
    /// The table's name (after [`RunTables::finish`]) and the file written until then.
    path: PathBuf,
    partial: PathBuf,
    every: usize,
    planes: Vec<f64>,
    /// The recorded planes, planned on the scene's operator (`None` without planes).
    /// Asserted unwind-safe so that `RunTables` stays so (as in 1.0): the probe is only
    /// read after it is built (its transforms' plans are immutable), so a panic cannot
    /// leave it half changed.
    probe: Option<std::panic::AssertUnwindSafe<StressProbe>>,
    /// Stable states of the run so far (those kept on resume included).
    stable: usize,
}

impl FieldsTable {
    /// `dir/fields.csv` and `dir/fields.csv.partial`.
    fn paths(dir: &Path) -> (PathBuf, PathBuf) {
        (
            dir.join(FIELDS_FILE),
            dir.join(format!("{FIELDS_FILE}{PARTIAL}")),
        )
    }

    /// The writer of `driver`'s fields into `file` (`stable`: the stable states before
    /// its first row); `None` when `options` record none.
    fn new(
        driver: &Driver,
        options: &RunOptions,
        dir: &Path,
        file: impl FnOnce(&Path) -> Result<TableFile>,
        stable: usize,
    ) -> Result<Option<Self>> {
        let every = options.fields_every();
        if every == 0 {
            return Ok(None);
        }
        let planes = options.field_planes().to_vec();
        let probe = profiles::planes_probe(driver, &planes)?;
        let (path, partial) = Self::paths(dir);
        Ok(Some(Self {
            file: file(&partial)?,
            path,
            partial,
            every,
            planes,
            probe,
            stable,
        }))
    }

    /// The rows of the stable state `index` just reached (load `x = F/(μF_N)`, precursor
    /// `ℓ/Lx`), when it is one the scene records.
    fn record(&mut self, driver: &Driver, index: usize, x: f64, ell: f64) -> Result<()> {
        self.stable += 1;
        if !(self.stable - 1).is_multiple_of(self.every) {
            return Ok(());
        }
        let mut text = String::new();
        let mut row = |field: &str, k: usize, z: f64, values: &[f64]| {
            text.push_str(&format!("{index},{x:.12e},{ell:.12e},{field},{k},{z:.12e}"));
            for v in values {
                text.push_str(&format!(",{v:.12e}"));
            }
            text.push('\n');
        };
        let area = driver.cell_contact_area()?;
        for (iy, cells) in area.chunks_exact(driver.grid().nx()).enumerate() {
            row(FIELD_AREA, iy, 0.0, cells);
        }
        if let Some(probe) = &self.probe {
            let stresses = driver.stresses_at(std::slice::from_ref(&probe.0))?;
            for (k, (plane, &z)) in stresses.planes.iter().zip(&self.planes).enumerate() {
                row(FIELD_COULOMB, k, z, plane.profile().coulomb_of_means());
            }
        }
        self.file
            .write_all(text.as_bytes())
            .map_err(|e| Error::io("writing table", &self.partial, e))
    }
}

/// A stable state as `contact_map.csv` needs it.
#[derive(Debug)]
struct MapState {
    event: usize,
    columns: Vec<f64>,
}

/// `dir/NAME` and `dir/NAME.partial` of each table.
fn table_paths(dir: &Path) -> ([PathBuf; 3], [PathBuf; 3]) {
    (
        TABLES.map(|n| dir.join(n)),
        TABLES.map(|n| dir.join(format!("{n}{PARTIAL}"))),
    )
}

impl RunTables {
    /// New tables in `dir` (which must exist), header only, for `driver`'s run, recording
    /// what its scene's run options ask ([`crate::Scene::run_options`]): as
    /// [`RunTables::create_with`].
    ///
    /// # Errors
    /// As [`RunTables::create_with`].
    pub fn create(dir: &Path, driver: &Driver) -> Result<Self> {
        Self::create_with(dir, driver, driver.scene().run_options())
    }

    /// New tables in `dir` (which must exist), header only, for `driver`'s run, recording
    /// what `options` ask beside the three tables (`fields.csv`, `profiles.csv`): the
    /// options are checked against the scene, the directory is locked, the tables of an
    /// earlier run there removed, the scene recorded with these options (`scene.json`,
    /// feature `serde`; a resume and `precursors movie` read them there). The driver
    /// starts with the options' probes and thread count when built by
    /// [`crate::Scene::driver_with`] with the same options.
    ///
    /// ```
    /// use precursors::{output::RunTables, RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-with-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
    /// let mut driver = scene.driver()?;
    /// // The interface profiles, and the stresses 2 mm above it, at half the friction limit.
    /// let options = RunOptions::new().record_profiles(&[0.5], &[0.002]);
    /// RunTables::create_with(&dir, &driver, &options)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let profiles = std::fs::read_to_string(dir.join("profiles.csv"))?;
    /// // 3 rows at the interface and 4 on the plane, for the one load.
    /// assert_eq!(profiles.lines().count(), 1 + 3 + 4);
    /// assert!(profiles.lines().nth(1).unwrap().starts_with("5.000000000000e-1,"));
    /// // A plane outside the block is refused before anything is written.
    /// let outside = RunOptions::new().record_profiles(&[0.5], &[0.02]);
    /// assert!(RunTables::create_with(&dir, &driver, &outside).is_err());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::CustomContactRule`] for a driver under a custom contact rule
    /// ([`crate::ContactLaw`]); [`Error::OutOfRange`] for options the scene cannot
    /// record, naming the key; [`Error::DirectoryLocked`] when another process writes the
    /// directory;
    /// [`Error::Io`] when a file cannot be written or removed.
    pub fn create_with(dir: &Path, driver: &Driver, options: &RunOptions) -> Result<Self> {
        check_options(driver, options)?;
        let lock = DirLock::lock(dir)?;
        layout::check_not_a_sweeps(dir)?;
        Self::start(dir, driver, options, Some(lock))
    }

    /// [`RunTables::create_with`] in a directory whose lock the caller holds (`lock:
    /// None`) or passes on.
    pub(crate) fn start(
        dir: &Path,
        driver: &Driver,
        options: &RunOptions,
        lock: Option<DirLock>,
    ) -> Result<Self> {
        check_options(driver, options)?;
        let (paths, partials) = table_paths(dir);
        remove_stale_temporaries(dir)?;
        remove_derived(dir)?;
        for path in &paths {
            remove_if_exists(path)?;
        }
        #[cfg(feature = "serde")]
        write_atomically(
            &dir.join(RUN_SCENE),
            driver
                .scene()
                .to_builder()
                .run_options(options.clone())
                .to_json()?
                .as_bytes(),
            "recording the scene",
        )?;
        let nx = driver.grid().nx();
        let open = |t: usize, header: &str| new_table(&partials[t], header);
        let events = open(0, EVENTS_HEADER)?;
        let curve = open(1, CURVE_HEADER)?;
        let map = open(2, &contact_map_header(nx))?;
        // An earlier run's recordings never pass for this run's.
        remove_recordings(dir)?;
        let fields = FieldsTable::new(
            driver,
            options,
            dir,
            |path| new_table(path, &fields_header(nx)),
            0,
        )?;
        let profiles = ProfilesTable::new(
            driver,
            options,
            dir,
            |path| new_table(path, &profiles::header(nx)),
            profiles::Levels::new(options.profile_loads()),
        )?;
        Ok(Self {
            events,
            curve,
            map,
            dir: dir.to_path_buf(),
            paths,
            partials,
            stable_states: 0,
            next_level: 0,
            in_effect: None,
            slipped: false,
            fields,
            profiles,
            grid: *driver.grid(),
            bounds: check::Bounds::of(driver),
            _lock: lock,
        })
    }

    /// The tables in `dir` continued after `driver` was resumed from a checkpoint,
    /// recording what its scene's run options ask ([`crate::Scene::run_options`]): as
    /// [`RunTables::resume_with`].
    ///
    /// # Errors
    /// As [`RunTables::resume_with`].
    pub fn resume(dir: &Path, driver: &Driver) -> Result<Self> {
        Self::resume_with(dir, driver, driver.scene().run_options())
    }

    /// The tables in `dir` continued after `driver` was resumed ([`crate::Scene::resume`])
    /// from a checkpoint taken at a stable state, recording what `options` ask. The
    /// directory is locked; then, before anything is written, its recorded scene
    /// (`scene.json`, feature `serde`) must be the driver's, and the tables (each
    /// `NAME.partial` if present, else `NAME`) must hold whole rows under their headers,
    /// `events.csv` the events 1, 2, ... up to the checkpoint's (a last row cut by a crash
    /// is dropped), `curve.csv` and `contact_map.csv` the stable states and load levels
    /// reached by then, and with `options` recording them, `fields.csv` and
    /// `profiles.csv` what they record up to then. The `.partial` tables are then
    /// rewritten (atomically) with the rows up to the checkpoint's event; complete tables
    /// of a finished run stay until [`RunTables::finish`] replaces them. Where the
    /// checkpoint records the digests of the rows it covers ([`RunTables::checkpoint`]),
    /// the kept rows must be those, every table it covers continued; its site states must
    /// be those the kept events leave; and `options` must record what the directory
    /// recorded (its `fields.csv`, `profiles.csv` and `scene.json`): a resume continues
    /// every recorded table or none.
    ///
    /// ```
    /// # #[cfg(feature = "serde")] {
    /// use precursors::{output::RunTables, Event, RunOptions, Scene};
    /// use std::ops::ControlFlow;
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-resume-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder().block(0.012, 0.002, 0.010).normal_load(50.0).seed(0).build()?;
    /// // The stresses 2 mm above the interface at every stable state, beside the tables.
    /// let options = RunOptions::new().record_fields(1, &[0.002]);
    /// let mut driver = scene.driver_with(&options)?;
    /// let mut tables = RunTables::create_with(&dir, &driver, &options)?;
    /// // Stop at the fifth stable state and take a checkpoint there.
    /// let mut stable = 0;
    /// tables.run_until(&mut driver, None, |event, _| match event {
    ///     Event::Stable { .. } if { stable += 1; stable == 5 } => ControlFlow::Break(()),
    ///     _ => ControlFlow::Continue(()),
    /// })?;
    /// let checkpoint = tables.checkpoint(&driver)?;
    /// drop(tables);
    /// // Later, maybe in another process: the driver and the tables continued.
    /// let mut resumed = scene.resume_with(&checkpoint, &options)?;
    /// let tables = RunTables::resume_with(&dir, &resumed, &options)?;
    /// assert!(tables.fields_path().unwrap().ends_with("fields.csv"));
    /// tables.run_to_slip(&mut resumed, None, |_, _| {})?;
    /// assert!(dir.join("fields.csv").is_file());
    /// std::fs::remove_dir_all(&dir)?;
    /// # }
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::CustomContactRule`] for a driver under a custom contact rule;
    /// [`Error::OutOfRange`] for options the scene cannot record;
    /// [`Error::RunDirectory`] for a missing directory or (feature `serde`) one without
    /// its scene record; [`Error::CheckpointSceneMismatch`], naming the first differing
    /// key, when the recorded scene is another; [`Error::CorruptTable`], naming the file
    /// and line, for a table that is damaged, too short or inconsistent with the others,
    /// or whose kept rows differ from those the checkpoint covers;
    /// [`Error::InvalidCheckpoint`] for a checkpoint inside an avalanche, one whose site
    /// states are not those of the kept events, or one covering other tables;
    /// [`Error::RunDirectory`] for other observers than the directory recorded;
    /// [`Error::DirectoryLocked`]; [`Error::Io`].
    pub fn resume_with(dir: &Path, driver: &Driver, options: &RunOptions) -> Result<Self> {
        check_options(driver, options)?;
        if !dir.is_dir() {
            return Err(Error::RunDirectory {
                path: dir.to_path_buf(),
                reason: "no such directory: resume continues the run whose tables are there".into(),
            });
        }
        let lock = DirLock::lock(dir)?;
        layout::check_not_a_sweeps(dir)?;
        #[cfg(feature = "serde")]
        check_scene_record(dir, driver)?;
        let k = driver.event_count();
        let (paths, partials) = table_paths(dir);
        // The tables of the run under way (or cut), else those of a finished run.
        let mut old: [Option<String>; 3] = Default::default();
        let mut read = partials.clone();
        for t in 0..3 {
            (old[t], read[t]) = read_old(&partials[t], &paths[t])?;
        }
        let covered = driver.kept_tables();
        let map_rows = covered
            .and_then(|tables| tables.iter().find(|t| t.table() == TABLES[2]))
            .map(TableDigest::rows);
        let plan = continuation(
            [old[0].as_deref(), old[1].as_deref(), old[2].as_deref()],
            &read,
            (k, map_rows),
            &check::Bounds::of(driver),
            driver.force(),
        )?;
        let in_effect = if plan.in_effect {
            Some(MapState {
                event: k,
                columns: driver.column_contact_area()?,
            })
        } else {
            None
        };
        let kept = Recordings::kept(dir, driver, options, &plan)?;
        if let Some(covered) = covered {
            let mut tables: Vec<(&str, &Path, &str)> = (0..3)
                .map(|t| (TABLES[t], read[t].as_path(), plan.texts[t].as_str()))
                .collect();
            if let Some((text, path)) = &kept.fields {
                tables.push((FIELDS_FILE, path, text));
            }
            if let Some((text, path, _)) = &kept.profiles {
                tables.push((layout::PROFILES_TABLE, path, text));
            }
            resume::check_covered(covered, &tables)?;
        }
        resume::check_site_states(
            driver.contact_rule(),
            driver.friction_limit(),
            &plan.site_events,
            driver.site_states(),
            &read[0],
        )?;
        check_recorded_observers(dir, options)?;
        // Checked: now the directory is written.
        remove_stale_temporaries(dir)?;
        let continued = |t: usize| append_to(&partials[t], &plan.written(t));
        let (events, curve, map) = (continued(0)?, continued(1)?, continued(2)?);
        let (fields, profiles) = kept.continue_in(dir, driver, options, plan.stable.len())?;
        Ok(Self {
            events,
            curve,
            map,
            dir: dir.to_path_buf(),
            paths,
            partials,
            stable_states: 0,
            next_level: plan.next_level,
            in_effect,
            slipped: false,
            fields,
            profiles,
            grid: *driver.grid(),
            bounds: check::Bounds::of(driver),
            _lock: Some(lock),
        })
    }

    /// The paths of `events.csv`, `curve.csv` and `contact_map.csv` (their names once
    /// [`RunTables::finish`]ed; until then they are written with `.partial`).
    pub fn paths(&self) -> [&Path; 3] {
        [&self.paths[0], &self.paths[1], &self.paths[2]]
    }

    /// The path of `fields.csv` (written as `fields.csv.partial` until
    /// [`RunTables::finish`]), `None` when the scene records no fields
    /// ([`crate::SceneBuilder::record_fields`]); [`RunTables::resume_with`]'s example
    /// reads it.
    pub fn fields_path(&self) -> Option<&Path> {
        self.fields.as_ref().map(|f| f.path.as_path())
    }

    /// Stable states recorded by this writer (not counting rows kept on resume).
    pub fn stable_states(&self) -> usize {
        self.stable_states
    }

    /// Writes the row(s) of `event`, just returned by `driver.step()`: one row of
    /// `events.csv`, and one of `curve.csv` for a stable state (and one of
    /// `contact_map.csv` when it reaches the map's next level).
    ///
    /// # Errors
    /// [`Error::Io`] when a row cannot be written; the driver's errors for the fields of
    /// the state (none after a successful step).
    pub fn record(&mut self, driver: &Driver, event: &Event) -> Result<()> {
        let index = driver.event_count();
        let exceeds = driver.area_exceeds_nominal()?;
        write_event(&mut self.events, index, event, exceeds)
            .map_err(|e| Error::io("writing table", &self.partials[0], e))?;
        if let Event::Stable { load, .. } = *event {
            self.stable_states += 1;
            let mu_fn = driver.friction_limit();
            let (broken, attached) = counts(driver.site_states());
            let ell = driver.precursor_length()?;
            let slip = driver.slip_per_newton()?;
            // The slip columns at 17 digits (exact): avalanches take their differences.
            writeln!(
                self.curve,
                "{index},{:.12e},{:.12e},{},{:.12e},{:.12e},{:.12e},{broken},{attached},{},\
                 {:.16e},{:.16e},{:.16e}",
                load.force,
                load.force / mu_fn,
                optional(load.drive_displacement),
                driver.real_contact_area()?,
                ell,
                ell / driver.grid().block().lx(),
                u8::from(exceeds),
                slip.potency,
                slip.potency_moment,
                slip.load_compliance,
            )
            .map_err(|e| Error::io("writing table", &self.partials[1], e))?;
            let x = load.force / mu_fn;
            if let Some(fields) = &mut self.fields {
                fields.record(driver, index, x, ell / driver.grid().block().lx())?;
            }
            if let Some(profiles) = &mut self.profiles {
                profiles.reach(driver, index, load.force, true)?;
            }
            self.map_rows_below(x, true)?;
            self.in_effect = Some(MapState {
                event: index,
                columns: driver.column_contact_area()?,
            });
        }
        if let Event::GlobalSlip { load } = *event {
            if let Some(profiles) = &mut self.profiles {
                profiles.reach(driver, index, load.force, false)?;
            }
            let mu_fn = driver.friction_limit();
            self.map_rows_below(load.force / mu_fn, false)?;
            self.slipped = true;
        }
        Ok(())
    }

    /// The rows of `contact_map.csv` for the levels below the load `x = F/(μF_N)` of a new
    /// state (`stable`) or of global slip: the state in effect until now held there.
    /// Before the first stable state there is none: the map starts at the first level at
    /// or above its load. The levels stop at the friction limit.
    fn map_rows_below(&mut self, x: f64, stable: bool) -> Result<()> {
        // No stable state carries more than μF_N (every site holds |φ_x| ≤ μφ_z): in the
        // tests' scenes it stays below 0.999 (1 + 2.2e-16 at global slip), the
        // margin covers the loosest solver tolerance (1e-6). Beyond, the driver's result
        // is wrong; an infinite load made the loop below endless. Global slip under a
        // driving spring may overshoot μF_N (sites re-attach in the last avalanche): its
        // levels stop at the limit, so the map has at most 201 rows.
        const LIMIT: f64 = 1.0 + 1e-5;
        if !(x.is_finite() && (x <= LIMIT || !stable)) {
            return Err(Error::LoadBeyondFriction {
                ratio: x,
                limit: LIMIT,
            });
        }
        let x = x.min(LIMIT);
        let Some(state) = &self.in_effect else {
            self.next_level = first_level_at_or_above(x);
            return Ok(());
        };
        while level(self.next_level) < x {
            let mut row = format!("{},{:.3}", state.event, level(self.next_level));
            for a in &state.columns {
                row.push_str(&format!(",{a:.12e}"));
            }
            writeln!(self.map, "{row}")
                .map_err(|e| Error::io("writing table", &self.partials[2], e))?;
            self.next_level += 1;
        }
        Ok(())
    }

    /// Writes the rows so far to disk (flushed and synced): call it before a checkpoint is
    /// written, so that the tables reach the checkpoint's event whatever happens next.
    ///
    /// # Errors
    /// [`Error::Io`] when a file cannot be written or synced.
    pub fn flush(&mut self) -> Result<()> {
        for (table, path) in [
            (&mut self.events, &self.partials[0]),
            (&mut self.curve, &self.partials[1]),
            (&mut self.map, &self.partials[2]),
        ] {
            table
                .sync()
                .map_err(|e| Error::io("writing table", path, e))?;
        }
        if let Some(fields) = &mut self.fields {
            fields
                .file
                .sync()
                .map_err(|e| Error::io("writing table", &fields.partial, e))?;
        }
        if let Some(profiles) = &mut self.profiles {
            profiles.flush()?;
        }
        Ok(())
    }

    /// A checkpoint of `driver` that covers the rows written so far: the tables are
    /// [flushed](RunTables::flush) to disk, and the checkpoint records the digest of each
    /// table's rows (`events.csv`, `curve.csv`, `contact_map.csv`, and `fields.csv` and
    /// `profiles.csv` where recorded), so that [`RunTables::resume`] refuses kept rows
    /// edited after it was taken. `RunTables::run_until` (feature `serde`) takes its checkpoints so; take
    /// one at a stable state to resume the tables from it.
    ///
    /// # Errors
    /// [`Error::Io`] when a table cannot be written or synced.
    pub fn checkpoint(&mut self, driver: &Driver) -> Result<crate::driver::Checkpoint> {
        self.flush()?;
        let mut tables: Vec<TableDigest> = [&self.events, &self.curve, &self.map]
            .iter()
            .zip(TABLES)
            .map(|(table, name)| table.digest(name))
            .collect();
        if let Some(fields) = &self.fields {
            tables.push(fields.file.digest(FIELDS_FILE));
        }
        if let Some(profiles) = &self.profiles {
            tables.push(profiles.digest());
        }
        Ok(driver.checkpoint().with_tables(tables))
    }

    /// Runs `driver` to global slip writing its tables (feature `serde`), as
    /// [`RunTables::run_until`] with an observer that never stops the run, then the
    /// tables [finished](RunTables::finish). Returns the tables' paths.
    ///
    /// ```
    /// use precursors::{output::RunTables, Event, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.012, 0.002, 0.010)
    ///     .normal_load(50.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// # let out = std::env::temp_dir().join(format!("precursors-doc-run-{}", std::process::id()));
    /// # std::fs::create_dir_all(&out).unwrap();
    /// let tables = RunTables::create(&out, &driver)?;
    /// let mut ruptures = 0;
    /// let [events, _curve, _map] = tables.run_to_slip(&mut driver, None, |event, _| {
    ///     ruptures += matches!(event, Event::Rupture { .. }) as usize;
    /// })?;
    /// assert!(events.is_file() && ruptures > 0);
    /// # std::fs::remove_dir_all(&out).ok();
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`RunTables::run_until`] and [`RunTables::finish`].
    #[cfg(feature = "serde")]
    pub fn run_to_slip(
        mut self,
        driver: &mut Driver,
        checkpoint: Option<(&Path, std::num::NonZeroU64)>,
        mut observe: impl FnMut(&Event, &Driver),
    ) -> Result<[PathBuf; 3]> {
        self.run_until(driver, checkpoint, |event, driver| {
            observe(event, driver);
            ControlFlow::<std::convert::Infallible>::Continue(())
        })?;
        self.finish()
    }

    /// The one run loop (feature `serde`) of the program's `run` and `resume`, of a
    /// sweep's runs and of the Python package: steps `driver` writing its tables, each
    /// event [recorded](RunTables::record), then `observe` called with it and the driver
    /// in the state right after it; with `checkpoint = Some((path, every))`, at every
    /// `every`-th stable state recorded by this writer, the tables
    /// [flushed](RunTables::flush) and a checkpoint covering their rows
    /// ([`RunTables::checkpoint`]) written over `path` ([`crate::Checkpoint::write_to`]),
    /// so a resume finds every row up to it, and refuses one edited since.
    ///
    /// Returns `Ok(None)` at global slip (then [`RunTables::finish`] the tables), or
    /// `Ok(Some(value))` as soon as `observe` returns `ControlFlow::Break(value)`: the rows
    /// so far are then flushed to disk, the tables stay `NAME.partial`, and a later call
    /// continues with the next event (as [`Driver::run`]). A run stopped so is resumed in
    /// another process from its last checkpoint (`precursors resume`).
    ///
    /// ```
    /// use precursors::{output::RunTables, Event, Scene};
    /// use std::ops::ControlFlow;
    /// let scene = Scene::builder().block(0.012, 0.002, 0.010).normal_load(50.0).build()?;
    /// let mut driver = scene.driver()?;
    /// # let out = std::env::temp_dir().join(format!("precursors-doc-until-{}", std::process::id()));
    /// # std::fs::create_dir_all(&out).unwrap();
    /// let mut tables = RunTables::create(&out, &driver)?;
    /// // Stop at the first rupture: the rows so far are on disk, still `.partial`.
    /// let stop = |event: &Event, _: &_| match event {
    ///     Event::Rupture { .. } => ControlFlow::Break(()),
    ///     _ => ControlFlow::Continue(()),
    /// };
    /// assert_eq!(tables.run_until(&mut driver, None, stop)?, Some(()));
    /// assert!(out.join("events.csv.partial").is_file());
    /// // Continue to global slip, then finish.
    /// let never = |_: &Event, _: &_| ControlFlow::<()>::Continue(());
    /// assert_eq!(tables.run_until(&mut driver, None, never)?, None);
    /// let [events, ..] = tables.finish()?;
    /// assert!(events.is_file());
    /// # std::fs::remove_dir_all(&out).ok();
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// The first error of [`Driver::step`], [`RunTables::record`], [`RunTables::flush`]
    /// or [`crate::Checkpoint::write_to`]; a checkpoint `path` naming a file of the run
    /// directory ([`check_output_path`]).
    #[cfg(feature = "serde")]
    pub fn run_until<B>(
        &mut self,
        driver: &mut Driver,
        checkpoint: Option<(&Path, std::num::NonZeroU64)>,
        mut observe: impl FnMut(&Event, &Driver) -> ControlFlow<B>,
    ) -> Result<Option<B>> {
        if let Some((path, _)) = checkpoint {
            check_output_path(&self.dir, path)?;
        }
        while let Some(event) = driver.step()? {
            self.record(driver, &event)?;
            if let (Event::Stable { .. }, Some((path, every))) = (&event, checkpoint) {
                if (self.stable_states() as u64).is_multiple_of(every.get()) {
                    self.checkpoint(driver)?.write_to(path)?;
                }
            }
            if let ControlFlow::Break(value) = observe(&event, driver) {
                self.flush()?;
                return Ok(Some(value));
            }
        }
        Ok(None)
    }

    /// Ends a run that reached global slip: the tables are flushed and synced,
    /// `per_avalanche.csv` and `fronts.csv` derived from them and written, then the
    /// tables renamed from `NAME.partial` to `NAME` (replacing those of an earlier run),
    /// and the directory's lock (if this writer took it) is released. Returns the tables'
    /// paths.
    ///
    /// # Errors
    /// [`Error::RunDirectory`] when global slip was not recorded (the tables stay
    /// `.partial`); [`Error::Io`] when a table cannot be written, synced or renamed;
    /// [`Error::CorruptTable`] when the tables written are not the whole run (another
    /// process changed them).
    pub fn finish(mut self) -> Result<[PathBuf; 3]> {
        if !self.slipped {
            return Err(Error::RunDirectory {
                path: self.dir.clone(),
                reason: format!(
                    "the run has not reached global slip: its tables stay \
                     NAME{PARTIAL}"
                ),
            });
        }
        self.flush()?;
        // The derived tables before the renames: a run whose events.csv has its name has
        // them too.
        let read = |t: usize| crate::files::read_text(&self.partials[t], "reading table");
        derived::write(
            &self.dir,
            &self.grid,
            &self.bounds,
            [&read(0)?, &read(1)?],
            [&self.partials[0], &self.partials[1]],
        )?;
        // events.csv last: a crash between the renames leaves it .partial, so a resume
        // or a rerun still sees the run as not finished.
        if let Some(fields) = &self.fields {
            rename_table(&fields.partial, &fields.path)?;
        }
        if let Some(profiles) = &self.profiles {
            profiles.rename()?;
        }
        for t in [2, 1, 0] {
            rename_table(&self.partials[t], &self.paths[t])?;
        }
        sync_dir(&self.dir).map_err(|e| Error::io("syncing directory", &self.dir, e))?;
        Ok(self.paths.clone())
    }
}

/// What a resumed run keeps of what it recorded beside its tables, checked and cut back
/// to the checkpoint (`None` where the options record nothing of the kind).
struct Recordings {
    /// `fields.csv`'s text, and the path it was read from.
    fields: Option<(String, PathBuf)>,
    /// `profiles.csv`'s text, the path it was read from, and the rule where it stands.
    profiles: Option<(String, PathBuf, profiles::Levels)>,
}

impl Recordings {
    /// Reads and checks the recordings of `dir` against the tables' continuation `plan`;
    /// writes nothing.
    fn kept(
        dir: &Path,
        driver: &Driver,
        options: &RunOptions,
        plan: &resume::Continuation,
    ) -> Result<Self> {
        let nx = driver.grid().nx();
        let fields = if options.fields_every() > 0 {
            let (path, partial) = FieldsTable::paths(dir);
            let (old, read) = read_old(&partial, &path)?;
            let text = fields_continuation(
                old.as_deref(),
                &read,
                &plan.stable,
                (options.fields_every(), options.field_planes()),
                (nx, driver.grid().ny()),
            )?;
            Some((text, read))
        } else {
            None
        };
        let profiles = if options.profile_loads().is_empty() {
            None
        } else {
            let (path, partial) = ProfilesTable::paths(dir);
            let (old, read) = read_old(&partial, &path)?;
            let states: Vec<(usize, f64)> = plan
                .stable
                .iter()
                .copied()
                .zip(plan.loads.iter().copied())
                .collect();
            // The loads as curve.csv writes them (a value read back prints the same).
            let load_text = |event: usize| {
                states
                    .iter()
                    .find(|s| s.0 == event)
                    .map(|s| format!("{:.12e}", s.1))
            };
            let (text, rule) =
                profiles::continuation(old.as_deref(), &read, options, nx, &states, load_text)?;
            Some((text, read, rule))
        };
        Ok(Self { fields, profiles })
    }

    /// The writers continuing the kept recordings in `dir` (`stable`: the stable states
    /// kept); a recording the options no longer ask for is removed (it would not cover
    /// the run).
    fn continue_in(
        self,
        dir: &Path,
        driver: &Driver,
        options: &RunOptions,
        stable: usize,
    ) -> Result<(Option<FieldsTable>, Option<ProfilesTable>)> {
        // A recording the options do not ask for was refused (`check_recorded_observers`):
        // none is there to remove.
        let fields = match self.fields {
            Some((text, _)) => {
                FieldsTable::new(driver, options, dir, |path| append_to(path, &text), stable)?
            }
            None => None,
        };
        let profiles = match self.profiles {
            Some((text, _, rule)) => {
                ProfilesTable::new(driver, options, dir, |path| append_to(path, &text), rule)?
            }
            None => None,
        };
        Ok((fields, profiles))
    }
}

/// Removes the temporary files of the tables and the scene record that a writer killed
/// while writing one left in `dir`; only the lock holder writes them.
fn remove_stale_temporaries(dir: &Path) -> Result<()> {
    let names: Vec<String> = TABLES
        .iter()
        .map(|n| format!("{n}{PARTIAL}"))
        .chain([
            RUN_SCENE.to_string(),
            format!("{FIELDS_FILE}{PARTIAL}"),
            format!("{}{PARTIAL}", layout::PROFILES_TABLE),
        ])
        .chain(layout::DERIVED_TABLES.map(String::from))
        .collect();
    crate::files::remove_temporaries(dir, &names)
}

/// Removes the figures and movies of an earlier run from `dir` ([`layout::derived`]): they
/// would stand beside tables they were not drawn from.
fn remove_derived(dir: &Path) -> Result<()> {
    let entries = fs::read_dir(dir).map_err(|e| Error::io("reading directory", dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io("reading directory", dir, e))?;
        let is_file = entry.file_type().is_ok_and(|t| !t.is_dir());
        if is_file && entry.file_name().to_str().is_some_and(layout::derived) {
            crate::files::remove_if_exists(&entry.path(), "removing the earlier run's figure")?;
        }
    }
    Ok(())
}

/// Removes the regular file `path` where it exists (a link there is refused).
fn remove_if_exists(path: &Path) -> Result<()> {
    crate::files::remove_if_exists(path, "removing the earlier run's table")
}

/// Renames a table from `partial` to its name `path`, refusing a link or any other
/// file that is not a regular one at `path` (a rename would replace it silently).
pub(crate) fn rename_table(partial: &Path, path: &Path) -> Result<()> {
    check_replaceable(path, "renaming table")?;
    fs::rename(partial, path).map_err(|e| Error::io("renaming table", path, e))
}

/// Removes `fields.csv` and `fields.csv.partial` from `dir` (where they exist).
fn remove_fields(dir: &Path) -> Result<()> {
    let (path, partial) = FieldsTable::paths(dir);
    remove_if_exists(&path)?;
    remove_if_exists(&partial)
}

/// Removes `profiles.csv` and `profiles.csv.partial` from `dir` (where they exist).
fn remove_profiles(dir: &Path) -> Result<()> {
    let (path, partial) = ProfilesTable::paths(dir);
    remove_if_exists(&path)?;
    remove_if_exists(&partial)
}

/// Removes what an earlier run recorded beside its tables.
fn remove_recordings(dir: &Path) -> Result<()> {
    remove_fields(dir)?;
    remove_profiles(dir)
}

/// A table being written: its buffered file and the running digest of its rows, which a
/// checkpoint records ([`RunTables::checkpoint`]) and a resume checks the kept rows against.
#[derive(Debug)]
pub(crate) struct TableFile {
    file: BufWriter<File>,
    digest: RowDigest,
}

impl TableFile {
    /// Writes the rows so far to disk (flushed and synced).
    pub(crate) fn sync(&mut self) -> io::Result<()> {
        self.file.flush()?;
        self.file.get_ref().sync_data()
    }

    /// What a checkpoint records of the rows so far of the table `name`.
    pub(crate) fn digest(&self, name: &str) -> TableDigest {
        self.digest.table(name)
    }
}

impl Write for TableFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.file.write(buf)?;
        self.digest.update(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

/// A new table at `path` holding its header (an old one there replaced; a link or a FIFO
/// refused, never written through).
fn new_table(path: &Path, header: &str) -> Result<TableFile> {
    let mut file = crate::files::create(path, "creating table")?;
    writeln!(file, "{header}").map_err(|e| Error::io("writing table", path, e))?;
    Ok(TableFile {
        file: BufWriter::new(file),
        digest: RowDigest::new(),
    })
}

/// The table at `path` rewritten (atomically) as `text` (its header and the rows kept),
/// opened to append.
fn append_to(path: &Path, text: &str) -> Result<TableFile> {
    write_atomically(path, text.as_bytes(), "writing table")?;
    let file = crate::files::open(path, OpenOptions::new().append(true), "opening table")?;
    Ok(TableFile {
        file: BufWriter::new(file),
        digest: RowDigest::of_rows(text.lines().skip(1)),
    })
}

/// The text of a table of a run under way (`partial`), else of a finished run (`path`),
/// and the path read (`partial` when neither exists).
fn read_old(partial: &Path, path: &Path) -> Result<(Option<String>, PathBuf)> {
    for p in [partial, path] {
        if let Some(text) = read_text_if_exists(p, "reading table")? {
            return Ok((Some(text), p.to_path_buf()));
        }
    }
    Ok((None, partial.to_path_buf()))
}

/// Refuses run options that `driver`'s scene cannot record, naming the key.
fn check_options(driver: &Driver, options: &RunOptions) -> Result<()> {
    // The tables are checked against a built-in rule (the friction limit μF_N, the
    // replay of the site events) and the directory records the scene's keys.
    driver
        .scene()
        .contact_rule()
        .built_in("recording a run directory")?;
    let probes = options.probe_spec().unwrap_or(driver.scene().probes());
    crate::scene::check_run_options(options, driver.grid(), probes.tolerance())
}

/// Refuses, before anything is written, a resume into `dir` that would not continue
/// every table recorded there with `options`: `fields.csv` or `profiles.csv` (or their
/// `.partial`) that `options` do not record, or (feature `serde`) a `scene.json` whose
/// observers (keys `fields`, `profiles`) differ from `options`' (it must describe the
/// tables present, and a resume does not rewrite it).
fn check_recorded_observers(dir: &Path, options: &RunOptions) -> Result<()> {
    let refuse = |reason: String| {
        Err(Error::RunDirectory {
            path: dir.to_path_buf(),
            reason,
        })
    };
    for (name, recorded) in [
        (FIELDS_FILE, options.fields_every() > 0),
        (layout::PROFILES_TABLE, !options.profile_loads().is_empty()),
    ] {
        let partial = format!("{name}{PARTIAL}");
        let found = [name, partial.as_str()]
            .into_iter()
            .find(|n| !recorded && fs::symlink_metadata(dir.join(n)).is_ok())
            .map(String::from);
        if let Some(found) = found {
            return refuse(format!(
                "it holds {found}, which this resume would not continue (it records no {name}): \
                 resume with the observers the run was recorded with (its scene.json), or run \
                 the scene again into another directory"
            ));
        }
    }
    #[cfg(feature = "serde")]
    {
        let path = dir.join(RUN_SCENE);
        if let Some(text) = read_text_if_exists(&path, "reading the scene record")? {
            let recorded = crate::scene::SceneBuilder::from_json_str(&text).map_err(|e| {
                Error::RunDirectory {
                    path: path.clone(),
                    reason: format!("not a scene file ({})", crate::error::Chain(&e)),
                }
            })?;
            let run = recorded.current_run();
            let differs = if run.fields_every() != options.fields_every()
                || run.field_planes() != options.field_planes()
            {
                Some("fields")
            } else if run.profile_loads() != options.profile_loads()
                || run.profile_planes() != options.profile_planes()
            {
                Some("profiles")
            } else {
                None
            };
            if let Some(key) = differs {
                return refuse(format!(
                    "its {RUN_SCENE} records other `{key}` than this resume records: the \
                     tables would not be the ones it describes; resume with the observers \
                     it records, or run the scene again into another directory"
                ));
            }
        }
    }
    Ok(())
}

/// Refuses a directory whose recorded scene is not `driver`'s, or that records none.
#[cfg(feature = "serde")]
fn check_scene_record(dir: &Path, driver: &Driver) -> Result<()> {
    let path = dir.join(RUN_SCENE);
    let text = match read_text_if_exists(&path, "reading the scene record")? {
        Some(text) => text,
        None => {
            return Err(Error::RunDirectory {
                path: dir.to_path_buf(),
                reason: format!(
                    "it holds no {RUN_SCENE}, the record of the scene its tables belong to \
                     (written when a run starts), so the checkpoint cannot be checked against \
                     them: run the scene again into this directory, or resume into a copy of \
                     the directory of the checkpoint's run"
                ),
            })
        }
    };
    let recorded =
        crate::scene::SceneBuilder::from_json_str(&text).map_err(|e| Error::RunDirectory {
            path: path.clone(),
            reason: format!("not a scene file ({})", crate::error::Chain(&e)),
        })?;
    match crate::driver::scene_mismatch(
        &driver.scene().to_builder(),
        "the checkpoint's scene",
        &recorded,
        &format!("the scene recorded in {}", path.display()),
    ) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Map level `k`: `F/(μF_N) = k · 0.005`.
fn level(k: u64) -> f64 {
    k as f64 * MAP_STEP
}

/// The first map level at or above the load `x = F/(μF_N)` (0 for `x <= 0`). Rounded to
/// 1e-9 of a step first, so that a load on a level up to rounding counts as on it.
fn first_level_at_or_above(x: f64) -> u64 {
    ((x / MAP_STEP * 1e9).round() / 1e9).max(0.0).ceil() as u64
}

/// Broken and attached sites of `states`.
pub(crate) fn counts(states: &[SiteState]) -> (usize, usize) {
    let broken = states.iter().filter(|s| **s == SiteState::Broken).count();
    let attached = states.iter().filter(|s| **s == SiteState::Attached).count();
    (broken, attached)
}

fn optional(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.12e}")).unwrap_or_default()
}

fn write_event(out: &mut impl Write, index: usize, event: &Event, exceeds: bool) -> io::Result<()> {
    let kind = event.kind();
    let (site, load, energy, ruptures) = match *event {
        Event::LoadRaised { load } | Event::GlobalSlip { load } => (None, Some(load), None, None),
        Event::Rupture { site, load, energy } => (Some(site), Some(load), Some(energy), None),
        Event::Detach { site } | Event::Attach { site } => (Some(site), None, None, None),
        Event::Stable { load, ruptures } => (None, Some(load), None, Some(ruptures)),
    };
    let (ix, iy) = site.map_or((String::new(), String::new()), |s| {
        (s.ix.to_string(), s.iy.to_string())
    });
    writeln!(
        out,
        "{index},{kind},{ix},{iy},{},{},{},{},{}",
        optional(load.map(|l| l.force)),
        optional(load.and_then(|l| l.drive_displacement)),
        optional(energy),
        ruptures.map(|r| r.to_string()).unwrap_or_default(),
        u8::from(exceeds)
    )
}
