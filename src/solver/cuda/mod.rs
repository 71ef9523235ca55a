//! The CUDA backend (feature `cuda`; docs/gpu.md): the spectral backend's rule on an
//! NVIDIA GPU. The set system `A = C_SS + diag(d)` is applied through the DCT-diagonal
//! operator on the device (cuFFT, `operator.rs`, kernels.cu), and pcg.rs's one CG runs its
//! phases there (`phases.rs`): per iteration only the reductions' scalars cross to the
//! host. Per set solve the set, `d`, `b` and the warm start go up and the tractions and
//! the displacements' grid product come back (a few `O(N)` copies).
//!
//! The launch code reaches the device through one seam (`seam.rs`'s `Device`): the GPU
//! (`gpu.rs`) or, in the tests, the host emulator (`emulator.rs`), under the same code.
//!
//! Preconditioners: the host's choices. Cold solves take the restricted spectral inverse;
//! warm normal solves FSAI (its rows built on the host, `fsai.rs`) with the coarse space
//! of aggregates on large grids (`coarse.rs`, kept on the device); warm tangential solves
//! Jacobi.

// Kernel launches, copies and libraries opened by path are unsafe calls of the bindings;
// each says why it is sound.
#![allow(unsafe_code)]

mod coarse;
mod device;
mod fsai;
mod gpu;
mod kernels;
mod libraries;
mod memory;
mod operator;
mod phases;
mod seam;
mod timing;
mod vectors;

#[cfg(test)]
mod emulated;
#[cfg(test)]
mod emulator;

pub use device::{cuda_device, CudaDevice};
pub use timing::{record_cuda_phase_times, CudaPhaseTimes};

use super::fsai::{Entries, Fsai};
use super::parallel::Parallelism;
use super::pcg::{max_abs, run_cg, Effort};
use super::set::{SetProblem, SetSolve};
use super::spectral::{stale_mean, Precond, SpectralRule, FSAI_RADIUS};
use super::system::Compliance;
use crate::error::{Error, Result};
use crate::green::InfluencePlan;
use coarse::DeviceCoarse;
use device::Gpu;
use fsai::DeviceFsai;
use gpu::Cuda;
use kernels::Kernels;
use operator::Transforms;
use phases::{DevicePhases, DevicePrecond};
use seam::Device;
use timing::{timed, timed_mut, timed_solve, Part};
use vectors::SetVectors;

/// The device's state kept between solves: plans, buffers, the operator's table and the
/// spectral preconditioner's with its `d̄`. On the GPU ([`Cuda`]), or in the tests on the
/// host emulator (`emulator.rs`): the same code.
pub(crate) struct CudaCore<D: Device = Cuda> {
    device: D,
    transforms: Transforms<D>,
    vectors: SetVectors<D>,
    plan: InfluencePlan,
    compliance: Compliance,
    /// Mean diagonal of `C_s` (m/Pa), Jacobi's elastic part.
    diag_c: f64,
    operator: D::Buffer<f64>,
    inverse: Option<(f64, D::Buffer<f64>)>,
    /// FSAI: the exact local entries of `C_s` and the factor on the host (built on first
    /// use), its copy on the device.
    fsai: Option<(Entries, Fsai, DeviceFsai<D>)>,
    /// The two-level preconditioner's coarse space (built on first use).
    coarse: Option<DeviceCoarse<D>>,
    /// The grid product of the last solve (`C_s f` on every cell).
    grid: D::Buffer<f64>,
}

impl<D: Device> std::fmt::Debug for CudaCore<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CudaCore")
            .field("device", &self.device)
            .finish_non_exhaustive()
    }
}

impl CudaCore<Cuda> {
    /// Opens the GPU, checks its free memory against the estimate, compiles the kernels
    /// and allocates everything the solves use.
    pub(crate) fn new(plan: &InfluencePlan, compliance: Compliance) -> Result<Self> {
        let (nx, ny) = (plan.grid().nx(), plan.grid().ny());
        // The kernels index cells with an `int`: every cell, set position and offset
        // below is then one too.
        seam::int("grid cells", nx * ny)?;
        let gpu = Gpu::open()?;
        memory::check_fits(
            &gpu.info.to_string(),
            memory::device_bytes(nx, ny),
            gpu.free_bytes()?,
        )?;
        let kernels = Kernels::compile(&gpu)?;
        CudaCore::on(Cuda { gpu, kernels }, plan, compliance)
    }
}

impl<D: Device> CudaCore<D> {
    /// Everything the solves use allocated on `device`.
    fn on(device: D, plan: &InfluencePlan, compliance: Compliance) -> Result<Self> {
        let (nx, ny) = (plan.grid().nx(), plan.grid().ny());
        let n = nx * ny;
        seam::int("grid cells", n)?;
        // cuFFT's symbols load with its first plan: a panic there is a library problem.
        let transforms = device::guarded("creating the cuFFT plans", || {
            Transforms::new(&device, nx, ny).map_err(|e| e.to_string())
        })
        .map_err(|reason| Error::CudaUnavailable {
            reason,
            hint: libraries::HINT.to_string(),
        })?;
        let vectors = SetVectors::new(&device, n)?;
        let operator = device.upload(
            "cuMemcpyHtoD (DCT table)",
            &operator::table(plan, compliance, |e| e),
        )?;
        let grid = device.zeros::<f64>(n)?;
        Ok(CudaCore {
            diag_c: compliance.mean_diagonal(plan),
            device,
            transforms,
            vectors,
            plan: plan.clone(),
            compliance,
            operator,
            inverse: None,
            fsai: None,
            coarse: None,
            grid,
        })
    }

    fn build_inverse(&mut self, mean_d: f64) -> Result<()> {
        let values = operator::table(&self.plan, self.compliance, |e| 1.0 / (e + mean_d));
        let table = self.device.upload("cuMemcpyHtoD (DCT table)", &values)?;
        self.inverse = Some((mean_d, table));
        Ok(())
    }

    /// Solves `problem` with `precond`; `f` holds the warm start.
    pub(crate) fn solve(
        &mut self,
        problem: SetProblem<'_>,
        precond: Precond,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        timed_solve(|| self.solve_timed(problem, precond, f, effort))
    }

    /// [`CudaCore::solve`], its parts timed when [`timing`] records.
    fn solve_timed(
        &mut self,
        problem: SetProblem<'_>,
        precond: Precond,
        mut f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        let m = problem.set.len();
        let n = self.plan.grid().len();
        // The copies below assume these lengths (the bindings would panic otherwise).
        for (name, found) in [
            ("d (one compliance per set site)", problem.d.len()),
            ("b (one right-hand side per set site)", problem.b.len()),
            ("f (one warm start per set site)", f.len()),
        ] {
            if found != m {
                return Err(Error::LengthMismatch {
                    name,
                    expected: m,
                    found,
                });
            }
        }
        if m > n || problem.set.iter().any(|&i| i >= n) {
            return Err(Error::LengthMismatch {
                name: "set (distinct sites of the grid)",
                expected: n,
                found: m,
            });
        }
        let upkeep = Part::PreconditionerUpkeep;
        if precond == Precond::Spectral {
            if let Some(mean_d) = stale_mean(self.preconditioner_mean(), problem.d) {
                self.timed(upkeep, |core| core.build_inverse(mean_d))?;
            }
        }
        if matches!(precond, Precond::Fsai | Precond::TwoLevel) {
            self.timed(upkeep, |core| {
                core.prepare_fsai(problem, effort.parallelism)
            })?;
        }
        self.timed(Part::Copies, |core| core.upload_problem(problem, &f))?;
        if precond == Precond::TwoLevel {
            self.timed(Part::CoarseUpkeep, |core| core.prepare_coarse(problem))?;
        }
        let norm = self.compliance.norm + problem.d.iter().fold(0.0f64, |a, x| a.max(*x));
        let mut phases = self.phases(precond, m, norm);
        let outcome = run_cg(&mut phases, m, max_abs(problem.b), problem.total, effort)?;
        // The displacements' product `C_s f` on every cell, of the returned `f`.
        self.timed(Part::Operator, |core| core.grid_product())?;
        let (device, v) = (&self.device, &self.vectors);
        let mut grid_product = vec![0.0; n];
        timed(device, Part::Copies, || {
            device.dtoh("cuMemcpyDtoH (tractions)", &v.f, &mut f)?;
            device.dtoh("cuMemcpyDtoH (grid product)", &self.grid, &mut grid_product)?;
            device.synchronize("cuStreamSynchronize (solve results)")
        })?;
        Ok(SetSolve {
            f,
            outcome,
            grid_product,
        })
    }

    /// The phases of a solve of the `m` sites on the device with `precond` (its state
    /// prepared); `norm` bounds `‖A‖₂`.
    fn phases(&mut self, precond: Precond, m: usize, norm: f64) -> DevicePhases<'_, D> {
        let device_precond = match (precond, &self.inverse, &mut self.fsai) {
            (Precond::Spectral, Some((_, table)), _) => DevicePrecond::Spectral { table },
            (Precond::Fsai | Precond::TwoLevel, _, Some((_, _, copy))) => DevicePrecond::Fsai(copy),
            _ => DevicePrecond::Jacobi {
                diag_c: self.diag_c,
            },
        };
        DevicePhases {
            device: &self.device,
            transforms: &mut self.transforms,
            operator: &self.operator,
            v: &mut self.vectors,
            precond: device_precond,
            coarse: match precond {
                Precond::TwoLevel => self.coarse.as_mut().filter(|c| c.valid()),
                _ => None,
            },
            m,
            norm,
        }
    }

    /// `C_s f` on every cell into `grid`, `f` the set vector on the device.
    fn grid_product(&mut self) -> Result<()> {
        let v = &self.vectors;
        self.transforms
            .filter(&self.device, &self.operator, &v.f, &v.pos)?;
        self.transforms.gather_grid(&self.device, &mut self.grid)
    }

    /// The FSAI factor brought up to date for the problem's set and compliances on the
    /// host (the rows around changed sites), then its refreshed rows copied. Its table of
    /// exact entries is built on first use on `parallelism`'s threads.
    fn prepare_fsai(&mut self, problem: SetProblem<'_>, parallelism: Parallelism) -> Result<()> {
        let device = &self.device;
        let (entries, fsai, copy) = match &mut self.fsai {
            Some(built) => built,
            slot => {
                let grid = self.plan.grid();
                let Compliance { scale, shift, .. } = self.compliance;
                let fsai = Fsai::new(grid.nx(), grid.len(), FSAI_RADIUS);
                let copy = DeviceFsai::new(device, &fsai, grid.len())?;
                let entries = Entries::new(&self.plan, scale, shift, parallelism)?;
                slot.insert((entries, fsai, copy))
            }
        };
        fsai.update(entries, problem.set, problem.d);
        copy.sync(device, fsai)
    }

    /// The coarse space brought up to date for the problem's set and compliances (already
    /// on the device). After a failure its state is dropped: the next solve builds it
    /// anew rather than trust a half-updated `E`.
    fn prepare_coarse(&mut self, problem: SetProblem<'_>) -> Result<()> {
        let device = &self.device;
        let coarse = match &mut self.coarse {
            Some(built) => built,
            slot => {
                let grid = self.plan.grid();
                slot.insert(DeviceCoarse::new(device, grid.nx(), grid.ny())?)
            }
        };
        let updated = coarse.update(
            device,
            &mut self.transforms,
            &self.operator,
            &mut self.vectors,
            problem.set,
            problem.d,
        );
        if updated.is_err() {
            self.coarse = None;
        }
        updated
    }

    /// The set, its positions on the grid, `d`, `b` and the warm start `f` to the device.
    fn upload_problem(&mut self, problem: SetProblem<'_>, f: &[f64]) -> Result<()> {
        let m = problem.set.len();
        let n = self.plan.grid().len();
        // Cells and positions are below N, which fits an `int` (`CudaCore::new`).
        let set: Vec<i32> = problem.set.iter().map(|&i| i as i32).collect();
        let mut pos = vec![-1i32; n];
        for (j, &i) in problem.set.iter().enumerate() {
            pos[i] = j as i32;
        }
        let device = &self.device;
        let v = &mut self.vectors;
        let copy = "cuMemcpyHtoD (set problem)";
        device.htod(copy, &pos, &mut v.pos)?;
        if m > 0 {
            device.htod(copy, &set, &mut v.set)?;
            for (host, on_device) in [(problem.d, &mut v.d), (problem.b, &mut v.b), (f, &mut v.f)] {
                device.htod(copy, host, on_device)?;
            }
        }
        Ok(())
    }

    /// Runs `f` on this core, its time added to `part` when [`timing`] records.
    fn timed<T>(&mut self, part: Part, f: impl FnOnce(&mut Self) -> Result<T>) -> Result<T> {
        timed_mut(self, |core| timing::sync(&core.device), part, f)
    }
}

/// The spectral rule on the GPU: the host's preconditioner choices and `d̄`, so a
/// checkpoint resumes across the two backends.
impl<D: Device> SpectralRule for CudaCore<D> {
    fn solve(
        &mut self,
        problem: SetProblem<'_>,
        precond: Precond,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        CudaCore::solve(self, problem, precond, f, effort)
    }
    fn preconditioner_mean(&self) -> Option<f64> {
        self.inverse.as_ref().map(|(d, _)| *d)
    }
    fn restore_preconditioner(&mut self, mean: Option<f64>) -> Result<()> {
        match mean {
            Some(d) => self.build_inverse(d),
            None => {
                self.inverse = None;
                Ok(())
            }
        }
    }
    /// One: the device runs the whole set (the host's threads only build FSAI's table).
    fn parts(&self) -> usize {
        1
    }
    /// Not tracked on the device (the host's tests ask it of the host's backends).
    #[cfg(test)]
    fn built(&self) -> bool {
        false
    }
}

/// The buffers free themselves on the context's stream, which is the calling thread's
/// current context's: a solver dropped on another thread (Python's garbage collector)
/// would leak them without this.
impl<D: Device> Drop for CudaCore<D> {
    fn drop(&mut self) {
        self.device.bind_to_thread();
    }
}
