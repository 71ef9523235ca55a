//! Stresses inside the block: the shear stress `τ = σ_xz`, the normal stress `σ = σ_zz`
//! and the Coulomb stress `τ_C = |τ| - μ|σ|` (paper Suppl. "Calculation of Coulomb
//! stress"), on planes `z = const` (every cell, through the DCT) and at points `(x, y, z)`
//! (a mode series), with the top, lateral and normal load terms.
//!
//! With cell-constant bottom tractions `φ` (Pa) and the loads, docs/model.md section 1 gives
//!
//! ```text
//! τ(x,y,z) = -T_z[φ_x] + F_top z/(Lz Lx Ly) + F_lat s_lat(x, z)
//! σ(x,y,z) = -T_z[φ_z] - F_N z/(Lz Lx Ly)
//! ```
//!
//! where `T_z` multiplies each cosine mode of the bottom traction by
//! `sinh κ(Lz-z)/sinh κLz` (the mean by `(Lz-z)/Lz`) and `s_lat` is the rod's stress per
//! newton ([`RodLoad::stress_influence_at`]). At `z = 0` the stresses are `τ = -φ_x`,
//! `σ = -φ_z` (the interface tractions, with the sign of a stress on the face of outward
//! normal `-z`); at `z = Lz` they are the top tractions.
//!
//! On a plane the result is cell-averaged (the Galerkin convention of docs/model.md section 2,
//! [`PlaneTransfer`]); at a point it is the exact value for cell-constant tractions:
//! a cell-constant field has the cosine coefficients `(2w_p/N) S_p D(p')` with the
//! aliases `p = 2Nq ± p'` of the DCT-II coefficient `D(p')` (sign `(-1)^q`), so a point
//! probe is a fixed kernel `K` over the cells, built once: `T_z[φ](P) = Σ_j K_j φ_j`.
//!
//! ```
//! use precursors::{Point, Scene};
//! use precursors::ProbeSpec;
//! let scene = Scene::builder()
//!     .block(0.020, 0.004, 0.010)
//!     .normal_load(80.0)
//!     .seed(0)
//!     .probes(ProbeSpec::default().with_plane(2e-3).with_point(Point::new(0.005, 0.002, 2e-3)))
//!     .build()?;
//! let mut driver = scene.driver()?;
//! driver.step()?; // the normal equilibrium at zero shear
//! let stresses = driver.stresses()?;
//! let plane = &stresses.planes[0];
//! // Force balance through the plane: ∫ σ_zz dA = -F_N.
//! let total: f64 = plane.normal().iter().sum::<f64>() * scene.grid().cell_area();
//! assert!((total + 80.0).abs() < 1e-9 * 80.0);
//! # Ok::<(), precursors::Error>(())
//! ```

use crate::error::{check_slice, check_tolerance, Error, Result};
use crate::geometry::{Grid, Point};
use crate::green::top_stress_influence;
use crate::green::{InfluencePlan, PlaneTransfer, RodLoad};
use rustdct::DctPlanner;
use std::f64::consts::PI;

/// Largest alias shell of a point kernel (the sum converges like `e^{-2π q z/Δ}`).
const MAX_SHELLS: usize = 64;

/// Where stresses are wanted: planes `z = const` and points. Requested on a driver at
/// any time ([`crate::Driver::add_probes`]), or on a scene ([`crate::SceneBuilder::probes`])
/// as the set every driver of the scene starts with; neither changes the scene's
/// identity (checkpoints resume across them). Nothing is planned without them.
///
/// The fields are private: the tolerance is valid by construction
/// ([`ProbeSpec::with_tolerance`]); the heights of planes and the points are checked
/// against the block where the probes are planned (a scene's build,
/// [`crate::Driver::add_probes`], [`StressProbe::new`]).
///
/// ```
/// use precursors::{Point, ProbeSpec};
/// let spec = ProbeSpec::default()
///     .with_plane(2e-3)
///     .with_point(Point::new(0.005, 0.002, 2e-3))
///     .with_tolerance(1e-12)?;
/// assert_eq!((spec.planes(), spec.points().len(), spec.tolerance()), (&[2e-3][..], 1, 1e-12));
/// assert!(ProbeSpec::default().with_tolerance(0.0).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "ProbeSpecFields", into = "ProbeSpecFields")
)]
#[non_exhaustive]
pub struct ProbeSpec {
    planes: Vec<f64>,
    points: Vec<Point>,
    tolerance: f64,
}

impl Default for ProbeSpec {
    fn default() -> Self {
        Self {
            planes: Vec::new(),
            points: Vec::new(),
            tolerance: 1e-10,
        }
    }
}

impl ProbeSpec {
    /// Heights `z ∈ [0, Lz]` (m) of the planes (scene-file key `probes.planes`).
    pub fn planes(&self) -> &[f64] {
        &self.planes
    }

    /// Points inside the block (m; scene-file key `probes.points`). Each costs a kernel
    /// of `N` values, built once from alias sums over every mode (`O(N)` times the alias
    /// shells, which grow like `Δ/z` for points close to the interface) and one 2-D DCT:
    /// use planes for fields, points for a few probes.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Absolute accuracy of the transfer factors (dimensionless, `> 0`; default `1e-10`;
    /// scene-file key `probes.tolerance`): the stresses are accurate to this times the
    /// largest traction. The lateral load's series is summed to this relative to the
    /// load's scale.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The same spec with one more plane, at height `z` (m; checked against the block
    /// where the probes are planned).
    #[must_use]
    pub fn with_plane(mut self, z: f64) -> Self {
        self.planes.push(z);
        self
    }

    /// The same spec with one more point probe (m; checked against the block where the
    /// probes are planned).
    #[must_use]
    pub fn with_point(mut self, point: Point) -> Self {
        self.points.push(point);
        self
    }

    /// The same spec with another accuracy (dimensionless, finite and `> 0`).
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`] for a tolerance that is not finite and `> 0`.
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        self.tolerance = check_tolerance(tolerance)?;
        Ok(self)
    }

    /// Whether nothing is requested.
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty() && self.points.is_empty()
    }
}

/// A [`ProbeSpec`] as serde sees it (feature `serde`): the scene file's `probes` keys,
/// points as `[x, y, z]` (a missing key takes the default), read back through the `with_`
/// modifiers.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct ProbeSpecFields {
    planes: Vec<f64>,
    points: Vec<[f64; 3]>,
    tolerance: f64,
}

#[cfg(feature = "serde")]
impl Default for ProbeSpecFields {
    fn default() -> Self {
        ProbeSpec::default().into()
    }
}

#[cfg(feature = "serde")]
impl From<ProbeSpec> for ProbeSpecFields {
    fn from(spec: ProbeSpec) -> Self {
        Self {
            points: spec.points.iter().map(Point::coords).collect(),
            planes: spec.planes,
            tolerance: spec.tolerance,
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<ProbeSpecFields> for ProbeSpec {
    type Error = Error;
    fn try_from(f: ProbeSpecFields) -> Result<Self> {
        let spec = f.planes.iter().fold(
            ProbeSpec::default().with_tolerance(f.tolerance)?,
            |spec, &z| spec.with_plane(z),
        );
        Ok(f.points.iter().fold(spec, |spec, &[x, y, z]| {
            spec.with_point(Point::new(x, y, z))
        }))
    }
}

/// The loads and interface tractions a stress evaluation needs
/// ([`StressProbe::evaluate`]). The tractions' lengths are checked against the probe's
/// grid when evaluated; the loads and the friction coefficient when set.
///
/// ```
/// use precursors::ProbeInput;
/// let (phi_x, phi_z) = (vec![0.0; 4], vec![1e5; 4]);
/// let input = ProbeInput::new(&phi_x, &phi_z)
///     .with_loads(0.0, 10.0, 40.0)?
///     .with_friction_coefficient(0.7)?;
/// assert_eq!((input.lateral_force(), input.friction_coefficient()), (10.0, 0.7));
/// assert!(input.with_friction_coefficient(-1.0).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct ProbeInput<'a> {
    shear_traction: &'a [f64],
    normal_traction: &'a [f64],
    top_force: f64,
    lateral_force: f64,
    normal_load: f64,
    friction_coefficient: f64,
}

impl<'a> ProbeInput<'a> {
    /// Tractions only (no external load): `F_top = F_lat = F_N = 0`, `μ = 0.5`. The
    /// shear traction `φ_x` and normal traction `φ_z` (Pa), one per cell.
    pub fn new(shear_traction: &'a [f64], normal_traction: &'a [f64]) -> Self {
        Self {
            shear_traction,
            normal_traction,
            top_force: 0.0,
            lateral_force: 0.0,
            normal_load: 0.0,
            friction_coefficient: 0.5,
        }
    }

    /// With the external loads (N, finite): the top shear force `F_top` and the lateral
    /// shear force `F_lat` (along +x), the normal load `F_N` (pressing down).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a load that is not finite.
    pub fn with_loads(self, top_force: f64, lateral_force: f64, normal_load: f64) -> Result<Self> {
        for (name, value) in [
            ("top_force", top_force),
            ("lateral_force", lateral_force),
            ("normal_load", normal_load),
        ] {
            if !value.is_finite() {
                return Err(Error::NonFinite {
                    name,
                    index: 0,
                    value,
                });
            }
        }
        Ok(Self {
            top_force,
            lateral_force,
            normal_load,
            ..self
        })
    }

    /// With the friction coefficient `μ` of the Coulomb stress (dimensionless, finite and
    /// `≥ 0`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a negative or non-finite coefficient.
    pub fn with_friction_coefficient(self, friction_coefficient: f64) -> Result<Self> {
        if !(friction_coefficient.is_finite() && friction_coefficient >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "friction_coefficient",
                value: friction_coefficient,
                reason: "the friction coefficient must be finite and >= 0",
            });
        }
        Ok(Self {
            friction_coefficient,
            ..self
        })
    }

    /// Bottom shear traction `φ_x` per cell (Pa).
    pub fn shear_traction(&self) -> &'a [f64] {
        self.shear_traction
    }

    /// Bottom normal traction `φ_z` per cell (Pa).
    pub fn normal_traction(&self) -> &'a [f64] {
        self.normal_traction
    }

    /// Top shear force `F_top` (N, along +x).
    pub fn top_force(&self) -> f64 {
        self.top_force
    }

    /// Lateral shear force `F_lat` (N, along +x) on the trailing face.
    pub fn lateral_force(&self) -> f64 {
        self.lateral_force
    }

    /// Normal load `F_N` (N, pressing down).
    pub fn normal_load(&self) -> f64 {
        self.normal_load
    }

    /// Friction coefficient `μ` of the Coulomb stress (dimensionless).
    pub fn friction_coefficient(&self) -> f64 {
        self.friction_coefficient
    }
}

/// Stresses on one plane, per cell in the paper's order `i = iy·Nx + ix` (Pa).
///
/// Read a cell with [`PlaneStress::at`] (`None` out of range), a whole field with
/// [`PlaneStress::shear`], [`PlaneStress::normal`], [`PlaneStress::coulomb`]; with the
/// `nalgebra` feature, a field as an `Ny x Nx` matrix with `Grid::field_to_dmatrix`. The
/// fields are read-only: the shape `Nx x Ny`, the three fields and `μ` belong together
/// ([`PlaneStress::at`] and [`PlaneStress::profile`] rely on it).
///
/// ```
/// use precursors::{ProbeSpec, Scene};
/// let scene = Scene::builder()
///     .block(0.020, 0.004, 0.010)
///     .normal_load(80.0)
///     .probes(ProbeSpec::default().with_plane(2e-3))
///     .build()?;
/// let mut driver = scene.driver()?;
/// driver.step()?;
/// let stresses = driver.stresses()?;
/// let plane = &stresses.planes[0];
/// assert_eq!((plane.z(), plane.nx(), plane.ny()), (2e-3, 20, 4));
/// assert_eq!(plane.shear().len(), 20 * 4);
/// let cell = plane.at(3, 1).unwrap();
/// assert_eq!(cell.normal, plane.normal()[plane.index(3, 1).unwrap()]);
/// assert_eq!(plane.profile().normal().len(), 20);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "PlaneStressFields", into = "PlaneStressFields")
)]
#[non_exhaustive]
pub struct PlaneStress {
    /// Height of the plane (m).
    z: f64,
    /// Cells along x `Nx` (the length of a row).
    nx: usize,
    /// Cells along y `Ny` (the number of rows).
    ny: usize,
    /// Shear stress `τ = σ_xz` (Pa), cell averages.
    shear: Vec<f64>,
    /// Normal stress `σ = σ_zz` (Pa, negative in compression), cell averages.
    normal: Vec<f64>,
    /// Coulomb stress `τ_C = |τ| - μ|σ|` (Pa) of the cell averages.
    coulomb: Vec<f64>,
    /// The `μ` of the Coulomb stresses (the driver's, or [`ProbeInput`]'s).
    friction_coefficient: f64,
    /// Cell length along x `Δx` (m), for [`Profile::x`]; `None` only for a plane read
    /// from a serde value written before 1.2.
    dx: Option<f64>,
}

/// A [`PlaneStress`] as serde sees it (feature `serde`): its accessors' names, read back
/// with the counts checked (`Nx, Ny ≥ 1`, `Nx·Ny` values of each field).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneStressFields {
    z: f64,
    nx: usize,
    ny: usize,
    shear: Vec<f64>,
    normal: Vec<f64>,
    coulomb: Vec<f64>,
    friction_coefficient: f64,
    /// Added in 1.2: absent from values written before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    dx: Option<f64>,
}

#[cfg(feature = "serde")]
impl From<PlaneStress> for PlaneStressFields {
    fn from(p: PlaneStress) -> Self {
        Self {
            z: p.z,
            nx: p.nx,
            ny: p.ny,
            shear: p.shear,
            normal: p.normal,
            coulomb: p.coulomb,
            friction_coefficient: p.friction_coefficient,
            dx: p.dx,
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<PlaneStressFields> for PlaneStress {
    type Error = Error;
    fn try_from(f: PlaneStressFields) -> Result<Self> {
        for (axis, n) in [("x", f.nx), ("y", f.ny)] {
            if n == 0 {
                return Err(Error::EmptyGrid { axis });
            }
        }
        // No vector holds more than `usize::MAX` values: an overflowing `Nx·Ny` mismatches.
        let cells = f.nx.saturating_mul(f.ny);
        for (name, values) in [
            ("shear", &f.shear),
            ("normal", &f.normal),
            ("coulomb", &f.coulomb),
        ] {
            if values.len() != cells {
                return Err(Error::LengthMismatch {
                    name,
                    expected: cells,
                    found: values.len(),
                });
            }
        }
        Ok(Self {
            z: f.z,
            nx: f.nx,
            ny: f.ny,
            shear: f.shear,
            normal: f.normal,
            coulomb: f.coulomb,
            friction_coefficient: f.friction_coefficient,
            dx: f
                .dx
                .map(|dx| crate::error::check_length("dx", dx))
                .transpose()?,
        })
    }
}

/// Profiles along x, averaged over y: one value per column `ix` of the plane, at the
/// column's centre `x` (m; [`Profile::x`]), stresses in Pa.
///
/// The y-average of a plane: each column's mean of the plane's cells. Read it through
/// methods, as [`PlaneStress`]: [`Profile::x`], [`Profile::shear`], [`Profile::normal`],
/// [`Profile::coulomb_of_means`], [`Profile::mean_coulomb`] (the public fields of 1.0 are
/// deprecated from 1.2).
///
/// The two Coulomb profiles average at different moments (`⟨·⟩_y` the mean over the
/// column's `Ny` cells, `μ` the plane's [`PlaneStress::friction_coefficient`]):
///
/// ```text
/// coulomb_of_means(x) = |⟨τ⟩_y| - μ|⟨σ⟩_y|       the Coulomb stress of the mean stresses
/// mean_coulomb(x)     = ⟨|τ| - μ|σ|⟩_y           the mean of the cells' Coulomb stresses
/// mean_coulomb - coulomb_of_means = (⟨|τ|⟩_y - |⟨τ⟩_y|) - μ(⟨|σ|⟩_y - |⟨σ⟩_y|)
/// ```
///
/// They are equal in a column where `τ` keeps one sign and `σ` keeps one sign (both
/// brackets are zero), and differ where one of them changes sign along y (its bracket is
/// then `> 0`; `τ` raises `mean_coulomb`, `σ` lowers it). The paper's `τ_C(x, z_P)` on a plane above the interface is
/// `coulomb_of_means`; its interface profile `τ_C(x)` (at `z = 0`) is `mean_coulomb`.
/// `profiles.csv` writes them as the columns `coulomb_of_means_Pa` and `mean_coulomb_Pa`.
///
/// ```
/// use precursors::{Point, ProbeSpec, Scene};
/// let scene = Scene::builder()
///     .block(0.020, 0.004, 0.010)
///     .normal_load(80.0)
///     .probes(ProbeSpec::default().with_plane(2e-3).with_point(Point::new(0.010, 0.002, 1e-3)))
///     .build()?;
/// let mut driver = scene.driver()?;
/// driver.step()?;                               // the normal equilibrium under F_N = 80 N
/// let stresses = driver.stresses()?;
/// let plane = &stresses.planes[0];
/// let profile = plane.profile();
/// assert_eq!(profile.normal().len(), plane.nx());
/// assert_eq!(profile.x()[3], 3.5e-3);           // 1 mm columns: centre of column 3 (m)
/// let column_3: f64 = (0..plane.ny()).map(|iy| plane.at(3, iy).unwrap().normal).sum();
/// assert!((profile.normal()[3] - column_3 / plane.ny() as f64).abs() < 1e-9 * column_3.abs());
/// // Under a normal load only, no column is past the Coulomb threshold.
/// assert!(profile.coulomb_of_means().iter().all(|&c| c < 0.0));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Profile {
    /// `⟨τ⟩_y(x, z) = (1/Ly) ∫ τ dy` (Pa).
    #[deprecated(since = "1.2.0", note = "use the method `Profile::shear()`")]
    pub shear: Vec<f64>,
    /// `⟨σ⟩_y(x, z) = (1/Ly) ∫ σ dy` (Pa).
    #[deprecated(since = "1.2.0", note = "use the method `Profile::normal()`")]
    pub normal: Vec<f64>,
    /// `|⟨τ⟩_y| - μ|⟨σ⟩_y|` (Pa): the paper's `τ_C(x, z_P)`.
    #[deprecated(since = "1.2.0", note = "use the method `Profile::coulomb_of_means()`")]
    pub coulomb_of_means: Vec<f64>,
    /// `⟨|τ| - μ|σ|⟩_y` (Pa): the paper's interface `τ_C(x)`.
    #[deprecated(since = "1.2.0", note = "use the method `Profile::mean_coulomb()`")]
    pub mean_coulomb: Vec<f64>,
    /// The columns' centres `(ix + 1/2)·Δx` (m); empty for a profile of a plane read from
    /// a serde value written before 1.2, which did not record `Δx` (a field added later
    /// has a default: docs/compatibility.md).
    #[cfg_attr(feature = "serde", serde(default))]
    x: Vec<f64>,
}

// The fields stay readable through 1.x; the crate itself reads them only here.
#[allow(deprecated)]
impl Profile {
    /// The centre `x = (ix + 1/2)·Δx` of each column `ix` (m), from `x = 0` at the
    /// trailing face: the abscissa of every other profile. Empty only for a profile of a
    /// plane read from a serde value written before 1.2.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// `⟨τ⟩_y(x, z) = (1/Ly) ∫ τ dy` (Pa), the mean shear stress `σ_xz` of each column.
    pub fn shear(&self) -> &[f64] {
        &self.shear
    }

    /// `⟨σ⟩_y(x, z) = (1/Ly) ∫ σ dy` (Pa, negative in compression), the mean normal
    /// stress `σ_zz` of each column.
    pub fn normal(&self) -> &[f64] {
        &self.normal
    }

    /// `|⟨τ⟩_y| - μ|⟨σ⟩_y|` (Pa): the Coulomb stress of the column's mean stresses, the
    /// paper's `τ_C(x, z_P)` on a plane above the interface (see [`Profile`] for how it
    /// differs from [`Profile::mean_coulomb`]).
    pub fn coulomb_of_means(&self) -> &[f64] {
        &self.coulomb_of_means
    }

    /// `⟨|τ| - μ|σ|⟩_y` (Pa): the mean of the column's cell Coulomb stresses
    /// ([`PlaneStress::coulomb`]), the paper's interface profile `τ_C(x)` (see
    /// [`Profile`] for how it differs from [`Profile::coulomb_of_means`]).
    pub fn mean_coulomb(&self) -> &[f64] {
        &self.mean_coulomb
    }
}

/// The stresses of one cell of a plane (Pa, cell averages).
///
/// ```
/// use precursors::{Point, ProbeSpec, Scene};
/// let scene = Scene::builder()
///     .block(0.020, 0.004, 0.010)
///     .normal_load(80.0)
///     .probes(ProbeSpec::default().with_plane(2e-3).with_point(Point::new(0.010, 0.002, 1e-3)))
///     .build()?;
/// let mut driver = scene.driver()?;
/// driver.step()?;                               // the normal equilibrium under F_N = 80 N
/// let stresses = driver.stresses()?;
/// let plane = &stresses.planes[0];
/// let cell = plane.at(5, 2).unwrap();            // ix = 5, iy = 2
/// assert_eq!(cell.normal, plane.normal()[2 * plane.nx() + 5]);
/// let mu = plane.friction_coefficient();
/// assert!((cell.coulomb - (cell.shear.abs() - mu * cell.normal.abs())).abs() < 1e-6);
/// assert!(plane.at(plane.nx(), 0).is_none());    // out of range
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct CellStress {
    /// Shear stress `τ = σ_xz` (Pa).
    pub shear: f64,
    /// Normal stress `σ = σ_zz` (Pa, negative in compression).
    pub normal: f64,
    /// Coulomb stress `|τ| - μ|σ|` (Pa).
    pub coulomb: f64,
}

impl PlaneStress {
    /// Height `z` of the plane (m).
    pub fn z(&self) -> f64 {
        self.z
    }

    /// Cells along x, `Nx` (the length of a row).
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Cells along y, `Ny` (the number of rows).
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Shear stress `τ = σ_xz` (Pa), cell averages in the order `i = iy·Nx + ix`.
    pub fn shear(&self) -> &[f64] {
        &self.shear
    }

    /// Normal stress `σ = σ_zz` (Pa, negative in compression), cell averages in the
    /// order `i = iy·Nx + ix`.
    pub fn normal(&self) -> &[f64] {
        &self.normal
    }

    /// Coulomb stress `τ_C = |τ| - μ|σ|` (Pa) of the cell averages, in the order
    /// `i = iy·Nx + ix`, with `μ` = [`PlaneStress::friction_coefficient`].
    pub fn coulomb(&self) -> &[f64] {
        &self.coulomb
    }

    /// The index `i = iy·Nx + ix` of cell `(ix, iy)`, `None` unless `ix < Nx` and
    /// `iy < Ny`.
    pub fn index(&self, ix: usize, iy: usize) -> Option<usize> {
        (ix < self.nx && iy < self.ny).then(|| iy * self.nx + ix)
    }

    /// The stresses of cell `(ix, iy)` (column `ix` along x, row `iy` along y), `None`
    /// unless `ix < Nx` and `iy < Ny`.
    pub fn at(&self, ix: usize, iy: usize) -> Option<CellStress> {
        let i = self.index(ix, iy)?;
        Some(CellStress {
            shear: *self.shear.get(i)?,
            normal: *self.normal.get(i)?,
            coulomb: *self.coulomb.get(i)?,
        })
    }

    /// The friction coefficient `μ` (dimensionless) of [`PlaneStress::coulomb`] and of
    /// [`PlaneStress::profile`]: the driver's ([`crate::Driver::friction_coefficient`])
    /// for [`crate::Driver::stresses`], [`ProbeInput::with_friction_coefficient`]'s for
    /// [`StressProbe::evaluate`].
    pub fn friction_coefficient(&self) -> f64 {
        self.friction_coefficient
    }

    /// The y-averaged profiles along x (Pa), with the plane's friction coefficient `μ`
    /// ([`PlaneStress::friction_coefficient`]) for the Coulomb stress of the averages.
    pub fn profile(&self) -> Profile {
        let friction_coefficient = self.friction_coefficient;
        let (nx, ny) = (self.nx, self.ny);
        let mean = |v: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; nx];
            for row in v.chunks_exact(nx) {
                out.iter_mut()
                    .zip(row)
                    .for_each(|(o, x)| *o += x / ny as f64);
            }
            out
        };
        let shear = mean(&self.shear);
        let normal = mean(&self.normal);
        let coulomb_of_means = shear
            .iter()
            .zip(&normal)
            .map(|(t, s)| t.abs() - friction_coefficient * s.abs())
            .collect();
        // Δx is unknown only for a plane read from a serde value written before 1.2.
        let x = self.dx.map_or_else(Vec::new, |dx| {
            (0..nx).map(|ix| (ix as f64 + 0.5) * dx).collect()
        });
        #[allow(deprecated)] // the 1.0 fields, read through the methods
        Profile {
            mean_coulomb: mean(&self.coulomb),
            shear,
            normal,
            coulomb_of_means,
            x,
        }
    }
}

/// Stresses at one point (Pa).
///
/// ```
/// use precursors::{Point, ProbeSpec, Scene};
/// let scene = Scene::builder()
///     .block(0.020, 0.004, 0.010)
///     .normal_load(80.0)
///     .probes(ProbeSpec::default().with_plane(2e-3).with_point(Point::new(0.010, 0.002, 1e-3)))
///     .build()?;
/// let mut driver = scene.driver()?;
/// driver.step()?;                               // the normal equilibrium under F_N = 80 N
/// let stresses = driver.stresses()?;
/// let p = &stresses.points[0];
/// assert_eq!(p.point, Point::new(0.010, 0.002, 1e-3));
/// assert!(p.normal < 0.0 && p.coulomb < 0.0);       // compressed, below the threshold
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct PointStress {
    /// Where (m).
    pub point: Point,
    /// Shear stress `τ = σ_xz` (Pa).
    pub shear: f64,
    /// Normal stress `σ = σ_zz` (Pa).
    pub normal: f64,
    /// Coulomb stress `|τ| - μ|σ|` (Pa).
    pub coulomb: f64,
}

/// Everything the probes measured in one state.
///
/// The block carries `F_N` on every plane: the normal stresses of a plane sum, over the
/// cells, to `-F_N` (force balance of the slab above it).
///
/// ```
/// use precursors::{Point, ProbeSpec, Scene};
/// let scene = Scene::builder()
///     .block(0.020, 0.004, 0.010)
///     .normal_load(80.0)
///     .probes(ProbeSpec::default().with_plane(2e-3).with_point(Point::new(0.010, 0.002, 1e-3)))
///     .build()?;
/// let mut driver = scene.driver()?;
/// driver.step()?;                               // the normal equilibrium under F_N = 80 N
/// let stresses = driver.stresses()?;
/// assert_eq!((stresses.planes.len(), stresses.points.len()), (1, 1));
/// let cell_area = 1e-3 * 1e-3;                      // 1 mm cells (m²)
/// let force: f64 = stresses.planes[0].normal().iter().sum::<f64>() * cell_area;
/// assert!((force + 80.0).abs() < 1e-6 * 80.0);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Stresses {
    /// One per requested plane, in request order.
    pub planes: Vec<PlaneStress>,
    /// One per requested point, in request order.
    pub points: Vec<PointStress>,
}

#[derive(Debug, Clone)]
struct PlaneProbe {
    transfer: PlaneTransfer,
    /// Lateral stress per newton, per column (m⁻²).
    lateral: Option<Vec<f64>>,
    /// Top load's stress per newton (m⁻²).
    top: f64,
}

#[derive(Debug, Clone)]
struct PointProbe {
    point: Point,
    /// `T_z[φ](P) = Σ_j kernel_j φ_j` (dimensionless).
    kernel: Vec<f64>,
    lateral: Option<f64>,
    top: f64,
}

/// Stress probes planned once for a geometry (and a lateral load, if any); evaluated on
/// any state by [`StressProbe::evaluate`].
///
/// Uniform bottom tractions that balance a top shear `F` and a normal load `F_N` leave the
/// block in a uniform stress state, `τ = F/(Lx Ly)` and `σ = -F_N/(Lx Ly)` on every plane
/// (the elementary equilibrium of a box, independent of the Green function):
///
/// ```
/// use precursors::{green::InfluencePlan, Block, Grid, ProbeInput, ProbeSpec, StressProbe};
/// let block = Block::new(0.010, 0.004, 0.006)?;
/// let grid = Grid::new(block, 10, 4)?;
/// let plan = InfluencePlan::builder(grid).build()?;
/// let probe = StressProbe::new(&plan, &ProbeSpec::default().with_plane(3e-3), None)?;
/// let (force, normal_load, area) = (2.0, 50.0, 0.010 * 0.004);
/// let (phi_x, phi_z) = (vec![-force / area; 40], vec![normal_load / area; 40]);
/// let input = ProbeInput::new(&phi_x, &phi_z).with_loads(force, 0.0, normal_load)?;
/// let plane = &probe.evaluate(&input)?.planes[0];
/// assert!(plane.shear().iter().all(|&t| (t - force / area).abs() < 1e-8 * force / area));
/// assert!(plane.normal().iter().all(|&s| (s + normal_load / area).abs() < 1e-8 * normal_load / area));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct StressProbe {
    grid: Grid,
    planes: Vec<PlaneProbe>,
    points: Vec<PointProbe>,
}

impl StressProbe {
    /// Plans the probes of `spec` on `plan`'s grid; `lateral` is the trailing-face load
    /// (if the scene has one), whose stress term is tabulated now.
    ///
    /// # Errors
    /// [`Error::OutsideBlock`] for a plane or point outside the block;
    /// [`Error::InvalidTolerance`]; [`Error::SeriesNotConverged`] when a transfer's or a point's
    /// series does not reach the tolerance.
    pub fn new(plan: &InfluencePlan, spec: &ProbeSpec, lateral: Option<&RodLoad>) -> Result<Self> {
        let grid = *plan.grid();
        let block = *grid.block();
        let tol = check_tolerance(spec.tolerance)?;
        // The lateral series' natural scale is 1/(Ly Lz) per newton.
        let lateral_tol = tol / (block.ly() * block.lz());
        let planes = spec
            .planes
            .iter()
            .map(|&z| {
                Ok(PlaneProbe {
                    transfer: plan.plane_transfer(z, tol)?,
                    lateral: lateral
                        .map(|r| r.stress_influence_cells(&grid, z, lateral_tol))
                        .transpose()?,
                    top: top_stress_influence(&block, z)?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut planner = DctPlanner::new();
        let points = spec
            .points
            .iter()
            .map(|&point| {
                let kernel = point_kernel(&grid, point, tol, &mut planner)?;
                Ok(PointProbe {
                    point,
                    kernel,
                    lateral: lateral
                        .map(|r| r.stress_influence_at(point.x, point.z, lateral_tol))
                        .transpose()?
                        .map(|e| e.value),
                    top: top_stress_influence(&block, point.z)?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            grid,
            planes,
            points,
        })
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The stresses of a state. A lateral force needs a probe planned with a lateral
    /// load ([`Error::InvalidParameter`] otherwise).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] / [`Error::NonFinite`] for bad tractions;
    /// [`Error::InvalidParameter`] for a lateral force on a probe planned without a
    /// lateral load.
    pub fn evaluate(&self, input: &ProbeInput<'_>) -> Result<Stresses> {
        let n = self.grid.len();
        check_slice("shear_traction", input.shear_traction, n)?;
        check_slice("normal_traction", input.normal_traction, n)?;
        let mu = input.friction_coefficient();
        let lateral_missing = input.lateral_force != 0.0
            && (self.planes.iter().any(|p| p.lateral.is_none())
                || self.points.iter().any(|p| p.lateral.is_none()));
        if lateral_missing {
            return Err(Error::InvalidParameter {
                name: "lateral_force",
                value: input.lateral_force,
                reason: "the probes were planned without a lateral load",
            });
        }
        let nx = self.grid.nx();
        let coulomb = |t: f64, s: f64| t.abs() - mu * s.abs();
        let mut planes = Vec::with_capacity(self.planes.len());
        for p in &self.planes {
            let mut shear = vec![0.0; n];
            let mut normal = vec![0.0; n];
            if p.transfer.z() == 0.0 {
                // The interface itself: the tractions, exactly (no transform rounding).
                shear
                    .iter_mut()
                    .zip(input.shear_traction)
                    .for_each(|(s, f)| *s = -f);
                normal
                    .iter_mut()
                    .zip(input.normal_traction)
                    .for_each(|(s, f)| *s = -f);
            } else {
                p.transfer.stress(input.shear_traction, &mut shear)?;
                p.transfer.stress(input.normal_traction, &mut normal)?;
            }
            for (i, (t, s)) in shear.iter_mut().zip(normal.iter_mut()).enumerate() {
                *t += input.top_force * p.top;
                if let Some(l) = &p.lateral {
                    *t += input.lateral_force * l[i % nx];
                }
                *s -= input.normal_load * p.top;
            }
            let coulomb = shear
                .iter()
                .zip(&normal)
                .map(|(t, s)| coulomb(*t, *s))
                .collect();
            planes.push(PlaneStress {
                z: p.transfer.z(),
                nx,
                ny: self.grid.ny(),
                shear,
                normal,
                coulomb,
                friction_coefficient: mu,
                dx: Some(self.grid.dx()),
            });
        }
        let dot = |k: &[f64], v: &[f64]| k.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let points = self
            .points
            .iter()
            .map(|p| {
                let shear = -dot(&p.kernel, input.shear_traction)
                    + input.top_force * p.top
                    + p.lateral.map_or(0.0, |l| input.lateral_force * l);
                let normal = -dot(&p.kernel, input.normal_traction) - input.normal_load * p.top;
                PointStress {
                    point: p.point,
                    shear,
                    normal,
                    coulomb: coulomb(shear, normal),
                }
            })
            .collect();
        Ok(Stresses { planes, points })
    }
}

/// The lowest height above the interface (m) at which a point probe's alias sums
/// ([`point_kernel`]) are sure to reach `tol` within [`MAX_SHELLS`] shells on `grid`
/// (`z = 0` needs no sum). At shell `s` the terms have `κ >= (2s-1)π/Δ`
/// (`Δ = max(dx, dy)`), `|a| <= 2/n` on one axis and `(2/n)·2/((2s-1)π)` (the sinc) on
/// the axis at the shell, at most `4(2s+1)` of them, each times `transfer(κ) <=
/// e^{-κz}/(1 - e^{-2κLz})`; the sum stops when that bound times `r/(1 - r)`,
/// `r = e^{-2πz/Δ}`, is below `tol`. The bound at `s = MAX_SHELLS` decreases with `z`:
/// bisected. `Lz` when not even the top converges (then only `z = 0`).
pub(crate) fn lowest_point(grid: &Grid, tol: f64) -> f64 {
    let delta = grid.dx().max(grid.dy());
    let lz = grid.block().lz();
    let s = MAX_SHELLS as f64;
    let kappa = (2.0 * s - 1.0) * PI / delta;
    let (nx, ny) = (grid.nx() as f64, grid.ny() as f64);
    let bound = |z: f64| {
        let r = (-2.0 * PI * z / delta).exp();
        4.0 * (2.0 * s + 1.0)
            * (4.0 / (nx * ny))
            * (2.0 / ((2.0 * s - 1.0) * PI))
            * (-kappa * z).exp()
            / -(-2.0 * kappa * lz).exp_m1()
            * r
            / -(-2.0 * PI * z / delta).exp_m1()
    };
    if bound(lz) > tol {
        return lz;
    }
    let (mut lo, mut hi) = (0.0, lz);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if bound(mid) <= tol {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// `sinh κ(Lz - z)/sinh κLz` with decaying exponentials; `(Lz - z)/Lz` at κ = 0.
fn transfer(kappa: f64, z: f64, lz: f64) -> f64 {
    if kappa == 0.0 {
        return (lz - z) / lz;
    }
    ((-kappa * z).exp() - (-kappa * (2.0 * lz - z)).exp()) / (-(-2.0 * kappa * lz).exp_m1())
}

/// The aliases `(sign (-1)^q · 2w_p S_p/N · cos(k_p x), k_p)` of the 1-D DCT mode `mode`
/// with `|q| = shell`.
fn shell_terms(mode: usize, n: usize, length: f64, x: f64, shell: usize) -> Vec<(f64, f64)> {
    let cell = length / n as f64;
    let term = |p: f64, q: usize| {
        let k = p * PI / length;
        let w = if p == 0.0 { 0.5 } else { 1.0 };
        let half = 0.5 * k * cell;
        let s = if half == 0.0 { 1.0 } else { half.sin() / half };
        let sign = if q.is_multiple_of(2) { 1.0 } else { -1.0 };
        (sign * 2.0 * w * s / n as f64 * (k * x).cos(), k)
    };
    let base = 2 * n * shell;
    if shell == 0 {
        vec![term(mode as f64, 0)]
    } else if mode == 0 {
        vec![term(base as f64, shell)]
    } else {
        vec![
            term((base - mode) as f64, shell),
            term((base + mode) as f64, shell),
        ]
    }
}

/// The kernel `K` with `T_z[φ](P) = Σ_j K_j φ_j` for cell-constant `φ`:
/// `K_ij = Σ_{p',m'} W(p',m') cos(k_p' x_i) cos(k_m' y_j)` (a 2-D DCT-III of the alias
/// sums `W`). At `z = 0` it is the indicator of the cell holding `P` (averaged over the
/// cells sharing an edge or corner with it, the limit of the series there).
fn point_kernel(
    grid: &Grid,
    point: Point,
    tol: f64,
    planner: &mut DctPlanner<f64>,
) -> Result<Vec<f64>> {
    let block = grid.block();
    let (lx, ly, lz) = (block.lx(), block.ly(), block.lz());
    for (name, value, max) in [("x", point.x, lx), ("y", point.y, ly)] {
        if !(value.is_finite() && (0.0..=max).contains(&value)) {
            return Err(Error::OutsideBlock { name, value, max });
        }
    }
    let z = block.check_height(point.z)?;
    let (nx, ny) = (grid.nx(), grid.ny());
    if z == 0.0 {
        return Ok(cell_indicator(grid, point));
    }
    let mut w = vec![0.0; nx * ny];
    for m in 0..ny {
        for p in 0..nx {
            let mut sum = 0.0;
            let mut shell = 0;
            loop {
                // Terms with max(|q_x|, |q_y|) = shell.
                let mut shell_sum = 0.0;
                let mut shell_bound = 0.0;
                for qx in 0..=shell {
                    for qy in 0..=shell {
                        if qx.max(qy) != shell {
                            continue;
                        }
                        for (ax, kx) in shell_terms(p, nx, lx, point.x, qx) {
                            for (ay, ky) in shell_terms(m, ny, ly, point.y, qy) {
                                let t = ax * ay * transfer((kx * kx + ky * ky).sqrt(), z, lz);
                                shell_sum += t;
                                shell_bound += t.abs();
                            }
                        }
                    }
                }
                sum += shell_sum;
                // The shells decay like e^{-2π z/Δ} each: the next is below this bound.
                let ratio = (-2.0 * PI * z / grid.dx().max(grid.dy())).exp();
                if shell > 0 && shell_bound * ratio / (1.0 - ratio) <= tol {
                    break;
                }
                if shell >= MAX_SHELLS {
                    return Err(Error::SeriesNotConverged {
                        what: "alias sum of a point stress probe (z too close to 0?)",
                        value: sum,
                        error: shell_bound,
                        tolerance: tol,
                        terms: (shell * shell) as u64,
                    });
                }
                shell += 1;
            }
            w[m * nx + p] = sum;
        }
    }
    // K = DCT-III over x then y; rustdct's DCT-III halves the first entry: double it.
    let dct_x = planner.plan_dct3(nx);
    let dct_y = planner.plan_dct3(ny);
    for row in w.chunks_exact_mut(nx) {
        row[0] *= 2.0;
        dct_x.process_dct3(row);
    }
    let mut column = vec![0.0; ny];
    for ix in 0..nx {
        for (iy, c) in column.iter_mut().enumerate() {
            *c = w[iy * nx + ix];
        }
        column[0] *= 2.0;
        dct_y.process_dct3(&mut column);
        for (iy, c) in column.iter().enumerate() {
            w[iy * nx + ix] = *c;
        }
    }
    Ok(w)
}

/// The cells holding `P` on the bottom face, weighted equally (1 inside a cell, ½ each on
/// an edge, ¼ each at a corner).
fn cell_indicator(grid: &Grid, point: Point) -> Vec<f64> {
    let near = |v: f64, d: f64, n: usize| -> Vec<usize> {
        let s = v / d;
        let r = s.round();
        if (s - r).abs() < 1e-12 && r > 0.0 && (r as usize) < n {
            vec![r as usize - 1, r as usize]
        } else {
            vec![(s.floor() as usize).min(n - 1)]
        }
    };
    let xs = near(point.x, grid.dx(), grid.nx());
    let ys = near(point.y, grid.dy(), grid.ny());
    let mut k = vec![0.0; grid.len()];
    let share = 1.0 / (xs.len() * ys.len()) as f64;
    for &iy in &ys {
        for &ix in &xs {
            // `near` clamps to the grid: the flat index is in range.
            k[iy * grid.nx() + ix] = share;
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Block;

    /// The two Coulomb profiles on a plane written by hand (`Nx = 3`, `Ny = 2`, `μ = 1/2`,
    /// `Δx = 3 mm`), each value worked out on paper. Column 0: `τ` changes sign along y,
    /// so `⟨|τ|⟩ = 2 > |⟨τ⟩| = 1` and `mean_coulomb` exceeds `coulomb_of_means` by 1 Pa.
    /// Column 1: `σ` changes sign, `⟨|σ|⟩ = 4 > |⟨σ⟩| = 2`, and `mean_coulomb` falls short
    /// by `μ·2 = 1` Pa. Column 2: one sign each, the two agree.
    #[test]
    fn the_two_coulomb_profiles_differ_where_a_stress_changes_sign_along_y() {
        // Rows iy = 0 and iy = 1 of columns 0, 1, 2 (Pa).
        let shear = vec![3.0, 2.0, 2.0, -1.0, 4.0, 4.0];
        let normal = vec![-2.0, -6.0, -6.0, -2.0, 2.0, -2.0];
        // |τ| - μ|σ| cell by cell: 3-1, 2-3, 2-3 / 1-1, 4-1, 4-1.
        let coulomb = vec![2.0, -1.0, -1.0, 0.0, 3.0, 3.0];
        let plane = PlaneStress {
            z: 0.0,
            nx: 3,
            ny: 2,
            shear,
            normal,
            coulomb,
            friction_coefficient: 0.5,
            dx: Some(3e-3),
        };
        let p = plane.profile();
        assert_eq!(p.shear(), [1.0, 3.0, 3.0]);
        assert_eq!(p.normal(), [-2.0, -2.0, -4.0]);
        // |⟨τ⟩| - μ|⟨σ⟩|: 1 - 1, 3 - 1, 3 - 2.
        assert_eq!(p.coulomb_of_means(), [0.0, 2.0, 1.0]);
        // ⟨|τ| - μ|σ|⟩: (2 + 0)/2, (-1 + 3)/2, (-1 + 3)/2.
        assert_eq!(p.mean_coulomb(), [1.0, 1.0, 1.0]);
        // Column centres (ix + 1/2)·Δx (m).
        let x = p.x();
        assert_eq!(x.len(), 3);
        for (got, want) in x.iter().zip([1.5e-3, 4.5e-3, 7.5e-3]) {
            assert!((got - want).abs() <= 1e-15, "{got} vs {want}");
        }
        // Without Δx (a plane read from a serde value written before 1.2), no abscissa.
        let old = PlaneStress { dx: None, ..plane };
        assert!(old.profile().x().is_empty());
    }

    /// The documented lowest point converges on grids of several shapes and tolerances,
    /// at the corner, the middle and an edge of the face (the bound is sufficient; below
    /// it a sum may or may not converge).
    #[test]
    fn the_lowest_point_converges() {
        for (lx, ly, lz, nx, ny, tol) in [
            (0.014, 0.003, 0.075, 14, 3, 1e-10),
            (0.004, 0.004, 0.002, 4, 4, 1e-15),
            (0.006, 0.002, 0.02, 12, 2, 1e-6),
        ] {
            let grid = Grid::new(Block::new(lx, ly, lz).unwrap(), nx, ny).unwrap();
            let z = lowest_point(&grid, tol);
            assert!(z > 0.0 && z < 0.2 * grid.dx().max(grid.dy()), "{z}");
            let mut planner = DctPlanner::new();
            for (x, y) in [(0.0, 0.0), (0.5 * lx, 0.5 * ly), (lx, 0.3 * ly)] {
                let kernel = point_kernel(&grid, Point::new(x, y, z), tol, &mut planner)
                    .unwrap_or_else(|e| panic!("({x}, {y}, {z}): {e}"));
                assert!(kernel.iter().all(|k| k.is_finite()));
            }
        }
    }
}
