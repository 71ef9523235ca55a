//! The CG's phases on the device ([`PhaseRunner`]): pcg.rs's scalar logic asks for a
//! phase, the kernels run its local updates and main work on the set vectors, and only
//! the phase's three scalars cross to the host (one small copy per reduction).

use super::coarse::{DeviceCoarse, Target};
use super::fsai::DeviceFsai;
use super::kernels::Launch;
use super::operator::Transforms;
use super::seam::{int, Device};
use super::timing::{timed, Part};
use super::vectors::{SetVectors, REDUCTION_BLOCKS};
use crate::error::Result;
use crate::solver::pcg::{Main, Phase, PhaseRunner, Pre};

/// The preconditioner of a device solve.
pub(super) enum DevicePrecond<'a, D: Device> {
    /// `z = r / (diag_c + d)`.
    Jacobi { diag_c: f64 },
    /// `z = P_S (C_s + d̄ I)⁻¹ P_S r` through its DCT table.
    Spectral { table: &'a D::Buffer<f64> },
    /// `z = Gᵀ G r`, the host's FSAI factor copied to the device.
    Fsai(&'a mut DeviceFsai<D>),
}

/// One set solve's phases on the device.
pub(super) struct DevicePhases<'a, D: Device> {
    pub(super) device: &'a D,
    pub(super) transforms: &'a mut Transforms<D>,
    pub(super) operator: &'a D::Buffer<f64>,
    pub(super) v: &'a mut SetVectors<D>,
    pub(super) precond: DevicePrecond<'a, D>,
    /// Sites in the set.
    pub(super) m: usize,
    /// `‖A‖₂` bound (m/Pa).
    pub(super) norm: f64,
    /// The coarse space, when it applies (A-DEF2: pcg.rs).
    pub(super) coarse: Option<&'a mut DeviceCoarse<D>>,
}

/// Which vectors a product reads and writes.
#[derive(Clone, Copy)]
enum Product {
    /// `q = A p`.
    Direction,
    /// `r = A f`.
    Residual,
    /// `t = A z` (the coarse correction's).
    Coarse,
}

impl<D: Device> PhaseRunner for DevicePhases<'_, D> {
    /// The phase's kernels, FFTs and copies; the first that fails stops the CG with its
    /// error (`Error::Cuda` naming the call).
    /// Each part is timed when [`super::timing`] records (docs/gpu.md).
    fn run(&mut self, phase: Phase) -> Result<[f64; 3]> {
        let device = self.device;
        timed(device, Part::Updates, || self.pre(phase.pre))?;
        timed(device, Part::Preconditioner, || self.prolong(phase.pre))?;
        let reductions = Part::Reductions;
        match phase.main {
            Main::Nothing => Ok([0.0; 3]),
            Main::SumF => {
                let [s, _, _] = timed(device, reductions, || {
                    self.reduce(0, Vector::F, Vector::F, Vector::F)
                })?;
                Ok([s, 0.0, 0.0])
            }
            Main::Direction { .. } => {
                timed(device, Part::Operator, || self.product(Product::Direction))?;
                let [pq, _, _] = timed(device, reductions, || {
                    self.reduce(1, Vector::P, Vector::Q, Vector::Q)
                })?;
                Ok([pq, 0.0, 0.0])
            }
            Main::Residual { offset, .. } => {
                timed(device, Part::Operator, || self.product(Product::Residual))?;
                timed(device, Part::Updates, || self.residual_tail(offset))?;
                Ok([0.0; 3])
            }
            Main::Precondition { .. } => {
                timed(device, Part::Preconditioner, || self.precondition())?;
                let [s, _, _] = timed(device, reductions, || {
                    self.reduce(0, Vector::Z, Vector::Z, Vector::Z)
                })?;
                Ok([s, 0.0, 0.0])
            }
            Main::Measure => timed(device, reductions, || {
                self.reduce(2, Vector::R, Vector::F, Vector::Z)
            }),
            Main::CoarseProduct { .. } => {
                timed(device, Part::Operator, || self.product(Product::Coarse))?;
                timed(device, Part::Preconditioner, || self.restrict(true))?;
                Ok([0.0; 3])
            }
            Main::Restrict => {
                timed(device, Part::Preconditioner, || self.restrict(false))?;
                Ok([0.0; 3])
            }
        }
    }

    fn product_stages(&self) -> usize {
        1
    }
    fn precondition_stages(&self) -> usize {
        1
    }
    fn norm_bound(&self) -> f64 {
        self.norm
    }
    fn has_coarse(&self) -> bool {
        self.coarse.as_ref().is_some_and(|c| c.valid())
    }
    fn coarse_solve(&mut self) -> Result<()> {
        match self.coarse.as_deref_mut() {
            Some(coarse) => timed(self.device, Part::Preconditioner, || {
                coarse.solve(self.device)
            }),
            None => Ok(()),
        }
    }
}

impl<D: Device> DevicePhases<'_, D> {
    /// `Zᵀ (r - t)` (`with_t`) or `Zᵀ r`, for the next coarse solve (asked only when the
    /// coarse space applies).
    fn restrict(&mut self, with_t: bool) -> Result<()> {
        let Some(coarse) = self.coarse.as_deref_mut() else {
            return Ok(());
        };
        let v = &*self.v;
        let t = with_t.then_some(&v.t);
        coarse.restrict(self.device, &v.r, t, &v.pos, Target::Rhs)
    }

    /// The prolongations a phase's updates ask for, after the others: `f -= Z y`,
    /// `z += Z y`.
    fn prolong(&mut self, pre: Pre) -> Result<()> {
        let Some(coarse) = self.coarse.as_deref() else {
            return Ok(());
        };
        let v = &mut *self.v;
        if pre.coarse_f {
            coarse.prolong(self.device, &mut v.f, -1.0, &v.set, self.m)?;
        }
        if pre.coarse_z {
            coarse.prolong(self.device, &mut v.z, 1.0, &v.set, self.m)?;
        }
        Ok(())
    }

    /// The local updates of `pre` (pcg.rs's `Pre::apply`, kernels.cu's flags).
    fn pre(&mut self, pre: Pre) -> Result<()> {
        let mut flags = 0i32;
        let (mut shift, mut alpha, mut u, mut beta) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        if pre.keep_best {
            flags |= 1;
        }
        if pre.restore_best {
            flags |= 2;
        }
        if let Some(s) = pre.shift_f {
            flags |= 4;
            shift = s;
        }
        if let Some((a, update_r)) = pre.step {
            flags |= 8;
            alpha = a;
            if update_r {
                flags |= 16;
            }
        }
        if let Some(value) = pre.project {
            flags |= 32;
            u = value;
        }
        if pre.w_from_z {
            flags |= 64;
        }
        match pre.direction {
            Some(None) => flags |= 128,
            Some(Some(b)) => {
                flags |= 256;
                beta = b;
            }
            None => {}
        }
        if pre.fill_r_one {
            flags |= 512;
        }
        if flags == 0 {
            return Ok(());
        }
        let Some(cfg) = self.device.over("sites in the set", self.m)? else {
            return Ok(());
        };
        let m = int("sites in the set", self.m)?;
        let v = &mut *self.v;
        // SAFETY: every vector holds at least m values.
        unsafe {
            self.device.pre_updates(
                cfg,
                &mut v.f,
                &mut v.r,
                &mut v.z,
                &mut v.p,
                &v.q,
                &mut v.w,
                &mut v.best,
                flags,
                shift,
                alpha,
                u,
                beta,
                m,
            )
        }
    }

    /// `q = A p` or `r = A f` (`A = C_SS + diag(d)`).
    fn product(&mut self, which: Product) -> Result<()> {
        let v = &mut *self.v;
        let (x, y) = match which {
            Product::Direction => (&v.p, &mut v.q),
            Product::Residual => (&v.f, &mut v.r),
            Product::Coarse => (&v.z, &mut v.t),
        };
        self.transforms
            .filter(self.device, self.operator, x, &v.pos)?;
        self.transforms
            .gather_set(self.device, &v.set, &v.d, x, y, true, self.m)
    }

    /// `r += offset - b`.
    fn residual_tail(&mut self, offset: f64) -> Result<()> {
        let Some(cfg) = self.device.over("sites in the set", self.m)? else {
            return Ok(());
        };
        let m = int("sites in the set", self.m)?;
        let v = &mut *self.v;
        // SAFETY: r and b hold at least m values.
        unsafe { self.device.residual_tail(cfg, &mut v.r, &v.b, offset, m) }
    }

    /// `z = M⁻¹ r`.
    fn precondition(&mut self) -> Result<()> {
        let v = &mut *self.v;
        match &mut self.precond {
            DevicePrecond::Jacobi { diag_c } => {
                let Some(cfg) = self.device.over("sites in the set", self.m)? else {
                    return Ok(());
                };
                let m = int("sites in the set", self.m)?;
                // SAFETY: r, d, z hold at least m values.
                unsafe { self.device.jacobi(cfg, &v.r, &v.d, *diag_c, &mut v.z, m) }
            }
            DevicePrecond::Spectral { table } => {
                self.transforms.filter(self.device, table, &v.r, &v.pos)?;
                self.transforms
                    .gather_set(self.device, &v.set, &v.d, &v.r, &mut v.z, false, self.m)
            }
            DevicePrecond::Fsai(fsai) => {
                fsai.apply(self.device, &v.set, &v.pos, &v.r, &mut v.z, self.m)
            }
        }
    }

    /// A reduction in a fixed order (kernels.cu's modes: 0 `Σ a`, 1 `aᵀ b`, 2
    /// `[max |a|, max |b|, aᵀ c]`), its three values copied to the host.
    fn reduce(&mut self, mode: i32, a: Vector, b: Vector, c: Vector) -> Result<[f64; 3]> {
        let device = self.device;
        let count = self
            .m
            .div_ceil(device.threads() as usize)
            .clamp(1, REDUCTION_BLOCKS);
        let (m, count32) = (
            int("sites in the set", self.m)?,
            int("reduction blocks", count)?,
        );
        let (first, last) = (
            device.blocks("reduction blocks", count)?,
            device.blocks("one block", 1)?,
        );
        let SetVectors {
            f,
            r,
            z,
            p,
            q,
            partials,
            scalars,
            ..
        } = &mut *self.v;
        let (f, r, z, p, q) = (&*f, &*r, &*z, &*p, &*q);
        let of = move |which: Vector| -> &D::Buffer<f64> {
            match which {
                Vector::F => f,
                Vector::R => r,
                Vector::Z => z,
                Vector::P => p,
                Vector::Q => q,
            }
        };
        let (a, b, c) = (of(a), of(b), of(c));
        // SAFETY: a, b, c hold at least m values, `partials` 3 per block, `scalars` 3.
        unsafe { device.reduce_partial(first, mode, a, b, c, m, partials) }?;
        // SAFETY: as above.
        unsafe { device.reduce_final(last, mode, partials, count32, scalars) }?;
        let mut out = [0.0f64; 3];
        device.dtoh("cuMemcpyDtoH (reduction)", scalars, &mut out)?;
        device.synchronize("cuStreamSynchronize (reduction)")?;
        Ok(out)
    }
}

/// A set vector a reduction reads.
#[derive(Clone, Copy)]
enum Vector {
    F,
    R,
    Z,
    P,
    Q,
}
