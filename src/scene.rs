//! A complete simulation set-up: block, grid, material, interface springs, normal load
//! and the shear drive, validated once by [`SceneBuilder::build`].
//!
//! A scene computes only what it needs: the lateral load table (paper Eq. `G_x_lat`) only
//! for a drive with a lateral part, the dense matrix only when the solver backend is dense
//! (by default: [`Backend::Auto`](crate::solver::Backend::Auto) up to
//! [`AUTO_DENSE_LIMIT`](crate::solver::AUTO_DENSE_LIMIT) cells).
//!
//! ```
//! use precursors::{Drive, Lateral, Scene};
//! // The paper's calibration scene (Fig. 2b): 140 x 7 x 75 mm, 1 mm cells, F_N = 3.5 kN,
//! // rod at h = 6 mm with Δh = 2 mm.
//! let scene = Scene::builder()
//!     .block(0.140, 0.007, 0.075)
//!     .cell_size(1e-3, 1e-3)
//!     .normal_load(3.5e3)
//!     .drive(Drive::Force(Lateral::Rod { height: 6e-3, half_width: 2e-3 }.into()))
//!     .seed(1)
//!     .build()?;
//! assert_eq!(scene.grid().len(), 980);
//! # Ok::<(), precursors::Error>(())
//! ```

use crate::contact::ContactRule;
use crate::error::{check_tolerance, Error, Result};
use crate::geometry::{Block, Grid};
use crate::green::{InfluencePlan, Planner, RodLoad};
use crate::interface::{AreaLaw, HeightDistribution, Heights, Interface, Material, SpringLaw};
use crate::probe::{ProbeSpec, StressProbe};
use crate::recording::RunOptions;
use crate::solver::SolverOptions;
use crate::surface::SurfaceSpectrum;

mod bounds;
pub(crate) use bounds::{probes as check_probes, run_options as check_run_options};
pub(crate) mod file;
pub(crate) mod schema;

/// Relative tolerance of the lateral load table.
const LATERAL_TOLERANCE: f64 = 1e-12;

/// Where a lateral shear acts on the trailing face `x = 0`.
///
/// ```
/// use precursors::{Drive, Error, Lateral, Scene};
/// let base = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0);               // F_N (N)
/// // The paper's rod: a band z ∈ [4, 8] mm of the trailing face.
/// let rod = Lateral::Rod { height: 6e-3, half_width: 2e-3 };
/// assert!(base.clone().drive(Drive::Force(rod.into())).build()?.has_lateral_table());
/// // A band reaching above the top face (z up to 11 mm > Lz = 10 mm) is refused.
/// let high = Lateral::Rod { height: 9e-3, half_width: 2e-3 };
/// let refused = base.clone().drive(Drive::Force(high.into())).build();
/// assert!(matches!(refused, Err(Error::RodBandOutsideFace { .. })));
/// // The whole trailing face (h = Δh = Lz/2 = 5 mm).
/// base.drive(Drive::Force(Lateral::Side.into())).build()?;
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(from = "LateralFields", into = "LateralFields")
)]
#[non_exhaustive]
pub enum Lateral {
    /// The paper's rod: a band `z ∈ [height - half_width, height + half_width]` (m).
    Rod {
        /// Height `h` of the band's centre above the interface (m).
        height: f64,
        /// Half-width `Δh` of the band (m).
        half_width: f64,
    },
    /// The whole trailing face (`h = Δh = Lz/2`).
    Side,
}

/// How the total shear force `F = F_top + F_lat` is split under force control.
///
/// ```
/// use precursors::{Drive, Error, Event, ForceLoad, Lateral, Scene};
/// let base = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0);               // F_N (N)
/// // A uniform top shear: no lateral load, and Amontons' law, the block slides at μ F_N.
/// let top = base.clone().drive(Drive::Force(ForceLoad::Top)).build()?;
/// assert!(!top.has_lateral_table());
/// let mut slip = 0.0;
/// for event in top.driver()? {
///     if let Event::GlobalSlip { load } = event? {
///         slip = load.force;                                    // F (N)
///     }
/// }
/// let mu_fn = top.material().friction_coefficient() * 40.0;     // μ F_N = 20 N
/// assert!((slip / mu_fn - 1.0).abs() < 1e-9);
/// // F_top = 3 F_lat (the paper's n = 3), the lateral part on the rod.
/// let rod = Lateral::Rod { height: 6e-3, half_width: 2e-3 };
/// let mixed = ForceLoad::Mixed { ratio: 3.0, lateral: rod };
/// assert!(base.clone().drive(Drive::Force(mixed)).build()?.has_lateral_table());
/// assert_eq!(ForceLoad::from(rod), ForceLoad::Lateral(rod));
/// let negative = ForceLoad::Mixed { ratio: -1.0, lateral: rod };
/// let refused = base.drive(Drive::Force(negative)).build();
/// assert!(matches!(refused, Err(Error::InvalidParameter { name: "drive.ratio", .. })));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(from = "ForceLoadFields", into = "ForceLoadFields")
)]
#[non_exhaustive]
pub enum ForceLoad {
    /// Uniform shear on the top face only.
    Top,
    /// Lateral shear only.
    Lateral(Lateral),
    /// Both, with `F_top = ratio · F_lat` (the paper's `n`, dimensionless, ≥ 0).
    Mixed {
        /// `n = F_top / F_lat` (dimensionless).
        ratio: f64,
        /// Where the lateral part acts.
        lateral: Lateral,
    },
}

impl From<Lateral> for ForceLoad {
    fn from(lateral: Lateral) -> Self {
        ForceLoad::Lateral(lateral)
    }
}

/// The shear drive: the quasi-static control parameter.
///
/// ```
/// use precursors::{Drive, Error, Event, ForceLoad, Lateral, Scene};
/// // The default: the paper's rod at h = 6 mm, Δh = 2 mm, under force control.
/// let rod = Lateral::Rod { height: 6e-3, half_width: 2e-3 };
/// assert_eq!(Drive::default(), Drive::Force(ForceLoad::Lateral(rod)));
/// // Displacement control: the paper's driving spring K_S = 4e6 N/m on the trailing face.
/// let spring = Drive::Spring { stiffness: 4e6, lateral: Lateral::Side };
/// let base = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0);               // F_N (N)
/// let mut driver = base.clone().drive(spring).build()?.driver()?;
/// driver.step()?;                                           // zero shear
/// let Some(Event::LoadRaised { load }) = driver.step()? else { unreachable!() };
/// assert!(load.drive_displacement.is_some_and(|u_s| u_s > 0.0)); // U_S (m)
/// // A spring without stiffness is refused, naming its scene-file key.
/// let limp = Drive::Spring { stiffness: 0.0, lateral: Lateral::Side };
/// let refused = base.drive(limp).build();
/// assert!(matches!(refused, Err(Error::InvalidParameter { name: "drive.stiffness", .. })));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(from = "DriveFields", into = "DriveFields")
)]
#[non_exhaustive]
pub enum Drive {
    /// Force control: the shear force `F` (N) is raised from threshold to threshold.
    Force(ForceLoad),
    /// Displacement control through a driving spring on the trailing face (paper Eq.
    /// `spring_shear_force`): `F_lat = K_S (U_S - ⟨u_x⟩)`, with the drive displacement
    /// `U_S` (m) raised from threshold to threshold.
    Spring {
        /// `K_S` (N/m, finite, > 0; the paper uses `4e6`).
        stiffness: f64,
        /// Where the spring acts.
        lateral: Lateral,
    },
}

/// Shortcuts for the drives a scene file names by `kind` (`"rod"`, `"top"`, `"side"`), under
/// force control.
///
/// ```
/// use precursors::{Drive, ForceLoad, Lateral, Scene};
/// // The paper's default drive, as the scene file writes {"kind": "rod"}.
/// assert_eq!(Drive::rod(6e-3, 2e-3), Drive::default());
/// assert_eq!(Drive::top(), Drive::Force(ForceLoad::Top));
/// assert_eq!(Drive::side(), Drive::Force(ForceLoad::Lateral(Lateral::Side)));
/// assert!(Scene::builder().drive(Drive::rod(4e-3, 1e-3)).build()?.has_lateral_table());
/// # Ok::<(), precursors::Error>(())
/// ```
impl Drive {
    /// The rod on the trailing face at `height` (m) above the interface, pressing a band of
    /// `half_width` (m) on each side of it, under force control (scene file
    /// `{"kind": "rod", "height": h, "half_width": w}`).
    pub fn rod(height: f64, half_width: f64) -> Drive {
        Drive::Force(ForceLoad::Lateral(Lateral::Rod { height, half_width }))
    }

    /// A uniform shear on the top face, under force control (`{"kind": "top"}`).
    pub fn top() -> Drive {
        Drive::Force(ForceLoad::Top)
    }

    /// A uniform load on the whole trailing face, under force control (`{"kind": "side"}`).
    pub fn side() -> Drive {
        Drive::Force(ForceLoad::Lateral(Lateral::Side))
    }
}

impl Default for Drive {
    /// The paper's rod at `h = 6 mm`, `Δh = 2 mm`, under force control.
    fn default() -> Self {
        Drive::Force(ForceLoad::Lateral(Lateral::Rod {
            height: 6e-3,
            half_width: 2e-3,
        }))
    }
}

/// Where the asperity heights come from.
///
/// ```
/// use precursors::{Error, HeightSource, Scene};
/// // The default: the paper's truncated Gaussian (mean 1 µm, sd 1 µm), seed 1.
/// assert!(matches!(HeightSource::default(), HeightSource::Random { seed: 1, .. }));
/// // Given heights (m), one per cell in the order i = iy·Nx + ix: 1 to 2 µm along x.
/// let values: Vec<f64> = (0..40).map(|i| 1e-6 * (1.0 + (i % 10) as f64 / 9.0)).collect();
/// let base = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells: 40 heights
///     .normal_load(40.0);               // F_N (N)
/// let scene = base.clone().heights(values.clone().into()).build()?;
/// assert_eq!(scene.interface().heights(), &values[..]);
/// // One height short of the grid is refused.
/// let short = base.heights(HeightSource::Values(values[..39].to_vec())).build();
/// assert!(short.is_err());
/// // The same heights from a text file: one per line, `#` comments.
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("heights.txt");
/// let lines: String = values.iter().map(|h| format!("{h}\n")).collect();
/// std::fs::write(&path, format!("# heights (m), i = iy·Nx + ix\n{lines}"))?;
/// assert_eq!(HeightSource::from_file(&path)?, HeightSource::Values(values));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "HeightSourceFields", into = "HeightSourceFields")
)]
#[non_exhaustive]
pub enum HeightSource {
    /// Truncated Gaussian heights from a seed ([`Heights::truncated_gaussian`]).
    Random {
        /// Mean and standard deviation before truncation (m).
        distribution: HeightDistribution,
        /// Seed of the generator.
        seed: u64,
    },
    /// Given heights (m), one per cell in the paper's order `i = iy·Nx + ix`.
    Values(Vec<f64>),
    /// A Gaussian random surface with a length scale, averaged over each cell
    /// ([`Heights::random_surface`]): the same seed gives the same surface at every cell
    /// size. Scene-file kinds `gaussian_surface` and `self_affine_surface`.
    ///
    /// ```
    /// use precursors::{HeightDistribution, HeightSource, Scene, SurfaceSpectrum};
    /// let surface = HeightSource::Surface {
    ///     spectrum: SurfaceSpectrum::gaussian(2e-3)?,          // ξ = 2 mm
    ///     distribution: HeightDistribution::default(),          // mean 1 µm, sd 1 µm, cut at 0
    ///     seed: 3,
    /// };
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
    ///     .cells(10, 4)                     // 1 mm cells
    ///     .normal_load(40.0)                // F_N (N)
    ///     .heights(surface)
    ///     .build()?;
    /// assert!(scene.interface().heights().iter().all(|&u0| u0 > 0.0));
    /// # Ok::<(), precursors::Error>(())
    /// ```
    Surface {
        /// The power spectrum of the surface.
        spectrum: SurfaceSpectrum,
        /// The heights' marginal: the Gaussian before truncation at 0 (m).
        distribution: HeightDistribution,
        /// Seed of the surface's Fourier coefficients.
        seed: u64,
    },
}

/// A [`Lateral`] as serde sees it (feature `serde`): the scene file's `lateral` object,
/// `{"kind": "rod", "height": h, "half_width": Δh}` or `{"kind": "side"}` (a struct
/// variant, so that a key beside `kind` is refused).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum LateralFields {
    Rod { height: f64, half_width: f64 },
    Side {},
}

#[cfg(feature = "serde")]
impl From<Lateral> for LateralFields {
    fn from(lateral: Lateral) -> Self {
        match lateral {
            Lateral::Rod { height, half_width } => Self::Rod { height, half_width },
            Lateral::Side => Self::Side {},
        }
    }
}

#[cfg(feature = "serde")]
impl From<LateralFields> for Lateral {
    fn from(f: LateralFields) -> Self {
        match f {
            LateralFields::Rod { height, half_width } => Lateral::Rod { height, half_width },
            LateralFields::Side {} => Lateral::Side,
        }
    }
}

/// A [`ForceLoad`] as serde sees it (feature `serde`): the scene file's `drive` object
/// of kind `top`, `rod`, `side` or `mixed` (a lateral load only is `rod` or `side`).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum ForceLoadFields {
    Top {},
    Rod { height: f64, half_width: f64 },
    Side {},
    Mixed { ratio: f64, lateral: Lateral },
}

#[cfg(feature = "serde")]
impl From<ForceLoad> for ForceLoadFields {
    fn from(load: ForceLoad) -> Self {
        match load {
            ForceLoad::Top => Self::Top {},
            ForceLoad::Lateral(Lateral::Rod { height, half_width }) => {
                Self::Rod { height, half_width }
            }
            ForceLoad::Lateral(Lateral::Side) => Self::Side {},
            ForceLoad::Mixed { ratio, lateral } => Self::Mixed { ratio, lateral },
        }
    }
}

#[cfg(feature = "serde")]
impl From<ForceLoadFields> for ForceLoad {
    fn from(f: ForceLoadFields) -> Self {
        match f {
            ForceLoadFields::Top {} => ForceLoad::Top,
            ForceLoadFields::Rod { height, half_width } => {
                ForceLoad::Lateral(Lateral::Rod { height, half_width })
            }
            ForceLoadFields::Side {} => ForceLoad::Lateral(Lateral::Side),
            ForceLoadFields::Mixed { ratio, lateral } => ForceLoad::Mixed { ratio, lateral },
        }
    }
}

/// A [`Drive`] as serde sees it (feature `serde`): the scene file's `drive` object, of
/// kind `top`, `rod`, `side`, `mixed` (force control) or `spring`. The values are
/// checked when a scene is built, as the Rust builder's.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum DriveFields {
    Top {},
    Rod { height: f64, half_width: f64 },
    Side {},
    Mixed { ratio: f64, lateral: Lateral },
    Spring { stiffness: f64, lateral: Lateral },
}

#[cfg(feature = "serde")]
impl From<Drive> for DriveFields {
    fn from(drive: Drive) -> Self {
        match drive {
            Drive::Force(load) => match ForceLoadFields::from(load) {
                ForceLoadFields::Top {} => Self::Top {},
                ForceLoadFields::Rod { height, half_width } => Self::Rod { height, half_width },
                ForceLoadFields::Side {} => Self::Side {},
                ForceLoadFields::Mixed { ratio, lateral } => Self::Mixed { ratio, lateral },
            },
            Drive::Spring { stiffness, lateral } => Self::Spring { stiffness, lateral },
        }
    }
}

#[cfg(feature = "serde")]
impl From<DriveFields> for Drive {
    fn from(f: DriveFields) -> Self {
        let force = |load: ForceLoadFields| Drive::Force(load.into());
        match f {
            DriveFields::Top {} => force(ForceLoadFields::Top {}),
            DriveFields::Rod { height, half_width } => {
                force(ForceLoadFields::Rod { height, half_width })
            }
            DriveFields::Side {} => force(ForceLoadFields::Side {}),
            DriveFields::Mixed { ratio, lateral } => {
                force(ForceLoadFields::Mixed { ratio, lateral })
            }
            DriveFields::Spring { stiffness, lateral } => Drive::Spring { stiffness, lateral },
        }
    }
}

/// A [`HeightSource`] as serde sees it (feature `serde`): the scene file's `heights`
/// object but the kind `file` (a source holds values, not a path): `gaussian`, `values`,
/// `gaussian_surface` or `self_affine_surface`, with the scene file's keys and defaults,
/// read back through [`HeightDistribution::new`] and the [`SurfaceSpectrum`] constructors.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum HeightSourceFields {
    Gaussian {
        #[serde(default = "default_mean")]
        mean: f64,
        #[serde(default = "default_std_dev")]
        std_dev: f64,
        #[serde(default = "default_seed")]
        seed: u64,
    },
    Values {
        values: Vec<f64>,
    },
    GaussianSurface {
        correlation_length: f64,
        #[serde(default = "default_mean")]
        mean: f64,
        #[serde(default = "default_std_dev")]
        std_dev: f64,
        #[serde(default = "default_seed")]
        seed: u64,
    },
    SelfAffineSurface {
        hurst: f64,
        roll_off: f64,
        short_cutoff: f64,
        long_cutoff: f64,
        #[serde(default = "default_mean")]
        mean: f64,
        #[serde(default = "default_std_dev")]
        std_dev: f64,
        #[serde(default = "default_seed")]
        seed: u64,
    },
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
    DEFAULT_SEED
}

#[cfg(feature = "serde")]
impl From<HeightSource> for HeightSourceFields {
    fn from(source: HeightSource) -> Self {
        match source {
            HeightSource::Random { distribution, seed } => Self::Gaussian {
                mean: distribution.mean(),
                std_dev: distribution.std_dev(),
                seed,
            },
            HeightSource::Values(values) => Self::Values { values },
            HeightSource::Surface {
                spectrum,
                distribution,
                seed,
            } => {
                let (mean, std_dev) = (distribution.mean(), distribution.std_dev());
                match spectrum {
                    SurfaceSpectrum::Gaussian { correlation_length } => Self::GaussianSurface {
                        correlation_length,
                        mean,
                        std_dev,
                        seed,
                    },
                    SurfaceSpectrum::SelfAffine {
                        hurst,
                        roll_off,
                        short_cutoff,
                        long_cutoff,
                    } => Self::SelfAffineSurface {
                        hurst,
                        roll_off,
                        short_cutoff,
                        long_cutoff,
                        mean,
                        std_dev,
                        seed,
                    },
                }
            }
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<HeightSourceFields> for HeightSource {
    type Error = Error;
    fn try_from(f: HeightSourceFields) -> Result<Self> {
        Ok(match f {
            HeightSourceFields::Gaussian {
                mean,
                std_dev,
                seed,
            } => HeightSource::Random {
                distribution: HeightDistribution::new(mean, std_dev)?,
                seed,
            },
            HeightSourceFields::Values { values } => HeightSource::Values(values),
            HeightSourceFields::GaussianSurface {
                correlation_length,
                mean,
                std_dev,
                seed,
            } => HeightSource::Surface {
                spectrum: SurfaceSpectrum::gaussian(correlation_length)?,
                distribution: HeightDistribution::new(mean, std_dev)?,
                seed,
            },
            HeightSourceFields::SelfAffineSurface {
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
        })
    }
}

impl HeightSource {
    /// The same random source with another seed; the paper's Gaussian heights with this
    /// seed for given values (a calibration's realizations).
    pub(crate) fn reseeded(&self, seed: u64) -> HeightSource {
        match self {
            HeightSource::Random { distribution, .. } => HeightSource::Random {
                distribution: *distribution,
                seed,
            },
            HeightSource::Surface {
                spectrum,
                distribution,
                ..
            } => HeightSource::Surface {
                spectrum: *spectrum,
                distribution: *distribution,
                seed,
            },
            HeightSource::Values(_) => HeightSource::Random {
                distribution: HeightDistribution::default(),
                seed,
            },
        }
    }

    /// Whether the heights are drawn from a seed (realizations differ by it).
    #[cfg(feature = "serde")]
    pub(crate) fn is_random(&self) -> bool {
        !matches!(self, HeightSource::Values(_))
    }

    /// Heights (m) read from a text file: one value per line in the paper's cell order
    /// `i = iy·Nx + ix`; blank lines and lines starting with `#` are skipped. Each value
    /// must be finite and `> 0`; the count is checked against the grid at
    /// [`SceneBuilder::build`].
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read (with its path); [`Error::HeightsFile`]
    /// for a line that is not a finite height `> 0`, or no height at all.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<HeightSource> {
        Self::read_file(path.as_ref(), None)
    }

    /// [`HeightSource::from_file`] for a grid of `cells` cells (when known): a file longer
    /// than such a grid's heights can be (1 MiB of comments and 256 bytes a height), or
    /// holding more heights, is refused before it is read whole; without a grid, the file
    /// must fit in the memory available.
    pub(crate) fn read_file(path: &std::path::Path, cells: Option<usize>) -> Result<HeightSource> {
        let name = path.display().to_string();
        read_values(
            path,
            cells,
            "reading heights file",
            ("height", "heights"),
            |value| {
                (!(value.is_finite() && value > 0.0))
                    .then(|| format!("{value} m is not a height: heights must be finite and > 0"))
            },
            |line, reason| Error::HeightsFile {
                path: name.clone(),
                line,
                reason,
            },
        )
        .map(HeightSource::Values)
    }
}

/// The values of a text file of one value per line in the paper's cell order
/// `i = iy·Nx + ix` (blank lines and lines starting with `#` skipped), for a grid of
/// `cells` cells when known: a file longer than such a grid's values can be (1 MiB of
/// comments and 256 bytes a value), or holding more values, is refused before it is read
/// whole; without a grid, the file must fit in the memory available. `noun` names a value
/// and the values in messages, `invalid` says why a value is refused (`None`: valid),
/// `error` makes the error of a line (0: the file as a whole) and its reason.
fn read_values(
    path: &std::path::Path,
    cells: Option<usize>,
    operation: &'static str,
    (one, many): (&str, &str),
    invalid: impl Fn(f64) -> Option<String>,
    error: impl Fn(usize, String) -> Error,
) -> Result<Vec<f64>> {
    // 1 MiB of comments and 256 bytes a value. Checked on the length reported (a long
    // file is refused unread) and on the bytes read (a device reports 0).
    let limit = cells.map(|c| (1u64 << 20).saturating_add((c as u64).saturating_mul(256)));
    let too_long = |size: &str| {
        error(
            0,
            format!(
                "the file has {size} bytes, more than the {} bytes that {} {many} (one per \
                 cell) and their comments may take",
                limit.unwrap_or_default(),
                cells.unwrap_or_default()
            ),
        )
    };
    let size = std::fs::metadata(path)
        .map_err(|e| Error::io(operation, path, e))?
        .len();
    if limit.is_some_and(|l| size > l) {
        return Err(too_long(&size.to_string()));
    }
    // The text and the values (8 bytes each, from at least 2 bytes of text) within the
    // memory available.
    let bytes = crate::files::read_bytes(path, operation)?;
    if limit.is_some_and(|l| bytes.len() as u64 > l) {
        return Err(too_long(&format!("at least {}", bytes.len())));
    }
    let text = match std::str::from_utf8(&bytes) {
        Ok(text) => text,
        Err(e) => {
            let prefix = &bytes[..e.valid_up_to()];
            let line = prefix.iter().filter(|b| **b == b'\n').count() + 1;
            return Err(error(
                line,
                format!(
                    "the file is not UTF-8 text: byte {} (0x{:02x}) is not valid UTF-8",
                    e.valid_up_to(),
                    bytes[e.valid_up_to()]
                ),
            ));
        }
    };
    let mut values = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |reason: String| error(number + 1, reason);
        if cells.is_some_and(|cells| values.len() == cells) {
            return Err(bad(format!(
                "one {one} more than the grid's {} cells",
                values.len()
            )));
        }
        let value: f64 = line.parse().map_err(|e| {
            // A line may be megabytes long: its start says enough.
            let start: String = line.chars().take(40).collect();
            let cut = if start.len() < line.len() { "..." } else { "" };
            bad(format!("{start:?}{cut} is not a number ({e})"))
        })?;
        if let Some(reason) = invalid(value) {
            return Err(bad(reason));
        }
        values.push(value);
    }
    if values.is_empty() {
        return Err(error(0, format!("the file holds no {many}")));
    }
    Ok(values)
}

/// Where a map of per-site values comes from: a friction coefficient (dimensionless),
/// `c_x` (N/m³) or `c_z` (N/m²) per site in place of the scalar of the material or the
/// spring law ([`SceneBuilder::friction_map`], [`SceneBuilder::c_x_map`],
/// [`SceneBuilder::c_z_map`]; the scene-file key `maps`, docs/scene-format.md). Each value
/// must lie in its scalar's range (docs/scene-format.md, "Valid ranges"); the scene refuses
/// others naming the key and the site ([`Error::MapValue`]).
///
/// ```
/// use precursors::{Drive, Scene, SiteMap, SurfaceSpectrum};
/// let base = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells: 40 sites
///     .normal_load(40.0)                // F_N (N)
///     .drive(Drive::top());
/// // μ from 0.4 to 0.6 along x, one value per cell in the order i = iy·Nx + ix.
/// let mu: Vec<f64> = (0..40).map(|i| 0.4 + 0.2 * (i % 10) as f64 / 9.0).collect();
/// let scene = base.clone().friction_map(SiteMap::Values(mu.clone())).build()?;
/// assert_eq!(scene.interface().friction_map(), Some(&mu[..]));
/// // c_x from the surface generator: ξ = 2 mm, mean 1.65e12 N/m³, sd 20 %, its own seed.
/// let c_x = SiteMap::Surface {
///     spectrum: SurfaceSpectrum::gaussian(2e-3)?,
///     mean: 1.65e12,
///     std_dev: 0.33e12,
///     seed: 9,
/// };
/// let scene = base.clone().c_x_map(c_x).build()?;
/// assert!(scene.interface().c_x_map().unwrap().iter().all(|&c| c > 0.0));
/// // A map of the wrong size, or with a value out of its scalar's range, is refused.
/// assert!(base.clone().friction_map(SiteMap::Values(vec![0.5; 39])).build().is_err());
/// assert!(base.friction_map(SiteMap::Values(vec![1e9; 40])).build().is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "file::MapSpec", into = "file::MapSpec")
)]
#[non_exhaustive]
pub enum SiteMap {
    /// One value per site, in the paper's cell order `i = iy·Nx + ix` (in the unit of
    /// the scalar it replaces).
    Values(Vec<f64>),
    /// A random map from the heights' generator ([`Heights::random_surface`]) with its
    /// own seed: a Gaussian field of the spectrum's correlation, mapped onto a Gaussian
    /// of `mean` and `std_dev` truncated at 0, averaged over each cell. The same seed
    /// gives the same map at every cell size and, bit for bit, on every machine (a test
    /// pins values); with the heights' seed and spectrum it is the heights' field (fully
    /// correlated with them). Scene-file kinds `gaussian_surface` and
    /// `self_affine_surface`.
    Surface {
        /// The power spectrum of the field.
        spectrum: SurfaceSpectrum,
        /// Mean of the Gaussian before truncation at 0 (in the scalar's unit; within the
        /// scalar's range).
        mean: f64,
        /// Standard deviation of the Gaussian before truncation (`>= 0`; `0`: every
        /// site the mean).
        std_dev: f64,
        /// Seed of the field's Fourier coefficients.
        seed: u64,
    },
}

impl SiteMap {
    /// A map read from a text file: one value per line in the paper's cell order
    /// `i = iy·Nx + ix`; blank lines and lines starting with `#` are skipped. Each value
    /// must be finite and `> 0`; the count and the ranges are checked against the scene
    /// at [`SceneBuilder::build`].
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read (with its path); [`Error::MapFile`]
    /// (key `maps`) for a line that is not a finite value `> 0`, or no value at all.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<SiteMap> {
        Self::read_file(path.as_ref(), None, "maps", (0.0, f64::INFINITY), "")
    }

    /// [`SiteMap::from_file`] for the scene-file key `key` on a grid of `cells` cells
    /// (when known: a longer file is refused before it is read whole): each value within
    /// `range` (in `unit`).
    pub(crate) fn read_file(
        path: &std::path::Path,
        cells: Option<usize>,
        key: &'static str,
        (min, max): (f64, f64),
        unit: &str,
    ) -> Result<SiteMap> {
        read_values(
            path,
            cells,
            "reading map file",
            ("value", "values"),
            |value| {
                let valid = value.is_finite() && value > 0.0 && (min..=max).contains(&value);
                (!valid).then(|| {
                    format!(
                        "{value}{}{unit} is not a value of {key}: finite and > 0{}",
                        if unit.is_empty() { "" } else { " " },
                        if max.is_finite() {
                            format!(", within [{min:e}, {max:e}]")
                        } else {
                            String::new()
                        }
                    )
                })
            },
            |line, reason| Error::MapFile {
                key,
                path: path.to_path_buf(),
                line,
                reason,
            },
        )
        .map(SiteMap::Values)
    }

    /// The map's values on `grid`, one per site in cell order `i = iy·Nx + ix`: given
    /// ones as they are, a random map's drawn (`O(N log N)` work), as a scene on `grid`
    /// takes them (`precursors info` prints their mean, spread and extremes). Neither
    /// their count nor their range is checked here ([`SceneBuilder::build`] does).
    ///
    /// ```
    /// use precursors::{Block, Grid, SiteMap, SurfaceSpectrum};
    /// let grid = Grid::new(Block::new(0.010, 0.004, 0.010)?, 10, 4)?;
    /// let map = SiteMap::Surface {
    ///     spectrum: SurfaceSpectrum::gaussian(2e-3)?,      // ξ = 2 mm
    ///     mean: 0.5,
    ///     std_dev: 0.0,                                    // no spread: the mean everywhere
    ///     seed: 7,
    /// };
    /// assert!(map.values(&grid)?.iter().all(|&mu| (mu - 0.5).abs() < 1e-12));
    /// assert_eq!(SiteMap::Values(vec![0.4; 40]).values(&grid)?, vec![0.4; 40]);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// Those of the surface generator ([`Error::SurfaceTooLarge`], [`Error::OutOfMemory`]).
    pub fn values(&self, grid: &Grid) -> Result<Vec<f64>> {
        match self {
            SiteMap::Values(values) => Ok(values.clone()),
            SiteMap::Surface {
                spectrum,
                mean,
                std_dev,
                seed,
            } => crate::surface::Plan::new(grid, spectrum)?.cell_averages(
                grid,
                &crate::surface::Truncated::new(*mean, *std_dev),
                *seed,
            ),
        }
    }
}

impl From<Vec<f64>> for SiteMap {
    /// One value per site in cell order `i = iy·Nx + ix` ([`SiteMap::Values`]), validated
    /// at [`SceneBuilder::build`].
    fn from(values: Vec<f64>) -> Self {
        SiteMap::Values(values)
    }
}

/// The maps a scene gives, by key ([`MAP_KEYS`]): `None` takes the scalar.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct SiteMaps(pub(crate) [Option<SiteMap>; 3]);

/// The keys of the maps, in the order of [`SiteMaps`]: the friction coefficient, `c_x`,
/// `c_z`.
pub(crate) const MAP_KEYS: [&str; 3] = ["friction_coefficient", "c_x", "c_z"];

/// The friction coefficient that normalises the loads `F/(μF_N)` and bounds a stable
/// state's `F ≤ μF_N`: the material's `μ`, or the friction map's largest value where it
/// is larger (docs/model.md, "Maps").
pub(crate) fn friction_limit(mu: f64, map: Option<&[f64]>) -> f64 {
    map.map_or(mu, |m| m.iter().fold(mu, |a, &b| a.max(b)))
}

impl From<Vec<f64>> for HeightSource {
    /// Given heights (m) in cell order `i = iy·Nx + ix`
    /// ([`HeightSource::Values`]), validated at [`SceneBuilder::build`].
    fn from(values: Vec<f64>) -> Self {
        HeightSource::Values(values)
    }
}

impl From<Heights> for HeightSource {
    /// Heights already validated ([`Heights::try_from`], [`Heights::from_values`]); the
    /// count is checked against the grid at [`SceneBuilder::build`].
    fn from(heights: Heights) -> Self {
        HeightSource::Values(heights.values().to_vec())
    }
}

/// The heights' seed of a scene that gives none (the calibration scene's): the builder's,
/// [`HeightSource::default`]'s and the scene file's `heights.seed` default.
pub(crate) const DEFAULT_SEED: u64 = 1;

impl Default for HeightSource {
    /// The paper's Gaussian heights ([`HeightDistribution::default`]) from seed 1.
    fn default() -> Self {
        HeightSource::Random {
            distribution: HeightDistribution::default(),
            seed: DEFAULT_SEED,
        }
    }
}

/// How the face is cut into cells.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cells {
    Size(f64, f64),
    Count(usize, usize),
}

/// Builder of a [`Scene`]; every field has the paper's default (calibration scene,
/// seed 1). With the `serde` feature it reads and writes the JSON scene format
/// (`docs/scene-format.md`): `SceneBuilder::from_json_file`, `SceneBuilder::to_json`.
///
/// ```
/// use precursors::{Error, Material, Scene};
/// // The defaults are the paper's calibration scene: its grid, checked without planning.
/// let grid = Scene::builder().grid()?;
/// assert_eq!((grid.nx(), grid.ny()), (140, 7));                // 1 mm cells
/// // A small block of a softer material.
/// let builder = Scene::builder()
///     .block(0.010, 0.004, 0.010)                              // Lx, Ly, Lz (m)
///     .cells(10, 4)                                            // Nx, Ny
///     .material(Material::new(2e9, 0.35, 0.6)?)                // E (Pa), ν, μ
///     .normal_load(40.0)                                       // F_N (N)
///     .seed(3);                                                // the heights' realization
/// assert_eq!(builder.check()?.len(), 40);                      // everything but the plan
/// let scene = builder.clone().build()?;
/// assert_eq!(scene.material().friction_coefficient(), 0.6);
/// // An invalid value is refused at build, naming it.
/// let refused = builder.normal_load(-1.0).build();
/// assert!(matches!(refused, Err(Error::InvalidParameter { name: "normal_load", .. })));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone)]
#[must_use]
pub struct SceneBuilder {
    lengths: (f64, f64, f64),
    cells: Cells,
    material: Material,
    law: SpringLaw,
    heights: HeightSource,
    // The seed of `seed()`: kept so that a later `heights()` of a random kind takes it,
    // and given values refuse it at `check()`, whatever the order of the calls.
    seed: Option<u64>,
    normal_load: f64,
    drive: Drive,
    solver: SolverOptions,
    plan_tolerance: f64,
    probes: ProbeSpec,
    max_cells: usize,
    run: RunOptions,
    confirm_metres: bool,
    /// The rule of the site transitions (scene-file key `contact`).
    contact: ContactRule,
    /// Per-site maps of μ, c_x, c_z (scene-file key `maps`).
    maps: SiteMaps,
}

impl PartialEq for SceneBuilder {
    /// The same scene: the seed of [`SceneBuilder::seed`] counts through the heights it
    /// seeded (and as a seed given with given heights, which `build` refuses).
    fn eq(&self, other: &Self) -> bool {
        let refused = |b: &Self| match b.heights {
            HeightSource::Values(_) => b.seed,
            _ => None,
        };
        self.lengths == other.lengths
            && self.cells == other.cells
            && self.material == other.material
            && self.law == other.law
            && self.heights == other.heights
            && refused(self) == refused(other)
            && self.normal_load == other.normal_load
            && self.drive == other.drive
            && self.solver == other.solver
            && self.plan_tolerance == other.plan_tolerance
            && self.probes == other.probes
            && self.max_cells == other.max_cells
            && self.run == other.run
            && self.confirm_metres == other.confirm_metres
            && self.contact == other.contact
            && self.maps == other.maps
    }
}

impl Default for SceneBuilder {
    fn default() -> Self {
        Self {
            lengths: (0.140, 0.007, 0.075),
            cells: Cells::Size(1e-3, 1e-3),
            material: Material::default(),
            law: SpringLaw::default(),
            heights: HeightSource::default(),
            seed: None,
            normal_load: 3.5e3,
            drive: Drive::default(),
            solver: SolverOptions::default(),
            plan_tolerance: 1e-8,
            probes: ProbeSpec::default(),
            max_cells: crate::green::DEFAULT_MAX_CELLS,
            run: RunOptions::default(),
            confirm_metres: false,
            contact: ContactRule::Paper,
            maps: SiteMaps::default(),
        }
    }
}

impl SceneBuilder {
    /// Block lengths `Lx, Ly, Lz` (m; default 140 x 7 x 75 mm).
    pub fn block(mut self, lx: f64, ly: f64, lz: f64) -> Self {
        self.lengths = (lx, ly, lz);
        self
    }

    /// Cell size `Δx, Δy` (m; default 1 mm); must divide the face.
    pub fn cell_size(mut self, dx: f64, dy: f64) -> Self {
        self.cells = Cells::Size(dx, dy);
        self
    }

    /// Cell counts `Nx, Ny` instead of a cell size.
    pub fn cells(mut self, nx: usize, ny: usize) -> Self {
        self.cells = Cells::Count(nx, ny);
        self
    }

    /// Material (default PMMA, `μ = 0.5`).
    pub fn material(mut self, material: Material) -> Self {
        self.material = material;
        self
    }

    /// Spring constants `c_x` (N/m³), `c_z` (N/m²) and the area law (default the paper's).
    pub fn springs(mut self, law: SpringLaw) -> Self {
        self.law = law;
        self
    }

    /// The real-contact-area law of the springs (default [`AreaLaw::Paper`]); the
    /// constants set by [`SceneBuilder::springs`] stay. It changes the outputs (areas,
    /// precursor lengths), not the events.
    pub fn area_law(mut self, area_law: AreaLaw) -> Self {
        self.law = self.law.with_area_law(area_law);
        self
    }

    /// Heights source (default: paper Gaussian, seed 1). A seed given by
    /// [`SceneBuilder::seed`], before or after, replaces the seed of a random source;
    /// given values replace the random heights, a seed given before included.
    pub fn heights(mut self, heights: HeightSource) -> Self {
        self.heights = match (self.seed, &heights) {
            (Some(seed), HeightSource::Random { .. } | HeightSource::Surface { .. }) => {
                heights.reseeded(seed)
            }
            (_, HeightSource::Values(_)) => {
                self.seed = None;
                heights
            }
            _ => heights,
        };
        self
    }

    /// The seed of random heights (default 1): the paper's Gaussian heights (mean 1 µm,
    /// sd 1 µm, truncated at 0) unless [`SceneBuilder::heights`] gives another random
    /// source ([`HeightSource::Random`] with another distribution, or
    /// [`HeightSource::Surface`]), which keeps its distribution and spectrum and takes
    /// this seed. The order of the two calls does not matter: `.heights(surface).seed(5)`
    /// and `.seed(5).heights(surface)` are the same surface, from seed 5. Given heights
    /// ([`HeightSource::Values`], a heights file) take no seed: set after a seed they
    /// replace the random heights, seed included; a seed set after them is refused at
    /// [`SceneBuilder::check`] and [`SceneBuilder::build`] ([`Error::InvalidCount`]
    /// naming `seed`; it replaced them with the paper's Gaussian heights before 1.1).
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = Some(seed);
        if !matches!(self.heights, HeightSource::Values(_)) {
            self.heights = self.heights.reseeded(seed);
        }
        self
    }

    /// Normal load `F_N` (N, finite and > 0; default 3.5 kN).
    pub fn normal_load(mut self, normal_load: f64) -> Self {
        self.normal_load = normal_load;
        self
    }

    /// The shear drive (default: rod at 6 mm, Δh = 2 mm, force control).
    pub fn drive(mut self, drive: Drive) -> Self {
        self.drive = drive;
        self
    }

    /// Options of the equilibrium solvers (scene-file object `solver`; the same method
    /// name as [`crate::solver::EquilibriumSolverBuilder::solver_options`]).
    pub fn solver_options(mut self, options: SolverOptions) -> Self {
        self.solver = options;
        self
    }

    /// The most cells [`SceneBuilder::build`] accepts (default
    /// [`DEFAULT_MAX_CELLS`](crate::green::DEFAULT_MAX_CELLS) = `1e6`; scene-file key
    /// `max_cells`): a larger grid is refused with [`Error::GridTooLarge`] and its
    /// estimated memory and time ([`crate::GridCost`]) before anything is allocated.
    /// Raise it for a grid whose cost you accept; it does not change results.
    pub fn max_cells(mut self, max_cells: usize) -> Self {
        self.max_cells = max_cells;
        self
    }

    /// Confirms a block of a metre or more under a mean normal pressure below `1e-6` of
    /// Young's modulus (scene-file key `confirm_metres`; default `false`). Without it such
    /// a scene is refused with [`Error::LikelyMillimetres`]: its numbers point to lengths
    /// typed in millimetres. It does not change results.
    ///
    /// ```
    /// use precursors::{Error, Scene};
    /// // 140 x 7 x 75 "m" at the calibration's 3.5 kN: 3.6 Pa, millimetres most likely.
    /// let mm = Scene::builder().block(140.0, 7.0, 75.0).cell_size(1.0, 1.0);
    /// assert!(matches!(mm.clone().check(), Err(Error::LikelyMillimetres { .. })));
    /// assert!(mm.confirm_metres(true).check().is_ok());
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn confirm_metres(mut self, confirm: bool) -> Self {
        self.confirm_metres = confirm;
        self
    }

    /// The rule of the site transitions (scene-file key `contact`; default
    /// [`ContactRule::Paper`]): a built-in rule, or a downstream crate's
    /// ([`ContactRule::custom`], which gives up scene files and checkpoints:
    /// [`crate::ContactLaw`]). Checked by [`SceneBuilder::check`]: a re-forming built-in
    /// rule needs a valid [`crate::Delay`] and a force drive.
    ///
    /// ```
    /// use precursors::{ContactRule, Error, Scene};
    /// let anchored = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .contact_rule(ContactRule::Anchored)
    ///     .build()?;
    /// assert_eq!(anchored.contact_rule(), &ContactRule::Anchored);
    /// # Ok::<(), Error>(())
    /// ```
    pub fn contact_rule(mut self, rule: ContactRule) -> Self {
        self.contact = rule;
        self
    }

    /// The rule of the site transitions given ([`SceneBuilder::contact_rule`]).
    pub(crate) fn contact(&self) -> &ContactRule {
        &self.contact
    }

    /// A friction coefficient per site in place of the material's `μ` (scene-file key
    /// `maps.friction_coefficient`; default none): site `i` breaks at
    /// `|φ_x,i| = μ_i φ_z,i`. The material's `μ` stays the scene's reference: the loads
    /// `F/(μF_N)` of the tables are normalised by the larger of it and the map's largest
    /// value, the friction limit no stable state exceeds ([`crate::Driver::friction_limit`]);
    /// the stress probes' Coulomb stress and a rejuvenation delay's load use it. Each value
    /// within the scalar's range ([`SiteMap`]); checked at [`SceneBuilder::check`] (given
    /// values) and [`SceneBuilder::build`] (drawn ones).
    pub fn friction_map(mut self, map: SiteMap) -> Self {
        self.maps.0[0] = Some(map);
        self
    }

    /// `c_x` (N/m³) per site in place of the spring law's (scene-file key `maps.c_x`;
    /// default none): `k_x,i = c_x,i exp(-u_z,i/u0_i)`. Checked as
    /// [`SceneBuilder::friction_map`].
    pub fn c_x_map(mut self, map: SiteMap) -> Self {
        self.maps.0[1] = Some(map);
        self
    }

    /// `c_z` (N/m²) per site in place of the spring law's (scene-file key `maps.c_z`;
    /// default none): `k_z,i = c_z,i / u0_i`. Checked as [`SceneBuilder::friction_map`];
    /// the normal load's bound `F_N ≤ 650 ΔA c_z` takes the map's smallest value.
    pub fn c_z_map(mut self, map: SiteMap) -> Self {
        self.maps.0[2] = Some(map);
        self
    }

    /// The friction coefficient that normalises the loads of the scene's tables
    /// ([`friction_limit`]): the material's `μ`, or the friction map's largest value
    /// (drawn for a random map) where larger.
    ///
    /// # Errors
    /// Those of [`SceneBuilder::grid`] and of the surface generator, for a random map.
    #[cfg(feature = "serde")] // the row checks of a run directory read it
    pub(crate) fn limit_friction_coefficient(&self) -> Result<f64> {
        let mu = self.material.friction_coefficient();
        match &self.maps.0[0] {
            None => Ok(mu),
            Some(map) => Ok(friction_limit(mu, Some(&map.values(&self.grid()?)?))),
        }
    }

    /// The maps set so far (see [`SceneBuilder::current_springs`]).
    pub(crate) fn current_maps(&self) -> &SiteMaps {
        &self.maps
    }

    /// `interface` with the scene's maps, drawn and checked: each value in its scalar's
    /// range, and the normal load within the bound of the smallest `c_z`.
    fn with_maps(&self, mut interface: Interface, grid: &Grid) -> Result<Interface> {
        for (k, map) in self.maps.0.iter().enumerate() {
            let Some(map) = map else { continue };
            let values = map.values(grid)?;
            bounds::map_values(k, &values, grid.len())?;
            interface = match k {
                0 => interface.with_friction_map(values)?,
                1 => interface.with_c_x_map(values)?,
                _ => interface.with_c_z_map(values)?,
            };
        }
        if let Some(c_z) = interface.c_z_map() {
            bounds::load_exponent(self, grid, c_z.iter().fold(f64::INFINITY, |a, &b| a.min(b)))?;
        }
        Ok(interface)
    }

    /// The plan tolerance (scene-file key `plan_tolerance`): the largest relative error
    /// accepted on the influence operator's eigenvalues (dimensionless, default `1e-8`, as
    /// [`crate::green::InfluencePlanBuilder::plan_tolerance`]; not the solver's linear
    /// tolerance, [`crate::solver::SolverOptions::tolerance`]): they are computed to about
    /// 1e-13 whatever it is (`docs/accuracy.md`). The lateral load
    /// table is always summed to `1e-12` relative (closed forms, cheap).
    pub fn plan_tolerance(mut self, plan_tolerance: f64) -> Self {
        self.plan_tolerance = plan_tolerance;
        self
    }

    /// The stress probes every driver of the scene starts with (planes and points,
    /// default none): planned and validated at build, read with
    /// [`crate::Driver::stresses`]. A driver adds more at any time with
    /// [`crate::Driver::add_probes`]. The probes are not part of the scene's identity: a
    /// checkpoint resumes on the scene with other probes. The scene file's key `probes`;
    /// [`RunOptions::probes`] gives a run other probes (docs/compatibility.md,
    /// "Observers").
    pub fn probes(mut self, probes: ProbeSpec) -> Self {
        self.probes = probes;
        self
    }

    /// What a run of the scene records beside its three tables (default: nothing; the
    /// scene file's keys `fields` and `profiles`): the options
    /// [`crate::output::RunTables::create`] takes for its run (`create_with` takes
    /// others). Recording observes: it changes neither the events nor the scene's
    /// identity (a checkpoint resumes across it; the resumed tables are checked against
    /// it). Checked when the scene is built, each refusal naming its key.
    ///
    /// ```
    /// use precursors::{RunOptions, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .run_options(RunOptions::new().record_fields(5, &[0.0, 0.005]))
    ///     .build()?;
    /// assert_eq!(scene.run_options().fields_every(), 5);
    /// assert_eq!(scene.run_options().field_planes(), [0.0, 0.005]);
    /// // Outside the block: refused when the scene is built.
    /// let outside = RunOptions::new().record_profiles(&[0.5], &[0.02]);
    /// assert!(Scene::builder().block(0.010, 0.004, 0.010).run_options(outside).build().is_err());
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn run_options(mut self, options: RunOptions) -> Self {
        self.run = options;
        self
    }

    /// Records the fields of the run's stable states for the movies: as
    /// [`RunOptions::record_fields`] in [`SceneBuilder::run_options`].
    #[deprecated(
        since = "1.1.0",
        note = "what a run records is a `RunOptions`: \
                `.run_options(RunOptions::new().record_fields(every, planes))`"
    )]
    pub fn record_fields(mut self, every: usize, planes: &[f64]) -> Self {
        self.run = self.run.record_fields(every, planes);
        self
    }

    /// What the scene's observers cost on its grid ([`RunOptions::cost`]): the tables
    /// its run options record, and every plane and point it plans (the run options'
    /// and, where the run options give their own probes, the scene's too). `precursors
    /// info` prints it; a run is refused above [`RunOptions::max_output_bytes`].
    ///
    /// ```
    /// use precursors::{RunOptions, Scene};
    /// let builder = Scene::builder() // the calibration block, 140 x 7 cells
    ///     .run_options(RunOptions::new().record_fields(10, &[0.01]));
    /// let cost = builder.observer_cost()?;
    /// // At most 99 recorded states of 7 area rows and 1 plane row, 140 values each.
    /// assert!(cost.fields_bytes > 99.0 * 8.0 * 140.0 * 17.0);
    /// assert!(cost.fields_bytes < 99.0 * 8.0 * (140.0 * 21.0 + 100.0));
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// Those of [`SceneBuilder::grid`].
    pub fn observer_cost(&self) -> Result<crate::recording::ObserverCost> {
        Ok(bounds::observer_cost(self, &self.grid()?))
    }

    /// The probes a scene built from this builder starts its drivers with: the run
    /// options' where given, else those of [`SceneBuilder::probes`].
    pub(crate) fn effective_probes(&self) -> &ProbeSpec {
        self.run.probe_spec().unwrap_or(&self.probes)
    }

    /// The spring constants set so far (the builder's getters are the crate's; users
    /// read them from the built [`Scene::springs`]: a getter cannot share its setter's
    /// name on the builder).
    pub(crate) fn current_springs(&self) -> SpringLaw {
        self.law
    }

    /// The normal load set so far (N; see [`SceneBuilder::current_springs`]).
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub(crate) fn current_normal_load(&self) -> f64 {
        self.normal_load
    }

    /// The run options set so far (see [`SceneBuilder::current_springs`]).
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub(crate) fn current_run(&self) -> &RunOptions {
        &self.run
    }

    /// The heights source set so far (see [`SceneBuilder::current_springs`]).
    pub(crate) fn current_heights(&self) -> &HeightSource {
        &self.heights
    }

    /// The block and grid of the scene, validated (and the cell limit checked) without
    /// building anything else: e.g. to print a scene's size and [`crate::GridCost`]
    /// before running it. [`SceneBuilder::check`] checks the rest of the scene too.
    ///
    /// # Errors
    /// The first invalid length or cell size or count; [`Error::GridTooLarge`] above
    /// [`SceneBuilder::max_cells`], or [`Error::LengthInMillimetres`] holding it when the
    /// cells are given by size and a block length is 1 m or more; [`Error::OutOfRange`] (naming the scene-file key) for
    /// a length, an aspect ratio or a cell size outside the ranges of
    /// `docs/scene-format.md` ("Valid ranges").
    pub fn grid(&self) -> Result<Grid> {
        bounds::geometry(self)?;
        let (lx, ly, lz) = self.lengths;
        let block = Block::new(lx, ly, lz)?;
        let grid = match self.cells {
            Cells::Size(dx, dy) => Grid::from_cell_size(block, dx, dy)?,
            Cells::Count(nx, ny) => Grid::new(block, nx, ny)?,
        };
        crate::cost::check_cells(grid.nx(), grid.ny(), self.max_cells).map_err(|e| {
            // Cells of a given size and a length of a metre or more: millimetres typed as
            // metres, most likely.
            let lengths = [("block.lx", lx), ("block.ly", ly), ("block.lz", lz)];
            match lengths.into_iter().find(|&(_, v)| v >= 1.0) {
                Some((key, value)) if matches!(self.cells, Cells::Size(..)) => {
                    Error::LengthInMillimetres {
                        key,
                        value,
                        source: Box::new(e),
                    }
                }
                _ => e,
            }
        })?;
        Ok(grid)
    }

    /// Everything [`SceneBuilder::build`] checks but the operator's plan, without the
    /// allocations of a scene: every value's sign, finiteness and range
    /// (`docs/scene-format.md`, "Valid ranges"), the heights (a count of values against
    /// the grid; random heights are not drawn), the drive's band, and the memory the scene
    /// would need against the memory available (Linux). A scene that passes is refused by
    /// `build` only when its plan does not reach [`SceneBuilder::plan_tolerance`] (below
    /// about `2e-13`) or the probes' sums do not converge ([`Error::SeriesNotConverged`]), or a
    /// point probe lies on an edge of the rod's band at `x = 0`
    /// ([`Error::SingularPoint`]). Returns the grid.
    ///
    /// # Errors
    /// The first invalid value, as [`SceneBuilder::build`] reports it: the errors of
    /// [`SceneBuilder::grid`]; [`Error::InvalidParameter`], [`Error::InvalidTolerance`],
    /// [`Error::InvalidCount`], [`Error::LengthMismatch`], [`Error::NonFinite`],
    /// [`Error::NonPositiveHeight`], [`Error::RodBandOutsideFace`],
    /// [`Error::DenseThreads`] for values the model cannot take; [`Error::OutOfRange`]
    /// (naming the scene-file key, with the valid range) for values it cannot honour;
    /// [`Error::OutOfMemory`] when the scene would need more memory than is available.
    pub fn check(&self) -> Result<Grid> {
        let grid = self.grid()?;
        let block = *grid.block();
        crate::green::check_memory(
            || format!("a scene of {} x {} cells", grid.nx(), grid.ny()),
            bounds::memory_bytes(self, &grid),
            "use fewer cells (or fewer probes), or a machine with more memory",
        )?;
        check_tolerance(self.plan_tolerance)?;
        check_contact_rule(&self.contact, self.drive)?;
        if !(self.normal_load.is_finite() && self.normal_load > 0.0) {
            return Err(Error::InvalidParameter {
                name: "normal_load",
                value: self.normal_load,
                reason: "the normal load must be finite and > 0 N",
            });
        }
        if let (HeightSource::Values(_), Some(seed)) = (&self.heights, self.seed) {
            return Err(Error::InvalidCount {
                name: "seed",
                value: seed,
                reason: "given heights (values or a heights file) take no seed: leave the \
                         seed out, or give random heights",
            });
        }
        match &self.heights {
            HeightSource::Values(v) => Heights::check_values(&grid, v)?,
            HeightSource::Surface { spectrum, .. } => {
                crate::surface::Plan::new(&grid, spectrum)?;
            }
            HeightSource::Random { .. } => {}
        }
        match self.drive {
            Drive::Force(ForceLoad::Mixed { ratio, .. })
                if !(ratio.is_finite() && ratio >= 0.0) =>
            {
                return Err(Error::InvalidParameter {
                    name: "drive.ratio",
                    value: ratio,
                    reason: "the mixed-load ratio n = F_top/F_lat must be finite and >= 0",
                });
            }
            Drive::Spring { stiffness, .. } if !(stiffness.is_finite() && stiffness > 0.0) => {
                return Err(Error::InvalidParameter {
                    name: "drive.stiffness",
                    value: stiffness,
                    reason: "the driving spring's stiffness K_S must be finite and > 0 N/m",
                });
            }
            _ => {}
        }
        if let Some(Lateral::Rod { height, half_width }) = self.lateral() {
            RodLoad::new(&block, height, half_width)?;
        }
        // The planes' heights and the points: `bounds::physics`, naming their key.
        bounds::physics(self, &grid)?;
        Ok(grid)
    }

    /// The lateral part of the drive, if any.
    fn lateral(&self) -> Option<Lateral> {
        match self.drive {
            Drive::Force(ForceLoad::Top) => None,
            Drive::Force(ForceLoad::Lateral(l))
            | Drive::Force(ForceLoad::Mixed { lateral: l, .. })
            | Drive::Spring { lateral: l, .. } => Some(l),
        }
    }

    /// Everything [`SceneBuilder::build`] checks before planning the operator
    /// ([`SceneBuilder::check`]), with the block, grid, heights (drawn: `O(N)`) and
    /// lateral load.
    pub(crate) fn checked(&self) -> Result<(Block, Grid, Heights, Option<Lateral>)> {
        let grid = self.check()?;
        let block = *grid.block();
        let heights = match &self.heights {
            HeightSource::Random { distribution, seed } => {
                Heights::truncated_gaussian(&grid, *distribution, *seed)?
            }
            HeightSource::Values(v) => Heights::from_values(&grid, v.clone())?,
            HeightSource::Surface {
                spectrum,
                distribution,
                seed,
            } => Heights::random_surface(&grid, *spectrum, *distribution, *seed)?,
        };
        Ok((block, grid, heights, self.lateral()))
    }

    /// Validates everything and plans the operator (`O(N)` eigenvalues).
    ///
    /// # Errors
    /// The first invalid option, as a typed [`Error`] naming it.
    pub fn build(self) -> Result<Scene> {
        self.build_with_planner(&Planner::new())
    }

    /// [`SceneBuilder::build`] with the operator from `planner`: scenes of one geometry
    /// (block, cells, plan tolerance) share one plan, planned once, e.g. realizations of
    /// the heights or sweeps over loads and drives.
    ///
    /// # Errors
    /// As [`SceneBuilder::build`].
    pub fn build_with_planner(mut self, planner: &Planner) -> Result<Scene> {
        let (lx, ly, lz) = self.lengths;
        let (block, grid, heights, lateral) = self.checked()?;
        let plan = planner.plan_with_max_cells(grid, self.plan_tolerance, self.max_cells)?;
        // Displacement per newton of the lateral load, cell-averaged (m/N): only built
        // when a lateral load exists.
        let rod = match lateral {
            None => None,
            Some(Lateral::Rod { height, half_width }) => {
                Some(RodLoad::new(&block, height, half_width)?)
            }
            Some(Lateral::Side) => Some(RodLoad::uniform_side(&block)),
        };
        let lateral_response = match &rod {
            None => None,
            Some(rod) => {
                let scale = lx / (ly * lz);
                let columns = rod.influence_cells(&grid, LATERAL_TOLERANCE * scale)?;
                let m = self.material.modulus();
                let mut cells = Vec::with_capacity(grid.len());
                for _ in 0..grid.ny() {
                    cells.extend(columns.iter().map(|v| v / m));
                }
                Some(cells)
            }
        };
        let interface = self.with_maps(Interface::new(grid, heights, self.law)?, &grid)?;
        let limit_mu = friction_limit(
            self.material.friction_coefficient(),
            interface.friction_map(),
        );
        // The seed is in the heights now: `to_builder` then takes given values.
        self.seed = None;
        let probe = plan_probes(&plan, self.effective_probes(), rod.as_ref())?;
        Ok(Scene {
            inner: std::sync::Arc::new(Built {
                probe,
                rod,
                grid,
                interface,
                plan,
                lateral_response,
                limit_mu,
                builder: self,
            }),
        })
    }
}

/// `spec` planned on `plan` (`None` when it has no probe).
pub(crate) fn plan_probes(
    plan: &InfluencePlan,
    spec: &ProbeSpec,
    lateral: Option<&RodLoad>,
) -> Result<Option<StressProbe>> {
    if spec.is_empty() {
        Ok(None)
    } else {
        StressProbe::new(plan, spec, lateral).map(Some)
    }
}

/// A validated simulation set-up; [`Scene::driver`] runs it. A clone is cheap (the scene
/// is shared: its drivers hold it).
///
/// ```
/// use precursors::{Drive, ForceLoad, Scene};
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0)                // F_N (N)
///     .build()?;
/// assert_eq!(scene.grid().len(), 40);
/// assert_eq!(scene.material().friction_coefficient(), 0.5);   // PMMA, the paper's μ
/// assert_eq!(scene.interface().attached_count(), 40);         // every site in contact
/// assert!(scene.has_lateral_table());                          // the default rod drive
/// // A variant: the same set-up under a top shear.
/// let top = scene.to_builder().drive(Drive::Force(ForceLoad::Top)).build()?;
/// assert!(!top.has_lateral_table() && top.normal_load() == 40.0);
/// assert_eq!(top.interface().heights(), scene.interface().heights()); // same seed
/// // Drivers of one scene run the same events.
/// let (a, b) = (scene.driver()?, scene.clone().driver()?);
/// assert!(a.zip(b).all(|(a, b)| a.ok() == b.ok()));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Scene {
    inner: std::sync::Arc<Built>,
}

/// What a scene holds: what it was built from (its one form of the set-up: material,
/// loads, drive, solver options, probes) and what it built from it.
#[derive(Debug)]
struct Built {
    /// What the scene was built from (a checkpoint records it).
    builder: SceneBuilder,
    grid: Grid,
    interface: Interface,
    plan: InfluencePlan,
    lateral_response: Option<Vec<f64>>,
    /// The lateral load, if the drive has one (the probes' lateral term).
    rod: Option<RodLoad>,
    /// The default probes, planned at build.
    probe: Option<StressProbe>,
    /// The friction coefficient of the friction limit ([`friction_limit`]).
    limit_mu: f64,
}

impl Scene {
    /// A builder with the paper's calibration scene as defaults.
    pub fn builder() -> SceneBuilder {
        SceneBuilder::default()
    }

    /// The builder this scene was built from (for instance to write it as a scene file
    /// with the `serde` feature, or to vary one parameter).
    pub fn to_builder(&self) -> SceneBuilder {
        self.inner.builder.clone()
    }

    /// The grid (and through it the block).
    pub fn grid(&self) -> &Grid {
        &self.inner.grid
    }

    /// The material.
    pub fn material(&self) -> Material {
        self.inner.builder.material
    }

    /// The interface in its initial state (every site attached).
    pub fn interface(&self) -> &Interface {
        &self.inner.interface
    }

    /// The normal load `F_N` (N).
    pub fn normal_load(&self) -> f64 {
        self.inner.builder.normal_load
    }

    /// The drive.
    pub fn drive(&self) -> Drive {
        self.inner.builder.drive
    }

    /// The solver options ([`SceneBuilder::solver_options`]).
    pub fn solver_options(&self) -> SolverOptions {
        self.inner.builder.solver
    }

    /// The spring constants ([`SceneBuilder::springs`]).
    pub fn springs(&self) -> SpringLaw {
        self.inner.interface.law()
    }

    /// Where the heights came from ([`SceneBuilder::heights`], [`SceneBuilder::seed`]);
    /// the heights themselves are [`Interface::heights`] of [`Scene::interface`].
    pub fn heights(&self) -> &HeightSource {
        &self.inner.builder.heights
    }

    /// The planned influence operator.
    pub fn plan(&self) -> &InfluencePlan {
        &self.inner.plan
    }

    /// The stress probes every driver of the scene starts with: those of its run options'
    /// [`RunOptions::probes`] where given, else [`SceneBuilder::probes`] (empty by
    /// default).
    pub fn probes(&self) -> &ProbeSpec {
        self.inner.builder.effective_probes()
    }

    /// What a run of the scene records beside its tables
    /// ([`SceneBuilder::run_options`]; nothing by default).
    pub fn run_options(&self) -> &RunOptions {
        &self.inner.builder.run
    }

    /// Every how many stable states a run records its fields (0: none, the default).
    #[deprecated(since = "1.1.0", note = "use `scene.run_options().fields_every()`")]
    pub fn fields_every(&self) -> usize {
        self.inner.builder.run.fields_every()
    }

    /// The heights `z` (m) of the planes whose y-averaged Coulomb stress a run records.
    #[deprecated(since = "1.1.0", note = "use `scene.run_options().field_planes()`")]
    pub fn field_planes(&self) -> &[f64] {
        self.inner.builder.run.field_planes()
    }

    /// The default probes as planned at build (`None` when there are none).
    pub(crate) fn stress_probe(&self) -> Option<&StressProbe> {
        self.inner.probe.as_ref()
    }

    /// The friction coefficient of the friction limit `μF_N` ([`friction_limit`]): the
    /// material's `μ` unless the friction map has a larger value.
    pub(crate) fn limit_friction_coefficient(&self) -> f64 {
        self.inner.limit_mu
    }

    /// The rule of the site transitions ([`SceneBuilder::contact_rule`]; scene-file key
    /// `contact`).
    pub fn contact_rule(&self) -> &ContactRule {
        &self.inner.builder.contact
    }

    /// The lateral load of the drive, if any (the probes' lateral stress term).
    pub(crate) fn lateral_load(&self) -> Option<&RodLoad> {
        self.inner.rod.as_ref()
    }

    /// `(F_top, F_lat)` (N) per newton of the driven force `F`.
    pub(crate) fn load_split(&self) -> (f64, f64) {
        match self.drive() {
            Drive::Force(ForceLoad::Top) => (1.0, 0.0),
            Drive::Force(ForceLoad::Mixed { ratio, .. }) => {
                (ratio / (1.0 + ratio), 1.0 / (1.0 + ratio))
            }
            _ => (0.0, 1.0),
        }
    }

    /// Whether the scene built the lateral load table (only drives with a lateral part).
    pub fn has_lateral_table(&self) -> bool {
        self.inner.lateral_response.is_some()
    }

    /// Displacement `e` (m/N) of each cell per newton of the driven force in the absence
    /// of interface tractions: per newton of total shear `F` under force control, per
    /// newton of spring force under displacement control. `None` for a top shear (a
    /// constant, absorbed by `⟨u_x⟩`).
    pub(crate) fn unit_load_displacement(&self) -> Vec<f64> {
        match (&self.inner.lateral_response, self.drive()) {
            (Some(e), Drive::Force(ForceLoad::Mixed { ratio, .. })) => {
                e.iter().map(|v| v / (1.0 + ratio)).collect()
            }
            (Some(e), _) => e.clone(),
            (None, _) => vec![0.0; self.inner.grid.len()],
        }
    }
}

/// Refuses a contact rule the protocol cannot run: a re-forming rule's delay out of
/// range, or re-forming sites under a spring drive (its force drops at each rupture, so
/// sites may re-form for ever and the run never reach global slip).
fn check_contact_rule(rule: &ContactRule, drive: Drive) -> Result<()> {
    let Some(delay) = rule.delay() else {
        return Ok(());
    };
    delay.check()?;
    if let Drive::Spring { .. } = drive {
        return Err(Error::InvalidChoice {
            name: "contact.rule",
            value: "rejuvenation",
            reason: "under a spring drive the force drops at each rupture and re-formed sites \
                     may hold it below global slip for ever: drive by force (drive.kind \
                     \"force\"), or use the rule \"anchored\"",
        });
    }
    Ok(())
}

/// "Leave out what a given scene does not need" (docs/architecture.md, "What a scene leaves
/// out"): what a built scene holds follows its drive and its probes.
#[cfg(test)]
mod leaves_out {
    use super::*;
    use crate::green::built;

    fn small() -> SceneBuilder {
        Scene::builder()
            .block(0.010, 0.004, 0.010)
            .cells(10, 4)
            .seed(0)
    }

    #[test]
    fn a_top_drive_has_no_lateral_load_and_no_probes_no_transfer() {
        let top = small().drive(Drive::Force(ForceLoad::Top)).build().unwrap();
        assert!(top.inner.rod.is_none() && top.inner.lateral_response.is_none());
        assert!(top.inner.probe.is_none());
        let rod = small()
            .probes(ProbeSpec::default().with_plane(2e-3))
            .build()
            .unwrap();
        assert!(rod.inner.rod.is_some() && rod.inner.lateral_response.is_some());
        assert!(rod.inner.probe.is_some());
    }

    #[test]
    fn scenes_of_one_geometry_share_one_plan() {
        let planner = Planner::new();
        built::take();
        for seed in 1..=3 {
            small()
                .seed(seed)
                .normal_load(40.0 * seed as f64)
                .build_with_planner(&planner)
                .unwrap();
        }
        assert_eq!(built::take().plans, 1);
        // Another geometry gets its own plan; without a planner, each build plans.
        small().cells(5, 2).build_with_planner(&planner).unwrap();
        small().build().unwrap();
        assert_eq!(built::take().plans, 2);
    }

    #[test]
    fn a_scene_builds_only_the_load_series_and_transfers_it_uses() {
        let planes = || ProbeSpec::default().with_plane(2e-3).with_plane(5e-3);
        let top = || small().drive(Drive::Force(ForceLoad::Top));
        let cases = [
            (top(), (0, 0)),
            (top().probes(planes()), (0, 2)),
            // The rod's displacements; with probes, also its stresses on each plane.
            (small(), (1, 0)),
            (small().probes(planes()), (3, 2)),
        ];
        built::take();
        for (builder, (load_series, transfers)) in cases {
            builder.build().unwrap();
            let b = built::take();
            assert_eq!(
                (b.plans, b.load_series, b.transfers),
                (1, load_series, transfers)
            );
        }
    }

    #[test]
    fn a_driver_builds_no_plan_series_or_transfer_of_its_own() {
        let scene = small()
            .probes(ProbeSpec::default().with_plane(2e-3))
            .build()
            .unwrap();
        built::take();
        let mut driver = scene.driver().unwrap();
        for _ in 0..50 {
            if driver.step().unwrap().is_none() {
                break;
            }
        }
        driver.stresses().unwrap();
        let b = built::take();
        assert_eq!((b.plans, b.load_series, b.transfers), (0, 0, 0));
    }

    #[test]
    fn a_driver_builds_no_preconditioner_before_a_solve_needs_it() {
        // The spectral backend's FSAI, its local entries and the spectral inverse are
        // built on first use only.
        let scene = small()
            .solver_options(
                SolverOptions::default()
                    .with_backend(crate::solver::Backend::Spectral)
                    .unwrap(),
            )
            .build()
            .unwrap();
        let mut driver = scene.driver().unwrap();
        assert!(!driver.solver_holds_preconditioners());
        // The first equilibria build what the warm solves use: the check can fail.
        // To the first rupture (a site broken), without naming the driver's events (the
        // driver's layer is above the scene's).
        while driver.interface().broken_count() == 0 && driver.step().unwrap().is_some() {}
        assert!(driver.solver_holds_preconditioners());
    }
}
