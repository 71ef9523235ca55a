//! The DCT-diagonal products on the device: the four batched cuFFT plans, the grid's buffers, and `y = C3(W ⊙ C2 x)` for a set vector `x`
//! and a diagonal `W` (the operator's, the spectral preconditioner's). The algebra is in
//! kernels.cu's header.

use super::device::{cuda_error, zeros};
use super::kernels::{int, over, Kernels};
use crate::error::Result;
use crate::green::InfluencePlan;
use crate::solver::system::Compliance;
use cudarc::cufft::sys::{cufftType, double2};
use cudarc::cufft::CudaFft;
use cudarc::driver::{CudaSlice, CudaStream};
use std::sync::Arc;

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
pub(super) struct Transforms {
    nx: usize,
    ny: usize,
    rows_forward: CudaFft,
    columns_forward: CudaFft,
    columns_inverse: CudaFft,
    rows_inverse: CudaFft,
    /// Real grids (`Nx·Ny`): the rows in, then the columns, then the results.
    real_a: CudaSlice<f64>,
    real_b: CudaSlice<f64>,
    /// Half spectra of the rows (`Ny x (Nx/2 + 1)`) and of the columns (`Nx x (Ny/2 + 1)`).
    rows: CudaSlice<double2>,
    columns: CudaSlice<double2>,
    filtered: CudaSlice<double2>,
}

/// The bytes of [`Transforms`]' buffers on an `nx x ny` grid (the FFT plans' work areas
/// are cuFFT's and counted apart, `memory.rs`).
pub(super) fn transform_bytes(nx: usize, ny: usize) -> f64 {
    let n = (nx * ny) as f64;
    let rows = (ny * (nx / 2 + 1)) as f64;
    let columns = (nx * (ny / 2 + 1)) as f64;
    2.0 * 8.0 * n + 16.0 * (rows + 2.0 * columns)
}

impl Transforms {
    pub(super) fn new(stream: &Arc<CudaStream>, nx: usize, ny: usize) -> Result<Self> {
        let plan = |n: usize, batch: usize, kind: cufftType| {
            let (n, batch) = (int("FFT length", n)?, int("FFT batch", batch)?);
            CudaFft::plan_many(&[n], None, 1, 0, None, 1, 0, kind, batch, stream.clone())
                .map_err(|e| cuda_error("cufftPlanMany", e))
        };
        let alloc = |n: usize| zeros::<f64>(stream, n);
        let complex = |n: usize| zeros::<double2>(stream, n);
        Ok(Transforms {
            nx,
            ny,
            rows_forward: plan(nx, ny, cufftType::CUFFT_D2Z)?,
            columns_forward: plan(ny, nx, cufftType::CUFFT_D2Z)?,
            columns_inverse: plan(ny, nx, cufftType::CUFFT_Z2D)?,
            rows_inverse: plan(nx, ny, cufftType::CUFFT_Z2D)?,
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
        stream: &Arc<CudaStream>,
        k: &Kernels,
        table: &CudaSlice<f64>,
        x: &CudaSlice<f64>,
        pos: &CudaSlice<i32>,
    ) -> Result<()> {
        // The grid's sizes fit an `int` (`CudaCore::new`).
        let (nx, ny) = (
            int("grid cells along x", self.nx)?,
            int("grid cells along y", self.ny)?,
        );
        let n = self.nx * self.ny;
        let rows = self.ny * (self.nx / 2 + 1);
        let columns = self.nx * (self.ny / 2 + 1);
        if let Some(cfg) = over("grid cells", n)? {
            // SAFETY: `x` holds a value per set site, `pos` and `real_a` Nx·Ny values.
            unsafe { k.scatter_rows(stream, cfg, x, pos, &mut self.real_a, nx, ny) }?;
        }
        self.rows_forward
            .exec_d2z(&self.real_a, &mut self.rows)
            .map_err(|e| cuda_error("cufftExecD2Z (rows)", e))?;
        if let Some(cfg) = over("grid cells", n)? {
            // SAFETY: `rows` holds Ny·(Nx/2 + 1) values, `real_b` Nx·Ny.
            unsafe { k.rows_to_columns(stream, cfg, &self.rows, &mut self.real_b, nx, ny) }?;
        }
        self.columns_forward
            .exec_d2z(&self.real_b, &mut self.columns)
            .map_err(|e| cuda_error("cufftExecD2Z (columns)", e))?;
        if let Some(cfg) = over("half spectra of the columns", columns)? {
            // SAFETY: `columns` and `filtered` hold Nx·(Ny/2 + 1) values, the table Nx·Ny.
            unsafe {
                k.filter_columns(
                    stream,
                    cfg,
                    &self.columns,
                    table,
                    &mut self.filtered,
                    nx,
                    ny,
                )
            }?;
        }
        self.columns_inverse
            .exec_z2d(&mut self.filtered, &mut self.real_a)
            .map_err(|e| cuda_error("cufftExecZ2D (columns)", e))?;
        if let Some(cfg) = over("half spectra of the rows", rows)? {
            // SAFETY: `real_a` holds Nx·Ny values, `rows` Ny·(Nx/2 + 1).
            unsafe { k.columns_to_rows(stream, cfg, &self.real_a, &mut self.rows, nx, ny) }?;
        }
        self.rows_inverse
            .exec_z2d(&mut self.rows, &mut self.real_b)
            .map_err(|e| cuda_error("cufftExecZ2D (rows)", e))
    }

    /// `y = (last filter on the set) + d ⊙ x` (`with_d`) over the `m` sites of `set`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather_set(
        &self,
        stream: &Arc<CudaStream>,
        k: &Kernels,
        set: &CudaSlice<i32>,
        d: &CudaSlice<f64>,
        x: &CudaSlice<f64>,
        y: &mut CudaSlice<f64>,
        with_d: bool,
        m: usize,
    ) -> Result<()> {
        let Some(cfg) = over("sites in the set", m)? else {
            return Ok(());
        };
        let (m32, nx) = (
            int("sites in the set", m)?,
            int("grid cells along x", self.nx)?,
        );
        // SAFETY: set, d, x and y hold at least m values and the set's cells are below
        // Nx·Ny, the values `real_b` holds.
        unsafe {
            k.gather_set(
                stream,
                cfg,
                &self.real_b,
                set,
                d,
                x,
                y,
                i32::from(with_d),
                m32,
                nx,
            )
        }
    }

    /// The last filter on every cell (cell order) into `out`.
    pub(super) fn gather_grid(
        &self,
        stream: &Arc<CudaStream>,
        k: &Kernels,
        out: &mut CudaSlice<f64>,
    ) -> Result<()> {
        let Some(cfg) = over("grid cells", self.nx * self.ny)? else {
            return Ok(());
        };
        let (nx, ny) = (
            int("grid cells along x", self.nx)?,
            int("grid cells along y", self.ny)?,
        );
        // SAFETY: `out` and `real_b` hold Nx·Ny values.
        unsafe { k.gather_grid(stream, cfg, &self.real_b, out, nx, ny) }
    }
}
