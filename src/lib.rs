//! # precursors
//!
//! The scalar elastic model of frictional precursors of A. Taloni, A. Benassi, S. Sandfeld
//! and S. Zapperi, "Scalar model for frictional precursors dynamics": a 3-D elastic block
//! `[0,Lx] x [0,Ly] x [0,Lz]` on a rough rigid substrate, two decoupled scalar Laplace
//! problems `M ∇²u_x = 0`, `M ∇²u_z = 0` (`M = E/(1+ν)`) solved with the box's Neumann
//! Green function, and a grid of interfacial springs on the bottom face.
//!
//! Units are SI throughout: lengths in m, forces in N, tractions and stresses in Pa.
//! Sign conventions are those of [`docs/model.md`][model] section 1: both shear loads
//! point along +x, the normal load presses the block down, bottom tractions `φ_z ≥ 0`
//! push up.
//!
//! [model]: https://github.com/precursors-model/precursors/blob/main/docs/model.md
//!
//! Where things are (each item has one path):
//!
//! * the crate root: the model as a user runs it. A [`Scene`] (from a [`SceneBuilder`]:
//!   [`Block`], [`Grid`], [`Material`], [`SpringLaw`], [`Heights`], [`Drive`], probes)
//!   gives a [`Driver`], an iterator of [`Event`]s (ruptures, detachments, attachments,
//!   load steps, stable states, global slip) with the observables between them (real
//!   contact area, precursor length, tractions, [`Stresses`] on planes and at points) and
//!   [`Checkpoint`]s; one [`Error`] type for all of it. The [`ContactRule`] of the site
//!   transitions is the paper's by default; a downstream crate writes its own as a
//!   [`ContactLaw`].
//! * [`green`]: the box's Neumann Green function (`G` and `∂G/∂z` at points, the load
//!   terms) and the Galerkin influence operator of a grid, planned once per geometry and
//!   applied matrix-free through the 2-D DCT.
//! * [`solver`]: the normal and tangential equilibria (dense and spectral backends), their
//!   options and reports, usable without a driver.
//! * [`calibration`]: fits of the paper's two adjustable spring constants.
//! * [`output`]: the tables of a run directory, as the program writes them.
//! * `sweep` (feature `serde`): studies over scene keys and realizations, run in a
//!   directory and merged into ensemble tables; `plot` (feature `plot`): figures.
//!
//! Features: `serde` (JSON scene files and checkpoints), `nalgebra` (heights from and
//! fields to `nalgebra` matrices and vectors, row `iy` and column `ix`), `plot` (module
//! `plot`: figures with axes, units, legends and colour bars as PNG or SVG), `cli` (the
//! program `precursors`, [docs/cli.md][cli]).
//!
//! **Stability.** From 1.0 the crate follows semantic versioning: the public API (one
//! path per item, listed in `api/public-api.txt` and checked in CI), the scene-file format,
//! the checkpoint layout (version 3) and the run and sweep directory layouts change
//! incompatibly only in a new major version; event sequences may change at rounding
//! level in a minor release, with a CHANGELOG entry. What is and is not covered, and the
//! MSRV policy: [docs/compatibility.md][compat].
//!
//! [cli]: https://github.com/precursors-model/precursors/blob/main/docs/cli.md
//! [compat]: https://github.com/precursors-model/precursors/blob/main/docs/compatibility.md
//!
//! A scene driven from zero shear to global slip, event by event: the real contact area,
//! the precursor length `ℓ` and the Coulomb stress on a plane inside the block, read
//! between events (a small block so that the example runs in a moment; the builder's
//! defaults are the paper's calibration scene, docs/model.md):
//!
//! ```
//! use precursors::{Event, ProbeSpec, Scene};
//!
//! let scene = Scene::builder()
//!     .block(0.030, 0.007, 0.075)                       // Lx, Ly, Lz (m)
//!     .cell_size(1e-3, 1e-3)                            // 30 x 7 cells (m)
//!     .normal_load(750.0)                               // F_N (N); rod drive, PMMA
//!     .seed(1)                                          // the heights' realization
//!     .probes(ProbeSpec::default().with_plane(2e-3))    // stresses at z = 2 mm
//!     .build()?;
//! let mut driver = scene.driver()?;
//! let (lx, mu_fn) = (0.030, scene.material().friction_coefficient() * 750.0);
//! while let Some(event) = driver.step()? {
//!     match event {
//!         Event::Stable { load, .. } => {
//!             let area = driver.real_contact_area()?;          // A_R (m²)
//!             let ell = driver.precursor_length()?;             // ℓ (m)
//!             let plane = &driver.stresses()?.planes[0];        // τ, σ, τ_C (Pa)
//!             let profile = plane.profile();                    // along x, y-averaged
//!             let tau_c = profile.mean_coulomb();               // τ_C(x) (Pa)
//!             assert!(area > 0.0 && (0.0..=lx).contains(&ell) && tau_c.len() == 30);
//!             assert!(load.force <= mu_fn * (1.0 + 1e-9));      // F ≤ μF_N
//!         }
//!         Event::GlobalSlip { load } => println!("slip at F/(μF_N) = {}", load.force / mu_fn),
//!         _ => {}                                           // load raised, ruptures, ...
//!     }
//! }
//! # Ok::<(), precursors::Error>(())
//! ```
//!
//! The operator alone, planned once per geometry and applied matrix-free:
//!
//! ```
//! use precursors::{Block, Grid, green::InfluencePlan};
//! let block = Block::new(0.14, 0.007, 0.075)?;          // 140 x 7 x 75 mm
//! let grid = Grid::from_cell_size(block, 1e-3, 1e-3)?;   // 1 mm cells: 140 x 7
//! let plan = InfluencePlan::builder(grid).plan_tolerance(1e-8).build()?;
//! let traction = vec![1.0; grid.len()];                  // 1 Pa everywhere
//! let mut u = vec![0.0; grid.len()];
//! plan.apply(&traction, &mut u)?;                        // Ĝ φ (m⁻¹ Pa)
//! // A uniform traction only excites the mean mode: Σ_j Ĝ_ij = Lz / (3 ΔA).
//! let expected = 0.075 / (3.0 * grid.cell_area());
//! assert!((u[17] - expected).abs() < 1e-9 * expected);
//! # Ok::<(), precursors::Error>(())
//! ```
#![deny(missing_docs)]
#![warn(clippy::missing_errors_doc)]
// Unsafe code only in the CUDA backend (kernel launches, libraries opened by path), which
// allows it for its module alone.
#![cfg_attr(not(feature = "cuda"), forbid(unsafe_code))]
#![cfg_attr(feature = "cuda", deny(unsafe_code))]

mod avalanche;
pub mod calibration;
mod contact;
mod cost;
mod driver;
mod error;
mod files;
mod format;
mod geometry;
pub mod green;
mod interface;
mod lock;
#[cfg(feature = "nalgebra")]
mod matrix;
pub mod output;
#[cfg(feature = "plot")]
pub mod plot;
mod probe;
mod recording;
mod scene;
pub mod solver;
pub mod statistics;
mod surface;
#[cfg(feature = "serde")]
pub mod sweep;

pub use avalanche::{Avalanche, Avalanches, DamageFront};
pub use contact::{ContactLaw, ContactRule, CustomRule, Delay, SiteView};
pub use cost::GridCost;
pub use driver::{
    Checkpoint, Driver, Event, Load, RunState, Site, SlipPerNewton, SlipProfile, SolveStats,
};
pub use error::{Error, Result};
pub use geometry::{Block, Grid, Point};
pub use interface::{
    AreaLaw, HeightDistribution, Heights, Interface, Material, SiteState, SpringLaw,
};
pub use probe::{
    CellStress, PlaneStress, PointStress, ProbeInput, ProbeSpec, Profile, StressProbe, Stresses,
};
pub use recording::{ObserverCost, RunOptions};
pub use scene::{Drive, ForceLoad, HeightSource, Lateral, Scene, SceneBuilder, SiteMap};
pub use surface::SurfaceSpectrum;

/// The `nalgebra` this crate converts to and from (feature `nalgebra`): heights from an
/// `Ny x Nx` `DMatrix` (row `iy`, column `ix`: [`Heights::from_dmatrix`]), fields to a
/// `DMatrix` ([`Grid::field_to_dmatrix`]) or to a `DVector` in the cell order
/// `i = iy·Nx + ix` ([`Grid::field_to_dvector`]).
#[cfg(feature = "nalgebra")]
pub use nalgebra;

/// The README's code blocks, compiled and run as doctests so they stay true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
