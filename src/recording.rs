//! What a run records and how it runs beside its three tables ([`RunOptions`]):
//! observers, never part of the physics. They change neither the events nor the scene's
//! identity.

use crate::geometry::Grid;
use crate::probe::ProbeSpec;

/// What a run records beside `events.csv`, `curve.csv` and `contact_map.csv`: the fields
/// for the movies (`fields.csv`) and the interface and stress profiles at requested loads
/// (`profiles.csv`; layouts in the `output` module's docs); and what observes a run
/// without changing its events: the stress probes its driver starts with and the
/// solver's thread count ([`crate::Scene::driver_with`]).
///
/// The setters never fail; the values are checked against the scene when a run starts
/// ([`crate::output::RunTables::create_with`]) or when a scene that carries them is built
/// ([`crate::SceneBuilder::run_options`], the scene file's keys `fields` and `profiles`),
/// each refusal naming its key.
///
/// ```
/// use precursors::RunOptions;
/// let options = RunOptions::new()
///     .record_fields(10, &[0.002])
///     .record_profiles(&[0.5, 0.1, 0.9], &[0.0, 0.002]);
/// assert_eq!(options.fields_every(), 10);
/// assert_eq!(options.profile_loads(), [0.1, 0.5, 0.9]); // in increasing order
/// assert_eq!(options.profile_planes(), [0.0, 0.002]);
/// assert_eq!(RunOptions::default(), RunOptions::new()); // records nothing more
/// assert_eq!(options.probe_spec(), None); // the scene's probes
/// assert_eq!(options.thread_count(), 0); // the scene's thread count
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(from = "RunOptionsFields", into = "RunOptionsFields")
)]
#[non_exhaustive]
pub struct RunOptions {
    pub(crate) fields: FieldRecording,
    pub(crate) profiles: ProfileRecording,
    /// The probes a driver starts with instead of the scene's (`None`: the scene's).
    pub(crate) probes: Option<ProbeSpec>,
    /// The solver's thread count (0: the scene's).
    pub(crate) threads: usize,
    /// The most bytes `fields.csv` and `profiles.csv` may take, estimated before the run.
    pub(crate) max_output_bytes: f64,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            fields: FieldRecording::default(),
            profiles: ProfileRecording::default(),
            probes: None,
            threads: 0,
            max_output_bytes: RunOptions::DEFAULT_MAX_OUTPUT_BYTES,
        }
    }
}

/// The most bytes of a row's leading columns (event, load, field, height) in
/// `fields.csv` and `profiles.csv`.
const ROW_PREFIX_BYTES: f64 = 96.0;
/// The most bytes of a value written with 13 significant digits (`-1.234567890123e-100,`).
const VALUE_BYTES: f64 = 21.0;
/// Memory a planned plane or point keeps, per cell (B), measured with
/// `examples/observer_cost.rs` (docs/performance.md, "Observer costs").
const KERNEL_BYTES_PER_CELL: f64 = 24.0;
/// Time to plan a plane (s, one thread): a part per plane and one per cell, measured
/// likewise.
const PLAN_SECONDS: f64 = 1e-3;
const PLAN_SECONDS_PER_CELL: f64 = 1.5e-6;
/// Time to plan a point, per cell (s, one thread), measured likewise.
const POINT_SECONDS_PER_CELL: f64 = 3e-6;
/// Time to evaluate one plane in one stable state, per cell (s, one thread), measured
/// likewise.
const EVALUATION_SECONDS_PER_CELL: f64 = 2e-7;

/// What recording a run's observers costs ([`RunOptions::cost`]): estimates, for one
/// thread of a release build; `precursors info` prints them.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ObserverCost {
    /// The most bytes `fields.csv` takes (B).
    pub fields_bytes: f64,
    /// The bytes `profiles.csv` takes (B, at most: a load the run never reaches has no
    /// rows).
    pub profiles_bytes: f64,
    /// Memory the planned planes and points keep (B).
    pub memory_bytes: f64,
    /// Time to plan every plane and point (s).
    pub plan_seconds: f64,
    /// The most time to evaluate the recorded planes over the run (s).
    pub record_seconds: f64,
}

impl ObserverCost {
    /// The bytes of `fields.csv` and `profiles.csv` together (B): what
    /// [`RunOptions::max_output_bytes`] bounds.
    pub fn output_bytes(&self) -> f64 {
        self.fields_bytes + self.profiles_bytes
    }
}

/// What a run records of its fields ([`RunOptions::record_fields`]): every `every`-th
/// stable state (0: none), the planes of the Coulomb stress profiles.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct FieldRecording {
    pub(crate) every: usize,
    pub(crate) planes: Vec<f64>,
}

/// The loads and planes of the profiles a run records ([`RunOptions::record_profiles`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct ProfileRecording {
    /// `F/(μF_N)`, increasing, each once.
    pub(crate) loads: Vec<f64>,
    pub(crate) planes: Vec<f64>,
}

impl RunOptions {
    /// The default limit on the bytes of `fields.csv` and `profiles.csv` together, as
    /// [`ObserverCost::output_bytes`] estimates them before a run: 10 GB.
    pub const DEFAULT_MAX_OUTPUT_BYTES: f64 = 1e10;

    /// Records nothing beyond the three tables (the default).
    pub fn new() -> Self {
        Self::default()
    }

    /// Records the fields of the run's stable states for the movies (`precursors movie`,
    /// `crate::plot::Movie`, feature `plot`) into `fields.csv`: at the 1st, the
    /// `(1 + every)`-th, the `(1 + 2·every)`-th, ... stable state, the real contact area
    /// `A_R` of each cell (m²) and the y-averaged Coulomb stress `τ_C(x, z)` (Pa) on each
    /// of `planes` (heights `z` in m above the interface, `0` or within the block's
    /// probe range: docs/scene-format.md). `every = 0` records nothing; `planes` may be
    /// empty (the contact area only). Scene-file key `fields`.
    pub fn record_fields(mut self, every: usize, planes: &[f64]) -> Self {
        self.fields = FieldRecording {
            every,
            planes: planes.to_vec(),
        };
        self
    }

    /// Records profiles along `x`, averaged over `y`, in the stable state in effect at
    /// each of `loads` (`F/(μF_N)`, within `[0, 1]`; kept in increasing order, each once)
    /// into `profiles.csv`: the shear displacement `u_x` of the interface (m) and its
    /// tractions `φ_x`, `φ_z` (Pa), and on each of `planes` (heights `z` in m, as for
    /// [`RunOptions::record_fields`]) the stresses `τ`, `σ` and the Coulomb stresses of
    /// [`crate::Profile`] (Pa). The state in effect at a load is the last stable state
    /// reached at or below it (as in `contact_map.csv`); a load the run never passes has
    /// no row. Empty `loads` record nothing. Scene-file key `profiles`.
    pub fn record_profiles(mut self, loads: &[f64], planes: &[f64]) -> Self {
        let mut loads = loads.to_vec();
        // NaN sorts last and is refused with its key when the options are checked.
        loads.sort_by(f64::total_cmp);
        loads.dedup();
        self.profiles = ProfileRecording {
            loads,
            planes: planes.to_vec(),
        };
        self
    }

    /// The most bytes (B) the recorded tables `fields.csv` and `profiles.csv` may take
    /// together (default [`RunOptions::DEFAULT_MAX_OUTPUT_BYTES`], 10 GB; scene-file key
    /// `max_output_bytes`). A run whose estimate ([`RunOptions::cost`]) is above it is
    /// refused before it starts, with [`crate::Error::OutputTooLarge`]; raise it for a
    /// recording whose size you accept. It does not change results.
    ///
    /// ```
    /// use precursors::{Error, RunOptions, Scene};
    /// // Profiles at 1000 loads on 1000 planes of the calibration block: about 10 GB.
    /// let loads: Vec<f64> = (0..1000).map(|k| k as f64 / 1000.0).collect();
    /// let planes: Vec<f64> = (0..1000).map(|k| 0.010 + 0.060 * k as f64 / 1000.0).collect();
    /// let options = RunOptions::new().record_profiles(&loads, &planes);
    /// let scene = Scene::builder().run_options(options.clone());
    /// assert!(matches!(scene.check(), Err(Error::OutputTooLarge { .. })));
    /// let raised = Scene::builder().run_options(options.max_output_bytes(1e11));
    /// assert!(raised.check().is_ok());
    /// ```
    pub fn max_output_bytes(mut self, bytes: f64) -> Self {
        self.max_output_bytes = bytes;
        self
    }

    /// The limit given with [`RunOptions::max_output_bytes`] (B).
    pub fn output_limit(&self) -> f64 {
        self.max_output_bytes
    }

    /// What recording these options costs on `grid`, with `probes` the probes the run's
    /// driver starts with (its scene's, or [`RunOptions::probes`]): the bytes of
    /// `fields.csv` and `profiles.csv`, the memory and planning time of every plane and
    /// point, and the time to evaluate the recorded planes over the run. Estimates for
    /// one thread of a release build, fitted to `examples/observer_cost.rs`
    /// (docs/performance.md, "Observer costs"); the table sizes are upper bounds: every
    /// site breaks at most once, so a run has at most `N + 1` stable states.
    ///
    /// ```
    /// use precursors::{Grid, Block, ProbeSpec, RunOptions};
    /// let grid = Grid::new(Block::new(0.140, 0.007, 0.075)?, 140, 7)?;
    /// let options = RunOptions::new().record_profiles(&[0.5], &[0.0, 0.01]);
    /// let cost = options.cost(&grid, &ProbeSpec::default());
    /// // 3 interface rows and 4 rows per plane, 140 values each: about 30 kB.
    /// assert!(cost.profiles_bytes > 11.0 * 140.0 * 17.0 && cost.profiles_bytes < 40e3);
    /// assert_eq!(cost.fields_bytes, 0.0);
    /// assert_eq!(cost.output_bytes(), cost.profiles_bytes);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn cost(&self, grid: &Grid, probes: &ProbeSpec) -> ObserverCost {
        let n = grid.len() as f64;
        let row = ROW_PREFIX_BYTES + VALUE_BYTES * grid.nx() as f64;
        let fields = &self.fields;
        let profiles = &self.profiles;
        // Every site breaks once and every avalanche breaks one at least.
        let states = if fields.every == 0 {
            0.0
        } else {
            (grid.len() + 1).div_ceil(fields.every) as f64
        };
        let field_planes = if fields.every == 0 {
            0
        } else {
            fields.planes.len()
        };
        let loads = profiles.loads.len() as f64;
        let profile_planes = if profiles.loads.is_empty() {
            0
        } else {
            profiles.planes.len()
        };
        let probes = self.probes.as_ref().unwrap_or(probes);
        let planes = (field_planes + profile_planes + probes.planes().len()) as f64;
        let points = probes.points().len() as f64; // Profiles evaluate their planes in every stable state until the last load is
                                                   // passed (which state is in effect at a load shows only at the next one).
        let profile_states = if profile_planes == 0 { 0.0 } else { n + 1.0 };
        let evaluations = states * field_planes as f64 + profile_states * profile_planes as f64;
        ObserverCost {
            fields_bytes: states * (grid.ny() + field_planes) as f64 * row,
            profiles_bytes: loads * (3 + 4 * profile_planes) as f64 * row,
            memory_bytes: (planes + points) * KERNEL_BYTES_PER_CELL * n,
            plan_seconds: planes * (PLAN_SECONDS + PLAN_SECONDS_PER_CELL * n)
                + points * POINT_SECONDS_PER_CELL * n,
            record_seconds: evaluations * EVALUATION_SECONDS_PER_CELL * n,
        }
    }

    /// The stress probes (planes and points) a driver of the run starts with, in place of
    /// its scene's ([`crate::SceneBuilder::probes`], scene-file key `probes`): planned
    /// and checked by [`crate::Scene::driver_with`], read with
    /// [`crate::Driver::stresses`]. An empty `ProbeSpec` starts with none. Probes
    /// observe: the events do not depend on them.
    ///
    /// ```
    /// use precursors::{ProbeSpec, RunOptions, Scene};
    /// let scene = Scene::builder().block(0.020, 0.004, 0.010).normal_load(80.0).build()?;
    /// // The scene has no probes; this run's driver starts with a plane at z = 2 mm.
    /// let options = RunOptions::new().probes(ProbeSpec::default().with_plane(2e-3));
    /// assert_eq!(options.probe_spec().map(|spec| spec.planes()), Some(&[2e-3][..]));
    /// let mut driver = scene.driver_with(&options)?;
    /// driver.step()?;                                   // the normal equilibrium
    /// let plane = &driver.stresses()?.planes[0];
    /// // Through the plane the block carries F_N: ∫ σ_zz dA = -80 N.
    /// let force: f64 = plane.normal().iter().sum::<f64>() * scene.grid().cell_area();
    /// assert!((plane.z(), (force + 80.0).abs() < 1e-6 * 80.0) == (2e-3, true));
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn probes(mut self, probes: ProbeSpec) -> Self {
        self.probes = Some(probes);
        self
    }

    /// The number of threads the run's solves use ([`crate::solver::Parallelism`]: `1`
    /// the calling thread only, `n > 1` the calling thread and `n - 1` helpers), in place
    /// of its scene's (the scene file's `solver.threads`); `0`, the default, keeps the
    /// scene's. Applied by [`crate::Scene::driver_with`]. The events are bit for bit the
    /// same for every thread count.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }

    /// The probes given with [`RunOptions::probes`] (`None`: the scene's, the default).
    pub fn probe_spec(&self) -> Option<&ProbeSpec> {
        self.probes.as_ref()
    }

    /// The thread count given with [`RunOptions::threads`] (0: the scene's, the default).
    pub fn thread_count(&self) -> usize {
        self.threads
    }

    /// Every how many stable states the fields are recorded (0: never, the default).
    pub fn fields_every(&self) -> usize {
        self.fields.every
    }

    /// The heights `z` (m) of the planes whose y-averaged Coulomb stress the fields hold.
    pub fn field_planes(&self) -> &[f64] {
        &self.fields.planes
    }

    /// The loads `F/(μF_N)` of the profiles, increasing (empty: none, the default).
    pub fn profile_loads(&self) -> &[f64] {
        &self.profiles.loads
    }

    /// The heights `z` (m) of the planes of the profiles.
    pub fn profile_planes(&self) -> &[f64] {
        &self.profiles.planes
    }
}

/// [`RunOptions`] as serde sees them (feature `serde`): the scene file's `fields` and
/// `profiles` objects (a missing key records nothing), read back through
/// [`RunOptions::record_fields`] and [`RunOptions::record_profiles`] (which sorts the
/// loads and drops repeats); `probes` (a [`ProbeSpec`]) and `threads` (a count) only when
/// given (missing: the scene's), so options written before they existed read the same.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct RunOptionsFields {
    fields: FieldsFields,
    profiles: ProfilesFields,
    #[serde(skip_serializing_if = "Option::is_none")]
    probes: Option<ProbeSpec>,
    #[serde(skip_serializing_if = "is_zero")]
    threads: usize,
    /// Written only when it is not the default.
    #[serde(skip_serializing_if = "is_default_limit", default = "default_limit")]
    max_output_bytes: f64,
}

/// Whether an output limit is the default.
#[cfg(feature = "serde")]
fn is_default_limit(bytes: &f64) -> bool {
    *bytes == RunOptions::DEFAULT_MAX_OUTPUT_BYTES
}

/// The default output limit.
#[cfg(feature = "serde")]
fn default_limit() -> f64 {
    RunOptions::DEFAULT_MAX_OUTPUT_BYTES
}

/// Whether a thread count is the default (the scene's).
#[cfg(feature = "serde")]
fn is_zero(threads: &usize) -> bool {
    *threads == 0
}

/// `fields`: [`FieldRecording`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct FieldsFields {
    every: usize,
    planes: Vec<f64>,
}

/// `profiles`: [`ProfileRecording`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct ProfilesFields {
    loads: Vec<f64>,
    planes: Vec<f64>,
}

#[cfg(feature = "serde")]
impl From<RunOptions> for RunOptionsFields {
    fn from(o: RunOptions) -> Self {
        Self {
            fields: FieldsFields {
                every: o.fields.every,
                planes: o.fields.planes,
            },
            profiles: ProfilesFields {
                loads: o.profiles.loads,
                planes: o.profiles.planes,
            },
            probes: o.probes,
            threads: o.threads,
            max_output_bytes: o.max_output_bytes,
        }
    }
}

#[cfg(feature = "serde")]
impl From<RunOptionsFields> for RunOptions {
    fn from(f: RunOptionsFields) -> Self {
        let options = RunOptions::new()
            .record_fields(f.fields.every, &f.fields.planes)
            .record_profiles(&f.profiles.loads, &f.profiles.planes)
            .threads(f.threads)
            .max_output_bytes(f.max_output_bytes);
        match f.probes {
            Some(probes) => options.probes(probes),
            None => options,
        }
    }
}
