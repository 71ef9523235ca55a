//! The coarse space of the two-level preconditioner on the device (solver/coarse.rs's
//! aggregates; the CG applies it as A-DEF2). The host tracks which aggregates' sites or
//! compliances changed; the device keeps `E = Zᵀ A Z`, its factor, its inverse and the
//! border `w = E⁻¹ c`, `cᵀ w` (kernels.cu), so a CG iteration's coarse work (a restriction,
//! a solve of at most 512 unknowns, a prolongation) never leaves it.
//!
//! Why `E`'s columns come from operator products: column `a` is `Zᵀ A 1_{S_a}`, one DCT
//! product per changed aggregate, at any `N`. The host's pair sums of exact entries
//! cost `|S_a| N` per changed aggregate (4e9 terms at N = 1e6). The price: an entry of
//! `E` comes from the product of whichever of its two aggregates changed last, so its
//! last bits depend on the run's history (a resumed run agrees with the uninterrupted
//! one to rounding, not bit for bit; docs/gpu.md).

use super::device::{cuda_error, zeros};
use super::operator::{over, Kernels, Transforms, THREADS};
use super::vectors::SetVectors;
use crate::error::Result;
use crate::solver::coarse::Aggregates;
use cudarc::driver::{CudaSlice, CudaStream, LaunchConfig, PushKernelArg};
use std::sync::Arc;

/// The bytes of a [`DeviceCoarse`] with `count` aggregates.
pub(super) fn coarse_bytes(count: usize) -> f64 {
    8.0 * (3 * count * count + 5 * count + 2) as f64
}

/// The aggregates whose column of `E` the last [`Aggregates::enter`] made stale: those
/// whose sites or compliances changed, ascending.
pub(super) fn stale_columns(aggregates: &Aggregates) -> Vec<usize> {
    (0..aggregates.count())
        .filter(|&a| aggregates.touched(a))
        .collect()
}

/// The device's coarse space.
pub(super) struct DeviceCoarse {
    aggregates: Aggregates,
    /// Kernel arguments: grid width and height, cells per block side, blocks along x,
    /// aggregates.
    nx: i32,
    ny: i32,
    block: i32,
    bx: i32,
    count: i32,
    e: CudaSlice<f64>,
    lower: CudaSlice<f64>,
    inverse: CudaSlice<f64>,
    /// Site counts per aggregate, `E⁻¹ c`, the restriction, the solution, `[valid, cᵀ w]`.
    c: CudaSlice<f64>,
    w: CudaSlice<f64>,
    g: CudaSlice<f64>,
    solution: CudaSlice<f64>,
    info: CudaSlice<f64>,
    /// Whether `E` was positive definite (the correction is skipped otherwise).
    valid: bool,
}

/// Where a restriction goes.
pub(super) enum Target {
    /// Column and row `a` of `E`.
    Column(usize),
    /// The restriction a coarse solve reads.
    Rhs,
}

impl DeviceCoarse {
    /// The aggregates of an `nx x ny` grid, nothing on the set yet.
    pub(super) fn new(stream: &Arc<CudaStream>, nx: usize, ny: usize) -> Result<Self> {
        let aggregates = Aggregates::new(nx, ny);
        let count = aggregates.count();
        let real = |len: usize| zeros::<f64>(stream, len);
        Ok(DeviceCoarse {
            nx: nx as i32,
            ny: ny as i32,
            block: aggregates.block() as i32,
            bx: aggregates.blocks_x() as i32,
            count: count as i32,
            aggregates,
            e: real(count * count)?,
            lower: real(count * count)?,
            inverse: real(count * count)?,
            c: real(count)?,
            w: real(count)?,
            g: real(count)?,
            solution: real(count)?,
            info: real(2)?,
            valid: false,
        })
    }

    /// Whether the coarse correction applies.
    pub(super) fn valid(&self) -> bool {
        self.valid
    }

    /// Brings `E`, its factor, inverse and border up to date for `set` with compliances
    /// `d`, both already on the device in `v` (`v.p`, `v.q` serve as scratch: the CG
    /// sets them before reading them). One product per stale column; the factor only
    /// when a column changed. Reads the validity back (one small copy).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn update(
        &mut self,
        stream: &Arc<CudaStream>,
        kernels: &Kernels,
        transforms: &mut Transforms,
        operator: &CudaSlice<f64>,
        v: &mut SetVectors,
        set: &[usize],
        d: &[f64],
    ) -> Result<()> {
        if self.aggregates.enter(set, d).is_none() {
            return Ok(());
        }
        let m = set.len();
        let mut counts = vec![0.0; self.aggregates.count()];
        for (a, c) in counts.iter_mut().enumerate() {
            *c = self.aggregates.members(a).len() as f64;
        }
        stream
            .memcpy_htod(&counts, &mut self.c)
            .map_err(|e| cuda_error("cuMemcpyHtoD", e))?;
        for a in stale_columns(&self.aggregates) {
            if let Some(cfg) = over(m) {
                let (m32, a32) = (m as i32, a as i32);
                // SAFETY: the argument list matches kernels.cu's coarse_indicator; set and
                // p hold at least m values.
                unsafe {
                    stream
                        .launch_builder(&kernels.coarse_indicator)
                        .arg(&v.set)
                        .arg(&m32)
                        .arg(&self.nx)
                        .arg(&self.block)
                        .arg(&self.bx)
                        .arg(&a32)
                        .arg(&mut v.p)
                        .launch(cfg)
                }
                .map_err(|e| cuda_error("coarse_indicator", e))?;
            }
            transforms.filter(stream, kernels, operator, &v.p, &v.pos)?;
            transforms.gather_set(stream, kernels, &v.set, &v.d, &v.p, &mut v.q, true, m)?;
            self.restrict(stream, kernels, &v.q, None, &v.pos, Target::Column(a))?;
        }
        self.factor(stream, kernels)
    }

    /// The empty aggregates fixed, then `E`'s factor, inverse and border; the validity
    /// read back.
    fn factor(&mut self, stream: &Arc<CudaStream>, kernels: &Kernels) -> Result<()> {
        let one = LaunchConfig {
            grid_dim: (1, 1, 1),
            block_dim: (THREADS, 1, 1),
            shared_mem_bytes: 0,
        };
        let each = over(self.count as usize).unwrap_or(one);
        // SAFETY (this function's launches): the argument lists match kernels.cu's
        // coarse_fix_empty, coarse_factor, coarse_invert and coarse_border; e, lower and
        // inverse hold count² values, c and w count, info 2.
        unsafe {
            stream
                .launch_builder(&kernels.coarse_fix_empty)
                .arg(&mut self.e)
                .arg(&self.c)
                .arg(&self.count)
                .launch(each)
        }
        .map_err(|e| cuda_error("coarse_fix_empty", e))?;
        stream
            .memcpy_dtod(&self.e, &mut self.lower)
            .map_err(|e| cuda_error("cuMemcpyDtoD", e))?;
        unsafe {
            stream
                .launch_builder(&kernels.coarse_factor)
                .arg(&mut self.lower)
                .arg(&self.count)
                .arg(&mut self.info)
                .launch(one)
        }
        .map_err(|e| cuda_error("coarse_factor", e))?;
        unsafe {
            stream
                .launch_builder(&kernels.coarse_invert)
                .arg(&self.lower)
                .arg(&self.count)
                .arg(&mut self.inverse)
                .launch(each)
        }
        .map_err(|e| cuda_error("coarse_invert", e))?;
        unsafe {
            stream
                .launch_builder(&kernels.coarse_border)
                .arg(&self.inverse)
                .arg(&self.c)
                .arg(&self.count)
                .arg(&mut self.w)
                .arg(&mut self.info)
                .launch(one)
        }
        .map_err(|e| cuda_error("coarse_border", e))?;
        let mut info = [0.0f64; 2];
        stream
            .memcpy_dtoh(&self.info, info.as_mut_slice())
            .map_err(|e| cuda_error("cuMemcpyDtoH", e))?;
        stream
            .synchronize()
            .map_err(|e| cuda_error("cuStreamSynchronize", e))?;
        self.valid = info[0] == 1.0;
        Ok(())
    }

    /// `Zᵀ (x - t)` (`t` given) or `Zᵀ x` into `into`.
    pub(super) fn restrict(
        &mut self,
        stream: &Arc<CudaStream>,
        kernels: &Kernels,
        x: &CudaSlice<f64>,
        t: Option<&CudaSlice<f64>>,
        pos: &CudaSlice<i32>,
        into: Target,
    ) -> Result<()> {
        let cfg = LaunchConfig {
            grid_dim: (self.count as u32, 1, 1),
            block_dim: (THREADS, 1, 1),
            shared_mem_bytes: 0,
        };
        let subtract = i32::from(t.is_some());
        let (out, column) = match into {
            Target::Column(a) => (&mut self.e, a as i32),
            Target::Rhs => (&mut self.g, -1),
        };
        // SAFETY: the argument list matches kernels.cu's coarse_restrict; x and t hold a
        // value per set site, pos one per cell, out count² values (a column) or count.
        unsafe {
            stream
                .launch_builder(&kernels.coarse_restrict)
                .arg(x)
                .arg(t.unwrap_or(x))
                .arg(&subtract)
                .arg(pos)
                .arg(&self.nx)
                .arg(&self.ny)
                .arg(&self.block)
                .arg(&self.bx)
                .arg(out)
                .arg(&column)
                .arg(&self.count)
                .launch(cfg)
        }
        .map(|_| ())
        .map_err(|e| cuda_error("coarse_restrict", e))
    }

    /// The bordered coarse solve of the last restriction, left on the device.
    pub(super) fn solve(&mut self, stream: &Arc<CudaStream>, kernels: &Kernels) -> Result<()> {
        let one = LaunchConfig {
            grid_dim: (1, 1, 1),
            block_dim: (THREADS, 1, 1),
            shared_mem_bytes: 0,
        };
        // SAFETY: the argument list matches kernels.cu's coarse_solve; inverse holds
        // count² values, g, c, w and solution count, info 2.
        unsafe {
            stream
                .launch_builder(&kernels.coarse_solve)
                .arg(&self.inverse)
                .arg(&self.g)
                .arg(&self.c)
                .arg(&self.w)
                .arg(&self.info)
                .arg(&self.count)
                .arg(&mut self.solution)
                .launch(one)
        }
        .map(|_| ())
        .map_err(|e| cuda_error("coarse_solve", e))
    }

    /// `x += sign Z y` on the `m` sites of `set`, `y` the last coarse solution.
    pub(super) fn prolong(
        &self,
        stream: &Arc<CudaStream>,
        kernels: &Kernels,
        x: &mut CudaSlice<f64>,
        sign: f64,
        set: &CudaSlice<i32>,
        m: usize,
    ) -> Result<()> {
        let Some(cfg) = over(m) else {
            return Ok(());
        };
        let m32 = m as i32;
        // SAFETY: the argument list matches kernels.cu's coarse_prolong; x and set hold
        // at least m values, solution count.
        unsafe {
            stream
                .launch_builder(&kernels.coarse_prolong)
                .arg(x)
                .arg(&self.solution)
                .arg(&sign)
                .arg(set)
                .arg(&m32)
                .arg(&self.nx)
                .arg(&self.block)
                .arg(&self.bx)
                .launch(cfg)
        }
        .map(|_| ())
        .map_err(|e| cuda_error("coarse_prolong", e))
    }
}
