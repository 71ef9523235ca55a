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
use super::kernels::{blocks, int, over, Kernels};
use super::operator::Transforms;
use super::vectors::SetVectors;
use crate::error::Result;
use crate::solver::coarse::Aggregates;
use cudarc::driver::{CudaSlice, CudaStream};
use std::sync::Arc;

/// The bytes of a [`DeviceCoarse`] with `count` aggregates.
pub(super) fn coarse_bytes(count: usize) -> f64 {
    8.0 * (3 * count * count + 5 * count + 2) as f64
}

/// The aggregates whose column of `E` the last [`Aggregates::enter`] made stale: those
/// whose sites or compliances changed, ascending.
pub(super) fn stale_columns(aggregates: &Aggregates) -> Vec<usize> {
    let layout = aggregates.layout();
    (0..aggregates.count())
        .filter(|&a| layout.touched[a])
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
            nx: int("grid cells along x", nx)?,
            ny: int("grid cells along y", ny)?,
            block: int("cells per aggregate side", aggregates.layout().block)?,
            bx: int("aggregates along x", aggregates.layout().blocks_x)?,
            count: int("aggregates", count)?,
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
            .map_err(|e| cuda_error("cuMemcpyHtoD (aggregate site counts)", e))?;
        for a in stale_columns(&self.aggregates) {
            if let Some(cfg) = over("sites in the set", m)? {
                let (m32, a32) = (int("sites in the set", m)?, int("aggregates", a)?);
                // SAFETY: set and p hold at least m values.
                unsafe {
                    kernels.coarse_indicator(
                        stream, cfg, &v.set, m32, self.nx, self.block, self.bx, a32, &mut v.p,
                    )
                }?;
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
        let one = blocks("one block", 1)?;
        let each = over("aggregates", self.count as usize)?.unwrap_or(one);
        // SAFETY (this function's launches): e, lower and inverse hold count² values, c
        // and w count, info 2.
        unsafe { kernels.coarse_fix_empty(stream, each, &mut self.e, &self.c, self.count) }?;
        stream
            .memcpy_dtod(&self.e, &mut self.lower)
            .map_err(|e| cuda_error("cuMemcpyDtoD (coarse matrix to its factor)", e))?;
        unsafe { kernels.coarse_factor(stream, one, &mut self.lower, self.count, &mut self.info) }?;
        unsafe { kernels.coarse_invert(stream, each, &self.lower, self.count, &mut self.inverse) }?;
        unsafe {
            kernels.coarse_border(
                stream,
                one,
                &self.inverse,
                &self.c,
                self.count,
                &mut self.w,
                &mut self.info,
            )
        }?;
        let mut info = [0.0f64; 2];
        stream
            .memcpy_dtoh(&self.info, info.as_mut_slice())
            .map_err(|e| cuda_error("cuMemcpyDtoH (coarse validity)", e))?;
        stream
            .synchronize()
            .map_err(|e| cuda_error("cuStreamSynchronize (coarse upkeep)", e))?;
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
        // One block per aggregate.
        let cfg = blocks("aggregates", self.count as usize)?;
        let subtract = i32::from(t.is_some());
        let (out, column) = match into {
            Target::Column(a) => (&mut self.e, int("aggregates", a)?),
            Target::Rhs => (&mut self.g, -1),
        };
        // SAFETY: x and t hold a value per set site, pos one per cell, out count² values
        // (a column) or count.
        unsafe {
            kernels.coarse_restrict(
                stream,
                cfg,
                x,
                t.unwrap_or(x),
                subtract,
                pos,
                self.nx,
                self.ny,
                self.block,
                self.bx,
                out,
                column,
                self.count,
            )
        }
    }

    /// The bordered coarse solve of the last restriction, left on the device.
    pub(super) fn solve(&mut self, stream: &Arc<CudaStream>, kernels: &Kernels) -> Result<()> {
        let one = blocks("one block", 1)?;
        // SAFETY: inverse holds count² values, g, c, w and solution count, info 2.
        unsafe {
            kernels.coarse_solve(
                stream,
                one,
                &self.inverse,
                &self.g,
                &self.c,
                &self.w,
                &self.info,
                self.count,
                &mut self.solution,
            )
        }
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
        let Some(cfg) = over("sites in the set", m)? else {
            return Ok(());
        };
        let m32 = int("sites in the set", m)?;
        // SAFETY: x and set hold at least m values, solution count.
        unsafe {
            kernels.coarse_prolong(
                stream,
                cfg,
                x,
                &self.solution,
                sign,
                set,
                m32,
                self.nx,
                self.block,
                self.bx,
            )
        }
    }
}
