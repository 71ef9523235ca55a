//! What a run records and how it runs beside its three tables ([`RunOptions`]):
//! observers, never part of the physics. They change neither the events nor the scene's
//! identity.

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
#[derive(Debug, Clone, PartialEq, Default)]
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

    /// The stress probes (planes and points) a driver of the run starts with, in place of
    /// its scene's ([`crate::SceneBuilder::probes`], scene-file key `probes`): planned
    /// and checked by [`crate::Scene::driver_with`], read with
    /// [`crate::Driver::stresses`]. An empty `ProbeSpec` starts with none. Probes
    /// observe: the events do not depend on them.
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
        }
    }
}

#[cfg(feature = "serde")]
impl From<RunOptionsFields> for RunOptions {
    fn from(f: RunOptionsFields) -> Self {
        let options = RunOptions::new()
            .record_fields(f.fields.every, &f.fields.planes)
            .record_profiles(&f.profiles.loads, &f.profiles.planes)
            .threads(f.threads);
        match f.probes {
            Some(probes) => options.probes(probes),
            None => options,
        }
    }
}
