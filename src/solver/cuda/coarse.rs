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

use super::kernels::Launch;
use super::operator::Transforms;
use super::seam::{int, Device};
use super::vectors::SetVectors;
use crate::error::Result;
use crate::solver::coarse::Aggregates;

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
pub(super) struct DeviceCoarse<D: Device> {
    aggregates: Aggregates,
    /// Kernel arguments: grid width and height, cells per block side, blocks along x,
    /// aggregates.
    nx: i32,
    ny: i32,
    block: i32,
    bx: i32,
    count: i32,
    pub(super) e: D::Buffer<f64>,
    lower: D::Buffer<f64>,
    inverse: D::Buffer<f64>,
    /// Site counts per aggregate, `E⁻¹ c`, the restriction, the solution, `[valid, cᵀ w]`.
    c: D::Buffer<f64>,
    w: D::Buffer<f64>,
    g: D::Buffer<f64>,
    pub(super) solution: D::Buffer<f64>,
    pub(super) info: D::Buffer<f64>,
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

impl<D: Device> DeviceCoarse<D> {
    /// The aggregates of an `nx x ny` grid, nothing on the set yet.
    pub(super) fn new(device: &D, nx: usize, ny: usize) -> Result<Self> {
        let aggregates = Aggregates::new(nx, ny);
        let count = aggregates.count();
        let real = |len: usize| device.zeros::<f64>(len);
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
        device: &D,
        transforms: &mut Transforms<D>,
        operator: &D::Buffer<f64>,
        v: &mut SetVectors<D>,
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
        device.htod("cuMemcpyHtoD (aggregate site counts)", &counts, &mut self.c)?;
        for a in stale_columns(&self.aggregates) {
            if let Some(cfg) = device.over("sites in the set", m)? {
                let (m32, a32) = (int("sites in the set", m)?, int("aggregates", a)?);
                // SAFETY: set and p hold at least m values.
                unsafe {
                    device.coarse_indicator(
                        cfg, &v.set, m32, self.nx, self.block, self.bx, a32, &mut v.p,
                    )
                }?;
            }
            transforms.filter(device, operator, &v.p, &v.pos)?;
            transforms.gather_set(device, &v.set, &v.d, &v.p, &mut v.q, true, m)?;
            self.restrict(device, &v.q, None, &v.pos, Target::Column(a))?;
        }
        self.factor(device)
    }

    /// The empty aggregates fixed, then `E`'s factor, inverse and border; the validity
    /// read back.
    fn factor(&mut self, device: &D) -> Result<()> {
        let one = device.blocks("one block", 1)?;
        let each = device
            .over("aggregates", self.count as usize)?
            .unwrap_or(one);
        // SAFETY (this function's launches): e, lower and inverse hold count² values, c
        // and w count, info 2.
        unsafe { device.coarse_fix_empty(each, &mut self.e, &self.c, self.count) }?;
        device.dtod(
            "cuMemcpyDtoD (coarse matrix to its factor)",
            &self.e,
            &mut self.lower,
        )?;
        unsafe { device.coarse_factor(one, &mut self.lower, self.count, &mut self.info) }?;
        unsafe { device.coarse_invert(each, &self.lower, self.count, &mut self.inverse) }?;
        unsafe {
            device.coarse_border(
                one,
                &self.inverse,
                &self.c,
                self.count,
                &mut self.w,
                &mut self.info,
            )
        }?;
        let mut info = [0.0f64; 2];
        device.dtoh("cuMemcpyDtoH (coarse validity)", &self.info, &mut info)?;
        device.synchronize("cuStreamSynchronize (coarse upkeep)")?;
        self.valid = info[0] == 1.0;
        Ok(())
    }

    /// `Zᵀ (x - t)` (`t` given) or `Zᵀ x` into `into`.
    pub(super) fn restrict(
        &mut self,
        device: &D,
        x: &D::Buffer<f64>,
        t: Option<&D::Buffer<f64>>,
        pos: &D::Buffer<i32>,
        into: Target,
    ) -> Result<()> {
        // One block per aggregate.
        let cfg = device.blocks("aggregates", self.count as usize)?;
        let subtract = i32::from(t.is_some());
        let (out, column) = match into {
            Target::Column(a) => (&mut self.e, int("aggregates", a)?),
            Target::Rhs => (&mut self.g, -1),
        };
        // SAFETY: x and t hold a value per set site, pos one per cell, out count² values
        // (a column) or count.
        unsafe {
            device.coarse_restrict(
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
    pub(super) fn solve(&mut self, device: &D) -> Result<()> {
        let one = device.blocks("one block", 1)?;
        // SAFETY: inverse holds count² values, g, c, w and solution count, info 2.
        unsafe {
            device.coarse_solve(
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
        device: &D,
        x: &mut D::Buffer<f64>,
        sign: f64,
        set: &D::Buffer<i32>,
        m: usize,
    ) -> Result<()> {
        let Some(cfg) = device.over("sites in the set", m)? else {
            return Ok(());
        };
        let m32 = int("sites in the set", m)?;
        // SAFETY: x and set hold at least m values, solution count.
        unsafe {
            device.coarse_prolong(
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
