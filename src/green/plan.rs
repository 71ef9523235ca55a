//! The Galerkin influence operator of the grid (docs/model.md section 2), planned once
//! per geometry and shared.
//!
//! `Ĝ_ij = (1/ΔA²) ∫_cell i ∫_cell j G(x,ξ;y,η;0,0) dA dA'` is diagonal in the 2-D DCT-II
//! basis of the grid. With `θ = p'π/(2Nx)` the aliases of the mode `p'` are the
//! wavenumbers `k = 2|θ + qπ|/Δx`, `q ∈ ℤ`, with cell-averaging weights
//! `S² = sin²θ/(θ + qπ)²` (summing to 1), and
//!
//! `Ĝ_ij = Σ_{p',m'} λ(p',m') cos(p'π(ix_i+½)/Nx) cos(p'π(ix_j+½)/Nx) cos(m'π(iy_i+½)/Ny) cos(m'π(iy_j+½)/Ny)`,
//! `λ(p',m') = (4/(Lx Ly)) Σ_{aliases} w_p w_m S_p² S_m² coth(κ Lz)/κ` (m⁻¹),
//!
//! `κ² = k_p² + k_m²`, `w_0 = ½`, and `Lz/3` in place of `coth(κLz)/κ` at `κ = 0`.
//! The alias sum is not summed term by term (it converges like `1/Q`): written as an
//! integral over a Gaussian's width of a product of two 1-D alias sums, it is evaluated
//! to about 1e-13 for every mode in `O(N)` work, whatever the tolerance
//! (`green/spectrum.rs`, `docs/accuracy.md`).

use super::dct::{cosine_table, Dct2d};
use super::spectrum::eigenvalues;
use crate::error::{check_slice, check_tolerance, Error, Result};
use crate::geometry::Grid;
use std::sync::Arc;

/// Largest grid for which [`InfluencePlan::dense`] assembles a matrix.
pub const DENSE_LIMIT: usize = 20_000;

/// Builder of an [`InfluencePlan`].
///
/// ```
/// use precursors::{green::InfluencePlan, Block, Error, Grid};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.005)?, 10, 4)?;    // 40 cells of 1 mm²
/// let plan = InfluencePlan::builder(grid).plan_tolerance(1e-10).build()?;
/// assert_eq!(plan.plan_tolerance(), 1e-10);
/// assert!(plan.max_relative_error() <= 1e-10);          // every eigenvalue within it
/// // A cap on the grid's size, checked before anything is computed.
/// let e = InfluencePlan::builder(grid).max_cells(20).build().unwrap_err();
/// assert!(matches!(e, Error::GridTooLarge { nx: 10, ny: 4, limit: 20, .. }));
/// let e = InfluencePlan::builder(grid).plan_tolerance(0.0).build().unwrap_err();
/// assert!(matches!(e, Error::InvalidTolerance { .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone)]
#[must_use]
pub struct InfluencePlanBuilder {
    grid: Grid,
    tolerance: f64,
    max_cells: usize,
}

impl InfluencePlanBuilder {
    /// The plan tolerance: the largest relative error accepted on an eigenvalue
    /// (dimensionless, default `1e-8`; the scene's [`crate::SceneBuilder::plan_tolerance`],
    /// scene-file key `plan_tolerance`; the solver's linear tolerance is another,
    /// [`crate::solver::SolverOptions::tolerance`]). The eigenvalues are computed to about 1e-13
    /// whatever it is (same cost); the build fails with [`Error::SeriesNotConverged`] when an
    /// eigenvalue's error estimate exceeds it, which happens for tolerances below about
    /// `2e-13`.
    pub fn plan_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// The most cells [`InfluencePlanBuilder::build`] accepts (default
    /// [`DEFAULT_MAX_CELLS`](super::DEFAULT_MAX_CELLS) = `1e6`): a larger grid is refused
    /// with [`Error::GridTooLarge`] and its estimated cost ([`GridCost`](crate::GridCost))
    /// before anything is allocated. Raise it for a grid whose cost you accept.
    pub fn max_cells(mut self, max_cells: usize) -> Self {
        self.max_cells = max_cells;
        self
    }

    /// Computes the eigenvalues and plans the DCTs.
    ///
    /// # Errors
    /// [`Error::GridTooLarge`] above [`InfluencePlanBuilder::max_cells`] cells;
    /// [`Error::InvalidTolerance`] for a tolerance that is not finite and `> 0`;
    /// [`Error::SeriesNotConverged`] when an eigenvalue's error estimate exceeds the tolerance.
    pub fn build(self) -> Result<InfluencePlan> {
        let grid = self.grid;
        super::check_cells(grid.nx(), grid.ny(), self.max_cells)?;
        let tol = check_tolerance(self.tolerance)?;
        #[cfg(test)]
        super::built::count(|b| b.plans += 1);
        let (lambda, errors, nodes) = eigenvalues(&grid);
        let mut max_rel_error: f64 = 0.0;
        for (&value, &error) in lambda.iter().zip(&errors) {
            if error > tol * value {
                return Err(Error::SeriesNotConverged {
                    what: "an eigenvalue of the influence operator (computed to about 1e-13 at \
                           best, from quadrature nodes counted as terms)",
                    value,
                    error,
                    tolerance: tol,
                    terms: nodes as u64,
                });
            }
            max_rel_error = max_rel_error.max(error / value);
        }
        Ok(InfluencePlan::from_eigenvalues(
            grid,
            tol,
            lambda,
            max_rel_error,
        ))
    }
}

/// The Galerkin influence operator `Ĝ` of a grid, planned once and reused.
///
/// `Ĝ` maps cell-constant tractions on the bottom face (Pa) to cell-averaged
/// displacements times `M/ΔA`: the displacement is `u = ⟨u⟩ + (ΔA/M) Ĝ φ`; its entries
/// are in m⁻¹. It is applied matrix-free through the 2-D DCT in `O(N log N)`
/// ([`InfluencePlan::apply`]) or assembled densely for small grids ([`InfluencePlan::dense`]).
///
/// A plan is cheap to clone: clones share the eigenvalues and the planned transforms
/// (`Arc`), so one plan serves every scene, solver and probe of its geometry
/// ([`crate::Scene::builder`]'s `plan`, [`Planner`](super::Planner)).
///
/// ```
/// use precursors::{green::InfluencePlan, Block, Grid};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.005)?, 10, 4)?;    // 40 cells of 1 mm²
/// let plan = InfluencePlan::builder(grid).build()?;
/// let n = grid.len();
/// let dense = plan.dense()?;                              // Ĝ, 40 x 40, row-major (m⁻¹)
/// let scale = dense[0];
/// assert!((dense[3 * n + 17] - dense[17 * n + 3]).abs() < 1e-10 * scale); // symmetric
/// // 1 Pa on cell 17: the matrix-free product is the dense column, largest at the cell.
/// let mut traction = vec![0.0; n];
/// traction[17] = 1.0;
/// let mut u = vec![0.0; n];
/// plan.apply(&traction, &mut u)?;
/// assert!((u[3] - dense[3 * n + 17]).abs() < 1e-10 * scale);
/// assert!(u.iter().all(|&v| v <= u[17]));
/// // The mean mode's eigenvalue is Lz / (3 ΔA) (m⁻¹).
/// let mean = plan.eigenvalue(0, 0).unwrap();
/// assert!((mean / (0.005 / (3.0 * grid.cell_area())) - 1.0).abs() < 1e-9);
/// assert!(plan.clone().same_plan(&plan));                 // clones share one plan
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Clone)]
pub struct InfluencePlan {
    inner: Arc<PlanData>,
}

struct PlanData {
    grid: Grid,
    tolerance: f64,
    lambda: Vec<f64>,
    /// The operator's table: λ scaled for unnormalised DCT-III (×2 for p' = 0 and for
    /// m' = 0).
    table: SpectralTable,
    max_rel_error: f64,
    dct: Arc<Dct2d>,
}

/// The diagonal of an operator with the eigenvectors of `Ĝ` (the 2-D DCT-II modes of the
/// grid), in the form the plan's transforms apply ([`InfluencePlan::spectral_table`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SpectralTable(Vec<f64>);

impl SpectralTable {
    /// Row-major `Ny x Nx`, in the scaling of the unnormalised transforms.
    pub(super) fn values(&self) -> &[f64] {
        &self.0
    }
}

impl std::fmt::Debug for InfluencePlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InfluencePlan")
            .field("grid", &self.inner.grid)
            .field("tolerance", &self.inner.tolerance)
            .field("max_rel_error", &self.inner.max_rel_error)
            .finish_non_exhaustive()
    }
}

/// Diagonal for [`Dct2d::filter`]: the eigenvalue table times the DCT-III scaling.
pub(super) fn dct_diagonal(grid: &Grid, values: &[f64]) -> Vec<f64> {
    let (nx, ny) = (grid.nx(), grid.ny());
    let mut out = values.to_vec();
    for m in 0..ny {
        for p in 0..nx {
            let mut s = 1.0;
            if p == 0 {
                s *= 2.0;
            }
            if m == 0 && ny > 1 {
                s *= 2.0;
            }
            out[m * nx + p] *= s;
        }
    }
    out
}

impl InfluencePlan {
    /// A builder for the operator of `grid` with the default tolerance.
    pub fn builder(grid: Grid) -> InfluencePlanBuilder {
        InfluencePlanBuilder {
            grid,
            tolerance: 1e-8,
            max_cells: super::DEFAULT_MAX_CELLS,
        }
    }

    fn from_eigenvalues(grid: Grid, tolerance: f64, lambda: Vec<f64>, max_rel_error: f64) -> Self {
        let table = SpectralTable(dct_diagonal(&grid, &lambda));
        Self {
            inner: Arc::new(PlanData {
                dct: Arc::new(Dct2d::new(grid.nx(), grid.ny())),
                grid,
                tolerance,
                lambda,
                table,
                max_rel_error,
            }),
        }
    }

    /// Whether `self` and `other` share one planned operator (clones of one plan).
    pub fn same_plan(&self, other: &InfluencePlan) -> bool {
        Arc::ptr_eq(&self.inner, &other.inner)
    }

    /// The planned transforms (the plane transfer shares them).
    pub(super) fn dct(&self) -> &Arc<Dct2d> {
        &self.inner.dct
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.inner.grid
    }

    /// The plan tolerance the plan was built with: the largest relative error it accepted
    /// on an eigenvalue ([`InfluencePlanBuilder::plan_tolerance`]).
    pub fn plan_tolerance(&self) -> f64 {
        self.inner.tolerance
    }

    /// Largest estimated relative error of an eigenvalue.
    pub fn max_relative_error(&self) -> f64 {
        self.inner.max_rel_error
    }

    /// `λ(p', m')` (m⁻¹), the coefficient of `cos(p'·)cos(p'·)cos(m'·)cos(m'·)` in `Ĝ`
    /// (module docs); `p' < Nx`, `m' < Ny`. `None` outside the grid. The public form is
    /// [`InfluencePlan::eigenvalue`] (the same number in the orthonormal basis).
    pub(crate) fn lambda(&self, p: usize, m: usize) -> Option<f64> {
        (p < self.inner.grid.nx() && m < self.inner.grid.ny())
            .then(|| self.inner.lambda[m * self.inner.grid.nx() + p])
    }

    /// Eigenvalue of `Ĝ` (m⁻¹) for the orthonormal DCT-II mode `(p', m')`:
    /// `λ / (α_p'² α_m'²)` with `α_0² = 1/N`, `α_{>0}² = 2/N`.
    pub fn eigenvalue(&self, p: usize, m: usize) -> Option<f64> {
        let (nx, ny) = (self.inner.grid.nx() as f64, self.inner.grid.ny() as f64);
        let ax = if p == 0 { 1.0 / nx } else { 2.0 / nx };
        let ay = if m == 0 { 1.0 / ny } else { 2.0 / ny };
        self.lambda(p, m).map(|l| l / (ax * ay))
    }

    /// `out = Ĝ v` (m⁻¹ times the units of `v`), matrix-free in `O(N log N)`. Allocates
    /// its scratch on every call: repeated products go through
    /// [`InfluencePlan::apply_with_scratch`].
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `v` or `out` does not hold one value per cell;
    /// [`Error::NonFinite`] for a NaN or infinite input.
    pub fn apply(&self, v: &[f64], out: &mut [f64]) -> Result<()> {
        let n = self.inner.grid.len();
        check_slice("v", v, n)?;
        if out.len() != n {
            return Err(Error::LengthMismatch {
                name: "out",
                expected: n,
                found: out.len(),
            });
        }
        out.copy_from_slice(v);
        self.apply_with_scratch(out, &mut vec![0.0; self.scratch_len()])
    }

    /// The scratch [`InfluencePlan::apply_with_scratch`] needs: this many `f64` values
    /// (about `N` plus the 1-D transforms' own; fixed per plan).
    pub fn scratch_len(&self) -> usize {
        self.inner.dct.filter_scratch_len()
    }

    /// `buffer ← Ĝ buffer` in place (m⁻¹ times the units of `buffer`), with caller-owned
    /// scratch of at least [`InfluencePlan::scratch_len`] values whose contents are
    /// overwritten: no allocation, so a loop of products allocates once (the convention of
    /// rustdct's `process_dct2_with_scratch`).
    ///
    /// ```
    /// use precursors::{Block, Grid, green::InfluencePlan};
    /// let grid = Grid::from_cell_size(Block::new(0.14, 0.007, 0.075)?, 1e-3, 1e-3)?;
    /// let plan = InfluencePlan::builder(grid).build()?;
    /// let mut scratch = vec![0.0; plan.scratch_len()];
    /// let mut u = vec![1.0; grid.len()];                     // 1 Pa everywhere
    /// for _ in 0..3 {
    ///     plan.apply_with_scratch(&mut u, &mut scratch)?;    // Ĝ³ φ, no allocation
    /// }
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `buffer` does not hold one value per cell or
    /// `scratch` is shorter than [`InfluencePlan::scratch_len`]; [`Error::NonFinite`] for a
    /// NaN or infinite input.
    pub fn apply_with_scratch(&self, buffer: &mut [f64], scratch: &mut [f64]) -> Result<()> {
        check_slice("buffer", buffer, self.inner.grid.len())?;
        let need = self.scratch_len();
        if scratch.len() < need {
            return Err(Error::LengthMismatch {
                name: "scratch",
                expected: need,
                found: scratch.len(),
            });
        }
        self.filter_in_place(&self.inner.table, buffer, scratch);
        Ok(())
    }

    /// `buf ← T buf` in place for an operator `T` with `Ĝ`'s eigenvectors, given by its
    /// table (`scratch`: at least [`InfluencePlan::scratch_len`] values).
    pub(crate) fn filter_in_place(
        &self,
        table: &SpectralTable,
        buf: &mut [f64],
        scratch: &mut [f64],
    ) {
        let nx = self.inner.grid.nx();
        self.inner.dct.filter(buf, &table.0, nx, scratch);
    }

    /// The operator's own table.
    pub(crate) fn operator_table(&self) -> &SpectralTable {
        &self.inner.table
    }

    /// The table of the operator with the same eigenvectors as `Ĝ` and eigenvalues
    /// `map(p', m', eigenvalue(p', m'))`.
    pub(crate) fn spectral_table(&self, map: impl Fn(usize, usize, f64) -> f64) -> SpectralTable {
        SpectralTable(dct_diagonal(&self.inner.grid, &self.mode_weights(map)))
    }

    /// The weights `map(p', m', eigenvalue(p', m')) α_p'² α_m'²` of an operator with the
    /// eigenvectors of `Ĝ`, row-major `Ny x Nx`: its diagonal between the unnormalised
    /// DCT-II and its transpose (the CUDA backend's tables; the host's add the DCT-III's
    /// halved first term, [`InfluencePlan::spectral_table`]).
    pub(crate) fn mode_weights(&self, map: impl Fn(usize, usize, f64) -> f64) -> Vec<f64> {
        let (nx, ny) = (self.inner.grid.nx(), self.inner.grid.ny());
        let mut values = vec![0.0; nx * ny];
        for m in 0..ny {
            let ay = if m == 0 { 1.0 } else { 2.0 } / ny as f64;
            for p in 0..nx {
                let ax = if p == 0 { 1.0 } else { 2.0 } / nx as f64;
                let k = m * nx + p;
                let eigen = self.inner.lambda[k] / (ax * ay);
                values[k] = map(p, m, eigen) * (ax * ay);
            }
        }
        values
    }

    /// The dense matrix `Ĝ` (m⁻¹), row-major `N x N`, assembled from the eigenvalue table
    /// by explicit cosine sums (independent of the DCT path). Refused above
    /// [`DENSE_LIMIT`] cells.
    ///
    /// # Errors
    /// [`Error::TooLargeForDense`] above [`DENSE_LIMIT`] cells.
    pub fn dense(&self) -> Result<Vec<f64>> {
        let n = self.inner.grid.len();
        if n > DENSE_LIMIT {
            return Err(Error::TooLargeForDense {
                n,
                limit: DENSE_LIMIT,
            });
        }
        let (nx, ny) = (self.inner.grid.nx(), self.inner.grid.ny());
        let cx = cosine_table(nx);
        let cy = cosine_table(ny);
        // B_m[a][b] = Σ_p λ(p,m) cx[p][a] cx[p][b], then Ĝ = Σ_m cy[m]⊗cy[m] ⊗ B_m.
        let mut g = vec![0.0; n * n];
        let mut bm = vec![0.0; nx * nx];
        for m in 0..ny {
            bm.iter_mut().for_each(|x| *x = 0.0);
            for p in 0..nx {
                let l = self.inner.lambda[m * nx + p];
                let row = &cx[p * nx..(p + 1) * nx];
                for a in 0..nx {
                    let la = l * row[a];
                    for b in 0..nx {
                        bm[a * nx + b] += la * row[b];
                    }
                }
            }
            let crow = &cy[m * ny..(m + 1) * ny];
            for iy in 0..ny {
                for jy in 0..ny {
                    let c = crow[iy] * crow[jy];
                    for a in 0..nx {
                        let dst =
                            &mut g[(iy * nx + a) * n + jy * nx..(iy * nx + a) * n + jy * nx + nx];
                        let src = &bm[a * nx..(a + 1) * nx];
                        for (d, s) in dst.iter_mut().zip(src) {
                            *d += c * s;
                        }
                    }
                }
            }
        }
        Ok(g)
    }
}
