//! Checkpoints: a [`Driver`] frozen between two events, resumable on its scene.
//!
//! A checkpoint holds everything the protocol and the solvers carry from one event to the
//! next, including the solvers' warm starts, the dense backend's LDLᵀ factor and the
//! spectral preconditioner's `d̄`: iterative solves stop at a tolerance, so their results
//! depend on where they start and how they are preconditioned at the rounding level, and
//! a near-tie between two sites would otherwise let a resumed run pick another rupture.
//! With the full state, a resumed run repeats the uninterrupted one bit for bit (same
//! build, same CPU features: the FFT kernels are chosen at run time).

use super::{Driver, Phase};
use crate::contact::ContactState;
use crate::driver::Event;
use crate::error::{Error, Result};
use crate::interface::SiteState;
use crate::scene::{file, Scene, SceneBuilder};
use crate::solver::{AnchorResponse, NormalEquilibrium, SolverState, TangentialResponse};

/// Version of the checkpoint layout; a checkpoint of another version is refused.
/// Version 2: the scene digest; the dense backend's one factor. Version 3: the JSON form
/// ends with a digest of its whole content; unknown keys are refused. Version 4: the
/// digests of the table rows it covers (`tables`). Version 5: the state of an anchored
/// contact rule (`contact`), written only under such a rule: the paper's rule still
/// writes version 4, byte for byte, and versions 3 and 4 resume under it.
const FORMAT: u32 = 5;

/// The layout the paper's contact rule writes ([`FORMAT`]'s version 4).
const PAPER_FORMAT: u32 = 4;

/// The oldest layout still read: version 3 (1.x) has no table digests, and its tables are
/// checked as before them (row by row and against each other).
const OLDEST_FORMAT: u32 = 3;

/// Rows between two marks of a table's digest: an edit is located to within this many
/// rows (the marks of a table of `r` rows add about `r / 3` bytes to a checkpoint).
const MARK_ROWS: u64 = 64;

/// The last key of a checkpoint's JSON form: its digest ([`Checkpoint::to_json`]).
#[cfg(feature = "serde")]
const DIGEST_KEY: &str = ",\"digest\":\"";

/// FNV-1a's (64 bits) starting value.
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a (64 bits) of `hash` followed by `bytes`: a digest that is the same on every
/// platform and build.
fn fnv1a_extend(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// FNV-1a (64 bits) of a text.
fn fnv1a(text: &str) -> u64 {
    fnv1a_extend(FNV_OFFSET, text.as_bytes())
}

/// The running digest of a table's rows as they are written (its header excluded):
/// FNV-1a of their bytes, newlines included, with its value after every [`MARK_ROWS`]-th
/// row kept. A checkpoint records it ([`TableDigest`]).
#[derive(Debug, Clone)]
pub(crate) struct RowDigest {
    rows: u64,
    hash: u64,
    marks: Vec<u64>,
}

impl RowDigest {
    /// The digest of no rows.
    pub(crate) fn new() -> Self {
        Self {
            rows: 0,
            hash: FNV_OFFSET,
            marks: Vec::new(),
        }
    }

    /// The digest of `rows` (each without its newline).
    pub(crate) fn of_rows<'a>(rows: impl IntoIterator<Item = &'a str>) -> Self {
        let mut digest = Self::new();
        for row in rows {
            digest.update(row.as_bytes());
            digest.update(b"\n");
        }
        digest
    }

    /// Adds bytes written to the table.
    pub(crate) fn update(&mut self, bytes: &[u8]) {
        // Row by row: the marks fall after each MARK_ROWS-th newline.
        for line in bytes.split_inclusive(|&b| b == b'\n') {
            self.hash = fnv1a_extend(self.hash, line);
            if line.ends_with(b"\n") {
                self.rows += 1;
                if self.rows.is_multiple_of(MARK_ROWS) {
                    self.marks.push(self.hash);
                }
            }
        }
    }

    /// What a checkpoint records of the rows so far of the table `name`.
    pub(crate) fn table(&self, name: &str) -> TableDigest {
        TableDigest {
            table: name.to_string(),
            rows: self.rows,
            marks: self.marks.clone(),
            digest: self.hash,
        }
    }
}

/// What a checkpoint records of a table of its run ([`RowDigest`]): the rows it covers
/// (after the header) and their digest, with the digest after every [`MARK_ROWS`]-th row
/// so that an edit is located.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct TableDigest {
    table: String,
    rows: u64,
    marks: Vec<u64>,
    digest: u64,
}

/// Where kept rows differ from those a checkpoint covers ([`TableDigest::difference`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowDifference {
    /// The first differing row is one of the rows `first..=last` (numbered from 1 after
    /// the header).
    Rows { first: u64, last: u64 },
    /// Only `kept` rows are kept, the checkpoint covers more.
    Missing { kept: u64 },
    /// More rows are kept than the checkpoint covers.
    Extra { covered: u64 },
}

impl TableDigest {
    /// The table's name (`events.csv`).
    pub(crate) fn table(&self) -> &str {
        &self.table
    }

    /// Rows covered (after the header).
    pub(crate) fn rows(&self) -> u64 {
        self.rows
    }

    /// Where `rows` (each without its newline) differ from the rows digested, `None` when
    /// they are the same.
    pub(crate) fn difference(&self, rows: &[&str]) -> Option<RowDifference> {
        let mut digest = RowDigest::new();
        for (k, row) in rows.iter().enumerate().take(self.rows as usize) {
            digest.update(row.as_bytes());
            digest.update(b"\n");
            let n = k as u64 + 1;
            if n.is_multiple_of(MARK_ROWS)
                && self.marks.get(k / MARK_ROWS as usize) != Some(&digest.hash)
            {
                return Some(RowDifference::Rows {
                    first: n + 1 - MARK_ROWS,
                    last: n,
                });
            }
        }
        let kept = rows.len() as u64;
        if kept < self.rows {
            return Some(RowDifference::Missing { kept });
        }
        if digest.hash != self.digest {
            return Some(RowDifference::Rows {
                first: self.rows - self.rows % MARK_ROWS + 1,
                last: self.rows,
            });
        }
        (kept > self.rows).then_some(RowDifference::Extra { covered: self.rows })
    }

    /// Whether its marks are those of its row count (a checkpoint that holds others was
    /// not written by this crate).
    fn consistent(&self) -> bool {
        let last = if self.rows.is_multiple_of(MARK_ROWS) {
            self.marks.last().copied().unwrap_or(FNV_OFFSET)
        } else {
            self.digest
        };
        self.marks.len() as u64 == self.rows / MARK_ROWS && last == self.digest
    }
}

/// The digest of a scene: each key of its identity ([`file::identity`]) and a hash of
/// its exact value.
fn digest(scene: &SceneBuilder) -> Vec<(String, u64)> {
    file::identity(scene)
        .into_iter()
        .map(|(key, value)| (key, fnv1a(&value)))
        .collect()
}

/// The first key whose hash differs between two digests (or that only one holds).
fn first_difference(a: &[(String, u64)], b: &[(String, u64)]) -> Option<String> {
    a.iter()
        .find(|(key, hash)| !b.iter().any(|(k, h)| k == key && h == hash))
        .or_else(|| b.iter().find(|(key, _)| !a.iter().any(|(k, _)| k == key)))
        .map(|(key, _)| key.clone())
}

/// [`Error::CheckpointSceneMismatch`] naming the first option in which `b` describes
/// another run than `a` (`a_is`, `b_is`: what each scene is, for the message), if any.
pub(crate) fn scene_mismatch(
    a: &SceneBuilder,
    a_is: &str,
    b: &SceneBuilder,
    b_is: &str,
) -> Option<Error> {
    let key = file::first_difference(a, b)?;
    Some(Error::CheckpointSceneMismatch {
        reason: format!(
            "{a_is} has {}, {b_is} has {}",
            value_of(a, &key),
            value_of(b, &key)
        ),
        key,
    })
}

/// The value of `key` in `scene`, shortened for a message.
fn value_of(scene: &SceneBuilder, key: &str) -> String {
    match file::identity(scene).into_iter().find(|(k, _)| k == key) {
        None => "no such key".into(),
        Some((_, v)) if v.chars().count() > 48 => {
            format!("{}...", v.chars().take(45).collect::<String>())
        }
        Some((_, v)) => v,
    }
}

/// A snapshot of a [`Driver`] between two events ([`Driver::checkpoint`]), resumed by
/// [`Scene::resume`]. With the `serde` feature it serialises in any serde format
/// (`Checkpoint::to_json` for JSON, `Checkpoint::write_to` and `Checkpoint::read_from`
/// for files); floats must round-trip exactly (they do in JSON through this crate, which
/// enables `serde_json`'s `float_roundtrip`).
///
/// A checkpoint holds its scene and a digest of it (a hash of every option by its
/// scene-file key): [`Scene::resume`] refuses, naming the first differing key, a scene
/// that differs from the checkpoint's and a checkpoint whose stored scene was edited
/// after it was taken ([`Error::CheckpointSceneMismatch`]). Its JSON form also ends with
/// a digest of its whole content (FNV-1a, 64 bits: it detects edits and damage, it is no
/// signature), checked when it is read: an edited count, site state or number, or a
/// damaged file, is refused with the reason. [`Scene::resume`] also checks its state
/// against the protocol and the physics (both equilibria hold, one residual evaluation
/// each; a stable state holds its load). Taken by
/// [`crate::output::RunTables::checkpoint`], it records the digests of the table rows it
/// covers, which [`crate::output::RunTables::resume`] checks the kept rows against
/// (layout version 4; version 3 checkpoints, without them, still resume).
///
/// ```
/// use precursors::{Event, Scene};
/// let scene = Scene::builder().block(0.012, 0.002, 0.010).normal_load(50.0).seed(2).build()?;
/// let mut driver = scene.driver()?;
/// let first: Vec<Event> = driver.by_ref().take(30).collect::<Result<_, _>>()?;
/// let checkpoint = driver.checkpoint();
/// let rest: Vec<Event> = driver.collect::<Result<_, _>>()?;
/// // Later, or in another process (after a round trip through JSON with `serde`):
/// let resumed: Vec<Event> = scene.resume(&checkpoint)?.collect::<Result<_, _>>()?;
/// assert_eq!(resumed, rest);
/// # let _ = first;
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Checkpoint {
    format: u32,
    scene: SceneBuilder,
    scene_digest: Vec<(String, u64)>,
    states: Vec<SiteState>,
    normal: Option<NormalEquilibrium>,
    response: Option<TangentialResponse>,
    initial_columns: Vec<f64>,
    control: f64,
    pending: Vec<Event>,
    phase: Phase,
    avalanche_ruptures: usize,
    events: usize,
    solver: SolverState,
    /// An anchored rule's state and its anchors' response (layout version 5; none under
    /// the paper's rule).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    contact: Option<ContactCheckpoint>,
    /// The digests of the table rows it covers, when taken by
    /// [`crate::output::RunTables::checkpoint`] (none in layout version 3).
    #[cfg_attr(feature = "serde", serde(default))]
    tables: Option<Vec<TableDigest>>,
}

/// What a checkpoint holds of an anchored contact rule.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
struct ContactCheckpoint {
    state: ContactState,
    /// The anchors' response `g0` (none before the first event).
    anchor: Option<AnchorResponse>,
}

impl Checkpoint {
    /// The scene the checkpoint was taken on (build it to resume in a new process).
    pub fn scene(&self) -> &SceneBuilder {
        &self.scene
    }

    /// Events the driver had returned when the checkpoint was taken.
    pub fn event_count(&self) -> usize {
        self.events
    }

    /// The checkpoint with the digests of the rows of its run's tables (`RunTables`).
    pub(crate) fn with_tables(mut self, tables: Vec<TableDigest>) -> Self {
        self.tables = Some(tables);
        self
    }

    /// The checkpoint as compact JSON (feature `serde`), ending with the key `digest`:
    /// the FNV-1a (64 bits, 16 hexadecimal digits) of the text before it closed with `}`,
    /// that is of the checkpoint's compact JSON without its digest.
    ///
    /// # Errors
    /// [`Error::CustomContactRule`] for a checkpoint of a driver under a custom contact
    /// rule ([`crate::ContactLaw`]: a scene file cannot name it);
    /// [`Error::InvalidCheckpoint`] if serialisation fails (it does not for a checkpoint
    /// taken by [`Driver::checkpoint`] under a built-in rule).
    #[cfg(feature = "serde")]
    pub fn to_json(&self) -> Result<String> {
        self.scene.contact().built_in("writing a checkpoint")?;
        let body = serde_json::to_string(self).map_err(|e| Error::InvalidCheckpoint {
            reason: format!("cannot be written as JSON: {e}"),
        })?;
        let open = body.strip_suffix('}').unwrap_or(&body);
        Ok(format!("{open}{DIGEST_KEY}{:016x}\"}}", fnv1a(&body)))
    }

    /// Reads a checkpoint written by [`Checkpoint::to_json`] (feature `serde`) and checks
    /// its digest.
    ///
    /// # Errors
    /// [`Error::InvalidCheckpoint`] when `text` is not a checkpoint (not JSON, cut short,
    /// an unknown key), is of another layout version, or does not match its digest (it
    /// was edited or damaged); [`Error::CheckpointSceneMismatch`], naming the key, when
    /// the edit is in its scene.
    #[cfg(feature = "serde")]
    pub fn from_json_str(text: &str) -> Result<Checkpoint> {
        verified(text).map_err(|refusal| match refusal {
            Refusal::Scene(e) => e,
            Refusal::Reason(reason) => Error::InvalidCheckpoint {
                reason: format!("not a valid checkpoint: {reason}"),
            },
        })
    }

    /// Writes the checkpoint as JSON to `path` atomically (feature `serde`): to a
    /// temporary file in the same directory, synced to disk, then renamed over `path`
    /// (and the directory synced on Unix). A crash leaves the old file or the new one,
    /// never half of one.
    ///
    /// # Errors
    /// [`Error::Io`] with the path of the file that could not be written, synced or
    /// renamed (the temporary file is removed); [`Error::InvalidCheckpoint`] when the
    /// checkpoint cannot be written as JSON.
    #[cfg(feature = "serde")]
    pub fn write_to(&self, path: impl AsRef<std::path::Path>) -> Result<()> {
        crate::files::write_atomically(
            path.as_ref(),
            self.to_json()?.as_bytes(),
            "writing checkpoint",
        )
    }

    /// Reads a checkpoint file written by [`Checkpoint::write_to`] (or holding
    /// [`Checkpoint::to_json`]'s text; feature `serde`).
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read; [`Error::CheckpointFile`], with the
    /// path, when it holds no valid checkpoint (not JSON, cut short, an unknown key,
    /// another layout version, a content that does not match its digest);
    /// [`Error::CheckpointSceneMismatch`] as [`Checkpoint::from_json_str`].
    #[cfg(feature = "serde")]
    pub fn read_from(path: impl AsRef<std::path::Path>) -> Result<Checkpoint> {
        let path = path.as_ref();
        let text = crate::files::read_text(path, "reading checkpoint")?;
        verified(&text).map_err(|refusal| match refusal {
            Refusal::Scene(e) => e,
            Refusal::Reason(reason) => Error::CheckpointFile {
                path: path.display().to_string(),
                reason,
            },
        })
    }
}

/// Why a checkpoint's text was refused.
#[cfg(feature = "serde")]
enum Refusal {
    /// Its scene was edited: the error names the key.
    Scene(Error),
    /// Anything else.
    Reason(String),
}

/// The checkpoint of `text` once its version, keys and digest are checked.
#[cfg(feature = "serde")]
fn verified(text: &str) -> std::result::Result<Checkpoint, Refusal> {
    /// The version alone, read before the layout it decides.
    #[derive(serde::Deserialize)]
    struct Version {
        format: Option<u32>,
    }
    let reason = |r: String| Refusal::Reason(r);
    let text = text.trim_end();
    let version: Version = serde_json::from_str(text).map_err(|e| reason(e.to_string()))?;
    match version.format {
        None => return Err(reason("it has no `format` key".into())),
        Some(v) if !(OLDEST_FORMAT..=FORMAT).contains(&v) => {
            return Err(reason(format!(
                "layout version {v}, this build reads versions {OLDEST_FORMAT} to {FORMAT} \
                 (version 3 added a digest of the whole content, version 4 the digests of \
                 the table rows, version 5 the state of an anchored contact rule): resume it with the precursors version that wrote it, or \
                 start the run again"
            )))
        }
        Some(_) => {}
    }
    let no_digest = || reason("it does not end with its digest (the key `digest`)".into());
    let at = text.rfind(DIGEST_KEY).ok_or_else(no_digest)?;
    let hex = text[at + DIGEST_KEY.len()..]
        .strip_suffix("\"}")
        .filter(|h| h.len() == 16)
        .ok_or_else(no_digest)?;
    let stored = u64::from_str_radix(hex, 16).map_err(|_| no_digest())?;
    let body = format!("{}}}", &text[..at]);
    let checkpoint: Checkpoint = serde_json::from_str(&body).map_err(|e| reason(e.to_string()))?;
    if fnv1a(&body) != stored {
        if let Some(key) = first_difference(&checkpoint.scene_digest, &digest(&checkpoint.scene)) {
            return Err(Refusal::Scene(Error::CheckpointSceneMismatch {
                reason: format!(
                    "the scene stored in the checkpoint was edited after the checkpoint was \
                     taken (its digest differs; it now holds {})",
                    value_of(&checkpoint.scene, &key)
                ),
                key,
            }));
        }
        return Err(reason(
            "its content does not match its digest: it was edited or damaged after it was \
             written"
                .into(),
        ));
    }
    Ok(checkpoint)
}

impl Driver {
    /// A snapshot of the driver as it stands (between two events); [`Scene::resume`]
    /// continues from it with exactly the events this driver would return. Under a custom
    /// contact rule ([`crate::ContactLaw`]) the snapshot can be neither resumed nor
    /// written ([`Error::CustomContactRule`]).
    pub fn checkpoint(&self) -> Checkpoint {
        let contact = self.contact.as_ref().map(|state| ContactCheckpoint {
            state: state.clone(),
            anchor: self.anchor.clone(),
        });
        Checkpoint {
            format: match contact {
                Some(_) => FORMAT,
                None => PAPER_FORMAT,
            },
            scene: self.scene.to_builder(),
            scene_digest: digest(&self.scene.to_builder()),
            states: self.interface.states().to_vec(),
            normal: self.normal.clone(),
            response: self.response.clone(),
            initial_columns: self.initial_columns.clone(),
            control: self.control,
            pending: self.pending.iter().copied().collect(),
            phase: self.phase,
            avalanche_ruptures: self.avalanche_ruptures,
            events: self.events,
            solver: self.solver.state(),
            contact,
            tables: None,
        }
    }
}

impl Scene {
    /// A driver continuing from `checkpoint`, which must have been taken on this scene
    /// (same builder: block, grid, material, springs, heights, loads, solver options; the
    /// thread count may differ, results do not depend on it; so may the probes, which
    /// observe: the resumed driver has this scene's, add others with
    /// [`Driver::add_probes`]).
    ///
    /// # Errors
    /// [`Error::CheckpointSceneMismatch`], naming the first differing option by its
    /// scene-file key, when the checkpoint was taken on another scene or its stored
    /// scene was edited since (the digest differs); [`Error::InvalidCheckpoint`] when it
    /// is of another layout version or inconsistent; [`Error::CustomContactRule`] under a
    /// custom contact rule ([`crate::ContactLaw`]: its state is not recorded); those of
    /// [`Scene::driver`].
    pub fn resume(&self, checkpoint: &Checkpoint) -> Result<Driver> {
        self.resume_with(checkpoint, self.run_options())
    }

    /// [`Scene::resume`] with the driver observed as `options` ask (probes, threads: as
    /// [`Scene::driver_with`]); give [`crate::output::RunTables::resume_with`] the same
    /// options (its example resumes a run this way).
    ///
    /// # Errors
    /// As [`Scene::resume`] and [`Scene::driver_with`].
    pub fn resume_with(
        &self,
        checkpoint: &Checkpoint,
        options: &crate::recording::RunOptions,
    ) -> Result<Driver> {
        self.check_checkpoint_scene(checkpoint)?;
        let started = self.check_checkpoint_state(checkpoint)?;
        let mut driver = self.driver_with(options)?;
        for (i, state) in checkpoint.states.iter().enumerate() {
            driver.interface.set_state(i, *state);
        }
        driver.solver.restore(checkpoint.solver.clone(), started)?;
        // λ is a function of the two equilibria: recomputed rather than stored (it holds
        // infinities, which JSON cannot).
        if let Some(contact) = &checkpoint.contact {
            driver.contact = Some(contact.state.clone());
            driver.anchor = contact.anchor.clone();
        }
        if let (Some(normal), Some(response)) = (&checkpoint.normal, &checkpoint.response) {
            let rule = driver.contact_rule();
            let anchor = match rule.anchors() {
                true => Some(driver.anchor.as_ref().map_or(&[][..], |a| &a.traction[..])),
                false => None,
            };
            (driver.breaking, driver.breaking_low) = rule.thresholds(
                &driver.interface,
                (&normal.traction, &response.traction),
                anchor,
                driver.friction_coefficient(),
                None,
            )?;
        }
        driver.normal = checkpoint.normal.clone();
        driver.response = checkpoint.response.clone();
        driver.initial_columns = checkpoint.initial_columns.clone();
        driver.control = checkpoint.control;
        driver.pending = checkpoint.pending.iter().copied().collect();
        driver.phase = checkpoint.phase;
        driver.avalanche_ruptures = checkpoint.avalanche_ruptures;
        driver.events = checkpoint.events;
        driver.kept_tables = checkpoint
            .tables
            .clone()
            .map(|tables| (checkpoint.events, tables));
        if checkpoint.phase == Phase::Failed {
            // A checkpoint does not hold the failure's message (layout version 3).
            driver.failure = Some("it was resumed from the checkpoint of a failed driver".into());
        }
        driver.refresh_shear();
        // A stable state holds its load: no attached site breaks under it (the test the
        // protocol's avalanche step makes, on the same values). A load raised by an edit
        // would otherwise break sites at a load the run never reached.
        if checkpoint.phase == Phase::Stable {
            let force = driver.force();
            if let Some(i) = driver.contact_rule().first_over_threshold(
                driver.interface.states(),
                &driver.breaking,
                &driver.breaking_low,
                force,
            ) {
                return Err(Error::InvalidCheckpoint {
                    reason: format!(
                        "it is a stable state at F = {force:e} N, but site {i} breaks at {:e} N: \
                         its load or state was edited",
                        driver.breaking[i]
                    ),
                });
            }
        }
        Ok(driver)
    }

    /// Refuses a checkpoint of another layout, or whose scene was edited or is not this
    /// one ([`Scene::resume`]'s first checks).
    fn check_checkpoint_scene(&self, checkpoint: &Checkpoint) -> Result<()> {
        // A custom rule's state is not recorded, nor its checks written.
        self.contact_rule().built_in("resuming a checkpoint")?;
        checkpoint
            .scene
            .contact()
            .built_in("resuming a checkpoint")?;
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        if !(OLDEST_FORMAT..=FORMAT).contains(&checkpoint.format) {
            return bad(format!(
                "layout version {} (this build reads versions {OLDEST_FORMAT} to {FORMAT})",
                checkpoint.format
            ));
        }
        if let Some(tables) = &checkpoint.tables {
            if checkpoint.format < PAPER_FORMAT {
                return bad(format!(
                    "layout version {} holds no table digests, this one does",
                    checkpoint.format
                ));
            }
            if let Some(t) = tables.iter().find(|t| !t.consistent()) {
                return bad(format!(
                    "the digest of {} does not fit its {} rows",
                    t.table, t.rows
                ));
            }
        }
        if let Some(key) = first_difference(&checkpoint.scene_digest, &digest(&checkpoint.scene)) {
            return Err(Error::CheckpointSceneMismatch {
                reason: format!(
                    "the scene stored in the checkpoint was edited after the checkpoint was \
                     taken (its digest differs; it now holds {})",
                    value_of(&checkpoint.scene, &key)
                ),
                key,
            });
        }
        let mine = self.to_builder();
        if let Some(e) = scene_mismatch(
            &checkpoint.scene,
            "the checkpoint's scene",
            &mine,
            "the scene resumed on",
        ) {
            return Err(e);
        }
        // Version 5 holds an anchored rule's state, and only it; the paper's rule writes 4.
        let anchored = self.contact_rule().anchors();
        if checkpoint.contact.is_some() != anchored || (checkpoint.format == FORMAT) != anchored {
            return bad(format!(
                "layout version {} {} the state of an anchored contact rule, and the scene's \
                 rule is {:?} (its checkpoints are of version {})",
                checkpoint.format,
                match checkpoint.contact {
                    Some(_) => "with",
                    None => "without",
                },
                self.contact_rule(),
                if anchored { FORMAT } else { PAPER_FORMAT }
            ));
        }
        Ok(())
    }

    /// Refuses a checkpoint whose state no driver of this scene writes (its digest may
    /// have been recomputed after an edit): lengths, values and the protocol's invariants.
    /// Returns whether the driver had returned events.
    fn check_checkpoint_state(&self, checkpoint: &Checkpoint) -> Result<bool> {
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        let n = self.grid().len();
        if checkpoint.states.len() != n {
            return bad(format!(
                "{} site states for a grid of {n} cells",
                checkpoint.states.len()
            ));
        }
        let lengths_ok = |v: &[f64]| v.len() == n && v.iter().all(|x| x.is_finite());
        if let Some(normal) = &checkpoint.normal {
            if !(lengths_ok(&normal.traction) && lengths_ok(&normal.displacement)) {
                return bad(format!(
                    "the normal equilibrium does not have {n} finite values"
                ));
            }
        }
        if let Some(response) = &checkpoint.response {
            if !(lengths_ok(&response.traction) && lengths_ok(&response.displacement)) {
                return bad(format!(
                    "the tangential response does not have {n} finite values"
                ));
            }
        }
        // What a driver holds once it has returned an event (the first is the stable state
        // at zero shear: both equilibria solved, the columns' areas recorded, the solver's
        // warm starts set) and holds none of before: a checkpoint whose digest was
        // recomputed after an edit must still be one a driver could have written.
        let started = checkpoint.events > 0;
        let columns = checkpoint.initial_columns.len();
        let nx = self.grid().nx();
        if columns != if started { nx } else { 0 }
            || !checkpoint
                .initial_columns
                .iter()
                .all(|a| a.is_finite() && *a >= 0.0)
        {
            return bad(format!(
                "{columns} initial column areas after {} events (a driver records the {nx} \
                 columns' finite areas >= 0 at its first event, none before)",
                checkpoint.events
            ));
        }
        if checkpoint.normal.is_some() != started || checkpoint.response.is_some() != started {
            return bad(format!(
                "after {} events it {} the equilibria (a driver solves them for its first \
                 event)",
                checkpoint.events,
                if started { "lacks" } else { "holds" }
            ));
        }
        if let Some(contact) = &checkpoint.contact {
            if let Err(reason) = contact.state.check(self.contact_rule(), &checkpoint.states) {
                return bad(format!("its contact rule's state: {reason}"));
            }
            let anchor_ok = match &contact.anchor {
                Some(a) => {
                    lengths_ok(&a.traction) && lengths_ok(&a.displacement) && a.offset.is_finite()
                }
                None => true,
            };
            if contact.anchor.is_some() != started || !anchor_ok {
                return bad(format!(
                    "after {} events it {} the anchors' response (a driver solves it, with {n} \
                     finite values, for its first event)",
                    checkpoint.events,
                    if contact.anchor.is_some() {
                        "holds"
                    } else {
                        "lacks"
                    }
                ));
            }
        }
        self.check_checkpoint_protocol(checkpoint, started)?;
        self.check_checkpoint_equilibria(checkpoint)?;
        if !checkpoint.control.is_finite() {
            return bad(format!("the load {} is not finite", checkpoint.control));
        }
        if let Phase::Avalanche { forced: Some(i) } = checkpoint.phase {
            if i >= n {
                return bad(format!("the threshold site {i} is beyond the grid's {n}"));
            }
        }
        Ok(started)
    }

    /// The checkpoint's equilibria against the physics they solve, once each (one product
    /// with the influence operator per equilibrium): the site states are those of its
    /// normal equilibrium; the displacements are those of the tractions (`u = U + e +
    /// (ΔA/M) Ĝ φ`, up to a constant); on attached sites the springs hold
    /// (`u_z + φ_z/k_z = u0`, `u_x + φ_x/k_x = 0`) to the solver's tolerance, normwise as
    /// the solver measures it; off them no traction; the tractions carry the loads
    /// (`ΔA Σ φ_z = F_N`, `ΔA Σ φ_x = -1 N` per newton). A checkpoint forged with a
    /// recomputed digest (tractions scaled, a site's state changed) fails one of them.
    fn check_checkpoint_equilibria(&self, checkpoint: &Checkpoint) -> Result<()> {
        let (Some(normal), Some(response)) = (&checkpoint.normal, &checkpoint.response) else {
            return Ok(());
        };
        // Done or failed: the last rupture or solve left the equilibria behind the states.
        if !matches!(
            checkpoint.phase,
            Phase::Stable | Phase::Reformed | Phase::Avalanche { .. }
        ) {
            return Ok(());
        }
        let states = &checkpoint.states;
        if !normal.states.is_empty() && normal.states != *states {
            let i = (0..states.len())
                .find(|&i| normal.states.get(i) != Some(&states[i]))
                .unwrap_or(0);
            return Err(Error::InvalidCheckpoint {
                reason: format!(
                    "site {i} is {:?}, its normal equilibrium has it {:?}: the site states were \
                     edited",
                    states[i],
                    normal.states.get(i)
                ),
            });
        }
        let n = states.len();
        let cell = self.grid().cell_area();
        let scale = cell / self.material().modulus();
        let product = |f: &[f64]| -> Result<Vec<f64>> {
            let mut out = vec![0.0; n];
            self.plan().apply(f, &mut out)?;
            out.iter_mut().for_each(|x| *x *= scale);
            Ok(out)
        };
        let attached: Vec<bool> = states.iter().map(|s| *s == SiteState::Attached).collect();
        let interface = self.interface();
        let normal_compliance = interface.normal_compliance();
        let tangential_compliance = (0..n)
            .map(|i| match attached[i] {
                true => interface.tangential_compliance_at(i, normal.displacement[i]),
                false => Ok(0.0),
            })
            .collect::<Result<Vec<f64>>>()?;
        let zero = vec![0.0; n];
        let unit_load = self.unit_load_displacement();
        let tolerance = RESIDUAL_FACTOR * self.solver_options().tolerance();
        let mut checks = vec![
            Equilibrium {
                name: "normal",
                traction: &normal.traction,
                displacement: &normal.displacement,
                product: product(&normal.traction)?,
                applied: &zero,
                compliance: &normal_compliance,
                rest: interface.heights(),
                total: self.normal_load(),
            },
            Equilibrium {
                name: "tangential",
                traction: &response.traction,
                displacement: &response.displacement,
                product: product(&response.traction)?,
                applied: &unit_load,
                compliance: &tangential_compliance,
                rest: &zero,
                total: -1.0,
            },
        ];
        // An anchored rule's springs at zero load: anchored at `a`, no net force.
        if let Some((state, Some(anchor))) = checkpoint
            .contact
            .as_ref()
            .map(|c| (&c.state, c.anchor.as_ref()))
        {
            checks.push(Equilibrium {
                name: "anchors'",
                traction: &anchor.traction,
                displacement: &anchor.displacement,
                product: product(&anchor.traction)?,
                applied: &zero,
                compliance: &tangential_compliance,
                rest: &state.anchors,
                total: 0.0,
            });
        }
        for check in checks {
            if let Some(reason) = check.violation(&attached, cell, tolerance) {
                return Err(Error::InvalidCheckpoint {
                    reason: format!(
                        "its {} equilibrium does not hold: {reason} (the tolerance {tolerance:e} \
                         is {RESIDUAL_FACTOR} times the solver's): its tractions, displacements \
                         or site states were edited",
                        check.name
                    ),
                });
            }
        }
        Ok(())
    }

    /// The protocol's own state in a checkpoint ([`Scene::check_checkpoint_state`]).
    fn check_checkpoint_protocol(&self, checkpoint: &Checkpoint, started: bool) -> Result<()> {
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        let n = self.grid().len();
        let nx = self.grid().nx();
        // The protocol's own state: it starts before the first event only, its queued
        // events name sites of the grid (index and column, row agreeing), and the ruptures
        // of an avalanche each broke a site that stays broken.
        let start = checkpoint.phase == Phase::Start;
        if (start && (started || !checkpoint.pending.is_empty()))
            // Before the first event: starting, or failed at the first step.
            || (!started && !start && checkpoint.phase != Phase::Failed)
        {
            return bad(format!(
                "phase {:?} after {} events with {} queued (a driver starts before its first \
                 event only, with none queued)",
                checkpoint.phase,
                checkpoint.events,
                checkpoint.pending.len()
            ));
        }
        for event in &checkpoint.pending {
            let site = match event {
                Event::Rupture { site, .. } | Event::Detach { site } | Event::Attach { site } => {
                    *site
                }
                _ => continue,
            };
            if site.index >= n || site.ix != site.index % nx || site.iy != site.index / nx {
                return bad(format!(
                    "a queued event names site {} at ({}, {}), not a site of the {nx} x {} grid",
                    site.index,
                    site.ix,
                    site.iy,
                    n / nx
                ));
            }
        }
        let bound = self
            .contact_rule()
            .avalanche_ruptures_bound(&checkpoint.states);
        if checkpoint.avalanche_ruptures > bound {
            return bad(format!(
                "{} ruptures in the avalanche under way, but {bound} broken sites",
                checkpoint.avalanche_ruptures
            ));
        }
        Ok(())
    }
}

/// How far above the solver's tolerance a checkpoint's equilibria may be off
/// ([`Scene::check_checkpoint_equilibria`]): the solver measures its backward error with
/// `‖A‖ ‖φ‖`, this check with the smaller `‖A φ‖`, and its product is another
/// implementation of the operator's (rounding apart).
const RESIDUAL_FACTOR: f64 = 1e4;

/// An equilibrium of a checkpoint, as [`Scene::check_checkpoint_equilibria`] checks it.
struct Equilibrium<'a> {
    name: &'static str,
    traction: &'a [f64],
    displacement: &'a [f64],
    /// `(ΔA/M) Ĝ φ`.
    product: Vec<f64>,
    /// The displacement the load causes without the tractions (`e`; zero for the normal).
    applied: &'a [f64],
    /// The springs' compliance `1/k` on attached sites.
    compliance: &'a [f64],
    /// The displacement at which an attached spring carries no traction (`u0`; zero for
    /// the shear).
    rest: &'a [f64],
    /// The load the tractions carry (N).
    total: f64,
}

impl Equilibrium<'_> {
    /// The first way it fails to hold to `tolerance` (normwise), if any.
    fn violation(&self, attached: &[bool], cell: f64, tolerance: f64) -> Option<String> {
        let n = self.traction.len();
        let max = |f: &dyn Fn(usize) -> f64| (0..n).map(f).fold(0.0_f64, f64::max);
        // u - e - Cφ is the constant U wherever the displacement is the tractions'.
        let offset: Vec<f64> = (0..n)
            .map(|i| self.displacement[i] - self.applied[i] - self.product[i])
            .collect();
        let mean = offset.iter().sum::<f64>() / n as f64;
        let size =
            max(&|i| self.product[i].abs() + self.applied[i].abs() + self.displacement[i].abs())
                + mean.abs();
        let spread = max(&|i| (offset[i] - mean).abs());
        if spread > tolerance * size {
            return Some(format!(
                "the displacements are not those of the tractions (off by {spread:e} m against \
                 a scale of {size:e} m)"
            ));
        }
        if let Some(i) = (0..n).find(|&i| !attached[i] && self.traction[i] != 0.0) {
            return Some(format!(
                "site {i}, not attached, carries the traction {:e} Pa",
                self.traction[i]
            ));
        }
        let spring =
            |i: usize| self.displacement[i] + self.compliance[i] * self.traction[i] - self.rest[i];
        let size = max(&|i| match attached[i] {
            true => {
                self.product[i].abs()
                    + self.applied[i].abs()
                    + (self.compliance[i] * self.traction[i]).abs()
                    + self.rest[i].abs()
            }
            false => 0.0,
        }) + mean.abs();
        if let Some(i) = (0..n).find(|&i| attached[i] && spring(i).abs() > tolerance * size) {
            return Some(format!(
                "the spring of site {i} is off by {:e} m against a scale of {size:e} m",
                spring(i)
            ));
        }
        let carried = cell * self.traction.iter().sum::<f64>();
        // No net load (the anchors'): against the tractions' own size.
        let load = match self.total {
            0.0 => cell * self.traction.iter().map(|t| t.abs()).sum::<f64>(),
            total => total.abs(),
        };
        if (carried - self.total).abs() > tolerance * load {
            return Some(format!(
                "the tractions carry {carried:e} N, the load is {:e} N",
                self.total
            ));
        }
        None
    }
}
