//! The interfacial springs of the bottom face (docs/model.md section 3).
//!
//! Each cell `i` of the grid holds one spring of rest height `u0_i > 0` (m), the local
//! height of the rough substrate. Per unit area the springs have normal stiffness
//! `k_z,i = c_z / u0_i` and tangential stiffness `k_x,i = c_x exp(-u_z,i / u0_i)` (N/m³).
//! A site is [`SiteState::Attached`] while it pushes (`φ_z = k_z (u0 - u_z) ≥ 0`),
//! [`SiteState::Detached`] when the block's bottom lies above it (`u_z > u0`, no force, it
//! may re-attach), and [`SiteState::Broken`] once it slipped under the Coulomb rule (never
//! re-attaches). The solvers ([`crate::solver`]) work with compliances `1/k` (m³/N),
//! which stay finite when springs are stiff (`u0 → 0`).
//!
//! `μ`, `c_x` and `c_z` are the scalars of the material and the spring law unless the
//! interface has a map of them ([`Interface::with_friction_map`],
//! [`Interface::with_c_x_map`], [`Interface::with_c_z_map`]; a scene's key `maps`): one
//! value per site. Without a map the scalar code runs as before, bit for bit; a map with
//! every value equal to the scalar gives the same bits (the same expressions, the value
//! read from the map).

use crate::error::{check_slice, Error, Result};
use crate::geometry::Grid;
use crate::surface::{Plan, SurfaceSpectrum, Truncated};
use rand::rngs::Xoshiro256PlusPlus;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::sync::Arc;

/// Bulk and friction properties of the block. Defaults: the paper's PMMA.
///
/// The fields are private: a `Material` is valid by construction ([`Material::new`], the
/// `with_` modifiers).
///
/// ```
/// use precursors::Material;
/// let m = Material::default().with_friction_coefficient(0.7)?;
/// assert_eq!((m.young_modulus(), m.friction_coefficient()), (3.833e9, 0.7));
/// assert!(Material::default().with_poisson_ratio(0.6).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "MaterialFields", into = "MaterialFields")
)]
#[non_exhaustive]
pub struct Material {
    young_modulus: f64,
    poisson_ratio: f64,
    friction_coefficient: f64,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            young_modulus: 3.833e9,
            poisson_ratio: 0.38,
            friction_coefficient: 0.5,
        }
    }
}

impl Material {
    /// A validated material: Young's modulus `E` (Pa) finite and `> 0`, Poisson's ratio
    /// `ν` in `(-1, 0.5]`, the friction coefficient `μ` (dimensionless) finite and `> 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first value out of range.
    pub fn new(young_modulus: f64, poisson_ratio: f64, friction_coefficient: f64) -> Result<Self> {
        let m = Self {
            young_modulus,
            poisson_ratio,
            friction_coefficient,
        };
        m.check()?;
        Ok(m)
    }

    fn check(self) -> Result<Self> {
        if !(self.young_modulus.is_finite() && self.young_modulus > 0.0) {
            return Err(Error::InvalidParameter {
                name: "young_modulus",
                value: self.young_modulus,
                reason: "Young's modulus must be finite and > 0 Pa",
            });
        }
        if !(self.poisson_ratio > -1.0 && self.poisson_ratio <= 0.5) {
            return Err(Error::InvalidParameter {
                name: "poisson_ratio",
                value: self.poisson_ratio,
                reason: "Poisson's ratio must lie in (-1, 0.5]",
            });
        }
        if !(self.friction_coefficient.is_finite() && self.friction_coefficient > 0.0) {
            return Err(Error::InvalidParameter {
                name: "friction_coefficient",
                value: self.friction_coefficient,
                reason: "the friction coefficient must be finite and > 0 (with μ = 0 every \
                         site slips at zero shear and the loads F/(μF_N) are undefined)",
            });
        }
        Ok(self)
    }

    /// Young's modulus `E` (Pa). Default `3.833e9`.
    pub fn young_modulus(&self) -> f64 {
        self.young_modulus
    }

    /// Poisson's ratio `ν` (dimensionless, in `(-1, 0.5]`). Default `0.38`.
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    /// Static local friction coefficient `μ` (dimensionless, `> 0`). Default `0.5`.
    pub fn friction_coefficient(&self) -> f64 {
        self.friction_coefficient
    }

    /// The same material with Young's modulus `E` (Pa).
    ///
    /// # Errors
    /// As [`Material::new`].
    pub fn with_young_modulus(self, young_modulus: f64) -> Result<Self> {
        Self {
            young_modulus,
            ..self
        }
        .check()
    }

    /// The same material with Poisson's ratio `ν` (dimensionless).
    ///
    /// # Errors
    /// As [`Material::new`].
    pub fn with_poisson_ratio(self, poisson_ratio: f64) -> Result<Self> {
        Self {
            poisson_ratio,
            ..self
        }
        .check()
    }

    /// The same material with the friction coefficient `μ` (dimensionless).
    ///
    /// # Errors
    /// As [`Material::new`].
    pub fn with_friction_coefficient(self, friction_coefficient: f64) -> Result<Self> {
        Self {
            friction_coefficient,
            ..self
        }
        .check()
    }

    /// The scalar model's modulus `M = E / (1 + ν)` (Pa).
    pub fn modulus(&self) -> f64 {
        self.young_modulus / (1.0 + self.poisson_ratio)
    }
}

/// The real contact area of an attached site (docs/model.md section 3). It enters the
/// outputs only (total area, precursor length), never the equilibria or the events.
///
/// ```
/// use precursors::{AreaLaw, Block, Grid, Heights, Interface, SpringLaw};
/// let grid = Grid::new(Block::new(0.002, 0.001, 0.005)?, 2, 1)?;   // two 1 mm² cells
/// let heights = Heights::from_values(&grid, vec![1e-6; 2])?;        // u0 = 1 µm
/// let u_z = [-0.5e-6, 0.5e-6];       // the first cell pressed 0.5 µm below the mean plane (m)
/// let paper = Interface::new(grid, heights.clone(), SpringLaw::default())?;
/// let law = SpringLaw::default().with_area_law(AreaLaw::Capped);
/// let capped = Interface::new(grid, heights, law)?;
/// let (a, b) = (paper.cell_contact_area(&u_z)?, capped.cell_contact_area(&u_z)?);
/// let cell = grid.cell_area();                                      // ΔA = 1e-6 m²
/// // Paper: ΔA/(e-1) [e^1.5 - 1] ≈ 2.026 ΔA, more than the cell; capped at ΔA.
/// assert!((a[0] / cell - 2.0263).abs() < 1e-4 && b[0] == cell);
/// // Below ΔA the laws agree: ΔA/(e-1) [e^0.5 - 1] ≈ 0.378 ΔA.
/// assert!(a[1] == b[1] && (a[1] / cell - 0.3775).abs() < 1e-4);
/// assert_eq!(AreaLaw::default(), AreaLaw::Paper);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum AreaLaw {
    /// The paper's law `A_R,i = ΔA/(e-1) [exp(-(u_z,i - u0_i)/u0_i) - 1]` (m²), unbounded:
    /// a site pressed below the substrate's mean plane (`u_z < 0`) has more real contact
    /// area than its cell, and the total may exceed the nominal area `Lx·Ly`
    /// ([`crate::Driver::area_exceeds_nominal`]). The default.
    #[default]
    Paper,
    /// The paper's law capped at the cell area: `min(A_R,i, ΔA)` (m²), so the total never
    /// exceeds the nominal area `Lx·Ly`.
    Capped,
}

/// The constants of the spring laws and the real-contact-area law. Defaults: the paper's
/// calibrated PMMA values and its area law.
///
/// The fields are private: a `SpringLaw` is valid by construction ([`SpringLaw::new`],
/// the `with_` modifiers).
///
/// ```
/// use precursors::{AreaLaw, SpringLaw};
/// let law = SpringLaw::default().with_c_z(3e8)?.with_area_law(AreaLaw::Capped);
/// assert_eq!((law.c_x(), law.c_z(), law.area_law()), (1.65e12, 3e8, AreaLaw::Capped));
/// assert!(SpringLaw::new(-1.0, 1e8).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "SpringLawFields", into = "SpringLawFields")
)]
#[non_exhaustive]
pub struct SpringLaw {
    c_x: f64,
    c_z: f64,
    area_law: AreaLaw,
}

impl Default for SpringLaw {
    fn default() -> Self {
        Self {
            c_x: 1.65e12,
            c_z: 1.65e8,
            area_law: AreaLaw::Paper,
        }
    }
}

impl SpringLaw {
    /// A validated law: `c_x` (N/m³) and `c_z` (N/m²) finite and `> 0`; the paper's area
    /// law.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a constant that is not finite and `> 0`.
    pub fn new(c_x: f64, c_z: f64) -> Result<Self> {
        Self {
            c_x,
            c_z,
            area_law: AreaLaw::Paper,
        }
        .check()
    }

    fn check(self) -> Result<Self> {
        for (name, value) in [("c_x", self.c_x), ("c_z", self.c_z)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "spring constants must be finite and > 0",
                });
            }
        }
        Ok(self)
    }

    /// `c_x` (N/m³): tangential stiffness per unit area of a site at `u_z = 0`. Default
    /// `1.65e12`.
    pub fn c_x(&self) -> f64 {
        self.c_x
    }

    /// `c_z` (N/m²): `k_z = c_z / u0`. Default `1.65e8`.
    pub fn c_z(&self) -> f64 {
        self.c_z
    }

    /// The real contact area of an attached site (m², outputs only). Default
    /// [`AreaLaw::Paper`].
    pub fn area_law(&self) -> AreaLaw {
        self.area_law
    }

    /// The same law with another `c_x` (N/m³).
    ///
    /// # Errors
    /// As [`SpringLaw::new`].
    pub fn with_c_x(self, c_x: f64) -> Result<Self> {
        Self { c_x, ..self }.check()
    }

    /// The same law with another `c_z` (N/m²).
    ///
    /// # Errors
    /// As [`SpringLaw::new`].
    pub fn with_c_z(self, c_z: f64) -> Result<Self> {
        Self { c_z, ..self }.check()
    }

    /// The same constants with another real-contact-area law.
    #[must_use]
    pub fn with_area_law(self, area_law: AreaLaw) -> Self {
        Self { area_law, ..self }
    }
}

/// The Gaussian the heights are drawn from before truncation at 0. Defaults: the paper's
/// mean 1 µm and standard deviation 1 µm.
///
/// The fields are private: a distribution is valid by construction
/// ([`HeightDistribution::new`], the `with_` modifiers): a finite mean, a finite standard
/// deviation `≥ 0`, and `mean ≥ -3 std_dev` (and `mean > 0` when `std_dev = 0`), so that
/// rejection sampling keeps at least 0.1 % of draws.
///
/// ```
/// use precursors::HeightDistribution;
/// let d = HeightDistribution::new(2e-6, 0.5e-6)?;
/// assert_eq!((d.mean(), d.std_dev()), (2e-6, 0.5e-6));
/// assert!(HeightDistribution::new(1e-6, -1e-6).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        try_from = "HeightDistributionFields",
        into = "HeightDistributionFields"
    )
)]
#[non_exhaustive]
pub struct HeightDistribution {
    mean: f64,
    std_dev: f64,
}

impl Default for HeightDistribution {
    fn default() -> Self {
        Self {
            mean: 1e-6,
            std_dev: 1e-6,
        }
    }
}

impl HeightDistribution {
    /// A distribution with the given mean and standard deviation (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a mean or standard deviation that is not finite (or
    /// negative), or a mean below `-3` standard deviations.
    pub fn new(mean: f64, std_dev: f64) -> Result<Self> {
        Self { mean, std_dev }.check()
    }

    /// Mean of the untruncated Gaussian (m). Default `1e-6`.
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Standard deviation of the untruncated Gaussian (m, `≥ 0`). Default `1e-6`.
    pub fn std_dev(&self) -> f64 {
        self.std_dev
    }

    /// The same distribution with another mean (m).
    ///
    /// # Errors
    /// As [`HeightDistribution::new`].
    pub fn with_mean(self, mean: f64) -> Result<Self> {
        Self { mean, ..self }.check()
    }

    /// The same distribution with another standard deviation (m).
    ///
    /// # Errors
    /// As [`HeightDistribution::new`].
    pub fn with_std_dev(self, std_dev: f64) -> Result<Self> {
        Self { std_dev, ..self }.check()
    }

    fn check(self) -> Result<Self> {
        let HeightDistribution { mean, std_dev } = self;
        if !mean.is_finite() {
            return Err(Error::InvalidParameter {
                name: "mean",
                value: mean,
                reason: "the mean height must be finite",
            });
        }
        if !(std_dev.is_finite() && std_dev >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "std_dev",
                value: std_dev,
                reason: "the standard deviation must be finite and >= 0 m",
            });
        }
        let ratio = if std_dev > 0.0 {
            mean / std_dev
        } else if mean > 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        if ratio < MIN_MEAN_OVER_SD {
            return Err(Error::InvalidParameter {
                name: "mean",
                value: mean,
                reason: "mean / std_dev must be >= -3 (and the mean > 0 when std_dev = 0): \
                         almost every draw would be cut at 0",
            });
        }
        Ok(self)
    }
}

/// Smallest `mean / std_dev` accepted: rejection sampling then keeps at least 0.1 % of draws.
const MIN_MEAN_OVER_SD: f64 = -3.0;

/// Rest heights `u0_i > 0` (m) of the springs, one per cell in the paper's order
/// `i = iy * Nx + ix`.
///
/// ```
/// use precursors::{Block, Error, Grid, HeightDistribution, Heights};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.005)?, 10, 4)?;   // 40 cells
/// // The paper's substrate: a Gaussian of mean 1 µm and standard deviation 1 µm cut at 0.
/// let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), 7)?;
/// assert_eq!(heights.len(), 40);
/// assert!(heights.values().iter().all(|&u0| u0 > 0.0));
/// // The same seed gives the same heights.
/// assert_eq!(heights, Heights::truncated_gaussian(&grid, HeightDistribution::default(), 7)?);
/// // A measured topography: one height (m) per cell, each > 0.
/// let flat = Heights::from_values(&grid, vec![1e-6; 40])?;
/// assert_eq!(flat.values()[39], 1e-6);
/// let e = Heights::from_values(&grid, vec![1e-6; 39]).unwrap_err();
/// assert!(matches!(e, Error::LengthMismatch { expected: 40, found: 39, .. }));
/// let mut dented = vec![1e-6; 40];
/// dented[5] = 0.0;
/// let e = Heights::from_values(&grid, dented).unwrap_err();
/// assert!(matches!(e, Error::NonPositiveHeight { index: 5, .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Heights {
    values: Vec<f64>,
}

impl Heights {
    /// Heights drawn from a Gaussian truncated at 0 (draws `≤ 0` are redrawn), seeded.
    ///
    /// The stream is fixed: `Xoshiro256PlusPlus::seed_from_u64(seed)` feeding
    /// `rand_distr::Normal`, one height per cell in cell order. The same seed gives the
    /// same heights on every platform (a value-stability test pins them).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `rand_distr` refuses the distribution (it does
    /// not: a [`HeightDistribution`] is valid by construction).
    pub fn truncated_gaussian(grid: &Grid, dist: HeightDistribution, seed: u64) -> Result<Self> {
        let HeightDistribution { mean, std_dev } = dist;
        let normal = Normal::new(mean, std_dev).map_err(|_| Error::InvalidParameter {
            name: "std_dev",
            value: std_dev,
            reason: "rejected by rand_distr::Normal",
        })?;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let values = (0..grid.len())
            .map(|_| loop {
                let h = normal.sample(&mut rng);
                if h > 0.0 {
                    break h;
                }
            })
            .collect();
        Ok(Self { values })
    }

    /// Heights of a Gaussian random surface with a length scale (docs/model.md section
    /// 3.1): a field `g` of unit variance with the power spectrum `spectrum`, synthesised
    /// from Fourier modes whose coefficients depend only on `(seed, mode)`, mapped onto
    /// the truncated Gaussian `dist` (the paper's marginal) by `u0 = F⁻¹(Φ(g))`, and
    /// averaged over each cell. The same seed gives the same surface at every cell size
    /// (a coarse cell's height is the mean of its fine cells' to about `1e-12` of the
    /// standard deviation) and the same heights bit for bit on every machine.
    ///
    /// ```
    /// use precursors::{Block, Grid, HeightDistribution, Heights, SurfaceSpectrum};
    /// let block = Block::new(0.016, 0.004, 0.010)?;                 // Lx, Ly, Lz (m)
    /// let xi = SurfaceSpectrum::gaussian(2e-3)?;                     // ξ = 2 mm
    /// let d = HeightDistribution::default();                         // the paper's marginal
    /// let coarse = Heights::random_surface(&Grid::new(block, 8, 2)?, xi, d, 7)?;  // 2 mm
    /// let fine = Heights::random_surface(&Grid::new(block, 16, 4)?, xi, d, 7)?;   // 1 mm
    /// assert!(coarse.values().iter().all(|&u0| u0 > 0.0));
    /// // Coarse cell (0, 0) is fine cells (0, 0), (1, 0), (0, 1), (1, 1).
    /// let f = fine.values();
    /// let mean = (f[0] + f[1] + f[16] + f[17]) / 4.0;
    /// assert!((coarse.values()[0] - mean).abs() < 1e-15);             // m
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::SurfaceTooLarge`] when the spectrum needs too many modes for the block,
    /// or the cells too many quadrature points; [`Error::OutOfMemory`];
    /// [`Error::NonPositiveHeight`] if a cell's height rounds to 0 (a field value beyond
    /// about 37 standard deviations: it does not happen).
    pub fn random_surface(
        grid: &Grid,
        spectrum: SurfaceSpectrum,
        dist: HeightDistribution,
        seed: u64,
    ) -> Result<Self> {
        let plan = Plan::new(grid, &spectrum)?;
        let values = plan.cell_averages(grid, &Truncated::new(dist.mean, dist.std_dev), seed)?;
        Self::check_values(grid, &values)?;
        Ok(Self { values })
    }

    /// User-supplied heights (a measured topography), in cell order `i = iy * Nx + ix`:
    /// one finite value `> 0` (m) per cell.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for a count other than the grid's; [`Error::NonFinite`];
    /// [`Error::NonPositiveHeight`].
    pub fn from_values(grid: &Grid, values: Vec<f64>) -> Result<Self> {
        Self::check_values(grid, &values)?;
        Ok(Self { values })
    }

    /// The checks of [`Heights::from_values`] without copying.
    pub(crate) fn check_values(grid: &Grid, values: &[f64]) -> Result<()> {
        check_slice("heights", values, grid.len())?;
        if let Some((index, &value)) = values.iter().enumerate().find(|(_, h)| **h <= 0.0) {
            return Err(Error::NonPositiveHeight { index, value });
        }
        Ok(())
    }

    /// The heights (m), in cell order.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Number of sites.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether there is no site (never true for heights built on a grid).
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

impl TryFrom<Vec<f64>> for Heights {
    type Error = Error;

    /// Heights (m) in cell order `i = iy·Nx + ix`, validated: at least one, each finite
    /// and `> 0`. The count is checked against the grid where they are used
    /// ([`Interface::new`], [`crate::SceneBuilder::build`]); [`Heights::from_values`]
    /// checks it at once.
    ///
    /// ```
    /// use precursors::Heights;
    /// let heights = Heights::try_from(vec![1e-6, 2e-6, 0.5e-6])?;
    /// assert_eq!(heights.values(), &[1e-6, 2e-6, 0.5e-6]);
    /// assert!(Heights::try_from(vec![1e-6, 0.0]).is_err());
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::EmptyInput`] for no value, [`Error::NonFinite`] for a NaN or an infinity,
    /// [`Error::NonPositiveHeight`] for a value `≤ 0`.
    fn try_from(values: Vec<f64>) -> Result<Self> {
        check_heights(&values)?;
        Ok(Self { values })
    }
}

impl TryFrom<&[f64]> for Heights {
    type Error = Error;

    /// As `TryFrom<Vec<f64>>` (copies the values).
    ///
    /// # Errors
    /// As `TryFrom<Vec<f64>>`.
    fn try_from(values: &[f64]) -> Result<Self> {
        check_heights(values)?;
        Ok(Self {
            values: values.to_vec(),
        })
    }
}

/// At least one height, each finite and `> 0` (m).
fn check_heights(values: &[f64]) -> Result<()> {
    if values.is_empty() {
        return Err(Error::EmptyInput {
            what: "heights",
            reason: "an interface needs one height per cell",
        });
    }
    check_slice("heights", values, values.len())?;
    if let Some((index, &value)) = values.iter().enumerate().find(|(_, h)| **h <= 0.0) {
        return Err(Error::NonPositiveHeight { index, value });
    }
    Ok(())
}

/// State of one interfacial spring.
///
/// ```
/// use precursors::{Block, Error, Grid, Heights, Interface, SiteState, SpringLaw};
/// use SiteState::{Attached, Broken, Detached};
/// let grid = Grid::new(Block::new(0.003, 0.001, 0.005)?, 3, 1)?;   // three 1 mm cells
/// let heights = Heights::from_values(&grid, vec![1e-6; 3])?;        // u0 = 1 µm
/// let mut interface = Interface::new(grid, heights, SpringLaw::default())?;
/// interface.set_states(&[Attached, Detached, Attached])?;           // e.g. a normal solve's
/// interface.break_site(2)?;                                         // Coulomb slip of site 2
/// assert_eq!(interface.states(), &[Attached, Detached, Broken]);
/// // Only attached sites resist shear: k_x = c_x e^{-u_z/u0} = c_x at u_z = 0 (N/m³).
/// assert_eq!(interface.tangential_stiffness(&[0.0; 3])?, vec![1.65e12, 0.0, 0.0]);
/// // A broken site never re-attaches (only `heal` starts a fresh contact).
/// let e = interface.set_states(&[Attached; 3]).unwrap_err();
/// assert!(matches!(e, Error::BrokenSite { index: 2 }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum SiteState {
    /// In contact: pushes with `φ_z = k_z (u0 - u_z) ≥ 0` and resists shear with `φ_x = -k_x u_x`.
    Attached,
    /// Out of contact (`u_z > u0`): no force; re-attaches when `u_z` falls below `u0`.
    Detached,
    /// Slipped under the Coulomb rule: no force, never re-attaches.
    Broken,
}

/// The springs of the bottom face: heights, law and the state of every site.
///
/// ```
/// use precursors::{Block, Grid, Heights, Interface, SpringLaw};
/// let grid = Grid::new(Block::new(0.004, 0.002, 0.005)?, 4, 2)?;   // eight 1 mm² cells
/// let heights = Heights::from_values(&grid, [1e-6, 2e-6].repeat(4))?; // u0 (m)
/// let mut interface = Interface::new(grid, heights, SpringLaw::default())?;
/// assert_eq!(interface.attached_count(), 8);                        // all attached at first
/// // k_z = c_z / u0 (N/m³) with the paper's c_z = 1.65e8 N/m².
/// let k_z = interface.normal_stiffness();
/// assert_eq!((k_z[0], k_z[1]), (1.65e8 / 1e-6, 1.65e8 / 2e-6));
/// // At u_z = 0 each site touches over its whole cell: A_R,i = ΔA (m²).
/// let area = interface.cell_contact_area(&[0.0; 8])?;
/// assert!(area.iter().all(|a| (a / grid.cell_area() - 1.0).abs() < 1e-12));
/// // The Coulomb rule: a site breaks at λ = μ φ_z / |φ_x(1 N)| (N).
/// let loads = interface.breaking_loads(&[1e3; 8], &[10.0; 8], 0.5)?; // Pa, Pa/N, μ
/// assert_eq!(loads[0], 50.0);
/// interface.break_site(3)?;
/// assert_eq!((interface.attached_count(), interface.broken_count()), (7, 1));
/// interface.heal();                                                 // a fresh contact
/// assert_eq!(interface.attached_count(), 8);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Interface {
    grid: Grid,
    heights: Heights,
    law: SpringLaw,
    states: Vec<SiteState>,
    /// Per-site `μ`, `c_x` (N/m³), `c_z` (N/m²): `None` takes the scalar (shared: a
    /// driver's interface is a clone of its scene's).
    friction: Option<Arc<[f64]>>,
    c_x: Option<Arc<[f64]>>,
    c_z: Option<Arc<[f64]>>,
}

/// The checks of a map's values: one per site, each finite and `> 0`.
fn site_map(key: &'static str, grid: &Grid, values: Vec<f64>) -> Result<Option<Arc<[f64]>>> {
    if values.len() != grid.len() {
        return Err(Error::LengthMismatch {
            name: key,
            expected: grid.len(),
            found: values.len(),
        });
    }
    if let Some((index, &value)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(Error::MapValue {
            key,
            index,
            value,
            range: "finite and > 0".into(),
        });
    }
    Ok(Some(values.into()))
}

impl Interface {
    /// An interface on `grid` with every site attached (the solvers then detach what
    /// must be). `heights` must have one value per cell.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when the heights are not one per cell.
    pub fn new(grid: Grid, heights: Heights, law: SpringLaw) -> Result<Self> {
        if heights.len() != grid.len() {
            return Err(Error::LengthMismatch {
                name: "heights",
                expected: grid.len(),
                found: heights.len(),
            });
        }
        Ok(Self {
            states: vec![SiteState::Attached; grid.len()],
            grid,
            heights,
            law,
            friction: None,
            c_x: None,
            c_z: None,
        })
    }

    /// The same interface with a friction coefficient per site (dimensionless, in cell
    /// order `i = iy·Nx + ix`) in place of the scalar `μ` of the Coulomb rule: site `i`
    /// breaks at `|φ_x,i| = μ_i φ_z,i` ([`Interface::breaking_loads`] then ignores its
    /// scalar argument but for its checks).
    ///
    /// ```
    /// use precursors::{Block, Grid, Heights, Interface, SpringLaw};
    /// let grid = Grid::new(Block::new(0.002, 0.001, 0.005)?, 2, 1)?;   // two cells
    /// let heights = Heights::from_values(&grid, vec![1e-6; 2])?;
    /// let interface = Interface::new(grid, heights, SpringLaw::default())?
    ///     .with_friction_map(vec![0.4, 0.8])?
    ///     .with_c_z_map(vec![1.65e8, 3.3e8])?;                       // N/m²
    /// // λ_i = μ_i φ_z / |φ_x(1 N)|: 0.4 · 1e3 / 10 and 0.8 · 1e3 / 10 (N).
    /// assert_eq!(interface.breaking_loads(&[1e3; 2], &[10.0; 2], 0.5)?, vec![40.0, 80.0]);
    /// assert_eq!(interface.normal_stiffness(), vec![1.65e8 / 1e-6, 3.3e8 / 1e-6]); // N/m³
    /// assert!(interface.c_x_map().is_none());                       // the scalar c_x
    /// assert!(Interface::new(grid, Heights::from_values(&grid, vec![1e-6; 2])?,
    ///     SpringLaw::default())?.with_friction_map(vec![0.5]).is_err()); // one per site
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for a count other than the grid's; [`Error::MapValue`]
    /// for a value that is not finite and `> 0`.
    pub fn with_friction_map(mut self, values: Vec<f64>) -> Result<Self> {
        self.friction = site_map("maps.friction_coefficient", &self.grid, values)?;
        Ok(self)
    }

    /// The same interface with `c_x` (N/m³) per site in place of the spring law's:
    /// `k_x,i = c_x,i exp(-u_z,i/u0_i)`.
    ///
    /// # Errors
    /// As [`Interface::with_friction_map`].
    pub fn with_c_x_map(mut self, values: Vec<f64>) -> Result<Self> {
        self.c_x = site_map("maps.c_x", &self.grid, values)?;
        Ok(self)
    }

    /// The same interface with `c_z` (N/m²) per site in place of the spring law's:
    /// `k_z,i = c_z,i / u0_i`.
    ///
    /// # Errors
    /// As [`Interface::with_friction_map`].
    pub fn with_c_z_map(mut self, values: Vec<f64>) -> Result<Self> {
        self.c_z = site_map("maps.c_z", &self.grid, values)?;
        Ok(self)
    }

    /// The friction coefficient of every site (cell order), `None` when every site has
    /// the material's scalar `μ`.
    pub fn friction_map(&self) -> Option<&[f64]> {
        self.friction.as_deref()
    }

    /// `c_x` (N/m³) of every site, `None` when every site has the spring law's.
    pub fn c_x_map(&self) -> Option<&[f64]> {
        self.c_x.as_deref()
    }

    /// `c_z` (N/m²) of every site, `None` when every site has the spring law's.
    pub fn c_z_map(&self) -> Option<&[f64]> {
        self.c_z.as_deref()
    }

    /// `c_x` (N/m³) of site `index`.
    #[inline]
    fn c_x_at(&self, index: usize) -> f64 {
        match &self.c_x {
            None => self.law.c_x,
            Some(map) => map[index],
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The spring heights `u0` (m), in cell order.
    pub fn heights(&self) -> &[f64] {
        self.heights.values()
    }

    /// The spring law.
    pub fn law(&self) -> SpringLaw {
        self.law
    }

    /// State of every site, in cell order.
    pub fn states(&self) -> &[SiteState] {
        &self.states
    }

    /// Number of attached sites.
    pub fn attached_count(&self) -> usize {
        self.count(SiteState::Attached)
    }

    /// Number of broken sites.
    pub fn broken_count(&self) -> usize {
        self.count(SiteState::Broken)
    }

    fn count(&self, state: SiteState) -> usize {
        self.states.iter().filter(|s| **s == state).count()
    }

    /// Breaks site `index` (Coulomb slip): it carries no force from now on.
    ///
    /// # Errors
    /// [`Error::SiteOutOfRange`] for an index beyond the grid.
    pub fn break_site(&mut self, index: usize) -> Result<()> {
        let n = self.states.len();
        let state = self
            .states
            .get_mut(index)
            .ok_or(Error::SiteOutOfRange { index, sites: n })?;
        *state = SiteState::Broken;
        Ok(())
    }

    /// Resets every site to attached (a fresh contact on the same substrate).
    pub fn heal(&mut self) {
        self.states.fill(SiteState::Attached);
    }

    pub(crate) fn set_state(&mut self, index: usize, state: SiteState) {
        self.states[index] = state;
    }

    /// Sets every site's state, e.g. to those of a normal equilibrium
    /// ([`crate::solver::NormalEquilibrium::states`]).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `states` does not hold one state per site;
    /// [`Error::BrokenSite`] when a broken site would be revived (only
    /// [`Interface::heal`] does that).
    pub fn set_states(&mut self, states: &[SiteState]) -> Result<()> {
        if states.len() != self.states.len() {
            return Err(Error::LengthMismatch {
                name: "states",
                expected: self.states.len(),
                found: states.len(),
            });
        }
        if let Some(i) = (0..states.len())
            .find(|&i| self.states[i] == SiteState::Broken && states[i] != SiteState::Broken)
        {
            return Err(Error::BrokenSite { index: i });
        }
        self.states.copy_from_slice(states);
        Ok(())
    }

    // `breaking_loads`, the Coulomb rule, is defined with the contact rule (contact.rs).

    /// Normal stiffness per unit area `k_z = c_z / u0` (N/m³) of every site (the value
    /// while attached; a detached or broken site exerts no force).
    pub fn normal_stiffness(&self) -> Vec<f64> {
        match &self.c_z {
            None => self.heights().iter().map(|h| self.law.c_z / h).collect(),
            Some(c_z) => self
                .heights()
                .iter()
                .zip(c_z.iter())
                .map(|(h, c)| c / h)
                .collect(),
        }
    }

    /// Normal compliance `1 / k_z = u0 / c_z` (m³/N) of every site.
    pub fn normal_compliance(&self) -> Vec<f64> {
        match &self.c_z {
            None => self.heights().iter().map(|h| h / self.law.c_z).collect(),
            Some(c_z) => self
                .heights()
                .iter()
                .zip(c_z.iter())
                .map(|(h, c)| h / c)
                .collect(),
        }
    }

    /// Tangential compliance `1 / k_x = exp(u_z / u0) / c_x` (m³/N) of attached site
    /// `i` at normal displacement `u_z` (m). Finite whenever `u_z ≤ u0` (attached).
    pub(crate) fn tangential_compliance_at(&self, index: usize, u_z: f64) -> Result<f64> {
        let value = (u_z / self.heights()[index]).exp() / self.c_x_at(index);
        if value.is_finite() {
            Ok(value)
        } else {
            Err(Error::NonFinite {
                name: "tangential compliance exp(u_z/u0)/c_x",
                index,
                value,
            })
        }
    }

    /// The elastic energy (J) of site `index`'s tangential spring under the shear traction
    /// `phi` (Pa) at the normal displacement `u_z` (m): `½ k_x u_x² ΔA`, written as
    /// `½ φ_x² ΔA / k_x`. The traction is what the tangential solve determines; `u_x =
    /// -φ_x/k_x` comes out of the elastic product as a difference of large terms whose
    /// rounding `k_x` (up to `c_x e^649` under strong compression) would multiply into
    /// energies of pure noise (docs/stability.md).
    ///
    /// # Errors
    /// [`Error::NonFinite`] when the compliance overflows (as
    /// [`Interface::tangential_compliance_at`]).
    pub(crate) fn rupture_energy(
        &self,
        index: usize,
        u_z: f64,
        phi: f64,
        cell: f64,
    ) -> Result<f64> {
        let compliance = self.tangential_compliance_at(index, u_z)?;
        Ok(0.5 * phi * phi * cell * compliance)
    }

    /// `ln` of [`Interface::rupture_energy`], without an exponential: the key that orders
    /// the candidates of a rupture, which neither underflow (energies below 1e-308 J at the
    /// corners of the valid ranges) nor overflow can tie. `-∞` for a zero traction.
    pub(crate) fn log_rupture_energy(&self, index: usize, u_z: f64, phi: f64, cell: f64) -> f64 {
        2.0 * phi.abs().ln() + (0.5 * cell).ln() + u_z / self.heights()[index]
            - self.c_x_at(index).ln()
    }

    /// Tangential stiffness per unit area (N/m³) at the normal displacements `u_z` (m):
    /// `k_x = c_x exp(-u_z / u0)` on attached sites, 0 on detached and broken ones (as in
    /// the paper). An overflow (a huge penetration of a tiny asperity) is reported as
    /// [`Error::NonFinite`].
    ///
    /// # Errors
    /// [`Error::LengthMismatch`]; [`Error::NonFinite`] for a NaN input or an overflow.
    pub fn tangential_stiffness(&self, u_z: &[f64]) -> Result<Vec<f64>> {
        check_slice("u_z", u_z, self.grid.len())?;
        u_z.iter()
            .enumerate()
            .map(|(index, u)| self.tangential_stiffness_at(index, *u))
            .collect()
    }

    /// [`Interface::tangential_stiffness`] of one site (N/m³).
    pub(crate) fn tangential_stiffness_at(&self, index: usize, u_z: f64) -> Result<f64> {
        if self.states[index] != SiteState::Attached {
            return Ok(0.0);
        }
        let value = self.c_x_at(index) * (-u_z / self.heights()[index]).exp();
        if value.is_finite() {
            Ok(value)
        } else {
            Err(Error::NonFinite {
                name: "tangential stiffness c_x exp(-u_z/u0)",
                index,
                value,
            })
        }
    }

    /// Real contact area per cell (m²) at the normal displacements `u_z` (m):
    /// `ΔA/(e-1) [exp(-(u_z - u0)/u0) - 1]` for attached sites, 0 otherwise. It equals
    /// `ΔA` when `u_z = 0` and, under the paper's [`AreaLaw::Paper`], exceeds it when the
    /// block penetrates below the substrate mean plane (`u_z < 0`); [`AreaLaw::Capped`]
    /// caps it at `ΔA`. Under the paper's law an overflow of the exponential is
    /// reported as [`Error::NonFinite`] (the capped law gives `ΔA`).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`]; [`Error::NonFinite`] for a NaN input or (paper's law) an
    /// overflow.
    pub fn cell_contact_area(&self, u_z: &[f64]) -> Result<Vec<f64>> {
        check_slice("u_z", u_z, self.grid.len())?;
        let cell = self.grid.cell_area();
        let cap = match self.law.area_law {
            AreaLaw::Capped => cell,
            _ => f64::INFINITY,
        };
        let scale = cell / (std::f64::consts::E - 1.0);
        self.heights()
            .iter()
            .zip(u_z)
            .zip(&self.states)
            .enumerate()
            .map(|(index, ((h, u), state))| {
                if *state != SiteState::Attached {
                    return Ok(0.0);
                }
                let value = scale * ((-(u - h) / h).exp() - 1.0);
                if value > cap {
                    // Also an overflow to +∞ under the capped law.
                    Ok(cap)
                } else if value.is_finite() {
                    Ok(value.max(0.0))
                } else {
                    Err(Error::NonFinite {
                        name: "real contact area",
                        index,
                        value,
                    })
                }
            })
            .collect()
    }
}

/// A [`Material`] as serde sees it (feature `serde`): the scene file's `material` keys
/// (a missing one takes the default), read back through [`Material::new`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct MaterialFields {
    young_modulus: f64,
    poisson_ratio: f64,
    friction_coefficient: f64,
}

#[cfg(feature = "serde")]
impl Default for MaterialFields {
    fn default() -> Self {
        Material::default().into()
    }
}

#[cfg(feature = "serde")]
impl From<Material> for MaterialFields {
    fn from(m: Material) -> Self {
        Self {
            young_modulus: m.young_modulus,
            poisson_ratio: m.poisson_ratio,
            friction_coefficient: m.friction_coefficient,
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<MaterialFields> for Material {
    type Error = Error;
    fn try_from(f: MaterialFields) -> Result<Self> {
        Material::new(f.young_modulus, f.poisson_ratio, f.friction_coefficient)
    }
}

/// A [`SpringLaw`] as serde sees it (feature `serde`): the scene file's `springs` keys (a
/// missing one takes the default), read back through [`SpringLaw::new`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SpringLawFields {
    c_x: f64,
    c_z: f64,
    area_law: AreaLaw,
}

#[cfg(feature = "serde")]
impl Default for SpringLawFields {
    fn default() -> Self {
        SpringLaw::default().into()
    }
}

#[cfg(feature = "serde")]
impl From<SpringLaw> for SpringLawFields {
    fn from(law: SpringLaw) -> Self {
        Self {
            c_x: law.c_x,
            c_z: law.c_z,
            area_law: law.area_law,
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<SpringLawFields> for SpringLaw {
    type Error = Error;
    fn try_from(f: SpringLawFields) -> Result<Self> {
        Ok(SpringLaw::new(f.c_x, f.c_z)?.with_area_law(f.area_law))
    }
}

/// A [`HeightDistribution`] as serde sees it (feature `serde`): the scene file's
/// `gaussian` heights keys `mean` and `std_dev` (a missing one takes the default), read
/// back through [`HeightDistribution::new`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct HeightDistributionFields {
    mean: f64,
    std_dev: f64,
}

#[cfg(feature = "serde")]
impl Default for HeightDistributionFields {
    fn default() -> Self {
        HeightDistribution::default().into()
    }
}

#[cfg(feature = "serde")]
impl From<HeightDistribution> for HeightDistributionFields {
    fn from(d: HeightDistribution) -> Self {
        Self {
            mean: d.mean,
            std_dev: d.std_dev,
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<HeightDistributionFields> for HeightDistribution {
    type Error = Error;
    fn try_from(f: HeightDistributionFields) -> Result<Self> {
        HeightDistribution::new(f.mean, f.std_dev)
    }
}
