//! The DCT-diagonal products on the device: the kernels compiled once per solver, the four
//! batched cuFFT plans, the grid's buffers, and `y = C3(W ⊙ C2 x)` for a set vector `x`
//! and a diagonal `W` (the operator's, the spectral preconditioner's). The algebra is in
//! kernels.cu's header.

use super::device::{cuda_error, guarded, zeros, Gpu};
use crate::error::{Error, Result};
use crate::green::InfluencePlan;
use crate::solver::system::Compliance;
use cudarc::cufft::sys::{cufftType, double2};
use cudarc::cufft::CudaFft;
use cudarc::driver::{CudaFunction, CudaSlice, CudaStream, LaunchConfig, PushKernelArg};
use cudarc::nvrtc::{compile_ptx_with_opts, CompileOptions, Ptx};
use std::sync::{Arc, OnceLock};

/// The kernels' source (NVRTC compiles it when a solver is built).
const SOURCE: &str = include_str!("kernels.cu");

/// Threads per block (kernels.cu's `THREADS`).
pub(super) const THREADS: u32 = 256;

/// One thread per element of `n`, `None` for none (a launch of no blocks is an error).
pub(super) fn over(n: usize) -> Option<LaunchConfig> {
    (n > 0).then(|| LaunchConfig {
        grid_dim: ((n as u32).div_ceil(THREADS), 1, 1),
        block_dim: (THREADS, 1, 1),
        shared_mem_bytes: 0,
    })
}

/// The compiled kernels.
pub(super) struct Kernels {
    pub(super) scatter_rows: CudaFunction,
    pub(super) rows_to_columns: CudaFunction,
    pub(super) filter_columns: CudaFunction,
    pub(super) columns_to_rows: CudaFunction,
    pub(super) gather_set: CudaFunction,
    pub(super) gather_grid: CudaFunction,
    pub(super) residual_tail: CudaFunction,
    pub(super) jacobi: CudaFunction,
    pub(super) pre_updates: CudaFunction,
    pub(super) reduce_partial: CudaFunction,
    pub(super) reduce_final: CudaFunction,
    pub(super) fsai_scatter: CudaFunction,
    pub(super) fsai_g: CudaFunction,
    pub(super) fsai_gt: CudaFunction,
    pub(super) coarse_indicator: CudaFunction,
    pub(super) coarse_restrict: CudaFunction,
    pub(super) coarse_fix_empty: CudaFunction,
    pub(super) coarse_factor: CudaFunction,
    pub(super) coarse_invert: CudaFunction,
    pub(super) coarse_border: CudaFunction,
    pub(super) coarse_solve: CudaFunction,
    pub(super) coarse_prolong: CudaFunction,
}

impl Kernels {
    /// Compiles kernels.cu (once per process) and loads its functions on `gpu`.
    pub(super) fn compile(gpu: &Gpu) -> Result<Self> {
        let unavailable = |reason: String| Error::CudaUnavailable {
            reason,
            hint: "report it with the output of `precursors info` (docs/gpu.md); use backend \
                   \"spectral\" meanwhile"
                .into(),
        };
        // Compiled once per process (NVRTC takes about 250 ms; the backend uses device 0
        // only, so one compute capability), loaded per solver.
        static IMAGE: OnceLock<((u32, u32), std::result::Result<Ptx, String>)> = OnceLock::new();
        let capability = gpu.info.compute_capability;
        let (compiled_for, image) = IMAGE.get_or_init(|| (capability, compile(capability)));
        let ptx = if *compiled_for == capability {
            image.clone()
        } else {
            compile(capability)
        }
        .map_err(unavailable)?;
        let module = guarded("loading the kernels", || {
            gpu.ctx
                .load_module(ptx)
                .map_err(|e| format!("the driver does not load the compiled kernels: {e}"))
        })
        .map_err(unavailable)?;
        let load = |name: &str| {
            module
                .load_function(name)
                .map_err(|e| unavailable(format!("kernel {name} is missing from the module: {e}")))
        };
        Ok(Kernels {
            scatter_rows: load("scatter_rows")?,
            rows_to_columns: load("rows_to_columns")?,
            filter_columns: load("filter_columns")?,
            columns_to_rows: load("columns_to_rows")?,
            gather_set: load("gather_set")?,
            gather_grid: load("gather_grid")?,
            residual_tail: load("residual_tail")?,
            jacobi: load("jacobi")?,
            pre_updates: load("pre_updates")?,
            reduce_partial: load("reduce_partial")?,
            reduce_final: load("reduce_final")?,
            fsai_scatter: load("fsai_scatter")?,
            fsai_g: load("fsai_g")?,
            fsai_gt: load("fsai_gt")?,
            coarse_indicator: load("coarse_indicator")?,
            coarse_restrict: load("coarse_restrict")?,
            coarse_fix_empty: load("coarse_fix_empty")?,
            coarse_factor: load("coarse_factor")?,
            coarse_invert: load("coarse_invert")?,
            coarse_border: load("coarse_border")?,
            coarse_solve: load("coarse_solve")?,
            coarse_prolong: load("coarse_prolong")?,
        })
    }
}

/// kernels.cu compiled for the GPU's architecture (`sm_XY`, a binary the driver loads as
/// it is), else as PTX for the driver to compile. Why a binary first: PTX carries the
/// ISA version of the NVRTC that wrote it, which a driver older than that NVRTC refuses
/// (`CUDA_ERROR_UNSUPPORTED_PTX_VERSION`); a binary of the same major version loads.
fn compile((major, minor): (u32, u32)) -> std::result::Result<Ptx, String> {
    guarded("compiling the kernels (NVRTC)", || {
        let binary = compile_binary(major, minor);
        binary.map(Ptx::from_binary).or_else(|binary_error| {
            let options = CompileOptions {
                name: Some("precursors_kernels.cu".into()),
                ..Default::default()
            };
            compile_ptx_with_opts(SOURCE, options).map_err(|e| {
                format!(
                    "the kernels do not compile with NVRTC (for sm_{major}{minor}: \
                     {binary_error}; as PTX: {e:?})"
                )
            })
        })
    })
}

/// kernels.cu as a binary for `sm_{major}{minor}` (NVRTC's `nvrtcGetCUBIN`, which the
/// bindings' safe API does not wrap).
fn compile_binary(major: u32, minor: u32) -> std::result::Result<Vec<u8>, String> {
    use cudarc::nvrtc::{result, sys};
    use std::ffi::{CStr, CString};
    let source = CString::new(SOURCE).map_err(|e| e.to_string())?;
    let name = CString::new("precursors_kernels.cu").map_err(|e| e.to_string())?;
    let program = result::create_program(&source, Some(&name)).map_err(|e| e.to_string())?;
    let options = [format!("--gpu-architecture=sm_{major}{minor}")];
    // SAFETY: `program` is a live NVRTC program until destroyed below; the log and the
    // binary are read into buffers of the sizes NVRTC reports.
    let outcome = unsafe {
        match result::compile_program(program, &options) {
            Err(e) => {
                let log = result::get_program_log(program)
                    .map(|log| CStr::from_ptr(log.as_ptr()).to_string_lossy().into_owned())
                    .unwrap_or_default();
                Err(format!("{e:?}: {log}"))
            }
            Ok(()) => {
                let mut size = 0usize;
                sys::nvrtcGetCUBINSize(program, &mut size)
                    .result()
                    .and_then(|()| {
                        let mut binary = vec![0u8; size];
                        sys::nvrtcGetCUBIN(program, binary.as_mut_ptr().cast())
                            .result()
                            .map(|()| binary)
                    })
                    .map_err(|e| format!("{e:?}"))
            }
        }
    };
    // SAFETY: destroyed once, after its last use.
    let _ = unsafe { result::destroy_program(program) };
    outcome
}

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
            CudaFft::plan_many(
                &[n as i32],
                None,
                1,
                0,
                None,
                1,
                0,
                kind,
                batch as i32,
                stream.clone(),
            )
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
        let (nx, ny) = (self.nx as i32, self.ny as i32);
        let n = self.nx * self.ny;
        let launch = |call: &'static str, e| cuda_error(call, e);
        if let Some(cfg) = over(n) {
            // SAFETY: the argument list matches kernels.cu's signature; every buffer holds
            // the Nx·Ny values the kernel reads or writes.
            unsafe {
                stream
                    .launch_builder(&k.scatter_rows)
                    .arg(x)
                    .arg(pos)
                    .arg(&mut self.real_a)
                    .arg(&nx)
                    .arg(&ny)
                    .launch(cfg)
            }
            .map_err(|e| launch("scatter_rows", e))?;
        }
        self.rows_forward
            .exec_d2z(&self.real_a, &mut self.rows)
            .map_err(|e| cuda_error("cufftExecD2Z (rows)", e))?;
        if let Some(cfg) = over(n) {
            // SAFETY: as above; `rows` holds Ny·(Nx/2 + 1) values.
            unsafe {
                stream
                    .launch_builder(&k.rows_to_columns)
                    .arg(&self.rows)
                    .arg(&mut self.real_b)
                    .arg(&nx)
                    .arg(&ny)
                    .launch(cfg)
            }
            .map_err(|e| launch("rows_to_columns", e))?;
        }
        self.columns_forward
            .exec_d2z(&self.real_b, &mut self.columns)
            .map_err(|e| cuda_error("cufftExecD2Z (columns)", e))?;
        if let Some(cfg) = over(self.nx * (self.ny / 2 + 1)) {
            // SAFETY: as above; `columns` and `filtered` hold Nx·(Ny/2 + 1) values, the
            // table Nx·Ny.
            unsafe {
                stream
                    .launch_builder(&k.filter_columns)
                    .arg(&self.columns)
                    .arg(table)
                    .arg(&mut self.filtered)
                    .arg(&nx)
                    .arg(&ny)
                    .launch(cfg)
            }
            .map_err(|e| launch("filter_columns", e))?;
        }
        self.columns_inverse
            .exec_z2d(&mut self.filtered, &mut self.real_a)
            .map_err(|e| cuda_error("cufftExecZ2D (columns)", e))?;
        if let Some(cfg) = over(self.ny * (self.nx / 2 + 1)) {
            // SAFETY: as above.
            unsafe {
                stream
                    .launch_builder(&k.columns_to_rows)
                    .arg(&self.real_a)
                    .arg(&mut self.rows)
                    .arg(&nx)
                    .arg(&ny)
                    .launch(cfg)
            }
            .map_err(|e| launch("columns_to_rows", e))?;
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
        let (with_d, m32, nx) = (i32::from(with_d), m as i32, self.nx as i32);
        let Some(cfg) = over(m) else { return Ok(()) };
        // SAFETY: the argument list matches kernels.cu; set, d, x and y hold at least m
        // values and the set's cells are below Nx·Ny.
        unsafe {
            stream
                .launch_builder(&k.gather_set)
                .arg(&self.real_b)
                .arg(set)
                .arg(d)
                .arg(x)
                .arg(y)
                .arg(&with_d)
                .arg(&m32)
                .arg(&nx)
                .launch(cfg)
        }
        .map(|_| ())
        .map_err(|e| cuda_error("gather_set", e))
    }

    /// The last filter on every cell (cell order) into `out`.
    pub(super) fn gather_grid(
        &self,
        stream: &Arc<CudaStream>,
        k: &Kernels,
        out: &mut CudaSlice<f64>,
    ) -> Result<()> {
        let (nx, ny) = (self.nx as i32, self.ny as i32);
        let Some(cfg) = over(self.nx * self.ny) else {
            return Ok(());
        };
        // SAFETY: the argument list matches kernels.cu; `out` holds Nx·Ny values.
        unsafe {
            stream
                .launch_builder(&k.gather_grid)
                .arg(&self.real_b)
                .arg(out)
                .arg(&nx)
                .arg(&ny)
                .launch(cfg)
        }
        .map(|_| ())
        .map_err(|e| cuda_error("gather_grid", e))
    }
}
