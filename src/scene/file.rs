//! The scene file's types (`docs/scene-format.md`): the scene's schema, declared once
//! through [`schema_struct!`] and [`schema_enum!`] (`scene/schema.rs`), and with the
//! `serde` feature the JSON scene format read and written through them.
//!
//! The file's layout is a private mirror of [`SceneBuilder`], so the Rust API and the
//! file format can evolve separately. Every key is optional (the paper's calibration
//! scene fills the gaps) and unknown keys are refused: a misspelt key must not silently
//! fall back to a default.

use super::schema::{schema_enum, schema_leaf, schema_struct, Schema, Walk};
use super::{
    Cells, Drive, ForceLoad, HeightSource, Lateral, SceneBuilder, SiteMap, SiteMaps, MAP_KEYS,
};
use crate::contact::{ContactRule, Delay};
use crate::interface::AreaLaw;
use crate::probe::ProbeSpec;
use crate::solver::{Backend, Parallelism, SolverOptions};
use crate::surface::SurfaceSpectrum;
use std::path::PathBuf;
#[cfg(feature = "serde")]
use {
    super::schema::KeyError,
    crate::error::{Error, Result},
    crate::geometry::Point,
    crate::interface::{HeightDistribution, Material, SpringLaw},
    crate::recording::RunOptions,
    serde::{Deserialize, Serialize},
    std::path::Path,
};

schema_struct! {
    /// A scene file: every key of a scene (`docs/scene-format.md`).
    #[derive(Debug, Clone, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    pub(crate) struct SceneFile {
        block: BlockSpec,
        cells: CellsSpec,
        material: MaterialSpec,
        springs: SpringsSpec,
        heights: HeightsSpec,
        /// Written only when the scene has a map, so files (and the checkpoints'
        /// identities) of other scenes stay as they were.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "MapsSpec::is_empty"))]
        maps: MapsSpec,
        normal_load: f64,
        drive: DriveSpec,
        solver: SolverSpec,
        plan_tolerance: f64,
        /// Written only when it is not the paper's rule, so files (and the checkpoints'
        /// identities) of other scenes stay as they were.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "ContactSpec::is_paper"))]
        contact: ContactSpec,
        // The observers (`[observer]`: not in the identity) are the run options' keys
        // (`RunOptions`), which 1.x scene files keep carrying.
        [observer] probes: ProbesSpec,
        /// Written only when it is not the default, so files of scenes within the default
        /// limit stay as they were.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "is_default_max_cells"))]
        [observer] max_cells: usize,
        /// Written only when fields are recorded, so files of other scenes stay as they
        /// were.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "FieldsSpec::is_off"))]
        [observer] fields: FieldsSpec,
        /// Written only when profiles are recorded.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "ProfilesSpec::is_off"))]
        [observer] profiles: ProfilesSpec,
        /// Written only when true (a block of a metre or more meant so), so files of
        /// other scenes stay as they were.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "is_false"))]
        [observer] confirm_metres: bool,
        /// Written only when it is not the default.
        #[cfg_attr(feature = "serde", serde(skip_serializing_if = "is_default_max_output_bytes"))]
        [observer] max_output_bytes: f64,
    }
}

/// `contact`: the rule of the site transitions (`docs/scene-format.md`). The paper's
/// rule is the default and leaves no key, in the file or in a checkpoint's identity
/// (every 1.x checkpoint's digest has none).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
struct ContactSpec {
    rule: RuleSpec,
    /// Only for the rule `rejuvenation`.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    delay: Option<DelaySpec>,
}

/// `contact.rule`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
enum RuleSpec {
    #[default]
    Paper,
    Anchored,
    Rejuvenation,
    /// A custom rule ([`ContactRule::Custom`]): in a scene's identity, never in a file
    /// (writing it is an error, reading it an unknown value).
    #[cfg_attr(feature = "serde", serde(skip))]
    Custom,
}

/// `contact.delay`: both must pass before a broken site re-forms.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
struct DelaySpec {
    stable_states: u64,
    load: f64,
}

impl Default for DelaySpec {
    fn default() -> Self {
        let delay = Delay::default();
        Self {
            stable_states: delay.stable_states,
            load: delay.load,
        }
    }
}

impl ContactSpec {
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    fn is_paper(&self) -> bool {
        *self == ContactSpec::default()
    }

    /// The rule; a delay given to a rule that does not re-form is refused.
    #[cfg(feature = "serde")]
    fn into_rule(self) -> Result<ContactRule> {
        Ok(match (self.rule, self.delay) {
            (RuleSpec::Paper, None) => ContactRule::Paper,
            (RuleSpec::Anchored, None) => ContactRule::Anchored,
            (RuleSpec::Rejuvenation, delay) => {
                let delay = delay.unwrap_or_default();
                ContactRule::Rejuvenation {
                    delay: Delay {
                        stable_states: delay.stable_states,
                        load: delay.load,
                    },
                }
            }
            (RuleSpec::Custom, _) => {
                return Err(Error::InvalidChoice {
                    name: "contact.rule",
                    value: "custom",
                    reason: "a custom rule is Rust code (ContactRule::custom), not a scene-file \
                             value",
                })
            }
            (rule, Some(_)) => {
                return Err(Error::InvalidChoice {
                    name: "contact.delay",
                    value: match rule {
                        RuleSpec::Paper => "paper",
                        _ => "anchored",
                    },
                    reason: "only the rule \"rejuvenation\" re-forms broken sites and takes a \
                             delay",
                })
            }
        })
    }
}

impl From<&ContactRule> for ContactSpec {
    fn from(rule: &ContactRule) -> Self {
        match rule {
            ContactRule::Paper => ContactSpec::default(),
            ContactRule::Anchored => ContactSpec {
                rule: RuleSpec::Anchored,
                delay: None,
            },
            ContactRule::Rejuvenation { delay } => ContactSpec {
                rule: RuleSpec::Rejuvenation,
                delay: Some(DelaySpec {
                    stable_states: delay.stable_states,
                    load: delay.load,
                }),
            },
            // Its identity names it a custom rule; writing it is refused
            // (`ContactRule::built_in`).
            ContactRule::Custom(_) => ContactSpec {
                rule: RuleSpec::Custom,
                delay: None,
            },
        }
    }
}

impl Schema for ContactSpec {
    /// No key for the paper's rule (the default): 1.x identities have none.
    fn keys(&self, path: &str, walk: Walk, out: &mut Vec<(String, String)>) {
        use super::schema::join;
        if self.is_paper() {
            return;
        }
        let rule = match self.rule {
            RuleSpec::Paper => "paper",
            RuleSpec::Anchored => "anchored",
            RuleSpec::Rejuvenation => "rejuvenation",
            RuleSpec::Custom => "custom",
        };
        out.push((join(path, "rule"), rule.to_string()));
        if let Some(delay) = &self.delay {
            let at = join(path, "delay");
            delay
                .stable_states
                .keys(&join(&at, "stable_states"), walk, out);
            delay.load.keys(&join(&at, "load"), walk, out);
        }
    }

    #[cfg(feature = "serde")]
    fn set(&mut self, at: &str, rest: &[&str], value: &serde_json::Value) -> Result<(), KeyError> {
        use super::schema::{join, replace};
        match rest {
            [] => replace(self, value),
            ["rule"] => replace(&mut self.rule, value),
            ["delay"] => replace(&mut self.delay, value),
            ["delay", "stable_states"] => {
                replace(&mut self.delay.get_or_insert_default().stable_states, value)
            }
            ["delay", "load"] => replace(&mut self.delay.get_or_insert_default().load, value),
            ["delay", segment, ..] => Err(KeyError::not_a_key(
                &join(at, "delay"),
                segment,
                &["stable_states", "load"],
            )),
            [segment, ..] => Err(KeyError::not_a_key(at, segment, &["rule", "delay"])),
        }
    }

    #[cfg(feature = "serde")]
    fn object_at(rest: &[&str]) -> bool {
        matches!(rest, [] | ["delay"])
    }
}

/// `maps`: per-site values in place of the scalars `material.friction_coefficient`,
/// `springs.c_x`, `springs.c_z` (`docs/scene-format.md`). A scene without maps leaves no
/// key, in the file or in a checkpoint's identity (every 1.x checkpoint's digest has none).
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
struct MapsSpec {
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    friction_coefficient: Option<MapSpec>,
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    c_x: Option<MapSpec>,
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    c_z: Option<MapSpec>,
}

schema_enum! {
    /// `maps.KEY`: where a map's values come from.
    #[derive(Debug, Clone, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(tag = "kind", deny_unknown_fields))]
    // Map files are read by the file format only (feature `serde`).
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub(super) enum MapSpec {
        Values = "values" {
            values: Vec<f64>,
        },
        File = "file" {
            path: PathBuf,
        },
        GaussianSurface = "gaussian_surface" {
            correlation_length: f64,
            mean: f64,
            std_dev: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_seed"))]
            seed: u64,
        },
        SelfAffineSurface = "self_affine_surface" {
            hurst: f64,
            roll_off: f64,
            short_cutoff: f64,
            long_cutoff: f64,
            mean: f64,
            std_dev: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_seed"))]
            seed: u64,
        },
    }
}

impl MapsSpec {
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    fn is_empty(&self) -> bool {
        *self == MapsSpec::default()
    }

    /// The maps in the order of [`MAP_KEYS`].
    fn fields(&self) -> [&Option<MapSpec>; 3] {
        [&self.friction_coefficient, &self.c_x, &self.c_z]
    }

    #[cfg(feature = "serde")]
    fn field_mut(&mut self, name: &str) -> Option<&mut Option<MapSpec>> {
        match name {
            "friction_coefficient" => Some(&mut self.friction_coefficient),
            "c_x" => Some(&mut self.c_x),
            "c_z" => Some(&mut self.c_z),
            _ => None,
        }
    }

    /// The maps; a map file is read relative to `base`, bounded by `grid_cells` (asked
    /// only for a file).
    #[cfg(feature = "serde")]
    fn into_maps(self, base: &Path, grid_cells: impl Fn() -> Option<usize>) -> Result<SiteMaps> {
        let mut maps = SiteMaps::default();
        for (k, spec) in [self.friction_coefficient, self.c_x, self.c_z]
            .into_iter()
            .enumerate()
        {
            maps.0[k] = match spec {
                None => None,
                Some(spec) => Some(spec.into_map(k, base, &grid_cells)?),
            };
        }
        Ok(maps)
    }
}

#[cfg(feature = "serde")]
impl MapSpec {
    /// The map of the key `MAP_KEYS[k]`.
    fn into_map(
        self,
        k: usize,
        base: &Path,
        grid_cells: &impl Fn() -> Option<usize>,
    ) -> Result<SiteMap> {
        Ok(match self {
            MapSpec::Values { values } => SiteMap::Values(values),
            MapSpec::File { path } => {
                const KEYS: [&str; 3] = ["maps.friction_coefficient", "maps.c_x", "maps.c_z"];
                let (min, max, unit) = super::bounds::map_range(k);
                SiteMap::read_file(&base.join(path), grid_cells(), KEYS[k], (min, max), unit)?
            }
            MapSpec::GaussianSurface {
                correlation_length,
                mean,
                std_dev,
                seed,
            } => SiteMap::Surface {
                spectrum: SurfaceSpectrum::gaussian(correlation_length)?,
                mean,
                std_dev,
                seed,
            },
            MapSpec::SelfAffineSurface {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
                mean,
                std_dev,
                seed,
            } => SiteMap::Surface {
                spectrum: SurfaceSpectrum::self_affine(hurst, roll_off, short_cutoff, long_cutoff)?,
                mean,
                std_dev,
                seed,
            },
        })
    }
}

impl From<&SiteMap> for MapSpec {
    fn from(map: &SiteMap) -> Self {
        match map {
            SiteMap::Values(values) => MapSpec::Values {
                values: values.clone(),
            },
            SiteMap::Surface {
                spectrum,
                mean,
                std_dev,
                seed,
            } => match *spectrum {
                SurfaceSpectrum::Gaussian { correlation_length } => MapSpec::GaussianSurface {
                    correlation_length,
                    mean: *mean,
                    std_dev: *std_dev,
                    seed: *seed,
                },
                SurfaceSpectrum::SelfAffine {
                    hurst,
                    roll_off,
                    short_cutoff,
                    long_cutoff,
                } => MapSpec::SelfAffineSurface {
                    hurst,
                    roll_off,
                    short_cutoff,
                    long_cutoff,
                    mean: *mean,
                    std_dev: *std_dev,
                    seed: *seed,
                },
            },
        }
    }
}

impl From<SiteMap> for MapSpec {
    fn from(map: SiteMap) -> Self {
        MapSpec::from(&map)
    }
}

#[cfg(feature = "serde")]
impl TryFrom<MapSpec> for SiteMap {
    type Error = Error;

    /// A map as serde reads it: the scene file's kinds but `file` (a map holds values,
    /// not a path).
    fn try_from(spec: MapSpec) -> Result<Self> {
        if let MapSpec::File { .. } = spec {
            return Err(Error::InvalidChoice {
                name: "kind",
                value: "file",
                reason: "a map holds its values, not a path: read the file with \
                         SiteMap::from_file",
            });
        }
        spec.into_map(0, Path::new("."), &|| None)
    }
}

impl From<&SiteMaps> for MapsSpec {
    fn from(maps: &SiteMaps) -> Self {
        let [friction_coefficient, c_x, c_z] = &maps.0;
        MapsSpec {
            friction_coefficient: friction_coefficient.as_ref().map(MapSpec::from),
            c_x: c_x.as_ref().map(MapSpec::from),
            c_z: c_z.as_ref().map(MapSpec::from),
        }
    }
}

impl Schema for MapsSpec {
    /// The keys of the maps given; none without maps (1.x identities have none).
    fn keys(&self, path: &str, walk: Walk, out: &mut Vec<(String, String)>) {
        use super::schema::join;
        for (name, map) in MAP_KEYS.iter().zip(self.fields()) {
            if let Some(map) = map {
                map.keys(&join(path, name), walk, out);
            }
        }
    }

    #[cfg(feature = "serde")]
    fn set(&mut self, at: &str, rest: &[&str], value: &serde_json::Value) -> Result<(), KeyError> {
        use super::schema::{join, replace};
        match rest {
            [] => replace(self, value),
            [name, rest @ ..] => {
                let Some(field) = self.field_mut(name) else {
                    return Err(KeyError::not_a_key(at, name, &MAP_KEYS));
                };
                let here = join(at, name);
                match (rest, field) {
                    ([], field) => replace(field, value),
                    ([segment, ..], None) => Err(KeyError::NotAnObject {
                        at: here,
                        segment: segment.to_string(),
                    }),
                    (rest, Some(map)) => map.set(&here, rest, value),
                }
            }
        }
    }

    #[cfg(feature = "serde")]
    fn object_at(rest: &[&str]) -> bool {
        match rest {
            [] => true,
            [name, rest @ ..] => MAP_KEYS.contains(name) && MapSpec::object_at(rest),
        }
    }
}

schema_struct! {
    /// `fields`: what a run records for the movies (`RunOptions::record_fields`).
    #[derive(Debug, Clone, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    struct FieldsSpec {
        every: usize,
        planes: Vec<f64>,
    }
}

#[cfg(feature = "serde")]
impl FieldsSpec {
    fn is_off(&self) -> bool {
        self.every == 0 && self.planes.is_empty()
    }
}

schema_struct! {
    /// `profiles`: the profiles a run records at given loads (`RunOptions::record_profiles`).
    #[derive(Debug, Clone, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    struct ProfilesSpec {
        loads: Vec<f64>,
        planes: Vec<f64>,
    }
}

#[cfg(feature = "serde")]
impl ProfilesSpec {
    fn is_off(&self) -> bool {
        self.loads.is_empty() && self.planes.is_empty()
    }
}

#[cfg(feature = "serde")]
fn is_false(value: &bool) -> bool {
    !*value
}

#[cfg(feature = "serde")]
fn is_default_max_output_bytes(bytes: &f64) -> bool {
    *bytes == RunOptions::DEFAULT_MAX_OUTPUT_BYTES
}

#[cfg(feature = "serde")]
fn is_default_max_cells(max_cells: &usize) -> bool {
    *max_cells == crate::green::DEFAULT_MAX_CELLS
}

schema_struct! {
    #[derive(Debug, Clone, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    struct ProbesSpec {
        planes: Vec<f64>,
        points: Vec<[f64; 3]>,
        tolerance: f64,
    }
}

schema_struct! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
    struct BlockSpec {
        lx: f64,
        ly: f64,
        lz: f64,
    }
}

schema_enum! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(tag = "kind", deny_unknown_fields))]
    enum CellsSpec {
        Size = "size" { dx: f64, dy: f64 },
        Count = "count" { nx: usize, ny: usize },
    }
}

schema_struct! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    struct MaterialSpec {
        young_modulus: f64,
        poisson_ratio: f64,
        friction_coefficient: f64,
    }
}

schema_struct! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    struct SpringsSpec {
        c_x: f64,
        c_z: f64,
        area_law: AreaLaw,
    }
}

schema_enum! {
    #[derive(Debug, Clone, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(tag = "kind", deny_unknown_fields))]
    // Heights files are read by the file format only (feature `serde`).
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    enum HeightsSpec {
        Gaussian = "gaussian" {
            #[cfg_attr(feature = "serde", serde(default = "default_mean"))]
            mean: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_std_dev"))]
            std_dev: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_seed"))]
            seed: u64,
        },
        Values = "values" {
            values: Vec<f64>,
        },
        File = "file" {
            path: PathBuf,
        },
        GaussianSurface = "gaussian_surface" {
            correlation_length: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_mean"))]
            mean: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_std_dev"))]
            std_dev: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_seed"))]
            seed: u64,
        },
        SelfAffineSurface = "self_affine_surface" {
            hurst: f64,
            roll_off: f64,
            short_cutoff: f64,
            long_cutoff: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_mean"))]
            mean: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_std_dev"))]
            std_dev: f64,
            #[cfg_attr(feature = "serde", serde(default = "default_seed"))]
            seed: u64,
        },
    }
}

schema_enum! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(tag = "kind", deny_unknown_fields))]
    enum LateralSpec {
        Rod = "rod" { height: f64, half_width: f64 },
        Side = "side" {},
    }
}

schema_enum! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(tag = "kind", deny_unknown_fields))]
    enum DriveSpec {
        Top = "top" {},
        Rod = "rod" {
            height: f64,
            half_width: f64,
        },
        Side = "side" {},
        Mixed = "mixed" {
            ratio: f64,
            lateral: LateralSpec,
        },
        Spring = "spring" {
            stiffness: f64,
            lateral: LateralSpec,
        },
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
enum BackendSpec {
    Auto,
    Dense,
    Spectral,
    Cuda,
}

// The identity names the rule, not the device: `cuda` solves the `spectral` rule (the
// same events within the solver tolerance), so a checkpoint resumes across the two.
schema_leaf!(BackendSpec, walk |v: &BackendSpec, walk: Walk| match (v, walk) {
    (BackendSpec::Cuda, Walk::Identity) => "spectral".to_string(),
    _ => format!("{v:?}").to_lowercase(),
});

schema_struct! {
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
    #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
    struct SolverSpec {
        backend: BackendSpec,
        tolerance: f64,
        max_active_set_iterations: usize,
        max_linear_iterations: usize,
        [observer] threads: ThreadsSpec,
    }
}

/// `solver.threads`: a count (`1`: the calling thread only; `0`: every core), `"all"`
/// (every core) or `"current"` (the caller's rayon pool).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
enum ThreadsSpec {
    Count(usize),
    Name(ThreadsName),
}

// By hand, not `untagged`: serde's untagged enums fail with "data did not match any
// variant of untagged enum ThreadsSpec", which names a Rust type and not what is valid.
#[cfg(feature = "serde")]
impl<'de> Deserialize<'de> for ThreadsSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Unexpected;
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = ThreadsSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(
                    "solver.threads as a whole number (0: one thread per core, 1: the calling \
                     thread only), \"all\" or \"current\"",
                )
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<ThreadsSpec, E> {
                usize::try_from(v)
                    .map(ThreadsSpec::Count)
                    .map_err(|_| E::invalid_value(Unexpected::Unsigned(v), &self))
            }
            fn visit_str<E: serde::de::Error>(
                self,
                v: &str,
            ) -> std::result::Result<ThreadsSpec, E> {
                match v {
                    "all" => Ok(ThreadsSpec::Name(ThreadsName::All)),
                    "current" => Ok(ThreadsSpec::Name(ThreadsName::Current)),
                    _ => Err(E::invalid_value(Unexpected::Str(v), &self)),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

schema_leaf!(ThreadsSpec, |v| match v {
    ThreadsSpec::Count(n) => format!("{n}"),
    ThreadsSpec::Name(name) => format!("{name:?}").to_lowercase(),
});

#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
enum ThreadsName {
    All,
    Current,
}

impl From<Parallelism> for ThreadsSpec {
    fn from(p: Parallelism) -> Self {
        match p {
            Parallelism::Threads(n) => ThreadsSpec::Count(n),
            Parallelism::CurrentPool => ThreadsSpec::Name(ThreadsName::Current),
            _ => ThreadsSpec::Count(1),
        }
    }
}

impl From<ThreadsSpec> for Parallelism {
    fn from(t: ThreadsSpec) -> Self {
        match t {
            ThreadsSpec::Count(n) => Parallelism::from_count(n),
            ThreadsSpec::Name(ThreadsName::All) => Parallelism::all_cores(),
            ThreadsSpec::Name(ThreadsName::Current) => Parallelism::CurrentPool,
        }
    }
}

#[cfg(feature = "serde")]
fn default_mean() -> f64 {
    HeightDistribution::default().mean()
}

#[cfg(feature = "serde")]
fn default_std_dev() -> f64 {
    HeightDistribution::default().std_dev()
}

#[cfg(feature = "serde")]
fn default_seed() -> u64 {
    crate::scene::DEFAULT_SEED
}

impl Default for SceneFile {
    fn default() -> Self {
        Self::from(&SceneBuilder::default())
    }
}

macro_rules! default_from_builder {
    ($spec:ty, $field:ident) => {
        impl Default for $spec {
            fn default() -> Self {
                SceneFile::from(&SceneBuilder::default()).$field
            }
        }
    };
}
default_from_builder!(MaterialSpec, material);
default_from_builder!(SpringsSpec, springs);
default_from_builder!(SolverSpec, solver);
default_from_builder!(ProbesSpec, probes);
default_from_builder!(FieldsSpec, fields);
default_from_builder!(ProfilesSpec, profiles);

impl From<Lateral> for LateralSpec {
    fn from(l: Lateral) -> Self {
        match l {
            Lateral::Rod { height, half_width } => LateralSpec::Rod { height, half_width },
            Lateral::Side => LateralSpec::Side {},
        }
    }
}

#[cfg(feature = "serde")]
impl From<LateralSpec> for Lateral {
    fn from(l: LateralSpec) -> Self {
        match l {
            LateralSpec::Rod { height, half_width } => Lateral::Rod { height, half_width },
            LateralSpec::Side {} => Lateral::Side,
        }
    }
}

impl From<Drive> for DriveSpec {
    fn from(drive: Drive) -> Self {
        match drive {
            Drive::Force(ForceLoad::Top) => DriveSpec::Top {},
            Drive::Force(ForceLoad::Lateral(Lateral::Rod { height, half_width })) => {
                DriveSpec::Rod { height, half_width }
            }
            Drive::Force(ForceLoad::Lateral(Lateral::Side)) => DriveSpec::Side {},
            Drive::Force(ForceLoad::Mixed { ratio, lateral }) => DriveSpec::Mixed {
                ratio,
                lateral: lateral.into(),
            },
            Drive::Spring { stiffness, lateral } => DriveSpec::Spring {
                stiffness,
                lateral: lateral.into(),
            },
        }
    }
}

#[cfg(feature = "serde")]
impl From<DriveSpec> for Drive {
    fn from(drive: DriveSpec) -> Self {
        match drive {
            DriveSpec::Top {} => Drive::Force(ForceLoad::Top),
            DriveSpec::Rod { height, half_width } => {
                Drive::Force(ForceLoad::Lateral(Lateral::Rod { height, half_width }))
            }
            DriveSpec::Side {} => Drive::Force(ForceLoad::Lateral(Lateral::Side)),
            DriveSpec::Mixed { ratio, lateral } => Drive::Force(ForceLoad::Mixed {
                ratio,
                lateral: lateral.into(),
            }),
            DriveSpec::Spring { stiffness, lateral } => Drive::Spring {
                stiffness,
                lateral: lateral.into(),
            },
        }
    }
}

impl From<Cells> for CellsSpec {
    fn from(cells: Cells) -> Self {
        match cells {
            Cells::Size(dx, dy) => CellsSpec::Size { dx, dy },
            Cells::Count(nx, ny) => CellsSpec::Count { nx, ny },
        }
    }
}

#[cfg(feature = "serde")]
impl From<CellsSpec> for Cells {
    fn from(cells: CellsSpec) -> Self {
        match cells {
            CellsSpec::Size { dx, dy } => Cells::Size(dx, dy),
            CellsSpec::Count { nx, ny } => Cells::Count(nx, ny),
        }
    }
}

impl From<&HeightSource> for HeightsSpec {
    fn from(heights: &HeightSource) -> Self {
        match heights {
            HeightSource::Random { distribution, seed } => HeightsSpec::Gaussian {
                mean: distribution.mean(),
                std_dev: distribution.std_dev(),
                seed: *seed,
            },
            HeightSource::Values(values) => HeightsSpec::Values {
                values: values.clone(),
            },
            HeightSource::Surface {
                spectrum,
                distribution,
                seed,
            } => match *spectrum {
                SurfaceSpectrum::Gaussian { correlation_length } => HeightsSpec::GaussianSurface {
                    correlation_length,
                    mean: distribution.mean(),
                    std_dev: distribution.std_dev(),
                    seed: *seed,
                },
                SurfaceSpectrum::SelfAffine {
                    hurst,
                    roll_off,
                    short_cutoff,
                    long_cutoff,
                } => HeightsSpec::SelfAffineSurface {
                    hurst,
                    roll_off,
                    short_cutoff,
                    long_cutoff,
                    mean: distribution.mean(),
                    std_dev: distribution.std_dev(),
                    seed: *seed,
                },
            },
        }
    }
}

impl From<&SolverOptions> for SolverSpec {
    fn from(solver: &SolverOptions) -> Self {
        SolverSpec {
            backend: match solver.backend() {
                Backend::Dense => BackendSpec::Dense,
                Backend::Spectral => BackendSpec::Spectral,
                Backend::Cuda => BackendSpec::Cuda,
                _ => BackendSpec::Auto,
            },
            tolerance: solver.tolerance(),
            max_active_set_iterations: solver.max_active_set_iterations(),
            max_linear_iterations: solver.max_linear_iterations(),
            threads: solver.parallelism().into(),
        }
    }
}

impl From<&ProbeSpec> for ProbesSpec {
    fn from(probes: &ProbeSpec) -> Self {
        ProbesSpec {
            planes: probes.planes().to_vec(),
            points: probes.points().iter().map(|p| [p.x, p.y, p.z]).collect(),
            tolerance: probes.tolerance(),
        }
    }
}

impl From<&SceneBuilder> for SceneFile {
    fn from(b: &SceneBuilder) -> Self {
        // Every field of the builder, by name: a field added to the builder and not to
        // the file does not compile.
        let SceneBuilder {
            lengths: (lx, ly, lz),
            cells,
            material,
            law,
            heights,
            seed: _,
            normal_load,
            drive,
            solver,
            plan_tolerance,
            probes,
            max_cells,
            run,
            confirm_metres,
            contact,
            maps,
        } = b;
        SceneFile {
            block: BlockSpec {
                lx: *lx,
                ly: *ly,
                lz: *lz,
            },
            cells: (*cells).into(),
            material: MaterialSpec {
                young_modulus: material.young_modulus(),
                poisson_ratio: material.poisson_ratio(),
                friction_coefficient: material.friction_coefficient(),
            },
            springs: SpringsSpec {
                c_x: law.c_x(),
                c_z: law.c_z(),
                area_law: law.area_law(),
            },
            heights: heights.into(),
            maps: maps.into(),
            normal_load: *normal_load,
            drive: (*drive).into(),
            // The run options' probes and threads, where given, are those the scene's
            // drivers use: the file's keys for them.
            solver: SolverSpec {
                threads: match run.thread_count() {
                    0 => solver.parallelism().into(),
                    n => Parallelism::Threads(n).into(),
                },
                ..solver.into()
            },
            plan_tolerance: *plan_tolerance,
            probes: run.probe_spec().unwrap_or(probes).into(),
            max_cells: *max_cells,
            fields: FieldsSpec {
                every: run.fields_every(),
                planes: run.field_planes().to_vec(),
            },
            profiles: ProfilesSpec {
                loads: run.profile_loads().to_vec(),
                planes: run.profile_planes().to_vec(),
            },
            confirm_metres: *confirm_metres,
            max_output_bytes: run.output_limit(),
            contact: contact.into(),
        }
    }
}

#[cfg(feature = "serde")]
impl HeightsSpec {
    /// The height source; a heights file is read relative to `base`, bounded by
    /// `grid_cells` (asked only for a file).
    fn into_source(
        self,
        base: &Path,
        grid_cells: impl FnOnce() -> Option<usize>,
    ) -> Result<HeightSource> {
        Ok(match self {
            HeightsSpec::Gaussian {
                mean,
                std_dev,
                seed,
            } => HeightSource::Random {
                distribution: HeightDistribution::new(mean, std_dev)?,
                seed,
            },
            HeightsSpec::Values { values } => HeightSource::Values(values),
            HeightsSpec::GaussianSurface {
                correlation_length,
                mean,
                std_dev,
                seed,
            } => HeightSource::Surface {
                spectrum: SurfaceSpectrum::gaussian(correlation_length)?,
                distribution: HeightDistribution::new(mean, std_dev)?,
                seed,
            },
            HeightsSpec::SelfAffineSurface {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
                mean,
                std_dev,
                seed,
            } => HeightSource::Surface {
                spectrum: SurfaceSpectrum::self_affine(hurst, roll_off, short_cutoff, long_cutoff)?,
                distribution: HeightDistribution::new(mean, std_dev)?,
                seed,
            },
            HeightsSpec::File { path } => HeightSource::read_file(&base.join(path), grid_cells())?,
        })
    }
}

#[cfg(feature = "serde")]
impl SolverSpec {
    /// The solver's options; iteration counts out of range name their key (a count of 0
    /// included).
    fn into_options(self) -> Result<SolverOptions> {
        super::bounds::solver_iterations(
            self.max_active_set_iterations,
            self.max_linear_iterations,
        )?;
        SolverOptions::default()
            .with_parallelism(self.threads.into())?
            .with_backend(match self.backend {
                BackendSpec::Auto => Backend::Auto,
                BackendSpec::Dense => Backend::Dense,
                BackendSpec::Spectral => Backend::Spectral,
                BackendSpec::Cuda => Backend::Cuda,
            })?
            .with_tolerance(self.tolerance)?
            .with_max_active_set_iterations(self.max_active_set_iterations)?
            .with_max_linear_iterations(self.max_linear_iterations)
    }
}

#[cfg(feature = "serde")]
impl ProbesSpec {
    fn to_spec(&self) -> Result<ProbeSpec> {
        let probes = self.planes.iter().fold(
            ProbeSpec::default().with_tolerance(self.tolerance)?,
            |spec, &z| spec.with_plane(z),
        );
        Ok(self.points.iter().fold(probes, |spec, [x, y, z]| {
            spec.with_point(Point::new(*x, *y, *z))
        }))
    }
}

#[cfg(feature = "serde")]
impl SceneFile {
    /// The builder; a heights file is read relative to `base`.
    fn into_builder(self, base: &Path) -> Result<SceneBuilder> {
        let SceneFile {
            block,
            cells,
            material,
            springs,
            heights,
            maps,
            normal_load,
            drive,
            solver,
            plan_tolerance,
            probes,
            max_cells,
            fields,
            profiles,
            confirm_metres,
            max_output_bytes,
            contact,
        } = self;
        let material = Material::new(
            material.young_modulus,
            material.poisson_ratio,
            material.friction_coefficient,
        )?;
        let law = SpringLaw::new(springs.c_x, springs.c_z)?.with_area_law(springs.area_law);
        let heights = heights.into_source(base, || grid_cells(block, cells, max_cells))?;
        let maps = maps.into_maps(base, || grid_cells(block, cells, max_cells))?;
        let solver = solver.into_options()?;
        let probes = probes.to_spec()?;
        Ok(SceneBuilder {
            lengths: (block.lx, block.ly, block.lz),
            cells: cells.into(),
            material,
            law,
            heights,
            seed: None,
            normal_load,
            drive: drive.into(),
            solver,
            plan_tolerance,
            probes,
            max_cells,
            run: RunOptions::new()
                .record_fields(fields.every, &fields.planes)
                .record_profiles(&profiles.loads, &profiles.planes)
                .max_output_bytes(max_output_bytes),
            confirm_metres,
            contact: Default::default(),
            maps,
        }
        .contact_rule(contact.into_rule()?))
    }
}

/// The grid's cell count, which bounds a heights file before it is read (`None` when the
/// grid is not valid: then the memory available bounds it).
#[cfg(feature = "serde")]
fn grid_cells(block: BlockSpec, cells: CellsSpec, max_cells: usize) -> Option<usize> {
    let builder = SceneBuilder::default()
        .block(block.lx, block.ly, block.lz)
        .max_cells(max_cells);
    let builder = match cells {
        CellsSpec::Size { dx, dy } => builder.cell_size(dx, dy),
        CellsSpec::Count { nx, ny } => builder.cells(nx, ny),
    };
    builder.grid().ok().map(|g| g.len())
}

/// What the format has at a key path: an object (serde would also take an array, its
/// fields by position, which the format does not document: refused), an array of
/// objects, or anything (checked by the format's types).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg(feature = "serde")]
pub(crate) enum Shape {
    Object,
    Objects,
    Any,
}

/// The shape of a scene file's key path (dotted, `""` for the top level), from the
/// schema ([`object_at`]).
#[cfg(feature = "serde")]
pub(crate) fn scene_shape(path: &str) -> Shape {
    if object_at(path) {
        Shape::Object
    } else {
        Shape::Any
    }
}

/// A walk of a JSON document that checks the objects of `shape` (no allocation beyond the
/// keys: the values are skipped).
#[cfg(feature = "serde")]
pub(crate) struct Shaped<'a> {
    pub(crate) path: String,
    pub(crate) shape: &'a dyn Fn(&str) -> Shape,
}

#[cfg(feature = "serde")]
impl<'de> serde::de::DeserializeSeed<'de> for Shaped<'_> {
    type Value = ();

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> std::result::Result<(), D::Error> {
        match (self.shape)(&self.path) {
            Shape::Object => d.deserialize_map(self),
            Shape::Objects => d.deserialize_seq(self),
            Shape::Any => d.deserialize_ignored_any(serde::de::IgnoredAny).map(|_| ()),
        }
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::de::Visitor<'de> for Shaped<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let place = if self.path.is_empty() {
            "the top level".to_string()
        } else {
            format!("`{}`", self.path.replace(".#", "[]"))
        };
        match (self.shape)(&self.path) {
            Shape::Objects => write!(f, "an array of objects at {place}"),
            _ => write!(
                f,
                "an object {{\"key\": value, ...}} at {place} (the format has no positional \
                 arrays)"
            ),
        }
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<(), A::Error> {
        while let Some(key) = map.next_key::<String>()? {
            let path = if self.path.is_empty() {
                key
            } else {
                format!("{}.{key}", self.path)
            };
            map.next_value_seed(Shaped {
                path,
                shape: self.shape,
            })?;
        }
        Ok(())
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(
        self,
        mut seq: A,
    ) -> std::result::Result<(), A::Error> {
        if (self.shape)(&self.path) != Shape::Objects {
            return Err(serde::de::Error::invalid_type(
                serde::de::Unexpected::Seq,
                &self,
            ));
        }
        let path = format!("{}.#", self.path);
        while seq
            .next_element_seed(Shaped {
                path: path.clone(),
                shape: self.shape,
            })?
            .is_some()
        {}
        Ok(())
    }
}

/// Checks the objects of `text` against `shape` (as [`Shaped`]).
#[cfg(feature = "serde")]
pub(crate) fn check_shape(text: &str, shape: &dyn Fn(&str) -> Shape) -> serde_json::Result<()> {
    use serde::de::DeserializeSeed;
    let mut d = serde_json::Deserializer::from_str(text);
    Shaped {
        path: String::new(),
        shape,
    }
    .deserialize(&mut d)?;
    d.end()
}

/// Checks the objects of a scene-file JSON value at the key path `path` ([`scene_shape`]).
#[cfg(feature = "serde")]
fn check_value_shape(path: &str, value: &serde_json::Value) -> Result<(), KeyError> {
    use serde::de::DeserializeSeed;
    Ok(Shaped {
        path: path.to_string(),
        shape: &scene_shape,
    }
    .deserialize(value)?)
}

/// The text of a JSON file (`what`: `"scene file"`, `"sweep file"`): its size checked
/// against the memory available before it is read (parsed, it takes up to about five
/// times its size), and its bytes checked to be UTF-8 (a byte that is not is an error of
/// the file's content, at its line and column, not of reading it: `content_error`).
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::OutOfMemory`]; `content_error`'s
/// error for bytes that are not UTF-8.
#[cfg(feature = "serde")]
pub(crate) fn read_json_text<E: From<Error>>(
    path: &Path,
    operation: &'static str,
    content_error: impl FnOnce(usize, usize, String) -> E,
) -> Result<String, E> {
    let mut bytes = crate::files::read_bytes(path, operation)?;
    // A UTF-8 byte order mark (editors on Windows write one) is not JSON, and serde_json
    // would report only "expected value at line 1 column 1"; RFC 8259 section 8.1 lets a
    // parser ignore it.
    if bytes.starts_with(BYTE_ORDER_MARK) {
        bytes.drain(..BYTE_ORDER_MARK.len());
    }
    String::from_utf8(bytes).map_err(|e| {
        let (line, column, reason) = not_utf8(e.as_bytes(), e.utf8_error());
        content_error(line, column, reason)
    })
}

/// The UTF-8 encoding of U+FEFF, which some editors put at the start of a text file.
#[cfg(feature = "serde")]
const BYTE_ORDER_MARK: &[u8] = b"\xEF\xBB\xBF";

/// The line and column (1-based) of the first byte that is not UTF-8, and a message.
#[cfg(feature = "serde")]
pub(crate) fn not_utf8(bytes: &[u8], e: std::str::Utf8Error) -> (usize, usize, String) {
    let valid = &bytes[..e.valid_up_to()];
    let line = valid.iter().filter(|b| **b == b'\n').count() + 1;
    let start = valid.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
    let column = String::from_utf8_lossy(&valid[start..]).chars().count() + 1;
    (
        line,
        column,
        format!(
            "the file is not UTF-8 text: byte {} (0x{:02x}) at line {line}, column {column} is \
             not valid UTF-8",
            e.valid_up_to(),
            bytes[e.valid_up_to()]
        ),
    )
}

/// A JSON error of the scene file at `path` (`None`: text given directly).
#[cfg(feature = "serde")]
fn json_error(path: Option<&Path>, e: serde_json::Error) -> Error {
    Error::SceneFile {
        path: path.map(Path::to_path_buf),
        line: e.line(),
        column: e.column(),
        source: Box::new(e),
    }
}

#[cfg(feature = "serde")]
impl SceneFile {
    /// The scene file of a JSON object (a sweep's base scene), with every key: heights
    /// files read relative to `base` and held as values (the form a sweep's axes set keys
    /// in).
    ///
    /// # Errors
    /// [`KeyError::Value`] for a value outside the format; the scene's errors for a
    /// heights file.
    pub(crate) fn from_value(
        value: &serde_json::Value,
        base: &Path,
    ) -> std::result::Result<SceneFile, SceneValueError> {
        check_value_shape("", value)?;
        let file = SceneFile::deserialize(value).map_err(KeyError::from)?;
        Ok(SceneFile::from(&file.into_builder(base)?))
    }

    /// Sets the dotted `key` (a sweep's axis) to `value`, read as the file reads it.
    ///
    /// # Errors
    /// [`KeyError`]: not a key of the scene, a key below a value that is not an object, a
    /// value the key does not take (or an array where the file has an object).
    pub(crate) fn set(&mut self, key: &str, value: &serde_json::Value) -> Result<(), KeyError> {
        check_value_shape(key, value)?;
        let segments: Vec<&str> = key.split('.').collect();
        Schema::set(self, "", &segments, value)
    }

    /// The scene as JSON, every key written.
    ///
    /// # Errors
    /// [`KeyError::Value`] if serialisation fails (it does not for a scene's values).
    pub(crate) fn to_value(&self) -> Result<serde_json::Value, KeyError> {
        Ok(serde_json::to_value(self)?)
    }

    /// The builder of the scene (heights given as values: no file is read).
    ///
    /// # Errors
    /// Those of a heights file named in it.
    pub(crate) fn to_builder(&self) -> Result<SceneBuilder> {
        self.clone().into_builder(Path::new("."))
    }
}

/// Why a sweep's base scene is not a scene.
#[derive(Debug, thiserror::Error)]
#[cfg(feature = "serde")]
pub(crate) enum SceneValueError {
    /// A value outside the format.
    #[error(transparent)]
    Key(#[from] KeyError),
    /// A heights file that cannot be read.
    #[error(transparent)]
    Scene(#[from] Error),
}

#[cfg(feature = "serde")]
impl SceneBuilder {
    /// Reads a scene from JSON text (`docs/scene-format.md`; feature `serde`). A heights
    /// file named in it is read relative to the current directory. Nothing is validated
    /// beyond the format until [`SceneBuilder::build`].
    ///
    /// # Errors
    /// [`Error::SceneFile`] for invalid JSON or a key outside the format; those of
    /// [`HeightSource::from_file`] for a heights file.
    pub fn from_json_str(text: &str) -> Result<SceneBuilder> {
        check_shape(text, &scene_shape).map_err(|e| json_error(None, e))?;
        let file: SceneFile = serde_json::from_str(text).map_err(|e| json_error(None, e))?;
        file.into_builder(Path::new("."))
    }

    /// Reads a scene file (`docs/scene-format.md`; feature `serde`). A heights file named
    /// in it is read relative to the scene file's directory.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read; [`Error::SceneFile`] (with the path,
    /// line and column) for invalid JSON or a key outside the format; those of
    /// [`HeightSource::from_file`] for a heights file.
    pub fn from_json_file(path: impl AsRef<Path>) -> Result<SceneBuilder> {
        let path = path.as_ref();
        let text = read_json_text(path, "reading scene file", |line, column, reason| {
            Error::SceneFile {
                path: Some(path.to_path_buf()),
                line,
                column,
                source: reason.into(),
            }
        })?;
        check_shape(&text, &scene_shape).map_err(|e| json_error(Some(path), e))?;
        let file: SceneFile = serde_json::from_str(&text).map_err(|e| json_error(Some(path), e))?;
        file.into_builder(path.parent().unwrap_or(Path::new(".")))
    }

    /// The scene as JSON (`docs/scene-format.md`; feature `serde`), every key written.
    /// Heights read from a file are written as values. Reading it back gives an equal
    /// builder: floats round-trip exactly.
    ///
    /// # Errors
    /// [`Error::CustomContactRule`] under a custom contact rule ([`crate::ContactLaw`]: a
    /// scene file cannot name it); [`Error::SceneFile`] if serialisation fails (it does
    /// not for a builder's values).
    pub fn to_json(&self) -> Result<String> {
        self.contact().built_in("writing the scene as JSON")?;
        serde_json::to_string_pretty(&SceneFile::from(self)).map_err(|e| json_error(None, e))
    }
}

#[cfg(feature = "serde")]
impl Serialize for SceneBuilder {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        self.contact()
            .built_in("serialising the scene")
            .map_err(serde::ser::Error::custom)?;
        SceneFile::from(self).serialize(serializer)
    }
}

#[cfg(feature = "serde")]
impl<'de> Deserialize<'de> for SceneBuilder {
    /// Heights files are read relative to the current directory.
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        SceneFile::deserialize(deserializer)?
            .into_builder(Path::new("."))
            .map_err(serde::de::Error::custom)
    }
}

/// Every key of `scene` with its exact value, in the file's order (observers included).
#[cfg(any(feature = "plot", test))]
pub(crate) fn all_keys(scene: &SceneBuilder) -> Vec<(String, String)> {
    let mut keys = Vec::new();
    SceneFile::from(scene).keys("", Walk::All, &mut keys);
    keys
}

/// The scene's identity: every key that identifies the run (all but the observers,
/// declared `[observer]` in the file's types: [`Walk::Identity`]) with its exact value,
/// as `(key path, value)` in the file's order. Checkpoints store a digest of it.
pub(crate) fn identity(scene: &SceneBuilder) -> Vec<(String, String)> {
    let mut keys = Vec::new();
    SceneFile::from(scene).keys("", Walk::Identity, &mut keys);
    keys
}

/// The first key of the identity (in `a`'s order, then keys only `b` has) in which `b`
/// describes another run than `a`, `None` for the same run.
pub(crate) fn first_difference(a: &SceneBuilder, b: &SceneBuilder) -> Option<String> {
    let (mine, theirs) = (identity(a), identity(b));
    mine.iter()
        .find(|key_value| !theirs.contains(key_value))
        .or_else(|| {
            theirs
                .iter()
                .find(|(k, _)| !mine.iter().any(|(m, _)| m == k))
        })
        .map(|(key, _)| key.clone())
}

/// Whether the scene file has an object at the dotted `path` (`""`: the top level; `#`
/// steps into an array's elements).
#[cfg(feature = "serde")]
pub(crate) fn object_at(path: &str) -> bool {
    if path.is_empty() {
        return true;
    }
    let segments: Vec<&str> = path.split('.').collect();
    <SceneFile as Schema>::object_at(&segments)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::probe::ProbeSpec;
    use crate::scene::{Drive, ForceLoad, HeightSource, Lateral};
    use crate::solver::{Parallelism, SolverOptions};

    /// Scenes with every kind of every enum of the file.
    fn scenes() -> Vec<SceneBuilder> {
        let rod = Lateral::Rod {
            height: 3e-3,
            half_width: 1e-3,
        };
        let base = SceneBuilder::default().block(0.02, 0.004, 0.01);
        vec![
            base.clone(),
            base.clone()
                .cells(20, 4)
                .drive(Drive::Force(ForceLoad::Top)),
            base.clone()
                .drive(Drive::Force(ForceLoad::Lateral(Lateral::Side))),
            base.clone().drive(Drive::Force(ForceLoad::Mixed {
                ratio: 0.5,
                lateral: rod,
            })),
            base.clone()
                .drive(Drive::Spring {
                    stiffness: 4e6,
                    lateral: Lateral::Side,
                })
                .heights(HeightSource::Values(vec![1e-6; 80])),
            base.clone().heights(HeightSource::Surface {
                spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
                distribution: crate::interface::HeightDistribution::new(2e-6, 1e-6).unwrap(),
                seed: 5,
            }),
            // Half of each value stays valid: λ_s < λ_r/2, λ_l/2 ≥ λ_r.
            base.clone().heights(HeightSource::Surface {
                spectrum: SurfaceSpectrum::self_affine(0.7, 3e-3, 0.6e-3, 8e-3).unwrap(),
                distribution: crate::interface::HeightDistribution::default(),
                seed: 6,
            }),
            base.clone()
                .friction_map(SiteMap::Surface {
                    spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
                    mean: 0.5,
                    std_dev: 0.1,
                    seed: 3,
                })
                .c_z_map(SiteMap::Values(vec![1.65e8; 80])),
            base.clone().c_x_map(SiteMap::Surface {
                spectrum: SurfaceSpectrum::self_affine(0.7, 3e-3, 0.6e-3, 8e-3).unwrap(),
                mean: 1e12,
                std_dev: 2e11,
                seed: 4,
            }),
            base.solver_options(
                SolverOptions::default()
                    .with_parallelism(Parallelism::Threads(3))
                    .unwrap(),
            )
            .max_cells(5000)
            .probes(ProbeSpec::default().with_plane(1e-3))
            .run_options(RunOptions::new().record_profiles(&[0.2, 0.4], &[0.0])),
        ]
    }

    #[test]
    fn the_identity_is_every_key_but_the_observers() {
        for scene in scenes() {
            let all = all_keys(&scene);
            let identity = identity(&scene);
            assert!(identity.iter().all(|k| all.contains(k)));
            let left_out: Vec<&str> = all
                .iter()
                .filter(|k| !identity.contains(k))
                .map(|(k, _)| k.as_str())
                .collect();
            assert!(left_out.contains(&"solver.threads"), "{left_out:?}");
            assert!(left_out.iter().all(|k| *k == "solver.threads"
                || *k == "max_cells"
                || *k == "confirm_metres"
                || *k == "max_output_bytes"
                || k.starts_with("probes.")
                || k.starts_with("fields.")
                || k.starts_with("profiles.")));
        }
    }

    #[test]
    fn an_observer_does_not_change_the_identity_and_every_other_key_does() {
        let a = SceneBuilder::default();
        let b = a
            .clone()
            .solver_options(
                SolverOptions::default()
                    .with_parallelism(Parallelism::Threads(2))
                    .unwrap(),
            )
            .max_cells(10)
            .confirm_metres(true)
            .probes(ProbeSpec::default().with_plane(1e-3))
            .run_options(
                RunOptions::new()
                    .record_fields(3, &[1e-3])
                    .record_profiles(&[0.5], &[1e-3]),
            );
        assert_eq!(first_difference(&a, &b), None);
        // The run options' probes and threads, which the file writes as `probes` and
        // `solver.threads`.
        let c = a.clone().run_options(
            RunOptions::new()
                .probes(ProbeSpec::default().with_plane(2e-3))
                .threads(4),
        );
        let file = SceneFile::from(&c);
        assert_ne!(file, SceneFile::from(&a));
        assert_eq!(first_difference(&a, &c), None);
        assert_eq!(identity(&a), identity(&c));
        assert_eq!(
            first_difference(&a, &a.clone().normal_load(1.0)).as_deref(),
            Some("normal_load")
        );
        assert_eq!(
            first_difference(&a, &a.clone().seed(4)).as_deref(),
            Some("heights.seed")
        );
        let top = a.clone().drive(Drive::Force(ForceLoad::Top));
        assert_eq!(first_difference(&a, &top).as_deref(), Some("drive.kind"));
        // A key only the second has.
        assert_eq!(first_difference(&top, &a).as_deref(), Some("drive.kind"));
    }

    /// A scene's maps are in its identity, key by key; a scene without maps has no key of
    /// them (the pinned identity of the default scene is a 1.x checkpoint's).
    #[test]
    fn the_maps_are_in_the_identity_only_when_given() {
        let a = SceneBuilder::default();
        assert!(identity(&a).iter().all(|(k, _)| !k.starts_with("maps")));
        let map = |seed| SiteMap::Surface {
            spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
            mean: 0.5,
            std_dev: 0.1,
            seed,
        };
        let b = a.clone().friction_map(map(3));
        let keys: Vec<String> = identity(&b).into_iter().map(|(k, _)| k).collect();
        for key in [
            "maps.friction_coefficient.kind",
            "maps.friction_coefficient.correlation_length",
            "maps.friction_coefficient.mean",
            "maps.friction_coefficient.std_dev",
            "maps.friction_coefficient.seed",
        ] {
            assert!(keys.iter().any(|k| k == key), "{key}: {keys:?}");
        }
        assert_eq!(
            first_difference(&a, &b).as_deref(),
            Some("maps.friction_coefficient.kind")
        );
        let c = a.clone().friction_map(map(4));
        assert_eq!(
            first_difference(&b, &c).as_deref(),
            Some("maps.friction_coefficient.seed")
        );
        let d = a.c_x_map(SiteMap::Values(vec![1e12; 980]));
        assert_eq!(first_difference(&d, &b).as_deref(), Some("maps.c_x.kind"));
    }

    /// `cuda` solves the `spectral` rule: one identity, so a checkpoint resumes across the
    /// two; `dense` is another rule.
    #[test]
    fn the_cuda_backend_has_the_spectral_identity() {
        let with = |backend| {
            SceneBuilder::default()
                .solver_options(SolverOptions::default().with_backend(backend).unwrap())
        };
        let (cuda, spectral) = (with(Backend::Cuda), with(Backend::Spectral));
        assert_ne!(SceneFile::from(&cuda), SceneFile::from(&spectral));
        assert_eq!(identity(&cuda), identity(&spectral));
        assert_eq!(first_difference(&cuda, &spectral), None);
        assert_eq!(first_difference(&spectral, &cuda), None);
        assert!(identity(&cuda).contains(&("solver.backend".into(), "spectral".into())));
        // Every key's exact value: the backend as written.
        assert!(all_keys(&cuda).contains(&("solver.backend".into(), "cuda".into())));
        assert_eq!(
            first_difference(&cuda, &with(Backend::Dense)).as_deref(),
            Some("solver.backend")
        );
    }

    #[cfg(feature = "serde")]
    #[test]
    fn the_objects_of_the_file() {
        for path in [
            "",
            "block",
            "cells",
            "maps",
            "maps.c_x",
            "heights",
            "drive",
            "drive.lateral",
            "probes",
            "fields",
        ] {
            assert!(object_at(path), "{path}");
        }
        for path in [
            "normal_load",
            "maps.mu",
            "maps.c_x.mean",
            "block.lx",
            "drive.height",
            "probes.points",
            "x",
            "block.x",
        ] {
            assert!(!object_at(path), "{path}");
        }
    }

    /// The flattened keys of a JSON object (dotted paths to its non-object values).
    #[cfg(feature = "serde")]
    fn flattened(value: &serde_json::Value, path: &str, out: &mut Vec<String>) {
        match value.as_object() {
            Some(map) => {
                for (k, v) in map {
                    flattened(v, &crate::scene::schema::join(path, k), out);
                }
            }
            None => out.push(path.to_string()),
        }
    }

    /// The checkpoint's identity of the default scene, written out by hand from
    /// docs/scene-format.md: checkpoints of earlier versions hold a digest of exactly
    /// these keys and values.
    #[test]
    fn the_identity_of_the_default_scene_is_pinned() {
        let expected = [
            ("block.lx", "0.14"),
            ("block.ly", "0.007"),
            ("block.lz", "0.075"),
            ("cells.kind", "size"),
            ("cells.dx", "0.001"),
            ("cells.dy", "0.001"),
            ("material.young_modulus", "3833000000.0"),
            ("material.poisson_ratio", "0.38"),
            ("material.friction_coefficient", "0.5"),
            ("springs.c_x", "1650000000000.0"),
            ("springs.c_z", "165000000.0"),
            ("springs.area_law", "paper"),
            ("heights.kind", "gaussian"),
            ("heights.mean", "1e-6"),
            ("heights.std_dev", "1e-6"),
            ("heights.seed", "1"),
            ("normal_load", "3500.0"),
            ("drive.kind", "rod"),
            ("drive.height", "0.006"),
            ("drive.half_width", "0.002"),
            ("solver.backend", "auto"),
            ("solver.tolerance", "1e-13"),
            ("solver.max_active_set_iterations", "1000"),
            ("solver.max_linear_iterations", "20000"),
            ("plan_tolerance", "1e-8"),
        ];
        let identity = identity(&SceneBuilder::default());
        let identity: Vec<(&str, &str)> = identity
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        assert_eq!(identity, expected);
    }

    /// A scene file -> scene -> checkpoint: the checkpoint's scene has the file's
    /// identity, and the identity's keys are the file's keys but the observers.
    #[cfg(feature = "serde")]
    #[test]
    fn a_scene_file_its_checkpoint_and_its_identity_have_one_key_set() {
        let text = r#"{ "block": { "lx": 0.012, "ly": 0.002, "lz": 0.010 },
                        "cells": { "kind": "count", "nx": 12, "ny": 2 },
                        "normal_load": 50.0,
                        "drive": { "kind": "spring", "stiffness": 4e6,
                                   "lateral": { "kind": "rod", "height": 0.003, "half_width": 0.001 } },
                        "solver": { "threads": 2 },
                        "probes": { "planes": [0.001] } }"#;
        let builder = SceneBuilder::from_json_str(text).unwrap();
        let scene = builder.clone().build().unwrap();
        let mut driver = scene.driver().unwrap();
        driver.step().unwrap();
        let checkpoint = driver.checkpoint();
        assert_eq!(identity(checkpoint.scene()), identity(&builder));
        let mut keys = Vec::new();
        flattened(
            &serde_json::from_str(&builder.to_json().unwrap()).unwrap(),
            "",
            &mut keys,
        );
        // The observers, as docs/scene-format.md lists them (the run options' keys).
        let observer = |k: &str| {
            ["solver.threads", "max_cells"].contains(&k)
                || ["probes.", "fields.", "profiles."]
                    .iter()
                    .any(|p| k.starts_with(p))
        };
        keys.retain(|k| !observer(k));
        keys.sort();
        let mut from_identity: Vec<String> =
            identity(&builder).into_iter().map(|(k, _)| k).collect();
        from_identity.sort();
        assert_eq!(keys, from_identity);
        for key in ["drive.lateral.height", "cells.nx", "drive.stiffness"] {
            assert!(keys.iter().any(|k| k == key), "{key}");
        }
    }

    /// Every key a sweep can set (every key of the file) round-trips through the schema:
    /// set to its own value it changes nothing; set to another value it changes that key
    /// alone.
    #[cfg(feature = "serde")]
    #[test]
    fn every_key_a_sweep_can_set_round_trips() {
        for scene in scenes() {
            let file = SceneFile::from(&scene);
            let json = file.to_value().unwrap();
            let before = all_keys(&scene);
            for (key, exact) in &before {
                // A key the file leaves out at its default (`max_cells`): its exact value.
                let written = key.split('.').fold(&json, |v, k| &v[k]);
                let parsed;
                let value = if written.is_null() {
                    parsed = serde_json::from_str::<serde_json::Value>(exact).unwrap();
                    &parsed
                } else {
                    written
                };
                let mut same = file.clone();
                same.set(key, value)
                    .unwrap_or_else(|e| panic!("{key}: {e}"));
                assert_eq!(same, file, "{key}");
                let other = match value {
                    // Half of a valid value stays valid for every key (a Poisson ratio,
                    // a tolerance, a length), which the value types check on construction.
                    serde_json::Value::Number(n) if n.is_f64() => {
                        serde_json::json!(n.as_f64().unwrap() * 0.5)
                    }
                    serde_json::Value::Number(n) => serde_json::json!(n.as_u64().unwrap() + 1),
                    _ => continue,
                };
                let mut changed = file.clone();
                changed.set(key, &other).unwrap();
                let after = all_keys(&changed.to_builder().unwrap());
                let differing: Vec<&str> = before
                    .iter()
                    .zip(&after)
                    .filter(|(a, b)| a != b)
                    .map(|(a, _)| a.0.as_str())
                    .collect();
                assert_eq!(differing, [key.as_str()], "{key}");
            }
            // Not keys of the scene: typed errors naming the place.
            let mut f = file.clone();
            assert!(matches!(
                f.set("block.lxx", &serde_json::json!(1.0)),
                Err(KeyError::NotAKey { .. })
            ));
            assert!(matches!(
                f.set("normal_load.x", &serde_json::json!(1.0)),
                Err(KeyError::NotAnObject { .. })
            ));
            assert!(matches!(
                f.set("normal_load", &serde_json::json!("heavy")),
                Err(KeyError::Value(_))
            ));
        }
    }
}
