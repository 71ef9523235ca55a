//! The DCT-diagonal products on the device: the four batched cuFFT plans, the grid's buffers, and `y = C3(W ⊙ C2 x)` for a set vector `x`
//! and a diagonal `W` (the operator's, the spectral preconditioner's). The algebra is in
//! kernels.cu's header.

use super::kernels::Launch;
use super::seam::{int, Device, FftKind};
use crate::error::Result;
use crate::green::InfluencePlan;
use crate::solver::system::Compliance;
use cudarc::cufft::sys::double2;

/// The diagonal of the operator with eigenvalues `map(eigenvalue of C_s)` between
/// kernels.cu's unnormalised transforms, row-major `Ny x Nx`.
pub(super) fn table(
    plan: &InfluencePlan,
    compliance: Compliance,
    map: impl Fn(f64) -> f64,
) -> Vec<f64> {
    let n = plan.grid().len();
    plan.mode_weights(|p, m, eigen| map(compliance.eigenvalue(n, p, m, eigen)))
}

/// The grid's buffers and FFT plans.
pub(super) struct Transforms<D: Device> {
    nx: usize,
    ny: usize,
    rows_forward: D::Plan,
    columns_forward: D::Plan,
    columns_inverse: D::Plan,
    rows_inverse: D::Plan,
    /// Real grids (`Nx·Ny`): the rows in, then the columns, then the results.
    real_a: D::Buffer<f64>,
    real_b: D::Buffer<f64>,
    /// Half spectra of the rows (`Ny x (Nx/2 + 1)`) and of the columns (`Nx x (Ny/2 + 1)`).
    rows: D::Buffer<double2>,
    columns: D::Buffer<double2>,
    filtered: D::Buffer<double2>,
}

/// The bytes of [`Transforms`]' buffers on an `nx x ny` grid (the FFT plans' work areas
/// are cuFFT's and counted apart, `memory.rs`).
pub(super) fn transform_bytes(nx: usize, ny: usize) -> f64 {
    let n = (nx * ny) as f64;
    let rows = (ny * (nx / 2 + 1)) as f64;
    let columns = (nx * (ny / 2 + 1)) as f64;
    2.0 * 8.0 * n + 16.0 * (rows + 2.0 * columns)
}

impl<D: Device> Transforms<D> {
    pub(super) fn new(device: &D, nx: usize, ny: usize) -> Result<Self> {
        // Batches of contiguous lines: the rows (Ny lines of Nx), then the columns.
        let plan = |n: usize, batch: usize, kind| device.plan(kind, &[n], batch);
        let alloc = |n: usize| device.zeros::<f64>(n);
        let complex = |n: usize| device.zeros::<double2>(n);
        Ok(Transforms {
            nx,
            ny,
            rows_forward: plan(nx, ny, FftKind::D2Z)?,
            columns_forward: plan(ny, nx, FftKind::D2Z)?,
            columns_inverse: plan(ny, nx, FftKind::Z2D)?,
            rows_inverse: plan(nx, ny, FftKind::Z2D)?,
            real_a: alloc(nx * ny)?,
            real_b: alloc(nx * ny)?,
            rows: complex(ny * (nx / 2 + 1))?,
            columns: complex(nx * (ny / 2 + 1))?,
            filtered: complex(nx * (ny / 2 + 1))?,
        })
    }

    /// `real_b = C3(W ⊙ C2 x)` on the grid in kernels.cu's row order, `x` the set vector
    /// placed by `pos`.
    pub(super) fn filter(
        &mut self,
        k: &D,
        table: &D::Buffer<f64>,
        x: &D::Buffer<f64>,
        pos: &D::Buffer<i32>,
    ) -> Result<()> {
        // The grid's sizes fit an `int` (`CudaCore::new`).
        let (nx, ny) = (
            int("grid cells along x", self.nx)?,
            int("grid cells along y", self.ny)?,
        );
        let n = self.nx * self.ny;
        let rows = self.ny * (self.nx / 2 + 1);
        let columns = self.nx * (self.ny / 2 + 1);
        if let Some(cfg) = k.over("grid cells", n)? {
            // SAFETY: `x` holds a value per set site, `pos` and `real_a` Nx·Ny values.
            unsafe { k.scatter_rows(cfg, x, pos, &mut self.real_a, nx, ny) }?;
        }
        k.d2z(
            "cufftExecD2Z (rows)",
            &self.rows_forward,
            &self.real_a,
            &mut self.rows,
        )?;
        if let Some(cfg) = k.over("grid cells", n)? {
            // SAFETY: `rows` holds Ny·(Nx/2 + 1) values, `real_b` Nx·Ny.
            unsafe { k.rows_to_columns(cfg, &self.rows, &mut self.real_b, nx, ny) }?;
        }
        k.d2z(
            "cufftExecD2Z (columns)",
            &self.columns_forward,
            &self.real_b,
            &mut self.columns,
        )?;
        if let Some(cfg) = k.over("half spectra of the columns", columns)? {
            // SAFETY: `columns` and `filtered` hold Nx·(Ny/2 + 1) values, the table Nx·Ny.
            unsafe { k.filter_columns(cfg, &self.columns, table, &mut self.filtered, nx, ny) }?;
        }
        k.z2d(
            "cufftExecZ2D (columns)",
            &self.columns_inverse,
            &mut self.filtered,
            &mut self.real_a,
        )?;
        if let Some(cfg) = k.over("half spectra of the rows", rows)? {
            // SAFETY: `real_a` holds Nx·Ny values, `rows` Ny·(Nx/2 + 1).
            unsafe { k.columns_to_rows(cfg, &self.real_a, &mut self.rows, nx, ny) }?;
        }
        k.z2d(
            "cufftExecZ2D (rows)",
            &self.rows_inverse,
            &mut self.rows,
            &mut self.real_b,
        )
    }

    /// `y = (last filter on the set) + d ⊙ x` (`with_d`) over the `m` sites of `set`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather_set(
        &self,
        k: &D,
        set: &D::Buffer<i32>,
        d: &D::Buffer<f64>,
        x: &D::Buffer<f64>,
        y: &mut D::Buffer<f64>,
        with_d: bool,
        m: usize,
    ) -> Result<()> {
        let Some(cfg) = k.over("sites in the set", m)? else {
            return Ok(());
        };
        let (m32, nx) = (
            int("sites in the set", m)?,
            int("grid cells along x", self.nx)?,
        );
        // SAFETY: set, d, x and y hold at least m values and the set's cells are below
        // Nx·Ny, the values `real_b` holds.
        unsafe { k.gather_set(cfg, &self.real_b, set, d, x, y, i32::from(with_d), m32, nx) }
    }

    /// The last filter on every cell (cell order) into `out`.
    pub(super) fn gather_grid(&self, k: &D, out: &mut D::Buffer<f64>) -> Result<()> {
        let Some(cfg) = k.over("grid cells", self.nx * self.ny)? else {
            return Ok(());
        };
        let (nx, ny) = (
            int("grid cells along x", self.nx)?,
            int("grid cells along y", self.ny)?,
        );
        // SAFETY: `out` and `real_b` hold Nx·Ny values.
        unsafe { k.gather_grid(cfg, &self.real_b, out, nx, ny) }
    }
}
