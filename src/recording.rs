//! What a run records beside its three tables ([`RunOptions`]): observers, never part of
//! the physics. They change neither the events nor the scene's identity.

/// What a run records beside `events.csv`, `curve.csv` and `contact_map.csv`: the fields
/// for the movies (`fields.csv`) and the interface and stress profiles at requested loads
/// (`profiles.csv`; layouts in the `output` module's docs).
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
/// loads and drops repeats).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct RunOptionsFields {
    fields: FieldsFields,
    profiles: ProfilesFields,
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
        }
    }
}

#[cfg(feature = "serde")]
impl From<RunOptionsFields> for RunOptions {
    fn from(f: RunOptionsFields) -> Self {
        RunOptions::new()
            .record_fields(f.fields.every, &f.fields.planes)
            .record_profiles(&f.profiles.loads, &f.profiles.planes)
    }
}
